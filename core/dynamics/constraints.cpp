#include "dynamics/constraints.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {

// a body-fixed vector in world axes with its first two time derivatives (qdd = 0)
// a . b for autodiff scalars whose derivative vectors may be empty (constants):
// every product is evaluated into a plain scalar before it is summed, so that
// Eigen's AutoDiffScalar can make the derivative sizes coherent (it cannot
// inside an unevaluated expression, where a constant's empty derivative would
// silently drop or misread the other's)
template <class S>
S dot3(const Vec3T<S>& a, const Vec3T<S>& b, Eigen::Index nd) {
  S r = ad_coherent(S(a[0] * b[0]), nd);
  for (int k = 1; k < 3; ++k) {
    const S p = ad_coherent(S(a[k] * b[k]), nd);
    r = r + p;
  }
  return r;
}

template <class S>
struct Attached {
  Vec3T<S> x, xd, xdd;
};

// (rates false: x alone, xd and xdd zero: for phi and Jc, which do not read them)
template <class S>
Attached<S> attached(const DataT<S>& d, int body, const Eigen::Vector3d& local, Eigen::Index nd, bool rates = true) {
  auto coh = [nd](auto& m) { ad_make_coherent(m, nd); };
  const Vec3T<S> x = d.oMi[body].R * local.cast<S>();
  if (!rates) {
    Vec3T<S> xc = x, z = Vec3T<S>::Zero();
    coh(xc);
    coh(z);
    return {xc, z, z};
  }
  const Vec3T<S> w = angular_velocity<S>(d, body), al = angular_acceleration<S>(d, body);
  Vec3T<S> xc = x, wc = w, alc = al;
  coh(xc);
  coh(wc);
  coh(alc);
  Vec3T<S> xd = wc.cross(xc);
  coh(xd);
  Vec3T<S> xdd = alc.cross(xc) + wc.cross(xd);
  coh(xdd);
  return {xc, xd, xdd};
}

// a coupler's row: sum_k ratio_k q_k - offset; Jc holds the ratios, gamma is zero
template <class S>
void coupler_row(const ConstraintModel& c, DataT<S>& d, const VecXT<S>& q, bool jac, bool gam, Eigen::Index nd) {
  S phi = ad_coherent(S(-c.offset), nd);
  for (int k = 0; k < c.ncoupled; ++k) {
    const S term = ad_coherent(S(c.ratio[k] * q[c.iq[k]]), nd);
    phi = phi + term;
  }
  d.phi[c.row] = phi;
  if (gam) d.gamma[c.row] = ad_coherent(S(0), nd);
  if (!jac) return;
  for (Eigen::Index j = 0; j < d.Jc.cols(); ++j) d.Jc(c.row, j) = ad_coherent(S(0), nd);
  for (int k = 0; k < c.ncoupled; ++k) d.Jc(c.row, c.iv[k]) = ad_coherent(S(c.ratio[k]), nd);
}

// a disc lying flat on its plane: |n - (n . a) a| below this has no contact direction
constexpr double kDiscFlatness = 1e-6;

