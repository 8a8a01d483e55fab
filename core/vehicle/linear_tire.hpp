// The linear tire force law, on double or Eigen::AutoDiffScalar, with the input and output of every
// tire law of core/vehicle (tire_forces.hpp: ISO-W axes at the contact point):
//   Fx = C_kappa kappa,  Fy = -C_alpha alpha + C_gamma gamma,  Mz = -t Fy (t a pneumatic trail),
//   and, when a friction coefficient mu > 0 is given, (Fx, Fy) scaled down together to the
//   friction circle sqrt(Fx^2 + Fy^2) <= mu Fz (Mz follows the scaled Fy).
// Mx = My = 0; Kxk = C_kappa, Kya = -C_alpha (ISO-W: a normal tire's Fy falls with alpha).
// This is the tire of the single-track (bicycle) model (docs/tires.md).
#pragma once

#include <cmath>

#include "vehicle/tire_forces.hpp"

namespace codyna {

struct LinearTireParameters {
  double C_kappa = 0;          // longitudinal slip stiffness (N)
  double C_alpha = 0;          // cornering stiffness (N/rad, positive)
  double C_gamma = 0;          // camber stiffness (N/rad)
  double mu = 0;               // friction limit (0: none)
  double trail = 0;            // pneumatic trail t (m)
  double unloaded_radius = 0;  // reported as Re (m)
};

template <class S>
TireForces<S> linear_tire(const LinearTireParameters& p, const TireInput<S>& input) {
  const TireInput<S> in = tire_coherent(input);
  using std::sqrt;
  TireForces<S> out;
  S Fz = in.Fz;
  if (tire_value(Fz) < 0) Fz = in.Fz * 0.0;
  S Fx = p.C_kappa * in.kappa;
  S Fy = -p.C_alpha * in.alpha + p.C_gamma * in.gamma;
  if (p.mu > 0) {
    const S F2 = Fx * Fx + Fy * Fy;
    const S limit = p.mu * Fz;
    if (tire_value(F2) > tire_value(limit) * tire_value(limit)) {
      const S scale = limit / S(sqrt(F2));
      Fx = Fx * scale;
      Fy = Fy * scale;
    }
  }
  out.Fx = Fx;
  out.Fy = Fy;
  out.Fz = Fz;
  out.Mx = Fz * 0.0;
  out.My = Fz * 0.0;
  out.Mz = -p.trail * Fy;
  out.Kxk = Fz * 0.0 + p.C_kappa;
  out.Kya = Fz * 0.0 - p.C_alpha;
  out.Re = Fz * 0.0 + p.unloaded_radius;
  out.mux = Fz * 0.0 + p.mu;
  out.muy = Fz * 0.0 + p.mu;
  out.trail = Fz * 0.0 + p.trail;
  out.Mzr = Fz * 0.0;
  out.omega = p.unloaded_radius > 0 ? S((1.0 + in.kappa) * in.Vx / p.unloaded_radius) : S(Fz * 0.0);
  return out;
}

}  // namespace codyna
