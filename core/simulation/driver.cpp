#include "simulation/driver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace codyna {

namespace {

constexpr double kDriverPi = 3.14159265358979323846;

double wrap_angle_driver(double a) {
  a = std::fmod(a + kDriverPi, 2 * kDriverPi);
  if (a < 0) a += 2 * kDriverPi;
  return a - kDriverPi;
}

[[noreturn]] void driver_refuse(const std::string& where, const std::string& field, const std::string& what,
                                double got) {
  std::ostringstream os;
  os << where << "/" << field << ": expected " << what << ", got " << got;
  throw std::invalid_argument(os.str());
}

std::string driver_name_list(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

class Driver final : public Controller {
 public:
  explicit Driver(DriverSettings s) : s_(std::move(s)) {}
  int nxc() const override { return 2; }
  double sample_time() const override { return s_.sample_time; }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    Eigen::VectorXd u = s_.u0;
    const DriverLaw law = driver_law(s_, in.y[s_.out_x], in.y[s_.out_y], in.y[s_.out_yaw]);
    const double delta = law.pure_pursuit - s_.lateral_gain * xc[0];
    u[s_.in_steer] = s_.steering_ratio * delta;
    if (s_.in_drive >= 0)
      u[s_.in_drive] = s_.u0[s_.in_drive] + s_.speed_kp * (s_.speed - in.y[s_.out_speed]) + s_.speed_ki * xc[1];
    return u;
  }
  Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    const PathProjection p = project_on_path(s_.path, Eigen::Vector2d(in.y[s_.out_x], in.y[s_.out_y]));
    Eigen::VectorXd next = xc;
    next[0] += s_.sample_time * p.lateral;
    if (s_.in_drive >= 0) next[1] += s_.sample_time * (s_.speed - in.y[s_.out_speed]);
    return next;
  }
  std::vector<std::string> state_names() const override { return {"driver.lateral_error_integral", "driver.speed_error_integral"}; }
  std::string describe() const override {
    std::ostringstream os;
    os << "driver (pure pursuit, preview " << s_.preview << " m, lateral gain " << s_.lateral_gain << " rad/(m s)";
    if (s_.in_drive >= 0) os << "; PI on speed " << s_.speed << " m/s, kp " << s_.speed_kp << ", ki " << s_.speed_ki;
    os << "; sampled every " << s_.sample_time << " s)";
    return os.str();
  }

 private:
  DriverSettings s_;
};

class SpeedHold final : public Controller {
 public:
  explicit SpeedHold(SpeedHoldSettings s) : s_(s) {}
  int nxc() const override { return 1; }
  double sample_time() const override { return s_.sample_time; }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    return Eigen::VectorXd::Constant(1, s_.u0 + s_.kp * (s_.speed - in.y[0]) + s_.ki * xc[0]);
  }
  Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    return Eigen::VectorXd::Constant(1, xc[0] + s_.sample_time * (s_.speed - in.y[0]));
  }
  std::vector<std::string> state_names() const override { return {"speed.error_integral"}; }
  std::string describe() const override {
    std::ostringstream os;
    os << "PI on speed " << s_.speed << " m/s, kp " << s_.kp << ", ki " << s_.ki << ", sampled every " << s_.sample_time << " s";
    return os.str();
  }

 private:
  SpeedHoldSettings s_;
};

}  // namespace

std::unique_ptr<Controller> make_speed_hold(const SpeedHoldSettings& s, const std::string& where) {
  if (!(s.kp >= 0)) driver_refuse(where, "speed_kp", "a number >= 0", s.kp);
  if (!(s.ki >= 0)) driver_refuse(where, "speed_ki", "a number >= 0", s.ki);
  if (s.kp == 0 && s.ki == 0) driver_refuse(where, "speed_kp", "a gain > 0 (or speed_ki > 0): a PI of zero gains holds nothing", s.kp);
  if (!(s.sample_time > 0) || !std::isfinite(s.sample_time)) driver_refuse(where, "sample_time", "a number > 0", s.sample_time);
  if (!std::isfinite(s.speed) || !std::isfinite(s.u0) || !std::isfinite(s.kp) || !std::isfinite(s.ki))
    throw std::invalid_argument(where + ": the speed controller's numbers must be finite");
  return std::make_unique<SpeedHold>(s);
}

