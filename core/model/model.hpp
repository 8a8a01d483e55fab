// Model: the immutable, index-based form of a ModelSpec, made by compile().
// Body 0 is the ground; body i >= 1 is moved by joint i relative to its
// parent body parent[i] < i (topological order). Algorithms read a Model
// and write into a Data (dynamics/data.hpp); they never change a Model.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "model/model_spec.hpp"
#include "spatial/spatial.hpp"

namespace codyna {

struct JointModel {
  std::string name;
  JointType type = JointType::Fixed;
  int parent = -1;                 // parent body
  int idx_q = 0, idx_v = 0;        // first coordinate in q and in v
  int nq = 0, nv = 0;
  SE3 X_PF;                        // joint frame F in parent body coordinates
  SE3 X_CM;                        // joint frame M in child body coordinates
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit, joint frame
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  // unit, joint frame (universal)
  int spec_index = -1;             // position in ModelSpec::joints (for messages)
};

struct ConstraintModel {
  std::string name;
  ConstraintType type = ConstraintType::Ball;
  int body_a = 0, body_b = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_a = Eigen::Vector3d::UnitZ();           // unit, body_a
  Eigen::Vector3d perp_a1 = Eigen::Vector3d::UnitX(), perp_a2 = Eigen::Vector3d::UnitY();  // unit, body_a, perpendicular to axis_a
  Eigen::Vector3d perp_b1 = Eigen::Vector3d::UnitX(), perp_b2 = Eigen::Vector3d::UnitY();  // unit, body_b, perpendicular to axis_b
  int row = 0, nrows = 0;          // rows in the stacked constraint vector
  // coupler: sum_k ratio[k] q[iq[k]] = offset over ncoupled scalar coordinates (iv[k] their
  // velocity indices); body_a, body_b are the first two joints' child bodies (for messages)
  int ncoupled = 0;
  int iq[3] = {0, 0, 0}, iv[3] = {0, 0, 0};
  double ratio[3] = {0, 0, 0};
  double offset = 0;
  bool offset_given = false;
  // rolling_ball: the ball's radius (point_b is its centre, axis_a the plane's normal, perp_a1 and
  // perp_a2 the plane's directions of no slip); its first row is on q, the other two on v only.
  // rolling_disc: the same, with the disc's axle axis_b (unit, body_b)
  double radius = 0;
  Eigen::Vector3d axis_b = Eigen::Vector3d::UnitZ();
};

struct SpringDamperModel {
  std::string name;
  int body_a = 0, body_b = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();
  double stiffness = 0, damping = 0, rest_length = 0;
};

struct JointSpringModel {
  std::string name;
  int iq = 0, iv = 0;             // the coordinate it acts on
  double stiffness = 0, damping = 0, rest_position = 0;
};

struct BodyForceModel {
  std::string name;
  int body = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
  bool in_world = true;
};

struct BushingModel {
  std::string name;
  int body_a = 0, body_b = 0;
  SE3 X_a, X_b;  // the bushing's frames in body_a's and body_b's frames
  Eigen::Vector3d kt = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();  // translational, A's axes
  Eigen::Vector3d kr = Eigen::Vector3d::Zero(), cr = Eigen::Vector3d::Zero();  // rotational, A's axes
};

struct MagicFormulaParameters;  // vehicle/tir_file.hpp
struct RoadSurface;             // vehicle/road.hpp

enum class TireLaw { Linear, Fiala, MagicFormula };

// A tire (EffectType::Tire; dynamics/tire_effect.hpp evaluates it): the wheel body's centre and unit
// spin axis, the road plane on road_body, the vertical spring-damper and the force law's numbers.
struct TireModel {
  std::string name;
  int body = 0;                                           // the wheel
  Eigen::Vector3d center = Eigen::Vector3d::Zero();       // wheel body coordinates
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();        // unit, wheel body coordinates
  double unloaded_radius = 0, rolling_radius = 0;         // m (rolling_radius: Re of the slip)
  int road_body = 0;
  Eigen::Vector3d road_point = Eigen::Vector3d::Zero();   // road body coordinates
  Eigen::Vector3d road_normal = Eigen::Vector3d::UnitZ(); // unit, road body coordinates
  // a road of heights in road_body's frame (road_point, road_normal then unused; null: the plane),
  // shared by the tires that name the same road; its friction regions scale the law's friction
  std::shared_ptr<const RoadSurface> road;
  // magic_formula on a road with friction regions: the .tir parameters with LMUX, LMUY scaled, one
  // per region of road->friction
  std::vector<std::shared_ptr<const MagicFormulaParameters>> mf_regions;
  double vertical_stiffness = 0, vertical_damping = 0;    // N/m, N s/m
  double low_speed = 0.1;                                 // m/s
  TireLaw law = TireLaw::Linear;
  // linear and fiala (fiala: friction = mu_max, sliding_friction = mu_min)
  double C_kappa = 0, C_alpha = 0, C_gamma = 0, friction = 0, sliding_friction = 0, trail = 0, width = 0,
         rolling_resistance = 0;
  std::shared_ptr<const MagicFormulaParameters> mf;       // magic_formula: the .tir file read
  int side = 0;                                           // magic_formula: 0 as the file, 1 left, 2 right
  // transient slip (dynamics/tire_effect.hpp): relaxation lengths (m; 0: none) and the indices of
  // the contact's longitudinal and lateral deflections in the effect states (Model::ns; -1: none)
  double relaxation_x = 0, relaxation_y = 0;
  int state_x = -1, state_y = -1;
  // magic_formula: the lengths from the .tir file at the contact's load (tire_relaxation_lengths;
  // relaxation_x, relaxation_y then hold them at FNOMIN, upright: what a tire off the road relaxes by)
  bool relaxation_from_file = false;
};

struct ActuatorModel {
  std::string name;
  ActuatorType type = ActuatorType::JointForce;
  int iv = 0;                      // joint_force, motion: velocity index it drives
  int iq = 0;                      // motion: the coordinate's index in q
  int body = 0;                    // body_force
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), direction = Eigen::Vector3d::UnitX();  // direction unit
  bool in_world = true;
  double gain = 1.0, u0 = 0.0;
  double min = -std::numeric_limits<double>::infinity(), max = std::numeric_limits<double>::infinity();
  std::string unit;
  int body_b = 0;                  // line_force: from body/point to body_b/point_b
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  // the mixes that drive this actuator, (mix index, weight): its input is u + sum weight * u_mix;
  // a mix itself acts only through the actuators it drives
  std::vector<std::pair<int, double>> driven_by;
};

