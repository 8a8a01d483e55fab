#include "study/sweep.hpp"

#include "analysis/stability.hpp"

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
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/tools.hpp"

namespace codyna {

namespace {

constexpr int kFormatVersion = 1;
constexpr long long kMaxVariants = 10'000'000;
constexpr const char* kCsvHeadStart = "variant,status";

struct Names {
  OptionStyle style;
  std::string operator()(const std::string& dashed) const { return option_name(style, dashed); }
};

std::string trim(std::string s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return {};
  const auto b = s.find_last_not_of(" \t");
  return s.substr(a, b - a + 1);
}

bool parse_number(const std::string& text, double& out) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  const char* first = t.data();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), out);
  return ec == std::errc() && ptr == t.data() + t.size() && std::isfinite(out);
}

std::string fmt(double x) {
  std::ostringstream os;
  os << std::setprecision(10) << x;
  return os.str();
}

// ------------------------------------------------------------------ random numbers
// Counter-based: every number is a hash of (seed, variant, field, draw), so variant i never
// depends on which variants ran before it, on which thread, or in which process.

std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// uniform on the open interval (0, 1), 53 bits
double unit_draw(std::uint64_t seed, long long i, std::size_t k, int draw) {
  std::uint64_t h = splitmix64(seed);
  h = splitmix64(h ^ static_cast<std::uint64_t>(i));
  h = splitmix64(h ^ static_cast<std::uint64_t>(k));
  h = splitmix64(h ^ static_cast<std::uint64_t>(draw));
  return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53;
}

// ------------------------------------------------------------------ --vary parsing

SweepVary parse_vary(const std::string& text, const nlohmann::json& file, const std::string& model, const Names& opt) {
  const std::string label = opt("vary") + " " + text;
  const auto eq = text.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument(label + ": expected FIELD=SPEC (e.g. /bodies/1/mass=5:15:11)");
  SweepVary v;
  v.field = trim(text.substr(0, eq));
  v.spec = trim(text.substr(eq + 1));
  if (v.field.empty() || v.field[0] != '/')
    throw std::invalid_argument(label + ": the field must be a JSON pointer into the model file, starting with / "
                                "(e.g. /bodies/1/mass, /effects/0/stiffness, /joints/2/q0)");
  nlohmann::json::json_pointer ptr;
  try {
    ptr = nlohmann::json::json_pointer(v.field);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(label + ": " + v.field + " is not a JSON pointer (" + e.what() + ")");
  }
  const nlohmann::json* at = nullptr;
  try {
    if (file.contains(ptr)) at = &file.at(ptr);
  } catch (const nlohmann::json::exception&) {
    at = nullptr;
  }
  if (!at) {
    // the longest part of the path that exists, to say where it went wrong
    nlohmann::json::json_pointer have = ptr;
    while (!have.empty()) {
      have = have.parent_pointer();
      bool ok = false;
      try {
        ok = file.contains(have);
      } catch (const nlohmann::json::exception&) {
      }
      if (ok) break;
    }
    std::string where;
    const nlohmann::json& p = have.empty() ? file : file.at(have);
    if (p.is_array()) where = " (" + (have.empty() ? std::string("/") : have.to_string()) + " has " + std::to_string(p.size()) + " entries)";
    else if (p.is_object()) {
      where = " (" + (have.empty() ? std::string("the top level") : have.to_string()) + " has ";
      int n = 0;
      for (auto it = p.begin(); it != p.end(); ++it) where += std::string(n++ ? ", " : "") + it.key();
      where += ")";
    }
    throw std::invalid_argument(label + ": the model file " + model + " has no field " + v.field + where);
  }
  if (!at->is_number())
    throw std::invalid_argument(label + ": " + v.field + " in " + model + " is not a number (it is " + at->type_name() +
                                "); vary one number, e.g. " + v.field + "/0");
  v.nominal = at->get<double>();
  const std::string& s = v.spec;
  const std::string grammar = "expected a:b:n (n values from a to b), [v1,v2,...], normal(mu,sigma) or uniform(a,b)";
  if (s.empty()) throw std::invalid_argument(label + ": no SPEC after = (" + grammar + ")");
  const auto two_args = [&](const char* name, double& x, double& y) {
    const std::string head = std::string(name) + "(";
    if (s.rfind(head, 0) != 0) return false;
    if (s.back() != ')') throw std::invalid_argument(label + ": " + name + "(...) is not closed by )");
    const std::string inner = s.substr(head.size(), s.size() - head.size() - 1);
    const auto comma = inner.find(',');
    if (comma == std::string::npos || !parse_number(inner.substr(0, comma), x) || !parse_number(inner.substr(comma + 1), y))
      throw std::invalid_argument(label + ": expected " + name + "(NUMBER,NUMBER)");
    return true;
  };
  if (s[0] == '[') {
    nlohmann::json list;
    try {
      list = nlohmann::json::parse(s);
    } catch (const nlohmann::json::exception&) {
      throw std::invalid_argument(label + ": the list is not [v1,v2,...] of numbers");
    }
    if (!list.is_array() || list.empty()) throw std::invalid_argument(label + ": the list is empty or not a list");
    for (const auto& x : list) {
      if (!x.is_number()) throw std::invalid_argument(label + ": the list holds " + x.dump() + ", not a number");
      v.values.push_back(x.get<double>());
    }
    v.kind = SweepVary::Grid;
  } else if (two_args("normal", v.a, v.b)) {
    if (!(v.b >= 0)) throw std::invalid_argument(label + ": normal(mu,sigma) needs sigma >= 0");
    v.kind = SweepVary::Normal;
  } else if (two_args("uniform", v.a, v.b)) {
    if (!(v.b > v.a)) throw std::invalid_argument(label + ": uniform(a,b) needs a < b");
    v.kind = SweepVary::Uniform;
  } else if (std::count(s.begin(), s.end(), ':') == 2) {
    const auto c1 = s.find(':'), c2 = s.find(':', c1 + 1);
    double a = 0, b = 0, n = 0;
    if (!parse_number(s.substr(0, c1), a) || !parse_number(s.substr(c1 + 1, c2 - c1 - 1), b) ||
        !parse_number(s.substr(c2 + 1), n))
      throw std::invalid_argument(label + ": " + grammar);
    if (n < 1 || n != std::floor(n) || n > kMaxVariants)
      throw std::invalid_argument(label + ": n in a:b:n must be a whole number from 1 to " + std::to_string(kMaxVariants));
    const long long count = static_cast<long long>(n);
    if (count == 1 && a != b) throw std::invalid_argument(label + ": a:b:1 holds one value; give a:a:1 or [a]");
    for (long long k = 0; k < count; ++k)
      v.values.push_back(k == count - 1 ? b : a + (b - a) * static_cast<double>(k) / static_cast<double>(count - 1));
    v.kind = SweepVary::Grid;
  } else {
    throw std::invalid_argument(label + ": " + grammar);
  }
  return v;
}

// ------------------------------------------------------------------ per variant

void sort_poles(Eigen::VectorXcd& p) {
  std::sort(p.data(), p.data() + p.size(), [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.real() < b.real() || (a.real() == b.real() && a.imag() < b.imag());
  });
}

Eigen::VectorXcd poles_of(const Eigen::MatrixXd& A) {
  Eigen::VectorXcd p = A.size() ? Eigen::VectorXcd(A.eigenvalues()) : Eigen::VectorXcd();
  sort_poles(p);
  return p;
}

double max_real(const Eigen::VectorXcd& p) {
  return p.size() ? p.real().maxCoeff() : -std::numeric_limits<double>::infinity();
}

