#include "study/jobs.hpp"
#include "analysis/response_figures.hpp"

#include "analysis/stability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "analysis/discretize.hpp"
#include "dynamics/prepare.hpp"
#include "io/mat_export.hpp"
#include "io/model_file.hpp"
#include "io/output_guard.hpp"
#include "io/results_file.hpp"
#include "simulation/model_controller.hpp"
#include "simulation/trajectory_linearization.hpp"

namespace codyna {

std::string option_name(OptionStyle style, const std::string& dashed) {
  if (style == OptionStyle::Flag) return "--" + dashed;
  std::string s = dashed;
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

namespace {

// what the front end calls an option
struct Names {
  OptionStyle style;
  std::string operator()(const std::string& dashed) const { return option_name(style, dashed); }
};

// a job's messages: kept, and handed to the front end as they arise
struct Teller {
  const StudyMessages& tell;
  std::vector<std::string>& notes;
  std::vector<std::string>& warnings;
  void note(const std::string& s) const {
    notes.push_back(s);
    if (tell) tell({StudyMessage::Note, s});
  }
  void warning(const std::string& s) const {
    warnings.push_back(s);
    if (tell) tell({StudyMessage::Warning, s});
  }
};

// The study and solver fields a request gave, each with its option as the front end writes it.
// A refusal of the study at FIELD[/REST] that comes from a value the request gave is said of the
// option ("--hold cart: unknown coordinate ..."): the user typed it, the file may not have it.
class GivenFields {
 public:
  explicit GivenFields(const Names& opt) : opt_(opt) {}
  void add(bool given, const std::string& field, const std::string& dashed) {
    if (given) fields_.emplace_back(field, opt_(dashed));
  }
  template <class F>
  auto run(F&& f) const -> decltype(f()) {
    try {
      return f();
    } catch (const ModelError& e) {
      for (const auto& [field, option] : fields_) {
        const std::string& p = e.path();
        if (p.compare(0, field.size(), field) != 0 || (p.size() > field.size() && p[field.size()] != '/')) continue;
        const std::string rest = p.size() > field.size() ? p.substr(field.size() + 1) : std::string();
        throw std::invalid_argument(option + (rest.empty() ? "" : " " + rest) + ": " + e.detail());
      }
      throw;
    }
  }

 private:
  Names opt_;
  std::vector<std::pair<std::string, std::string>> fields_;
};

void add_point_fields(GivenFields& g, const PointRequest& p) {
  g.add(p.operating_point.has_value(), "/analysis/operating_point", "operating-point");
  g.add(p.independent.has_value(), "/analysis/independent", "independent");
  g.add(p.trim_free.has_value(), "/analysis/trim_free", "trim-free");
  g.add(p.free_inputs.has_value(), "/analysis/free_inputs", "free-inputs");
  g.add(!p.hold.empty(), "/analysis/set", "hold");
  g.add(!p.initial.empty(), "/analysis/initial", "initial");
  g.add(!p.targets.empty(), "/analysis/output_targets", "target");
}

void apply_pairs(std::vector<std::pair<std::string, double>>& into, const std::vector<std::string>& given_pairs,
                 const std::string& flag) {
  for (const std::string& s : given_pairs) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw std::invalid_argument(flag + " " + s + ": expected NAME=VALUE");
    const std::string name = s.substr(0, eq);
    double value;
    try {
      std::size_t used = 0;
      value = std::stod(s.substr(eq + 1), &used);
      if (used != s.size() - eq - 1) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw std::invalid_argument(flag + " " + s + ": expected a number after '='");
    }
    if (!std::isfinite(value)) throw std::invalid_argument(flag + " " + s + ": expected a finite number");
    auto it = std::find_if(into.begin(), into.end(), [&](const auto& p) { return p.first == name; });
    if (it != into.end()) it->second = value;
    else into.emplace_back(name, value);
  }
}

std::string names_of(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& n : v) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "none" : s;
}

// NAME=VALUE[@TIME] -> {"KEY": NAME, "type": "step", "value": VALUE, "time": TIME}, or a JSON object as it is
nlohmann::json signal_json(const std::string& text, const char* key, const std::string& flag) {
  const auto first = text.find_first_not_of(" \t");
  if (first != std::string::npos && text[first] == '{') {
    try {
      return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      throw std::invalid_argument(flag + " " + text + ": not a JSON object (" + e.what() + ")");
    }
  }
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument(flag + " " + text + ": expected NAME=VALUE[@TIME] or a JSON object {\"" + key + "\": ...}");
  const std::string rest = text.substr(eq + 1);
  const auto at = rest.find('@');
  const auto number = [&](const std::string& s, const char* what) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(x))
      throw std::invalid_argument(flag + " " + text + ": expected a finite number for the " + what);
    return x;
  };
  nlohmann::json j = {{key, text.substr(0, eq)}, {"type", "step"}, {"value", number(rest.substr(0, at), "value")}};
  if (at != std::string::npos) j["time"] = number(rest.substr(at + 1), "time after '@'");
  return j;
}

