#include "dynamics/energy.hpp"

#include <cmath>

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {
template <class S>
S kinetic_sum(const Model& model, const DataT<S>& d, const VecXT<S>& v) {
  S T(0);
  for (int i = 1; i < model.nbodies; ++i) T += S(0.5) * d.v[i].dot(model.inertia[i].cast<S>() * d.v[i]);
  if (model.armature.size() != 0)  // the rotors' (armature): 1/2 armature v^2 on each coordinate
    for (int k = 0; k < model.nv; ++k)
      if (model.armature[k] != 0) {
        const S t = S(0.5 * model.armature[k]) * v[k] * v[k];  // evaluated: see rnea
        T += t;
      }
  return T;
}

template <class S>
S potential_sum(const Model& model, const DataT<S>& d, const VecXT<S>& q) {
  using std::sqrt;
  S V(0);
  if (model.has_gravity)
    for (int i = 1; i < model.nbodies; ++i)
      V -= S(model.mass[i]) * model.gravity.cast<S>().dot(d.oMi[i].act_point(model.com[i].cast<S>()));
  for (const SpringDamperModel& s : model.springs) {
    const Vec3T<S> dp = d.oMi[s.body_b].act_point(s.point_b.cast<S>()) - d.oMi[s.body_a].act_point(s.point_a.cast<S>());
    const S e = sqrt(dp.squaredNorm()) - S(s.rest_length);
    V += S(0.5 * s.stiffness) * e * e;
  }
  for (const JointSpringModel& s : model.joint_springs) {
    const S e = q[s.iq] - S(s.rest_position);
    V += S(0.5 * s.stiffness) * e * e;
  }
  return V;
}
}  // namespace

template <class S>
S kinetic_energy(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v) {
  forward_kinematics<S>(model, d, q, v);
  return kinetic_sum<S>(model, d, v);
}

template <class S>
S potential_energy(const Model& model, DataT<S>& d, const VecXT<S>& q) {
  forward_kinematics<S>(model, d, q);
  return potential_sum<S>(model, d, q);
}

double kinetic_energy_after_kinematics(const Model& model, const Data& data, const Eigen::VectorXd& v) {
  return kinetic_sum<double>(model, data, v);
}
double potential_energy_after_kinematics(const Model& model, const Data& data, const Eigen::VectorXd& q) {
  return potential_sum<double>(model, data, q);
}

template double kinetic_energy<double>(const Model&, DataT<double>&, const VecXT<double>&, const VecXT<double>&);
template double potential_energy<double>(const Model&, DataT<double>&, const VecXT<double>&);
template ADScalar kinetic_energy<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&, const VecXT<ADScalar>&);
template ADScalar potential_energy<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