// a contact row of rolling: e . (v_b(P) - v_a(P)) with e a vector of body_a and the contact point
// P = c - Rd (c = p_b the centre, Rd = R n for a ball, R d for a disc; Rdd its rate):
//   v_b(P) - v_a(P) = w = -dp' + Rd x w_b + (P - p_a) x w_a,  dp = p_a - c,
// its Jc row and gamma = d/dt (e . w) at qdd = 0 = e' . w + e . w', with P' - p_a' = -dp' - Rd'
template <class S>
void contact_row(const Model& model, DataT<S>& d, const ConstraintModel& c, int r, const Attached<S>& t,
                 const Vec3T<S>& Rn, const Vec3T<S>& Rnd, const Vec3T<S>& dpc, const Vec3T<S>& dpd,
                 const Vec3T<S>& dpdd, Eigen::Index nd, Eigen::Index k, bool gam) {
  (void)model;
  auto coh = [nd](auto& m) { ad_make_coherent(m, nd); };
  const auto Jp = d.Jp.leftCols(k), Jwa = d.Jwa.leftCols(k), Jwb = d.Jwb.leftCols(k);  // the first k columns: fill_rows
  Vec3T<S> Pa = -dpc - Rn;  // P - p_a
  coh(Pa);
  Vec3T<S> tn = t.x.cross(Rn), tP = t.x.cross(Pa), mt = -t.x;
  coh(tn);
  coh(tP);
  coh(mt);
  d.Jc.row(r).head(k).noalias() = mt.transpose() * Jp;
  d.Jc.row(r).head(k).noalias() += tn.transpose() * Jwb;
  d.Jc.row(r).head(k).noalias() += tP.transpose() * Jwa;
  if (!gam) return;
  Vec3T<S> wa = angular_velocity<S>(d, c.body_a), wb = angular_velocity<S>(d, c.body_b);
  Vec3T<S> aa = angular_acceleration<S>(d, c.body_a), ab = angular_acceleration<S>(d, c.body_b);
  coh(wa);
  coh(wb);
  coh(aa);
  coh(ab);
  Vec3T<S> Pad = -dpd - Rnd;
  coh(Pad);
  Vec3T<S> w = Rn.cross(wb);
  coh(w);
  Vec3T<S> wP = Pa.cross(wa);
  coh(wP);
  w = w + wP - dpd;
  coh(w);
  Vec3T<S> wd1 = Rnd.cross(wb), wd2 = Rn.cross(ab), wd3 = Pad.cross(wa), wd4 = Pa.cross(aa);
  coh(wd1);
  coh(wd2);
  coh(wd3);
  coh(wd4);
  Vec3T<S> wd = wd1 + wd2;
  coh(wd);
  wd = wd + wd3;
  coh(wd);
  wd = wd + wd4;
  coh(wd);
  wd = wd - dpdd;
  coh(wd);
  const S s1 = dot3<S>(t.xd, w, nd), s2 = dot3<S>(t.x, wd, nd);
  d.gamma[r] = s1 + s2;
}

// the rows r0 .. r0 + n of Jc, written in their first k columns (the constraint's support, cols
// ascending), moved to their columns; Jc is zero elsewhere (fill_rows keeps it so: clearing only
// the supports costs k a row, not nv). In place from the end: cols[p] >= p, and a slot p left
// behind is zeroed after it is read (a smaller p may then move into it).
void spread_rows(Eigen::MatrixXd& Jc, int r0, int n, const std::vector<int>& cols) {
  const Eigen::Index k = static_cast<Eigen::Index>(cols.size());
  for (int r = r0; r < r0 + n; ++r)
    for (Eigen::Index p = k - 1; p >= 0; --p) {
      const Eigen::Index col = cols[static_cast<std::size_t>(p)];
      if (col == p) continue;
      Jc(r, col) = Jc(r, p);
      Jc(r, p) = 0.0;
    }
}