void apply_plant(ModelSpec& spec, const PlantRequest& f, const Names& opt) {
  const auto check = [](const std::vector<std::string>& given_names, const std::vector<std::string>& known,
                        const std::string& flag, const char* what) {
    for (const std::string& n : given_names)
      if (std::find(known.begin(), known.end(), n) == known.end())
        throw std::invalid_argument(flag + ": no " + what + " named \"" + n + "\" (" + what + "s: " + names_of(known) + ")");
  };
  std::vector<std::string> actuators, sensors, effects;
  for (const auto& a : spec.actuators) actuators.push_back(a.name);
  for (const auto& s : spec.sensors) sensors.push_back(s.name);
  for (const auto& e : spec.effects) effects.push_back(e.name);
  if (f.inputs) {
    check(*f.inputs, actuators, opt("inputs"), "actuator");
    spec.plant.inputs = *f.inputs;
  }
  if (f.outputs) {
    check(*f.outputs, sensors, opt("outputs"), "sensor");
    spec.plant.outputs = *f.outputs;
  }
  if (f.disabled_effects) {
    check(*f.disabled_effects, effects, opt("disable-effect"), "effect");
    spec.analysis.disabled_effects = *f.disabled_effects;
  }
  if (!f.references && !f.disturbances) return;
  // the signals are read by the model file's reader, from the spec with the options' lists in it
  nlohmann::json j = to_json(spec);
  if (f.references) {
    j["analysis"]["references"] = nlohmann::json::array();
    for (const std::string& r : *f.references)
      j["analysis"]["references"].push_back(signal_json(r, "output", opt("reference")));
  }
  if (f.disturbances) {
    j["analysis"]["disturbances"] = nlohmann::json::array();
    for (const std::string& d : *f.disturbances)
      j["analysis"]["disturbances"].push_back(signal_json(d, "actuator", opt("disturbance")));
  }
  const std::string label = f.references && f.disturbances ? opt("reference") + "/" + opt("disturbance")
                            : f.references                 ? opt("reference")
                                                           : opt("disturbance");
  ModelSpec read = parse_model_spec(j, label);
  spec.analysis.references = read.analysis.references;
  spec.analysis.disturbances = read.analysis.disturbances;
}

void apply_point(StudySpec& s, const PointRequest& p, const Names& opt) {
  apply_pairs(s.set, p.hold, opt("hold"));
  // --initial operating-point (or model) says where the run starts; NAME=VALUE entries set coordinates there
  std::vector<std::string> pairs;
  for (const std::string& v : p.initial) {
    if (std::find(study_starts().begin(), study_starts().end(), v) != study_starts().end()) s.start = v;
    else if (v.find('=') == std::string::npos)
      throw std::invalid_argument(opt("initial") + " " + v + ": expected NAME=VALUE, or where the run starts: " +
                                  study_starts()[0] + " or " + study_starts()[1]);
    else pairs.push_back(v);
  }
  apply_pairs(s.initial, pairs, opt("initial"));
  if (p.trim_free) s.trim_free = *p.trim_free;
  if (p.free_inputs) s.free_inputs = *p.free_inputs;
  apply_pairs(s.output_targets, p.targets, opt("target"));
  if (p.steady_body) s.steady.body = *p.steady_body;
  if (p.speed) s.steady.speed = *p.speed;
  // the turn: one of three, a given one replaces the file's
  if (p.yaw_rate || p.radius || p.lateral_acceleration) {
    s.steady.yaw_rate = p.yaw_rate;
    s.steady.radius = p.radius;
    s.steady.lateral_acceleration = p.lateral_acceleration;
  }
}

