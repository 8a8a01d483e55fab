// The tire effect (EffectType::Tire): a wheel body rolling on a road plane, its contact, slips and
// force law, on any scalar (double; codyna's ADScalar; the fixed-size AutoDiffScalar of
// dynamics/derivatives.cpp), so that applied_forces and the analytic Jacobian run the same lines.
//
// Axes ISO-W at the contact (docs/tires.md): with a the wheel's unit spin axis (the axle, pointing to
// the wheel's left) and n the road's unit normal,
//   x = (a x n) / |a x n|   forward along the wheel's heading in the road plane
//   z = n,  y = z x x       to the left
//   gamma = asin(n . a)     camber, the wheel plane's tilt about x (top to the right: positive)
// The contact point P lies in the wheel plane below the centre c: d = -(n - (n.a) a) / cos(gamma) is
// the wheel plane's downward radius, h = n . (c - r0) the centre's height over the road, s = h /
// cos(gamma) the loaded radius, P = c + s d (on the road), the deflection pen = R0 - s and its rate.
// Velocities are relative to the road body: with w_rel the wheel's angular velocity less the road's,
// Omega = w_rel . a the spin, the wheel carrier's angular velocity w_c = w_rel - Omega a, and
// V = v_wheel(c) - v_road(c) + w_c x (P - c) the velocity of the contact point moving with the carrier:
// Vx = x . V, Vy = y . V and, with the regularized speed |Vx|_v (= |Vx| for |Vx| >= v_low,
// v_low / 2 + Vx^2 / (2 v_low) below: continuously differentiable, positive),
//   kappa = -(Vx - Omega Re) / |Vx|_v,   alpha = atan(Vy / |Vx|_v)   (a normal tire: Fy < 0 for alpha > 0)
// Re the tire's rolling radius. Normal load Fz = k pen + c pen' while the wheel touches the road
// (pen > 0) and that is positive; otherwise the tire carries nothing (continuous; its derivative
// jumps where the wheel touches down). The law gives Fx, Fy, Mx, My, Mz at P in these axes; the
// wheel takes F = Fx x + Fy y + Fz z at P and M = Mx x + My y + Mz z, i.e. about its centre the
// wrench (F, M + (P - c) x F); a road on a moving body takes the opposite.
//
// Transient slip (relaxation; Pacejka, Tire and Vehicle Dynamics, the linear first-order model in
// its deflection form): a tire with relaxation lengths sigma_x, sigma_y > 0 carries the contact's
// longitudinal and lateral deflections u_x, u_y as states, with
//   du_x/dt = -(Vx - Omega Re) - |Vx|_v u_x / sigma_x,   kappa' = u_x / sigma_x
//   du_y/dt = Vy - |Vx|_v u_y / sigma_y,                 alpha' = atan(u_y / sigma_y)
// and the law takes kappa', alpha' for kappa, alpha. At rest in the states (du/dt = 0) they equal the
// steady slips above; a slip that changes reaches the force after about sigma / |Vx| seconds. Off the
// road the deflections relax at the rate of the lowest regularized speed (v_low / 2).
#pragma once

#include <cmath>

#include "model/model.hpp"
#include "spatial/spatial.hpp"
#include "vehicle/fiala.hpp"
#include "vehicle/linear_tire.hpp"
#include "vehicle/magic_formula.hpp"
#include "vehicle/magic_formula_relaxation.hpp"
#include "vehicle/road.hpp"

