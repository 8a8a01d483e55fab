// A disc rolling without slip on a plane (issue 19, rolling_disc): a wheel or a coin of radius R
// whose axle a (axis_b, on the disc) is not along the plane's normal n. The contact direction is
// d = (n - (n.a) a) / |n - (n.a) a|, the contact point P = c - R d; the rows are the centre's height
// n . (c - p_a) - R sqrt(1 - (n.a)^2) (on q) and no slip t . (v_b(P) - v_a(P)) along the plane's two
// directions (on v only). Checked against:
//   closed forms of the rows at a given lean;
//   the rows' acceleration term against the central time difference of Jc v along motions;
//   the analytic plant Jacobian (TreeDerivatives) against automatic differentiation (1e-12) and
//     against central differences, on the floor and on a tilting plate, leaning;
//   simulation against closed forms derived below: an upright disc rolls straight at its speed, an
//     upright disc rolls down an incline at m g sin(b) / (m + I3 / R^2) = (2/3) g sin(b), the lean
//     oscillation of an upright disc rolling at Omega has the frequency of the linearized equations;
//   a disc rolling and wobbling on a level floor keeps its energy;
//   bad input (radius 0, axle 0, a disc lying flat) refused naming the field.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/joint.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "jacobian_check.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

// a thin uniform disc: I1 = m R^2 / 4 about a diameter, I3 = m R^2 / 2 about the axle (body y)
constexpr double m_disc = 1.5, R_disc = 0.2, g_disc = 9.81;
constexpr double I1 = m_disc * R_disc * R_disc / 4, I3 = m_disc * R_disc * R_disc / 2;

// the disc on the ground plane through the origin with normal n (a free joint; the axle is body y)
ModelSpec floor_disc(const Eigen::Vector3d& n = Eigen::Vector3d::UnitZ()) {
  const std::string text = R"({
  "codyna_model": 1, "name": "disc",
  "bodies": [{"name": "disc", "mass": 1.5, "com": [0, 0, 0], "inertia": [0.015, 0.03, 0.015]}],
  "joints": [{"name": "disc", "type": "free", "parent": "ground", "child": "disc", "q0": {"position": [0, 0, 0.2]}}],
  "constraints": [{"name": "contact", "type": "rolling_disc", "body_a": "ground", "axis_a": [0, 0, 1],
                   "body_b": "disc", "axis_b": [0, 1, 0], "radius": 0.2}],
  "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]}],
  "actuators": [{"name": "drive", "type": "body_torque", "body": "disc", "direction": [0, 1, 0], "frame": "body", "unit": "N m"}],
  "sensors": [
    {"name": "x", "type": "point_position", "body": "disc", "component": 0, "unit": "m"},
    {"name": "y", "type": "point_position", "body": "disc", "component": 1, "unit": "m"},
    {"name": "z", "type": "point_position", "body": "disc", "component": 2, "unit": "m"},
    {"name": "tip_z", "type": "point_position", "body": "disc", "point": [0, 1, 0], "component": 2, "unit": "m"}
  ],
  "plant": {"inputs": ["drive"], "outputs": ["x", "y", "z", "tip_z"]},
  "analysis": {"operating_point": "initial", "controller": "none"},
  "solver": {"rtol": 1e-11, "atol": 1e-13, "t_end": 1.0, "output_step": 0.01}
})";
  ModelSpec spec = study_parse_model_text(text, "disc");
  spec.constraints.at(0).axis_a = n.normalized();
  return spec;
}

// the contact direction of an axle a on a plane of normal n
Eigen::Vector3d contact_direction(const Eigen::Vector3d& n, const Eigen::Vector3d& a) {
  return (n - n.dot(a) * a).normalized();
}

