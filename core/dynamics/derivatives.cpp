#include "dynamics/derivatives.hpp"

#include <unsupported/Eigen/AutoDiff>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "dynamics/tire_effect.hpp"

namespace codyna {

namespace {

using Vec6 = Vec6T<double>;
using Mat6 = Mat6T<double>;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Forward differentiation over the local variables of at most two bodies:
// [0, 6) pose twist of body a, [6, 12) velocity change of body a, [12, 24) the same for body b.
using Der24 = Eigen::Matrix<double, 24, 1>;
using AD = Eigen::AutoDiffScalar<Der24>;
using Vec3A = Eigen::Matrix<AD, 3, 1>;
using Mat3A = Eigen::Matrix<AD, 3, 3>;

Vec6 crm(const Vec6& m, const Vec6& x) { return cross_motion<double>(m, x); }
Vec6 crf(const Vec6& m, const Vec6& f) { return cross_force<double>(m, f); }

using Inertia = RigidInertiaT<double>;

// The "Coriolis inertia" V x* I - I V x of a world inertia I = (m, h, J) (about the world origin)
// moving with V = [w; v]: the time derivative of I, itself of an inertia's form with zero mass,
// [dJ, [dh]; [dh]^T, 0], with dh = w x h + m v and dJ = [w] J - J [w] - ([h][v] + [v][h]), where
// [w] J - J [w] = Y + Y^T for Y = [w] J (J symmetric) and [h][v] + [v][h] = v h^T + h v^T - 2 (h.v) 1
Inertia inertia_rate(const Vec6& V, const Inertia& I) {
  const Vec3 w = V.head<3>(), v = V.tail<3>();
  Inertia r;
  r.m = 0.0;
  r.h = w.cross(I.h) + I.m * v;
  Mat3 Y;
  for (int c = 0; c < 3; ++c) Y.col(c) = w.cross(Vec3(I.I.col(c)));
  const double hv2 = 2.0 * I.h.dot(v);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k <= c; ++k) {
      double e = Y(k, c) + Y(c, k) - v[k] * I.h[c] - I.h[k] * v[c];
      if (k == c) e += hv2;
      r.I(k, c) = e;
      r.I(c, k) = e;
    }
  return r;
}

// an inertia rate (zero mass) applied to a motion [x; y]: [dJ x + dh x y; -dh x x]
Vec6 apply_rate(const Inertia& B, const Vec6& m) {
  const Vec3 x = m.head<3>(), y = m.tail<3>();
  Vec6 r;
  r << B.I * x + B.h.cross(y), x.cross(B.h);
  return r;
}

struct BodyAD {
  Mat3A R;
  Vec3A p;
  Vec3A w, vO;  // world angular velocity, velocity of the point at the world origin
  Vec3A point(const Vec3& x) const { return R * x.cast<AD>() + p; }
  Vec3A point_velocity(const Vec3A& x) const { return vO + w.cross(x); }
};

// the pose and velocity of a body as functions of its local variables (offset 0 or 12);
// ground (body 0) and inactive slots are constants
BodyAD body_ad(const SE3& g, const Vec6& V, int offset, bool active) {
  BodyAD b;
  Vec3A dw, dv, Dw, Dv;
  for (int k = 0; k < 3; ++k) {
    dw[k] = AD(0.0);
    dv[k] = AD(0.0);
    Dw[k] = AD(V[k]);
    Dv[k] = AD(V[3 + k]);
    if (active) {
      dw[k].derivatives()[offset + k] = 1.0;
      dv[k].derivatives()[offset + 3 + k] = 1.0;
      Dw[k].derivatives()[offset + 6 + k] = 1.0;
      Dv[k].derivatives()[offset + 9 + k] = 1.0;
    }
  }
  const Mat3A R0 = g.R.cast<AD>();
  const Vec3A p0 = g.p.cast<AD>();
  b.R = R0 + skew<AD>(dw) * R0;
  b.p = p0 + dw.cross(p0) + dv;
  b.w = Dw;
  b.vO = Dv;
  return b;
}

void wrench_value(const Vec3A& x, const Vec3A& F, const Vec3A& T, Vec6& w, Eigen::Matrix<double, 6, 24>& dw) {
  const Vec3A n = x.cross(F) + T;
  for (int k = 0; k < 3; ++k) {
    w[k] = n[k].value();
    w[3 + k] = F[k].value();
    dw.row(k) = n[k].derivatives().transpose();
    dw.row(3 + k) = F[k].derivatives().transpose();
  }
}

// A body point (or a body-fixed vector) in world axes with its first two time
// derivatives, and their derivatives with respect to the body's 18 local
// variables [pose twist, velocity V, acceleration A] (world axes, about the
// origin; the pose twist moves x by dtheta x x + dp). With P = dx/dpose,
// W = [w]x and Al = [alpha]x:
//   dx   = [P, 0, 0]
//   dxd  = [W P, P, 0]
//   dxdd = [(Al + W W) P, [-[xd]x, 0] + W P, P]
struct LocalKin {
  Vec3 x, xd, xdd;
  Eigen::Matrix<double, 3, 18> Dx, Dxd, Dxdd;
};
LocalKin local_kin(const SE3& g, const Vec6& V, const Vec6& A, const Vec3& l, bool vector, bool active) {
  LocalKin k;
  const Vec3 w = V.head<3>(), al = A.head<3>();
  k.x = g.R * l;
  if (!vector) k.x += g.p;
  k.xd = w.cross(k.x);
  if (!vector) k.xd += V.tail<3>();
  k.xdd = al.cross(k.x) + w.cross(k.xd);
  if (!vector) k.xdd += A.tail<3>();
  k.Dx.setZero();
  k.Dxd.setZero();
  k.Dxdd.setZero();
  if (!active) return k;
  Eigen::Matrix<double, 3, 6> P;
  P.leftCols<3>() = -skew<double>(k.x);
  if (vector) P.rightCols<3>().setZero();
  else P.rightCols<3>().setIdentity();
  const Mat3 W = skew<double>(w);
  const Eigen::Matrix<double, 3, 6> WP = W * P;
  k.Dx.leftCols<6>() = P;
  k.Dxd.leftCols<6>() = WP;
  k.Dxd.middleCols<6>(6) = P;
  k.Dxdd.leftCols<6>().noalias() = skew<double>(al) * P + W * WP;
  k.Dxdd.middleCols<6>(6) = WP;
  k.Dxdd.middleCols<3>(6) -= skew<double>(k.xd);
  k.Dxdd.middleCols<6>(12) = P;
  return k;
}

// rotor inertia (armature): tau += armature a on each coordinate (constant: no q or v derivative)
void add_armature_force(const Model& m, const Eigen::VectorXd& a, Eigen::VectorXd& tau) {
  if (m.armature.size() != 0) tau.array() += m.armature.array() * a.array();
}

using Grad36 = Eigen::Matrix<double, 36, 1>;
// a rolling_disc lying flat on its plane: |n - (n . a) a| below this has no contact direction (as
// in constraints.cpp)
constexpr double kDiscFlat = 1e-6;
// g += D^T f on the 18 variables of `slot`
void add_grad(Grad36& g, int slot, const Vec3& f, const Eigen::Matrix<double, 3, 18>& D) {
  g.segment<18>(18 * slot).noalias() += D.transpose() * f;
}

}  // namespace

bool TreeDerivatives::supports(const Model& model) { return model.nc == 0; }

TreeDerivatives::TreeDerivatives(const Model& model) : m_(&model), d_(model), llt_(model.nv) { size_for(model); }

void TreeDerivatives::bind(const Model& model) {
  if (llt_.rows() != model.nv) llt_ = Eigen::LLT<Eigen::MatrixXd>(model.nv);  // (m_ may be gone: not read)
  m_ = &model;
  d_.reset(model);
  size_for(model);
}

// everything the model determines, set as a new object would have it; std::vector::clear/assign
// and Eigen's setZero keep their storage when the sizes repeat (bind() on a model of the same
// shape makes no heap allocation but Data's constants' scratch)
void TreeDerivatives::size_for(const Model& model) {
  const int nb = model.nbodies, nv = model.nv;
  units_.clear();
  unit_begin_.assign(nb, 0);
  unit_end_.assign(nb, 0);
  col_unit_.assign(nv, 0);
  for (int i = 1; i < nb; ++i) {
    const JointModel& j = model.joints[i];
    unit_begin_[i] = static_cast<int>(units_.size());
    const bool chain = j.type == JointType::Universal || j.type == JointType::Planar;
    if (chain) {
      for (int c = 0; c < j.nv; ++c) units_.push_back({i, j.idx_v + c, 1});
    } else if (j.nv > 0) {
      units_.push_back({i, j.idx_v, j.nv});
    }
    unit_end_[i] = static_cast<int>(units_.size());
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u)
      for (int c = 0; c < units_[u].n; ++c) col_unit_[units_[u].iv + c] = u;
  }
  path_.resize(static_cast<std::size_t>(nb));
  if (nb > 0) path_[0].clear();
  for (int i = 1; i < nb; ++i) {
    path_[i].assign(path_[model.parent[i]].begin(), path_[model.parent[i]].end());
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) path_[i].push_back(u);
  }
  const int nu = static_cast<int>(units_.size());
  S_.assign(nb, Mat6xT<double>());
  V_.assign(nb, Vec6::Zero());
  A_.assign(nb, Vec6::Zero());
  Vpar_.assign(nu, Vec6::Zero());
  Apar_.assign(nu, Vec6::Zero());
  Vu_.assign(nu, Vec6::Zero());
  I_.assign(nb, Inertia());
  Ic_.assign(nb, Inertia());
  Bc_.assign(nb, Inertia());
  hb_.assign(nb, Vec6::Zero());
  fv_.assign(nb, Vec6::Zero());
  hc_.assign(nb, Vec6::Zero());
  cu_.assign(nu, Vec6::Zero());
  F_.assign(nb, Vec6::Zero());
  PR_.assign(nu, Rows12::Zero());
  {
    std::vector<char>& below = below_;
    below.assign(static_cast<std::size_t>(nb), 0);
    sub_begin_.assign(static_cast<std::size_t>(nb) + 1, 0);
    sub_bodies_.clear();
    for (int i = 0; i < nb; ++i) {
      sub_begin_[i] = static_cast<int>(sub_bodies_.size());
      if (i == 0) continue;
      std::fill(below.begin(), below.end(), 0);
      below[i] = 1;
      for (int b = i + 1; b < nb; ++b) below[b] = below[model.parent[b]];
      for (int b = i; b < nb; ++b)
        if (below[b] && unit_begin_[b] < unit_end_[b]) sub_bodies_.push_back(b);
    }
    sub_begin_[nb] = static_cast<int>(sub_bodies_.size());
  }
  com_.assign(nb, ComInertia());
  for (int i = 1; i < nb; ++i) {
    const Mat3 cx = skew<double>(model.com[i]);
    com_[i].m = model.mass[i];
    com_[i].c = model.com[i];
    com_[i].Ic = model.inertia[i].topLeftCorner<3, 3>() - model.mass[i] * cx * cx.transpose();
  }
  qdd.setZero(nv);
  qdd_zero_.setZero(nv);
  tau.setZero(nv);
  dtau_dq.setZero(nv, nv);
  dtau_dv.setZero(nv, nv);
  Q.setZero(nv);
  dQ_dq.setZero(nv, nv);
  dQ_dv.setZero(nv, nv);
  dQ_du.setZero(nv, model.nu());
  dqdd_dq.setZero(nv, nv);
  dqdd_dv.setZero(nv, nv);
  dqdd_du.setZero(nv, model.nu());
  M.setZero(nv, nv);
  rhs_.setZero(nv, 2 * nv + model.nu());
  const int nm = static_cast<int>(model.motions.size());
  dqdd_dacc.setZero(nv, nm);
  driven_.clear();
  free_.clear();
  for (int k : model.motions) driven_.push_back(model.actuators[static_cast<std::size_t>(k)].iv);
  for (int i = 0; i < nv; ++i)
    if (std::find(driven_.begin(), driven_.end(), i) == driven_.end()) free_.push_back(i);
  if (nm > 0) {
    const int nf = static_cast<int>(free_.size());
    Mff_.setZero(nf, nf);
    Rf_.setZero(nf, 2 * nv + model.nu() + nm);
    if (llt_ff_.rows() != nf) llt_ff_ = Eigen::LLT<Eigen::MatrixXd>(nf);
  }
  Minv_.setZero(nv, nv);
  chol_.setZero(nv, nv);
  chol_inv_.setZero(nv, nv);
  scratch_row_.setZero(nv);
  IA_.assign(nb, Mat6::Zero());
  Fb_.resize(static_cast<std::size_t>(nb));
  Ab_.resize(static_cast<std::size_t>(nb));
  for (int i = 0; i < nb; ++i) {
    Fb_[i].setZero(6, nv);
    Ab_[i].setZero(6, nv);
  }
  Uu_.assign(nu, Mat6::Zero());
  pa_.assign(nb, Vec6::Zero());
  X_.setZero(nv, 2 * nv);
  scratch_rows_.setZero(6, 2 * nv);  // k rows of a unit over nv (M^-1) or 2 nv (X_) columns
  Fr_.resize(static_cast<std::size_t>(nb));
  Ar_.resize(static_cast<std::size_t>(nb));
  for (int i = 0; i < nb; ++i) {
    Fr_[i].setZero(6, 2 * nv);
    Ar_[i].setZero(6, 2 * nv);
  }
  av_.assign(nb, Vec6::Zero());
  Dinv_.assign(nu, Mat6::Zero());
  col_begin_.assign(nb, nv);
  col_end_.assign(nb, 0);
  for (int i = nb - 1; i > 0; --i) {
    const JointModel& j = model.joints[i];
    if (j.nv > 0) {
      col_begin_[i] = std::min(col_begin_[i], j.idx_v);
      col_end_[i] = std::max(col_end_[i], j.idx_v + j.nv);
    }
    const int p = model.parent[i];
    if (p > 0 && col_begin_[i] < col_end_[i]) {
      col_begin_[p] = std::min(col_begin_[p], col_begin_[i]);
      col_end_[p] = std::max(col_end_[p], col_end_[i]);
    }
  }
  for (int i = 0; i < nb; ++i)
    if (col_begin_[i] >= col_end_[i]) col_begin_[i] = col_end_[i] = 0;
  // depth-first numbering (every subtree's columns exactly its range): one shared force block
  std::vector<int>& sub_nv = sub_nv_;
  sub_nv.assign(nb, 0);
  children_.assign(nb, 0);
  for (int i = nb - 1; i > 0; --i) {
    sub_nv[i] += model.joints[i].nv;
    const int p = model.parent[i];
    sub_nv[p] += sub_nv[i];
    ++children_[p];
  }
  depth_first_ = true;
  for (int i = 1; i < nb; ++i)
    if (col_end_[i] - col_begin_[i] != sub_nv[i]) depth_first_ = false;
  lambda_.assign(nv, -1);
  col_sub_end_.assign(nv, 0);
  {
    bool ordered = true;
    long work = 0;
    for (int i = 1; i < nb; ++i) {
      const JointModel& j = model.joints[i];
      int above = -1;  // the last column of the nearest ancestor with one
      for (int p = model.parent[i]; p > 0; p = model.parent[p])
        if (model.joints[p].nv > 0) {
          above = model.joints[p].idx_v + model.joints[p].nv - 1;
          break;
        }
      for (int a = 0; a < j.nv; ++a) {
        const int c = j.idx_v + a;
        lambda_[c] = a == 0 ? above : c - 1;
        if (lambda_[c] >= c) ordered = false;
        col_sub_end_[c] = col_end_[i];
        work += static_cast<long>(col_end_[i] - c) * (col_end_[i] - c);
      }
    }
    tree_inverse_ = ordered && nv >= kDenseInverseBelow && nv < kRowsSolveFrom &&
                    6 * work <= static_cast<long>(nv) * nv * nv;
  }
  scratch_.setZero(nv);
  Jc.setZero(model.nc, nv);
  dc_dq.setZero(model.nc, nv);
  dc_dv.setZero(model.nc, nv);
  dphid_dq.setZero(model.nc, nv);
  c.setZero(model.nc);
}

