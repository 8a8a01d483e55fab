#include "dynamics/crba.hpp"

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

template <class S>
const MatXT<S>& crba(const Model& model, DataT<S>& d, const VecXT<S>& q) {
  forward_kinematics<S>(model, d, q);
  return crba_after_kinematics<S>(model, d);
}

// In a frame common to a whole tree: world axes, moments about the origin of
// the tree's root body (the body of that tree attached to ground), so that
//   M(a, b) = S_b . (Ic_body(a) S_a)   for b = a or b an ancestor of a,
// S_a the world motion axis of velocity index a and Ic the composite inertia,
// without a transform between bodies: one 6-vector dot product per pair. The
// origin at the root (not at the world origin) keeps the moments of a model
// far from the world origin as small as the model itself.
template <class S>
void crba_world_terms(const Model& model, DataT<S>& d) {
  const ModelConstants& k = d.constants;
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const SE3T<S>& X = d.oMi[i];
    const Vec3T<S> r = X.p - d.oMi[k.root[i]].p;  // body origin from the tree origin
    k.com_inertia[i].template to_frame<S>(X.R, r, d.Iw[i]);
    for (int c = 0; c < j.nv; ++c) {
      Vec6T<S>& sw = d.Sw[j.idx_v + c];
      const auto sb = d.Sb[i].col(c);
      const Vec3T<S> w = X.R * sb.template head<3>();
      sw.template head<3>() = w;
      sw.template tail<3>().noalias() = X.R * sb.template tail<3>();
      sw.template tail<3>() += r.cross(w);
    }
  }
}

template <class S>
const MatXT<S>& crba_composite(const Model& model, DataT<S>& d) {
  const ModelConstants& k = d.constants;
  for (int i = 1; i < model.nbodies; ++i) d.Ic[i] = d.Iw[i];
  for (int i = model.nbodies - 1; i > 0; --i) {
    const int p = model.parent[i];
    if (p > 0) d.Ic[p] += d.Ic[i];
  }
  const int nv = model.nv;
  if (d.M.rows() != nv || d.M.cols() != nv) d.M.setZero(nv, nv);
  else if (!k.dense_mass_matrix) d.M.setZero();
  S* M = d.M.data();
  for (int a = 0; a < nv; ++a) {
    const Vec6T<S> F = d.Ic[k.dof_body[a]].apply(d.Sw[a]);
    for (int b = a; b >= 0; b = k.dof_parent[b]) {
      const S m = d.Sw[b].dot(F);
      M[a + static_cast<std::ptrdiff_t>(b) * nv] = m;
      M[b + static_cast<std::ptrdiff_t>(a) * nv] = m;
    }
  }
  // rotor inertia (armature) on the diagonal
  if (model.armature.size() != 0)
    for (int a = 0; a < nv; ++a) M[a + static_cast<std::ptrdiff_t>(a) * nv] += S(model.armature[a]);
  return d.M;
}

template <class S>
const MatXT<S>& crba_after_kinematics(const Model& model, DataT<S>& d) {
  crba_world_terms<S>(model, d);
  return crba_composite<S>(model, d);
}

template void crba_world_terms<double>(const Model&, DataT<double>&);
template void crba_world_terms<ADScalar>(const Model&, DataT<ADScalar>&);
template const MatXT<double>& crba_composite<double>(const Model&, DataT<double>&);
template const MatXT<ADScalar>& crba_composite<ADScalar>(const Model&, DataT<ADScalar>&);
template const MatXT<double>& crba_after_kinematics<double>(const Model&, DataT<double>&);
template const MatXT<ADScalar>& crba_after_kinematics<ADScalar>(const Model&, DataT<ADScalar>&);
template const MatXT<double>& crba<double>(const Model&, DataT<double>&, const VecXT<double>&);
template const MatXT<ADScalar>& crba<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
