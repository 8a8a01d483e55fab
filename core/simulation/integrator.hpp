// Integrators behind one interface, so that benchmarks swap them freely:
//   ida          SUNDIALS IDA (variable-order BDF) on the index-1 DAE form with
//                multipliers as algebraic variables (the paper's residual form)
//   cvode-bdf    SUNDIALS CVODE, BDF with Newton iterations (stiff problems); for closed
//                loops it projects onto the constraints after every step (CVodeSetProjFn)
//   cvode-adams  SUNDIALS CVODE, Adams-Moulton with fixed-point iterations (non-stiff)
//   arkode       SUNDIALS ARKODE ERKStep, adaptive explicit Runge-Kutta (order 4 default); with
//                loops it projects onto the constraints after every step (postprocess hook)
//   rk4          fixed-step classical Runge-Kutta (step = max_step, or 1 ms), the reference
//   alf          index-3 augmented Lagrangian with mass-orthogonal projections, trapezoidal rule with
//                error control (or a fixed step): passes singular positions and redundant constraints
// All advance to an exact output/event time (stop time set, no overshoot) and
// can be reset after a discontinuity (controller sample, projection).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "simulation/closed_loop.hpp"
#include "simulation/result.hpp"

namespace codyna {

struct IntegratorSettings {
  std::string method = "auto";  // auto: chosen per model (simulation/integrator_choice.hpp)
  double rtol = 1e-8, atol = 1e-10;
  double max_step = 0;  // 0 = no limit (rk4: its fixed step, default 1e-3)
  // cvode-bdf / ida: the Newton matrix from the analytic derivatives where the system has them
  // (ClosedLoopSystem::exact_ode_jacobian / exact_dae_jacobian); false: SUNDIALS' difference quotients
  bool exact_jacobian = true;
  // alf: the penalty alpha (> 0; in the units of the generalized forces per constraint violation;
  // used as alpha (10 ms / h)^2 at steps h under 10 ms; 1e11: A02's multipliers converge near the
  // flat position at tolerances to 1e-7, 1e8 stalls there below 1e-4, measured),
  // the most Newton iterations per step, and (alf_fixed_step) every step max_step (default 1 ms)
  // instead of the error control at rtol, atol (simulation/alf.cpp)
  double alf_penalty = 1e11;
  int alf_iterations = 100;
  bool alf_fixed_step = false;
  // alf: each step combined from finer trapezoidal steps (Richardson's extrapolation, the
  // trapezoidal rule's h^2 term cancels, fourth order): at fixed steps the step and its two halves
  // (x2 + (x2 - x1)/3), with error control two halves x1 and four quarters x2 (the same formula;
  // |x2 - x1|/3 the error estimate)
  bool alf_extrapolate = false;
};

// a model file's solver settings as the integrators take them (alf's absent settings: its defaults)
IntegratorSettings integrator_settings(const SolverSpec& solver);

class IntegratorFailure : public std::runtime_error {
 public:
  IntegratorFailure(double t, const std::string& reason) : std::runtime_error(reason), t_(t) {}
  double time() const { return t_; }

 private:
  double t_;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual void reset(double t, const Eigen::VectorXd& y) = 0;  // y in ODE layout [q; v; xc]
  virtual void advance(double t_out) = 0;                       // throws IntegratorFailure
  // to an output time t_out that the integrator may step past (state() is then interpolated at
  // t_out), never past t_stop >= t_out, the next time it must stop at (a controller sample, a
  // jump, the run's end); by default a stop at t_out (alf at fixed steps: its steps do not bend
  // to the outputs)
  virtual void advance_output(double t_out, double t_stop) {
    (void)t_stop;
    advance(t_out);
  }
  virtual Eigen::VectorXd state() const = 0;                    // ODE layout
  virtual bool projects() const { return false; }               // keeps loops on the manifold itself
  virtual void add_stats(SolverStats& s) const = 0;
};

// A plain ODE y' = f(t, y) by ARKODE's explicit Dormand-Prince 5(4) pair (ERKStep) at the given
// tolerances, advanced to exact stop times; reset() after a discontinuity. For the linear
// closed loop of --compare-linear, integrated far below the nonlinear run's tolerances.
class OdeIntegrator {
 public:
  using Rhs = std::function<void(double t, const Eigen::VectorXd& y, Eigen::VectorXd& ydot)>;
  OdeIntegrator(Rhs f, double rtol, double atol);
  ~OdeIntegrator();
  OdeIntegrator(const OdeIntegrator&) = delete;
  OdeIntegrator& operator=(const OdeIntegrator&) = delete;
  void reset(double t, const Eigen::VectorXd& y);
  void advance(double t_out);  // throws IntegratorFailure
  Eigen::VectorXd state() const;
  long steps() const;          // accepted steps since construction

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// the index-3 augmented Lagrangian integrator (simulation/alf.cpp); throws std::invalid_argument
// for a model it does not take or bad settings, naming them
std::unique_ptr<Integrator> make_alf_integrator(ClosedLoopSystem& system, const IntegratorSettings& settings);

// throws std::invalid_argument for an unknown method or bad tolerances, and for "auto", which
// the caller resolves first (choose_integrator)
std::unique_ptr<Integrator> make_integrator(ClosedLoopSystem& system, const IntegratorSettings& settings);

}  // namespace codyna