// asymptotically stable (analysis/stability.hpp): every pole stable, continuous or sampled
bool stable_poles(const Eigen::VectorXcd& p, const Eigen::MatrixXd& A, bool discrete) {
  return classify_poles(p, discrete, stability_tolerance(A)).asymptotically_stable();
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// The varied fields of one element of the model file's arrays (/bodies/1/mass, /bodies/1/com/0):
// a variant reads that element again into a copy of the nominal spec (io/model_file.hpp,
// parse_model_element), the rest of the file is not read again.
struct ElementEdit {
  std::string section;
  std::size_t index = 0;
  std::vector<std::pair<nlohmann::json::json_pointer, std::size_t>> fields;  // below the element; which value
};

struct Context {
  const SweepRequest* request;
  const SweepPlan* plan;
  const nlohmann::json* file;
  const ModelSpec* nominal = nullptr;
  std::vector<nlohmann::json::json_pointer> pointers;
  std::vector<ElementEdit> edits;
  bool whole_file = false;  // a varied field outside the element arrays: each variant's file is read whole
  // the nominal model's tree, names and indices when the varied fields leave them as they are
  // (numbers_changed, study_linearize_structure): a variant makes what it changes in a copy
  const Model* structure = nullptr;
  NumbersChanged changed;
  LinearizeRequest linearize;
  int nx = 0, nu = 0, ny = 0;
  std::vector<std::string> state_names;
  bool closed_loop = false, redesign = false, simulate = false;
  bool replace_controller = false;  // simulate with K fixed: the file's controller becomes a state feedback K
  std::string controller_point;     // where that state feedback is applied
  Eigen::MatrixXd K;
};

// Per column of e (samples x outputs, y - target at times t): the overshoot in % of the
// excursion E = max |e| past the target, on the side opposite to the excursion, and the time e
// enters the band |e| <= 0.02 E for good (e linear between samples), NaN when the last sample is
// outside it; E = 0: 0 % at t[0]. docs/parameter-studies.md, "Figures of merit".
void response_figures(const std::vector<double>& t, const Eigen::MatrixXd& e, Eigen::VectorXd& overshoot,
                      Eigen::VectorXd& settling) {
  const Eigen::Index N = e.rows();
  for (Eigen::Index j = 0; j < e.cols(); ++j) {
    const auto col = e.col(j);
    if (N == 0 || !col.allFinite()) continue;
    Eigen::Index peak = 0;
    const double E = col.cwiseAbs().maxCoeff(&peak);
    if (E == 0) {
      overshoot[j] = 0;
      settling[j] = t[0];
      continue;
    }
    const double s = col[peak] > 0 ? 1.0 : -1.0;
    overshoot[j] = 100.0 * std::max(0.0, (-s * col).maxCoeff()) / E;
    const double band = 0.02 * E;
    Eigen::Index k = N - 1;
    if (std::abs(col[k]) > band) continue;
    while (k > 0 && std::abs(col[k - 1]) <= band) --k;
    if (k == 0) {
      settling[j] = t[0];
      continue;
    }
    // e(k-1) is outside the band, e(k) inside: where the line between them meets it
    const double a = col[k - 1], b = col[k], edge = a > 0 ? band : -band;
    const double f = (a - edge) / (a - b);
    const std::size_t i = static_cast<std::size_t>(k);
    settling[j] = t[i - 1] + f * (t[i] - t[i - 1]);
  }
}

// The variant's nonlinear closed-loop run with the sweep's controller.
void simulate_variant(const Context& c, nlohmann::json j, SweepVariant& v) {
  try {
    if (c.replace_controller) {
      nlohmann::json K = nlohmann::json::array();
      for (Eigen::Index a = 0; a < c.K.rows(); ++a) {
        nlohmann::json row = nlohmann::json::array();
        for (Eigen::Index b = 0; b < c.K.cols(); ++b) row.push_back(c.K(a, b));
        K.push_back(row);
      }
      j["controller"] = {{"type", "state_feedback"}, {"K", K}, {"operating_point", c.controller_point}};
      if (j.contains("analysis") && j["analysis"].is_object()) j["analysis"]["controller"] = "model";
    }
    SimulateRequest sr;
    sr.model = c.request->model;
    const SimulateJob sj = study_simulate_job(sr, study_parse_model(j, c.request->model));
    const SimulationResult& r = sj.result;
    v.sim_status = r.completed ? 0 : 1;
    v.sim_reason = r.completed ? std::string() : r.failure;
    v.sim_t_end = r.t.empty() ? 0.0 : r.t.back();
    v.peak_input = sj.max_abs_input;
    v.final_error = 0;
    const Eigen::Index ny = r.y.cols();
    v.overshoot = v.settling_time = Eigen::VectorXd::Constant(ny, std::numeric_limits<double>::quiet_NaN());
    if (!r.t.empty() && ny > 0) {
      const Eigen::Index last = r.y.rows() - 1;
      Eigen::VectorXd target = sj.setup.plant ? sj.setup.plant->lin.system.y0 : Eigen::VectorXd::Zero(ny);
      if (r.y_reference.cols() == ny && r.y_reference.rows() == r.y.rows()) target = r.y_reference.row(last).transpose();
      if (target.size() == ny) {
        v.final_error = (r.y.row(last).transpose() - target).cwiseAbs().maxCoeff();
        if (r.completed) response_figures(r.t, r.y.rowwise() - target.transpose(), v.overshoot, v.settling_time);
      } else {
        v.final_error = std::numeric_limits<double>::quiet_NaN();
      }
    }
    // seconds at a limit per Plant/In: 0 never, NaN for an input without limits
    const Model& m = sj.model;
    v.saturation_time = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(m.plant_inputs.size()),
                                                  std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) {
      const ActuatorModel& a = m.actuators[static_cast<std::size_t>(m.plant_inputs[k])];
      if (!std::isfinite(a.min) && !std::isfinite(a.max)) continue;
      double at = 0;
      for (const Saturation& sat : sj.saturation)
        if (sat.actuator == a.name) at += sat.at_max + sat.at_min;
      v.saturation_time[static_cast<Eigen::Index>(k)] = at;
    }
  } catch (const std::exception& e) {
    v.sim_status = 2;
    v.sim_reason = e.what();
    v.peak_input.resize(0);
    v.overshoot.resize(0);
    v.settling_time.resize(0);
    v.saturation_time.resize(0);
  }
}

// the variant's model file, the varied fields set
nlohmann::json variant_file(const Context& c, const SweepVariant& v) {
  nlohmann::json j = *c.file;
  for (std::size_t k = 0; k < c.pointers.size(); ++k) j[c.pointers[k]] = v.values[k];
  return j;
}

// the variant's spec: what reading variant_file gives, by reading only the edited elements again
ModelSpec variant_spec(const Context& c, const SweepVariant& v) {
  if (c.whole_file) return study_parse_model(variant_file(c, v), c.request->model);
  ModelSpec spec = *c.nominal;
  for (const ElementEdit& e : c.edits) {
    nlohmann::json element = (*c.file)[e.section][e.index];
    for (const auto& [pointer, k] : e.fields) element[pointer] = v.values[k];
    parse_model_element(spec, e.section, e.index, element, c.request->model);
  }
  return spec;
}

// what the varied fields change of the compiled model when they leave its tree, names and indices
// as they are (compile_numbers): a body's mass, com or inertia (or a component of them), any field of
// an effect, a joint's q0 or v0, an actuator's or a sensor's numbers (NumbersChanged); nothing otherwise
std::optional<NumbersChanged> numbers_changed(const std::vector<SweepVary>& vary) {
  NumbersChanged what;
  for (const SweepVary& v : vary) {
    const std::string& f = v.field;
    const std::size_t a = f.find('/', 1), b = a == std::string::npos ? a : f.find('/', a + 1);
    if (b == std::string::npos || b == a + 1 || !std::all_of(f.begin() + static_cast<long>(a) + 1, f.begin() + static_cast<long>(b), ::isdigit))
      return std::nullopt;
    const std::string section = f.substr(1, a - 1);
    const std::size_t e = f.find('/', b + 1);
    const std::string name = f.substr(b + 1, e == std::string::npos ? std::string::npos : e - b - 1);
    if (section == "bodies" && (name == "mass" || name == "com" || name == "inertia"))
      what.bodies = true;
    else if (section == "effects")
      what.effects = true;
    else if (section == "joints" && (name == "q0" || name == "v0"))
      what.initial = true;
    else if (section == "actuators" && (name == "gain" || name == "u0" || name == "min" || name == "max" || name == "point" ||
                                        name == "direction" || name == "point_a" || name == "point_b" || name == "weights"))
      what.actuators = true;
    else if (section == "sensors" && (name == "point" || name == "axis" || name == "point_a" || name == "point_b"))
      what.sensors = true;
    else
      return std::nullopt;
  }
  if (vary.empty()) return std::nullopt;
  return what;
}

