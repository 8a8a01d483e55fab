// control/place: pole placement against a closed form, against the
// eigenvalues of the closed loop, and against GNU Octave's place() (single
// input, where K is unique) when octave-cli is on PATH.
#include "control/place.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "peer_util.hpp"

namespace codyna {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXcd;
using Complex = std::complex<double>;
using test::CommandResult;
using test::octave_literal;
using test::octave_print;
using test::on_path;
using test::parse_matrix;
using test::relative_difference;
using test::run_octave;

// ------------------------------------------------------------------ helpers


// the largest |placed - wanted| over max(1, |wanted|), each wanted pole matched
// to its nearest unmatched eigenvalue of A - B K
double pole_error(const MatrixXd& closed_loop, const VectorXcd& wanted) {
  const VectorXcd placed = closed_loop.eigenvalues();
  std::vector<bool> taken(placed.size(), false);
  double worst = 0;
  for (const Complex& p : wanted) {
    Eigen::Index best = -1;
    for (Eigen::Index j = 0; j < placed.size(); ++j)
      if (!taken[j] && (best < 0 || std::abs(placed[j] - p) < std::abs(placed[best] - p))) best = j;
    if (best < 0) return std::numeric_limits<double>::infinity();
    taken[best] = true;
    worst = std::max(worst, std::abs(placed[best] - p) / std::max(1.0, std::abs(p)));
  }
  return worst;
}

VectorXcd poles(std::initializer_list<Complex> list) {
  VectorXcd v(static_cast<Eigen::Index>(list.size()));
  Eigen::Index i = 0;
  for (const Complex& p : list) v[i++] = p;
  return v;
}

MatrixXd random_matrix(int rows, int cols, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return MatrixXd::NullaryExpr(rows, cols, [&] { return normal(rng); });
}

// MISSION.md example 1, upright: A = [0 1; 3g/4 0], B = [0; 0.075]
const double kA21 = 3 * 9.81 / 4, kB2 = 0.075;
MatrixXd pendulum_A() { return Eigen::Matrix2d{{0, 1}, {kA21, 0}}; }
MatrixXd pendulum_B() { return Eigen::Vector2d(0, kB2); }

// MISSION.md example 2 in the paper's state order [h, h', theta, theta']
MatrixXd cart_A() {
  const double m2 = 20, m3 = 10, l3 = 2, g = 9.81, den = 4 * m2 + m3;
  MatrixXd A = MatrixXd::Zero(4, 4);
  A(0, 1) = 1;
  A(1, 2) = -3 * m3 * g / den;
  A(2, 3) = 1;
  A(3, 2) = 6 * (m2 + m3) * g / (den * l3);
  return A;
}
MatrixXd cart_B() {
  const double m2 = 20, m3 = 10, l3 = 2, den = 4 * m2 + m3;
  return Eigen::Vector4d(0, 4 / den, 0, -6 / (l3 * den));
}
VectorXcd cart_poles() { return poles({-1.0, -2.0, {-1.5, 1.0}, {-1.5, -1.0}}); }

// ------------------------------------------------------------------ correctness

// A - B K = [0 1; a - b k1, -b k2] has s^2 + b k2 s + b k1 - a = (s + 2)(s + 3),
// so k1 = (a + 6) / b and k2 = 5 / b
TEST(Place, PendulumMatchesClosedForm) {
  const MatrixXd K = place(pendulum_A(), pendulum_B(), poles({-2.0, -3.0}));
  EXPECT_LT(relative_difference(K, Eigen::RowVector2d((kA21 + 6) / kB2, 5 / kB2)), 1e-13) << K;
}

TEST(Place, CartPendulumPlacesRealPolesAndAComplexPair) {
  const MatrixXd K = place(cart_A(), cart_B(), cart_poles());
  ASSERT_EQ(K.rows(), 1);
  ASSERT_EQ(K.cols(), 4);
  EXPECT_LT(pole_error(cart_A() - cart_B() * K, cart_poles()), 1e-8);
}

// a requested pole at an open-loop eigenvalue (the Sylvester equation would be
// singular without the pre-feedback): q'' = u at {0, -1} needs K = [0 1]
TEST(Place, PoleAtAnOpenLoopEigenvalue) {
  const MatrixXd A = Eigen::Matrix2d{{0, 1}, {0, 0}}, B = Eigen::Vector2d(0, 1);
  const MatrixXd K = place(A, B, poles({0.0, -1.0}));
  EXPECT_LT((K - Eigen::RowVector2d(0, 1)).cwiseAbs().maxCoeff(), 1e-12) << K;
}

TEST(Place, MultiInputRandomPlantsGetTheirPoles) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const MatrixXd A = random_matrix(6, 6, rng), B = random_matrix(6, 2, rng);
    // a double pole is allowed with two inputs
    const VectorXcd wanted = poles({-1.0, -2.0, -2.0, {-0.5, 3.0}, {-0.5, -3.0}, -4.0});
    const MatrixXd K = place(A, B, wanted);
    EXPECT_LT(pole_error(A - B * K, wanted), 1e-8) << "trial " << trial;
  }
}

