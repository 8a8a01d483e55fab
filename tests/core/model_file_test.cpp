#include "io/model_file.hpp"

#include "dynamics/prepare.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>

#include "model/errors.hpp"

namespace codyna {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

// A pendulum_spec with a few of everything; the bad-input tests each break one thing in it.
constexpr const char* kPendulum = R"({
  "codyna_model": 1,
  "name": "pendulum",
  "description": "a rod on a pin",
  "bodies": [
    {"name": "link", "mass": 2.0, "com": [0, -0.5, 0], "inertia": [0.1, 0.001, 0.1],
     "shapes": [{"type": "cylinder", "radius": 0.02, "length": 1.0,
                 "frame": {"position": [0, -0.5, 0], "rotation": {"axis": [1, 0, 0], "angle_deg": 90}},
                 "color": [0.2, 0.4, 0.6]}]}
  ],
  "joints": [
    {"name": "pivot", "type": "revolute", "parent": "ground", "child": "link",
     "parent_frame": {"position": [0, 1.5, 0]}, "axis": [0, 0, 2], "q0": 0.5, "v0": [-1.25]}
  ],
  "effects": [{"name": "gravity", "type": "gravity"}],
  "actuators": [{"name": "motor", "type": "joint_force", "joint": "pivot", "min": -2, "max": 2, "unit": "N m"}],
  "sensors": [{"name": "tip_x", "type": "point_position", "body": "link", "point": [0, -1, 0], "component": "x"}],
  "plant": {"inputs": ["motor"], "outputs": ["tip_x"]},
  "solver": {"integrator": "rk4", "t_end": 2.5}
})";

// One element of every type, every field given a value other than its default.
constexpr const char* kEverything = R"({
  "codyna_model": 1,
  "name": "everything",
  "description": "one of each element",
  "bodies": [
    {"name": "b1", "mass": 1.5, "com": [0.1, 0.2, 0.3], "inertia": [0.01, 0.02, 0.03, 0.001, -0.002, 0.003],
     "shapes": [
       {"type": "box", "size": [0.1, 0.2, 0.3], "color": [0.1, 0.2, 0.3, 0.4],
        "frame": {"position": [0, 0.5, 0], "rotation": {"rpy": [0.1, 0.2, 0.3]}}},
       {"type": "cylinder", "radius": 0.02, "length": 0.7, "color": [1, 0, 0]},
       {"type": "sphere", "radius": 0.04, "frame": {"rotation": {"quaternion": [1, 2, 3, 4]}}}]},
    {"name": "b2", "mass": 2, "inertia": [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.3]]},
    {"name": "b3", "mass": 3, "inertia": [1, 1, 1]},
    {"name": "b4", "mass": 4, "inertia": [1, 1, 1]},
    {"name": "b5", "mass": 5, "inertia": [1, 1, 1]},
    {"name": "b6", "mass": 6, "inertia": [1, 1, 1]},
    {"name": "b7", "mass": 7, "inertia": [1, 1, 1]},
    {"name": "b8", "mass": 8, "inertia": [1, 1, 1]}
  ],
  "joints": [
    {"name": "j1", "type": "revolute", "parent": "ground", "child": "b1",
     "parent_frame": {"position": [0.1, 0.2, 0.3], "rotation": {"axis": [1, 1, 1], "angle": 0.7}},
     "child_frame": {"position": [-0.1, 0, 0], "rotation": {"rpy": [0.3, -0.2, 0.1]}},
     "axis": [1, 1, 0], "q0": 0.3, "v0": -0.1},
    {"name": "j2", "type": "prismatic", "parent": "b1", "child": "b2", "axis": [1, 0, 0], "q0": [0.2], "v0": [0.5]},
    {"name": "j3", "type": "fixed", "parent": "b2", "child": "b3",
     "parent_frame": {"rotation": {"matrix": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}}},
    {"name": "j4", "type": "spherical", "parent": "b3", "child": "b4",
     "q0": {"rotation": {"axis": [1, 2, 3], "angle": 0.4}}, "v0": [0.1, 0.2, 0.3]},
    {"name": "j5", "type": "universal", "parent": "b4", "child": "b5", "axis": [0, 0, 3], "axis2": [1, 0, 1],
     "q0": [0.1, 0.2], "v0": [0.3, 0.4]},
    {"name": "j6", "type": "cylindrical", "parent": "b5", "child": "b6", "axis": [0, 1, 0],
     "q0": [0.1, 0.2], "v0": [1, 2]},
    {"name": "j7", "type": "planar", "parent": "b6", "child": "b7", "q0": [1, 2, 0.3], "v0": [0.1, 0.2, 0.3]},
    {"name": "j8", "type": "free", "parent": "ground", "child": "b8",
     "q0": [1, 2, 3, 1, 1, 0, 0], "v0": [1, 2, 3, 4, 5, 6]}
  ],
  "constraints": [
    {"name": "c1", "type": "ball", "body_a": "b1", "point_a": [1, 0, 0], "body_b": "b2", "point_b": [0, 1, 0]},
    {"name": "c2", "type": "revolute", "body_a": "b3", "point_a": [0, 0, 1], "body_b": "ground",
     "point_b": [1, 1, 1], "axis_a": [1, 0, 0], "axis_b": [0, 3, 4]},
    {"name": "c3", "type": "planar_revolute", "body_a": "b5", "body_b": "b6", "axis_a": [0, 1, 0]}
  ],
  "effects": [
    {"name": "e1", "type": "gravity", "g": [0, 0, -9.81]},
    {"name": "e2", "type": "spring_damper", "body_a": "b1", "point_a": [0.1, 0, 0], "body_b": "ground",
     "point_b": [0, 0.2, 0], "stiffness": 100, "damping": 2.5, "rest_length": 0.3},
    {"name": "e3", "type": "joint_spring_damper", "joint": "j7", "dof": 2, "stiffness": 10, "damping": 0.1,
     "rest_position": 0.2},
    {"name": "e4", "type": "joint_friction", "joint": "j5", "dof": 1, "damping": 0.05},
    {"name": "e5", "type": "body_force", "body": "b8", "point": [0, 0, 1], "force": [1, 2, 3],
     "torque": [0.1, 0.2, 0.3], "frame": "body"}
  ],
  "actuators": [
    {"name": "a1", "type": "joint_force", "joint": "j6", "dof": 1, "gain": 2, "u0": 0.5, "min": -1, "max": 3,
     "unit": "N"},
    {"name": "a2", "type": "body_force", "body": "b8", "point": [1, 0, 0], "direction": [0, 3, 4], "frame": "body",
     "gain": 10, "u0": -0.5, "max": 1}
  ],
  "sensors": [
    {"name": "s1", "type": "joint_position", "joint": "j1", "unit": "deg"},
    {"name": "s2", "type": "joint_velocity", "joint": "j7", "dof": 2},
    {"name": "s3", "type": "point_position", "body": "b2", "point": [1, 2, 3], "component": "y", "frame": "b1"},
    {"name": "s4", "type": "point_velocity", "body": "b2", "point": [0, 0, 1], "component": 2},
    {"name": "s5", "type": "body_angle", "body": "b4", "axis": [1, 0, 0]},
    {"name": "s6", "type": "distance", "body_a": "b1", "point_a": [1, 0, 0], "body_b": "b8", "point_b": [0, 0, 1]}
  ],
  "plant": {"inputs": ["a1", "a2"], "outputs": ["s1", "s3", "s6"]},
  "controller": {"type": "pid", "kp": [[1, 2, 3], [4, 5, 6]], "ki": [[0.1, 0, 0], [0, 0.2, -0.3]],
                 "kd": [[0.5, 0, 0], [0, 0, 0.25]], "setpoint": [0.1, -0.2, 0.3], "operating_point": "trim"},
  "solver": {"integrator": "cvode", "rtol": 1e-6, "atol": 1e-9, "t_end": 10, "output_step": 0.05, "max_step": 0.1}
})";