// phi always; Jc with jac; gamma with gam (from the velocities and accelerations at qdd = 0 of
// the kinematics); with jac alone, the Jacobians from the positions of forward kinematics
// (velocities and accelerations not read for any output); a contact row's Jc writes are empty
// without jac (its k is 0)
template <class S>
void fill_rows(const Model& model, DataT<S>& d, const VecXT<S>& q, bool jac, bool gam, Eigen::Index nd) {
  auto coh = [nd](auto& m) { ad_make_coherent(m, nd); };
  constexpr bool kDouble = std::is_same_v<S, double>;
  for (std::size_t ci = 0; ci < model.constraints.size(); ++ci) {
    const ConstraintModel& c = model.constraints[ci];
    if (c.type == ConstraintType::Coupler) {
      coupler_row<S>(c, d, q, jac, gam, nd);
      continue;
    }
    const Vec3T<S> pa = point_position<S>(d, c.body_a, c.point_a), pb = point_position<S>(d, c.body_b, c.point_b);
    const Vec3T<S> dp = pa - pb;
    Vec3T<S> dpd = Vec3T<S>::Zero(), dpdd = Vec3T<S>::Zero();
    // in double the Jacobians are formed on the constraint's support only (k columns: the joints on
    // its bodies' paths), the rows written in Jc's first k columns and spread at the end
    const std::vector<int>& cols = d.constants.constraint_cols[ci];
    const Eigen::Index k = kDouble ? static_cast<Eigen::Index>(cols.size()) : model.nv;
    if constexpr (kDouble) {  // Data's workspace: no heap after the first call
      for (MatXT<S>* m : {&d.Jp, &d.Jwa, &d.Jwb, &d.Jwd})
        if (m->cols() != model.nv) m->resize(3, model.nv);
      // Jc is zero off the supports (Data makes it zero; only these rows write it, and
      // plant_function zeroes whole rows): the rows' last values, on the support, cleared for
      // the compact rows and spread_rows
      if (jac)
        for (int r = c.row; r < c.row + c.nrows; ++r)
          for (const int col : cols) d.Jc(r, col) = 0.0;
    }
    if (gam) {
      dpd = point_velocity<S>(d, c.body_a, c.point_a) - point_velocity<S>(d, c.body_b, c.point_b);
      dpdd = point_acceleration<S>(d, c.body_a, c.point_a) - point_acceleration<S>(d, c.body_b, c.point_b);
    }
    if (jac) {
      if constexpr (kDouble) {
        // the joints' world motions on the support, each on the side(s) whose path holds it; the
        // point Jacobians: linear rows less (point x angular rows)
        const std::vector<int>& side = d.constants.constraint_side[ci];
        for (Eigen::Index p = 0; p < k; ++p) {
          const int col = cols[static_cast<std::size_t>(p)], i = d.constants.dof_body[static_cast<std::size_t>(col)];
          const SE3T<S>& X = d.oMi[i];
          const Eigen::Index sub = col - model.joints[i].idx_v;
          const Vec3T<S> w = X.R * d.Sb[i].col(sub).template head<3>();
          const Vec3T<S> lin = X.R * d.Sb[i].col(sub).template tail<3>() + X.p.cross(w);
          const int sd = side[static_cast<std::size_t>(p)];
          Vec3T<S> jp = Vec3T<S>::Zero();
          d.Jwa.col(p).setZero();
          d.Jwb.col(p).setZero();
          if (sd == 3) {  // on both paths: the two points' velocities differ by the lever arms only
            d.Jwa.col(p) = w;
            d.Jwb.col(p) = w;
            jp = pb.cross(w) - pa.cross(w);
          } else if (sd == 1) {
            d.Jwa.col(p) = w;
            jp = lin - pa.cross(w);
          } else {
            d.Jwb.col(p) = w;
            jp = pb.cross(w) - lin;
          }
          d.Jp.col(p) = jp;
        }
      } else {
        d.Jp = point_jacobian<S>(model, d, c.body_a, c.point_a) - point_jacobian<S>(model, d, c.body_b, c.point_b);
        d.Jwa = body_jacobian_world<S>(model, d, c.body_a).topRows(3);
        d.Jwb = body_jacobian_world<S>(model, d, c.body_b).topRows(3);
      }
    }
    // constants (ground, fixed axes) beside variables: one derivative size for all
    Vec3T<S> dpc = dp;
    coh(dpc);
    if (gam) {
      coh(dpd);
      coh(dpdd);
    }
    if (jac) {
      if constexpr (!kDouble) {
        coh(d.Jp);
        coh(d.Jwa);
        coh(d.Jwb);
        d.Jwd = d.Jwa - d.Jwb;
      } else {
        d.Jwd.leftCols(k) = d.Jwa.leftCols(k) - d.Jwb.leftCols(k);
      }
    }
    // (blocks made after the autodiff path's assignments, which may resize)
    const Eigen::Index kb = jac ? k : 0;
    const auto Jp = d.Jp.leftCols(kb), Jwa = d.Jwa.leftCols(kb), Jwd = d.Jwd.leftCols(kb);
    int r = c.row;
    switch (c.type) {
      case ConstraintType::Ball:
      case ConstraintType::Revolute:
        d.phi.template segment<3>(r) = dpc;
        if (jac) d.Jc.middleRows(r, 3).leftCols(k) = Jp;
        if (gam) d.gamma.template segment<3>(r) = dpdd;
        if (c.type == ConstraintType::Ball) break;
        r += 3;
        for (const Eigen::Vector3d* perp : {&c.perp_b1, &c.perp_b2}) {
          // a . b with a on body_a, b on body_b
          const Attached<S> a = attached<S>(d, c.body_a, c.axis_a, nd, gam), b = attached<S>(d, c.body_b, *perp, nd, gam);
          d.phi[r] = dot3<S>(a.x, b.x, nd);
          if (jac) {
            Vec3T<S> axb = a.x.cross(b.x);
            coh(axb);
            d.Jc.row(r).head(k).noalias() = axb.transpose() * Jwd;
          }
          if (gam) {
            const S g1 = dot3<S>(a.xdd, b.x, nd), g2 = dot3<S>(a.xd, b.xd, nd), g3 = dot3<S>(a.x, b.xdd, nd);
            const S g2x2 = ad_coherent(S(S(2) * g2), nd);
            const S g12 = g1 + g2x2;
            d.gamma[r] = g12 + g3;
          }
          ++r;
        }
        break;
      case ConstraintType::PlanarRevolute:
        for (const Eigen::Vector3d* perp : {&c.perp_a1, &c.perp_a2}) {
          const Attached<S> e = attached<S>(d, c.body_a, *perp, nd, gam);
          d.phi[r] = dot3<S>(e.x, dpc, nd);
          if (jac) {
            Vec3T<S> exd = e.x.cross(dpc);
            coh(exd);
            d.Jc.row(r).head(k).noalias() = exd.transpose() * Jwa;
            d.Jc.row(r).head(k).noalias() += e.x.transpose() * Jp;
          }
          if (gam) {
            const S g1 = dot3<S>(e.xdd, dpc, nd), g2 = dot3<S>(e.xd, dpd, nd), g3 = dot3<S>(e.x, dpdd, nd);
            const S g2x2 = ad_coherent(S(S(2) * g2), nd);
            const S g12 = g1 + g2x2;
            d.gamma[r] = g12 + g3;
          }
          ++r;
        }
        break;
      case ConstraintType::RollingBall: {
        // the plane's normal n and directions t1, t2 on body_a; the ball's centre c = p_b, the contact
        // point P = c - R n. Height: n . (c - p_a) - R (on q). No slip: t . (v_b(P) - v_a(P)) with
        // v_b(P) - v_a(P) = w = -dp' + R n x w_b + (P - p_a) x w_a, dp = p_a - c (on v only: phi 0)
        const S R = ad_coherent(S(c.radius), nd);
        const Attached<S> n = attached<S>(d, c.body_a, c.axis_a, nd);
        Vec3T<S> ndp = dpc.cross(n.x), mn = -n.x;  // -(n x dp), -n: products of small negated factors
        coh(ndp);                                   // (no heap: a negated product would be a temporary)
        coh(mn);
        const S h = dot3<S>(n.x, dpc, nd);
        d.phi[r] = -h - R;
        if (jac) {
          d.Jc.row(r).head(k).noalias() = ndp.transpose() * Jwa;
          d.Jc.row(r).head(k).noalias() += mn.transpose() * Jp;
        }
        if (gam) {
          const S g1 = dot3<S>(n.xdd, dpc, nd), g2 = dot3<S>(n.xd, dpd, nd), g3 = dot3<S>(n.x, dpdd, nd);
          const S g2x2 = ad_coherent(S(S(2) * g2), nd);
          const S g12 = g1 + g2x2;
          d.gamma[r] = -(g12 + g3);
        }
        ++r;
        Vec3T<S> Rn = n.x * R, Rnd = n.xd * R;
        coh(Rn);
        coh(Rnd);
        for (const Eigen::Vector3d* perp : {&c.perp_a1, &c.perp_a2}) {
          d.phi[r] = ad_coherent(S(0), nd);
          if (jac || gam)
            contact_row<S>(model, d, c, r, attached<S>(d, c.body_a, *perp, nd), Rn, Rnd, dpc, dpd, dpdd, nd, kb, gam);
          ++r;
        }
        break;
      }
      case ConstraintType::RollingDisc: {
        // the plane's normal n (body_a), the axle a (body_b); k = n . a, s = |n - k a| = sqrt(1 - k^2),
        // the contact direction d = (n - k a) / s (in the disc's plane, towards the plane's side:
        // n . d = s > 0), the contact point P = c - R d. Height: n . (c - p_a) - R s (on q); its
        // rate is n . (v_b(P) - v_a(P)) (the normal velocity at the contact), so that all three
        // rows are e . (v_b(P) - v_a(P)) for e = n, t1, t2: the ball's slip rows with R n -> R d.
        const S R = ad_coherent(S(c.radius), nd);
        const Attached<S> n = attached<S>(d, c.body_a, c.axis_a, nd), a = attached<S>(d, c.body_b, c.axis_b, nd);
        const S k = dot3<S>(n.x, a.x, nd);
        const S kk = ad_coherent(S(k * k), nd);
        const S one = ad_coherent(S(1), nd);
        const S s2 = one - kk;
        if (!(ad_value(s2) >= kDiscFlatness * kDiscFlatness))
          throw std::domain_error("rolling_disc " + c.name + ": the disc lies flat on the plane (|n - (n.a) a| = " +
                                  std::to_string(std::sqrt(std::max(0.0, ad_value(s2)))) +
                                  "): its contact point is undefined there");
        using std::sqrt;
        const S sv = sqrt(s2);
        Vec3T<S> ka = a.x * k;
        coh(ka);
        Vec3T<S> dir = n.x - ka;  // n - k a, then / s
        coh(dir);
        dir = dir / sv;
        coh(dir);
        const S h = dot3<S>(n.x, dpc, nd);
        const S Rs = ad_coherent(S(R * sv), nd);
        d.phi[r] = -h - Rs;  // n . (c - p_a) - R s
        if (!jac) {
          d.phi[r + 1] = ad_coherent(S(0), nd);
          d.phi[r + 2] = ad_coherent(S(0), nd);
          if (!gam) break;
        }
        // k' = n' . a + n . a', u' = n' - k' a - k a', d' = (u' - d (d . u')) / s
        const S k1 = dot3<S>(n.xd, a.x, nd), k2 = dot3<S>(n.x, a.xd, nd);
        const S kd = k1 + k2;
        Vec3T<S> kda = a.x * kd, kad = a.xd * k;
        coh(kda);
        coh(kad);
        Vec3T<S> ud = n.xd - kda;
        coh(ud);
        ud = ud - kad;
        coh(ud);
        const S du = dot3<S>(dir, ud, nd);
        Vec3T<S> ddu = dir * du;
        coh(ddu);
        Vec3T<S> dird = ud - ddu;
        coh(dird);
        dird = dird / sv;
        coh(dird);
        Vec3T<S> Rd = dir * R, Rdd = dird * R;
        coh(Rd);
        coh(Rdd);
        contact_row<S>(model, d, c, r++, n, Rd, Rdd, dpc, dpd, dpdd, nd, kb, gam);
        for (const Eigen::Vector3d* perp : {&c.perp_a1, &c.perp_a2}) {
          d.phi[r] = ad_coherent(S(0), nd);
          contact_row<S>(model, d, c, r, attached<S>(d, c.body_a, *perp, nd), Rd, Rdd, dpc, dpd, dpdd, nd, kb, gam);
          ++r;
        }
        break;
      }
      case ConstraintType::Coupler: break;  // coupler_row
    }
    if constexpr (kDouble)
      if (jac) spread_rows(d.Jc, c.row, c.nrows, cols);
  }
#ifndef NDEBUG
  if constexpr (kDouble)  // (debug builds: the rows are zero off their supports, as the clearing assumes)
    if (jac)
      for (std::size_t ci = 0; ci < model.constraints.size(); ++ci) {
        const ConstraintModel& c = model.constraints[ci];
        std::vector<char> on(static_cast<std::size_t>(model.nv), 0);
        for (const int col : d.constants.constraint_cols[ci]) on[static_cast<std::size_t>(col)] = 1;
        for (int r = c.row; r < c.row + c.nrows; ++r)
          for (int j = 0; j < model.nv; ++j) assert(on[static_cast<std::size_t>(j)] || d.Jc(r, j) == 0.0);
      }
#endif
}

}  // namespace