PathProjection project_on_path(const DriverPath& path, const Eigen::Vector2d& p) {
  PathProjection r;
  if (path.kind == DriverPath::Kind::Circle) {
    const Eigen::Vector2d d = p - path.center;
    const double dist = d.norm();
    const double phi = dist > 0 ? std::atan2(d.y(), d.x()) : path.start_angle;
    const double sgn = path.radius > 0 ? 1.0 : -1.0;
    const double R = std::abs(path.radius);
    r.s = path.radius * wrap_angle_driver(phi - path.start_angle);
    r.point = path.center + R * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    r.tangent = sgn * Eigen::Vector2d(-std::sin(phi), std::cos(phi));
    r.lateral = sgn * (R - dist);
    return r;
  }
  double best = std::numeric_limits<double>::infinity(), s0 = 0;
  const std::size_t n = path.points.size();
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const Eigen::Vector2d a = path.points[k], b = path.points[k + 1];
    const Eigen::Vector2d ab = b - a;
    const double len = ab.norm();
    double t = ab.dot(p - a) / (len * len);
    // the ends extend the first and last segments
    if (k > 0) t = std::max(t, 0.0);
    if (k + 2 < n) t = std::min(t, 1.0);
    const Eigen::Vector2d q = a + t * ab;
    const double dist = (p - q).norm();
    if (dist < best) {
      best = dist;
      r.s = s0 + t * len;
      r.point = q;
      r.tangent = ab / len;
      const Eigen::Vector2d e = p - q;
      r.lateral = r.tangent.x() * e.y() - r.tangent.y() * e.x();
    }
    s0 += len;
  }
  return r;
}

Eigen::Vector2d path_point(const DriverPath& path, double s) {
  if (path.kind == DriverPath::Kind::Circle) {
    const double phi = path.start_angle + s / path.radius;
    return path.center + std::abs(path.radius) * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  const std::size_t n = path.points.size();
  double s0 = 0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const Eigen::Vector2d a = path.points[k], b = path.points[k + 1];
    const double len = (b - a).norm();
    if (s <= s0 + len || k + 2 == n) return a + (b - a) * ((s - s0) / len);
    s0 += len;
  }
  return path.points.front();
}

DriverPath path_table(const std::vector<Eigen::Vector2d>& points, const std::string& what) {
  if (points.size() < 2)
    throw std::invalid_argument(what + ": expected at least 2 points, got " + std::to_string(points.size()));
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!points[k].allFinite()) throw std::invalid_argument(what + "/" + std::to_string(k) + ": expected finite x, y");
    if (k > 0 && (points[k] - points[k - 1]).norm() == 0)
      throw std::invalid_argument(what + "/" + std::to_string(k) + ": the same point as the one before it");
  }
  DriverPath p;
  p.kind = DriverPath::Kind::Table;
  p.points = points;
  return p;
}

DriverPath path_straight(const Eigen::Vector2d& start, double heading, double length) {
  if (!(length > 0)) throw std::invalid_argument("straight path: expected a length > 0");
  DriverPath p;
  p.kind = DriverPath::Kind::Straight;
  p.points = {start, start + length * Eigen::Vector2d(std::cos(heading), std::sin(heading))};
  return p;
}

DriverPath path_circle(const Eigen::Vector2d& start, double heading, double radius) {
  if (!(std::abs(radius) > 0) || !std::isfinite(radius))
    throw std::invalid_argument("circle path: expected a radius != 0, got " + std::to_string(radius));
  DriverPath p;
  p.kind = DriverPath::Kind::Circle;
  p.radius = radius;
  p.center = start + radius * Eigen::Vector2d(-std::sin(heading), std::cos(heading));
  const Eigen::Vector2d d = start - p.center;
  p.start_angle = std::atan2(d.y(), d.x());
  return p;
}

