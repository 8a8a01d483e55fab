// The Fiala (brush) tire force law as MSC Adams Tire and Project Chrono define it, on double or
// Eigen::AutoDiffScalar, with the input and output of every tire law of core/vehicle
// (tire_forces.hpp: ISO-W axes at the contact point).
//
// With the comprehensive slip S = min(1, sqrt(kappa^2 + tan(alpha)^2)) the friction coefficient
// is mu = mu_max - (mu_max - mu_min) S. Critical slips: kappa_c = |mu Fz / (2 C_kappa)|,
// alpha_c = atan(3 mu Fz / C_alpha).
//   Fx = C_kappa kappa                                      for |kappa| < kappa_c,
//   Fx = sign(kappa) (mu Fz - (mu Fz)^2 / (4 |kappa| C_kappa))  beyond (sliding);
//   with H = 1 - C_alpha |tan alpha| / (3 mu Fz), for |alpha| <= alpha_c:
//   Fy = -mu Fz (1 - H^3) sign(alpha),  Mz = mu Fz w (1 - H) H^3 sign(alpha)
//   (w the tread width: Adams writes 2 R2 with R2 half the width, Chrono w), and beyond:
//   Fy = -mu Fz sign(alpha), Mz = 0;
//   My = -C_rr Fz sign(omega), omega's sign that of (1 + kappa) Vx (C_rr a length, as Adams'
//   ROLLING_RESISTANCE); Mx = 0. Kxk = C_kappa, Kya = -C_alpha (the slopes at zero slip).
// Left out, as in Adams and Chrono: camber, combined-slip coupling beyond the common mu, turn slip,
// relaxation (transient slip).
#pragma once

#include <cmath>

#include "vehicle/tire_forces.hpp"

namespace codyna {

struct FialaParameters {
  double C_kappa = 0;          // longitudinal slip stiffness (N)
  double C_alpha = 0;          // cornering stiffness (N/rad, positive)
  double mu_max = 1;           // friction at zero slip (Adams UMAX)
  double mu_min = 1;           // friction at full slip (Adams UMIN)
  double width = 0;            // tread width w (m)
  double rolling_resistance = 0;  // C_rr (m)
  double unloaded_radius = 0;  // reported as Re (m)
};

template <class S>
TireForces<S> fiala_tire(const FialaParameters& p, const TireInput<S>& input) {
  const TireInput<S> in = tire_coherent(input);
  using std::abs;
  using std::sqrt;
  using std::tan;
  TireForces<S> out;
  S Fz = in.Fz;
  if (tire_value(Fz) < 0) Fz = in.Fz * 0.0;
  const S ta = tan(in.alpha);
  const S s2 = in.kappa * in.kappa + ta * ta;
  S slip = tire_value(s2) > 0 ? S(sqrt(s2)) : S(s2 * 0.0);
  if (tire_value(slip) > 1) slip = slip * 0.0 + 1.0;
  const S mu = p.mu_max - (p.mu_max - p.mu_min) * slip;
  const S muFz = mu * Fz;
  const double kappa_c = std::abs(tire_value(muFz) / (2 * p.C_kappa));
  const double alpha_c = std::atan(3 * tire_value(muFz) / p.C_alpha);
  if (std::abs(tire_value(in.kappa)) < kappa_c)
    out.Fx = p.C_kappa * in.kappa;
  else
    out.Fx = tire_sign(in.kappa) * (muFz - muFz * muFz / (4 * abs(in.kappa) * p.C_kappa));
  if (std::abs(tire_value(in.alpha)) <= alpha_c && tire_value(muFz) > 0) {
    // with x = C_alpha tan(alpha) / (3 mu Fz), H = 1 - |x|: (1 - H^3) sign(alpha) = x (3 - 3|x| + x^2)
    // and (1 - H) sign(alpha) = x, written so that the derivative at alpha = 0 is -C_alpha
    const S x = p.C_alpha * ta / (3.0 * muFz);
    const S ax = abs(x);
    const S H = 1.0 - ax;
    out.Fy = -muFz * x * (3.0 - 3.0 * ax + ax * ax);
    out.Mz = muFz * p.width * x * (H * H * H);
  } else {
    out.Fy = -muFz * tire_sign(in.alpha);
    out.Mz = muFz * 0.0;
  }
  out.Fz = Fz;
  out.Mx = Fz * 0.0;
  out.My = -p.rolling_resistance * Fz * tire_sign(S((1.0 + in.kappa) * in.Vx));
  out.Kxk = Fz * 0.0 + p.C_kappa;
  out.Kya = Fz * 0.0 - p.C_alpha;
  out.Re = Fz * 0.0 + p.unloaded_radius;
  out.mux = mu;
  out.muy = mu;
  out.trail = Fz * 0.0;
  out.Mzr = Fz * 0.0;
  out.omega = p.unloaded_radius > 0 ? S((1.0 + in.kappa) * in.Vx / p.unloaded_radius) : S(Fz * 0.0);
  return out;
}

}  // namespace codyna
