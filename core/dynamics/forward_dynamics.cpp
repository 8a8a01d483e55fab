#include "dynamics/forward_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <Eigen/Cholesky>

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

namespace {
template <class M>
void resize_if(M& m, Eigen::Index r, Eigen::Index c) {
  if (m.rows() != r || m.cols() != c) m.resize(r, c);
}

// M a + J^T lam = f, J a + rhs = 0 in the loop workspace: w.X holds [f, J^T] (M's size x 1 + na),
// w.J and w.rhs the kept rows. With M = L L^T (Eigen's blocked Cholesky in place in w.L, a copy of
// M: no heap once sized), [y, Y] = L^-1 [f, J^T] by one triangular solve; the Schur complement
// J M^-1 J^T = Y^T Y and J M^-1 f = Y^T y give the multipliers (w.lam), and w.X.col(0) becomes
// a = L^-T (y - Y lam). Throws for a matrix that is not positive definite (a NaN pivot included).
void schur_solve(const Eigen::MatrixXd& M, Data::LoopSolve& w, int na) {
  auto factor = [](const Eigen::MatrixXd& A, Eigen::MatrixXd& L) {
    L = A;  // (the same size as before: no reallocation)
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(L);
    // (a NaN pivot passes Eigen's test d <= 0: refused here by the diagonal's sum)
    if (llt.info() != Eigen::Success || !std::isfinite(L.diagonal().sum()))
      throw std::runtime_error("matrix is not positive definite");
  };
  factor(M, w.L);
  w.L.triangularView<Eigen::Lower>().solveInPlace(w.X);
  const auto y = w.X.col(0);
  const auto Y = w.X.rightCols(na);
  resize_if(w.A, na, na);
  w.A.noalias() = Y.transpose() * Y;
  resize_if(w.lam, na, 1);
  w.lam.noalias() = Y.transpose() * y;
  w.lam += w.rhs;
  factor(w.A, w.LA);
  w.LA.triangularView<Eigen::Lower>().solveInPlace(w.lam);
  w.LA.transpose().triangularView<Eigen::Upper>().solveInPlace(w.lam);
  w.X.col(0).noalias() -= Y * w.lam;
  w.L.transpose().triangularView<Eigen::Upper>().solveInPlace(w.X.col(0));
}

// d.loop.rows: the rows of Jc kept at this configuration, the first of the column-pivoted QR of
// Jc^T up to the rank fixed at assembly, in increasing order. Where that rank is every row (no
// redundant constraint) the answer is all of them, without the factorization.
void kept_loop_rows(const Model& model, Data& d) {
  Data::LoopSolve& w = d.loop;
  const int rank = static_cast<int>(model.active_rows.size());
  w.rows.clear();
  if (rank == model.nc) {
    for (int k = 0; k < rank; ++k) w.rows.push_back(k);
    return;
  }
  w.qr.compute(d.Jc.transpose());
  const auto& perm = w.qr.colsPermutation().indices();
  for (int k = 0; k < rank; ++k) w.rows.push_back(perm[k]);
  std::sort(w.rows.begin(), w.rows.end());
}

// the closed-loop branch of forward_dynamics in double, in data's workspace
// (the same steps and the same arithmetic as the generic branch below, no heap
// after the first call); forward_kinematics(q, v) and applied_forces have run
const Eigen::VectorXd& closed_loop_dynamics(const Model& model, Data& d, const Eigen::VectorXd& q,
                                            const Eigen::VectorXd& v, const Eigen::VectorXd& Q,
                                            const Baumgarte& stab) {
  crba_after_kinematics<double>(model, d);
  nonlinear_effects<double>(model, d, q, v);
  constraint_terms<double>(model, d, q, v);
  Data::LoopSolve& w = d.loop;
  const int nv = model.nv;
  // independent rows at this configuration (partition_rows with the rank fixed at assembly)
  kept_loop_rows(model, d);
  const int na = static_cast<int>(w.rows.size());
  resize_if(w.J, na, nv);
  resize_if(w.rhs, na, 1);
  for (int k = 0; k < na; ++k) {
    w.J.row(k) = d.Jc.row(w.rows[k]);
    w.rhs[k] = d.gamma[w.rows[k]];
  }
  if (stab.alpha != 0.0 || stab.beta != 0.0) {
    resize_if(w.Jvel, na, 1);
    w.Jvel.noalias() = w.J * v;
    for (int k = 0; k < na; ++k)
      w.rhs[k] += 2.0 * stab.alpha * w.Jvel[k] + stab.beta * stab.beta * d.phi[w.rows[k]];
  }
  resize_if(w.X, nv, 1 + na);
  w.X.col(0) = Q - d.nle;
  w.X.rightCols(na) = w.J.transpose();
  schur_solve(d.M, w, na);
  d.qdd = w.X.col(0);
  d.lambda.setZero(model.nc);
  for (int k = 0; k < na; ++k) d.lambda[w.rows[k]] = w.lam[k];
  return d.qdd;
}

// prescribed_dynamics (below) in double, in data's workspace: the same equations, no heap after the
// first call; forward_kinematics(q, v) and applied_forces have run. The independent loop rows are
// kept in d.loop.rows, as closed_loop_dynamics keeps them.
const Eigen::VectorXd& prescribed_dynamics_double(const Model& model, Data& d, const Eigen::VectorXd& q,
                                                  const Eigen::VectorXd& v, const Eigen::VectorXd& Q,
                                                  const Baumgarte& stab) {
  const int nv = model.nv, nm = static_cast<int>(model.motions.size());
  crba_after_kinematics<double>(model, d);
  nonlinear_effects<double>(model, d, q, v);
  Data::LoopSolve& w = d.loop;
  if (static_cast<int>(w.driven.size()) != nm || static_cast<int>(w.free.size()) + nm != nv) {
    w.driven.clear();
    w.free.clear();
    for (int k = 0; k < nm; ++k) w.driven.push_back(model.actuators[static_cast<std::size_t>(model.motions[k])].iv);
    for (int i = 0; i < nv; ++i)
      if (std::find(w.driven.begin(), w.driven.end(), i) == w.driven.end()) w.free.push_back(i);
  }
  const int nf = static_cast<int>(w.free.size());
  resize_if(w.f, nv, 1);
  w.f = Q - d.nle;
  for (int k = 0; k < nm; ++k) w.f.noalias() -= d.M.col(w.driven[k]) * d.motion_acc[k];
  w.rows.clear();
  if (model.nc > 0) {
    constraint_terms<double>(model, d, q, v);
    kept_loop_rows(model, d);
  }
  const int na = static_cast<int>(w.rows.size());
  resize_if(w.Mff, nf, nf);
  resize_if(w.X, nf, 1 + na);
  resize_if(w.J, na, nf);
  resize_if(w.rhs, na, 1);
  for (int i = 0; i < nf; ++i) {
    for (int j = 0; j < nf; ++j) w.Mff(i, j) = d.M(w.free[i], w.free[j]);
    w.X(i, 0) = w.f[w.free[i]];
  }
  for (int k = 0; k < na; ++k) {
    for (int i = 0; i < nf; ++i) w.J(k, i) = d.Jc(w.rows[k], w.free[i]);
    w.rhs[k] = d.gamma[w.rows[k]];
    // a driven coordinate of a loop: J_f a_f = -J_d a_d - gamma
    for (int j = 0; j < nm; ++j) w.rhs[k] += d.Jc(w.rows[k], w.driven[j]) * d.motion_acc[j];
  }
  d.qdd.setZero(nv);
  d.lambda.setZero(model.nc);
  if (nf > 0) {
    if (stab.alpha != 0.0 || stab.beta != 0.0)
      for (int k = 0; k < na; ++k) {
        double Jvel = 0.0;
        for (int c = 0; c < nv; ++c) Jvel += d.Jc(w.rows[k], c) * v[c];
        w.rhs[k] += 2.0 * stab.alpha * Jvel + stab.beta * stab.beta * d.phi[w.rows[k]];
      }
    w.X.rightCols(na) = w.J.transpose();
    schur_solve(w.Mff, w, na);
    for (int k = 0; k < na; ++k) d.lambda[w.rows[k]] = w.lam[k];
    for (int i = 0; i < nf; ++i) d.qdd[w.free[i]] = w.X(i, 0);
  }
  for (int k = 0; k < nm; ++k) d.qdd[w.driven[k]] = d.motion_acc[k];
  for (int k = 0; k < nm; ++k) {
    d.motion_force[k] = d.nle[w.driven[k]] - Q[w.driven[k]] + d.M.row(w.driven[k]).dot(d.qdd);
    for (int r = 0; r < na; ++r) d.motion_force[k] += d.Jc(w.rows[r], w.driven[k]) * d.lambda[w.rows[r]];  // the loops' share
  }
  return d.qdd;
}

// Motion inputs: their coordinates d follow prescribed accelerations a (data.motion_acc; q and v
// there are the caller's), so only the free coordinates f are unknown:
//   M_ff qdd_f = (Q - nle - M_:d a)_f - J_f^T lambda,   J_f qdd_f + J_d a + gamma = -stab
// (J_d: the loops' columns of the driven coordinates, a crank driven in a four-bar; prepare_model
// checks that the loops keep the rank of Jc on the free columns, so the rows independent in Jc
// are independent in J_f). The generalized force each motion supplies is (M qdd + nle - Q + Jc^T lambda)_d.
template <class S>
const VecXT<S>& prescribed_dynamics(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v,
                                    const VecXT<S>& Q, const Baumgarte& stab) {
  const int nv = model.nv, nm = static_cast<int>(model.motions.size());
  crba<S>(model, d, q);
  nonlinear_effects<S>(model, d, q, v);
  std::vector<int> dr(nm), fr;
  for (int k = 0; k < nm; ++k) dr[k] = model.actuators[model.motions[k]].iv;
  for (int i = 0; i < nv; ++i)
    if (std::find(dr.begin(), dr.end(), i) == dr.end()) fr.push_back(i);
  const int nf = static_cast<int>(fr.size());
  // (every product is evaluated into an S before it is summed: an autodiff sum of unevaluated
  // products does not reconcile a constant's empty derivatives with the others')
  VecXT<S> rhs = Q - d.nle;
  for (int k = 0; k < nm; ++k)
    for (int i = 0; i < nv; ++i) {
      const S p = d.M(i, dr[k]) * d.motion_acc[k];
      rhs[i] = rhs[i] - p;
    }
  std::vector<int> rows;
  if (model.nc > 0) {
    constraint_terms<S>(model, d, q, v);
    Eigen::MatrixXd Jv(model.nc, nv);
    for (int r = 0; r < model.nc; ++r)
      for (int c = 0; c < nv; ++c) Jv(r, c) = ad_value(d.Jc(r, c));
    rows = partition_rows(Jv, 1e-9, static_cast<int>(model.active_rows.size())).independent;
  }
  const int na = static_cast<int>(rows.size());
  MatXT<S> Mff(nf, nf), B(nf, 1 + na);
  for (int i = 0; i < nf; ++i) {
    for (int j = 0; j < nf; ++j) Mff(i, j) = d.M(fr[i], fr[j]);
    B(i, 0) = rhs[fr[i]];
    for (int k = 0; k < na; ++k) B(i, 1 + k) = d.Jc(rows[k], fr[i]);
  }
  d.qdd.setZero(nv);
  d.lambda.setZero(model.nc);
  // one derivative size for every entry the solves below combine (a constant's empty vector
  // beside a variable's inside a product is lost: a drive torque's column of B came out zero)
  const Eigen::Index nd = std::max({ad_size(Mff), ad_size(B), ad_size(d.gamma), ad_size(d.motion_acc), ad_size(v)});
  ad_make_coherent(Mff, nd);
  ad_make_coherent(B, nd);
  if (nf > 0) {
    const MatXT<S> X = cholesky_solve<S>(Mff, B);
    VecXT<S> qf = X.col(0);
    if (na > 0) {
      VecXT<S> crhs(na);
      for (int k = 0; k < na; ++k) {
        crhs[k] = ad_coherent(d.gamma[rows[k]], nd);
        for (int j = 0; j < nm; ++j) {
          const S p = d.Jc(rows[k], dr[j]) * d.motion_acc[j];
          crhs[k] = crhs[k] + p;
        }
      }
      if (stab.alpha != 0.0 || stab.beta != 0.0)
        for (int k = 0; k < na; ++k) {
          S Jvel = S(0.0);
          for (int c = 0; c < nv; ++c) {
            const S p = d.Jc(rows[k], c) * v[c];
            Jvel = Jvel + p;
          }
          const S a = S(2.0 * stab.alpha) * Jvel, b = S(stab.beta * stab.beta) * d.phi[rows[k]];
          crhs[k] = crhs[k] + a;
          crhs[k] = crhs[k] + b;
        }
      const MatXT<S> Jt = B.rightCols(na);
      const MatXT<S> A = Jt.transpose() * X.rightCols(na);
      const VecXT<S> lam = cholesky_solve<S>(A, MatXT<S>(Jt.transpose() * X.col(0) + crhs)).col(0);
      qf -= X.rightCols(na) * lam;
      for (int k = 0; k < na; ++k) d.lambda[rows[k]] = lam[k];
    }
    for (int i = 0; i < nf; ++i) d.qdd[fr[i]] = qf[i];
  }
  for (int k = 0; k < nm; ++k) d.qdd[dr[k]] = d.motion_acc[k];
  for (int k = 0; k < nm; ++k) {
    S f = d.nle[dr[k]] - Q[dr[k]];
    for (int c = 0; c < nv; ++c) {
      const S p = d.M(dr[k], c) * d.qdd[c];
      f = f + p;
    }
    for (int r : rows) {  // the loops' share, J_d^T lambda
      const S p = d.Jc(r, dr[k]) * d.lambda[r];
      f = f + p;
    }
    d.motion_force[k] = f;
  }
  return d.qdd;
}
}  // namespace

