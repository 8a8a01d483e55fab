// StudySpec: the choices a user makes around a model for one study of it, kept
// in the model file's "analysis" section (docs/model-format.md) so that a saved
// session comes back as it was. The command line's flags and the GUI's widgets
// only fill this description; core's workflow functions (study/workflow.hpp)
// run it. Nothing here is validated against the model: the workflow does that
// when it runs (unknown names are errors there, with the field's path).
#pragma once

#include <cmath>
#include <numbers>
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
struct SignalSpec {
  std::string output;         // Plant/Out name
  std::string type = "step";  // step | ramp | sine | table
  double time = 0.0;          // s
  double value = 0.0;         // step
  double slope = 0.0;         // ramp, unit/s
  double amplitude = 0.0, frequency = 0.0, phase = 0.0;  // sine: unit, Hz, rad
  std::vector<std::pair<double, double>> points;         // table: (t, r), t increasing
  bool operator==(const SignalSpec&) const = default;
};

// r(t) of a signal about the base value y0
double signal_value(const SignalSpec& s, double t, double y0);

struct StudySpec {
  // effects (ModelSpec::effects, by name) switched off for this study: they are
  // left out of the compiled model, so a run never evaluates them
  std::vector<std::string> disabled_effects;

  // operating point: "initial", "equilibrium", "trim" or "time=T" (T >= 0, seconds)
  std::string operating_point = "equilibrium";
  // joint coordinates set in the initial state before anything runs (q names as
  // `codyna info` prints them), then the loops are re-assembled
  std::vector<std::pair<std::string, double>> set;
  // closed loops: the independent coordinates (empty = automatic choice)
  std::vector<std::string> independent;

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
  bool compare_linear = false;       // also run the linear closed loop beside the nonlinear one
  // time-varying references on Plant/Out outputs (the others stay at y0); every controller
  // type follows them: PID acts on r - y, state feedback adds Nbar (r - y0), LTI sees y - r
  std::vector<SignalSpec> references;

  bool operator==(const StudySpec&) const = default;
};

// the accepted words, for messages and for the GUI's choices
inline const std::vector<std::string>& study_methods() {
  static const std::vector<std::string> v{"exact", "fd-forward", "fd-central"};
  return v;
}
inline const std::vector<std::string>& signal_types() {
  static const std::vector<std::string> v{"step", "ramp", "sine", "table"};
  return v;
}
inline const std::vector<std::string>& study_controllers() {
  static const std::vector<std::string> v{"model", "none", "lqr", "file"};
  return v;
}

inline double signal_value(const SignalSpec& s, double t, double y0) {
  if (s.type == "table") {
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

}  // namespace codyna