// what a tire sensor reads (kTireQuantityNames' order)
enum class TireQuantity { SlipAngle, LongitudinalSlip, Camber, Fx, Fy, Fz, Mz };

struct SensorModel {
  std::string name;
  SensorType type = SensorType::JointPosition;
  int iq = 0, iv = 0;              // joint sensors
  int body = 0;                    // point sensors, body_angle, angular_velocity, acceleration
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int component = 0;
  int frame = 0;                   // body whose axes express point sensors, angular_velocity, acceleration (0 = ground)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(), perp1 = Eigen::Vector3d::UnitX(), perp2 = Eigen::Vector3d::UnitY();
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  // body_angle: body orientation at zero configuration
  int body_a = 0, body_b = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();
  int tire = 0;                    // tire: index into Model::tires
  TireQuantity quantity = TireQuantity::SlipAngle;
  bool specific_force = false;     // acceleration: a - g (gravity the model's gravity effect)
  std::string unit;
};

struct Model {
  std::string name;
  int nq = 0;                      // configuration size
  int nv = 0;                      // velocity (tangent) size = degrees of freedom of the tree
  int nbodies = 1;                 // including ground

  std::vector<std::string> body_names;   // [nbodies]
  std::vector<int> parent;               // [nbodies], parent[0] = -1
  std::vector<JointModel> joints;        // [nbodies], joints[0] unused (ground)
  std::vector<double> mass;              // [nbodies]
  std::vector<Eigen::Vector3d> com;      // [nbodies], body coordinates
  std::vector<Mat6T<double>> inertia;    // [nbodies], spatial inertia in body coordinates
  std::vector<int> body_spec_index;      // [nbodies], position in ModelSpec::bodies (-1 for ground)

  // One naming scheme (docs/model-format.md, "Coordinate and rate names"), the same in
  // `info`, --hold/--initial, --trim-free/--independent, the exported state names and the GUI:
  //   v_names: the coordinates, one per degree of freedom: J (revolute, prismatic), J.1 J.2
  //     (universal), J.angle J.slide (cylindrical), J.x J.y J.angle (planar), J.rx J.ry J.rz
  //     (ball: rotation vector), J.rx J.ry J.rz J.x J.y J.z (free: rotation vector, position).
  //   rate_names: their rates: NAME_dot, except a ball's or free joint's angular velocity
  //     J.wx J.wy J.wz and a free joint's linear velocity J.vx J.vy J.vz (child-frame axes;
  //     not the derivatives of the rotation vector or of the parent-frame position).
  //   q_names: the stored configuration (a quaternion's J.qw .. J.qz), for result files.
  std::vector<std::string> q_names;      // [nq]
  std::vector<std::string> v_names;      // [nv] coordinates
  std::vector<std::string> v_units;      // [nv] "rad" or "m"
  std::vector<std::string> rate_names;   // [nv] rates (units: rate_unit(v_units))