JacobianMethod method_of(const std::string& s, const Names& opt) {
  if (s == "exact") return JacobianMethod::Exact;
  if (s == "fd-forward") return JacobianMethod::ForwardDifference;
  if (s == "fd-central") return JacobianMethod::CentralDifference;
  throw std::invalid_argument(opt("method") + " " + s + ": expected exact, fd-forward or fd-central");
}

// the model file's study, with the request on top
ModelSpec linearize_spec(const LinearizeRequest& a, ModelSpec spec) {
  const Names opt{a.style};
  apply_plant(spec, a.plant, opt);
  StudySpec& s = spec.analysis;
  if (a.point.operating_point) s.operating_point = *a.point.operating_point;
  if (a.method) s.method = *a.method;
  if (a.discrete) {
    if (!(*a.discrete >= 0) || !std::isfinite(*a.discrete))
      throw std::invalid_argument(opt("discrete") + ": the sample time must be positive (0 = continuous)");
    s.discrete = *a.discrete;
  }
  if (a.mat_version) {
    if (*a.mat_version != "5" && *a.mat_version != "7.3") throw std::invalid_argument(opt("mat-version") + ": expected 5 or 7.3");
    s.mat_version = *a.mat_version;
  }
  if (a.point.independent) s.independent = *a.point.independent;
  if (a.name) {
    if (*a.name != matlab_identifier(*a.name))
      throw std::invalid_argument(opt("name") + " " + *a.name + ": not a valid MATLAB identifier (try " +
                                  matlab_identifier(*a.name) + ")");
    s.export_name = *a.name;
  }
  if (a.method) method_of(*a.method, opt);  // a clear message for a bad option
  if (a.closed_loop) s.closed_loop.enabled = true;
  if (a.lqr && a.controller) throw std::invalid_argument(opt("controller") + " and " + opt("lqr") + ": choose one");
  if ((a.lqr || a.controller) && !a.closed_loop && !s.closed_loop.enabled)
    throw std::invalid_argument((a.lqr ? opt("lqr") : opt("controller")) + ": a controller is used by " +
                                opt("closed-loop") + " only (add it)");
  if (a.lqr) s.controller = "lqr";
  if (a.controller) {
    s.controller = "file";
    s.controller_file = std::filesystem::absolute(*a.controller).string();  // relative to the working folder
  }
  if (a.q_weights) s.q_weights = *a.q_weights;
  if (a.r_weights) s.r_weights = *a.r_weights;
  if (a.lqr_controllable_part) {
    if (s.controller != "lqr")
      throw std::invalid_argument(opt("lqr-controllable-part") + ": goes with " + opt("lqr") +
                                  " (or \"controller\": \"lqr\" in the study)");
    s.lqr_controllable_part = true;
  }
  apply_point(s, a.point, opt);
  return spec;
}

