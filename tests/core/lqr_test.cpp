// control/lqr: LQR gains and Riccati solutions against closed forms, against
// the Riccati equations written out independently here, and against GNU
// Octave's lqr / dlqr (SLICOT SB02OD) when octave-cli is on PATH.
#include "control/lqr.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

#include "test_util.hpp"
#include "peer_util.hpp"

namespace codyna {
namespace {

using Eigen::MatrixXd;
using test::CommandResult;
using test::octave_literal;
using test::octave_print;
using test::on_path;
using test::parse_matrix;
using test::relative_difference;
using test::run_octave;

// ------------------------------------------------------------------ helpers


MatrixXd scalar(double v) { return MatrixXd::Constant(1, 1, v); }

// MISSION.md example 2 in the paper's state order [h, h', theta, theta']
struct Plant {
  MatrixXd A, B;
};

Plant cart_pendulum_lqr() {
  const double m2 = 20, m3 = 10, l3 = 2, g = 9.81, den = 4 * m2 + m3;
  Plant p{MatrixXd::Zero(4, 4), MatrixXd::Zero(4, 1)};
  p.A(0, 1) = 1;
  p.A(1, 2) = -3 * m3 * g / den;
  p.A(2, 3) = 1;
  p.A(3, 2) = 6 * (m2 + m3) * g / (den * l3);
  p.B(1) = 4 / den;
  p.B(3) = -6 / (l3 * den);
  return p;
}

// weights h by 10, theta by 100, the rates by 1; R = 0.01
MatrixXd cart_Q() { return Eigen::Vector4d(10, 1, 100, 1).asDiagonal(); }
MatrixXd cart_R() { return scalar(0.01); }

// exact zero-order hold, exp([A B; 0 0] T) = [Ad Bd; 0 I]
Plant zoh(const Plant& c, double T) {
  const Eigen::Index n = c.A.rows(), m = c.B.cols();
  MatrixXd M = MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = c.A * T;
  M.topRightCorner(n, m) = c.B * T;
  const MatrixXd E = M.exp();
  return {E.topLeftCorner(n, n), E.topRightCorner(n, m)};
}

// The Riccati equations in their textbook form (cross term kept), relative to
// the size of their terms; written here independently of the solver.
double care_relative_residual(const Plant& p, const MatrixXd& Q, const MatrixXd& R, const MatrixXd& N,
                              const MatrixXd& X) {
  const MatrixXd AtX = p.A.transpose() * X, L = X * p.B + N;
  const MatrixXd gain_term = L * R.inverse() * L.transpose();
  const MatrixXd res = AtX + AtX.transpose() - gain_term + Q;
  return res.norm() / (2 * AtX.norm() + gain_term.norm() + Q.norm());
}

double dare_relative_residual(const Plant& p, const MatrixXd& Q, const MatrixXd& R, const MatrixXd& N,
                              const MatrixXd& X) {
  const MatrixXd AtXA = p.A.transpose() * X * p.A, L = p.A.transpose() * X * p.B + N;
  const MatrixXd gain_term = L * (R + p.B.transpose() * X * p.B).inverse() * L.transpose();
  const MatrixXd res = AtXA - X - gain_term + Q;
  return res.norm() / (AtXA.norm() + X.norm() + gain_term.norm() + Q.norm());
}

MatrixXd closed_loop(const Plant& p, const MatrixXd& K) { return p.A - p.B * K; }

double max_real_part(const MatrixXd& M) { return M.eigenvalues().real().maxCoeff(); }
double spectral_radius(const MatrixXd& M) { return M.eigenvalues().cwiseAbs().maxCoeff(); }

// ------------------------------------------------------------------ closed forms

// a x + b u, cost q x^2 + r u^2:  2 a X - b^2 X^2 / r + q = 0, so
// X = r (a + sqrt(a^2 + b^2 q / r)) / b^2,  K = b X / r,  a - b K = -sqrt(a^2 + b^2 q / r)
TEST(LqrClosedForm, ScalarContinuous) {
  for (const auto& [a, b, q, r] : std::vector<std::array<double, 4>>{
           {1, 1, 1, 1}, {-2, 0.5, 3, 0.1}, {4, 2, 0, 1}, {0, 1, 1, 1}, {1e-3, 10, 1e4, 1e-2}, {1, 1, 1e8, 1e-8}}) {
    const double root = std::sqrt(a * a + b * b * q / r);
    const double X = r * (a + root) / (b * b);
    const LqrResult res = lqr(scalar(a), scalar(b), scalar(q), scalar(r));
    EXPECT_NEAR(res.X(0, 0), X, 1e-13 * std::abs(X)) << a << " " << b << " " << q << " " << r;
    EXPECT_NEAR(res.K(0, 0), b * X / r, 1e-13 * std::abs(b * X / r));
    EXPECT_NEAR(res.closed_loop_poles[0].real(), -root, 1e-13 * root);
    EXPECT_EQ(res.closed_loop_poles[0].imag(), 0.0);
    EXPECT_NEAR(care(scalar(a), scalar(b), scalar(q), scalar(r))(0, 0), X, 1e-13 * std::abs(X));
  }
}

// x+ = a x + b u:  X = q + a^2 r X / (r + b^2 X), i.e.
// b^2 X^2 + (r - q b^2 - a^2 r) X - q r = 0 (positive root), K = a b X / (r + b^2 X)
TEST(LqrClosedForm, ScalarDiscrete) {
  for (const auto& [a, b, q, r] : std::vector<std::array<double, 4>>{
           {1, 1, 1, 1}, {0.5, 0.5, 3, 0.1}, {2, 1, 0, 1}, {-1.5, 0.2, 1, 2}, {0.9, 1, 1e8, 1e-8}}) {
    const double c = r - q * b * b - a * a * r;
    const double X = (-c + std::sqrt(c * c + 4 * b * b * q * r)) / (2 * b * b);
    const double K = a * b * X / (r + b * b * X);
    const LqrResult res = dlqr(scalar(a), scalar(b), scalar(q), scalar(r));
    EXPECT_NEAR(res.X(0, 0), X, 1e-13 * std::abs(X)) << a << " " << b << " " << q << " " << r;
    EXPECT_NEAR(res.K(0, 0), K, 1e-13 * std::abs(K));
    EXPECT_NEAR(res.closed_loop_poles[0].real(), a - b * K, 1e-13);
    EXPECT_NEAR(dare(scalar(a), scalar(b), scalar(q), scalar(r))(0, 0), X, 1e-13 * std::abs(X));
  }
}

// q'' = u, Q = I, R = 1: X = [sqrt3 1; 1 sqrt3], K = [1 sqrt3], poles -sqrt3/2 +- i/2
TEST(LqrClosedForm, DoubleIntegrator) {
  const MatrixXd A = Eigen::Matrix2d{{0, 1}, {0, 0}}, B = Eigen::Vector2d(0, 1);
  const double s3 = std::sqrt(3.0);
  const LqrResult res = lqr(A, B, MatrixXd::Identity(2, 2), scalar(1));
  EXPECT_LT(relative_difference(res.K, Eigen::RowVector2d(1, s3)), 1e-14) << res.K;
  EXPECT_LT(relative_difference(res.X, Eigen::Matrix2d{{s3, 1}, {1, s3}}), 1e-14) << res.X;
  ASSERT_EQ(res.closed_loop_poles.size(), 2);
  EXPECT_NEAR(res.closed_loop_poles[0].real(), -s3 / 2, 1e-14);
  EXPECT_NEAR(res.closed_loop_poles[0].imag(), -0.5, 1e-14);
  EXPECT_NEAR(res.closed_loop_poles[1].imag(), 0.5, 1e-14);
}

// ------------------------------------------------------------------ the paper's plant

TEST(Lqr, CartPendulumSolvesRiccatiAndStabilizes) {
  const Plant p = cart_pendulum_lqr();
  const LqrResult res = lqr(p.A, p.B, cart_Q(), cart_R());
  EXPECT_LT(care_relative_residual(p, cart_Q(), cart_R(), MatrixXd::Zero(4, 1), res.X), 1e-10);
  EXPECT_LT(relative_difference(res.X, res.X.transpose()), 1e-15);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(res.X).eigenvalues().minCoeff(), 0.0);  // Q > 0: X > 0
  EXPECT_LT(max_real_part(closed_loop(p, res.K)), 0.0);
  EXPECT_LT(res.closed_loop_poles.real().maxCoeff(), 0.0);
  EXPECT_LT(relative_difference(res.K, cart_R().inverse() * p.B.transpose() * res.X), 1e-14);
}

TEST(Dlqr, CartPendulumZohSolvesRiccatiAndStabilizes) {
  const Plant d = zoh(cart_pendulum_lqr(), 0.02);
  const LqrResult res = dlqr(d.A, d.B, cart_Q(), cart_R());
  EXPECT_LT(dare_relative_residual(d, cart_Q(), cart_R(), MatrixXd::Zero(4, 1), res.X), 1e-10);
  EXPECT_LT(spectral_radius(closed_loop(d, res.K)), 1.0);
  EXPECT_LT(res.closed_loop_poles.cwiseAbs().maxCoeff(), 1.0);
}

// the cross term, checked against the equations with N written out (not the
// change of variables the solver uses)
TEST(Lqr, CrossTermSatisfiesTheFullEquations) {
  const Plant p = cart_pendulum_lqr();
  const MatrixXd N = Eigen::Vector4d(0.1, 0, 0.2, 0.01);  // [Q N; N' R] stays positive semidefinite
  const LqrResult c = lqr(p.A, p.B, cart_Q(), cart_R(), N);
  EXPECT_LT(care_relative_residual(p, cart_Q(), cart_R(), N, c.X), 1e-10);
  EXPECT_LT(relative_difference(c.K, cart_R().inverse() * (p.B.transpose() * c.X + N.transpose())), 1e-14);
  EXPECT_LT(max_real_part(closed_loop(p, c.K)), 0.0);

  const Plant d = zoh(p, 0.02);
  const LqrResult k = dlqr(d.A, d.B, cart_Q(), cart_R(), N);
  EXPECT_LT(dare_relative_residual(d, cart_Q(), cart_R(), N, k.X), 1e-10);
  EXPECT_LT(spectral_radius(closed_loop(d, k.K)), 1.0);
}

// a larger multi-input plant with an unstable open loop
TEST(Lqr, RandomMultiInputPlants) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const auto random = [&](int r, int c) { return MatrixXd(MatrixXd::NullaryExpr(r, c, [&] { return normal(rng); })); };
  for (int trial = 0; trial < 5; ++trial) {
    const Plant p{random(12, 12), random(12, 3)};
    const MatrixXd L = random(12, 12), Q = L * L.transpose() / 12, Rh = random(3, 3);
    const MatrixXd R = Rh * Rh.transpose() + MatrixXd::Identity(3, 3);
    const LqrResult c = lqr(p.A, p.B, Q, R);
    EXPECT_LT(care_relative_residual(p, Q, R, MatrixXd::Zero(12, 3), c.X), 1e-12) << trial;
    EXPECT_LT(max_real_part(closed_loop(p, c.K)), 0.0);
    const Plant d{p.A / 3, p.B};
    const LqrResult k = dlqr(d.A, d.B, Q, R);
    EXPECT_LT(dare_relative_residual(d, Q, R, MatrixXd::Zero(12, 3), k.X), 1e-12) << trial;
    EXPECT_LT(spectral_radius(closed_loop(d, k.K)), 1.0);
  }
}

