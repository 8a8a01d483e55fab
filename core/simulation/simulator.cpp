#include "simulation/simulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "simulation/integrator_choice.hpp"

namespace codyna {

namespace {

// the samples recorded so far, grown row by row
struct Recorder {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, v, u, y, xc, s;
  std::vector<double> T, V, pv, vv;
  std::vector<Eigen::VectorXd> y_linear;
  std::vector<Eigen::VectorXd> r, d;  // reference and disturbance at each sample (when the run has them)

  static Eigen::MatrixXd stack(const std::vector<Eigen::VectorXd>& rows, Eigen::Index cols) {
    Eigen::MatrixXd M(static_cast<Eigen::Index>(rows.size()), cols);
    if (cols == 0) return M;  // no data to take rows of (row() of a null buffer is pointer arithmetic on null)
    for (std::size_t i = 0; i < rows.size(); ++i) M.row(i) = rows[i].transpose();
    return M;
  }
};

// the linear closed loop: dx' = xdot0 + A dx + B du, y = y0 + C dx + D du, same controller,
// integrated by ARKODE's Dormand-Prince 5(4) at (rtol, atol), restarted at every controller
// sample (the held input jumps there)
std::vector<Eigen::VectorXd> linear_run(const Model& model, const Controller* ctrl, const LinearPlant& plant,
                                        const std::vector<double>& times, const Eigen::VectorXd& dx0,
                                        const std::function<Eigen::VectorXd(double)>& reference,
                                        const std::function<Eigen::VectorXd(double)>& disturbance,
                                        const std::function<Eigen::VectorXd(double)>& disturbance_rate, double rtol,
                                        double atol, std::string& failure) {
  double now = times.front();  // the time the stages below are evaluated at (for the reference)
  const LinearSystem& s = plant.lin.system;
  const int nx = s.nx(), nz = s.npositions();
  const bool discrete = ctrl && ctrl->sample_time() > 0;
  const int nxc = ctrl ? ctrl->nxc() : 0;
  Eigen::VectorXd held = s.u0, xcd = Eigen::VectorXd::Zero(discrete ? nxc : 0);
  const int nd = disturbance ? static_cast<int>(plant.disturbance_actuators.size()) : 0;
  // the disturbance inputs at `now`, through their B and D columns
  auto dw = [&]() {
    Eigen::VectorXd d(nd);
    if (nd == 0) return d;
    const Eigen::VectorXd all = disturbance(now);
    for (int k = 0; k < nd; ++k) d[k] = all[plant.disturbance_actuators[k]];
    return d;
  };
  // disturbed motion inputs: the controller sees the mechanism's state x = xi + Fw w + Fw_rate w'
  const bool shifted = nd > 0 && plant.Fw.cols() == nd;
  auto shift = [&]() {
    Eigen::VectorXd x = plant.Fw * dw();
    if (disturbance_rate && plant.Fw_rate.cols() == nd) {
      const Eigen::VectorXd all = disturbance_rate(now);
      Eigen::VectorXd r(nd);
      for (int k = 0; k < nd; ++k) r[k] = all[plant.disturbance_actuators[k]];
      x += plant.Fw_rate * r;
    }
    return x;
  };
  auto measure = [&](const Eigen::VectorXd& dx, const Eigen::VectorXd& du) {
    ControllerInput in;
    in.t = now;
    if (reference) in.r = reference(now);
    in.y = s.y0 + s.C * dx + s.D * du;
    if (nd) in.y += plant.Dw * dw();
    Eigen::VectorXd rate = Eigen::VectorXd::Zero(nx);  // constant-velocity rate, as for the nonlinear plant
    if (2 * nz == nx) rate.head(nz) = dx.tail(nz) + s.xdot0.head(nz);
    else rate.head(nz) = s.A.topRightCorner(nz, nx - nz) * dx.tail(nx - nz) + s.xdot0.head(nz);  // rolling
    in.ydot = s.C * rate;
    in.x = shifted ? Eigen::VectorXd(dx + shift()) : dx;
    return in;
  };
  auto input = [&](const Eigen::VectorXd& dx, const Eigen::VectorXd& xc) -> Eigen::VectorXd {
    if (!ctrl) return s.u0;
    Eigen::VectorXd u = discrete ? held : ctrl->output(measure(dx, Eigen::VectorXd::Zero(s.nu())), xc);
    for (int k = 0; k < s.nu(); ++k) {
      const ActuatorModel& a = model.actuators[model.plant_inputs[k]];
      u[k] = std::clamp(u[k], a.min, a.max);
    }
    return u;
  };
  const int nc = discrete ? 0 : nxc;
  auto f = [&](const Eigen::VectorXd& z) {
    const Eigen::VectorXd dx = z.head(nx), xc = z.tail(nc);
    const Eigen::VectorXd du = input(dx, xc) - s.u0;
    Eigen::VectorXd r(nx + nc);
    r.head(nx) = s.xdot0 + s.A * dx + s.B * du;
    if (nd) r.head(nx) += plant.Bw * dw();
    if (nc) {
      ControllerInput in = measure(dx, du);
      in.u = s.u0 + du;  // the inputs applied (saturated), for anti-windup
      r.tail(nc) = ctrl->update(in, xc);
    }
    return r;
  };
  Eigen::VectorXd z = Eigen::VectorXd::Zero(nx + nc);
  z.head(nx) = dx0;
  if (shifted) z.head(nx) -= shift();
  std::vector<Eigen::VectorXd> out;
  double t = times.front(), next_sample = t;
  const double Ts = discrete ? ctrl->sample_time() : 0;
  auto sample = [&]() {
    const ControllerInput in = measure(z.head(nx), held - s.u0);
    held = ctrl->output(in, xcd);
    xcd = ctrl->update(in, xcd);
    next_sample += Ts;
  };
  if (discrete) sample();
  auto record = [&]() {
    Eigen::VectorXd y = s.y0 + s.C * z.head(nx) + s.D * (input(z.head(nx), z.tail(nc)) - s.u0);
    if (nd) y += plant.Dw * dw();
    out.push_back(y);
  };
  record();
  OdeIntegrator ode(
      [&](double tt, const Eigen::VectorXd& zz, Eigen::VectorXd& zd) {
        now = tt;
        zd = f(zz);
      },
      rtol, atol);
  ode.reset(t, z);
  for (std::size_t i = 1; i < times.size(); ++i) {
    while (t < times[i] - 1e-12) {
      const double target = discrete ? std::min(times[i], next_sample) : times[i];
      try {
        ode.advance(target);
      } catch (const IntegratorFailure& e) {
        // an unstable linear loop grows without bound: the rest of the comparison is not a number
        failure = "the linear closed loop could not be integrated past t = " + std::to_string(e.time()) + " s (" + e.what() + ")";
        while (out.size() < times.size()) out.push_back(Eigen::VectorXd::Constant(s.ny(), std::nan("")));
        return out;
      }
      z = ode.state();
      t = target;
      now = t;
      if (discrete && t >= next_sample - 1e-12) {
        sample();
        ode.reset(t, z);
      }
    }
    now = t;
    record();
  }
  return out;
}

}  // namespace

Model held_at(const Model& model, const OperatingPoint& op, SimulationOptions& options) {
  if (op.q.size() != model.nq || op.v.size() != model.nv || op.u.size() != model.nu())
    throw std::invalid_argument("held_at: the operating point does not belong to the model");
  Model run = model;
  for (std::size_t k = 0; k < run.actuators.size(); ++k) run.actuators[k].u0 = op.u[static_cast<Eigen::Index>(k)];
  options.q0 = op.q;
  options.v0 = op.v;
  options.s0 = op.s;
  return run;
}

SimulationResult simulate(const Model& model, const Controller* controller, const LinearPlant* plant,
                          const SimulationOptions& o, const SimulationCallbacks& cb) {
  if (!std::isfinite(o.t0) || !std::isfinite(o.t_end) || !(o.t_end > o.t0))
    throw std::invalid_argument("simulate: the end time must be a finite number after the start time");
  if (!std::isfinite(o.output_step) || !(o.output_step > 0))
    throw std::invalid_argument("simulate: the output step must be a finite number > 0");
  // the work is bounded before it starts: a run that would not end or not fit is refused with the numbers
  const double samples = (o.t_end - o.t0) / o.output_step + 1;
  if (samples > o.max_samples) {
    std::ostringstream os;
    os << "simulate: " << (o.t_end - o.t0) << " s at an output step of " << o.output_step << " s would record "
       << samples << " samples, more than the limit of " << o.max_samples
       << " (raise the output step, or the limit: --max-samples)";
    throw std::invalid_argument(os.str());
  }
  const IntegratorSettings& is = o.integrator;
  if (!(is.rtol > 0 && is.rtol < 1) || !(is.atol > 0 && std::isfinite(is.atol)))
    throw std::invalid_argument("simulate: tolerances must be finite: rtol in (0, 1), atol > 0");
  if (!(is.max_step >= 0) || !std::isfinite(is.max_step))
    throw std::invalid_argument("simulate: the largest step must be a finite number >= 0 (0 = no limit)");
  if (is.max_step > 0 && (o.t_end - o.t0) / is.max_step > 1e9) {
    std::ostringstream os;
    os << "simulate: a largest step of " << is.max_step << " s over " << (o.t_end - o.t0) << " s means at least "
       << (o.t_end - o.t0) / is.max_step << " steps (more than 1e9): raise the step (--max-step)";
    throw std::invalid_argument(os.str());
  }
  if (controller && controller->sample_time() > 0 && (o.t_end - o.t0) / controller->sample_time() > o.max_samples * 100.0) {
    std::ostringstream os;
    os << "simulate: the controller's sample time " << controller->sample_time() << " s gives "
       << (o.t_end - o.t0) / controller->sample_time() << " samples over the run, more than 100 times the sample limit of "
       << o.max_samples << " (raise the sample time, or the limit: --max-samples)";
    throw std::invalid_argument(os.str());
  }
  if (model.dof() == 0)
    throw std::invalid_argument("simulate: the model has no degrees of freedom (every body is fixed or locked by its loops): "
                                "nothing moves, nothing to simulate");
  if (controller && controller->needs_state() && !plant)
    throw std::invalid_argument("simulate: state feedback needs the linearized plant it was designed on");
  if (controller && !controller->needs_state())
    for (std::size_t i = 0; i < model.plant_outputs.size(); ++i) {
      const int k = model.plant_outputs[i];
      if (sensor_reads_accelerations(model.sensors[static_cast<std::size_t>(k)].type) &&
          controller->reads_output(static_cast<int>(i))) {
        const bool reaction = model.sensors[static_cast<std::size_t>(k)].type == SensorType::MotionForce;
        throw std::invalid_argument("simulate: the controller measures \"" + model.sensors[static_cast<std::size_t>(k)].name +
                                    (reaction ? "\", a motion input's reaction force" : "\", an acceleration") +
                                    ", which depends on the inputs the controller "
                                    "computes (an algebraic loop); feed back positions or velocities, or use state "
                                    "feedback (the " + (reaction ? "reaction" : "acceleration") + " is then recorded as an output)");
      }
    }
  const SampledBeside& bs = o.beside;
  const Controller* beside = bs.controller;
  if (beside) {
    const double Tb = beside->sample_time();
    if (!(Tb > 0) || !std::isfinite(Tb))
      throw std::invalid_argument("simulate: the controller beside (" + beside->describe() +
                                  ") must be sampled (a sample time > 0)");
    if ((o.t_end - o.t0) / Tb > o.max_samples * 100.0) {
      std::ostringstream os;
      os << "simulate: the controller beside's sample time " << Tb << " s gives " << (o.t_end - o.t0) / Tb
         << " samples over the run, more than 100 times the sample limit of " << o.max_samples;
      throw std::invalid_argument(os.str());
    }
    if (beside->needs_state() || beside->needs_rates() || beside->nxc() < 0)
      throw std::invalid_argument("simulate: the controller beside reads outputs only (no state feedback, no rates)");
    if (bs.actuators.empty()) throw std::invalid_argument("simulate: the controller beside sets no actuator");
    for (std::size_t i = 0; i < bs.actuators.size(); ++i) {
      const int a = bs.actuators[i];
      if (a < 0 || a >= model.nu()) throw std::invalid_argument("simulate: the controller beside names an actuator the model does not have");
      const std::string& name = model.actuators[static_cast<std::size_t>(a)].name;
      if (std::count(bs.actuators.begin(), bs.actuators.end(), a) > 1)
        throw std::invalid_argument("simulate: the controller beside sets \"" + name + "\" twice");
      if (controller && std::count(model.plant_inputs.begin(), model.plant_inputs.end(), a))
        throw std::invalid_argument("simulate: the controller beside sets \"" + name +
                                    "\", a Plant/In input the first controller drives: give each controller its own inputs");
    }
    for (const int k : bs.sensors) {
      if (k < 0 || k >= static_cast<int>(model.sensors.size()))
        throw std::invalid_argument("simulate: the controller beside names a sensor the model does not have");
      if (sensor_reads_accelerations(model.sensors[static_cast<std::size_t>(k)].type))
        throw std::invalid_argument("simulate: the controller beside reads \"" + model.sensors[static_cast<std::size_t>(k)].name +
                                    "\", which depends on the inputs (an acceleration or a reaction): feed back positions or velocities");
    }
    if (o.compare_linear)
      throw std::invalid_argument("simulate: the linear comparison does not run a controller beside the first");
  }
  const auto wall0 = std::chrono::steady_clock::now();

  std::optional<PlantFunction> pf;
  Eigen::VectorXd x_ref;
  if (plant) {
    pf.emplace(model, plant->op.q, plant->op.u, plant->lin.partition);
    x_ref = Eigen::VectorXd::Zero(pf->nx());
    for (int k = 0; k < pf->nw(); ++k) x_ref[pf->nz() + k] = plant->op.v[pf->rates()[static_cast<std::size_t>(k)]];
  }
  const Eigen::VectorXd u_nominal = plant ? plant->op.u : model.u_nominal();
  ClosedLoopSystem sys(model, controller, pf ? &*pf : nullptr, x_ref, u_nominal, o.stabilization);
  if (o.reference) sys.set_reference(o.reference);
  if (o.disturbance) sys.set_disturbance(o.disturbance);
  if (o.disturbance_rate) sys.set_disturbance_rates(o.disturbance_rate, o.disturbance_acceleration);

  // initial state, on the constraint manifold
  Eigen::VectorXd q0 = o.q0.size() ? o.q0 : model.q0, v0 = o.v0.size() ? o.v0 : model.v0;
  if (q0.size() != model.nq || v0.size() != model.nv) throw std::invalid_argument("simulate: initial state has the wrong size");
  // a motion that starts moving at t0 (a ramp from 0, a table's first segment) jolts the others
  // from the state given, as at any later jump of its rate
  const Eigen::VectorXd jump0 =
      model.motions.empty() ? Eigen::VectorXd()
                            : Eigen::VectorXd(sys.motion_rates(o.t0) -
                                              sys.motion_rates(o.t0 - 1e-9 * std::max(1.0, std::abs(o.t0))));
  // the driven coordinates where their motions start, their rates those just before t0; the
  // loops close on the others (assemble holds the driven ones)
  sys.apply_motions(o.t0, q0, v0);
  for (std::size_t i = 0; i < model.motions.size(); ++i)
    v0[model.actuators[static_cast<std::size_t>(model.motions[i])].iv] -= jump0[static_cast<Eigen::Index>(i)];
  if (model.nc) {
    const AssemblyResult a = assemble(model, q0, v0);
    if (!a.converged) throw std::invalid_argument("simulate: the initial state cannot be assembled onto the loop closures");
    q0 = a.q;
    v0 = a.v;
  }
  if (jump0.size() && jump0.cwiseAbs().maxCoeff() > 0) {
    Data dj(model);
    v0 += prescribed_velocity_jump(model, dj, q0, jump0);  // jump0 on the driven coordinates
  }
  sys.apply_motions(o.t0, q0, v0);
  Eigen::VectorXd s0 = o.s0;
  if (s0.size() == 0) {
    Data ds(model);
    s0 = effect_states_steady(model, ds, q0, v0);
  }
  if (s0.size() != model.ns) throw std::invalid_argument("simulate: the initial effect states have the wrong size");
  const int ns = model.ns, i_s = model.nq + model.nv;  // s in y: i_s .. i_s + ns
  Eigen::VectorXd y(sys.ode_size());
  y << q0, v0, s0, Eigen::VectorXd::Zero(sys.nxc());

  const bool discrete = controller && controller->sample_time() > 0;
  const double Ts = discrete ? controller->sample_time() : 0;
  Eigen::VectorXd xcd = Eigen::VectorXd::Zero(discrete ? controller->nxc() : 0);
  long sample_index = 0;
  auto controller_sample = [&](double t) {
    sys.set_effect_states(y.segment(i_s, ns));
    const ControllerInput in = sys.measure(t, y.head(model.nq), y.segment(model.nq, model.nv));
    sys.set_held(controller->output(in, xcd));
    xcd = controller->update(in, xcd);
    ++sample_index;
  };
  if (discrete) controller_sample(o.t0);
  // the controller beside: its samples on its own clock, its outputs held on its actuators
  const double Tb = beside ? beside->sample_time() : 0;
  Eigen::VectorXd xcb = Eigen::VectorXd::Zero(beside ? beside->nxc() : 0);
  long beside_index = 0;
  Data db(model);
  auto beside_sample = [&](double t) {
    const Eigen::VectorXd q = y.head(model.nq), v = y.segment(model.nq, model.nv);
    db.s = y.segment(i_s, ns);
    forward_kinematics<double>(model, db, q, v);
    ControllerInput in;
    in.t = t;
    in.y = sensor_outputs<double>(model, db, bs.sensors, q, v);
    const Eigen::VectorXd u = beside->output(in, xcb);
    if (u.size() != static_cast<Eigen::Index>(bs.actuators.size()))
      throw std::invalid_argument("simulate: the controller beside gives " + std::to_string(u.size()) + " values for " +
                                  std::to_string(bs.actuators.size()) + " actuators");
    sys.set_beside_held(u);
    xcb = beside->update(in, xcb);
    ++beside_index;
  };
  if (beside) {
    sys.set_beside(bs.actuators);
    beside_sample(o.t0);
  }

  SimulationResult r;
  IntegratorSettings settings = o.integrator;
  const bool chosen = settings.method == "auto";
  if (chosen) {  // the default: chosen from the closed loop at the initial state
    const IntegratorChoice choice = choose_integrator(sys, o.t0, y, o.t_end - o.t0, settings.rtol);
    apply_choice(choice, settings);
    r.stats.integrator_choice = choice.reason;
  }
  r.stats.integrator = settings.method;
  r.stats.rtol = o.integrator.rtol;
  r.stats.atol = o.integrator.atol;
  r.stats.max_step = o.integrator.max_step;
  auto integrator = make_integrator(sys, settings);
  integrator->reset(o.t0, y);

  Recorder rec;
  Data d(model);
  bool reactions = false;  // a motion's reaction or an acceleration among the outputs: the accelerations at each sample
  for (int k : model.plant_outputs) reactions = reactions || sensor_reads_accelerations(model.sensors[static_cast<std::size_t>(k)].type);
  Eigen::VectorXd motion_acc;
  auto record = [&](double t) {
    Eigen::VectorXd q = y.head(model.nq), v = y.segment(model.nq, model.nv);
    sys.apply_motions(t, q, v, &motion_acc);  // exactly where they are driven (the state integrates their rates)
    Eigen::VectorXd xc = discrete ? xcd : Eigen::VectorXd(y.tail(sys.nxc()));
    if (xcb.size()) {  // the beside controller's states after the first's
      xc.conservativeResize(xc.size() + xcb.size());
      xc.tail(xcb.size()) = xcb;
    }
    const Eigen::VectorXd s = y.segment(i_s, ns);
    sys.set_effect_states(s);
    d.s = s;
    const Eigen::VectorXd u = sys.inputs(t, q, v, y.tail(sys.nxc()));
    if (reactions) {
      d.motion_acc = motion_acc;
      forward_dynamics<double>(model, d, q, v, u);
    }
    // one pass of kinematics for the outputs, the energies and the loops' drift
    forward_kinematics<double>(model, d, q, v);
    const Eigen::VectorXd out = sensor_outputs<double>(model, d, model.plant_outputs, q, v);
    const double kinetic = kinetic_energy_after_kinematics(model, d, v), potential = potential_energy_after_kinematics(model, d, q);
    const auto [pv, vv] = constraint_violation_after_kinematics(model, d, q, v);  // max |phi|, max |Jc v|
    rec.t.push_back(t);
    rec.q.push_back(q);
    rec.v.push_back(v);
    rec.u.push_back(u);
    rec.y.push_back(out);
    rec.xc.push_back(xc);
    rec.s.push_back(s);
    rec.T.push_back(kinetic);
    rec.V.push_back(potential);
    rec.pv.push_back(pv);
    rec.vv.push_back(vv);
    if (o.reference) rec.r.push_back(o.reference(t));
    if (o.disturbance) rec.d.push_back(o.disturbance(t));
    if (cb.on_sample) cb.on_sample(Snapshot{t, q, v, u, out});
    if (cb.progress) cb.progress(t, o.t_end);
  };
  record(o.t0);

  sys.set_cancel(cb.cancel, cb.stop);  // from here a cancel (or the caller's stop) ends the integrator's step
  const auto halted = [&cb] { return (cb.cancel && cb.cancel->load()) || (cb.stop && cb.stop->load()); };
  const double eps = 1e-12 * std::max(1.0, std::abs(o.t_end));
  // drift the integrator leaves on the loops is not covered by its error test (IDA's
  // index-1 form): a drift of 1e-9 allowed at 1e-10 costs Andrews' squeezer two digits
  // (docs/work-precision.md), so the threshold follows atol when that is tighter
  const double projection_tolerance = std::min(o.projection_tolerance, 0.1 * o.integrator.atol);
  long out_index = 1;
  std::size_t jump_index = 0;
  double t = o.t0;
  while (t < o.t_end - eps) {
    if (halted()) {
      r.cancelled = true;
      break;
    }
    const double next_out = std::min(o.t0 + out_index * o.output_step, o.t_end);
    const double next_sample = discrete ? o.t0 + sample_index * Ts : o.t_end;
    // a motion input's rate jumps (a ramp starts, a table's knot): stop there for its impulse
    while (jump_index < o.rate_jumps.size() && o.rate_jumps[jump_index] <= t + eps) ++jump_index;
    const double next_jump = jump_index < o.rate_jumps.size() ? o.rate_jumps[jump_index] : o.t_end;
    const double next_beside = beside ? o.t0 + beside_index * Tb : o.t_end;
    const double target = std::min({next_out, next_sample, next_beside, next_jump, o.t_end});
    // the times the run must stop at exactly; an output time before them may be stepped past
    const double stop = std::min({next_sample, next_beside, next_jump, o.t_end});
    try {
      if (target < stop - eps)
        integrator->advance_output(target, stop);
      else
        integrator->advance(target);
    } catch (const IntegratorFailure& f) {
      if (halted()) {  // stopped inside the step (ClosedLoopSystem::set_cancel)
        r.cancelled = true;
        break;
      }
      if (chosen && settings.method != kAutoFallbackIntegrator) {
        // auto chose from the initial state; the run became stiff (tires sliding, a contact):
        // on from the last state reached with the stiff method, and the log says so
        r.stats.integrator_choice += auto_fallback_note(settings.method, f.time(), f.what(), t);
        integrator->add_stats(r.stats);
        settings.method = kAutoFallbackIntegrator;
        r.stats.integrator = settings.method;
        r.stats.integrator_fell_back = true;
        integrator = make_integrator(sys, settings);
        integrator->reset(t, y);
        ++r.stats.restarts;
        continue;
      }
      std::ostringstream os;
      os << "t = " << f.time() << " s: " << f.what();
      r.failure = os.str();
      break;
    }
    t = target;
    y = integrator->state();
    // a run that diverges ends here, with the reason, instead of the solver spinning
    Eigen::Index worst = 0;
    const double largest = y.size() ? y.cwiseAbs().maxCoeff(&worst) : 0.0;
    if (!std::isfinite(largest) || largest > o.divergence_bound) {
      std::ostringstream os;
      const std::string what = worst < model.nq ? model.q_names[worst]
                               : worst < model.nq + model.nv ? model.rate_names[worst - model.nq]
                               : worst < i_s + ns ? model.s_names[static_cast<std::size_t>(worst - i_s)]
                                                 : "controller state " + std::to_string(worst - i_s - ns);
      os << "t = " << t << " s: diverged: " << what << " = " << y[worst] << " is past the bound "
         << o.divergence_bound << " (the last sane sample is at t = " << (rec.t.empty() ? o.t0 : rec.t.back()) << " s)";
      r.failure = os.str();
      break;
    }
    bool restart = false;
    if (jump_index < o.rate_jumps.size() && t >= o.rate_jumps[jump_index] - eps) {
      // the other coordinates take the impulse of the motions' rate jumps (and the integrator restarts)
      const double tj = o.rate_jumps[jump_index];
      const Eigen::VectorXd jump = sys.motion_rates(tj) - sys.motion_rates(tj - 1e-9 * std::max(1.0, std::abs(tj)));
      if (jump.size() && jump.cwiseAbs().maxCoeff() > 0) {
        Eigen::VectorXd q = y.head(model.nq);
        y.segment(model.nq, model.nv) += prescribed_velocity_jump(model, d, q, jump);
        restart = true;
      }
      ++jump_index;
    }
    if (model.nc && !integrator->projects() && sys.project(y, projection_tolerance, t)) {
      ++r.stats.projections;
      restart = true;
    }
    if (model.nc && sys.rows_degraded(y.head(model.nq))) restart = true;  // re-choose the multiplier rows
    if (discrete && t >= next_sample - eps) {
      controller_sample(t);
      restart = true;
    }
    if (beside && t >= next_beside - eps) {
      beside_sample(t);
      restart = true;
    }
    if (restart) {
      integrator->reset(t, y);
      ++r.stats.restarts;
    }
    if (t >= next_out - eps) {
      record(t);
      ++out_index;
    }
  }
  r.completed = !r.cancelled && r.failure.empty();
  integrator->add_stats(r.stats);

  const int N = static_cast<int>(rec.t.size());
  r.t = rec.t;
  r.q = Recorder::stack(rec.q, model.nq);
  r.v = Recorder::stack(rec.v, model.nv);
  r.u = Recorder::stack(rec.u, model.nu());
  r.y = Recorder::stack(rec.y, static_cast<Eigen::Index>(model.plant_outputs.size()));
  r.xc = Recorder::stack(rec.xc, (discrete ? controller->nxc() : sys.nxc()) + xcb.size());
  r.s = Recorder::stack(rec.s, ns);
  r.s_names = model.s_names;
  r.kinetic_energy = rec.T;
  r.potential_energy = rec.V;
  r.constraint_violation = rec.pv;
  r.velocity_violation = rec.vv;
  if (!rec.r.empty()) r.y_reference = Recorder::stack(rec.r, r.y.cols());
  if (!rec.d.empty()) r.u_disturbance = Recorder::stack(rec.d, r.u.cols());
  r.q_names = model.q_names;
  r.v_names = model.rate_names;  // NAME_dot, a ball's or free joint's wx.., vx..
  for (const auto& a : model.actuators) {
    r.input_names.push_back(a.name);
    r.input_units.push_back(a.unit);
  }
  for (int k : model.plant_outputs) {
    r.output_names.push_back(model.sensors[k].name);
    r.output_units.push_back(model.sensors[k].unit);
  }
  if (controller) r.controller_state_names = controller->state_names();
  if (beside)
    for (const std::string& n : beside->state_names()) r.controller_state_names.push_back(n);
  r.controller = controller ? controller->describe() : "none (actuators at their nominal values)";
  r.model_name = model.name;
  r.model_file = model.source_file;
  r.codyna_version = CODYNA_VERSION;

  if (o.compare_linear && plant && N > 0) {
    const Eigen::VectorXd dx0 = pf->qv_to_state(q0, v0) - x_ref;
    // far below the nonlinear run's tolerances, so that the gap is the model's, not the integrators';
    // a rerun at 100 times looser tolerances bounds the error of the looser one (reported beside it)
    r.linear_rtol = std::clamp(1e-3 * o.integrator.rtol, 1e-13, 1e-10);
    r.linear_atol = std::clamp(1e-3 * o.integrator.atol, 1e-15, 1e-12);
    const auto lin = linear_run(model, controller, *plant, rec.t, dx0, o.reference, o.disturbance,
                                o.disturbance_rate, r.linear_rtol, r.linear_atol, r.linear_failure);
    r.y_linear = Recorder::stack(lin, r.y.cols());
    if (r.linear_failure.empty()) {
      std::string loose_failure;
      const auto check = linear_run(model, controller, *plant, rec.t, dx0, o.reference, o.disturbance,
                                    o.disturbance_rate, 100 * r.linear_rtol, 100 * r.linear_atol, loose_failure);
      if (loose_failure.empty() && r.y_linear.size() > 0)
        r.linear_error_estimate = (Recorder::stack(check, r.y.cols()) - r.y_linear).cwiseAbs().maxCoeff();
    }
  }
  r.stats.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  (void)N;
  return r;
}

}  // namespace codyna