// the free joint at rest on the plane (normal n, through the origin) with orientation Rot, rolling
// with world angular velocity w: c = R d (the contact at the origin), v_c = w x (R d)
void set_rolling(JointSpec& j, const Eigen::Matrix3d& Rot, const Eigen::Vector3d& n, const Eigen::Vector3d& w) {
  const Eigen::Vector3d dv = contact_direction(n, Rot * Eigen::Vector3d::UnitY());
  const Eigen::Vector3d c = R_disc * dv, v = w.cross(R_disc * dv);
  const Eigen::Quaterniond qr(Rot);
  j.q0 = (Eigen::VectorXd(7) << c.x(), c.y(), c.z(), qr.w(), qr.x(), qr.y(), qr.z()).finished();
  // the free joint's rates in the child's axes
  const Eigen::Vector3d wb = Rot.transpose() * w, vb = Rot.transpose() * v;
  j.v0 = (Eigen::VectorXd(6) << wb, vb).finished();
}

Eigen::Matrix3d lean(double phi) { return Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()).toRotationMatrix(); }

// the disc on a plate tilted by two revolute joints (tilt_x driven by a motion input, tilt_y free
// on a spring, with a joint torque): the plane turns with body_a, the disc leans on it
ModelSpec plate_disc() {
  const std::string text = R"({
  "codyna_model": 1, "name": "plate_disc",
  "bodies": [
    {"name": "gimbal", "mass": 0.4, "com": [0, 0, 0], "inertia": [0.004, 0.004, 0.008]},
    {"name": "plate", "mass": 3.0, "com": [0.05, -0.02, -0.03], "inertia": [0.09, 0.08, 0.16]},
    {"name": "disc", "mass": 1.5, "com": [0, 0, 0], "inertia": [0.015, 0.03, 0.015]}
  ],
  "joints": [
    {"name": "tilt_x", "type": "revolute", "parent": "ground", "child": "gimbal", "axis": [1, 0, 0], "q0": 0.0},
    {"name": "tilt_y", "type": "revolute", "parent": "gimbal", "child": "plate", "axis": [0, 1, 0], "q0": 0.0},
    {"name": "disc", "type": "free", "parent": "ground", "child": "disc", "q0": {"position": [0.1, 0.05, 0.2]}}
  ],
  "constraints": [{"name": "contact", "type": "rolling_disc", "body_a": "plate", "point_a": [0, 0, -0.02],
                   "axis_a": [0, 0, 1], "body_b": "disc", "point_b": [0, 0, 0], "axis_b": [0, 1, 0], "radius": 0.2}],
  "effects": [
    {"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
    {"name": "spring", "type": "joint_spring_damper", "joint": "tilt_y", "stiffness": 40.0, "damping": 0.3}
  ],
  "actuators": [
    {"name": "alpha_x", "type": "motion", "joint": "tilt_x", "unit": "rad"},
    {"name": "torque_y", "type": "joint_force", "joint": "tilt_y", "unit": "N m"},
    {"name": "drive", "type": "body_torque", "body": "disc", "direction": [0, 1, 0], "frame": "body", "unit": "N m"}
  ],
  "sensors": [
    {"name": "X", "type": "point_position", "body": "disc", "component": 0, "frame": "plate", "unit": "m"},
    {"name": "vy", "type": "point_velocity", "body": "disc", "point": [0, 0.1, 0.05], "component": 1, "unit": "m/s"}
  ],
  "plant": {"inputs": ["alpha_x", "torque_y", "drive"], "outputs": ["X", "vy"]},
  "analysis": {"operating_point": "initial", "controller": "none"},
  "solver": {"t_end": 1.0, "output_step": 0.01}
})";
  ModelSpec spec = study_parse_model_text(text, "plate_disc");
  // leaning 0.35 rad and turned 0.6 rad about the normal, rolling and wobbling (the plate level
  // at q0: its top at z = -0.02, so the contact is at (0, 0, -0.02))
  const Eigen::Matrix3d Rot = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()).toRotationMatrix() * lean(0.35);
  set_rolling(spec.joints.at(2), Rot, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.4, -1.1, 2.0));
  spec.joints.at(2).q0[2] -= 0.02;
  return spec;
}