// which element each varied field belongs to (Context::edits), or whole_file
void plan_edits(Context& c, const std::vector<SweepVary>& vary) {
  static const char* const sections[] = {"bodies", "joints", "constraints", "effects", "actuators", "sensors"};
  for (std::size_t k = 0; k < vary.size(); ++k) {
    const std::string& f = vary[k].field;  // "/section/index/rest..."
    const std::size_t a = f.find('/', 1), b = a == std::string::npos ? a : f.find('/', a + 1);
    const std::string section = f.substr(1, a == std::string::npos ? std::string::npos : a - 1);
    const std::string index = a == std::string::npos ? "" : f.substr(a + 1, b == std::string::npos ? b : b - a - 1);
    const bool known = std::find_if(std::begin(sections), std::end(sections),
                                    [&](const char* s) { return section == s; }) != std::end(sections);
    const bool digits = !index.empty() && index.size() < 9 && std::all_of(index.begin(), index.end(), ::isdigit) &&
                        (index == "0" || index[0] != '0');
    if (!known || !digits || b == std::string::npos || !c.file->contains(section) || !(*c.file)[section].is_array() ||
        std::stoul(index) >= (*c.file)[section].size() || !(*c.file)[section][std::stoul(index)].is_object()) {
      c.whole_file = true;
      return;
    }
    const std::size_t i = std::stoul(index);
    auto it = std::find_if(c.edits.begin(), c.edits.end(), [&](const ElementEdit& e) { return e.section == section && e.index == i; });
    if (it == c.edits.end()) it = c.edits.insert(c.edits.end(), ElementEdit{section, i, {}});
    it->fields.emplace_back(nlohmann::json::json_pointer(f.substr(b)), k);
  }
}

void run_variant(const Context& c, long long i, SweepVariant& v) {
  v.values = c.plan->values(i);
  try {
    const ModelSpec spec = variant_spec(c, v);
    const auto simulate_after = [&] {
      if (c.simulate) simulate_variant(c, variant_file(c, v), v);
    };
    const LinearizeJob lj =
        c.structure ? study_linearize_job(c.linearize, spec, *c.structure, c.changed) : study_linearize_job(c.linearize, spec);
    const LinearSystem& sys = lj.linearization.lin.system;  // continuous
    if (sys.nx() != c.nx || sys.nu() != c.nu || sys.ny() != c.ny) {
      v.status = SweepStatus::SizeDiffers;
      v.reason = "A, B, C, D are " + std::to_string(sys.nx()) + " states, " + std::to_string(sys.nu()) + " inputs, " +
                 std::to_string(sys.ny()) + " outputs where the nominal model's are " + std::to_string(c.nx) + ", " +
                 std::to_string(c.nu) + ", " + std::to_string(c.ny);
      return;
    }
    if (sys.state_names != c.state_names) {
      v.status = SweepStatus::SizeDiffers;
      v.reason = "its states are (" + joined(sys.state_names) + ") where the nominal model's are (" +
                 joined(c.state_names) + ")";
      return;
    }
    v.A = sys.A;
    v.B = sys.B;
    v.C = sys.C;
    v.D = sys.D;
    v.open_poles = poles_of(sys.A);
    v.open_max_real = max_real(v.open_poles);
    v.open_stable = stable_poles(v.open_poles, sys.A, sys.Ts > 0);
    v.uncontrollable = static_cast<int>(lj.uncontrollable.size());
    if (v.uncontrollable) v.uncontrollable_text = study_describe_modes(lj.uncontrollable);
    if (c.closed_loop) {
      Eigen::MatrixXd K = c.K;
      if (c.redesign) {
        const StudySimulation setup = study_simulation(lj.model);
        const Eigen::MatrixXd* g = setup.controller ? setup.controller->gain() : nullptr;
        if (!g) throw std::invalid_argument("the LQR was not designed again for this variant");
        K = *g;
        v.K = K;
      }
      const Eigen::MatrixXd Acl = sys.A - sys.B * K;
      v.closed_poles = poles_of(Acl);
      v.closed_max_real = max_real(v.closed_poles);
      v.stable = stable_poles(v.closed_poles, Acl, sys.Ts > 0);
    } else {
      v.stable = stable_poles(v.open_poles, sys.A, sys.Ts > 0);
    }
    v.status = SweepStatus::Ok;
    simulate_after();
  } catch (const ModelError& e) {
    v.status = SweepStatus::ModelError;
    v.reason = e.what();
  } catch (const ConvergenceError& e) {
    v.status = SweepStatus::NotConverged;
    v.reason = e.what();
  } catch (const std::invalid_argument& e) {
    v.status = SweepStatus::Refused;
    v.reason = e.what();
  } catch (const std::exception& e) {
    v.status = SweepStatus::Failed;
    v.reason = e.what();
  }
  if (v.status != SweepStatus::Ok) {
    v.A.resize(0, 0);
    v.B.resize(0, 0);
    v.C.resize(0, 0);
    v.D.resize(0, 0);
    v.K.resize(0, 0);
    v.open_poles.resize(0);
    v.closed_poles.resize(0);
    v.stable = false;
    v.uncontrollable = 0;
    v.uncontrollable_text.clear();
  }
}

// ------------------------------------------------------------------ output checks

// the CSV is checked as the other outputs are (io/output_guard.hpp), by its own header
void guard_csv(const std::string& path, const std::string& model) {
  if (study_same_file(path, model))
    throw std::invalid_argument(path + ": this is the input file " + model +
                                " (the same file); codyna never writes an output over its input: choose another name");
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return;
  if (!S_ISREG(st.st_mode)) throw std::invalid_argument(path + ": exists and is not a regular file; choose another name");
  if (st.st_size == 0) return;
  std::ifstream in(path, std::ios::binary);
  std::string head(std::strlen(kCsvHeadStart), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  if (head != kCsvHeadStart)
    throw std::invalid_argument(path + ": exists and is not a sweep CSV written by codyna (it does not begin \"" +
                                kCsvHeadStart + "\"); codyna never replaces a file it did not write: remove it or choose another name");
}

// ------------------------------------------------------------------ the journal (resume)
// One line per finished variant, a JSON object whose numbers are hexadecimal texts (exact, NaN
// and infinities included), after a first line naming the study by a hash of the model file's
// bytes and every option that changes a result.

std::uint64_t hash_text(std::uint64_t h, const std::string& text) {
  for (unsigned char ch : text) h = (h ^ ch) * 0x100000001b3ULL;  // FNV-1a
  return splitmix64(h ^ text.size());
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

// the first line of a study's journal: what makes its variants what they are
std::string journal_head(const SweepRequest& r, const std::string& model_bytes, long long count) {
  std::uint64_t h = hash_text(0xcbf29ce484222325ULL, model_bytes);
  for (const std::string& v : r.vary) h = hash_text(h, v);
  h = hash_text(h, r.seed ? std::to_string(*r.seed) : "-");
  h = hash_text(h, r.samples ? std::to_string(*r.samples) : "-");
  h = hash_text(h, r.redesign);
  h = hash_text(h, r.simulate ? "simulate" : "");
  h = hash_text(h, CODYNA_VERSION);
  char key[17];
  std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(h));
  return std::string("codyna sweep journal 1 ") + key + " " + std::to_string(count) + "\n";
}

// the second line: the request itself, so that sweep-merge needs only the shards
std::string journal_request(const SweepRequest& r) {
  nlohmann::json j = {{"model", r.model}, {"vary", r.vary}, {"redesign", r.redesign}, {"simulate", r.simulate}};
  j["samples"] = r.samples ? nlohmann::json(*r.samples) : nlohmann::json();
  j["seed"] = r.seed ? nlohmann::json(std::to_string(*r.seed)) : nlohmann::json();
  return "request " + j.dump() + "\n";
}

bool is_journal(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string first;
  return !(in && std::getline(in, first) && !first.empty() && first.rfind("codyna sweep journal ", 0) != 0);
}

}  // namespace

