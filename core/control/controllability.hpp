// Which modes of dx = A x + B u the inputs cannot move, and which the outputs of
// y = C x cannot see: the Popov-Belevitch-Hautus test, one eigenvalue at a time.
// A mode lambda is uncontrollable when rank [A - lambda I, B] < n (a left
// eigenvector w with w^H B = 0), unobservable when rank [A - lambda I; C] < n.
// Each mode is named by the states that dominate its shape, so a user reads
// "the yaw of the spherical pendulum" rather than an index.
//
// Cost: one eigen decomposition and one SVD of an n x (n + m) matrix per
// eigenvalue, O(n^4); fine for the plants of mechanisms (n up to a few hundred).
#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

namespace codyna {

struct HiddenMode {
  std::complex<double> eigenvalue;
  std::vector<std::string> states;  // dominant states of its shape (|entry| >= 0.5 of the largest), largest first
  double margin = 0;                // smallest singular value of the PBH matrix, relative to its largest
};

// rel_tol: a PBH matrix whose smallest singular value is below rel_tol times its largest is rank deficient
std::vector<HiddenMode> uncontrollable_modes(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                             const std::vector<std::string>& state_names, double rel_tol = 1e-9);
std::vector<HiddenMode> unobservable_modes(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C,
                                           const std::vector<std::string>& state_names, double rel_tol = 1e-9);

// "lambda = 0 (ball.wz, ball.wz_dot); lambda = ..." for messages
std::string describe(const std::vector<HiddenMode>& modes);

}  // namespace codyna
