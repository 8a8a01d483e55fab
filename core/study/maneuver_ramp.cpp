// The maneuvers whose steer is a ramp at a set rate (study/maneuver_job.hpp): slowly increasing
// steer (SAE J266, FMVSS 126 S5.1.2's characterization) and NHTSA's fishhook (fixed timing).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "model/errors.hpp"
#include "study/maneuver_detail.hpp"
#include "study/tire_contacts.hpp"
#include "study/workflow.hpp"

namespace codyna::mnv {

namespace {

constexpr double kG = 9.80665;

// the amplitude: --steer, or --steer-scale times the steady steer at 0.3 g (scale_default when
// neither is given); refused when neither can be had
double ramp_amplitude(ManeuverReport& rep, const ManeuverRequest& r, const ModelSpec& spec, const OpenLoop& ol,
                      double scale_default) {
  const Flags flag{r.style};
  if (r.steer && r.steer_scale)
    throw std::invalid_argument(flag("steer-scale") + ": give the amplitude or its scale, not both (" + flag("steer") + ")");
  if (r.steer) {
    if (!std::isfinite(*r.steer) || *r.steer == 0) throw std::invalid_argument(flag("steer") + ": expected a steer other than 0");
    return *r.steer;
  }
  const double scale = r.steer_scale ? *r.steer_scale : scale_default;
  if (!std::isfinite(scale) || scale == 0)
    throw std::invalid_argument(flag("steer-scale") + ": expected a multiple of the steer at 0.3 g other than 0");
  steer_at_03g(rep, r, spec, ol, "");
  if (!std::isfinite(rep.steer_03g))
    throw std::invalid_argument(flag("steer") + ": give the amplitude; " + rep.notes.back());
  return scale * rep.steer_03g;
}

double ramp_rate(const ManeuverRequest& r, double fallback) { return positive(Flags{r.style}, r.steer_rate, fallback, "steer-rate"); }

// the steady body's state at every sample
std::vector<BodyState> ramp_states(const Model& run, const ManeuverReport& rep, int body) {
  Data d(run);
  std::vector<BodyState> out;
  out.reserve(static_cast<std::size_t>(rep.result.samples()));
  for (int k = 0; k < rep.result.samples(); ++k)
    out.push_back(body_state(run, d, body, rep.result.q.row(k).transpose(), rep.result.v.row(k).transpose()));
  return out;
}

// the straight run's handling numbers with the steer as the input (its K, L and steering ratio)
std::optional<HandlingNumbers> ramp_handling(ManeuverReport& rep, const OpenLoop& ol) {
  try {
    return straight_handling(ol);
  } catch (const std::exception& e) {
    rep.notes.push_back(std::string("no handling numbers to compare with: ") + e.what());
  }
  return std::nullopt;
}

}  // namespace

namespace {

// The speed held through the run by a PI on the forward speed (--drive, --speed-kp, --speed-ki,
// --speed-output, --sample-time), beside the file's controller: its reference the speed output's
// value at the start
std::unique_ptr<Controller> speed_hold(ManeuverReport& rep, const ManeuverRequest& r, const OpenLoop& ol,
                                       const std::string& speed_name, SampledBeside& hold) {
  const Flags flag{r.style};
  const Model& m = ol.model;
  const auto find = [](const auto& list, const std::string& name) {
    for (std::size_t k = 0; k < list.size(); ++k)
      if (list[k].name == name) return static_cast<int>(k);
    return -1;
  };
  const int drive = find(m.actuators, *r.drive), speed = find(m.sensors, speed_name);
  if (drive < 0) {
    std::string all;
    for (const ActuatorModel& a : m.actuators) all += (all.empty() ? "" : ", ") + a.name;
    throw std::invalid_argument(flag("drive") + ": the speed controller needs the actuator \"" + *r.drive +
                                "\", which the model does not have (actuators: " + all + ")");
  }
  if (speed < 0) throw std::invalid_argument(flag("speed-output") + ": the model has no sensor \"" + speed_name + "\"");
  if (ol.controller && std::count(m.plant_inputs.begin(), m.plant_inputs.end(), drive))
    throw std::invalid_argument(flag("drive") + ": \"" + *r.drive + "\" is a Plant/In of the model file's controller, which acts on it already");
  if (drive == ol.steer) throw std::invalid_argument(flag("drive") + ": \"" + *r.drive + "\" is the steer the maneuver drives");
  SpeedHoldSettings s;
  s.kp = r.speed_kp.value_or(0.0);
  s.ki = r.speed_ki.value_or(0.0);
  if (!(s.kp >= 0)) throw std::invalid_argument(flag("speed-kp") + ": expected a number >= 0");
  if (!(s.ki >= 0)) throw std::invalid_argument(flag("speed-ki") + ": expected a number >= 0");
  if (s.kp == 0 && s.ki == 0)
    throw std::invalid_argument(flag("speed-kp") + ": the speed held through " + flag("drive") + " needs a gain > 0 (" +
                                flag("speed-kp") + " or " + flag("speed-ki") + ")");
  s.sample_time = positive(flag, r.sample_time, 0.01, "sample-time");
  s.u0 = ol.op.u[drive];
  Data d(m);
  forward_kinematics<double>(m, d, ol.op.q, ol.op.v);
  d.s = ol.op.s;
  s.speed = sensor_outputs<double>(m, d, std::vector<int>{speed}, ol.op.q, ol.op.v)[0];
  std::unique_ptr<Controller> pi = make_speed_hold(s, flag("drive"));
  hold.controller = pi.get();
  hold.sensors = {speed};
  hold.actuators = {drive};
  rep.speed_hold = "\"" + *r.drive + "\" by a " + pi->describe() + " (of \"" + speed_name + "\")";
  return pi;
}

}  // namespace

ManeuverReport slowly_increasing_steer(const ManeuverRequest& r, const ModelSpec& spec_given) {
  const Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  // the speed held (SAE J266's constant speed) when a drive is given: its speed sensor added when
  // the model has none of that name
  ModelSpec spec = spec_given;
  DriverSignals names;
  if (r.speed_output) names.speed = *r.speed_output;
  if (r.drive) spec = with_driver_sensors(std::move(spec), names, r, rep.notes, true);
  else if (r.speed_kp || r.speed_ki || r.speed_output || r.sample_time)
    throw std::invalid_argument(flag(r.speed_kp ? "speed-kp" : r.speed_ki ? "speed-ki" : r.speed_output ? "speed-output" : "sample-time") +
                                ": the speed is held only through a drive input (" + flag("drive") + ")");
  const OpenLoop ol = open_loop_setup(r, spec, true);
  rep.model_name = ol.model.name;
  rep.speed = ol.start.v_body.norm();
  SampledBeside hold;
  std::unique_ptr<Controller> pi;
  if (r.drive) pi = speed_hold(rep, r, ol, names.speed, hold);
  const double amplitude = ramp_amplitude(rep, r, spec, ol, 2.5);
  rep.steer = amplitude;
  const double rate = ramp_rate(r, 13.5 * kPi / 180);
  const double t0 = r.steer_time ? *r.steer_time : 0.5;
  if (!(t0 >= 0) || !std::isfinite(t0)) throw std::invalid_argument(flag("steer-time") + ": expected a time >= 0");
  const double T = std::abs(amplitude) / rate;
  rep.steer_start = t0;
  rep.steer_end = t0 + T;
  const double t_end = r.t_end ? *r.t_end : t0 + T;
  if (!(t_end > t0) || !std::isfinite(t_end)) throw std::invalid_argument(flag("t-end") + ": expected a time past the steer's start");
  const double sign = amplitude > 0 ? 1.0 : -1.0;
  const std::optional<HandlingNumbers> h = ramp_handling(rep, ol);
  if (h) rep.handling_gradient = h->understeer_gradient;
  const Model run = open_loop_run(rep, r, ol, piecewise_linear({t0, t0 + T}, {0.0, amplitude}), {t0, t0 + T}, t_end,
                                  pi ? &hold : nullptr);
  if (rep.result.samples() < 3) return rep;
  const std::vector<BodyState> st = ramp_states(run, rep, ol.body);
  const std::vector<double>& t = rep.result.t;
  const auto steer_at = [&](std::size_t k) { return rep.result.u(static_cast<Eigen::Index>(k), ol.steer) - ol.op.u[ol.steer]; };
  const auto ay = [&](std::size_t k) { return st[k].speed_along_heading * st[k].yaw_rate; };
  for (std::size_t k = 0; k < st.size(); ++k) {
    if (std::abs(ay(k)) > rep.sis_ay_max) {
      rep.sis_ay_max = std::abs(ay(k));
      rep.sis_steer_at_ay_max = steer_at(k);
      rep.sis_time_ay_max = t[k];
    }
    if (std::isnan(rep.sis_steer_03g) && k > 0 && std::abs(ay(k)) >= 0.3 * kG) {
      // linear interpolation between the samples either side
      const double a0 = std::abs(ay(k - 1)), a1 = std::abs(ay(k)), w = (0.3 * kG - a0) / (a1 - a0);
      rep.sis_steer_03g = steer_at(k - 1) + w * (steer_at(k) - steer_at(k - 1));
      rep.sis_time_03g = t[k - 1] + w * (t[k] - t[k - 1]);
      rep.sis_speed_03g = st[k - 1].speed_along_heading + w * (st[k].speed_along_heading - st[k - 1].speed_along_heading);
    }
  }
  if (std::isnan(rep.sis_steer_03g)) {
    rep.notes.push_back("the run does not reach 0.3 g (largest |a_y| " + std::to_string(rep.sis_ay_max) +
                        " m/s^2): raise the amplitude (" + flag("steer") + ")");
  } else {
    // the steady turns at the run's speed there: at 0.3 g, and at 0.1 g for the gradient's secant
    try {
      rep.sis_steady_steer_03g = steady_steer_at(r, spec, ol, sign * 0.3 * kG, rep.sis_speed_03g);
      if (h && h->wheelbase > 0) {
        const double s01 = steady_steer_at(r, spec, ol, sign * 0.1 * kG, rep.sis_speed_03g);
        rep.sis_steady_gradient = sign * (rep.sis_steady_steer_03g - s01) / h->steering_ratio / (0.2 * kG) -
                                  h->wheelbase / (rep.sis_speed_03g * rep.sis_speed_03g);
      }
    } catch (const std::exception& e) {
      rep.notes.push_back(std::string("no steady turn to compare with: ") + e.what());
    }
  }
  if (std::isfinite(rep.sis_steer_03g) && h && h->wheelbase > 0) {
    // delta / ratio - L r / U = K a_y in every steady turn: its slope over a_y between 0.1 and 0.3 g
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (std::size_t k = 0; k < st.size() && t[k] <= rep.sis_time_03g; ++k) {
      const double a = std::abs(ay(k));
      if (a < 0.1 * kG) continue;
      const double x = sign * ay(k);
      const double y = sign * (steer_at(k) / h->steering_ratio - h->wheelbase * st[k].yaw_rate / st[k].speed_along_heading);
      sx += x, sy += y, sxx += x * x, sxy += x * y;
      ++n;
    }
    if (n >= 3) rep.sis_gradient = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  }
  write(rep, r);
  return rep;
}

namespace {

// the steady body's roll (atan2(R21, R22) of its rotation) and its rate (the roll's derivative
// along v: by the tangent step q (+) eps v, eps 1e-7 s)
struct Roll {
  double angle = 0, rate = 0;
};
Roll body_roll(const Model& m, Data& d, int body, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  const auto angle = [&](const Eigen::VectorXd& x) {
    forward_kinematics<double>(m, d, x, v);
    const SE3& X = d.oMi[static_cast<std::size_t>(body)];
    return std::atan2(X.R(2, 1), X.R(2, 2));
  };
  const double eps = 1e-7;
  Roll r;
  r.angle = angle(q);
  const Eigen::VectorXd ahead = integrate<double>(m, q, Eigen::VectorXd(eps * v));
  r.rate = std::remainder(angle(ahead) - r.angle, 2 * kPi) / eps;
  return r;
}

}  // namespace

ManeuverReport fishhook(const ManeuverRequest& r, const ModelSpec& spec) {
  const Flags flag{r.style};
  if (r.dwell && r.dwell_roll_rate)
    throw std::invalid_argument(flag("dwell-roll-rate") + ": give the dwell or the roll rate that ends it, not both (" + flag("dwell") + ")");
  if (r.dwell_roll_rate && (!(*r.dwell_roll_rate > 0) || !std::isfinite(*r.dwell_roll_rate)))
    throw std::invalid_argument(flag("dwell-roll-rate") + ": expected a roll rate > 0 (deg/s; NHTSA: 1.5)");
  ManeuverReport rep;
  rep.type = r.type;
  const OpenLoop ol = open_loop_setup(r, spec, true);
  rep.model_name = ol.model.name;
  rep.speed = ol.start.v_body.norm();
  if (ol.model.tires.empty())
    throw ModelError(ol.model.source_file, "/effects", "the fishhook reads the tires' loads: the model has no tire");
  const double A = ramp_amplitude(rep, r, spec, ol, 6.5);
  rep.steer = A;
  const double rate = ramp_rate(r, 720 * kPi / 180);
  double dwell = r.dwell ? *r.dwell : 0.25;
  if (!(dwell >= 0) || !std::isfinite(dwell)) throw std::invalid_argument(flag("dwell") + ": expected a time >= 0");
  const double t0 = r.steer_time ? *r.steer_time : 0.5;
  if (!(t0 >= 0) || !std::isfinite(t0)) throw std::invalid_argument(flag("steer-time") + ": expected a time >= 0");
  const double t1 = t0 + std::abs(A) / rate;
  if (r.dwell_roll_rate) {
    // NHTSA's roll-rate feedback: a first run to A and held there finds where the roll rate, once
    // past the threshold, falls back to it at or after the steer's peak (linear between samples);
    // that run and the maneuver's are the same up to there (same profile, stops and samples)
    const double threshold = *r.dwell_roll_rate * kPi / 180;
    const double longest = 5.0;  // s of dwell looked through
    double switch_at = -1, last_t = 0, last_rate = 0;
    bool armed = false;
    std::unique_ptr<Data> dd;
    const RunUntil until = [&](const Model& run, const Snapshot& sn) {
      if (!dd) dd = std::make_unique<Data>(run);
      const double p = std::abs(body_roll(run, *dd, ol.body, sn.q, sn.v).rate);
      const double prev_t = last_t, prev = last_rate;
      last_t = sn.t, last_rate = p;
      if (p > threshold) armed = true;
      if (!armed || sn.t < t1 - 1e-12 || p > threshold) return false;
      const double crossing = prev > threshold ? prev_t + (prev - threshold) / (prev - p) * (sn.t - prev_t) : sn.t;
      switch_at = std::max(t1, std::min(crossing, sn.t));
      return true;
    };
    ManeuverReport first;
    first.type = r.type;
    open_loop_run(first, r, ol, piecewise_linear({t0, t1}, {0.0, A}), {t0, t1}, t1 + longest, nullptr, until);
    if (switch_at < 0) {
      // never fell back (or never rose): the run to A and held is what there is to report
      std::ostringstream os;
      os << "the roll rate did not " << (armed ? "fall back to " : "reach ") << *r.dwell_roll_rate << " deg/s within "
         << longest << " s of the steer's first peak: no roll-rate dwell";
      if (first.valid) {
        first.valid = false;
        first.invalid_reason = os.str();
      }
      first.model_name = rep.model_name;
      first.speed = rep.speed;
      first.steer = rep.steer;
      first.steer_03g = rep.steer_03g;
      first.notes.insert(first.notes.begin(), rep.notes.begin(), rep.notes.end());
      rep = first;
      write(rep, r);
      return rep;
    }
    dwell = switch_at - t1;
    rep.fh_roll_rate_dwell = true;
  }
  rep.fh_dwell = dwell;
  // to A, the dwell, through to -A at the same rate, held 3 s, back to zero over 2 s (NHTSA)
  const double t2 = t1 + dwell, t3 = t2 + 2 * std::abs(A) / rate, t4 = t3 + 3.0, t5 = t4 + 2.0;
  std::vector<double> knots = {t0, t1}, values = {0.0, A};
  if (dwell > 0) knots.push_back(t2), values.push_back(A);
  for (const auto& [tk, vk] : {std::pair{t3, -A}, std::pair{t4, -A}, std::pair{t5, 0.0}}) knots.push_back(tk), values.push_back(vk);
  rep.steer_start = t0;
  rep.steer_end = t5;
  const double t_end = r.t_end ? *r.t_end : t5 + 1.0;
  if (!(t_end > t0) || !std::isfinite(t_end)) throw std::invalid_argument(flag("t-end") + ": expected a time past the steer's start");
  const Model run = open_loop_run(rep, r, ol, piecewise_linear(knots, values), knots, t_end);
  if (rep.result.samples() < 1) return rep;
  const std::vector<BodyState> st = ramp_states(run, rep, ol.body);
  const std::vector<double>& t = rep.result.t;
  // each tire's side: its wheel centre in the steady body's axes at the start
  const std::vector<TireContactReport> c0 = study_tire_contacts(run, ol.op.q, ol.op.v);
  Data d(run);
  forward_kinematics<double>(run, d, ol.op.q, ol.op.v);
  const SE3& X = d.oMi[static_cast<std::size_t>(ol.body)];
  for (const TireContactReport& c : c0) {
    rep.fh_tires.push_back(c.name);
    rep.fh_sides.push_back((X.R.transpose() * (c.center - X.p)).y() > 0 ? "left" : "right");
    rep.fh_min_load.push_back(c.Fz);
    rep.fh_min_load_time.push_back(t.front());
  }
  for (std::size_t k = 0; k < st.size(); ++k) {
    if (std::abs(st[k].roll) > rep.fh_max_roll) rep.fh_max_roll = std::abs(st[k].roll), rep.fh_max_roll_time = t[k];
    rep.fh_ay_max = std::max(rep.fh_ay_max, std::abs(ol.lateral_acceleration >= 0 ? rep.result.y(static_cast<Eigen::Index>(k), ol.lateral_acceleration)
                                                                                   : st[k].speed_along_heading * st[k].yaw_rate));
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    const Eigen::VectorXd s = rep.result.s.cols() ? Eigen::VectorXd(rep.result.s.row(i).transpose()) : Eigen::VectorXd();
    const std::vector<TireContactReport> c = study_tire_contacts(run, rep.result.q.row(i).transpose(), rep.result.v.row(i).transpose(), s);
    bool off_left = true, off_right = true, any_left = false, any_right = false;
    for (std::size_t j = 0; j < c.size(); ++j) {
      if (c[j].Fz < rep.fh_min_load[j]) rep.fh_min_load[j] = c[j].Fz, rep.fh_min_load_time[j] = t[k];
      bool& off = rep.fh_sides[j] == "left" ? off_left : off_right;
      (rep.fh_sides[j] == "left" ? any_left : any_right) = true;
      off = off && !c[j].in_contact;
    }
    if (rep.fh_lift_time < 0 && ((any_left && off_left) || (any_right && off_right))) {
      rep.fh_lift_time = t[k];
      rep.fh_lift_side = any_left && off_left ? "left" : "right";
    }
  }
  write(rep, r);
  return rep;
}

}  // namespace codyna::mnv
