// Transmission zeros of one channel (analysis/zeros.hpp) against closed forms: rational
// transfer functions realized by hand, and the cart-pendulum's force-to-cart-position channel,
// whose zeros are the poles of the pendulum with the cart held (s^2 = 3 g / (2 l) for the
// paper's uniform rod), and by a second method: H vanishes at each zero.
#include "analysis/zeros.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

LinearSystem siso(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::RowVectorXd& c, double d) {
  LinearSystem s;
  s.A = A;
  s.B = b;
  s.C = c;
  s.D = Eigen::MatrixXd::Constant(1, 1, d);
  return s;
}

std::complex<double> channel(const LinearSystem& s, int j, int i, std::complex<double> at) {
  const Eigen::Index n = s.A.rows();
  const Eigen::MatrixXcd M = at * Eigen::MatrixXcd::Identity(n, n) - s.A.cast<std::complex<double>>();
  const Eigen::VectorXcd x = M.partialPivLu().solve(s.B.col(j).cast<std::complex<double>>());
  return s.C.row(i).cast<std::complex<double>>().dot(x) + s.D(i, j);
}

TEST(Zeros, RationalTransferFunctions) {
  Eigen::MatrixXd A(2, 2);
  A << 0, 1, -3, -4;  // (s + 1)(s + 3)
  // (s + 2) / ((s + 1)(s + 3))
  ChannelZeros z = transmission_zeros(siso(A, Eigen::Vector2d(0, 1), Eigen::RowVector2d(2, 1), 0.0), 0, 0);
  ASSERT_EQ(z.zeros.size(), 1);
  EXPECT_NEAR(z.zeros[0].real(), -2.0, 1e-12);
  EXPECT_EQ(z.zeros[0].imag(), 0.0);
  // 1 + 1 / (s + 1) = (s + 2) / (s + 1): a feed-through moves the zero
  z = transmission_zeros(siso(Eigen::MatrixXd::Constant(1, 1, -1), Eigen::VectorXd::Ones(1), Eigen::RowVectorXd::Ones(1), 1.0), 0, 0);
  ASSERT_EQ(z.zeros.size(), 1);
  EXPECT_NEAR(z.zeros[0].real(), -2.0, 1e-12);
  // (s^2 + 2 s + 5) / (s^3 + ...): a complex pair -1 +- 2j
  Eigen::MatrixXd A3(3, 3);
  A3 << 0, 1, 0, 0, 0, 1, -6, -11, -6;
  z = transmission_zeros(siso(A3, Eigen::Vector3d(0, 0, 1), Eigen::RowVector3d(5, 2, 1), 0.0), 0, 0);
  ASSERT_EQ(z.zeros.size(), 2);
  EXPECT_NEAR(z.zeros[0].real(), -1.0, 1e-10);
  EXPECT_NEAR(z.zeros[0].imag(), -2.0, 1e-10);
  EXPECT_NEAR(z.zeros[1].imag(), 2.0, 1e-10);
  // 1 / (s^2 + 1): none; a channel that is zero everywhere: said so
  A << 0, 1, -1, 0;
  z = transmission_zeros(siso(A, Eigen::Vector2d(0, 1), Eigen::RowVector2d(1, 0), 0.0), 0, 0);
  EXPECT_EQ(z.zeros.size(), 0);
  EXPECT_FALSE(z.identically_zero);
  z = transmission_zeros(siso(A, Eigen::Vector2d(0, 1), Eigen::RowVector2d(0, 0), 0.0), 0, 0);
  EXPECT_TRUE(z.identically_zero);
  EXPECT_THROW(transmission_zeros(siso(A, Eigen::Vector2d(0, 1), Eigen::RowVector2d(1, 0), 0.0), 1, 0),
               std::invalid_argument);
}

TEST(Zeros, CartPendulumCartPositionHasTheHeldCartPendulumsPoles) {
  const Model m = test::load_example("cart_pendulum.json");
  const Linearization lin = linearize(m, static_equilibrium(m, initial_point(m)));
  const LinearSystem& s = lin.system;
  const auto& out = s.output_names;
  const int h = static_cast<int>(std::find(out.begin(), out.end(), "h") - out.begin());
  ASSERT_LT(h, static_cast<int>(out.size()));
  const ChannelZeros z = transmission_zeros(s, 0, h);
  ASSERT_EQ(z.zeros.size(), 2);  // 4 states, relative degree 2
  const double l = 2.0, g = 9.81, expected = std::sqrt(3 * g / (2 * l));
  EXPECT_NEAR(z.zeros[0].real(), -expected, 1e-9);
  EXPECT_NEAR(z.zeros[1].real(), expected, 1e-9);
  for (Eigen::Index k = 0; k < 2; ++k) {
    EXPECT_EQ(z.zeros[k].imag(), 0.0);
    // H vanishes there, against its size nearby
    EXPECT_LT(std::abs(channel(s, 0, h, z.zeros[k])), 1e-10 * std::abs(channel(s, 0, h, 2.0 * z.zeros[k])));
  }
}

}  // namespace
}  // namespace codyna