// The controller forms of docs/model-format.md, one of each type.
constexpr const char* kPidController =
    R"({"type": "pid", "kp": [[218.1]], "kd": [[64]], "setpoint": [1.5708], "operating_point": "equilibrium"})";
constexpr const char* kStateFeedbackController = R"({"type": "state_feedback", "K": [[-31.6, -959.4, -66.2, -323.5]]})";
constexpr const char* kLtiController =
    R"({"type": "lti", "Ac": [[0]], "Bc": [[1]], "Cc": [[12800]], "Dc": [[-13018]], "Ts": 0.005})";
constexpr const char* kLqrController = R"({"type": "lqr", "q_weights": [10, 100, 1, 1], "r_weights": [0.01]})";

// ---------------------------------------------------------------- helpers

void expect_near(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected, double tol) {
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tol) << "actual:\n" << actual << "\nexpected:\n" << expected;
}

// Bit-exact equality of doubles, vectors and matrices; plain == for the rest.
template <class T>
bool same(const T& a, const T& b) {
  if constexpr (std::is_base_of_v<Eigen::DenseBase<T>, T>)
    return a.rows() == b.rows() && a.cols() == b.cols() &&
           (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
  else if constexpr (std::is_same_v<T, double>)
    return std::memcmp(&a, &b, sizeof a) == 0;
  else
    return a == b;
}

#define EXPECT_SAME(field) EXPECT_TRUE(same(a.field, b.field)) << "field " #field

void expect_same_model(const FrameSpec& a, const FrameSpec& b) {
  EXPECT_SAME(position);
  EXPECT_SAME(rotation);
}

void expect_same_model(const ShapeSpec& a, const ShapeSpec& b) {
  EXPECT_SAME(type);
  EXPECT_SAME(size);
  EXPECT_SAME(radius);
  EXPECT_SAME(length);
  EXPECT_SAME(color);
  expect_same_model(a.frame, b.frame);
}

void expect_same_model(const BodySpec& a, const BodySpec& b);
void expect_same_model(const JointSpec& a, const JointSpec& b);
void expect_same_model(const ConstraintSpec& a, const ConstraintSpec& b);
void expect_same_model(const EffectSpec& a, const EffectSpec& b);
void expect_same_model(const ActuatorSpec& a, const ActuatorSpec& b);
void expect_same_model(const SensorSpec& a, const SensorSpec& b);

template <class T>
void expect_same_model(const std::vector<T>& a, const std::vector<T>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("element " + std::to_string(i));
    expect_same_model(a[i], b[i]);
  }
}

void expect_same_model(const BodySpec& a, const BodySpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(mass);
  EXPECT_SAME(com);
  EXPECT_SAME(inertia);
  expect_same_model(a.shapes, b.shapes);
}

void expect_same_model(const JointSpec& a, const JointSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(type);
  EXPECT_SAME(parent);
  EXPECT_SAME(child);
  EXPECT_SAME(axis);
  EXPECT_SAME(axis2);
  EXPECT_SAME(q0);
  EXPECT_SAME(v0);
  expect_same_model(a.parent_frame, b.parent_frame);
  expect_same_model(a.child_frame, b.child_frame);
}

void expect_same_model(const ConstraintSpec& a, const ConstraintSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(type);
  EXPECT_SAME(body_a);
  EXPECT_SAME(body_b);
  EXPECT_SAME(point_a);
  EXPECT_SAME(point_b);
  EXPECT_SAME(axis_a);
  EXPECT_SAME(axis_b);
}

void expect_same_model(const EffectSpec& a, const EffectSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(type);
  EXPECT_SAME(g);
  EXPECT_SAME(body_a);
  EXPECT_SAME(body_b);
  EXPECT_SAME(point_a);
  EXPECT_SAME(point_b);
  EXPECT_SAME(stiffness);
  EXPECT_SAME(damping);
  EXPECT_SAME(rest_length);
  EXPECT_SAME(joint);
  EXPECT_SAME(dof);
  EXPECT_SAME(rest_position);
  EXPECT_SAME(force);
  EXPECT_SAME(torque);
  EXPECT_SAME(in_world);
}

void expect_same_model(const ActuatorSpec& a, const ActuatorSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(type);
  EXPECT_SAME(joint);
  EXPECT_SAME(dof);
  EXPECT_SAME(body);
  EXPECT_SAME(point);
  EXPECT_SAME(direction);
  EXPECT_SAME(in_world);
  EXPECT_SAME(gain);
  EXPECT_SAME(u0);
  EXPECT_SAME(min);
  EXPECT_SAME(max);
  EXPECT_SAME(unit);
}

void expect_same_model(const SensorSpec& a, const SensorSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(type);
  EXPECT_SAME(joint);
  EXPECT_SAME(dof);
  EXPECT_SAME(body);
  EXPECT_SAME(point);
  EXPECT_SAME(component);
  EXPECT_SAME(frame);
  EXPECT_SAME(axis);
  EXPECT_SAME(body_a);
  EXPECT_SAME(body_b);
  EXPECT_SAME(point_a);
  EXPECT_SAME(point_b);
  EXPECT_SAME(unit);
}

void expect_same_model(const ControllerSpec& a, const ControllerSpec& b) {
  EXPECT_SAME(type);
  EXPECT_SAME(kp);
  EXPECT_SAME(ki);
  EXPECT_SAME(kd);
  EXPECT_SAME(setpoint);
  EXPECT_SAME(K);
  EXPECT_SAME(Ac);
  EXPECT_SAME(Bc);
  EXPECT_SAME(Cc);
  EXPECT_SAME(Dc);
  EXPECT_SAME(Ts);
  ASSERT_EQ(a.q_weights.size(), b.q_weights.size());
  for (std::size_t i = 0; i < a.q_weights.size(); ++i) EXPECT_TRUE(same(a.q_weights[i], b.q_weights[i])) << i;
  ASSERT_EQ(a.r_weights.size(), b.r_weights.size());
  for (std::size_t i = 0; i < a.r_weights.size(); ++i) EXPECT_TRUE(same(a.r_weights[i], b.r_weights[i])) << i;
  EXPECT_SAME(operating_point);
}

void expect_same_model(const ModelSpec& a, const ModelSpec& b) {
  EXPECT_SAME(name);
  EXPECT_SAME(description);
  expect_same_model(a.bodies, b.bodies);
  expect_same_model(a.joints, b.joints);
  expect_same_model(a.constraints, b.constraints);
  expect_same_model(a.effects, b.effects);
  expect_same_model(a.actuators, b.actuators);
  expect_same_model(a.sensors, b.sensors);
  EXPECT_SAME(plant.inputs);
  EXPECT_SAME(plant.outputs);
  expect_same_model(a.controller, b.controller);
  EXPECT_SAME(solver.integrator);
  EXPECT_SAME(solver.rtol);
  EXPECT_SAME(solver.atol);
  EXPECT_SAME(solver.t_end);
  EXPECT_SAME(solver.output_step);
  EXPECT_SAME(solver.max_step);
}

#undef EXPECT_SAME

ModelSpec parse_model(const std::string& text) { return parse_model_spec_text(text, "test.json"); }

// f() must throw a ModelError for `file` at exactly `path` whose message contains `phrase`.
template <class F>
void expect_model_error(F f, const std::string& file, const std::string& path, const std::string& phrase) {
  try {
    f();
    ADD_FAILURE() << "expected a ModelError at " << path;
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.path(), path) << what;
    EXPECT_EQ(what.rfind(file + ": " + (path.empty() ? "" : path + ": "), 0), 0u) << what;
    EXPECT_NE(what.find(phrase), std::string::npos) << what << "\n  lacks: " << phrase;
  }
}

void expect_model_error(const json& j, const std::string& path, const std::string& phrase) {
  expect_model_error([&] { parse_model_spec(j, "bad.json"); }, "bad.json", path, phrase);
}

json pendulum_spec() { return json::parse(kPendulum); }

