#include "study/workflow.hpp"

#include "analysis/stability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "analysis/discretize.hpp"
#include "analysis/plant_function.hpp"
#include "control/controllability.hpp"
#include "control/lqr.hpp"
#include "control/lqr_controllable.hpp"
#include "dynamics/assembly.hpp"
#include "dynamics/joint.hpp"
#include "io/controller_file.hpp"
#include "io/curves_file.hpp"
#include "io/output_guard.hpp"
#include "io/signal_file.hpp"
#include "dynamics/prepare.hpp"
#include "model/compile.hpp"
#include "model/errors.hpp"
#include "simulation/model_controller.hpp"

namespace codyna {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  return all;
}

MatVariables read_mat_file_or_invalid(const std::string& path) {
  try {
    return read_mat_file(path);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
}

std::string listed(const std::vector<std::string>& names) {
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  return all.empty() ? "none" : all;
}

[[noreturn]] void workflow_fail(const Model& m, const std::string& field, const std::string& what) {
  throw ModelError(m.source_file, "/analysis/" + field, what);
}

// a steady-state search that did not converge: a failure of the work (exit code 2), not bad input
[[noreturn]] void not_converged(const Model& m, const std::string& what) {
  throw ConvergenceError((m.source_file.empty() ? std::string() : m.source_file + ": ") + "/analysis/operating_point: " + what);
}

JacobianMethod method_of_model(const Model& m) {
  const std::string& s = m.spec.analysis.method;
  if (s == "exact") return JacobianMethod::Exact;
  if (s == "fd-forward") return JacobianMethod::ForwardDifference;
  if (s == "fd-central") return JacobianMethod::CentralDifference;
  workflow_fail(m, "method", "unknown method \"" + s + "\" (expected one of: " + listed(study_methods()) + ")");
}

SimulationOptions solver_options(const Model& m) {
  SimulationOptions o;
  const SolverSpec& sp = m.spec.solver;
  o.integrator.method = sp.integrator;
  o.integrator.rtol = sp.rtol;
  o.integrator.atol = sp.atol;
  o.integrator.max_step = sp.max_step;
  o.t_end = sp.t_end;
  o.output_step = sp.output_step;
  return o;
}

Eigen::MatrixXd diagonal(const Model& m, const std::vector<double>& w, int n, const char* field) {
  if (w.empty()) return Eigen::MatrixXd::Identity(n, n);
  if (static_cast<int>(w.size()) != n)
    workflow_fail(m, field, "expected " + std::to_string(n) + " weights (one per " + (n && field[0] == 'q' ? "state" : "input") +
                       "), got " + std::to_string(w.size()));
  // Q = diag(q) >= 0 and R = diag(r) > 0: what an LQR design needs, said of the weight given
  const bool r = field[0] == 'r';
  for (std::size_t k = 0; k < w.size(); ++k)
    if (!std::isfinite(w[k]) || (r ? !(w[k] > 0) : !(w[k] >= 0))) {
      std::ostringstream os;
      os << "weight " << k + 1 << " is " << w[k] << ": expected " << (r ? "a number > 0 (R must be positive definite)"
                                                                        : "a number >= 0 (Q must be positive semidefinite)");
      workflow_fail(m, field, os.str());
    }
  return Eigen::Map<const Eigen::VectorXd>(w.data(), n).asDiagonal();
}

// The study choices that define a plant, as the JSON text exported with it (codyna_study).
std::string plant_study_json(const StudySpec& s, const std::string& operating_point) {
  nlohmann::ordered_json j;
  j["operating_point"] = operating_point;
  nlohmann::ordered_json set = nlohmann::ordered_json::object();
  for (const auto& [name, value] : s.set) set[name] = value;
  j["set"] = set;
  j["independent"] = s.independent;
  j["disabled_effects"] = s.disabled_effects;
  // the steady-state search's knowns and unknowns (left out when unused, as older exports have them)
  if (!s.trim_free.empty()) j["trim_free"] = s.trim_free;
  if (!s.free_inputs.empty()) j["free_inputs"] = s.free_inputs;
  if (!s.output_targets.empty()) {
    nlohmann::ordered_json t = nlohmann::ordered_json::object();
    for (const auto& [name, value] : s.output_targets) t[name] = value;
    j["output_targets"] = t;
  }
  return j.dump();
}

// The modes the inputs cannot move; an eigenvalue within round-off of 0 is reported as 0 (a
// double pole at 0, the free yaw of a spherical pendulum, comes out of the eigen decomposition
// split by about sqrt(eps ||A||))
std::vector<HiddenMode> uncontrollable(const LinearSystem& sys) {
  std::vector<HiddenMode> modes = uncontrollable_modes(sys.A, sys.B, sys.state_names);
  const double tiny = 1.5e-8 * std::max(1.0, sys.A.norm());
  for (HiddenMode& h : modes)
    if (std::abs(h.eigenvalue) < tiny) h.eigenvalue = 0.0;
  return modes;
}

// An LQR needs every mode that does not decay by itself to be movable by the inputs; say which are not.
void require_stabilizable(const Model& m, const LinearSystem& sys) {
  std::vector<HiddenMode> bad;
  const double tol = stability_tolerance(sys.A);
  for (const HiddenMode& h : uncontrollable(sys))
    if (classify_pole(h.eigenvalue, sys.Ts > 0, tol) != Stability::Stable) bad.push_back(h);
  if (bad.empty()) return;
  throw std::invalid_argument((m.source_file.empty() ? std::string() : m.source_file + ": ") +
                              "lqr: the plant is not stabilizable: the Plant/In inputs cannot move " + describe(bad) +
                              " (add an input that acts on them, or hold them with a joint spring or damper; or design "
                              "on the controllable part only: \"lqr_controllable_part\": true in the analysis section, "
                              "codyna simulate --lqr-controllable-part)");
}

// A signal as the run uses it: a "file" signal read into its points (a table); a file that
// cannot be used is a ModelError at the signal's field, with the file's own message
SignalSpec resolved(const Model& m, const SignalSpec& s, const std::string& field) {
  if (s.type != "file") return s;
  SignalSpec r = s;
  try {
    r.points = read_signal_file(study_path(m, s.file));
  } catch (const std::invalid_argument& e) {
    workflow_fail(m, field + "/file", e.what());
  }
  return r;
}

// A signal's rate and acceleration (right-continuous: a ramp's rate is its slope from `time` on),
// and the times where its rate jumps: what a motion input driven by it needs
double signal_rate(const SignalSpec& s, double t) {
  if (s.type == "table" || s.type == "file") {
    const auto& p = s.points;
    for (std::size_t k = 1; k < p.size(); ++k)
      if (t >= p[k - 1].first && t < p[k].first) return (p[k].second - p[k - 1].second) / (p[k].first - p[k - 1].first);
    return 0.0;
  }
  if (t < s.time) return 0.0;
  const double w = 2 * std::numbers::pi * s.frequency;
  if (s.type == "ramp") return s.slope;
  if (s.type == "sine") return s.amplitude * w * std::cos(w * (t - s.time) + s.phase);
  return 0.0;
}
double signal_acceleration(const SignalSpec& s, double t) {
  if (s.type != "sine" || t < s.time) return 0.0;
  const double w = 2 * std::numbers::pi * s.frequency;
  return -s.amplitude * w * w * std::sin(w * (t - s.time) + s.phase);
}
std::vector<double> signal_rate_jumps(const SignalSpec& s) {
  if (s.type == "table" || s.type == "file") {
    std::vector<double> t;
    for (const auto& p : s.points) t.push_back(p.first);
    return t;
  }
  if (s.type == "ramp" || s.type == "sine") return {s.time};
  return {};
}

// d(t) on actuators that are not Plant/In: in the nonlinear run, and through their own B and D
// columns (the plant linearized with them as extra inputs) in the linear comparison
void attach_disturbances(const Model& m, StudySimulation& out) {
  const StudySpec& s = m.spec.analysis;
  if (s.disturbances.empty()) return;
  std::vector<std::pair<int, SignalSpec>> signals;
  std::vector<int> actuators;
  std::vector<std::string> names;
  for (const auto& a : m.actuators) names.push_back(a.name);
  for (std::size_t k = 0; k < s.disturbances.size(); ++k) {
    const DisturbanceSpec& d = s.disturbances[k];
    const std::string field = "disturbances/" + std::to_string(k);
    const auto it = std::find(names.begin(), names.end(), d.actuator);
    if (it == names.end())
      workflow_fail(m, field + "/actuator", "no actuator named \"" + d.actuator + "\" (actuators: " + listed(names) + ")");
    const int i = static_cast<int>(it - names.begin());
    if (std::find(m.plant_inputs.begin(), m.plant_inputs.end(), i) != m.plant_inputs.end())
      workflow_fail(m, field + "/actuator", "\"" + d.actuator + "\" is a Plant/In input, driven by the controller; a disturbance " +
                                       "goes on an actuator that is not (add one, e.g. a body_force on the same body)");
    if (std::find(actuators.begin(), actuators.end(), i) != actuators.end())
      workflow_fail(m, field + "/actuator", "a second disturbance on \"" + d.actuator + "\"");
    actuators.push_back(i);
    signals.emplace_back(i, resolved(m, d, field));
    if (m.actuators[static_cast<std::size_t>(i)].type == ActuatorType::Motion) {
      // a motion input moves its coordinate: no jump in position (an infinite rate)
      const SignalSpec& sig = signals.back().second;
      if (sig.type == "step")
        workflow_fail(m, field + "/type", "a step on the motion input \"" + d.actuator + "\" would move its coordinate at once; " +
                                     "use a ramp or a table");
      if (sig.type == "sine" && std::abs(sig.amplitude * std::sin(sig.phase)) > 1e-12)
        workflow_fail(m, field + "/phase", "a sine on the motion input \"" + d.actuator + "\" must start at 0 (phase 0 or pi), " +
                                      "or its coordinate would jump");
    }
  }
  const int nu = m.nu();
  out.options.disturbance = [nu, signals](double t) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(nu);
    for (const auto& [i, sig] : signals) d[i] += signal_value(sig, t, 0.0);
    return d;
  };
  bool moves = false;
  for (const auto& [i, sig] : signals) {
    if (m.actuators[static_cast<std::size_t>(i)].type != ActuatorType::Motion) continue;
    moves = true;
    for (double t : signal_rate_jumps(sig)) out.options.rate_jumps.push_back(t);
  }
  if (moves) {
    std::sort(out.options.rate_jumps.begin(), out.options.rate_jumps.end());
    out.options.disturbance_rate = [nu, signals](double t) {
      Eigen::VectorXd d = Eigen::VectorXd::Zero(nu);
      for (const auto& [i, sig] : signals) d[i] += signal_rate(sig, t);
      return d;
    };
    out.options.disturbance_acceleration = [nu, signals](double t) {
      Eigen::VectorXd d = Eigen::VectorXd::Zero(nu);
      for (const auto& [i, sig] : signals) d[i] += signal_acceleration(sig, t);
      return d;
    };
  }
  if (!out.plant) return;
  // the same linearization with the disturbed actuators as extra inputs: their B and D columns
  Model wide = m;
  wide.plant_inputs.insert(wide.plant_inputs.end(), actuators.begin(), actuators.end());
  LinearizeOptions lo;
  lo.independent = s.independent;
  const Linearization l = linearize(wide, out.plant->op, lo);
  auto plant = std::make_shared<LinearPlant>(*out.plant);
  const int nd = static_cast<int>(actuators.size());
  plant->disturbance_actuators = actuators;
  plant->Bw = l.system.B.rightCols(nd);
  plant->Dw = l.system.D.rightCols(nd);
  if (l.motion_shift.size()) {
    plant->Fw = l.motion_shift.rightCols(nd);
    plant->Fw_rate = l.motion_rate_shift.rightCols(nd);
  }
  out.plant = plant;
}

