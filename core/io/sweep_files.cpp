#include "io/sweep_files.hpp"


#include <hdf5.h>
#include <matio.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/hdf5_handle.hpp"
#include "io/hdf5_quiet.hpp"
#include "io/hdf5_write.hpp"
#include "io/mat_export.hpp"
#include "io/output_guard.hpp"

namespace codyna {
namespace {

constexpr int kFormatVersion = 1;

// ------------------------------------------------------------------ the journal (resume)
// One line per finished variant, a JSON object whose numbers are hexadecimal texts (exact, NaN
// and infinities included), after a first line naming the study by a hash of the model file's
// bytes and every option that changes a result.

std::uint64_t hash_text(std::uint64_t h, const std::string& text) {
  for (unsigned char ch : text) h = (h ^ ch) * 0x100000001b3ULL;  // FNV-1a
  return sweep_mix64(h ^ text.size());
}

// NaN as its bits ("nan:7ff8000000000000"): its sign and payload (0/0 gives -nan on x86) come
// back as they were, so a merged file keeps the single run's bytes
std::string hex(double x) {
  char buf[64];
  if (std::isnan(x)) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    std::snprintf(buf, sizeof buf, "nan:%016llx", static_cast<unsigned long long>(bits));
    return buf;
  }
  const auto res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::hex);
  return std::string(buf, res.ptr);
}

double unhex(const nlohmann::json& j) {
  const std::string t = j.get<std::string>();
  double x = 0;
  if (t.size() == 20 && t.rfind("nan:", 0) == 0) {
    std::uint64_t bits = 0;
    const auto [ptr, ec] = std::from_chars(t.data() + 4, t.data() + t.size(), bits, 16);
    if (ec != std::errc() || ptr != t.data() + t.size()) throw std::runtime_error("not a number: " + t);
    std::memcpy(&x, &bits, sizeof x);
    return x;
  }
  const char* first = t.data();
  const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), x, std::chars_format::hex);
  if (ec != std::errc() || ptr != t.data() + t.size()) throw std::runtime_error("not a number: " + t);
  return x;
}

Eigen::MatrixXd decode_matrix(const nlohmann::json& j) {
  Eigen::MatrixXd m(j.at(0).get<Eigen::Index>(), j.at(1).get<Eigen::Index>());
  if (static_cast<Eigen::Index>(j.at(2).size()) != m.size()) throw std::runtime_error("matrix size");
  for (Eigen::Index k = 0; k < m.size(); ++k) m.data()[k] = unhex(j.at(2).at(static_cast<std::size_t>(k)));
  return m;
}
Eigen::VectorXcd decode_poles(const nlohmann::json& j) {
  const Eigen::MatrixXd m = decode_matrix(j);
  Eigen::VectorXcd p(m.rows());
  for (Eigen::Index k = 0; k < m.rows(); ++k) p[k] = {m(k, 0), m(k, 1)};
  return p;
}

// One journal line: the JSON object nlohmann::json would dump for these fields (keys in its sorted
// order, numbers as hex() strings, no spaces), written straight into one string: a variant's line is
// made on its worker thread, outside the lock, without a JSON tree per number (Sweep.JournalLines...)
class JournalWriter {
 public:
  explicit JournalWriter(std::string& out) : s_(out) {}
  void key(const char* k) {
    s_ += first_ ? "{\"" : ",\"";
    first_ = false;
    s_ += k;
    s_ += "\":";
  }
  void number(double x) {
    s_ += '"';
    char buf[64];
    if (std::isnan(x)) {
      s_ += hex(x);
    } else {
      const auto res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::hex);
      s_.append(buf, res.ptr);
    }
    s_ += '"';
  }
  void integer(long long x) { s_ += std::to_string(x); }
  void text(const std::string& t) { s_ += nlohmann::json(t).dump(); }
  void boolean(bool b) { s_ += b ? "true" : "false"; }
  // [rows, cols, ["hex", ...]] (what decode_matrix reads)
  void matrix(const double* data, Eigen::Index rows, Eigen::Index cols) {
    s_ += '[';
    integer(rows);
    s_ += ',';
    integer(cols);
    s_ += ",[";
    for (Eigen::Index k = 0; k < rows * cols; ++k) {
      if (k) s_ += ',';
      number(data[k]);
    }
    s_ += "]]";
  }
  void matrix(const Eigen::MatrixXd& m) { matrix(m.data(), m.rows(), m.cols()); }
  void vector(const Eigen::VectorXd& v) { matrix(v.data(), v.size(), 1); }
  void poles(const Eigen::VectorXcd& p) {  // a poles x 2 matrix: the real parts, then the imaginary parts (decode_poles)
    s_ += '[';
    integer(p.size());
    s_ += ",2,[";
    for (int part = 0; part < 2; ++part)
      for (Eigen::Index k = 0; k < p.size(); ++k) {
        if (part || k) s_ += ',';
        number(part ? p[k].imag() : p[k].real());
      }
    s_ += "]]";
  }
  void end() { s_ += first_ ? "{}\n" : "}\n"; }

 private:
  std::string& s_;
  bool first_ = true;
};