void trajectory_job(LinearizeJob& job, const LinearizeRequest& a) {
  const Names opt{a.style};
  const Model& m = job.model;
  if (m.spec.analysis.discrete != 0)
    throw std::invalid_argument(opt("trajectory") + ": export is continuous-time only (drop " + opt("discrete") + ")");
  if (m.spec.analysis.mat_version != "5") throw std::invalid_argument(opt("trajectory") + ": export is MAT v5 only");
  SimulationOptions o;
  o.integrator = integrator_settings(m.spec.solver);
  const double T = *a.trajectory;
  o.t_end = T;
  o.output_step = a.trajectory_step && *a.trajectory_step > 0 ? *a.trajectory_step : m.spec.solver.output_step;
  if (!std::isfinite(T) || (a.trajectory_step && !(*a.trajectory_step > 0 && std::isfinite(*a.trajectory_step))))
    throw std::invalid_argument(opt("trajectory") + ", " + opt("trajectory-step") + ": expected finite numbers of seconds > 0");
  if (!m.spec.analysis.initial.empty()) {  // the run starts at the study's initial state
    const StudyInitialState start = study_initial_state(m);
    o.q0 = start.q;
    o.v0 = start.v;
  }
  const double points = T / o.output_step + 1;
  if (points > 100000)
    throw std::invalid_argument(opt("trajectory") + " " + std::to_string(T) + " with a step of " +
                                std::to_string(o.output_step) + " s gives " +
                                std::to_string(static_cast<long long>(points)) + " linearizations (at most 100000): raise " +
                                opt("trajectory-step"));
  if (!a.out.empty()) {
    const std::filesystem::path base = std::filesystem::path(a.out) / job.name;
    guard_output(base.string() + ".mat", OutputKind::PlantMat, {a.model});
    guard_output(base.string() + ".m", OutputKind::PlantScript, {a.model});
  }
  std::unique_ptr<LinearPlant> plant;
  std::unique_ptr<Controller> controller;
  if (has_model_controller(m)) {
    plant = std::make_unique<LinearPlant>(controller_plant(m));
    controller = make_model_controller(m, *plant);
  }
  const SimulationResult r = simulate(m, controller.get(), plant.get(), o);
  if (!r.completed) throw std::runtime_error(opt("trajectory") + ": the simulation failed: " + r.failure);
  LinearizeOptions lo;
  lo.method = method_of(m.spec.analysis.method, opt);
  lo.independent = m.spec.analysis.independent;
  const std::vector<Linearization> lin = linearize_along(m, r, lo);
  job.trajectory = true;
  job.method = to_string(lo.method);
  job.trajectory_controller = controller ? controller->describe() : std::string("open loop");
  job.times.assign(r.t.begin(), r.t.end());
  job.times.resize(lin.size());
  for (const Linearization& l : lin) job.systems.push_back(l.system);
  job.max_real.resize(static_cast<Eigen::Index>(lin.size()));
  job.min_real.resize(static_cast<Eigen::Index>(lin.size()));
  for (std::size_t k = 0; k < lin.size(); ++k) {
    const Eigen::VectorXcd ev = job.systems[k].A.eigenvalues();
    job.max_real[static_cast<Eigen::Index>(k)] = ev.real().maxCoeff();
    job.min_real[static_cast<Eigen::Index>(k)] = ev.real().minCoeff();
  }
  if (a.out.empty()) return;
  std::filesystem::create_directories(a.out);
  const ExportPaths p = export_trajectory(job.systems, std::vector<double>(r.t.begin(), r.t.end()), a.out, job.name);
  job.written = {p.mat_file, p.m_file};
}

}  // namespace

