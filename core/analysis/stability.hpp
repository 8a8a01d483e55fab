// stability: the one rule that says whether a pole, and a system, is stable. Every front end
// shows what this says (the CLI's warnings, the GUI's pole map and mode table, the sweep's
// count, Python's flags); none decides it again.
//
// A pole's margin is Re(s) for a continuous system and |z| - 1 for a discrete one. Computed
// eigenvalues carry round-off of about eps ||A||, so a pole within
//     tolerance = 1e-9 max(1, ||A||_F)
// of the boundary is marginal (a rigid-body mode, an integrator, a pure oscillation: not
// asymptotically stable, not growing either); beyond it on the stable side it is stable, on
// the other side unstable. A system is asymptotically stable when every pole is stable.
// modal_analysis (analysis/modal.hpp) applies this rule to each mode, and also calls marginal
// the modes that stand for a repeated s = 0 (their computed eigenvalues scatter by eps^(1/k)).
#pragma once

#include <Eigen/Core>
#include <complex>

namespace codyna {

enum class Stability { Stable, Marginal, Unstable };

const char* to_string(Stability s);  // "stable", "marginal", "unstable"

// 1e-9 max(1, ||A||_F)
double stability_tolerance(const Eigen::MatrixXd& A);

// the class of one pole (s, or z when `discrete`) against `tolerance` (stability_tolerance(A))
Stability classify_pole(std::complex<double> pole, bool discrete, double tolerance);

struct PoleCount {
  int stable = 0, marginal = 0, unstable = 0;
  bool asymptotically_stable() const { return marginal == 0 && unstable == 0; }
};
PoleCount classify_poles(const Eigen::VectorXcd& poles, bool discrete, double tolerance);

// the poles of `poles` that classify_pole calls unstable, in their order
Eigen::VectorXcd unstable_poles(const Eigen::VectorXcd& poles, bool discrete, double tolerance);

}  // namespace codyna
