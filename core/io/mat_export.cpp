#include "io/mat_export.hpp"

#include "io/hdf5_quiet.hpp"
#include "io/output_guard.hpp"

#include <matio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.hpp"

#ifndef CODYNA_VERSION
#define CODYNA_VERSION "unknown"
#endif

namespace codyna {
namespace {

// ---------------------------------------------------------------- the plant

// The six name/unit lists in the order they are written.
struct NameList {
  const char* var;                       // variable name in the .mat
  const std::vector<std::string>* list;  // points into a LinearSystem
};

std::array<NameList, 6> name_lists(const LinearSystem& s) {
  return {{{"state_names", &s.state_names},
           {"input_names", &s.input_names},
           {"output_names", &s.output_names},
           {"state_units", &s.state_units},
           {"input_units", &s.input_units},
           {"output_units", &s.output_units}}};
}

// The numeric variables of NAME.mat in the order they are written.
// (with motion inputs among the inputs, the shift of the states their realization makes)
std::vector<std::pair<const char*, Eigen::MatrixXd>> plant_matrices(const LinearSystem& s) {
  std::vector<std::pair<const char*, Eigen::MatrixXd>> v{{"A", s.A},   {"B", s.B},   {"C", s.C},   {"D", s.D},
                                                         {"x0", s.x0}, {"u0", s.u0}, {"y0", s.y0}, {"xdot0", s.xdot0},
                                                         {"Ts", Eigen::MatrixXd::Constant(1, 1, s.Ts)}};
  if (s.state_shift.size() > 0) {
    v.emplace_back("state_shift", s.state_shift);
    v.emplace_back("state_rate_shift", s.state_rate_shift);
  }
  return v;
}

class PlantChecker {
 public:
  explicit PlantChecker(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& reason) const { throw std::runtime_error(file_ + ": " + reason); }

  void matrix(Eigen::MatrixXd& m, Eigen::Index rows, Eigen::Index cols, const char* what, bool empty_is_zero) const {
    if (m.size() == 0 && empty_is_zero) m = Eigen::MatrixXd::Zero(rows, cols);
    if (m.rows() != rows || m.cols() != cols)
      fail(std::string(what) + " is " + dims(m) + ", expected " + std::to_string(rows) + "x" + std::to_string(cols));
    if (!m.allFinite()) fail(std::string(what) + " has NaN or Inf entries");
  }

  void vector(Eigen::VectorXd& v, Eigen::Index n, const char* what) const {
    Eigen::MatrixXd m = v;
    matrix(m, n, 1, what, /*empty_is_zero=*/true);
    v = m;
  }

  // empty -> default ("x1", ... or ""), else exactly n entries
  void names(std::vector<std::string>& list, std::size_t n, const char* what, const std::string& prefix) const {
    if (list.empty() && n > 0)
      for (std::size_t i = 0; i < n; ++i) list.push_back(prefix.empty() ? "" : prefix + std::to_string(i + 1));
    if (list.size() != n)
      fail(std::string(what) + " has " + std::to_string(list.size()) + " entries, expected " + std::to_string(n));
  }

 private:
  static std::string dims(const Eigen::MatrixXd& m) {
    return std::to_string(m.rows()) + "x" + std::to_string(m.cols());
  }
  std::string file_;
};

// `sys` with defaults filled in; throws (naming `file`) if the sizes do not fit.
LinearSystem completed_plant(LinearSystem s, const std::string& file) {
  const PlantChecker check(file);
  const Eigen::Index nx = s.A.rows(), nu = s.B.cols(), ny = s.C.rows();
  check.matrix(s.A, nx, nx, "A", false);
  check.matrix(s.B, nx, nu, "B", false);
  check.matrix(s.C, ny, nx, "C", false);
  check.matrix(s.D, ny, nu, "D", true);
  check.vector(s.x0, nx, "x0");
  check.vector(s.u0, nu, "u0");
  check.vector(s.y0, ny, "y0");
  check.vector(s.xdot0, nx, "xdot0");
  if (!(s.Ts >= 0.0) || !std::isfinite(s.Ts)) check.fail("Ts must be 0 (continuous) or positive");
  check.names(s.state_names, nx, "state_names", "x");
  check.names(s.input_names, nu, "input_names", "u");
  check.names(s.output_names, ny, "output_names", "y");
  check.names(s.state_units, nx, "state_units", "");
  check.names(s.input_units, nu, "input_units", "");
  check.names(s.output_units, ny, "output_units", "");
  if (s.codyna_version.empty()) s.codyna_version = CODYNA_VERSION;
  return s;
}

// ---------------------------------------------------------------- text

// MATLAB char arrays are UTF-16; invalid UTF-8 bytes become U+FFFD.
std::u16string utf16(const std::string& s) {
  std::u16string out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const int len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    char32_t cp = len == 1 ? c : len == 2 ? c & 0x1F : len == 3 ? c & 0x0F : c & 0x07;
    bool ok = len > 0 && i + len <= s.size();
    for (int k = 1; ok && k < len; ++k) {
      const auto t = static_cast<unsigned char>(s[i + k]);
      ok = (t >> 6) == 0x2;
      cp = (cp << 6) | (t & 0x3F);
    }
    if (!ok) {
      out.push_back(u'\uFFFD');
      ++i;
      continue;
    }
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<char16_t>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<char16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<char16_t>(cp));
    }
    i += len;
  }
  return out;
}