// The linear closed loop's poles of a linear controller (state feedback, LTI) about the plant's point
void attach_linear_poles(StudySimulation& out) {
  if (!out.plant || !out.controller || out.controller->pid()) return;
  const LinearSystem& sys = out.plant->lin.system;
  const std::optional<LinearLaw> law = out.controller->linear_law(sys.nx(), sys.ny());
  if (!law) return;
  DisturbanceInputs w;
  w.Bw = Eigen::MatrixXd::Zero(sys.nx(), 0);
  w.Dw = Eigen::MatrixXd::Zero(sys.ny(), 0);
  ClosedLoopLinear loop;
  try {
    loop = close_loop(sys, *law, w, out.controller->state_names(), out.controller->describe());
  } catch (const std::invalid_argument& e) {
    out.notes.push_back(std::string("no linear closed-loop poles: ") + e.what());
    return;
  }
  const Eigen::MatrixXd& A = loop.system.A;
  Eigen::VectorXcd p = A.size() ? Eigen::VectorXcd(A.eigenvalues()) : Eigen::VectorXcd();
  std::sort(p.data(), p.data() + p.size(), [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  out.linear_poles = p;
  out.linear_discrete = loop.system.Ts > 0;
  out.linear_tolerance = stability_tolerance(A);
  out.linear_unstable = classify_poles(p, out.linear_discrete, out.linear_tolerance).unstable > 0;
}

// PID anti-windup, from the study, on whichever PID the study runs
void attach_anti_windup(const Model& m, StudySimulation& out) {
  const StudySpec& s = m.spec.analysis;
  AntiWindup aw;
  if (s.anti_windup == "none") return;
  if (s.anti_windup == "back_calculation") aw.method = AntiWindup::Method::BackCalculation;
  else if (s.anti_windup == "conditional") aw.method = AntiWindup::Method::Conditional;
  else workflow_fail(m, "anti_windup", "unknown anti-windup method \"" + s.anti_windup + "\" (expected one of: " + listed(anti_windup_methods()) + ")");
  aw.tracking_time = s.tracking_time;
  if (aw.method == AntiWindup::Method::BackCalculation && !(s.tracking_time > 0 && std::isfinite(s.tracking_time)))
    workflow_fail(m, "tracking_time", "back_calculation needs a tracking time > 0 (s), e.g. the integral time kp/ki");
  const PidGains* g = out.controller ? out.controller->pid() : nullptr;
  if (!g)
    workflow_fail(m, "anti_windup", "applies to a PID controller; the study's controller is " +
                               (out.controller ? out.controller->describe() : std::string("none")));
  if (!g->Ki.size()) workflow_fail(m, "anti_windup", "the PID controller has no integral action (ki): nothing winds up");
  out.controller = make_pid(g->Kp, g->Ki, g->Kd, g->r, g->u0, aw);
}

// r(t) on the Plant/Out outputs for the run; state feedback gets its Nbar feed-forward
void attach_references(const Model& m, StudySimulation& out) {
  const StudySpec& s = m.spec.analysis;
  if (!out.plant || !out.controller)
    workflow_fail(m, "references", "a reference needs a controller to follow it (the controller source is \"" + s.controller + "\")");
  const LinearSystem& sys = out.plant->lin.system;
  std::vector<std::pair<int, SignalSpec>> signals;
  std::vector<int> tracked;
  for (std::size_t k = 0; k < s.references.size(); ++k) {
    const auto it = std::find(sys.output_names.begin(), sys.output_names.end(), s.references[k].output);
    if (it == sys.output_names.end())
      workflow_fail(m, "references/" + std::to_string(k) + "/output",
           "\"" + s.references[k].output + "\" is not a Plant/Out output (outputs: " + listed(sys.output_names) + ")");
    const int i = static_cast<int>(it - sys.output_names.begin());
    if (std::find(tracked.begin(), tracked.end(), i) != tracked.end())
      workflow_fail(m, "references/" + std::to_string(k) + "/output", "a second reference for \"" + s.references[k].output + "\"");
    tracked.push_back(i);
    signals.emplace_back(i, resolved(m, s.references[k], "references/" + std::to_string(k)));
  }
  const Eigen::VectorXd y0 = sys.y0;
  out.options.reference = [y0, signals](double t) {
    Eigen::VectorXd r = y0;
    for (const auto& [i, sig] : signals) r[i] = signal_value(sig, t, y0[i]);
    return r;
  };
  if (const Eigen::MatrixXd* K = out.controller->gain()) {
    const Eigen::MatrixXd Nbar = reference_gain(sys.A, sys.B, sys.C, *K, tracked);
    out.controller = make_state_feedback(*K, sys.u0, Nbar, sys.y0);
  }
}

}  // namespace

bool adopt_controller_study(ModelSpec& spec, const std::string& file) {
  StudySpec& s = spec.analysis;
  if (s.controller != "file" || s.controller_file.empty()) return false;
  Model where;  // only for study_path's folder
  where.source_file = file;
  const std::string path = study_path(where, s.controller_file);
  MatVariables vars;
  try {
    vars = read_mat_file(path);
  } catch (const std::exception&) {
    return false;  // reported when the controller is loaded
  }
  const auto it = vars.strings.find("codyna_study");
  if (it == vars.strings.end() || it->second.empty()) return false;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(it->second.front());
    const std::string before = s.operating_point;
    const std::string carried_point = j.at("operating_point").get<std::string>();
    std::vector<std::pair<std::string, double>> carried;
    for (const auto& [name, value] : j.at("set").items()) carried.emplace_back(name, value.get<double>());
    // a coordinate held by the study (analysis set, --hold / --set) must be one the controller's
    // own point holds, at the same value: the controller is applied about that point only
    for (const auto& [name, value] : s.set) {
      const std::string& held = name;  // a structured binding cannot be captured by clang 14's lambdas
      const auto it = std::find_if(carried.begin(), carried.end(), [&](const auto& c) { return c.first == held; });
      if (it != carried.end() && it->second == value) continue;
      std::ostringstream os;
      os.precision(17);
      os << path << ": the controller carries the operating point it was designed about (codyna_study: " << carried_point
         << ", held: ";
      for (std::size_t k = 0; k < carried.size(); ++k) os << (k ? ", " : "") << carried[k].first << " = " << carried[k].second;
      os << (carried.empty() ? "none" : "") << "), and the held coordinate " << name << " = " << value
         << " (analysis set, --hold / --set) "
         << (it == carried.end() ? "is not one of them" : "is held there at another value") << ": a carried controller is "
         << "applied about its own point only. Leave the hold out; to start the run elsewhere use --initial " << name
         << "=VALUE (analysis initial); to design about another point, export there and save the controller again";
      throw std::invalid_argument(os.str());
    }
    s.operating_point = carried_point;
    s.set = carried;
    s.independent = j.at("independent").get<std::vector<std::string>>();
    s.disabled_effects = j.at("disabled_effects").get<std::vector<std::string>>();
    s.trim_free = j.value("trim_free", std::vector<std::string>{});
    s.free_inputs = j.value("free_inputs", std::vector<std::string>{});
    s.output_targets.clear();
    if (j.contains("output_targets"))
      for (const auto& [name, value] : j.at("output_targets").items()) s.output_targets.emplace_back(name, value.get<double>());
    spec.notes.push_back(path + ": the controller was designed about the " + s.operating_point +
                         " point of its export (coordinates set, independent coordinates and effects as there)" +
                         (before != s.operating_point ? "; using that point instead of " + before : std::string()));
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(path + ": codyna_study is not what codyna exports: " + e.what());
  }
  return true;
}

