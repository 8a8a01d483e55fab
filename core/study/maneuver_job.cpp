#include "study/maneuver_job.hpp"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "dynamics/data.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "io/atomic_file.hpp"
#include "model/errors.hpp"
#include "simulation/driver.hpp"
#include "simulation/simulator.hpp"
#include "simulation/stepper.hpp"
#include "study/files.hpp"
#include "study/maneuver_detail.hpp"

namespace codyna {

namespace {

mnv::SteerProfile mnv_ramp(double amplitude, double t0, double T) {
  const double w = mnv::kPi / T;
  mnv::SteerProfile p;
  p.value = [=](double t) { return t < t0 ? 0.0 : t > t0 + T ? amplitude : amplitude * 0.5 * (1 - std::cos(w * (t - t0))); };
  p.rate = [=](double t) { return t < t0 || t > t0 + T ? 0.0 : amplitude * 0.5 * w * std::sin(w * (t - t0)); };
  p.acceleration = [=](double t) { return t < t0 || t > t0 + T ? 0.0 : amplitude * 0.5 * w * w * std::cos(w * (t - t0)); };
  return p;
}

// one period of a sine of frequency f, held at its second peak (-amplitude) for `dwell`
mnv::SteerProfile mnv_sine_dwell(double amplitude, double t0, double f, double dwell) {
  const double w = 2 * mnv::kPi * f, t_peak = 0.75 / f, t_end = 1.0 / f + dwell;
  // the sine's phase time at t (the dwell removed), or -1 outside the steer, or -2 in the dwell
  const auto phase = [=](double t) {
    const double tau = t - t0;
    if (tau < 0 || tau > t_end) return -1.0;
    if (tau < t_peak) return tau;
    if (tau < t_peak + dwell) return -2.0;
    return tau - dwell;
  };
  mnv::SteerProfile p;
  p.value = [=](double t) {
    const double s = phase(t);
    return s == -1.0 ? 0.0 : s == -2.0 ? -amplitude : amplitude * std::sin(w * s);
  };
  p.rate = [=](double t) {
    const double s = phase(t);
    return s < 0 ? 0.0 : amplitude * w * std::cos(w * s);
  };
  p.acceleration = [=](double t) {
    const double s = phase(t);
    return s < 0 ? 0.0 : -amplitude * w * w * std::sin(w * s);
  };
  return p;
}

ManeuverReport mnv_open_loop(const ManeuverRequest& r, const ModelSpec& spec, bool sine) {
  const mnv::Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  const mnv::OpenLoop ol = mnv::open_loop_setup(r, spec, true);
  rep.model_name = ol.model.name;
  rep.speed = ol.start.v_body.norm();
  const int iy = ol.yaw_rate, ia = ol.lateral_acceleration;
  const mnv::BodyState& s0 = ol.start;

  if (sine) mnv::steer_at_03g(rep, r, spec, ol, "; the lateral displacement is asked at any amplitude");
  double amplitude = r.steer ? *r.steer : (sine ? 0.05 : 0.01);
  if (sine && r.steer_scale) {
    if (r.steer) throw std::invalid_argument(flag("steer-scale") + ": give the amplitude or its scale, not both (" + flag("steer") + ")");
    if (!std::isfinite(*r.steer_scale) || *r.steer_scale == 0)
      throw std::invalid_argument(flag("steer-scale") + ": expected a multiple of the steer at 0.3 g other than 0");
    if (!std::isfinite(rep.steer_03g))
      throw std::invalid_argument(flag("steer-scale") + ": " + rep.notes.back());
    amplitude = *r.steer_scale * rep.steer_03g;
  }
  if (!std::isfinite(amplitude) || amplitude == 0)
    throw std::invalid_argument(flag("steer") + ": expected a steer amplitude other than 0");
  rep.steer = amplitude;
  const double t0 = r.steer_time ? *r.steer_time : 0.5;
  if (!(t0 >= 0) || !std::isfinite(t0)) throw std::invalid_argument(flag("steer-time") + ": expected a time >= 0");
  mnv::SteerProfile profile;
  std::vector<double> stops;
  double t_end = 0, t_ref = 0;
  if (sine) {
    const double f = mnv::positive(flag, r.frequency, 0.7, "frequency");
    const double dwell = r.dwell ? *r.dwell : 0.5;
    if (!(dwell >= 0)) throw std::invalid_argument(flag("dwell") + ": expected a time >= 0");
    profile = mnv_sine_dwell(amplitude, t0, f, dwell);
    // the steer's acceleration jumps there: the run stops and the integrator starts again
    stops = {t0, t0 + 0.75 / f, t0 + 0.75 / f + dwell, t0 + 1.0 / f + dwell};
    rep.steer_start = t0;
    rep.steer_end = t0 + 1.0 / f + dwell;
    t_end = r.t_end ? *r.t_end : rep.steer_end + 2.0;
    if (t_end < rep.steer_end + 1.75)
      throw std::invalid_argument(flag("t-end") + ": the run must last 1.75 s past the steer's end (" +
                                  std::to_string(rep.steer_end + 1.75) + " s)");
  } else {
    const double ramp = mnv::positive(flag, r.ramp, 0.05, "ramp");
    profile = mnv_ramp(amplitude, t0, ramp);
    stops = {t0, t0 + ramp};
    t_ref = t0 + ramp / 2;
    t_end = r.t_end ? *r.t_end : t0 + ramp + 4.0;
    if (!(t_end > t0 + ramp + 0.5))
      throw std::invalid_argument(flag("t-end") + ": the run must last at least 0.5 s past the ramp's end");
  }
  const Model run = mnv::open_loop_run(rep, r, ol, profile, stops, t_end);
  Data d(run);

  if (rep.result.samples() >= 3) {
    const std::vector<double> yaw = mnv::column(rep.result, iy);
    if (sine) {
      // the lateral displacement from the start, perpendicular to the start's heading
      std::vector<double> lateral(yaw.size());
      const Eigen::Vector2d n(-std::sin(s0.heading), std::cos(s0.heading));
      for (int k = 0; k < rep.result.samples(); ++k) {
        const mnv::BodyState s = mnv::body_state(run, d, ol.body, rep.result.q.row(k).transpose(), rep.result.v.row(k).transpose());
        lateral[static_cast<std::size_t>(k)] = n.dot((s.p - s0.p).head<2>());
      }
      try {
        // FMVSS 126: the peak after the steer changes sign (its second half wave's direction)
        rep.sine = sine_with_dwell_metrics(rep.result.t, yaw, lateral, rep.steer_start, rep.steer_end, -amplitude,
                                           rep.steer_start + 0.5 / mnv::positive(flag, r.frequency, 0.7, "frequency"));
        // FMVSS 126 S5.2.3: the displacement only of runs at 5 x the steer at 0.3 g or more
        rep.displacement_applies = !std::isfinite(rep.steer_03g) || std::abs(amplitude) >= 5 * rep.steer_03g * (1 - 1e-12);
        rep.sine.passes_fmvss126 = rep.sine.yrr_1_00 <= 35.0 && rep.sine.yrr_1_75 <= 20.0 &&
                                   (!rep.displacement_applies || std::abs(rep.sine.lateral_displacement) >= 1.83);
      } catch (const std::invalid_argument& e) {
        rep.valid = false;
        if (rep.invalid_reason.empty()) rep.invalid_reason = e.what();
      }
    } else {
      try {
        rep.yaw_rate = step_response_metrics(rep.result.t, yaw, t_ref, amplitude);
        if (ia >= 0) {
          rep.lateral_acceleration = step_response_metrics(rep.result.t, mnv::column(rep.result, ia), t_ref, amplitude);
          rep.has_lateral_acceleration = true;
        }
      } catch (const std::invalid_argument& e) {
        rep.valid = false;
        if (rep.invalid_reason.empty()) rep.invalid_reason = e.what();
      }
    }
  }
  mnv::write(rep, r);
  return rep;
}

// a stepped run's names, units and provenance, as a simulation's result carries them
void mnv_name_result(SimulationResult& res, const Model& run, const ManeuverRequest& r, const Controller& driver,
                     const Stepper& st) {
  res.q_names = run.q_names;
  res.v_names = run.rate_names;
  for (const ActuatorModel& a : run.actuators) {
    res.input_names.push_back(a.name);
    res.input_units.push_back(a.unit);
  }
  for (int k : run.plant_outputs) {
    res.output_names.push_back(run.sensors[static_cast<std::size_t>(k)].name);
    res.output_units.push_back(run.sensors[static_cast<std::size_t>(k)].unit);
  }
  res.controller_state_names = driver.state_names();
  res.controller = driver.describe();
  res.model_name = run.name;
  res.model_file = r.model;
  res.codyna_version = CODYNA_VERSION;
  res.stats = st.stats();
}

// the lateral error from the start of section 1 to the end of section 6, and the cones: the
// car's rectangle (width x length about the position outputs) in the lane's frame against each
// section's lines. The part of the rectangle inside a section (between its first and last cones
// along x) is its corners there and the points where its edges cross the section's ends (a car
// leaving a section turned can touch its last cone with a side, its corners beyond or before it);
// `local` the lane in its own frame, placed at `start` turned by yaw0
void mnv_lane_metrics(ManeuverReport& rep, const mnv::Flags& flag, const DriverPath& local, const DriverSettings& ds,
                      const Eigen::Vector2d& start, double yaw0, const std::vector<double>& lateral, double width,
                      double length) {
  const SimulationResult& res = rep.result;
  const Eigen::Rotation2Dd rot(yaw0);
  const int done = static_cast<int>(res.t.size());
  const double gate_from = local.gate_start.front(), gate_to = local.gate_end.back();
  std::vector<double> tin, ein;
  const std::size_t gates = local.gate_start.size();
  std::vector<bool> hit(gates, false);
  rep.cone_clearance.assign(gates, std::numeric_limits<double>::infinity());
  for (int k = 0; k < done; ++k) {
    const Eigen::Vector2d p = rot.inverse() * (Eigen::Vector2d(res.y(k, ds.out_x), res.y(k, ds.out_y)) - start);
    const double psi = res.y(k, ds.out_yaw) - yaw0;
    if (p.x() >= gate_from && p.x() <= gate_to) {
      tin.push_back(res.t[static_cast<std::size_t>(k)]);
      ein.push_back(lateral[static_cast<std::size_t>(k)]);
    }
    const Eigen::Rotation2Dd body_rot(psi);
    Eigen::Vector2d corner[4];
    const double along[4] = {-0.5, 0.5, 0.5, -0.5}, across[4] = {-0.5, -0.5, 0.5, 0.5};  // around the outline
    for (int c = 0; c < 4; ++c) corner[c] = p + body_rot * Eigen::Vector2d(along[c] * length, across[c] * width);
    for (std::size_t g = 0; g < gates; ++g) {
      const double x0 = local.gate_start[g], x1 = local.gate_end[g];
      const auto check = [&](const Eigen::Vector2d& point) {
        const double margin = local.gate_width[g] / 2 - std::abs(point.y() - local.gate_center[g]);
        rep.cone_clearance[g] = std::min(rep.cone_clearance[g], margin);
        if (margin >= 0 || hit[g]) return;
        hit[g] = true;
        std::ostringstream os;
        os << "section " << (g == 0 ? 1 : g == 1 ? 3 : 5) << " (" << local.gate_width[g] << " m wide) at x = "
           << std::setprecision(4) << point.x() - local.gate_start.front() << " m, t = " << res.t[static_cast<std::size_t>(k)] << " s";
        rep.cones_hit.push_back(os.str());
      };
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector2d& a = corner[c];
        const Eigen::Vector2d& b = corner[(c + 1) % 4];
        if (a.x() >= x0 && a.x() <= x1) check(a);
        for (const double xe : {x0, x1})
          if ((a.x() - xe) * (b.x() - xe) < 0) check(a + (b - a) * ((xe - a.x()) / (b.x() - a.x())));
      }
    }
  }
  for (double& c : rep.cone_clearance)
    if (!std::isfinite(c)) c = std::nan("");  // the run ended before the section
  if (tin.empty()) {
    rep.valid = false;
    if (rep.invalid_reason.empty()) rep.invalid_reason = "the run ended before the lane (raise " + flag("t-end") + ")";
  } else {
    rep.path = path_error_metrics(tin, ein);
  }
}

// the driver's gains: the request's, else the model file's driver controller's (from_file), else
// defaults for the car (preview half a second of travel, at least 5 m)
void mnv_driver_gains(DriverSettings& ds, const ManeuverRequest& r, const mnv::Flags& flag, const Model& m,
                      bool from_file, double speed) {
  const ControllerSpec& c = m.spec.controller;
  ds.preview = mnv::positive(flag, r.preview, from_file ? c.preview : std::max(5.0, 0.5 * speed), "preview");
  ds.wheelbase = from_file ? c.wheelbase : (m.spec.analysis.handling.wheelbase ? *m.spec.analysis.handling.wheelbase : 2.7);
  ds.steering_ratio = from_file ? c.steering_ratio : (m.spec.analysis.handling.steering_ratio ? *m.spec.analysis.handling.steering_ratio : 1.0);
  ds.lateral_gain = from_file ? c.lateral_gain : 0.05;
  if (r.lateral_gain) {
    if (!(*r.lateral_gain >= 0)) throw std::invalid_argument(flag("lateral-gain") + ": expected a number >= 0");
    ds.lateral_gain = *r.lateral_gain;
  }
  ds.speed = speed;
  ds.speed_kp = r.speed_kp ? *r.speed_kp : from_file ? c.speed_kp : 0.0;
  ds.speed_ki = r.speed_ki ? *r.speed_ki : from_file ? c.speed_ki : 0.0;
  ds.sample_time = mnv::positive(flag, r.sample_time, from_file ? c.sample_time : 0.01, "sample-time");
  if (r.speed_kp && !(*r.speed_kp >= 0)) throw std::invalid_argument(flag("speed-kp") + ": expected a number >= 0");
  if (r.speed_ki && !(*r.speed_ki >= 0)) throw std::invalid_argument(flag("speed-ki") + ": expected a number >= 0");
}

// the driver's signals by name: the request's, else the model file's driver controller's, else
// the study's handling steer
DriverSignals mnv_driver_names(const ManeuverRequest& r, const Model& m, bool from_file) {
  const ControllerSpec& c = m.spec.controller;
  DriverSignals names;
  if (from_file) names = DriverSignals{c.x, c.y, c.yaw, c.forward_speed, c.steer, c.drive};
  else if (!m.spec.analysis.handling.steer.empty()) names.steer = m.spec.analysis.handling.steer;
  if (r.x) names.x = *r.x;
  if (r.y) names.y = *r.y;
  if (r.yaw) names.yaw = *r.yaw;
  if (r.speed_output) names.speed = *r.speed_output;
  if (r.drive) names.drive = *r.drive;
  return names;
}

ManeuverReport mnv_lane_change(const ManeuverRequest& r, const ModelSpec& spec) {
  const mnv::Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  const Model m = study_model(mnv::straight_spec(r, spec), r.model);
  rep.model_name = m.name;
  const bool from_file = m.spec.controller.type == ControllerType::Driver;
  const ControllerSpec& c = m.spec.controller;
  const DriverSignals names = mnv_driver_names(r, m, from_file);
  const int body = mnv::steady_body(m);
  const OperatingPoint op = study_operating_point(m, "steady");
  Data d(m);
  const mnv::BodyState s0 = mnv::body_state(m, d, body, op.q, op.v);
  rep.speed = s0.v_body.norm();

  DriverSettings ds;
  std::vector<std::string> outputs, inputs;
  for (int k : m.plant_outputs) outputs.push_back(m.sensors[static_cast<std::size_t>(k)].name);
  for (int k : m.plant_inputs) inputs.push_back(m.actuators[static_cast<std::size_t>(k)].name);
  Eigen::VectorXd u0(static_cast<Eigen::Index>(inputs.size()));
  for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) u0[static_cast<Eigen::Index>(k)] = op.u[m.plant_inputs[k]];
  ds.u0 = u0;
  // the names: refused naming the flag when the request gave them, else the file's field
  const std::string file_field = (m.source_file.empty() ? "" : m.source_file + ": ") + "/controller/";
  resolve_driver_signals(ds, names, outputs, inputs, [&](const std::string& field) {
    for (const auto& [given, name, key] : {std::tuple{r.x.has_value(), "x", "x"}, {r.y.has_value(), "y", "y"},
                                           {r.yaw.has_value(), "yaw", "yaw"},
                                           {r.speed_output.has_value(), "forward_speed", "speed-output"},
                                           {r.drive.has_value(), "drive", "drive"}})
      if (given && field == name) return flag(key);
    return file_field + field;
  });
  // the output names were resolved: their values at the start
  SimulationOptions o;
  const Model run = held_at(m, op, o);
  Stepper st(run, mnv::integrator(run));
  st.set_cancel(r.cancel);  // seen inside the steps too
  st.reset(0, o.q0, o.v0);
  const Eigen::VectorXd y0 = st.outputs();
  const double yaw0 = y0[ds.out_yaw];
  if (std::abs(yaw0) > 1e-9)
    rep.notes.push_back("the lane is laid out along the car's heading at the start");
  const double width = mnv::positive(flag, r.width, from_file ? c.vehicle_width : 1.8, "width");
  const double length = mnv::positive(flag, r.length, 4.5, "length");
  ds.path = path_double_lane_change(Eigen::Vector2d(0, 0), width);
  // into the world: rotated by the start's heading about the start's position
  const Eigen::Vector2d start(y0[ds.out_x], y0[ds.out_y]);
  const Eigen::Rotation2Dd rot(yaw0);
  DriverPath local = ds.path;
  for (Eigen::Vector2d& p : ds.path.points) p = start + rot * p;
  mnv::lane_layout(rep, local, start, yaw0);
  mnv_driver_gains(ds, r, flag, m, from_file, rep.speed);
  const std::unique_ptr<Controller> driver = make_driver(ds, flag("driver"));