std::string utf8(const char16_t* u, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < n; ++i) {
    char32_t cp = u[i];
    if (cp >= 0xD800 && cp < 0xDC00 && i + 1 < n && u[i + 1] >= 0xDC00 && u[i + 1] < 0xE000)
      cp = 0x10000 + ((cp - 0xD800) << 10) + (u[++i] - 0xDC00);
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  return out;
}

// One line of text for a comment or a '...' literal: control characters
// (a newline would end the comment) become blanks.
std::string one_line(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = ' ';
  return out;
}

// shortest text that reads back as the same double ("0.01", not "0.010000")
std::string mat_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  for (int precision = 1; precision < 17; ++precision) {
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", precision, x);
    if (std::strtod(shorter, nullptr) == x) return shorter;
  }
  return buf;
}

std::string quoted_text(const std::string& s) {
  std::string out = "'";
  for (char c : one_line(s)) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// ---------------------------------------------------------------- MAT writing

struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using VarPtr = std::unique_ptr<matvar_t, VarFree>;

VarPtr checked(matvar_t* v, const char* name) {
  if (!v) throw std::runtime_error(std::string("cannot create MAT variable ") + name);
  return VarPtr(v);
}

VarPtr double_var(const char* name, const Eigen::MatrixXd& m) {
  size_t dims[2] = {static_cast<size_t>(m.rows()), static_cast<size_t>(m.cols())};
  return checked(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(m.data()), 0), name);
}

// rows x cols x N, slice k = pages[k] (MATLAB's A(:,:,k))
VarPtr double3_var(const char* name, const std::vector<Eigen::MatrixXd>& pages, Eigen::Index rows, Eigen::Index cols) {
  std::vector<double> data;
  data.reserve(static_cast<std::size_t>(rows * cols) * pages.size());
  for (const Eigen::MatrixXd& p : pages) data.insert(data.end(), p.data(), p.data() + p.size());
  size_t dims[3] = {static_cast<size_t>(rows), static_cast<size_t>(cols), pages.size()};
  return checked(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 3, dims, data.data(), 0), name);
}

// '' is 0x0 as in MATLAB; otherwise a 1xN row of UTF-16 code units
VarPtr char_var(const char* name, const std::string& s) {
  std::u16string u = utf16(s);
  size_t dims[2] = {u.empty() ? 0u : 1u, u.size()};
  return checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, u.data(), 0), name);
}

VarPtr cellstr_var(const char* name, const std::vector<std::string>& list) {
  size_t dims[2] = {list.size(), 1};
  VarPtr cell = checked(Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0), name);
  for (std::size_t i = 0; i < list.size(); ++i)
    Mat_VarSetCell(cell.get(), static_cast<int>(i), char_var(nullptr, list[i]).release());
  return cell;
}

// rows padded with blanks, like char({'a', 'bcd'}); 0x0 for an empty list
VarPtr char_matrix_var(const char* name, const std::vector<std::string>& list) {
  std::vector<std::u16string> rows;
  std::size_t width = 0;
  for (const auto& s : list) width = std::max(width, rows.emplace_back(utf16(s)).size());
  if (!rows.empty()) width = std::max<std::size_t>(width, 1);  // all '' -> a blank column, not 0x0
  const std::size_t n = rows.size();
  std::u16string data(n * width, u' ');
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t c = 0; c < rows[r].size(); ++c) data[c * n + r] = rows[r][c];  // column-major
  size_t dims[2] = {n, width};
  return checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, data.data(), 0), name);
}

using MatField = std::pair<const char*, VarPtr>;

VarPtr struct_var(const char* name, std::vector<MatField> fields) {
  std::vector<const char*> names;
  for (const auto& f : fields) names.push_back(f.first);
  size_t dims[2] = {1, 1};
  VarPtr s = checked(Mat_VarCreateStruct(name, 2, dims, names.data(), static_cast<unsigned>(names.size())), name);
  for (auto& f : fields) Mat_VarSetStructFieldByName(s.get(), f.first, 0, f.second.release());
  return s;
}

class MatWriter {
 public:
  MatWriter(const std::string& path, MatVersion v, const std::string& target) : target_(target) {
    const bool v73 = v == MatVersion::V73;
    const std::string header = std::string(v73 ? "MATLAB 7.3 MAT-file" : "MATLAB 5.0 MAT-file") +
                               ", Platform: codyna, Created by: codyna " CODYNA_VERSION " with libmatio";
    mat_ = Mat_CreateVer(path.c_str(), header.c_str(), v73 ? MAT_FT_MAT73 : MAT_FT_MAT5);
    if (!mat_) fail(std::string("cannot create a ") + (v73 ? "MAT v7.3" : "MAT v5") + " file at " + path);
  }
  ~MatWriter() {
    if (mat_) Mat_Close(mat_);
  }
  MatWriter(const MatWriter&) = delete;
  MatWriter& operator=(const MatWriter&) = delete;

