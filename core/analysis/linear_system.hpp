// LinearSystem: a plant linearized about an operating point, with everything
// that must travel with the matrices (names, units, offsets, provenance).
//   dx = A x + B u,  y = C x + D u   (deviations: x = x0 + dx, u = u0 + du, y = y0 + dy)
// Ts = 0 means continuous time; Ts > 0 means the discrete map x[k+1] = A x[k] + B u[k]
// obtained by an exact zero-order hold with sample time Ts.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace codyna {

struct LinearSystem {
  Eigen::MatrixXd A, B, C, D;
  Eigen::VectorXd x0, u0, y0, xdot0;
  double Ts = 0.0;
  // the position states z, first in x = [z; w]: nx / 2, or fewer velocities w with rolling's
  // non-holonomic rows (-1: not known, nx / 2). zdot = A_zw w about the operating point
  int positions = -1;
  int npositions() const { return positions >= 0 ? positions : nx() / 2; }
  std::vector<std::string> state_names, input_names, output_names;
  std::vector<std::string> state_units, input_units, output_units;
  // Motion inputs among the inputs: the realization without their rates keeps the model proper by
  // shifting states, x = xi + state_shift du + state_rate_shift du' (deviations; x the physical
  // coordinates and rates, xi the state of A, B, C, D). Each row the shift touches is named with
  // a trailing '~' ("X2_dot~" is X2_dot - (b2/m2) W, not the wheel's velocity): state_meaning says
  // what it is. Both [nx x nu], empty without motion inputs.
  Eigen::MatrixXd state_shift, state_rate_shift;

  // provenance
  std::string model_name;        // as in the model file
  std::string model_file;        // path it was loaded from, if any
  std::string operating_point;   // e.g. "initial", "equilibrium", "trim", "time=1.5"
  std::string method;            // "exact", "fd-forward", "fd-central"
  double time = 0.0;             // time of the operating point
  std::string codyna_version;
  // the study choices that define this plant (JSON: operating_point, set, independent,
  // disabled_effects), exported as codyna_study so that a controller saved with it comes
  // back to the same plant; "" when the plant was not linearized through a study
  std::string study;
  // numbers read at the operating point that travel with the plant, name -> value in SI units
  // (the handling numbers of a car at a steady motion: analysis/handling.hpp); exported as the
  // struct `handling` of NAME.mat when there are any
  std::vector<std::pair<std::string, double>> handling;

  bool shifted(int i) const;  // state i is a shifted one (its name ends in '~')
  int nx() const { return static_cast<int>(A.rows()); }
  int nu() const { return static_cast<int>(B.cols()); }
  int ny() const { return static_cast<int>(C.rows()); }
};

// What state i is, in words of the physical coordinates and the inputs: "X2_dot - 46.9375 W"
// (and "- c W'" for a rate term) for a shifted state, "" for one that is what its name says.
std::string state_meaning(const LinearSystem& s, int i);

}  // namespace codyna