namespace {
const JointModel& joint_of_v(const Model& m, int iv) {
  for (int b = 1; b < m.nbodies; ++b)
    if (iv >= m.joints[b].idx_v && iv < m.joints[b].idx_v + m.joints[b].nv) return m.joints[b];
  throw std::logic_error("velocity index out of range");
}

}  // namespace

Eigen::VectorXd study_coordinates(const Model& m, const Eigen::VectorXd& q) {
  if (q.size() != m.nq) throw std::invalid_argument("study_coordinates: q has the wrong size");
  Eigen::VectorXd c(m.nv);
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (j.type == JointType::Spherical) {
      c.segment<3>(j.idx_v) = rotation_log(q.segment<4>(j.idx_q));
    } else if (j.type == JointType::Free) {
      c.segment<3>(j.idx_v) = rotation_log(q.segment<4>(j.idx_q + 3));
      c.segment<3>(j.idx_v + 3) = q.segment<3>(j.idx_q);
    } else {
      c.segment(j.idx_v, j.nv) = q.segment(j.idx_q, j.nq);
    }
  }
  return c;
}

namespace {
// `pairs` set on (q, v) and the loops closed with them held; errors at /analysis/FIELD[/NAME]
StudyInitialState set_coordinates(const Model& m, Eigen::VectorXd q, Eigen::VectorXd v,
                                  const std::vector<std::pair<std::string, double>>& pairs, const std::string& field) {
  // coordinates set by the user are held exactly while the loops are closed (Adams' locked
  // initial conditions); positions by q name, rates by "NAME_dot" or a rate's own name
  AssemblyOptions hold;
  std::vector<std::pair<std::string, double>> positions;  // what was asked, to check it afterwards
  const auto joint_of_q = [&](int iq) {
    for (int i = 1; i < m.nbodies; ++i)
      if (iq >= m.joints[i].idx_q && iq < m.joints[i].idx_q + m.joints[i].nq) return i;
    return 0;
  };
  for (const auto& [name, value] : pairs) {
    if (!std::isfinite(value) || std::abs(value) > 1e6)
      workflow_fail(m, field + "/" + name, "expected a finite number of magnitude at most 1e6 (m, rad, m/s or rad/s)");
    const auto lock_joint = [&](const JointModel& j) {
      for (int k = 0; k < j.nv; ++k) hold.locked_positions.push_back(j.idx_v + k);
    };
    if (const auto it = std::find(m.v_names.begin(), m.v_names.end(), name); it != m.v_names.end()) {
      // a coordinate (Model::v_names)
      const int iv = static_cast<int>(it - m.v_names.begin());
      const JointModel& j = joint_of_v(m, iv);
      const int c = iv - j.idx_v;
      if (j.nq == j.nv) {
        q[j.idx_q + c] = value;
        hold.locked_positions.push_back(iv);
      } else if (j.type == JointType::Free && c >= 3) {
        q[j.idx_q + c - 3] = value;  // a free joint's position
        lock_joint(j);
      } else {  // a component of a ball's or free joint's rotation vector
        const int iq = j.idx_q + (j.type == JointType::Free ? 3 : 0);
        Eigen::Vector3d r = rotation_log(q.segment<4>(iq));
        r[c] = value;
        q.segment<4>(iq) = rotation_exp(r);
        lock_joint(j);
      }
      positions.emplace_back(name, value);
      continue;
    }
    if (const auto it = std::find(m.q_names.begin(), m.q_names.end(), name); it != m.q_names.end()) {
      // a component of a stored quaternion (J.qw .. J.qz): the whole joint is held
      const int iq = static_cast<int>(it - m.q_names.begin());
      q[iq] = value;
      lock_joint(m.joints[joint_of_q(iq)]);
      continue;
    }
    const auto iv = std::find(m.rate_names.begin(), m.rate_names.end(), name);
    if (iv == m.rate_names.end())
      workflow_fail(m, field + "/" + name, "unknown coordinate \"" + name + "\" (coordinates: " + listed(m.v_names) + "; rates: " +
                                 listed(m.rate_names) + ")");
    v[iv - m.rate_names.begin()] = value;
    hold.locked_velocities.push_back(static_cast<int>(iv - m.rate_names.begin()));
  }
  const AssemblyResult r = assemble(m, q, v, hold);
  if (!r.converged) {
    // say which values cannot be held, and where the loops would put them
    const AssemblyResult free = assemble(m, q, v);
    std::ostringstream os;
    os.precision(8);
    os << "the coordinates " << (field == "set" ? "set" : "of the initial state") << " cannot all be held: the loops close only to a residual of " << r.position_residual
       << " (velocities " << r.velocity_residual << ")";
    if (free.converged)
      for (const auto& [name, value] : positions) {
        const double there = study_coordinates(m, free.q)[std::find(m.v_names.begin(), m.v_names.end(), name) - m.v_names.begin()];
        os << "; closing them freely puts " << name << " at " << there << " (" << value << " asked, off by "
           << there - value << ")";
      }
    workflow_fail(m, field, os.str());
  }
  return {r.q, r.v, true};
}

}  // namespace

