#include <Eigen/Eigenvalues>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "analysis/discretize.hpp"
#include "analysis/linearize.hpp"
#include "analysis/modal.hpp"
#include "analysis/operating_point.hpp"
#include "commands.hpp"
#include "control/controllability.hpp"
#include "io/model_file.hpp"
#include "io/output_guard.hpp"
#include "common.hpp"
#include "io/mat_export.hpp"
#include "simulation/model_controller.hpp"
#include "simulation/simulator.hpp"
#include "simulation/trajectory_linearization.hpp"
#include "study/workflow.hpp"

namespace codyna::cli {

namespace {

struct LinearizeArgs {
  std::string model, out, op = "equilibrium", method = "exact", mat_version = "5", name, controller;
  double discrete = 0.0, trajectory = 0.0, trajectory_step = 0.0;
  bool closed_loop = false, lqr = false, lqr_controllable_part = false;
  std::vector<double> q_weights, r_weights;
  std::vector<std::string> independent, set, initial, trim_free, free_inputs, targets;
  PlantFlags plant;
  const CLI::App* cmd = nullptr;  // to tell given flags (they override the file's analysis section)
};

JacobianMethod method_of(const std::string& s) {
  if (s == "exact") return JacobianMethod::Exact;
  if (s == "fd-forward") return JacobianMethod::ForwardDifference;
  if (s == "fd-central") return JacobianMethod::CentralDifference;
  throw std::invalid_argument("--method " + s + ": expected exact, fd-forward or fd-central");
}

// --trajectory: simulate (with the model's controller, if it declares one) and linearize
// the plant about every output sample
void run_trajectory(const Model& m, const LinearizeArgs& a, const std::string& name) {
  if (m.spec.analysis.discrete != 0) throw std::invalid_argument("--trajectory: export is continuous-time only (drop --discrete)");
  if (m.spec.analysis.mat_version != "5") throw std::invalid_argument("--trajectory: export is MAT v5 only");
  SimulationOptions o;
  o.integrator.method = m.spec.solver.integrator;
  o.integrator.rtol = m.spec.solver.rtol;
  o.integrator.atol = m.spec.solver.atol;
  o.integrator.max_step = m.spec.solver.max_step;
  o.t_end = a.trajectory;
  o.output_step = a.trajectory_step > 0 ? a.trajectory_step : m.spec.solver.output_step;
  if (!std::isfinite(a.trajectory) || (given(a.cmd, "--trajectory-step") && !(a.trajectory_step > 0 && std::isfinite(a.trajectory_step))))
    throw std::invalid_argument("--trajectory, --trajectory-step: expected finite numbers of seconds > 0");
  if (!m.spec.analysis.initial.empty()) {  // the run starts at the study's initial state
    const StudyInitialState start = study_initial_state(m);
    o.q0 = start.q;
    o.v0 = start.v;
  }
  const double points = a.trajectory / o.output_step + 1;
  if (points > 100000)
    throw std::invalid_argument("--trajectory " + std::to_string(a.trajectory) + " with a step of " +
                                std::to_string(o.output_step) + " s gives " + std::to_string(static_cast<long long>(points)) +
                                " linearizations (at most 100000): raise --trajectory-step");
  const std::filesystem::path base = std::filesystem::path(a.out) / name;
  guard_output(base.string() + ".mat", OutputKind::PlantMat, {a.model});
  guard_output(base.string() + ".m", OutputKind::PlantScript, {a.model});
  std::unique_ptr<LinearPlant> plant;
  std::unique_ptr<Controller> controller;
  if (has_model_controller(m)) {
    plant = std::make_unique<LinearPlant>(controller_plant(m));
    controller = make_model_controller(m, *plant);
  }
  const SimulationResult r = simulate(m, controller.get(), plant.get(), o);
  if (!r.completed) throw std::runtime_error("--trajectory: the simulation failed: " + r.failure);
  LinearizeOptions lo;
  lo.method = method_of(m.spec.analysis.method);
  lo.independent = m.spec.analysis.independent;
  const std::vector<Linearization> lin = linearize_along(m, r, lo);
  std::vector<LinearSystem> systems;
  for (const Linearization& l : lin) systems.push_back(l.system);
  std::cout << "model            " << m.name << " (" << m.dof() << " DOF)\n"
            << "trajectory       " << lin.size() << " points, t = 0 .. " << r.t.back() << " s, "
            << (controller ? controller->describe() : std::string("open loop")) << "\n"
            << "method           " << to_string(lo.method) << "\n"
            << "states           ";
  for (std::size_t k = 0; k < systems[0].state_names.size(); ++k) std::cout << (k ? ", " : "") << systems[0].state_names[k];
  std::cout << "\n\n     t [s]   max Re(eig A)   min Re(eig A)\n";
  const std::size_t every = std::max<std::size_t>(1, lin.size() / 10);
  for (std::size_t k = 0; k < lin.size(); k += every) {
    const Eigen::VectorXcd ev = systems[k].A.eigenvalues();
    std::cout << std::setw(10) << r.t[k] << std::setw(16) << ev.real().maxCoeff() << std::setw(16) << ev.real().minCoeff() << "\n";
  }
  std::filesystem::create_directories(a.out);
  const ExportPaths p = export_trajectory(systems, std::vector<double>(r.t.begin(), r.t.end()), a.out, name);
  std::cout << "\nwrote " << p.mat_file << "\nwrote " << p.m_file << "\n";
}

// the study's controller around the plant: NAME_cl.{mat,m} and the step and frequency curves
void run_closed_loop(const Model& m, const LinearizeArgs& a, const StudyClosedLoop& cl) {
  for (const std::string& n : cl.setup.notes) std::cerr << "codyna: note: " << n << "\n";
  for (const std::string& n : cl.notes) std::cerr << "codyna: note: closed loop: " << n << "\n";
  const LinearSystem& s = cl.loop.system;
  std::cout << "\nclosed loop      " << cl.loop.controller << " (" << cl.setup.controller_source << "), "
            << s.nx() << " states, " << (s.Ts > 0 ? "discrete, Ts = " + std::to_string(s.Ts) : std::string("continuous")) << "\n"
            << "inputs           ";
  for (std::size_t k = 0; k < s.input_names.size(); ++k) std::cout << (k ? ", " : "") << s.input_names[k];
  std::cout << "\noutputs          ";
  for (std::size_t k = 0; k < s.output_names.size(); ++k) std::cout << (k ? ", " : "") << s.output_names[k];
  std::cout << "\n\n" << format_modes(cl.poles) << "\n";
  for (const std::string& f : study_export_closed_loop(m, cl, a.out)) std::cout << "wrote " << f << "\n";
}

// the model file's study, with the flags given on the command line on top
ModelSpec study_of(const LinearizeArgs& a) {
  ModelSpec spec = load_spec(a.model);
  apply_plant_flags(spec, a.plant, a.cmd);
  StudySpec& s = spec.analysis;
  if (given(a.cmd, "--operating-point")) s.operating_point = a.op;
  if (given(a.cmd, "--method")) s.method = a.method;
  if (given(a.cmd, "--discrete")) {
    if (!(a.discrete >= 0) || !std::isfinite(a.discrete))
      throw std::invalid_argument("--discrete: the sample time must be positive (0 = continuous)");
    s.discrete = a.discrete;
  }
  if (given(a.cmd, "--mat-version")) {
    if (a.mat_version != "5" && a.mat_version != "7.3") throw std::invalid_argument("--mat-version: expected 5 or 7.3");
    s.mat_version = a.mat_version;
  }
  if (given(a.cmd, "--independent")) s.independent = a.independent;
  if (given(a.cmd, "--name")) {
    if (a.name != matlab_identifier(a.name))
      throw std::invalid_argument("--name " + a.name + ": not a valid MATLAB identifier (try " + matlab_identifier(a.name) + ")");
    s.export_name = a.name;
  }
  if (given(a.cmd, "--method")) method_of(a.method);  // a clear message for a bad flag
  if (a.closed_loop) s.closed_loop.enabled = true;
  if (a.lqr && !a.controller.empty()) throw std::invalid_argument("--controller and --lqr: choose one");
  if ((a.lqr || !a.controller.empty()) && !a.closed_loop && !s.closed_loop.enabled)
    throw std::invalid_argument(std::string(a.lqr ? "--lqr" : "--controller") + ": a controller is used by --closed-loop only (add it)");
  if (a.lqr) s.controller = "lqr";
  if (!a.controller.empty()) {
    s.controller = "file";
    s.controller_file = std::filesystem::absolute(a.controller).string();  // a flag's path is relative to here
  }
  if (given(a.cmd, "--q-weights")) s.q_weights = a.q_weights;
  if (given(a.cmd, "--r-weights")) s.r_weights = a.r_weights;
  if (a.lqr_controllable_part) {
    if (s.controller != "lqr") throw std::invalid_argument("--lqr-controllable-part: goes with --lqr (or \"controller\": \"lqr\" in the study)");
    s.lqr_controllable_part = true;
  }
  apply_set(s, a.set);
  apply_initial(s, a.initial);
  if (given(a.cmd, "--trim-free")) s.trim_free = a.trim_free;
  if (given(a.cmd, "--free-input")) s.free_inputs = a.free_inputs;
  apply_targets(s, a.targets);
  return spec;
}

void run(const LinearizeArgs& a) {
  const Model m = study_model(study_of(a), a.model);
  if (!m.assembly_moves.empty())
    std::cerr << "codyna: note: closing the loops moved the joints' q0/v0: " << assembly_moves_text(m) << "\n";
  const std::string name = study_export_name(m);
  if (m.plant_inputs.empty() && m.plant_outputs.empty())
    std::cerr << "codyna: warning: the model selects no Plant/In or Plant/Out; exporting the state equations only\n";
  else if (m.plant_inputs.empty())
    std::cerr << "codyna: warning: the model selects no Plant/In (plant.inputs): B and D have no columns, no controller can act\n";
  else if (m.plant_outputs.empty())
    std::cerr << "codyna: warning: the model selects no Plant/Out (plant.outputs): C and D have no rows\n";
  if (given(a.cmd, "--trajectory")) {
    if (!(a.trajectory > 0) || !std::isfinite(a.trajectory))
      throw std::invalid_argument("--trajectory: expected an end time of seconds > 0");
    if (m.spec.analysis.closed_loop.enabled) throw std::invalid_argument("--closed-loop: not along a --trajectory (one operating point)");
    return run_trajectory(m, a, name);
  }
  {  // an export that would replace the model (or a file codyna did not write) fails before the work
    const std::filesystem::path base = std::filesystem::path(a.out) / name;
    guard_output(base.string() + ".mat", OutputKind::PlantMat, {a.model});
    guard_output(base.string() + ".m", OutputKind::PlantScript, {a.model});
    if (m.spec.analysis.closed_loop.enabled) {
      guard_output(base.string() + "_cl.mat", OutputKind::PlantMat, {a.model});
      guard_output(base.string() + "_cl.m", OutputKind::PlantScript, {a.model});
      guard_output(base.string() + "_cl_step.csv", OutputKind::CurvesCsv, {a.model});
      guard_output(base.string() + "_cl_freq.csv", OutputKind::CurvesCsv, {a.model});
    }
  }
  if (!a.initial.empty())
    throw std::invalid_argument("--initial: the initial state of a run; linearize uses it with --trajectory only (the "
                                "operating point's coordinates are --hold NAME=VALUE)");
  const StudyLinearization sl = study_linearize(m);
  // the closed loop's operating point (the model controller's own may differ) is found before
  // anything is written, so that a search that fails leaves no export behind
  std::optional<StudyClosedLoop> cl;
  if (m.spec.analysis.closed_loop.enabled) cl = study_closed_loop(m);
  const OperatingPoint& op = sl.op;
  const Linearization& lin = sl.lin;
  const LinearSystem& sys = sl.system;
  LinearizeOptions opt;
  opt.method = method_of(m.spec.analysis.method);

  std::cout << "model            " << m.name << " (" << m.dof() << " DOF)\n"
            << "operating point  " << op.kind;
  if (op.kind == "equilibrium" || op.kind == "trim")
    std::cout << " (residual " << op.residual << ", " << op.iterations << " iterations)";
  std::cout << "\nmethod           " << to_string(opt.method);
  if (opt.method != JacobianMethod::Exact) std::cout << " (max relative difference from exact: " << lin.fd_error << ")";
  std::cout << "\ntime             " << (sys.Ts > 0 ? "discrete, Ts = " + std::to_string(sys.Ts) : std::string("continuous")) << "\n";
  if (!lin.partition.dependent.empty()) {
    std::cout << "independent      ";
    for (std::size_t k = 0; k < lin.partition.independent.size(); ++k)
      std::cout << (k ? ", " : "") << m.v_names[lin.partition.independent[k]];
    std::cout << "\n";
  }
  std::cout << "\n";
  const auto labelled = [](const std::vector<std::string>& names, const Eigen::VectorXd& v) { return name_values(names, v); };
  std::cout << "x0\n" << labelled(sys.state_names, sys.x0) << "u0\n" << labelled(sys.input_names, sys.u0)
            << "y0\n" << labelled(sys.output_names, sys.y0) << "xdot0\n" << labelled(sys.state_names, sys.xdot0) << "\n";
  print_matrix("A", sys.A, sys.state_names, sys.state_names);
  print_matrix("B", sys.B, sys.state_names, sys.input_names);
  print_matrix("C", sys.C, sys.output_names, sys.state_names);
  print_matrix("D", sys.D, sys.output_names, sys.input_names);
  std::cout << "\n" << format_modes(modal_analysis(sys)) << "\n";
  // what the inputs cannot move and the outputs cannot see, named (continuous plant)
  const LinearSystem& c = lin.system;
  const auto uc = uncontrollable_modes(c.A, c.B, c.state_names), uo = unobservable_modes(c.A, c.C, c.state_names);
  std::cout << "controllable     " << (uc.empty() ? std::string("yes, every mode") : "no: " + describe(uc)) << "\n"
            << "observable       " << (uo.empty() ? std::string("yes, every mode") : "no: " + describe(uo)) << "\n\n";

  const ExportPaths p = study_export(m, sys, a.out);
  std::cout << "wrote " << p.mat_file << "\nwrote " << p.m_file << "\n";
  if (cl) run_closed_loop(m, a, *cl);
}

}  // namespace

void add_linearize(CLI::App& app) {
  auto a = std::make_shared<LinearizeArgs>();
  auto* cmd = app.add_subcommand("linearize", "Linearize the plant (Plant/In -> Plant/Out) and export NAME.mat + NAME.m");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--out", a->out, "output directory (created if missing)")->required();
  cmd->add_option("--operating-point", a->op, "initial | equilibrium | trim | time=T")->capture_default_str();
  cmd->add_option("--method", a->method, "exact | fd-forward | fd-central")->capture_default_str();
  cmd->add_option("--discrete", a->discrete, "sample time Ts > 0: exact zero-order-hold discrete model");
  cmd->add_option("--mat-version", a->mat_version, "5 | 7.3")->capture_default_str();
  cmd->add_option("--independent", a->independent, "closed loops: independent coordinate names")->delimiter(',');
  cmd->add_option("--hold,--set", a->set, "NAME=VALUE: hold a joint coordinate (or rate, NAME_dot) in the operating-point search: set in the model's state and kept exactly by the equilibrium and trim searches (repeatable; --set is the older name)");
  cmd->add_option("--initial", a->initial, "NAME=VALUE: with --trajectory, the simulation's initial state (repeatable); the operating point does not depend on it");
  cmd->add_option("--trim-free", a->trim_free, "trim: coordinates the trim solves instead of holding (comma-separated)")->delimiter(',');
  cmd->add_option("--free-input", a->free_inputs, "equilibrium/trim: Plant/In inputs solved for (comma-separated; trim default: all)")->delimiter(',');
  cmd->add_option("--target", a->targets, "NAME=VALUE: a Plant/Out value the equilibrium/trim must reach (repeatable)");
  cmd->add_option("--trajectory", a->trajectory, "T: linearize along a simulation from 0 to T (the model's controller in the loop, if any) instead of at one point");
  cmd->add_option("--trajectory-step", a->trajectory_step, "DT: spacing of the points along the trajectory (default: the model's output_step)");
  cmd->add_option("--name", a->name, "plant name (default: the model name as a MATLAB identifier)");
  cmd->add_flag("--closed-loop", a->closed_loop, "also export the linear closed loop with the study's controller: NAME_cl.mat + NAME_cl.m, NAME_cl_step.csv, NAME_cl_freq.csv");
  cmd->add_flag("--lqr", a->lqr, "the closed loop's controller: an LQR designed on this plant");
  cmd->add_option("--controller", a->controller, "the closed loop's controller: a .mat with K, Kp/Ki/Kd or Ac,Bc,Cc,Dc[,Ts] (as simulate --controller)");
  cmd->add_flag("--lqr-controllable-part", a->lqr_controllable_part, "with --lqr on a plant that is not stabilizable: design on the controllable part");
  cmd->add_option("--q-weights", a->q_weights, "LQR state weights (diagonal of Q), in state order")->delimiter(',');
  cmd->add_option("--r-weights", a->r_weights, "LQR input weights (diagonal of R)")->delimiter(',');
  add_plant_flags(cmd, a->plant);
  a->cmd = cmd;
  cmd->callback([a] { set_exit_code(run_guarded([&] { run(*a); })); });
}

}  // namespace codyna::cli