std::string journal_line(long long i, const SweepVariant& v) {
  std::string line;
  line.reserve(256 + 24 * static_cast<std::size_t>(v.A.size() + v.B.size() + v.C.size() + v.D.size() + v.K.size() +
                                                     2 * (v.open_poles.size() + v.closed_poles.size())));
  JournalWriter w(line);
  w.key("A"), w.matrix(v.A);
  w.key("B"), w.matrix(v.B);
  w.key("C"), w.matrix(v.C);
  w.key("D"), w.matrix(v.D);
  w.key("K"), w.matrix(v.K);
  w.key("closed_max_real"), w.number(v.closed_max_real);
  w.key("closed_poles"), w.poles(v.closed_poles);
  w.key("final_error"), w.number(v.final_error);
  w.key("i"), w.integer(i);
  w.key("open_max_real"), w.number(v.open_max_real);
  w.key("open_poles"), w.poles(v.open_poles);
  w.key("open_stable"), w.boolean(v.open_stable);
  w.key("overshoot"), w.vector(v.overshoot);
  w.key("peak_input"), w.vector(v.peak_input);
  w.key("reason"), w.text(v.reason);
  w.key("saturation_time"), w.vector(v.saturation_time);
  w.key("settling_time"), w.vector(v.settling_time);
  w.key("sim_reason"), w.text(v.sim_reason);
  w.key("sim_status"), w.integer(v.sim_status);
  w.key("sim_t_end"), w.number(v.sim_t_end);
  w.key("stable"), w.boolean(v.stable);
  w.key("status"), w.integer(static_cast<int>(v.status));
  w.key("uncontrollable"), w.integer(v.uncontrollable);
  w.key("uncontrollable_text"), w.text(v.uncontrollable_text);
  w.key("values");
  line += '[';
  for (std::size_t k = 0; k < v.values.size(); ++k) {
    if (k) line += ',';
    w.number(v.values[k]);
  }
  line += ']';
  w.end();
  return line;
}

SweepVariant journal_variant(const nlohmann::json& j) {
  SweepVariant v;
  for (const auto& x : j.at("values")) v.values.push_back(unhex(x));
  v.status = static_cast<SweepStatus>(j.at("status").get<int>());
  v.reason = j.at("reason").get<std::string>();
  v.A = decode_matrix(j.at("A"));
  v.B = decode_matrix(j.at("B"));
  v.C = decode_matrix(j.at("C"));
  v.D = decode_matrix(j.at("D"));
  v.K = decode_matrix(j.at("K"));
  v.open_poles = decode_poles(j.at("open_poles"));
  v.closed_poles = decode_poles(j.at("closed_poles"));
  v.open_max_real = unhex(j.at("open_max_real"));
  v.closed_max_real = unhex(j.at("closed_max_real"));
  v.stable = j.at("stable").get<bool>();
  v.open_stable = j.value("open_stable", false);  // journals before 2026-11 lack it
  v.uncontrollable = j.at("uncontrollable").get<int>();
  v.uncontrollable_text = j.at("uncontrollable_text").get<std::string>();
  v.sim_status = j.at("sim_status").get<int>();
  v.sim_reason = j.at("sim_reason").get<std::string>();
  v.sim_t_end = unhex(j.at("sim_t_end"));
  v.final_error = unhex(j.at("final_error"));
  const auto vector = [&](const char* key) {
    const Eigen::MatrixXd m = decode_matrix(j.at(key));
    return m.size() ? Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.data(), m.size())) : Eigen::VectorXd();
  };
  v.peak_input = vector("peak_input");
  v.overshoot = vector("overshoot");
  v.settling_time = vector("settling_time");
  v.saturation_time = vector("saturation_time");
  return v;
}

