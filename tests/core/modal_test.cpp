// analysis/modal: eigenvalues, frequency, damping and shapes against closed forms.
#include "analysis/modal.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "analysis/discretize.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

// m x'' + c x' + k x = u with m = 2, c = 2, k = 50: wn = 5 rad/s, zeta = 0.1
LinearSystem mass_spring_damper() {
  const double m = 2, c = 2, k = 50;
  LinearSystem s;
  s.A = Eigen::Matrix2d{{0, 1}, {-k / m, -c / m}};
  s.B = Eigen::Vector2d(0, 1 / m);
  s.C = Eigen::RowVector2d(1, 0);
  s.D = Eigen::MatrixXd::Zero(1, 1);
  s.state_names = {"x", "x_dot"};
  return s;
}

// MISSION.md example 1 at the upright position: theta'' = (3g/4) dtheta + 0.075 u
LinearSystem upright_pendulum() {
  const double g = 9.81;
  LinearSystem s;
  s.A = Eigen::Matrix2d{{0, 1}, {3 * g / 4, 0}};
  s.B = Eigen::Vector2d(0, 0.075);
  s.C = Eigen::RowVector2d(1, 0);
  s.D = Eigen::MatrixXd::Zero(1, 1);
  s.state_names = {"theta", "theta_dot"};
  return s;
}

void expect_is_mode_of(const Eigen::MatrixXd& A, const Mode& m) {
  EXPECT_NEAR(m.shape.cwiseAbs().maxCoeff(), 1.0, 1e-15);
  Eigen::Index k;
  m.shape.cwiseAbs().maxCoeff(&k);
  EXPECT_EQ(m.shape(k), std::complex<double>(1.0, 0.0));
  EXPECT_LE((A.cast<std::complex<double>>() * m.shape - m.eigenvalue * m.shape).norm(), 1e-12);
}

TEST(ModalAnalysis, MassSpringDamperHasKnownFrequencyAndDamping) {
  const LinearSystem s = mass_spring_damper();
  const ModalAnalysis ma = modal_analysis(s);
  ASSERT_EQ(ma.modes.size(), 2u);
  const double wd = 5 * std::sqrt(1 - 0.01);
  EXPECT_NEAR(ma.modes[0].eigenvalue.real(), -0.5, 1e-12);
  EXPECT_NEAR(ma.modes[0].eigenvalue.imag(), -wd, 1e-12);  // sorted by frequency, then imaginary part
  EXPECT_NEAR(ma.modes[1].eigenvalue.imag(), wd, 1e-12);
  for (const Mode& m : ma.modes) {
    EXPECT_NEAR(m.natural_frequency, 5.0, 1e-12);
    EXPECT_NEAR(m.damping_ratio, 0.1, 1e-12);
    EXPECT_EQ(m.s, m.eigenvalue);
    expect_is_mode_of(s.A, m);
  }
  EXPECT_EQ(ma.state_names, s.state_names);
}

TEST(ModalAnalysis, UprightPendulumHasRealPairPlusMinusSqrt3gOver4) {
  const LinearSystem s = upright_pendulum();
  const ModalAnalysis ma = modal_analysis(s);
  ASSERT_EQ(ma.modes.size(), 2u);
  const double r = std::sqrt(3 * 9.81 / 4);
  EXPECT_NEAR(ma.modes[0].eigenvalue.real(), -r, 1e-12);
  EXPECT_NEAR(ma.modes[1].eigenvalue.real(), r, 1e-12);
  EXPECT_EQ(ma.modes[0].eigenvalue.imag(), 0.0);
  EXPECT_EQ(ma.modes[0].damping_ratio, 1.0);   // real negative
  EXPECT_EQ(ma.modes[1].damping_ratio, -1.0);  // real positive: the unstable mode
  for (const Mode& m : ma.modes) {
    EXPECT_NEAR(m.natural_frequency, r, 1e-12);
    expect_is_mode_of(s.A, m);
  }
}

TEST(ModalAnalysis, ZeroEigenvalueReportsLikeDamp) {
  LinearSystem s = mass_spring_damper();
  s.A = Eigen::Matrix2d{{0, 1}, {0, 0}};  // a free mass
  for (const Mode& m : modal_analysis(s).modes) {
    EXPECT_EQ(m.natural_frequency, 0.0);
    EXPECT_EQ(m.damping_ratio, -1.0);  // what damp() says in MATLAB and Octave
  }
}

TEST(ModalAnalysis, DiscreteSystemKeepsZAndRecoversContinuousFrequency) {
  const double Ts = 0.01;
  const LinearSystem c = mass_spring_damper();
  const ModalAnalysis ma = modal_analysis(discretize_zoh(c, Ts));
  const ModalAnalysis mc = modal_analysis(c);
  ASSERT_EQ(ma.modes.size(), 2u);
  EXPECT_EQ(ma.Ts, Ts);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LE(std::abs(ma.modes[i].eigenvalue - std::exp(mc.modes[i].eigenvalue * Ts)), 1e-13);  // z = e^(lambda Ts)
    EXPECT_LE(std::abs(ma.modes[i].s - mc.modes[i].eigenvalue), 1e-10);
    EXPECT_NEAR(ma.modes[i].natural_frequency, 5.0, 1e-10);
    EXPECT_NEAR(ma.modes[i].damping_ratio, 0.1, 1e-10);
  }
}

