#include "dynamics/aba.hpp"

#include <type_traits>

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {
template <class S>
using SmallMatT = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// inverse of a small symmetric positive definite joint-space matrix (at most
// 6 x 6, no heap): Cholesky D = L L^T, then D^-1 = L^-T L^-1. A matrix that is
// not positive definite (a massless subtree) gives non-finite values, as the
// division of the one-coordinate case does.
template <class S>
void small_inverse(const SmallMatT<S>& D, SmallMatT<S>& Dinv) {
  using std::sqrt;
  const Eigen::Index n = D.rows();
  Dinv.resize(n, n);
  if (n == 1) {
    Dinv(0, 0) = S(1) / D(0, 0);
    return;
  }
  SmallMatT<S> L(n, n);  // lower triangle used; its diagonal holds 1 / L(j, j)
  for (Eigen::Index j = 0; j < n; ++j) {
    S dj = D(j, j);
    for (Eigen::Index k = 0; k < j; ++k) dj -= L(j, k) * L(j, k);
    const S ljj = sqrt(dj);
    L(j, j) = S(1) / ljj;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      S t = D(i, j);
      for (Eigen::Index k = 0; k < j; ++k) t -= L(i, k) * L(j, k);
      L(i, j) = t / ljj;
    }
  }
  // W = L^-1 (lower triangular), by forward substitution on the identity
  SmallMatT<S> W = SmallMatT<S>::Zero(n, n);
  for (Eigen::Index c = 0; c < n; ++c) {
    W(c, c) = L(c, c);
    for (Eigen::Index i = c + 1; i < n; ++i) {
      S t = S(0);
      for (Eigen::Index k = c; k < i; ++k) t -= L(i, k) * W(k, c);
      W(i, c) = t * L(i, i);
    }
  }
  // D^-1 = W^T W
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = r; c < n; ++c) {
      S t = S(0);
      for (Eigen::Index k = c; k < n; ++k) t += W(k, r) * W(k, c);
      Dinv(r, c) = t;
      Dinv(c, r) = t;
    }
}
}  // namespace

template <class S>
const VecXT<S>& aba(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& tau) {
  forward_kinematics<S>(model, d, q, v);
  return aba_after_kinematics<S>(model, d, v, tau);
}

namespace {
// velocity-product terms: bias accelerations c and the bodies' bias forces
// (the start of pA), from the velocities
template <class S>
void aba_velocity_terms(const Model& model, DataT<S>& d, const VecXT<S>& v) {
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const Vec6T<S>& vi = d.v[i];
    Vec6T<S> pb;  // written to both from registers (a copy of d.pB[i] would reload it)
    if constexpr (std::is_same_v<S, double>)  // the structured inertia: no 6 x 6 product
      pb = cross_force<S>(vi, d.constants.body_inertia[i].apply(vi));
    else
      pb = cross_force<S>(vi, Vec6T<S>(model.inertia[i].template cast<S>() * vi));
    d.pB[i] = pb;
    d.pA[i] = pb;
    if (j.nv == 1) {
      d.c[i] = d.cJ[i] + cross_motion_scaled<S>(vi, d.Sb[i].data(), v[j.idx_v]);
      continue;
    }
    Vec6T<S> vJ;
    if (j.nv > 0) vJ.noalias() = d.Sb[i] * v.segment(j.idx_v, j.nv);
    else vJ.setZero();
    d.c[i] = d.cJ[i] + cross_motion<S>(vi, vJ);
  }
}

// the outward pass: accelerations from the ground's (-g) to the leaves
template <class S>
const VecXT<S>& aba_forward_pass(const Model& model, DataT<S>& d) {
  d.a[0].setZero();
  if (model.has_gravity) d.a[0].template tail<3>() = -model.gravity.cast<S>();
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const Vec6T<S> ap = d.liMi[i].inv_act_motion(d.a[j.parent]) + d.c[i];
    if (j.nv == 1) {
      const Vec6T<S> s = d.Sb[i].col(0);
      const S qdd_i = d.Dinv[i](0, 0) * (d.u[i](0) - d.U[i].col(0).dot(ap));
      d.qdd[j.idx_v] = qdd_i;
      d.a[i] = ap + s * qdd_i;
    } else if (j.nv > 0) {
      Eigen::Matrix<S, Eigen::Dynamic, 1, 0, 6, 1> r = d.u[i];
      r.noalias() -= d.U[i].transpose() * ap;
      Eigen::Matrix<S, Eigen::Dynamic, 1, 0, 6, 1> qdd_i(j.nv);
      qdd_i.noalias() = d.Dinv[i] * r;
      d.qdd.segment(j.idx_v, j.nv) = qdd_i;
      d.a[i] = ap + d.Sb[i] * qdd_i;
    } else {
      d.a[i] = ap;
    }
  }
  // data.a holds accelerations including the gravity offset here; keep the
  // documented meaning (no gravity) for callers that read it. The offset is a
  // pure linear acceleration a0 = -g of the ground: in body i it is R_i^T a0.
  if (model.has_gravity) {
    const Vec3T<S> a0 = d.a[0].template tail<3>();
    for (int i = 1; i < model.nbodies; ++i) d.a[i].template tail<3>().noalias() -= d.oMi[i].R.transpose() * a0;
    d.a[0].setZero();
  }
  return d.qdd;
}
}  // namespace

