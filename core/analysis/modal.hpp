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

namespace codyna {

struct Mode {
  std::complex<double> eigenvalue;     // lambda (continuous) or z (discrete)
  std::complex<double> s;              // continuous equivalent: lambda, or log(z)/Ts
  double natural_frequency = 0.0;      // rad/s, |s|
  double damping_ratio = 0.0;          // -Re(s)/|s|
  Eigen::VectorXcd shape;              // nx; largest |entry| = 1, made real and positive
};

struct ModalAnalysis {
  std::vector<Mode> modes;              // sorted by natural frequency, then Im(s), then Re(s)
  std::vector<std::string> state_names; // nx, as in the system
  double Ts = 0.0;                      // 0: continuous
};

// Throws std::invalid_argument if A is not square or has NaN/Inf entries.
ModalAnalysis modal_analysis(const LinearSystem& sys);

// A readable table: eigenvalue, frequency (rad/s and Hz), damping, and the
// dominant states of each mode shape (|entry| >= 0.5, largest first).
std::string format_modes(const ModalAnalysis& m);

}  // namespace codyna
