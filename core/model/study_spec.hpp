// StudySpec: the choices a user makes around a model for one study of it, kept
// in the model file's "analysis" section (docs/model-format.md) so that a saved
// session comes back as it was. The command line's flags and the GUI's widgets
// only fill this description; core's workflow functions (study/workflow.hpp)
// run it. Nothing here is validated against the model: the workflow does that
// when it runs (unknown names are errors there, with the field's path).
#pragma once

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace codyna {

// A reference signal r(t) for one Plant/Out output, in the output's unit. Before `time`
// it is the operating point's y0; after it:
//   step   value                                  (an absolute value, not an increment)
//   ramp   y0 + slope (t - time)
//   sine   y0 + amplitude sin(2 pi frequency (t - time) + phase)
//   table  piecewise linear through points [[t, r], ...], held beyond the ends
//   file   a table read from `file` (io/signal_file.hpp: CSV t,value with a header, or a
//          .mat with vectors t and value); the workflow reads it into `points` when it runs
struct SignalSpec {
  std::string output;         // Plant/Out name (references)
  std::string type = "step";  // step | ramp | sine | table | file
  double time = 0.0;          // s
  double value = 0.0;         // step
  double slope = 0.0;         // ramp, unit/s
  double amplitude = 0.0, frequency = 0.0, phase = 0.0;  // sine: unit, Hz, rad
  std::vector<std::pair<double, double>> points;         // table: (t, r), t increasing
  std::string file;           // file: the time series; relative = to the model file's folder
  bool operator==(const SignalSpec&) const = default;
};

// A disturbance d(t) added to an actuator that is not a Plant/In input (a force on the cart
// of a pendulum): the actuator's value is u0 + d(t), then limited to its [min, max] like any
// actuator's. d(t) is the signal about a base of 0: a step of `value` adds `value` after `time`.
struct DisturbanceSpec : SignalSpec {
  std::string actuator;       // actuator name (not Plant/In)
  bool operator==(const DisturbanceSpec&) const = default;
};

// The linear closed-loop analysis (analysis/closed_loop_linear.hpp): the plant and the
// study's controller as one linear system, its poles, step and frequency responses.
struct ClosedLoopSpec {
  bool enabled = false;          // `codyna linearize` also exports NAME_cl.{m,mat} and the curves
  double step_time = 0.0;        // s, end of the step responses; 0 = from the slowest pole
  int step_points = 501;         // samples of each step response (>= 2)
  double frequency_min = 0.0;    // rad/s, log grid of the frequency responses; 0 = from the poles
  double frequency_max = 0.0;    // rad/s; 0 = from the poles
  int frequency_points = 200;    // (>= 2)
  bool operator==(const ClosedLoopSpec&) const = default;
};

// r(t) of a signal about the base value y0
double signal_value(const SignalSpec& s, double t, double y0);
// its rate and acceleration (right-continuous: a ramp's rate is its slope from `time` on), and
// the times where its rate jumps: what a motion input driven by it needs
double signal_rate(const SignalSpec& s, double t);
double signal_acceleration(const SignalSpec& s, double t);
std::vector<double> signal_rate_jumps(const SignalSpec& s);

// The steady motion of operating point "steady" (analysis/operating_point.hpp, SteadyMotionSpec):
// the body whose speed and turn are given ("" = the first body on a free or planar joint to
// ground), its forward speed (unset = as at the start) and at most one of yaw rate, path radius
// (> 0 left) and lateral acceleration (> 0 left); none = straight.
struct SteadySpec {
  std::string body;
  std::optional<double> speed, yaw_rate, radius, lateral_acceleration;
  bool operator==(const SteadySpec&) const = default;
};

// The handling numbers at a steady motion (analysis/handling.hpp): the Plant/In steer input, the
// Plant/Out yaw rate and, when the model has them, lateral acceleration and sideslip; the
// wheelbase (unset = the distance between the foremost and the rearmost tire along the heading);
// the steering ratio: steer input per road-wheel angle (unset = 1: the steer is the road wheels'
// angle; a steering wheel's angle through a 16:1 gear is 16).
struct HandlingSpec {
  std::string steer, yaw_rate, lateral_acceleration, sideslip;
  std::optional<double> wheelbase, steering_ratio;
  bool operator==(const HandlingSpec&) const = default;
};

struct StudySpec {
  // effects (ModelSpec::effects, by name) switched off for this study: they are
  // left out of the compiled model, so a run never evaluates them
  std::vector<std::string> disabled_effects;

  // operating point: "initial", "equilibrium", "trim", "steady" or "time=T" (T >= 0, seconds)
  std::string operating_point = "equilibrium";
  // the held coordinates of the operating-point search (`--hold`, alias `--set`): joint
  // coordinates and rates (q names as `codyna info` prints them, rates as NAME_dot) set in
  // the model's initial state before anything runs, the loops re-assembled with them held;
  // the equilibrium and trim searches start there and keep them exactly
  std::vector<std::pair<std::string, double>> set;
  // the simulation's initial state (`--initial`), apart from the operating point: the same
  // names, set on top of the state above and assembled onto the loops with them held. The
  // operating point is searched from the model's state, not from this one; only the runs
  // (simulate, linearize --trajectory) start here.
  std::vector<std::pair<std::string, double>> initial;
  // where a run starts: "model" (the model's state, the coordinates set and `initial` on it) or
  // "operating-point" (the point the controller's plant is linearized about, or the study's
  // operating point without a plant; `initial` sets coordinates on top of it: an offset from the
  // point, a disturbed start). `--initial operating-point` on the command line.
  std::string start = "model";
  // closed loops: the independent coordinates (empty = automatic choice)
  std::vector<std::string> independent;
  // the steady-state search (operating points equilibrium and trim), as
  // Simulink Control Design's operspec: coordinates set above are held
  // exactly; a trim holds every independent coordinate except `trim_free`
  // (solved), an equilibrium solves every coordinate not set; `free_inputs`
  // are the Plant/In inputs solved for (a trim's default: all of Plant/In; an
  // equilibrium's: none), within their limits; `output_targets` are Plant/Out
  // values the steady state must reach
  std::vector<std::string> trim_free;
  std::vector<std::string> free_inputs;
  std::vector<std::pair<std::string, double>> output_targets;
  // operating point "steady": the motion held (the free_inputs, held coordinates and output
  // targets above apply to it too)
  SteadySpec steady;
  // handling numbers at a steady motion: computed when `steer` and `yaw_rate` are named
  HandlingSpec handling;

  // linearization and export
  std::string method = "exact";  // "exact", "fd-forward", "fd-central"
  double discrete = 0.0;         // > 0: exact zero-order-hold discrete model with this sample time
  std::string mat_version = "5"; // "5" or "7.3"
  std::string export_name;       // plant name; "" = the model's name as a MATLAB identifier
  std::string export_dir;        // where NAME.m + NAME.mat go; "" = asked at export; relative = to the model file

  // simulation (integrator, tolerances and times are the model's "solver" section)
  std::string controller = "model";  // "model" (the model file's controller, if any), "none", "lqr", "file"
  std::string controller_file;       // "file": a .mat (K, Kp/Ki/Kd or Ac/Bc/Cc/Dc); relative = to the model file
  std::vector<double> q_weights, r_weights;  // "lqr": diagonals of Q (nx) and R (nu); empty = identity
  // "lqr" on a plant that is not stabilizable: design on the controllable part only
  // (control/lqr_controllable.hpp); the modes the inputs cannot move are named and stay as
  // they are. Off by default: without it such a plant is an error that names those modes.
  bool lqr_controllable_part = false;
  bool compare_linear = false;       // also run the linear closed loop beside the nonlinear one
  // the region where the linear parts are trusted: |coordinate - its operating-point value| <= this
  // (rad or m) on the coordinates the linear dynamics depend on (study_linear_region)
  double linear_region = 0.5;
  // time-varying references on Plant/Out outputs (the others stay at y0); every controller
  // type follows them: PID acts on r - y, state feedback adds Nbar (r - y0), LTI sees y - r
  std::vector<SignalSpec> references;
  // disturbances d(t) added to actuators that are not Plant/In (in the nonlinear run and,
  // through those actuators' B and D columns, in the linear comparison and closed loop)
  std::vector<DisturbanceSpec> disturbances;
  // PID anti-windup when an actuator sits at its min/max: "none" (the default: the integral
  // runs on), "back_calculation" (dxi/dt = r - y + pinv(Ki) (u_applied - u) / tracking_time)
  // or "conditional" (an integral is held while it would drive a saturated input further)
  std::string anti_windup = "none";
  double tracking_time = 0.0;        // s, > 0: back_calculation's time constant
  ClosedLoopSpec closed_loop;

  bool operator==(const StudySpec&) const = default;
};

// the accepted words, for messages and for the GUI's choices
inline const std::vector<std::string>& study_methods() {
  static const std::vector<std::string> v{"exact", "fd-forward", "fd-central"};
  return v;
}
inline const std::vector<std::string>& signal_types() {
  static const std::vector<std::string> v{"step", "ramp", "sine", "table", "file"};
  return v;
}
inline const std::vector<std::string>& anti_windup_methods() {
  static const std::vector<std::string> v{"none", "back_calculation", "conditional"};
  return v;
}
inline const std::vector<std::string>& study_starts() {
  static const std::vector<std::string> v{"model", "operating-point"};
  return v;
}
inline const std::vector<std::string>& study_controllers() {
  static const std::vector<std::string> v{"model", "none", "lqr", "file"};
  return v;
}

inline double signal_value(const SignalSpec& s, double t, double y0) {
  if (s.type == "table" || s.type == "file") {
    const auto& p = s.points;
    if (p.empty()) return y0;
    if (t <= p.front().first) return p.front().second;
    for (std::size_t k = 1; k < p.size(); ++k)
      if (t <= p[k].first) {
        const double a = (t - p[k - 1].first) / (p[k].first - p[k - 1].first);
        return p[k - 1].second + a * (p[k].second - p[k - 1].second);
      }
    return p.back().second;
  }
  if (t < s.time) return y0;
  if (s.type == "step") return s.value;
  if (s.type == "ramp") return y0 + s.slope * (t - s.time);
  if (s.type == "sine") return y0 + s.amplitude * std::sin(2 * std::numbers::pi * s.frequency * (t - s.time) + s.phase);
  return y0;
}

inline double signal_rate(const SignalSpec& s, double t) {
  if (s.type == "table" || s.type == "file") {
    const auto& p = s.points;
    for (std::size_t k = 1; k < p.size(); ++k)
      if (t >= p[k - 1].first && t < p[k].first) return (p[k].second - p[k - 1].second) / (p[k].first - p[k - 1].first);
    return 0.0;
  }
  if (t < s.time) return 0.0;
  const double w = 2 * std::numbers::pi * s.frequency;
  if (s.type == "ramp") return s.slope;
  if (s.type == "sine") return s.amplitude * w * std::cos(w * (t - s.time) + s.phase);
  return 0.0;
}

inline double signal_acceleration(const SignalSpec& s, double t) {
  if (s.type != "sine" || t < s.time) return 0.0;
  const double w = 2 * std::numbers::pi * s.frequency;
  return -s.amplitude * w * w * std::sin(w * (t - s.time) + s.phase);
}

inline std::vector<double> signal_rate_jumps(const SignalSpec& s) {
  if (s.type == "table" || s.type == "file") {
    std::vector<double> t;
    for (const auto& p : s.points) t.push_back(p.first);
    return t;
  }
  if (s.type == "ramp" || s.type == "sine") return {s.time};
  return {};
}

}  // namespace codyna
