// Rolling without slip on a plane (issue 19): a rolling_ball constraint holds a ball's centre at
// its radius over a plane (one condition on the coordinates) and its contact point at rest on the
// plane (two on the velocities only: non-holonomic). Checked against closed forms derived by hand:
//   the ball and plate (examples/ball_plate.json): each axis is the ball and beam,
//     X/alpha_y = (m g - (J/R) s^2) / ((m + J/R^2) s^2), Y/alpha_x = -X/alpha_y's;
//   a ball released on a plate held at a tilt b: X(t) = X0 + m g sin(b) t^2 / (2 (m + J/R^2));
//   a ball on a turntable spun up at t = 0 to W: the impulse gives the centre kappa W z x r0, and
//     then its velocity turns at kappa W (kappa = J / (J + m R^2) = 2/7 for a solid ball);
//   a ball rolling on a fixed incline keeps its energy;
// the no-slip rows' acceleration term against the central difference of Jc v along a motion, and
// the plant's Jacobian (automatic differentiation) against central differences.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/joint.hpp"
#include "model/errors.hpp"
#include "spatial/autodiff.hpp"
#include "spatial/linalg.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "jacobian_check.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using cd = std::complex<double>;

constexpr double m = 0.111, R = 0.015, J = 9.99e-6, g_ball = 9.8;
constexpr double mass_eff = m + J / (R * R);

ModelSpec plate() { return study_read_model(test::example_path("ball_plate.json")); }

int rolling_column(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<int>(it - names.begin());
}

TEST(Rolling, TheBallOnAPlateHasFiveCoordinatesAndThreeRates) {
  const Model mod = study_model(plate());
  EXPECT_EQ(mod.nc, 3);
  EXPECT_EQ(mod.velocity_rows, (std::vector<int>{1, 2}));
  EXPECT_EQ(mod.active_rows.size(), 3u);
  EXPECT_EQ(mod.active_velocity_rows, 2);
  EXPECT_EQ(mod.dof(), 5);  // the free joint's 6 less the height
  EXPECT_EQ(mod.rate_dof(), 3);
  const CoordinatePartition p = partition_coordinates(mod, mod.q0);
  EXPECT_EQ(p.independent.size(), 5u);
  EXPECT_EQ(p.dependent.size(), 1u);
  EXPECT_EQ(p.rate_dependent.size(), 2u);
  EXPECT_EQ(p.rates().size(), 3u);
  const LinearSystem s = study_linearize(mod).system;
  ASSERT_EQ(s.nx(), 8);
  EXPECT_EQ(s.positions, 5);
  ASSERT_EQ(s.state_names.size(), 8u);
  // the position states are coordinates, the velocity states rates
  for (int k = 0; k < 5; ++k) EXPECT_EQ(s.state_units[k].find("/s"), std::string::npos) << s.state_names[k];
  for (int k = 5; k < 8; ++k) EXPECT_NE(s.state_units[k].find("/s"), std::string::npos) << s.state_names[k];
}