namespace {
// what the user should know of a point that moves: the motion, the frame A is taken in, and
// whether its eigenvalues are the motion's
template <class Say>
void motion_notes(const Model& m, const StudyLinearization& sl, const Say& say) {
  if (sl.op.motion) say.note("steady motion: " + study_motion_text(m, sl.op));
  if (sl.lin.about_motion) {
    say.note("linearized about the motion: the state is the deviation from the pose that moves with it "
             "(turning with it), so A is the same wherever along the motion it is taken");
    std::ostringstream os;
    if (sl.lin.motion_residual > 1e-6)
      os << "the state is not steady in the moving frame (rates left " << sl.lin.motion_residual << ")";
    if (sl.lin.motion_drift > 1e-6)
      os << (os.tellp() ? "; " : "") << "A's eigenvalues change along the motion (by " << sl.lin.motion_drift
         << " of their largest)";
    if (os.tellp())
      say.warning("not a relative equilibrium: " + os.str() +
                  "; the eigenvalues describe this instant, not the motion's stability");
  } else if (sl.op.kind != "steady" && motion_of_state(m, sl.op.q, sl.op.v).turns()) {
    say.warning("the operating point moves (a free, planar or ball joint turning): A is taken in the coordinates "
                "fixed at this instant, and its eigenvalues are not the motion's stability; operating point steady "
                "finds the steady motion and linearizes about it");
  }
}

LinearizeJob linearize_job(const LinearizeRequest& a, const ModelSpec& file_spec, const Model* structure,
                           NumbersChanged what, const StudyMessages& tell) {
  const Names opt{a.style};
  LinearizeJob job;
  const Teller say{tell, job.notes, job.warnings};
  job.model = structure ? study_model(linearize_spec(a, file_spec), a.model, *structure, what)
                        : study_model(linearize_spec(a, file_spec), a.model);
  const Model& m = job.model;
  if (!m.assembly_moves.empty())
    say.note("closing the loops moved the joints' q0/v0: " + study_assembly_moves_text(m));
  job.name = study_export_name(m);
  if (m.plant_inputs.empty() && m.plant_outputs.empty())
    say.warning("the model selects no Plant/In or Plant/Out; exporting the state equations only");
  else if (m.plant_inputs.empty())
    say.warning("the model selects no Plant/In (plant.inputs): B and D have no columns, no controller can act");
  else if (m.plant_outputs.empty())
    say.warning("the model selects no Plant/Out (plant.outputs): C and D have no rows");
  if (a.trajectory) {
    if (!(*a.trajectory > 0) || !std::isfinite(*a.trajectory))
      throw std::invalid_argument(opt("trajectory") + ": expected an end time of seconds > 0");
    if (m.spec.analysis.closed_loop.enabled)
      throw std::invalid_argument(opt("closed-loop") + ": not along a " + opt("trajectory") + " (one operating point)");
    trajectory_job(job, a);
    return job;
  }
  if (!a.out.empty()) {  // an export that would replace the model (or a file codyna did not write) fails before the work
    const std::filesystem::path base = std::filesystem::path(a.out) / job.name;
    guard_output(base.string() + ".mat", OutputKind::PlantMat, {a.model});
    guard_output(base.string() + ".m", OutputKind::PlantScript, {a.model});
    if (m.spec.analysis.closed_loop.enabled) {
      guard_output(base.string() + "_cl.mat", OutputKind::PlantMat, {a.model});
      guard_output(base.string() + "_cl.m", OutputKind::PlantScript, {a.model});
      guard_output(base.string() + "_cl_step.csv", OutputKind::CurvesCsv, {a.model});
      guard_output(base.string() + "_cl_freq.csv", OutputKind::CurvesCsv, {a.model});
    }
  }
  if (!a.point.initial.empty())
    throw std::invalid_argument(opt("initial") + ": the initial state of a run; linearize uses it with " + opt("trajectory") +
                                " only (the operating point's coordinates are " + opt("hold") + " NAME=VALUE)");
  job.linearization = study_linearize(m);
  motion_notes(m, job.linearization, say);
  // the closed loop's operating point (the model controller's own may differ) is found before
  // anything is written, so that a search that fails leaves no export behind
  if (m.spec.analysis.closed_loop.enabled) job.closed_loop = study_closed_loop(m);
  job.method = to_string(method_of(m.spec.analysis.method, opt));
  if (a.modes) job.modes = modal_analysis(job.linearization.system);
  // what the inputs cannot move and the outputs cannot see, named (continuous plant)
  const LinearSystem& c = job.linearization.lin.system;
  job.uncontrollable = uncontrollable_modes(c.A, c.B, c.state_names);
  if (a.modes) job.unobservable = unobservable_modes(c.A, c.C, c.state_names);
  if (a.out.empty()) return job;
  const ExportPaths p = study_export(m, job.linearization.system, a.out);
  job.written = {p.mat_file, p.m_file};
  if (job.closed_loop) job.closed_loop_written = study_export_closed_loop(m, *job.closed_loop, a.out);
  return job;
}
}  // namespace

namespace {
GivenFields linearize_fields(const LinearizeRequest& a) {
  GivenFields g(Names{a.style});
  add_point_fields(g, a.point);
  g.add(a.method.has_value(), "/analysis/method", "method");
  g.add(a.discrete.has_value(), "/analysis/discrete", "discrete");
  g.add(a.name.has_value(), "/analysis/export_name", "name");
  g.add(a.q_weights.has_value(), "/analysis/q_weights", "q-weights");
  g.add(a.r_weights.has_value(), "/analysis/r_weights", "r-weights");
  g.add(a.controller.has_value(), "/analysis/controller_file", "controller");
  return g;
}
}  // namespace

LinearizeJob study_linearize_job(const LinearizeRequest& a, const ModelSpec& spec, const StudyMessages& tell) {
  return linearize_fields(a).run([&] { return linearize_job(a, spec, nullptr, {}, tell); });
}

LinearizeJob study_linearize_job(const LinearizeRequest& a, const ModelSpec& spec, const Model& structure,
                                 NumbersChanged what, const StudyMessages& tell) {
  return linearize_fields(a).run([&] { return linearize_job(a, spec, &structure, what, tell); });
}

Model study_linearize_structure(const LinearizeRequest& a, const ModelSpec& spec) {
  return study_model_structure(linearize_spec(a, spec), a.model);
}

