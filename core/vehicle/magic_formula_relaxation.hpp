// The relaxation lengths of a Magic Formula tire (the transient slip of dynamics/tire_effect.hpp)
// from its .tir file, at a load Fz and camber gamma, on any scalar (double or an automatic-
// differentiation scalar: the lengths depend on the load, so their derivative enters the
// Jacobian). Fz0' = LFZO FNOMIN, dfz = (Fz - Fz0') / Fz0', R0 = UNLOADED_RADIUS.
//   MF 5.2 (the MF-Tyre manual's):
//     sigma_kappa = (PTX1 + PTX2 dfz) exp(-PTX3 dfz) LSGKP R0 Fz / Fz0'
//     sigma_alpha = (1 - PKY3 |gamma|) PTY1 sin(2 atan(Fz / (PTY2 Fz0'))) R0 LFZO LSGAL
//   MF 6.1, 6.2 (Pacejka, Tire and Vehicle Dynamics, 3rd ed., ch. 7: the slip stiffness over the
//   carcass stiffness at the contact):
//     sigma_kappa = Kxk / C_Fx,  C_Fx = LONGITUDINAL_STIFFNESS (1 + PCFX1 dfz + PCFX2 dfz^2)(1 + PCFX3 dpi)
//     sigma_alpha = |Kya| / C_Fy, C_Fy = LATERAL_STIFFNESS (1 + PCFY1 dfz + PCFY2 dfz^2)(1 + PCFY3 dpi)
//   with Kxk, Kya the Magic Formula's slip stiffnesses at (Fz, gamma) (magic_formula.hpp) and dpi
//   at the file's inflation pressure INFLPRES.
#pragma once

#include <cmath>
#include <utility>

#include "vehicle/magic_formula.hpp"

namespace codyna {

template <class S>
std::pair<S, S> magic_formula_relaxation_lengths(const MagicFormulaParameters& P, const S& Fz, const S& gamma, const S& Vx,
                                                 const MagicFormulaOptions& options = {}) {
  using std::exp;
  using std::sin;
  const double Fz0p = P.LFZO * P.FNOMIN, R0 = P.UNLOADED_RADIUS;
  const S dfz = (Fz - Fz0p) / Fz0p;
  if (P.version == MagicFormulaVersion::MF52) {
    const S decay = exp(S(dfz * (-P.PTX3)));
    const S sx = (dfz * P.PTX2 + P.PTX1) * decay * (P.LSGKP * R0 / Fz0p) * Fz;
    const S ratio = Fz / (P.PTY2 * Fz0p);
    const S turn = tire_atan(ratio) * 2.0;
    const S camber = S(gamma * tire_sign(gamma)) * (-P.PKY3) + 1.0;
    const S sy = camber * sin(turn) * (P.PTY1 * R0 * P.LFZO * P.LSGAL);
    return {sx, sy};
  }
  const double dpi = (P.INFLPRES - P.NOMPRES) / P.NOMPRES;
  TireInput<S> in;
  const S zero = Fz * 0.0;
  in.Fz = Fz;
  in.gamma = gamma;
  in.Vx = Vx;
  in.kappa = in.alpha = in.phit = in.pressure = zero;
  const TireForces<S> f = magic_formula<S>(P, tire_coherent(in), options);
  const S CFx = (dfz * P.PCFX1 + dfz * dfz * P.PCFX2 + 1.0) * (P.LONGITUDINAL_STIFFNESS * (1.0 + P.PCFX3 * dpi));
  const S CFy = (dfz * P.PCFY1 + dfz * dfz * P.PCFY2 + 1.0) * (P.LATERAL_STIFFNESS * (1.0 + P.PCFY3 * dpi));
  const S Kya = f.Kya * tire_sign(f.Kya);
  return {S(f.Kxk / CFx), S(Kya / CFy)};
}

}  // namespace codyna
