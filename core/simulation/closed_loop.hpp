// The closed loop as equations an integrator can step:
//   ODE form  y = [q; v; s; xc]         y' = [qdot(q, v); qdd(q, v, s, u); ds/dt; dxc/dt]
//   DAE form  Y = [q; v; s; xc; lambda] F(t, Y, Y') = [q' - qdot(q, v);
//                                                      M v' + nle - Q(u) + Ja^T lambda;
//                                                      s' - ds/dt (q, v, s);
//                                                      dxc/dt residual;
//                                                      Ja v' + gamma + stab]      (index 1)
// (the residual system (3) of the paper, with the output equation evaluated
// separately). u = saturate(controller(y, ...)) on Plant/In, nominal u0 on the
// other actuators. s: the effect states (Model::ns, a tire's transient slip). xc holds only
// continuous controller states; a discrete
// controller's state and held output live in the simulator.
// Not thread-safe: one ClosedLoopSystem per simulation (it owns a Data).
#pragma once

#include <atomic>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>

#include "analysis/plant_function.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/data.hpp"
#include "spatial/autodiff.hpp"
#include "simulation/controller.hpp"

namespace codyna {

class ClosedLoopSystem {
 public:
  // plant: the linearization's plant function (needed by state feedback); x_ref: its state at the
  // operating point ([0; w_ref]), so that state feedback sees x - x0
  ClosedLoopSystem(const Model& model, const Controller* controller, const PlantFunction* plant,
                   const Eigen::VectorXd& x_ref, const Eigen::VectorXd& u_nominal, Baumgarte stab = {});

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }
  int nxc() const { return continuous_states_; }
  int ns() const { return model_.ns; }
  int na() const { return static_cast<int>(model_.active_rows.size()); }
  int ode_size() const { return nq() + nv() + ns() + nxc(); }
  // The effect states the next measure() and inputs() see (a state's s; rhs and residual set them
  // from their y). Needed before measuring at a recorded sample when ns() > 0.
  void set_effect_states(const Eigen::VectorXd& s) const { data_.s = s; }
  int dae_size() const { return ode_size() + na(); }
  const Model& model() const { return model_; }

  // the Plant/In values held until changed: by a discrete controller at its samples,
  // or from outside when there is no controller (co-simulation, Stepper)
  void set_held(const Eigen::VectorXd& u_plant) { held_ = u_plant; }
  // A second controller beside the first, sampled (SimulationOptions::beside): the actuators it
  // sets (Model::actuators indices, none of them a Plant/In the first controller drives) take the
  // values it holds (plus a disturbance on them), set at its samples; a motion input among them
  // rests between its samples (zero-order hold) as under a sampled controller
  void set_beside(std::vector<int> actuators) { beside_actuators_ = std::move(actuators); }
  void set_beside_held(const Eigen::VectorXd& u) { beside_held_ = u; }
  // r(t) for the Plant/Out outputs, handed to the controller (empty: its own setpoint)
  void set_reference(std::function<Eigen::VectorXd(double)> r) { reference_ = std::move(r); }
  // d(t) added to the actuators' nominal values (one entry per actuator, Model::actuators;
  // the Plant/In entries are replaced by the controller's output anyway)
  void set_disturbance(std::function<Eigen::VectorXd(double)> d) { disturbance_ = std::move(d); }
  // motion inputs moved by the disturbance: its rate and acceleration (SimulationOptions)
  void set_disturbance_rates(std::function<Eigen::VectorXd(double)> rate, std::function<Eigen::VectorXd(double)> acc) {
    disturbance_rate_ = std::move(rate);
    disturbance_acceleration_ = std::move(acc);
  }
  // Motion inputs (Model::motions): their coordinates in q, v set to the prescribed u(t), u'(t)
  // (u0 plus the disturbance, or the held Plant/In value at rest), their accelerations u''(t)
  // into the Data rhs() uses, and into `acc` when given. Nothing without motion inputs.
  void apply_motions(double t, Eigen::VectorXd& q, Eigen::VectorXd& v, Eigen::VectorXd* acc = nullptr);
  // the motions' rates at t (Model::motions order; 0 where no disturbance moves them)
  Eigen::VectorXd motion_rates(double t) const;

