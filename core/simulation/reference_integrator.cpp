#include "simulation/reference_integrator.hpp"

#include "dynamics/assembly.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"

namespace codyna {

namespace {
// time derivative in ambient coordinates: qd = qdot(q, v) (quaternion rates), vd = qdd
struct Deriv {
  Eigen::VectorXd dq, dv;
};
Deriv f(const Model& m, Data& d, const State& x, const Eigen::VectorXd& u) {
  const Eigen::VectorXd dv = forward_dynamics<double>(m, d, x.q, x.v, u);
  return {qdot<double>(m, x.q, x.v), dv};
}
State advance(const State& x, const Deriv& k, double h) { return {x.q + h * k.dq, x.v + h * k.dv}; }
}  // namespace

State rk4_step(const Model& m, Data& d, const State& x, const Eigen::VectorXd& u, double h) {
  // classical RK4 on the embedding (q in R^nq); the quaternion ODE is exact
  // there, so the method keeps its order; unit length is restored per step
  const Deriv k1 = f(m, d, x, u);
  const Deriv k2 = f(m, d, advance(x, k1, h / 2), u);
  const Deriv k3 = f(m, d, advance(x, k2, h / 2), u);
  const Deriv k4 = f(m, d, advance(x, k3, h), u);
  State r{x.q + h / 6 * (k1.dq + 2 * k2.dq + 2 * k3.dq + k4.dq), x.v + h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv)};
  normalize(m, r.q);
  return r;
}

State rk4_integrate(const Model& m, const State& x0, const Eigen::VectorXd& u, double h, int n, bool project) {
  Data d(m);
  State x = x0;
  AssemblyOptions opt;
  opt.tolerance = 1e-13;
  for (int i = 0; i < n; ++i) {
    x = rk4_step(m, d, x, u, h);
    if (project && m.nc > 0) {
      const AssemblyResult a = assemble(m, x.q, x.v, opt);
      x.q = a.q;
      x.v = a.v;
    }
  }
  return x;
}

}  // namespace codyna
