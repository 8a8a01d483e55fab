// Sensor outputs: one scalar per sensor (see SensorType). Needs
// forward_kinematics(q, v) on data; motion_force reads the reaction and acceleration the joint
// accelerations qdd that forward_dynamics (which runs the kinematics too) kept on data, so both need
// forward_dynamics at the same q, v and inputs first (sensor_reads_accelerations); tire sensors
// evaluate the tire's contact as the tire effect does. sensor_outputs evaluates only the sensors
// listed in `which` (indices into Model::sensors), so outputs nobody asked
// for are never computed.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>
#include <vector>

#include "dynamics/data.hpp"

namespace codyna {

namespace detail {
inline double scalar_value(double x) { return x; }
template <class D>
double scalar_value(const Eigen::AutoDiffScalar<D>& x) {
  return x.value();
}
// atan2(y, x) keeping the derivatives' own type: Eigen's atan2 of AutoDiffScalars returns
// dynamic-size derivatives (a heap allocation in the fixed-size differentiation of
// TreeDerivatives); d atan2 = (x dy - y dx) / (x^2 + y^2). A constant's derivatives may be
// empty (dynamic sizes): then only the other's count.
inline double atan2_keep(double y, double x) { return std::atan2(y, x); }
template <class D>
Eigen::AutoDiffScalar<D> atan2_keep(const Eigen::AutoDiffScalar<D>& y, const Eigen::AutoDiffScalar<D>& x) {
  using Der = typename Eigen::AutoDiffScalar<D>::DerType;
  const double yv = y.value(), xv = x.value(), r2 = xv * xv + yv * yv;
  const double wy = r2 > 0 ? xv / r2 : 0.0, wx = r2 > 0 ? -yv / r2 : 0.0;
  Der der;
  if (y.derivatives().size() == 0) der = wx * x.derivatives();
  else if (x.derivatives().size() == 0) der = wy * y.derivatives();
  else der = wy * y.derivatives() + wx * x.derivatives();
  return Eigen::AutoDiffScalar<D>(std::atan2(yv, xv), der);
}
}  // namespace detail

// How far the rotation R (a body's orientation relative to a reference one)
// turns about the unit axis a (world axes): the component a . phi of its
// rotation vector phi = theta n = log(R), theta in [0, pi]. For a rotation
// about a itself this is the signed angle in (-pi, pi]; for any small rotation
// it is the small rotation about a, so two axes measure the two components of
// one tilt alike (body_angle; docs/model-format.md). Generic in the scalar
// (double and forward autodiff) and smooth away from theta = pi.
template <class S, class M3>
S rotation_about_axis(const M3& R, const Eigen::Vector3d& a) {
  using std::atan2;
  using std::sqrt;
  // sin(theta) n from the antisymmetric part, cos(theta) from the trace
  const S sx = S(R(2, 1) - R(1, 2)) * 0.5, sy = S(R(0, 2) - R(2, 0)) * 0.5, sz = S(R(1, 0) - R(0, 1)) * 0.5;
  const S c = (S(R(0, 0) + R(1, 1)) + R(2, 2) - 1.0) * 0.5;
  const S s2 = sx * sx + sy * sy + sz * sz;
  if (detail::scalar_value(c) > -0.5) {  // theta < 120 deg
    const S sa = sx * a[0] + sy * a[1] + sz * a[2];
    if (detail::scalar_value(s2) < 1e-16) return sa * (1.0 + s2 / 6.0);  // theta / sin(theta) = 1 + theta^2 / 6 + ...
    const S sn = sqrt(s2);
    return detail::atan2_keep(sn, c) / sn * sa;
  }
  // Near pi sin(theta) vanishes: the axis from the symmetric part
  // (R + R^T) / 2 - cos(theta) I = (1 - cos(theta)) n n^T, its sign from sin(theta) n.
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (detail::scalar_value(R(i, i)) > detail::scalar_value(R(k, k))) k = i;
  const S bkk = S(R(k, k)) - c;
  const S scale = sqrt(bkk * (1.0 - c));
  S n[3];
  for (int i = 0; i < 3; ++i) n[i] = (i == k ? bkk : S(S(R(i, k) + R(k, i)) * 0.5)) / scale;
  const S along = n[0] * sx + n[1] * sy + n[2] * sz;
  const double sign = detail::scalar_value(along) < 0 ? -1.0 : 1.0;
  const S theta = detail::scalar_value(s2) > 0 ? S(detail::atan2_keep(S(sqrt(s2)), c)) : S(c * 0.0 + 3.14159265358979323846);
  return theta * (n[0] * a[0] + n[1] * a[1] + n[2] * a[2]) * sign;
}

template <class S>
S sensor_value(const Model& model, const DataT<S>& data, const SensorModel& sensor, const VecXT<S>& q,
               const VecXT<S>& v);

template <class S>
VecXT<S> sensor_outputs(const Model& model, const DataT<S>& data, const std::vector<int>& which, const VecXT<S>& q,
                        const VecXT<S>& v);

}  // namespace codyna