// ------------------------------------------------------------------ bad input

TEST(Lqr, RejectsMismatchedSizesNamingTheMatrices) {
  const Plant p = cart_pendulum_lqr();
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A.leftCols(3), p.B, cart_Q(), cart_R()), "lqr: A is 4x3",
                               "square");
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, p.B.topRows(3), cart_Q(), cart_R()), "lqr: B is 3x1",
                               "expected 4 rows to match A (4x4)");
  EXPECT_INVALID_ARGUMENT_WITH(dlqr(p.A, p.B, MatrixXd::Identity(3, 3), cart_R()), "dlqr: Q is 3x3",
                               "expected 4x4 to match A (4x4)");
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, p.B, cart_Q(), MatrixXd::Identity(2, 2)), "R is 2x2",
                               "expected 1x1 to match the columns of B (4x1)");
  EXPECT_INVALID_ARGUMENT_WITH(care(p.A, p.B, cart_Q(), cart_R(), MatrixXd::Zero(4, 2)), "care: N is 4x2",
                               "expected 4x1");
  EXPECT_INVALID_ARGUMENT_WITH(dare(p.A, MatrixXd(4, 0), cart_Q(), MatrixXd(0, 0)), "dare: B is 4x0",
                               "at least one column");
}

TEST(Lqr, RejectsBadWeights) {
  const Plant p = cart_pendulum_lqr();
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, p.B, cart_Q(), scalar(0)), "lqr: R is not symmetric positive definite");
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, p.B, cart_Q(), scalar(-1)), "R is not symmetric positive definite");
  const MatrixXd R2 = Eigen::Matrix2d{{1, 2}, {2, 1}};  // symmetric, indefinite
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, MatrixXd::Ones(4, 2), cart_Q(), R2), "R is not symmetric positive definite");
  const MatrixXd R3 = Eigen::Matrix2d{{1, 0.5}, {0, 1}};
  EXPECT_INVALID_ARGUMENT_WITH(dlqr(p.A, MatrixXd::Ones(4, 2), cart_Q(), R3), "dlqr: R is not symmetric");
  MatrixXd Q = cart_Q();
  Q(0, 1) = 1;
  EXPECT_INVALID_ARGUMENT_WITH(lqr(p.A, p.B, Q, cart_R()), "lqr: Q is not symmetric");
  MatrixXd A = p.A;
  A(1, 2) = std::nan("");
  EXPECT_INVALID_ARGUMENT_WITH(lqr(A, p.B, cart_Q(), cart_R()), "lqr: A has NaN or Inf entries");
}