// Body-coordinate ABA. One-coordinate joints (the common case) take a path
// with fixed-size vectors; the transform of an articulated inertia to the
// parent is the structured add_transformed_inertia (spatial.hpp).
template <class S>
const VecXT<S>& aba_after_kinematics(const Model& model, DataT<S>& d, const VecXT<S>& v, const VecXT<S>& tau) {
  for (int i = 1; i < model.nbodies; ++i) d.IA[i] = model.inertia[i].template cast<S>();
  aba_velocity_terms<S>(model, d, v);
  const std::vector<Vec6T<S>>& c = d.c;
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    const int p = j.parent;
    Mat6T<S>& Ia = d.Ia[i];
    Vec6T<S> pa;
    if (j.nv == 1) {
      const Vec6T<S> s = d.Sb[i].col(0);
      const Vec6T<S> Ui = d.IA[i] * s;
      // D = S^T IA S plus the coordinate's rotor inertia (armature)
      S D = s.dot(Ui);
      if (model.armature.size() != 0) D += S(model.armature[j.idx_v]);
      const S Dinv = S(1) / D;
      const S ui = tau[j.idx_v] - s.dot(d.pA[i]);
      d.U[i] = Ui;
      d.Dinv[i].resize(1, 1);
      d.Dinv[i](0, 0) = Dinv;
      d.u[i].resize(1);
      d.u[i](0) = ui;
      if (p == 0) continue;
      const Vec6T<S> UD = Ui * Dinv;
      Ia = d.IA[i];
      Ia.noalias() -= UD * Ui.transpose();
      pa = d.pA[i] + Ia * c[i] + UD * ui;
    } else {
      d.U[i].noalias() = d.IA[i] * d.Sb[i];
      SmallMatT<S> D = d.Sb[i].transpose() * d.U[i];
      if (model.armature.size() != 0)
        for (int c = 0; c < j.nv; ++c) D(c, c) += S(model.armature[j.idx_v + c]);
      small_inverse<S>(D, d.Dinv[i]);
      d.u[i] = tau.segment(j.idx_v, j.nv);  // in two steps: tau.segment - product would evaluate into a heap temporary
      d.u[i].noalias() -= d.Sb[i].transpose() * d.pA[i];
      if (p == 0) continue;
      const Mat6xT<S> UD = d.U[i] * d.Dinv[i];
      Ia = d.IA[i];
      Ia.noalias() -= UD * d.U[i].transpose();
      pa = d.pA[i] + Ia * c[i] + UD * d.u[i];
    }
    add_transformed_inertia<S>(d.liMi[i], Ia, d.IA[p]);
    d.pA[p] += d.liMi[i].act_force(pa);
  }
  return aba_forward_pass<S>(model, d);
}

template <class S>
const VecXT<S>& aba_same_motion(const Model& model, DataT<S>& d, const VecXT<S>& tau, bool reset_bias);

// The inward pass without its inertia part: IA, Ia, U and Dinv depend on the
// positions only and are those of the last full pass.
template <class S>
const VecXT<S>& aba_same_positions(const Model& model, DataT<S>& d, const VecXT<S>& v, const VecXT<S>& tau) {
  aba_velocity_terms<S>(model, d, v);
  return aba_same_motion<S>(model, d, tau, false);
}

// the inward pass on the velocity terms (c, pB) already in data
template <class S>
const VecXT<S>& aba_same_motion(const Model& model, DataT<S>& d, const VecXT<S>& tau, bool reset_bias) {
  if (reset_bias)
    for (int i = 1; i < model.nbodies; ++i) d.pA[i] = d.pB[i];
  const std::vector<Vec6T<S>>& c = d.c;
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    const int p = j.parent;
    Vec6T<S> pa;
    if (j.nv == 1) {
      const Vec6T<S> s = d.Sb[i].col(0);
      const S ui = tau[j.idx_v] - s.dot(d.pA[i]);
      d.u[i](0) = ui;
      if (p == 0) continue;
      const Vec6T<S> UD = d.U[i].col(0) * d.Dinv[i](0, 0);
      pa = d.pA[i] + d.Ia[i] * c[i] + UD * ui;
    } else {
      d.u[i] = tau.segment(j.idx_v, j.nv);
      d.u[i].noalias() -= d.Sb[i].transpose() * d.pA[i];
      if (p == 0) continue;
      const Mat6xT<S> UD = d.U[i] * d.Dinv[i];
      pa = d.pA[i] + d.Ia[i] * c[i] + UD * d.u[i];
    }
    d.pA[p] += d.liMi[i].act_force(pa);
  }
  return aba_forward_pass<S>(model, d);
}

template const VecXT<double>& aba_same_positions<double>(const Model&, DataT<double>&, const VecXT<double>&,
                                                        const VecXT<double>&);
template const VecXT<double>& aba_same_motion<double>(const Model&, DataT<double>&, const VecXT<double>&, bool);
template const VecXT<double>& aba_after_kinematics<double>(const Model&, DataT<double>&, const VecXT<double>&,
                                                          const VecXT<double>&);
template const VecXT<ADScalar>& aba_after_kinematics<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                                              const VecXT<ADScalar>&);
template const VecXT<double>& aba<double>(const Model&, DataT<double>&, const VecXT<double>&, const VecXT<double>&,
                                          const VecXT<double>&);
template const VecXT<ADScalar>& aba<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                              const VecXT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
