#include "dynamics/kinematics.hpp"

#include "dynamics/joint.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {
// v[i] and cJ[i] of body i from its parent's velocity (liMi, Sb of body i
// already written); returns the joint velocity S qd
template <class S>
Vec6T<S> body_velocity(const JointModel& j, DataT<S>& d, int i, const VecXT<S>& q, const VecXT<S>& v) {
  Vec6T<S> vJ;
  if (j.nv == 1) vJ = d.Sb[i].col(0) * v[j.idx_v];
  else if (j.nv > 0) vJ.noalias() = d.Sb[i] * v.segment(j.idx_v, j.nv);
  else vJ.setZero();
  if (j.type == JointType::Universal || j.type == JointType::Planar)
    d.cJ[i] = j.X_CM.cast<S>().act_motion(joint_bias<S>(j, q, v));
  else
    d.cJ[i].setZero();
  d.v[i] = d.liMi[i].inv_act_motion(d.v[j.parent]) + vJ;
  return vJ;
}

// a[i] of body i from its parent's (v[i], cJ[i] written; vJ the joint velocity)
template <class S>
void body_acceleration(const JointModel& j, DataT<S>& d, int i, const Vec6T<S>& vJ, const VecXT<S>& v,
                       const VecXT<S>& qdd) {
  Vec6T<S> aJ;
  if (j.nv == 1) {
    aJ = d.Sb[i].col(0) * qdd[j.idx_v];
    d.a[i] = d.liMi[i].inv_act_motion(d.a[j.parent]) + aJ + d.cJ[i] +
             cross_motion_scaled<S>(d.v[i], d.Sb[i].data(), v[j.idx_v]);  // (vJ not read back)
    return;
  }
  if (j.nv > 0) aJ.noalias() = d.Sb[i] * qdd.segment(j.idx_v, j.nv);
  else aJ.setZero();
  d.a[i] = d.liMi[i].inv_act_motion(d.a[j.parent]) + aJ + d.cJ[i] + cross_motion<S>(d.v[i], vJ);
}

template <class S>
void fk(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>* v, const VecXT<S>* qdd) {
  SE3T<S> X_FM;
  Mat6xT<S> S_M;
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const ModelConstants::Joint& k = d.constants.joints[i];
    const int p = j.parent;
    SE3T<S>& liMi = d.liMi[i];
    if (j.type == JointType::Revolute) {
      // X_PF Rot(axis, q) X_CM^-1 = (Rot(R_PF axis, q) R0, Rot(R_PF axis, q) p0 + p_PF)
      S sq, cq;
      sin_cos(q[j.idx_q], sq, cq);
      const Mat3T<S> Rq = axis_rotation<S>(k.axis_P, cq, sq);
      if (k.r0_identity) liMi.R = Rq;
      else liMi.R.noalias() = Rq * k.R0.template cast<S>();
      if (k.p0_zero) {
        liMi.p = k.X_PF.p.template cast<S>();
      } else {
        liMi.p.noalias() = Rq * k.p0.template cast<S>();
        liMi.p += k.X_PF.p.template cast<S>();
      }
    } else if (j.type == JointType::Spherical || j.type == JointType::Free) {
      // X_PF (Rq, t) X_MC, t = 0 or the free joint's position, the products in joint_transform's
      // order and without those by exact identities (the same numbers, bit for bit)
      const int iq = j.idx_q + (j.type == JointType::Free ? 3 : 0);
      const Mat3T<S> Rq = quat_to_matrix<S>(q[iq], q[iq + 1], q[iq + 2], q[iq + 3]);
      const Vec3T<S> pf = k.X_PF.p.template cast<S>();
      Mat3T<S> R;
      Vec3T<S> p;
      if (k.pf_rotation_identity) {
        R = Rq;
        if (j.type == JointType::Free) p = Vec3T<S>(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2]) + pf;
        else p = pf;
      } else {
        const Mat3T<S> Rpf = k.X_PF.R.template cast<S>();
        R.noalias() = Rpf * Rq;
        if (j.type == JointType::Free) p.noalias() = Rpf * Vec3T<S>(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2]);
        else p.setZero();
        p += pf;
      }
      if (k.mc_identity) {
        liMi.R = R;
        liMi.p = p;
      } else {
        liMi.R.noalias() = R * k.X_MC.R.template cast<S>();
        liMi.p.noalias() = R * k.X_MC.p.template cast<S>();
        liMi.p += p;
      }
    } else {
      joint_transform<S>(j, q, X_FM, S_M);
      liMi = k.X_PF.template cast<S>() * X_FM * k.X_MC.template cast<S>();
      if (!k.constant_S) d.Sb[i] = j.X_CM.cast<S>().motion_matrix() * S_M;
    }
    if (k.constant_S) d.Sb[i] = k.Sb.template cast<S>();
    if (p == 0) {
      d.oMi[i] = liMi;
    } else {
      const SE3T<S>& oMp = d.oMi[p];
      d.oMi[i].R.noalias() = oMp.R * liMi.R;
      d.oMi[i].p.noalias() = oMp.R * liMi.p;
      d.oMi[i].p += oMp.p;
    }
    if (!v) continue;
    const Vec6T<S> vJ = body_velocity<S>(j, d, i, q, *v);
    if (qdd) body_acceleration<S>(j, d, i, vJ, *v, *qdd);
  }
}
}  // namespace

