// Figures of merit of a response: overshoot and settling time per output (docs/parameter-studies.md,
// "Figures of merit"), what a parameter study records of each variant's closed-loop run; and the
// gap between a nonlinear run and the linear model's run beside it (codyna simulate
// --compare-linear).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace codyna {

// Per column of e (samples x outputs, y - target at times t): the overshoot in % of the
// excursion E = max |e| past the target, on the side opposite to the excursion, and the time e
// enters the band |e| <= 0.02 E for good (e linear between samples), NaN when the last sample is
// outside it; E = 0: 0 % at t[0]. docs/parameter-studies.md, "Figures of merit".
void response_figures(const std::vector<double>& t, const Eigen::MatrixXd& e, Eigen::VectorXd& overshoot,
                      Eigen::VectorXd& settling);

// The linear model's gap per output column of y (samples x outputs, the nonlinear run) from
// y_linear (the linear model's run at the same times t): the largest |y - y_linear|, that in % of
// the output's range about its final value (max |y - y(end)|, at least 1e-12), and the first time
// the gap passes 1 % of that range (-1 when it never does). Empty when y_linear does not have y's rows.
struct LinearGap {
  Eigen::VectorXd largest, percent, from;
};
LinearGap linear_gap(const std::vector<double>& t, const Eigen::MatrixXd& y, const Eigen::MatrixXd& y_linear);

}  // namespace codyna