bool is_journal(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string first;
  return !(in && std::getline(in, first) && !first.empty() && first.rfind("codyna sweep journal ", 0) != 0);
}

}  // namespace

std::uint64_t sweep_hash_text(std::uint64_t h, const std::string& text) { return hash_text(h, text); }
std::string sweep_journal_line(long long i, const SweepVariant& v) { return journal_line(i, v); }
SweepVariant sweep_journal_variant(const nlohmann::json& j) { return journal_variant(j); }
bool is_sweep_journal(const std::string& path) { return is_journal(path); }

// ------------------------------------------------------------------ HDF5

namespace {

using FileError = Hdf5Error;
using Handle = Hdf5Handle;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// variants x rows x cols, row-major per variant (what MATLAB/Octave read as rows x cols x variants)
std::vector<double> stack(const std::vector<SweepVariant>& vs, Eigen::MatrixXd SweepVariant::*field, Eigen::Index rows,
                          Eigen::Index cols) {
  std::vector<double> out(vs.size() * static_cast<std::size_t>(rows * cols), kNaN);
  std::size_t at = 0;
  for (const SweepVariant& v : vs) {
    const Eigen::MatrixXd& M = v.*field;
    if (v.status == SweepStatus::Ok && M.rows() == rows && M.cols() == cols)
      for (Eigen::Index a = 0; a < rows; ++a)
        for (Eigen::Index b = 0; b < cols; ++b) out[at + static_cast<std::size_t>(a * cols + b)] = M(a, b);
    at += static_cast<std::size_t>(rows * cols);
  }
  return out;
}

// variants x size, row i = variant i's vector (NaN when it has none of that size)
std::vector<double> rows(const std::vector<SweepVariant>& vs, Eigen::VectorXd SweepVariant::*field, Eigen::Index size) {
  std::vector<double> out(vs.size() * static_cast<std::size_t>(size), kNaN);
  for (std::size_t i = 0; i < vs.size(); ++i) {
    const Eigen::VectorXd& x = vs[i].*field;
    if (x.size() == size) std::copy(x.data(), x.data() + size, out.begin() + static_cast<std::ptrdiff_t>(i * static_cast<std::size_t>(size)));
  }
  return out;
}

void write_poles(hid_t file, const std::string& group, const std::vector<SweepVariant>& vs,
                 Eigen::VectorXcd SweepVariant::*field, double SweepVariant::*maxr, Eigen::Index n) {
  std::vector<double> re(vs.size() * static_cast<std::size_t>(n), kNaN), im = re, mr(vs.size(), kNaN);
  for (std::size_t i = 0; i < vs.size(); ++i) {
    const Eigen::VectorXcd& p = vs[i].*field;
    if (vs[i].status != SweepStatus::Ok || p.size() != n) continue;
    for (Eigen::Index k = 0; k < n; ++k) {
      re[i * static_cast<std::size_t>(n) + static_cast<std::size_t>(k)] = p[k].real();
      im[i * static_cast<std::size_t>(n) + static_cast<std::size_t>(k)] = p[k].imag();
    }
    mr[i] = vs[i].*maxr;
  }
  h5::write_doubles(file, group + "/poles_real", {vs.size(), static_cast<hsize_t>(n)}, re);
  h5::write_doubles(file, group + "/poles_imag", {vs.size(), static_cast<hsize_t>(n)}, im);
  h5::write_doubles(file, group + "/max_real", {vs.size()}, mr);
}

void write_contents(hid_t file, const SweepJob& job) {
  const auto& vs = job.variants;
  const std::size_t n = vs.size(), nv = job.plan.vary.size();
  const Eigen::Index nx = static_cast<Eigen::Index>(job.state_names.size()), nu = static_cast<Eigen::Index>(job.input_names.size()),
                     ny = static_cast<Eigen::Index>(job.output_names.size());
  h5::write_attribute(file, "/", "format", std::string("codyna sweep"));
  h5::write_attribute(file, "/", "format_version", static_cast<long long>(kFormatVersion));
  h5::write_attribute(file, "/", "model_file", job.model_file);
  h5::write_attribute(file, "/", "model_name", job.model_name);
  h5::write_attribute(file, "/", "codyna_version", std::string(CODYNA_VERSION));
  h5::write_attribute(file, "/", "design", std::string(job.plan.random ? "random" : "grid"));
  h5::write_attribute(file, "/", "variants", static_cast<long long>(n));
  if (job.plan.random) h5::write_attribute_u64(file, "/", "seed", job.plan.seed);
  h5::write_attribute(file, "/", "operating_point", job.operating_point);
  h5::write_attribute(file, "/", "method", job.method);
  h5::write_attribute(file, "/", "controller", job.controller);
  h5::write_attribute(file, "/", "gain", std::string(!job.closed_loop ? "none" : job.redesigned ? "redesigned" : "fixed"));

  h5::create_group(file, "/parameters");
  std::vector<std::string> fields, specs;
  std::vector<double> nominal, values(n * nv, kNaN);
  for (const SweepVary& v : job.plan.vary) {
    fields.push_back(v.field);
    specs.push_back(v.spec);
    nominal.push_back(v.nominal);
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < nv && k < vs[i].values.size(); ++k) values[i * nv + k] = vs[i].values[k];
  h5::write_doubles(file, "/parameters/values", {n, nv}, values);
  h5::write_strings(file, "/parameters/fields", fields);
  h5::write_strings(file, "/parameters/specs", specs);
  h5::write_doubles(file, "/parameters/nominal", {nv}, nominal);

  h5::create_group(file, "/status");
  std::vector<int> codes;
  std::vector<std::string> reasons;
  for (const SweepVariant& v : vs) {
    codes.push_back(static_cast<int>(v.status));
    reasons.push_back(v.reason);
  }
  h5::write_ints(file, "/status/code", codes);
  h5::write_strings(file, "/status/reason", reasons);
  h5::write_attribute(file, "/status", "codes",
                  std::string("0 ok, 1 model error, 2 not converged, 3 refused, 4 failed, 5 sizes differ"));

  h5::create_group(file, "/names");
  h5::write_strings(file, "/names/states", job.state_names);
  h5::write_strings(file, "/names/inputs", job.input_names);
  h5::write_strings(file, "/names/outputs", job.output_names);

  h5::create_group(file, "/linear");
  h5::write_doubles(file, "/linear/A", {n, static_cast<hsize_t>(nx), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::A, nx, nx));
  h5::write_doubles(file, "/linear/B", {n, static_cast<hsize_t>(nx), static_cast<hsize_t>(nu)}, stack(vs, &SweepVariant::B, nx, nu));
  h5::write_doubles(file, "/linear/C", {n, static_cast<hsize_t>(ny), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::C, ny, nx));
  h5::write_doubles(file, "/linear/D", {n, static_cast<hsize_t>(ny), static_cast<hsize_t>(nu)}, stack(vs, &SweepVariant::D, ny, nu));

  h5::create_group(file, "/open_loop");
  write_poles(file, "/open_loop", vs, &SweepVariant::open_poles, &SweepVariant::open_max_real, nx);
  std::vector<int> unc, stable;
  for (const SweepVariant& v : vs) {
    unc.push_back(v.status == SweepStatus::Ok ? v.uncontrollable : -1);
    stable.push_back(v.stable ? 1 : 0);
  }
  h5::write_ints(file, "/open_loop/uncontrollable", unc);
  if (job.simulated) {
    h5::create_group(file, "/simulation");
    std::vector<int> st;
    std::vector<std::string> why;
    std::vector<double> reached(n, kNaN), err(n, kNaN);
    for (std::size_t i = 0; i < n; ++i) {
      const SweepVariant& v = vs[i];
      st.push_back(v.sim_status);
      why.push_back(v.sim_reason);
      if (v.sim_status == 0 || v.sim_status == 1) {
        reached[i] = v.sim_t_end;
        err[i] = v.final_error;
      }
    }
    h5::write_ints(file, "/simulation/status", st);
    h5::write_strings(file, "/simulation/reason", why);
    h5::write_doubles(file, "/simulation/t_reached", {n}, reached);
    h5::write_doubles(file, "/simulation/peak_input", {n, static_cast<hsize_t>(nu)}, rows(vs, &SweepVariant::peak_input, nu));
    h5::write_doubles(file, "/simulation/final_error", {n}, err);
    h5::write_doubles(file, "/simulation/overshoot", {n, static_cast<hsize_t>(ny)}, rows(vs, &SweepVariant::overshoot, ny));
    h5::write_doubles(file, "/simulation/settling_time", {n, static_cast<hsize_t>(ny)}, rows(vs, &SweepVariant::settling_time, ny));
    h5::write_doubles(file, "/simulation/saturation_time", {n, static_cast<hsize_t>(nu)},
                  rows(vs, &SweepVariant::saturation_time, nu));
    h5::write_attribute(file, "/simulation", "status_codes",
                    std::string("-1 not run (the variant failed), 0 reached t_end, 1 the run failed, 2 it could not be set up"));
  }
  if (!job.closed_loop) {
    h5::write_ints(file, "/open_loop/stable", stable);
    return;
  }
  h5::create_group(file, "/closed_loop");
  if (job.redesigned) {
    h5::write_doubles(file, "/closed_loop/K", {n, static_cast<hsize_t>(nu), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::K, nu, nx));
  } else {
    std::vector<double> k(static_cast<std::size_t>(nu * nx));
    for (Eigen::Index a = 0; a < nu; ++a)
      for (Eigen::Index b = 0; b < nx; ++b) k[static_cast<std::size_t>(a * nx + b)] = job.K(a, b);
    h5::write_doubles(file, "/closed_loop/K", {static_cast<hsize_t>(nu), static_cast<hsize_t>(nx)}, k);
  }
  write_poles(file, "/closed_loop", vs, &SweepVariant::closed_poles, &SweepVariant::closed_max_real, nx);
  h5::write_ints(file, "/closed_loop/stable", stable);
}

void append_number(std::string& line, double x) {
  if (!std::isfinite(x)) {
    line += std::isnan(x) ? "nan" : (x > 0 ? "inf" : "-inf");
    return;
  }
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 17);
  line.append(buf, res.ptr);
}

