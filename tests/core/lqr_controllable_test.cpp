// LQR on the controllable part, against a plant whose controllable part is
// known by construction: blockdiag(controllable cart-pendulum-like block,
// an undriven oscillator and an undriven integrator), hidden by a random
// orthogonal change of coordinates.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <random>

#include "control/controllability.hpp"
#include "control/lqr_controllable.hpp"

namespace codyna {
namespace {

TEST(LqrControllablePart, EqualsLqrOfTheKnownControllableBlock) {
  // controllable block: linearized cart-pendulum (x, th, xd, thd), force input
  Eigen::MatrixXd A1(4, 4), B1(4, 1);
  A1 << 0, 0, 1, 0, 0, 0, 0, 1, 0, -1.96, -0.1, 0, 0, 21.56, 0.2, 0;
  B1 << 0, 0, 1.0, -2.0;
  // undriven: an undamped oscillator (+/- 3i) and an integrator (0)
  Eigen::MatrixXd A2(3, 3);
  A2 << 0, 3, 0, -3, 0, 0, 0, 0, 0;
  Eigen::MatrixXd Ab = Eigen::MatrixXd::Zero(7, 7), Bb = Eigen::MatrixXd::Zero(7, 1);
  Ab.topLeftCorner(4, 4) = A1;
  Ab.bottomRightCorner(3, 3) = A2;
  Ab(0, 6) = 0.5;  // coupling from the uncontrollable into the controllable part (A stays block triangular)
  Bb.topRows(4) = B1;
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  Eigen::MatrixXd G(7, 7);
  for (int i = 0; i < 49; ++i) G.data()[i] = g(rng);
  const Eigen::MatrixXd T = Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ();  // x = T xb
  const Eigen::MatrixXd A = T * Ab * T.transpose(), B = T * Bb;
  Eigen::VectorXd qd(7);
  qd << 10, 100, 1, 1, 2, 2, 3;
  const Eigen::MatrixXd Qb = qd.asDiagonal();
  const Eigen::MatrixXd Q = T * Qb * T.transpose(), R = Eigen::MatrixXd::Constant(1, 1, 0.5);

  EXPECT_THROW(lqr(A, B, Q, R), std::invalid_argument);  // not stabilizable as a whole
  const ControllablePartLqr d = lqr_controllable_part(A, B, Q, R);
  ASSERT_EQ(d.Tc.cols(), 4);
  EXPECT_NEAR((d.Tc.transpose() * d.Tc - Eigen::MatrixXd::Identity(4, 4)).norm(), 0.0, 1e-12);
  // the same subspace as the known one: T's first four columns
  const Eigen::MatrixXd P1 = d.Tc * d.Tc.transpose(), P2 = T.leftCols(4) * T.leftCols(4).transpose();
  EXPECT_LT((P1 - P2).norm(), 1e-10);
  // the gain: lqr of the known block, in the original coordinates
  const LqrResult ref = lqr(A1, B1, Qb.topLeftCorner(4, 4), R);
  Eigen::MatrixXd Kref = Eigen::MatrixXd::Zero(1, 7);
  Kref.leftCols(4) = ref.K;
  Kref = Kref * T.transpose();
  EXPECT_LT((d.lqr.K - Kref).norm() / Kref.norm(), 1e-9);
  // closed-loop poles: the designed ones and the uncontrollable ones, unmoved
  Eigen::EigenSolver<Eigen::MatrixXd> es(A - B * d.lqr.K, false);
  Eigen::VectorXcd got = es.eigenvalues();
  ASSERT_EQ(d.uncontrollable_poles.size(), 3);
  int found = 0;
  for (const auto& p : d.uncontrollable_poles) {
    EXPECT_TRUE(std::abs(std::abs(p.imag()) - 3.0) < 1e-9 || std::abs(p) < 1e-9) << p;
    for (Eigen::Index k = 0; k < got.size(); ++k)
      if (std::abs(got[k] - p) < 1e-7) {
        ++found;
        break;
      }
  }
  EXPECT_EQ(found, 3);
  for (const auto& p : ref.closed_loop_poles) {
    bool ok = false;
    for (Eigen::Index k = 0; k < got.size(); ++k) ok = ok || std::abs(got[k] - p) < 1e-7;
    EXPECT_TRUE(ok) << p;
  }
}

TEST(LqrControllablePart, FullyControllableEqualsLqr) {
  Eigen::MatrixXd A(2, 2), B(2, 1);
  A << 0, 1, 9.81, 0;
  B << 0, 1;
  const Eigen::MatrixXd Q = Eigen::Vector2d(10, 1).asDiagonal(), R = Eigen::MatrixXd::Identity(1, 1);
  const ControllablePartLqr d = lqr_controllable_part(A, B, Q, R);
  EXPECT_EQ(d.Tu.cols(), 0);
  EXPECT_LT((d.lqr.K - lqr(A, B, Q, R).K).norm(), 1e-10);
}

TEST(LqrControllablePart, NoInputMovesNothing) {
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2), B = Eigen::MatrixXd::Zero(2, 1);
  EXPECT_THROW(lqr_controllable_part(A, B, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1)),
               std::invalid_argument);
}

}  // namespace
}  // namespace codyna
