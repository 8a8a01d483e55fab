// Test helpers: matrix comparison, example loading, random models.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <string>

#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"

// EXPECT_INVALID_ARGUMENT_WITH(statement, "part", ...): the statement throws
// std::invalid_argument and its message contains every part
#define EXPECT_INVALID_ARGUMENT_WITH(statement, ...)                                    \
  do {                                                                                  \
    try {                                                                               \
      statement;                                                                        \
      ADD_FAILURE() << "no exception from " #statement;                                 \
    } catch (const std::invalid_argument& e) {                                          \
      for (const std::string& part : std::vector<std::string>{__VA_ARGS__})             \
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)                  \
            << "message \"" << e.what() << "\" lacks \"" << part << "\"";               \
    }                                                                                   \
  } while (0)

namespace codyna::test {

// |a - b| <= tol * max(1, |b|) entrywise-norm, with a readable failure message
inline ::testing::AssertionResult MatrixNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tol) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    return ::testing::AssertionFailure() << "size " << a.rows() << "x" << a.cols() << " vs " << b.rows() << "x" << b.cols();
  const double err = (a - b).cwiseAbs().maxCoeff();
  const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
  if (a.size() == 0 || err <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max |a - b| = " << err << " > " << tol << " * " << scale << "\na =\n"
                                       << a << "\nb =\n" << b;
}

inline std::string example_path(const std::string& name) { return std::string(CODYNA_EXAMPLES_DIR) + "/" + name; }

inline Model load_example(const std::string& name) {
  const std::string path = example_path(name);
  return compile(load_model_spec(path), path);
}

// A rotation from three uniform numbers
inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

inline Eigen::Vector3d random_vec(std::mt19937& rng, double s = 1.0) {
  std::uniform_real_distribution<double> u(-s, s);
  return {u(rng), u(rng), u(rng)};
}

// A branched 3-D tree of n bodies whose joints cycle through every joint type
// (ball and free among them), with random frames, masses and inertias; gravity on.
inline ModelSpec random_tree_spec(unsigned seed, int n = 10, bool gravity = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const JointType types[] = {JointType::Free, JointType::Revolute, JointType::Spherical, JointType::Prismatic,
                             JointType::Universal, JointType::Cylindrical, JointType::Planar, JointType::Fixed,
                             JointType::Revolute, JointType::Spherical};
  ModelSpec s;
  s.name = "random_tree_" + std::to_string(seed);
  for (int i = 0; i < n; ++i) {
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 0.5 + 2.0 * u01(rng);
    b.com = random_vec(rng, 0.3);
    // principal moments that satisfy the triangle inequality, in random axes
    const double a = 0.05 + 0.1 * u01(rng), c = 0.05 + 0.1 * u01(rng);
    const double bb = std::abs(a - c) + 0.01 + 0.05 * u01(rng);
    const Eigen::Matrix3d R = random_rotation(rng);
    b.inertia = R * Eigen::Vector3d(a, bb, c).asDiagonal() * R.transpose();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.type = types[i % 10];
    j.parent = i == 0 ? std::string(kGroundName) : "b" + std::to_string(static_cast<int>(u01(rng) * i));
    j.child = b.name;
    j.parent_frame.position = random_vec(rng, 0.5);
    j.parent_frame.rotation = random_rotation(rng);
    j.child_frame.position = random_vec(rng, 0.2);
    j.child_frame.rotation = random_rotation(rng);
    j.axis = random_vec(rng).normalized();
    j.axis2 = j.axis.cross(random_vec(rng)).normalized();
    s.joints.push_back(j);
  }
  if (gravity) {
    EffectSpec g;
    g.name = "gravity";
    g.type = EffectType::Gravity;
    g.g = Eigen::Vector3d(0.3, -9.81, 0.5);
    s.effects.push_back(g);
  }
  return s;
}

// a random configuration (unit quaternions), velocity or acceleration
inline Eigen::VectorXd random_q(const Model& m, std::mt19937& rng);
inline Eigen::VectorXd random_v(const Model& m, std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(m.nv);
  for (int i = 0; i < m.nv; ++i) v[i] = u(rng);
  return v;
}

// a random 3-D tree with ball and free joints, inputs and outputs of every kind
inline ModelSpec random_plant(unsigned seed) {
  ModelSpec s = test::random_tree_spec(seed, 10);
  ActuatorSpec a;
  a.name = "tau1";
  a.type = ActuatorType::JointForce;
  a.joint = "j1";
  s.actuators.push_back(a);
  a.name = "push";
  a.type = ActuatorType::BodyForce;
  a.body = "b4";
  a.point = Eigen::Vector3d(0.1, 0.2, 0.3);
  a.direction = Eigen::Vector3d(1, 2, 3);
  a.in_world = false;
  s.actuators.push_back(a);
  a.name = "twist";
  a.type = ActuatorType::BodyTorque;
  a.body = "b6";
  a.direction = Eigen::Vector3d(0.3, -1, 0.5);
  a.in_world = false;
  s.actuators.push_back(a);
  SensorSpec y;
  y.name = "p5";
  y.type = SensorType::PointPosition;
  y.body = "b5";
  y.point = Eigen::Vector3d(0.3, 0, 0);
  y.component = 2;
  y.frame = "b1";
  s.sensors.push_back(y);
  y.name = "v6";
  y.type = SensorType::PointVelocity;
  y.body = "b6";
  y.component = 0;
  y.frame = kGroundName;
  s.sensors.push_back(y);
  y.name = "ang2";
  y.type = SensorType::BodyAngle;
  y.body = "b2";
  y.axis = Eigen::Vector3d(0, 0, 1);
  s.sensors.push_back(y);
  y.name = "dist";
  y.type = SensorType::Distance;
  y.body_a = "b3";
  y.body_b = "b8";
  y.point_b = Eigen::Vector3d(0.1, 0.1, 0.1);
  s.sensors.push_back(y);
  y.name = "w1";
  y.type = SensorType::JointVelocity;
  y.joint = "j1";
  s.sensors.push_back(y);
  s.plant.inputs = {"tau1", "push", "twist"};
  s.plant.outputs = {"p5", "v6", "ang2", "dist", "w1"};
  EffectSpec e;
  e.name = "spring";
  e.type = EffectType::SpringDamper;
  e.body_a = "b3";
  e.body_b = "b7";
  e.stiffness = 50;
  e.damping = 2;
  e.rest_length = 0.1;
  s.effects.push_back(e);
  e.name = "fric";
  e.type = EffectType::JointFriction;
  e.joint = "j4";  // universal: two coordinates
  e.dof = 1;
  e.damping = 0.3;
  s.effects.push_back(e);
  e.name = "ball_damper";
  e.type = EffectType::JointDamper;
  e.joint = "j2";  // spherical
  e.damping = 0.2;
  s.effects.push_back(e);
  return s;
}

}  // namespace codyna::test

#include "dynamics/joint.hpp"

namespace codyna::test {
inline Eigen::VectorXd random_q(const Model& m, std::mt19937& rng) {
  return integrate<double>(m, neutral(m), random_v(m, rng, 1.5));
}
}  // namespace codyna::test
