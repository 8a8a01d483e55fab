// lqr / dlqr: linear-quadratic regulator design, and the algebraic Riccati
// equations (care / dare) and Lyapunov / Sylvester equations behind it.
//
// Sign convention (as MATLAB's and Octave's lqr, dlqr): u = -K x.
//
// Continuous, x' = A x + B u, minimizes  J = int_0^inf x'Qx + u'Ru + 2 x'Nu dt:
//   A'X + XA - (XB + N) R^-1 (B'X + N') + Q = 0,      K = R^-1 (B'X + N')
// Discrete, x[k+1] = A x[k] + B u[k], minimizes  J = sum_k x'Qx + u'Ru + 2 x'Nu:
//   A'XA - X - (A'XB + N)(R + B'XB)^-1 (B'XA + N') + Q = 0,
//                                                     K = (R + B'XB)^-1 (B'XA + N')
// X is the symmetric stabilizing solution: eig(A - BK) lies in the open left
// half plane (continuous) or inside the unit circle (discrete).
//
// The cross term is removed first by the usual change of variables
// (A, Q) -> (A - B R^-1 N', Q - N R^-1 N'), G = B R^-1 B'. Then
//   care: the matrix sign function of the Hamiltonian [A -G; -Q -A'], by
//         Newton's iteration with determinant scaling in Byers' symmetric form
//         (Roberts 1971/1980; Byers 1987, Lin. Alg. Appl. 85), and X from its
//         stable invariant subspace by a least-squares solve;
//   dare: the structure-preserving doubling algorithm SDA (Chu, Fan, Lin &
//         Wang 2004, Int. J. Control 77; convergence: Lin & Xu 2006, SIAM J.
//         Matrix Anal. Appl. 28);
// each followed by up to three Newton refinement steps (Kleinman 1968 /
// Hewer 1971) in correction form, which bring the residual to rounding level.
// Before iterating, G and Q are balanced to equal norms (X = s X~).
// X is accepted if its relative residual, a normwise backward error
// (||residual||_F / (||Q|| + 2 ||A|| ||X|| + ||G|| ||X||^2), and its discrete
// analogue), is below 1e-10 and A - B K is stable; otherwise the solvers throw.
// A discrete problem on which SDA fails (it needs (Q, A) detectable, e.g. not
// Q = 0 with A unstable) is solved again by the sign function of the Cayley
// transformed symplectic pencil (Gardiner & Laub 1986).
//
// Cost: O(n^3) per iteration; about 10-20 sign or 5-30 doubling iterations
// of (2n)^3 resp. n^3, plus two Schur decompositions per Newton step.
#pragma once

#include <Eigen/Core>

namespace codyna {

struct LqrResult {
  Eigen::MatrixXd K;                  // m x n, u = -K x
  Eigen::MatrixXd X;                  // n x n, symmetric stabilizing Riccati solution
  Eigen::VectorXcd closed_loop_poles;  // n, eig(A - B K), sorted by real then imaginary part
};

// Throws std::invalid_argument for mismatched sizes (naming the matrices and
// their sizes), NaN/Inf entries, Q not symmetric, R not symmetric positive
// definite, or when no stabilizing solution exists ("no stabilizing solution:
// (A, B) may not be stabilizable or (Q, A) may have unobservable modes on the
// imaginary axis" / "... unit circle"). N may be empty (no cross term).
LqrResult lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
              const Eigen::MatrixXd& R, const Eigen::MatrixXd& N = {});
LqrResult dlqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
               const Eigen::MatrixXd& R, const Eigen::MatrixXd& N = {});

// The stabilizing solutions X of the Riccati equations above (same checks).
Eigen::MatrixXd care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& N = {});
Eigen::MatrixXd dare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const Eigen::MatrixXd& N = {});

// Linear matrix equations, MATLAB's conventions, by Bartels-Stewart on complex
// Schur forms (Bartels & Stewart 1972); O(n^3). Throw std::invalid_argument
// when the equation is singular (eigenvalue conditions below, to rounding).
//   sylvester: A X + X B = C            (no eigenvalue of A equals one of -B)
//   lyap:      A X + X A' + Q = 0       (no lambda_i + lambda_j = 0)
//   dlyap:     A X A' - X + Q = 0       (no lambda_i lambda_j = 1)
Eigen::MatrixXd sylvester(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C);
Eigen::MatrixXd lyap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q);
Eigen::MatrixXd dlyap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q);

}  // namespace codyna
