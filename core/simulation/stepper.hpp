// Stepper: the nonlinear plant stepped from outside, for co-simulation (a MEX
// gateway stepping it from Octave/MATLAB as the paper's S-function did, a GUI's
// interactive mode). The caller holds the Plant/In values constant over each
// step (zero-order hold) and reads the Plant/Out values at its end; the other
// actuators stay at their nominal u0. Loops are kept on the constraint manifold
// as in simulate(). One Stepper per thread.
#pragma once

#include <atomic>
#include <memory>

#include "simulation/closed_loop.hpp"
#include "simulation/integrator.hpp"

namespace codyna {

class Stepper {
 public:
  Stepper(const Model& model, const IntegratorSettings& settings, double projection_tolerance = 1e-9);

  // back to a state (assembled onto the loops); empty q/v = the model's initial state
  void reset(double t0 = 0.0, const Eigen::VectorXd& q = {}, const Eigen::VectorXd& v = {});
  // advances by dt > 0 with Plant/In values u held; returns the Plant/Out values at the end
  // throws IntegratorFailure (the state stays at the last successful step) or std::invalid_argument
  const Eigen::VectorXd& step(const Eigen::VectorXd& u, double dt);

  double time() const { return t_; }
  Eigen::VectorXd q() const { return y_.head(model_.nq); }
  Eigen::VectorXd v() const { return y_.segment(model_.nq, model_.nv); }
  const Eigen::VectorXd& outputs() const { return out_; }
  int nu() const { return static_cast<int>(model_.plant_inputs.size()); }
  int ny() const { return static_cast<int>(model_.plant_outputs.size()); }
  SolverStats stats() const;
  // a front end's Cancel (may be null): seen inside the integrator's steps; step() then throws
  // IntegratorFailure, and the caller tells it from a failure by the flag
  void set_cancel(const std::atomic<bool>* cancel) {
    cancel_ = cancel;
    sys_.set_cancel(cancel);
  }

 private:
  void measure();
  // t_, y_ (assembled onto the loops) and the held nominal inputs; no integrator reset
  void set_state(double t0, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

  const Model& model_;
  double projection_tolerance_;
  ClosedLoopSystem sys_;
  std::unique_ptr<Integrator> integrator_;
  IntegratorSettings settings_;  // the method in use (auto's choice, then its fallback)
  bool chosen_ = false;          // by auto
  Eigen::VectorXd y_, out_;
  double t_ = 0;
  SolverStats extra_;
  const std::atomic<bool>* cancel_ = nullptr;
};

}  // namespace codyna
