#include "study/maneuver_job.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "dynamics/data.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "io/atomic_file.hpp"
#include "model/errors.hpp"
#include "simulation/driver.hpp"
#include "simulation/model_controller.hpp"
#include "simulation/simulator.hpp"
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

// A controller whose last output() is kept where another can read it: the driver's held steer,
// from which the controller beside it takes its yaw-rate reference (the intended yaw rate of what
// the driver steers, as an ESC reads the steering wheel)
class Watched final : public Controller {
 public:
  Watched(const Controller& inner, std::shared_ptr<Eigen::VectorXd> last) : inner_(inner), last_(std::move(last)) {}
  int nxc() const override { return inner_.nxc(); }
  double sample_time() const override { return inner_.sample_time(); }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    *last_ = inner_.output(in, xc);
    return *last_;
  }
  Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const override { return inner_.update(in, xc); }
  std::vector<std::string> state_names() const override { return inner_.state_names(); }
  std::string describe() const override { return inner_.describe(); }

 private:
  const Controller& inner_;
  std::shared_ptr<Eigen::VectorXd> last_;
};

// the index of `name` in `names`, refused naming the field with the names there are
int mnv_find(const std::vector<std::string>& names, const std::string& name, const std::string& label, const char* kind) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<int>(k);
  std::string all;
  for (const std::string& n : names) all += (all.empty() ? "" : ", ") + n;
  throw std::invalid_argument(label + ": the driver needs the " + kind + " \"" + name + "\", which the model does not have (" +
                              kind + "s: " + all + ")");
}