TEST(ModalAnalysis, FormatsAReadableTable) {
  const std::string table = format_modes(modal_analysis(upright_pendulum()));
  EXPECT_NE(table.find("wn (rad/s)"), std::string::npos) << table;
  EXPECT_NE(table.find("f (Hz)"), std::string::npos) << table;
  EXPECT_NE(table.find("-2.71247 + 0j"), std::string::npos) << table;
  EXPECT_NE(table.find("0.431703"), std::string::npos) << table;  // sqrt(3g/4) / (2 pi) Hz
  EXPECT_NE(table.find("theta_dot (1.00)\n"), std::string::npos) << table;  // theta is 1/2.71 = 0.37 < 0.5
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 3);
  const std::string discrete = format_modes(modal_analysis(discretize_zoh(mass_spring_damper(), 0.01)));
  EXPECT_NE(discrete.find("s = log(z)/Ts"), std::string::npos) << discrete;
  EXPECT_NE(discrete.find("Ts = 0.01 s"), std::string::npos) << discrete;
}

TEST(ModalAnalysis, RejectsNonSquareOrNonFiniteA) {
  LinearSystem s = mass_spring_damper();
  s.A.resize(2, 3);
  EXPECT_THROW(modal_analysis(s), std::invalid_argument);
  s = mass_spring_damper();
  s.A(1, 0) = std::nan("");
  EXPECT_THROW(modal_analysis(s), std::invalid_argument);
  s.A.resize(0, 0);
  EXPECT_TRUE(modal_analysis(s).modes.empty());
}

}  // namespace
// A repeated zero eigenvalue (a floating body: twelve rigid-body modes in Jordan chains of
// length 2 and 4) is one row with the states of its generalized eigenspace, whatever the
// computed eigenvalues scatter to; its damping is "-". The chains are hidden by a similarity
// with a well-conditioned random T, so the computed eigenvalues are eps^(1/4) ~ 1e-4 off zero.
TEST(ModalAnalysis, RepeatedZeroIsOneRowWithItsStates) {
  // a pendulum on a cart: x, theta, x_dot, theta_dot; zero (x2: position and rate of the cart) and +-wn
  LinearSystem cart;
  cart.A = Eigen::Matrix4d{{0, 0, 1, 0}, {0, 0, 0, 1}, {0, -2.0, 0, 0}, {0, 24.0, 0, 0}};
  cart.B = Eigen::MatrixXd::Zero(4, 1);
  cart.C = Eigen::MatrixXd::Zero(1, 4);
  cart.D = Eigen::MatrixXd::Zero(1, 1);
  cart.state_names = {"x", "theta", "x_dot", "theta_dot"};
  const ModalAnalysis mc = modal_analysis(cart);
  EXPECT_EQ(mc.zero_count, 2);
  // the cart's position and velocity lie in the zero space; theta and theta_dot do not (the +-sqrt(24) modes)
  EXPECT_EQ(mc.zero_states, (std::vector<int>{0, 2}));
  const std::string table = format_modes(mc);
  EXPECT_NE(table.find("1-2   0 (x2)"), std::string::npos) << table;
  EXPECT_NE(table.find(" -         x, x_dot\n"), std::string::npos) << table;
  EXPECT_NE(table.find("3     -4.89898 + 0j"), std::string::npos) << table;
  EXPECT_NE(table.find("4     4.89898 + 0j                 4.89898       0.779697      -1.0000"), std::string::npos) << table;
  EXPECT_NE(table.find("a rigid-body motion or an integrator"), std::string::npos) << table;

  // a free body at hover: x'' = g ry, y'' = -g rx, z'' and the three angular accelerations are inputs
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(12, 12);
  J.topRightCorner(6, 6).setIdentity();
  J(9, 1) = 9.81;
  J(10, 0) = -9.81;
  LinearSystem body;
  body.B = Eigen::MatrixXd::Zero(12, 1);
  body.C = Eigen::MatrixXd::Zero(1, 12);
  body.D = Eigen::MatrixXd::Zero(1, 1);
  for (const char* n : {"rx", "ry", "rz", "x", "y", "z", "wx", "wy", "wz", "vx", "vy", "vz"}) body.state_names.push_back(n);
  body.A = J;
  const ModalAnalysis exact = modal_analysis(body);
  EXPECT_EQ(exact.zero_count, 12);
  EXPECT_EQ(exact.zero_states.size(), 12u);
  const std::string t = format_modes(exact);
  EXPECT_NE(t.find("1-12  0 (x12)"), std::string::npos) << t;
  EXPECT_EQ(std::count(t.begin(), t.end(), '\n'), 3) << t;  // header, the one row, the note

  // the same chains seen through a similarity: scattered eigenvalues, the same zero space
  std::srand(7);
  const Eigen::MatrixXd T = Eigen::MatrixXd::Identity(12, 12) + 0.2 * Eigen::MatrixXd::Random(12, 12);
  body.A = T * J * T.inverse();
  const ModalAnalysis scattered = modal_analysis(body);
  double largest = 0;
  for (const Mode& m : scattered.modes) largest = std::max(largest, std::abs(m.eigenvalue));
  EXPECT_GT(largest, 1e-6);  // the computed eigenvalues are visibly not zero ...
  EXPECT_EQ(scattered.zero_count, 12);  // ... but the zero space is found whole
  EXPECT_NE(format_modes(scattered).find("1-12  0 (x12)"), std::string::npos);

  // discrete: z = 1 (ZOH of the cart) is the same row
  const ModalAnalysis d = modal_analysis(discretize_zoh(cart, 0.01));
  EXPECT_EQ(d.zero_count, 2);
  EXPECT_NE(format_modes(d).find("1-2   1 (x2)"), std::string::npos) << format_modes(d);
}

}  // namespace codyna
