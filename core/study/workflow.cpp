#include "study/workflow.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "study/workflow_detail.hpp"

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

using namespace workflow_detail;

namespace workflow_detail {

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
  o.integrator = integrator_settings(sp);
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

}  // namespace workflow_detail

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

namespace workflow_detail {
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

}  // namespace workflow_detail

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
  if (which == "steady") {
    if (!s.trim_free.empty())
      workflow_fail(m, "trim_free", "coordinates are freed for operating point trim only (a steady motion solves every coordinate not held)");
    SteadyMotionSpec spec;
    spec.body = s.steady.body;
    spec.speed = s.steady.speed;
    spec.yaw_rate = s.steady.yaw_rate;
    spec.radius = s.steady.radius;
    spec.lateral_acceleration = s.steady.lateral_acceleration;
    spec.free_inputs = s.free_inputs;
    spec.held = set_positions;
    spec.outputs = s.output_targets;
    try {
      return steady_motion(m, start, spec, s.independent);
    } catch (const std::invalid_argument& e) {
      workflow_fail(m, "steady", e.what());
    } catch (const ConvergenceError& e) {
      not_converged(m, e.what());
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
  workflow_fail(m, "operating_point", "unknown operating point \"" + which + "\" (expected one of: initial, equilibrium, trim, steady, time=T)");
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
  if (out.op.kind == "steady" && (!s.handling.steer.empty() || !s.handling.yaw_rate.empty())) {
    out.handling = study_handling(m, out);
    const HandlingNumbers& h = *out.handling;
    out.lin.system.handling = {{"speed", h.speed},
                               {"wheelbase", h.wheelbase},
                               {"steering_ratio", h.steering_ratio},
                               {"yaw_rate_gain", h.yaw_rate_gain},
                               {"lateral_acceleration_gain", h.lateral_acceleration_gain},
                               {"understeer_gradient", h.understeer_gradient},
                               {"understeer_gradient_deg_per_g", h.understeer_gradient_deg_per_g},
                               {"characteristic_speed", h.characteristic_speed},
                               {"critical_speed", h.critical_speed},
                               {"yaw_natural_frequency", h.yaw_natural_frequency},
                               {"yaw_damping_ratio", h.yaw_damping_ratio}};
    if (h.sideslip_given) out.lin.system.handling.emplace_back("sideslip_gain", h.sideslip_gain);
  }
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

}  // namespace codyna
