#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "dynamics/kinematics.hpp"
#include "analysis/linearize.hpp"
#include "model/errors.hpp"
#include "simulation/model_controller.hpp"
#include "simulation/simulator.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "study/workflow_detail.hpp"
#include "study/maneuver_detail.hpp"

namespace codyna::mnv {


double positive(const Flags& flag, const std::optional<double>& v, double fallback, const char* name) {
  if (!v) return fallback;
  if (!(*v > 0) || !std::isfinite(*v)) {
    std::ostringstream os;
    os << flag(name) << ": expected a number > 0, got " << *v;
    throw std::invalid_argument(os.str());
  }
  return *v;
}

int actuator(const Model& m, const std::string& name, const std::string& field) {
  for (std::size_t k = 0; k < m.actuators.size(); ++k)
    if (m.actuators[k].name == name) return static_cast<int>(k);
  throw ModelError(m.source_file, field, "the maneuver needs the actuator \"" + name + "\", which the model does not have");
}

int output(const Model& m, const std::string& name, const std::string& field, bool required) {
  for (std::size_t k = 0; k < m.plant_outputs.size(); ++k)
    if (m.sensors[static_cast<std::size_t>(m.plant_outputs[k])].name == name) return static_cast<int>(k);
  if (!required) return -1;
  std::string have;
  for (int k : m.plant_outputs) have += (have.empty() ? "" : ", ") + m.sensors[static_cast<std::size_t>(k)].name;
  throw ModelError(m.source_file, field,
                   "the maneuver needs the Plant/Out output \"" + name + "\" (Plant/Out: " + (have.empty() ? "none" : have) + ")");
}

// the body whose motion the steady search sets (study.steady.body, or the first on a free or
// planar joint to ground)
int steady_body(const Model& m) {
  const std::string& name = m.spec.analysis.steady.body;
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[static_cast<std::size_t>(b)];
    if (!name.empty() ? m.body_names[static_cast<std::size_t>(b)] == name
                      : j.parent == 0 && (j.type == JointType::Free || j.type == JointType::Planar))
      return b;
  }
  throw ModelError(m.source_file, "/analysis/steady/body", "the maneuver needs a body on a free or planar joint to ground");
}

// the steady body's centre of mass in the world, its heading, roll, and its velocity in its own axes
BodyState body_state(const Model& m, Data& d, int body, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  forward_kinematics<double>(m, d, q, v);
  const SE3& X = d.oMi[static_cast<std::size_t>(body)];
  const Eigen::Vector3d c = m.com[static_cast<std::size_t>(body)];
  BodyState s;
  s.p = X.act_point(c);
  const Vec6T<double>& V = d.v[static_cast<std::size_t>(body)];
  s.v_body = V.tail<3>() + V.head<3>().cross(c);
  s.heading = std::atan2(X.R(1, 0), X.R(0, 0));
  s.roll = std::atan2(X.R(2, 1), X.R(2, 2));
  const Eigen::Vector3d v_world = X.R * s.v_body, w_world = X.R * V.head<3>();
  s.speed_along_heading = std::cos(s.heading) * v_world.x() + std::sin(s.heading) * v_world.y();
  s.yaw_rate = w_world.z();
  return s;
}

IntegratorSettings integrator(const Model& m) {
  return integrator_settings(m.spec.solver);
}

// the study's straight steady run at the request's speed
ModelSpec straight_spec(const ManeuverRequest& r, ModelSpec spec) {
  if (r.integrator) {
    if (!is_integrator_name(*r.integrator))
      throw std::invalid_argument(option_name(r.style, "integrator") + ": unknown integrator \"" + *r.integrator +
                                  "\" (expected one of " + integrator_names() + ")");
    spec.solver.integrator = *r.integrator;
  }
  spec.analysis.operating_point = "steady";
  if (r.speed) spec.analysis.steady.speed = *r.speed;
  spec.analysis.steady.yaw_rate.reset();
  spec.analysis.steady.radius.reset();
  spec.analysis.steady.lateral_acceleration.reset();
  return spec;
}