namespace {

// the model file's study and solver settings, with the request on top
ModelSpec simulate_spec(const SimulateRequest& a, ModelSpec spec) {
  const Names opt{a.style};
  apply_plant(spec, a.plant, opt);
  StudySpec& s = spec.analysis;
  if (a.controller.has_value() + a.lqr + a.open_loop > 1)
    throw std::invalid_argument(opt("controller") + ", " + opt("lqr") + " and " + opt("open-loop") + ": choose one");
  if (a.controller) {
    s.controller = "file";
    s.controller_file = std::filesystem::absolute(*a.controller).string();  // relative to the working folder
  }
  if (a.lqr) s.controller = "lqr";
  if (a.open_loop) s.controller = "none";
  if (a.lqr_controllable_part) {
    if (s.controller != "lqr")
      throw std::invalid_argument(opt("lqr-controllable-part") + ": goes with " + opt("lqr") +
                                  " (or \"controller\": \"lqr\" in the study)");
    s.lqr_controllable_part = true;
  }
  if (a.q_weights) s.q_weights = *a.q_weights;
  if (a.r_weights) s.r_weights = *a.r_weights;
  if (a.point.operating_point) {
    s.operating_point = *a.point.operating_point;
    // the request's point also overrides where the model's own controller is linearized
    if (spec.controller.type != ControllerType::None) spec.controller.operating_point = *a.point.operating_point;
  }
  if (a.point.independent) s.independent = *a.point.independent;
  if (a.compare_linear) s.compare_linear = true;
  if (a.linear_region) {
    if (!(*a.linear_region > 0) || !std::isfinite(*a.linear_region))
      throw std::invalid_argument(opt("linear-region") + ": expected a bound > 0 (rad or m)");
    s.linear_region = *a.linear_region;
  }
  apply_point(s, a.point, opt);
  SolverSpec& sp = spec.solver;
  // each number given is checked where it enters, with its option named
  const auto check = [&](const char* name, const std::optional<double>& x, auto ok, const char* expected) {
    if (!x) return false;
    if (!std::isfinite(*x) || !ok(*x))
      throw std::invalid_argument(opt(name) + " " + std::to_string(*x) + ": expected " + expected);
    return true;
  };
  if (a.integrator) sp.integrator = *a.integrator;
  if (check("rtol", a.rtol, [](double x) { return x > 0 && x < 1; }, "a number in (0, 1)")) sp.rtol = *a.rtol;
  if (check("atol", a.atol, [](double x) { return x > 0; }, "a number > 0")) sp.atol = *a.atol;
  if (check("max-step", a.max_step, [](double x) { return x >= 0; }, "a number >= 0 (0 = no limit)")) sp.max_step = *a.max_step;
  if (check("t-end", a.t_end, [](double x) { return x > 0; }, "a number of seconds > 0")) sp.t_end = *a.t_end;
  if (check("output-step", a.output_step, [](double x) { return x > 0; }, "a number of seconds > 0"))
    sp.output_step = *a.output_step;
  if (check("alf-penalty", a.alf_penalty, [](double x) { return x > 0; }, "a penalty > 0 (alf's default 1e11)"))
    sp.alf_penalty = *a.alf_penalty;
  if (a.alf_iterations) {
    if (*a.alf_iterations < 1)
      throw std::invalid_argument(opt("alf-iterations") + " " + std::to_string(*a.alf_iterations) +
                                  ": expected a number of Newton iterations >= 1 (alf's default 100)");
    sp.alf_iterations = *a.alf_iterations;
  }
  if (a.alf_fixed_step) sp.alf_fixed_step = *a.alf_fixed_step;
  if (a.alf_extrapolate) sp.alf_extrapolate = *a.alf_extrapolate;
  check("max-samples", a.max_samples, [](double x) { return x >= 1; }, "a number >= 1");
  check("divergence-bound", a.divergence_bound, [](double x) { return x > 0; }, "a number > 0");
  return spec;
}

}  // namespace

