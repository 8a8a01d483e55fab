#include "io/output_guard.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace codyna {

namespace {

std::string head_of(const std::string& path, std::size_t n) {
  std::string s(n, '\0');
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return {};
  s.resize(std::fread(s.data(), 1, n, f));
  std::fclose(f);
  return s;
}

bool starts_with(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }

// what codyna itself writes, told by the first bytes
bool written_by_codyna(const std::string& path, OutputKind k) {
  const std::string h = head_of(path, 512);
  switch (k) {
    case OutputKind::ResultsHdf5:
      return starts_with(h, "\x89HDF\r\n\x1a\n");  // an HDF5 file (results are read back by read_results_hdf5)
    case OutputKind::ResultsCsv: {
      // the header row of a codyna results table: "t,..."
      return starts_with(h, "t,") || starts_with(h, "\"t\",");
    }
    case OutputKind::CurvesCsv:
      return starts_with(h, "t,") || starts_with(h, "w,");
    case OutputKind::PlantMat:
      return (starts_with(h, "MATLAB 5.0 MAT-file") || starts_with(h, "MATLAB 7.3 MAT-file")) &&
             h.find("codyna") != std::string::npos;
    case OutputKind::PlantScript:
      return starts_with(h, "% ") && h.substr(0, h.find('\n')).find("exported by codyna") != std::string::npos;
    case OutputKind::Mjcf:
      return starts_with(h, "<!-- MJCF written by codyna");  // io/export_mjcf.hpp's kMjcfHeader
    case OutputKind::SweepCsv:
      return starts_with(h, "variant,status");  // io/sweep_files.hpp's kSweepCsvHead
    case OutputKind::TireCsv:
      return starts_with(h, "Fx,Fy,Fz,");
    case OutputKind::FrequencyResponseCsv:
      return starts_with(h, "w_rad_s,f_Hz,");
    case OutputKind::KcCsv:
      return starts_with(h, "sweep,wheel,travel_m,");
  }
  return false;
}

std::string first_line(const std::string& path) {
  std::string h = head_of(path, 60);
  h = h.substr(0, h.find('\n'));
  for (char& c : h)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return h;
}

}  // namespace

const char* describe(OutputKind k) {
  switch (k) {
    case OutputKind::ResultsHdf5: return "an HDF5 results file";
    case OutputKind::ResultsCsv: return "a CSV results file";
    case OutputKind::CurvesCsv: return "a CSV of closed-loop responses";
    case OutputKind::PlantMat: return "a plant .mat export";
    case OutputKind::PlantScript: return "a plant .m export";
    case OutputKind::Mjcf: return "an MJCF export";
    case OutputKind::SweepCsv: return "a sweep CSV";
    case OutputKind::TireCsv: return "a tire CSV";
    case OutputKind::FrequencyResponseCsv: return "a frequency-response CSV";
    case OutputKind::KcCsv: return "a K&C rig CSV";
  }
  return "an output";
}

bool same_file(const std::string& path, const std::string& other) {
  struct stat a{}, b{};
  if (path.empty() || other.empty() || ::stat(path.c_str(), &a) != 0 || ::stat(other.c_str(), &b) != 0) return false;
  return a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

void guard_output(const std::string& path, OutputKind kind, const std::vector<std::string>& inputs) {
  if (path.empty()) throw std::invalid_argument("an output path is empty");
  for (const std::string& in : inputs)
    if (same_file(path, in))
      throw std::invalid_argument(path + ": this is the input file " + in +
                                  " (the same file); codyna never writes an output over its input: choose another name");
  struct stat st{};
  if (::lstat(path.c_str(), &st) != 0) return;  // nothing there: fine
  if (S_ISLNK(st.st_mode) && ::stat(path.c_str(), &st) != 0) return;  // a dangling link is replaced by the output
  if (!S_ISREG(st.st_mode))
    throw std::invalid_argument(path + ": exists and is not a regular file (" +
                                (S_ISDIR(st.st_mode) ? std::string("a directory") : std::string("a FIFO, socket or device")) +
                                "); choose another name");
  if (st.st_size == 0) return;  // an empty file holds nothing to lose
  if (!written_by_codyna(path, kind))
    throw std::invalid_argument(path + ": exists and is not " + describe(kind) + " written by codyna (it begins \"" +
                                first_line(path) + "\"); codyna never replaces a file it did not write: remove it "
                                "or choose another name");
}

}  // namespace codyna