TEST(Lqr, ReportsNoStabilizingSolution) {
  const std::string why = "no stabilizing solution: (A, B) may not be stabilizable or (Q, A) may have unobservable "
                          "modes on the ";
  // the unstable mode x1 is not reached by the input
  const MatrixXd A = Eigen::Matrix2d{{1, 0}, {0, -1}}, B = Eigen::Vector2d(0, 1), I = MatrixXd::Identity(2, 2);
  EXPECT_INVALID_ARGUMENT_WITH(lqr(A, B, I, scalar(1)), "lqr: " + why + "imaginary axis");
  EXPECT_INVALID_ARGUMENT_WITH(care(A, B, I, scalar(1)), "care: " + why + "imaginary axis");
  EXPECT_INVALID_ARGUMENT_WITH(dlqr(2 * A, B, I, scalar(1)), "dlqr: " + why + "unit circle");
  EXPECT_INVALID_ARGUMENT_WITH(dare(2 * A, B, I, scalar(1)), "dare: " + why + "unit circle");
  // an undamped oscillator that Q does not see: its modes on the imaginary axis cannot move
  const MatrixXd osc = Eigen::Matrix2d{{0, 1}, {-1, 0}};
  EXPECT_INVALID_ARGUMENT_WITH(lqr(osc, MatrixXd::Zero(2, 1), I, scalar(1)), why + "imaginary axis");
  EXPECT_INVALID_ARGUMENT_WITH(lqr(osc, B, MatrixXd::Zero(2, 2), scalar(1)), why + "imaginary axis");
  // a rotation by 1 rad has its poles on the unit circle
  const MatrixXd rot = Eigen::Matrix2d{{std::cos(1.0), -std::sin(1.0)}, {std::sin(1.0), std::cos(1.0)}};
  EXPECT_INVALID_ARGUMENT_WITH(dlqr(rot, B, MatrixXd::Zero(2, 2), scalar(1)), why + "unit circle");
}

