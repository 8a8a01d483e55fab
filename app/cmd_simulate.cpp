// codyna simulate: flags -> a SimulateRequest, one study call (study_simulate_job), and the
// printing. What the flags mean and every computation live in core/study/.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "study/jobs.hpp"

namespace codyna::cli {

namespace {

struct SimulateArgs {
  std::string model, out, csv, controller, integrator;
  bool compare_linear = false, quiet = false, open_loop = false;
  double linear_region = 0;
  double t_end = 0, rtol = 0, atol = 0, max_step = -1, output_step = 0, alf_penalty = 0;
  int alf_iterations = 0;
  bool alf_fixed_step = false;
  bool alf_extrapolate = false;
  // the simulator's own limits unless given (shown as the defaults in --help)
  double max_samples = SimulationOptions{}.max_samples, divergence_bound = SimulationOptions{}.divergence_bound;
  PointFlags point;
  LqrFlags lqr;
  PlantFlags plant;
  const CLI::App* cmd = nullptr;  // to tell given flags (they override the file's analysis and solver sections)
};

std::string row(const Eigen::MatrixXd& M, int r) {
  std::ostringstream os;
  os.precision(17);
  for (Eigen::Index c = 0; c < M.cols(); ++c) os << (c ? " " : "") << M(r, c);
  return os.str();
}

std::string poles_text(const Eigen::VectorXcd& p, int precision) {
  std::ostringstream os;
  os.precision(precision);
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    os << (k ? ", " : "") << p[k].real();
    if (p[k].imag() != 0) os << (p[k].imag() < 0 ? "-" : "+") << std::abs(p[k].imag()) << "i";
  }
  return os.str();
}

SimulateRequest simulate_request_of(const SimulateArgs& a) {
  SimulateRequest r;
  r.model = a.model;
  r.out = a.out;
  r.csv = a.csv;
  r.plant = plant_request(a.plant, a.cmd);
  if (!a.controller.empty()) r.controller = a.controller;
  r.open_loop = a.open_loop;
  apply_lqr_flags(a.lqr, a.cmd, r);
  r.point = point_request(a.point, a.cmd);
  r.compare_linear = a.compare_linear;
  if (given(a.cmd, "--linear-region")) r.linear_region = a.linear_region;
  if (!a.integrator.empty()) r.integrator = a.integrator;
  if (given(a.cmd, "--rtol")) r.rtol = a.rtol;
  if (given(a.cmd, "--atol")) r.atol = a.atol;
  if (given(a.cmd, "--max-step")) r.max_step = a.max_step;
  if (given(a.cmd, "--t-end")) r.t_end = a.t_end;
  if (given(a.cmd, "--output-step")) r.output_step = a.output_step;
  if (given(a.cmd, "--alf-penalty")) r.alf_penalty = a.alf_penalty;
  if (given(a.cmd, "--alf-iterations")) r.alf_iterations = a.alf_iterations;
  if (a.alf_fixed_step) r.alf_fixed_step = true;
  if (a.alf_extrapolate) r.alf_extrapolate = true;
  if (given(a.cmd, "--max-samples")) r.max_samples = a.max_samples;
  if (given(a.cmd, "--divergence-bound")) r.divergence_bound = a.divergence_bound;
  return r;
}

// alf's own settings as the run used them ("fixed steps of 0.005 s, penalty 1e+11, Newton ")
std::string alf_settings(const SolverSpec& sp, const SolverStats& stats) {
  if (stats.integrator != "alf") return "";
  const IntegratorSettings is = integrator_settings(sp);
  std::ostringstream os;
  if (is.alf_fixed_step) os << "fixed steps of " << (is.max_step > 0 ? is.max_step : 1e-3) << " s, ";
  if (is.alf_extrapolate) os << "each step extrapolated from two halves, ";
  os << "penalty " << is.alf_penalty << ", at most " << is.alf_iterations << " iterations a step, Newton at ";
  return os.str();
}

// what is known before the run: the controller, the linear closed loop, the operating point and the start
void print_setup(const SimulateJob& job, const SimulateArgs& a) {
  const Model& m = job.model;
  const StudySimulation& setup = job.setup;
  const LinearPlant* plant = setup.plant.get();
  if (setup.controller) {
    const std::string& src = m.spec.analysis.controller;
    if (src == "lqr") {
      const LinearSystem& s = plant->lin.system;
      std::cout << "LQR about the " << plant->op.kind << " point, states (";
      for (std::size_t k = 0; k < s.state_names.size(); ++k) std::cout << (k ? ", " : "") << s.state_names[k];
      std::cout << "):\n";
      for (int r = 0; r < setup.lqr_gain.rows(); ++r) std::cout << "K(" << s.input_names[r] << ") = [" << row(setup.lqr_gain, r) << "]\n";
      std::cout << "closed-loop poles";
      for (Eigen::Index k = 0; k < setup.lqr_poles.size(); ++k)
        std::cout << (k ? ", " : " ") << setup.lqr_poles[k].real() << (setup.lqr_poles[k].imag() < 0 ? "-" : "+")
                  << std::abs(setup.lqr_poles[k].imag()) << "i";
      std::cout << "\n";
    } else if (src == "file") {
      std::cout << "controller from " << a.controller << ": " << setup.controller->describe() << "\n";
    } else {
      std::cout << "controller from the model file: " << setup.controller->describe() << " (about the " << plant->op.kind
                << " point)\n";
    }
  }
  if (setup.linear_poles.size())
    std::cout << "linear closed-loop poles (" << (setup.linear_discrete ? "discrete, z" : "continuous, s") << ", about the "
              << plant->op.kind << " point): " << poles_text(setup.linear_poles, 12) << "\n";
  if (plant) {
    // the point the linear parts (controller, comparison) are about, apart from where the run starts
    std::cout << "operating point  " << plant->op.kind;
    if (plant->op.kind == "equilibrium" || plant->op.kind == "trim") std::cout << " (residual " << plant->op.residual << ")";
    std::cout << ":";
    std::cout << " " << name_values(m.v_names, job.op_coordinates, true, 10) << std::setprecision(10);
    for (int k : m.plant_inputs) std::cout << ", " << m.actuators[k].name << " = " << plant->op.u[k];
    std::cout << std::setprecision(6) << "\n";
  }
  if (m.spec.analysis.start == "operating-point") {
    std::cout << "start            at the " << setup.start_point << " point";
    if (m.spec.analysis.initial.empty()) std::cout << (plant ? " (x0 of the controller's linearization)" : " (the study's operating point)");
    else std::cout << " with the initial coordinates set: " << name_values(m.v_names, job.initial_coordinates, true, 10);
    std::cout << std::setprecision(6) << "\n";
  } else if (!m.spec.analysis.initial.empty()) {
    std::cout << "initial state   ";
    std::cout << " " << name_values(m.v_names, job.initial_coordinates, true, 10);
    std::cout << std::setprecision(6) << " (the study's initial state, apart from the operating point)\n";
  }
}

void summary(const SimulateJob& job) {
  const SimulationResult& r = job.result;
  const Model& m = job.model;
  const StudySimulation& setup = job.setup;
  const LinearPlant* plant = setup.plant.get();
  const int N = r.samples();
  std::cout << "\nsimulation       " << (r.completed ? "completed" : r.cancelled ? "cancelled" : "FAILED") << ", t = "
            << r.t.front() << " .. " << r.t.back() << " s, " << N << " samples\n";
  if (!r.failure.empty()) std::cout << "failure          " << r.failure << "\n";
  std::cout << "controller       " << r.controller << "\n"
            << "integrator       " << r.stats.integrator << " (" << alf_settings(job.model.spec.solver, r.stats) << "rtol "
            << r.stats.rtol << ", atol " << r.stats.atol << "): " << r.stats.steps << " steps, " << r.stats.rhs_evals << " evaluations, " << r.stats.jac_evals
            << " Jacobians, " << r.stats.projections << " projections, " << std::setprecision(3) << r.stats.wall_time
            << " s\n" << std::setprecision(6);
  if (!r.stats.integrator_choice.empty()) std::cout << "                 " << r.stats.integrator_choice << "\n";
  if (setup.linear_unstable) {
    std::cout << "warning          unstable linear closed loop: " << job.unstable_poles.size() << " of "
              << setup.linear_poles.size() << " poles "
              << (setup.linear_discrete ? "outside the unit circle" : "with positive real part") << " (";
    for (Eigen::Index k = 0; k < job.unstable_poles.size(); ++k)
      std::cout << (k ? ", " : "") << poles_text(job.unstable_poles.segment(k, 1), 6);
    std::cout << ")\n";
  }
  if (N == 0) return;
  // the operating point's outputs print by the rule of every printed vector: round-off at or
  // below 1e-12 of the vector's scale shows as 0
  const double y0_scale = plant && plant->lin.system.y0.size() ? plant->lin.system.y0.cwiseAbs().maxCoeff() : 0.0;
  for (int k = 0; k < r.y.cols(); ++k) {
    const double y0 = plant ? shown(plant->lin.system.y0[k], y0_scale) : r.y(0, k);
    std::cout << "output " << std::left << std::setw(10) << r.output_names[k] << std::right << " start "
              << std::setw(11) << r.y(0, k) << "  end " << std::setw(11) << r.y(N - 1, k) << "  ("
              << (plant ? "y0 at the " + plant->op.kind + " point: " : std::string("start: ")) << y0 << ") ["
              << r.output_units[k] << "]\n";
  }
  for (std::size_t i = 0; i < m.plant_inputs.size(); ++i) {
    const ActuatorModel& act = m.actuators[m.plant_inputs[i]];
    std::cout << "input  " << std::left << std::setw(10) << act.name << std::right << " max |u| "
              << job.max_abs_input[static_cast<Eigen::Index>(i)] << " [" << act.unit << "]\n";
  }
  for (const Saturation& s : job.saturation) std::cout << "saturation       " << saturation_text(s) << "\n";
  std::cout << "energy           " << job.energy_start << " -> " << job.energy_end << " J\n";
  if (m.nc)
    std::cout << "constraint drift max |phi| " << job.max_constraint_violation << ", max |Jc v| " << job.max_velocity_violation
              << "\n";
  if (job.linear_gap.size()) {
    std::cout << "linear vs nonlinear (same controller, same start):\n";
    for (int k = 0; k < r.y.cols(); ++k) {
      std::cout << "  " << std::left << std::setw(10) << r.output_names[k] << std::right << " max |y - y_lin| "
                << job.linear_gap[k] << " (" << job.linear_gap_percent[k] << " % of its excursion); "
                << (job.linear_gap_from[k] < 0 ? std::string("within 1 % throughout")
                                               : "parts beyond 1 % at t = " + std::to_string(job.linear_gap_from[k]) + " s")
                << "\n";
    }
    // the two runs' own errors beside the gap: a gap near them is the integrators', not the model's
    std::cout << "  nonlinear run: " << r.stats.integrator << " at rtol " << r.stats.rtol << ", atol " << r.stats.atol
              << "; linear run: Dormand-Prince 5(4) at rtol " << r.linear_rtol << ", atol "
              << r.linear_atol;
    if (r.linear_error_estimate >= 0)
      std::cout << " (a rerun at 100x looser tolerances differs by " << r.linear_error_estimate << ")";
    std::cout << "\n";
    if (!r.linear_failure.empty()) std::cout << "  " << r.linear_failure << "\n";
  }
  if (plant) {
    // how far the run went from the point the linear parts are about
    const LinearRegion& lr = job.region;
    if (!lr.measured.empty()) {
      std::string names;
      for (const auto& n : lr.measured) names += (names.empty() ? "" : ", ") + n;
      std::cout << "linear region    |q - q_op| <= " << lr.bound << " on " << names << ": ";
      if (lr.left_at < 0) std::cout << "stayed within (largest " << lr.largest << ", " << lr.largest_on << ")\n";
      else
        std::cout << "left at t = " << lr.left_at << " s (" << lr.left_on << "), largest " << lr.largest << " ("
                  << lr.largest_on << ")\n";
      if (lr.settled && lr.final_distance > lr.bound)
        std::cout << "                 the run ends at rest " << lr.final_distance << " from the operating point ("
                  << lr.final_on << "): it settled elsewhere\n";
    }
  }
}

void run_simulate(const SimulateArgs& a) {
  const SimulateRequest req = simulate_request_of(a);
  SimulationCallbacks cb;
  const bool bar = !a.quiet && isatty(STDERR_FILENO);
  int last = -1;
  double t0 = 0;
  if (bar)
    cb.progress = [&](double t, double t_end) {
      const int pct = static_cast<int>(100 * (t - t0) / (t_end - t0));
      if (pct == last) return;
      last = pct;
      const int w = 40, filled = pct * w / 100;
      std::fprintf(stderr, "\r[%s%s] %3d%%  t = %.3f s", std::string(filled, '#').c_str(), std::string(w - filled, '.').c_str(), pct, t);
      std::fflush(stderr);
    };
  const auto ready = [&](const SimulateJob& job) {
    t0 = job.setup.options.t0;
    print_setup(job, a);
  };
  bool bar_open = false;  // the progress bar's line is not ended yet
  const auto tell = [&](const StudyMessage& msg) {
    if (bar_open) std::fprintf(stderr, "\n");
    bar_open = false;
    print_message(msg);
  };
  const auto progress = cb.progress;
  if (bar)
    cb.progress = [&](double t, double t_end) {
      progress(t, t_end);
      bar_open = true;
    };
  const SimulateJob job = study_simulate_job(req, load_spec(a.model), cb, ready, tell);
  if (bar && bar_open) std::fprintf(stderr, "\n");
  summary(job);
  const SimulationResult& r = job.result;
  std::cout << "wrote " << a.out << (a.csv.empty() ? "" : "\nwrote " + a.csv) << "\n";
  if (!r.completed && !r.cancelled) throw std::runtime_error("the run failed at " + r.failure + "; the partial result is in " + a.out);
}

}  // namespace