  // the run: sampled driver, zero-order hold on the plant (simulation/stepper.hpp)
  const double lane_end = local.gate_end.back() + 20;
  const double t_end = r.t_end ? *r.t_end : (lane_end) / std::max(rep.speed, 1.0);
  const int steps = static_cast<int>(std::ceil(t_end / ds.sample_time));
  if (steps > 2000000) throw std::invalid_argument(flag("t-end") + ": too many driver samples");
  SimulationResult& res = rep.result;
  res.q.resize(steps + 1, run.nq);
  res.v.resize(steps + 1, run.nv);
  res.u.resize(steps + 1, run.nu());
  res.y.resize(steps + 1, static_cast<Eigen::Index>(outputs.size()));
  res.xc.resize(steps + 1, 2);
  Eigen::VectorXd xc = Eigen::VectorXd::Zero(2);
  std::vector<double> lateral;
  ControllerInput in;
  int done = 0;
  res.completed = true;
  for (int k = 0; k <= steps; ++k) {
    in.t = st.time();
    in.y = st.outputs();
    const Eigen::VectorXd u = driver->output(in, xc);
    res.t.push_back(in.t);
    res.q.row(k) = st.q().transpose();
    res.v.row(k) = st.v().transpose();
    Eigen::VectorXd ua = run.nu() ? Eigen::VectorXd(op.u) : Eigen::VectorXd();
    for (std::size_t i = 0; i < m.plant_inputs.size(); ++i) ua[m.plant_inputs[i]] = u[static_cast<Eigen::Index>(i)];
    res.u.row(k) = ua.transpose();
    res.y.row(k) = in.y.transpose();
    res.xc.row(k) = xc.transpose();
    res.kinetic_energy.push_back(kinetic_energy<double>(run, d, st.q(), st.v()));
    res.potential_energy.push_back(std::nan(""));
    res.constraint_violation.push_back(0);
    res.velocity_violation.push_back(0);
    lateral.push_back(project_on_path(ds.path, Eigen::Vector2d(in.y[ds.out_x], in.y[ds.out_y])).lateral);
    rep.max_steer = std::max(rep.max_steer, std::abs(u[ds.in_steer]));
    done = k + 1;
    if (k == steps) break;
    if (r.cancel && r.cancel->load()) throw StudyCancelled("the maneuver was cancelled");
    if (r.progress) r.progress(res.t.back(), t_end);
    xc = driver->update(in, xc);
    try {
      st.step(u, ds.sample_time);
    } catch (const std::exception& e) {
      if (r.cancel && r.cancel->load()) throw StudyCancelled("the maneuver was cancelled");
      res.completed = false;
      res.failure = e.what();
      break;
    }
  }
  res.q.conservativeResize(done, Eigen::NoChange);
  res.v.conservativeResize(done, Eigen::NoChange);
  res.u.conservativeResize(done, Eigen::NoChange);
  res.y.conservativeResize(done, Eigen::NoChange);
  res.xc.conservativeResize(done, Eigen::NoChange);
  mnv_name_result(res, run, r, *driver, st);
  mnv::check_run(rep, res, run, body);