// about the ball at rest on the level plate: X/alpha_y = (m g - (J/R) s^2) / ((m + J/R^2) s^2),
// Y/alpha_x its negative; no cross-coupling
TEST(Rolling, EachAxisOfTheBallAndPlateIsTheBallAndBeam) {
  const Model mod = study_model(plate());
  const LinearSystem s = study_linearize(mod).system;
  ASSERT_EQ(s.nu(), 2);
  ASSERT_EQ(s.ny(), 2);
  ASSERT_EQ(s.input_names, (std::vector<std::string>{"alpha_x", "alpha_y"}));
  ASSERT_EQ(s.output_names, (std::vector<std::string>{"X", "Y"}));
  const int n = s.nx();
  double worst = 0, cross = 0;
  for (double w : {0.05, 0.3, 1.0, 2.5, 7.0, 15.0, 40.0, 120.0, 600.0, 3000.0}) {
    const cd z(0, w);
    const Eigen::MatrixXcd M = z * Eigen::MatrixXcd::Identity(n, n) - s.A.cast<cd>();
    const Eigen::MatrixXcd G = s.C.cast<cd>() * M.partialPivLu().solve(s.B.cast<cd>()) + s.D.cast<cd>();
    const cd xy = (m * g_ball - (J / R) * z * z) / (mass_eff * z * z);
    worst = std::max({worst, std::abs(G(0, 1) - xy) / std::abs(xy), std::abs(G(1, 0) + xy) / std::abs(xy)});
    cross = std::max({cross, std::abs(G(0, 0)), std::abs(G(1, 1))});
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(cross, 1e-12);
  // the feedthrough the motion input keeps: -(J/R) / (m + J/R^2) on X from alpha_y
  EXPECT_NEAR(s.D(0, 1), -(J / R) / mass_eff, 1e-13);
}

// a run of the ball and plate with the plate held at alpha_y = b, the ball released at rest at
// (X0, Y0) on it: X(t) = X0 + m g sin(b) t^2 / (2 (m + J/R^2)), Y stays
TEST(Rolling, ABallReleasedOnATiltedPlateFollowsTheClosedForm) {
  ModelSpec spec = plate();
  const double b = 0.05, X0 = 0.3, Y0 = 0.1;
  spec.joints.at(1).q0 = Eigen::VectorXd::Constant(1, b);
  JointSpec& ball = spec.joints.at(2);
  ball.q0 = (Eigen::VectorXd(7) << X0 * std::cos(b), Y0, -X0 * std::sin(b), 1, 0, 0, 0).finished();
  spec.analysis.controller = "none";
  spec.solver.t_end = 1.0;
  spec.solver.output_step = 0.01;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  const Model mod = study_model(spec);
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const int ix = rolling_column(r.output_names, "X"), iy = rolling_column(r.output_names, "Y");
  double worst_x = 0, worst_y = 0, worst_phi = 0, worst_slip = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[static_cast<std::size_t>(i)];
    worst_x = std::max(worst_x, std::abs(r.y(i, ix) - (X0 + m * g_ball * std::sin(b) * t * t / (2 * mass_eff))));
    worst_y = std::max(worst_y, std::abs(r.y(i, iy) - Y0));
    worst_phi = std::max(worst_phi, r.constraint_violation[static_cast<std::size_t>(i)]);
    worst_slip = std::max(worst_slip, r.velocity_violation[static_cast<std::size_t>(i)]);
  }
  EXPECT_GT(r.y(r.samples() - 1, ix) - X0, 0.1);  // it rolled: the test can fail
  EXPECT_LT(worst_x, 1e-8);
  EXPECT_LT(worst_y, 1e-10);
  EXPECT_LT(worst_phi, 1e-10);
  EXPECT_LT(worst_slip, 1e-9);
}

// a turntable turned by a motion input at W from t = 0 under a ball rolling at v0 along y
ModelSpec turntable(double W) {
  const std::string text = R"({
  "codyna_model": 1, "name": "turntable",
  "bodies": [
    {"name": "table", "mass": 2.0, "com": [0, 0, -0.02], "inertia": [0.05, 0.05, 0.1]},
    {"name": "ball", "mass": 0.111, "com": [0, 0, 0], "inertia": [9.99e-6, 9.99e-6, 9.99e-6]}
  ],
  "joints": [
    {"name": "spin", "type": "revolute", "parent": "ground", "child": "table", "axis": [0, 0, 1]},
    {"name": "ball", "type": "free", "parent": "ground", "child": "ball",
     "q0": {"position": [0.1, 0, 0.015]}, "v0": [-13.333333333333334, 0, 0, 0, 0.2, 0]}
  ],
  "constraints": [
    {"name": "contact", "type": "rolling_ball", "body_a": "table", "axis_a": [0, 0, 1], "body_b": "ball", "radius": 0.015}
  ],
  "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.8]}],
  "actuators": [{"name": "drive", "type": "motion", "joint": "spin"}],
  "sensors": [
    {"name": "px", "type": "point_position", "body": "ball", "component": 0},
    {"name": "py", "type": "point_position", "body": "ball", "component": 1},
    {"name": "vx", "type": "point_velocity", "body": "ball", "component": 0},
    {"name": "vy", "type": "point_velocity", "body": "ball", "component": 1}
  ],
  "plant": {"inputs": [], "outputs": ["px", "py", "vx", "vy"]},
  "analysis": {"operating_point": "initial", "controller": "none",
               "disturbances": [{"actuator": "drive", "type": "ramp", "time": 0.0, "slope": )" +
                           std::to_string(W) + R"(}]},
  "solver": {"rtol": 1e-11, "atol": 1e-13, "t_end": 1.5, "output_step": 0.01}
})";
  return study_parse_model_text(text, "turntable");
}