// positions and velocities: world motion subspaces, inertias and unit velocities
void TreeDerivatives::world_kinematics(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  forward_kinematics<double>(*m_, d_, q, v);
  for (int i = 1; i < m_->nbodies; ++i) {
    const JointModel& j = m_->joints[i];
    const SE3& g = d_.oMi[i];
    S_[i].resize(6, j.nv);
    for (int c = 0; c < j.nv; ++c) S_[i].col(c) = g.act_motion(Vec6(d_.Sb[i].col(c)));
    // world inertia about the world origin, from mass, com and rotational inertia
    com_[i].to_frame(g.R, g.p, I_[i]);
    const int p = j.parent;
    Vec6 Vp = p > 0 ? V_[p] : Vec6::Zero();
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      const auto Su = S_[i].middleCols(un.iv - j.idx_v, un.n);
      Vpar_[u] = Vp;
      if (un.n == 1) {
        const Vec6 vJ = Su.col(0) * v[un.iv];
        Vp += vJ;
        cu_[u] = cross_motion_scaled<double>(Vp, Su.col(0).data(), v[un.iv]);
      } else {
        const Vec6 vJ = Su * v.segment(un.iv, un.n);
        Vp += vJ;
        cu_[u] = crm(Vp, vJ);
      }
      Vu_[u] = Vp;
    }
    V_[i] = Vp;
    hb_[i] = I_[i].apply(Vp);
    fv_[i] = crf(Vp, hb_[i]);
  }
}

// accelerations for joint accelerations a (gravity enters as A_0 = -g); the units' velocity-product
// terms cu_ are world_kinematics'
void TreeDerivatives::accelerations(const Eigen::VectorXd& a) {
  Vec6 A0 = Vec6::Zero();
  if (m_->has_gravity) A0.tail<3>() = -m_->gravity;
  for (int i = 1; i < m_->nbodies; ++i) {
    const JointModel& j = m_->joints[i];
    const int p = j.parent;
    Vec6 Ap = p > 0 ? A_[p] : A0;
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      const auto Su = S_[i].middleCols(un.iv - j.idx_v, un.n);
      Apar_[u] = Ap;
      if (un.n == 1) Ap += Su.col(0) * a[un.iv];
      else Ap.noalias() += Su * a.segment(un.iv, un.n);
      Ap += cu_[u];
    }
    A_[i] = Ap;
  }
}

// subtree composites of inertia, momentum and Coriolis inertia; the unit rows P = S^T Ic and
// R = S^T (Bc + H(hc)) = (Bc S - S x* hc)^T (Ic, Bc symmetric; H(h)^T s = -(s x* h))
void TreeDerivatives::composites() {
  for (int i = 1; i < m_->nbodies; ++i) {
    Ic_[i] = I_[i];
    hc_[i] = hb_[i];
    Bc_[i] = inertia_rate(V_[i], I_[i]);
  }
  for (int i = m_->nbodies - 1; i > 0; --i) {
    const int p = m_->parent[i];
    if (p > 0) {
      Ic_[p] += Ic_[i];
      hc_[p] += hc_[i];
      Bc_[p] += Bc_[i];
    }
  }
  for (int i = 1; i < m_->nbodies; ++i) {
    if (unit_begin_[i] == unit_end_[i]) continue;
    const JointModel& j = m_->joints[i];
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      for (int c = 0; c < un.n; ++c) {
        const Vec6 s = S_[i].col(un.iv - j.idx_v + c);
        const Vec6 P = Ic_[i].apply(s);
        const Vec6 R = apply_rate(Bc_[i], s) - crf(s, hc_[i]);
        PR_[u].row(c) << P.transpose(), R.transpose();
      }
    }
  }
}

// body forces of the RNEA and their subtree sums; tau = S^T F
void TreeDerivatives::forces() {
  for (int i = 1; i < m_->nbodies; ++i) F_[i] = I_[i].apply(A_[i]) + fv_[i];
  for (int i = m_->nbodies - 1; i > 0; --i) {
    const JointModel& j = m_->joints[i];
    if (j.nv > 0) tau.segment(j.idx_v, j.nv).noalias() = S_[i].transpose() * F_[i];
    const int p = j.parent;
    if (p > 0) F_[p] += F_[i];
  }
}

// M(i, j) = S_i^T Ic_i S_j for unit j at or above unit i
void TreeDerivatives::mass_matrix() {
  for (int i = 1; i < m_->nbodies; ++i) {
    for (int ui = unit_begin_[i]; ui < unit_end_[i]; ++ui) {
      const Unit& a = units_[ui];
      for (int uj : path_[i]) {
        const Unit& b = units_[uj];
        const auto Sj = S_[b.body].middleCols(b.iv - m_->joints[b.body].idx_v, b.n);
        if (a.n == 1 && b.n == 1) {
          M(a.iv, b.iv) = M(b.iv, a.iv) = PR_[ui].row(0).head<6>().dot(Vec6(Sj.col(0)));
          if (uj == ui) break;
          continue;
        }
        if (a.n == 3 && b.n == 3) {
          const Eigen::Matrix<double, 6, 3> sj = Sj;
          M.block<3, 3>(a.iv, b.iv).noalias() = PR_[ui].topLeftCorner<3, 6>() * sj;
          if (uj == ui) break;
          M.block<3, 3>(b.iv, a.iv) = M.block<3, 3>(a.iv, b.iv).transpose();
          continue;
        }
        M.block(a.iv, b.iv, a.n, b.n).noalias() = PR_[ui].topLeftCorner(a.n, 6) * Sj;
        if (uj != ui) M.block(b.iv, a.iv, b.n, a.n) = M.block(a.iv, b.iv, a.n, b.n).transpose();
        if (uj == ui) break;
      }
    }
  }
  if (m_->armature.size() != 0) M.diagonal() += m_->armature;  // rotor inertia
}

