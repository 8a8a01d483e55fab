// modal_analysis: eigenvalues and mode shapes of a LinearSystem's A.
//
// Continuous (Ts = 0): frequency and damping come from the eigenvalue lambda.
// Discrete (Ts > 0): the eigenvalue z is kept as `eigenvalue`; frequency and
// damping come from the equivalent continuous eigenvalue s = log(z) / Ts
// (principal branch, so frequencies above Nyquist fold back).
//
//   natural_frequency = |s|  (rad/s)
//   damping_ratio     = -Re(s) / |s|   (1: real negative, -1: real positive;
//                       -1 for s = 0, as damp() in MATLAB and Octave reports it)
//
// Cost: one dense nonsymmetric eigen decomposition, O(nx^3).
#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "analysis/linear_system.hpp"
#include "analysis/stability.hpp"

namespace codyna {

struct Mode {
  std::complex<double> eigenvalue;     // lambda (continuous) or z (discrete)
  std::complex<double> s;              // continuous equivalent: lambda, or log(z)/Ts
  double natural_frequency = 0.0;      // rad/s, |s|
  double damping_ratio = 0.0;          // -Re(s)/|s|
  Eigen::VectorXcd shape;              // nx; largest |entry| = 1, made real and positive
  Stability stability = Stability::Stable;  // of `eigenvalue` (analysis/stability.hpp, the one rule)
};

struct ModalAnalysis {
  std::vector<Mode> modes;              // sorted by natural frequency, then Im(s), then Re(s)
  std::vector<std::string> state_names; // nx, as in the system
  double Ts = 0.0;                      // 0: continuous
  double stability_tolerance = 1e-9;    // stability_tolerance(A): what Mode::stability was decided with
  // The eigenvalue s = 0 (z = 1 when discrete): a rigid-body motion or an integrator. Its
  // multiplicity is the dimension of the generalized null space of A (of A - I), found by
  // growing null(A), then {x : A x in it}, ... with a rank tolerance of 1e-9 max(1, max|A_ij|):
  // a repeated zero's computed eigenvalues scatter by eps^(1/k) and its eigenvectors are
  // arbitrary within that space, so the modes[0 .. zero_count) (the smallest) stand for it
  // together, and `zero_states` lists the states that lie mostly in it (squared projection
  // >= 0.5), in state order.
  int zero_count = 0;
  std::vector<int> zero_states;
};

// Throws std::invalid_argument if A is not square or has NaN/Inf entries.
ModalAnalysis modal_analysis(const LinearSystem& sys);

// How many modes Mode::stability calls stable, marginal, unstable (what a verdict says)
PoleCount count_stability(const ModalAnalysis& m);

// A readable table: eigenvalue, frequency (rad/s and Hz), damping, and the
// dominant states of each mode shape (|entry| >= 0.5, largest first). The zero
// eigenvalue is one row for all its modes ("1-12  0 (x12)") with the states of its
// generalized eigenspace, and its damping, undefined, is printed "-" (the value kept
// in Mode::damping_ratio is damp()'s -1).
std::string format_modes(const ModalAnalysis& m);

}  // namespace codyna