namespace {
// the spec study_model compiles: the controller file's study adopted, disabled effects left out
ModelSpec study_compiled_spec(const ModelSpec& spec_in, const std::string& file) {
  ModelSpec spec = spec_in;
  adopt_controller_study(spec, file);
  const StudySpec& s = spec.analysis;
  // effects switched off for this study are left out of the compiled model
  for (std::size_t k = 0; k < s.disabled_effects.size(); ++k) {
    const std::string& name = s.disabled_effects[k];
    const auto it = std::find_if(spec.effects.begin(), spec.effects.end(), [&](const EffectSpec& e) { return e.name == name; });
    if (it == spec.effects.end()) {
      std::vector<std::string> names;
      for (const auto& e : spec_in.effects) names.push_back(e.name);
      throw ModelError(file, "/analysis/disabled_effects/" + std::to_string(k),
                       "no effect named \"" + name + "\" (effects: " + listed(names) + ")");
    }
    spec.effects.erase(it);
  }
  return spec;
}

// what study_model adds to the compiled model
Model study_finish_model(Model m, const StudySpec& s) {
  m.spec.analysis = s;  // compile keeps the spec; the study travels with it
  if (!s.set.empty()) {
    // the held coordinates move the model's own state: the operating-point search starts there
    StudyInitialState held = set_coordinates(m, m.q0, m.v0, s.set, "set");
    m.q0 = held.q;
    m.v0 = held.v;
  }
  if (!s.initial.empty()) study_initial_state(m);  // its names and values are checked before any work
  return m;
}
}  // namespace

