// The linear closed loop: a linearized plant and a controller's linear law
// (LinearLaw below; simulation/controller.hpp gives each controller's) as one linear system, with its poles,
// step responses and frequency responses (docs/linearization.md, "The linear
// closed loop").
//
// Plant (deviations from the operating point x0, u0, y0; w: disturbance inputs,
// actuators that are not Plant/In, through their own B and D columns Bw, Dw):
//   dx' = A dx + B du + Bw dw,      dy = C dx + D du + Dw dw
// Controller (LinearLaw; ydot = C_z w is the outputs' rate at constant velocity,
// the z-columns of C times the plant's velocity states):
//   xc' = Ak xc + Bx dx + By dy + Bv ydot + Br dr
//   du  = Ck xc + Dx dx + Dy dy + Dv ydot + Dr dr
// Closed loop, state [dx; xc], inputs [dr; dw] (a reference per Plant/Out output,
// r - y0, then the disturbances), outputs [dy; du] (the Plant/Out outputs, then
// the actuator efforts on Plant/In):
//   d/dt [dx; xc] = Acl [dx; xc] + Bcl [dr; dw],   [dy; du] = Ccl [dx; xc] + Dcl [dr; dw]
// The algebraic loop du = ... + Dy D du is solved exactly ((I - Dy D) must be
// invertible). Sign conventions are the simulation's: PID acts on r - y, state
// feedback is u = u0 - K dx + Nbar (r - y0), an LTI controller sees y - r.
// A sampled controller (Ts > 0) closes the loop around the plant's exact ZOH
// model at Ts: the closed loop is then discrete (Ts recorded), exact at the samples.
// Saturation and anti-windup are not part of it (a linear loop never saturates).
#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "analysis/linear_system.hpp"
#include "analysis/modal.hpp"

namespace codyna {

// A controller as linear maps of deviations, for the linear closed loop
// (close_loop below); saturation and anti-windup are left out:
//   xc' = Ak xc + Bx dx + By dy + Bv ydot + Br dr        (xc[k+1] = ... when Ts > 0)
//   du  = Ck xc + Dx dx + Dy dy + Dv ydot + Dr dr
// dx = x - x0 (plant state), dy = y - y0, dr = r - y0, ydot the outputs' rates at constant
// velocity; every matrix has its full size (zeros where a signal is not used).
struct LinearLaw {
  Eigen::MatrixXd Ak, Bx, By, Bv, Br;  // nxc x (nxc, nx, ny, ny, ny)
  Eigen::MatrixXd Ck, Dx, Dy, Dv, Dr;  // nu x (nxc, nx, ny, ny, ny)
  double Ts = 0.0;                     // > 0: a sampled controller (zero-order hold)
};

struct ClosedLoopLinear {
  // A..D = Acl..Dcl; names: states (plant's, then the controller's), inputs ("r_" + output,
  // then "d_" + actuator), outputs (Plant/Out names, then "u_" + Plant/In name); offsets:
  // x0 = [x0; 0], u0 = [y0; the disturbed actuators' nominal values], y0 = [y0; u0]
  LinearSystem system;
  int nx = 0, nxc = 0;  // plant and controller states
  int nr = 0, nd = 0;   // reference and disturbance inputs
  int ny = 0, nu = 0;   // plant outputs and efforts
  std::string controller;  // the controller's description
};

// Disturbance columns of the plant: Bw (nx x nd), Dw (ny x nd), names and units per column,
// and the disturbed actuators' nominal values.
struct DisturbanceInputs {
  Eigen::MatrixXd Bw, Dw;
  std::vector<std::string> names, units;
  Eigen::VectorXd nominal;
};

// `plant` continuous (Ts = 0), state [z; w] as linearize() orders it (nz = nx / 2). Throws
// std::invalid_argument when the law does not fit the plant or the algebraic loop is singular.
ClosedLoopLinear close_loop(const LinearSystem& plant, const LinearLaw& law, const DisturbanceInputs& w = {},
                            const std::vector<std::string>& controller_state_names = {},
                            const std::string& controller_description = "");

// Step responses: y[j] (N x (ny + nu)) is the response of every output to a unit step on
// input j from rest, at the times t (from 0, equally spaced; for a discrete loop multiples of
// Ts). Exact: the state is advanced by the matrix exponential over each interval.
struct StepResponse {
  std::vector<double> t;
  std::vector<Eigen::MatrixXd> y;  // one per input
};
StepResponse step_response(const LinearSystem& sys, double t_end, int points);

// Frequency responses H(j w) = C (j w I - A)^-1 B + D (continuous) or with z = exp(j w Ts)
// (discrete), at each w (rad/s). magnitude |H|, phase in degrees, unwrapped along w for each
// input-output pair (starting from the principal value at the first frequency).
struct FrequencyResponse {
  std::vector<double> w;
  std::vector<Eigen::MatrixXcd> H;          // one (outputs x inputs) per frequency
  std::vector<Eigen::MatrixXd> magnitude;   // |H|
  std::vector<Eigen::MatrixXd> phase_deg;   // unwrapped
};
FrequencyResponse frequency_response(const LinearSystem& sys, const std::vector<double>& w);

// n frequencies from w_min to w_max, equally spaced in log10 (both ends included)
std::vector<double> log_grid(double w_min, double w_max, int n);

// Defaults from the poles: the step responses last 8 / (the slowest decay rate), kept within
// [1, 1000] s (10 s when no pole decays); the frequencies span a decade below the slowest
// non-zero pole frequency to a decade above the fastest, rounded out to whole decades
// (0.01 .. 100 rad/s when all poles are at 0), capped at the Nyquist frequency when discrete.
double default_step_time(const ModalAnalysis& poles);
std::pair<double, double> default_frequency_range(const ModalAnalysis& poles, double Ts);

}  // namespace codyna