  mnv_lane_metrics(rep, flag, local, ds, start, yaw0, lateral, width, length);
  mnv::write(rep, r);
  return rep;
}

}  // namespace

ManeuverReport study_maneuver_job(const ManeuverRequest& r, const ModelSpec& spec, const StudyMessages& tell) {
  const mnv::Flags flag{r.style};
  std::string known;
  for (const char* t : kManeuverTypes) known += (known.empty() ? "" : ", ") + std::string(t);
  if (r.type.empty()) throw std::invalid_argument(flag("type") + ": expected one of " + known);
  for (const std::string& f : {r.out, r.csv})
    if (!f.empty()) study_guard_output(f, f == r.out ? OutputKind::ResultsHdf5 : (r.type == "constant-radius" || r.type == "constant-speed" ? OutputKind::CurvesCsv : OutputKind::ResultsCsv), {r.model});
  ManeuverReport rep;
  ModelSpec given = spec;
  if (r.free_inputs) given.analysis.free_inputs = *r.free_inputs;
  if (r.type == "step-steer") rep = mnv_open_loop(r, given, false);
  else if (r.type == "sine-with-dwell") rep = mnv_open_loop(r, given, true);
  else if (r.type == "swept-sine") rep = mnv::swept_sine(r, given);
  else if (r.type == "double-lane-change") rep = mnv_lane_change(r, given);
  else if (r.type == "constant-radius") rep = mnv::constant_radius(r, given);
  else if (r.type == "constant-speed") rep = mnv::constant_speed(r, given);
  else if (r.type == "slowly-increasing-steer") rep = mnv::slowly_increasing_steer(r, given);
  else if (r.type == "fishhook") rep = mnv::fishhook(r, given);
  else throw std::invalid_argument(flag("type") + ": unknown maneuver \"" + r.type + "\" (expected one of " + known + ")");
  if (tell) {
    for (const std::string& n : rep.notes) tell({StudyMessage::Note, n});
    for (const std::string& w : rep.warnings) tell({StudyMessage::Warning, w});
  }
  return rep;
}