// M^-1 by the articulated-body algorithm in world axes, with a unit force on every coordinate at
// once (no velocity, no gravity): row r of M^-1 holds the accelerations of coordinate r. Backward,
// each unit of body i (last first) with U = IA S, D = S^T U (+ armature) gives the rows
// B = D^-1 (E - S^T F) of its coordinates over the subtree's columns (E: the unit forces on its
// own), then F += U B and IA -= U D^-1 U^T pass to the unit or body above. Forward, each unit's
// rows become D^-1 (u - U^T A_above) = B - D^-1 U^T A_above and A += S rows. Rows are contiguous
// (row-major), so every step is a few fused passes over the columns.
void TreeDerivatives::inverse_mass_matrix() {
  const int nb = m_->nbodies, nv = m_->nv;
  const bool arm = m_->armature.size() != 0;
  // depth-first numbering: the subtrees' column ranges of siblings are disjoint, so one block
  // holds every body's forces (Fb_[0]); otherwise each body has its own, added to its parent's
  for (int i = 1; i < nb; ++i) IA_[i] = I_[i].matrix();
  if (depth_first_) {
    Fb_[0].setZero();
  } else {
    for (int i = 1; i < nb; ++i) Fb_[i].middleCols(col_begin_[i], col_end_[i] - col_begin_[i]).setZero();
  }
  for (int i = nb - 1; i > 0; --i) {
    const JointModel& j = m_->joints[i];
    const int c0 = col_begin_[i], len = col_end_[i] - c0;
    Mat6& Ia = IA_[i];
    double* F = Fb_[depth_first_ ? 0 : i].data() + c0;  // row r of the subtree's columns at F + r * nv
    for (int u = unit_end_[i] - 1; u >= unit_begin_[i]; --u) {
      const Unit& un = units_[u];
      const int k = un.n;
      const auto S = S_[i].middleCols(un.iv - j.idx_v, k);
      Mat6& U = Uu_[u];
      Mat6& Dinv = Dinv_[u];
      U.leftCols(k).noalias() = Ia * S;
      if (k == 1) {
        double D = S.col(0).dot(U.col(0));
        if (arm) D += m_->armature[un.iv];
        if (!(D > 0)) throw std::runtime_error("the mass matrix is not positive definite at this configuration");
        Dinv(0, 0) = 1.0 / D;
      } else if (k == 3) {  // a ball joint
        Mat3 D;
        D.noalias() = S.transpose() * U.leftCols<3>();
        if (arm) D.diagonal() += m_->armature.segment<3>(un.iv);
        const Eigen::LLT<Mat3> llt(D);
        if (llt.info() != Eigen::Success)
          throw std::runtime_error("the mass matrix is not positive definite at this configuration");
        Dinv.topLeftCorner<3, 3>() = llt.solve(Mat3::Identity());
      } else {
        Mat6 D = Mat6::Identity();
        D.topLeftCorner(k, k).noalias() = S.transpose() * U.leftCols(k);
        if (arm) D.topLeftCorner(k, k).diagonal() += m_->armature.segment(un.iv, k);
        const Eigen::LLT<Mat6> llt(D);
        if (llt.info() != Eigen::Success)
          throw std::runtime_error("the mass matrix is not positive definite at this configuration");
        Dinv = llt.solve(Mat6::Identity());
      }
      // B = D^-1 (E - S^T F) on the subtree's columns, into the unit's rows of M^-1
      for (int a = 0; a < k; ++a) {
        double* row = Minv_.row(un.iv + a).data();
        std::fill(row + c0, row + nv, 0.0);  // the forward pass reads from the subtree's first column on
        double* w = row + c0;
        const double s0 = S(0, a), s1 = S(1, a), s2 = S(2, a), s3 = S(3, a), s4 = S(4, a), s5 = S(5, a);
        for (int c = 0; c < len; ++c)
          w[c] = -(s0 * F[c] + s1 * F[nv + c] + s2 * F[2 * nv + c] + s3 * F[3 * nv + c] + s4 * F[4 * nv + c] +
                   s5 * F[5 * nv + c]);
        w[un.iv - c0 + a] += 1.0;
      }
      if (k == 1) {
        double* w = Minv_.row(un.iv).data() + c0;
        const double d = Dinv(0, 0);
        for (int c = 0; c < len; ++c) w[c] *= d;
      } else {
        auto rows = Minv_.block(un.iv, c0, k, len);
        scratch_rows_.topLeftCorner(k, len) = rows;
        rows = Dinv.topLeftCorner(k, k).lazyProduct(scratch_rows_.topLeftCorner(k, len));  // (len <= nv)
      }
      // F += U B
      for (int a = 0; a < k; ++a) {
        const double* b = Minv_.row(un.iv + a).data() + c0;
        for (int r = 0; r < 6; ++r) {
          const double ur = U(r, a);
          double* fr = F + r * nv;
          for (int c = 0; c < len; ++c) fr[c] += ur * b[c];
        }
      }
      if (k == 1) {
        Ia.noalias() -= Dinv(0, 0) * U.col(0) * U.col(0).transpose();
      } else {
        Mat6 UD;
        UD.leftCols(k) = U.leftCols(k).lazyProduct(Dinv.topLeftCorner(k, k));
        Ia -= UD.leftCols(k).lazyProduct(U.leftCols(k).transpose());
      }
    }
    const int p = j.parent;
    if (p > 0) {
      IA_[p] += Ia;
      if (!depth_first_) Fb_[p].middleCols(c0, len) += Fb_[i].middleCols(c0, len);
    }
  }
  // forward, on the columns from the subtree's first on: every other entry is the mirror of one
  // computed there (c < first(r) <= r gives r >= first(c)), as accurate as the upper triangle
  for (int i = 1; i < nb; ++i) {
    const JointModel& j = m_->joints[i];
    const int p = j.parent, cb = col_begin_[i], w = nv - cb;
    Rows6& A = Ab_[i];
    const bool moving = p > 0;
    if (moving && children_[p] == 1) A.swap(Ab_[p]);  // an only child takes its parent's block over
    else if (moving) A.middleCols(cb, w) = Ab_[p].middleCols(cb, w);
    else A.middleCols(cb, w).setZero();
    double* Ad = A.data() + cb;
    bool any = moving;
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      const int k = un.n;
      const auto S = S_[i].middleCols(un.iv - j.idx_v, k);
      if (any) {  // rows -= D^-1 U^T A
        Mat6 G;   // D^-1 U^T, k x 6 (padded)
        G.topRows(k) = Dinv_[u].topLeftCorner(k, k).lazyProduct(Uu_[u].leftCols(k).transpose());
        for (int a = 0; a < k; ++a) {
          double* row = Minv_.row(un.iv + a).data() + cb;
          const double g0 = G(a, 0), g1 = G(a, 1), g2 = G(a, 2), g3 = G(a, 3), g4 = G(a, 4), g5 = G(a, 5);
          for (int c = 0; c < w; ++c)
            row[c] -= g0 * Ad[c] + g1 * Ad[nv + c] + g2 * Ad[2 * nv + c] + g3 * Ad[3 * nv + c] + g4 * Ad[4 * nv + c] +
                      g5 * Ad[5 * nv + c];
        }
      }
      for (int a = 0; a < k; ++a) {  // A += S rows
        const double* row = Minv_.row(un.iv + a).data() + cb;
        for (int r = 0; r < 6; ++r) {
          const double sr = S(r, a);
          if (sr == 0.0) continue;
          double* ar = Ad + r * nv;
          for (int c = 0; c < w; ++c) ar[c] += sr * row[c];
        }
      }
      any = true;
    }
  }
  for (int i = 1; i < nb; ++i) {
    const JointModel& j = m_->joints[i];
    for (int a = 0; a < j.nv; ++a) {
      const int r = j.idx_v + a;
      for (int c = 0; c < col_begin_[i]; ++c) Minv_(r, c) = Minv_(c, r);
    }
  }
}

// M^-1 of a branched tree's M by Featherstone's LTDL factorization (RBDA, section 6.5):
// M = L^T D L, eliminated from the leaves up along the parent columns lambda, so that L keeps the
// branch sparsity of M (L(k, i) only for i an ancestor of k). W = L^-1 is unit lower with the same
// pattern (column k on k's subtree, inside the range [k, col_sub_end_[k]) and zero on the range's
// other columns, which belong to other branches: their ancestors from k on are not k's), and
// M^-1 = W D^-1 W^T = sum over k of w_k w_k^T / D(k): one rank-one update on each column's
// subtree block, O(sum of the squared subtree widths) against a chain's n^3 / 3.
void TreeDerivatives::tree_inverse() {
  const int n = m_->nv;
  double* H = chol_.data();          // column-major: M(k, i) then L(k, i) at H[k + i n], i <= k
  double* W = chol_inv_.data();      // W(a, k) at W[a + k n], a in k's subtree
  double* D = scratch_row_.data();
  for (int k = 0; k < n; ++k)
    for (int i = k; i >= 0; i = lambda_[i]) H[k + i * n] = M(k, i);
  for (int k = n - 1; k >= 0; --k) {
    const double d = H[k + k * n];
    if (!(d > 0)) throw std::runtime_error("the mass matrix is not positive definite at this configuration");
    D[k] = d;
    for (int i = lambda_[k]; i >= 0; i = lambda_[i]) {
      const double a = H[k + i * n] / d;
      for (int j = i; j >= 0; j = lambda_[j]) H[i + j * n] -= a * H[k + j * n];
      H[k + i * n] = a;
    }
  }
  // L W = 1, column by column: W(a, k) = -sum over ancestors j of a from k on of L(a, j) W(j, k)
  for (int k = 0; k < n; ++k) {
    double* w = W + k * n;
    w[k] = 1.0;
    for (int a = k + 1; a < col_sub_end_[k]; ++a) {
      double s = 0.0;
      for (int j = lambda_[a]; j >= k; j = lambda_[j]) s -= H[a + j * n] * w[j];
      w[a] = s;
    }
  }
  Minv_.setZero();
  for (int k = 0; k < n; ++k) {
    const int e = col_sub_end_[k];
    const double* w = W + k * n;
    const double inv = 1.0 / D[k];
    for (int b = k; b < e; ++b) {
      const double f = w[b] * inv;
      double* row = Minv_.row(b).data();
      for (int a = k; a < e; ++a) row[a] += f * w[a];
    }
  }
}

// M^-1 of a small model's M (nv < kDenseInverseBelow) from its root-free Cholesky factors,
// M = L D L^T (L unit lower), M^-1 = L^-T D^-1 L^-1, in plain loops: at these sizes Eigen's
// blocked solvers cost more in setup than the arithmetic, and the articulated bodies' passes
// more than both. No square root: a one-coordinate model's M^-1 is 1 / M exactly.
void TreeDerivatives::small_inverse() {
  const int n = m_->nv;
  double* L = chol_.data();  // column-major: L(i, j) at L[i + j n], i > j; 1 / D(j) at L[j + j n]
  double* W = chol_inv_.data();
  double* t = scratch_row_.data();  // L(j, k) D(k), k < j
  for (int j = 0; j < n; ++j) {
    double d = M(j, j);
    for (int k = 0; k < j; ++k) {
      t[k] = L[j + k * n] * W[k + k * n];  // (W's diagonal, 1 and not stored, holds D)
      d -= L[j + k * n] * t[k];
    }
    if (!(d > 0)) throw std::runtime_error("the mass matrix is not positive definite at this configuration");
    const double inv = 1.0 / d;
    L[j + j * n] = inv;
    W[j + j * n] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = M(i, j);
      for (int k = 0; k < j; ++k) s -= L[i + k * n] * t[k];
      L[i + j * n] = s * inv;
    }
  }
  // W = L^-1 (unit lower, its diagonal not stored): column j by forward substitution on e_j
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i < n; ++i) {
      double s = -L[i + j * n];
      for (int k = j + 1; k < i; ++k) s -= L[i + k * n] * W[k + j * n];
      W[i + j * n] = s;
    }
  // M^-1 (a, b) = sum over k >= max(a, b) of W(k, a) W(k, b) / D(k), W(k, k) = 1
  for (int a = 0; a < n; ++a)
    for (int b = 0; b <= a; ++b) {
      const double wb = a == b ? 1.0 : W[a + b * n];
      double s = wb * L[a + a * n];
      for (int k = a + 1; k < n; ++k) s += W[k + a * n] * W[k + b * n] * L[k + k * n];
      Minv_(a, b) = s;
      Minv_(b, a) = s;
    }
}

// x = M^-1 f by the same articulated bodies (after inverse_mass_matrix): as accurate as the
// forward dynamics' own recursion, where the product M^-1 f loses digits to the cancellation in f
// (the derivatives of x, taken at x, would lose them again: 1e-10 against 1e-12 on a 60-link chain)
void TreeDerivatives::articulated_solve(const Eigen::VectorXd& f, Eigen::VectorXd& x) {
  const int nb = m_->nbodies;
  for (int i = 1; i < nb; ++i) pa_[i].setZero();
  Vec6 t, w;
  for (int i = nb - 1; i > 0; --i) {
    const JointModel& j = m_->joints[i];
    Vec6& pa = pa_[i];
    for (int u = unit_end_[i] - 1; u >= unit_begin_[i]; --u) {
      const Unit& un = units_[u];
      const int k = un.n;
      for (int a = 0; a < k; ++a) t[a] = f[un.iv + a] - S_[i].col(un.iv - j.idx_v + a).dot(pa);  // u
      for (int a = 0; a < k; ++a) {
        x[un.iv + a] = t[a];
        w[a] = Dinv_[u].row(a).head(k).dot(t.head(k));
      }
      for (int a = 0; a < k; ++a) pa.noalias() += w[a] * Uu_[u].col(a);
    }
    if (j.parent > 0) pa_[j.parent] += pa;
  }
  for (int i = 1; i < nb; ++i) {
    const JointModel& j = m_->joints[i];
    Vec6 acc = j.parent > 0 ? av_[j.parent] : Vec6::Zero();
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      const int k = un.n;
      for (int a = 0; a < k; ++a) t[a] = x[un.iv + a] - Uu_[u].col(a).dot(acc);
      for (int a = 0; a < k; ++a) x[un.iv + a] = Dinv_[u].row(a).head(k).dot(t.head(k));
      for (int a = 0; a < k; ++a) acc.noalias() += x[un.iv + a] * S_[i].col(un.iv - j.idx_v + a);
    }
    av_[i] = acc;
  }
}