// a leaning floor disc (0.45 rad, turned about z), rolling and wobbling
ModelSpec leaning_floor_disc() {
  ModelSpec spec = floor_disc();
  const Eigen::Matrix3d Rot = Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix() * lean(0.45);
  set_rolling(spec.joints.at(0), Rot, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.7, 5.0, -1.3));
  return spec;
}

int column(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<int>(it - names.begin());
}

TEST(RollingDisc, TheRowsAreTheHeightOverRCosLeanAndTheContactPointsVelocity) {
  const Model mod = study_model(floor_disc());
  EXPECT_EQ(mod.nc, 3);
  EXPECT_EQ(mod.row_names, (std::vector<std::string>{"contact.height", "contact.slip_u", "contact.slip_v"}));
  EXPECT_EQ(mod.velocity_rows, (std::vector<int>{1, 2}));
  EXPECT_EQ(mod.dof(), 5);
  EXPECT_EQ(mod.rate_dof(), 3);
  Data d(mod);
  // leaning phi with the centre at height h: the height row is h - R cos(phi) (the contact point
  // is R cos(phi) below the centre)
  for (double phi : {0.0, 0.3, -0.8, 1.2}) {
    const double h = 0.137;
    const Eigen::Quaterniond qr(lean(phi) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()).toRotationMatrix());
    const Eigen::VectorXd q = (Eigen::VectorXd(7) << 0.3, -0.2, h, qr.w(), qr.x(), qr.y(), qr.z()).finished();
    const Eigen::VectorXd& phi_q = constraint_residual<double>(mod, d, q);
    EXPECT_NEAR(phi_q[0], h - R_disc * std::cos(phi), 1e-15) << phi;
    EXPECT_EQ(phi_q[1], 0.0);
    EXPECT_EQ(phi_q[2], 0.0);
    // rolling (v_c = w x R d): Jc v = 0 on the three rows; slipping by s at the contact: Jc v = s
    const Eigen::Matrix3d Rot = qr.toRotationMatrix();
    const Eigen::Vector3d w(0.3, -4.0, 1.1), dv = contact_direction(Eigen::Vector3d::UnitZ(), Rot.col(1));
    EXPECT_NEAR(dv.z(), std::cos(phi), 1e-15);
    const Eigen::Vector3d s(0.05, -0.02, 0.01);
    for (int slip = 0; slip < 2; ++slip) {
      const Eigen::Vector3d v = w.cross(R_disc * dv) + (slip ? s : Eigen::Vector3d::Zero());
      const Eigen::VectorXd vq = (Eigen::VectorXd(6) << Rot.transpose() * w, Rot.transpose() * v).finished();
      constraint_terms<double>(mod, d, q, vq);
      const Eigen::Vector3d Jv = d.Jc * vq;
      const ConstraintModel& c = mod.constraints.at(0);
      const Eigen::Vector3d expected = slip ? Eigen::Vector3d(s.z(), c.perp_a1.dot(s), c.perp_a2.dot(s)) : Eigen::Vector3d::Zero();
      EXPECT_LT((Jv - expected).cwiseAbs().maxCoeff(), 1e-14) << phi << " slip " << slip << ": " << Jv.transpose();
    }
  }
}