Model study_model(const ModelSpec& spec_in, const std::string& file) {
  const ModelSpec spec = study_compiled_spec(spec_in, file);
  return study_finish_model(compile(spec, file), spec.analysis);
}

Model study_model(const ModelSpec& spec_in, const std::string& file, const Model& structure, NumbersChanged what) {
  const ModelSpec spec = study_compiled_spec(spec_in, file);
  Model m = compile_numbers(structure, spec, what, file);
  prepare_model(m);  // compile() is compile_structure then prepare_model
  return study_finish_model(std::move(m), spec.analysis);
}

Model study_model_structure(const ModelSpec& spec_in, const std::string& file) {
  Model m = compile_structure(study_compiled_spec(spec_in, file), file);
  m.spec = ModelSpec{};
  return m;
}

StudyInitialState study_initial_state(const Model& m) {
  const StudySpec& s = m.spec.analysis;
  if (s.initial.empty()) return {m.q0, m.v0, false};
  return set_coordinates(m, m.q0, m.v0, s.initial, "initial");
}

OperatingPoint study_operating_point(const Model& m, const std::string& which_in, const std::atomic<bool>* cancel) {
  const StudySpec& s = m.spec.analysis;
  const std::string which = which_in.empty() ? s.operating_point : which_in;
  const OperatingPoint start = initial_point(m);
  if (which == "initial") return start;
  // the coordinates set by the user (Model::v_names; not rates) are held; a ball's or free
  // joint's component along the joint's axes at the start (hold all three for the whole rotation)
  std::vector<std::string> set_positions;
  for (const auto& [name, value] : s.set)
    if (std::count(m.v_names.begin(), m.v_names.end(), name)) set_positions.push_back(name);
  const bool spec_given = !s.trim_free.empty() || !s.free_inputs.empty() || !s.output_targets.empty();
  if ((which == "equilibrium" && (spec_given || !set_positions.empty())) || (which == "trim" && spec_given)) {
    SteadyStateSpec spec;
    spec.held = set_positions;
    spec.outputs = s.output_targets;
    spec.free_inputs = s.free_inputs;
    if (which == "trim") {
      // every independent coordinate is held except those the user frees
      const CoordinatePartition p = partition_holding(m, start.q, set_positions, s.independent);
      spec.held.clear();
      for (int i : p.independent) {
        const std::string& name = m.v_names[static_cast<std::size_t>(i)];
        if (!std::count(s.trim_free.begin(), s.trim_free.end(), name)) spec.held.push_back(name);
      }
      for (const std::string& name : s.trim_free)
        if (!std::count(m.v_names.begin(), m.v_names.end(), name))
          workflow_fail(m, "trim_free", "unknown coordinate \"" + name + "\" (coordinates: " + listed(m.v_names) + ")");
      if (spec.free_inputs.empty())
        for (int k : m.plant_inputs) spec.free_inputs.push_back(m.actuators[static_cast<std::size_t>(k)].name);
    } else if (!s.trim_free.empty()) {
      workflow_fail(m, "trim_free", "coordinates are freed for operating point trim only (an equilibrium solves every coordinate not set)");
    }
    std::vector<std::string> outputs;
    for (int k : m.plant_outputs) outputs.push_back(m.sensors[static_cast<std::size_t>(k)].name);
    for (const auto& [name, value] : s.output_targets)
      if (!std::count(outputs.begin(), outputs.end(), name))
        workflow_fail(m, "output_targets/" + name, "output \"" + name + "\" is not in Plant/Out (" + listed(outputs) + ")");
    try {
      return steady_state(m, start, spec, s.independent, which);
    } catch (const std::invalid_argument& e) {
      workflow_fail(m, "operating_point", std::string(which) + ": " + e.what());
    } catch (const ConvergenceError& e) {
      not_converged(m, which + ": " + e.what());
    }
  }
  if (which == "equilibrium") {
    const OperatingPoint op = static_equilibrium(m, start, s.independent);
    try {
      require_steady_state(m, op, s.independent);
    } catch (const ConvergenceError& e) {
      not_converged(m, std::string(e.what()) + "; searched from the model's initial state; or choose the operating point "
                                               "initial, trim or time=T");
    }
    return op;
  }
  if (which == "trim") {
    try {
      const OperatingPoint op = trim(m, start, s.independent);
      require_steady_state(m, op, s.independent);
      return op;
    } catch (const ConvergenceError& e) {
      not_converged(m, e.what());
    }
  }
  if (which.rfind("time=", 0) == 0) {
    char* end = nullptr;
    const double t = std::strtod(which.c_str() + 5, &end);
    if (end == which.c_str() + 5 || *end != 0 || !std::isfinite(t) || t < 0)
      workflow_fail(m, "operating_point", "\"" + which + "\": expected time=T with T >= 0 seconds");
    // the state the simulation reaches at t with the actuators at their nominal values (no controller)
    if (t == 0) return snapshot_point(m, 0.0, m.q0, m.v0, start.u);
    SimulationOptions o = solver_options(m);
    o.t_end = t;
    o.output_step = t;
    SimulationCallbacks cb;
    cb.cancel = cancel;
    const SimulationResult r = simulate(m, nullptr, nullptr, o, cb);
    if (r.cancelled) {
      std::ostringstream os;
      os << "operating point " << which << ": cancelled at t = " << (r.t.empty() ? 0.0 : r.t.back()) << " s";
      throw StudyCancelled(os.str());
    }
    if (!r.completed) throw std::runtime_error("operating point " + which + ": the simulation failed: " + r.failure);
    const int last = r.samples() - 1;
    return snapshot_point(m, t, r.q.row(last).transpose(), r.v.row(last).transpose(), start.u);
  }
  workflow_fail(m, "operating_point", "unknown operating point \"" + which + "\" (expected one of: initial, equilibrium, trim, time=T)");
}