TEST(Rolling, ABallOnATurntableCirclesAtTwoSeventhsOfItsRate) {
  const double W = 2.0, kappa = J / (J + m * R * R);
  ASSERT_NEAR(kappa, 2.0 / 7.0, 1e-12);  // a solid ball
  const Model mod = study_model(turntable(W));
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const int ipx = rolling_column(r.output_names, "px"), ipy = rolling_column(r.output_names, "py");
  const int ivx = rolling_column(r.output_names, "vx"), ivy = rolling_column(r.output_names, "vy");
  // the spin-up's impulse: the centre gains kappa W z x r0 = (0, kappa W 0.1)
  const Eigen::Vector2d r0(r.y(0, ipx), r.y(0, ipy)), v0(r.y(0, ivx), r.y(0, ivy));
  EXPECT_NEAR(r0.x(), 0.1, 1e-12);
  EXPECT_NEAR(r0.y(), 0.0, 1e-12);
  EXPECT_NEAR(v0.x(), 0.0, 1e-10);
  EXPECT_NEAR(v0.y(), 0.2 + kappa * W * 0.1, 1e-10);
  // then v(t) = Rot(kappa W t) v0, r(t) = r0 + Rot(kappa W t) b - b, b = -z x v0 / (kappa W)
  const double wc = kappa * W;
  const Eigen::Vector2d bvec = Eigen::Vector2d(v0.y(), -v0.x()) / wc;
  double worst_r = 0, worst_v = 0, worst_slip = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double th = wc * r.t[static_cast<std::size_t>(i)];
    const Eigen::Rotation2Dd rot(th);
    const Eigen::Vector2d pos = r0 + rot * bvec - bvec, vel = rot * v0;
    worst_r = std::max(worst_r, (Eigen::Vector2d(r.y(i, ipx), r.y(i, ipy)) - pos).norm());
    worst_v = std::max(worst_v, (Eigen::Vector2d(r.y(i, ivx), r.y(i, ivy)) - vel).norm());
    worst_slip = std::max(worst_slip, r.velocity_violation[static_cast<std::size_t>(i)]);
  }
  // over 1.5 s the velocity turns by 0.86 rad: far from the table's co-rotation (W t = 3 rad)
  EXPECT_GT(wc * r.t.back(), 0.8);
  EXPECT_LT(worst_r, 1e-8);
  EXPECT_LT(worst_v, 1e-8);
  EXPECT_LT(worst_slip, 1e-9);
}

// the turntable's ball on a fixed plane through the origin with this normal (the ground's)
ModelSpec incline(const Eigen::Vector3d& normal) {
  ModelSpec spec = turntable(0.0);
  spec.actuators.clear();
  spec.analysis.disturbances.clear();
  spec.joints.erase(spec.joints.begin());
  spec.bodies.erase(spec.bodies.begin());
  spec.constraints.at(0).body_a = "ground";
  spec.constraints.at(0).axis_a = normal.normalized();
  return spec;
}