// d/dt (Jc(q) v) = Jc qdd + gamma along a motion (q, v, a): central differences in time of Jc v,
// on the floor and on the moving plate, at random leaning configurations
TEST(RollingDisc, TheAccelerationTermIsTheTimeDerivativeOfJcV) {
  int checked = 0;
  for (const ModelSpec& spec : {leaning_floor_disc(), plate_disc()}) {
    const Model mod = study_model(spec);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    Data d(mod);
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd v(mod.nv), a(mod.nv);
      for (int i = 0; i < mod.nv; ++i) v[i] = 2 * U(rng), a[i] = 2 * U(rng);
      const Eigen::VectorXd q =
          integrate<double>(mod, mod.q0, Eigen::VectorXd(0.3 * Eigen::VectorXd::NullaryExpr(mod.nv, [&] { return U(rng); })));
      constraint_terms<double>(mod, d, q, v);
      const Eigen::VectorXd expected = d.Jc * a + d.gamma;
      const double h = 1e-4;
      auto Jv = [&](double t) {
        const Eigen::VectorXd qt = integrate<double>(mod, q, Eigen::VectorXd(t * v + 0.5 * t * t * a));
        const Eigen::VectorXd vt = v + t * a;
        constraint_terms<double>(mod, d, qt, vt);
        return Eigen::VectorXd(d.Jc * vt);
      };
      const Eigen::VectorXd fd = (Jv(h) - Jv(-h)) / (2 * h);
      for (int row = 0; row < 3; ++row)
        EXPECT_NEAR(fd[row], expected[row], 1e-6 * std::max(1.0, std::abs(expected[row]))) << spec.name << " " << trial << " row " << row;
      EXPECT_GT(expected.cwiseAbs().maxCoeff(), 0.1);  // a term that can be wrong
      ++checked;
    }
  }
  EXPECT_EQ(checked, 10);
}

// the analytic Jacobian (TreeDerivatives through the disc's rows: the contact direction's chain
// rule over both bodies) against automatic differentiation of the plant function, at the leaning
// operating points with random rates, motion rates and accelerations
TEST(RollingDisc, TheAnalyticJacobianEqualsAutomaticDifferentiation) {
  int checked = 0;
  for (const ModelSpec& spec : {leaning_floor_disc(), plate_disc(), study_read_model(test::example_path("rolling_disc.json"))}) {
    const Model mod = study_model(spec);
    const CoordinatePartition p = partition_coordinates(mod, mod.q0);
    const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
    ASSERT_EQ(f.nw(), f.nz() - 2) << spec.name;
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), u(f.nu() + 2 * f.nm());
      for (int i = f.nz(); i < f.nx(); ++i) x[i] = 3.0 * U(rng);
      for (int i = 0; i < f.nu(); ++i) {  // a motion input at its nominal value (the operating point's)
        const int k = mod.plant_inputs[static_cast<std::size_t>(i)];
        u[i] = mod.u_nominal()[k] + (mod.actuators[static_cast<std::size_t>(k)].type == ActuatorType::Motion ? 0.0 : 0.2 * U(rng));
      }
      for (int i = f.nu(); i < u.size(); ++i) u[i] = U(rng);
      const double scale =
          test::expect_analytic_equals_autodiff(f, x, u, spec.name + " trial " + std::to_string(trial));
      EXPECT_GT(scale, 1.0);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

// the plant's Jacobian against central differences of the plant function, away from the
// operating point (position deviations too) and in motion
TEST(RollingDisc, ThePlantJacobianAgreesWithCentralDifferences) {
  for (const ModelSpec& spec : {leaning_floor_disc(), plate_disc()}) {
    const Model mod = study_model(spec);
    const CoordinatePartition p = partition_coordinates(mod, mod.q0);
    const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x(f.nx()), u(f.nu() + 2 * f.nm());
      for (int i = 0; i < x.size(); ++i) x[i] = (i < f.nz() ? 0.05 : 2.0) * U(rng);
      for (int i = 0; i < u.size(); ++i) u[i] = (i < f.nu() ? 0.05 : 1.0) * U(rng);
      EXPECT_GT(test::expect_exact_equals_central_differences(f, x, u, spec.name + " " + std::to_string(trial), 1e-8), 1.0);
    }
  }
}