namespace {

// the swept sine's table and characteristic values
void mnv_swept_text(std::ostream& os, const ManeuverReport& r) {
  const double deg = 180 / mnv::kPi;
  os << "steer amplitude  " << r.steer << " (swept from " << r.steer_start << " s to " << r.steer_end << " s)\n";
  if (r.sw_frequency.empty()) return;
  const bool lin = r.sw_has_linear, lat = !r.sw_lateral.empty();
  os << "yaw rate per steer" << (lat ? " / lateral acceleration per steer" : "") << (lin ? " (the linear model's beside)" : "")
     << "\n  f (Hz)      gain        phase (deg)" << (lin ? "  linear gain  phase (deg)" : "")
     << (lat ? "  a_y gain     phase (deg)" : "") << (lat && lin ? "  linear gain  phase (deg)" : "") << "\n";
  const auto pair = [&os, deg](std::complex<double> h) {
    os << "  " << std::setw(11) << std::abs(h) << "  " << std::setw(11) << std::arg(h) * deg;
  };
  for (std::size_t k = 0; k < r.sw_frequency.size(); ++k) {
    os << "  " << std::setw(8) << r.sw_frequency[k];
    pair(r.sw_yaw[k]);
    if (lin) pair(r.sw_yaw_linear[k]);
    if (lat) pair(r.sw_lateral[k]);
    if (lat && lin) pair(r.sw_lateral_linear[k]);
    os << "\n";
  }
  const auto metrics = [&os, lat](const char* who, const SweptSineCharacteristics& m) {
    os << who << "steady gain " << m.yaw_gain_low << " 1/s, resonance " << m.resonance_hz << " Hz, peak ratio "
       << m.peak_ratio << ", yaw-rate phase at 1 Hz " << m.yaw_phase_1hz << " deg";
    if (lat) os << ", a_y phase at 1 Hz " << m.lateral_phase_1hz << " deg";
    os << "\n";
  };
  os << "ISO 7401 (the steady gain: at " << r.sw_frequency.front() << " Hz)\n";
  metrics("  run:     ", r.sw_metrics);
  if (!lin) return;
  metrics("  linear:  ", r.sw_metrics_linear);
  os << "largest gap  yaw rate " << r.sw_gap_yaw * 100 << " % at " << r.sw_gap_yaw_hz << " Hz";
  if (lat) os << ", lateral acceleration " << r.sw_gap_lateral * 100 << " % at " << r.sw_gap_lateral_hz << " Hz";
  os << " (of the linear response's largest)\n";
}

}  // namespace

