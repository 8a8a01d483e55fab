// StudySpec: the choices a user makes around a model for one study of it, kept
// in the model file's "analysis" section (docs/model-format.md) so that a saved
// session comes back as it was. The command line's flags and the GUI's widgets
// only fill this description; core's workflow functions (study/workflow.hpp)
// run it. Nothing here is validated against the model: the workflow does that
// when it runs (unknown names are errors there, with the field's path).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace codyna {

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

  bool operator==(const StudySpec&) const = default;
};

// the accepted words, for messages and for the GUI's choices
inline const std::vector<std::string>& study_methods() {
  static const std::vector<std::string> v{"exact", "fd-forward", "fd-central"};
  return v;
}
inline const std::vector<std::string>& study_controllers() {
  static const std::vector<std::string> v{"model", "none", "lqr", "file"};
  return v;
}

}  // namespace codyna
