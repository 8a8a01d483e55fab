// The fixed-step reference integrator: classical Runge-Kutta 4 on
// (q, v) with qd = qdot(q, v), unit quaternions renormalized after each step,
// and (for closed loops) an optional projection back onto the constraint
// manifold. Simple on purpose: tests hold the adaptive integrators against it.
#pragma once

#include <Eigen/Core>

#include "dynamics/data.hpp"

namespace codyna {

struct State {
  Eigen::VectorXd q, v;
};

// One RK4 step of size h with constant actuator values u.
State rk4_step(const Model& model, Data& data, const State& x, const Eigen::VectorXd& u, double h);

// n steps from x; projects onto phi = 0, Jc v = 0 after each step when `project` and the model has loops.
State rk4_integrate(const Model& model, const State& x, const Eigen::VectorXd& u, double h, int n, bool project = true);

}  // namespace codyna
