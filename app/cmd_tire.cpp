// codyna tire: the tire test rig (study/tire_job.hpp) from the command line.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/tire_job.hpp"

namespace codyna::cli {

namespace {

struct TireArgs {
  std::string tir, model, tire, side, out, loads, kappa, alpha, gamma;
  double speed = 16.7;
};

void run_tire(const TireArgs& a, const CLI::App* cmd) {
  TireRequest r;
  r.tir = a.tir;
  r.model = a.model;
  r.tire = a.tire;
  r.side = a.side;
  r.out = a.out;
  r.speed = a.speed;
  if (given(cmd, "--load")) r.loads = study_tire_grid(a.loads, "--load");
  if (given(cmd, "--kappa")) r.kappa = study_tire_grid(a.kappa, "--kappa");
  if (given(cmd, "--alpha")) r.alpha = study_tire_grid(a.alpha, "--alpha");
  if (given(cmd, "--gamma")) r.gamma = study_tire_grid(a.gamma, "--gamma");
  const TireJob job = study_tire_job(r);
  for (const std::string& n : job.notes) std::cerr << "codyna: note: " << n << "\n";
  std::cout << "tire     " << job.tire << "\n"
            << "points   " << job.rows.rows() << " (" << job.columns.size() << " columns: Fx ... Kxk, ISO-W axes, SI units)\n";
  if (!job.written.empty()) std::cout << "wrote " << job.written << "\n";
}

}  // namespace

void add_tire(CLI::App& app) {
  auto a = std::make_shared<TireArgs>();
  auto* cmd = app.add_subcommand("tire", "Evaluate a tire over load, slip, slip angle and camber (the tire test rig): CSV in MFeval's column order");
  cmd->add_option("--tir", a->tir, "a .tir property file (Magic Formula 5.2, 6.1, 6.2)");
  cmd->add_option("--model", a->model, "a model file whose tire element --tire is evaluated (its law and numbers)");
  cmd->add_option("--tire", a->tire, "the model's tire element");
  cmd->add_option("--side", a->side, ".tir: mount on the left or right side (default: as the file)");
  cmd->add_option("--load", a->loads, "vertical loads, N: V, V1,V2,... or A:B:N (default .tir: 0.5, 1, 1.5 FNOMIN)");
  cmd->add_option("--kappa", a->kappa, "longitudinal slips (-), as --load (default 0)");
  cmd->add_option("--alpha", a->alpha, "slip angles, rad, as --load (default 0)");
  cmd->add_option("--gamma", a->gamma, "cambers, rad, as --load (default 0)");
  cmd->add_option("--speed", a->speed, "forward speed Vx, m/s")->capture_default_str();
  cmd->add_option("--out", a->out, "the CSV file to write")->required();
  cmd->callback([a, cmd] { set_exit_code(run_guarded([&] { run_tire(*a, cmd); })); });
}

}  // namespace codyna::cli