// a run that left the road, or spun
void check_run(ManeuverReport& rep, const SimulationResult& res, const Model& m, int body) {
  if (res.stats.integrator_fell_back) rep.notes.push_back("integrator " + res.stats.integrator_choice);
  Data d(m);
  double worst = 0, at = 0;
  for (int k = 0; k < res.samples(); ++k) {
    const BodyState s = body_state(m, d, body, res.q.row(k).transpose(), res.v.row(k).transpose());
    const double beta = std::atan2(s.v_body.y(), std::abs(s.v_body.x()));
    if (std::abs(beta) > worst) {
      worst = std::abs(beta);
      at = res.t[static_cast<std::size_t>(k)];
    }
  }
  rep.max_sideslip = worst;
  rep.max_sideslip_time = at;
  if (!res.completed) {
    rep.valid = false;
    rep.invalid_reason = "the run did not complete: " + (res.failure.empty() ? std::string("cancelled") : res.failure);
  } else if (worst > 20 * kPi / 180) {
    std::ostringstream os;
    os << "the car spun out: its sideslip reached " << worst * 180 / kPi << " deg at t = " << at << " s";
    rep.valid = false;
    rep.invalid_reason = os.str();
  }
}

std::vector<double> column(const SimulationResult& r, int k) {
  std::vector<double> c(static_cast<std::size_t>(r.samples()));
  for (int i = 0; i < r.samples(); ++i) c[static_cast<std::size_t>(i)] = r.y(i, k);
  return c;
}

void write(ManeuverReport& rep, const ManeuverRequest& r) {
  if (!r.out.empty()) {
    study_write_results_hdf5(rep.result, r.out);
    rep.written.push_back(r.out);
  }
  if (!r.csv.empty()) {
    study_write_results_csv(rep.result, r.csv);
    rep.written.push_back(r.csv);
  }
}


void attach_controller(OpenLoop& ol, const ManeuverRequest& r, const ModelSpec& spec, bool controlled) {
  const Model& m = ol.model;
  const Flags flag{r.style};
  const std::string kind = to_string(m.spec.controller.type);
  if (!controlled)
    throw std::invalid_argument(flag("open-loop") + ": the model file has a " + kind + " controller, and a " + r.type +
                                " maneuver compares the run with the open-loop linear model: run it " + flag("open-loop") +
                                " (the controller left out)");
  const std::string& steer = m.spec.analysis.handling.steer;
  for (int k : m.plant_inputs)
    if (m.actuators[static_cast<std::size_t>(k)].name == steer)
      throw ModelError(m.source_file, "/plant/inputs",
                       "the maneuver drives the steer \"" + steer + "\", and the model file's " + kind +
                           " controller acts on it too (a Plant/In): give the controller other inputs (brakes, a yaw "
                           "moment, rear steer), or run the maneuver " + flag("open-loop"));
  if (m.plant_inputs.empty()) throw ModelError(m.source_file, "/plant/inputs", "the model file's controller needs Plant/In actuators");
  // about the straight run, wherever the file says its controller was designed: a maneuver starts there
  auto plant = std::make_shared<LinearPlant>();
  plant->op = ol.op;
  LinearizeOptions lo;
  lo.independent = m.spec.analysis.independent;
  plant->lin = linearize(m, plant->op, lo);
  ol.controller = make_model_controller(m, *plant);
  ol.plant = plant;
  ol.controller_text = "the model file's " + kind + " controller: " + ol.controller->describe();
  if (ol.yaw_rate < 0) return;
  // the intended yaw rate: the steady yaw rate of the linear car for the steer (its straight run,
  // steer in, yaw rate out), limited to what the road holds at the run's speed
  const double mu = positive(flag, r.friction, 0.85, "friction");
  std::optional<HandlingNumbers> h;
  try {
    h = straight_handling(ol);
  } catch (const std::exception&) {
  }
  if (!h || !(h->yaw_rate_gain != 0))
    throw ModelError(m.source_file, "/analysis/handling",
                     "the controller's yaw-rate reference needs the straight run's steady yaw-rate gain, which the "
                     "linearization does not give; run the maneuver " + flag("open-loop"));
  ol.reference_gain = h->yaw_rate_gain;
  ol.reference_limit = mu * 9.80665 / std::max(ol.start.speed_along_heading, 1e-9);
}

