#include "dynamics/sensors.hpp"

#include <stdexcept>

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "dynamics/kinematics.hpp"
#include "dynamics/tire_effect.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {
// body i's spatial acceleration in its own axes (gravity not included) at the joint accelerations
// qdd, from what forward_kinematics(q, v) wrote (liMi, Sb, v, cJ): the recursion of
// forward_kinematics(q, v, qdd) along the body's ancestors only (no heap)
template <class S>
Vec6T<S> sensor_body_acceleration(const Model& model, const DataT<S>& d, int i, const VecXT<S>& v, const VecXT<S>& qdd) {
  if (i <= 0) return Vec6T<S>::Zero();
  const JointModel& j = model.joints[static_cast<std::size_t>(i)];
  // the accelerations and the motion subspaces come from forward_dynamics on this data: without
  // them there is no acceleration to read (a caller's error, said rather than read out of range)
  if (qdd.size() != model.nv || d.Sb[static_cast<std::size_t>(i)].cols() < j.nv)
    throw std::logic_error("acceleration sensor: the accelerations were not computed on this data (run forward_dynamics first)");
  const Vec6T<S> ap = sensor_body_acceleration<S>(model, d, j.parent, v, qdd);
  Vec6T<S> vJ = Vec6T<S>::Zero(), aJ = Vec6T<S>::Zero();
  for (int c = 0; c < j.nv; ++c) {
    vJ += d.Sb[i].col(c) * v[j.idx_v + c];
    aJ += d.Sb[i].col(c) * qdd[j.idx_v + c];
  }
  return Vec6T<S>(d.liMi[i].inv_act_motion(ap) + aJ + d.cJ[i] + cross_motion<S>(d.v[i], vJ));
}

// the tire's contact state as the tire effect computes it (false: off the road, no force)
template <class S>
bool sensor_tire_contact(const DataT<S>& d, const TireModel& t, TireContact<S>& c) {
  Mat3T<S> Rw = d.oMi[t.body].R, Rr = d.oMi[t.road_body].R;
  Vec3T<S> pw = d.oMi[t.body].p, pr = d.oMi[t.road_body].p;
  Vec3T<S> ww = angular_velocity<S>(d, t.body), wr = angular_velocity<S>(d, t.road_body);
  Vec3T<S> vw = point_velocity<S>(d, t.body, Eigen::Vector3d::Zero()), vr = point_velocity<S>(d, t.road_body, Eigen::Vector3d::Zero());
  if constexpr (!std::is_same_v<S, double>) {
    // the ground's constants with the wheel's derivative size (as applied_forces does)
    const Eigen::Index n = std::max({ad_size(Rw), ad_size(pw), ad_size(ww), ad_size(vw), ad_size(Rr), ad_size(pr),
                                     ad_size(wr), ad_size(vr)});
    ad_make_coherent(Rw, n);
    ad_make_coherent(pw, n);
    ad_make_coherent(ww, n);
    ad_make_coherent(vw, n);
    ad_make_coherent(Rr, n);
    ad_make_coherent(pr, n);
    ad_make_coherent(wr, n);
    ad_make_coherent(vr, n);
  }
  // with transient slip, the deflections the caller set in d.s (the slips the law takes)
  if (t.state_x < 0 && t.state_y < 0) return tire_contact<S>(t, Rw, pw, ww, vw, Rr, pr, wr, vr, c);
  VecXT<S> s = d.s;  // sized Model::ns by the Data
  if constexpr (!std::is_same_v<S, double>) ad_make_coherent(s, std::max(ad_size(s), ad_size(pw)));
  return tire_contact<S>(t, Rw, pw, ww, vw, Rr, pr, wr, vr, c, &s);
}
}  // namespace

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
    case SensorType::AngularVelocity: {
      const Vec3T<S> w = angular_velocity<S>(d, s.body);
      return Vec3T<S>(d.oMi[s.frame].R.transpose() * w)[s.component];
    }
    case SensorType::Acceleration: {
      // the accelerations forward_dynamics kept on this data (at the same q, v and inputs)
      if (d.qdd.size() != model.nv) return S(0);
      const Vec6T<S> a = sensor_body_acceleration<S>(model, d, s.body, v, d.qdd);
      const Vec6T<S>& vb = d.v[s.body];
      const Vec3T<S> w = vb.template head<3>(), al = a.template head<3>();
      const Vec3T<S> r = s.point.cast<S>();
      const Vec3T<S> vp = Vec3T<S>(vb.template tail<3>()) + w.cross(r);
      Vec3T<S> aw = d.oMi[s.body].R * Vec3T<S>(Vec3T<S>(a.template tail<3>()) + al.cross(r) + w.cross(vp));
      if (s.specific_force && model.has_gravity) aw -= model.gravity.cast<S>();
      return Vec3T<S>(d.oMi[s.frame].R.transpose() * aw)[s.component];
    }
    case SensorType::Tire: {
      TireContact<S> c;
      if (!sensor_tire_contact<S>(d, model.tires[static_cast<std::size_t>(s.tire)], c)) return S(0);
      switch (s.quantity) {
        case TireQuantity::SlipAngle: return c.input.alpha;
        case TireQuantity::LongitudinalSlip: return c.input.kappa;
        case TireQuantity::Camber: return c.input.gamma;
        case TireQuantity::Fx: return c.out.Fx;
        case TireQuantity::Fy: return c.out.Fy;
        case TireQuantity::Fz: return c.input.Fz;
        case TireQuantity::Mz: return c.out.Mz;
      }
      return S(0);
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
