// The driver: a path follower (pure pursuit with integral action on the lateral error) and a
// speed controller (PI on forward speed), as a sampled Controller (zero-order hold, sample_time):
//
//   lateral error   e  = signed distance of the measured point (x, y) from the path, > 0 left of it
//   pure pursuit    alpha = the look-ahead point's bearing from the heading, the look-ahead point
//                   `preview` metres along the path ahead of the point of the path nearest (x, y)
//                   delta = atan(2 L sin(alpha) / preview) - k_e * integral(e dt)   (road-wheel angle)
//   steer input     u_steer = steering_ratio * delta
//   drive input     u_drive = u0_drive + kp (U_ref - U) + ki integral(U_ref - U) dt
//
// The integral term removes the steady offset pure pursuit alone leaves on a curve (it steers the
// kinematic angle atan(L / R); a car that understeers needs more): on a circle the steady state
// has e = 0 and the steer the car needs there. It reads four Plant/Out outputs (x, y, yaw, forward
// speed; names in DriverSettings) and writes one or two Plant/In inputs (steer; drive optional);
// the other Plant/In inputs stay at their u0, so it leaves them to whatever else holds them.
// States (sampled): the two integrals.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "simulation/controller.hpp"

namespace codyna {

// A path in the road plane: a polyline of (x, y) points (a table, a straight, the ISO 3888-1
// centre line), or an exact circle.
struct DriverPath {
  enum class Kind { Table, Straight, Circle, DoubleLaneChange } kind = Kind::Table;
  std::vector<Eigen::Vector2d> points;  // polyline (not a circle): at least 2 distinct points
  Eigen::Vector2d center{0, 0};         // circle
  double radius = 0;                    // circle: > 0 turns left, < 0 right (the path's own sense)
  double start_angle = 0;               // circle: polar angle of the start point about the centre
  // double lane change: its sections (x from the start of section 1) and lane widths (ISO 3888-1)
  std::vector<double> gate_start, gate_end, gate_center, gate_width;
};

// nearest point of a path to p
struct PathProjection {
  double s = 0;                       // arc length along the path (a circle: from its start, any sign)
  Eigen::Vector2d point{0, 0};        // on the path
  Eigen::Vector2d tangent{1, 0};      // unit, in the path's direction
  double lateral = 0;                 // signed distance of p from the path, > 0 left of it
};
PathProjection project_on_path(const DriverPath& path, const Eigen::Vector2d& p);
// the point at arc length s (a polyline is extended along its last segment past its end, and
// along its first before its start)
Eigen::Vector2d path_point(const DriverPath& path, double s);

// a table of points; throws std::invalid_argument (`what` names the field) with fewer than two
// distinct points or two equal neighbours
DriverPath path_table(const std::vector<Eigen::Vector2d>& points, const std::string& what = "path");
// a straight of `length` from `start` along heading `heading` (rad)
DriverPath path_straight(const Eigen::Vector2d& start, double heading, double length);
// a circle through `start` tangent to `heading`, radius R (> 0 left, < 0 right; |R| > 0)
DriverPath path_circle(const Eigen::Vector2d& start, double heading, double radius);
// ISO 3888-1's double lane change centre line for a car of width `width` (m) along +x from
// `start` (section 1 begins `lead_in` metres ahead of start): sections 15, 30, 25, 25, 15, 15 m;
// lane widths 1.1 w + 0.25 (1), w + 1 (3), 1.3 w + 0.25 (5 and 6); lane 3 offset to the left by
// 3.5 m (the right-hand cone lines of sections 1 and 3 are 3.5 m apart), lanes 5 and 6 back on
// the right-hand line of section 1; the centre line moves between the lane centres over sections
// 2 and 4 along a half cosine (continuous heading).
DriverPath path_double_lane_change(const Eigen::Vector2d& start, double width, double lead_in = 50,
                                   double run_out = 60);

struct DriverSettings {
  DriverPath path;
  double preview = 10;                // m, pure pursuit's look-ahead distance (> 0)
  double wheelbase = 2.7;             // m (> 0)
  double steering_ratio = 1;          // steer input per road-wheel angle (!= 0)
  double lateral_gain = 0.05;         // k_e, rad of road-wheel angle per (m s) of lateral error (>= 0)
  double speed = 0;                   // m/s, the speed held (when a drive input is given)
  double speed_kp = 0, speed_ki = 0;  // drive input per m/s, per m (>= 0)
  double sample_time = 0.01;          // s (> 0)
  // Plant/Out indices (into the plant's outputs) and Plant/In indices (drive -1: none)
  int out_x = -1, out_y = -1, out_yaw = -1, out_speed = -1;
  int in_steer = -1, in_drive = -1;
  Eigen::VectorXd u0;                 // Plant/In nominal values (the inputs the driver does not set stay there)
};

// The field names a model file's driver reads the indices from, resolved against the plant's
// Plant/Out and Plant/In names: a name the plant lacks is std::invalid_argument naming the field
// (`where` + "/x") and listing the plant's names.
struct DriverSignals {
  std::string x = "x", y = "y", yaw = "yaw", speed = "speed";  // Plant/Out
  std::string steer = "steer", drive;                          // Plant/In (drive "" = none)
};
void resolve_driver_signals(DriverSettings& s, const DriverSignals& names, const std::vector<std::string>& outputs,
                            const std::vector<std::string>& inputs, const std::string& where);
// the same, each field named in a refusal by `label(field)` (the flag a request gave it by, or the
// file's field path), the field as a model file writes it (x, y, yaw, forward_speed, steer, drive)
void resolve_driver_signals(DriverSettings& s, const DriverSignals& names, const std::vector<std::string>& outputs,
                            const std::vector<std::string>& inputs,
                            const std::function<std::string(const std::string& field)>& label);
// the same for each field name as a model file writes it (x, y, yaw, forward_speed, steer, drive)

// checks the settings (std::invalid_argument naming the field as `where` + "/preview" ...)
std::unique_ptr<Controller> make_driver(const DriverSettings& s, const std::string& where = "driver");

// the road-wheel angle and lateral error of a driver at one measurement, without its integral
// (what output() uses; for tests and reports)
struct DriverLaw {
  double lateral = 0, pure_pursuit = 0, alpha = 0;
};
DriverLaw driver_law(const DriverSettings& s, double x, double y, double yaw);

// The driver's speed controller alone: a PI on forward speed, sampled (zero-order hold), for a
// maneuver whose steer is a set profile but whose speed is held (slowly increasing steer at
// constant speed, SAE J266). It reads one output (the forward speed, y[0]) and writes one input
// (the drive, u[0]):  u = u0 + kp (U_ref - U) + ki integral(U_ref - U) dt.  States: the integral.
struct SpeedHoldSettings {
  double speed = 0;                   // m/s, U_ref
  double kp = 0, ki = 0;              // drive input per m/s, per m (>= 0, not both 0)
  double sample_time = 0.01;          // s (> 0)
  double u0 = 0;                      // the drive's nominal value
};
// checks the settings (std::invalid_argument naming the field as `where` + "/speed_kp" ...)
std::unique_ptr<Controller> make_speed_hold(const SpeedHoldSettings& s, const std::string& where = "speed");

// The settings a model file's controller of type "driver" gives (ModelSpec::controller), its names
// resolved against the model's Plant/Out and Plant/In; u0: the Plant/In nominal values. Errors
// name the file and the field ("FILE: /controller/x: the driver needs the Plant/Out ...").
DriverSettings model_driver_settings(const Model& model, const Eigen::VectorXd& u0);

}  // namespace codyna