// The pendulum_spec with `controller` (JSON text) as its controller.
json with_controller(const std::string& controller) {
  json j = pendulum_spec();
  j["controller"] = json::parse(controller);
  return j;
}

ControllerSpec read_controller(const std::string& controller) {
  return parse_model_spec(with_controller(controller), "controller.json").controller;
}

// `actual` has exactly the size and (bit for bit) the entries of `expected`.
void expect_exact(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  EXPECT_TRUE(same(actual, expected)) << "actual (" << actual.rows() << " x " << actual.cols() << "):\n"
                                      << actual << "\nexpected (" << expected.rows() << " x " << expected.cols()
                                      << "):\n" << expected;
}

// The rotation matrix that `rotation` (the JSON of a ROT) reads as.
Eigen::Matrix3d read_rotation(const json& rotation) {
  json j = pendulum_spec();
  j["joints"][0]["parent_frame"]["rotation"] = rotation;
  return parse_model_spec(j, "rotation.json").joints[0].parent_frame.rotation;
}

Eigen::Matrix3d read_inertia(const json& inertia) {
  json j = pendulum_spec();
  j["bodies"][0]["inertia"] = inertia;
  return parse_model_spec(j, "inertia.json").bodies[0].inertia;
}

Eigen::Matrix3d rot_x(double a) {
  Eigen::Matrix3d R;
  R << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return R;
}
Eigen::Matrix3d rot_y(double a) {
  Eigen::Matrix3d R;
  R << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return R;
}
Eigen::Matrix3d rot_z(double a) {
  Eigen::Matrix3d R;
  R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return R;
}