  void write(VarPtr var) {
    if (Mat_VarWrite(mat_, var.get(), MAT_COMPRESSION_NONE) != 0)
      fail(std::string("cannot write variable ") + var->name);
  }
  void close() {
    const int rc = Mat_Close(mat_);
    mat_ = nullptr;
    if (rc != 0) fail("cannot finish writing (disk full?)");
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const { throw std::runtime_error(target_ + ": " + reason); }
  mat_t* mat_ = nullptr;
  std::string target_;
};

VarPtr info_var(const LinearSystem& s, const std::string& name) {
  std::vector<MatField> fields;
  fields.emplace_back("name", char_var(nullptr, name));
  fields.emplace_back("model_name", char_var(nullptr, s.model_name));
  fields.emplace_back("model_file", char_var(nullptr, s.model_file));
  fields.emplace_back("operating_point", char_var(nullptr, s.operating_point));
  fields.emplace_back("method", char_var(nullptr, s.method));
  fields.emplace_back("time", double_var(nullptr, Eigen::MatrixXd::Constant(1, 1, s.time)));
  fields.emplace_back("codyna_version", char_var(nullptr, s.codyna_version));
  return struct_var("info", std::move(fields));
}

void write_plant_mat(const LinearSystem& s, const std::string& name, const std::string& path, MatVersion v,
                     const std::string& target) {
  MatWriter w(path, v, target);
  for (const auto& [var, m] : plant_matrices(s)) w.write(double_var(var, m));
  for (const auto& l : name_lists(s)) {
    w.write(cellstr_var(l.var, *l.list));
    if (v == MatVersion::V73) w.write(char_matrix_var((std::string(l.var) + "_char").c_str(), *l.list));
  }
  w.write(info_var(s, name));
  if (!s.study.empty()) w.write(char_var("codyna_study", s.study));
  if (!s.handling.empty()) {
    std::vector<MatField> fields;
    for (const auto& [field, value] : s.handling) fields.emplace_back(field.c_str(), double_var(nullptr, Eigen::MatrixXd::Constant(1, 1, value)));
    w.write(struct_var("handling", std::move(fields)));
  }
  w.close();
}

// ---------------------------------------------------------------- NAME.m

// What the states marked ~ are, and the way back to the physical coordinates and rates
std::string shifted_states_note(const LinearSystem& s) {
  std::ostringstream out;
  bool any = false;
  for (int i = 0; i < s.nx(); ++i)
    if (s.shifted(i)) {
      if (!any)
        out << "% States marked ~ are shifted: motion inputs enter without their rates (a proper model), and\n"
            << "% the physical deviations are  dx_physical = dx + state_shift*du + state_rate_shift*du'\n"
            << "% (state_shift, state_rate_shift: nx x nu, in the .mat):\n";
      any = true;
      out << "%   " << one_line(s.state_names[static_cast<std::size_t>(i)]) << " = " << one_line(state_meaning(s, i)) << "\n";
    }
  return out.str();
}

// "%   1  force  [N]" lines
std::string signal_table(const std::vector<std::string>& names, const std::vector<std::string>& units) {
  std::size_t width = 0;
  for (const auto& n : names) width = std::max(width, one_line(n).size());
  std::ostringstream out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string n = one_line(names[i]);
    out << "%   " << i + 1 << "  " << n << std::string(width - n.size(), ' ') << "  ["
        << (units[i].empty() ? "-" : one_line(units[i])) << "]\n";
  }
  if (names.empty()) out << "%   (none)\n";
  return out.str();
}

// plant_inputs = { ...\n  'force'  % [N]\n};
std::string cellstr_literal(const char* var, const std::vector<std::string>& names,
                            const std::vector<std::string>& units) {
  if (names.empty()) return std::string(var) + " = cell(0, 1);\n";
  std::string out = std::string(var) + " = { ...\n";
  for (std::size_t i = 0; i < names.size(); ++i)
    out += "  " + quoted_text(names[i]) + "  % [" + (units[i].empty() ? "-" : one_line(units[i])) + "]\n";
  return out + "};\n";
}

std::string header_comment(const LinearSystem& s, const std::string& name, MatVersion v) {
  std::ostringstream h;
  h << "% " << name << ".m - plant exported by codyna " << one_line(s.codyna_version) << "\n"
    << "%\n"
    << "% Model:            " << one_line(s.model_name)
    << (s.model_file.empty() ? "" : "  (" + one_line(s.model_file) + ")") << "\n"
    << "% Operating point:  " << one_line(s.operating_point) << ", t = " << mat_number(s.time) << " s\n"
    << "% Linearization:    " << one_line(s.method) << "\n"
    << "% Time:             "
    << (s.Ts > 0 ? "discrete, Ts = " + mat_number(s.Ts) + " s (zero-order hold)" : std::string("continuous (Ts = 0)"))
    << "\n"
    << "%\n"
    << "% Deviations about the operating point (x0, u0, y0, xdot0 in " << name << ".mat):\n"
    << "%   x = x0 + dx,  u = u0 + du,  y = y0 + dy\n"
    << (s.Ts > 0 ? "%   dx[k+1] = A dx[k] + B du[k]\n" : "%   d(dx)/dt = A dx + B du\n")
    << "%   dy = C dx + D du\n"
    << (s.Ts > 0 ? "% xdot0 is the continuous-time derivative at the operating point (0 at an equilibrium).\n"
                 : "% Away from an equilibrium xdot0 is not zero: d(dx)/dt = xdot0 + A dx + B du.\n")
    << "%\n"
    << "% Inputs (plant_inputs):\n"
    << signal_table(s.input_names, s.input_units) << "% Outputs (plant_outputs):\n"
    << signal_table(s.output_names, s.output_units) << "% States (state_names):\n"
    << signal_table(s.state_names, s.state_units) << shifted_states_note(s) << "%\n"
    << "% Runs as it is in MATLAB and GNU Octave: loads " << name << ".mat from this script's\n"
    << "% folder and, when ss() exists (Control System Toolbox; Octave's control package,\n"
    << "% loaded here when installed), builds the named state-space model sys.\n"
    << (s.study.empty() ? std::string()
                        : "%\n% A controller designed here comes back to codyna with its operating point and state\n"
                          "% order when saved with them:  save('-v7', 'K.mat', 'K', 'codyna_study', 'state_names')\n"
                          "% (codyna simulate MODEL --controller K.mat then needs no other flag).\n");
  if (v == MatVersion::V73)
    h << "% This is a MAT v7.3 file. Octave cannot read its cell arrays, so each name list\n"
      << "% is also stored as a blank-padded char matrix (state_names_char, ...) and this\n"
      << "% script uses cellstr() of it when the cell array did not load.\n";
  return h.str();
}