DriverPath path_double_lane_change(const Eigen::Vector2d& start, double width, double lead_in, double run_out) {
  if (!(width > 0)) throw std::invalid_argument("double lane change: expected a vehicle width > 0");
  const double w1 = 1.1 * width + 0.25, w3 = width + 1.0, w5 = 1.3 * width + 0.25;
  const double y1 = 0, y3 = -w1 / 2 + 3.5 + w3 / 2, y5 = -w1 / 2 + w5 / 2;
  const double x0 = start.x() + lead_in;
  // section ends along x from x0: 15 | 30 | 25 | 25 | 15 + 15
  const double e1 = x0 + 15, e2 = e1 + 30, e3 = e2 + 25, e4 = e3 + 25, e6 = e4 + 30;
  DriverPath p;
  p.kind = DriverPath::Kind::DoubleLaneChange;
  const auto blend = [](double a, double b, double t) { return a + (b - a) * 0.5 * (1 - std::cos(kDriverPi * t)); };
  const double step = 0.1;
  for (double x = start.x(); x <= e6 + run_out + 1e-9; x += step) {
    double y = y1;
    if (x > e1 && x < e2) y = blend(y1, y3, (x - e1) / (e2 - e1));
    else if (x >= e2 && x <= e3) y = y3;
    else if (x > e3 && x < e4) y = blend(y3, y5, (x - e3) / (e4 - e3));
    else if (x >= e4) y = y5;
    p.points.emplace_back(x, start.y() + y);
  }
  p.gate_start = {x0, e2, e4};
  p.gate_end = {e1, e3, e6};
  p.gate_center = {start.y() + y1, start.y() + y3, start.y() + y5};
  p.gate_width = {w1, w3, w5};
  return p;
}

DriverLaw driver_law(const DriverSettings& s, double x, double y, double yaw) {
  DriverLaw law;
  const Eigen::Vector2d pos(x, y);
  const PathProjection p = project_on_path(s.path, pos);
  law.lateral = p.lateral;
  const Eigen::Vector2d d = path_point(s.path, p.s + s.preview) - pos;
  const double c = std::cos(yaw), sn = std::sin(yaw);
  law.alpha = std::atan2(-sn * d.x() + c * d.y(), c * d.x() + sn * d.y());
  const double ld = std::max(d.norm(), 1e-9);
  law.pure_pursuit = std::atan(2 * s.wheelbase * std::sin(law.alpha) / ld);
  return law;
}

void resolve_driver_signals(DriverSettings& s, const DriverSignals& names, const std::vector<std::string>& outputs,
                            const std::vector<std::string>& inputs, const std::string& where) {
  resolve_driver_signals(s, names, outputs, inputs, [&](const std::string& field) { return where + "/" + field; });
}

void resolve_driver_signals(DriverSettings& s, const DriverSignals& names, const std::vector<std::string>& outputs,
                            const std::vector<std::string>& inputs,
                            const std::function<std::string(const std::string& field)>& label) {
  const auto find = [&](const std::vector<std::string>& list, const std::string& name, const std::string& field,
                        const char* kind) {
    for (std::size_t k = 0; k < list.size(); ++k)
      if (list[k] == name) return static_cast<int>(k);
    throw std::invalid_argument(label(field) + ": the driver needs the " + kind + " \"" + name +
                                "\", which the plant does not have (" + kind + ": " + driver_name_list(list) + ")");
  };
  s.out_x = find(outputs, names.x, "x", "Plant/Out");
  s.out_y = find(outputs, names.y, "y", "Plant/Out");
  s.out_yaw = find(outputs, names.yaw, "yaw", "Plant/Out");
  s.out_speed = find(outputs, names.speed, "forward_speed", "Plant/Out");
  s.in_steer = find(inputs, names.steer, "steer", "Plant/In");
  s.in_drive = names.drive.empty() ? -1 : find(inputs, names.drive, "drive", "Plant/In");
}