template <class S>
const VecXT<S>& constraint_residual(const Model& model, DataT<S>& d, const VecXT<S>& q) {
  forward_kinematics<S>(model, d, q);
  fill_rows<S>(model, d, q, false, false, ad_size(q));
  return d.phi;
}

template <class S>
void constraint_terms(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v) {
  if (d.zero_v.size() != model.nv) d.zero_v = VecXT<S>::Zero(model.nv);
  forward_kinematics<S>(model, d, q, v, d.zero_v);
  fill_rows<S>(model, d, q, true, true, std::max(ad_size(q), ad_size(v)));
}

void constraint_jacobian_after_kinematics(const Model& model, Data& d, const Eigen::VectorXd& q) {
  fill_rows<double>(model, d, q, true, false, 0);
}

std::pair<double, double> constraint_violation_after_kinematics(const Model& model, Data& d, const Eigen::VectorXd& q,
                                                                 const Eigen::VectorXd& v) {
  if (model.nc == 0) return {0.0, 0.0};
  fill_rows<double>(model, d, q, true, false, 0);
  return {d.phi.cwiseAbs().maxCoeff(), (d.Jc * v).cwiseAbs().maxCoeff()};
}

void constraint_gamma_after_positions(const Model& model, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  if (d.zero_v.size() != model.nv) d.zero_v = Eigen::VectorXd::Zero(model.nv);
  rate_kinematics<double>(model, d, q, v, d.zero_v);
  fill_rows<double>(model, d, q, false, true, 0);
}

#define CODYNA_INSTANTIATE(S)                                                                           \
  template const VecXT<S>& constraint_residual<S>(const Model&, DataT<S>&, const VecXT<S>&);            \
  template void constraint_terms<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