void add_simulate(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  auto* cmd = app.add_subcommand("simulate", "Simulate the nonlinear model, with a controller in the loop");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--out", a->out, "results file (HDF5)")->required();
  cmd->add_option("--csv", a->csv, "also write the results as CSV");
  cmd->add_option("--controller", a->controller, "controller .mat: K (state feedback), Kp/Ki/Kd (PID) or Ac,Bc,Cc,Dc[,Ts] (LTI); default: the model file's controller, if any");
  cmd->add_flag("--open-loop", a->open_loop, "ignore the model's controller: actuators at their nominal values");
  add_lqr_flags(cmd, a->lqr, "design an LQR state feedback on the linearized plant and use it",
                "with --lqr on a plant that is not stabilizable: design on the controllable part, leaving the modes no input moves (named) as they are");
  add_point_flags(cmd, a->point, "where the controller's plant is linearized: initial | equilibrium | trim | time=T",
                  "NAME=VALUE: hold a joint coordinate (or rate, NAME_dot) in the operating-point search: set in the model's state, kept exactly by the equilibrium and trim searches, and the run's start unless --initial says otherwise (repeatable; --set is the older name)",
                  "NAME=VALUE: the run's initial state: a joint coordinate (or rate, NAME_dot), the loops closed with it held (repeatable); the operating point is searched apart from it, from the model's state. 'operating-point': the run starts at the operating point the controller is linearized about (x0), NAME=VALUE then setting coordinates on it");
  cmd->add_flag("--compare-linear", a->compare_linear, "also simulate the linear closed loop and report where it parts from the nonlinear one");
  cmd->add_option("--linear-region", a->linear_region, "R: report when a coordinate the linear dynamics depend on is more than R (rad or m) from its operating-point value (default 0.5, or the file's analysis.linear_region)");
  cmd->add_option("--t-end", a->t_end, "end time [s] (default: the model's solver settings)");
  cmd->add_option("--integrator", a->integrator, integrator_names(" | ") + " (default: the model file's solver, auto when it names none)");
  cmd->add_option("--rtol", a->rtol, "relative tolerance");
  cmd->add_option("--atol", a->atol, "absolute tolerance");
  cmd->add_option("--max-step", a->max_step, "largest step [s] (rk4 and alf with --alf-fixed-step: the fixed step)");
  cmd->add_option("--alf-penalty", a->alf_penalty, "alf: the penalty on the constraints (> 0; default the file's, else 1e11)");
  cmd->add_option("--alf-iterations", a->alf_iterations, "alf: the most Newton iterations a step (>= 1; default 100)");
  cmd->add_flag("--alf-fixed-step", a->alf_fixed_step, "alf: every step --max-step (default 1 ms) instead of the error control");
  cmd->add_flag("--alf-extrapolate", a->alf_extrapolate,
                "alf: each step combined from finer trapezoidal steps (Richardson's extrapolation: fourth order; at fixed steps the step and two halves, with error control two halves and four quarters)");
  cmd->add_option("--output-step", a->output_step, "output interval [s]");
  cmd->add_flag("--quiet", a->quiet, "no progress bar");
  cmd->add_option("--max-samples", a->max_samples, "refuse runs that would record more output samples")->capture_default_str();
  cmd->add_option("--divergence-bound", a->divergence_bound, "end the run when a state entry grows past this")->capture_default_str();
  add_plant_flags(cmd, a->plant);
  a->cmd = cmd;
  cmd->callback([a] {
    set_exit_code(run_guarded([&] { run_simulate(*a); }));
  });
}

}  // namespace codyna::cli