// X_ := M^-1 X_ (nv x m, row-major: each coordinate's row over the m right-hand sides), by the
// articulated bodies of inverse_mass_matrix: backward, rows = D^-1 (rows - S^T F) and F += U rows;
// forward, rows -= D^-1 U^T A and A += S rows. 24 multiply-adds per coordinate and column, each a
// pass over contiguous rows. An only child takes its parent's blocks over (a chain copies nothing).
void TreeDerivatives::articulated_solve_rows() {
  const int nb = m_->nbodies, mc = static_cast<int>(X_.cols());
  for (int i = 1; i < nb; ++i)
    if (children_[i] != 1) Fr_[i].setZero();
  for (int i = nb - 1; i > 0; --i) {
    const JointModel& j = m_->joints[i];
    double* F = Fr_[i].data();
    for (int u = unit_end_[i] - 1; u >= unit_begin_[i]; --u) {
      const Unit& un = units_[u];
      const int k = un.n;
      const auto S = S_[i].middleCols(un.iv - j.idx_v, k);
      for (int a = 0; a < k; ++a) {
        double* w = X_.row(un.iv + a).data();
        const double s0 = S(0, a), s1 = S(1, a), s2 = S(2, a), s3 = S(3, a), s4 = S(4, a), s5 = S(5, a);
        for (int c = 0; c < mc; ++c)
          w[c] -= s0 * F[c] + s1 * F[mc + c] + s2 * F[2 * mc + c] + s3 * F[3 * mc + c] + s4 * F[4 * mc + c] +
                  s5 * F[5 * mc + c];
      }
      const Mat6& Dinv = Dinv_[u];
      if (k == 1) {
        X_.row(un.iv) *= Dinv(0, 0);
      } else {
        auto rows = X_.middleRows(un.iv, k);
        scratch_rows_.topLeftCorner(k, mc) = rows;
        rows = Dinv.topLeftCorner(k, k).lazyProduct(scratch_rows_.topLeftCorner(k, mc));
      }
      const Mat6& U = Uu_[u];
      for (int r = 0; r < 6; ++r) {
        double* fr = F + r * mc;
        for (int a = 0; a < k; ++a) {
          const double ur = U(r, a);
          const double* b = X_.row(un.iv + a).data();
          for (int c = 0; c < mc; ++c) fr[c] += ur * b[c];
        }
      }
    }
    const int p = j.parent;
    if (p > 0) {
      if (children_[p] == 1) Fr_[p].swap(Fr_[i]);
      else Fr_[p] += Fr_[i];
    }
  }
  for (int i = 1; i < nb; ++i) {
    const JointModel& j = m_->joints[i];
    const int p = j.parent;
    Rows6& A = Ar_[i];
    if (p > 0 && children_[p] == 1) A.swap(Ar_[p]);
    else if (p > 0) A = Ar_[p];
    double* Ad = A.data();
    bool any = p > 0;
    for (int u = unit_begin_[i]; u < unit_end_[i]; ++u) {
      const Unit& un = units_[u];
      const int k = un.n;
      const auto S = S_[i].middleCols(un.iv - j.idx_v, k);
      if (any) {  // rows -= D^-1 U^T A
        Mat6 G;
        G.topRows(k) = Dinv_[u].topLeftCorner(k, k).lazyProduct(Uu_[u].leftCols(k).transpose());
        for (int a = 0; a < k; ++a) {
          double* row = X_.row(un.iv + a).data();
          const double g0 = G(a, 0), g1 = G(a, 1), g2 = G(a, 2), g3 = G(a, 3), g4 = G(a, 4), g5 = G(a, 5);
          for (int c = 0; c < mc; ++c)
            row[c] -= g0 * Ad[c] + g1 * Ad[mc + c] + g2 * Ad[2 * mc + c] + g3 * Ad[3 * mc + c] + g4 * Ad[4 * mc + c] +
                      g5 * Ad[5 * mc + c];
        }
        for (int r = 0; r < 6; ++r) {  // A += S rows
          double* ar = Ad + r * mc;
          for (int a = 0; a < k; ++a) {
            const double sr = S(r, a);
            const double* row = X_.row(un.iv + a).data();
            for (int c = 0; c < mc; ++c) ar[c] += sr * row[c];
          }
        }
      } else {  // A = S rows (the first unit from the ground)
        for (int r = 0; r < 6; ++r) {
          double* ar = Ad + r * mc;
          for (int c = 0; c < mc; ++c) ar[c] = 0.0;
          for (int a = 0; a < k; ++a) {
            const double sr = S(r, a);
            const double* row = X_.row(un.iv + a).data();
            for (int c = 0; c < mc; ++c) ar[c] += sr * row[c];
          }
        }
      }
      any = true;
    }
    if (!any) A.setZero();  // a body welded to the ground
  }
}

void TreeDerivatives::differentiate_rnea() {
  const int nb = m_->nbodies;
  dtau_dq.setZero();  // units in other branches do not depend on each other
  dtau_dv.setZero();
  for (int i = 1; i < nb; ++i) {
    if (unit_begin_[i] == unit_end_[i]) continue;
    const JointModel& ji = m_->joints[i];
    for (int k = unit_begin_[i]; k < unit_end_[i]; ++k) {
      const Unit& uk = units_[k];
      const Vec6& Vp = Vpar_[k];
      const Vec6& Ap = Apar_[k];
      const Vec6 Vsum = Vp + Vu_[k];
      for (int c = 0; c < uk.n; ++c) {
        const int col = uk.iv + c;
        const Vec6 s = S_[i].col(uk.iv - ji.idx_v + c);
        const Vec6 u = crm(s, Vp);
        const Vec6 dw = crm(u, Vp) - crm(s, Ap);
        const Vec6 cv = -crm(s, Vsum);
        // dtau_dq = P dw - R u, dtau_dv = P cv + R s: one dot product with [P, R] each
        Eigen::Matrix<double, 12, 1> xq, xv;
        xq << dw, -u;
        xv << cv, s;
        // units at or below k
        for (int sb = sub_begin_[i]; sb < sub_begin_[i + 1]; ++sb) {
          const int b = sub_bodies_[sb];
          for (int j = (b == i ? k : unit_begin_[b]); j < unit_end_[b]; ++j) {
            const Unit& uj = units_[j];
            if (uj.n == 1) {  // one column: fixed-size dot products
              dtau_dq(uj.iv, col) = PR_[j].row(0).dot(xq);
              dtau_dv(uj.iv, col) = PR_[j].row(0).dot(xv);
              continue;
            }
            if (uj.n == 3) {  // a ball joint: fixed-size 3 x 6 products
              dtau_dq.block<3, 1>(uj.iv, col).noalias() = PR_[j].topRows<3>() * xq;
              dtau_dv.block<3, 1>(uj.iv, col).noalias() = PR_[j].topRows<3>() * xv;
              continue;
            }
            dtau_dq.block(uj.iv, col, uj.n, 1).noalias() = PR_[j].topRows(uj.n) * xq;
            dtau_dv.block(uj.iv, col, uj.n, 1).noalias() = PR_[j].topRows(uj.n) * xv;
          }
        }
        // units above k: the whole subtree's force change
        // (Bc + H(hc)) x = Bc x + x x* hc
        const Vec6 G = crf(s, F_[i]) + Ic_[i].apply(dw) - (apply_rate(Bc_[i], u) + crf(u, hc_[i]));
        const Vec6 Gv = apply_rate(Bc_[i], s) + crf(s, hc_[i]) + Ic_[i].apply(cv);
        auto above = [&](int j) {
          const Unit& uj = units_[j];
          const auto Sj = S_[uj.body].middleCols(uj.iv - m_->joints[uj.body].idx_v, uj.n);
          if (uj.n == 1) {
            const Vec6 sj = Sj.col(0);
            dtau_dq(uj.iv, col) = sj.dot(G);
            dtau_dv(uj.iv, col) = sj.dot(Gv);
            return;
          }
          if (uj.n == 3) {
            const Eigen::Matrix<double, 6, 3> sj = Sj;
            dtau_dq.block<3, 1>(uj.iv, col).noalias() = sj.transpose() * G;
            dtau_dv.block<3, 1>(uj.iv, col).noalias() = sj.transpose() * Gv;
            return;
          }
          dtau_dq.block(uj.iv, col, uj.n, 1).noalias() = Sj.transpose() * G;
          dtau_dv.block(uj.iv, col, uj.n, 1).noalias() = Sj.transpose() * Gv;
        };
        for (int j = unit_begin_[i]; j < k; ++j) above(j);
        for (int j : path_[m_->parent[i]]) above(j);
      }
    }
  }
}

void TreeDerivatives::rnea_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
  world_kinematics(q, v);
  accelerations(a);
  composites();
  forces();
  add_armature_force(*m_, a, tau);
  differentiate_rnea();
}

// chain rule for one world wrench w on `body` whose local derivatives dw are
// taken with respect to the poses/velocities of body_a (columns 0..11) and body_b (12..23)
void TreeDerivatives::add_body_wrench(int body, const Vec6& w, const Eigen::Matrix<double, 6, 24>& dw, int body_a,
                                      int body_b) {
  if (body == 0) return;  // the ground reacts; it does not move
  const std::vector<int>& path = path_[body];
  auto S_of = [&](int u) {
    const Unit& un = units_[u];
    return S_[un.body].middleCols(un.iv - m_->joints[un.body].idx_v, un.n);
  };
  for (int pj : path) {
    const Unit& uj = units_[pj];
    Q.segment(uj.iv, uj.n).noalias() += S_of(pj).transpose() * w;
  }
  // the wrench's own joint columns turn with the coordinates above them
  for (std::size_t pi = 0; pi < path.size(); ++pi) {
    const Unit& up = units_[path[pi]];
    const auto Sp = S_of(path[pi]);
    for (int c = 0; c < up.n; ++c) {
      const Vec6 g = -crf(Vec6(Sp.col(c)), w);
      for (std::size_t pj = pi; pj < path.size(); ++pj) {
        const Unit& uj = units_[path[pj]];
        dQ_dq.block(uj.iv, up.iv + c, uj.n, 1).noalias() += S_of(path[pj]).transpose() * g;
      }
    }
  }
  // the wrench's dependence on the poses and velocities of the bodies it reads
  for (int slot = 0; slot < 2; ++slot) {
    const int beta = slot == 0 ? body_a : body_b;
    if (beta <= 0) continue;
    const auto Dpose = dw.middleCols<6>(12 * slot);
    const auto Dvel = dw.middleCols<6>(12 * slot + 6);
    if (Dpose.isZero(0) && Dvel.isZero(0)) continue;
    for (int pu : path_[beta]) {
      const Unit& up = units_[pu];
      const auto Sp = S_of(pu);
      const Vec6 rel = V_[beta] - Vpar_[pu];
      for (int c = 0; c < up.n; ++c) {
        const Vec6 s = Sp.col(c);
        const Vec6 gq = Dpose * s + Dvel * crm(s, rel);
        const Vec6 gv = Dvel * s;
        for (int pj : path) {
          const Unit& uj = units_[pj];
          const auto Sj = S_of(pj);
          dQ_dq.block(uj.iv, up.iv + c, uj.n, 1).noalias() += Sj.transpose() * gq;
          dQ_dv.block(uj.iv, up.iv + c, uj.n, 1).noalias() += Sj.transpose() * gv;
        }
      }
    }
  }
}