void append_csv_field(std::string& line, const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) {
    line += text;
    return;
  }
  line += '"';
  for (char ch : text) line.append(ch == '"' ? 2 : 1, ch);
  line += '"';
}

}  // namespace

void write_sweep_hdf5(const SweepJob& job, const std::string& path) {
  guard_output(path, OutputKind::ResultsHdf5, {job.model_file});
  AtomicFile out(path);
  try {
    const QuietHdf5 quiet;
    Handle file(H5Fcreate(out.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                "cannot create " + out.temp_path());
    write_contents(file, job);
    file.close("cannot finish " + out.temp_path());
  } catch (const FileError& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  out.commit();
}

void write_sweep_csv(const SweepJob& job, const std::string& path) {
  guard_output(path, OutputKind::SweepCsv, {job.model_file});
  std::string text = kSweepCsvHead;
  for (const SweepVary& v : job.plan.vary) {
    text += ',';
    append_csv_field(text, v.field);
  }
  text += ",open_loop_max_real";
  if (job.closed_loop) text += ",closed_loop_max_real";
  text += ",stable,uncontrollable";
  if (job.simulated) {
    text += ",sim_status,peak_input,final_error";
    for (const auto& [label, names] : {std::pair{"overshoot:", &job.output_names}, {"settling_time:", &job.output_names},
                                       {"saturation_time:", &job.input_names}})
      for (const std::string& name : *names) {
        text += ',';
        append_csv_field(text, label + name);
      }
  }
  text += ",reason\n";
  for (std::size_t i = 0; i < job.variants.size(); ++i) {
    const SweepVariant& v = job.variants[i];
    const bool ok = v.status == SweepStatus::Ok;
    text += std::to_string(i) + ',' + to_string(v.status);
    for (double x : v.values) {
      text += ',';
      append_number(text, x);
    }
    text += ',';
    append_number(text, ok ? v.open_max_real : kNaN);
    if (job.closed_loop) {
      text += ',';
      append_number(text, ok ? v.closed_max_real : kNaN);
    }
    text += std::string(",") + (v.stable ? "1" : "0") + ',' + (ok ? std::to_string(v.uncontrollable) : std::string());
    if (job.simulated) {
      text += ',' + std::to_string(v.sim_status) + ',';
      append_number(text, v.peak_input.size() ? v.peak_input.maxCoeff() : kNaN);
      text += ',';
      append_number(text, v.sim_status == 0 || v.sim_status == 1 ? v.final_error : kNaN);
      const auto each = [&](const Eigen::VectorXd& x, std::size_t size) {
        for (std::size_t k = 0; k < size; ++k) {
          text += ',';
          append_number(text, x.size() == static_cast<Eigen::Index>(size) ? x[static_cast<Eigen::Index>(k)] : kNaN);
        }
      };
      each(v.overshoot, job.output_names.size());
      each(v.settling_time, job.output_names.size());
      each(v.saturation_time, job.input_names.size());
    }
    text += ',';
    append_csv_field(text, v.reason.empty() ? v.sim_reason : v.reason);
    text += '\n';
  }
  write_file_atomically(path, text);
}

namespace {

struct MatVarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatVar = std::unique_ptr<matvar_t, MatVarFree>;

MatVar mat_checked(matvar_t* v, const char* name) {
  if (!v) throw std::runtime_error(std::string("cannot create MAT variable ") + (name ? name : "(cell)"));
  return MatVar(v);
}

// column-major data of dims
MatVar mat_doubles(const char* name, std::vector<size_t> dims, std::vector<double> data) {
  return mat_checked(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, static_cast<int>(dims.size()), dims.data(), data.data(), 0),
                     name);
}

MatVar mat_char(const char* name, const std::string& s) {
  std::u16string u = mat_utf16(s);  // as the plant export stores text
  size_t dims[2] = {u.empty() ? 0u : 1u, u.size()};
  return mat_checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, u.data(), 0), name);
}