// ------------------------------------------------------------------ linear matrix equations

TEST(LinearMatrixEquations, SolveTheirEquations) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const auto random = [&](int r, int c) { return MatrixXd(MatrixXd::NullaryExpr(r, c, [&] { return normal(rng); })); };
  const MatrixXd A = random(7, 7) - 4 * MatrixXd::Identity(7, 7), B = random(3, 3) + 5 * MatrixXd::Identity(3, 3);
  const MatrixXd C = random(7, 3), Q = random(7, 7) + random(7, 7).transpose();
  const MatrixXd X = sylvester(A, B, C);
  EXPECT_LT((A * X + X * B - C).norm(), 1e-12 * C.norm());
  const MatrixXd P = lyap(A, Q);
  EXPECT_LT((A * P + P * A.transpose() + Q).norm(), 1e-12 * Q.norm());
  const MatrixXd As = A / (1.1 * spectral_radius(A)), S = dlyap(As, Q);
  EXPECT_LT((As * S * As.transpose() - S + Q).norm(), 1e-12 * Q.norm());
  EXPECT_INVALID_ARGUMENT_WITH(sylvester(MatrixXd::Identity(2, 2), -MatrixXd::Identity(2, 2), MatrixXd::Ones(2, 2)),
                               "sylvester: singular equation");
  EXPECT_INVALID_ARGUMENT_WITH(lyap(Eigen::Matrix2d{{0, 1}, {-1, 0}}, MatrixXd::Identity(2, 2)),
                               "lyap: singular equation");
  EXPECT_INVALID_ARGUMENT_WITH(dlyap(MatrixXd::Identity(2, 2), MatrixXd::Identity(2, 2)), "dlyap: singular equation");
  EXPECT_INVALID_ARGUMENT_WITH(sylvester(A, B, C.transpose()), "sylvester: C is 3x7, expected 7x3");
}

