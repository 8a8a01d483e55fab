// A model description in plain C++17 types, between codyna's ModelSpec (C++20 headers) and
// the Simbody translation unit (bench/simbody_sim.cpp: Simbody 3.7's headers do not build as
// C++20). Frames: position p and row-major rotation R, as codyna's FrameSpec.
#pragma once

#include <string>
#include <vector>

#include "simbody_peer.hpp"

namespace codyna::peer {

struct PFrame {
  double p[3] = {0, 0, 0};
  double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
};
struct PBody {
  std::string name;
  double mass = 0, com[3] = {0, 0, 0}, I[9] = {0};  // inertia about the com, body axes, row-major
};
enum class PJointType { Revolute, Prismatic, Spherical };
struct PJoint {
  std::string name, parent, child;
  PJointType type = PJointType::Revolute;
  PFrame parent_frame, child_frame;
  double axis[3] = {0, 0, 1};
  std::vector<double> q0, v0;
};
enum class PConstraintType { Ball, Revolute, PlanarRevolute };
struct PConstraint {
  PConstraintType type = PConstraintType::Ball;
  std::string body_a, body_b;
  double point_a[3] = {0, 0, 0}, point_b[3] = {0, 0, 0}, axis_a[3] = {0, 0, 1}, axis_b[3] = {0, 0, 1};
};
enum class PEffectType { Gravity, SpringDamper };
struct PEffect {
  PEffectType type = PEffectType::Gravity;
  double g[3] = {0, 0, 0};
  std::string body_a, body_b;
  double point_a[3] = {0, 0, 0}, point_b[3] = {0, 0, 0};
  double stiffness = 0, damping = 0, rest_length = 0;
};
struct PJointForce {  // a constant generalized force (an actuator held at its nominal value)
  std::string joint;
  int dof = 0;
  double value = 0;
};
struct PlainModel {
  std::vector<PBody> bodies;
  std::vector<PJoint> joints;
  std::vector<PConstraint> constraints;
  std::vector<PEffect> effects;
  std::vector<PJointForce> joint_forces;
};

PeerRun run_plain(const PlainModel& model, const std::string& problem, const std::string& integrator, double tol,
                  double t_end, double output_step, int repeats, int a02_n);

}  // namespace codyna::peer