std::string load_block(const std::string& name, MatVersion v) {
  const std::string load = "load(fullfile(codyna_here, '" + name + ".mat'));\n";
  return "codyna_here = fileparts(mfilename('fullpath'));\n" +
         (v == MatVersion::V73
              ? "codyna_warnings = warning('off', 'all');  % Octave warns about each cell array it cannot read\n" +
                    load + "warning(codyna_warnings);\n"
              : load) +
         "if exist('OCTAVE_VERSION', 'builtin')\n"
         "  try\n"
         "    pkg load control\n"
         "  catch\n"
         "    % no control package: the matrices and lists below are still defined\n"
         "  end\n"
         "end\n";
}

// Octave reads a v7.3 file's empty matrices as their size vectors and does
// not read its cell arrays; set the first from the known sizes, take the
// second from the char matrices.
std::string v73_fixups(const LinearSystem& s) {
  std::ostringstream out;
  out << "% Octave reads the empty matrices of a v7.3 file as their sizes and skips its cell arrays:\n";
  for (const auto& [var, m] : plant_matrices(s))
    if (m.size() == 0) out << var << " = zeros(" << m.rows() << ", " << m.cols() << ");\n";
  for (const auto& l : name_lists(s)) {
    const std::string var = l.var;
    if (l.list->empty())
      out << var << " = cell(0, 1);\n";
    else
      out << "if ~exist('" << var << "', 'var') || ~iscell(" << var << "), " << var << " = cellstr(char(" << var
          << "_char)); end\n";
  }
  out << "clear('__refs_')  % Octave's name for the file's #refs# group\n";
  return out.str();
}

// ss() rejects a model with neither inputs nor outputs in Octave, so only build one with either.
const char* model_block =
    "sys = [];\n"
    "if exist('ss') >= 2 && (size(B, 2) > 0 || size(C, 1) > 0)\n"
    "  if Ts > 0\n"
    "    sys = ss(A, B, C, D, Ts);\n"
    "  else\n"
    "    sys = ss(A, B, C, D);\n"
    "  end\n"
    "  sys.StateName = state_names;\n"
    "  sys.InputName = plant_inputs;\n"
    "  sys.OutputName = plant_outputs;\n"
    "end\n";

std::string or_unset(const std::string& s) { return s.empty() ? "(unset)" : s; }

std::string summary_block(const LinearSystem& s, const std::string& name) {
  return "if Ts > 0\n"
         "  codyna_kind = sprintf('discrete-time (Ts = %g s)', Ts);\n"
         "else\n"
         "  codyna_kind = 'continuous-time';\n"
         "end\n"
         "fprintf(['%s: %s plant of model %s at operating point %s (%s linearization),\\n' ...\n"
         "         '  %d states (%s),\\n  %d inputs (%s),\\n  %d outputs (%s).\\n'], ...\n"
         "        '" + name + "', codyna_kind, " + quoted_text(or_unset(s.model_name)) + ", " +
         quoted_text(or_unset(s.operating_point)) + ", " + quoted_text(or_unset(s.method)) + ", ...\n"
         "        size(A, 1), strjoin(reshape(state_names, 1, []), ', '), ...\n"
         "        size(B, 2), strjoin(reshape(plant_inputs, 1, []), ', '), ...\n"
         "        size(C, 1), strjoin(reshape(plant_outputs, 1, []), ', '));\n"
         "if isempty(sys)\n"
         "  fprintf('  ss() is not available (or there are no inputs and outputs): use A, B, C, D.\\n');\n"
         "else\n"
         "  fprintf('  The named state-space model is sys.\\n');\n"
         "end\n"
         "clear codyna_here codyna_kind codyna_warnings\n";
}

}  // namespace

// ---------------------------------------------------------------- public

std::u16string mat_utf16(const std::string& s) { return utf16(s); }

