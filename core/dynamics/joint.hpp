// Joint kinematics and configuration-space operations.
//
// joint_transform: X_FM(q) (pose of the child joint frame M in the parent
//   joint frame F) and the motion subspace S_M (6 x nv, M coordinates), so the
//   joint velocity is v_J = S_M qd. Reads q[idx_q .. idx_q+nq).
// joint_bias: c_J = (d/dt S_M) qd in M coordinates (non-zero for universal
//   and planar joints).
// integrate / difference / qdot / normalize: q lives on a manifold (quaternions
//   for spherical and free joints), v in its tangent space; integrate(q, dv) is
//   the retraction q (+) dv used by Newton solves, linearization and integrators,
//   difference its inverse.
#pragma once

#include <Eigen/Core>

#include "model/model.hpp"
#include "spatial/spatial.hpp"

namespace codyna {

template <class S>
void joint_transform(const JointModel& j, const VecXT<S>& q, SE3T<S>& X_FM, Mat6xT<S>& S_M);

template <class S>
Vec6T<S> joint_bias(const JointModel& j, const VecXT<S>& q, const VecXT<S>& v);

// q (+) dv, size nq
template <class S>
VecXT<S> integrate(const Model& model, const VecXT<S>& q, const VecXT<S>& dv);

// the same into r (no allocation when r already has size nq)
template <class S>
void integrate_into(const Model& model, const VecXT<S>& q, const VecXT<S>& dv, VecXT<S>& r);

// The one quaternion log and exp of the tree (what integrate and difference use for ball and free
// joints): the rotation vector (|r| <= pi, the shorter way round) of a quaternion (w, x, y, z),
// normalized first (a zero quaternion gives 0), and the unit quaternion of a rotation vector.
Eigen::Vector3d rotation_log(const Eigen::Vector4d& wxyz);
Eigen::Vector4d rotation_exp(const Eigen::Vector3d& r);

// dv such that integrate(q0, dv) == q1 (double only)
Eigen::VectorXd difference(const Model& model, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1);

// time derivative of q for velocity v, size nq
template <class S>
VecXT<S> qdot(const Model& model, const VecXT<S>& q, const VecXT<S>& v);

// d/dt of a tangent deviation dq (q = integrate(q_ref, dq), q_ref fixed) for
// velocity v: v itself for additive coordinates; Jr^-1(dq) w for rotations,
// Exp(dq_w) v_lin for the translation of a free joint. Size nv.
template <class S>
VecXT<S> tangent_rate(const Model& model, const VecXT<S>& dq, const VecXT<S>& v);

template <class S>
void tangent_rate_into(const Model& model, const VecXT<S>& dq, const VecXT<S>& v, VecXT<S>& r);

// unit quaternions, in place
void normalize(const Model& model, Eigen::VectorXd& q);


}  // namespace codyna
