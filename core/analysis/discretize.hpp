// discretize_zoh: the exact zero-order-hold discretization of a continuous
// LinearSystem with sample time Ts.
//
//   exp([A B; 0 0] Ts) = [Ad Bd; 0 I]      (Van Loan; one matrix exponential)
//   x[k+1] = Ad x[k] + Bd u[k],  y[k] = C x[k] + D u[k]
//
// C, D, names, units, offsets and provenance are copied; Ts is recorded.
// xdot0 keeps the continuous derivative at the operating point: away from
// equilibrium the discrete map has the affine term (integral_0^Ts exp(A s) ds) xdot0,
// which is not folded into Ad or Bd.
// Cost: one (nx+nu)^2 matrix exponential, O((nx+nu)^3).
#pragma once

#include "analysis/linear_system.hpp"

namespace codyna {

// Throws std::invalid_argument if Ts is not positive and finite, if `c` is
// already discrete (c.Ts > 0), or if A, B do not fit together.
LinearSystem discretize_zoh(const LinearSystem& c, double Ts);

}  // namespace codyna