// a ball rolling and spinning on a fixed incline (the plane on the ground): no work is done by the
// contact, so the energy is constant
TEST(Rolling, ABallRollingOnAFixedInclineKeepsItsEnergy) {
  ModelSpec spec = incline(Eigen::Vector3d(0.3, 0, 1));
  const ConstraintSpec& c = spec.constraints.at(0);
  // on the plane, rolling along y and spinning about the normal: v = w x (R n)
  const Eigen::Vector3d n = c.axis_a, w(-5.0, 2.0, 3.0);
  const Eigen::Vector3d v = w.cross(R * n);
  JointSpec& ball = spec.joints.at(0);
  const Eigen::Vector3d p = R * n;
  ball.q0 = (Eigen::VectorXd(7) << p.x(), p.y(), p.z(), 1, 0, 0, 0).finished();
  ball.v0 = (Eigen::VectorXd(6) << w.x(), w.y(), w.z(), v.x(), v.y(), v.z()).finished();
  spec.solver.t_end = 0.5;  // (a quarter of a metre down the slope: 0.08 J of potential energy)
  const Model mod = study_model(spec);
  EXPECT_LT(mod.assembly_residual, 1e-12);
  EXPECT_TRUE(mod.assembly_moves.empty());
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  double drift = 0;
  for (int i = 0; i < r.samples(); ++i)
    drift = std::max(drift, std::abs(r.kinetic_energy[static_cast<std::size_t>(i)] +
                                     r.potential_energy[static_cast<std::size_t>(i)] - E0));
  EXPECT_GT(std::abs(r.potential_energy.back() - r.potential_energy[0]), 0.05);  // it rolled down
  EXPECT_LT(drift, 1e-8 * std::abs(r.potential_energy.back() - r.potential_energy[0]));
}

// d/dt (Jc(q) v) = Jc qdd + gamma along a motion (q, v, a): central differences in time of Jc v
TEST(Rolling, TheNoSlipRowsAccelerationTermIsTheTimeDerivativeOfTheirVelocity) {
  const Model mod = study_model(plate());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Data d(mod);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q = mod.q0, v(mod.nv), a(mod.nv);
    for (int i = 0; i < mod.nv; ++i) v[i] = U(rng), a[i] = U(rng);
    q = integrate<double>(mod, q, Eigen::VectorXd(0.3 * Eigen::VectorXd::NullaryExpr(mod.nv, [&] { return U(rng); })));
    constraint_terms<double>(mod, d, q, v);
    const Eigen::VectorXd expected = d.Jc * a + d.gamma;
    const double h = 1e-4;
    auto Jv = [&](double t) {
      // q(t) = q (+) (t v + t^2/2 a), v(t) = v + t a  (tangent steps: exact to second order)
      const Eigen::VectorXd qt = integrate<double>(mod, q, Eigen::VectorXd(t * v + 0.5 * t * t * a));
      const Eigen::VectorXd vt = v + t * a;
      constraint_terms<double>(mod, d, qt, vt);
      return Eigen::VectorXd(d.Jc * vt);
    };
    const Eigen::VectorXd fd = (Jv(h) - Jv(-h)) / (2 * h);
    for (int row : {1, 2})
      EXPECT_NEAR(fd[row], expected[row], 1e-6 * std::max(1.0, std::abs(expected[row]))) << trial << " row " << row;
    EXPECT_NEAR(fd[0], expected[0], 1e-6 * std::max(1.0, std::abs(expected[0]))) << trial;
  }
}

// the plant's Jacobian (automatic differentiation through the rolling rows) against central
// differences of the plant function, away from the operating point and in motion (the ball's
// rotation away from the reference: the dependent height's Newton step needs d phi / d(dq) there,
// not Jc, for its derivative to be exact)
TEST(Rolling, ThePlantJacobianAgreesWithCentralDifferences) {
  const Model mod = study_model(plate());
  const CoordinatePartition p = partition_coordinates(mod, mod.q0);
  const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
  ASSERT_EQ(f.nx(), 8);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd x(f.nx()), u(f.nu() + 2 * f.nm());
    for (int i = 0; i < x.size(); ++i) x[i] = (i < f.nz() ? 0.05 : 1.0) * U(rng);
    for (int i = 0; i < u.size(); ++i) u[i] = (i < f.nu() ? 0.05 : 1.0) * U(rng);
    EXPECT_GT(test::expect_exact_equals_central_differences(f, x, u, std::to_string(trial), 1e-9), 1.0);
  }
}

