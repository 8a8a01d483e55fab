// The suspension kinematics and compliance rig (K&C, `codyna kc`; docs/kc.md): a suspension
// corner (or an axle) held at its body, swept quasi-statically through wheel travel, steer and loads at the
// contact patch, with the wheel's angles and positions at every point and their gradients at the
// design position.
//   held: the body the suspension hangs on ("" = the root of the wheel's tree); its joint's
//     coordinates stay where the model puts them (a chassis on a free joint is held there)
//   each point: a static equilibrium of the model's springs and bushings (gravity and tires left
//     out: the rig's pad carries the wheel) with the wheel centre's height in the held body's frame
//     prescribed (one more position constraint per wheel), the steer input (a motion actuator) at its value,
//     the wheel's spin held (a longitudinal load is a braking force) and the loads Fx, Fy, Mz at
//     the contact patch (held body axes). On a linkage with no freedom left it is the kinematic
//     solution; with bushings it is their static solution.
//   method: Newton on the equilibrium and the constraints together (the stiffness by central
//     differences of the generalized forces, minimum-norm steps), continued from the design point
//     outwards, a failing step halved; gradients from the linear sensitivity at the design point.
//   cost: each Newton iteration evaluates the generalized forces 2 nf + 1 times (nf the free
//     coordinates); the example corner's 9-point travel sweep and its gradients take a few ms.
// Angles (degrees, held body axes: x forward, y left, z up; ISO 8855 / SAE J670 agree on these):
//   camber: the wheel's top leaning outward positive; toe: toe-in positive (the wheel's front
//   turned towards the centreline); caster: the kingpin's top rearward positive; kingpin
//   inclination: its top inward positive. The kingpin is the line through the upright's two ball
//   joints to the control arms (the upright's balls whose other body no motion input moves: not
//   the tie rod's); without exactly two such balls caster and kingpin are NaN (a note says so).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace codyna {

struct ModelSpec;

struct KcRange {
  double min = 0, max = 0;
  int points = 0;
};

struct KcRequest {
  std::string model;                // the model file (messages, relative paths)
  const ModelSpec* spec = nullptr;  // or the model as edited, read instead of the file
  // the wheel bodies or their tire elements: one (a corner) or two (an axle: the roll sweep);
  // empty = the model's only tire
  std::vector<std::string> wheels;
  std::string held;                 // the body held ("" = the root of the wheels' tree)
  std::string steer;                // a motion input ("" = the model's only one, if any)
  std::optional<double> radius;     // m (default: each wheel's tire's unloaded radius)
  // the sweeps (none given: travel -0.05:0.05:11)
  std::optional<KcRange> travel;    // m, wheel centre height from design, positive up (bump); an axle's wheels together
  std::optional<KcRange> roll;      // deg of body roll (right hand about x: the left side up), an axle only
  std::optional<KcRange> steer_range;  // the steer input's unit
  std::optional<KcRange> fx, fy;    // N at each wheel's contact patch, held body axes
  std::optional<KcRange> mz;        // N m about the held body's z axis, on each wheel
  std::string csv;                  // the table as CSV ("" = none)
};

// one wheel at one sweep point
struct KcPoint {
  std::string sweep;                // "travel", "roll", "steer", "Fx", "Fy", "Mz" ("design" for the design point)
  std::string wheel;                // the wheel body
  double travel = 0, roll = 0, steer = 0, fx = 0, fy = 0, mz = 0;  // the point's settings (roll in deg)
  Eigen::Vector3d wheel_centre = Eigen::Vector3d::Zero();  // m, held body frame
  Eigen::Vector3d contact = Eigen::Vector3d::Zero();       // m, held body frame
  double camber = 0, toe = 0, caster = 0, kingpin = 0;     // deg
  double track_change = 0;          // m: twice the contact's outward move (a symmetric axle's track)
  double wheelbase_change = 0;      // m: the contact's forward move
  // where the kingpin meets the ground (the contact's height): the contact outboard of it
  // (scrub radius, positive outboard) and behind it (caster trail, positive behind); m, NaN without a kingpin
  double scrub_radius = 0, caster_trail = 0;
};

// a wheel's gradients at the design point (zero travel, roll, steer and loads)
struct KcGradients {
  double bump_steer = 0, bump_camber = 0;     // deg of toe, camber per m of travel (an axle: both wheels)
  double track_per_travel = 0;                // m per m
  double roll_centre_height = 0;              // m above the contact patch, from this wheel alone (a symmetric axle's)
  double roll_steer = 0, roll_camber = 0;     // deg per deg of body roll (right hand about x)
  double fy_steer = 0, fy_camber = 0;         // deg per kN of Fy (lateral-force compliance)
  double fx_steer = 0, fx_camber = 0;         // deg per kN of Fx
  double mz_steer = 0, mz_camber = 0;         // deg per kN m of Mz
};

struct KcWheel {
  std::string name;                           // the wheel body
  double radius = 0;                          // m
  KcPoint design;
  KcGradients gradients;
};

struct KcReport {
  std::string model, held, steer;             // names as found ("" steer: none)
  std::string steer_unit;
  std::vector<KcWheel> wheels;
  std::vector<KcPoint> points;                // in sweep order, each sweep's values in order, the wheels in turn
  // an axle: the kinematic roll centre, where the two wheels' lines (through the contact point,
  // normal to its motion in the y-z plane under travel) meet; m, held frame (NaN: one wheel, or parallel)
  double roll_centre_y = 0, roll_centre_z = 0;
  std::vector<std::string> notes;
  std::string written;                        // the CSV ("" when none)
};

// Throws std::invalid_argument for a bad request (naming the option: --wheel, --held, --steer,
// --radius, --travel, --roll, --steer-range, --fx, --fy, --mz, --csv), ModelError for a bad model file and
// ConvergenceError for a point the suspension cannot reach (naming the option and the value).
// Nothing is written unless every point is solved.
KcReport study_kc_job(const KcRequest& request);

// "MIN:MAX:N" (MIN < MAX, N >= 2 points) for `option`
KcRange study_kc_range(const std::string& text, const std::string& option);

// the CSV's columns, in order
std::vector<std::string> study_kc_columns();

// the report as the CLI prints it: the design point, each sweep's table, the gradients
std::string study_kc_text(const KcReport& report);

}  // namespace codyna