std::string study_maneuver_text(const ManeuverReport& r) {
  std::ostringstream os;
  os << std::setprecision(6);
  const double deg = 180 / mnv::kPi;
  os << "maneuver         " << r.type << "\n";
  os << "model            " << r.model_name << "\n";
  if (r.type == "constant-radius" || r.type == "constant-speed") {
    if (r.type == "constant-radius") os << "radius           " << r.radius << " m\n";
    else os << "speed            " << r.speed << " m/s\n";
    const bool lin = r.cr_linear_steer.size() == r.cr_speed.size();
    os << "  speed (m/s)   a_y (m/s^2)   steer        " << (lin ? "linear steer  " : "")
       << "road wheel (deg)  sideslip (deg)  roll (deg)  K (deg/g)\n";
    for (std::size_t k = 0; k < r.cr_speed.size(); ++k) {
      os << "  " << std::setw(12) << r.cr_speed[k] << "  " << std::setw(12) << r.cr_lateral_acceleration[k] << "  "
         << std::setw(11) << r.cr_steer[k] << "  ";
      if (lin) os << std::setw(12) << r.cr_linear_steer[k] << "  ";
      os << std::setw(16) << r.cr_road_wheel[k] * deg << "  " << std::setw(14) << r.cr_sideslip[k] * deg << "  "
         << std::setw(10) << r.cr_roll[k] * deg << "  "
         << (k < r.cr_gradient.size() ? r.cr_gradient[k] * deg * 9.80665 : std::nan("")) << "\n";
    }
    const auto gradient = [&os, deg](double K) { os << K << " rad/(m/s^2) = " << K * deg * 9.80665 << " deg/g"; };
    if (!r.cr_gradient.empty()) {
      os << "understeer gradient at the lowest a_y   ";
      gradient(r.cr_gradient.front());
      os << "\n";
      if (r.linear_gradient) {
        os << (r.type == "constant-radius" ? "linear model's, same speeds and a_y     " : "linear model's, same a_y                ");
        gradient(*r.linear_gradient);
        os << " (difference " << std::abs(r.cr_gradient.front() - *r.linear_gradient) / std::abs(*r.linear_gradient) * 100
           << " %)\n";
      }
      if (r.handling_gradient) {
        std::ostringstream label;
        label << std::setprecision(6) << "handling number K at " << r.speed << " m/s";
        os << std::left << std::setw(40) << label.str() << std::right;
        gradient(*r.handling_gradient);
        if (r.type == "constant-radius") os << " (constant speed: without dK/dU)";
        else os << " (difference " << std::abs(r.cr_gradient.front() - *r.handling_gradient) / std::abs(*r.handling_gradient) * 100 << " %)";
        os << "\n";
      }
    }
  } else {
    os << "speed            " << r.speed << " m/s\n";
  }
  if (!r.controller.empty()) {
    os << "controller       " << r.controller << "\n";
    if (r.reference_limit > 0)
      os << "  reference      yaw rate " << r.reference_gain << " 1/s x steer, within +-" << r.reference_limit
         << " rad/s (the straight run's steady gain; mu g / U)\n";
    for (std::size_t k = 0; k < r.controller_inputs.size(); ++k)
      os << "  largest |u - u0| " << r.controller_inputs[k] << " " << r.controller_effort[k] << "\n";
  }
  if (r.type == "step-steer" || r.type == "sine-with-dwell" || r.type == "slowly-increasing-steer" || r.type == "fishhook")
    os << "largest sideslip " << r.max_sideslip * deg << " deg at " << r.max_sideslip_time << " s\n";
  if (r.type == "step-steer") {
    os << "steer step       " << r.steer << "\n";
    const auto line = [&os](const char* name, const StepMetrics& m, const char* unit) {
      os << name << "\n"
         << "  steady-state gain     " << m.gain << " " << unit << " per steer\n"
         << "  response time (90 %)  " << m.response_time << " s\n"
         << "  peak response time    " << m.peak_time << " s\n"
         << "  overshoot             " << m.overshoot_percent << " %\n";
    };
    line("yaw rate", r.yaw_rate, "1/s");
    if (r.has_lateral_acceleration) line("lateral acceleration", r.lateral_acceleration, "m/s^2");
  } else if (r.type == "sine-with-dwell") {
    os << "steer amplitude  " << r.steer << " (steer from " << r.steer_start << " s to " << r.steer_end << " s)\n"
       << "yaw-rate peak (2nd half)    " << r.sine.peak_yaw_rate << " rad/s at " << r.sine.peak_time << " s\n"
       << "yaw-rate ratio at 1.00 s    " << r.sine.yrr_1_00 << " % (FMVSS 126: at most 35 %)\n"
       << "yaw-rate ratio at 1.75 s    " << r.sine.yrr_1_75 << " % (at most 20 %)\n"
       << "lateral displacement        " << r.sine.lateral_displacement << " m at 1.07 s (at least 1.83 m"
       << (r.displacement_applies ? "" : "; not asked below 5 x the steer at 0.3 g") << ")\n";
    if (std::isfinite(r.steer_03g))
      os << "steer at 0.3 g              " << r.steer_03g << " (steady turns, left and right); amplitude "
         << std::abs(r.steer) / r.steer_03g << " x\n";
    os << "FMVSS 126                   " << (r.sine.passes_fmvss126 ? "passes" : "fails") << "\n";
  } else if (r.type == "swept-sine") {
    mnv_swept_text(os, r);
  } else if (r.type == "double-lane-change") {
    os << "path error       max " << r.path.max_abs << " m at " << r.path.at << " s, RMS " << r.path.rms << " m\n"
       << "largest steer    " << r.max_steer << "\n"
       << "cones            " << (r.cones_hit.empty() ? "none hit" : std::to_string(r.cones_hit.size()) + " section(s) hit") << "\n";
    if (r.cone_clearance.size() == 3)
      os << "cone clearance   sections 1, 3, 5-6: " << r.cone_clearance[0] << ", " << r.cone_clearance[1] << ", "
         << r.cone_clearance[2] << " m (< 0: a lane line crossed)\n";
    for (const std::string& c : r.cones_hit) os << "  hit: " << c << "\n";
  } else if (r.type == "slowly-increasing-steer") {
    const auto pct = [](double a, double b) { return std::abs(a - b) / std::abs(b) * 100; };
    os << "steer ramp       to " << r.steer << " (from " << r.steer_start << " s to " << r.steer_end << " s)\n";
    if (std::isfinite(r.sis_steer_03g)) {
      os << "at 0.3 g         steer " << r.sis_steer_03g << " at " << r.sis_time_03g << " s, speed " << r.sis_speed_03g
         << " m/s (a_y = U r)\n";
      if (std::isfinite(r.sis_steady_steer_03g))
        os << "  steady turn's  steer " << r.sis_steady_steer_03g << " (difference " << pct(r.sis_steer_03g, r.sis_steady_steer_03g)
           << " %)\n";
    }
    if (std::isfinite(r.sis_gradient)) {
      os << "understeer gradient (0.1 .. 0.3 g)  " << r.sis_gradient << " rad/(m/s^2) = " << r.sis_gradient * deg * 9.80665
         << " deg/g (road-wheel angle)\n";
      if (std::isfinite(r.sis_steady_gradient))
        os << "  steady turns' (same a_y, speed)  " << r.sis_steady_gradient << " rad/(m/s^2) = "
           << r.sis_steady_gradient * deg * 9.80665 << " deg/g (difference " << pct(r.sis_gradient, r.sis_steady_gradient) << " %)\n";
      if (r.handling_gradient)
        os << "  handling number K (low a_y)      " << *r.handling_gradient << " rad/(m/s^2) = "
           << *r.handling_gradient * deg * 9.80665 << " deg/g (difference " << pct(r.sis_gradient, *r.handling_gradient) << " %)\n";
    }
    os << "largest a_y      " << r.sis_ay_max << " m/s^2 (" << r.sis_ay_max / 9.80665 << " g) at steer " << r.sis_steer_at_ay_max
       << " (" << r.sis_time_ay_max << " s)\n";
  } else if (r.type == "fishhook") {
    os << "steer            +-" << std::abs(r.steer) << " (from " << r.steer_start << " s to " << r.steer_end << " s)\n"
       << "largest roll     " << r.fh_max_roll * deg << " deg at " << r.fh_max_roll_time << " s\n"
       << "largest a_y      " << r.fh_ay_max << " m/s^2 (" << r.fh_ay_max / 9.80665 << " g)\n"
       << "smallest tire loads\n";
    for (std::size_t k = 0; k < r.fh_tires.size(); ++k)
      os << "  " << std::left << std::setw(14) << r.fh_tires[k] << std::setw(7) << r.fh_sides[k] << std::right << std::setw(12)
         << r.fh_min_load[k] << " N at " << r.fh_min_load_time[k] << " s\n";
    os << "two-wheel lift   " << (r.fh_lift_time < 0 ? std::string("none") : r.fh_lift_side + " side off the road at ");
    if (r.fh_lift_time >= 0) os << r.fh_lift_time << " s";
    os << "\n";
  }
  if (!r.valid) os << "metrics INVALID: " << r.invalid_reason << "\n";
  for (const std::string& w : r.written) os << "wrote " << w << "\n";
  return os.str();
}

}  // namespace codyna
