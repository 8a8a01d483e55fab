#include "dynamics/forward_dynamics.hpp"

#include "dynamics/aba.hpp"
#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "spatial/autodiff.hpp"
#include "spatial/linalg.hpp"

namespace codyna {

template <class S>
const VecXT<S>& forward_dynamics(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v,
                                 const VecXT<S>& u, const Baumgarte& stab) {
  forward_kinematics<S>(model, d, q, v);
  const VecXT<S>& Q = applied_forces<S>(model, d, q, v, u);  // data.Q: nothing below writes it
  if (model.nc == 0) {
    d.lambda.setZero(model.nc);
    return aba_after_kinematics<S>(model, d, v, Q);
  }
  crba<S>(model, d, q);
  nonlinear_effects<S>(model, d, q, v);
  constraint_terms<S>(model, d, q, v);
  // independent rows at this configuration: which rows are redundant can change
  // along a motion (Bricard's mechanism), the constrained accelerations do not
  Eigen::MatrixXd Jv(model.nc, model.nv);
  for (int r = 0; r < model.nc; ++r)
    for (int c = 0; c < model.nv; ++c) Jv(r, c) = ad_value(d.Jc(r, c));
  const std::vector<int> rows = partition_rows(Jv, 1e-9, static_cast<int>(model.active_rows.size())).independent;
  const int na = static_cast<int>(rows.size());
  MatXT<S> J(na, model.nv);
  VecXT<S> rhs(na);
  for (int k = 0; k < na; ++k) {
    const int r = rows[k];
    J.row(k) = d.Jc.row(r);
    rhs[k] = d.gamma[r];
  }
  if (stab.alpha != 0.0 || stab.beta != 0.0) {
    const VecXT<S> Jvel = J * v;
    for (int k = 0; k < na; ++k)
      rhs[k] += S(2.0 * stab.alpha) * Jvel[k] + S(stab.beta * stab.beta) * d.phi[rows[k]];
  }
  // [qdd_free, M^-1 J^T] in one factorization
  MatXT<S> B(model.nv, 1 + na);
  B.col(0) = Q - d.nle;
  B.rightCols(na) = J.transpose();
  const MatXT<S> X = cholesky_solve<S>(d.M, B);
  const MatXT<S> A = J * X.rightCols(na);
  const VecXT<S> lam = cholesky_solve<S>(A, MatXT<S>(J * X.col(0) + rhs)).col(0);
  d.qdd = X.col(0) - X.rightCols(na) * lam;
  d.lambda.setZero(model.nc);
  for (int k = 0; k < na; ++k) d.lambda[rows[k]] = lam[k];
  return d.qdd;
}

template const VecXT<double>& forward_dynamics<double>(const Model&, DataT<double>&, const VecXT<double>&,
                                                       const VecXT<double>&, const VecXT<double>&, const Baumgarte&);
template const VecXT<ADScalar>& forward_dynamics<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                                           const VecXT<ADScalar>&, const VecXT<ADScalar>&,
                                                           const Baumgarte&);

}  // namespace codyna
