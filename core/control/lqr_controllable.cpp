#include "control/lqr_controllable.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace codyna {

namespace {
// columns of Z not in the span of the orthonormal basis T (appended to T); returns them
Eigen::MatrixXd add_new_directions(Eigen::MatrixXd& T, const Eigen::MatrixXd& Z, double thresh) {
  Eigen::MatrixXd R = Z;
  if (T.cols() > 0) {
    R -= T * (T.transpose() * R);
    R -= T * (T.transpose() * R);  // twice is enough (Kahan-Parlett)
  }
  if (R.cols() == 0) return Eigen::MatrixXd(T.rows(), 0);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeThinU);
  int r = 0;
  for (Eigen::Index k = 0; k < svd.singularValues().size(); ++k)
    if (svd.singularValues()[k] > thresh) ++r;
  const Eigen::MatrixXd U = svd.matrixU().leftCols(r);
  Eigen::MatrixXd T2(T.rows(), T.cols() + r);
  T2 << T, U;
  T = T2;
  return U;
}
}  // namespace

Eigen::MatrixXd controllable_subspace(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double tol) {
  const Eigen::Index n = A.rows();
  if (A.cols() != n || B.rows() != n)
    throw std::invalid_argument("controllable_subspace: A must be n x n and B n x m (A is " + std::to_string(A.rows()) +
                                " x " + std::to_string(A.cols()) + ", B " + std::to_string(B.rows()) + " x " +
                                std::to_string(B.cols()) + ")");
  const double scale = std::max({A.norm(), B.norm(), 1.0});
  const double thresh = tol * scale;
  Eigen::MatrixXd T(n, 0);
  Eigen::MatrixXd fresh = add_new_directions(T, B, thresh);
  while (fresh.cols() > 0 && T.cols() < n) fresh = add_new_directions(T, A * fresh, thresh);
  return T;
}

ControllablePartLqr lqr_controllable_part(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                          const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R,
                                          const Eigen::MatrixXd& N) {
  const Eigen::Index n = A.rows();
  if (!A.allFinite() || !B.allFinite())
    throw std::invalid_argument("lqr: A and B must be finite");
  ControllablePartLqr out;
  out.Tc = controllable_subspace(A, B);
  const Eigen::Index nc = out.Tc.cols();
  // orthogonal complement
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(out.Tc);
  const Eigen::MatrixXd full = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  out.Tu = full.rightCols(n - nc);
  if (nc == 0) throw std::invalid_argument("lqr: the inputs move no state (the controllable part is empty)");
  if (Q.rows() != n || Q.cols() != n)
    throw std::invalid_argument("lqr: Q must be " + std::to_string(n) + " x " + std::to_string(n));
  const Eigen::MatrixXd Ac = out.Tc.transpose() * A * out.Tc, Bc = out.Tc.transpose() * B;
  Eigen::MatrixXd Qc = out.Tc.transpose() * Q * out.Tc;
  Qc = 0.5 * (Qc + Qc.transpose()).eval();
  const Eigen::MatrixXd Nc = N.size() ? Eigen::MatrixXd(out.Tc.transpose() * N) : Eigen::MatrixXd();
  const LqrResult rc = lqr(Ac, Bc, Qc, R, Nc);
  out.lqr.K = rc.K * out.Tc.transpose();
  out.lqr.X = out.Tc * rc.X * out.Tc.transpose();
  if (n - nc > 0) {
    out.uncontrollable_poles = Eigen::EigenSolver<Eigen::MatrixXd>(out.Tu.transpose() * A * out.Tu, false).eigenvalues();
  }
  Eigen::VectorXcd poles(n);
  poles << rc.closed_loop_poles, out.uncontrollable_poles;
  std::sort(poles.data(), poles.data() + n, [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  out.lqr.closed_loop_poles = poles;
  return out;
}

}  // namespace codyna
