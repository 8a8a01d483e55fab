// IFToMM A02, N four-bars (docs/BENCHMARKS.md), as examples/iftomm_a02_four_bars.json
// has it for N = 4: cranks crank0..crankN pinned to ground at x = 0..N, couplers
// coupler1..couplerN pinned to the top of the previous crank and closed (planar
// revolute, 2 rows) on the top of the next one; slender 1 m, 1 kg links; B0 at 1 m/s in
// +x (every crank at -1 rad/s), cranks vertical, g = 9.81 in -y. Shared by the work-
// precision study (bench/work_precision.cpp) and the peer tests. Not an example file: the
// GUI tests pick every body of every example, and the 41 m chain is too long for their view.
// The exact motion is a rigid rotation phi(t) of every crank:
//   a phi'' = b g sin(phi), a = (N+1)/3 + N, b = (N+1)/2 + N, phi(0) = 0, phi'(0) = -1.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "model/model_spec.hpp"

namespace codyna::iftomm {

inline ModelSpec a02_spec(int N) {
  ModelSpec s;
  s.name = "iftomm_a02_" + std::to_string(N);
  auto rod = [](const std::string& name, const Eigen::Vector3d& com, int axial) {
    BodySpec b;
    b.name = name;
    b.mass = 1.0;
    b.com = com;
    Eigen::Vector3d I = Eigen::Vector3d::Constant(1.0 / 12);
    I[axial] = 5e-5;
    b.inertia = I.asDiagonal();
    return b;
  };
  for (int i = 0; i <= N; ++i) s.bodies.push_back(rod("crank" + std::to_string(i), Eigen::Vector3d(0, 0.5, 0), 1));
  for (int i = 1; i <= N; ++i) s.bodies.push_back(rod("coupler" + std::to_string(i), Eigen::Vector3d(0.5, 0, 0), 0));
  for (int i = 0; i <= N; ++i) {
    JointSpec j;
    j.name = "pivot" + std::to_string(i);
    j.parent = "ground";
    j.child = "crank" + std::to_string(i);
    j.parent_frame.position = Eigen::Vector3d(i, 0, 0);
    j.q0 = Eigen::VectorXd::Constant(1, 0.0);
    j.v0 = Eigen::VectorXd::Constant(1, -1.0);
    s.joints.push_back(j);
  }
  for (int i = 1; i <= N; ++i) {
    JointSpec j;
    j.name = "pin" + std::to_string(i);
    j.parent = "crank" + std::to_string(i - 1);
    j.child = "coupler" + std::to_string(i);
    j.parent_frame.position = Eigen::Vector3d(0, 1, 0);
    j.q0 = Eigen::VectorXd::Constant(1, 0.0);
    j.v0 = Eigen::VectorXd::Constant(1, 1.0);
    s.joints.push_back(j);
    ConstraintSpec c;
    c.name = "close" + std::to_string(i);
    c.type = ConstraintType::PlanarRevolute;
    c.body_a = "coupler" + std::to_string(i);
    c.point_a = Eigen::Vector3d(1, 0, 0);
    c.body_b = "crank" + std::to_string(i);
    c.point_b = Eigen::Vector3d(0, 1, 0);
    c.axis_a = Eigen::Vector3d::UnitZ();
    s.constraints.push_back(c);
  }
  EffectSpec e;
  e.name = "gravity";
  e.type = EffectType::Gravity;
  e.g = Eigen::Vector3d(0, -9.81, 0);
  s.effects.push_back(e);
  return s;
}

// phi(t) of the exact 1-DOF reduction at the given (increasing) times, by RK4 at steps of
// at most h (1e-4 s: error below 1e-12 rad over 20 s, checked against h / 2)
inline Eigen::VectorXd a02_exact(int N, const std::vector<double>& times, double h = 1e-4) {
  const double a = (N + 1) / 3.0 + N, b = (N + 1) / 2.0 + N, g = 9.81;
  auto rhs = [&](const Eigen::Vector2d& y) { return Eigen::Vector2d(y[1], b * g * std::sin(y[0]) / a); };
  Eigen::Vector2d y(0.0, -1.0);
  double t = 0;
  Eigen::VectorXd phi(times.size());
  for (size_t i = 0; i < times.size(); ++i) {
    while (t < times[i] - 1e-12) {
      const double s = std::min(h, times[i] - t);
      const Eigen::Vector2d k1 = rhs(y), k2 = rhs(y + s / 2 * k1), k3 = rhs(y + s / 2 * k2), k4 = rhs(y + s * k3);
      y += s / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += s;
    }
    phi[i] = y[0];
  }
  return phi;
}

}  // namespace codyna::iftomm
