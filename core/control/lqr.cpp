#include "control/lqr.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace codyna {
namespace {

using Eigen::Index;
using Eigen::MatrixXcd;
using Eigen::MatrixXd;
using Eigen::VectorXcd;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kResidualLimit = 1e-10;  // backward error of X accepted at the end
constexpr double kSymmetryTol = 1e-10;   // relative asymmetry accepted in Q and R
constexpr int kMaxSignIterations = 100;
constexpr int kMaxSdaIterations = 100;
constexpr int kNewtonSteps = 3;

// ------------------------------------------------------------------ messages

std::string size_of(const MatrixXd& M) { return std::to_string(M.rows()) + "x" + std::to_string(M.cols()); }

std::string number(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

std::string number(std::complex<double> z) {
  return number(z.real()) + (z.imag() < 0 ? " - " : " + ") + number(std::abs(z.imag())) + "i";
}

[[noreturn]] void fail(const std::string& who, const std::string& what) {
  throw std::invalid_argument(who + ": " + what);
}

std::string no_stabilizing_solution(bool discrete) {
  return std::string("no stabilizing solution: (A, B) may not be stabilizable or (Q, A) may have unobservable modes on the ") +
         (discrete ? "unit circle" : "imaginary axis");
}

// ------------------------------------------------------------------ small helpers

double norm1(const MatrixXd& M) { return M.size() == 0 ? 0.0 : M.cwiseAbs().colwise().sum().maxCoeff(); }

MatrixXd symmetric_part(const MatrixXd& M) { return 0.5 * (M + M.transpose()); }

// the complex Schur form A = U T U^*, T upper triangular
struct SchurForm {
  MatrixXcd T, U;
};

SchurForm complex_schur(const MatrixXd& A) {
  Eigen::ComplexSchur<MatrixXd> s(A);
  if (s.info() != Eigen::Success) throw std::invalid_argument("complex Schur decomposition did not converge");
  return {s.matrixT(), s.matrixU()};
}

// a triangular system whose diagonal is this close to zero makes the equation singular
double singular_limit(const MatrixXcd& S, const MatrixXcd& T) {
  return 10 * kEps * (S.cwiseAbs().maxCoeff() + T.cwiseAbs().maxCoeff() + std::numeric_limits<double>::min());
}

void check_square(const std::string& who, const std::string& name, const MatrixXd& M) {
  if (M.rows() != M.cols()) fail(who, name + " is " + size_of(M) + ", expected a square matrix");
  if (!M.allFinite()) fail(who, name + " has NaN or Inf entries");
}

}  // namespace

// ------------------------------------------------------------------ linear matrix equations

Eigen::MatrixXd sylvester(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C) {
  check_square("sylvester", "A", A);
  check_square("sylvester", "B", B);
  const Index n = A.rows(), m = B.rows();
  if (C.rows() != n || C.cols() != m)
    fail("sylvester", "C is " + size_of(C) + ", expected " + std::to_string(n) + "x" + std::to_string(m));
  if (n == 0 || m == 0) return MatrixXd::Zero(n, m);

  // S Y + Y T = U^* C V with A = U S U^*, B = V T V^*, solved column by column:
  // (S + T_jj I) y_j = f_j - sum_{l<j} y_l T_lj
  const SchurForm a = complex_schur(A), b = complex_schur(B);
  const MatrixXcd F = a.U.adjoint() * C * b.U;
  const double tiny = singular_limit(a.T, b.T);
  MatrixXcd Y(n, m);
  for (Index j = 0; j < m; ++j) {
    MatrixXcd M = a.T;
    M.diagonal().array() += b.T(j, j);
    if (M.diagonal().cwiseAbs().minCoeff() <= tiny)
      fail("sylvester", "singular equation: A and -B have a common eigenvalue");
    const Eigen::VectorXcd rhs = F.col(j) - Y.leftCols(j) * b.T.col(j).head(j);
    Y.col(j) = M.triangularView<Eigen::Upper>().solve(rhs);
  }
  return (a.U * Y * b.U.adjoint()).real();
}

Eigen::MatrixXd lyap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q) {
  check_square("lyap", "A", A);
  if (Q.rows() != A.rows() || Q.cols() != A.rows())
    fail("lyap", "Q is " + size_of(Q) + ", expected " + size_of(A) + " to match A");
  try {
    return sylvester(A, A.transpose(), -Q);
  } catch (const std::invalid_argument&) {
    fail("lyap", "singular equation: A has eigenvalues with lambda_i + lambda_j = 0");
  }
}