StudyLinearization study_linearize(const Model& m) {
  const StudySpec& s = m.spec.analysis;
  StudyLinearization out;
  LinearizeOptions o;
  o.method = method_of_model(m);
  o.independent = s.independent;
  if (!(s.discrete >= 0) || !std::isfinite(s.discrete)) workflow_fail(m, "discrete", "expected a sample time >= 0 (0 = continuous)");
  out.op = study_operating_point(m);
  out.lin = linearize(m, out.op, o);
  out.lin.system.study = plant_study_json(s, s.operating_point);
  out.system = s.discrete > 0 ? discretize_zoh(out.lin.system, s.discrete) : out.lin.system;
  if (s.discrete > 0 && !(out.system.A.allFinite() && out.system.B.allFinite())) {
    std::ostringstream os;
    os << "a sample time of " << s.discrete << " s is too long for this plant: exp(A Ts) overflows";
    workflow_fail(m, "discrete", os.str());
  }
  return out;
}

std::string study_export_name(const Model& m) {
  const std::string& given = m.spec.analysis.export_name;
  if (given.empty()) return matlab_identifier(m.name);
  if (given != matlab_identifier(given))
    workflow_fail(m, "export_name", "\"" + given + "\" is not a valid MATLAB identifier (try " + matlab_identifier(given) + ")");
  return given;
}

std::string study_path(const Model& m, const std::string& path) {
  const std::filesystem::path p(path);
  if (p.empty() || p.is_absolute() || m.source_file.empty()) return path;
  return (std::filesystem::path(m.source_file).parent_path() / p).lexically_normal().string();
}

ExportPaths study_export(const Model& m, const LinearSystem& sys, const std::string& dir_in) {
  const StudySpec& s = m.spec.analysis;
  const std::string dir = dir_in.empty() ? study_path(m, s.export_dir) : dir_in;
  if (dir.empty()) workflow_fail(m, "export_dir", "no folder to export to (choose one)");
  if (s.mat_version != "5" && s.mat_version != "7.3") workflow_fail(m, "mat_version", "expected 5 or 7.3");
  const std::string name = study_export_name(m);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the export folder: " + ec.message());
  return export_plant(sys, dir, name, s.mat_version == "7.3" ? MatVersion::V73 : MatVersion::V5);
}

StudySimulation study_simulation(const Model& m, const std::atomic<bool>* cancel) {
  const StudySpec& s = m.spec.analysis;
  StudySimulation out;
  out.options = solver_options(m);
  out.options.compare_linear = s.compare_linear;
  const std::string& src = s.controller;
  if (std::find(study_controllers().begin(), study_controllers().end(), src) == study_controllers().end())
    workflow_fail(m, "controller", "unknown controller source \"" + src + "\" (expected one of: " + listed(study_controllers()) + ")");
  const bool from_model = src == "model" && has_model_controller(m);
  const bool need_plant = from_model || src == "lqr" || src == "file" || s.compare_linear;
  if (need_plant) {
    if ((src == "lqr" || src == "file" || from_model) && m.plant_inputs.empty())
      throw ModelError(m.source_file, "/plant/inputs", "a controller needs Plant/In actuators");
    auto plant = std::make_shared<LinearPlant>();
    // a model's controller is linearized where it was designed; the others where the study says
    const std::string point = from_model ? m.spec.controller.operating_point : s.operating_point;
    plant->op = study_operating_point(m, point, cancel);
    LinearizeOptions lo;
    lo.independent = s.independent;
    plant->lin = linearize(m, plant->op, lo);
    plant->lin.system.study = plant_study_json(s, point);
    out.plant = plant;
  }
  if (from_model) {
    if (m.spec.controller.type == ControllerType::Lqr) require_stabilizable(m, out.plant->lin.system);
    out.controller = make_model_controller(m, *out.plant);
    out.controller_source = std::string("the model file's ") + to_string(m.spec.controller.type) + " controller";
  } else if (src == "lqr") {
    const LinearSystem& sys = out.plant->lin.system;
    const Eigen::MatrixXd Q = diagonal(m, s.q_weights, sys.nx(), "q_weights");
    const Eigen::MatrixXd R = diagonal(m, s.r_weights, sys.nu(), "r_weights");
    if (s.lqr_controllable_part) {
      // the modes no input moves are named and left as they are; the rest is designed on
      out.uncontrollable = uncontrollable(sys);
      const ControllablePartLqr d = lqr_controllable_part(sys.A, sys.B, Q, R);
      out.lqr_gain = d.lqr.K;
      out.lqr_poles = d.lqr.closed_loop_poles;
      if (!out.uncontrollable.empty()) {
        std::string note = "lqr on the controllable part (" + std::to_string(d.Tc.cols()) + " of " +
                           std::to_string(sys.nx()) + " states): the Plant/In inputs cannot move " +
                           describe(out.uncontrollable) + "; these poles stay where they are";
        const double tol = stability_tolerance(sys.A);
        for (const HiddenMode& h : out.uncontrollable)
          if (classify_pole(h.eigenvalue, sys.Ts > 0, tol) == Stability::Unstable) {
            note += " (one of them is unstable: the loop is not stable)";
            break;
          }
        out.notes.push_back(note);
      }
    } else {
      require_stabilizable(m, sys);
      const LqrResult d = lqr(sys.A, sys.B, Q, R);
      out.lqr_gain = d.K;
      out.lqr_poles = d.closed_loop_poles;
    }
    out.controller = make_state_feedback(out.lqr_gain, sys.u0);
    out.controller_source = "lqr";
  } else if (src == "file") {
    if (s.controller_file.empty()) workflow_fail(m, "controller_file", "the controller source is a file, but none is named");
    const LinearSystem& sys = out.plant->lin.system;
    const std::string path = study_path(m, s.controller_file);
    // a controller saved with the export's lists must fit this plant by name, not only by size
    const MatVariables vars = read_mat_file_or_invalid(path);
    for (const auto& [list, names] : {std::pair{"state_names", &sys.state_names}, std::pair{"input_names", &sys.input_names},
                                      std::pair{"output_names", &sys.output_names}}) {
      const auto it = vars.strings.find(list);
      if (it != vars.strings.end() && it->second != *names)
        throw std::invalid_argument(path + ": the controller was designed for " + list + " (" + joined(it->second) +
                                    ") but this plant has (" + joined(*names) + "): it belongs to another plant or state order");
    }
    out.controller = load_controller(path, sys.nx(), sys.nu(), sys.ny(), sys.y0, sys.u0);
    out.controller_source = s.controller_file;
    if (!vars.strings.count("codyna_study")) {
      // nothing says where it was designed: say where it is applied, and how to carry the point
      std::ostringstream os;
      os.precision(10);
      os << path << " carries no codyna_study: the controller is applied about this study's " << out.plant->op.kind
         << " point (";
      const Eigen::VectorXd c = study_coordinates(m, out.plant->op.q);
      const double scale = std::max(1.0, c.size() ? c.cwiseAbs().maxCoeff() : 0.0);  // round-off prints as 0
      for (int k = 0; k < m.nv; ++k)
        os << (k ? ", " : "") << m.v_names[static_cast<std::size_t>(k)] << " = " << (std::abs(c[k]) <= 1e-12 * scale ? 0.0 : c[k]);
      for (int k : m.plant_inputs) os << ", " << m.actuators[static_cast<std::size_t>(k)].name << " = " << out.plant->op.u[k];
      os << "), which may not be the point it was designed about; to carry the design point, save the export's "
            "codyna_study with it, e.g. in Octave after run('NAME.m'): save('-v7', 'K.mat', 'K', 'codyna_study', 'state_names')";
      out.notes.push_back(os.str());
    }
  } else {
    out.controller_source = "none";
  }
  if (s.start == "operating-point") {
    // the run starts at the point the controller's plant was linearized about (x0: what a
    // control engineer means by the start of a regulation), or the study's point without a plant;
    // coordinates the study sets in `initial` are set on top of it
    const OperatingPoint op = out.plant ? out.plant->op : study_operating_point(m, "", cancel);
    out.options.q0 = op.q;
    out.options.v0 = op.v;
    out.start = op.kind;
    if (!s.initial.empty()) {
      const StudyInitialState start = set_coordinates(m, op.q, op.v, s.initial, "initial");
      out.options.q0 = start.q;
      out.options.v0 = start.v;
      out.start += " + study initial";
    }
  } else if (s.start != "model") {
    workflow_fail(m, "start", "unknown start \"" + s.start + "\" (expected one of: " + listed(study_starts()) + ")");
  } else if (!s.initial.empty()) {
    // the run starts where the study's initial state says, about the operating point found above
    const StudyInitialState start = study_initial_state(m);
    out.options.q0 = start.q;
    out.options.v0 = start.v;
    out.start = "study initial";
  }
  attach_anti_windup(m, out);
  if (!s.references.empty()) attach_references(m, out);
  attach_disturbances(m, out);
  if (out.options.compare_linear && !out.plant) out.options.compare_linear = false;
  attach_linear_poles(out);
  return out;
}

