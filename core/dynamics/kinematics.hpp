// Forward kinematics by the recursive (velocity transformation) method, and
// the kinematic quantities of points and bodies derived from it.
//
// forward_kinematics(q):         writes liMi, oMi, Sb            O(n)
// forward_kinematics(q, v):      + v, cJ
// forward_kinematics(q, v, qdd): + a (body accelerations; gravity not included)
// The point/body functions read what forward_kinematics wrote; body 0 is ground.
#pragma once

#include "dynamics/data.hpp"
#include "model/model.hpp"

namespace codyna {

template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q);
template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v);
template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& qdd);
// the velocity stage alone (v, cJ) on the positions (liMi, Sb) that
// forward_kinematics(q) already wrote: a velocity change at the same q
template <class S>
void velocity_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v);
// the velocity and acceleration stages (v, cJ, a) on the positions forward_kinematics(q) wrote:
// forward_kinematics(q, v, qdd) without its positions' trigonometry
template <class S>
void rate_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& qdd);

// world position, velocity and (classical) acceleration of point p (body coordinates) of a body
template <class S>
Vec3T<S> point_position(const DataT<S>& data, int body, const Eigen::Vector3d& p);
template <class S>
Vec3T<S> point_velocity(const DataT<S>& data, int body, const Eigen::Vector3d& p);
template <class S>
Vec3T<S> point_acceleration(const DataT<S>& data, int body, const Eigen::Vector3d& p);
// world angular velocity and acceleration of a body
template <class S>
Vec3T<S> angular_velocity(const DataT<S>& data, int body);
template <class S>
Vec3T<S> angular_acceleration(const DataT<S>& data, int body);

// 6 x nv Jacobian of a body: rows 0-2 world angular velocity, rows 3-5 the
// world velocity of the body-fixed point that is at the world origin.
template <class S>
MatXT<S> body_jacobian_world(const Model& model, const DataT<S>& data, int body);
// the same into J (resized only when its size differs; no heap after that)
template <class S>
void body_jacobian_world_into(const Model& model, const DataT<S>& data, int body, MatXT<S>& J);
// 3 x nv Jacobian of the world velocity of point p (body coordinates)
template <class S>
MatXT<S> point_jacobian(const Model& model, const DataT<S>& data, int body, const Eigen::Vector3d& p);

}  // namespace codyna
