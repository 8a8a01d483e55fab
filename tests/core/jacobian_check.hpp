// The plant function's analytic Jacobian (TreeDerivatives) against automatic differentiation of
// its eval<ADScalar> and against central differences, as the rolling tests check it at random states.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"

namespace codyna::test {

// equal to tol of the largest entry, which is returned (0 when there was nothing to compare)
inline double expect_analytic_equals_autodiff(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                              const std::string& label, double tol = 1e-12) {
  Eigen::MatrixXd Ja;
  if (!f.analytic_jacobian(x, u, Ja)) {
    ADD_FAILURE() << label << ": no analytic Jacobian";
    return 0.0;
  }
  const Eigen::MatrixXd Jd = plant_jacobian_autodiff(f, x, u);
  if (Ja.rows() != Jd.rows() || Ja.cols() != Jd.cols()) {
    ADD_FAILURE() << label << ": " << Ja.rows() << " x " << Ja.cols() << " against " << Jd.rows() << " x " << Jd.cols();
    return 0.0;
  }
  const double scale = Jd.cwiseAbs().maxCoeff();
  Eigen::Index ir = 0, ic = 0;
  const double worst = (Ja - Jd).cwiseAbs().maxCoeff(&ir, &ic);
  EXPECT_LT(worst, tol * scale) << label << " at (" << ir << ", " << ic << "): " << Ja(ir, ic) << " vs " << Jd(ir, ic);
  return scale;
}

// plant_jacobian's exact method at (x, u) against central differences of the whole plant function
// (position deviations too), to tol of the largest entry, which is returned
inline double expect_exact_equals_central_differences(const PlantFunction& f, const Eigen::VectorXd& x,
                                                      const Eigen::VectorXd& u, const std::string& label, double tol) {
  const Eigen::MatrixXd Ja = plant_jacobian(f, x, u, JacobianMethod::Exact);
  const Eigen::MatrixXd Jf = plant_jacobian_fd_full(f, x, u, true);
  const double scale = Ja.cwiseAbs().maxCoeff();
  Eigen::Index ir = 0, ic = 0;
  const double worst = (Ja - Jf).cwiseAbs().maxCoeff(&ir, &ic);
  EXPECT_LT(worst, tol * scale) << label << " at (" << ir << ", " << ic << "): " << Ja(ir, ic) << " vs " << Jf(ir, ic);
  return scale;
}

}  // namespace codyna::test