Eigen::MatrixXd dlyap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q) {
  check_square("dlyap", "A", A);
  const Index n = A.rows();
  if (Q.rows() != n || Q.cols() != n) fail("dlyap", "Q is " + size_of(Q) + ", expected " + size_of(A) + " to match A");
  if (n == 0) return MatrixXd(0, 0);

  // T Y T^* - Y + C = 0 with A = U T U^*, C = U^* Q U, from the last column back:
  // (conj(T_jj) T - I) y_j = -c_j - T r_j,  r_j = sum_{l>j} y_l conj(T_jl)
  const SchurForm a = complex_schur(A);
  const MatrixXcd C = a.U.adjoint() * Q * a.U;
  const double tiny = singular_limit(a.T, MatrixXcd::Identity(1, 1));
  MatrixXcd Y(n, n);
  for (Index j = n - 1; j >= 0; --j) {
    const Index tail = n - 1 - j;
    const Eigen::VectorXcd r = Y.rightCols(tail) * a.T.row(j).tail(tail).adjoint();
    MatrixXcd M = std::conj(a.T(j, j)) * a.T;
    M.diagonal().array() -= 1.0;
    if (M.diagonal().cwiseAbs().minCoeff() <= tiny)
      fail("dlyap", "singular equation: A has eigenvalues with lambda_i lambda_j = 1");
    const Eigen::VectorXcd rhs = -C.col(j) - a.T * r;
    Y.col(j) = M.triangularView<Eigen::Upper>().solve(rhs);
  }
  return (a.U * Y * a.U.adjoint()).real();
}

