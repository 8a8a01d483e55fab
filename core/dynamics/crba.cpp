#include "dynamics/crba.hpp"

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

template <class S>
const MatXT<S>& crba(const Model& model, DataT<S>& d, const VecXT<S>& q) {
  forward_kinematics<S>(model, d, q);
  return crba_after_kinematics<S>(model, d);
}

template <class S>
const MatXT<S>& crba_after_kinematics(const Model& model, DataT<S>& d) {
  for (int i = 0; i < model.nbodies; ++i) d.Ic[i] = model.inertia[i].cast<S>();
  for (int i = model.nbodies - 1; i > 0; --i) {
    const int p = model.parent[i];
    if (p > 0) {
      const Mat6T<S> Xi = d.liMi[i].inverse().motion_matrix();  // parent -> child motion
      d.Ic[p] += Xi.transpose() * d.Ic[i] * Xi;
    }
  }
  d.M.setZero(model.nv, model.nv);
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& ji = model.joints[i];
    if (ji.nv == 0) continue;
    Mat6xT<S> F = d.Ic[i] * d.Sb[i];
    d.M.block(ji.idx_v, ji.idx_v, ji.nv, ji.nv) = d.Sb[i].transpose() * F;
    for (int k = i; model.parent[k] > 0; k = model.parent[k]) {
      F = d.liMi[k].inverse().motion_matrix().transpose() * F;  // force transform child -> parent
      const int p = model.parent[k];
      const JointModel& jp = model.joints[p];
      if (jp.nv == 0) continue;
      d.M.block(jp.idx_v, ji.idx_v, jp.nv, ji.nv) = d.Sb[p].transpose() * F;
      d.M.block(ji.idx_v, jp.idx_v, ji.nv, jp.nv) = d.M.block(jp.idx_v, ji.idx_v, jp.nv, ji.nv).transpose();
    }
  }
  return d.M;
}

template const MatXT<double>& crba_after_kinematics<double>(const Model&, DataT<double>&);
template const MatXT<ADScalar>& crba_after_kinematics<ADScalar>(const Model&, DataT<ADScalar>&);
template const MatXT<double>& crba<double>(const Model&, DataT<double>&, const VecXT<double>&);
template const MatXT<ADScalar>& crba<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
