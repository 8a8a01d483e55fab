#include "model/model_spec.hpp"

#include <array>
#include <utility>

namespace codyna {

namespace {
template <class E, std::size_t N>
const char* name_of(const std::array<std::pair<E, const char*>, N>& table, E e) {
  for (const auto& [k, v] : table)
    if (k == e) return v;
  return "?";
}
template <class E, std::size_t N>
std::optional<E> value_of(const std::array<std::pair<E, const char*>, N>& table, const std::string& s) {
  for (const auto& [k, v] : table)
    if (s == v) return k;
  return std::nullopt;
}

constexpr std::array<std::pair<JointType, const char*>, 8> kJoints{{
    {JointType::Revolute, "revolute"},
    {JointType::Prismatic, "prismatic"},
    {JointType::Fixed, "fixed"},
    {JointType::Spherical, "spherical"},
    {JointType::Universal, "universal"},
    {JointType::Cylindrical, "cylindrical"},
    {JointType::Planar, "planar"},
    {JointType::Free, "free"},
}};
constexpr std::array<std::pair<ConstraintType, const char*>, 6> kConstraints{{
    {ConstraintType::Ball, "ball"},
    {ConstraintType::Revolute, "revolute"},
    {ConstraintType::PlanarRevolute, "planar_revolute"},
    {ConstraintType::Coupler, "coupler"},
    {ConstraintType::RollingBall, "rolling_ball"},
    {ConstraintType::RollingDisc, "rolling_disc"},
}};
constexpr std::array<std::pair<EffectType, const char*>, 8> kEffects{{
    {EffectType::Gravity, "gravity"},
    {EffectType::SpringDamper, "spring_damper"},
    {EffectType::JointSpringDamper, "joint_spring_damper"},
    {EffectType::JointFriction, "joint_friction"},
    {EffectType::JointDamper, "joint_damper"},
    {EffectType::BodyForce, "body_force"},
    {EffectType::Bushing, "bushing"},
    {EffectType::Tire, "tire"},
}};
constexpr std::array<std::pair<ActuatorType, const char*>, 6> kActuators{{
    {ActuatorType::JointForce, "joint_force"},
    {ActuatorType::BodyForce, "body_force"},
    {ActuatorType::BodyTorque, "body_torque"},
    {ActuatorType::LineForce, "line_force"},
    {ActuatorType::Mix, "mix"},
    {ActuatorType::Motion, "motion"},
}};
constexpr std::array<std::pair<SensorType, const char*>, 11> kSensors{{
    {SensorType::JointPosition, "joint_position"},
    {SensorType::JointVelocity, "joint_velocity"},
    {SensorType::PointPosition, "point_position"},
    {SensorType::PointVelocity, "point_velocity"},
    {SensorType::BodyAngle, "body_angle"},
    {SensorType::Distance, "distance"},
    {SensorType::DistanceRate, "distance_rate"},
    {SensorType::MotionForce, "motion_force"},
    {SensorType::AngularVelocity, "angular_velocity"},
    {SensorType::Acceleration, "acceleration"},
    {SensorType::Tire, "tire"},
}};
constexpr std::array<std::pair<ShapeType, const char*>, 3> kShapes{{
    {ShapeType::Box, "box"},
    {ShapeType::Cylinder, "cylinder"},
    {ShapeType::Sphere, "sphere"},
}};
constexpr std::array<std::pair<ControllerType, const char*>, 6> kControllers{{
    {ControllerType::None, "none"},
    {ControllerType::Pid, "pid"},
    {ControllerType::StateFeedback, "state_feedback"},
    {ControllerType::Lti, "lti"},
    {ControllerType::Lqr, "lqr"},
    {ControllerType::Driver, "driver"},
}};
}  // namespace

int joint_nq(JointType t) {
  switch (t) {
    case JointType::Revolute: case JointType::Prismatic: return 1;
    case JointType::Fixed: return 0;
    case JointType::Spherical: return 4;
    case JointType::Universal: case JointType::Cylindrical: return 2;
    case JointType::Planar: return 3;
    case JointType::Free: return 7;
  }
  return 0;
}

int joint_nv(JointType t) {
  switch (t) {
    case JointType::Revolute: case JointType::Prismatic: return 1;
    case JointType::Fixed: return 0;
    case JointType::Spherical: return 3;
    case JointType::Universal: case JointType::Cylindrical: return 2;
    case JointType::Planar: return 3;
    case JointType::Free: return 6;
  }
  return 0;
}

const char* to_string(JointType t) { return name_of(kJoints, t); }
const char* to_string(ConstraintType t) { return name_of(kConstraints, t); }
const char* to_string(EffectType t) { return name_of(kEffects, t); }
const char* to_string(ActuatorType t) { return name_of(kActuators, t); }
const char* to_string(SensorType t) { return name_of(kSensors, t); }
bool sensor_reads_accelerations(SensorType t) { return t == SensorType::MotionForce || t == SensorType::Acceleration; }
const char* to_string(ShapeType t) { return name_of(kShapes, t); }
const char* to_string(ControllerType t) { return name_of(kControllers, t); }
std::optional<JointType> joint_type_from_string(const std::string& s) { return value_of(kJoints, s); }
std::optional<ConstraintType> constraint_type_from_string(const std::string& s) { return value_of(kConstraints, s); }
std::optional<EffectType> effect_type_from_string(const std::string& s) { return value_of(kEffects, s); }
std::optional<ActuatorType> actuator_type_from_string(const std::string& s) { return value_of(kActuators, s); }
std::optional<SensorType> sensor_type_from_string(const std::string& s) { return value_of(kSensors, s); }
std::optional<ShapeType> shape_type_from_string(const std::string& s) { return value_of(kShapes, s); }
std::optional<ControllerType> controller_type_from_string(const std::string& s) {
  return value_of(kControllers, s);
}

bool is_integrator_name(const std::string& name) {
  for (const char* n : kIntegratorNames)
    if (name == n) return true;
  return false;
}

std::string integrator_names(const std::string& separator, bool with_auto) {
  std::string out;
  for (const char* n : kIntegratorNames) {
    if (!with_auto && std::string(n) == "auto") continue;
    out += (out.empty() ? "" : separator) + std::string(n);
  }
  return out;
}

}  // namespace codyna