// an upright disc rolling at V along x (spin V / R about its axle, above the speed where the lean
// is stable: Omega^2 = 36 > g / (3 R) = 16.4) keeps rolling straight at V: x = V t, y = 0, z = R
TEST(RollingDisc, AnUprightDiscRollsStraightAtItsSpeed) {
  ModelSpec spec = floor_disc();
  const double V = 1.2;
  set_rolling(spec.joints.at(0), Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, V / R_disc, 0));
  spec.solver.t_end = 2.0;
  const Model mod = study_model(spec);
  EXPECT_TRUE(mod.assembly_moves.empty());
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const int ix = column(r.output_names, "x"), iy = column(r.output_names, "y"), iz = column(r.output_names, "z");
  double worst = 0, slip = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[static_cast<std::size_t>(i)];
    worst = std::max({worst, std::abs(r.y(i, ix) - V * t), std::abs(r.y(i, iy)), std::abs(r.y(i, iz) - R_disc)});
    slip = std::max(slip, r.velocity_violation[static_cast<std::size_t>(i)]);
  }
  EXPECT_NEAR(r.t.back(), 2.0, 1e-12);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(slip, 1e-9);
}

// an upright disc released at rest on a fixed incline of slope b, its axle horizontal: the contact
// force does no work and its moment about the centre spins the disc: m s'' = m g sin b - F,
// I3 s'' / R = F R, so s'' = m g sin b / (m + I3 / R^2) = (2/3) g sin b for the thin disc
TEST(RollingDisc, AnUprightDiscRollsDownAnInclineAtTwoThirdsGSinB) {
  const double b = 0.3;
  const Eigen::Vector3d n(std::sin(b), 0, std::cos(b)), down(std::cos(b), 0, -std::sin(b));
  ModelSpec spec = floor_disc(n);
  set_rolling(spec.joints.at(0), Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()).toRotationMatrix(), n, Eigen::Vector3d::Zero());
  const Model mod = study_model(spec);
  EXPECT_TRUE(mod.assembly_moves.empty());
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const int ix = column(r.output_names, "x"), iy = column(r.output_names, "y"), iz = column(r.output_names, "z");
  const double acc = m_disc * g_disc * std::sin(b) / (m_disc + I3 / (R_disc * R_disc));
  EXPECT_NEAR(acc, 2.0 / 3.0 * g_disc * std::sin(b), 1e-14);
  const Eigen::Vector3d c0 = R_disc * n;
  double worst = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[static_cast<std::size_t>(i)];
    const Eigen::Vector3d c = c0 + 0.5 * acc * t * t * down;
    worst = std::max(worst, (Eigen::Vector3d(r.y(i, ix), r.y(i, iy), r.y(i, iz)) - c).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(r.y(r.samples() - 1, ix) - c0.x(), 0.5);  // it rolled: about 0.9 m_disc
  EXPECT_LT(worst, 1e-9);
}