ManeuverReport mnv_lane_change(const ManeuverRequest& r, const ModelSpec& spec) {
  const mnv::Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  ModelSpec s = mnv::straight_spec(r, spec);
  const bool from_file = s.controller.type == ControllerType::Driver;
  const ControllerSpec c = s.controller;
  DriverSignals names;
  if (from_file) names = DriverSignals{c.x, c.y, c.yaw, c.forward_speed, c.steer, c.drive};
  else if (!s.analysis.handling.steer.empty()) names.steer = s.analysis.handling.steer;
  if (r.x) names.x = *r.x;
  if (r.y) names.y = *r.y;
  if (r.yaw) names.yaw = *r.yaw;
  if (r.speed_output) names.speed = *r.speed_output;
  if (r.drive) names.drive = *r.drive;
  s = mnv::with_driver_sensors(std::move(s), names, r, rep.notes);

  // the car at its straight run, and the model file's controller (not a driver) beside the driver
  // unless --open-loop
  mnv::OpenLoop ol;
  ol.model = study_model(s, r.model);
  const Model& m = ol.model;
  rep.model_name = m.name;
  ol.body = mnv::steady_body(m);
  ol.op = study_operating_point(m, "steady");
  Data d(m);
  ol.start = mnv::body_state(m, d, ol.body, ol.op.q, ol.op.v);
  rep.speed = ol.start.v_body.norm();

  // the driver's signals among the model's sensors and actuators: refused naming the flag when the
  // request gave them, else the file's field
  std::vector<std::string> sensors, actuators;
  for (const SensorModel& x : m.sensors) sensors.push_back(x.name);
  for (const ActuatorModel& a : m.actuators) actuators.push_back(a.name);
  const std::string file_field = (m.source_file.empty() ? "" : m.source_file + ": ") + (from_file ? "/controller/" : "");
  const auto label = [&](bool given, const char* key, const char* field) {
    return given || !from_file ? flag(key) : file_field + field;
  };
  SampledBeside beside;
  beside.sensors = {mnv_find(sensors, names.x, label(r.x.has_value(), "x", "x"), "sensor"),
                    mnv_find(sensors, names.y, label(r.y.has_value(), "y", "y"), "sensor"),
                    mnv_find(sensors, names.yaw, label(r.yaw.has_value(), "yaw", "yaw"), "sensor"),
                    mnv_find(sensors, names.speed, label(r.speed_output.has_value(), "speed-output", "forward_speed"), "sensor")};
  // the steer: the file's driver's, else the study's handling steer (default "steer")
  const std::string steer_label = from_file ? file_field + "steer"
                                            : (m.source_file.empty() ? "" : m.source_file + ": ") + "/analysis/handling/steer";
  beside.actuators = {mnv_find(actuators, names.steer, steer_label, "actuator")};
  if (!names.drive.empty())
    beside.actuators.push_back(mnv_find(actuators, names.drive, label(r.drive.has_value(), "drive", "drive"), "actuator"));

  if (!r.open_loop && has_model_controller(m) && !from_file) {
    // what acts beside the driver: never on what the driver sets
    for (const int a : beside.actuators)
      if (std::count(m.plant_inputs.begin(), m.plant_inputs.end(), a))
        throw ModelError(m.source_file, "/plant/inputs",
                         "the driver sets \"" + actuators[static_cast<std::size_t>(a)] + "\", and the model file's " +
                             to_string(m.spec.controller.type) + " controller acts on it too (a Plant/In): give the controller " +
                             "other inputs (brakes, a yaw moment, rear steer), or run the maneuver " + flag("open-loop"));
    ol.steer = beside.actuators.front();
    const std::string& yaw_rate = m.spec.analysis.handling.yaw_rate;
    ol.yaw_rate = yaw_rate.empty() ? -1 : mnv::output(m, yaw_rate, "/analysis/handling/yaw_rate", false);
    mnv::attach_controller(ol, r, s, true);
  }

  DriverSettings ds;
  ds.u0.resize(static_cast<Eigen::Index>(beside.actuators.size()));
  for (std::size_t k = 0; k < beside.actuators.size(); ++k) ds.u0[static_cast<Eigen::Index>(k)] = ol.op.u[beside.actuators[k]];
  ds.out_x = 0, ds.out_y = 1, ds.out_yaw = 2, ds.out_speed = 3, ds.in_steer = 0, ds.in_drive = names.drive.empty() ? -1 : 1;
  // the lane along the car's heading from where the car's position outputs are at the start
  SimulationOptions o;
  const Model run = held_at(m, ol.op, o);
  Data dr(run);
  forward_kinematics<double>(run, dr, ol.op.q, ol.op.v);
  dr.s = ol.op.s;
  const Eigen::VectorXd y0 = sensor_outputs<double>(run, dr, beside.sensors, ol.op.q, ol.op.v);
  const double yaw0 = y0[2];
  if (std::abs(yaw0) > 1e-9) rep.notes.push_back("the lane is laid out along the car's heading at the start");
  const double width = mnv::positive(flag, r.width, from_file ? c.vehicle_width : 1.8, "width");
  const double length = mnv::positive(flag, r.length, 4.5, "length");
  ds.path = path_double_lane_change(Eigen::Vector2d(0, 0), width);
  const Eigen::Vector2d start(y0[0], y0[1]);
  const Eigen::Rotation2Dd rot(yaw0);
  DriverPath local = ds.path;
  for (Eigen::Vector2d& p : ds.path.points) p = start + rot * p;
  mnv::lane_layout(rep, local, start, yaw0);
  mnv_driver_gains(ds, r, flag, m, from_file, rep.speed);
  const std::unique_ptr<Controller> driver = make_driver(ds, flag("driver"));
  auto held = std::make_shared<Eigen::VectorXd>(ds.u0);
  const Watched watched(*driver, held);
  beside.controller = &watched;

  // the run: the driver sampled (zero-order hold) beside the file's controller, recorded at the
  // driver's samples
  const double lane_end = local.gate_end.back() + 20;
  o.t_end = r.t_end ? *r.t_end : lane_end / std::max(rep.speed, 1.0);
  if (!(o.t_end > 0) || !std::isfinite(o.t_end)) throw std::invalid_argument(flag("t-end") + ": expected a time > 0");
  if (o.t_end / ds.sample_time > 2000000) throw std::invalid_argument(flag("t-end") + ": too many driver samples");
  o.output_step = ds.sample_time;
  o.integrator = mnv::integrator(run);
  o.beside = beside;
  if (ol.controller && ol.yaw_rate >= 0) {
    // the intended yaw rate of the driver's held steer (less the straight run's)
    const Eigen::VectorXd yr0 = ol.plant->lin.system.y0;
    const int iy = ol.yaw_rate;
    const double gain = ol.reference_gain, limit = ol.reference_limit, steer0 = ds.u0[0];
    o.reference = [yr0, iy, gain, limit, steer0, held](double) {
      Eigen::VectorXd ref = yr0;
      ref[iy] += std::clamp(gain * ((*held)[0] - steer0), -limit, limit);
      return ref;
    };
  }
  SimulationCallbacks cb;
  cb.cancel = r.cancel;
  cb.progress = r.progress;
  rep.result = simulate(run, ol.controller.get(), ol.plant.get(), o, cb);
  SimulationResult& res = rep.result;
  if ((r.cancel && r.cancel->load()) || res.cancelled) throw StudyCancelled("the maneuver was cancelled");
  res.controller = "driver: " + driver->describe() + (ol.controller ? "; beside it " + ol.controller_text : "");
  if (ol.controller) {
    mnv::report_controller(rep, ol, run);
    rep.controller += ", beside the driver";
  }

  // the driver's signals as the run's outputs (those not among Plant/Out), and its lateral error
  const int N = res.samples();
  int cols[4];
  std::vector<int> extra;
  for (int i = 0; i < 4; ++i) {
    const std::string& n = sensors[static_cast<std::size_t>(beside.sensors[static_cast<std::size_t>(i)])];
    const auto it = std::find(res.output_names.begin(), res.output_names.end(), n);
    if (it != res.output_names.end() && std::find(extra.begin(), extra.end(), beside.sensors[static_cast<std::size_t>(i)]) == extra.end()) {
      cols[i] = static_cast<int>(it - res.output_names.begin());
    } else {
      cols[i] = static_cast<int>(res.output_names.size());
      extra.push_back(beside.sensors[static_cast<std::size_t>(i)]);
      res.output_names.push_back(n);
      res.output_units.push_back(run.sensors[static_cast<std::size_t>(beside.sensors[static_cast<std::size_t>(i)])].unit);
    }
  }
  if (!extra.empty()) {
    const Eigen::Index ny = res.y.cols();
    res.y.conservativeResize(N, ny + static_cast<Eigen::Index>(extra.size()));
    for (int k = 0; k < N; ++k) {
      const Eigen::VectorXd q = res.q.row(k).transpose(), v = res.v.row(k).transpose();
      if (run.ns) dr.s = res.s.row(k).transpose();
      forward_kinematics<double>(run, dr, q, v);
      res.y.row(k).tail(static_cast<Eigen::Index>(extra.size())) = sensor_outputs<double>(run, dr, extra, q, v).transpose();
    }
  }
  std::vector<double> lateral(static_cast<std::size_t>(N));
  for (int k = 0; k < N; ++k) {
    lateral[static_cast<std::size_t>(k)] = project_on_path(ds.path, Eigen::Vector2d(res.y(k, cols[0]), res.y(k, cols[1]))).lateral;
    rep.max_steer = std::max(rep.max_steer, std::abs(res.u(k, beside.actuators.front())));
  }
  mnv::check_run(rep, res, run, ol.body);
  DriverSettings columns = ds;
  columns.out_x = cols[0], columns.out_y = cols[1], columns.out_yaw = cols[2], columns.out_speed = cols[3];
  mnv_lane_metrics(rep, flag, local, columns, start, yaw0, lateral, width, length);
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
  // a flag the maneuver does not read is refused, naming the maneuvers that do (never ignored)
  struct Only {
    bool given;
    const char* flag;
    std::vector<std::string> types;
  };
  const std::vector<std::string> lane = {"double-lane-change"}, held = {"double-lane-change", "slowly-increasing-steer"};
  const Only only[] = {
      {r.ramp.has_value(), "ramp", {"step-steer"}},
      {r.frequency.has_value(), "frequency", {"sine-with-dwell"}},
      {r.frequency_min.has_value(), "frequency-min", {"swept-sine"}},
      {r.frequency_max.has_value(), "frequency-max", {"swept-sine"}},
      {r.sweep_time.has_value(), "sweep-time", {"swept-sine"}},
      {r.steer_rate.has_value(), "steer-rate", {"slowly-increasing-steer", "fishhook"}},
      {r.dwell_roll_rate.has_value(), "dwell-roll-rate", {"fishhook"}},
      {r.speed_min.has_value(), "speed-min", {"constant-radius"}},
      {r.speed_max.has_value(), "speed-max", {"constant-radius"}},
      {r.ay_min.has_value(), "ay-min", {"constant-speed"}},
      {r.ay_max.has_value(), "ay-max", {"constant-speed"}},
      {r.width.has_value(), "width", lane},
      {r.length.has_value(), "length", lane},
      {r.preview.has_value(), "preview", lane},
      {r.lateral_gain.has_value(), "lateral-gain", lane},
      {r.x.has_value(), "x", lane},
      {r.y.has_value(), "y", lane},
      {r.yaw.has_value(), "yaw", lane},
      {r.drive.has_value(), "drive", held},
      {r.speed_kp.has_value(), "speed-kp", held},
      {r.speed_ki.has_value(), "speed-ki", held},
      {r.speed_output.has_value(), "speed-output", held},
      {r.sample_time.has_value(), "sample-time", held},
  };
  const bool known_type = std::find(std::begin(kManeuverTypes), std::end(kManeuverTypes), r.type) != std::end(kManeuverTypes);
  for (const Only& o : only) {
    if (!o.given || !known_type || std::find(o.types.begin(), o.types.end(), r.type) != o.types.end()) continue;
    std::string which;
    for (const std::string& t : o.types) which += (which.empty() ? "" : ", ") + t;
    throw std::invalid_argument(flag(o.flag) + ": the " + r.type + " maneuver does not take it (it is for " + which + ")");
  }
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
    os << "speed held       " << (r.speed_hold.empty() ? "no (the drive stays at the straight run's)" : r.speed_hold) << "\n";
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
       << "dwell            " << r.fh_dwell << " s" << (r.fh_roll_rate_dwell ? " (until the roll rate fell back)" : "") << "\n"
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
