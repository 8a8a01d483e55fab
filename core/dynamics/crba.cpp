#include "dynamics/crba.hpp"

#include <type_traits>

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
    const bool angular = k.joints[i].sb_angular_only;  // (X.R 0 + r x w is r x w, bit for bit)
    for (int c = 0; c < j.nv; ++c) {
      Vec6T<S>& sw = d.Sw[j.idx_v + c];
      const auto sb = d.Sb[i].col(c);
      const Vec3T<S> w = X.R * sb.template head<3>();
      sw.template head<3>() = w;
      if (angular) {
        sw.template tail<3>() = r.cross(w);
      } else {
        sw.template tail<3>().noalias() = X.R * sb.template tail<3>();
        sw.template tail<3>() += r.cross(w);
      }
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
  if constexpr (std::is_same_v<S, double>) {
    // the same products with the force's six components in registers: a Vec6 made by scalar
    // stores and read back as vectors stalls on every pair (store forwarding); a chain's
    // ancestors are the indices below, without the walk through dof_parent
    for (int a = 0; a < nv; ++a) {
      const RigidInertiaT<double>& I = d.Ic[k.dof_body[a]];
      const double* s = d.Sw[a].data();
      const double w0 = s[0], w1 = s[1], w2 = s[2], v0 = s[3], v1 = s[4], v2 = s[5];
      const double* h = I.h.data();
      const double f0 = I.I(0, 0) * w0 + I.I(0, 1) * w1 + I.I(0, 2) * w2 + (h[1] * v2 - h[2] * v1);
      const double f1 = I.I(1, 0) * w0 + I.I(1, 1) * w1 + I.I(1, 2) * w2 + (h[2] * v0 - h[0] * v2);
      const double f2 = I.I(2, 0) * w0 + I.I(2, 1) * w1 + I.I(2, 2) * w2 + (h[0] * v1 - h[1] * v0);
      const double f3 = I.m * v0 - (h[1] * w2 - h[2] * w1);
      const double f4 = I.m * v1 - (h[2] * w0 - h[0] * w2);
      const double f5 = I.m * v2 - (h[0] * w1 - h[1] * w0);
      double* col = M + static_cast<std::ptrdiff_t>(a) * nv;  // M(:, a)
      auto pair = [&](int b) {
        const double* t = d.Sw[b].data();
        const double m = t[0] * f0 + t[1] * f1 + t[2] * f2 + t[3] * f3 + t[4] * f4 + t[5] * f5;
        col[b] = m;
        M[a + static_cast<std::ptrdiff_t>(b) * nv] = m;
      };
      if (k.dense_mass_matrix)
        for (int b = a; b >= 0; --b) pair(b);
      else
        for (int b = a; b >= 0; b = k.dof_parent[b]) pair(b);
    }
  } else {
    for (int a = 0; a < nv; ++a) {
      const Vec6T<S> F = d.Ic[k.dof_body[a]].apply(d.Sw[a]);
      for (int b = a; b >= 0; b = k.dof_parent[b]) {
        const S m = d.Sw[b].dot(F);
        M[a + static_cast<std::ptrdiff_t>(b) * nv] = m;
        M[b + static_cast<std::ptrdiff_t>(a) * nv] = m;
      }
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
