// place: state-feedback pole placement, u = -K x with eig(A - B K) = poles.
//
// Method: the Sylvester-equation method (Bhattacharyya & de Souza 1982,
// Systems & Control Letters 1; also Tsui). With Lambda the real block-diagonal
// form of the poles (a conjugate pair s +- iw as the block [s w; -w s]) and a
// parameter matrix G (m x n), solve
//     A X - X Lambda = B G,    then   K = G X^-1,
// so that (A - B K) X = X Lambda. X is solved by Bartels-Stewart on complex
// Schur forms (see sylvester() in control/lqr.hpp); no characteristic
// polynomial is formed (Ackermann's formula loses accuracy quickly with n).
//
// Single input (m = 1): K is unique, so K equals Octave's / MATLAB's place().
// Multiple inputs: K is not unique. Several deterministic pseudo-random G are
// tried and the one whose eigenvector matrix X has the smallest condition
// number is kept (kappa(X) bounds the sensitivity of the placed poles, the
// robustness measure of Kautsky, Nichols & Van Dooren 1985). The resulting K
// places the same poles as Octave's place() but generally differs from it.
//
// Controllability is decided by the orthogonal staircase reduction
// (controllability Hessenberg form; Van Dooren 1981, IEEE TAC 26) with a
// relative rank tolerance of 1e-10. If A already has an eigenvalue at (or
// very near) a requested pole, a pseudo-random pre-feedback K0 first moves
// A's spectrum away; then K = K0 + K1.
//
// Cost: O(n^3) per trial (two complex Schur forms and an SVD of n x n).
#pragma once

#include <Eigen/Core>

namespace codyna {

// poles: n entries, complex ones in conjugate pairs. A pole may repeat at most
// rank(B) times (a repeated pole needs that many independent eigenvectors).
// Throws std::invalid_argument for mismatched sizes, NaN/Inf entries, poles
// not in conjugate pairs, poles repeated beyond rank(B), or (A, B) not
// controllable (naming the modes that cannot be moved); std::runtime_error if
// the placed poles miss the requested ones by more than 1e-6 relative (a
// numerically ill-conditioned placement).
Eigen::MatrixXd place(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::VectorXcd& poles);

}  // namespace codyna