SimulationResult study_simulate(const Model& m, const StudySimulation& setup, const SimulationCallbacks& cb) {
  SimulationResult r = simulate(m, setup.controller.get(), setup.plant.get(), setup.options, cb);
  r.model_file = m.source_file;
  std::ostringstream settings;
  const SimulationOptions& o = setup.options;
  settings << "{\"integrator\": \"" << o.integrator.method << "\", \"rtol\": " << o.integrator.rtol << ", \"atol\": "
           << o.integrator.atol << ", \"max_step\": " << o.integrator.max_step << ", \"t_end\": " << o.t_end
           << ", \"output_step\": " << o.output_step << ", \"operating_point\": \""
           << (setup.plant ? setup.plant->op.kind : "") << "\", \"controller\": \"" << setup.controller_source << "\"";
  if (setup.plant) {
    // the point itself (coordinates by name, every actuator's nominal value), apart from the start
    nlohmann::ordered_json q = nlohmann::ordered_json::object(), u = nlohmann::ordered_json::object();
    for (int k = 0; k < m.nq; ++k) q[m.q_names[static_cast<std::size_t>(k)]] = setup.plant->op.q[k];
    for (int k = 0; k < m.nu(); ++k) u[m.actuators[static_cast<std::size_t>(k)].name] = setup.plant->op.u[k];
    settings << ", \"operating_point_q\": " << q.dump() << ", \"operating_point_u\": " << u.dump();
  }
  settings << ", \"initial_state\": \"" << setup.start << "\"}";
  r.settings_json = settings.str();
  return r;
}

StudyClosedLoop study_closed_loop(const Model& m) {
  const StudySpec& st = m.spec.analysis;
  StudyClosedLoop r;
  r.setup = study_simulation(m);
  if (!r.setup.controller || !r.setup.plant)
    workflow_fail(m, "controller", "the closed loop needs a controller: the controller source is \"" + st.controller + "\"" +
                              (st.controller == "model" ? " and the model file declares none" : std::string()) +
                              " (choose lqr, file, or give the model a controller)");
  const LinearPlant& plant = *r.setup.plant;
  const LinearSystem& sys = plant.lin.system;
  std::shared_ptr<const Controller> ctrl = r.setup.controller;
  // a state feedback with no reference in the study: Nbar for the first outputs, so that the
  // reference inputs of the loop mean what they would in a run with references there
  if (const Eigen::MatrixXd* K = ctrl->gain(); K && st.references.empty() && sys.ny() > 0) {
    std::vector<int> tracked;
    std::string names;
    for (int k = 0; k < std::min(sys.nu(), sys.ny()); ++k) {
      tracked.push_back(k);
      names += (names.empty() ? "" : ", ") + sys.output_names[k];
    }
    try {
      ctrl = make_state_feedback(*K, sys.u0, reference_gain(sys.A, sys.B, sys.C, *K, tracked), sys.y0);
      r.notes.push_back("the study names no reference: the state feedback's Nbar tracks " + names +
                        " (the first Plant/Out outputs, one per input); the other references have no effect");
    } catch (const std::invalid_argument& e) {
      r.notes.push_back(std::string("no Nbar feed-forward (") + e.what() + "): the references have no effect");
    }
  }
  DisturbanceInputs w;
  w.Bw = plant.Bw.size() ? plant.Bw : Eigen::MatrixXd::Zero(sys.nx(), 0);
  w.Dw = plant.Dw.size() ? plant.Dw : Eigen::MatrixXd::Zero(sys.ny(), 0);
  if (w.Bw.cols() != w.Dw.cols()) w.Dw = Eigen::MatrixXd::Zero(sys.ny(), w.Bw.cols());
  w.nominal.resize(static_cast<Eigen::Index>(plant.disturbance_actuators.size()));
  for (std::size_t k = 0; k < plant.disturbance_actuators.size(); ++k) {
    const ActuatorModel& a = m.actuators[plant.disturbance_actuators[k]];
    w.names.push_back(a.name);
    w.units.push_back(a.unit);
    w.nominal[static_cast<Eigen::Index>(k)] = plant.op.u[plant.disturbance_actuators[k]];
  }
  const std::optional<LinearLaw> law = ctrl->linear_law(sys.nx(), sys.ny());
  if (!law) throw std::invalid_argument("closed loop: the controller (" + ctrl->describe() + ") has no linear form for this plant");
  r.loop = close_loop(sys, *law, w, ctrl->state_names(), ctrl->describe());
  r.poles = modal_analysis(r.loop.system);
  if (sys.xdot0.size() && sys.xdot0.cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, sys.A.norm()))
    r.notes.push_back("the operating point is not an equilibrium (xdot0 is not zero): the loop describes deviations "
                      "about a moving point, the responses leave out xdot0");
  const ClosedLoopSpec& c = st.closed_loop;
  if (c.step_points < 2) workflow_fail(m, "closed_loop/step_points", "expected at least 2 points");
  if (c.frequency_points < 2) workflow_fail(m, "closed_loop/frequency_points", "expected at least 2 points");
  const double t_end = c.step_time > 0 ? c.step_time : default_step_time(r.poles);
  r.step = step_response(r.loop.system, t_end, c.step_points);
  auto [w_min, w_max] = default_frequency_range(r.poles, r.loop.system.Ts);
  if (c.frequency_min > 0) w_min = c.frequency_min;
  if (c.frequency_max > 0) w_max = c.frequency_max;
  if (!(w_max > w_min)) {
    std::ostringstream os;
    os << "the frequency range is empty (" << w_min << " .. " << w_max << " rad/s): choose frequency_max above frequency_min";
    workflow_fail(m, "closed_loop/frequency_max", os.str());
  }
  r.frequency = frequency_response(r.loop.system, log_grid(w_min, w_max, c.frequency_points));
  return r;
}

