#include "dynamics/data.hpp"

#include <algorithm>

#include "dynamics/joint.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

ModelConstants::ModelConstants(const Model& model) { assign(model); }

void ModelConstants::assign(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.nbodies);
  joints.assign(nb, Joint{});
  com_inertia.resize(nb);
  body_inertia.resize(nb);
  root.assign(nb, 0);
  dof_body.assign(static_cast<std::size_t>(model.nv), 0);
  dof_parent.assign(static_cast<std::size_t>(model.nv), -1);
  for (int i = 0; i < model.nbodies; ++i) {
    com_inertia[i] = ComInertia::from_matrix(model.inertia[i]);
    body_inertia[i] = RigidInertiaT<double>::from_matrix(model.inertia[i]);
  }
  std::vector<int> last_dof(nb, -1);  // the last velocity index at or above body i
  const Eigen::VectorXd q_neutral = neutral(model);
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    Joint& c = joints[i];
    c.X_PF = j.X_PF;
    c.X_MC = j.X_CM.inverse();
    c.constant_S = j.type != JointType::Universal && j.type != JointType::Planar;
    if (c.constant_S) {
      SE3 X;
      Mat6xT<double> S_M;
      joint_transform<double>(j, q_neutral, X, S_M);
      c.Sb = j.X_CM.motion_matrix() * S_M;
    }
    c.axis_P = j.X_PF.R * j.axis;
    c.R0 = j.X_PF.R * c.X_MC.R;
    c.p0 = j.X_PF.R * c.X_MC.p;
    const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
    c.r0_identity = c.R0 == I3;
    c.p0_zero = c.p0 == Eigen::Vector3d::Zero();
    c.pf_rotation_identity = j.X_PF.R == I3;
    c.mc_identity = c.X_MC.R == I3 && c.X_MC.p == Eigen::Vector3d::Zero();
    c.sb_angular_only = c.constant_S && c.Sb.cols() > 0 && c.Sb.bottomRows(3).isZero(0.0);
    const int p = j.parent;
    root[i] = p == 0 ? i : root[p];
    int up = last_dof[p];
    for (int k = 0; k < j.nv; ++k) {
      dof_body[j.idx_v + k] = i;
      dof_parent[j.idx_v + k] = up;
      up = j.idx_v + k;
    }
    last_dof[i] = up;
  }
  long pairs = 0;
  for (int a = 0; a < model.nv; ++a)
    for (int b = a; b >= 0; b = dof_parent[b]) ++pairs;
  dense_mass_matrix = pairs == static_cast<long>(model.nv) * (model.nv + 1) / 2;
  // the constraints' supports (the inner vectors keep their storage when the shape is the same)
  constraint_cols.resize(model.constraints.size());
  constraint_side.resize(model.constraints.size());
  std::vector<int> side(static_cast<std::size_t>(model.nv), 0);
  for (std::size_t k = 0; k < model.constraints.size(); ++k) {
    const ConstraintModel& c = model.constraints[k];
    std::fill(side.begin(), side.end(), 0);
    if (c.type == ConstraintType::Coupler) {
      for (int i = 0; i < c.ncoupled; ++i) side[static_cast<std::size_t>(c.iv[i])] = 3;
    } else {
      for (int which = 0; which < 2; ++which)
        for (int b = which == 0 ? c.body_a : c.body_b; b > 0; b = model.parent[b])
          for (int i = 0; i < model.joints[b].nv; ++i) side[static_cast<std::size_t>(model.joints[b].idx_v + i)] |= 1 << which;
    }
    constraint_cols[k].clear();
    constraint_side[k].clear();
    for (int i = 0; i < model.nv; ++i)
      if (side[static_cast<std::size_t>(i)]) {
        constraint_cols[k].push_back(i);
        constraint_side[k].push_back(side[static_cast<std::size_t>(i)]);
      }
  }
  body_force_sources = !model.springs.empty() || !model.body_forces.empty() || !model.bushings.empty() ||
                       !model.tires.empty();
  for (const ActuatorModel& a : model.actuators)
    if (a.type != ActuatorType::JointForce && a.type != ActuatorType::Motion) body_force_sources = true;
}

template <class S>
DataT<S>::DataT(const Model& model) : constants(model) {
  size_for(model);
}

template <class S>
void DataT<S>::reset(const Model& model) {
  // (the workspaces sized at their first use are sized again by the algorithms when the sizes differ)
  constants.assign(model);
  size_for(model);
}

// every stage's arrays sized for the model and zeroed (std::vector::assign and Eigen's resize keep
// their storage when the sizes are those they had: reset() on a model of the same shape makes no
// heap allocation but ModelConstants' three scratch arrays)
template <class S>
void DataT<S>::size_for(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.nbodies);
  liMi.assign(nb, SE3T<S>());
  oMi.assign(nb, SE3T<S>());
  Sb.assign(nb, Mat6xT<S>(6, 0));
  v.assign(nb, Vec6T<S>::Zero());
  cJ.assign(nb, Vec6T<S>::Zero());
  a.assign(nb, Vec6T<S>::Zero());
  f.assign(nb, Vec6T<S>::Zero());
  fext.assign(nb, Vec6T<S>::Zero());
  IA.assign(nb, Mat6T<S>::Zero());
  Ia.assign(nb, Mat6T<S>::Zero());
  pA.assign(nb, Vec6T<S>::Zero());
  pB.assign(nb, Vec6T<S>::Zero());
  U.assign(nb, Mat6xT<S>(6, 0));
  Dinv.assign(nb, typename decltype(Dinv)::value_type());
  u.assign(nb, typename decltype(u)::value_type());
  c.assign(nb, Vec6T<S>::Zero());
  Iw.assign(nb, RigidInertiaT<S>());
  Ic.assign(nb, RigidInertiaT<S>());
  Sw.assign(static_cast<std::size_t>(model.nv), Vec6T<S>::Zero());
  fsum.assign(nb, Vec6T<S>::Zero());
  tau = VecXT<S>::Zero(model.nv);
  // M [nv x nv] is sized by crba() when a mass matrix is asked for: ABA and kinematics never need it
  nle = VecXT<S>::Zero(model.nv);
  Q = VecXT<S>::Zero(model.nv);
  qdd = VecXT<S>::Zero(model.nv);
  lambda = VecXT<S>::Zero(model.nc);
  motion_acc = VecXT<S>::Zero(static_cast<Eigen::Index>(model.motions.size()));
  motion_force = VecXT<S>::Zero(static_cast<Eigen::Index>(model.motions.size()));
  s = VecXT<S>::Zero(model.ns);
  sdot = VecXT<S>::Zero(model.ns);
  phi = VecXT<S>::Zero(model.nc);
  Jc = MatXT<S>::Zero(model.nc, model.nv);
  gamma = VecXT<S>::Zero(model.nc);
  zero_v = VecXT<S>::Zero(model.nv);
}

template struct DataT<double>;
template struct DataT<ADScalar>;

}  // namespace codyna