void TreeDerivatives::applied_force_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                const Eigen::VectorXd& u) {
  // the same forces as applied_forces(), with their derivatives
  Q.setZero();
  dQ_dq.setZero();
  dQ_dv.setZero();
  dQ_du.setZero();
  for (const JointSpringModel& s : m_->joint_springs) {
    Q[s.iv] -= s.stiffness * (q[s.iq] - s.rest_position) + s.damping * v[s.iv];
    dQ_dq(s.iv, s.iv) -= s.stiffness;
    dQ_dv(s.iv, s.iv) -= s.damping;
  }
  for (const JointSpringModel& s : m_->joint_frictions) {
    Q[s.iv] -= s.damping * v[s.iv];
    dQ_dv(s.iv, s.iv) -= s.damping;
  }

  Vec6 w;
  Eigen::Matrix<double, 6, 24> dw;
  const Vec3A zero3 = Vec3A::Constant(AD(0.0));
  // spring-dampers in closed form: with dp = x_b - x_a, L = |dp|, n = dp / L,
  // Ld = n . (xd_b - xd_a), tension T = k (L - L0) + c Ld, F = T n on x_a and -F on x_b:
  //   dn = (I - n n^T) / L d(dp),  dT = k n . d(dp) + c (vrel . dn + n . d(vrel)),  dF = n dT + T dn
  using Mat3x24 = Eigen::Matrix<double, 3, 24>;
  for (const SpringDamperModel& s : m_->springs) {
    const LocalKin a = local_kin(d_.oMi[s.body_a], V_[s.body_a], Vec6::Zero(), s.point_a, false, s.body_a > 0);
    const LocalKin b = local_kin(d_.oMi[s.body_b], V_[s.body_b], Vec6::Zero(), s.point_b, false, s.body_b > 0);
    const Vec3 dp = b.x - a.x, vrel = b.xd - a.xd;
    const double L = dp.norm();
    const bool coincident = !(L > 1e-12);
    // as applied_forces: at coincident points only a rest length 0 spring acts, with F = k dp
    if (coincident && !(s.rest_length == 0.0 && s.stiffness != 0.0)) continue;
    Mat3x24 Dxa = Mat3x24::Zero(), Dxb = Mat3x24::Zero(), Dvrel;
    Dxa.leftCols<12>() = a.Dx.leftCols<12>();
    Dxb.rightCols<12>() = b.Dx.leftCols<12>();
    Dvrel.leftCols<12>() = -a.Dxd.leftCols<12>();
    Dvrel.rightCols<12>() = b.Dxd.leftCols<12>();
    const Mat3x24 Ddp = Dxb - Dxa;
    Vec3 F;
    Mat3x24 DF;
    if (coincident) {
      F = s.stiffness * dp;
      DF = s.stiffness * Ddp;
    } else {
      const Vec3 n = dp / L;
      const Mat3x24 Dn = (Mat3::Identity() - n * n.transpose()) / L * Ddp;
      const double Ld = n.dot(vrel);
      const double T = s.stiffness * (L - s.rest_length) + s.damping * Ld;
      const Eigen::Matrix<double, 1, 24> DT =
          s.stiffness * n.transpose() * Ddp + s.damping * (vrel.transpose() * Dn + n.transpose() * Dvrel);
      F = T * n;
      DF = n * DT + T * Dn;
    }
    const Mat3 Fx = skew<double>(F);
    w << a.x.cross(F), F;
    dw.topRows<3>().noalias() = skew<double>(a.x) * DF - Fx * Dxa;
    dw.bottomRows<3>() = DF;
    add_body_wrench(s.body_a, w, dw, s.body_a, s.body_b);
    w << -b.x.cross(F), -F;
    dw.topRows<3>().noalias() = Fx * Dxb - skew<double>(b.x) * DF;
    dw.bottomRows<3>() = -DF;
    add_body_wrench(s.body_b, w, dw, s.body_a, s.body_b);
  }
  // bushings: the wrench of core/dynamics/effects.cpp as a function of both bodies' local variables
  for (const BushingModel& bm : m_->bushings) {
    const BodyAD a = body_ad(d_.oMi[bm.body_a], V_[bm.body_a], 0, bm.body_a > 0);
    const BodyAD b = body_ad(d_.oMi[bm.body_b], V_[bm.body_b], 12, bm.body_b > 0);
    const Mat3A RA = a.R * bm.X_a.R.cast<AD>(), RB = b.R * bm.X_b.R.cast<AD>();
    const Vec3A xA = a.point(bm.X_a.p), xB = b.point(bm.X_b.p);
    const Mat3A Rrel = RA.transpose() * RB;
    const Vec3A dist = RA.transpose() * (xB - xA);
    const Vec3A vel = RA.transpose() * (b.point_velocity(xB) - a.point_velocity(xB));
    const Vec3A wrel = RA.transpose() * (b.w - a.w);
    Vec3A F, T;
    for (int k = 0; k < 3; ++k) {
      const AD theta = rotation_about_axis<AD>(Rrel, Eigen::Vector3d::Unit(k));
      F[k] = -(bm.kt[k] * dist[k] + bm.ct[k] * vel[k]);
      T[k] = -(bm.kr[k] * theta + bm.cr[k] * wrel[k]);
    }
    wrench_value(xB, Vec3A(RA * F), Vec3A(RA * T), w, dw);
    add_body_wrench(bm.body_b, w, dw, bm.body_a, bm.body_b);
    w = -w;
    dw = -dw;
    add_body_wrench(bm.body_a, w, dw, bm.body_a, bm.body_b);
  }
  // tires: the contact, slips and law of dynamics/tire_effect.hpp on the wheel's (slot 0) and the
  // road body's (slot 12) local variables
  for (const TireModel& t : m_->tires) {
    const BodyAD a = body_ad(d_.oMi[t.body], V_[t.body], 0, t.body > 0);
    const BodyAD r = body_ad(d_.oMi[t.road_body], V_[t.road_body], 12, t.road_body > 0);
    TireContact<AD> c;
    if (!tire_contact<AD>(t, a.R, a.p, a.w, a.point_velocity(a.p), r.R, r.p, r.w, r.point_velocity(r.p), c)) continue;
    wrench_value(c.point, c.force, c.moment, w, dw);
    add_body_wrench(t.body, w, dw, t.body, t.road_body);
    if (t.road_body > 0) {
      w = -w;
      dw = -dw;
      add_body_wrench(t.road_body, w, dw, t.body, t.road_body);
    }
  }
  for (const BodyForceModel& f : m_->body_forces) {
    const BodyAD a = body_ad(d_.oMi[f.body], V_[f.body], 0, f.body > 0);
    Vec3A F = f.force.cast<AD>(), T = f.torque.cast<AD>();
    if (!f.in_world) {
      F = a.R * f.force.cast<AD>();
      T = a.R * f.torque.cast<AD>();
    }
    wrench_value(a.point(f.point), F, T, w, dw);
    add_body_wrench(f.body, w, dw, f.body, 0);
  }
  // a wrench per unit input of actuator k on `body` into dQ/du: its own column, and the columns of
  // the mixes that drive it, weighted
  auto input_wrench = [&](int body, const Vec6& wu, int k) {
    if (body <= 0) return;
    for (int pu : path_[body]) {
      const Unit& up = units_[pu];
      const auto Sp = S_[up.body].middleCols(up.iv - m_->joints[up.body].idx_v, up.n);
      dQ_du.block(up.iv, k, up.n, 1).noalias() += Sp.transpose() * wu;
      for (const auto& [mix, weight] : m_->actuators[k].driven_by)
        dQ_du.block(up.iv, mix, up.n, 1).noalias() += weight * (Sp.transpose() * wu);
    }
  };
  for (int k = 0; k < m_->nu(); ++k) {
    const ActuatorModel& act = m_->actuators[k];
    if (act.type == ActuatorType::Mix || act.type == ActuatorType::Motion) continue;  // no force of its own
    double uk_in = u[k];  // the input with the mixes' shares
    for (const auto& [mix, weight] : act.driven_by) uk_in += weight * u[mix];
    if (act.type == ActuatorType::JointForce) {
      Q[act.iv] += act.gain * uk_in;
      dQ_du(act.iv, k) += act.gain;
      for (const auto& [mix, weight] : act.driven_by) dQ_du(act.iv, mix) += act.gain * weight;
      continue;
    }
    if (act.type == ActuatorType::LineForce) {
      // as a spring-damper whose tension is T = -gain u (pushing apart): F = T n on x_a, -F on x_b,
      // dF = T dn with dn = (I - n n^T) / L d(dp); per unit input, F_u = -gain n
      const LocalKin a = local_kin(d_.oMi[act.body], V_[act.body], Vec6::Zero(), act.point, false, act.body > 0);
      const LocalKin b = local_kin(d_.oMi[act.body_b], V_[act.body_b], Vec6::Zero(), act.point_b, false, act.body_b > 0);
      const Vec3 dp = b.x - a.x;
      const double L = dp.norm();
      if (!(L > 1e-12)) continue;
      const Vec3 n = dp / L;
      const Vec3 Fu = -act.gain * n;
      Vec6 wu;
      wu << a.x.cross(Fu), Fu;
      input_wrench(act.body, wu, k);
      wu << -b.x.cross(Fu), -Fu;
      input_wrench(act.body_b, wu, k);
      if (uk_in == 0.0) continue;
      Mat3x24 Dxa = Mat3x24::Zero(), Dxb = Mat3x24::Zero();
      Dxa.leftCols<12>() = a.Dx.leftCols<12>();
      Dxb.rightCols<12>() = b.Dx.leftCols<12>();
      const Mat3x24 Dn = (Mat3::Identity() - n * n.transpose()) / L * (Dxb - Dxa);
      const double T = -act.gain * uk_in;
      const Vec3 F = T * n;
      const Mat3x24 DF = T * Dn;
      const Mat3 Fx = skew<double>(F);
      w << a.x.cross(F), F;
      dw.topRows<3>().noalias() = skew<double>(a.x) * DF - Fx * Dxa;
      dw.bottomRows<3>() = DF;
      add_body_wrench(act.body, w, dw, act.body, act.body_b);
      w << -b.x.cross(F), -F;
      dw.topRows<3>().noalias() = Fx * Dxb - skew<double>(b.x) * DF;
      dw.bottomRows<3>() = -DF;
      add_body_wrench(act.body_b, w, dw, act.body, act.body_b);
      continue;
    }
    if (act.body == 0) continue;
    const BodyAD a = body_ad(d_.oMi[act.body], V_[act.body], 0, true);
    const bool torque = act.type == ActuatorType::BodyTorque;
    Vec3A F = act.direction.cast<AD>() * AD(act.gain);
    if (!act.in_world) F = a.R * F;
    const Vec3A x = a.point(act.point);
    // per unit input (linear in u); a body_torque actuator applies a couple
    wrench_value(x, torque ? zero3 : F, torque ? F : zero3, w, dw);
    input_wrench(act.body, w, k);
    if (uk_in == 0.0) continue;
    const AD uk(uk_in);
    wrench_value(x, torque ? zero3 : Vec3A(F * uk), torque ? Vec3A(F * uk) : zero3, w, dw);
    add_body_wrench(act.body, w, dw, act.body, 0);
  }
}

