// Figures of merit of a response (analysis/response_figures): overshoot and settling time against
// the closed forms of a second-order step response, and the linear model's gap against a
// hand-made pair of signals.
#include "analysis/response_figures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace codyna {
namespace {

// the error of an underdamped second-order step response, y - 1 = -exp(-zeta wn t) (cos wd t +
// zeta / sqrt(1 - zeta^2) sin wd t)
double second_order_error(double zeta, double wn, double t) {
  const double s = std::sqrt(1 - zeta * zeta), wd = wn * s;
  return -std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta / s * std::sin(wd * t));
}

TEST(ResponseFigures, SecondOrderStepOvershootIsTheClosedForm) {
  for (const double zeta : {0.1, 0.3, 0.5, 0.7}) {
    const double wn = 3.0, dt = 1e-4;
    std::vector<double> t;
    for (double ti = 0; ti <= 40; ti += dt) t.push_back(ti);
    Eigen::MatrixXd e(static_cast<Eigen::Index>(t.size()), 1);
    for (std::size_t i = 0; i < t.size(); ++i) e(static_cast<Eigen::Index>(i), 0) = second_order_error(zeta, wn, t[i]);
    Eigen::VectorXd overshoot(1), settling(1);
    response_figures(t, e, overshoot, settling);
    // E = |e(0)| = 1: the overshoot is the first peak past the target, exp(-pi zeta / sqrt(1 - zeta^2));
    // sampled at dt the peak is missed by at most O(dt^2) of its curvature
    const double closed = 100 * std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta));
    EXPECT_NEAR(overshoot[0], closed, 1e-5) << "zeta " << zeta;
    // settling into 2 % for good: the last time |e| = 0.02, found by bisection on the closed form
    // beside the sampled answer (linear between samples: within dt^2 times the slope's change)
    double last = 0;
    for (std::size_t i = t.size() - 1; i > 0; --i)
      if (std::abs(second_order_error(zeta, wn, t[i - 1])) > 0.02) {
        double a = t[i - 1], b = t[i];
        for (int it = 0; it < 60; ++it) {
          const double m = 0.5 * (a + b);
          (std::abs(second_order_error(zeta, wn, m)) > 0.02 ? a : b) = m;
        }
        last = 0.5 * (a + b);
        break;
      }
    EXPECT_NEAR(settling[0], last, 1e-6) << "zeta " << zeta;
  }
}

TEST(ResponseFigures, LinearGapIsTheLargestDifferenceAndWhenItPassesOnePercent) {
  const std::vector<double> t{0, 1, 2, 3, 4};
  Eigen::MatrixXd y(5, 2), yl(5, 2);
  // output 0 goes 0 -> 2 (range 2 about its final value); the linear run lags by 0.01, 0.05, 0.3
  y.col(0) << 0, 1, 2, 2, 2;
  yl.col(0) << 0, 0.99, 1.95, 2.3, 2;
  // output 1: equal runs
  y.col(1) << 1, 2, 3, 4, 5;
  yl.col(1) = y.col(1);
  const LinearGap g = linear_gap(t, y, yl);
  ASSERT_EQ(g.largest.size(), 2);
  EXPECT_NEAR(g.largest[0], 0.3, 1e-15);  // |2 - 2.3| in binary
  EXPECT_NEAR(g.percent[0], 15.0, 1e-12);
  EXPECT_DOUBLE_EQ(g.from[0], 2.0);  // 0.05 > 1 % of 2 first at t = 2 (0.01 is not)
  EXPECT_DOUBLE_EQ(g.largest[1], 0.0);
  EXPECT_DOUBLE_EQ(g.from[1], -1.0);
  // a linear run of other sizes is no comparison
  EXPECT_EQ(linear_gap(t, y, Eigen::MatrixXd(4, 2)).largest.size(), 0);
}

}  // namespace
}  // namespace codyna