void report_controller(ManeuverReport& rep, const OpenLoop& ol, const Model& run) {
  rep.controller = ol.controller_text;
  rep.reference_gain = ol.reference_gain;
  rep.reference_limit = ol.yaw_rate >= 0 ? ol.reference_limit : 0.0;
  if (rep.result.samples() == 0) return;
  const Eigen::VectorXd& u0 = ol.plant->op.u;
  for (int k : run.plant_inputs) {
    double largest = 0;
    for (int i = 0; i < rep.result.samples(); ++i) largest = std::max(largest, std::abs(rep.result.u(i, k) - u0[k]));
    rep.controller_inputs.push_back(run.actuators[static_cast<std::size_t>(k)].name);
    rep.controller_effort.push_back(largest);
  }
}

HandlingNumbers straight_handling(const OpenLoop& ol) {
  // what study_linearize gives a model whose only Plant/In is the steer, at the same point
  Model with = ol.model;
  with.plant_inputs = {ol.steer};
  StudyLinearization sl;
  sl.op = ol.op;
  LinearizeOptions o;
  o.method = workflow_detail::method_of_model(with);
  o.independent = with.spec.analysis.independent;
  sl.lin = linearize(with, sl.op, o);
  return workflow_detail::study_handling(with, sl);
}

OpenLoop open_loop_setup(const ManeuverRequest& r, const ModelSpec& spec, bool controlled) {
  OpenLoop ol;
  ol.model = study_model(straight_spec(r, spec), r.model);
  const Model& m = ol.model;
  const HandlingSpec& h = m.spec.analysis.handling;
  if (h.steer.empty())
    throw ModelError(m.source_file, "/analysis/handling/steer", "the maneuver needs the steer input named here");
  if (h.yaw_rate.empty())
    throw ModelError(m.source_file, "/analysis/handling/yaw_rate", "the maneuver needs the yaw-rate output named here");
  ol.steer = actuator(m, h.steer, "/analysis/handling/steer");
  ol.yaw_rate = output(m, h.yaw_rate, "/analysis/handling/yaw_rate", true);
  ol.lateral_acceleration =
      h.lateral_acceleration.empty() ? -1 : output(m, h.lateral_acceleration, "/analysis/handling/lateral_acceleration", false);
  ol.body = steady_body(m);
  ol.op = study_operating_point(m, "steady");
  Data d(m);
  ol.start = body_state(m, d, ol.body, ol.op.q, ol.op.v);
  if (!r.open_loop && has_model_controller(m) && m.spec.controller.type != ControllerType::Driver)
    attach_controller(ol, r, spec, controlled);
  return ol;
}

double steady_steer_at(const ManeuverRequest& r, const ModelSpec& spec, const OpenLoop& ol, double a_y, double speed) {
  ModelSpec s = straight_spec(r, spec);
  s.analysis.steady.speed = speed > 0 ? speed : ol.start.speed_along_heading;
  s.analysis.steady.lateral_acceleration = a_y;
  const Model m = study_model(s, r.model);
  const OperatingPoint op = study_operating_point(m, "steady");
  return op.u[ol.steer] - ol.op.u[ol.steer];
}

void steer_at_03g(ManeuverReport& rep, const ManeuverRequest& r, const ModelSpec& spec, const OpenLoop& ol,
                  const std::string& otherwise) {
  const double g03 = 0.3 * 9.80665;
  try {
    rep.steer_03g = 0.5 * (std::abs(steady_steer_at(r, spec, ol, g03)) + std::abs(steady_steer_at(r, spec, ol, -g03)));
  } catch (const std::exception& e) {
    rep.notes.push_back(std::string("no steer at 0.3 g (the steady turn at the run's speed): ") + e.what() + otherwise);
  }
}