TEST(Place, IsReproducible) {
  std::mt19937 rng(9);
  const MatrixXd A = random_matrix(5, 5, rng), B = random_matrix(5, 3, rng);
  const VectorXcd wanted = poles({-1.0, -2.0, -3.0, {-1.0, 1.0}, {-1.0, -1.0}});
  EXPECT_EQ(place(A, B, wanted), place(A, B, wanted));
}

// ------------------------------------------------------------------ bad input

TEST(Place, RejectsUncontrollablePairNamingTheMode) {
  // x1' = 2 x1 has no input; x2' = -x2 + u
  const MatrixXd A = Eigen::Matrix2d{{2, 0}, {0, -1}}, B = Eigen::Vector2d(0, 1);
  EXPECT_INVALID_ARGUMENT_WITH(place(A, B, poles({-1.0, -2.0})), "place: (A, B) is not controllable",
                               "1 mode(s) cannot be moved", "at 2");
  // the same, hidden by a change of coordinates
  const MatrixXd T = Eigen::Matrix2d{{1, 2}, {3, 5}};
  EXPECT_INVALID_ARGUMENT_WITH(place(T * A * T.inverse(), T * B, poles({-1.0, -2.0})),
                               "(A, B) is not controllable");
  // the cart alone, without the rod: the rod's states are not driven
  MatrixXd Ac = cart_A(), Bc = cart_B();
  Ac(1, 2) = 0;
  Bc(3) = 0;
  EXPECT_INVALID_ARGUMENT_WITH(place(Ac, Bc, cart_poles()), "(A, B) is not controllable", "2 mode(s)");
}

TEST(Place, RejectsPolesThatAreNotConjugatePairs) {
  EXPECT_INVALID_ARGUMENT_WITH(place(cart_A(), cart_B(), poles({-1.0, -2.0, {-1.5, 1.0}, {-1.5, -1.2}})),
                               "poles must come in complex-conjugate pairs", "-1.5 + 1i has no partner -1.5 - 1i");
  EXPECT_INVALID_ARGUMENT_WITH(place(pendulum_A(), pendulum_B(), poles({{-1.0, 1.0}, -2.0})),
                               "complex-conjugate pairs");
}

TEST(Place, RejectsPolesRepeatedBeyondTheInputs) {
  EXPECT_INVALID_ARGUMENT_WITH(place(pendulum_A(), pendulum_B(), poles({-2.0, -2.0})),
                               "place: pole -2 is repeated 2 times, more than rank(B) = 1");
  std::mt19937 rng(1);
  const MatrixXd A = random_matrix(4, 4, rng), B = random_matrix(4, 2, rng);
  EXPECT_INVALID_ARGUMENT_WITH(place(A, B, poles({-1.0, -1.0, -1.0, -2.0})), "repeated 3 times, more than rank(B) = 2");
  // two identical input columns are one input direction
  MatrixXd B1(4, 2);
  B1 << B.col(0), B.col(0);
  EXPECT_INVALID_ARGUMENT_WITH(place(A, B1, poles({-1.0, -1.0, -3.0, -2.0})), "more than rank(B) = 1");
}