MatVar mat_cellstr(const char* name, const std::vector<std::string>& list) {
  size_t dims[2] = {list.size(), 1};
  MatVar cell = mat_checked(Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0), name);
  for (std::size_t i = 0; i < list.size(); ++i) Mat_VarSetCell(cell.get(), static_cast<int>(i), mat_char(nullptr, list[i]).release());
  return cell;
}

// rows x cols x n, page k = variant k's matrix (NaN when it failed)
MatVar mat_stack(const char* name, const std::vector<SweepVariant>& vs, Eigen::MatrixXd SweepVariant::*field, Eigen::Index rows,
                 Eigen::Index cols) {
  std::vector<double> data(vs.size() * static_cast<std::size_t>(rows * cols), kNaN);
  for (std::size_t k = 0; k < vs.size(); ++k) {
    const Eigen::MatrixXd& M = vs[k].*field;
    if (vs[k].status == SweepStatus::Ok && M.rows() == rows && M.cols() == cols)
      std::copy(M.data(), M.data() + M.size(), data.begin() + static_cast<std::ptrdiff_t>(k * static_cast<std::size_t>(rows * cols)));
  }
  return mat_doubles(name, {static_cast<size_t>(rows), static_cast<size_t>(cols), vs.size()}, std::move(data));
}

// nx x n, column k = variant k's poles (real or imaginary parts)
MatVar mat_poles(const char* name, const std::vector<SweepVariant>& vs, Eigen::VectorXcd SweepVariant::*field, Eigen::Index nx,
                 bool imag) {
  std::vector<double> data(vs.size() * static_cast<std::size_t>(nx), kNaN);
  for (std::size_t k = 0; k < vs.size(); ++k) {
    const Eigen::VectorXcd& p = vs[k].*field;
    if (vs[k].status != SweepStatus::Ok || p.size() != nx) continue;
    for (Eigen::Index j = 0; j < nx; ++j) data[k * static_cast<std::size_t>(nx) + static_cast<std::size_t>(j)] = imag ? p[j].imag() : p[j].real();
  }
  return mat_doubles(name, {static_cast<size_t>(nx), vs.size()}, std::move(data));
}