std::vector<std::string> study_export_closed_loop(const Model& m, const StudyClosedLoop& cl, const std::string& dir_in) {
  const StudySpec& s = m.spec.analysis;
  const std::string dir = dir_in.empty() ? study_path(m, s.export_dir) : dir_in;
  if (dir.empty()) workflow_fail(m, "export_dir", "no folder to export to (choose one)");
  const std::string name = study_export_name(m) + "_cl";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the export folder: " + ec.message());
  const std::filesystem::path base = std::filesystem::path(dir) / name;
  const std::string step = base.string() + "_step.csv", freq = base.string() + "_freq.csv";
  guard_output(step, OutputKind::CurvesCsv, {m.source_file});
  guard_output(freq, OutputKind::CurvesCsv, {m.source_file});
  const ExportPaths p = export_closed_loop(cl.loop, cl.poles, cl.step.t, cl.frequency.w, dir, name);
  write_step_csv(cl.loop, cl.step, step);
  write_frequency_csv(cl.loop, cl.frequency, freq);
  return {p.mat_file, p.m_file, step, freq};
}

Eigen::VectorXd study_mode_pose(const Model& model, const Eigen::VectorXd& q_op,
                                const std::vector<std::string>& state_names, const Eigen::VectorXcd& shape,
                                double phase, double amplitude) {
  if (q_op.size() != model.nq) throw std::invalid_argument("study_mode_pose: q_op has the wrong size");
  // the position states are the first half of the state; each names one tangent coordinate
  const int npos = static_cast<int>(std::min<std::size_t>(state_names.size() / 2, static_cast<std::size_t>(shape.size())));
  std::vector<int> index(npos, -1);
  for (int k = 0; k < npos; ++k) {
    // every position state is a coordinate (Model::v_names; a ball's or free joint's rx..z
    // the tangent of its rotation and translation); states that name none are skipped
    const auto v = std::find(model.v_names.begin(), model.v_names.end(), state_names[k]);
    if (v != model.v_names.end()) index[k] = static_cast<int>(v - model.v_names.begin());
  }
  double largest = 0;
  for (int k = 0; k < npos; ++k)
    if (index[k] >= 0) largest = std::max(largest, std::abs(shape[k]));
  if (!(largest > 0) || !std::isfinite(largest)) return q_op;
  const std::complex<double> turn = std::polar(amplitude / largest, phase);
  Eigen::VectorXd dv = Eigen::VectorXd::Zero(model.nv);
  for (int k = 0; k < npos; ++k)
    if (index[k] >= 0) dv[index[k]] += (shape[k] * turn).real();
  Eigen::VectorXd q = integrate<double>(model, q_op, dv);
  if (model.nc > 0) {
    const AssemblyResult r = assemble(model, q, Eigen::VectorXd::Zero(model.nv));
    if (r.converged) q = r.q;
  }
  return q;
}

LinearRegion study_linear_region(const Model& m, const StudySimulation& setup, const SimulationResult& r) {
  LinearRegion out;
  out.bound = m.spec.analysis.linear_region;
  if (!setup.plant || r.samples() == 0 || r.q.cols() != m.nq) return out;
  const Linearization& lin = setup.plant->lin;
  const Eigen::MatrixXd& A = lin.system.A;
  const int nz = static_cast<int>(lin.partition.independent.size());
  std::vector<int> coords;
  for (int k = 0; k < nz && k < A.cols(); ++k)
    if (A.col(k).cwiseAbs().maxCoeff() > 0) {
      coords.push_back(lin.partition.independent[static_cast<std::size_t>(k)]);
      out.measured.push_back(m.v_names[static_cast<std::size_t>(coords.back())]);
    }
  if (coords.empty()) return out;
  const Eigen::VectorXd& q_op = setup.plant->op.q;
  double vmax = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const Eigen::VectorXd d = difference(m, q_op, Eigen::VectorXd(r.q.row(i).transpose()));
    double dist = 0;
    std::string on;
    for (std::size_t c = 0; c < coords.size(); ++c)
      if (std::abs(d[coords[c]]) > dist) dist = std::abs(d[coords[c]]), on = out.measured[c];
    if (out.left_at < 0 && dist > out.bound) out.left_at = r.t[static_cast<std::size_t>(i)], out.left_on = on;
    if (dist > out.largest) out.largest = dist, out.largest_on = on;
    if (i == r.samples() - 1) out.final_distance = dist, out.final_on = on;
    if (r.v.cols()) vmax = std::max(vmax, r.v.row(i).cwiseAbs().maxCoeff());
  }
  const double v_end = r.v.cols() ? r.v.row(r.samples() - 1).cwiseAbs().maxCoeff() : 0.0;
  out.settled = v_end <= std::max(1e-9, 1e-4 * vmax);
  return out;
}

}  // namespace codyna
