// codyna linearize: flags -> a LinearizeRequest, one study call (study_linearize_job), and the
// printing. What the flags mean and every computation live in core/study/.
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "study/jobs.hpp"

namespace codyna::cli {

namespace {
// with rolling: the rates apart from the coordinates
std::string rates_said(const Model& m) {
  return m.active_velocity_rows > 0 ? ", " + std::to_string(m.rate_dof()) + " rates" : std::string();
}

struct LinearizeArgs {
  std::string model, out, method = "exact", mat_version = "5", name, controller;
  double discrete = 0.0, trajectory = 0.0, trajectory_step = 0.0;
  bool closed_loop = false;
  PointFlags point;
  LqrFlags lqr;
  PlantFlags plant;
  const CLI::App* cmd = nullptr;  // to tell given flags (they override the file's analysis section)
};

LinearizeRequest request_of(const LinearizeArgs& a) {
  LinearizeRequest r;
  r.model = a.model;
  r.out = a.out;
  r.plant = plant_request(a.plant, a.cmd);
  r.point = point_request(a.point, a.cmd);
  if (given(a.cmd, "--method")) r.method = a.method;
  if (given(a.cmd, "--discrete")) r.discrete = a.discrete;
  if (given(a.cmd, "--mat-version")) r.mat_version = a.mat_version;
  if (given(a.cmd, "--name")) r.name = a.name;
  r.closed_loop = a.closed_loop;
  if (!a.controller.empty()) r.controller = a.controller;
  apply_lqr_flags(a.lqr, a.cmd, r);
  if (given(a.cmd, "--trajectory")) r.trajectory = a.trajectory;
  if (given(a.cmd, "--trajectory-step")) r.trajectory_step = a.trajectory_step;
  return r;
}

void print_trajectory(const LinearizeJob& job) {
  const Model& m = job.model;
  std::cout << "model            " << m.name << " (" << m.dof() << " DOF" << rates_said(m) << ")\n"
            << "trajectory       " << job.systems.size() << " points, t = 0 .. " << job.times.back() << " s, "
            << job.trajectory_controller << "\n"
            << "method           " << job.method << "\n"
            << "states           ";
  for (std::size_t k = 0; k < job.systems[0].state_names.size(); ++k)
    std::cout << (k ? ", " : "") << job.systems[0].state_names[k];
  std::cout << "\n\n     t [s]   max Re(eig A)   min Re(eig A)\n";
  const std::size_t every = std::max<std::size_t>(1, job.systems.size() / 10);
  for (std::size_t k = 0; k < job.systems.size(); k += every) {
    const auto i = static_cast<Eigen::Index>(k);
    std::cout << std::setw(10) << job.times[k] << std::setw(16) << job.max_real[i] << std::setw(16) << job.min_real[i] << "\n";
  }
  std::cout << "\nwrote " << job.written[0] << "\nwrote " << job.written[1] << "\n";
}

// the study's controller around the plant: NAME_cl.{mat,m} and the step and frequency curves
void print_closed_loop(const LinearizeJob& job) {
  const StudyClosedLoop& cl = *job.closed_loop;
  for (const std::string& n : cl.setup.notes) std::cerr << "codyna: note: " << n << "\n";
  for (const std::string& n : cl.notes) std::cerr << "codyna: note: closed loop: " << n << "\n";
  const LinearSystem& s = cl.loop.system;
  std::cout << "\nclosed loop      " << cl.loop.controller << " (" << cl.setup.controller_source << "), "
            << s.nx() << " states, " << (s.Ts > 0 ? "discrete, Ts = " + std::to_string(s.Ts) : std::string("continuous")) << "\n"
            << "inputs           ";
  for (std::size_t k = 0; k < s.input_names.size(); ++k) std::cout << (k ? ", " : "") << s.input_names[k];
  std::cout << "\noutputs          ";
  for (std::size_t k = 0; k < s.output_names.size(); ++k) std::cout << (k ? ", " : "") << s.output_names[k];
  std::cout << "\n\n" << study_format_modes(cl.poles) << "\n";
  for (const std::string& f : job.closed_loop_written) std::cout << "wrote " << f << "\n";
}

void print(const LinearizeJob& job) {
  const Model& m = job.model;
  const OperatingPoint& op = job.linearization.op;
  const Linearization& lin = job.linearization.lin;
  const LinearSystem& sys = job.linearization.system;
  std::cout << "model            " << m.name << " (" << m.dof() << " DOF" << rates_said(m) << ")\n"
            << "operating point  " << op.kind;
  if (op.kind == "equilibrium" || op.kind == "trim" || op.kind == "steady")
    std::cout << " (residual " << op.residual << ", " << op.iterations << " iterations)";
  if (op.motion) std::cout << "\nmotion           " << study_motion_text(m, op);
  std::cout << "\nmethod           " << job.method;
  if (job.method != "exact") std::cout << " (max relative difference from exact: " << lin.fd_error << ")";
  std::cout << "\ntime             " << (sys.Ts > 0 ? "discrete, Ts = " + std::to_string(sys.Ts) : std::string("continuous")) << "\n";
  if (!lin.partition.dependent.empty()) {
    std::cout << "independent      ";
    for (std::size_t k = 0; k < lin.partition.independent.size(); ++k)
      std::cout << (k ? ", " : "") << m.v_names[lin.partition.independent[k]];
    std::cout << "\n";
  }
  if (!lin.partition.rate_dependent.empty()) {
    // rolling: these coordinates are states, their rates follow from the others'
    std::cout << "rates not states ";
    for (std::size_t k = 0; k < lin.partition.rate_dependent.size(); ++k)
      std::cout << (k ? ", " : "") << m.rate_names[lin.partition.rate_dependent[k]];
    std::cout << " (they follow from the rolling conditions)\n";
  }
  for (int i = 0; i < sys.nx(); ++i)
    if (sys.shifted(i))  // a motion input's realization: not the physical rate its name began as
      std::cout << "shifted state    " << sys.state_names[static_cast<std::size_t>(i)] << " = " << state_meaning(sys, i)
                << " (motion inputs enter without their rates; the .mat holds state_shift)\n";
  std::cout << "\n";
  std::cout << "x0\n" << name_values(sys.state_names, sys.x0) << "u0\n" << name_values(sys.input_names, sys.u0)
            << "y0\n" << name_values(sys.output_names, sys.y0) << "xdot0\n" << name_values(sys.state_names, sys.xdot0) << "\n";
  print_matrix("A", sys.A, sys.state_names, sys.state_names);
  print_matrix("B", sys.B, sys.state_names, sys.input_names);
  print_matrix("C", sys.C, sys.output_names, sys.state_names);
  print_matrix("D", sys.D, sys.output_names, sys.input_names);
  std::cout << "\n" << study_format_modes(job.modes) << "\n";
  std::cout << "controllable     " << study_hidden_modes_text(job.uncontrollable) << "\n"
            << "observable       " << study_hidden_modes_text(job.unobservable) << "\n\n";
  if (job.linearization.handling) std::cout << study_handling_text(*job.linearization.handling) << "\n";
  std::cout << "wrote " << job.written[0] << "\nwrote " << job.written[1] << "\n";
  if (job.closed_loop) print_closed_loop(job);
}

void run(const LinearizeArgs& a) {
  const LinearizeRequest r = request_of(a);
  const LinearizeJob job = study_linearize_job(r, load_spec(a.model), print_message);
  if (job.trajectory) print_trajectory(job);
  else print(job);
}

}  // namespace

void add_linearize(CLI::App& app) {
  auto a = std::make_shared<LinearizeArgs>();
  auto* cmd = app.add_subcommand("linearize", "Linearize the plant (Plant/In -> Plant/Out) and export NAME.mat + NAME.m");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--out", a->out, "output directory (created if missing)")->required();
  add_point_flags(cmd, a->point, "initial | equilibrium | trim | steady | time=T",
                  "NAME=VALUE: hold a joint coordinate (or rate, NAME_dot) in the operating-point search: set in the model's state and kept exactly by the equilibrium and trim searches (repeatable; --set is the older name)",
                  "NAME=VALUE: with --trajectory, the simulation's initial state (repeatable); the operating point does not depend on it");
  cmd->add_option("--method", a->method, "exact | fd-forward | fd-central")->capture_default_str();
  cmd->add_option("--discrete", a->discrete, "sample time Ts > 0: exact zero-order-hold discrete model");
  cmd->add_option("--mat-version", a->mat_version, "5 | 7.3")->capture_default_str();
  cmd->add_option("--trajectory", a->trajectory, "T: linearize along a simulation from 0 to T (the model's controller in the loop, if any) instead of at one point");
  cmd->add_option("--trajectory-step", a->trajectory_step, "DT: spacing of the points along the trajectory (default: the model's output_step)");
  cmd->add_option("--name", a->name, "plant name (default: the model name as a MATLAB identifier)");
  cmd->add_flag("--closed-loop", a->closed_loop, "also export the linear closed loop with the study's controller: NAME_cl.mat + NAME_cl.m, NAME_cl_step.csv, NAME_cl_freq.csv");
  cmd->add_option("--controller", a->controller, "the closed loop's controller: a .mat with K, Kp/Ki/Kd or Ac,Bc,Cc,Dc[,Ts] (as simulate --controller)");
  add_lqr_flags(cmd, a->lqr, "the closed loop's controller: an LQR designed on this plant",
                "with --lqr on a plant that is not stabilizable: design on the controllable part");
  add_plant_flags(cmd, a->plant);
  a->cmd = cmd;
  cmd->callback([a] { set_exit_code(run_guarded([&] { run(*a); })); });
}

}  // namespace codyna::cli