std::unique_ptr<Controller> make_driver(const DriverSettings& s, const std::string& where) {
  if (!(s.preview > 0)) driver_refuse(where, "preview", "a number > 0", s.preview);
  if (!(s.wheelbase > 0)) driver_refuse(where, "wheelbase", "a number > 0", s.wheelbase);
  if (!(s.steering_ratio != 0) || !std::isfinite(s.steering_ratio))
    driver_refuse(where, "steering_ratio", "a number != 0", s.steering_ratio);
  if (!(s.lateral_gain >= 0)) driver_refuse(where, "lateral_gain", "a number >= 0", s.lateral_gain);
  if (!(s.speed_kp >= 0)) driver_refuse(where, "speed_kp", "a number >= 0", s.speed_kp);
  if (!(s.speed_ki >= 0)) driver_refuse(where, "speed_ki", "a number >= 0", s.speed_ki);
  if (!(s.sample_time > 0)) driver_refuse(where, "sample_time", "a number > 0", s.sample_time);
  if (s.path.kind != DriverPath::Kind::Circle && s.path.points.size() < 2)
    throw std::invalid_argument(where + "/path: expected at least 2 points, got " + std::to_string(s.path.points.size()));
  const int nu = static_cast<int>(s.u0.size());
  if (s.in_steer < 0 || s.in_steer >= nu || s.in_drive >= nu || s.out_x < 0 || s.out_y < 0 || s.out_yaw < 0 ||
      s.out_speed < 0)
    throw std::invalid_argument(where + ": the driver's inputs and outputs are not resolved against the plant");
  return std::make_unique<Driver>(s);
}

DriverSettings model_driver_settings(const Model& model, const Eigen::VectorXd& u0) {
  const ControllerSpec& c = model.spec.controller;
  const std::string where = (model.source_file.empty() ? std::string() : model.source_file + ": ") + "/controller";
  DriverSettings s;
  if (c.path == "circle") {
    if (c.radius == 0) throw std::invalid_argument(where + "/radius: a circle path needs a radius other than 0");
    s.path = path_circle(c.path_start, c.path_heading, c.radius);
  } else if (c.path == "double_lane_change") {
    s.path = path_double_lane_change(c.path_start, c.vehicle_width);
  } else if (c.path == "table") {
    if (c.path_points.rows() < 2 || c.path_points.cols() != 2)
      throw std::invalid_argument(where + "/path_points: a table path needs at least 2 points [x, y]");
    std::vector<Eigen::Vector2d> pts;
    for (Eigen::Index k = 0; k < c.path_points.rows(); ++k) pts.emplace_back(c.path_points(k, 0), c.path_points(k, 1));
    s.path = path_table(pts, where + "/path_points");
  } else {
    s.path = path_straight(c.path_start, c.path_heading, c.path_length);
  }
  s.preview = c.preview;
  s.wheelbase = c.wheelbase;
  s.steering_ratio = c.steering_ratio;
  s.lateral_gain = c.lateral_gain;
  s.speed = c.speed;
  s.speed_kp = c.speed_kp;
  s.speed_ki = c.speed_ki;
  s.sample_time = c.sample_time;
  s.u0 = u0;
  std::vector<std::string> outputs, inputs;
  for (int k : model.plant_outputs) outputs.push_back(model.sensors[static_cast<std::size_t>(k)].name);
  for (int k : model.plant_inputs) inputs.push_back(model.actuators[static_cast<std::size_t>(k)].name);
  resolve_driver_signals(s, DriverSignals{c.x, c.y, c.yaw, c.forward_speed, c.steer, c.drive}, outputs, inputs, where);
  make_driver(s, where);  // the checks
  return s;
}

}  // namespace codyna