std::string matlab_identifier(const std::string& s) {
  static const char* const reserved[] = {
      // MATLAB and Octave keywords
      "break", "case", "catch", "classdef", "continue", "do", "else", "elseif", "end", "end_try_catch",
      "end_unwind_protect", "endclassdef", "endenumeration", "endevents", "endfor", "endfunction", "endif",
      "endmethods", "endparfor", "endproperties", "endswitch", "endwhile", "enumeration", "events", "for",
      "function", "global", "if", "methods", "otherwise", "parfor", "persistent", "properties", "return",
      "spmd", "switch", "try", "until", "unwind_protect", "unwind_protect_cleanup", "while",
      // variables NAME.m defines (running NAME would show the variable instead)
      "A", "B", "C", "D", "x0", "u0", "y0", "xdot0", "Ts", "info", "sys", "plant_inputs", "plant_outputs", "state_shift",
      "state_rate_shift",
      "state_names", "input_names", "output_names", "state_units", "input_units", "output_units", "codyna_here",
      "codyna_kind", "codyna_warnings",
      // functions NAME.m calls (NAME.m would shadow them in its folder)
      "ss", "load", "fileparts", "mfilename", "fullfile", "exist", "pkg", "iscell", "isempty", "cellstr", "cell",
      "size", "fprintf", "sprintf", "strjoin", "reshape", "clear", "lqr", "c2d"};
  std::string id;
  for (char c : s) id += std::isalnum(static_cast<unsigned char>(c)) && static_cast<unsigned char>(c) < 0x80 ? c : '_';
  if (id.empty()) return "plant";
  if (!std::isalpha(static_cast<unsigned char>(id[0]))) id = "m_" + id;
  id.resize(std::min<std::size_t>(id.size(), 63));
  if (std::find(std::begin(reserved), std::end(reserved), id) != std::end(reserved)) id += "_plant";
  return id;
}

std::string plant_script(const LinearSystem& sys, const std::string& name, MatVersion v) {
  const LinearSystem s = completed_plant(sys, name + ".m");
  return header_comment(s, name, v) + "\n" + load_block(name, v) +
         (v == MatVersion::V73 ? v73_fixups(s) : "") + "\n" +
         cellstr_literal("plant_inputs", s.input_names, s.input_units) +
         cellstr_literal("plant_outputs", s.output_names, s.output_units) + "\n" + model_block + "\n" +
         summary_block(s, name);
}

ExportPaths export_plant(const LinearSystem& sys, const std::string& dir, const std::string& name, MatVersion v) {
  const std::string base = (std::filesystem::path(dir) / name).string();
  const ExportPaths paths{base + ".mat", base + ".m"};
  if (matlab_identifier(name) != name)
    throw std::runtime_error(paths.mat_file + ": '" + name + "' is not a valid MATLAB identifier or is reserved" +
                             " (use '" + matlab_identifier(name) + "')");
  guard_output(paths.mat_file, OutputKind::PlantMat, {sys.model_file});
  guard_output(paths.m_file, OutputKind::PlantScript, {sys.model_file});
  const LinearSystem s = completed_plant(sys, paths.mat_file);
  const std::string script = plant_script(s, name, v);

  AtomicFile mat(paths.mat_file);
  {
    const QuietHdf5 quiet;  // a v7.3 file is HDF5: failures are reported here, not printed by the library
    write_plant_mat(s, name, mat.temp_path(), v, paths.mat_file);
  }
  AtomicFile m(paths.m_file);
  {
    std::ofstream out(m.temp_path(), std::ios::binary | std::ios::trunc);
    out << script;
    out.close();
    if (!out) throw std::runtime_error(paths.m_file + ": cannot write " + m.temp_path());
  }
  mat.commit();
  m.commit();
  return paths;
}

// ---------------------------------------------------------------- reading

