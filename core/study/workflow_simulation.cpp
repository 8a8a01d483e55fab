// The closed-loop run of a study (study/workflow.hpp): the controller and plant it needs
// (study_simulation), the run, the linear closed loop and its export, the linear region.
#include "study/workflow.hpp"
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

namespace {

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
    out.start_point = op.kind;
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