void TreeDerivatives::sensor_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                         const std::vector<int>& outputs) {
  const int ny = static_cast<int>(outputs.size());
  y.resize(ny);
  dy_dq.setZero(ny, m_->nv);
  dy_dv.setZero(ny, m_->nv);
  dy_da.setZero(ny, m_->nv);
  dy_du.setZero(ny, m_->nu());
  dy_dacc.setZero(ny, static_cast<Eigen::Index>(m_->motions.size()));
  bool reads_acc = false;
  for (int r = 0; r < ny; ++r) {
    const SensorModel& s = m_->sensors[outputs[r]];
    if (s.type == SensorType::Acceleration) {
      // y = e . x'' (e the frame's axis, x'' the point's acceleration; less g for the specific
      // force, which A_ carries as A_0 = -g) over [pose, V, A] of the body (slot 0) and the frame
      // (slot 1), chained at the accelerations a: the columns of a in dy_da
      reads_acc = true;
      Vec6 A0 = Vec6::Zero();
      if (m_->has_gravity) A0.tail<3>() = -m_->gravity;
      const Vec6 Ab = s.body > 0 ? Vec6(s.specific_force ? A_[s.body] : Vec6(A_[s.body] - A0))
                                 : Vec6(s.specific_force ? A0 : Vec6::Zero());
      const LocalKin xb = s.body > 0 ? local_kin(d_.oMi[s.body], V_[s.body], Ab, s.point, false, true)
                                     : local_kin(d_.oMi[0], Vec6::Zero(), Ab, s.point, false, false);
      const Vec3 unit_c = Vec3::Unit(s.component);
      const LocalKin e = s.frame > 0 ? local_kin(d_.oMi[s.frame], V_[s.frame], Vec6::Zero(), unit_c, true, true)
                                     : local_kin(d_.oMi[0], Vec6::Zero(), Vec6::Zero(), unit_c, true, false);
      Grad36 g = Grad36::Zero();
      add_grad(g, 0, e.x, xb.Dxdd);
      add_grad(g, 1, xb.xdd, e.Dx);
      y[r] = e.x.dot(xb.xdd);
      for (int slot = 0; slot < 2; ++slot) {
        const int beta = slot == 0 ? s.body : s.frame;
        if (beta <= 0) continue;
        const auto Cpose = g.segment<6>(18 * slot), CV = g.segment<6>(18 * slot + 6), CA = g.segment<6>(18 * slot + 12);
        for (int pu : path_[beta]) {
          const Unit& up = units_[pu];
          const auto Sp = S_[up.body].middleCols(up.iv - m_->joints[up.body].idx_v, up.n);
          const Vec6& Vp = Vpar_[pu];
          const Vec6 rel = V_[beta] - Vp;
          const Vec6 acc_rel = A_[beta] - Apar_[pu] - crm(Vp, rel);
          const Vec6 vel_after = V_[beta] - Vu_[pu] - Vp;
          for (int k = 0; k < up.n; ++k) {
            const Vec6 sc = Sp.col(k);
            const Vec6 dV = crm(sc, rel);                      // dV_beta / dq_s
            const Vec6 dA = crm(Vp, dV) + crm(sc, acc_rel);    // dA_beta / dq_s at fixed a
            const int col = up.iv + k;
            dy_dq(r, col) += Cpose.dot(sc) + CV.dot(dV) + CA.dot(dA);
            dy_dv(r, col) += CV.dot(sc) + CA.dot(crm(sc, vel_after));
            dy_da(r, col) += CA.dot(sc);
          }
        }
      }
      continue;
    }
    if (s.type == SensorType::JointPosition) {
      y[r] = q[s.iq];
      dy_dq(r, s.iv) = 1.0;
      continue;
    }
    if (s.type == SensorType::JointVelocity) {
      y[r] = v[s.iv];
      dy_dv(r, s.iv) = 1.0;
      continue;
    }
    int ba = 0, bb = 0;
    AD value;
    switch (s.type) {
      case SensorType::PointPosition:
      case SensorType::PointVelocity: {
        ba = s.body;
        bb = s.frame;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const BodyAD f = body_ad(d_.oMi[bb], V_[bb], 12, bb > 0);
        const Vec3A x = a.point(s.point);
        const Vec3A loc = s.type == SensorType::PointPosition ? Vec3A(f.R.transpose() * (x - f.p))
                                                               : Vec3A(f.R.transpose() * a.point_velocity(x));
        value = loc[s.component];
        break;
      }
      case SensorType::BodyAngle: {
        ba = s.body;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const Mat3A Rrel = a.R * s.R0.transpose().cast<AD>();
        value = rotation_about_axis<AD>(Rrel, s.axis);
        break;
      }
      case SensorType::Distance: {
        ba = s.body_a;
        bb = s.body_b;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const BodyAD b = body_ad(d_.oMi[bb], V_[bb], 12, bb > 0);
        value = sqrt((b.point(s.point_b) - a.point(s.point_a)).squaredNorm());
        break;
      }
      case SensorType::DistanceRate: {
        ba = s.body_a;
        bb = s.body_b;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const BodyAD b = body_ad(d_.oMi[bb], V_[bb], 12, bb > 0);
        const Vec3A xa = a.point(s.point_a), xb = b.point(s.point_b);
        const Vec3A dp = xb - xa, dv = b.point_velocity(xb) - a.point_velocity(xa);
        const AD L = sqrt(dp.squaredNorm());
        value = L.value() > 1e-12 ? AD(dp.dot(dv) / L) : AD(0.0);
        break;
      }
      case SensorType::AngularVelocity: {
        ba = s.body;
        bb = s.frame;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const BodyAD f = body_ad(d_.oMi[bb], V_[bb], 12, bb > 0);
        value = Vec3A(f.R.transpose() * a.w)[s.component];
        break;
      }
      case SensorType::Tire: {
        // the contact of dynamics/tire_effect.hpp on the wheel's (slot 0) and the road's (slot 12) variables
        const TireModel& t = m_->tires[static_cast<std::size_t>(s.tire)];
        ba = t.body;
        bb = t.road_body;
        const BodyAD a = body_ad(d_.oMi[ba], V_[ba], 0, ba > 0);
        const BodyAD rb = body_ad(d_.oMi[bb], V_[bb], 12, bb > 0);
        TireContact<AD> c;
        value = AD(0.0);
        if (tire_contact<AD>(t, a.R, a.p, a.w, a.point_velocity(a.p), rb.R, rb.p, rb.w, rb.point_velocity(rb.p), c)) {
          switch (s.quantity) {
            case TireQuantity::SlipAngle: value = c.input.alpha; break;
            case TireQuantity::LongitudinalSlip: value = c.input.kappa; break;
            case TireQuantity::Camber: value = c.input.gamma; break;
            case TireQuantity::Fx: value = c.out.Fx; break;
            case TireQuantity::Fy: value = c.out.Fy; break;
            case TireQuantity::Fz: value = c.input.Fz; break;
            case TireQuantity::Mz: value = c.out.Mz; break;
          }
        }
        break;
      }
      default:
        throw std::logic_error("TreeDerivatives: unknown sensor type");
    }
    y[r] = value.value();
    const Der24& g = value.derivatives();
    for (int slot = 0; slot < 2; ++slot) {
      const int beta = slot == 0 ? ba : bb;
      if (beta <= 0) continue;
      const Eigen::Matrix<double, 6, 1> Dpose = g.segment<6>(12 * slot), Dvel = g.segment<6>(12 * slot + 6);
      for (int pu : path_[beta]) {
        const Unit& up = units_[pu];
        const auto Sp = S_[up.body].middleCols(up.iv - m_->joints[up.body].idx_v, up.n);
        const Vec6 rel = V_[beta] - Vpar_[pu];
        for (int c = 0; c < up.n; ++c) {
          const Vec6 sc = Sp.col(c);
          dy_dq(r, up.iv + c) += Dpose.dot(sc) + Dvel.dot(crm(sc, rel));
          dy_dv(r, up.iv + c) += Dvel.dot(sc);
        }
      }
    }
  }
  if (!reads_acc) return;
  // the accelerations' own dependence: y(q, v, a(q, v, u)), a the dynamics' accelerations
  dy_dq.noalias() += dy_da * dqdd_dq;
  dy_dv.noalias() += dy_da * dqdd_dv;
  dy_du.noalias() = dy_da * dqdd_du;
  if (dqdd_dacc.rows() == m_->nv && dqdd_dacc.cols() == dy_dacc.cols()) dy_dacc.noalias() = dy_da * dqdd_dacc;
  if (feedthrough_read) return;
  // A caller that does not read dy_du and dy_dacc takes D from dy_dq and dy_dv alone: right for a
  // motion input's value and rate (coordinates of q and v), wrong for a force input's or a motion's
  // acceleration column. Refused where such a column is not zero rather than left out.
  for (int r = 0; r < ny; ++r) {
    const SensorModel& s = m_->sensors[outputs[r]];
    if (s.type != SensorType::Acceleration) continue;
    for (int k : m_->plant_inputs) {
      const ActuatorModel& act = m_->actuators[static_cast<std::size_t>(k)];
      double lost = 0;
      if (act.type != ActuatorType::Motion) lost = dy_du(r, k);
      else
        for (std::size_t j = 0; j < m_->motions.size(); ++j)
          if (m_->motions[j] == k && static_cast<Eigen::Index>(j) < dy_dacc.cols()) lost = dy_dacc(r, static_cast<Eigen::Index>(j));
      if (lost != 0.0)
        throw std::runtime_error("the exact Jacobian: the acceleration sensor \"" + s.name + "\" reads the input \"" +
                                 act.name + "\" directly (D = " + std::to_string(lost) +
                                 "), which the exact linearization does not take yet; linearize with --method fd-central");
    }
  }
}

void TreeDerivatives::compute(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                              const std::vector<int>& outputs) {
  const int nv = m_->nv, nu = m_->nu();
  // bias forces at qdd = 0, applied forces, mass matrix
  world_kinematics(q, v);
  accelerations(qdd_zero_);
  composites();
  forces();
  scratch_ = tau;
  applied_force_derivatives(q, v, u_all);
  scratch_ = Q - scratch_;
  if (nv < kDenseInverseBelow || tree_inverse_) {
    mass_matrix();
    if (tree_inverse_) tree_inverse();
    else small_inverse();
    qdd.noalias() = Minv_ * scratch_;
  } else {
    inverse_mass_matrix();
    articulated_solve(scratch_, qdd);
  }
  // inverse dynamics at the true accelerations, and its derivatives
  accelerations(qdd);
  forces();
  add_armature_force(*m_, qdd, tau);
  differentiate_rnea();
  // M^-1 (inverse_mass_matrix above), then products: a joint-force input's column is a column of M^-1
  if (nv >= kRowsSolveFrom) {
    // M^-1 [dQ_dq - dtau_dq, dQ_dv - dtau_dv] by the articulated bodies, all 2 nv columns at once:
    // about 48 nv^2 multiply-adds against the products' 2 nv^3
    X_.leftCols(nv) = dQ_dq - dtau_dq;
    X_.rightCols(nv) = dQ_dv - dtau_dv;
    articulated_solve_rows();
    dqdd_dq = X_.leftCols(nv);
    dqdd_dv = X_.rightCols(nv);
  } else {
    rhs_.leftCols(nv) = dQ_dq - dtau_dq;
    rhs_.middleCols(nv, nv) = dQ_dv - dtau_dv;
    dqdd_dq.noalias() = Minv_ * rhs_.leftCols(nv);
    dqdd_dv.noalias() = Minv_ * rhs_.middleCols(nv, nv);
  }
  for (int k = 0; k < nu; ++k) {
    const ActuatorModel& act = m_->actuators[k];
    if (act.type == ActuatorType::JointForce) dqdd_du.col(k) = act.gain * Minv_.col(act.iv);
    else dqdd_du.col(k).noalias() = Minv_ * dQ_du.col(k);
  }
  sensor_derivatives(q, v, outputs);
}

void TreeDerivatives::chain_constraint_row(int row, const Grad36& gc, const Grad36& gp, int body_a, int body_b) {
  for (int slot = 0; slot < 2; ++slot) {
    const int beta = slot == 0 ? body_a : body_b;
    if (beta <= 0) continue;
    const auto Cpose = gc.segment<6>(18 * slot), CV = gc.segment<6>(18 * slot + 6), CA = gc.segment<6>(18 * slot + 12);
    const auto Ppose = gp.segment<6>(18 * slot), PV = gp.segment<6>(18 * slot + 6);
    for (int pu : path_[beta]) {
      const Unit& up = units_[pu];
      const auto Sp = S_[up.body].middleCols(up.iv - m_->joints[up.body].idx_v, up.n);
      const Vec6& Vp = Vpar_[pu];
      const Vec6 rel = V_[beta] - Vp;
      const Vec6 acc_rel = A_[beta] - Apar_[pu] - crm(Vp, rel);
      const Vec6 vel_after = V_[beta] - Vu_[pu] - Vp;
      for (int k = 0; k < up.n; ++k) {
        const Vec6 s = Sp.col(k);
        const Vec6 dV = crm(s, rel);                          // dV_beta / dq_s
        const Vec6 dA = crm(Vp, dV) + crm(s, acc_rel);        // dA_beta / dq_s
        const Vec6 dAv = crm(s, vel_after);                   // dA_beta / dv_s
        const int col = up.iv + k;
        dc_dq(row, col) += Cpose.dot(s) + CV.dot(dV) + CA.dot(dA);
        dc_dv(row, col) += CV.dot(s) + CA.dot(dAv);
        Jc(row, col) += CA.dot(s);
        dphid_dq(row, col) += Ppose.dot(s) + PV.dot(dV);
      }
    }
  }
}