namespace {

[[noreturn]] void read_fail(const std::string& path, const std::string& reason) {
  throw std::runtime_error(path + ": " + reason);
}

// Files matio cannot read but that users are likely to hand us; "" if none of those.
std::string known_foreign_format(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(32, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  const auto starts = [&](const char* p) { return head.rfind(p, 0) == 0; };
  if (starts("# Created by Octave") || starts("# name:"))
    return "Octave text format; save with -v7 or -mat7-binary";
  if (starts("Octave-1-")) return "Octave binary format; save with -v7 or -mat7-binary";
  if (starts("\x89HDF\r\n\x1a\n"))
    return "HDF5 file without a MAT header (Octave -hdf5 format?); save with -v7 or -mat7-binary";
  return "";
}

const char* class_label(const matvar_t* v) {
  switch (v->class_type) {
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return "sparse (store full())";
    case MAT_C_FUNCTION: return "function handle";
    case MAT_C_OPAQUE: return "opaque object";
    default: return "unsupported class";
  }
}

template <class T>
Eigen::MatrixXd as_double(const matvar_t* v) {
  const auto rows = static_cast<Eigen::Index>(v->dims[0]), cols = static_cast<Eigen::Index>(v->dims[1]);
  if (rows * cols == 0) return Eigen::MatrixXd(rows, cols);
  return Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>>(static_cast<const T*>(v->data), rows, cols)
      .template cast<double>();
}

// true and `out` set for a real 2-D numeric variable; else `why` says what it is
bool numeric_matrix(const matvar_t* v, Eigen::MatrixXd& out, std::string& why) {
  if (v->isComplex) return why = "complex", false;
  if (v->rank != 2) return why = std::to_string(v->rank) + "-D array", false;
  switch (v->class_type) {
    case MAT_C_EMPTY: out.resize(static_cast<Eigen::Index>(v->dims[0]), static_cast<Eigen::Index>(v->dims[1]));
      return true;
    case MAT_C_DOUBLE: out = as_double<double>(v); return true;
    case MAT_C_SINGLE: out = as_double<float>(v); return true;
    case MAT_C_INT8: out = as_double<mat_int8_t>(v); return true;
    case MAT_C_UINT8: out = as_double<mat_uint8_t>(v); return true;
    case MAT_C_INT16: out = as_double<mat_int16_t>(v); return true;
    case MAT_C_UINT16: out = as_double<mat_uint16_t>(v); return true;
    case MAT_C_INT32: out = as_double<mat_int32_t>(v); return true;
    case MAT_C_UINT32: out = as_double<mat_uint32_t>(v); return true;
    case MAT_C_INT64: out = as_double<mat_int64_t>(v); return true;
    case MAT_C_UINT64: out = as_double<mat_uint64_t>(v); return true;
    default: return why = class_label(v), false;
  }
}

// The rows of a char variable as UTF-8, or nullopt for an encoding we do not read.
std::optional<std::vector<std::string>> char_rows(const matvar_t* v) {
  const std::size_t rows = v->dims[0], cols = v->dims[1];
  if (rows == 0 || cols == 0) return std::vector<std::string>{""};
  std::u16string units(rows * cols, u' ');
  if (v->data_type == MAT_T_UINT16 || v->data_type == MAT_T_UTF16) {
    std::memcpy(units.data(), v->data, units.size() * sizeof(char16_t));
  } else if ((v->data_type == MAT_T_UINT8 || v->data_type == MAT_T_UTF8) && v->nbytes == rows * cols) {
    const auto* bytes = static_cast<const unsigned char*>(v->data);
    std::copy(bytes, bytes + units.size(), units.begin());  // ASCII/Latin-1: one byte per character
  } else if (v->data_type == MAT_T_UTF8 && rows == 1) {
    return std::vector<std::string>{std::string(static_cast<const char*>(v->data), v->nbytes)};
  } else {
    return std::nullopt;
  }
  std::vector<std::string> out;
  for (std::size_t r = 0; r < rows; ++r) {
    std::u16string row;
    for (std::size_t c = 0; c < cols; ++c) row += units[c * rows + r];  // column-major
    if (rows > 1) row.erase(row.find_last_not_of(u' ') + 1);          // padding of a char matrix
    out.push_back(utf8(row.data(), row.size()));
  }
  return out;
}

// A char variable or a cell array of char rows as strings; nullopt otherwise.
std::optional<std::vector<std::string>> text(matvar_t* v) {
  if (v->rank != 2) return std::nullopt;
  if (v->class_type == MAT_C_CHAR) return char_rows(v);
  if (v->class_type != MAT_C_CELL) return std::nullopt;
  std::vector<std::string> out;
  const std::size_t n = v->dims[0] * v->dims[1];
  for (std::size_t i = 0; i < n; ++i) {
    const matvar_t* cell = Mat_VarGetCell(v, static_cast<int>(i));
    if (!cell || cell->rank != 2 || cell->class_type != MAT_C_CHAR || cell->dims[0] > 1) return std::nullopt;
    auto rows = char_rows(cell);
    if (!rows) return std::nullopt;
    out.push_back(rows->front());
  }
  return out;
}

}  // namespace

MatVariables read_mat_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) read_fail(path, "no such file");
  if (const std::string foreign = known_foreign_format(path); !foreign.empty()) read_fail(path, foreign);

  std::unique_ptr<mat_t, int (*)(mat_t*)> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY), Mat_Close);
  if (!mat) read_fail(path, "not a MAT file (or unreadable); save with -v7 or -mat7-binary");

  MatVariables out;
  while (VarPtr v{Mat_VarReadNext(mat.get())}) {
    const std::string name = v->name ? v->name : "";
    Eigen::MatrixXd m;
    std::string why;
    if (!numeric_matrix(v.get(), m, why)) {
      if (auto strings = text(v.get()))
        out.strings[name] = std::move(*strings);
      else
        out.skipped.push_back({name, why});
      continue;
    }
    if (!m.allFinite()) read_fail(path, "variable '" + name + "' has NaN or Inf entries");
    out.matrices[name] = std::move(m);
  }
  return out;
}

// ---------------------------------------------------------------- trajectories

namespace {

std::string trajectory_script(const LinearSystem& s, const std::string& name, std::size_t samples) {
  std::ostringstream m;
  m << "% " << name << ".m - linearizations along a trajectory, exported by codyna " << s.codyna_version << "\n"
    << "%\n% Model: " << one_line(s.model_name) << "  (" << one_line(s.model_file) << ")\n"
    << "% " << samples << " operating points along a simulation, at the times in t (" << one_line(s.method) << " linearization).\n"
    << "% About the k-th point, with deviations from x0(:,k), u0(:,k), y0(:,k):\n"
    << "%   d(dx)/dt = xdot0(:,k) + A(:,:,k) dx + B(:,:,k) du,   dy = C(:,:,k) dx + D(:,:,k) du\n"
    << "% plant_at(k) returns the named state-space model at point k (when ss() exists).\n\n"
    << "codyna_here = fileparts(mfilename('fullpath'));\n"
    << "load(fullfile(codyna_here, '" << name << ".mat'));\n"
    << "if exist('OCTAVE_VERSION', 'builtin')\n  try\n    pkg load control\n  catch\n  end\nend\n"
    << "plant_inputs = input_names;\nplant_outputs = output_names;\n"
    << "if exist('ss') >= 2\n"
    << "  plant_at = @(k) ss(A(:,:,k), B(:,:,k), C(:,:,k), D(:,:,k), 'StateName', state_names, "
       "'InputName', input_names, 'OutputName', output_names);\n"
    << "end\n"
    << "fprintf('%s: %d linearizations of model %s from t = %g to %g s, %d states, %d inputs, %d outputs.\\n', ...\n"
    << "        '" << name << "', numel(t), '" << one_line(s.model_name) << "', t(1), t(end), size(A, 1), size(B, 2), size(C, 1));\n"
    << "clear codyna_here\n";
  return m.str();
}

}  // namespace