namespace {

// ------------------------------------------------------------------ the Riccati problem

// The checked data and the cross-term-free form (Ar, G, Qr) both solvers work on.
struct Riccati {
  std::string who;
  bool discrete = false;
  MatrixXd A, B, Q, R, N;  // as given (Q, R symmetrized; N zero if it was empty)
  Eigen::LLT<MatrixXd> R_llt;
  MatrixXd Ar, G, Qr;      // A - B R^-1 N', B R^-1 B', Q - N R^-1 N'
};

void check_symmetric(const std::string& who, const std::string& name, const MatrixXd& M) {
  const double asym = (M - M.transpose()).cwiseAbs().maxCoeff();
  if (asym > kSymmetryTol * M.cwiseAbs().maxCoeff())
    fail(who, name + " is not symmetric (max |" + name + " - " + name + "'| = " + number(asym) + ")");
}

void check_sizes(const std::string& who, const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q, const MatrixXd& R,
                 const MatrixXd& N) {
  const Index n = A.rows(), m = B.cols();
  const std::string sn = std::to_string(n), sm = std::to_string(m);
  if (A.cols() != n || n == 0) fail(who, "A is " + size_of(A) + ", expected a non-empty square matrix");
  if (B.rows() != n || m == 0)
    fail(who, "B is " + size_of(B) + ", expected " + sn + " rows to match A (" + size_of(A) + ") and at least one column");
  if (Q.rows() != n || Q.cols() != n)
    fail(who, "Q is " + size_of(Q) + ", expected " + sn + "x" + sn + " to match A (" + size_of(A) + ")");
  if (R.rows() != m || R.cols() != m)
    fail(who, "R is " + size_of(R) + ", expected " + sm + "x" + sm + " to match the columns of B (" + size_of(B) + ")");
  if (N.size() != 0 && (N.rows() != n || N.cols() != m))
    fail(who, "N is " + size_of(N) + ", expected " + sn + "x" + sm + " (rows of A by columns of B)");
  const std::pair<const char*, const MatrixXd*> all[] = {{"A", &A}, {"B", &B}, {"Q", &Q}, {"R", &R}, {"N", &N}};
  for (const auto& [name, M] : all)
    if (!M->allFinite()) fail(who, std::string(name) + " has NaN or Inf entries");
}

Riccati make_riccati(const std::string& who, bool discrete, const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q,
                     const MatrixXd& R, const MatrixXd& N) {
  check_sizes(who, A, B, Q, R, N);
  check_symmetric(who, "Q", Q);
  check_symmetric(who, "R", R);
  Riccati p;
  p.who = who;
  p.discrete = discrete;
  p.A = A;
  p.B = B;
  p.Q = symmetric_part(Q);
  p.R = symmetric_part(R);
  p.N = N.size() == 0 ? MatrixXd::Zero(A.rows(), B.cols()) : N;

  // R must be safely invertible: its eigenvalues positive and not lost in rounding
  const Eigen::VectorXd r_eig = Eigen::SelfAdjointEigenSolver<MatrixXd>(p.R, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(r_eig.minCoeff() > 100 * kEps * r_eig.cwiseAbs().maxCoeff()))
    fail(who, "R is not symmetric positive definite (smallest eigenvalue " + number(r_eig.minCoeff()) + ")");
  p.R_llt.compute(p.R);

  const MatrixXd Rinv_Bt = p.R_llt.solve(B.transpose()), Rinv_Nt = p.R_llt.solve(p.N.transpose());
  p.G = symmetric_part(B * Rinv_Bt);
  p.Ar = A - B * Rinv_Nt;
  p.Qr = symmetric_part(p.Q - p.N * Rinv_Nt);
  return p;
}

// ------------------------------------------------------------------ residuals

// The relative residual is a normwise backward error: ||residual||_F over the
// bound of each term by norm products, e.g. ||Q|| + 2 ||A|| ||X|| + ||G|| ||X||^2.
// (Dividing by the norms of the computed terms instead would call accurate
// solutions of ill-conditioned problems wrong: with ||B'X|| << ||B|| ||X||
// those terms are computed with cancellation.)
struct Residual {
  MatrixXd value;        // the left-hand side of the Riccati equation at X
  double relative = 0;   // ||value||_F over the norm-product bound of its terms
  MatrixXd closed_loop;  // Ar - G X (continuous) or Ar - B F (discrete), = A - B K
};

double relative_to(const MatrixXd& value, double bound) {
  return value.norm() / std::max(bound, std::numeric_limits<double>::min());
}

Residual care_residual(const Riccati& p, const MatrixXd& X) {
  const MatrixXd AtX = p.Ar.transpose() * X;
  Residual r;
  r.value = symmetric_part(AtX + AtX.transpose() - X * p.G * X + p.Qr);
  const double x = X.norm();
  r.relative = relative_to(r.value, p.Qr.norm() + 2 * p.Ar.norm() * x + p.G.norm() * x * x);
  r.closed_loop = p.Ar - p.G * X;
  return r;
}

Residual dare_residual(const Riccati& p, const MatrixXd& X) {
  const MatrixXd XB = X * p.B;
  const Eigen::PartialPivLU<MatrixXd> S(p.R + p.B.transpose() * XB);
  const MatrixXd F = S.solve(XB.transpose() * p.Ar);  // (R + B'XB)^-1 B'X Ar
  Residual r;
  r.value = symmetric_part(p.Ar.transpose() * X * p.Ar - X - p.Ar.transpose() * XB * F + p.Qr);
  const double x = X.norm(), a = p.Ar.norm(), b = p.B.norm();
  const double S_inv = S.inverse().norm();
  r.relative = relative_to(r.value, p.Qr.norm() + x + a * a * x + a * a * b * b * x * x * S_inv);
  r.closed_loop = p.Ar - p.B * F;
  return r;
}

Residual residual(const Riccati& p, const MatrixXd& X) { return p.discrete ? dare_residual(p, X) : care_residual(p, X); }

// ------------------------------------------------------------------ continuous: matrix sign function

// J M J for J = [0 I; -I 0]
MatrixXd j_m_j(const MatrixXd& M) {
  const Index n = M.rows() / 2;
  MatrixXd out(2 * n, 2 * n);
  out << -M.bottomRightCorner(n, n), M.bottomLeftCorner(n, n), M.topRightCorner(n, n), -M.topLeftCorner(n, n);
  return out;
}

// Newton's iteration for sign(H) of a Hamiltonian H, run on Y = J H, which
// stays symmetric because the iterates stay Hamiltonian (Byers 1987):
// Y <- (c Y + J Y^-1 J / c) / 2 with the determinant scaling
// c = |det Y|^(-1/2n) until the iterates settle. Returns X with [I; X]
// spanning the stable invariant subspace of H.
MatrixXd stable_subspace_by_sign_function(const Riccati& p, MatrixXd Y) {
  const Index n = p.A.rows();
  const std::string axis = p.discrete ? "unit circle" : "imaginary axis";
  bool scaling = true, converged = false;
  double last_change = std::numeric_limits<double>::infinity();
  for (int k = 0; k < kMaxSignIterations && !converged; ++k) {
    const Eigen::PartialPivLU<MatrixXd> lu(Y);
    if (!(lu.rcond() > kEps))
      fail(p.who, no_stabilizing_solution(p.discrete) + " (the Hamiltonian has eigenvalues on or near the " + axis + ")");
    double c = 1.0;
    if (scaling) c = std::exp(-lu.matrixLU().diagonal().array().abs().log().sum() / static_cast<double>(2 * n));
    const MatrixXd next = symmetric_part(0.5 * (c * Y + j_m_j(lu.inverse()) / c));
    const double change = norm1(next - Y), size = norm1(next);
    Y = next;
    if (!Y.allFinite()) break;
    // near the limit scaling only slows the quadratic phase (Higham 2008, sec. 5.5)
    if (change <= 1e-2 * size) scaling = false;
    converged = change <= 1e-13 * size || (!scaling && change >= last_change && change <= 1e-6 * size);
    last_change = change;
  }
  if (!converged)
    fail(p.who, no_stabilizing_solution(p.discrete) + " (the sign function iteration did not converge)");

  // W = sign(H) = -J Y; the stable subspace [I; X] is the null space of W + I:
  // [W12; W22 + I] X = -[W11 + I; W21]
  const MatrixXd I = MatrixXd::Identity(n, n);
  MatrixXd M(2 * n, n), rhs(2 * n, n);
  M << -Y.bottomRightCorner(n, n), Y.topRightCorner(n, n) + I;
  rhs << Y.bottomLeftCorner(n, n) - I, -Y.topLeftCorner(n, n);
  const Eigen::ColPivHouseholderQR<MatrixXd> qr(M);
  if (qr.rank() < n)
    fail(p.who, no_stabilizing_solution(p.discrete) + " (the stable invariant subspace is not the graph of a matrix)");
  return symmetric_part(qr.solve(rhs));
}

// X = s X~ turns (G, Q) into (s G, Q / s); s = sqrt(||Q|| / ||G||) gives both
// the same norm, which keeps the Hamiltonian (or the pencil) balanced when the
// weights are far apart in size. The refinement works on the unscaled equation.
double balancing_scale(const Riccati& p) {
  const double q = p.Qr.norm(), g = p.G.norm();
  return q > 0 && g > 0 ? std::sqrt(q / g) : 1.0;
}

MatrixXd care_by_sign_function(const Riccati& p) {
  const double s = balancing_scale(p);
  MatrixXd Y(2 * p.A.rows(), 2 * p.A.rows());
  Y << -p.Qr / s, -p.Ar.transpose(), -p.Ar, s * p.G;  // J H for H = [Ar -sG; -Qr/s -Ar']
  return s * stable_subspace_by_sign_function(p, Y);
}

// The DARE's symplectic pencil M - lambda L, M = [Ar 0; -Qr I], L = [I G; 0 Ar'],
// has the deflating subspace [I; X] for |lambda| < 1. The Cayley transform
// mu = (lambda - 1) / (lambda + 1) maps it to the stable invariant subspace of
// the Hamiltonian (M + L)^-1 (M - L) (Gardiner & Laub 1986). No detectability
// of (Qr, Ar) is needed, unlike for SDA.
MatrixXd dare_by_cayley_sign_function(const Riccati& p) {
  const Index n = p.A.rows();
  const MatrixXd I = MatrixXd::Identity(n, n);
  const double s = balancing_scale(p);
  const MatrixXd G = s * p.G, Q = p.Qr / s;
  MatrixXd sum(2 * n, 2 * n), difference(2 * n, 2 * n);
  sum << p.Ar + I, G, -Q, I + p.Ar.transpose();
  difference << p.Ar - I, -G, -Q, I - p.Ar.transpose();
  const Eigen::PartialPivLU<MatrixXd> lu(sum);
  if (!(lu.rcond() > kEps))
    fail(p.who, no_stabilizing_solution(true) + " (the symplectic pencil has an eigenvalue at or near -1)");
  const MatrixXd H = lu.solve(difference);
  MatrixXd JH(2 * n, 2 * n);
  JH << H.bottomRows(n), -H.topRows(n);  // J H for J = [0 I; -I 0]
  return s * stable_subspace_by_sign_function(p, symmetric_part(JH));
}

// ------------------------------------------------------------------ discrete: doubling

// SDA: A <- A W^-1 A, G <- G + A W^-1 G A', H <- H + A' H W^-1 A with
// W = I + G H; H converges quadratically to X when a stabilizing X exists.
MatrixXd dare_by_doubling(const Riccati& p) {
  const Index n = p.A.rows();
  const MatrixXd I = MatrixXd::Identity(n, n);
  const double s = balancing_scale(p);
  MatrixXd Ak = p.Ar, Gk = s * p.G, Hk = p.Qr / s;
  bool converged = false;
  double last_change = std::numeric_limits<double>::infinity();
  for (int k = 0; k < kMaxSdaIterations && !converged; ++k) {
    const Eigen::PartialPivLU<MatrixXd> lu(I + Gk * Hk);
    if (!(lu.rcond() > kEps)) break;
    const MatrixXd W_A = lu.solve(Ak), W_G = lu.solve(Gk);
    const MatrixXd H_next = symmetric_part(Hk + Ak.transpose() * Hk * W_A);
    Gk = symmetric_part(Gk + Ak * W_G * Ak.transpose());
    Ak = Ak * W_A;
    const double change = norm1(H_next - Hk), size = norm1(H_next);
    Hk = H_next;
    if (!Hk.allFinite() || !Gk.allFinite() || !Ak.allFinite()) break;
    converged = change <= 1e-14 * size || (change >= last_change && change <= 1e-8 * size);
    last_change = change;
  }
  if (!converged) fail(p.who, no_stabilizing_solution(true) + " (the doubling iteration did not converge)");
  return s * Hk;
}

// ------------------------------------------------------------------ refinement and checks

// Newton steps in correction form: the Frechet derivative of the Riccati
// operator at X is D -> Ac' D + D Ac (Kleinman) or Ac' D Ac - D (Hewer), so
// the step solves a Lyapunov equation with the residual on the right.
MatrixXd refine(const Riccati& p, MatrixXd X) {
  Residual r = residual(p, X);
  for (int k = 0; k < kNewtonSteps && r.relative > kEps; ++k) {
    MatrixXd D;
    try {
      const MatrixXd Act = r.closed_loop.transpose();
      D = p.discrete ? dlyap(Act, r.value) : lyap(Act, r.value);
    } catch (const std::invalid_argument&) {
      break;  // closed loop not stable enough to refine; the final check decides
    }
    const MatrixXd X_next = symmetric_part(X + D);
    Residual r_next = residual(p, X_next);
    if (!(r_next.relative < r.relative)) break;
    X = X_next;
    r = std::move(r_next);
  }
  return X;
}

bool is_stable(const VectorXcd& poles, bool discrete, double scale) {
  const double margin = 100 * kEps;
  for (const auto& s : poles)
    if (discrete ? !(std::abs(s) < 1.0 - margin) : !(s.real() < -margin * scale)) return false;
  return true;
}

VectorXcd sorted_eigenvalues(const MatrixXd& M) {
  VectorXcd e = Eigen::EigenSolver<MatrixXd>(M, false).eigenvalues();
  std::sort(e.data(), e.data() + e.size(), [](const auto& a, const auto& b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  return e;
}

// X is accepted only if it solves the equation and stabilizes the loop
void check_solution(const Riccati& p, const MatrixXd& X) {
  const Residual r = residual(p, X);
  if (!(r.relative <= kResidualLimit))
    fail(p.who, no_stabilizing_solution(p.discrete) + " (relative Riccati residual " + number(r.relative) + ")");
  const VectorXcd poles = sorted_eigenvalues(r.closed_loop);
  if (!is_stable(poles, p.discrete, norm1(r.closed_loop))) {
    const auto worst = p.discrete ? *std::max_element(poles.begin(), poles.end(),
                                                      [](auto a, auto b) { return std::abs(a) < std::abs(b); })
                                  : poles[poles.size() - 1];
    fail(p.who, no_stabilizing_solution(p.discrete) + " (closed-loop pole " + number(worst) + ")");
  }
}

MatrixXd solve(const Riccati& p) {
  if (p.discrete) {
    try {
      const MatrixXd X = refine(p, dare_by_doubling(p));
      check_solution(p, X);
      return X;
    } catch (const std::invalid_argument&) {
      // SDA converges to the stabilizing X only when (Qr, Ar) is detectable;
      // the Cayley-transformed sign function covers the remaining cases
    }
  }
  const MatrixXd X = refine(p, p.discrete ? dare_by_cayley_sign_function(p) : care_by_sign_function(p));
  check_solution(p, X);
  return X;
}

LqrResult design(const Riccati& p) {
  LqrResult out;
  out.X = solve(p);
  if (p.discrete) {
    const MatrixXd XB = out.X * p.B;
    out.K = (p.R + p.B.transpose() * XB).partialPivLu().solve(XB.transpose() * p.A + p.N.transpose());
  } else {
    out.K = p.R_llt.solve(p.B.transpose() * out.X + p.N.transpose());
  }
  out.closed_loop_poles = sorted_eigenvalues(p.A - p.B * out.K);
  return out;
}

}  // namespace

// ------------------------------------------------------------------ public API

LqrResult lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R,
              const Eigen::MatrixXd& N) {
  return design(make_riccati("lqr", false, A, B, Q, R, N));
}

LqrResult dlqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R,
               const Eigen::MatrixXd& N) {
  return design(make_riccati("dlqr", true, A, B, Q, R, N));
}

Eigen::MatrixXd care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& N) {
  return solve(make_riccati("care", false, A, B, Q, R, N));
}

Eigen::MatrixXd dare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& N) {
  return solve(make_riccati("dare", true, A, B, Q, R, N));
}

}  // namespace codyna