std::string study_sweep_journal_path(const std::string& out) { return out + ".partial"; }

// ------------------------------------------------------------------ plan

std::vector<double> SweepPlan::values(long long i) const {
  std::vector<double> out(vary.size());
  if (!random) {
    long long rest = i;
    for (std::size_t k = vary.size(); k-- > 0;) {
      const long long n = static_cast<long long>(vary[k].values.size());
      out[k] = vary[k].values[static_cast<std::size_t>(rest % n)];
      rest /= n;
    }
    return out;
  }
  for (std::size_t k = 0; k < vary.size(); ++k) {
    const SweepVary& v = vary[k];
    if (v.kind == SweepVary::Uniform) {
      out[k] = v.a + (v.b - v.a) * unit_draw(seed, i, k, 0);
    } else {  // Box-Muller on two draws of its own
      const double u1 = unit_draw(seed, i, k, 0), u2 = unit_draw(seed, i, k, 1);
      out[k] = v.a + v.b * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
    }
  }
  return out;
}

SweepPlan study_sweep_plan(const SweepRequest& r, const nlohmann::json& file) {
  const Names opt{r.style};
  SweepPlan plan;
  if (r.vary.empty()) throw std::invalid_argument(opt("vary") + ": give at least one FIELD=SPEC (e.g. /bodies/1/mass=5:15:11)");
  std::vector<std::string> seen;
  for (const std::string& text : r.vary) {
    SweepVary v = parse_vary(text, file, r.model, opt);
    if (std::find(seen.begin(), seen.end(), v.field) != seen.end())
      throw std::invalid_argument(opt("vary") + " " + text + ": " + v.field + " is varied twice");
    seen.push_back(v.field);
    plan.vary.push_back(std::move(v));
  }
  long long grids = 0;
  std::string a_grid, a_random;
  for (const SweepVary& v : plan.vary) {
    if (v.kind == SweepVary::Grid) {
      ++grids;
      if (a_grid.empty()) a_grid = v.field + "=" + v.spec;
    } else if (a_random.empty()) {
      a_random = v.field + "=" + v.spec;
    }
  }
  if (grids > 0 && grids < static_cast<long long>(plan.vary.size()))
    throw std::invalid_argument(opt("vary") + ": a grid (" + a_grid + ") cannot be mixed with a distribution (" + a_random +
                                ") yet: vary grids only (a full grid) or distributions only (joint random samples)");
  plan.random = grids == 0;
  if (plan.random) {
    if (!r.samples) throw std::invalid_argument(opt("samples") + ": a random study (" + a_random + ") needs the number of samples");
    if (!r.seed) throw std::invalid_argument(opt("seed") + ": a random study (" + a_random + ") needs a seed (any whole number), so that it can be repeated");
    if (*r.samples < 1 || *r.samples > kMaxVariants)
      throw std::invalid_argument(opt("samples") + ": expected 1 to " + std::to_string(kMaxVariants));
    plan.count = *r.samples;
    plan.seed = *r.seed;
  } else {
    if (r.samples) throw std::invalid_argument(opt("samples") + ": a grid study's size is its grid's; " + opt("samples") + " is for distributions");
    if (r.seed) throw std::invalid_argument(opt("seed") + ": a grid study draws nothing; " + opt("seed") + " is for distributions");
    plan.count = 1;
    for (const SweepVary& v : plan.vary) {
      plan.count *= static_cast<long long>(v.values.size());
      if (plan.count > kMaxVariants)
        throw std::invalid_argument(opt("vary") + ": the full grid has more than " + std::to_string(kMaxVariants) + " variants");
    }
  }
  return plan;
}

const char* to_string(SweepStatus s) {
  switch (s) {
    case SweepStatus::Ok: return "ok";
    case SweepStatus::ModelError: return "model error";
    case SweepStatus::NotConverged: return "not converged";
    case SweepStatus::Refused: return "refused";
    case SweepStatus::Failed: return "failed";
    case SweepStatus::SizeDiffers: return "sizes differ";
  }
  return "failed";
}

// ------------------------------------------------------------------ the job

namespace {
// `merging`: study_sweep_merge resumes the whole study from the journal it joined, which is not
// news to its caller: no "resuming" note then
SweepJob sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress, bool merging);
}  // namespace

SweepJob study_sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress) {
  return sweep_job(r, tell, progress, false);
}

long long sweep_shard_size(long long n, long long index, long long count) {
  if (count <= 0) return n;
  return index < n ? (n - index + count - 1) / count : 0;
}

