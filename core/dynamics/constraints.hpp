// Loop-closure constraints phi(q) = 0 (see ConstraintModel), stacked in
// model order:
//   ball             phi = p_a - p_b                          (world, 3 rows)
//   revolute         ball rows, then a . b1, a . b2            (a = axis_a on body_a,
//                                                               b1, b2 perpendicular to axis_b on body_b)
//   planar_revolute  e1 . (p_a - p_b), e2 . (p_a - p_b)         (e1, e2 perpendicular to axis_a, on body_a)
//   coupler          sum_k ratio_k q_k - offset                  (scalar joint coordinates, 1 row; Jc constant)
// constraint_residual(q):   writes liMi, oMi, Sb, phi.
// constraint_terms(q, v):   + v, cJ, a (at qdd = 0), Jc = d phi/dq (tangent), gamma = dJc/dt v,
//                           so that d2/dt2 phi = Jc qdd + gamma.
// constraint_jacobian_after_kinematics(q): phi and Jc only, from the positions data holds: call it
//                           after forward kinematics at q (of any stage: rnea's, crba's); no
//                           kinematics of its own, gamma not written (the Newton iterations of alf).
#pragma once

#include <utility>

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& constraint_residual(const Model& model, DataT<S>& data, const VecXT<S>& q);

template <class S>
void constraint_terms(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v);

void constraint_jacobian_after_kinematics(const Model& model, Data& data, const Eigen::VectorXd& q);
// constraint_violation_after_kinematics(q, v): the drift (max |phi|, max |Jc v|) from the
// positions data holds (phi and Jc written; 0, 0 without loops)
std::pair<double, double> constraint_violation_after_kinematics(const Model& model, Data& data, const Eigen::VectorXd& q,
                                                                 const Eigen::VectorXd& v);
// constraint_gamma_after_positions(q, v): phi and gamma (v, cJ, a at qdd = 0 written) from the
// positions data holds (after forward kinematics at q of any stage); Jc not written
void constraint_gamma_after_positions(const Model& model, Data& data, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

}  // namespace codyna
