// The steady-state maneuvers (ISO 4138): constant radius and constant speed, each a sequence of
// the steady-motion search's turns, with the linear model's prediction of the same diagram
// (study/maneuver_job.hpp).
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/maneuver_detail.hpp"
#include "study/workflow.hpp"

namespace codyna::mnv {

namespace {

// one turn of the diagram: the search's speed and, by radius (m, signed) or by lateral
// acceleration (m/s^2, signed), its turn
struct TurnAsked {
  double speed = 0, radius = 0, lateral_acceleration = 0;
};

struct SteadyTurns {
  Model model;
  int steer = -1, body = -1;
  double ratio = 1;
  std::vector<double> yaw_rates;  // of each turn, about the road's normal
};

SteadyTurns steady_setup(const ManeuverRequest& r, const ModelSpec& spec, const TurnAsked& first) {
  ModelSpec s = spec;
  s.analysis.operating_point = "steady";
  s.analysis.steady.yaw_rate.reset();
  s.analysis.steady.lateral_acceleration.reset();
  s.analysis.steady.radius.reset();
  s.analysis.steady.speed = first.speed;
  SteadyTurns st{study_model(s, r.model), -1, -1, 1.0, {}};
  const Model& m = st.model;
  const HandlingSpec& h = m.spec.analysis.handling;
  if (h.steer.empty())
    throw ModelError(m.source_file, "/analysis/handling/steer", "the maneuver needs the steer input named here");
  st.steer = actuator(m, h.steer, "/analysis/handling/steer");
  st.ratio = h.steering_ratio ? *h.steering_ratio : 1.0;
  st.body = steady_body(m);
  return st;
}

// Each turn asked in order, each search started from the one before (a continuation); the table's
// rows; a turn the search does not find ends the table (rep invalid with the reason).
void steady_turns(ManeuverReport& rep, SteadyTurns& st, const std::vector<TurnAsked>& turns, bool a_from_radius,
                  const std::atomic<bool>* r_cancel) {
  Model& m = st.model;
  Data d(m);
  rep.cr_has_roll = m.joints[static_cast<std::size_t>(st.body)].type == JointType::Free;
  for (const TurnAsked& t : turns) {
    if (r_cancel && r_cancel->load()) throw StudyCancelled("the maneuver was cancelled");
    m.spec.analysis.steady.speed = t.speed;
    if (a_from_radius) m.spec.analysis.steady.radius = t.radius;
    else m.spec.analysis.steady.lateral_acceleration = t.lateral_acceleration;
    OperatingPoint op;
    try {
      op = study_operating_point(m, "steady");
    } catch (const std::exception& e) {
      rep.valid = false;
      std::ostringstream os;
      os << "no steady turn at " << t.speed << " m/s ";
      if (a_from_radius) os << "on the " << t.radius << " m radius (a_y " << t.speed * t.speed / std::abs(t.radius) << " m/s^2)";
      else os << "at a_y " << t.lateral_acceleration << " m/s^2";
      os << ": " << e.what();
      rep.invalid_reason = os.str();
      break;
    }
    m.q0 = op.q;
    m.v0 = op.v;
    for (std::size_t k = 0; k < m.actuators.size(); ++k) m.actuators[k].u0 = op.u[static_cast<Eigen::Index>(k)];
    const BodyState b = body_state(m, d, st.body, op.q, op.v);
    const double speed = b.v_body.norm();  // the centre of mass's
    rep.cr_speed.push_back(t.speed);        // along the heading in the road plane, as the search sets it
    // on one radius V^2 / R; at one speed V r (the centre of mass's, on its circle)
    rep.cr_lateral_acceleration.push_back(a_from_radius ? (t.radius > 0 ? 1.0 : -1.0) * speed * speed / std::abs(t.radius)
                                                        : speed * b.yaw_rate);
    rep.cr_steer.push_back(op.u[st.steer]);
    rep.cr_road_wheel.push_back(op.u[st.steer] / st.ratio);
    rep.cr_sideslip.push_back(std::atan2(b.v_body.y(), b.v_body.x()));
    rep.cr_roll.push_back(rep.cr_has_roll ? b.roll : 0.0);
    st.yaw_rates.push_back(b.yaw_rate);
  }
}

// The linear model's prediction of the diagram: at each point's speed U the linearization about
// the straight run gives its steer s0(U) and constant-speed yaw-rate gain G(U), so the turn of yaw
// rate r takes s0 + r / G; the gradient on the same a_y is the diagram's linear counterpart (on one
// radius it holds what changes with speed, dK/dU, and the steering's own ratio, which the handling
// number K at one speed does not). Returns the wheelbase of the handling numbers (0: none).
double linear_diagram(ManeuverReport& rep, const ManeuverRequest& r, const ModelSpec& spec, const SteadyTurns& st) {
  double wheelbase = 0;
  try {
    std::optional<StudyLinearization> lin;
    for (std::size_t k = 0; k < rep.cr_speed.size(); ++k) {
      if (!lin || rep.cr_speed[k] != rep.cr_speed[k - 1]) {
        ModelSpec ls = straight_spec(r, spec);
        ls.analysis.steady.speed = rep.cr_speed[k];
        lin = study_linearize(study_model(ls, r.model));
      }
      if (!lin->handling || !(lin->handling->yaw_rate_gain != 0)) {
        rep.notes.push_back("no linear understeer gradient to compare with: the straight run at " +
                            std::to_string(rep.cr_speed[k]) + " m/s has no yaw-rate gain (analysis.handling)");
        rep.cr_linear_steer.clear();
        return 0;
      }
      if (k == 0) {
        rep.handling_gradient = lin->handling->understeer_gradient;
        wheelbase = lin->handling->wheelbase;
      }
      rep.cr_linear_steer.push_back(lin->op.u[st.steer] + st.yaw_rates[k] / lin->handling->yaw_rate_gain);
    }
  } catch (const std::exception& e) {
    rep.notes.push_back(std::string("no linear understeer gradient to compare with: ") + e.what());
    rep.cr_linear_steer.clear();
    return 0;
  }
  if (rep.cr_linear_steer.size() < 2) return wheelbase;
  std::vector<double> road_wheel;
  for (double s : rep.cr_linear_steer) road_wheel.push_back(s / st.ratio);
  rep.cr_linear_gradient = understeer_diagram(rep.cr_lateral_acceleration, road_wheel);
  return wheelbase;
}

// the table as CSV (--csv)
void write_diagram(ManeuverReport& rep, const ManeuverRequest& r) {
  study_guard_output(r.csv, OutputKind::CurvesCsv, {r.model});
  const auto at = [](const std::vector<double>& v, std::size_t k) { return k < v.size() ? v[k] : std::nan(""); };
  std::ostringstream os;
  os << std::setprecision(17)
     << "speed,lateral_acceleration,steer,road_wheel_angle,sideslip,roll,understeer_gradient,linear_steer,"
        "linear_understeer_gradient\n";
  for (std::size_t k = 0; k < rep.cr_speed.size(); ++k)
    os << rep.cr_speed[k] << "," << rep.cr_lateral_acceleration[k] << "," << rep.cr_steer[k] << ","
       << rep.cr_road_wheel[k] << "," << rep.cr_sideslip[k] << "," << rep.cr_roll[k] << "," << at(rep.cr_gradient, k)
       << "," << at(rep.cr_linear_steer, k) << "," << at(rep.cr_linear_gradient, k) << "\n";
  write_file_atomically(r.csv, os.str());
  rep.written.push_back(r.csv);
}

int diagram_points(const Flags& flag, const ManeuverRequest& r) {
  const int n = r.points ? *r.points : 8;
  if (n < 2 || n > 1000) throw std::invalid_argument(flag("points") + ": expected 2 to 1000 points");
  return n;
}

}  // namespace

ManeuverReport constant_radius(const ManeuverRequest& r, const ModelSpec& spec) {
  const Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  if (!r.radius) throw std::invalid_argument(flag("radius") + ": the constant-radius maneuver needs a radius (m)");
  if (!(*r.radius != 0) || !std::isfinite(*r.radius))
    throw std::invalid_argument(flag("radius") + ": expected a radius other than 0 (m, > 0 turns left)");
  rep.radius = *r.radius;
  const double u_min = positive(flag, r.speed_min, 5.0, "speed-min");
  const double u_max = positive(flag, r.speed_max, std::sqrt(0.6 * 9.81 * std::abs(rep.radius)), "speed-max");
  if (!(u_max > u_min)) throw std::invalid_argument(flag("speed-max") + ": expected a speed above " + flag("speed-min"));
  const int n = diagram_points(flag, r);
  std::vector<TurnAsked> turns;
  for (int i = 0; i < n; ++i) turns.push_back({u_min + (u_max - u_min) * i / (n - 1), rep.radius, 0});
  SteadyTurns st = steady_setup(r, spec, turns.front());
  rep.model_name = st.model.name;
  steady_turns(rep, st, turns, true, r.cancel);
  if (rep.cr_speed.size() >= 2) rep.cr_gradient = understeer_diagram(rep.cr_lateral_acceleration, rep.cr_road_wheel);
  linear_diagram(rep, r, spec, st);
  if (!rep.cr_linear_gradient.empty()) rep.linear_gradient = rep.cr_linear_gradient.front();
  rep.speed = u_min;
  if (!r.csv.empty()) write_diagram(rep, r);
  return rep;
}

ManeuverReport constant_speed(const ManeuverRequest& r, const ModelSpec& spec) {
  const Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  const double a_min = r.ay_min ? *r.ay_min : 0.5, a_max = r.ay_max ? *r.ay_max : 0.6 * 9.80665;
  if (!std::isfinite(a_min) || a_min == 0) throw std::invalid_argument(flag("ay-min") + ": expected a lateral acceleration other than 0 (m/s^2, > 0 turns left)");
  if (!std::isfinite(a_max) || !(std::abs(a_max) > std::abs(a_min)) || a_max * a_min < 0)
    throw std::invalid_argument(flag("ay-max") + ": expected a lateral acceleration beyond " + flag("ay-min") + ", on its side");
  const int n = diagram_points(flag, r);
  const std::optional<double> speed = straight_spec(r, spec).analysis.steady.speed;  // the request's, else the file's
  const double U = speed ? *speed : 0.0;
  if (!(U > 0)) throw ModelError(r.model, "/analysis/steady/speed", "the constant-speed maneuver needs a speed (--speed)");
  std::vector<TurnAsked> turns;
  for (int i = 0; i < n; ++i) turns.push_back({U, 0, a_min + (a_max - a_min) * i / (n - 1)});
  SteadyTurns st = steady_setup(r, spec, turns.front());
  rep.model_name = st.model.name;
  rep.speed = U;
  steady_turns(rep, st, turns, false, r.cancel);
  const double L = linear_diagram(rep, r, spec, st);
  // the understeer gradient at one speed: d(delta)/d(a_y) - L / U^2 (the kinematic steer's share)
  if (rep.cr_speed.size() >= 2 && L > 0) {
    rep.cr_gradient = understeer_diagram(rep.cr_lateral_acceleration, rep.cr_road_wheel);
    for (double& K : rep.cr_gradient) K -= L / (U * U);
    for (double& K : rep.cr_linear_gradient) K -= L / (U * U);
    if (!rep.cr_linear_gradient.empty()) rep.linear_gradient = rep.cr_linear_gradient.front();
  } else if (rep.cr_speed.size() >= 2) {
    rep.notes.push_back("no understeer gradient: the wheelbase comes from the handling numbers (analysis.handling)");
  }
  if (!r.csv.empty()) write_diagram(rep, r);
  return rep;
}

}  // namespace codyna::mnv
