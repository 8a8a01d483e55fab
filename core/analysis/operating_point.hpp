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

OperatingPoint snapshot_point(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& u);

}  // namespace codyna