ExportPaths study_export_linearization(const Model& m, const LinearSystem& system, const std::string& dir) {
  const std::string target = dir.empty() ? std::string() : study_path(m, dir);
  const std::string folder = target.empty() ? study_path(m, m.spec.analysis.export_dir) : target;
  if (!folder.empty()) {  // (no folder at all: study_export says so)
    const std::filesystem::path base = std::filesystem::path(folder) / study_export_name(m);
    guard_output(base.string() + ".mat", OutputKind::PlantMat, {m.source_file});
    guard_output(base.string() + ".m", OutputKind::PlantScript, {m.source_file});
  }
  return study_export(m, system, target);
}

namespace {
SimulateJob simulate_job(const SimulateRequest& a, const ModelSpec& file_spec, const SimulationCallbacks& cb,
                         const std::function<void(const SimulateJob&)>& ready, const StudyMessages& tell);

GivenFields simulate_fields(const SimulateRequest& a) {
  GivenFields g(Names{a.style});
  add_point_fields(g, a.point);
  g.add(a.q_weights.has_value(), "/analysis/q_weights", "q-weights");
  g.add(a.r_weights.has_value(), "/analysis/r_weights", "r-weights");
  g.add(a.controller.has_value(), "/analysis/controller_file", "controller");
  g.add(a.linear_region.has_value(), "/analysis/linear_region", "linear-region");
  g.add(a.integrator.has_value(), "/solver/integrator", "integrator");
  g.add(a.rtol.has_value(), "/solver/rtol", "rtol");
  g.add(a.atol.has_value(), "/solver/atol", "atol");
  g.add(a.max_step.has_value(), "/solver/max_step", "max-step");
  g.add(a.t_end.has_value(), "/solver/t_end", "t-end");
  g.add(a.output_step.has_value(), "/solver/output_step", "output-step");
  g.add(a.alf_penalty.has_value(), "/solver/alf_penalty", "alf-penalty");
  g.add(a.alf_iterations.has_value(), "/solver/alf_iterations", "alf-iterations");
  g.add(a.alf_fixed_step.has_value(), "/solver/alf_fixed_step", "alf-fixed-step");
  g.add(a.alf_extrapolate.has_value(), "/solver/alf_extrapolate", "alf-extrapolate");
  return g;
}
}  // namespace

SimulateJob study_simulate_job(const SimulateRequest& a, const ModelSpec& file_spec, const SimulationCallbacks& cb,
                               const std::function<void(const SimulateJob&)>& ready, const StudyMessages& tell) {
  return simulate_fields(a).run([&] { return simulate_job(a, file_spec, cb, ready, tell); });
}

SimulateSetup study_simulate_setup(const SimulateRequest& a, const ModelSpec& file_spec, bool linearize,
                                   const std::atomic<bool>* cancel) {
  return simulate_fields(a).run([&] {
    SimulateSetup out{study_model(simulate_spec(a, file_spec), a.model), {}, std::nullopt};
    out.setup = study_simulation(out.model, cancel);
    if (linearize && !out.setup.plant) out.linearization = study_linearize(out.model);
    return out;
  });
}

