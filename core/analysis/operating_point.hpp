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
#include <string>
#include <vector>

#include "model/model.hpp"

namespace codyna {

struct OperatingPoint {
  std::string kind = "initial";  // "initial", "equilibrium", "trim", "time=T"
  double t = 0.0;
  Eigen::VectorXd q, v;          // nq, nv (on the constraint manifold)
  Eigen::VectorXd u;             // one value per actuator (Model::actuators)
  double residual = 0.0;         // max |qdd| left by equilibrium / trim
  int iterations = 0;
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

OperatingPoint snapshot_point(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& u);

}  // namespace codyna
