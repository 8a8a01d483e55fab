// Forward dynamics with loop closures: Andrews' squeezer at t = 0 against the
// Test Set for IVP Solvers (docs/BENCHMARKS.md section 1), and consistency of
// the constrained solution.
#include "dynamics/forward_dynamics.hpp"

#include "dynamics/aba.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/rnea.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

TEST(ForwardDynamics, AndrewsSqueezerAccelerationsAtTimeZero) {
  const Model m = test::load_example("andrews_squeezer.json");
  ASSERT_EQ(m.dof(), 1);
  ASSERT_EQ(m.nc, 6);
  ASSERT_TRUE(m.redundant_rows.empty());
  Data d(m);
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, m.q0, m.v0, m.u_nominal());
  const double ref_beta = 14222.4439199541138705911625887, ref_theta = -10666.8329399655854029433719415;
  const int ib = m.joints[m.find_joint("beta")].idx_v, it = m.joints[m.find_joint("Theta")].idx_v;
  EXPECT_NEAR(qdd[ib], ref_beta, 1e-10 * std::abs(ref_beta));
  EXPECT_NEAR(qdd[it], ref_theta, 1e-10 * std::abs(ref_theta));
  for (const char* other : {"gamma", "Phi", "delta", "Omega", "epsilon"})
    EXPECT_NEAR(qdd[m.joints[m.find_joint(other)].idx_v], 0.0, 1e-8) << other;
}

TEST(ForwardDynamics, AndrewsSqueezerMultipliersMatchTestSet) {
  const Model m = test::load_example("andrews_squeezer.json");
  Data d(m);
  forward_dynamics<double>(m, d, m.q0, m.v0, m.u_nominal());
  // Our rows of a planar_revolute closure are e1.(p_a - p_b), e2.(p_a - p_b) with
  // e1, e2 fixed on body_a (K2); the Test Set's are the world x, y components of
  // p_a - p_b. On the manifold both give the same generalized force when
  // lambda_ts = lambda1 e1 + lambda2 e2 (world x, y).
  const double ref[6] = {98.5668703962410896057654982170, -6.12268834425566265503114393122, 0, 0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const ConstraintModel& cm = m.constraints[c];
    const Eigen::Matrix3d R = d.oMi[cm.body_a].R;
    const Eigen::Vector3d lam = d.lambda[cm.row] * (R * cm.perp_a1) + d.lambda[cm.row + 1] * (R * cm.perp_a2);
    EXPECT_NEAR(lam.x(), ref[2 * c], 1e-9 * 100) << cm.name;
    EXPECT_NEAR(lam.y(), ref[2 * c + 1], 1e-9 * 100) << cm.name;
    EXPECT_NEAR(lam.z(), 0.0, 1e-12);
  }
}

// M qdd + nle = Q - J^T lambda and J qdd + gamma = 0 at a random consistent state
TEST(ForwardDynamics, ClosedLoopSolutionSatisfiesBothEquations) {
  for (const char* name : {"four_bar.json", "andrews_squeezer.json", "bricard.json"}) {
    const Model m = test::load_example(name);
    Data d(m);
    constraint_terms<double>(m, d, m.q0, m.v0);
    // a velocity in the null space of Jc
    Eigen::FullPivLU<Eigen::MatrixXd> lu(d.Jc);
    const Eigen::MatrixXd N = lu.kernel();
    const Eigen::VectorXd v = N * Eigen::VectorXd::LinSpaced(N.cols(), 0.5, 1.5) * 3.0;
    const Eigen::VectorXd u = m.u_nominal();
    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, m.q0, v, u);
    const Eigen::VectorXd lambda = d.lambda, Q = d.Q;
    const Eigen::MatrixXd M = crba<double>(m, d, m.q0);
    const Eigen::VectorXd h = nonlinear_effects<double>(m, d, m.q0, v);
    constraint_terms<double>(m, d, m.q0, v);
    EXPECT_TRUE(MatrixNear(M * qdd + h, Q - d.Jc.transpose() * lambda, 1e-9)) << name;
    EXPECT_TRUE(MatrixNear(d.Jc * qdd + d.gamma, Eigen::VectorXd::Zero(m.nc), 1e-9)) << name;
  }
}

TEST(ForwardDynamics, TreeUsesAbaAndMatchesIt) {
  const Model m = test::load_example("double_pendulum.json");
  Data d(m);
  Eigen::VectorXd u = Eigen::VectorXd::Constant(m.nu(), 0.7);
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, m.q0, m.v0, u);
  const Eigen::MatrixXd M = crba<double>(m, d, m.q0);
  const Eigen::VectorXd h = nonlinear_effects<double>(m, d, m.q0, m.v0);
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.nv);
  Q[m.actuators[0].iv] += 0.7 * m.actuators[0].gain;
  EXPECT_TRUE(MatrixNear(qdd, M.llt().solve(Q - h), 1e-12));
}

}  // namespace
}  // namespace codyna
