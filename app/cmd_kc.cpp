// codyna kc: the suspension kinematics and compliance rig (study/kc_job.hpp) from the command line.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/kc_job.hpp"

namespace codyna::cli {

namespace {

struct KcArgs {
  std::string model, held, steer, travel, roll, steer_range, fx, fy, mz, csv;
  std::vector<std::string> wheels;
  double radius = 0;
};

void run_kc(const KcArgs& a, const CLI::App* cmd) {
  KcRequest r;
  r.model = a.model;
  r.wheels = a.wheels;
  r.held = a.held;
  r.steer = a.steer;
  r.csv = a.csv;
  if (given(cmd, "--radius")) r.radius = a.radius;
  if (given(cmd, "--travel")) r.travel = study_kc_range(a.travel, "--travel");
  if (given(cmd, "--roll")) r.roll = study_kc_range(a.roll, "--roll");
  if (given(cmd, "--steer-range")) r.steer_range = study_kc_range(a.steer_range, "--steer-range");
  if (given(cmd, "--fx")) r.fx = study_kc_range(a.fx, "--fx");
  if (given(cmd, "--fy")) r.fy = study_kc_range(a.fy, "--fy");
  if (given(cmd, "--mz")) r.mz = study_kc_range(a.mz, "--mz");
  const ModelSpec spec = load_spec(a.model);
  r.spec = &spec;
  const KcReport rep = study_kc_job(r);
  for (const std::string& n : rep.notes) std::cerr << "codyna: note: " << n << "\n";
  std::cout << study_kc_text(rep);
  if (!rep.written.empty()) std::cout << "wrote " << rep.written << "\n";
}

}  // namespace

void add_kc(CLI::App& app) {
  auto a = std::make_shared<KcArgs>();
  auto* cmd = app.add_subcommand("kc", "Suspension kinematics and compliance (the K&C rig): camber, toe, caster, kingpin, track and "
                                       "wheelbase over wheel travel, steer and contact-patch loads, and their gradients");
  cmd->add_option("model", a->model, "model file (JSON): a suspension corner")->required();
  cmd->add_option("--wheel", a->wheels, "the wheel body or its tire element (default: the model's only tire); twice: an axle's two wheels");
  cmd->add_option("--held", a->held, "the body held (default: the root of the wheel's joint tree, the chassis)");
  cmd->add_option("--steer", a->steer, "the motion input that steers (default: the model's only one)");
  cmd->add_option("--radius", a->radius, "m, the wheel's radius (default: its tire's unloaded radius)");
  cmd->add_option("--travel", a->travel, "MIN:MAX:N, m of wheel centre travel from design, up positive (default -0.05:0.05:11 when no sweep is given)");
  cmd->add_option("--roll", a->roll, "MIN:MAX:N, deg of body roll (right hand about x, left side up), an axle (two --wheel)");
  cmd->add_option("--steer-range", a->steer_range, "MIN:MAX:N in the steer input's unit, at design height");
  cmd->add_option("--fx", a->fx, "MIN:MAX:N, N of longitudinal force at each contact patch (a braking force: the spin held)");
  cmd->add_option("--fy", a->fy, "MIN:MAX:N, N of lateral force at the contact patch (left positive)");
  cmd->add_option("--mz", a->mz, "MIN:MAX:N, N m of aligning moment about the vertical");
  cmd->add_option("--csv", a->csv, "the table as CSV");
  cmd->callback([a, cmd] { set_exit_code(run_guarded([&] { run_kc(*a, cmd); })); });
}

}  // namespace codyna::cli