namespace {
SweepJob sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress, bool merging) {
  const Names opt{r.style};
  SweepJob job;
  const auto note = [&](const std::string& text) {
    job.notes.push_back(text);
    if (tell) tell({StudyMessage::Note, text});
  };
  if (r.redesign != "" && r.redesign != "lqr")
    throw std::invalid_argument(opt("redesign") + " " + r.redesign + ": expected lqr");
  if (r.threads < 0) throw std::invalid_argument(opt("threads") + ": expected 1 or more (0: every core)");
  const bool shard = r.shard_count > 0;
  const bool memory = shard && r.journal_in_memory;  // an MPI rank's slice: the whole study's outputs checked below
  if (shard) {
    if (r.shard_index < 0 || r.shard_index >= r.shard_count)
      throw std::invalid_argument(opt("shard") + " " + std::to_string(r.shard_index) + "/" + std::to_string(r.shard_count) +
                                  ": expected K/N with 0 <= K < N");
  }
  if (shard && !memory) {
    if (r.out.empty()) throw std::invalid_argument(opt("shard") + ": give " + opt("out") + " (the shard's file)");
    if (!r.csv.empty() || !r.mat.empty())
      throw std::invalid_argument(opt("shard") + ": a shard writes its variants only (" + opt("out") +
                                  "); codyna sweep-merge writes the results, CSV and MAT files");
    if (study_same_file(r.out, r.model))
      throw std::invalid_argument(r.out + ": this is the input file " + r.model + "; choose another name");
    if (!is_journal(r.out))
      throw std::invalid_argument(r.out + ": exists and is not a shard of codyna sweep; codyna never replaces a file it "
                                  "did not write: remove it or choose another name");
  }
  // the outputs, before any work
  if (!r.out.empty() && (!shard || memory)) study_guard_output(r.out, OutputKind::ResultsHdf5, {r.model});
  if (!r.csv.empty()) {
    guard_csv(r.csv, r.model);
    if (!r.out.empty() && (r.csv == r.out || study_same_file(r.csv, r.out)))
      throw std::invalid_argument(opt("csv") + " " + r.csv + ": the same file as " + opt("out"));
  }
  if (!r.mat.empty()) {
    const std::filesystem::path p(r.mat);
    if (p.extension() != ".mat") throw std::invalid_argument(opt("mat") + " " + r.mat + ": expected DIR/NAME.mat");
    if (study_matlab_identifier(p.stem().string()) != p.stem().string())
      throw std::invalid_argument(opt("mat") + " " + r.mat + ": '" + p.stem().string() + "' is not a MATLAB identifier (try " +
                                  study_matlab_identifier(p.stem().string()) + ".mat)");
    if (!p.parent_path().empty()) {
      std::error_code ec;
      std::filesystem::create_directories(p.parent_path(), ec);
      if (ec) throw std::runtime_error(p.parent_path().string() + ": cannot create the folder: " + ec.message());
    }
    study_guard_output(r.mat, OutputKind::PlantMat, {r.model});
    study_guard_output((p.parent_path() / (p.stem().string() + ".m")).string(), OutputKind::PlantScript, {r.model});
  }
  // errors name the file and the field
  const ModelSpec nominal_spec = r.model_text.empty() ? study_read_model(r.model) : study_parse_model_text(r.model_text, r.model);
  for (const std::string& n : nominal_spec.notes) note(n);
  std::string model_bytes = r.model_text;
  if (model_bytes.empty()) {
    std::ifstream in(r.model, std::ios::binary);
    model_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const nlohmann::json file = nlohmann::json::parse(model_bytes);
  job.plan = study_sweep_plan(r, file);
  job.model_file = r.model;
  job.model_name = nominal_spec.name;

  // the nominal model: its linearization and controller must work, or there is no study
  Context c;
  c.request = &r;
  c.plan = &job.plan;
  c.file = &file;
  c.nominal = &nominal_spec;
  for (const SweepVary& v : job.plan.vary) c.pointers.emplace_back(v.field);
  plan_edits(c, job.plan.vary);
  c.linearize.style = r.style;
  c.linearize.model = r.model;
  c.linearize.modes = false;  // a variant records its poles and uncontrollable modes only
  const LinearizeJob nominal = study_linearize_job(c.linearize, nominal_spec);
  const Model& m = nominal.model;
  std::optional<Model> structure;
  if (const std::optional<NumbersChanged> what = numbers_changed(job.plan.vary); what && !c.whole_file) {
    structure = study_linearize_structure(c.linearize, nominal_spec);
    c.structure = &*structure;
    c.changed = *what;
  }
  const StudySpec& s = m.spec.analysis;
  if (s.discrete != 0)
    throw std::invalid_argument(r.model + ": /analysis/discrete: a sweep linearizes in continuous time only (not built yet: "
                                "discrete studies)");
  const LinearSystem& sys = nominal.linearization.lin.system;
  c.nx = sys.nx();
  c.nu = sys.nu();
  c.ny = sys.ny();
  c.state_names = sys.state_names;
  job.state_names = sys.state_names;
  job.input_names = sys.input_names;
  job.output_names = sys.output_names;
  job.operating_point = nominal.linearization.op.kind;
  job.method = nominal.method;
  job.nominal_open_poles = poles_of(sys.A);
  const bool model_controller = s.controller == "model" && m.spec.controller.type != ControllerType::None;
  const bool is_lqr = s.controller == "lqr" || (model_controller && m.spec.controller.type == ControllerType::Lqr);
  if (model_controller && m.spec.controller.operating_point != s.operating_point)
    throw std::invalid_argument(r.model + ": the model file's controller is designed at its " +
                                m.spec.controller.operating_point + " point, the study linearizes at " + s.operating_point +
                                ": a sweep closes the loop where it linearizes (set /analysis/operating_point to \"" +
                                m.spec.controller.operating_point + "\")");
  if (!r.redesign.empty() && !is_lqr)
    throw std::invalid_argument(opt("redesign") + " lqr: the study's controller is not an LQR (the model file's "
                                "controller of type lqr, or \"controller\": \"lqr\" in its analysis section)");
  if (s.controller != "none" && (model_controller || s.controller != "model")) {
    const StudySimulation setup = study_simulation(m);
    const Eigen::MatrixXd* g = setup.controller ? setup.controller->gain() : nullptr;
    if (g && g->rows() == c.nu && g->cols() == c.nx) {
      c.closed_loop = true;
      c.K = *g;
      c.redesign = r.redesign == "lqr";
      job.closed_loop = true;
      job.K = *g;
      job.redesigned = c.redesign;
      job.controller = setup.controller_source + (c.redesign ? ", designed again for every variant"
                                                             : ", K designed on the nominal model and fixed");
      job.nominal_closed_poles = poles_of(sys.A - sys.B * c.K);
    } else if (setup.controller) {
      note("the study's controller (" + setup.controller_source + ") is not a state feedback: open-loop figures only");
    }
  }
  if (!job.closed_loop && job.controller.empty()) job.controller = "none (open loop)";
  if (r.simulate) {
    c.simulate = true;
    job.simulated = true;
    // K fixed: the file's own LQR (or the study's) would be designed again on each variant; the
    // nominal K is handed to the run as the model file's state feedback instead
    if (c.closed_loop && !c.redesign && (is_lqr || (model_controller && m.spec.controller.type == ControllerType::StateFeedback))) {
      c.replace_controller = true;
      c.controller_point = model_controller ? m.spec.controller.operating_point : s.operating_point;
    }
  }

  // the variants
  const long long n = job.plan.count;
  job.variants.resize(static_cast<std::size_t>(n));
  unsigned threads = r.threads > 0 ? static_cast<unsigned>(r.threads) : std::max(1u, std::thread::hardware_concurrency());
  if (s.controller == "file" && threads > 1) {
    // the controller file is read again with every variant's model (matio, HDF5 for v7.3: not thread-safe)
    note("the study's controller is a file: variants run on one thread");
    threads = 1;
  }
  threads = static_cast<unsigned>(std::min<long long>(threads, n));
  // the journal: the variants an interrupted run of this very study finished
  std::vector<char> have(static_cast<std::size_t>(n), 0);
  std::ofstream journal;
  job.shard_index = shard ? r.shard_index : 0;
  job.shard_count = shard ? r.shard_count : 0;
  const std::string journal_path =
      memory ? r.journal_file : r.out.empty() ? std::string() : shard ? r.out : study_sweep_journal_path(r.out);
  if (memory) job.journal = journal_head(r, model_bytes, n) + journal_request(r);
  if (!journal_path.empty()) {
    const std::string head = journal_head(r, model_bytes, n), request_line = journal_request(r);
    std::error_code ec;
    if (r.resume && std::filesystem::exists(journal_path, ec)) {
      std::ifstream in(journal_path, std::ios::binary);
      std::string line;
      if (!std::getline(in, line) || line + "\n" != head)
        throw std::invalid_argument(journal_path + ": the journal of another study (other model file contents or options) "
                                    "is in the way: remove it to start afresh");
      std::string kept = head + request_line;
      while (std::getline(in, line)) {
        if (in.eof()) break;  // a last line without its newline was cut by the interruption
        if (line.rfind("request ", 0) == 0) continue;
        try {
          const nlohmann::json j = nlohmann::json::parse(line);
          const long long i = j.at("i").get<long long>();
          if (i < 0 || i >= n || have[static_cast<std::size_t>(i)] || !job.in_shard(i)) continue;
          SweepVariant v = journal_variant(j);
          if (v.values != job.plan.values(i)) continue;
          job.variants[static_cast<std::size_t>(i)] = std::move(v);
          have[static_cast<std::size_t>(i)] = 1;
          ++job.resumed;
          kept += line + "\n";
          if (memory) job.journal += line + "\n";
        } catch (const std::exception&) {
          // a damaged line: that variant runs again
        }
      }
      in.close();
      write_file_atomically(journal_path, kept);  // without the damaged lines, then appended to
      if (job.resumed > 0 && !shard && !merging)
        note("resuming: " + std::to_string(job.resumed) + " of " + std::to_string(n) + " variants were done (" +
             journal_path + ")");
      if (job.resumed > 0 && shard) {
        const long long slice = sweep_shard_size(n, r.shard_index, r.shard_count);
        note("resuming: " + std::to_string(job.resumed) + " of the " + std::to_string(slice) + " variants of slice " +
             std::to_string(r.shard_index) + "/" + std::to_string(r.shard_count) + " were done (" + journal_path + ")");
      }
    } else {
      if (!is_journal(journal_path))
        throw std::invalid_argument(journal_path + ": exists and is not the journal of a codyna sweep; codyna never "
                                    "replaces a file it did not write: remove it or choose another --out");
      write_file_atomically(journal_path, head + request_line);
    }
    journal.open(journal_path, std::ios::binary | std::ios::app);
    if (!journal) throw std::runtime_error(journal_path + ": cannot append to the journal");
  }
  std::atomic<long long> next{0}, done{job.resumed};
  std::mutex report;
  std::exception_ptr fatal;
  const auto worker = [&] {
    for (;;) {
      if (progress.cancel && progress.cancel->load()) return;
      const long long i = next.fetch_add(1);
      if (i >= n) return;
      if (have[static_cast<std::size_t>(i)] || !job.in_shard(i)) continue;
      SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      try {
        run_variant(c, i, v);
      } catch (...) {  // not a failure of the variant (out of memory): the study stops
        const std::lock_guard<std::mutex> lock(report);
        if (!fatal) fatal = std::current_exception();
        next.store(n);
        return;
      }
      const std::string line = journal.is_open() || memory ? journal_line(i, v) : std::string();
      const long long d = done.fetch_add(1) + 1;
      const std::lock_guard<std::mutex> lock(report);
      if (journal.is_open()) journal << line << std::flush;
      if (memory) job.journal += line;
      if (progress.done) progress.done(d, n);
    }
  };
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  if (fatal) std::rethrow_exception(fatal);
  const long long expected = sweep_shard_size(n, r.shard_index, r.shard_count);
  if (done.load() < expected) throw StudyCancelled("the sweep was cancelled after " + std::to_string(done.load()) + " of " +
                                            std::to_string(expected) + " variants");

  // the summary: the worst case is the completed variant with the largest max real part (first on ties)
  double worst = -std::numeric_limits<double>::infinity();
  for (long long i = 0; i < n; ++i) {
    if (!job.in_shard(i)) continue;
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    if (v.status != SweepStatus::Ok) {
      ++job.failed;
      continue;
    }
    if (v.stable) ++job.stable;
    if (v.sim_status == 0) ++job.sim_completed;
    if (v.peak_input.size() > 0 &&
        (job.largest_input < 0 ||
         v.peak_input.maxCoeff() > job.variants[static_cast<std::size_t>(job.largest_input)].peak_input.maxCoeff()))
      job.largest_input = i;
    const double x = job.closed_loop ? v.closed_max_real : v.open_max_real;
    if (job.worst < 0 || x > worst) {
      worst = x;
      job.worst = i;
    }
  }

  if (memory) return job;  // the journal in job.journal is the slice's result
  if (shard) {  // the shard's journal is its result
    journal.close();
    if (!journal) throw std::runtime_error(r.out + ": cannot finish the shard's file");
    // written again in the variants' order (it was appended to as they finished): the same bytes
    // whatever the threads and the order they finished in
    std::string text = journal_head(r, model_bytes, n) + journal_request(r);
    for (long long i = 0; i < n; ++i)
      if (job.in_shard(i)) text += journal_line(i, job.variants[static_cast<std::size_t>(i)]);
    write_file_atomically(r.out, text);
    job.written.push_back(r.out);
    return job;
  }
  if (!r.out.empty()) {
    study_write_sweep_hdf5(job, r.out);
    job.written.push_back(r.out);
  }
  if (!r.csv.empty()) {
    study_write_sweep_csv(job, r.csv);
    job.written.push_back(r.csv);
  }
  if (!r.mat.empty()) {
    study_write_sweep_mat(job, r.mat);
    job.written.push_back(r.mat);
    const std::filesystem::path p(r.mat);
    job.written.push_back((p.parent_path() / (p.stem().string() + ".m")).string());
  }
  if (journal.is_open()) {
    journal.close();
    std::error_code ec;
    std::filesystem::remove(journal_path, ec);
  }
  return job;
}
}  // namespace