template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q) {
  fk<S>(model, data, q, nullptr, nullptr);
}
template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v) {
  fk<S>(model, data, q, &v, nullptr);
}
template <class S>
void forward_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& qdd) {
  fk<S>(model, data, q, &v, &qdd);
}

template <class S>
void velocity_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v) {
  for (int i = 1; i < model.nbodies; ++i) body_velocity<S>(model.joints[i], data, i, q, v);
}

template <class S>
void rate_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& qdd) {
  for (int i = 1; i < model.nbodies; ++i) {
    const Vec6T<S> vJ = body_velocity<S>(model.joints[i], data, i, q, v);
    body_acceleration<S>(model.joints[i], data, i, vJ, v, qdd);
  }
}

template <class S>
Vec3T<S> point_position(const DataT<S>& data, int body, const Eigen::Vector3d& p) {
  return data.oMi[body].act_point(p.cast<S>());
}

template <class S>
Vec3T<S> point_velocity(const DataT<S>& data, int body, const Eigen::Vector3d& p) {
  const Vec6T<S>& v = data.v[body];
  const Vec3T<S> w = v.template head<3>();
  return data.oMi[body].R * (Vec3T<S>(v.template tail<3>()) + w.cross(p.cast<S>()));
}

template <class S>
Vec3T<S> point_acceleration(const DataT<S>& data, int body, const Eigen::Vector3d& p) {
  const Vec6T<S>& v = data.v[body];
  const Vec6T<S>& a = data.a[body];
  const Vec3T<S> w = v.template head<3>(), al = a.template head<3>();
  const Vec3T<S> r = p.cast<S>();
  const Vec3T<S> vp = Vec3T<S>(v.template tail<3>()) + w.cross(r);
  return data.oMi[body].R * (Vec3T<S>(a.template tail<3>()) + al.cross(r) + w.cross(vp));
}

template <class S>
Vec3T<S> angular_velocity(const DataT<S>& data, int body) {
  return data.oMi[body].R * Vec3T<S>(data.v[body].template head<3>());
}

template <class S>
Vec3T<S> angular_acceleration(const DataT<S>& data, int body) {
  return data.oMi[body].R * Vec3T<S>(data.a[body].template head<3>());
}

template <class S>
void body_jacobian_world_into(const Model& model, const DataT<S>& data, int body, MatXT<S>& J) {
  if (J.rows() != 6 || J.cols() != model.nv) J.resize(6, model.nv);
  J.setZero();
  for (int i = body; i > 0; i = model.parent[i]) {
    const JointModel& j = model.joints[i];
    const SE3T<S>& X = data.oMi[i];
    for (int c = 0; c < j.nv; ++c) {
      // world motion of the joint axis: [R w; R v + p x R w]
      const Vec3T<S> w = X.R * data.Sb[i].col(c).template head<3>();
      J.col(j.idx_v + c).template head<3>() = w;
      J.col(j.idx_v + c).template tail<3>() = X.R * data.Sb[i].col(c).template tail<3>() + X.p.cross(w);
    }
  }
}

template <class S>
MatXT<S> body_jacobian_world(const Model& model, const DataT<S>& data, int body) {
  MatXT<S> J = MatXT<S>::Zero(6, model.nv);
  for (int i = body; i > 0; i = model.parent[i]) {
    const JointModel& j = model.joints[i];
    if (j.nv == 0) continue;
    J.block(0, j.idx_v, 6, j.nv) = data.oMi[i].motion_matrix() * data.Sb[i];
  }
  return J;
}

template <class S>
MatXT<S> point_jacobian(const Model& model, const DataT<S>& data, int body, const Eigen::Vector3d& p) {
  const MatXT<S> J6 = body_jacobian_world<S>(model, data, body);
  const Vec3T<S> pw = point_position<S>(data, body, p);
  return J6.bottomRows(3) - skew<S>(pw) * J6.topRows(3);
}

#define CODYNA_INSTANTIATE(S)                                                                              \
  template void forward_kinematics<S>(const Model&, DataT<S>&, const VecXT<S>&);                          \
  template void forward_kinematics<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&);         \
  template void forward_kinematics<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&,          \
                                      const VecXT<S>&);                                                   \
  template void velocity_kinematics<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&);        \
  template void rate_kinematics<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&,              \
                                   const VecXT<S>&);                                                      \
  template void body_jacobian_world_into<S>(const Model&, const DataT<S>&, int, MatXT<S>&);                \
  template Vec3T<S> point_position<S>(const DataT<S>&, int, const Eigen::Vector3d&);                      \
  template Vec3T<S> point_velocity<S>(const DataT<S>&, int, const Eigen::Vector3d&);                      \
  template Vec3T<S> point_acceleration<S>(const DataT<S>&, int, const Eigen::Vector3d&);                  \
  template Vec3T<S> angular_velocity<S>(const DataT<S>&, int);                                            \
  template Vec3T<S> angular_acceleration<S>(const DataT<S>&, int);                                        \
  template MatXT<S> body_jacobian_world<S>(const Model&, const DataT<S>&, int);                           \
  template MatXT<S> point_jacobian<S>(const Model&, const DataT<S>&, int, const Eigen::Vector3d&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
