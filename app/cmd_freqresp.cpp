// codyna freqresp: the frequency response of the nonlinear plant against the linear model's
// (study/freqresp_job.hpp).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/freqresp_job.hpp"

namespace codyna::cli {

namespace {

struct FreqRespArgs {
  std::string model, csv, out, frequencies, controller, integrator;
  std::vector<double> amplitudes;
  bool open_loop = false;
  LqrFlags lqr;
  PointFlags point;
  PlantFlags plant;
  double rtol = 0, atol = 0, max_step = 0;
  int settle_periods = FreqRespRequest{}.settle_periods, periods = FreqRespRequest{}.periods;
  int samples_per_period = FreqRespRequest{}.samples_per_period, harmonics = FreqRespRequest{}.harmonics;
  CLI::App* cmd = nullptr;
};

void run_freqresp(const FreqRespArgs& a) {
  FreqRespRequest r;
  SimulateRequest& s = r.run;
  s.model = a.model;
  s.plant = plant_request(a.plant, a.cmd);
  if (!a.controller.empty()) s.controller = a.controller;
  s.open_loop = a.open_loop;
  apply_lqr_flags(a.lqr, a.cmd, s);
  s.point = point_request(a.point, a.cmd);
  if (!a.integrator.empty()) s.integrator = a.integrator;
  if (given(a.cmd, "--rtol")) s.rtol = a.rtol;
  if (given(a.cmd, "--atol")) s.atol = a.atol;
  if (given(a.cmd, "--max-step")) s.max_step = a.max_step;
  r.frequencies = study_frequency_grid(a.frequencies, "--frequencies");
  r.amplitudes = a.amplitudes;
  r.settle_periods = a.settle_periods;
  r.periods = a.periods;
  r.samples_per_period = a.samples_per_period;
  r.harmonics = a.harmonics;
  r.csv = a.csv;
  r.out = a.out;
  const ModelSpec spec = load_spec(a.model);
  const FreqRespJob job = study_freqresp_job(r, spec, {}, print_message);
  std::cout << study_freqresp_text(job);
  for (const std::string& w : job.written) std::cout << "wrote " << w << "\n";
}

}  // namespace

void add_freqresp(CLI::App& app) {
  auto a = std::make_shared<FreqRespArgs>();
  auto* cmd = app.add_subcommand(
      "freqresp", "Frequency response of the nonlinear plant (a sine on each Plant/In in turn, measured on every Plant/Out) against the linear model's");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--frequencies", a->frequencies, "rad/s: W1,W2,... or A:B:N (N from A to B, log-spaced)")->required();
  cmd->add_option("--amplitude", a->amplitudes, "the sine's amplitude, one for every Plant/In or one each (input units; default 0.01)");
  cmd->add_option("--settle-periods", a->settle_periods, "periods run before measuring (at least; longer when the loop's slowest pole needs it)")->capture_default_str();
  cmd->add_option("--periods", a->periods, "periods measured")->capture_default_str();
  cmd->add_option("--samples-per-period", a->samples_per_period, "output samples per period")->capture_default_str();
  cmd->add_option("--harmonics", a->harmonics, "harmonics fitted (the first is the response)")->capture_default_str();
  cmd->add_option("--csv", a->csv, "write the table as CSV");
  cmd->add_option("--out", a->out, "write the responses as HDF5 (G, the linear G, gaps, distortion per frequency)");
  cmd->add_option("--controller", a->controller, "controller .mat (default: the model file's controller, if any)");
  cmd->add_flag("--open-loop", a->open_loop, "ignore the model's controller: the plant alone (it must be stable)");
  add_lqr_flags(cmd, a->lqr, "close the loop with an LQR designed on the linearized plant (an unstable plant's response is measured in closed loop)",
                "with --lqr on a plant that is not stabilizable: design on the controllable part");
  add_point_flags(cmd, a->point, "the operating point: initial | equilibrium | trim | steady | time=T",
                  "NAME=VALUE: hold a joint coordinate (or rate, NAME_dot) in the operating-point search (repeatable)",
                  "NAME=VALUE: set a joint coordinate in the model's state before the search (repeatable)");
  cmd->add_option("--integrator", a->integrator, integrator_names(" | ") + " (default: the model file's solver)");
  cmd->add_option("--rtol", a->rtol, "relative tolerance");
  cmd->add_option("--atol", a->atol, "absolute tolerance");
  cmd->add_option("--max-step", a->max_step, "largest step [s]");
  add_plant_flags(cmd, a->plant);
  a->cmd = cmd;
  cmd->callback([a] { set_exit_code(run_guarded([&] { run_freqresp(*a); })); });
}

}  // namespace codyna::cli