SweepJob study_sweep_merge(const std::vector<std::string>& shards, const SweepRequest& outputs, const StudyMessages& tell) {
  if (shards.empty()) throw std::invalid_argument("sweep-merge: give the shards' files");
  std::vector<std::string> texts;
  for (const std::string& path : shards) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::invalid_argument(path + ": cannot read this shard");
    texts.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return study_sweep_merge_journals(texts, shards, outputs, tell);
}

SweepJob study_sweep_merge_journals(const std::vector<std::string>& journals, const std::vector<std::string>& names,
                                    const SweepRequest& outputs, const StudyMessages& tell) {
  if (journals.empty() || journals.size() != names.size()) throw std::invalid_argument("sweep-merge: give the shards' files");
  if (outputs.out.empty()) throw std::invalid_argument(option_name(outputs.style, "out") + ": the merged results (HDF5)");
  std::string head, request;
  std::map<long long, std::string> lines;
  for (std::size_t s = 0; s < journals.size(); ++s) {
    const std::string& path = names[s];
    std::istringstream in(journals[s]);
    std::string h, q, line;
    if (!std::getline(in, h) || h.rfind("codyna sweep journal ", 0) != 0 || !std::getline(in, q) || q.rfind("request ", 0) != 0)
      throw std::invalid_argument(path + ": not a shard written by codyna sweep --shard");
    if (head.empty()) {
      head = h;
      request = q;
    } else if (h != head) {
      throw std::invalid_argument(path + ": a shard of another study than " + names.front() +
                                  " (other model file contents or options)");
    }
    while (std::getline(in, line)) {
      if (in.eof()) break;
      try {
        lines.emplace(nlohmann::json::parse(line).at("i").get<long long>(), line);
      } catch (const std::exception&) {
      }
    }
  }
  const long long n = std::stoll(head.substr(head.rfind(' ') + 1));
  if (static_cast<long long>(lines.size()) != n) {
    std::string missing;
    long long count = 0;
    for (long long i = 0; i < n; ++i)
      if (!lines.count(i) && count++ < 8) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
    throw std::invalid_argument("sweep-merge: variants " + missing + (count > 8 ? ", ..." : "") + " (" + std::to_string(count) +
                                " of " + std::to_string(n) + ") are in none of the shards given: run (or resume) their shards first");
  }
  const nlohmann::json q = nlohmann::json::parse(request.substr(8));
  SweepRequest r = outputs;
  r.model = q.at("model").get<std::string>();
  r.vary = q.at("vary").get<std::vector<std::string>>();
  r.redesign = q.at("redesign").get<std::string>();
  r.simulate = q.at("simulate").get<bool>();
  r.samples.reset();
  r.seed.reset();
  if (!q.at("samples").is_null()) r.samples = q.at("samples").get<long long>();
  if (!q.at("seed").is_null()) r.seed = std::stoull(q.at("seed").get<std::string>());
  r.resume = true;
  r.shard_index = 0;
  r.shard_count = 0;
  // the joined journal: the whole study resumes from it with nothing left to run
  const std::string journal_path = study_sweep_journal_path(r.out);
  study_guard_output(r.out, OutputKind::ResultsHdf5, {r.model});
  if (!is_journal(journal_path))
    throw std::invalid_argument(journal_path + ": exists and is not the journal of a codyna sweep: remove it");
  std::string text = head + "\n" + request + "\n";
  for (const auto& [i, line] : lines) text += line + "\n";
  write_file_atomically(journal_path, text);
  try {
    SweepJob job = sweep_job(r, tell, {}, true);
    if (job.resumed != n) throw std::runtime_error("sweep-merge: " + std::to_string(n - job.resumed) + " variants were run again");
    return job;
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(journal_path, ec);
    throw;
  }
}

