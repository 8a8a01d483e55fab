// The models the derivative and linearization benchmarks share: n > 0 a chain of n hinges about
// alternating axes with a motor on each, n = 0 the 28-DOF ball-joint tree (a root hinge, 9 ball
// joints in three branches, a motor per coordinate); random but fixed inertias (seed 7 + n).
#pragma once

#include <Eigen/Geometry>
#include <random>
#include <string>

#include "model/model_spec.hpp"

namespace codyna::bench {

inline Eigen::Matrix3d rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

inline ModelSpec bench_model(int n) {
  std::mt19937 rng(7 + n);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  ModelSpec s;
  s.name = n ? "chain" + std::to_string(n) : "ball_tree";
  const int nb = n ? n : 10;
  for (int i = 0; i < nb; ++i) {
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 0.5 + u(rng);
    b.com = Eigen::Vector3d(0.3 * u(rng), 0.1 * u(rng), 0.05 * u(rng));
    const Eigen::Matrix3d R = rotation(rng);
    const double a = 0.02 + 0.02 * u(rng), c = 0.02 + 0.02 * u(rng);
    b.inertia = R * Eigen::Vector3d(a, c, 0.5 * (a + c)).asDiagonal() * R.transpose();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.child = b.name;
    if (n) {
      j.type = JointType::Revolute;
      j.parent = i ? "b" + std::to_string(i - 1) : std::string(kGroundName);
      j.axis = i % 3 == 0 ? Eigen::Vector3d::UnitZ() : (i % 3 == 1 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX());
    } else {
      j.type = i == 0 ? JointType::Revolute : JointType::Spherical;
      j.parent = i == 0 ? std::string(kGroundName) : "b" + std::to_string(i <= 3 ? 0 : i - 3);
    }
    j.parent_frame.position = i ? Eigen::Vector3d(0.4, 0.05 * (i % 2), 0.0) : Eigen::Vector3d::Zero();
    s.joints.push_back(j);
    if (j.type == JointType::Revolute) {
      ActuatorSpec a;
      a.name = "m" + std::to_string(i);
      a.joint = j.name;
      s.actuators.push_back(a);
      s.plant.inputs.push_back(a.name);
    } else {
      for (int k = 0; k < 3; ++k) {
        ActuatorSpec a;
        a.name = "m" + std::to_string(i) + "_" + std::to_string(k);
        a.joint = j.name;
        a.dof = k;
        s.actuators.push_back(a);
        s.plant.inputs.push_back(a.name);
      }
    }
  }
  EffectSpec g;
  g.name = "gravity";
  g.type = EffectType::Gravity;
  s.effects.push_back(g);
  return s;
}

}  // namespace codyna::bench