namespace {
SimulateJob simulate_job(const SimulateRequest& a, const ModelSpec& file_spec, const SimulationCallbacks& cb,
                         const std::function<void(const SimulateJob&)>& ready, const StudyMessages& tell) {
  const Names opt{a.style};
  SimulateJob job;
  const Teller say{tell, job.notes, job.warnings};
  const ModelSpec spec = simulate_spec(a, file_spec);
  job.model = study_model(spec, a.model);
  const Model& m = job.model;
  if (!m.assembly_moves.empty())
    say.note("closing the loops moved the joints' q0/v0: " + study_assembly_moves_text(m));
  for (std::size_t k = spec.notes.size(); k < m.spec.notes.size(); ++k) say.note(m.spec.notes[k]);
  // outputs that would replace the model, the controller file or a file codyna did not write are refused
  // before any work
  const std::vector<std::string> inputs{a.model, a.controller.value_or("")};
  if (!a.out.empty()) guard_output(a.out, OutputKind::ResultsHdf5, inputs);
  if (!a.csv.empty()) {
    guard_output(a.csv, OutputKind::ResultsCsv, inputs);
    if (a.csv == a.out || same_file(a.csv, a.out))
      throw std::invalid_argument(opt("csv") + " " + a.csv + ": the same file as " + opt("out"));
  }
  job.setup = study_simulation(m, cb.cancel);
  StudySimulation& setup = job.setup;
  for (const std::string& n : setup.notes) say.note(n);
  if (a.max_samples) setup.options.max_samples = *a.max_samples;
  if (a.divergence_bound) setup.options.divergence_bound = *a.divergence_bound;
  const LinearPlant* plant = setup.plant.get();
  if (setup.linear_poles.size() && setup.linear_unstable)
    say.warning("unstable linear closed loop: the controller does not stabilize the plant about the " + plant->op.kind +
                " point (check the sign of the gain: u = u0 - K (x - x0))");
  if (plant) job.op_coordinates = study_coordinates(m, plant->op.q);
  if (!m.spec.analysis.initial.empty()) job.initial_coordinates = study_coordinates(m, setup.options.q0);
  // the output paths' folders exist before time is spent on the run
  for (const std::string& p : {a.out, a.csv}) {
    if (p.empty()) continue;
    const auto dir = std::filesystem::path(p).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
      throw std::invalid_argument(p + ": the directory " + dir.string() + " does not exist");
  }
  if (ready) ready(job);
  job.result = study_simulate(m, setup, cb);
  const SimulationResult& r = job.result;
  if (!a.out.empty() || !a.csv.empty()) {
    write_results(r, a.out, a.csv);
    if (!a.out.empty()) job.written.push_back(a.out);
    if (!a.csv.empty()) job.written.push_back(a.csv);
  }
  job.saturation = saturation_report(m, r);
  const int N = r.samples();
  job.unstable_poles = unstable_poles(setup.linear_poles, setup.linear_discrete, setup.linear_tolerance);
  if (N > 0) {
    job.max_abs_input.resize(static_cast<Eigen::Index>(m.plant_inputs.size()));
    for (std::size_t k = 0; k < m.plant_inputs.size(); ++k)
      job.max_abs_input[static_cast<Eigen::Index>(k)] = r.u.col(m.plant_inputs[k]).cwiseAbs().maxCoeff();
    job.energy_start = r.kinetic_energy[0] + r.potential_energy[0];
    job.energy_end = r.kinetic_energy[N - 1] + r.potential_energy[N - 1];
    if (m.nc) {
      job.max_constraint_violation = *std::max_element(r.constraint_violation.begin(), r.constraint_violation.end());
      job.max_velocity_violation = *std::max_element(r.velocity_violation.begin(), r.velocity_violation.end());
    }
  }
  if (r.y_linear.rows() == N && N > 0) {
    const LinearGap gap = linear_gap(r.t, r.y, r.y_linear);
    job.linear_gap = gap.largest;
    job.linear_gap_percent = gap.percent;
    job.linear_gap_from = gap.from;
  }
  if (plant) {
    // how far the run went from the point the linear parts are about
    job.region = study_linear_region(m, setup, r);
    const LinearRegion& lr = job.region;
    if (!lr.measured.empty() && lr.left_at >= 0) {
      std::ostringstream os;
      os << "the state left the region where the linear model holds: |" << lr.left_on
         << " - its operating-point value| > " << lr.bound << " at t = " << lr.left_at << " s"
         << (lr.settled && lr.final_distance > lr.bound ? ", and settled elsewhere" : "");
      say.warning(os.str());
    }
  }
  return job;
}

}  // namespace

Model study_compile(const ModelSpec& spec, const std::string& file) { return compile(spec, file); }

std::string study_assembly_moves_text(const Model& m) {
  std::ostringstream os;
  os.precision(6);
  for (const Model::AssemblyMove& a : m.assembly_moves) {
    const auto iv = std::find(m.v_names.begin(), m.v_names.end(), a.name);
    const auto ir = std::find(m.rate_names.begin(), m.rate_names.end(), a.name);
    const std::size_t i = iv != m.v_names.end() ? static_cast<std::size_t>(iv - m.v_names.begin())
                                                : static_cast<std::size_t>(ir - m.rate_names.begin());
    const std::string unit = i < m.v_units.size() ? (iv != m.v_names.end() ? m.v_units[i] : rate_unit(m.v_units[i])) : "";
    os << (os.tellp() > 0 ? ", " : "") << a.name << " ";
    if (std::isfinite(a.from)) os << a.from << " -> " << a.to << " ";
    os << "(moved by " << a.by << " " << unit << ")";
  }
  return os.str();
}

}  // namespace codyna