// the loop closures: reactions -Jc^T lambda into Q and dQ_dq, and the rows' derivatives
void TreeDerivatives::constraint_derivatives(const Eigen::VectorXd& lambda, const Eigen::VectorXd& a) {
  Jc.setZero();
  dc_dq.setZero();
  dc_dv.setZero();
  dphid_dq.setZero();
  Vec6 A0 = Vec6::Zero();  // the true accelerations: A_ carries gravity as A_0 = -g
  if (m_->has_gravity) A0.tail<3>() = -m_->gravity;
  auto kin = [&](int body, const Vec3& l, bool vector) {
    return body > 0 ? local_kin(d_.oMi[body], V_[body], Vec6(A_[body] - A0), l, vector, true)
                    : local_kin(d_.oMi[0], Vec6::Zero(), Vec6::Zero(), l, vector, false);
  };
  Grad36 gc, gp;
  auto row_out = [&](int r, double value, int ba, int bb) {
    c[r] = value;
    chain_constraint_row(r, gc, gp, ba, bb);
  };
  // a reaction wrench w on `body` with dw/d(pose) of body_a (columns 0..5) and body_b (12..17)
  Vec6 w;
  Eigen::Matrix<double, 6, 24> dw;
  // row r = sign e . (x_a - x_b), e a vector of body_a (planar_revolute's rows, sign 1; rolling's
  // height, -1): phidot = sign (ed . dp + e . dpd), c = sign (edd . dp + 2 ed . dpd + e . dpdd)
  // with their gradients, and the reaction -lambda Jc_r^T
  auto along_row = [&](int r, const LocalKin& e, const LocalKin& xa, const LocalKin& xb, double sign, int ba, int bb) {
    const Vec3 dp = sign * (xa.x - xb.x), dpd = sign * (xa.xd - xb.xd), dpdd = sign * (xa.xdd - xb.xdd);
    const Vec3 ex = sign * e.x, exd = sign * e.xd, exdd = sign * e.xdd;
    gp.setZero();
    add_grad(gp, 0, dp, e.Dxd);
    add_grad(gp, 0, dpd, e.Dx);
    add_grad(gp, 0, exd, xa.Dx);
    add_grad(gp, 0, ex, xa.Dxd);
    add_grad(gp, 1, -exd, xb.Dx);
    add_grad(gp, 1, -ex, xb.Dxd);
    gc.setZero();
    add_grad(gc, 0, dp, e.Dxdd);
    add_grad(gc, 0, 2.0 * dpd, e.Dxd);
    add_grad(gc, 0, dpdd, e.Dx);
    add_grad(gc, 0, exdd, xa.Dx);
    add_grad(gc, 0, 2.0 * exd, xa.Dxd);
    add_grad(gc, 0, ex, xa.Dxdd);
    add_grad(gc, 1, -exdd, xb.Dx);
    add_grad(gc, 1, -2.0 * exd, xb.Dxd);
    add_grad(gc, 1, -ex, xb.Dxdd);
    row_out(r, e.xdd.dot(dp) + 2.0 * e.xd.dot(dpd) + e.x.dot(dpdd), ba, bb);
    // phidot = sign (w_a . (e x dp) + e . (velocity of x_a - velocity of x_b)): with l = -sign lambda,
    // body_a: [l (x_b x e); l e],  body_b: [-l (x_b x e); -l e]
    const double l = -sign * lambda[r];
    const Eigen::Matrix<double, 3, 6> de = e.Dx.leftCols<6>();  // d e / d pose_a
    const Eigen::Matrix<double, 3, 6> dxb = xb.Dx.leftCols<6>();
    const Mat3 exs = skew<double>(e.x), xbx = skew<double>(xb.x);
    dw.setZero();
    w << l * xb.x.cross(e.x), l * e.x;
    dw.block<3, 6>(0, 0).noalias() = l * xbx * de;
    dw.block<3, 6>(0, 12).noalias() = -l * exs * dxb;
    dw.block<3, 6>(3, 0) = l * de;
    add_body_wrench(ba, w, dw, ba, bb);
    w = -w;
    dw = -dw;
    add_body_wrench(bb, w, dw, ba, bb);
  };
  // a contact row of rolling: g = e . u, e a vector of body_a, u = v_b(P) - v_a(P) =
  // (V_b - V_a).tail + Om x P (spatial velocities at the world origin, Om = w_b - w_a) at the contact
  // point P, whose gradients over both bodies' [pose, V, A] are DP (pose only) and DPd (of P');
  // c = dg/dt = e' . u + e . u', u' = (A_b - A_a).tail + La x P + Om x P' (La = al_b - al_a); the
  // reaction -lambda Jc_r^T: on b the wrench -lambda [P x e; e], on a its opposite
  using Grad3 = Eigen::Matrix<double, 3, 36>;
  auto contact_row = [&](int r, const LocalKin& e, const Vec3& P, const Vec3& Pd, const Grad3& DP, const Grad3& DPd,
                         const Vec3& u, const Vec3& ud, const Vec3& Om, const Vec3& La, int ba, int bb) {
    const Vec3 eO = e.x.cross(Om), Pe = P.cross(e.x);
    gp.setZero();
    add_grad(gp, 0, u, e.Dx);
    gp.noalias() += DP.transpose() * eO;  // e . (Om x P) = P . (e x Om)
    gp.segment<3>(18 + 6) += Pe;           // Om . (P x e) and e . v_b
    gp.segment<3>(18 + 9) += e.x;
    gp.segment<3>(6) -= Pe;
    gp.segment<3>(9) -= e.x;
    // e' . u
    gc.setZero();
    add_grad(gc, 0, u, e.Dxd);
    const Vec3 edO = e.xd.cross(Om), Ped = P.cross(e.xd);
    gc.noalias() += DP.transpose() * edO;
    gc.segment<3>(18 + 6) += Ped;
    gc.segment<3>(18 + 9) += e.xd;
    gc.segment<3>(6) -= Ped;
    gc.segment<3>(9) -= e.xd;
    // e . u': through e, the accelerations, La x P, Om x P'
    add_grad(gc, 0, ud, e.Dx);
    gc.segment<3>(18 + 12) += Pe;
    gc.segment<3>(18 + 15) += e.x;
    gc.segment<3>(12) -= Pe;
    gc.segment<3>(15) -= e.x;
    const Vec3 eL = e.x.cross(La), Pde = Pd.cross(e.x);
    gc.noalias() += DP.transpose() * eL;
    gc.segment<3>(18 + 6) += Pde;
    gc.segment<3>(6) -= Pde;
    gc.noalias() += DPd.transpose() * eO;
    row_out(r, e.xd.dot(u) + e.x.dot(ud), ba, bb);
    const double l = lambda[r];
    const Eigen::Matrix<double, 3, 6> de = e.Dx.leftCols<6>();
    const Mat3 ex = skew<double>(e.x), Px = skew<double>(P);
    dw.setZero();
    w << -l * Pe, -l * e.x;
    // d(P x e) = -[e]x dP + [P]x de
    dw.block<3, 6>(0, 0).noalias() = l * (ex * DP.leftCols<6>() - Px * de);
    dw.block<3, 6>(0, 12).noalias() = l * ex * DP.middleCols<6>(18);
    dw.block<3, 6>(3, 0) = -l * de;
    add_body_wrench(bb, w, dw, ba, bb);
    w = -w;
    dw = -dw;
    add_body_wrench(ba, w, dw, ba, bb);
  };
  auto lift = [](int slot, const Eigen::Matrix<double, 3, 18>& D) {
    Grad3 G = Grad3::Zero();
    G.middleCols<18>(18 * slot) = D;
    return G;
  };
  for (const ConstraintModel& cm : m_->constraints) {
    if (cm.type == ConstraintType::Coupler) {
      // sum_k ratio_k q_k = offset: Jc is the ratios, c = Jc a, and the reaction -Jc^T lambda acts on
      // the coordinates themselves; nothing here depends on q or v
      double value = 0;
      for (int k = 0; k < cm.ncoupled; ++k) {
        Jc(cm.row, cm.iv[k]) = cm.ratio[k];
        Q[cm.iv[k]] -= cm.ratio[k] * lambda[cm.row];
        value += cm.ratio[k] * a[cm.iv[k]];
      }
      c[cm.row] = value;
      continue;
    }
    const int ba = cm.body_a, bb = cm.body_b;
    const LocalKin xa = kin(ba, cm.point_a, false), xb = kin(bb, cm.point_b, false);
    int r = cm.row;
    switch (cm.type) {
      case ConstraintType::Ball:
      case ConstraintType::Revolute: {
        for (int k = 0; k < 3; ++k) {
          gc.setZero();
          gp.setZero();
          gc.segment<18>(0) = xa.Dxdd.row(k).transpose();
          gc.segment<18>(18) = -xb.Dxdd.row(k).transpose();
          gp.segment<18>(0) = xa.Dxd.row(k).transpose();
          gp.segment<18>(18) = -xb.Dxd.row(k).transpose();
          row_out(r + k, xa.xdd[k] - xb.xdd[k], ba, bb);
        }
        // a force f = -lambda at x_a, -f at x_b: w = [x x f; f], d(x x f) = -[f]x dx
        const Vec3 f = -lambda.segment<3>(r);
        const Mat3 fx = skew<double>(f);
        dw.setZero();
        w << xa.x.cross(f), f;
        dw.block<3, 6>(0, 0).noalias() = -fx * xa.Dx.leftCols<6>();
        add_body_wrench(ba, w, dw, ba, bb);
        dw.setZero();
        w << -xb.x.cross(f), -f;
        dw.block<3, 6>(0, 12).noalias() = fx * xb.Dx.leftCols<6>();
        add_body_wrench(bb, w, dw, ba, bb);
        if (cm.type == ConstraintType::Ball) break;
        r += 3;
        const LocalKin u = kin(ba, cm.axis_a, true);
        for (const Eigen::Vector3d* perp : {&cm.perp_b1, &cm.perp_b2}) {
          const LocalKin b = kin(bb, *perp, true);
          // phidot = ud . b + u . bd;  c = udd . b + 2 ud . bd + u . bdd
          gp.setZero();
          add_grad(gp, 0, b.x, u.Dxd);
          add_grad(gp, 0, b.xd, u.Dx);
          add_grad(gp, 1, u.xd, b.Dx);
          add_grad(gp, 1, u.x, b.Dxd);
          gc.setZero();
          add_grad(gc, 0, b.x, u.Dxdd);
          add_grad(gc, 0, 2.0 * b.xd, u.Dxd);
          add_grad(gc, 0, b.xdd, u.Dx);
          add_grad(gc, 1, u.xdd, b.Dx);
          add_grad(gc, 1, 2.0 * u.xd, b.Dxd);
          add_grad(gc, 1, u.x, b.Dxdd);
          row_out(r, u.xdd.dot(b.x) + 2.0 * u.xd.dot(b.xd) + u.x.dot(b.xdd), ba, bb);
          // a couple T = -lambda (u x b) on body_a, -T on body_b:
          // dT = -lambda (-[b]x du + [u]x db)
          const double l = -lambda[r];
          const Vec3 T = l * u.x.cross(b.x);
          const Eigen::Matrix<double, 3, 6> dTa = -l * skew<double>(b.x) * u.Dx.leftCols<6>();
          const Eigen::Matrix<double, 3, 6> dTb = l * skew<double>(u.x) * b.Dx.leftCols<6>();
          dw.setZero();
          w << T, Vec3::Zero();
          dw.block<3, 6>(0, 0) = dTa;
          dw.block<3, 6>(0, 12) = dTb;
          add_body_wrench(ba, w, dw, ba, bb);
          w << -T, Vec3::Zero();
          dw.block<3, 6>(0, 0) = -dTa;
          dw.block<3, 6>(0, 12) = -dTb;
          add_body_wrench(bb, w, dw, ba, bb);
          ++r;
        }
        break;
      }
      case ConstraintType::PlanarRevolute:
        for (const Eigen::Vector3d* perp : {&cm.perp_a1, &cm.perp_a2}) along_row(r++, kin(ba, *perp, true), xa, xb, 1.0, ba, bb);
        break;
      case ConstraintType::RollingBall: {
        const double R = cm.radius;
        const LocalKin n = kin(ba, cm.axis_a, true);
        // height: phi = n . (c - p_a) - R = -(n . (p_a - c)) - R: the planar_revolute row along n,
        // negated
        along_row(r++, n, xa, xb, -1.0, ba, bb);
        // no slip along t: the contact rows with P = c - R n (the disc's with d = n: n turns with
        // body_a alone)
        const Vec6 Va = ba > 0 ? V_[ba] : Vec6::Zero(), Vb = bb > 0 ? V_[bb] : Vec6::Zero();
        const Vec6 Aa = ba > 0 ? Vec6(A_[ba] - A0) : Vec6::Zero(), Ab = bb > 0 ? Vec6(A_[bb] - A0) : Vec6::Zero();
        const Vec3 Om = Vb.head<3>() - Va.head<3>(), La = Ab.head<3>() - Aa.head<3>();
        const Vec3 P = xb.x - R * n.x, Pd = xb.xd - R * n.xd;
        const Grad3 DP = lift(1, xb.Dx) - R * lift(0, n.Dx), DPd = lift(1, xb.Dxd) - R * lift(0, n.Dxd);
        const Vec3 u = Vb.tail<3>() - Va.tail<3>() + Om.cross(P);
        const Vec3 ud = Ab.tail<3>() - Aa.tail<3>() + La.cross(P) + Om.cross(Pd);
        for (const Eigen::Vector3d* perp : {&cm.perp_a1, &cm.perp_a2})
          contact_row(r++, kin(ba, *perp, true), P, Pd, DP, DPd, u, ud, Om, La, ba, bb);
        break;
      }
      case ConstraintType::RollingDisc: {
        // n on body_a, the axle a on body_b: k = n . a, m = n - k a, s = |m|, d = m / s, P = c - R d.
        // Chain rule over both bodies' [pose, V, A] (Dx the gradient of x):
        //   Dk = a^T Dn + n^T Da,  Dm = Dn - a Dk - k Da,  Dd = (I - d d^T) Dm / s
        //   k' = n' . a + n . a',  m' = n' - k' a - k a',  s' = d . m',  d' = (m' - d s') / s
        //   Dk' = a^T Dn' + n'^T Da + a'^T Dn + n^T Da',  Dm' = Dn' - a Dk' - k' Da - a' Dk - k Da'
        //   Ds = d^T Dm,  Ds' = m'^T Dd + d^T Dm',  Dd' = (Dm' - Dd s' - d Ds' - d' Ds) / s
        // and then the three rows e . (v_b(P) - v_a(P)), e = n (the height's rate), t1, t2
        const double R = cm.radius;
        const LocalKin n = kin(ba, cm.axis_a, true), ax = kin(bb, cm.axis_b, true);
        const double k = n.x.dot(ax.x);
        const Vec3 mv = n.x - k * ax.x;
        const double s = mv.norm();
        if (!(s >= kDiscFlat))
          throw std::domain_error("rolling_disc " + cm.name + ": the disc lies flat on the plane (|n - (n.a) a| = " +
                                  std::to_string(s) + "): its contact point is undefined there");
        const Vec3 dv = mv / s;
        const Grad3 Dn = lift(0, n.Dx), Dnd = lift(0, n.Dxd), Da = lift(1, ax.Dx), Dad = lift(1, ax.Dxd);
        const Eigen::Matrix<double, 1, 36> Dk = ax.x.transpose() * Dn + n.x.transpose() * Da;
        const Grad3 Dm = Dn - ax.x * Dk - k * Da;
        const Mat3 proj = Mat3::Identity() - dv * dv.transpose();
        const Grad3 Dd = proj * Dm / s;
        const double kd = n.xd.dot(ax.x) + n.x.dot(ax.xd);
        const Vec3 md = n.xd - kd * ax.x - k * ax.xd;
        const double sd = dv.dot(md);
        const Vec3 dvd = (md - sd * dv) / s;
        const Eigen::Matrix<double, 1, 36> Dkd =
            ax.x.transpose() * Dnd + n.xd.transpose() * Da + ax.xd.transpose() * Dn + n.x.transpose() * Dad;
        const Grad3 Dmd = Dnd - ax.x * Dkd - kd * Da - ax.xd * Dk - k * Dad;
        const Eigen::Matrix<double, 1, 36> Ds = dv.transpose() * Dm;
        const Eigen::Matrix<double, 1, 36> Dsd = md.transpose() * Dd + dv.transpose() * Dmd;
        const Grad3 Ddd = (Dmd - sd * Dd - dv * Dsd - dvd * Ds) / s;
        const Vec3 P = xb.x - R * dv, Pd = xb.xd - R * dvd;
        const Grad3 DP = lift(1, xb.Dx) - R * Dd, DPd = lift(1, xb.Dxd) - R * Ddd;
        const Vec6 Va = ba > 0 ? V_[ba] : Vec6::Zero(), Vb = bb > 0 ? V_[bb] : Vec6::Zero();
        const Vec6 Aa = ba > 0 ? Vec6(A_[ba] - A0) : Vec6::Zero(), Ab = bb > 0 ? Vec6(A_[bb] - A0) : Vec6::Zero();
        const Vec3 Om = Vb.head<3>() - Va.head<3>(), La = Ab.head<3>() - Aa.head<3>();
        const Vec3 u = Vb.tail<3>() - Va.tail<3>() + Om.cross(P);
        const Vec3 ud = Ab.tail<3>() - Aa.tail<3>() + La.cross(P) + Om.cross(Pd);
        contact_row(r++, n, P, Pd, DP, DPd, u, ud, Om, La, ba, bb);
        for (const Eigen::Vector3d* perp : {&cm.perp_a1, &cm.perp_a2})
          contact_row(r++, kin(ba, *perp, true), P, Pd, DP, DPd, u, ud, Om, La, ba, bb);
        break;
      }
      case ConstraintType::Coupler: break;  // above
    }
  }
}