ExportPaths export_trajectory(const std::vector<LinearSystem>& systems, const std::vector<double>& times,
                              const std::string& dir, const std::string& name) {
  const std::string base = (std::filesystem::path(dir) / name).string();
  const ExportPaths paths{base + ".mat", base + ".m"};
  if (matlab_identifier(name) != name)
    throw std::runtime_error(paths.mat_file + ": '" + name + "' is not a valid MATLAB identifier or is reserved" +
                             " (use '" + matlab_identifier(name) + "')");
  if (systems.empty() || systems.size() != times.size())
    throw std::runtime_error(paths.mat_file + ": expected one linearization per time");
  guard_output(paths.mat_file, OutputKind::PlantMat, {systems[0].model_file});
  guard_output(paths.m_file, OutputKind::PlantScript, {systems[0].model_file});
  std::vector<LinearSystem> s;
  for (const LinearSystem& sys : systems) s.push_back(completed_plant(sys, paths.mat_file));
  const Eigen::Index nx = s[0].nx(), nu = s[0].nu(), ny = s[0].ny();
  for (const LinearSystem& x : s)
    if (x.nx() != nx || x.nu() != nu || x.ny() != ny || x.state_names != s[0].state_names)
      throw std::runtime_error(paths.mat_file + ": the linearizations differ in size or state order");
  auto pages = [&](auto get) {
    std::vector<Eigen::MatrixXd> p;
    for (const LinearSystem& x : s) p.push_back(get(x));
    return p;
  };
  auto columns = [&](auto get, Eigen::Index rows) {
    Eigen::MatrixXd M(rows, static_cast<Eigen::Index>(s.size()));
    for (std::size_t k = 0; k < s.size(); ++k) M.col(static_cast<Eigen::Index>(k)) = get(s[k]);
    return M;
  };
  AtomicFile mat(paths.mat_file);
  {
    MatWriter w(mat.temp_path(), MatVersion::V5, paths.mat_file);
    w.write(double3_var("A", pages([](const LinearSystem& x) { return x.A; }), nx, nx));
    w.write(double3_var("B", pages([](const LinearSystem& x) { return x.B; }), nx, nu));
    w.write(double3_var("C", pages([](const LinearSystem& x) { return x.C; }), ny, nx));
    w.write(double3_var("D", pages([](const LinearSystem& x) { return x.D; }), ny, nu));
    w.write(double_var("x0", columns([](const LinearSystem& x) { return x.x0; }, nx)));
    w.write(double_var("u0", columns([](const LinearSystem& x) { return x.u0; }, nu)));
    w.write(double_var("y0", columns([](const LinearSystem& x) { return x.y0; }, ny)));
    w.write(double_var("xdot0", columns([](const LinearSystem& x) { return x.xdot0; }, nx)));
    w.write(double_var("t", Eigen::Map<const Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()))));
    w.write(double_var("Ts", Eigen::MatrixXd::Zero(1, 1)));
    for (const auto& l : name_lists(s[0])) w.write(cellstr_var(l.var, *l.list));
    w.write(info_var(s[0], name));
    w.close();
  }
  AtomicFile m(paths.m_file);
  {
    std::ofstream out(m.temp_path(), std::ios::binary | std::ios::trunc);
    out << trajectory_script(s[0], name, s.size());
    out.close();
    if (!out) throw std::runtime_error(paths.m_file + ": cannot write " + m.temp_path());
  }
  mat.commit();
  m.commit();
  return paths;
}

// ---------------------------------------------------------------- closed loops

namespace {

std::vector<std::string> padded(std::vector<std::string> u, std::size_t n) {
  u.resize(n);
  return u;
}

std::string closed_loop_script(const ClosedLoopLinear& cl, const std::string& name) {
  const LinearSystem& s = cl.system;
  std::ostringstream m;
  m << "% " << name << ".m - linear closed loop exported by codyna " << one_line(s.codyna_version) << "\n"
    << "%\n"
    << "% Model:            " << one_line(s.model_name) << (s.model_file.empty() ? "" : "  (" + one_line(s.model_file) + ")") << "\n"
    << "% Operating point:  " << one_line(s.operating_point) << "\n"
    << "% Controller:       " << one_line(cl.controller) << "\n"
    << "% Time:             " << (s.Ts > 0 ? "discrete, Ts = " + mat_number(s.Ts) + " s (plant by zero-order hold)" : std::string("continuous"))
    << "\n%\n"
    << "% The plant linearized about its operating point with the controller's law, no saturation:\n"
    << (s.Ts > 0 ? "%   xcl[k+1] = Acl xcl[k] + Bcl w[k]\n" : "%   d(xcl)/dt = Acl xcl + Bcl w\n")
    << "%   z = Ccl xcl + Dcl w\n"
    << "% xcl = [plant state deviations; controller states], w = [references r - y0; disturbances],\n"
    << "% z = [outputs y - y0; actuator efforts u - u0]. Signs as in the simulation: PID acts on r - y,\n"
    << "% state feedback u = u0 - K dx + Nbar (r - y0), an LTI controller sees y - r.\n"
    << "%\n% Inputs (input_names_cl):\n" << signal_table(s.input_names, padded(s.input_units, s.input_names.size()))
    << "% Outputs (output_names_cl):\n" << signal_table(s.output_names, padded(s.output_units, s.output_names.size()))
    << "% States (state_names_cl):\n" << signal_table(s.state_names, padded(s.state_units, s.state_names.size()))
    << "%\n% poles_cl: [real, imag, natural frequency (rad/s), damping] per pole; t_step and w_freq are\n"
    << "% the grids of the curves codyna wrote beside this file (" << name << "_step.csv, " << name << "_freq.csv).\n\n"
    << "codyna_here = fileparts(mfilename('fullpath'));\n"
    << "load(fullfile(codyna_here, '" << name << ".mat'));\n"
    << "if exist('OCTAVE_VERSION', 'builtin')\n  try\n    pkg load control\n  catch\n  end\nend\n"
    << "sys_cl = [];\n"
    << "codyna_note = '';\n"
    << "if exist('ss') >= 2\n"
    << "  if Ts_cl > 0\n    sys_cl = ss(Acl, Bcl, Ccl, Dcl, Ts_cl);\n  else\n    sys_cl = ss(Acl, Bcl, Ccl, Dcl);\n  end\n"
    << "  sys_cl.StateName = state_names_cl;\n  sys_cl.InputName = input_names_cl;\n  sys_cl.OutputName = output_names_cl;\n"
    << "  codyna_note = '; the named state-space model is sys_cl';\n"
    << "end\n"
    << "fprintf('%s: linear closed loop of model %s, %d states, %d inputs, %d outputs%s.\\n', '" << name << "', "
    << quoted_text(or_unset(s.model_name)) << ", size(Acl, 1), size(Bcl, 2), size(Ccl, 1), codyna_note);\n"
    << "clear codyna_here codyna_note\n";
  return m.str();
}

}  // namespace

