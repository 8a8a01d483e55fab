// ModelSpec: the editable, named description of a mechanism. This is what a
// model file holds (io/model_file.hpp reads and writes it as JSON) and what
// the GUI edits. Nothing here is indexed or validated: compile() (model/compile.hpp)
// checks a spec and turns it into an immutable Model.
//
// Conventions: SI units; vectors in the frame named beside them; rotations
// as 3x3 matrices (the file format also accepts axis-angle and quaternions);
// the ground body is named "ground" and is implicit.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "model/study_spec.hpp"

namespace codyna {

inline constexpr const char* kGroundName = "ground";

// A frame given relative to a body frame: x_body = rotation * x_frame + position.
struct FrameSpec {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

enum class ShapeType { Box, Cylinder, Sphere };

struct ShapeSpec {
  ShapeType type = ShapeType::Box;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();  // box: full edge lengths x, y, z
  double radius = 0.05;                            // cylinder, sphere
  double length = 1.0;                             // cylinder, along the shape frame's z
  FrameSpec frame;                                 // shape frame in the body frame
  Eigen::Vector4d color{0.7, 0.7, 0.75, 1.0};      // rgba in [0, 1]
};

struct BodySpec {
  std::string name;
  double mass = 0.0;                                   // kg
  Eigen::Vector3d com = Eigen::Vector3d::Zero();       // m, body frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();   // kg m^2, about the com, body axes
  std::vector<ShapeSpec> shapes;
};

enum class JointType { Revolute, Prismatic, Fixed, Spherical, Universal, Cylindrical, Planar, Free };

// A joint moves `child` relative to `parent`. The joint frame F is fixed on the
// parent (parent_frame, in parent body coordinates), M on the child
// (child_frame, in child body coordinates); at zero joint position F and M
// coincide. Generalized coordinates by type (q | v):
//   revolute     angle about axis (rad)           | rate
//   prismatic    slide along axis (m)             | rate
//   fixed        -                                | -
//   spherical    quaternion (w, x, y, z) of M in F | angular velocity of M in M axes (3)
//   universal    angle about axis, then about axis2 (2) | rates (2)
//   cylindrical  angle about axis, slide along axis      | rates (2)
//   planar       x, y in F, angle about F's z            | rates (3)
//   free         position of M in F (3), quaternion (4)  | angular velocity, linear velocity of M's origin, both in M axes (6)
struct JointSpec {
  std::string name;
  JointType type = JointType::Revolute;
  std::string parent;   // body name or "ground"
  std::string child;    // body name
  FrameSpec parent_frame;
  FrameSpec child_frame;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // joint frame; revolute, prismatic, universal (first), cylindrical
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  // universal (second), in the joint frame at zero angle
  Eigen::VectorXd q0;   // initial position (size nq of the type); empty = zero position
  Eigen::VectorXd v0;   // initial velocity (size nv of the type); empty = zero
  // rotor inertia on the coordinates (MJCF's armature; a geared motor's N^2 J_rotor): added to the
  // mass matrix's diagonal, kg m^2 on a rotation, kg on a translation; empty = none, one value =
  // the same on every coordinate of the joint, else nv values (one per coordinate, v's order)
  Eigen::VectorXd armature;
};

// Loop-closure constraints close kinematic loops that the joint tree leaves open.
//   ball             point_a on body_a coincides with point_b on body_b (3 equations)
//   revolute         ball + axis_a (on body_a) stays parallel to axis_b (on body_b) (5)
//   planar_revolute  the two points coincide in the plane normal to axis_a (2);
//                    for planar mechanisms, whose loops would be redundant in 3-D
//   rolling_ball     a ball of `radius` centred at point_b on body_b rolls without slipping on the
//                    plane through point_a normal to axis_a (on body_a, the ball on the side axis_a
//                    points to): the centre's height (1 equation on q) and no slip at the contact
//                    (2 on the velocities only: non-holonomic)
//   rolling_disc     a disc (wheel, coin) of `radius` centred at point_b on body_b, its axle axis_b
//                    (on body_b), rolls without slipping on the same plane: the centre's height
//                    n . (c - p_a) = radius sqrt(1 - (n . a)^2) (on q) and no slip at the contact
//                    P = c - radius d, d the unit part of n normal to the axle (2 on v only);
//                    singular where the disc lies flat on the plane (n . a = +-1)
enum class ConstraintType { Ball, Revolute, PlanarRevolute, Coupler, RollingBall, RollingDisc };

struct ConstraintSpec {
  std::string name;
  ConstraintType type = ConstraintType::Ball;
  std::string body_a, body_b;  // body names or "ground"
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();  // body_a frame
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();  // body_b frame
  Eigen::Vector3d axis_a = Eigen::Vector3d::UnitZ();  // body_a frame (revolute, planar_revolute)
  Eigen::Vector3d axis_b = Eigen::Vector3d::UnitZ();  // body_b frame (revolute)
  // coupler: a linear relation among two or three scalar joint coordinates (revolute, prismatic),
  //   ratio_a q(joint_a) + ratio_b q(joint_b) + ratio_c q(joint_c) = offset
  // (a gear, a belt, a rack and pinion, a disc rolling on a line, a differential); joint_c may be
  // empty; without an offset, the joints' q0 as written satisfy it
  std::string joint_a, joint_b, joint_c;
  double ratio_a = 1, ratio_b = -1, ratio_c = 0;
  std::optional<double> offset;
  double radius = 0;  // rolling_ball, rolling_disc, m
};

// Force elements. Only those listed in a model are ever evaluated.
enum class EffectType {
  Gravity,           // g (world)
  SpringDamper,      // point-to-point: body_a/point_a to body_b/point_b; stiffness, damping, rest_length
  JointSpringDamper, // on one joint coordinate: stiffness, damping, rest_position
  JointFriction,     // viscous, on one joint coordinate: damping
  JointDamper,       // viscous, on every coordinate of a joint with one value: damping
  BodyForce,         // constant force at a body point and constant torque; in world or body axes
  Bushing,           // linear 6-component spring-damper between frame_a on body_a and frame_b on body_b
                     // (Adams' BUSHING): translations and small rotations of B in A's axes
  Tire,              // a tire on a wheel body (body_a) rolling on a road plane: contact, slips, a force law
                     // (linear, fiala, magic_formula from a .tir file); docs/tires.md
};

// A road surface of heights (docs/roads.md; vehicle/road.hpp), in the road body's x, y, z:
// a grid of heights (a CSV `file` relative to the model file, or the nodes `x`, `y` and the rows
// `z` inline), per-track profiles (a CSV `file` with s,z or s,left,right, or `s`, `left`, `right`
// inline; the tracks at `left_y`, `right_y`), or a generated ISO 8608 road of a class.
struct RoadGridSpec {
  std::string file;
  std::vector<double> x, y;
  Eigen::MatrixXd z;  // rows: y, columns: x
};
struct RoadProfileSpec {
  std::string file;
  std::vector<double> s, left, right;
  std::optional<double> left_y, right_y;
};
struct RoadIso8608Spec {
  std::string road_class;                      // "A" .. "H"
  double length = 0;                           // m
  std::vector<double> band{0.011, 2.83};       // cycle/m
  double spacing = 0.05;                       // m
  double start = 0;                            // m: x of the profile's s = 0
  int seed = 1;
  std::optional<double> left_y, right_y;
};
// a friction region: a box in the road body's x, y (each bound optional: unbounded) scaling the
// tire law's friction by `scale`
struct RoadFrictionSpec {
  std::vector<double> x, y;  // [min, max] or empty
  double scale = 1.0;
};

// A tire's road: the plane through `point` with normal `normal` (both in `body`'s coordinates; the
// ground by default), the wheel on the side the normal points to; or one surface of heights (grid,
// profile, iso8608) in `body`'s frame; friction regions on either; or `surface`, the name of a road
// of the model's `roads` (its surface and regions, in `body`'s frame).
struct RoadSpec {
  std::string body = kGroundName;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  std::string surface;
  std::optional<RoadGridSpec> grid;
  std::optional<RoadProfileSpec> profile;
  std::optional<RoadIso8608Spec> iso8608;
  std::vector<RoadFrictionSpec> friction;
};

// A road of the model's top-level `roads`, defined once and named by tires (RoadSpec::surface):
// one surface (grid, profile or iso8608) and friction regions, as a tire's road object holds them.
struct NamedRoadSpec {
  std::string name;
  std::optional<RoadGridSpec> grid;
  std::optional<RoadProfileSpec> profile;
  std::optional<RoadIso8608Spec> iso8608;
  std::vector<RoadFrictionSpec> friction;
};

// The tire force laws an effect of type tire may name, as written in a model file.
inline constexpr const char* kTireLawNames[] = {"linear", "fiala", "magic_formula"};

struct EffectSpec {
  std::string name;
  EffectType type = EffectType::Gravity;
  Eigen::Vector3d g{0.0, -9.81, 0.0};
  std::string body_a, body_b;                         // spring_damper; body_a is the body of body_force
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  double stiffness = 0.0;                             // N/m or N m/rad
  double damping = 0.0;                               // N s/m or N m s/rad
  double rest_length = 0.0;                           // m (spring_damper)
  std::string joint;                                  // joint effects
  int dof = 0;                                        // which coordinate of that joint (velocity index)
  double rest_position = 0.0;                         // joint_spring_damper
  Eigen::Vector3d force = Eigen::Vector3d::Zero();    // body_force, N
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();   // body_force, N m
  bool in_world = true;                               // body_force: axes of force/torque ("world" or "body")
  // bushing: frames on body_a and body_b that coincide at rest; the force on B in A's axes is
  // -K d - C v (d, v: B's origin relative to A's, in A's axes) and the torque -Kr theta - Cr w
  // (theta: the rotation vector of B relative to A, w the relative angular velocity, in A's axes)
  FrameSpec frame_a, frame_b;
  Eigen::Vector3d translational_stiffness = Eigen::Vector3d::Zero();  // N/m
  Eigen::Vector3d translational_damping = Eigen::Vector3d::Zero();    // N s/m
  Eigen::Vector3d rotational_stiffness = Eigen::Vector3d::Zero();     // N m/rad
  Eigen::Vector3d rotational_damping = Eigen::Vector3d::Zero();       // N m s/rad
  // tire (docs/tires.md, ISO-W axes at the contact): on the wheel body body_a, its centre `center`
  // and spin axis `spin_axis` (wheel body coordinates; the axle pointing to the wheel's left, so that
  // rolling forward is a positive spin about it), the unloaded radius, the road, a force law and the
  // vertical spring-damper of the tire's deflection. Law fields: linear (longitudinal_stiffness,
  // cornering_stiffness, camber_stiffness, friction, trail), fiala (longitudinal_stiffness,
  // cornering_stiffness, friction, sliding_friction, width, rolling_resistance), magic_formula (file:
  // a .tir file, relative to the model file; its [DIMENSION] UNLOADED_RADIUS and [VERTICAL]
  // VERTICAL_STIFFNESS, VERTICAL_DAMPING stand for the fields, which it then refuses; side: the
  // side of the car the tire is mounted on, mirrored when the file's TYRESIDE is the other)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();                   // m, wheel body
  Eigen::Vector3d spin_axis = Eigen::Vector3d::UnitY();               // wheel body
  std::optional<double> unloaded_radius;                              // m
  double rolling_radius = 0.0;                                        // m; 0: the unloaded radius
  RoadSpec road;
  std::string law = "linear";                                         // one of kTireLawNames
  double longitudinal_stiffness = 0.0;                                // N (per unit slip)
  double cornering_stiffness = 0.0;                                   // N/rad (positive)
  double camber_stiffness = 0.0;                                      // N/rad (linear)
  double friction = 0.0;                                              // linear: mu (0: none); fiala: mu_max
  double sliding_friction = 0.0;                                      // fiala: mu_min (0: = friction)
  double trail = 0.0;                                                 // m (linear)
  double width = 0.0;                                                 // m (fiala)
  double rolling_resistance = 0.0;                                    // m (fiala)
  std::string file;                                                   // magic_formula: the .tir file
  std::string side;                                                   // magic_formula: "left", "right" or "" (as the file)
  std::optional<double> vertical_stiffness, vertical_damping;         // N/m, N s/m
  double low_speed = 0.1;                                             // m/s: the slips' regularization
  // transient slip (docs/tires.md, "Relaxation"): the contact's longitudinal and lateral deflections
  // as states, relaxing over these lengths; 0: the slips act at once (no state)
  double longitudinal_relaxation_length = 0.0;                        // m
  double lateral_relaxation_length = 0.0;                             // m
  // magic_formula: both relaxation lengths from the .tir file at the tire's load (MF 5.2: PTX1-3,
  // PTY1-2; MF 6.1, 6.2: the slip stiffnesses over the carcass stiffnesses of [STRUCTURAL])
  bool relaxation_from_file = false;
};

// Actuators are the candidate plant inputs: each takes one scalar u.
enum class ActuatorType {
  JointForce,  // generalized force/torque on one coordinate of a joint: tau = gain * u
  BodyForce,   // force gain * u * direction at point of body; direction in world or body axes
  BodyTorque,  // torque gain * u * direction on body (a couple: no point); direction in world or body axes
  LineForce,   // force gain * u along the line from body_a/point_a to body_b/point_b, pushing the points
               // apart for u > 0 (a hydraulic cylinder, an active suspension strut): -F on a, +F on b
  Mix,         // one input driving several actuators: each of `drives` adds weight * u to its own input
               // (a rotor's thrust and reaction torque, a differential drive, a collective); acts through them
  Motion,      // a motion input: the joint coordinate (joint, dof) follows u (rad or m), its rate u' and its
               // acceleration u'' (a beam angle, a shaker table, the road under a tire on a prismatic joint);
               // the coordinate leaves the state, and its nominal value is the joint's q0
};

struct ActuatorSpec {
  std::string name;
  ActuatorType type = ActuatorType::JointForce;
  std::string joint;
  int dof = 0;
  std::string body;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  bool in_world = true;
  double gain = 1.0;
  double u0 = 0.0;  // nominal value (used when the actuator is not driven)
  std::optional<double> min, max;
  std::string unit;  // shown with the input; default from the type
  std::string body_a, body_b;  // line_force
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();
  std::vector<std::string> drives;  // mix: the actuators it drives (none of them a mix)
  Eigen::VectorXd weights;          // mix: one per driven actuator
};

// Sensors are the candidate plant outputs: each gives one scalar y.
enum class SensorType {
  JointPosition,   // joint, dof (for ball/free joints: the tangent coordinate relative to q0 is not offered; use body_angle)
  JointVelocity,   // joint, dof
  PointPosition,   // body, point; component (0, 1, 2) in the axes of `frame` (a body name or "ground")
  PointVelocity,   // same, velocity relative to ground, in the axes of `frame`
  BodyAngle,       // rotation of body about `axis` (world axes), measured from its zero-configuration orientation
  Distance,        // |p_b - p_a| between body_a/point_a and body_b/point_b
  DistanceRate,    // its rate d|p_b - p_a|/dt = n . (v_b - v_a) (0 where the points coincide)
  MotionForce,     // joint, dof driven by a motion input: the generalized force (N, N m) the motion supplies
                   // to hold the coordinate on its course, (M qdd + nle - Q) there; needs the accelerations
  AngularVelocity, // body's angular velocity (relative to ground), its component in the axes of `frame` (a gyro)
  Acceleration,    // body, point: the point's acceleration (relative to ground), component in the axes of
                   // `frame`; specific_force: a - g as an accelerometer reads it, else a; needs the accelerations
  Tire,            // tire (an effect of type tire): one of kTireQuantityNames, as the tire effect computes it
};

// What a tire sensor reads (SensorSpec::quantity), as written in a model file: the slips, camber and
// the force and aligning moment at the contact in the tire's ISO-W axes (docs/model-format.md).
inline constexpr const char* kTireQuantityNames[] = {"slip_angle", "longitudinal_slip", "camber", "Fx", "Fy", "Fz", "Mz"};

struct SensorSpec {
  std::string name;
  SensorType type = SensorType::JointPosition;
  std::string joint;
  int dof = 0;
  std::string body;      // point sensors, body_angle
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int component = 0;
  std::string frame = kGroundName;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  std::string body_a, body_b;  // distance, distance_rate
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  std::string tire;                     // tire: the tire effect's name
  std::string quantity = "slip_angle";  // tire: one of kTireQuantityNames
  bool specific_force = false;          // acceleration: true a - g (an accelerometer), false a
  std::string unit;
};

// true for the sensor types that read the accelerations (motion_force, acceleration): their value
// needs forward_dynamics at the same state and inputs, and depends on the inputs directly (D)
bool sensor_reads_accelerations(SensorType t);

// The Plant/In and Plant/Out panels: names of actuators and sensors, in order.
struct PlantSpec {
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
};

// A controller designed for the plant and stored with the model, so that it
// travels with it. Its signals are deviations from an operating point
// (x0, u0, y0) at which codyna linearizes the plant; u is in Plant/In order,
// y in Plant/Out order, x in the state order of codyna's linearization.
//   pid             u = u0 + kp (r - y) + ki xi - kd dy/dt,   dxi/dt = r - y
//                   (derivative action on the measurement)
//   state_feedback  u = u0 - K (x - x0)
//   lti             dxc/dt = Ac xc + Bc (y - y0),   u = u0 + Cc xc + Dc (y - y0);
//                   with Ts > 0 sampled, zero-order hold:
//                   xc[k+1] = Ac xc[k] + Bc (y[k] - y0),   u[k] = u0 + Cc xc[k] + Dc (y[k] - y0)
//   lqr             K = lqr(A, B, Q, R) of the linearized plant, then as state_feedback
// Reading a model file checks only that the matrices fit each other; their
// sizes against the plant (nu, ny, nx) are checked when a simulation uses them.
enum class ControllerType { None, Pid, StateFeedback, Lti, Lqr, Driver };

struct ControllerSpec {
  ControllerType type = ControllerType::None;
  // pid: gains (nu x ny, rows = Plant/In order, columns = Plant/Out order); empty ki/kd = none
  Eigen::MatrixXd kp, ki, kd;
  Eigen::VectorXd setpoint;  // pid: r (ny); empty = the operating point's y0
  // state_feedback: u = u0 - K (x - x0), K is nu x nx in the state order of codyna's linearization
  Eigen::MatrixXd K;
  // lti: dxc/dt = Ac xc + Bc (y - y0), u = u0 + Cc xc + Dc (y - y0); Ts > 0: sampled, zero-order hold
  Eigen::MatrixXd Ac, Bc, Cc, Dc;
  double Ts = 0.0;
  // lqr: designed by codyna on the linearized plant: Q = diag(q_weights) (nx), R = diag(r_weights) (nu);
  // empty = identity
  std::vector<double> q_weights, r_weights;
  // where the plant is linearized for the controller's offsets/state order: "initial", "equilibrium", "trim"
  std::string operating_point = "equilibrium";
  // driver (simulation/driver.hpp): pure pursuit on a path with integral action on the lateral
  // error, and a PI on forward speed. path: straight | circle | double_lane_change | table
  // (path_points, N x 2), from path_start (x, y) along path_heading (rad); the Plant/Out outputs
  // and Plant/In inputs it uses, by name (drive "" = the speed is not held)
  std::string path = "straight";
  double radius = 0, path_length = 1000, vehicle_width = 1.8, path_heading = 0;
  Eigen::Vector2d path_start = Eigen::Vector2d::Zero();
  Eigen::MatrixXd path_points;
  double preview = 10, wheelbase = 2.7, steering_ratio = 1, lateral_gain = 0.05;
  double speed = 0, speed_kp = 0, speed_ki = 0, sample_time = 0.01;
  std::string x = "x", y = "y", yaw = "yaw", forward_speed = "speed", steer = "steer", drive;
};

// Every integrator a run can name, "auto" first (chosen per model at the start of a run,
// simulation/integrator_choice.hpp): the one list the file check, the CLI's help, the GUI's
// drop-down and the errors are made from.
inline constexpr const char* kIntegratorNames[] = {"auto", "ida", "cvode-bdf", "cvode-adams", "arkode", "rk4", "alf"};
bool is_integrator_name(const std::string& name);
// the names joined by `separator` ("auto, ida, ..."); without "auto" when `with_auto` is false
std::string integrator_names(const std::string& separator = ", ", bool with_auto = true);

struct SolverSpec {
  std::string integrator = "auto";  // one of kIntegratorNames
  double rtol = 1e-8;
  double atol = 1e-10;
  double t_end = 5.0;
  double output_step = 0.01;
  double max_step = 0.0;  // 0 = no limit
  // alf only (simulation/alf.cpp; absent: its defaults, IntegratorSettings): the penalty, the most
  // Newton iterations a step, and every step max_step (0: 1 ms) instead of the error control
  std::optional<double> alf_penalty;
  std::optional<int> alf_iterations;
  bool alf_fixed_step = false;
  bool alf_extrapolate = false;  // alf: Richardson's extrapolation of each step (fourth order)
};

struct ModelSpec {
  std::string name = "model";
  std::string description;
  std::vector<BodySpec> bodies;
  std::vector<JointSpec> joints;
  std::vector<ConstraintSpec> constraints;
  std::vector<EffectSpec> effects;
  std::vector<ActuatorSpec> actuators;
  std::vector<SensorSpec> sensors;
  std::vector<NamedRoadSpec> roads;  // roads the tires name (docs/roads.md)
  PlantSpec plant;
  ControllerSpec controller;  // type None: no controller
  SolverSpec solver;
  StudySpec analysis;         // the study's choices (operating point, method, controller source, ...)

  // What the reader changed or assumed while reading a file ("FILE: /joints/0/axis: ... used
  // normalized"): for the front ends to show; never written back.
  std::vector<std::string> notes;
};

// Sizes of a joint type: configuration (nq) and velocity (nv).
int joint_nq(JointType t);
int joint_nv(JointType t);

// Names as used in model files ("revolute", "ball", "spring_damper", ...), and back.
const char* to_string(JointType t);
const char* to_string(ConstraintType t);
const char* to_string(EffectType t);
const char* to_string(ActuatorType t);
const char* to_string(SensorType t);
const char* to_string(ShapeType t);
const char* to_string(ControllerType t);  // None is "none"; a model file leaves such a controller out
std::optional<JointType> joint_type_from_string(const std::string& s);
std::optional<ConstraintType> constraint_type_from_string(const std::string& s);
std::optional<EffectType> effect_type_from_string(const std::string& s);
std::optional<ActuatorType> actuator_type_from_string(const std::string& s);
std::optional<SensorType> sensor_type_from_string(const std::string& s);
std::optional<ShapeType> shape_type_from_string(const std::string& s);
std::optional<ControllerType> controller_type_from_string(const std::string& s);

}  // namespace codyna