namespace codyna {

// What one evaluation found (world axes).
template <class S>
struct TireContact {
  Vec3T<S> point, force, moment;       // P, F at P, M about P
  Vec3T<S> ex, ey, ez;                 // the ISO-W axes at P
  Vec3T<S> center;                     // the wheel centre c
  S penetration{0.0}, penetration_rate{0.0}, Vx{0.0}, Vy{0.0}, omega{0.0};
  TireInput<S> input;                  // Fz, kappa, alpha, gamma, Vx handed to the law
  TireForces<S> out;                   // the law's forces and moments at P
  S rate_x{0.0}, rate_y{0.0};          // transient slip: du_x/dt, du_y/dt (0 without the state)
  S sigma_x{0.0}, sigma_y{0.0};        // transient slip: the relaxation lengths at this contact
};

// asin with its derivative 1 / sqrt(1 - x^2) (an evaluated scalar)
inline double tire_effect_asin(double x) { return std::asin(x); }
template <class D>
Eigen::AutoDiffScalar<D> tire_effect_asin(const Eigen::AutoDiffScalar<D>& x) {
  const double v = x.value();
  return Eigen::AutoDiffScalar<D>(std::asin(v), D(x.derivatives() * (1.0 / std::sqrt(1.0 - v * v))));
}

// |Vx| regularized below v_low: v_low / 2 + Vx^2 / (2 v_low), C1 at |Vx| = v_low, smooth through 0
template <class S>
S tire_effect_speed(const S& Vx, double v_low) {
  const double v = tire_value(Vx);
  if (std::abs(v) >= v_low) return v >= 0 ? S(Vx) : S(-Vx);
  return S(Vx * Vx * (0.5 / v_low) + 0.5 * v_low);
}

// a Magic Formula tire's options: mounted on the side the element says
inline MagicFormulaOptions tire_effect_mf_options(const TireModel& t) {
  MagicFormulaOptions options;
  options.mount = t.side == 1 ? TireMount::Left : t.side == 2 ? TireMount::Right : TireMount::AsFile;
  return options;
}

// The tire's force law at one contact state; region: the road's friction region at the contact
// (t.road->friction; -1: none), whose scale multiplies the law's friction (linear: mu; fiala: mu_max
// and mu_min; magic_formula: LMUX and LMUY, t.mf_regions)
template <class S>
TireForces<S> tire_effect_law(const TireModel& t, const TireInput<S>& in, int region = -1) {
  const double scale = region >= 0 ? t.road->friction[static_cast<std::size_t>(region)].scale : 1.0;
  switch (t.law) {
    case TireLaw::Linear: {
      LinearTireParameters p;
      p.C_kappa = t.C_kappa;
      p.C_alpha = t.C_alpha;
      p.C_gamma = t.C_gamma;
      p.mu = region >= 0 ? t.friction * scale : t.friction;
      p.trail = t.trail;
      p.unloaded_radius = t.unloaded_radius;
      return linear_tire<S>(p, in);
    }
    case TireLaw::Fiala: {
      FialaParameters p;
      p.C_kappa = t.C_kappa;
      p.C_alpha = t.C_alpha;
      p.mu_max = region >= 0 ? t.friction * scale : t.friction;
      p.mu_min = region >= 0 ? t.sliding_friction * scale : t.sliding_friction;
      p.width = t.width;
      p.rolling_resistance = t.rolling_resistance;
      p.unloaded_radius = t.unloaded_radius;
      return fiala_tire<S>(p, in);
    }
    case TireLaw::MagicFormula: break;
  }
  if (region >= 0) return magic_formula<S>(*t.mf_regions[static_cast<std::size_t>(region)], in, tire_effect_mf_options(t));
  return magic_formula<S>(*t.mf, in, tire_effect_mf_options(t));
}

// The road's height and gradient at (x, y) (road body coordinates) on the scalar S: the surface's
// values, and for an automatic-differentiation scalar the derivatives by the chain rule through the
// surface's second derivatives.
template <class S>
struct TireRoadPoint {
  S z, zx, zy;
};
inline TireRoadPoint<double> tire_effect_road(const RoadSurface& road, double x, double y) {
  const RoadHeight h = road.height(x, y);
  return {h.z, h.zx, h.zy};
}
template <class D>
TireRoadPoint<Eigen::AutoDiffScalar<D>> tire_effect_road(const RoadSurface& road, const Eigen::AutoDiffScalar<D>& x,
                                                         const Eigen::AutoDiffScalar<D>& y) {
  using A = Eigen::AutoDiffScalar<D>;
  const RoadHeight h = road.height(x.value(), y.value());
  const auto chain = [&](double fx, double fy) {
    // x and y carry the same derivatives' size, except a constant's (size 0 when dynamic)
    if (y.derivatives().size() == 0) return D(x.derivatives() * fx);
    if (x.derivatives().size() == 0) return D(y.derivatives() * fy);
    return D(x.derivatives() * fx + y.derivatives() * fy);
  };
  return {A(h.z, chain(h.zx, h.zy)), A(h.zx, chain(h.zxx, h.zxy)), A(h.zy, chain(h.zxy, h.zyy))};
}

// The road below the wheel centre c as a plane (world axes): its unit normal n and a point r0. A
// road of heights gives its tangent plane at the centre's x, y in the road body's frame (the
// "equivalent plane" of a point follower, docs/roads.md), and the friction region there.
template <class S>
void tire_effect_plane(const TireModel& t, const Mat3T<S>& Rr, const Vec3T<S>& pr, const Vec3T<S>& c, Vec3T<S>& n, Vec3T<S>& r0,
                       int& region) {
  using std::sqrt;
  region = -1;
  if (!t.road) {
    n = Rr * t.road_normal.cast<S>();
    r0 = Rr * t.road_point.cast<S>() + pr;
    return;
  }
  const Vec3T<S> cl = Rr.transpose() * Vec3T<S>(c - pr);
  const TireRoadPoint<S> h = tire_effect_road(*t.road, cl[0], cl[1]);
  const S inv = 1.0 / S(sqrt(h.zx * h.zx + h.zy * h.zy + 1.0));
  n = Rr * Vec3T<S>(S(-h.zx * inv), S(-h.zy * inv), inv);
  r0 = Rr * Vec3T<S>(cl[0], cl[1], h.z) + pr;
  region = t.road->region(tire_value(cl[0]), tire_value(cl[1]));
}

// The contact of tire t: wheel pose (R, p), angular velocity w and velocity v of its origin, the road
// body's likewise (world axes). Fills c; false when the tire carries no force (off the road, or the
// wheel lying flat on it), c's forces then zero. states: the effect states (Data::s) when the tire has
// transient slip (t.state_x, t.state_y; nullptr: the steady slips, as at rest in the states).
template <class S>
bool tire_contact(const TireModel& t, const Mat3T<S>& Rw, const Vec3T<S>& pw, const Vec3T<S>& ww, const Vec3T<S>& vw,
                  const Mat3T<S>& Rr, const Vec3T<S>& pr, const Vec3T<S>& wr, const Vec3T<S>& vr, TireContact<S>& c,
                  const VecXT<S>* states = nullptr) {
  using std::sqrt;
  const S zero = pw[0] * 0.0;
  c.force = Vec3T<S>::Constant(zero);
  c.moment = Vec3T<S>::Constant(zero);
  const bool lag_x = states && t.state_x >= 0, lag_y = states && t.state_y >= 0;
  // off the road: the deflections relax (at v_low / 2 over the length)
  c.rate_x = lag_x ? S((*states)[t.state_x] * (-0.5 * t.low_speed / t.relaxation_x)) : zero;
  c.rate_y = lag_y ? S((*states)[t.state_y] * (-0.5 * t.low_speed / t.relaxation_y)) : zero;
  const Vec3T<S> a = Rw * t.axis.cast<S>();
  c.center = Rw * t.center.cast<S>() + pw;
  Vec3T<S> n, r0;
  int region = -1;
  tire_effect_plane<S>(t, Rr, pr, c.center, n, r0, region);
  const S na = n.dot(a);
  const Vec3T<S> e = n - a * na;
  const S ce2 = e.squaredNorm();
  if (!(tire_value(ce2) > 1e-18)) return false;  // the wheel lies flat on the road: no heading
  const S ce = sqrt(ce2);                         // cos(gamma) = |a x n|
  const Vec3T<S> dn = -e / ce;                    // the wheel plane's downward radius
  const Vec3T<S> rc = c.center - r0;
  const S h = n.dot(rc);
  const S s = h / ce;
  c.penetration = t.unloaded_radius - s;
  if (!(tire_value(c.penetration) > 0)) return false;
  c.point = c.center + dn * s;
  c.ex = a.cross(n) / ce;
  c.ez = n;
  c.ey = n.cross(c.ex);
  // velocities relative to the road's material points
  const Vec3T<S> wrel = ww - wr;
  const Vec3T<S> vc = vw + ww.cross(Vec3T<S>(c.center - pw)) - vr - wr.cross(Vec3T<S>(c.center - pr));
  c.omega = wrel.dot(a);
  const S h_dot = n.dot(vc);
  const S na_dot = n.dot(wrel.cross(a));
  const S ce_dot = -na * na_dot / ce;
  const S s_dot = (h_dot * ce - h * ce_dot) / ce2;
  c.penetration_rate = -s_dot;
  const S Fz = t.vertical_stiffness * c.penetration + t.vertical_damping * c.penetration_rate;
  if (!(tire_value(Fz) > 0)) return false;
  const Vec3T<S> wc = wrel - a * c.omega;
  const Vec3T<S> V = vc + wc.cross(Vec3T<S>(c.point - c.center));
  c.Vx = c.ex.dot(V);
  c.Vy = c.ey.dot(V);
  const S speed = tire_effect_speed<S>(c.Vx, t.low_speed);
  c.input.Fz = Fz;
  c.input.gamma = tire_effect_asin(na);
  if (t.state_x >= 0 || t.state_y >= 0) {
    // the relaxation lengths: the element's, or the .tir file's at this load and camber
    if (t.relaxation_from_file) {
      const std::pair<S, S> lengths = magic_formula_relaxation_lengths<S>(*t.mf, Fz, c.input.gamma, c.Vx, tire_effect_mf_options(t));
      c.sigma_x = lengths.first;
      c.sigma_y = lengths.second;
    } else {
      c.sigma_x = zero + t.relaxation_x;
      c.sigma_y = zero + t.relaxation_y;
    }
  }
  const S slip_x = c.Vx - c.omega * t.rolling_radius;
  if (lag_x) {
    const S ux = (*states)[t.state_x];
    const S kappa = ux / c.sigma_x;
    c.rate_x = -slip_x - speed * kappa;
    c.input.kappa = kappa;
  } else {
    c.input.kappa = -slip_x / speed;
  }
  if (lag_y) {
    const S uy = (*states)[t.state_y];
    const S ratio = uy / c.sigma_y;
    c.rate_y = c.Vy - speed * ratio;
    c.input.alpha = tire_atan(ratio);
  } else {
    const S ratio = c.Vy / speed;
    c.input.alpha = tire_atan(ratio);
  }
  c.input.Vx = c.Vx;
  c.input.phit = zero;
  c.input.pressure = zero;
  c.out = tire_effect_law<S>(t, c.input, region);
  c.force = c.ex * c.out.Fx + c.ey * c.out.Fy + c.ez * Fz;
  c.moment = c.ex * c.out.Mx + c.ey * c.out.My + c.ez * c.out.Mz;
  return true;
}

}  // namespace codyna
