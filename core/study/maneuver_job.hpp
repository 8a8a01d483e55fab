// Standard handling maneuvers with their metrics (codyna maneuver, Python codyna.maneuver):
//
//   step-steer          ISO 7401: from the steady straight run (the study's steady motion at
//                       --speed), the steer input ramps by --steer over --ramp s (a half cosine:
//                       its rate and acceleration exact, so a motion input takes it) starting at
//                       --steer-time; yaw-rate and lateral-acceleration response times (to 90 %),
//                       peak response times, overshoots and steady-state gains (analysis/
//                       maneuver_metrics.hpp), times from the steer's 50 % point.
//   sine-with-dwell     ISO 19365 / FMVSS 126: one period of a --frequency (0.7 Hz) sine of
//                       amplitude --steer with a --dwell (0.5 s) at its second peak; the yaw-rate
//                       ratios 1.0 and 1.75 s after the steer ends, the lateral displacement of the
//                       steady body's centre of mass 1.07 s after the steer starts.
//   swept-sine          ISO 7401 frequency response: a sine of amplitude --steer whose frequency
//                       rises exponentially over --sweep-time s through the band from
//                       --frequency-min to --frequency-max (Hz; the sweep starts and ends 1.25
//                       times beyond, its first and last twentieth tapered by half cosines), then
//                       5 s at rest; the yaw-rate and lateral-acceleration responses to steer by the
//                       ratio of the transforms (analysis/frequency_estimate.hpp), against the
//                       linearization's; ISO 7401's characteristic values (steady gain, resonance,
//                       peak ratio, phases at 1 Hz) of both.
//   double-lane-change  ISO 3888-1, driven by the driver (simulation/driver.hpp) on the lane's
//                       centre line for a car of --width: the lateral error (max, RMS), and the
//                       cones hit (a --width x --length rectangle about the position outputs).
//                       The driver reads sensors and sets actuators by name (a position, heading
//                       or speed the model has no sensor of is measured on the steady body by
//                       sensors the run adds); the model file's controller runs beside it
//                       (simulate()'s SimulationOptions::beside), its yaw-rate reference from the
//                       driver's held steer.
//   constant-radius     ISO 4138 style: steady turns on one --radius at --points speeds rising from
//                       --speed-min to --speed-max, each the steady motion's search (the file's
//                       study, its free inputs) started from the one before; steer, road-wheel
//                       angle, sideslip and roll over lateral acceleration, the understeer gradient
//                       d(delta)/d(a_y) over a_y, against the linear model's prediction of the
//                       same diagram: at each speed, the linearization about the straight run
//                       (its steer s0(U) and constant-speed yaw-rate gain G(U)) gives the turn's
//                       steer s0 + r / G; its gradient on the same a_y (and, for reference, the
//                       handling number K at the first speed, a constant-speed gradient).
//   constant-speed      ISO 4138 style at one speed (--speed): steady turns at --points lateral
//                       accelerations from --ay-min to --ay-max; the same table, the understeer
//                       gradient d(delta)/d(a_y) - L / U^2, against the linear model's (the handling
//                       number K at that speed, and its prediction of each turn's steer).
//   slowly-increasing-steer  SAE J266 / FMVSS 126 S5.1.2: the steer rises at --steer-rate (13.5
//                       deg/s) to --steer (2.5 x the steer at 0.3 g); the steer at 0.3 g (a_y = U r)
//                       against the steady turn's at the speed there, the understeer gradient fitted
//                       over 0.1 .. 0.3 g against the steady turns' and the handling number
//                       (maneuver_ramp.cpp).
//   fishhook            NHTSA: to --steer (6.5 x the steer at 0.3 g) at --steer-rate (720 deg/s),
//                       --dwell (0.25 s; or, with --dwell-roll-rate R, until the roll rate falls to
//                       R deg/s: NHTSA's roll-rate feedback), to the opposite side, held 3 s, back over 2 s;
//                       the largest roll, each tire's smallest load, the first two-wheel lift.
// Step steer, sine with dwell, slowly increasing steer, fishhook and the double lane change run the model file's controller
// in the loop (ManeuverRequest::open_loop). An open-loop run stops when the car rolls over (60 deg).
// A run that leaves the road (the integrator fails, the speed or yaw rate runs away) is reported
// with its metrics marked invalid and the reason. Files: the run as HDF5 / CSV (--out, --csv;
// the constant radius: --csv, its table).
#pragma once

#include <atomic>
#include <cmath>
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/maneuver_metrics.hpp"
#include "study/jobs.hpp"

