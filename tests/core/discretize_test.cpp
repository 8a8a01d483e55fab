// analysis/discretize: exact zero-order hold against closed forms (the Octave
// c2d peer check is in mat_export_test.cpp, OctavePeer.C2dMatchesDiscretizeZoh).
#include "analysis/discretize.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

LinearSystem double_integrator() {
  LinearSystem s;
  s.A = Eigen::Matrix2d{{0, 1}, {0, 0}};
  s.B = Eigen::Vector2d(0, 1);
  s.C = Eigen::RowVector2d(1, 0);
  s.D = Eigen::MatrixXd::Zero(1, 1);
  s.x0 = Eigen::Vector2d(0.3, 0);
  s.state_names = {"p", "v"};
  s.method = "exact";
  return s;
}

TEST(DiscretizeZoh, DoubleIntegratorMatchesClosedForm) {
  for (double T : {1e-3, 0.01, 0.5, 3.0}) {
    const LinearSystem d = discretize_zoh(double_integrator(), T);
    EXPECT_TRUE(MatrixNear(d.A, Eigen::Matrix2d{{1, T}, {0, 1}}, 1e-15)) << "T = " << T;
    EXPECT_TRUE(MatrixNear(d.B, Eigen::Vector2d(T * T / 2, T), 1e-15)) << "T = " << T;
    EXPECT_EQ(d.Ts, T);
  }
}

TEST(DiscretizeZoh, ScalarSystemIsExponential) {
  for (double a : {-3.0, -0.1, 0.7}) {
    LinearSystem s;
    s.A = Eigen::MatrixXd::Constant(1, 1, a);
    s.B = Eigen::MatrixXd::Constant(1, 1, 2.0);
    s.C = Eigen::MatrixXd::Constant(1, 1, 1.0);
    s.D = Eigen::MatrixXd::Zero(1, 1);
    const double T = 0.2;
    const LinearSystem d = discretize_zoh(s, T);
    EXPECT_NEAR(d.A(0, 0), std::exp(a * T), 1e-15);
    EXPECT_NEAR(d.B(0, 0), 2.0 * std::expm1(a * T) / a, 1e-15);
  }
}

TEST(DiscretizeZoh, KeepsOutputsNamesOffsetsAndProvenance) {
  const LinearSystem c = double_integrator();
  const LinearSystem d = discretize_zoh(c, 0.1);
  EXPECT_TRUE(MatrixNear(d.C, c.C, 0.0));
  EXPECT_TRUE(MatrixNear(d.D, c.D, 0.0));
  EXPECT_TRUE(MatrixNear(d.x0, c.x0, 0.0));
  EXPECT_EQ(d.state_names, c.state_names);
  EXPECT_EQ(d.method, c.method);
}

TEST(DiscretizeZoh, WorksWithoutInputs) {
  LinearSystem s = double_integrator();
  s.B.resize(2, 0);
  s.D.resize(1, 0);
  const LinearSystem d = discretize_zoh(s, 0.5);
  EXPECT_TRUE(MatrixNear(d.A, Eigen::Matrix2d{{1, 0.5}, {0, 1}}, 1e-15));
  EXPECT_EQ(d.B.rows(), 2);
  EXPECT_EQ(d.B.cols(), 0);
}

TEST(DiscretizeZoh, StaticGainHasNoStates) {
  LinearSystem s;
  s.A.resize(0, 0);
  s.B.resize(0, 2);
  s.C.resize(1, 0);
  s.D = Eigen::RowVector2d(3, 4);
  const LinearSystem d = discretize_zoh(s, 0.1);
  EXPECT_EQ(d.A.size(), 0);
  EXPECT_EQ(d.B.cols(), 2);
  EXPECT_TRUE(MatrixNear(d.D, s.D, 0.0));
  EXPECT_EQ(d.Ts, 0.1);
}

TEST(DiscretizeZoh, RejectsBadSampleTimeAndDiscreteInput) {
  const LinearSystem c = double_integrator();
  for (double T : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    EXPECT_THROW(discretize_zoh(c, T), std::invalid_argument) << T;
  const LinearSystem d = discretize_zoh(c, 0.1);
  try {
    discretize_zoh(d, 0.1);
    ADD_FAILURE() << "a discrete system was discretized again";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("already discrete"), std::string::npos) << e.what();
  }
  LinearSystem bad = c;
  bad.B.resize(3, 1);
  EXPECT_THROW(discretize_zoh(bad, 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace codyna
