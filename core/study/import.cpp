#include "study/import.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "dynamics/prepare.hpp"
#include "io/atomic_file.hpp"
#include "io/export_mjcf.hpp"
#include "io/import_mjcf.hpp"
#include "io/import_urdf.hpp"
#include "io/model_file.hpp"
#include "io/output_guard.hpp"
#include "model/errors.hpp"

namespace codyna {

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}
std::string import_head(const std::string& path, std::size_t n) {
  std::ifstream f(path, std::ios::binary);
  std::string s(n, '\0');
  f.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(f.gcount()));
  return s;
}
}  // namespace

std::string study_import_format(const std::string& path) {
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".urdf") return "URDF";
  if (ext == ".mjcf") return "MJCF";
  const std::string h = import_head(path, 4096);
  const auto robot = h.find("<robot"), mujoco = h.find("<mujoco");
  if (robot != std::string::npos && (mujoco == std::string::npos || robot < mujoco)) return "URDF";
  if (mujoco != std::string::npos) return "MJCF";
  if (ext == ".xml") return "MJCF";
  return "";
}

bool study_import_available(const std::string& format) {
  if (format == "MJCF") return mjcf_import_available();
  if (format == "URDF") return urdf_import_available();
  return false;
}

ImportResult study_import(const std::string& path, const ImportOptions& options) {
  check_import_options(options);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw std::invalid_argument(path + ": cannot open file: No such file or directory");
  const std::string format = study_import_format(path);
  if (format.empty())
    throw std::invalid_argument(path + ": neither MJCF (<mujoco>, .xml) nor URDF (<robot>, .urdf): codyna imports those two");
  ImportResult r = format == "URDF" ? import_urdf(path, options) : import_mjcf(path, options);
  try {
    (void)compile(r.spec, path);
  } catch (const ModelError& e) {
    throw std::runtime_error(path + ": the imported model does not compile (a fault of the importer, please report it): " +
                             e.detail() + (e.path().empty() ? "" : " at " + e.path()));
  }
  return r;
}

ExportMjcfResult study_mjcf(const ModelSpec& spec, const std::string& label) {
  const Model m = compile(spec, label);
  MjcfExport e = export_mjcf(m, label);
  ExportMjcfResult r;
  if (mjcf_load_check_available()) {
    const std::string err = mjcf_load_check(e.xml);
    if (!err.empty())
      throw std::invalid_argument((label.empty() ? "model " + spec.name : label) + ": " + mjcf_load_check_version() +
                                  " does not load the MJCF written for it: " + err);
    r.checked_by = mjcf_load_check_version();
  }
  r.xml = std::move(e.xml);
  r.written = std::move(e.written);
  r.not_written = std::move(e.not_written);
  r.nbodies = e.nbodies;
  r.njoints = e.njoints;
  r.nactuators = e.nactuators;
  r.nequalities = e.nequalities;
  r.notes = spec.notes;
  return r;
}

ExportMjcfResult study_export_mjcf(const ExportMjcfRequest& request) {
  if (request.out.empty()) throw std::invalid_argument("the output MJCF file is not given (--out FILE.xml)");
  guard_output(request.out, OutputKind::Mjcf, {request.model});
  const ModelSpec spec = load_model_spec(request.model);
  ExportMjcfResult r = study_mjcf(spec, request.model);
  write_file_atomically(request.out, r.xml);
  return r;
}

void study_guard_model_output(const std::string& path, const std::vector<std::string>& inputs) {
  if (path.empty()) throw std::invalid_argument("the output model file is not given (--out MODEL.json)");
  for (const std::string& in : inputs)
    if (same_file(path, in))
      throw std::invalid_argument(path + ": this is the input file " + in +
                                  " (the same file); codyna never writes an output over its input: choose another name");
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return;
  if (!S_ISREG(st.st_mode)) throw std::invalid_argument(path + ": exists and is not a regular file; choose another name");
  if (st.st_size == 0) return;
  if (import_head(path, 512).find("\"codyna_model\"") == std::string::npos)
    throw std::invalid_argument(path + ": exists and is not a codyna model file; codyna never replaces a file it did "
                                "not write: remove it or choose another name");
}

ImportJobResult study_import_job(const ImportRequest& request) {
  study_guard_model_output(request.out, {request.file});
  ImportOptions o;
  o.ignore.insert(request.ignore.begin(), request.ignore.end());
  ImportResult r = study_import(request.file, o);
  const Model m = compile(r.spec, request.file);
  save_model_spec(r.spec, request.out);
  ImportJobResult out;
  out.dof = m.dof();
  out.nq = m.nq;
  out.nv = m.nv;
  out.spec = std::move(r.spec);
  out.report = std::move(r.report);
  return out;
}

}  // namespace codyna