namespace codyna {

// the maneuver types, in the order the help lists them
inline constexpr const char* kManeuverTypes[] = {"step-steer",      "sine-with-dwell",         "swept-sine",
                                                 "double-lane-change", "constant-radius",     "constant-speed",
                                                 "slowly-increasing-steer", "fishhook"};

struct ManeuverRequest {
  OptionStyle style = OptionStyle::Flag;
  std::string model;      // the model file
  std::string type;       // one of kManeuverTypes
  std::string out, csv;   // results ("" = not written)
  std::optional<double> speed;                 // m/s (the steady motion's; default the file's)
  std::optional<double> steer;                 // steer input amplitude (step, sine)
  std::optional<double> steer_time, ramp;      // s: when the steer starts (default 0.5), its ramp (0.05)
  std::optional<double> frequency, dwell;      // sine with dwell: Hz (0.7), s (0.5)
  // sine with dwell: the amplitude as a multiple of the steer of the steady turn at 0.3 g at the
  // run's speed (FMVSS 126's 5 .. 6.5 x delta_0.3g); not with steer
  std::optional<double> steer_scale;
  std::optional<double> frequency_min, frequency_max, sweep_time;  // swept sine: Hz (0.1, 2), s (30)
  // slowly increasing steer, fishhook: the steer's rate, steer units per s (13.5 deg/s, 720 deg/s:
  // the standards' at the steering wheel); their amplitude --steer, or --steer-scale times the
  // steady steer at 0.3 g (2.5, 6.5)
  std::optional<double> steer_rate;
  // fishhook with NHTSA's roll-rate feedback: the dwell ends when the steady body's roll rate, having
  // passed it, falls back to this (deg/s; NHTSA: 1.5); not with dwell
  std::optional<double> dwell_roll_rate;
  std::optional<double> t_end, output_step;    // s
  std::optional<std::string> integrator;       // the runs' (default the model file's solver)
  std::optional<double> radius;                // constant radius, m
  std::optional<double> speed_min, speed_max;  // constant radius, m/s
  std::optional<double> ay_min, ay_max;        // constant speed, m/s^2 (0.5, 0.6 g; > 0 turns left)
  std::optional<int> points;                   // constant radius (default 8); swept sine: the table's frequencies (12)
  // the steady motion's free inputs (StudySpec::free_inputs; a turn needs the drive that holds
  // the speed besides the steer): each given replaces the file's list
  std::optional<std::vector<std::string>> free_inputs;
  // the driver (double lane change)
  std::optional<double> width, length, preview, lateral_gain, speed_kp, speed_ki, sample_time;
  std::optional<std::string> x, y, yaw, speed_output, drive;  // Plant/Out / Plant/In names
  // step steer and sine with dwell run the model file's controller in the loop (on its Plant/In,
  // which must not hold the steer; about the straight run), unless open_loop; its reference on the
  // yaw-rate output (when a Plant/Out) is the driver's intended yaw rate, the straight run's steady
  // yaw-rate gain times the steer, within +-friction g / U (friction default 0.85)
  bool open_loop = false;
  std::optional<double> friction;
  // a front end's Cancel (not owned; null: none): the job then throws StudyCancelled
  const std::atomic<bool>* cancel = nullptr;
  // the run's progress (t, t_end), called from the job's thread (runs only, not the steady turns)
  std::function<void(double, double)> progress;
};

struct ManeuverReport {
  std::string type, model_name;
  double speed = 0;                      // m/s at the start
  // open loop: at the run's end, the steady body's speed along its heading in the road plane and
  // its yaw rate about the road's normal (what the steady-motion search takes)
  double end_speed = 0, end_yaw_rate = 0;
  std::vector<std::string> notes, warnings;
  // the controller in the loop ("" = none: open loop), and its yaw-rate reference: gain per steer
  // unit (1/s) and limit (rad/s); 0 when the yaw rate is not a Plant/Out
  std::string controller;
  double reference_gain = 0, reference_limit = 0;
  // per Plant/In of the controller: its name and the largest |u - u0| in the run
  std::vector<std::string> controller_inputs;
  std::vector<double> controller_effort;
  // the steady body's largest sideslip (rad, atan of its lateral over its forward speed) and when
  // (step steer, sine with dwell, swept sine)
  double max_sideslip = 0, max_sideslip_time = 0;
  bool valid = true;
  std::string invalid_reason;            // why the metrics are not to be trusted
  // step steer
  double steer = 0;                      // the step (steer input units)
  StepMetrics yaw_rate, lateral_acceleration;
  bool has_lateral_acceleration = false;
  // sine with dwell
  SineWithDwellMetrics sine;
  // the steer (from the straight run's) of the steady turn at 0.3 g at the run's speed, turning the
  // way the sine starts (NaN: not found; a note says why); FMVSS 126 asks the lateral displacement
  // only of runs at 5 times it or more (sine.passes_fmvss126 then counts it, else not)
  double steer_03g = std::nan("");
  bool displacement_applies = true;
  double steer_start = 0, steer_end = 0;
  // double lane change
  PathErrorMetrics path;
  std::vector<std::string> cones_hit;    // "section 3 at x = 81.2 m" (empty: none)
  // per section with cones (1, 3, 5-6): the smallest distance by which the car's outline inside the
  // section stayed within its lane over the run (m; < 0: it crossed a lane line there, a cone hit;
  // NaN: the run ended before the section)
  std::vector<double> cone_clearance;
  double max_steer = 0;
  // swept sine: the frequency responses to steer on the table's frequencies (Hz), estimated from
  // the run (the ratio of the transforms) and the linear model's (straight-run linearization);
  // ISO 7401's characteristic values of both (on a grid of 200), the largest gaps |H - H_lin| over
  // the linear response's largest |H_lin| and where (Hz)
  std::vector<double> sw_frequency, sw_input_share;
  std::vector<std::complex<double>> sw_yaw, sw_yaw_linear, sw_lateral, sw_lateral_linear;
  SweptSineCharacteristics sw_metrics, sw_metrics_linear;
  bool sw_has_linear = false;
  double sw_gap_yaw = 0, sw_gap_yaw_hz = 0, sw_gap_lateral = 0, sw_gap_lateral_hz = 0;
  // constant radius and constant speed: one entry per point (cr_gradient: constant radius
  // d(delta)/d(a_y), constant speed d(delta)/d(a_y) - L / U^2; so the linear ones)
  double radius = 0;
  std::vector<double> cr_speed, cr_lateral_acceleration, cr_steer, cr_road_wheel, cr_sideslip, cr_roll, cr_gradient;
  bool cr_has_roll = false;
  // the linear model's prediction at each speed (straight-run linearizations: s0(U) + r / G(U)),
  // its understeer diagram on the same a_y (empty when the study has no handling numbers)
  std::vector<double> cr_linear_steer, cr_linear_gradient;
  std::optional<double> linear_gradient;   // cr_linear_gradient's first: the linear model's, rad per m/s^2
  std::optional<double> handling_gradient; // the handling number K at the first speed (constant speed)
  // slowly increasing steer (a_y = U r of the steady body): where |a_y| first reaches 0.3 g, the
  // steer (less the straight run's), the time and the speed, against the steady turn's steer at
  // 0.3 g the same way at that speed (its steer less the straight run's at the start); the understeer gradient from the run, the slope of
  // delta / ratio - L r / U over a_y fitted between 0.1 and 0.3 g (rad per m/s^2, road-wheel angle;
  // NaN when the run does not reach 0.3 g), beside the handling number K (handling_gradient); the
  // largest |a_y| and the steer there
  double sis_steer_03g = std::nan(""), sis_time_03g = std::nan(""), sis_speed_03g = std::nan("");
  double sis_steady_steer_03g = std::nan(""), sis_gradient = std::nan("");
  // the steady turns' gradient over the same range, at the run's speed at 0.3 g: the secant of
  // delta / ratio - L / R between the turns at 0.1 and 0.3 g
  double sis_steady_gradient = std::nan("");
  double sis_ay_max = 0, sis_steer_at_ay_max = 0, sis_time_ay_max = 0;
  // slowly increasing steer: the drive that held the speed and how ("" = none: the drive stays at
  // the straight run's value and the speed falls as the turn tightens)
  std::string speed_hold;
  // fishhook: the steady body's largest |roll| (rad) and when; per tire its name, side ("left" /
  // "right" of the steady body at the start), smallest normal load (N) and when; the first sample
  // at which both tires of one side are off the road (a two-wheel lift: -1 none) and that side;
  // the largest |a_y| (the lateral-acceleration output's, or U r without one)
  double fh_max_roll = 0, fh_max_roll_time = 0, fh_lift_time = -1, fh_ay_max = 0;
  std::string fh_lift_side;
  // the dwell run (s): the one given, or where the roll rate fell to dwell_roll_rate (fh_roll_rate_dwell)
  double fh_dwell = 0;
  bool fh_roll_rate_dwell = false;
  std::vector<std::string> fh_tires, fh_sides;
  std::vector<double> fh_min_load, fh_min_load_time;
  // double lane change: the driver's path and the cones of its gates (at the lane's edges, about
  // every 5 m of a gate), world x, y in the road plane, for a front end to draw
  std::vector<Eigen::Vector2d> lane_path, lane_cones;
  // the run (time series; not for the constant radius)
  SimulationResult result;
  std::vector<std::string> written;
};

// The whole `codyna maneuver`. Refusals name the flag or keyword (style) or the model file's field.
ManeuverReport study_maneuver_job(const ManeuverRequest& r, const ModelSpec& spec, const StudyMessages& tell = {});

// The body whose motion a maneuver reads (the steady body: the study's analysis.steady.body, or
// the first on a free or planar joint to ground): its index in m; throws ModelError without one.
int study_maneuver_body(const Model& m);

// the report as `codyna maneuver` prints it
std::string study_maneuver_text(const ManeuverReport& r);

}  // namespace codyna
