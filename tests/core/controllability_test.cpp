// PBH tests of controllability and observability (control/controllability.hpp).
#include "control/controllability.hpp"

#include <gtest/gtest.h>

using namespace codyna;

TEST(Controllability, NamesTheModesTheInputsCannotMove) {
  // two decoupled double integrators, only the first driven, only the second measured
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4, 4);
  A(0, 1) = 1;
  A(2, 3) = 1;
  A(3, 2) = -4;  // the second one oscillates at 2 rad/s
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(4, 1), C = Eigen::MatrixXd::Zero(1, 4);
  B(1, 0) = 1;
  C(0, 2) = 1;
  const std::vector<std::string> names{"a", "a_dot", "b", "b_dot"};
  const auto uc = uncontrollable_modes(A, B, names);
  ASSERT_EQ(uc.size(), 1u);
  EXPECT_NEAR(uc[0].eigenvalue.real(), 0.0, 1e-12);
  EXPECT_NEAR(uc[0].eigenvalue.imag(), 2.0, 1e-12);
  // named by the second integrator's states only
  ASSERT_FALSE(uc[0].states.empty());
  EXPECT_EQ(uc[0].states.front(), "b");
  for (const auto& n : uc[0].states) EXPECT_TRUE(n == "b" || n == "b_dot") << n;
  const auto uo = unobservable_modes(A, C, names);
  ASSERT_EQ(uo.size(), 1u);
  EXPECT_NEAR(std::abs(uo[0].eigenvalue), 0.0, 1e-9);
  EXPECT_EQ(uo[0].states.front(), "a");
  EXPECT_EQ(describe(uc).substr(0, 20), "lambda = 0 +/- 2i (b");
  // fully controllable and observable: nothing named
  B(3, 0) = 1;
  C(0, 0) = 1;
  EXPECT_TRUE(uncontrollable_modes(A, B, names).empty());
  EXPECT_TRUE(unobservable_modes(A, C, names).empty());
}