// ------------------------------------------------------------------ HDF5

namespace {

using FileError = Hdf5Error;
using Handle = Hdf5Handle;
void check(herr_t rc, const std::string& what) { hdf5_check(rc, what); }

// no modification times in the object headers: the same study gives the same bytes
Handle untimed(hid_t cls, const std::string& what) {
  Handle p(H5Pcreate(cls), H5Pclose, what);
  check(H5Pset_obj_track_times(p, 0), what);
  return p;
}

void create_group(hid_t file, const std::string& name) {
  const std::string what = "cannot create group " + name;
  const Handle gcpl = untimed(H5P_GROUP_CREATE, what);
  Handle g(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose, what);
}

void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type, const std::vector<hsize_t>& dims,
                   const void* data) {
  const std::string what = "cannot write " + name;
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
  const Handle dcpl = untimed(H5P_DATASET_CREATE, what);
  Handle d(H5Dcreate2(file, name.c_str(), file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  std::size_t count = 1;
  for (hsize_t x : dims) count *= static_cast<std::size_t>(x);
  if (count > 0) check(H5Dwrite(d, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), what);
}

void write_doubles(hid_t file, const std::string& name, const std::vector<hsize_t>& dims, const std::vector<double>& v) {
  write_dataset(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, v.data());
}

void write_ints(hid_t file, const std::string& name, const std::vector<int>& v) {
  write_dataset(file, name, H5T_STD_I32LE, H5T_NATIVE_INT, {v.size()}, v.data());
}

void write_strings(hid_t file, const std::string& name, const std::vector<std::string>& list) {
  std::size_t width = 1;
  for (const std::string& s : list) width = std::max(width, s.size());
  std::vector<char> packed(list.size() * width, '\0');
  for (std::size_t i = 0; i < list.size(); ++i) std::memcpy(packed.data() + i * width, list[i].data(), list[i].size());
  const std::string what = "cannot write " + name;
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(type, width), what);
  check(H5Tset_strpad(type, H5T_STR_NULLPAD), what);
  write_dataset(file, name, type, type, {list.size()}, packed.data());
}

void write_attribute(hid_t file, const char* object, const char* name, hid_t ftype, hid_t mtype, const void* value) {
  const std::string what = std::string("cannot write attribute ") + name + " of " + object;
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle a(H5Acreate_by_name(file, object, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(a, mtype, value), what);
}
void write_attribute(hid_t file, const char* object, const char* name, const std::string& value) {
  const std::string what = std::string("cannot write attribute ") + name;
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(type, H5T_VARIABLE), what);
  check(H5Tset_cset(type, H5T_CSET_UTF8), what);
  const char* text = value.c_str();
  write_attribute(file, object, name, type, type, &text);
}
void write_attribute(hid_t file, const char* object, const char* name, long long value) {
  write_attribute(file, object, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &value);
}
void write_attribute_u64(hid_t file, const char* object, const char* name, std::uint64_t value) {
  write_attribute(file, object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

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
  write_doubles(file, group + "/poles_real", {vs.size(), static_cast<hsize_t>(n)}, re);
  write_doubles(file, group + "/poles_imag", {vs.size(), static_cast<hsize_t>(n)}, im);
  write_doubles(file, group + "/max_real", {vs.size()}, mr);
}

void write_contents(hid_t file, const SweepJob& job) {
  const auto& vs = job.variants;
  const std::size_t n = vs.size(), nv = job.plan.vary.size();
  const Eigen::Index nx = static_cast<Eigen::Index>(job.state_names.size()), nu = static_cast<Eigen::Index>(job.input_names.size()),
                     ny = static_cast<Eigen::Index>(job.output_names.size());
  write_attribute(file, "/", "format", std::string("codyna sweep"));
  write_attribute(file, "/", "format_version", static_cast<long long>(kFormatVersion));
  write_attribute(file, "/", "model_file", job.model_file);
  write_attribute(file, "/", "model_name", job.model_name);
  write_attribute(file, "/", "codyna_version", std::string(CODYNA_VERSION));
  write_attribute(file, "/", "design", std::string(job.plan.random ? "random" : "grid"));
  write_attribute(file, "/", "variants", static_cast<long long>(n));
  if (job.plan.random) write_attribute_u64(file, "/", "seed", job.plan.seed);
  write_attribute(file, "/", "operating_point", job.operating_point);
  write_attribute(file, "/", "method", job.method);
  write_attribute(file, "/", "controller", job.controller);
  write_attribute(file, "/", "gain", std::string(!job.closed_loop ? "none" : job.redesigned ? "redesigned" : "fixed"));

  create_group(file, "/parameters");
  std::vector<std::string> fields, specs;
  std::vector<double> nominal, values(n * nv, kNaN);
  for (const SweepVary& v : job.plan.vary) {
    fields.push_back(v.field);
    specs.push_back(v.spec);
    nominal.push_back(v.nominal);
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < nv && k < vs[i].values.size(); ++k) values[i * nv + k] = vs[i].values[k];
  write_doubles(file, "/parameters/values", {n, nv}, values);
  write_strings(file, "/parameters/fields", fields);
  write_strings(file, "/parameters/specs", specs);
  write_doubles(file, "/parameters/nominal", {nv}, nominal);

  create_group(file, "/status");
  std::vector<int> codes;
  std::vector<std::string> reasons;
  for (const SweepVariant& v : vs) {
    codes.push_back(static_cast<int>(v.status));
    reasons.push_back(v.reason);
  }
  write_ints(file, "/status/code", codes);
  write_strings(file, "/status/reason", reasons);
  write_attribute(file, "/status", "codes",
                  std::string("0 ok, 1 model error, 2 not converged, 3 refused, 4 failed, 5 sizes differ"));

  create_group(file, "/names");
  write_strings(file, "/names/states", job.state_names);
  write_strings(file, "/names/inputs", job.input_names);
  write_strings(file, "/names/outputs", job.output_names);

  create_group(file, "/linear");
  write_doubles(file, "/linear/A", {n, static_cast<hsize_t>(nx), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::A, nx, nx));
  write_doubles(file, "/linear/B", {n, static_cast<hsize_t>(nx), static_cast<hsize_t>(nu)}, stack(vs, &SweepVariant::B, nx, nu));
  write_doubles(file, "/linear/C", {n, static_cast<hsize_t>(ny), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::C, ny, nx));
  write_doubles(file, "/linear/D", {n, static_cast<hsize_t>(ny), static_cast<hsize_t>(nu)}, stack(vs, &SweepVariant::D, ny, nu));

  create_group(file, "/open_loop");
  write_poles(file, "/open_loop", vs, &SweepVariant::open_poles, &SweepVariant::open_max_real, nx);
  std::vector<int> unc, stable;
  for (const SweepVariant& v : vs) {
    unc.push_back(v.status == SweepStatus::Ok ? v.uncontrollable : -1);
    stable.push_back(v.stable ? 1 : 0);
  }
  write_ints(file, "/open_loop/uncontrollable", unc);
  if (job.simulated) {
    create_group(file, "/simulation");
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
    write_ints(file, "/simulation/status", st);
    write_strings(file, "/simulation/reason", why);
    write_doubles(file, "/simulation/t_reached", {n}, reached);
    write_doubles(file, "/simulation/peak_input", {n, static_cast<hsize_t>(nu)}, rows(vs, &SweepVariant::peak_input, nu));
    write_doubles(file, "/simulation/final_error", {n}, err);
    write_doubles(file, "/simulation/overshoot", {n, static_cast<hsize_t>(ny)}, rows(vs, &SweepVariant::overshoot, ny));
    write_doubles(file, "/simulation/settling_time", {n, static_cast<hsize_t>(ny)}, rows(vs, &SweepVariant::settling_time, ny));
    write_doubles(file, "/simulation/saturation_time", {n, static_cast<hsize_t>(nu)},
                  rows(vs, &SweepVariant::saturation_time, nu));
    write_attribute(file, "/simulation", "status_codes",
                    std::string("-1 not run (the variant failed), 0 reached t_end, 1 the run failed, 2 it could not be set up"));
  }
  if (!job.closed_loop) {
    write_ints(file, "/open_loop/stable", stable);
    return;
  }
  create_group(file, "/closed_loop");
  if (job.redesigned) {
    write_doubles(file, "/closed_loop/K", {n, static_cast<hsize_t>(nu), static_cast<hsize_t>(nx)}, stack(vs, &SweepVariant::K, nu, nx));
  } else {
    std::vector<double> k(static_cast<std::size_t>(nu * nx));
    for (Eigen::Index a = 0; a < nu; ++a)
      for (Eigen::Index b = 0; b < nx; ++b) k[static_cast<std::size_t>(a * nx + b)] = job.K(a, b);
    write_doubles(file, "/closed_loop/K", {static_cast<hsize_t>(nu), static_cast<hsize_t>(nx)}, k);
  }
  write_poles(file, "/closed_loop", vs, &SweepVariant::closed_poles, &SweepVariant::closed_max_real, nx);
  write_ints(file, "/closed_loop/stable", stable);
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

void study_write_sweep_hdf5(const SweepJob& job, const std::string& path) {
  study_guard_output(path, OutputKind::ResultsHdf5, {job.model_file});
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

void study_write_sweep_csv(const SweepJob& job, const std::string& path) {
  guard_csv(path, job.model_file);
  std::string text = kCsvHeadStart;
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
  std::u16string u;
  for (unsigned char ch : s) u.push_back(static_cast<char16_t>(ch < 128 ? ch : '?'));
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

void study_write_sweep_mat(const SweepJob& job, const std::string& mat_path) {
  const std::filesystem::path p(mat_path);
  const std::string name = p.stem().string();
  if (p.extension() != ".mat") throw std::invalid_argument(mat_path + ": expected DIR/NAME.mat");
  if (study_matlab_identifier(name) != name)
    throw std::invalid_argument(mat_path + ": '" + name + "' is not a MATLAB identifier (try " + study_matlab_identifier(name) + ".mat)");
  const std::string m_path = (p.parent_path() / (name + ".m")).string();
  study_guard_output(mat_path, OutputKind::PlantMat, {job.model_file});
  study_guard_output(m_path, OutputKind::PlantScript, {job.model_file});
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

std::string study_sweep_summary(const SweepJob& job) {
  std::ostringstream os;
  const long long n = static_cast<long long>(job.variants.size());
  const std::size_t fields = job.plan.vary.size();
  if (job.shard_count > 0) {
    const long long mine = sweep_shard_size(n, job.shard_index, job.shard_count);
    os << "shard            " << job.shard_index << "/" << job.shard_count << ": " << mine << " of the " << n
       << " variants (i % " << job.shard_count << " = " << job.shard_index << "), " << job.failed
       << " failed; codyna sweep-merge joins the shards\n";
    return os.str();
  }
  os << "sweep            " << job.model_name << ": " << n << " variants, "
     << (job.plan.random ? "joint random samples (seed " + std::to_string(job.plan.seed) + ")" : std::string("a full grid"))
     << " of " << fields << (fields == 1 ? " field" : " fields") << "\n";
  for (const SweepVary& v : job.plan.vary) os << "  " << v.field << " = " << v.spec << " (nominal " << fmt(v.nominal) << ")\n";
  os << "operating point  " << job.operating_point << ", " << job.method << " Jacobians\n";
  os << "closed loop      " << job.controller << "\n";
  if (job.closed_loop) {
    os << "nominal          max Re(closed-loop pole) = " << fmt(max_real(job.nominal_closed_poles)) << "\n";
  }
  os << "completed        " << (n - job.failed) << " of " << n << " (" << job.failed << " failed)\n";
  const long long completed = n - job.failed;
  os << "stable           " << job.stable << " of " << completed << " completed";
  if (completed > 0) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f", 100.0 * static_cast<double>(job.stable) / static_cast<double>(completed));
    os << " (" << pct << " %)";
  }
  os << (job.closed_loop ? ", closed loop" : ", open loop") << "\n";
  if (job.worst >= 0) {
    const SweepVariant& w = job.variants[static_cast<std::size_t>(job.worst)];
    os << "worst case       variant " << job.worst << ":";
    for (std::size_t k = 0; k < fields; ++k) os << (k ? "," : "") << " " << job.plan.vary[k].field << " = " << fmt(w.values[k]);
    os << ", max Re(" << (job.closed_loop ? "closed" : "open") << "-loop pole) = "
       << fmt(job.closed_loop ? w.closed_max_real : w.open_max_real) << "\n";
  }
  if (job.simulated) {
    os << "simulated        " << job.sim_completed << " of " << completed << " completed variants reached t_end\n";
    if (job.largest_input >= 0) {
      const SweepVariant& w = job.variants[static_cast<std::size_t>(job.largest_input)];
      os << "largest input    variant " << job.largest_input << ": peak |u| = " << fmt(w.peak_input.maxCoeff())
         << ", final error " << fmt(w.final_error) << "\n";
    }
    long long far = -1;
    for (long long i = 0; i < n; ++i) {
      const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      if ((v.sim_status == 0 || v.sim_status == 1) &&
          (far < 0 || v.final_error > job.variants[static_cast<std::size_t>(far)].final_error))
        far = i;
    }
    if (far >= 0)
      os << "largest error    variant " << far << ": final error " << fmt(job.variants[static_cast<std::size_t>(far)].final_error)
         << " (the largest |y - y0| over Plant/Out at t_end)\n";
    // the largest of a figure over the variants' entries, and whose it is
    const auto largest = [&](Eigen::VectorXd SweepVariant::*field, const std::vector<std::string>& names, const char* label,
                             const char* unit) {
      long long at = -1;
      Eigen::Index which = 0;
      double best = 0;
      for (long long i = 0; i < n; ++i) {
        const Eigen::VectorXd& x = job.variants[static_cast<std::size_t>(i)].*field;
        for (Eigen::Index k = 0; k < x.size() && k < static_cast<Eigen::Index>(names.size()); ++k)
          if (std::isfinite(x[k]) && (at < 0 || x[k] > best)) {
            at = i;
            which = k;
            best = x[k];
          }
      }
      if (at >= 0)
        os << label << fmt(best) << unit << " (" << names[static_cast<std::size_t>(which)] << "), variant " << at << "\n";
    };
    largest(&SweepVariant::overshoot, job.output_names, "overshoot        largest ", " %");
    largest(&SweepVariant::settling_time, job.output_names, "settling time    longest ", " s (2 % band)");
    largest(&SweepVariant::saturation_time, job.input_names, "at a limit       longest ", " s");
    long long unsettled = 0;
    for (const SweepVariant& v : job.variants)
      if (v.sim_status == 0 && v.settling_time.size() && !v.settling_time.allFinite()) ++unsettled;
    if (unsettled) os << "not settled      " << unsettled << " runs end outside the 2 % band of an output\n";
    long long shown = 0;
    for (long long i = 0; i < n && shown < 5; ++i) {
      const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      if (v.sim_status <= 0) continue;
      os << (shown++ ? "                 " : "run failed       ") << "variant " << i << ": " << v.sim_reason << "\n";
    }
  }
  long long listed = 0;
  for (long long i = 0; i < n; ++i) {
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    if (v.status == SweepStatus::Ok) continue;
    if (listed++ == 10) {
      os << "                 ... and " << (job.failed - 10) << " more (the file's /status/reason)\n";
      break;
    }
    os << (listed == 1 ? "failed           " : "                 ") << "variant " << i << " (" << to_string(v.status)
       << "): " << v.reason << "\n";
  }
  return os.str();
}

}  // namespace codyna
