// The scalar used for exact derivatives: forward-mode automatic
// differentiation (Eigen's AutoDiffScalar) with a dynamic derivative vector.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace codyna {

using ADScalar = Eigen::AutoDiffScalar<Eigen::VectorXd>;
using ADVec = Eigen::Matrix<ADScalar, Eigen::Dynamic, 1>;

// Seeds x as the independent variables: x_i gets derivative e_i (of size n, starting at offset).
inline ADVec ad_seed(const Eigen::VectorXd& x, int n, int offset) {
  ADVec r(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i)
    r[i] = ADScalar(x[i], Eigen::VectorXd::Unit(n, offset + i));
  return r;
}

inline ADVec ad_constant(const Eigen::VectorXd& x, int n) {
  ADVec r(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) r[i] = ADScalar(x[i], Eigen::VectorXd::Zero(n));
  return r;
}

inline double ad_value(const ADScalar& s) { return s.value(); }
inline double ad_value(double s) { return s; }

}  // namespace codyna
