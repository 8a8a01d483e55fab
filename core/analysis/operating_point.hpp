// Operating points: where a plant is linearized.
//   initial_point        the model's assembled initial state, actuators at u0
//   static_equilibrium   the configuration at rest (v = 0) where the accelerations
//                        vanish for the given actuator values (Newton on the
//                        independent coordinates, minimum-norm steps so neutral
//                        directions such as a cart's position stay where they are)
//   trim                 the Plant/In values that hold a given configuration at rest
//                        (least squares when there are fewer inputs than DOF;
//                        the residual says how well it holds)
//   snapshot_point       a state reached by simulation at time t
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "analysis/steady_motion.hpp"
#include "model/model.hpp"

namespace codyna {

struct OperatingPoint {
  std::string kind = "initial";  // "initial", "equilibrium", "trim", "time=T"
  double t = 0.0;
  Eigen::VectorXd q, v;          // nq, nv (on the constraint manifold)
  Eigen::VectorXd u;             // one value per actuator (Model::actuators)
  // the effect states (Model::ns: the tires' transient slip); empty: at rest at (q, v)
  // (effect_states_steady), which every operating point codyna finds is
  Eigen::VectorXd s;
  double residual = 0.0;         // max |qdd| left by equilibrium / trim
  int iterations = 0;
  // a steady motion (steady_motion below): the frame the state moves with; linearize() takes
  // the state's deviation from the pose that moves with it (steady_motion.hpp)
  std::optional<SteadyMotion> motion;
};

OperatingPoint initial_point(const Model& model);

// independent: coordinate names for closed loops (empty = automatic choice)
OperatingPoint static_equilibrium(const Model& model, const OperatingPoint& start,
                                  const std::vector<std::string>& independent = {});

OperatingPoint trim(const Model& model, const OperatingPoint& start, const std::vector<std::string>& independent = {});

// A steady state with known and unknown parts (Simulink Control Design's
// operspec, Adams' locked initial conditions): at rest (v = 0), the
// accelerations vanish; the coordinates `held` keep their start values
// exactly, the other independent coordinates are solved; the Plant/In inputs
// `free_inputs` are solved within their actuators' limits, the others keep
// their start values; each Plant/Out output named in `outputs` reaches its
// value. Gauss-Newton with minimum-norm steps on the unknowns. A free input
// that would leave its limits is held at the limit and the rest solved again;
// when that fails, the error names the limit that binds. Throws
// std::invalid_argument for an unknown name, and ConvergenceError when no
// steady state is found (saying what is left, the unknowns and what to free).
struct SteadyStateSpec {
  std::vector<std::string> held;         // coordinates (Model::v_names) held at their start values
  std::vector<std::string> free_inputs;  // Plant/In actuator names solved for
  std::vector<std::pair<std::string, double>> outputs;  // Plant/Out name -> value to reach
};

OperatingPoint steady_state(const Model& model, const OperatingPoint& start, const SteadyStateSpec& spec,
                            const std::vector<std::string>& independent = {}, const std::string& kind = "trim");

// The verdict on an equilibrium or trim found by the two searches above (which return their
// best effort): a residual at or above `tolerance` throws ConvergenceError (model/errors.hpp)
// naming the residual, the coordinate it is largest on, the unknowns and what to free.
// steady_state gives that verdict itself.
void require_steady_state(const Model& model, const OperatingPoint& op, const std::vector<std::string>& independent = {},
                          double tolerance = 1e-8);

// What to free when a steady state is not found (for messages): the Plant/In inputs not free,
// the coordinates held; `kind` "trim" frees held coordinates, an equilibrium holds fewer.
std::string steady_state_advice(const std::vector<std::string>& plant_inputs, const std::vector<std::string>& fixed_inputs,
                                const std::vector<std::string>& held, const std::string& kind);

// A steady motion (issue 39): a car straight at a speed or in a steady turn, a disc rolling. The
// body `body` (on a free or planar joint to ground; "" = the first such body) moves at forward
// speed `speed` (of its centre of mass along its heading: its x axis in the road plane, or for a
// body symmetric about an axle the direction it rolls; default: as at the start) and turns at
// `yaw_rate`, or on a path of `radius` (> 0 left), or at `lateral_acceleration` (> 0 left; at
// most one of the three; none: straight). Solved: the actuators `free_inputs` (any actuator;
// default Plant/In), every coordinate but those the user holds and those along which the motion
// may sit anywhere (the road plane, the heading, wheel spin angles, every coordinate the
// dynamics do not depend on), every velocity, and the moving frame's rates, so that in the frame
// that moves with the motion nothing changes (steady_motion.hpp); `outputs` reach their values.
// The result's `motion` is that frame: linearize() takes A about it. Throws
// std::invalid_argument for a bad spec (naming the field), ConvergenceError when no steady
// motion is found (saying what is left and what to free).
struct SteadyMotionSpec {
  std::string body;
  std::optional<double> speed, yaw_rate, radius, lateral_acceleration;
  std::vector<std::string> free_inputs;
  std::vector<std::string> held;
  std::vector<std::pair<std::string, double>> outputs;
};

OperatingPoint steady_motion(const Model& model, const OperatingPoint& start, const SteadyMotionSpec& spec,
                             const std::vector<std::string>& independent = {});

OperatingPoint snapshot_point(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& u);

}  // namespace codyna
