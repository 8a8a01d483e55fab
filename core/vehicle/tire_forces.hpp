// What every tire force law of core/vehicle takes and gives: the contact's state (TireInput) and
// the forces and moments at the contact point with the slip stiffnesses (TireForces), both
// templated on the scalar (double, or Eigen::AutoDiffScalar so that derivatives with respect to
// the inputs come from automatic differentiation), and the few scalar functions the laws need on
// both scalars (Eigen's AutoDiff has no atan, and a branch must look at a value, not at a
// derivative).
//
// Axes ISO-W (the axes of the .tir files and of MFeval): at the contact point, x forward along the
// wheel's heading in the road plane, z the road's normal (up), y = z x x (to the left).
//   kappa = -(Vx - Omega Re) / |Vx|   longitudinal slip, positive when driving
//   alpha = atan(Vy / |Vx|)           slip angle (rad); a normal tire gives Fy < 0 for alpha > 0
//   gamma                             camber (rad), the wheel plane's tilt about x
//   phit                              turn slip (1/m)
// Forces in N, moments in N m, all at the contact point in these axes.
#pragma once

#include <algorithm>
#include <cmath>
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace codyna {

template <class S>
struct TireInput {
  S Fz{0.0};        // vertical load (N), positive in compression; negative loads are taken as 0
  S kappa{0.0};     // longitudinal slip (-)
  S alpha{0.0};     // slip angle (rad)
  S gamma{0.0};     // camber (rad)
  S phit{0.0};      // turn slip (1/m)
  S Vx{0.0};        // the contact's forward velocity (m/s)
  S pressure{0.0};  // inflation pressure (Pa); 0 or less: the tire file's INFLPRES
};

template <class S>
struct TireForces {
  S Fx{0.0}, Fy{0.0}, Fz{0.0};  // N
  S Mx{0.0}, My{0.0}, Mz{0.0};  // N m: overturning, rolling resistance, aligning
  S Kxk{0.0};                   // longitudinal slip stiffness dFx0/dkappa at kappa = 0 (N)
  S Kya{0.0};                   // cornering stiffness dFy0/dalpha at alpha = 0 (N/rad)
  S Re{0.0};                    // effective rolling radius (m)
  S mux{0.0}, muy{0.0};         // friction coefficients (Magic Formula; Fiala: mu; linear: 0)
  S trail{0.0};                 // pneumatic trail t (m; Magic Formula only)
  S Mzr{0.0};                   // residual aligning moment (N m; Magic Formula only)
  S omega{0.0};                 // wheel spin (rad/s) the rolling radius was computed for
};

// Scalar helpers for double and Eigen::AutoDiffScalar (named tire_* to stay unique in codyna's
// unity builds).
inline double tire_value(double x) { return x; }
template <class D>
double tire_value(const Eigen::AutoDiffScalar<D>& x) {
  return x.value();
}

// atan with its derivative 1 / (1 + x^2) (pass an evaluated scalar, not an expression)
inline double tire_atan(double x) { return std::atan(x); }
template <class D>
Eigen::AutoDiffScalar<D> tire_atan(const Eigen::AutoDiffScalar<D>& x) {
  const double v = x.value();
  return Eigen::AutoDiffScalar<D>(std::atan(v), D(x.derivatives() * (1.0 / (1.0 + v * v))));
}

// MATLAB's sign: -1, 0 or +1 (a constant: its derivative is 0 where it exists)
template <class S>
double tire_sign(const S& x) {
  const double v = tire_value(x);
  return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
}
// sign that takes 0 as +1 (the guard of MFeval's epsilon terms)
template <class S>
double tire_sign_nz(const S& x) {
  return tire_value(x) < 0 ? -1.0 : 1.0;
}

// The input with one derivative size in all its scalars (unseeded ones get zeros): Eigen's
// AutoDiff adds derivative vectors of unevaluated expressions without making their sizes agree.
inline const TireInput<double>& tire_coherent(const TireInput<double>& in) { return in; }
template <class D>
TireInput<Eigen::AutoDiffScalar<D>> tire_coherent(TireInput<Eigen::AutoDiffScalar<D>> in) {
  Eigen::Index n = 0;
  for (auto* x : {&in.Fz, &in.kappa, &in.alpha, &in.gamma, &in.phit, &in.Vx, &in.pressure})
    n = std::max<Eigen::Index>(n, x->derivatives().size());
  for (auto* x : {&in.Fz, &in.kappa, &in.alpha, &in.gamma, &in.phit, &in.Vx, &in.pressure})
    if (x->derivatives().size() != n) x->derivatives() = D::Zero(n);
  return in;
}

}  // namespace codyna
