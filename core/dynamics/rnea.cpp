#include "dynamics/rnea.hpp"

#include <type_traits>

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

template <class S>
const VecXT<S>& rnea(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& a) {
  forward_kinematics<S>(model, d, q, v, a);
  const Vec3T<S> g = model.gravity.cast<S>();
  for (int i = 1; i < model.nbodies; ++i) {
    Vec6T<S> ag = d.a[i];
    if (model.has_gravity) ag.template tail<3>() -= d.oMi[i].R.transpose() * g;
    if constexpr (std::is_same_v<S, double>) {  // the structured inertia (m, h, I): no 6 x 6 products
      const RigidInertiaT<double>& I = d.constants.body_inertia[i];
      d.f[i] = I.apply(ag) + cross_force<S>(d.v[i], I.apply(d.v[i]));
    } else {
      const Mat6T<S> I = model.inertia[i].cast<S>();
      d.f[i] = I * ag + cross_force<S>(d.v[i], Vec6T<S>(I * d.v[i]));
    }
  }
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    if (j.nv > 0) d.tau.segment(j.idx_v, j.nv) = d.Sb[i].transpose() * d.f[i];
    if (j.parent > 0) d.f[j.parent] += d.liMi[i].act_force(d.f[i]);
  }
  // rotor inertia (armature): armature qdd on each coordinate (the product evaluated first, so that
  // an autodiff constant's empty derivative vector is made coherent by +=, not mixed in an expression)
  if (model.armature.size() != 0)
    for (int k = 0; k < model.nv; ++k)
      if (model.armature[k] != 0) {
        const S t = S(model.armature[k]) * a[k];
        d.tau[k] += t;
      }
  return d.tau;
}

template <class S>
const VecXT<S>& nonlinear_effects(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v) {
  if (d.zero_v.size() != model.nv) d.zero_v = VecXT<S>::Zero(model.nv);
  d.nle = rnea<S>(model, d, q, v, d.zero_v);
  return d.nle;
}

template <class S>
void add_body_forces_to_generalized(const Model& model, DataT<S>& d, VecXT<S>& Q) {
  std::vector<Vec6T<S>>& f = d.fsum;
  for (int i = 1; i < model.nbodies; ++i) f[i] = d.fext[i];
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    if (j.nv == 1) Q[j.idx_v] += d.Sb[i].col(0).dot(f[i]);
    else if (j.nv > 0) Q.segment(j.idx_v, j.nv).noalias() += d.Sb[i].transpose() * f[i];
    if (j.parent > 0) f[j.parent] += d.liMi[i].act_force(f[i]);
  }
}

template <class S>
VecXT<S> body_forces_to_generalized(const Model& model, DataT<S>& d) {
  VecXT<S> Q = VecXT<S>::Zero(model.nv);
  add_body_forces_to_generalized<S>(model, d, Q);
  return Q;
}

#define CODYNA_INSTANTIATE(S)                                                                           \
  template const VecXT<S>& rnea<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&,          \
                                   const VecXT<S>&);                                                   \
  template const VecXT<S>& nonlinear_effects<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&); \
  template VecXT<S> body_forces_to_generalized<S>(const Model&, DataT<S>&);                           \
  template void add_body_forces_to_generalized<S>(const Model&, DataT<S>&, VecXT<S>&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
