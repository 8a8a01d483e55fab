#include "io/signal_file.hpp"

#include <matio.h>

#include <cerrno>
#include <clocale>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "io/mat_export.hpp"

namespace codyna {

namespace {

constexpr std::uintmax_t kMaxBytes = 256u << 20;
constexpr std::size_t kMaxRows = 10000000;

[[noreturn]] void signal_fail(const std::string& path, const std::string& what) {
  throw std::invalid_argument(path + ": " + what);
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

// a whole field as a number (C locale), or nothing
bool parse_number(const std::string& text, double& x) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  // strtod follows the C locale unless a program changed LC_NUMERIC; codyna never does
  char* end = nullptr;
  errno = 0;
  x = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size();
}

std::string shown(const std::string& s) { return "\"" + (s.size() > 40 ? s.substr(0, 40) + "..." : s) + "\""; }

void check_sample(const std::string& path, const std::string& where_t, const std::string& where_v, double t, double v,
                  const std::vector<std::pair<double, double>>& before) {
  if (!std::isfinite(t)) signal_fail(path, where_t + ": the time is not a finite number");
  if (!std::isfinite(v)) signal_fail(path, where_v + ": the value is not a finite number");
  if (!before.empty() && !(t > before.back().first)) {
    std::ostringstream os;
    os.precision(17);
    os << where_t << ": the time " << t << " is not after the previous one (" << before.back().first
       << "): times must increase strictly";
    signal_fail(path, os.str());
  }
}

std::vector<std::pair<double, double>> read_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) signal_fail(path, "cannot open the file");
  std::string line, name_t, name_v;
  std::vector<std::pair<double, double>> out;
  long line_no = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty()) continue;
    const auto comma = line.find(',');
    const std::string a = comma == std::string::npos ? line : line.substr(0, comma);
    const std::string b = comma == std::string::npos ? "" : line.substr(comma + 1);
    if (!header) {
      double x, y;
      if (comma == std::string::npos || b.find(',') != std::string::npos)
        signal_fail(path, "line " + std::to_string(line_no) + ": expected a header of two column names (t,value), got " + shown(line));
      if (parse_number(a, x) && parse_number(b, y))
        signal_fail(path, "line " + std::to_string(line_no) + ": expected a header of two column names (t,value) before the numbers, got " + shown(line));
      name_t = trim(a);
      name_v = trim(b);
      header = true;
      continue;
    }
    const std::string row = "row " + std::to_string(out.size() + 1) + " (line " + std::to_string(line_no) + ")";
    if (comma == std::string::npos || b.find(',') != std::string::npos)
      signal_fail(path, row + ": expected two numbers separated by a comma (" + name_t + "," + name_v + "), got " + shown(line));
    double t, v;
    if (!parse_number(a, t)) signal_fail(path, row + ", column " + name_t + ": expected a number, got " + shown(trim(a)));
    if (!parse_number(b, v)) signal_fail(path, row + ", column " + name_v + ": expected a number, got " + shown(trim(b)));
    check_sample(path, row + ", column " + name_t, row + ", column " + name_v, t, v, out);
    out.emplace_back(t, v);
    if (out.size() > kMaxRows) signal_fail(path, "more than 1e7 rows");
  }
  if (!header) signal_fail(path, "empty: expected a header line (t,value) and at least one row");
  if (out.empty()) signal_fail(path, "no rows after the header (" + name_t + "," + name_v + "): expected at least one");
  return out;
}

// the entries of one real vector variable, read by matio directly (to name the element of a NaN)
std::vector<double> mat_vector(const std::string& path, const char* name) {
  std::unique_ptr<mat_t, int (*)(mat_t*)> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY), Mat_Close);
  if (!mat) signal_fail(path, "not a MAT file (or unreadable)");
  std::unique_ptr<matvar_t, void (*)(matvar_t*)> v(Mat_VarRead(mat.get(), name), Mat_VarFree);
  if (!v) signal_fail(path, std::string("no variable ") + name);
  const std::size_t n = v->rank == 2 ? v->dims[0] * v->dims[1] : 0;
  std::vector<double> out(n);
  if (v->class_type == MAT_C_DOUBLE && !v->isComplex && v->data)
    for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<const double*>(v->data)[k];
  else if (v->class_type == MAT_C_SINGLE && !v->isComplex && v->data)
    for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<const float*>(v->data)[k];
  else
    signal_fail(path, std::string("variable ") + name + ": expected a real double vector");
  return out;
}

std::vector<std::pair<double, double>> read_mat(const std::string& path) {
  Eigen::MatrixXd t, v;
  try {
    const MatVariables vars = read_mat_file(path);
    for (const char* name : {"t", "value"}) {
      const auto it = vars.matrices.find(name);
      if (it == vars.matrices.end()) {
        for (const SkippedVariable& s : vars.skipped)
          if (s.name == name) signal_fail(path, std::string("variable ") + name + " cannot be used (" + s.reason + "); expected a real vector");
        signal_fail(path, std::string("no variable ") + name + ": a signal .mat holds the vectors t and value");
      }
    }
    t = vars.matrices.at("t");
    v = vars.matrices.at("value");
  } catch (const std::runtime_error& e) {
    // a NaN or Inf is refused by the reader for the whole variable: find its element here
    if (std::string(e.what()).find("NaN or Inf") == std::string::npos) throw std::invalid_argument(e.what());
    for (const char* name : {"t", "value"}) {
      const std::vector<double> x = mat_vector(path, name);
      for (std::size_t k = 0; k < x.size(); ++k)
        if (!std::isfinite(x[k]))
          signal_fail(path, std::string("variable ") + name + ", row " + std::to_string(k + 1) + ": not a finite number");
    }
    throw std::invalid_argument(e.what());
  }
  for (const auto& [name, M] : {std::pair{"t", &t}, std::pair{"value", &v}})
    if (M->rows() != 1 && M->cols() != 1)
      signal_fail(path, std::string("variable ") + name + " is " + std::to_string(M->rows()) + " x " + std::to_string(M->cols()) +
                     ": expected a vector");
  if (t.size() != v.size())
    signal_fail(path, "t has " + std::to_string(t.size()) + " entries but value has " + std::to_string(v.size()) +
                   ": expected one value per time");
  if (t.size() == 0) signal_fail(path, "t and value are empty: expected at least one sample");
  std::vector<std::pair<double, double>> out;
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    const std::string row = ", row " + std::to_string(k + 1);
    check_sample(path, "variable t" + row, "variable value" + row, t(k), v(k), out);
    out.emplace_back(t(k), v(k));
  }
  return out;
}

}  // namespace

std::vector<std::pair<double, double>> read_signal_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) signal_fail(path, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) signal_fail(path, "not a regular file");
  if (std::filesystem::file_size(path, ec) > kMaxBytes) signal_fail(path, "larger than 256 MiB");
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".mat" || ext == ".MAT") return read_mat(path);
  return read_csv(path);
}

}  // namespace codyna