template <class S>
const VecXT<S>& forward_dynamics(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v,
                                 const VecXT<S>& u, const Baumgarte& stab) {
  forward_kinematics<S>(model, d, q, v);
  const VecXT<S>& Q = applied_forces<S>(model, d, q, v, u);  // data.Q: nothing below writes it
  if (!model.motions.empty()) {
    if constexpr (std::is_same_v<S, double>) return prescribed_dynamics_double(model, d, q, v, Q, stab);
    return prescribed_dynamics<S>(model, d, q, v, Q, stab);
  }
  if (model.nc == 0) {
    d.lambda.setZero(model.nc);
    return aba_after_kinematics<S>(model, d, v, Q);
  }
  if constexpr (std::is_same_v<S, double>) return closed_loop_dynamics(model, d, q, v, Q, stab);
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

Eigen::VectorXd prescribed_velocity_jump(const Model& model, Data& d, const Eigen::VectorXd& q,
                                         const Eigen::VectorXd& jump) {
  const int nv = model.nv, nm = static_cast<int>(model.motions.size());
  if (jump.size() != nm) throw std::invalid_argument("prescribed_velocity_jump: one rate jump per motion input");
  // the balance of prescribed_dynamics with no forces, no velocity terms and the jumps as accelerations
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nv);
  forward_kinematics<double>(model, d, q, zero);
  d.motion_acc = jump;
  // prescribed_dynamics subtracts nle (at rest: gravity alone); Q = nle cancels it, and gamma = 0
  nonlinear_effects<double>(model, d, q, zero);
  const Eigen::VectorXd Q = d.nle;
  const Eigen::VectorXd dv = prescribed_dynamics<double>(model, d, q, zero, Q, Baumgarte{});
  d.motion_acc.setZero();
  return dv;
}

}  // namespace codyna