void TreeDerivatives::compute_balance(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                                      const Eigen::VectorXd& a, const Eigen::VectorXd& lambda) {
  balance(q, v, u_all, a, lambda);
}

void TreeDerivatives::balance(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                              const Eigen::VectorXd& a, const Eigen::VectorXd& lambda) {
  world_kinematics(q, v);
  accelerations(a);
  composites();
  forces();
  add_armature_force(*m_, a, tau);
  differentiate_rnea();
  applied_force_derivatives(q, v, u_all);
  constraint_derivatives(lambda, a);
  mass_matrix();
  qdd = a;
}

void TreeDerivatives::compute_constrained(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                          const Eigen::VectorXd& u_all, const Eigen::VectorXd& a,
                                          const Eigen::VectorXd& lambda, const std::vector<int>& rows,
                                          const std::vector<int>& outputs) {
  const int nv = m_->nv, nu = m_->nu(), na = static_cast<int>(rows.size());
  balance(q, v, u_all, a, lambda);
  if (!m_->motions.empty()) {
    solve_prescribed(rows);
    sensor_derivatives(q, v, outputs);
    return;
  }
  llt_.compute(M);
  if (llt_.info() != Eigen::Success)
    throw std::runtime_error("the mass matrix is not positive definite at this configuration");
  // M da + Jr^T dlambda = dQ - dtau,  Jr da = -dc
  rhs_.leftCols(nv) = dQ_dq - dtau_dq;
  rhs_.middleCols(nv, nv) = dQ_dv - dtau_dv;
  rhs_.rightCols(nu) = dQ_du;
  for (Eigen::Index c0 = 0; c0 < rhs_.cols(); c0 += 48) {
    auto panel = rhs_.middleCols(c0, std::min<Eigen::Index>(48, rhs_.cols() - c0));
    llt_.solveInPlace(panel);
  }
  if (na > 0) {  // (no kept rows: the tree's derivatives; Eigen's solves must not see empty matrices)
    if (Jr_.rows() != na || Jr_.cols() != nv) Jr_.resize(na, nv);
    for (int k = 0; k < na; ++k) Jr_.row(k) = Jc.row(rows[k]);
    Y_ = Jr_.transpose();
    llt_.solveInPlace(Y_);
    if (Sc_.rows() != na) Sc_.resize(na, na);
    Sc_.noalias() = Jr_ * Y_;
    llt_schur_.compute(Sc_);
    if (llt_schur_.info() != Eigen::Success)
      throw std::runtime_error("the loop closures' Schur complement is singular at this configuration");
    if (T_.rows() != na || T_.cols() != rhs_.cols()) T_.resize(na, rhs_.cols());
    T_.noalias() = Jr_ * rhs_;
    for (int k = 0; k < na; ++k) {
      T_.row(k).head(nv) += dc_dq.row(rows[k]);
      T_.row(k).segment(nv, nv) += dc_dv.row(rows[k]);
    }
    llt_schur_.solveInPlace(T_);
    rhs_.noalias() -= Y_ * T_;
  }
  dqdd_dq = rhs_.leftCols(nv);
  dqdd_dv = rhs_.middleCols(nv, nv);
  dqdd_du = rhs_.rightCols(nu);
  sensor_derivatives(q, v, outputs);
}

// Motion inputs: the driven coordinates d hold their accelerations, so the balance is kept on the
// free coordinates f only (with the loops' kept rows r; Jr_d, the driven coordinates' columns, is
// not zero where a motion drives a loop's coordinate, a four-bar's crank):
//   M_ff da_f + Jr_f^T dlambda = (dQ - dtau)_f - M_fd da_d,   Jr_f da_f = -dc - Jr_d da_d,
// where dtau and dc are taken at the whole a (the driven accelerations included), da_d = 0 for the
// q, v and u columns and da_d = e_k for motion k's acceleration. The same Schur complement as
// the loops without motion, on M_ff, which stays positive definite with massless driven bodies.
void TreeDerivatives::solve_prescribed(const std::vector<int>& rows) {
  const int nv = m_->nv, nu = m_->nu(), na = static_cast<int>(rows.size());
  const int nm = static_cast<int>(driven_.size()), nf = static_cast<int>(free_.size());
  for (int i = 0; i < nf; ++i)
    for (int j = 0; j < nf; ++j) Mff_(i, j) = M(free_[i], free_[j]);
  if (nf > 0) {
    llt_ff_.compute(Mff_);
    if (llt_ff_.info() != Eigen::Success)
      throw std::runtime_error("the mass matrix of the coordinates no motion drives is not positive definite "
                               "at this configuration");
  }
  for (int i = 0; i < nf; ++i) {
    const int r = free_[i];
    Rf_.row(i).head(nv) = dQ_dq.row(r) - dtau_dq.row(r);
    Rf_.row(i).segment(nv, nv) = dQ_dv.row(r) - dtau_dv.row(r);
    Rf_.row(i).segment(2 * nv, nu) = dQ_du.row(r);
    for (int k = 0; k < nm; ++k) Rf_(i, 2 * nv + nu + k) = -M(r, driven_[k]);
  }
  if (nf > 0) {
    for (Eigen::Index c0 = 0; c0 < Rf_.cols(); c0 += 48) {
      auto panel = Rf_.middleCols(c0, std::min<Eigen::Index>(48, Rf_.cols() - c0));
      llt_ff_.solveInPlace(panel);
    }
    if (na > 0) {
      if (Jr_.rows() != na || Jr_.cols() != nf) Jr_.resize(na, nf);
      for (int k = 0; k < na; ++k)
        for (int i = 0; i < nf; ++i) Jr_(k, i) = Jc(rows[k], free_[i]);
      Y_ = Jr_.transpose();
      llt_ff_.solveInPlace(Y_);
      if (Sc_.rows() != na) Sc_.resize(na, na);
      Sc_.noalias() = Jr_ * Y_;
      llt_schur_.compute(Sc_);
      if (llt_schur_.info() != Eigen::Success)
        throw std::runtime_error("the loop closures' Schur complement is singular at this configuration");
      if (T_.rows() != na || T_.cols() != Rf_.cols()) T_.resize(na, Rf_.cols());
      T_.noalias() = Jr_ * Rf_;
      for (int k = 0; k < na; ++k) {
        T_.row(k).head(nv) += dc_dq.row(rows[k]);
        T_.row(k).segment(nv, nv) += dc_dv.row(rows[k]);
        for (int j = 0; j < nm; ++j) T_(k, 2 * nv + nu + j) += Jc(rows[k], driven_[j]);
      }
      llt_schur_.solveInPlace(T_);
      Rf_.noalias() -= Y_ * T_;
    }
  }
  dqdd_dq.setZero();
  dqdd_dv.setZero();
  dqdd_du.setZero();
  dqdd_dacc.setZero();
  for (int i = 0; i < nf; ++i) {
    const int r = free_[i];
    dqdd_dq.row(r) = Rf_.row(i).head(nv);
    dqdd_dv.row(r) = Rf_.row(i).segment(nv, nv);
    dqdd_du.row(r) = Rf_.row(i).segment(2 * nv, nu);
    dqdd_dacc.row(r) = Rf_.row(i).tail(nm);
  }
  for (int k = 0; k < nm; ++k) dqdd_dacc(driven_[k], k) = 1.0;
}

}  // namespace codyna