std::string m_quoted(const std::string& s) {
  std::string out = "'";
  for (char ch : s) {
    if (ch == '\n' || ch == '\r') ch = ' ';
    out += ch == '\'' ? std::string("''") : std::string(1, ch);
  }
  return out + "'";
}

std::string sweep_script(const SweepJob& job, const std::string& name) {
  std::ostringstream m;
  m << "% " << name << ".m - a parameter study (codyna sweep), exported by codyna " << CODYNA_VERSION << "\n"
    << "%\n% Model: " << job.model_name << "  (" << job.model_file << ")\n"
    << "% " << job.variants.size() << " variants of the fields in `fields` (values(k,:) is variant k's), "
    << (job.plan.random ? "joint random samples" : "a full grid") << "; " << job.operating_point << " point, " << job.method
    << " Jacobians.\n"
    << "% Variant k: A(:,:,k), B(:,:,k), C(:,:,k), D(:,:,k) (continuous; NaN when status(k) is not 0: see reason{k}),\n"
    << "% open_poles(:,k) = eig(A(:,:,k))";
  if (job.closed_loop)
    m << ", closed_poles(:,k) = eig(A(:,:,k) - B(:,:,k) * K" << (job.redesigned ? "(:,:,k)" : "") << ")";
  m << ".\n% sys: the completed variants ok = find(status == 0) as one ss array (MATLAB) or a cell array of ss\n"
    << "% (Octave's ss has no array dimension), when ss() exists.\n\n"
    << "codyna_here = fileparts(mfilename('fullpath'));\n"
    << "load(fullfile(codyna_here, '" << name << ".mat'));\n"
    << "if exist('OCTAVE_VERSION', 'builtin')\n  try\n    pkg load control\n  catch\n  end\nend\n"
    << "open_poles = open_poles_real + 1i * open_poles_imag;\n";
  if (job.closed_loop) m << "closed_poles = closed_poles_real + 1i * closed_poles_imag;\n";
  m << "ok = find(status == 0);\n"
    << "if exist('ss') >= 2\n"
    << "  if exist('OCTAVE_VERSION', 'builtin')\n"
    << "    sys = cell(numel(ok), 1);\n"
    << "    for codyna_k = 1:numel(ok)\n"
    << "      j = ok(codyna_k);\n"
    << "      sys{codyna_k} = ss(A(:,:,j), B(:,:,j), C(:,:,j), D(:,:,j), 'StateName', state_names, 'InputName', input_names, "
       "'OutputName', output_names);\n"
    << "    end\n"
    << "    clear codyna_k j\n"
    << "  else\n"
    << "    sys = ss(A(:,:,ok), B(:,:,ok), C(:,:,ok), D(:,:,ok), 'StateName', state_names, 'InputName', input_names, "
       "'OutputName', output_names);\n"
    << "  end\n"
    << "end\n"
    << "fprintf('%s: %d variants of model %s (%d completed), %d states, %d inputs, %d outputs.\\n', ...\n"
    << "        " << m_quoted(name) << ", numel(status), " << m_quoted(job.model_name)
    << ", numel(ok), size(A, 1), size(B, 2), size(C, 1));\n"
    << "clear codyna_here\n";
  return m.str();
}

}  // namespace

