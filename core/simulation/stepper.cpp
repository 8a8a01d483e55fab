#include "simulation/stepper.hpp"

#include <cmath>
#include <sstream>

#include "dynamics/assembly.hpp"
#include "dynamics/effects.hpp"
#include "simulation/integrator_choice.hpp"

namespace codyna {

Stepper::Stepper(const Model& model, const IntegratorSettings& settings, double projection_tolerance)
    : model_(model), projection_tolerance_(projection_tolerance),
      sys_(model, nullptr, nullptr, Eigen::VectorXd(), model.u_nominal()) {
  set_state(0.0, {}, {});
  settings_ = settings;
  chosen_ = settings.method == "auto";
  if (chosen_) {  // chosen at the model's initial state; a stepped run has no length: 1 s
    const IntegratorChoice choice = choose_integrator(sys_, t_, y_, 1.0, settings_.rtol);
    apply_choice(choice, settings_);
    extra_.integrator_choice = choice.reason;
  }
  integrator_ = make_integrator(sys_, settings_);
  extra_.integrator = settings_.method;
  extra_.rtol = settings.rtol;
  extra_.atol = settings.atol;
  extra_.max_step = settings.max_step;
  integrator_->reset(t_, y_);
  measure();
}

void Stepper::set_state(double t0, const Eigen::VectorXd& q_in, const Eigen::VectorXd& v_in) {
  Eigen::VectorXd q = q_in.size() ? q_in : model_.q0, v = v_in.size() ? v_in : model_.v0;
  if (q.size() != model_.nq || v.size() != model_.nv)
    throw std::invalid_argument("stepper: the state has the wrong size (nq = " + std::to_string(model_.nq) +
                                ", nv = " + std::to_string(model_.nv) + ")");
  if (model_.nc) {
    const AssemblyResult a = assemble(model_, q, v);
    if (!a.converged) throw std::invalid_argument("stepper: the state cannot be assembled onto the loop closures");
    q = a.q;
    v = a.v;
  }
  t_ = t0;
  y_.resize(sys_.ode_size());
  Data d(model_);
  y_ << q, v, effect_states_steady(model_, d, q, v);  // the effect states at rest there
  Eigen::VectorXd u(nu());
  for (int k = 0; k < nu(); ++k) u[k] = model_.actuators[model_.plant_inputs[k]].u0;
  sys_.set_held(u);
}

void Stepper::reset(double t0, const Eigen::VectorXd& q_in, const Eigen::VectorXd& v_in) {
  set_state(t0, q_in, v_in);
  integrator_->reset(t_, y_);
  measure();
}

void Stepper::measure() {
  sys_.set_effect_states(y_.segment(model_.nq + model_.nv, model_.ns));
  out_ = sys_.measure(t_, q(), v()).y;
}

const Eigen::VectorXd& Stepper::step(const Eigen::VectorXd& u, double dt) {
  if (u.size() != nu()) {
    std::ostringstream os;
    os << "stepper: expected " << nu() << " Plant/In values, got " << u.size();
    throw std::invalid_argument(os.str());
  }
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("stepper: the step must be a positive time");
  if (!u.allFinite()) throw std::invalid_argument("stepper: the inputs must be finite");
  sys_.set_held(u);
  integrator_->reset(t_, y_);  // the inputs jump: a discontinuity for the integrator
  ++extra_.restarts;
  try {
    integrator_->advance(t_ + dt);
  } catch (const IntegratorFailure& f) {
    if (!chosen_ || settings_.method == kAutoFallbackIntegrator || (cancel_ && cancel_->load())) throw;
    // auto's choice failed as the run turned stiff: this step again from its start, stiff
    extra_.integrator_choice += auto_fallback_note(settings_.method, f.time(), f.what(), t_);
    integrator_->add_stats(extra_);
    settings_.method = kAutoFallbackIntegrator;
    extra_.integrator = settings_.method;
    extra_.integrator_fell_back = true;
    integrator_ = make_integrator(sys_, settings_);
    integrator_->reset(t_, y_);
    integrator_->advance(t_ + dt);
  }
  t_ += dt;
  y_ = integrator_->state();
  if (model_.nc && !integrator_->projects() && sys_.project(y_, projection_tolerance_, t_)) ++extra_.projections;
  measure();
  return out_;
}

SolverStats Stepper::stats() const {
  SolverStats s = extra_;
  integrator_->add_stats(s);
  return s;
}

}  // namespace codyna
