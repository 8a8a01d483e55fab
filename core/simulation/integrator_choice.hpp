// The default integrator, "auto": chosen per model and initial state from the
// eigenvalues of the closed loop's Jacobian d ydot / d y there (ODE form, central
// differences), by the rule that was fastest at equal accuracy on the reference
// problems of the work-precision study (docs/work-precision.md, "The default integrator"):
//   stiff (a decay rate at least 100 times every other rate of the motion and 1 / span)
//     at rtol >= kAlfLooseRtol         -> alf, extrapolated (alf_extrapolate)
//     tighter (or rolling constraints) -> cvode-bdf
//   not stiff, a tree                  -> cvode-adams
//   not stiff, closed loops            -> arkode (explicit Runge-Kutta, projected every step)
// Models with more than kMaxAnalysed states are not analysed (their eigenvalues would cost
// more than a short run) and are taken as not stiff; the reason says so.
#pragma once

#include <Eigen/Core>
#include <string>

#include "simulation/closed_loop.hpp"
#include "simulation/integrator.hpp"

namespace codyna {

struct IntegratorChoice {
  std::string method;             // one of cvode-bdf, cvode-adams, arkode, alf
  bool alf_extrapolate = false;   // alf: with Richardson's extrapolation (the only way auto takes it)
  std::string reason;             // one line, for the run's log and results
  double fastest_decay = 0;       // max -Re(lambda) [1/s]
  double slow_rate = 0;           // max |lambda| of the other modes, or 1 / span [1/s]
  bool stiff = false, analysed = false;
};

constexpr int kMaxAnalysed = 600;

// The tightest accuracy where alf, extrapolated, wins on stiff models (docs/work-precision.md,
// "Twelfth round"): at rtol 1e-2 to 1e-4 on IFToMM's flyball (A05, a tree) and the K&C rig
// (closed loops), the only stiff examples, it takes 0.6 to 1.6 times cvode-bdf's time at the same
// rtol for errors 300 to 10000 times smaller, and is the faster of the two at equal error.
// Tighter, its error control gives far more than is asked, at up to 15 times the time (A05 at
// 1e-8), so cvode-bdf stays.
constexpr double kAlfLooseRtol = 1e-4;

// apply a choice to the settings the run's integrator is made from
void apply_choice(const IntegratorChoice& c, IntegratorSettings& s);

// What "auto" does when the method it chose fails during the run (a run that turns stiff after
// its start, e.g. tires that begin to slide): it goes on from the last state reached with this
// stiff method, and the run's integrator_choice says so (auto_fallback_note).
inline constexpr const char* kAutoFallbackIntegrator = "cvode-bdf";
std::string auto_fallback_note(const std::string& failed, double t_failed, const std::string& why, double t_from);

// y: the ODE-layout state [q; v; xc] at time t (on the constraints); span: the run's length;
// rtol: the run's relative tolerance
IntegratorChoice choose_integrator(ClosedLoopSystem& sys, double t, const Eigen::VectorXd& y, double span, double rtol);

}  // namespace codyna