void write_sweep_mat(const SweepJob& job, const std::string& mat_path) {
  const std::filesystem::path p(mat_path);
  const std::string name = p.stem().string();
  if (p.extension() != ".mat") throw std::invalid_argument(mat_path + ": expected DIR/NAME.mat");
  if (matlab_identifier(name) != name)
    throw std::invalid_argument(mat_path + ": '" + name + "' is not a MATLAB identifier (try " + matlab_identifier(name) + ".mat)");
  const std::string m_path = (p.parent_path() / (name + ".m")).string();
  guard_output(mat_path, OutputKind::PlantMat, {job.model_file});
  guard_output(m_path, OutputKind::PlantScript, {job.model_file});
  const auto& vs = job.variants;
  const std::size_t n = vs.size(), nv = job.plan.vary.size();
  const Eigen::Index nx = static_cast<Eigen::Index>(job.state_names.size()), nu = static_cast<Eigen::Index>(job.input_names.size()),
                     ny = static_cast<Eigen::Index>(job.output_names.size());
  AtomicFile mat(mat_path), script(m_path);
  {
    const std::string header = "MATLAB 5.0 MAT-file, codyna sweep " + name + ", codyna " + CODYNA_VERSION;
    mat_t* f = Mat_CreateVer(mat.temp_path().c_str(), header.c_str(), MAT_FT_MAT5);
    if (!f) throw std::runtime_error(mat_path + ": cannot create " + mat.temp_path());
    std::vector<MatVar> vars;
    vars.push_back(mat_stack("A", vs, &SweepVariant::A, nx, nx));
    vars.push_back(mat_stack("B", vs, &SweepVariant::B, nx, nu));
    vars.push_back(mat_stack("C", vs, &SweepVariant::C, ny, nx));
    vars.push_back(mat_stack("D", vs, &SweepVariant::D, ny, nu));
    std::vector<double> values(n * nv, kNaN), status(n), omr(n, kNaN), cmr(n, kNaN), stable(n);
    std::vector<std::string> fields, reasons;
    for (std::size_t k = 0; k < nv; ++k) fields.push_back(job.plan.vary[k].field);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < nv && k < vs[i].values.size(); ++k) values[k * n + i] = vs[i].values[k];  // column-major
      status[i] = static_cast<double>(static_cast<int>(vs[i].status));
      reasons.push_back(vs[i].reason);
      if (vs[i].status == SweepStatus::Ok) {
        omr[i] = vs[i].open_max_real;
        cmr[i] = vs[i].closed_max_real;
      }
      stable[i] = vs[i].stable ? 1 : 0;
    }
    vars.push_back(mat_doubles("values", {n, nv}, values));
    vars.push_back(mat_cellstr("fields", fields));
    vars.push_back(mat_doubles("status", {n, 1}, status));
    vars.push_back(mat_cellstr("reason", reasons));
    vars.push_back(mat_poles("open_poles_real", vs, &SweepVariant::open_poles, nx, false));
    vars.push_back(mat_poles("open_poles_imag", vs, &SweepVariant::open_poles, nx, true));
    vars.push_back(mat_doubles("open_max_real", {n, 1}, omr));
    vars.push_back(mat_doubles("stable", {n, 1}, stable));
    if (job.closed_loop) {
      if (job.redesigned) vars.push_back(mat_stack("K", vs, &SweepVariant::K, nu, nx));
      else vars.push_back(mat_doubles("K", {static_cast<size_t>(nu), static_cast<size_t>(nx)},
                                      std::vector<double>(job.K.data(), job.K.data() + job.K.size())));
      vars.push_back(mat_poles("closed_poles_real", vs, &SweepVariant::closed_poles, nx, false));
      vars.push_back(mat_poles("closed_poles_imag", vs, &SweepVariant::closed_poles, nx, true));
      vars.push_back(mat_doubles("closed_max_real", {n, 1}, cmr));
    }
    if (job.simulated) {  // n x size, row k = variant k's (NaN where it has none)
      const auto columns = [&](const char* name, Eigen::VectorXd SweepVariant::*field, Eigen::Index size) {
        std::vector<double> data(n * static_cast<std::size_t>(size), kNaN);
        for (std::size_t i = 0; i < n; ++i) {
          const Eigen::VectorXd& x = vs[i].*field;
          if (x.size() == size)
            for (Eigen::Index k = 0; k < size; ++k) data[static_cast<std::size_t>(k) * n + i] = x[k];
        }
        return mat_doubles(name, {n, static_cast<size_t>(size)}, std::move(data));
      };
      std::vector<double> sim_status(n), final_error(n, kNaN);
      for (std::size_t i = 0; i < n; ++i) {
        sim_status[i] = vs[i].sim_status;
        if (vs[i].sim_status == 0 || vs[i].sim_status == 1) final_error[i] = vs[i].final_error;
      }
      vars.push_back(mat_doubles("sim_status", {n, 1}, sim_status));
      vars.push_back(mat_doubles("final_error", {n, 1}, final_error));
      vars.push_back(columns("peak_input", &SweepVariant::peak_input, nu));
      vars.push_back(columns("overshoot", &SweepVariant::overshoot, ny));
      vars.push_back(columns("settling_time", &SweepVariant::settling_time, ny));
      vars.push_back(columns("saturation_time", &SweepVariant::saturation_time, nu));
    }
    vars.push_back(mat_cellstr("state_names", job.state_names));
    vars.push_back(mat_cellstr("input_names", job.input_names));
    vars.push_back(mat_cellstr("output_names", job.output_names));
    bool ok = true;
    for (const MatVar& v : vars) ok = ok && Mat_VarWrite(f, v.get(), MAT_COMPRESSION_NONE) == 0;
    ok = Mat_Close(f) == 0 && ok;
    if (!ok) throw std::runtime_error(mat_path + ": cannot write " + mat.temp_path());
  }
  {
    std::ofstream out(script.temp_path(), std::ios::binary | std::ios::trunc);
    out << sweep_script(job, name);
    out.close();
    if (!out) throw std::runtime_error(m_path + ": cannot write " + script.temp_path());
  }
  mat.commit();
  script.commit();
}

}  // namespace codyna