  ControllerInput measure(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  // every actuator's value at a state (controller output on Plant/In, saturated)
  Eigen::VectorXd inputs(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& xc) const;

  // A flag the caller sets to stop: rhs() and residual() then throw (the integrator stops inside
  // its step, however long the step: a stiff run's output interval may take minutes); the caller
  // tells the cancellation from a failure by the flag. A second flag (`stop`, may be null) is polled
  // the same way: a front end's Cancel and the caller's own reason to end a run stay apart.
  void set_cancel(const std::atomic<bool>* cancel, const std::atomic<bool>* stop = nullptr) {
    cancel_ = cancel;
    stop_ = stop;
  }

  void rhs(double t, const Eigen::VectorXd& y, Eigen::VectorXd& ydot);
  void residual(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& Yp, Eigen::VectorXd& F);
  // from an ODE-layout y: the DAE's consistent Y (with lambda) and Y'
  void consistent(double t, const Eigen::VectorXd& y, Eigen::VectorXd& Y, Eigen::VectorXd& Yp);
  // the DAE form's constraint rows (chosen in consistent()) have become ill-conditioned
  // at q compared with the best choice: the integrator should be reset
  bool rows_degraded(const Eigen::VectorXd& q);
  // back onto phi = 0, Jc v = 0 if the violation exceeds tol; returns whether it moved. The motion
  // inputs' coordinates are held: at their prescribed u(t), u'(t) when t is given (not NaN), else
  // where y has them
  bool project(Eigen::VectorXd& y, double tol, double t = std::numeric_limits<double>::quiet_NaN());
  // removes from a state-space vector e (ODE layout, e.g. an error estimate) its components
  // normal to the constraint manifold at y: Jc e_v = 0 and, where q is additive, Jc e_q = 0
  void project_tangent(const Eigen::VectorXd& y, Eigen::VectorXd& e);
  // max |phi|, max |Jc v|
  std::pair<double, double> violation(const Eigen::VectorXd& q, const Eigen::VectorXd& v);

  long evaluations() const { return evaluations_; }

  // Exact Jacobians from the analytic derivatives (dynamics/derivatives.hpp), for the implicit
  // integrators' Newton matrices. Available when u does not depend on the state inside a step
  // (no controller, or a discrete one whose output is held) and, for the ODE form of closed
  // loops, without Baumgarte stabilization; otherwise false and SUNDIALS difference-quotients.
  bool exact_ode_jacobian() const;
  bool exact_dae_jacobian() const;
  // d ydot / d y of rhs() [ode_size x ode_size]. Closed loops: the derivative of the
  // accelerations on the independent rows at q; rhs() drops near-singular directions of the
  // Schur complement on all rows, so near a singular configuration this is an approximation
  // (good enough for a Newton matrix). Returns false when not available.
  bool ode_jacobian(double t, const Eigen::VectorXd& y, Eigen::MatrixXd& J);
  // dF/dY + cj dF/dY' of residual() [dae_size x dae_size] (rows chosen by consistent())
  bool dae_jacobian(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& Yp, double cj, Eigen::MatrixXd& J);

  // the controller's state equation, told the Plant/In values applied (after saturation) in u
  // (the effect states measured are those set last: set_effect_states)
  Eigen::VectorXd controller_rates(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                   const Eigen::VectorXd& xc, const Eigen::VectorXd& u) const;

 private:
  Eigen::VectorXd saturate(Eigen::VectorXd u_all) const;
  // the beside controller's held values into u (one entry per actuator), d its disturbance (or empty)
  void apply_beside(Eigen::VectorXd& u, const Eigen::VectorXd& d) const;

  const Model& model_;
  const Controller* controller_;
  const PlantFunction* plant_;
  Eigen::VectorXd x_ref_, u_nominal_;
  std::optional<Eigen::VectorXd> held_;
  std::vector<int> beside_actuators_;
  Eigen::VectorXd beside_held_;
  std::function<Eigen::VectorXd(double)> reference_, disturbance_, disturbance_rate_, disturbance_acceleration_;
  Baumgarte stab_;
  int continuous_states_ = 0;
  std::vector<int> rows_;  // DAE form: constraint rows carrying multipliers
  mutable Data data_;
  mutable std::unique_ptr<DataT<ADScalar>> ad_data_;  // output rates (PD), made on first use
  long evaluations_ = 0;
  const std::atomic<bool>* cancel_ = nullptr;
  const std::atomic<bool>* stop_ = nullptr;
  void check_cancel() const {
    if ((cancel_ && cancel_->load(std::memory_order_relaxed)) || (stop_ && stop_->load(std::memory_order_relaxed)))
      throw std::runtime_error("cancelled");
  }
  // exact Jacobians: made on first use
  std::unique_ptr<TreeDerivatives> deriv_;
  Eigen::MatrixXd tangent_map_;  // [nv x nq] d(tangent)/dq at the last q
  Eigen::MatrixXd qdot_dq_, qdot_dv_;  // [nq x nq], [nq x nv]
  Eigen::VectorXd lambda_full_;
  void kinematic_jacobians(const Eigen::VectorXd& q, const Eigen::VectorXd& v);
};

}  // namespace codyna