SteerProfile piecewise_linear(const std::vector<double>& t, const std::vector<double>& v) {
  const auto segment = [t](double x) {  // the segment x lies in (right-continuous), -1 before, n-1 after
    if (x < t.front()) return -1;
    const auto it = std::upper_bound(t.begin(), t.end(), x);
    return static_cast<int>(it - t.begin()) - 1;
  };
  SteerProfile p;
  p.value = [t, v, segment](double x) {
    const int k = segment(x);
    if (k < 0) return v.front();
    if (k >= static_cast<int>(t.size()) - 1) return v.back();
    const std::size_t i = static_cast<std::size_t>(k);
    return v[i] + (v[i + 1] - v[i]) * (x - t[i]) / (t[i + 1] - t[i]);
  };
  p.rate = [t, v, segment](double x) {
    const int k = segment(x);
    if (k < 0 || k >= static_cast<int>(t.size()) - 1) return 0.0;
    const std::size_t i = static_cast<std::size_t>(k);
    return (v[i + 1] - v[i]) / (t[i + 1] - t[i]);
  };
  p.acceleration = [](double) { return 0.0; };
  return p;
}

Model open_loop_run(ManeuverReport& rep, const ManeuverRequest& r, const OpenLoop& ol, const SteerProfile& profile,
                    const std::vector<double>& stops, double t_end, const SampledBeside* beside,
                    const RunUntil& until) {
  const Flags flag{r.style};
  SimulationOptions o;
  o.integrator = integrator(ol.model);
  o.t_end = t_end;
  o.output_step = positive(flag, r.output_step, 0.005, "output-step");
  Model run = held_at(ol.model, ol.op, o);
  const Eigen::Index nu = run.nu();
  const int ks = ol.steer;
  const auto one = [nu, ks](double x) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(nu);
    v[ks] = x;
    return v;
  };
  o.disturbance = [one, profile](double t) { return one(profile.value(t)); };
  o.disturbance_rate = [one, profile](double t) { return one(profile.rate(t)); };
  o.disturbance_acceleration = [one, profile](double t) { return one(profile.acceleration(t)); };
  o.rate_jumps = stops;
  if (beside) o.beside = *beside;
  if (ol.controller) {
    const Eigen::VectorXd y0 = ol.plant->lin.system.y0;
    const int iy = ol.yaw_rate;
    const double gain = ol.reference_gain, limit = ol.reference_limit;
    if (iy >= 0)
      o.reference = [y0, iy, gain, limit, profile](double t) {
        Eigen::VectorXd ref = y0;
        ref[iy] += std::clamp(gain * profile.value(t), -limit, limit);
        return ref;
      };
  }
  // the run stops when the car rolls over (past kRolledOver: it does not come back, and a car on its
  // side is no maneuver), seen at each output sample; the user's cancel goes to the integrator itself,
  // which sees it inside its steps
  std::atomic<bool> rolled{false};
  double rolled_at = -1, roll_reached = 0;
  bool reached = false;  // `until` said so
  Data dk(run);
  const int body = ol.body;
  SimulationCallbacks cb;
  cb.cancel = r.cancel;
  cb.stop = &rolled;
  cb.progress = r.progress;
  cb.on_sample = [&](const Snapshot& sn) {
    forward_kinematics<double>(run, dk, sn.q, sn.v);
    const SE3& X = dk.oMi[static_cast<std::size_t>(body)];
    const double roll = std::atan2(X.R(2, 1), X.R(2, 2));
    if (std::abs(roll) > kRolledOver && rolled_at < 0) {
      rolled_at = sn.t;
      roll_reached = roll;
      rolled.store(true);
    }
    if (until && rolled_at < 0 && !reached && until(run, sn)) {
      reached = true;
      rolled.store(true);  // the same stop: the run ends here
    }
  };
  rep.result = simulate(run, ol.controller.get(), ol.plant.get(), o, cb);
  if ((r.cancel && r.cancel->load()) || (rep.result.cancelled && rolled_at < 0 && !reached))
    throw StudyCancelled("the maneuver was cancelled");
  if (reached) {  // ended where the caller asked: a complete run to there
    rep.result.cancelled = false;
    rep.result.completed = true;
  }
  if (ol.controller) report_controller(rep, ol, run);
  check_run(rep, rep.result, run, ol.body);
  if (rolled_at >= 0) {
    std::ostringstream os;
    os << "the car rolled over: its roll reached " << std::abs(roll_reached) * 180 / kPi << " deg at t = " << rolled_at
       << " s (the run stopped there)";
    rep.valid = false;
    rep.invalid_reason = os.str();
  }
  if (rep.result.samples() > 0) {
    Data d(run);
    const int last = rep.result.samples() - 1;
    const BodyState e = body_state(run, d, ol.body, rep.result.q.row(last).transpose(), rep.result.v.row(last).transpose());
    rep.end_speed = e.speed_along_heading;
    rep.end_yaw_rate = e.yaw_rate;
  }
  return run;
}