// A fresh, empty directory, removed at the end of the test.
class ModelTempDir {
 public:
  ModelTempDir() {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("codyna_model_file_" + std::string(info->name()) + "_" +
                                         std::to_string(std::random_device{}()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ModelTempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }
  std::size_t count() const { return std::distance(fs::directory_iterator(path_), fs::directory_iterator()); }

 private:
  fs::path path_;
};

// ---------------------------------------------------------------- reading

TEST(ModelFile, ParsesSmallModel) {
  const ModelSpec m = parse_model(kPendulum);
  EXPECT_EQ(m.name, "pendulum");
  EXPECT_EQ(m.description, "a rod on a pin");

  ASSERT_EQ(m.bodies.size(), 1u);
  const BodySpec& link = m.bodies[0];
  EXPECT_EQ(link.name, "link");
  EXPECT_EQ(link.mass, 2.0);
  EXPECT_EQ(link.com, Eigen::Vector3d(0, -0.5, 0));
  EXPECT_EQ(link.inertia, Eigen::Vector3d(0.1, 0.001, 0.1).asDiagonal().toDenseMatrix());
  ASSERT_EQ(link.shapes.size(), 1u);
  const ShapeSpec& rod = link.shapes[0];
  EXPECT_EQ(rod.type, ShapeType::Cylinder);
  EXPECT_EQ(rod.radius, 0.02);
  EXPECT_EQ(rod.length, 1.0);
  EXPECT_EQ(rod.frame.position, Eigen::Vector3d(0, -0.5, 0));
  expect_near(rod.frame.rotation, rot_x(kPi / 2), 1e-15);
  EXPECT_EQ(rod.color, Eigen::Vector4d(0.2, 0.4, 0.6, 1.0));

  ASSERT_EQ(m.joints.size(), 1u);
  const JointSpec& pivot = m.joints[0];
  EXPECT_EQ(pivot.name, "pivot");
  EXPECT_EQ(pivot.type, JointType::Revolute);
  EXPECT_EQ(pivot.parent, "ground");
  EXPECT_EQ(pivot.child, "link");
  EXPECT_EQ(pivot.parent_frame.position, Eigen::Vector3d(0, 1.5, 0));
  EXPECT_EQ(pivot.parent_frame.rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(pivot.child_frame.position, Eigen::Vector3d::Zero());
  EXPECT_EQ(pivot.axis, Eigen::Vector3d(0, 0, 1));  // normalized
  EXPECT_EQ(pivot.axis2, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(pivot.q0, Eigen::VectorXd::Constant(1, 0.5));
  EXPECT_EQ(pivot.v0, Eigen::VectorXd::Constant(1, -1.25));

  ASSERT_EQ(m.effects.size(), 1u);
  EXPECT_EQ(m.effects[0].type, EffectType::Gravity);
  EXPECT_EQ(m.effects[0].g, Eigen::Vector3d(0, -9.81, 0));

  ASSERT_EQ(m.actuators.size(), 1u);
  const ActuatorSpec& motor = m.actuators[0];
  EXPECT_EQ(motor.type, ActuatorType::JointForce);
  EXPECT_EQ(motor.joint, "pivot");
  EXPECT_EQ(motor.dof, 0);
  EXPECT_EQ(motor.gain, 1.0);
  EXPECT_EQ(motor.min, -2.0);
  EXPECT_EQ(motor.max, 2.0);
  EXPECT_EQ(motor.unit, "N m");

  ASSERT_EQ(m.sensors.size(), 1u);
  const SensorSpec& tip = m.sensors[0];
  EXPECT_EQ(tip.type, SensorType::PointPosition);
  EXPECT_EQ(tip.body, "link");
  EXPECT_EQ(tip.point, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(tip.component, 0);
  EXPECT_EQ(tip.frame, "ground");

  EXPECT_EQ(m.plant.inputs, std::vector<std::string>{"motor"});
  EXPECT_EQ(m.plant.outputs, std::vector<std::string>{"tip_x"});
  EXPECT_EQ(m.solver.integrator, "rk4");
  EXPECT_EQ(m.solver.t_end, 2.5);
  EXPECT_EQ(m.solver.rtol, SolverSpec{}.rtol);
  EXPECT_TRUE(m.constraints.empty());
}

TEST(ModelFile, ParsesEveryElementType) {
  const ModelSpec m = parse_model(kEverything);
  ASSERT_EQ(m.joints.size(), 8u);
  EXPECT_EQ(m.joints[0].axis, Eigen::Vector3d(1, 1, 0) / std::sqrt(2.0));
  EXPECT_EQ(m.joints[4].axis2, Eigen::Vector3d(1, 0, 1) / std::sqrt(2.0));
  EXPECT_EQ(m.constraints[1].axis_b, Eigen::Vector3d(0, 0.6, 0.8));
  EXPECT_EQ(m.effects[2].dof, 2);
  EXPECT_EQ(m.effects[4].body_a, "b8");
  EXPECT_EQ(m.effects[4].point_a, Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(m.effects[4].in_world);
  EXPECT_EQ(m.actuators[1].direction, Eigen::Vector3d(0, 0.6, 0.8));
  EXPECT_FALSE(m.actuators[1].in_world);
  EXPECT_FALSE(m.actuators[1].min.has_value());
  EXPECT_EQ(m.actuators[1].max, 1.0);
  EXPECT_EQ(m.sensors[2].component, 1);
  EXPECT_EQ(m.sensors[2].frame, "b1");
  EXPECT_EQ(m.sensors[3].component, 2);
  EXPECT_EQ(m.sensors[5].body_b, "b8");
  EXPECT_EQ(m.solver.max_step, 0.1);
}

TEST(ModelFile, RotationForms) {
  const double a = 0.7;
  const Eigen::Vector3d u = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0).finished();
  const Eigen::Matrix3d rodrigues = Eigen::Matrix3d::Identity() + std::sin(a) * K + (1 - std::cos(a)) * K * K;

  expect_near(read_rotation({{"axis", {1, 2, 2}}, {"angle", a}}), rodrigues, 1e-15);
  expect_near(read_rotation({{"axis", {0, 0, 5}}, {"angle_deg", 90}}), rot_z(kPi / 2), 1e-15);
  // (w, x, y, z) = (1, 1, 0, 0) / sqrt(2): 90 degrees about x; normalized on read
  expect_near(read_rotation({{"quaternion", {3, 3, 0, 0}}}), rot_x(kPi / 2), 1e-15);
  expect_near(read_rotation({{"quaternion", {std::cos(a / 2), u.x() * std::sin(a / 2), u.y() * std::sin(a / 2),
                                             u.z() * std::sin(a / 2)}}}),
              rodrigues, 1e-15);
  const json rows = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
  Eigen::Matrix3d cyclic;
  cyclic << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  EXPECT_EQ(read_rotation({{"matrix", rows}}), cyclic);  // taken as is
  expect_near(read_rotation({{"rpy", {0.1, -0.2, 0.3}}}), rot_z(0.3) * rot_y(-0.2) * rot_x(0.1), 1e-15);
  EXPECT_EQ(read_rotation({{"rpy", {0.0, 0.0, 0.0}}}), Eigen::Matrix3d::Identity());
}

TEST(ModelFile, InertiaForms) {
  EXPECT_EQ(read_inertia({1, 2, 3}), Eigen::Vector3d(1, 2, 3).asDiagonal().toDenseMatrix());

  Eigen::Matrix3d full;
  full << 1, 0.1, 0.2,  //
      0.1, 2, 0.3,      //
      0.2, 0.3, 3;
  EXPECT_EQ(read_inertia({1, 2, 3, 0.1, 0.2, 0.3}), full);
  EXPECT_EQ(read_inertia({{1, 0.1, 0.2}, {0.1, 2, 0.3}, {0.2, 0.3, 3}}), full);

  // asymmetry below 1e-12 (relative) is accepted, and kept so that the spec round-trips exactly
  const Eigen::Matrix3d I = read_inertia({{1, 0.1, 0.2}, {0.1 + 1e-13, 2, 0.3}, {0.2, 0.3, 3}});
  EXPECT_EQ(I(1, 0), 0.1 + 1e-13);
  expect_near(I, full, 2e-13);
}

TEST(ModelFile, JointInitialValueForms) {
  json j = json::parse(kEverything);
  const ModelSpec m = parse_model_spec(j, "q0.json");

  const Eigen::Quaterniond r(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const JointSpec& spherical = m.joints[3];
  ASSERT_EQ(spherical.q0.size(), 4);
  expect_near(spherical.q0, Eigen::Vector4d(r.w(), r.x(), r.y(), r.z()), 1e-15);

  const JointSpec& free = m.joints[7];
  ASSERT_EQ(free.q0.size(), 7);
  const double h = 1 / std::sqrt(2.0);
  expect_near(free.q0, (Eigen::VectorXd(7) << 1, 2, 3, h, h, 0, 0).finished(), 1e-16);
  EXPECT_EQ(free.v0, (Eigen::VectorXd(6) << 1, 2, 3, 4, 5, 6).finished());
  EXPECT_EQ(m.joints[2].q0.size(), 0);  // fixed joint: nothing

  // a free joint's q0 as a pose
  j["joints"][7]["q0"] = {{"position", {4, 5, 6}}, {"rotation", {{"axis", {0, 0, 1}}, {"angle_deg", 90}}}};
  const Eigen::VectorXd q = parse_model_spec(j, "q0.json").joints[7].q0;
  expect_near(q, (Eigen::VectorXd(7) << 4, 5, 6, h, 0, 0, h).finished(), 1e-15);
}

TEST(ModelFile, DefaultsOfOptionalFields) {
  const ModelSpec m = parse_model(R"({
    "name": "bare",
    "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1], "shapes": [{"type": "box"}]}],
    "joints": [{"name": "j", "type": "universal", "parent": "ground", "child": "b"}],
    "sensors": [{"name": "s", "type": "point_velocity", "body": "b"}]
  })");
  const ShapeSpec shape_default;
  EXPECT_EQ(m.bodies[0].com, Eigen::Vector3d::Zero());
  EXPECT_EQ(m.bodies[0].shapes[0].size, shape_default.size);
  EXPECT_EQ(m.bodies[0].shapes[0].color, shape_default.color);
  EXPECT_EQ(m.joints[0].axis, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(m.joints[0].axis2, Eigen::Vector3d::UnitY());
  EXPECT_EQ(m.joints[0].q0.size(), 0);
  EXPECT_EQ(m.sensors[0].frame, "ground");
  EXPECT_EQ(m.sensors[0].component, 0);
  EXPECT_EQ(m.solver.integrator, SolverSpec{}.integrator);
  EXPECT_TRUE(m.plant.inputs.empty());
  EXPECT_EQ(m.controller.type, ControllerType::None);
}

TEST(ModelFile, ControllerNames) {
  for (ControllerType t : {ControllerType::None, ControllerType::Pid, ControllerType::StateFeedback,
                           ControllerType::Lti, ControllerType::Lqr})
    EXPECT_EQ(controller_type_from_string(to_string(t)), t);
  EXPECT_STREQ(to_string(ControllerType::StateFeedback), "state_feedback");
  EXPECT_FALSE(controller_type_from_string("PID").has_value());
}

TEST(ModelFile, ParsesPidController) {
  const ControllerSpec c = read_controller(kPidController);
  EXPECT_EQ(c.type, ControllerType::Pid);
  expect_exact(c.kp, Eigen::MatrixXd{{218.1}});
  EXPECT_EQ(c.ki.size(), 0);  // no integral action
  expect_exact(c.kd, Eigen::MatrixXd{{64.0}});
  expect_exact(c.setpoint, Eigen::VectorXd::Constant(1, 1.5708));
  EXPECT_EQ(c.operating_point, "equilibrium");

  // a 1 x 1 matrix may be a plain number; without a setpoint r is the operating point's y0 (empty)
  const ControllerSpec p = read_controller(R"({"type": "pid", "kp": 218.1, "ki": 2})");
  expect_exact(p.kp, Eigen::MatrixXd{{218.1}});
  expect_exact(p.ki, Eigen::MatrixXd{{2.0}});
  EXPECT_EQ(p.kd.size(), 0);
  EXPECT_EQ(p.setpoint.size(), 0);

  // multivariable: nu x ny, rows in Plant/In order
  const ModelSpec m = parse_model(kEverything);
  expect_exact(m.controller.kp, Eigen::MatrixXd{{1, 2, 3}, {4, 5, 6}});
  expect_exact(m.controller.ki, Eigen::MatrixXd{{0.1, 0, 0}, {0, 0.2, -0.3}});
  expect_exact(m.controller.kd, Eigen::MatrixXd{{0.5, 0, 0}, {0, 0, 0.25}});
  expect_exact(m.controller.setpoint, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(m.controller.operating_point, "trim");
}

TEST(ModelFile, ParsesStateFeedbackController) {
  const ControllerSpec c = read_controller(kStateFeedbackController);
  EXPECT_EQ(c.type, ControllerType::StateFeedback);
  expect_exact(c.K, Eigen::MatrixXd{{-31.6, -959.4, -66.2, -323.5}});
  EXPECT_EQ(c.operating_point, "equilibrium");  // the default
  EXPECT_EQ(c.kp.size(), 0);

  const ControllerSpec two = read_controller(R"({"type": "state_feedback", "K": [[1, 2], [3, 4], [5, 6]],
                                                 "operating_point": "initial"})");
  expect_exact(two.K, Eigen::MatrixXd{{1, 2}, {3, 4}, {5, 6}});
  EXPECT_EQ(two.operating_point, "initial");
}

TEST(ModelFile, ParsesLtiController) {
  const ControllerSpec c = read_controller(kLtiController);
  EXPECT_EQ(c.type, ControllerType::Lti);
  expect_exact(c.Ac, Eigen::MatrixXd{{0.0}});
  expect_exact(c.Bc, Eigen::MatrixXd{{1.0}});
  expect_exact(c.Cc, Eigen::MatrixXd{{12800.0}});
  expect_exact(c.Dc, Eigen::MatrixXd{{-13018.0}});
  EXPECT_EQ(c.Ts, 0.005);

  // continuous (Ts left out), 2 states, 1 output, 2 inputs
  const ControllerSpec d = read_controller(R"({"type": "lti", "Ac": [[0, 1], [-2, -3]], "Bc": [[0], [1]],
                                               "Cc": [[1, 0], [0, 1]], "Dc": [[0.5], [-0.5]]})");
  expect_exact(d.Ac, Eigen::MatrixXd{{0, 1}, {-2, -3}});
  expect_exact(d.Bc, Eigen::MatrixXd{{0}, {1}});
  expect_exact(d.Cc, Eigen::MatrixXd{{1, 0}, {0, 1}});
  expect_exact(d.Dc, Eigen::MatrixXd{{0.5}, {-0.5}});
  EXPECT_EQ(d.Ts, 0.0);
}

TEST(ModelFile, ParsesLqrController) {
  const ControllerSpec c = read_controller(kLqrController);
  EXPECT_EQ(c.type, ControllerType::Lqr);
  EXPECT_EQ(c.q_weights, (std::vector<double>{10, 100, 1, 1}));
  EXPECT_EQ(c.r_weights, std::vector<double>{0.01});
  EXPECT_EQ(c.operating_point, "equilibrium");

  // weights left out: identity; a zero state weight is allowed
  const ControllerSpec d = read_controller(R"({"type": "lqr", "q_weights": [0, 1]})");
  EXPECT_EQ(d.q_weights, (std::vector<double>{0, 1}));
  EXPECT_TRUE(d.r_weights.empty());
}

TEST(ModelFile, NoController) {
  // "none" reads as no controller, which is not written
  const ModelSpec m = parse_model_spec(with_controller(R"({"type": "none"})"), "none.json");
  EXPECT_EQ(m.controller.type, ControllerType::None);
  EXPECT_FALSE(to_json(m).contains("controller"));
  EXPECT_FALSE(to_json(parse_model(kPendulum)).contains("controller"));
}

// ---------------------------------------------------------------- writing

TEST(ModelFile, RoundTripIsExact) {
  for (const char* text : {kPendulum, kEverything}) {
    const ModelSpec m = parse_model(text);
    const json j = to_json(m);
    expect_same_model(parse_model_spec(j, "written.json"), m);
    expect_same_model(parse_model(j.dump()), m);
    EXPECT_EQ(to_json(parse_model_spec(j, "written.json")), j);
    EXPECT_EQ(j["bodies"][0]["inertia"].size(), 6u);
    EXPECT_TRUE(j["joints"][0]["parent_frame"]["rotation"].contains("matrix"));
  }
}

TEST(ModelFile, RoundTripOfEveryControllerIsExact) {
  for (const char* controller : {kPidController, kStateFeedbackController, kLtiController, kLqrController}) {
    SCOPED_TRACE(controller);
    const ModelSpec m = parse_model_spec(with_controller(controller), "controller.json");
    const json j = to_json(m);
    expect_same_model(parse_model_spec(j, "written.json"), m);
    expect_same_model(parse_model(j.dump()), m);
    EXPECT_EQ(to_json(parse_model_spec(j, "written.json")), j);
    // written as given, with operating_point made explicit, matrices always as arrays of rows
    json expected = json::parse(controller);
    expected["operating_point"] = "equilibrium";
    EXPECT_EQ(j["controller"], expected);
  }
  // a 1 x 1 matrix given as a number is written as [[x]]
  const json j = to_json(parse_model_spec(with_controller(R"({"type": "pid", "kp": 2.5})"), "number.json"));
  EXPECT_EQ(j["controller"]["kp"], json::parse("[[2.5]]"));
}

TEST(ModelFile, RoundTripOfBuiltSpecIsBitExact) {
  ModelSpec m;
  m.name = "built";
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d w = Eigen::Vector3d::Random();
    const Eigen::Quaterniond q(Eigen::AngleAxisd(w.norm() * 3, w.normalized()));
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 1.0 / (i + 3);
    b.com = Eigen::Vector3d::Random() / 3;
    const Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    b.inertia = A * A.transpose();  // symmetric up to rounding; sometimes exactly
    m.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.type = JointType::Free;
    j.parent = kGroundName;
    j.child = b.name;
    j.parent_frame.rotation = q.toRotationMatrix();
    j.parent_frame.position = w * 1e-7;
    j.q0.resize(7);
    j.q0 << w, q.w(), q.x(), q.y(), q.z();
    j.v0 = Eigen::VectorXd::Random(6) * 1e14;
    m.joints.push_back(j);
  }
  // a sampled lti controller with awkward numbers
  ControllerSpec& c = m.controller;
  c.type = ControllerType::Lti;
  c.Ac = Eigen::MatrixXd::Random(3, 3) / 3;
  c.Bc = Eigen::MatrixXd::Random(3, 2) * 1e-300;
  c.Cc = Eigen::MatrixXd::Random(4, 3) * 1e14;
  c.Dc = Eigen::MatrixXd::Random(4, 2) / 7;
  c.Ts = 1.0 / 3;
  c.operating_point = "initial";
  expect_same_model(parse_model(to_json(m).dump()), m);

  // and each of the other types, with the fields of the others left at their defaults
  ModelSpec pid = m;
  pid.controller = {};
  pid.controller.type = ControllerType::Pid;
  pid.controller.kp = Eigen::MatrixXd::Random(2, 3) / 3;
  pid.controller.ki = Eigen::MatrixXd::Random(2, 3) * 1e-10;
  pid.controller.kd = Eigen::MatrixXd::Random(2, 3) / 11;
  pid.controller.setpoint = Eigen::VectorXd::Random(3) * std::numbers::pi;
  expect_same_model(parse_model(to_json(pid).dump()), pid);

  ModelSpec lqr = m;
  lqr.controller = {};
  lqr.controller.type = ControllerType::Lqr;
  lqr.controller.q_weights = {1.0 / 3, 0.0, 1e-300, 1e14};
  lqr.controller.r_weights = {2.0 / 3};
  lqr.controller.operating_point = "trim";
  expect_same_model(parse_model(to_json(lqr).dump()), lqr);
}

TEST(ModelFile, SaveThenLoad) {
  const ModelTempDir dir;
  const std::string path = (dir.path() / "everything.json").string();
  const ModelSpec m = parse_model(kEverything);
  save_model_spec(parse_model(kPendulum), path);
  save_model_spec(m, path);  // replaces the file
  expect_same_model(load_model_spec(path), m);
  EXPECT_EQ(json::parse(std::ifstream(path)), to_json(m));
  EXPECT_EQ(dir.count(), 1u);  // no temporary left over

  // readable by people: format version and name first
  std::ifstream in(path);
  std::string line1, line2, line3;
  std::getline(in, line1), std::getline(in, line2), std::getline(in, line3);
  EXPECT_EQ(line2, "  \"codyna_model\": 1,");
  EXPECT_EQ(line3, "  \"name\": \"everything\",");
}

TEST(ModelFile, SaveIntoMissingDirectoryThrowsAndWritesNothing) {
  const ModelTempDir dir;
  const fs::path missing = dir.path() / "missing";
  const std::string path = (missing / "m.json").string();
  try {
    save_model_spec(parse_model(kPendulum), path);
    ADD_FAILURE() << "save into a missing directory did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_EQ(dir.count(), 0u);
}

TEST(ModelFile, FailedSaveLeavesNoTemporaryFile) {
  const ModelTempDir dir;
  const fs::path target = dir.path() / "taken";
  fs::create_directory(target);  // a file cannot replace a directory
  EXPECT_THROW(save_model_spec(parse_model(kPendulum), target.string()), std::runtime_error);
  EXPECT_EQ(dir.count(), 1u);
  EXPECT_TRUE(fs::is_directory(target));

  ModelSpec m = parse_model(kPendulum);
  m.name = "\xff";  // not UTF-8: cannot be written as JSON
  const std::string path = (dir.path() / "m.json").string();
  try {
    save_model_spec(m, path);
    ADD_FAILURE() << "save of a name that is not UTF-8 did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_EQ(dir.count(), 1u);
}

// ---------------------------------------------------------------- bad input

TEST(ModelFileErrors, MalformedJsonReportsLineAndColumn) {
  const std::string text = "{\n  \"name\": \"m\",\n  \"bodies\": [\n    {\"name\": \"a\", \"mass\": 1,}\n  ]\n}\n";
  expect_model_error([&] { parse_model_spec_text(text, "inline.json"); }, "inline.json", "",
                     "invalid JSON at line 4, column 29");
  expect_model_error([&] { parse_model_spec_text("", "empty.json"); }, "empty.json", "", "line 1, column 1");
}

TEST(ModelFileErrors, MalformedJsonFile) {
  const std::string path = CODYNA_TEST_DATA_DIR "/bad_malformed.json";
  expect_model_error([&] { load_model_spec(path); }, path, "", "invalid JSON at line 6, column 5");
}

TEST(ModelFileErrors, UnknownJointTypeInFile) {
  const std::string path = CODYNA_TEST_DATA_DIR "/bad_joint_type.json";
  expect_model_error([&] { load_model_spec(path); }, path, "/joints/0/type",
                     "unknown joint type \"hinge\" (expected one of: revolute, prismatic, fixed, spherical, "
                     "universal, cylindrical, planar, free)");
}

TEST(ModelFileErrors, UnknownTypeInEveryList) {
  json j = pendulum_spec();
  j["constraints"] = {{{"name", "c"}, {"type", "ball"}, {"body_a", "link"}, {"body_b", "ground"}}};
  const struct {
    json::json_pointer type;
    const char* phrase;
  } cases[] = {
      {"/bodies/0/shapes/0/type"_json_pointer, "unknown shape type \"bogus\" (expected one of: box, cylinder, sphere)"},
      {"/joints/0/type"_json_pointer, "unknown joint type \"bogus\""},
      {"/constraints/0/type"_json_pointer,
       "unknown constraint type \"bogus\" (expected one of: ball, revolute, planar_revolute, coupler, rolling_ball, rolling_disc)"},
      {"/effects/0/type"_json_pointer, "unknown effect type \"bogus\" (expected one of: gravity, spring_damper,"},
      {"/actuators/0/type"_json_pointer, "unknown actuator type \"bogus\" (expected one of: joint_force, body_force, body_torque, line_force, mix, motion)"},
      {"/sensors/0/type"_json_pointer, "unknown sensor type \"bogus\" (expected one of: joint_position,"},
  };
  for (const auto& c : cases) {
    json bad = j;
    bad[c.type] = "bogus";
    expect_model_error(bad, c.type.to_string(), c.phrase);
  }
}

TEST(ModelFileErrors, MissingRequiredField) {
  json j = pendulum_spec();
  j["joints"][0].erase("child");
  expect_model_error(j, "/joints/0", "missing required field \"child\"");

  j = pendulum_spec();
  j.erase("name");
  expect_model_error(j, "", "missing required field \"name\"");

  j = pendulum_spec();
  j["effects"] = {{{"name", "spring"}, {"type", "spring_damper"}, {"body_a", "link"}}};
  expect_model_error(j, "/effects/0", "missing required field \"body_b\"");
}

TEST(ModelFileErrors, WrongType) {
  json j = pendulum_spec();
  j["bodies"][0]["mass"] = "ten";
  expect_model_error(j, "/bodies/0/mass", "expected a number, got string \"ten\"");

  j = pendulum_spec();
  j["bodies"][0]["com"] = {0, 1};
  expect_model_error(j, "/bodies/0/com", "expected an array of 3 numbers, got an array of 2 elements");

  j = pendulum_spec();
  j["actuators"][0]["dof"] = 0.5;
  expect_model_error(j, "/actuators/0/dof", "expected an integer, got number 0.5");

  j = pendulum_spec();
  j["bodies"] = {{"name", "link"}};
  expect_model_error(j, "/bodies", "expected an array, got an object");
}

TEST(ModelFileErrors, UnknownField) {
  json j = pendulum_spec();
  j["bodies"][0]["mas"] = 2.0;
  expect_model_error(j, "/bodies/0/mas", "unknown field \"mas\" (allowed: name, mass, com, inertia, shapes)");

  // a field of another type is unknown too
  j = pendulum_spec();
  j["effects"][0]["stiffness"] = 10;
  expect_model_error(j, "/effects/0/stiffness",
                     "unknown field \"stiffness\" (allowed for a gravity effect: name, type, g)");
}

TEST(ModelFileErrors, InitialValueOfWrongLength) {
  json j = pendulum_spec();
  j["joints"][0]["q0"] = {0.1, 0.2};
  expect_model_error(j, "/joints/0/q0", "expected 1 value (nq of a revolute joint), got 2");

  j = json::parse(kEverything);
  j["joints"][3]["v0"] = {1, 2, 3, 4};
  expect_model_error(j, "/joints/3/v0", "expected 3 values (nv of a spherical joint), got 4");
}

TEST(ModelFileErrors, NonOrthonormalRotationMatrix) {
  json j = pendulum_spec();
  j["joints"][0]["parent_frame"]["rotation"] = {{"matrix", {{1, 0, 0}, {0, 1, 1e-6}, {0, 0, 1}}}};
  expect_model_error(j, "/joints/0/parent_frame/rotation/matrix", "rotation matrix is not orthonormal");

  j["joints"][0]["parent_frame"]["rotation"] = {{"matrix", {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}}};
  expect_model_error(j, "/joints/0/parent_frame/rotation/matrix", "determinant -1");
}

TEST(ModelFileErrors, ZeroAxis) {
  json j = pendulum_spec();
  j["joints"][0]["axis"] = {0, 0, 0};
  expect_model_error(j, "/joints/0/axis", "expected a non-zero vector");

  j = pendulum_spec();
  j["bodies"][0]["shapes"][0]["frame"]["rotation"] = {{"quaternion", {0, 0, 0, 0}}};
  expect_model_error(j, "/bodies/0/shapes/0/frame/rotation/quaternion", "expected a non-zero quaternion");
}

TEST(ModelFileErrors, NonSymmetricInertia) {
  json j = pendulum_spec();
  j["bodies"][0]["inertia"] = {{1, 0.1, 0}, {0, 1, 0}, {0, 0, 1}};
  expect_model_error(j, "/bodies/0/inertia", "inertia matrix is not symmetric");
}

TEST(ModelFileErrors, BadRotationObject) {
  json j = pendulum_spec();
  auto& rotation = j["joints"][0]["parent_frame"]["rotation"];
  rotation = {{"rpy", {0, 0, 1}}, {"matrix", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
  expect_model_error(j, "/joints/0/parent_frame/rotation", "expected one rotation form");
  rotation = {{"axis", {0, 0, 1}}};
  expect_model_error(j, "/joints/0/parent_frame/rotation", "missing required field \"angle\"");
}

TEST(ModelFileErrors, UnsupportedFormatVersion) {
  json j = pendulum_spec();
  j["codyna_model"] = 2;
  expect_model_error(j, "/codyna_model", "unsupported format version 2");
}

// `controller` (JSON text) as the pendulum_spec's controller must fail at `path` with `phrase`.
void expect_controller_error(const std::string& controller, const std::string& path, const std::string& phrase) {
  SCOPED_TRACE(controller);
  expect_model_error(with_controller(controller), path, phrase);
}

TEST(ModelFileErrors, UnknownControllerType) {
  expect_controller_error(R"({"type": "mpc"})", "/controller/type",
                          "unknown controller type \"mpc\" (expected one of: none, pid, state_feedback, lti, lqr, driver)");
  expect_controller_error(R"({"kp": 1})", "/controller", "missing required field \"type\"");
  expect_model_error(with_controller("[1]"), "/controller", "expected an object, got an array of 1 element");
}

TEST(ModelFileErrors, UnknownControllerField) {
  expect_controller_error(R"({"type": "pid", "kp": 1, "kq": 2})", "/controller/kq",
                          "unknown field \"kq\" (allowed for a pid controller: type, kp, ki, kd, setpoint, "
                          "operating_point)");
  // a field of another controller type is unknown too
  expect_controller_error(R"({"type": "state_feedback", "K": [[1, 2]], "Ts": 0.01})", "/controller/Ts",
                          "unknown field \"Ts\" (allowed for a state_feedback controller: type, K, operating_point)");
  expect_controller_error(R"({"type": "none", "kp": 1})", "/controller/kp",
                          "unknown field \"kp\" (allowed for a none controller: type)");
}

TEST(ModelFileErrors, MissingControllerMatrix) {
  expect_controller_error(R"({"type": "pid", "kd": 1})", "/controller", "missing required field \"kp\"");
  expect_controller_error(R"({"type": "state_feedback"})", "/controller", "missing required field \"K\"");
  expect_controller_error(R"({"type": "lti", "Ac": 0, "Bc": 1, "Cc": 1})", "/controller",
                          "missing required field \"Dc\"");
}

TEST(ModelFileErrors, RaggedControllerMatrix) {
  expect_controller_error(R"({"type": "state_feedback", "K": [[1, 2, 3, 4], [5, 6, 7]]})", "/controller/K/1",
                          "expected 4 numbers like the first row, got 3");
  expect_controller_error(R"({"type": "state_feedback", "K": [[1], [2, 3]]})", "/controller/K/1",
                          "expected 1 number like the first row, got 2");
  expect_controller_error(R"({"type": "state_feedback", "K": [[1, 2], 3]})", "/controller/K/1",
                          "expected an array of 2 numbers like the first row, got number 3");
}

TEST(ModelFileErrors, MalformedControllerMatrix) {
  expect_controller_error(R"({"type": "pid", "kp": [[1, "2"]]})", "/controller/kp/0/1",
                          "expected a number, got string \"2\"");
  expect_controller_error(R"({"type": "pid", "kp": [[1, null]]})", "/controller/kp/0/1",
                          "expected a number, got null");
  // a row vector is an array of one row
  expect_controller_error(R"({"type": "state_feedback", "K": [1, 2]})", "/controller/K",
                          "expected an array of rows (a row vector is written [[a, b, ...]]), got an array of 2");
  expect_controller_error(R"({"type": "state_feedback", "K": []})", "/controller/K",
                          "expected a matrix (an array of rows, each an array of numbers; a 1 x 1 matrix may be a "
                          "number), got an array of 0 elements");
  expect_controller_error(R"({"type": "state_feedback", "K": [[]]})", "/controller/K/0",
                          "expected a row (a non-empty array of numbers), got an array of 0 elements");
  expect_controller_error(R"({"type": "state_feedback", "K": "1"})", "/controller/K",
                          "expected a matrix");
}

TEST(ModelFileErrors, InconsistentPidGains) {
  expect_controller_error(R"({"type": "pid", "kp": [[1, 2]], "ki": [[1], [2]]})", "/controller/ki",
                          "expected a 1 x 2 matrix (the size of kp), got 2 x 1");
  expect_controller_error(R"({"type": "pid", "kp": [[1, 2]], "kd": 3})", "/controller/kd",
                          "expected a 1 x 2 matrix (the size of kp), got 1 x 1");
  expect_controller_error(R"({"type": "pid", "kp": [[1, 2]], "setpoint": [0.5]})", "/controller/setpoint",
                          "expected 2 values (one per column of kp), got 1");
  expect_controller_error(R"({"type": "pid", "kp": 1, "setpoint": 0.5})", "/controller/setpoint",
                          "expected an array of numbers, got number 0.5");
}

TEST(ModelFileErrors, InconsistentLtiMatrices) {
  expect_controller_error(R"({"type": "lti", "Ac": [[1, 2]], "Bc": [[1]], "Cc": [[1, 2]], "Dc": [[0]]})",
                          "/controller/Ac", "expected a square matrix, got 1 x 2");
  expect_controller_error(R"({"type": "lti", "Ac": [[1, 0], [0, 1]], "Bc": [[1]], "Cc": [[1, 2]], "Dc": [[0]]})",
                          "/controller/Bc", "expected 2 rows (as many as Ac), got 1");
  expect_controller_error(R"({"type": "lti", "Ac": [[1, 0], [0, 1]], "Bc": [[1], [2]], "Cc": 1, "Dc": [[0]]})",
                          "/controller/Cc", "expected 2 columns (as many as Ac), got 1");
  expect_controller_error(R"({"type": "lti", "Ac": 1, "Bc": [[1, 2]], "Cc": [[1], [2]], "Dc": [[0, 0]]})",
                          "/controller/Dc", "expected a 2 x 2 matrix (rows of Cc by columns of Bc), got 1 x 2");
}

TEST(ModelFileErrors, NegativeSampleTime) {
  expect_controller_error(R"({"type": "lti", "Ac": 0, "Bc": 1, "Cc": 1, "Dc": 0, "Ts": -0.005})", "/controller/Ts",
                          "expected a number >= 0 (0 = continuous), got number -0.005");
}

TEST(ModelFileErrors, BadLqrWeight) {
  expect_controller_error(R"({"type": "lqr", "q_weights": [10, -1, 1, 1]})", "/controller/q_weights/1",
                          "expected a number >= 0, got number -1");
  expect_controller_error(R"({"type": "lqr", "r_weights": [-0.01]})", "/controller/r_weights/0",
                          "expected a number > 0 (R = diag(r_weights) must be positive definite), got number -0.01");
  expect_controller_error(R"({"type": "lqr", "r_weights": [1, 0]})", "/controller/r_weights/1",
                          "expected a number > 0");
  expect_controller_error(R"({"type": "lqr", "q_weights": 10})", "/controller/q_weights",
                          "expected an array, got number 10");
}

TEST(ModelFileErrors, BadOperatingPoint) {
  expect_controller_error(R"({"type": "lqr", "operating_point": "upright"})", "/controller/operating_point",
                          "unknown operating point \"upright\" (expected one of: initial, equilibrium, trim, steady)");
  expect_controller_error(R"({"type": "lqr", "operating_point": 0})", "/controller/operating_point",
                          "expected a string, got number 0");
}

TEST(ModelFileErrors, FileNotFound) {
  const std::string path = CODYNA_TEST_DATA_DIR "/no_such_model.json";
  expect_model_error([&] { load_model_spec(path); }, path, "", "cannot open file");
}

}  // namespace
}  // namespace codyna

// Absurd numbers are refused where they enter, with the field's path (reliability issue).
TEST(ModelFileErrors, AbsurdNumbersAreRefusedWithTheirPath) {
  const auto pendulum_spec = [](const std::string& body_extra, const std::string& top_extra = "") {
    return R"({"name": "p", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1, 0, 0, 0])" + body_extra +
           R"(}], "joints": [{"name": "j", "type": "revolute", "parent": "ground", "child": "b"}])" + top_extra + "}";
  };
  const auto error_of = [](const std::string& text) -> std::string {
    try {
      codyna::compile(codyna::parse_model_spec_text(text, "m.json"), "m.json");
    } catch (const codyna::ModelError& e) {
      return e.path() + ": " + e.detail();
    }
    return "";
  };
  EXPECT_EQ(error_of(pendulum_spec(R"(, "com": [0, 1e308, 0])")), "/bodies/0/com/1: expected a number of magnitude at most 1e15, got number 1e+308");
  EXPECT_NE(error_of(pendulum_spec(R"(, "shapes": [{"type": "sphere", "radius": -0.1}])")).find("/bodies/0/shapes/0/radius: expected a length > 0"), std::string::npos);
  EXPECT_NE(error_of(pendulum_spec(R"(, "shapes": [{"type": "box", "size": [1, 0, 1]}])")).find("/bodies/0/shapes/0/size"), std::string::npos);
  EXPECT_NE(error_of(pendulum_spec("", R"(, "solver": {"t_end": -5})")).find("/solver/t_end: expected an end time > 0"), std::string::npos);
  EXPECT_NE(error_of(pendulum_spec("", R"(, "solver": {"rtol": 2})")).find("/solver/rtol"), std::string::npos);
  // a denormal mass, and a 1e-300 inertia, beside a real body
  const std::string two = R"({"name": "p", "bodies": [{"name": "a", "mass": 1, "inertia": [1, 1, 1, 0, 0, 0]},
      {"name": "b", "mass": 1e-310, "inertia": [1, 1, 1, 0, 0, 0]}],
      "joints": [{"name": "j", "type": "revolute", "parent": "ground", "child": "a"},
                 {"name": "k", "type": "revolute", "parent": "a", "child": "b"}]})";
  EXPECT_NE(error_of(two).find("/bodies/1/mass: a mass of"), std::string::npos) << error_of(two);
  std::string tiny = two;
  tiny.replace(tiny.find("1e-310, \"inertia\": [1, 1, 1"), 29, "1, \"inertia\": [1e-300, 1e-300, 1e-300");
  EXPECT_NE(error_of(tiny).find("/bodies/1/inertia"), std::string::npos) << error_of(tiny);
  // the axis [0, 0, 1e308] that once loaded, saved and failed to load again is now refused at once
  EXPECT_NE(error_of(R"({"name": "p", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1, 0, 0, 0]}],
      "joints": [{"name": "j", "type": "revolute", "parent": "ground", "child": "b", "axis": [0, 0, 1e308]}]})")
                .find("/joints/0/axis/2"), std::string::npos);
}

// A direction that is not of unit length is used normalized, and the reader says so.
TEST(ModelFile, NonUnitAxisIsNormalizedWithANote) {
  const codyna::ModelSpec s = codyna::parse_model_spec_text(
      R"({"name": "p", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1, 0, 0, 0]}],
          "joints": [{"name": "j", "type": "revolute", "parent": "ground", "child": "b", "axis": [1, 0, 1]}]})", "m.json");
  EXPECT_NEAR(s.joints[0].axis.norm(), 1.0, 1e-15);
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("m.json: /joints/0/axis"), std::string::npos) << s.notes[0];
  EXPECT_NE(s.notes[0].find("length 1.41421"), std::string::npos) << s.notes[0];
  // unit axes say nothing, and notes are never written back
  const codyna::ModelSpec again = codyna::parse_model_spec(codyna::to_json(s), "again.json");
  EXPECT_TRUE(again.notes.empty());
  EXPECT_EQ(codyna::to_json(s).dump().find("notes"), std::string::npos);
}