// the analytic Jacobian (TreeDerivatives through the rolling rows: their accelerations' and
// reactions' derivatives, the velocity map with the no-slip rows) against automatic
// differentiation at the operating point's positions, with random rates, motion rates and
// accelerations: the ball and plate (a tilted, moving plane), the turntable (a motion outside
// Plant/In) and a free ball on a fixed incline (the plane on the ground)
TEST(Rolling, TheAnalyticJacobianEqualsAutomaticDifferentiation) {
  int checked = 0;
  for (const ModelSpec& spec : {plate(), turntable(2.0), incline(Eigen::Vector3d(0.3, 0.2, 1))}) {
    const Model mod = study_model(spec);
    const CoordinatePartition p = partition_coordinates(mod, mod.q0);
    const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), u(f.nu() + 2 * f.nm());
      for (int i = f.nz(); i < f.nx(); ++i) x[i] = 2.0 * U(rng);
      for (int i = 0; i < f.nu(); ++i) u[i] = mod.u_nominal()[mod.plant_inputs[static_cast<std::size_t>(i)]];
      for (int i = f.nu(); i < u.size(); ++i) u[i] = U(rng);
      test::expect_analytic_equals_autodiff(f, x, u, spec.name + " trial " + std::to_string(trial));
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

// A ball on the floor pushed at its centre by two horizontal forces: (m + J/R^2) x'' = F on each
// axis, exactly, whatever the ball's orientation. A PD on the measured X, Y (their rates through
// the plant's C and A_zw: 5 coordinates, 3 rates) brings it back to the origin, and the nonlinear
// closed loop equals the linear one to the integrator's tolerance. (An LQR on the full state would
// not: the linearization conserves X - R ry and Y + R rx, the ball's position tied to its
// orientation, as linearizations of rolling do; docs/model-format.md.)
TEST(Rolling, APdOnAPushedBallMatchesItsLinearClosedLoop) {
  const std::string text = R"({
  "codyna_model": 1, "name": "pushed_ball",
  "bodies": [{"name": "ball", "mass": 0.111, "com": [0, 0, 0], "inertia": [9.99e-6, 9.99e-6, 9.99e-6]}],
  "joints": [{"name": "ball", "type": "free", "parent": "ground", "child": "ball", "q0": {"position": [0, 0, 0.015]}}],
  "constraints": [{"name": "floor", "type": "rolling_ball", "body_a": "ground", "body_b": "ball", "radius": 0.015}],
  "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.8]}],
  "actuators": [
    {"name": "push_x", "type": "body_force", "body": "ball", "direction": [1, 0, 0], "unit": "N"},
    {"name": "push_y", "type": "body_force", "body": "ball", "direction": [0, 1, 0], "unit": "N"}
  ],
  "sensors": [
    {"name": "X", "type": "point_position", "body": "ball", "component": 0, "unit": "m"},
    {"name": "Y", "type": "point_position", "body": "ball", "component": 1, "unit": "m"}
  ],
  "plant": {"inputs": ["push_x", "push_y"], "outputs": ["X", "Y"]},
  "controller": {"type": "pid", "kp": [[1, 0], [0, 1]], "kd": [[0.8, 0], [0, 0.8]], "setpoint": [0, 0],
                 "operating_point": "initial"},
  "analysis": {"operating_point": "initial", "controller": "model", "compare_linear": true,
               "initial": {"ball.x": 0.1, "ball.y": -0.05}},
  "solver": {"rtol": 1e-11, "atol": 1e-13, "t_end": 5.0, "output_step": 0.01}
})";
  const Model mod = study_model(study_parse_model_text(text, "pushed_ball"));
  EXPECT_EQ(mod.dof(), 5);
  EXPECT_EQ(mod.rate_dof(), 3);
  const StudySimulation setup = study_simulation(mod);
  ASSERT_TRUE(setup.plant);
  const LinearSystem& s = setup.plant->lin.system;
  ASSERT_EQ(s.nx(), 8);
  ASSERT_EQ(s.positions, 5);
  // each axis: x/F = 1 / ((m + J/R^2) s^2)
  for (double w : {0.5, 3.0, 20.0}) {
    const cd z(0, w);
    const Eigen::MatrixXcd M = z * Eigen::MatrixXcd::Identity(8, 8) - s.A.cast<cd>();
    const Eigen::MatrixXcd G = s.C.cast<cd>() * M.partialPivLu().solve(s.B.cast<cd>()) + s.D.cast<cd>();
    const cd e = 1.0 / (mass_eff * z * z);
    EXPECT_LT(std::abs(G(0, 0) - e), 1e-10 * std::abs(e)) << w;
    EXPECT_LT(std::abs(G(1, 1) - e), 1e-10 * std::abs(e)) << w;
    EXPECT_LT(std::abs(G(0, 1)) + std::abs(G(1, 0)), 1e-12 * std::abs(e)) << w;
  }
  // the linear closed loop (the PD's rate term through C and A_zw): m_eff s^2 + kd s + kp on each
  // axis (twice), the rest at 0
  const StudyClosedLoop cl = study_closed_loop(mod);
  const Eigen::VectorXcd poles = Eigen::EigenSolver<Eigen::MatrixXd>(cl.loop.system.A).eigenvalues();
  const cd disc = std::sqrt(cd(0.8 * 0.8 - 4 * mass_eff * 1.0, 0));
  const cd s1 = (-0.8 + disc) / (2 * mass_eff), s2 = (-0.8 - disc) / (2 * mass_eff);  // -2.14, -3.01
  int found = 0;
  for (Eigen::Index k = 0; k < poles.size(); ++k)
    if (std::abs(poles[k] - s1) < 1e-9 || std::abs(poles[k] - s2) < 1e-9) ++found;
  EXPECT_EQ(found, 4) << poles.transpose();
  const SimulationResult r = study_simulate(mod, setup);
  ASSERT_TRUE(r.completed) << r.failure;
  ASSERT_EQ(r.y_linear.rows(), r.samples());
  const int ix = rolling_column(r.output_names, "X"), iy = rolling_column(r.output_names, "Y");
  EXPECT_NEAR(r.y(0, ix), 0.1, 1e-12);
  EXPECT_NEAR(r.y(0, iy), -0.05, 1e-12);
  double worst = 0;
  for (int i = 0; i < r.samples(); ++i)
    worst = std::max({worst, std::abs(r.y(i, ix) - r.y_linear(i, ix)), std::abs(r.y(i, iy) - r.y_linear(i, iy))});
  EXPECT_LT(worst, 1e-8);
  // back within 0.1 mm of the origin after 5 s (the slowest decay e^{-2.14 t})
  EXPECT_LT(std::hypot(r.y(r.samples() - 1, ix), r.y(r.samples() - 1, iy)), 1e-4);
}