namespace codyna {

std::string saturation_text(const Saturation& s) {
  std::ostringstream os;
  os << s.actuator << " at its limit from t = " << s.first << " s: " << s.at_max << " s at max, " << s.at_min << " s at min";
  return os.str();
}

std::vector<Saturation> saturation_report(const Model& model, const SimulationResult& r) {
  std::vector<Saturation> out;
  const int N = r.samples();
  if (N == 0 || r.u.cols() != model.nu()) return out;
  for (int k = 0; k < model.nu(); ++k) {
    const ActuatorModel& a = model.actuators[k];
    if (!std::isfinite(a.max) && !std::isfinite(a.min)) continue;
    Saturation s;
    s.actuator = a.name;
    bool any = false;
    for (int i = 0; i < N; ++i) {
      const double dt = i + 1 < N ? r.t[i + 1] - r.t[i] : 0.0;
      const double u = r.u(i, k);
      const double tol = 1e-12 * std::max(1.0, std::abs(u));
      const bool hi = std::isfinite(a.max) && u >= a.max - tol, lo = std::isfinite(a.min) && u <= a.min + tol;
      if (!hi && !lo) continue;
      if (!any) s.first = r.t[i];
      any = true;
      (hi ? s.at_max : s.at_min) += dt;
    }
    if (any) out.push_back(s);
  }
  return out;
}

}  // namespace codyna
