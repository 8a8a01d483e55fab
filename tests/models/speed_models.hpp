// The mechanisms of the MuJoCo speed benchmark (bench/mujoco_speed_bench.cpp),
// shared with the tests that use them (tests/alloc): 3-D hinge chains with
// tilted frames, off-axis coms and full inertias, one motor per joint, and a
// 28-DOF humanoid-like tree of ball joints and hinges.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <string>

#include "model/model_spec.hpp"

namespace codyna::speed_models {

inline Eigen::Matrix3d rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

inline Eigen::Vector3d uvec(std::mt19937& rng, double s) {
  std::uniform_real_distribution<double> u(-s, s);
  return {u(rng), u(rng), u(rng)};
}

// a body with an off-axis com and a full inertia tensor (principal moments
// that satisfy the triangle inequality, in tilted axes)
inline BodySpec body(const std::string& name, std::mt19937& rng, double mass, const Eigen::Vector3d& com, double size) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  BodySpec b;
  b.name = name;
  b.mass = mass;
  b.com = com;
  const double a = size * (0.5 + u01(rng)), c = size * (0.5 + u01(rng));
  const double bb = std::abs(a - c) + size * (0.1 + 0.5 * u01(rng));
  const Eigen::Matrix3d R = rot(3.0 * u01(rng), uvec(rng, 1.0) + Eigen::Vector3d(0.1, 0.1, 0.1));
  b.inertia = R * Eigen::Vector3d(a, bb, c).asDiagonal() * R.transpose();
  return b;
}

inline JointSpec joint(const std::string& name, JointType type, const std::string& parent, const std::string& child,
                const Eigen::Vector3d& p_parent, const Eigen::Matrix3d& R_parent, const Eigen::Vector3d& p_child,
                const Eigen::Matrix3d& R_child, const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.parent_frame.position = p_parent;
  j.parent_frame.rotation = R_parent;
  j.child_frame.position = p_child;
  j.child_frame.rotation = R_child;
  j.axis = axis.normalized();
  return j;
}

// one joint motor per coordinate of every joint, all of them plant inputs
inline void add_motors(ModelSpec& s) {
  for (const JointSpec& j : s.joints) {
    const int nv = j.type == JointType::Spherical ? 3 : 1;
    for (int k = 0; k < nv; ++k) {
      ActuatorSpec a;
      a.name = "motor_" + j.name + (nv > 1 ? "_" + std::to_string(k) : "");
      a.type = ActuatorType::JointForce;
      a.joint = j.name;
      a.dof = k;
      a.gain = 1.0 + 0.1 * (s.actuators.size() % 7);
      s.actuators.push_back(a);
      s.plant.inputs.push_back(a.name);
    }
  }
}

inline void add_gravity(ModelSpec& s) {
  EffectSpec g;
  g.name = "gravity";
  g.type = EffectType::Gravity;
  g.g = Eigen::Vector3d(0.3, -9.81, 0.5);
  s.effects.push_back(g);
}

inline ModelSpec chain(int n) {
  std::mt19937 rng(1000 + n);
  const Eigen::Vector3d axes[] = {{0.2, 0.1, 1.0}, {1.0, -0.3, 0.4}, {-0.2, 1.0, 0.3}, {0.6, 0.5, 0.7}};
  ModelSpec s;
  s.name = "chain_" + std::to_string(n);
  for (int i = 0; i < n; ++i) {
    const std::string b = "link" + std::to_string(i);
    s.bodies.push_back(body(b, rng, 0.6 + 0.1 * (i % 5), Eigen::Vector3d(0.03, -0.2, 0.02) + uvec(rng, 0.03), 0.02));
    const std::string parent = i == 0 ? std::string(kGroundName) : "link" + std::to_string(i - 1);
    const Eigen::Vector3d pp = i == 0 ? Eigen::Vector3d(0.1, 0.2, -0.05) : Eigen::Vector3d(0.0, -0.4, 0.0) + uvec(rng, 0.04);
    s.joints.push_back(joint("j" + std::to_string(i), JointType::Revolute, parent, b, pp,
                             rot(0.5, uvec(rng, 1.0) + Eigen::Vector3d(0.2, 0.2, 0.2)), uvec(rng, 0.02),
                             rot(0.3, uvec(rng, 1.0) + Eigen::Vector3d(0.1, 0.3, 0.1)), axes[i % 4]));
  }
  add_gravity(s);
  add_motors(s);
  return s;
}

// 16 bodies, 28 DOF: pelvis (ball to ground), torso (ball), head (hinge), jaw
// (hinge); arms: shoulder ball, elbow hinge, wrist hinge; legs: hip ball,
// knee hinge, ankle hinge
inline ModelSpec tree28() {
  std::mt19937 rng(28);
  ModelSpec s;
  s.name = "tree28";
  auto add = [&](const std::string& b, const std::string& parent, JointType type, const Eigen::Vector3d& at,
                 double mass, const Eigen::Vector3d& com, const Eigen::Vector3d& axis) {
    s.bodies.push_back(body(b, rng, mass, com + uvec(rng, 0.02), 0.02 * mass));
    s.joints.push_back(joint("j_" + b, type, parent, b, at + uvec(rng, 0.02), rot(0.4, uvec(rng, 1.0) + Eigen::Vector3d(0.3, 0.1, 0.2)),
                             uvec(rng, 0.02), rot(0.3, uvec(rng, 1.0) + Eigen::Vector3d(0.1, 0.2, 0.3)), axis));
  };
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(), z = Eigen::Vector3d::UnitZ();
  add("pelvis", kGroundName, JointType::Spherical, {0, 1.0, 0}, 8.0, {0, 0.05, 0}, z);
  add("torso", "pelvis", JointType::Spherical, {0, 0.15, 0}, 15.0, {0, 0.25, 0}, z);
  add("head", "torso", JointType::Revolute, {0, 0.5, 0}, 4.0, {0, 0.1, 0.02}, x + 0.3 * z);
  add("jaw", "head", JointType::Revolute, {0, 0.02, 0.08}, 0.3, {0, -0.03, 0.04}, x);
  for (int side = -1; side <= 1; side += 2) {
    const std::string sd = side < 0 ? "_l" : "_r";
    add("upper_arm" + sd, "torso", JointType::Spherical, {0.2 * side, 0.45, 0}, 2.0, {0, -0.15, 0}, z);
    add("forearm" + sd, "upper_arm" + sd, JointType::Revolute, {0, -0.3, 0}, 1.2, {0, -0.13, 0.01}, x + 0.2 * z);
    add("hand" + sd, "forearm" + sd, JointType::Revolute, {0, -0.27, 0}, 0.4, {0, -0.05, 0}, z + 0.1 * y);
    add("thigh" + sd, "pelvis", JointType::Spherical, {0.1 * side, -0.05, 0}, 7.0, {0, -0.2, 0}, z);
    add("shin" + sd, "thigh" + sd, JointType::Revolute, {0, -0.42, 0}, 3.5, {0, -0.2, 0.01}, x - 0.1 * y);
    add("foot" + sd, "shin" + sd, JointType::Revolute, {0, -0.42, 0}, 1.0, {0, -0.03, 0.06}, x + 0.15 * z);
  }
  add_gravity(s);
  add_motors(s);
  return s;
}

}  // namespace codyna::speed_models
