#include "dynamics/aba.hpp"

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"
#include "spatial/linalg.hpp"

namespace codyna {

namespace {
// inverse of a small joint-space matrix; the common one-coordinate case without a factorization
template <class S>
void small_inverse(const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>& D,
                   Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>& Dinv) {
  const Eigen::Index n = D.rows();
  Dinv.resize(n, n);
  if (n == 1) {
    Dinv(0, 0) = S(1) / D(0, 0);
  } else if (n > 1) {
    Dinv = lu_solve<S>(MatXT<S>(D), MatXT<S>::Identity(n, n));
  }
}
}  // namespace

template <class S>
const VecXT<S>& aba(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& tau) {
  forward_kinematics<S>(model, d, q, v);
  return aba_after_kinematics<S>(model, d, v, tau);
}

template <class S>
const VecXT<S>& aba_after_kinematics(const Model& model, DataT<S>& d, const VecXT<S>& v, const VecXT<S>& tau) {
  std::vector<Vec6T<S>>& c = d.c;
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const Mat6T<S> I = model.inertia[i].cast<S>();
    d.IA[i] = I;
    d.pA[i] = cross_force<S>(d.v[i], Vec6T<S>(I * d.v[i]));
    c[i] = d.cJ[i] + cross_motion<S>(d.v[i], Vec6T<S>(d.Sb[i] * v.segment(j.idx_v, j.nv)));
  }
  for (int i = model.nbodies - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    d.U[i] = d.IA[i] * d.Sb[i];
    const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6> D = d.Sb[i].transpose() * d.U[i];
    small_inverse<S>(D, d.Dinv[i]);
    d.u[i] = tau.segment(j.idx_v, j.nv) - d.Sb[i].transpose() * d.pA[i];
    const int p = j.parent;
    if (p == 0) continue;
    const Mat6T<S> Ia = d.IA[i] - d.U[i] * d.Dinv[i] * d.U[i].transpose();
    const Vec6T<S> pa = d.pA[i] + Ia * c[i] + d.U[i] * (d.Dinv[i] * d.u[i]);
    const Mat6T<S> Xi = d.liMi[i].inverse().motion_matrix();
    d.IA[p] += Xi.transpose() * Ia * Xi;
    d.pA[p] += d.liMi[i].act_force(pa);
  }
  d.a[0].setZero();
  if (model.has_gravity) d.a[0].template tail<3>() = -model.gravity.cast<S>();
  for (int i = 1; i < model.nbodies; ++i) {
    const JointModel& j = model.joints[i];
    const Vec6T<S> ap = d.liMi[i].inv_act_motion(d.a[j.parent]) + c[i];
    const Eigen::Matrix<S, Eigen::Dynamic, 1, 0, 6, 1> qdd_i = d.Dinv[i] * (d.u[i] - d.U[i].transpose() * ap);
    if (j.nv > 0) d.qdd.segment(j.idx_v, j.nv) = qdd_i;
    d.a[i] = ap + d.Sb[i] * qdd_i;
  }
  // data.a holds accelerations including the gravity offset here; keep the
  // documented meaning (no gravity) for callers that read it.
  if (model.has_gravity) {
    const Vec6T<S> a0 = d.a[0];
    for (int i = 1; i < model.nbodies; ++i) d.a[i] -= d.oMi[i].inverse().motion_matrix() * a0;
    d.a[0].setZero();
  }
  return d.qdd;
}

template const VecXT<double>& aba_after_kinematics<double>(const Model&, DataT<double>&, const VecXT<double>&,
                                                          const VecXT<double>&);
template const VecXT<ADScalar>& aba_after_kinematics<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                                              const VecXT<ADScalar>&);
template const VecXT<double>& aba<double>(const Model&, DataT<double>&, const VecXT<double>&, const VecXT<double>&,
                                          const VecXT<double>&);
template const VecXT<ADScalar>& aba<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                              const VecXT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
