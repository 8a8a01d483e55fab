// Linearization of the plant (Plant/In -> Plant/Out) at an operating point,
// in minimal coordinates (see plant_function.hpp for the state):
//   dx = A x + B u,  y = C x + D u   about (x0, u0, y0), with xdot0 = f(x0, u0).
// Jacobians two ways behind one interface:
//   Exact            analytic derivatives of the recursive algorithms at the
//                    operating point, trees and closed loops
//                    (dynamics/derivatives.hpp); at off-point states forward-mode
//                    automatic differentiation of the same Scalar-templated
//                    dynamics (default)
//   ForwardDifference (f(x + h e) - f(x)) / h,      h = sqrt(eps) max(1, |x_i|)
//   CentralDifference (f(x + h e) - f(x - h e)) / 2h, h = cbrt(eps) max(1, |x_i|)
//                    (on trees the velocity and input columns reuse the
//                    position stage: PlantFunction::fd_jacobian)
// The finite-difference results carry an accuracy estimate: their largest
// difference from the exact Jacobian, relative to its largest entry.
#pragma once

#include <string>
#include <vector>

#include "analysis/linear_system.hpp"
#include "analysis/operating_point.hpp"
#include "analysis/plant_function.hpp"

namespace codyna {

enum class JacobianMethod { Exact, ForwardDifference, CentralDifference };
const char* to_string(JacobianMethod m);  // "exact", "fd-forward", "fd-central"

struct LinearizeOptions {
  JacobianMethod method = JacobianMethod::Exact;
  std::vector<std::string> independent;  // closed loops: coordinate names to keep (empty = automatic)
};

struct Linearization {
  LinearSystem system;
  CoordinatePartition partition;
  double fd_error = 0.0;  // finite differences: max |J_fd - J_exact| / max |J_exact|; 0 for exact
  // motion inputs among Plant/In: the state is xi = x - motion_rate_shift u' - motion_shift u
  // (deviations; see linearize.cpp), which keeps the model proper; both empty without them
  Eigen::MatrixXd motion_shift, motion_rate_shift;  // [nx x nu]
  // About a steady motion that turns (OperatingPoint::motion; steady_motion.hpp): the state's
  // largest rate |x'| left at the operating point in the moving frame (0 for a relative
  // equilibrium), and the largest change of A a time further along the motion, relative to its
  // largest entry (of its eigenvalues, relative to their largest modulus, when a body spins or a
  // planar joint turns: their states' axes turn; 0 when A is the motion's). Both 0 otherwise.
  bool about_motion = false;
  double motion_residual = 0.0, motion_drift = 0.0;
};

Linearization linearize(const Model& model, const OperatingPoint& op, const LinearizeOptions& options = {});

// The full Jacobian [A B; C D] of the plant function at x, u (for checks and trim).
Eigen::MatrixXd plant_jacobian(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                               JacobianMethod method);

// Finite differences by a full evaluation of f per perturbed column (what
// plant_jacobian did before PlantFunction::fd_jacobian; still its path for
// closed loops): the reference that fd_jacobian is checked against.
Eigen::MatrixXd plant_jacobian_fd_full(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                       bool central);

// The same by forward-mode automatic differentiation of PlantFunction::eval,
// always (the independent check of the analytic path).
Eigen::MatrixXd plant_jacobian_autodiff(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u);

}  // namespace codyna