// The lean oscillation of an upright disc rolling at spin Omega (V = Omega R). Linearized about
// straight rolling along x (lean phi about x, heading psi about z, I1 about a diameter, I3 about
// the axle), with the contact force F at P = G - R z:
//   heading: F's moment about the vertical through G is (-R z) x F, horizontal: the vertical
//     angular momentum I1 psi' + I3 Omega (axle . z) = I1 psi' - I3 Omega phi is conserved (the
//     axle y turned by phi about x has z-component phi), so psi' = (I3 Omega / I1) phi from rest;
//   lean: about the contact line, (I1 + m R^2) phi'' = m g R phi - (I3 + m R^2) Omega psi'
//     (gravity's moment; the gyroscopic moment I3 Omega psi' of turning the spinning disc; the
//     centre's lateral acceleration V psi' = R Omega psi' times m at the lever R);
// so phi'' = -lambda^2 phi, lambda^2 = ((I3 + m R^2) I3 Omega^2 / I1 - m g R) / (I1 + m R^2),
// = (4/5) (3 Omega^2 - g / R) for the thin disc: stable iff Omega^2 > g / (3 R). Started upright
// with a small lean rate e, phi = (e / lambda) sin(lambda t); the point on the axle 1 m from the
// centre is at height R cos(phi) + sin(phi) = R + phi + O(phi^2).
TEST(RollingDisc, TheLeanOfAnUprightRollingDiscOscillatesAtTheClosedFormFrequency) {
  const double Omega = 8.0, e = 1e-5;
  const double lambda2 = ((I3 + m_disc * R_disc * R_disc) * I3 * Omega * Omega / I1 - m_disc * g_disc * R_disc) / (I1 + m_disc * R_disc * R_disc);
  ASSERT_NEAR(lambda2, 0.8 * (3 * Omega * Omega - g_disc / R_disc), 1e-12);
  const double lambda = std::sqrt(lambda2);  // 12.5 rad/s
  ModelSpec spec = floor_disc();
  set_rolling(spec.joints.at(0), Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d(e, Omega, 0));
  spec.solver.t_end = 1.5;
  spec.solver.output_step = 0.005;
  const Model mod = study_model(spec);
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const int it = column(r.output_names, "tip_z");
  double worst = 0, peak = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[static_cast<std::size_t>(i)];
    const double phi = r.y(i, it) - R_disc;
    worst = std::max(worst, std::abs(phi - e / lambda * std::sin(lambda * t)));
    peak = std::max(peak, std::abs(phi));
  }
  // three periods; the amplitude e / lambda = 8e-7 rad; the nonlinear terms are O(phi^2)
  EXPECT_NEAR(peak, e / lambda, 1e-3 * e / lambda);
  EXPECT_LT(worst, 1e-3 * e / lambda);
}

// a disc rolling, leaning and wobbling on a level floor: the contact does no work
TEST(RollingDisc, AWobblingDiscKeepsItsEnergy) {
  ModelSpec spec = leaning_floor_disc();
  spec.solver.t_end = 1.5;
  const Model mod = study_model(spec);
  EXPECT_LT(mod.assembly_residual, 1e-12);
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  double drift = 0, dpe = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    drift = std::max(drift, std::abs(r.kinetic_energy[k] + r.potential_energy[k] - E0));
    dpe = std::max(dpe, std::abs(r.potential_energy[k] - r.potential_energy[0]));
  }
  EXPECT_GT(dpe, 0.01 * r.kinetic_energy[0]);  // it wobbles: energy moves between the two
  EXPECT_LT(drift, 1e-8 * r.kinetic_energy[0]);
}

void expect_refused(const ModelSpec& spec, const std::string& path, const std::string& words) {
  try {
    study_model(spec);
    ADD_FAILURE() << "accepted: expected an error at " << path;
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(RollingDisc, BadInputIsRefusedNamingTheField) {
  ModelSpec spec = floor_disc();
  spec.constraints.at(0).radius = 0.0;
  expect_refused(spec, "/constraints/0/radius", "positive radius");
  spec.constraints.at(0).radius = std::nan("");
  expect_refused(spec, "/constraints/0/radius", "positive radius");
  spec = floor_disc();
  spec.constraints.at(0).axis_b = Eigen::Vector3d::Zero();
  expect_refused(spec, "/constraints/0/axis_b", "");
  // lying flat: the axle along the plane's normal
  spec = floor_disc();
  spec.constraints.at(0).axis_b = Eigen::Vector3d::UnitZ();
  expect_refused(spec, "/constraints/0", "lies flat");
  // and the file's own errors
  std::string text = R"({"codyna_model": 1, "name": "d", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1]}],
    "joints": [{"name": "j", "type": "free", "parent": "ground", "child": "b"}],
    "constraints": [{"name": "c", "type": "rolling_disc", "body_a": "ground", "body_b": "b", "axis_b": [0, 1, 0]}]})";
  try {
    study_parse_model_text(text, "d");
    ADD_FAILURE() << "accepted a rolling_disc without a radius";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/constraints/0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace codyna