// A number that overflows a double is reported with its field's path.
TEST(ModelFileErrors, OverflowingNumberNamesItsField) {
  const auto path_of = [](const std::string& text) -> std::string {
    try {
      codyna::parse_model_spec_text(text, "m.json");
    } catch (const codyna::ModelError& e) {
      return e.path() + ": " + e.detail();
    }
    return "";
  };
  EXPECT_EQ(path_of(R"({"name": "p", "bodies": [{"name": "b", "mass": 1e309}], "joints": []})").substr(0, 16), "/bodies/0/mass: ");
  EXPECT_EQ(path_of(R"({"name": "p", "bodies": [{"name": "b", "mass": 1, "com": [0, 1, )" + std::string(400, '9') +
                    "]}], \"joints\": []}").substr(0, 16), "/bodies/0/com/2:");
}

namespace codyna {
namespace {

// parse_model_element reads one element as parse_model_spec reads the whole file: on every
// example, each element of each array read again from its (edited) JSON into a copy of the
// file's spec gives the spec of the edited file read whole; a bad value names its field.
TEST(ModelFile, OneElementReadAgainEqualsTheWholeFileRead) {
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string path = entry.path().string();
    std::ifstream in(path);
    const nlohmann::json file = nlohmann::json::parse(in);
    const ModelSpec spec = parse_model_spec(file, path);
    for (const char* section : {"bodies", "joints", "constraints", "effects", "actuators", "sensors"}) {
      if (!file.contains(section)) continue;
      for (std::size_t i = 0; i < file[section].size(); ++i) {
        nlohmann::json edited = file;
        nlohmann::json& e = edited[section][i];
        if (e.contains("mass")) e["mass"] = e["mass"].get<double>() * 1.5;   // a number changed, when there is one
        if (e.contains("gain")) e["gain"] = e["gain"].get<double>() * 0.5;
        ModelSpec copy = spec;
        ASSERT_TRUE(parse_model_element(copy, section, i, e, path)) << path << " " << section << " " << i;
        EXPECT_EQ(to_json(copy), to_json(parse_model_spec(edited, path))) << path << " /" << section << "/" << i;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
  const std::string cart = std::string(CODYNA_EXAMPLES_DIR) + "/cart_pendulum.json";
  std::ifstream in(cart);
  const nlohmann::json file = nlohmann::json::parse(in);
  ModelSpec spec = parse_model_spec(file, cart);
  nlohmann::json rod = file["bodies"][1];
  rod["mass"] = "heavy";
  try {
    parse_model_element(spec, "bodies", 1, rod, cart);
    ADD_FAILURE() << "a mass of \"heavy\" was read";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/bodies/1/mass"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(cart), std::string::npos) << e.what();
  }
  EXPECT_EQ(spec.bodies[1].mass, 10.0) << "nothing changed by a refused element";
  EXPECT_FALSE(parse_model_element(spec, "solver", 0, rod, cart));
  EXPECT_FALSE(parse_model_element(spec, "bodies", 7, rod, cart));
}

// The kind of a fault, for a front end that acts on it without reading the message's words (the
// GUI's property editor drops the fields an element's old type had and fills a new type's
// required ones): an unknown field and a field of another tire law are UnknownField at the
// field's path; a missing required field is MissingField at the element's path, naming the field;
// a bad value is neither.
ModelError model_error_of(const std::string& text) {
  try {
    parse_model_spec_text(text, "kinds.json");
  } catch (const ModelError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for the model";
  return ModelError("", "", "");
}
std::string pendulum_with(const std::string& from, const std::string& to) {
  std::string s = kPendulum;
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(ModelFile, ErrorsSayTheirKind) {
  const ModelError unknown = model_error_of(pendulum_with(R"("mass": 2.0,)", R"("mass": 2.0, "colour": 1,)"));
  EXPECT_EQ(unknown.kind(), ModelError::Kind::UnknownField);
  EXPECT_EQ(unknown.path(), "/bodies/0/colour");
  const ModelError missing = model_error_of(pendulum_with(R"("child": "link",)", ""));
  EXPECT_EQ(missing.kind(), ModelError::Kind::MissingField);
  EXPECT_EQ(missing.path(), "/joints/0");
  EXPECT_EQ(missing.field(), "child");
  EXPECT_EQ(missing.detail(), "missing required field \"child\"");
  const ModelError law = model_error_of(pendulum_with(
      R"({"name": "gravity", "type": "gravity"})",
      R"({"name": "gravity", "type": "gravity"}, {"name": "tire", "type": "tire", "body": "link", "law": "linear",
          "unloaded_radius": 0.3, "vertical_stiffness": 2e5, "side": "left"})"));
  EXPECT_EQ(law.kind(), ModelError::Kind::UnknownField);
  EXPECT_EQ(law.path(), "/effects/1/side");
  const ModelError value = model_error_of(pendulum_with(R"("mass": 2.0,)", R"("mass": -2.0,)"));
  EXPECT_EQ(value.kind(), ModelError::Kind::Other);
  EXPECT_EQ(value.in_file("other.json").kind(), ModelError::Kind::Other);
  EXPECT_EQ(missing.in_file("other.json").field(), "child");
}

}  // namespace
}  // namespace codyna
