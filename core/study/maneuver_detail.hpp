// What the maneuvers of study/maneuver_job.hpp share (not an interface: maneuver_*.cpp only):
// the request's checks, the steady body's state, the straight run, the open-loop steer run.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/handling.hpp"
#include "analysis/operating_point.hpp"
#include "dynamics/data.hpp"
#include "model/model.hpp"
#include "simulation/controller.hpp"
#include "simulation/driver.hpp"
#include "simulation/integrator.hpp"
#include "simulation/simulator.hpp"
#include "simulation/result.hpp"
#include "study/maneuver_job.hpp"

namespace codyna::mnv {

inline constexpr double kPi = 3.14159265358979323846;
// a roll past this (rad) is a rollover: the open-loop runs stop there, their metrics invalid
inline constexpr double kRolledOver = 60 * kPi / 180;

struct Flags {
  OptionStyle style;
  std::string operator()(const std::string& dashed) const { return option_name(style, dashed); }
};

// v when given (refused unless finite and > 0, naming the flag), else fallback
double positive(const Flags& flag, const std::optional<double>& v, double fallback, const char* name);
// the actuator / Plant/Out index of name, refused naming the model file's field
int actuator(const Model& m, const std::string& name, const std::string& field);
int output(const Model& m, const std::string& name, const std::string& field, bool required);
// the body whose motion the steady search sets (study.steady.body, or the first on a free or
// planar joint to ground)
int steady_body(const Model& m);

// the steady body's centre of mass in the world, its heading, roll, and its velocity in its own axes
struct BodyState {
  Eigen::Vector3d p, v_body;
  double heading = 0, roll = 0;
  double speed_along_heading = 0, yaw_rate = 0;  // in the road plane (world x, y), about world z
};
BodyState body_state(const Model& m, Data& d, int body, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// one steer profile: value, rate and acceleration at t
struct SteerProfile {
  std::function<double(double)> value, rate, acceleration;
};

IntegratorSettings integrator(const Model& m);
// the study's straight steady run at the request's speed (its integrator checked)
ModelSpec straight_spec(const ManeuverRequest& r, ModelSpec spec);
// a run that did not complete, or spun (sideslip past 20 deg): rep invalid with the reason; a
// note when auto's integrator fell back
void check_run(ManeuverReport& rep, const SimulationResult& res, const Model& m, int body);
std::vector<double> column(const SimulationResult& r, int k);
// the run as --out / --csv
void write(ManeuverReport& rep, const ManeuverRequest& r);

// An open-loop steer run from the straight steady run: the model at its steady motion, the steer
// input (analysis.handling.steer), the yaw-rate and lateral-acceleration outputs (-1: none).
struct OpenLoop {
  Model model;
  OperatingPoint op;
  int steer = -1, yaw_rate = -1, lateral_acceleration = -1, body = -1;
  BodyState start;
  // the model file's controller in the loop (unless ManeuverRequest::open_loop), on its Plant/In
  // (never the steer, which the maneuver drives), linearized about the straight run; its reference
  // on the yaw-rate output is the driver's intended yaw rate: the straight run's steady yaw-rate
  // gain times the steer's deviation, within +-mu g / U (yaw_rate_reference)
  std::shared_ptr<const LinearPlant> plant;
  std::shared_ptr<const Controller> controller;
  std::string controller_text;
  double reference_gain = 0, reference_limit = 0;  // 1/s (per steer unit), rad/s
};
// The model file's controller (not a driver) into ol, linearized about ol.op, and the driver's
// intended yaw rate as its reference on the yaw-rate output (when ol.yaw_rate is a Plant/Out);
// ol.model, op, steer, yaw_rate, start set. !controlled: refused, asking for --open-loop (a
// maneuver that compares with the open-loop linear model). Refused when the controller acts on
// the steer.
void attach_controller(OpenLoop& ol, const ManeuverRequest& r, const ModelSpec& spec, bool controlled);
// the controller's text, its reference gain and limit and its inputs' largest |u - u0| in
// rep.result into rep (run: the model the run was made on)
void report_controller(ManeuverReport& rep, const OpenLoop& ol, const Model& run);
// The straight run's handling numbers (steer in, yaw rate out: analysis.handling) at ol.op, on
// ol.model with the steer as its only Plant/In: what study_linearize gives on the straight spec so
// changed, without compiling it again or searching its steady motion again. Throws as
// study_linearize's handling numbers do (a name the model lacks: ModelError).
HandlingNumbers straight_handling(const OpenLoop& ol);
// controlled: the run may take the model file's controller (step steer, sine with dwell); a
// maneuver that compares with the open-loop linear model refuses one (unless --open-loop)
OpenLoop open_loop_setup(const ManeuverRequest& r, const ModelSpec& spec, bool controlled = false);
// The steer (less the straight run's) of the steady turn at lateral acceleration a_y (m/s^2, > 0
// left) at the straight run's speed (or at `speed` when > 0), by the steady-motion search with the
// study's free inputs; throws what the search throws.
double steady_steer_at(const ManeuverRequest& r, const ModelSpec& spec, const OpenLoop& ol, double a_y, double speed = 0);
// FMVSS 126's reference steer into rep.steer_03g: the steady turns' at +-0.3 g at the run's speed,
// averaged (the standard finds it in slowly increasing steer, both ways; the steady search is that
// test's limit); when not found, a note: why, and `otherwise` (what that means for the maneuver)
void steer_at_03g(ManeuverReport& rep, const ManeuverRequest& r, const ModelSpec& spec, const OpenLoop& ol,
                  const std::string& otherwise);
// a steer through the knots (t, v) (t rising), linear between them, v.front() before and v.back()
// after: its rate jumps at the knots (where a run stops), its acceleration is zero between
SteerProfile piecewise_linear(const std::vector<double>& t, const std::vector<double>& v);
// Runs it to t_end with the steer's deviation from the steady run following `profile` (its rate
// and acceleration exact: a motion input takes it), stopping at `stops` (where the steer's
// acceleration jumps); fills rep.result, checks it (check_run), end_speed, end_yaw_rate. Returns
// the run's model (the steady one held at the point: the result's q, v are its).
// beside: a sampled controller beside the file's (a speed hold), or null; until: told every output
// sample (the run's model and the sample) after the rollover check, the run ends where it returns
// true (not a failure; rep.result ends at that sample)
using RunUntil = std::function<bool(const Model& run, const Snapshot& sample)>;
Model open_loop_run(ManeuverReport& rep, const ManeuverRequest& r, const OpenLoop& ol, const SteerProfile& profile,
                    const std::vector<double>& stops, double t_end, const SampledBeside* beside = nullptr,
                    const RunUntil& until = {});

// The driver's position, heading and forward speed (names: the request's, else the file driver's,
// else the defaults): a name the model has no sensor of (and the request did not give) is measured
// on the steady body's origin by a sensor added under that name (x, y in the ground's axes, the
// heading about the vertical, the forward speed in the body's axes); a note says so. speed_only:
// the forward speed alone (a speed controller without the driver).
ModelSpec with_driver_sensors(ModelSpec s, const DriverSignals& names, const ManeuverRequest& r,
                              std::vector<std::string>& notes, bool speed_only = false);

// the maneuvers in their own files
ManeuverReport swept_sine(const ManeuverRequest& r, const ModelSpec& spec);       // maneuver_swept.cpp
ManeuverReport constant_radius(const ManeuverRequest& r, const ModelSpec& spec);  // maneuver_steady.cpp
ManeuverReport constant_speed(const ManeuverRequest& r, const ModelSpec& spec);   // maneuver_steady.cpp
ManeuverReport slowly_increasing_steer(const ManeuverRequest& r, const ModelSpec& spec);  // maneuver_ramp.cpp
ManeuverReport fishhook(const ManeuverRequest& r, const ModelSpec& spec);                 // maneuver_ramp.cpp

// the double lane change's path and cones into rep (lane_path, lane_cones): `local` is the lane
// laid out from (0, 0) along +x, placed at `start` turned by `heading`
void lane_layout(ManeuverReport& rep, const DriverPath& local, const Eigen::Vector2d& start, double heading);

}  // namespace codyna::mnv