// ------------------------------------------------------------------ peer: GNU Octave

class OctaveLqrPeer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!on_path("octave-cli")) GTEST_SKIP() << "octave-cli is not on PATH";
  }
  // Octave may print "error: ignoring const execution_exception& while preparing
  // to exit"; that is harmless, so judge by the exit code and the marker.
  static void expect_finished(const CommandResult& r) {
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_NE(r.output.find("CODYNA_PEER_DONE"), std::string::npos) << r.output;
  }
  static void report(const std::string& what, double rel) {
    std::cout << "[   peer   ] " << what << ": max relative difference " << rel << "\n";
  }
};

TEST_F(OctaveLqrPeer, LqrAndDlqrMatchOnCartPendulumAndRandomPlant) {
  const Plant c = cart_pendulum_lqr(), d = zoh(c, 0.02);
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  const auto random = [&](int r, int cc) { return MatrixXd(MatrixXd::NullaryExpr(r, cc, [&] { return normal(rng); })); };
  const Plant p{random(6, 6), random(6, 2)};
  const MatrixXd L = random(6, 6), Qp = L * L.transpose(), Rp = Eigen::Matrix2d{{2, 0.5}, {0.5, 1}};

  const CommandResult r = run_octave(
      "A = " + octave_literal(c.A) + "; B = " + octave_literal(c.B) + "; Ad = " + octave_literal(d.A) +
      "; Bd = " + octave_literal(d.B) + "; Q = " + octave_literal(cart_Q()) + "; R = " + octave_literal(cart_R()) +
      "; Ap = " + octave_literal(p.A) + "; Bp = " + octave_literal(p.B) + "; Qp = " + octave_literal(Qp) +
      "; Rp = " + octave_literal(Rp) + "; " +
      "[K, X] = lqr(A, B, Q, R); [Kd, Xd] = dlqr(Ad, Bd, Q, R); Kp = lqr(Ap, Bp, Qp, Rp); Kpd = dlqr(Ap / 4, Bp, Qp, Rp); " +
      "Kp0 = lqr(Ap, Bp, zeros(6), Rp); Kpd0 = dlqr(Ap / 2, Bp, zeros(6), Rp); " + octave_print("K") +
      octave_print("X") + octave_print("Kd") + octave_print("Xd") + octave_print("Kp") + octave_print("Kpd") +
      octave_print("Kp0") + octave_print("Kpd0"));
  expect_finished(r);

  const LqrResult cont = lqr(c.A, c.B, cart_Q(), cart_R()), disc = dlqr(d.A, d.B, cart_Q(), cart_R());
  const LqrResult rand_c = lqr(p.A, p.B, Qp, Rp), rand_d = dlqr(p.A / 4, p.B, Qp, Rp);
  // Q = 0: the stabilizing solution only mirrors the unstable poles
  const LqrResult zero_c = lqr(p.A, p.B, MatrixXd::Zero(6, 6), Rp), zero_d = dlqr(p.A / 2, p.B, MatrixXd::Zero(6, 6), Rp);
  const std::vector<std::pair<std::string, std::pair<MatrixXd, MatrixXd>>> pairs = {
      {"lqr K (cart-pendulum)", {cont.K, parse_matrix(r.output, "K")}},
      {"lqr X (cart-pendulum)", {cont.X, parse_matrix(r.output, "X")}},
      {"dlqr K (cart-pendulum, ZOH 0.02 s)", {disc.K, parse_matrix(r.output, "Kd")}},
      {"dlqr X (cart-pendulum, ZOH 0.02 s)", {disc.X, parse_matrix(r.output, "Xd")}},
      {"lqr K (random 6x6, 2 inputs)", {rand_c.K, parse_matrix(r.output, "Kp")}},
      {"dlqr K (random 6x6 / 4, 2 inputs)", {rand_d.K, parse_matrix(r.output, "Kpd")}},
      {"lqr K (random 6x6, 2 inputs, Q = 0)", {zero_c.K, parse_matrix(r.output, "Kp0")}},
      {"dlqr K (random 6x6 / 2, 2 inputs, Q = 0)", {zero_d.K, parse_matrix(r.output, "Kpd0")}}};
  for (const auto& [what, ab] : pairs) {
    const double rel = relative_difference(ab.first, ab.second);
    report(what, rel);
    EXPECT_LT(rel, 1e-8) << what << "\ncodyna:\n" << ab.first << "\noctave:\n" << ab.second;
  }
}