// lu_solve in autodiff: an entry whose value is 0 where it varies keeps its derivative. A(p) =
// [[1, 0], [sin p, 1]], b = [1, 1]: x2 = 1 - sin p, dx2/dp = -1 at p = 0 (the elimination step
// used to be skipped on the value alone, which lost it: found by the turntable's Jacobian above,
// where -sin(rz) of the ball's rotation is such an entry at the reference)
TEST(Rolling, AutodiffLuSolveKeepsTheDerivativeOfAnEntryZeroWhereItVaries) {
  const ADScalar p(0.0, Eigen::VectorXd::Unit(1, 0));
  const ADScalar one(1.0, Eigen::VectorXd::Zero(1)), zero(0.0, Eigen::VectorXd::Zero(1));
  MatXT<ADScalar> A(2, 2), b(2, 1);
  A << one, zero, sin(p), one;
  b << one, one;
  const MatXT<ADScalar> x = lu_solve<ADScalar>(A, b);
  EXPECT_EQ(x(1, 0).value(), 1.0);
  ASSERT_EQ(x(1, 0).derivatives().size(), 1);
  EXPECT_EQ(x(1, 0).derivatives()[0], -1.0);
  EXPECT_EQ(x(0, 0).derivatives()[0], 0.0);
}

TEST(Rolling, ANonPositiveRadiusIsRefusedNamingTheField) {
  ModelSpec spec = plate();
  spec.constraints.at(0).radius = 0.0;
  try {
    study_model(spec);
    FAIL() << "accepted a radius of 0";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/constraints/0/radius"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("positive radius"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace codyna