// The driver's position, heading and forward speed: a name the model has no sensor of (and the
// request did not give) is measured on the steady body's origin by a sensor the maneuver adds
// under that name (the chassis origin's x and y in the ground's axes, its heading about the
// vertical, its forward speed in its own axes); a note says so.
ModelSpec with_driver_sensors(ModelSpec s, const DriverSignals& names, const ManeuverRequest& r,
                              std::vector<std::string>& notes, bool speed_only) {
  const auto has = [&s](const std::string& n) {
    return std::any_of(s.sensors.begin(), s.sensors.end(), [&n](const SensorSpec& x) { return x.name == n; });
  };
  struct Wanted {
    const std::string& name;
    bool given;
    SensorType type;
    int component;
    const char* what;
  };
  const Wanted wanted[] = {{names.x, r.x.has_value(), SensorType::PointPosition, 0, "x in the ground's axes"},
                           {names.y, r.y.has_value(), SensorType::PointPosition, 1, "y in the ground's axes"},
                           {names.yaw, r.yaw.has_value(), SensorType::BodyAngle, 2, "heading about the vertical"},
                           {names.speed, r.speed_output.has_value(), SensorType::PointVelocity, 0, "forward speed"}};
  std::string body = s.analysis.steady.body, added;
  for (const Wanted& w : wanted) {
    if (w.given || has(w.name) || (speed_only && w.type != SensorType::PointVelocity)) continue;
    if (body.empty()) {
      const Model m = study_model(s, r.model);
      body = m.body_names[static_cast<std::size_t>(steady_body(m))];
    }
    SensorSpec x;
    x.name = w.name;
    x.type = w.type;
    x.body = body;
    x.component = w.component;
    x.axis = Eigen::Vector3d::UnitZ();
    if (w.type == SensorType::PointVelocity) x.frame = body;
    s.sensors.push_back(x);
    added += (added.empty() ? "" : ", ") + ("\"" + w.name + "\" (" + w.what + ")");
  }
  if (!added.empty())
    notes.push_back(std::string(speed_only ? "the speed controller" : "the driver") + " reads " + body + "'s origin through sensors the maneuver added, the model having none of those names: " + added);
  return s;
}

void lane_layout(ManeuverReport& rep, const DriverPath& local, const Eigen::Vector2d& start, double heading) {
  const Eigen::Rotation2Dd rot(heading);
  rep.lane_path.clear();
  rep.lane_cones.clear();
  for (const Eigen::Vector2d& p : local.points) rep.lane_path.push_back(start + rot * p);
  for (std::size_t g = 0; g < local.gate_start.size(); ++g) {
    const double x0 = local.gate_start[g], x1 = local.gate_end[g];
    const int n = std::max(2, static_cast<int>(std::ceil((x1 - x0) / 5.0)) + 1);
    for (int k = 0; k < n; ++k)
      for (const double side : {-0.5, 0.5}) {
        const Eigen::Vector2d p(x0 + (x1 - x0) * k / (n - 1), local.gate_center[g] + side * local.gate_width[g]);
        rep.lane_cones.push_back(start + rot * p);
      }
  }
}

}  // namespace codyna::mnv

namespace codyna {

int study_maneuver_body(const Model& m) { return mnv::steady_body(m); }

}  // namespace codyna
