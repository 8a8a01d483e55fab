// RNEA against hand-derived Lagrange equations and against CRBA.
#include "dynamics/rnea.hpp"

#include <cmath>

#include "dynamics/crba.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

constexpr double g_rnea = 9.81;

// M(q) and nle(q, v) of a model at a state, by CRBA and RNEA
struct MassBias {
  Eigen::MatrixXd M;
  Eigen::VectorXd h;
};
MassBias mass_bias(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Data d(m);
  MassBias r;
  r.M = crba<double>(m, d, q);
  r.h = nonlinear_effects<double>(m, d, q, v);
  return r;
}

TEST(Rnea, PendulumMatchesLagrange) {
  const Model m = test::load_example("pendulum.json");
  const double mass = 10, l = 2;
  for (double th : {-0.7, 0.0, 0.3, 1.3962634015954636, 2.5}) {
    Eigen::VectorXd q(1), v(1);
    q << th;
    v << 1.7;
    const MassBias mb = mass_bias(m, q, v);
    Eigen::MatrixXd M(1, 1);
    M << mass * l * l / 3;
    Eigen::VectorXd h(1);
    h << mass * g_rnea * l / 2 * std::cos(th);  // gravity torque, theta from the horizontal
    EXPECT_TRUE(MatrixNear(mb.M, M, 1e-12));
    EXPECT_TRUE(MatrixNear(mb.h, h, 1e-12));
  }
}

TEST(Rnea, CartPendulumMatchesLagrange) {
  const Model m = test::load_example("cart_pendulum.json");
  const double m2 = 20, m3 = 10, l = 2;
  // s = +1 if the rod joint turns about +z, -1 about -z (the paper counts theta clockwise)
  const double s = m.joints[m.find_joint("rod_pivot")].axis.z();
  std::mt19937 rng(3);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd q = test::random_v(m, rng, 2.0), v = test::random_v(m, rng, 3.0);
    const double th = q[1], hd = v[0], thd = v[1];
    (void)hd;
    Eigen::MatrixXd M(2, 2);
    M << m2 + m3, -s * m3 * l / 2 * std::cos(th), -s * m3 * l / 2 * std::cos(th), m3 * l * l / 3;
    Eigen::VectorXd h(2);
    h << s * m3 * l / 2 * std::sin(th) * thd * thd, -m3 * g_rnea * l / 2 * std::sin(th);
    const MassBias mb = mass_bias(m, q, v);
    EXPECT_TRUE(MatrixNear(mb.M, M, 1e-12));
    EXPECT_TRUE(MatrixNear(mb.h, h, 1e-12));
  }
}

TEST(Rnea, DoublePendulumMatchesLagrange) {
  const Model m = test::load_example("double_pendulum.json");
  const double m1 = 1, m2 = 1, l1 = 1, l2 = 1, I1 = m1 * l1 * l1 / 12, I2 = m2 * l2 * l2 / 12;
  std::mt19937 rng(5);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd q = test::random_v(m, rng, 3.0), v = test::random_v(m, rng, 3.0);
    const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
    Eigen::MatrixXd M(2, 2);
    const double M22 = I2 + m2 * l2 * l2 / 4, M12 = M22 + m2 * l1 * l2 / 2 * c2;
    M << I1 + m1 * l1 * l1 / 4 + m2 * l1 * l1 + M22 + m2 * l1 * l2 * c2, M12, M12, M22;
    const double k2 = m2 * l1 * l2 / 2 * s2;
    Eigen::VectorXd h(2);
    h << -k2 * (2 * v[0] * v[1] + v[1] * v[1]) + m1 * g_rnea * l1 / 2 * std::sin(q[0]) +
             m2 * g_rnea * (l1 * std::sin(q[0]) + l2 / 2 * std::sin(q[0] + q[1])),
        k2 * v[0] * v[0] + m2 * g_rnea * l2 / 2 * std::sin(q[0] + q[1]);
    const MassBias mb = mass_bias(m, q, v);
    EXPECT_TRUE(MatrixNear(mb.M, M, 1e-12));
    EXPECT_TRUE(MatrixNear(mb.h, h, 1e-12));
  }
}

// rnea(q, v, a) == M(q) a + nle(q, v) on a random branched tree with every joint type
TEST(Rnea, EqualsMassMatrixTimesAccelerationPlusBias) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Model m = compile(test::random_tree_spec(seed, 12));
    std::mt19937 rng(seed);
    Data d(m);
    for (int k = 0; k < 4; ++k) {
      const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng), a = test::random_v(m, rng, 5);
      const Eigen::VectorXd tau = rnea<double>(m, d, q, v, a);
      const Eigen::MatrixXd M = crba<double>(m, d, q);
      const Eigen::VectorXd h = nonlinear_effects<double>(m, d, q, v);
      EXPECT_TRUE(MatrixNear(M * a + h, tau, 1e-11)) << "seed " << seed;
    }
  }
}

}  // namespace
}  // namespace codyna