TEST_F(OctaveLqrPeer, CrossTermMatches) {
  const Plant c = cart_pendulum_lqr(), d = zoh(c, 0.02);
  const MatrixXd N = Eigen::Vector4d(0.1, 0, 0.2, 0.01);
  const CommandResult r = run_octave(
      "A = " + octave_literal(c.A) + "; B = " + octave_literal(c.B) + "; Ad = " + octave_literal(d.A) +
      "; Bd = " + octave_literal(d.B) + "; Q = " + octave_literal(cart_Q()) + "; R = " + octave_literal(cart_R()) +
      "; N = " + octave_literal(N) + "; K = lqr(A, B, Q, R, N); Kd = dlqr(Ad, Bd, Q, R, N); " + octave_print("K") +
      octave_print("Kd"));
  expect_finished(r);
  const double rel_c = relative_difference(lqr(c.A, c.B, cart_Q(), cart_R(), N).K, parse_matrix(r.output, "K"));
  const double rel_d = relative_difference(dlqr(d.A, d.B, cart_Q(), cart_R(), N).K, parse_matrix(r.output, "Kd"));
  report("lqr K with N (cart-pendulum)", rel_c);
  report("dlqr K with N (cart-pendulum, ZOH 0.02 s)", rel_d);
  EXPECT_LT(rel_c, 1e-8);
  EXPECT_LT(rel_d, 1e-8);
}

}  // namespace
}  // namespace codyna
