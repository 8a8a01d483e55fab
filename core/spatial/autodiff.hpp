// The scalar used for exact derivatives: forward-mode automatic
// differentiation (Eigen's AutoDiffScalar) with a dynamic derivative vector.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <type_traits>
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

// Gives every entry of m a derivative vector of the common size (constants
// carry an empty one). Eigen's AutoDiffScalar makes sizes coherent only between
// evaluated scalars; inside an unevaluated product or sum an empty vector beside
// a full one is a size mismatch (an assertion with assertions on, silently
// lost derivatives without). Call it on matrices and vectors that mix
// constants with variables before products and dot products. No-op for double.
// n: the derivative size (0: the largest found in m).
template <class Derived>
void ad_make_coherent(Eigen::MatrixBase<Derived>& m, Eigen::Index n = 0) {
  if constexpr (std::is_same_v<typename Derived::Scalar, ADScalar>) {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i) n = std::max(n, m(i, j).derivatives().size());
    if (n == 0) return;
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i)
        if (m(i, j).derivatives().size() == 0) m(i, j).derivatives().setZero(n);
  }
}

// the largest derivative size among the entries of m (0 for double)
template <class Derived>
Eigen::Index ad_size(const Eigen::MatrixBase<Derived>& m) {
  Eigen::Index n = 0;
  if constexpr (std::is_same_v<typename Derived::Scalar, ADScalar>)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i) n = std::max(n, m(i, j).derivatives().size());
  return n;
}

// a scalar with a derivative vector of size n (zeros when it had none)
inline ADScalar ad_coherent(ADScalar s, Eigen::Index n) {
  if (s.derivatives().size() == 0 && n > 0) s.derivatives().setZero(n);
  return s;
}
inline double ad_coherent(double s, Eigen::Index) { return s; }

inline double ad_value(const ADScalar& s) { return s.value(); }
inline double ad_value(double s) { return s; }

}  // namespace codyna