  // loop closures
  std::vector<ConstraintModel> constraints;
  int nc = 0;                            // stacked constraint rows
  std::vector<std::string> row_names;    // [nc]
  std::vector<int> active_rows;          // independent rows, used in dynamics
  std::vector<int> redundant_rows;       // rows dependent on the others (named in row_names)
  // non-holonomic rows (rolling without slip): conditions on the velocities only, with no phi(q)
  // (Data::phi is 0 there); assembly, the position projections and the dependent positions use
  // the other rows. The active ones are counted apart: they remove rates, not coordinates.
  std::vector<int> velocity_rows;        // sorted
  int active_velocity_rows = 0;          // of active_rows

  // effects: only these are evaluated
  bool has_gravity = false;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  std::vector<SpringDamperModel> springs;
  std::vector<JointSpringModel> joint_springs;
  std::vector<JointSpringModel> joint_frictions;  // damping only
  std::vector<BodyForceModel> body_forces;
  std::vector<BushingModel> bushings;
  std::vector<TireModel> tires;
  // Effect states: first-order states that force elements carry (a tire's transient slip), in
  // every plant and simulation state after the velocities. Their rates come from applied_forces
  // (Data::s in, Data::sdot out); effect_states_steady gives the values at which they rest.
  int ns = 0;
  std::vector<std::string> s_names, s_units;  // [ns]: TIRE.deflection_x, TIRE.deflection_y; "m"

  std::vector<ActuatorModel> actuators;  // [nu_all]
  std::vector<SensorModel> sensors;      // [ny_all]
  std::vector<int> plant_inputs;         // indices into actuators
  // the motion actuators (indices into actuators): each holds its coordinate at u, u', u''
  // (prescribed, out of the state: dof() does not count it); on a loop's coordinate the loop
  // closes on the free coordinates (prepare_model refuses motions that lock or over-drive it)
  std::vector<int> motions;
  std::vector<int> plant_outputs;        // indices into sensors

  Eigen::VectorXd q0, v0;                // assembled initial state
  double assembly_residual = 0.0;        // max |phi(q0)|, |J v0| after assembly
  // what assembly changed in the joints' q0 and v0 to close the loops, by more than 1e-6 (m, rad,
  // m/s, rad/s): a coordinate (Model::v_names; `from`, `to` its values for a scalar joint, NaN for
  // a ball's or free joint's rotation, whose `by` is the tangent step) or a rate (rate_names)
  struct AssemblyMove {
    std::string name;
    double from = 0, to = 0, by = 0;
  };
  std::vector<AssemblyMove> assembly_moves;

  // rotor inertia per velocity index, added to the mass matrix's diagonal by every algorithm
  // (crba, aba, rnea, energy, derivatives); empty when no joint has any (JointSpec::armature)
  Eigen::VectorXd armature;              // [nv] or empty

  ModelSpec spec;                        // the spec it was compiled from
  std::string source_file;               // where the spec was read, if from a file

  int nu() const { return static_cast<int>(actuators.size()); }
  int ny() const { return static_cast<int>(sensors.size()); }
  // the coordinates left free by the holonomic loops and the motions (the plant's positions z)
  int dof() const {
    return nv - (static_cast<int>(active_rows.size()) - active_velocity_rows) - static_cast<int>(motions.size());
  }
  // the independent rates (the plant's velocities w): dof() less the active non-holonomic rows
  int rate_dof() const { return dof() - active_velocity_rows; }
  bool is_velocity_row(int row) const;
  Eigen::VectorXd u_nominal() const;     // u0 of every actuator
  int find_body(const std::string& name) const;  // -1 if absent
  int find_actuator(const std::string& name) const;
  int find_sensor(const std::string& name) const;
  int find_joint(const std::string& name) const;  // body index of the joint, -1 if absent
};

// the zero configuration (identity quaternions)
Eigen::VectorXd neutral(const Model& model);

// The unit of the time derivative of a quantity in `unit`: the one rule every front end prints
// rates with. "rad" -> "rad/s", "m/s" -> "m/s^2", "m/s^2" -> "m/s^3", "" (dimensionless) -> "1/s".
std::string rate_unit(const std::string& unit);

}  // namespace codyna
