// Figures of merit of a response: overshoot and settling time per output (docs/parameter-studies.md,
// "Figures of merit"), what a parameter study records of each variant's closed-loop run.
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

}  // namespace codyna
