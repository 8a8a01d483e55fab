// codyna maneuver: the standard handling maneuvers with their metrics (study/maneuver_job.hpp).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/maneuver_job.hpp"

namespace codyna::cli {

namespace {

struct ManeuverArgs {
  std::string model, type, out, csv, x, y, yaw, speed_output, drive, integrator;
  std::vector<std::string> free_inputs;
  double speed = 0, steer = 0, steer_time = 0, ramp = 0, frequency = 0, dwell = 0, dwell_roll_rate = 0, t_end = 0, output_step = 0;
  double steer_scale = 0, frequency_min = 0, frequency_max = 0, sweep_time = 0, ay_min = 0, ay_max = 0;
  double radius = 0, speed_min = 0, speed_max = 0, width = 0, length = 0, preview = 0, lateral_gain = 0;
  double speed_kp = 0, speed_ki = 0, sample_time = 0;
  double friction = 0, steer_rate = 0;
  int points = 0;
  bool open_loop = false;
};

void run_maneuver(const ManeuverArgs& a, const CLI::App* cmd) {
  ManeuverRequest r;
  r.model = a.model;
  r.type = a.type;
  r.out = a.out;
  r.csv = a.csv;
  const auto num = [cmd](const char* flag, double v, std::optional<double>& into) {
    if (given(cmd, flag)) into = v;
  };
  num("--speed", a.speed, r.speed);
  num("--steer", a.steer, r.steer);
  num("--steer-time", a.steer_time, r.steer_time);
  num("--ramp", a.ramp, r.ramp);
  num("--frequency", a.frequency, r.frequency);
  num("--dwell", a.dwell, r.dwell);
  num("--dwell-roll-rate", a.dwell_roll_rate, r.dwell_roll_rate);
  num("--steer-scale", a.steer_scale, r.steer_scale);
  num("--frequency-min", a.frequency_min, r.frequency_min);
  num("--frequency-max", a.frequency_max, r.frequency_max);
  num("--sweep-time", a.sweep_time, r.sweep_time);
  num("--t-end", a.t_end, r.t_end);
  num("--output-step", a.output_step, r.output_step);
  num("--radius", a.radius, r.radius);
  num("--speed-min", a.speed_min, r.speed_min);
  num("--speed-max", a.speed_max, r.speed_max);
  num("--ay-min", a.ay_min, r.ay_min);
  num("--ay-max", a.ay_max, r.ay_max);
  num("--width", a.width, r.width);
  num("--length", a.length, r.length);
  num("--preview", a.preview, r.preview);
  num("--lateral-gain", a.lateral_gain, r.lateral_gain);
  num("--speed-kp", a.speed_kp, r.speed_kp);
  num("--speed-ki", a.speed_ki, r.speed_ki);
  num("--sample-time", a.sample_time, r.sample_time);
  num("--friction", a.friction, r.friction);
  num("--steer-rate", a.steer_rate, r.steer_rate);
  r.open_loop = a.open_loop;
  if (given(cmd, "--points")) r.points = a.points;
  if (given(cmd, "--x")) r.x = a.x;
  if (given(cmd, "--y")) r.y = a.y;
  if (given(cmd, "--yaw")) r.yaw = a.yaw;
  if (given(cmd, "--speed-output")) r.speed_output = a.speed_output;
  if (given(cmd, "--drive")) r.drive = a.drive;
  if (given(cmd, "--integrator")) r.integrator = a.integrator;
  if (given(cmd, "--free-input")) r.free_inputs = a.free_inputs;
  const ModelSpec spec = load_spec(a.model);
  const ManeuverReport rep = study_maneuver_job(r, spec, print_message);
  std::cout << study_maneuver_text(rep);
  if (!rep.valid) throw std::runtime_error("the metrics are invalid: " + rep.invalid_reason);
}

}  // namespace

void add_maneuver(CLI::App& app) {
  auto a = std::make_shared<ManeuverArgs>();
  auto* cmd = app.add_subcommand("maneuver", "Run a standard handling maneuver (step steer, sine with dwell, swept sine, double lane change, constant radius, constant speed, slowly increasing steer, fishhook) and print its metrics");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--type", a->type, "step-steer | sine-with-dwell | swept-sine | double-lane-change | constant-radius | constant-speed | slowly-increasing-steer | fishhook")->required();
  cmd->add_option("--out", a->out, "the run as an HDF5 results file");
  cmd->add_option("--csv", a->csv, "the run as CSV (constant radius, constant speed: the table)");
  cmd->add_option("--speed", a->speed, "m/s, the straight run's speed (default: the model file's steady motion)");
  cmd->add_option("--steer", a->steer, "steer amplitude in the steer input's units (step: 0.01, sine: 0.05)");
  cmd->add_option("--steer-time", a->steer_time, "s, when the steer starts (default 0.5)");
  cmd->add_option("--ramp", a->ramp, "s, the step's ramp (half cosine; default 0.05)");
  cmd->add_option("--frequency", a->frequency, "Hz, sine with dwell (default 0.7)");
  cmd->add_option("--dwell", a->dwell, "s, sine with dwell (default 0.5), fishhook (default 0.25)");
  cmd->add_option("--dwell-roll-rate", a->dwell_roll_rate, "deg/s, fishhook: the dwell ends when the roll rate falls back to it (NHTSA's roll-rate feedback: 1.5)");
  cmd->add_option("--steer-scale", a->steer_scale, "the amplitude as a multiple of the steady steer at 0.3 g (sine with dwell, FMVSS 126: 5 .. 6.5; slowly increasing steer: default 2.5; fishhook: 6.5)");
  cmd->add_option("--steer-rate", a->steer_rate, "slowly increasing steer, fishhook: the steer's rate per s (13.5 deg/s, 720 deg/s, in rad)");
  cmd->add_option("--frequency-min", a->frequency_min, "Hz, swept sine's first frequency (default 0.1)");
  cmd->add_option("--frequency-max", a->frequency_max, "Hz, swept sine's last (default 2)");
  cmd->add_option("--sweep-time", a->sweep_time, "s, swept sine's sweep (default 30; 5 s at rest follow)");
  cmd->add_option("--t-end", a->t_end, "s, the run's length");
  cmd->add_option("--output-step", a->output_step, "s, open-loop runs' output step (default 0.005)");
  cmd->add_option("--radius", a->radius, "m, constant radius (> 0 left)");
  cmd->add_option("--speed-min", a->speed_min, "m/s, constant radius's first speed (default 5)");
  cmd->add_option("--speed-max", a->speed_max, "m/s, its last (default the speed of 0.6 g)");
  cmd->add_option("--ay-min", a->ay_min, "m/s^2, constant speed's first lateral acceleration (default 0.5; > 0 left)");
  cmd->add_option("--ay-max", a->ay_max, "m/s^2, its last (default 0.6 g)");
  cmd->add_option("--points", a->points, "constant radius, constant speed: the number of turns (default 8); swept sine: of the table's frequencies (12)");
  cmd->add_option("--width", a->width, "m, vehicle width for the ISO 3888-1 lane (default 1.8)");
  cmd->add_option("--length", a->length, "m, vehicle length for the cones (default 4.5)");
  cmd->add_option("--preview", a->preview, "m, the driver's look-ahead distance");
  cmd->add_option("--lateral-gain", a->lateral_gain, "rad/(m s), the driver's integral gain on the lateral error");
  cmd->add_option("--speed-kp", a->speed_kp, "the driver's speed PI: drive input per m/s");
  cmd->add_option("--speed-ki", a->speed_ki, "the driver's speed PI: drive input per m");
  cmd->add_option("--sample-time", a->sample_time, "s, the driver's sample time (default 0.01)");
  cmd->add_option("--x", a->x, "the Plant/Out output of the car's x position (default x)");
  cmd->add_option("--y", a->y, "the Plant/Out output of its y position (default y)");
  cmd->add_option("--yaw", a->yaw, "the Plant/Out output of its heading (default yaw)");
  cmd->add_option("--speed-output", a->speed_output, "the Plant/Out output of its forward speed (default speed)");
  cmd->add_option("--drive", a->drive, "the Plant/In input the speed controller drives (default: none)");
  cmd->add_flag("--open-loop", a->open_loop, "leave the model file's controller out (step steer and sine with dwell run it in the loop, on its Plant/In)");
  cmd->add_option("--friction", a->friction, "the road friction the controller's yaw-rate reference is limited by (mu g / U; default 0.85)");
  cmd->add_option("--integrator", a->integrator, "the runs' integrator (default: the model file's)");
  cmd->add_option("--free-input", a->free_inputs, "the steady motion's free inputs (a turn: steer,drive)")->delimiter(',');
  cmd->callback([a, cmd] { set_exit_code(run_guarded([&] { run_maneuver(*a, cmd); })); });
}

}  // namespace codyna::cli
