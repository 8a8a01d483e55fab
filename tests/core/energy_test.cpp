// Passive models conserve energy under the reference integrator; the energy
// functions agree with the dynamics (power balance).
#include "dynamics/energy.hpp"

#include "dynamics/constraints.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "simulation/reference_integrator.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

double energy_of(const Model& m, const State& x) {
  Data d(m);
  return kinetic_energy<double>(m, d, x.q, x.v) + potential_energy<double>(m, d, x.q);
}

void expect_conserved(const Model& m, State x, const Eigen::VectorXd& u, double h, double t_end, double rel_tol) {
  const double E0 = energy_of(m, x);
  const int steps = static_cast<int>(std::lround(t_end / h));
  double worst = 0.0;
  for (int chunk = 0; chunk < 10; ++chunk) {
    x = rk4_integrate(m, x, u, h, steps / 10);
    worst = std::max(worst, std::abs(energy_of(m, x) - E0));
  }
  const double scale = std::max(std::abs(E0), 1.0);
  EXPECT_LT(worst / scale, rel_tol) << m.name << ": E0 = " << E0 << ", worst drift " << worst;
}

TEST(Energy, DoublePendulumConservesOverTenSeconds) {
  const Model m = test::load_example("double_pendulum.json");
  State x{m.q0, m.v0};
  x.v << 2.0, -1.0;
  expect_conserved(m, x, Eigen::VectorXd::Zero(m.nu()), 1e-3, 10.0, 1e-9);
}

TEST(Energy, HeavyTopConservesAtFastSpin) {
  const Model m = test::load_example("heavy_top.json");
  expect_conserved(m, State{m.q0, m.v0}, Eigen::VectorXd::Zero(m.nu()), 1e-4, 1.0, 1e-8);
}

TEST(Energy, RandomFreeFloatingTreeConserves) {
  const Model m = compile(test::random_tree_spec(81, 8, true));
  std::mt19937 rng(81);
  expect_conserved(m, State{test::random_q(m, rng), test::random_v(m, rng, 1.0)}, Eigen::VectorXd(), 1e-3, 2.0, 1e-8);
}

TEST(Energy, FourBarWithSpringConserves) {
  const Model m = test::load_example("four_bar.json");
  State x{m.q0, m.v0};
  Data d(m);
  constraint_terms<double>(m, d, m.q0, m.v0);
  const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(d.Jc).kernel();
  x.v = N.col(0) * (1.5 / N.col(0).norm());
  expect_conserved(m, x, Eigen::VectorXd::Zero(m.nu()), 1e-3, 5.0, 1e-7);
}

// dE/dt = v^T Q_nonconservative: with only conservative effects, d/dt (T + V) = 0 pointwise
TEST(Energy, PowerBalanceOfTheDynamicsIsZeroWhenPassive) {
  const Model m = compile(test::random_tree_spec(82, 10, true));
  std::mt19937 rng(82);
  const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng);
  Data d(m);
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, q, v, Eigen::VectorXd());
  const double h = 1e-6;
  const State xp{integrate<double>(m, q, Eigen::VectorXd(h * v)), v + h * qdd};
  const State xm{integrate<double>(m, q, Eigen::VectorXd(-h * v)), v - h * qdd};
  EXPECT_NEAR((energy_of(m, xp) - energy_of(m, xm)) / (2 * h), 0.0, 1e-6 * (1 + std::abs(energy_of(m, {q, v}))));
}

}  // namespace
}  // namespace codyna