ExportPaths export_closed_loop(const ClosedLoopLinear& cl, const ModalAnalysis& poles, const std::vector<double>& t_step,
                               const std::vector<double>& w_freq, const std::string& dir, const std::string& name) {
  const std::string base = (std::filesystem::path(dir) / name).string();
  const ExportPaths paths{base + ".mat", base + ".m"};
  if (matlab_identifier(name) != name)
    throw std::runtime_error(paths.mat_file + ": '" + name + "' is not a valid MATLAB identifier or is reserved" +
                             " (use '" + matlab_identifier(name) + "')");
  const LinearSystem& s = cl.system;
  guard_output(paths.mat_file, OutputKind::PlantMat, {s.model_file});
  guard_output(paths.m_file, OutputKind::PlantScript, {s.model_file});
  for (const auto& [what, M] : {std::pair{"Acl", &s.A}, std::pair{"Bcl", &s.B}, std::pair{"Ccl", &s.C}, std::pair{"Dcl", &s.D}})
    if (!M->allFinite()) throw std::runtime_error(paths.mat_file + ": " + what + " has NaN or Inf entries");
  Eigen::MatrixXd P(static_cast<Eigen::Index>(poles.modes.size()), 4);
  for (std::size_t k = 0; k < poles.modes.size(); ++k) {
    const Mode& md = poles.modes[k];
    P.row(static_cast<Eigen::Index>(k)) << md.eigenvalue.real(), md.eigenvalue.imag(), md.natural_frequency, md.damping_ratio;
  }
  auto column = [](const std::vector<double>& v) {
    return Eigen::MatrixXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  };
  AtomicFile mat(paths.mat_file);
  {
    MatWriter w(mat.temp_path(), MatVersion::V5, paths.mat_file);
    w.write(double_var("Acl", s.A));
    w.write(double_var("Bcl", s.B));
    w.write(double_var("Ccl", s.C));
    w.write(double_var("Dcl", s.D));
    w.write(double_var("Ts_cl", Eigen::MatrixXd::Constant(1, 1, s.Ts)));
    w.write(double_var("x0_cl", s.x0));
    w.write(double_var("u0_cl", s.u0));
    w.write(double_var("y0_cl", s.y0));
    w.write(cellstr_var("state_names_cl", s.state_names));
    w.write(cellstr_var("input_names_cl", s.input_names));
    w.write(cellstr_var("output_names_cl", s.output_names));
    w.write(cellstr_var("state_units_cl", padded(s.state_units, s.state_names.size())));
    w.write(cellstr_var("input_units_cl", padded(s.input_units, s.input_names.size())));
    w.write(cellstr_var("output_units_cl", padded(s.output_units, s.output_names.size())));
    w.write(double_var("poles_cl", P));
    w.write(double_var("t_step", column(t_step)));
    w.write(double_var("w_freq", column(w_freq)));
    std::vector<MatField> fields;
    fields.emplace_back("name", char_var(nullptr, name));
    fields.emplace_back("model_name", char_var(nullptr, s.model_name));
    fields.emplace_back("model_file", char_var(nullptr, s.model_file));
    fields.emplace_back("operating_point", char_var(nullptr, s.operating_point));
    fields.emplace_back("controller", char_var(nullptr, cl.controller));
    fields.emplace_back("codyna_version", char_var(nullptr, s.codyna_version));
    w.write(struct_var("info_cl", std::move(fields)));
    w.close();
  }
  AtomicFile m(paths.m_file);
  {
    std::ofstream out(m.temp_path(), std::ios::binary | std::ios::trunc);
    out << closed_loop_script(cl, name);
    out.close();
    if (!out) throw std::runtime_error(paths.m_file + ": cannot write " + m.temp_path());
  }
  mat.commit();
  m.commit();
  return paths;
}

}  // namespace codyna