TEST(Place, RejectsMismatchedSizes) {
  EXPECT_INVALID_ARGUMENT_WITH(place(cart_A().leftCols(3), cart_B(), cart_poles()), "place: A is 4x3",
                               "square");
  EXPECT_INVALID_ARGUMENT_WITH(place(cart_A(), pendulum_B(), cart_poles()), "place: B is 2x1",
                               "expected 4 rows to match A (4x4)");
  EXPECT_INVALID_ARGUMENT_WITH(place(cart_A(), cart_B(), poles({-1.0, -2.0})), "place: poles has 2 entries",
                               "expected 4");
  EXPECT_INVALID_ARGUMENT_WITH(place(cart_A(), cart_B(), poles({-1.0, -2.0, -3.0, std::nan("")})),
                               "poles has NaN or Inf entries");
}

// ------------------------------------------------------------------ peer: GNU Octave

// an Octave row of complex poles, each part exact (the complex sibling of test::octave_literal)
std::string octave_literal(const VectorXcd& v) {
  std::string s = "[";
  char buf[80];
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.17g%+.17gi", i ? ", " : "", v[i].real(), v[i].imag());
    s += buf;
  }
  return s + "]";
}

// Single input: K is unique, so it must equal Octave's. Multi-input: Octave
// chooses another K; both must place the same poles.
TEST(OctavePlacePeer, SingleInputGainsEqualOctavesAndMultiInputPolesAgree) {
  if (!on_path("octave-cli")) GTEST_SKIP() << "octave-cli is not on PATH";
  std::mt19937 rng(21);
  const MatrixXd Ar = random_matrix(5, 5, rng), Br = random_matrix(5, 1, rng);
  const VectorXcd pr = poles({-1.0, -2.0, -3.0, {-0.5, 2.0}, {-0.5, -2.0}});
  const MatrixXd Am = random_matrix(5, 5, rng), Bm = random_matrix(5, 2, rng);

  // Octave writes "error: ignoring const execution_exception& while preparing to
  // exit" at exit; harmless, so judge by the exit code and the marker
  const CommandResult r = run_octave(
      "Kp = place(" + octave_literal(pendulum_A()) + ", " + octave_literal(pendulum_B()) + ", [-2 -3]); " +
      "Kc = place(" + octave_literal(cart_A()) + ", " + octave_literal(cart_B()) + ", " + octave_literal(cart_poles()) +
      "); Kr = place(" + octave_literal(Ar) + ", " + octave_literal(Br) + ", " + octave_literal(pr) + "); " +
      "Km = place(" + octave_literal(Am) + ", " + octave_literal(Bm) + ", " + octave_literal(pr) + "); " +
      octave_print("Kp") + octave_print("Kc") + octave_print("Kr") + octave_print("Km"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("CODYNA_PEER_DONE"), std::string::npos) << r.output;

  const std::vector<std::pair<std::string, std::pair<MatrixXd, MatrixXd>>> single = {
      {"place K (pendulum at -2, -3)", {place(pendulum_A(), pendulum_B(), poles({-2.0, -3.0})), parse_matrix(r.output, "Kp")}},
      {"place K (cart-pendulum)", {place(cart_A(), cart_B(), cart_poles()), parse_matrix(r.output, "Kc")}},
      {"place K (random 5x5, 1 input)", {place(Ar, Br, pr), parse_matrix(r.output, "Kr")}}};
  for (const auto& [what, ab] : single) {
    const double rel = relative_difference(ab.first, ab.second);
    std::cout << "[   peer   ] " << what << ": max relative difference " << rel << "\n";
    EXPECT_LT(rel, 1e-8) << what << "\ncodyna:\n" << ab.first << "\noctave:\n" << ab.second;
  }
  const MatrixXd Km = place(Am, Bm, pr), Km_octave = parse_matrix(r.output, "Km");
  const double ours = pole_error(Am - Bm * Km, pr), theirs = pole_error(Am - Bm * Km_octave, pr);
  std::cout << "[   peer   ] place (random 5x5, 2 inputs): pole error codyna " << ours << ", octave " << theirs
            << "; ||K|| codyna " << Km.norm() << ", octave " << Km_octave.norm() << "\n";
  EXPECT_LT(ours, 1e-8);
  EXPECT_LT(theirs, 1e-8);
}

}  // namespace
}  // namespace codyna
