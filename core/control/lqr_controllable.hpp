// LQR on the controllable part of a plant that is not stabilizable as a whole
// (an undriven rotation of a spherical pendulum, a free yaw): the design that
// a user of lqr would make by hand with a Kalman decomposition.
//
// The controllable subspace (the smallest A-invariant subspace containing
// range B) gets an orthonormal basis Tc by the controllability staircase
// (rank decisions by SVD with a relative tolerance). With Ac = Tc' A Tc,
// Bc = Tc' B, Qc = Tc' Q Tc (and Nc = Tc' N):
//   Kc = lqr(Ac, Bc, Qc, R, Nc),  K = Kc Tc'   (u = -K x, as lqr)
// The closed loop A - B K is block triangular in [Tc Tu]: its poles are
// eig(Ac - Bc Kc) and the uncontrollable eigenvalues eig(Tu' A Tu), which no
// feedback can move; they are returned so that the caller can say them.
#pragma once

#include <Eigen/Core>

#include "control/lqr.hpp"

namespace codyna {

struct ControllablePartLqr {
  LqrResult lqr;                        // K (m x n), X (n x n, = Tc Xc Tc'), closed_loop_poles (n)
  Eigen::MatrixXd Tc;                   // n x nc, orthonormal basis of the controllable subspace
  Eigen::MatrixXd Tu;                   // n x (n - nc), its orthogonal complement
  Eigen::VectorXcd uncontrollable_poles;  // eig(Tu' A Tu)
};

// Orthonormal basis of the controllable subspace of (A, B); rank decisions at
// tol * max(||A||, ||B||, 1) (tol default 1e-10).
Eigen::MatrixXd controllable_subspace(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double tol = 1e-10);

// Throws std::invalid_argument as lqr() does (sizes, NaN, Q, R), and when the
// controllable part itself has no stabilizing solution.
ControllablePartLqr lqr_controllable_part(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                          const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R,
                                          const Eigen::MatrixXd& N = {});

}  // namespace codyna
