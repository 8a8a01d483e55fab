// Small dense solvers written for any scalar type (double, or the autodiff
// scalar used for exact derivatives), so that derivatives flow through solves
// without relying on Eigen's decompositions supporting custom scalars.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace codyna {

// Solves A X = B for symmetric positive definite A (Cholesky, A = L L^T).
// Throws std::runtime_error if A is not positive definite.
template <class S>
Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> cholesky_solve(
    const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>& A,
    const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>& B) {
  using std::sqrt;
  const Eigen::Index n = A.rows();
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> L = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    S d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > S(0))) throw std::runtime_error("matrix is not positive definite");
    L(j, j) = sqrt(d);
    for (Eigen::Index i = j + 1; i < n; ++i) {
      S s = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / L(j, j);
    }
  }
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> X = B;
  for (Eigen::Index c = 0; c < X.cols(); ++c) {
    for (Eigen::Index i = 0; i < n; ++i) {  // L y = b
      S s = X(i, c);
      for (Eigen::Index k = 0; k < i; ++k) s -= L(i, k) * X(k, c);
      X(i, c) = s / L(i, i);
    }
    for (Eigen::Index i = n - 1; i >= 0; --i) {  // L^T x = y
      S s = X(i, c);
      for (Eigen::Index k = i + 1; k < n; ++k) s -= L(k, i) * X(k, c);
      X(i, c) = s / L(i, i);
    }
  }
  return X;
}

// Solves A X = B for a square nonsingular A (LU with partial pivoting).
template <class S>
Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> lu_solve(
    Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> A,
    Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> X) {
  using std::abs;
  const Eigen::Index n = A.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::Index piv = k;
    for (Eigen::Index i = k + 1; i < n; ++i)
      if (abs(A(i, k)) > abs(A(piv, k))) piv = i;
    if (A(piv, k) == S(0)) throw std::runtime_error("matrix is singular");
    if (piv != k) {
      A.row(k).swap(A.row(piv));
      X.row(k).swap(X.row(piv));
    }
    for (Eigen::Index i = k + 1; i < n; ++i) {
      const S f = A(i, k) / A(k, k);
      // skipped only when it is zero with its derivatives: an autodiff entry whose value is 0
      // where it varies (a sin at 0) still carries them
      if constexpr (std::is_arithmetic_v<S>) {
        if (f == S(0)) continue;
      } else {
        if (f.value() == 0.0 && (f.derivatives().size() == 0 || f.derivatives().isZero(0))) continue;
      }
      for (Eigen::Index j = k + 1; j < n; ++j) A(i, j) -= f * A(k, j);
      for (Eigen::Index c = 0; c < X.cols(); ++c) X(i, c) -= f * X(k, c);
    }
  }
  for (Eigen::Index c = 0; c < X.cols(); ++c)
    for (Eigen::Index i = n - 1; i >= 0; --i) {
      S s = X(i, c);
      for (Eigen::Index j = i + 1; j < n; ++j) s -= A(i, j) * X(j, c);
      X(i, c) = s / A(i, i);
    }
  return X;
}

}  // namespace codyna
