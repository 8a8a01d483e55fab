#include "dynamics/sensors.hpp"

#include <cmath>

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

template <class S>
S sensor_value(const Model& model, const DataT<S>& d, const SensorModel& s, const VecXT<S>& q, const VecXT<S>& v) {
  using std::atan2;
  using std::sqrt;
  switch (s.type) {
    case SensorType::JointPosition:
      return q[s.iq];
    case SensorType::JointVelocity:
      return v[s.iv];
    case SensorType::PointPosition: {
      const Vec3T<S> pw = point_position<S>(d, s.body, s.point);
      const SE3T<S>& F = d.oMi[s.frame];
      return Vec3T<S>(F.R.transpose() * (pw - F.p))[s.component];
    }
    case SensorType::PointVelocity: {
      const Vec3T<S> vw = point_velocity<S>(d, s.body, s.point);
      return Vec3T<S>(d.oMi[s.frame].R.transpose() * vw)[s.component];
    }
    case SensorType::BodyAngle: {
      // rotation of the body relative to its zero-configuration orientation, about the world axis
      // (the axis component of the rotation vector of R R0^T)
      const Mat3T<S> Rrel = d.oMi[s.body].R * s.R0.transpose().cast<S>();
      return rotation_about_axis<S>(Rrel, s.axis);
    }
    case SensorType::Distance: {
      const Vec3T<S> dp = point_position<S>(d, s.body_b, s.point_b) - point_position<S>(d, s.body_a, s.point_a);
      return sqrt(dp.squaredNorm());
    }
    case SensorType::DistanceRate: {
      const Vec3T<S> dp = point_position<S>(d, s.body_b, s.point_b) - point_position<S>(d, s.body_a, s.point_a);
      const S L = sqrt(dp.squaredNorm());
      if (!(ad_value(L) > 1e-12)) return S(0);
      const Vec3T<S> dv = point_velocity<S>(d, s.body_b, s.point_b) - point_velocity<S>(d, s.body_a, s.point_a);
      return S(dp.dot(dv)) / L;
    }
    case SensorType::MotionForce:
      // kept by forward_dynamics on this data (at the same q, v and inputs)
      for (std::size_t k = 0; k < model.motions.size(); ++k)
        if (model.actuators[static_cast<std::size_t>(model.motions[k])].iv == s.iv)
          return k < static_cast<std::size_t>(d.motion_force.size()) ? d.motion_force[static_cast<Eigen::Index>(k)] : S(0);
      return S(0);
  }
  return S(0);
}

template <class S>
VecXT<S> sensor_outputs(const Model& model, const DataT<S>& d, const std::vector<int>& which, const VecXT<S>& q,
                        const VecXT<S>& v) {
  VecXT<S> y(static_cast<Eigen::Index>(which.size()));
  for (std::size_t k = 0; k < which.size(); ++k) y[k] = sensor_value<S>(model, d, model.sensors[which[k]], q, v);
  return y;
}

#define CODYNA_INSTANTIATE(S)                                                                           \
  template S sensor_value<S>(const Model&, const DataT<S>&, const SensorModel&, const VecXT<S>&,        \
                             const VecXT<S>&);                                                          \
  template VecXT<S> sensor_outputs<S>(const Model&, const DataT<S>&, const std::vector<int>&,           \
                                      const VecXT<S>&, const VecXT<S>&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
