// The tire effect (EffectType::Tire, dynamics/tire_effect.hpp): a wheel at rest carries its weight
// and no slip makes no force; the wrench moved from the contact point to the wheel against a hand
// computation; the force continuous and differentiable through Vx = 0; the exact Jacobian of a car
// with tires (straight, turning with steer, braking) against central differences and automatic
// differentiation; a .tir tire equal to magic_formula at the same slips; the refusals and the
// round trip of the model file; and examples/single_track_car.json against the closed-form
// single-track (bicycle) model of Rajamani (ch. 2-3).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/data.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/tire_effect.hpp"
#include "model/errors.hpp"
#include "simulation/simulator.hpp"
#include "study/files.hpp"
#include "study/tire_contacts.hpp"
#include "study/workflow.hpp"
#include "jacobian_check.hpp"
#include "test_util.hpp"
#include "vehicle/magic_formula.hpp"
#include "vehicle/tir_file.hpp"

namespace codyna {
namespace {

const std::string tire_effect_tir = std::string(CODYNA_TEST_DATA_DIR) + "/tires/PacejkaBook_Defaults.tir";

// one wheel of mass m on a free joint over the ground road; the tire's JSON fields given
std::string tire_effect_wheel(const std::string& tire_fields, const std::string& q0, const std::string& v0,
                              double mass = 20.0) {
  char text[4000];
  std::snprintf(text, sizeof text, R"({"name": "wheel",
    "bodies": [{"name": "wheel", "mass": %.17g, "inertia": [0.5, 0.9, 0.5]}],
    "joints": [{"name": "J", "type": "free", "parent": "ground", "child": "wheel", "q0": %s, "v0": %s}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
                {"name": "tire", "type": "tire", "body": "wheel", %s}],
    "analysis": {"operating_point": "initial"}})",
                mass, q0.c_str(), v0.c_str(), tire_fields.c_str());
  return text;
}

const char* const tire_effect_linear_fields =
    R"("center": [0, 0, 0], "spin_axis": [0, 1, 0], "unloaded_radius": 0.3, "law": "linear",
       "longitudinal_stiffness": 60000, "cornering_stiffness": 50000, "camber_stiffness": 3000,
       "vertical_stiffness": 200000, "vertical_damping": 500)";

// the contact of the model's first tire at (q, v)
TireContact<double> tire_effect_contact_at(const Model& mod, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                           bool* touching = nullptr) {
  Data d(mod);
  forward_kinematics<double>(mod, d, q, v);
  const TireModel& t = mod.tires.at(0);
  TireContact<double> c;
  const bool on = tire_contact<double>(t, d.oMi[t.body].R, d.oMi[t.body].p, angular_velocity<double>(d, t.body),
                                       point_velocity<double>(d, t.body, Eigen::Vector3d::Zero()), d.oMi[t.road_body].R,
                                       d.oMi[t.road_body].p, angular_velocity<double>(d, t.road_body),
                                       point_velocity<double>(d, t.road_body, Eigen::Vector3d::Zero()), c);
  if (touching) *touching = on;
  return c;
}

TEST(TireEffect, AWheelAtRestCarriesItsWeightAndNoSlipMakesNoForce) {
  // 20 kg on k = 200000 N/m: deflection m g / k, the centre at R0 - m g / k; at rest the tire
  // carries m g and the wheel does not accelerate; rolling at V with Omega = V / R0 it makes no Fx, Fy
  const double m = 20, g = 9.81, k = 200000, R0 = 0.3;
  const double h = R0 - m * g / k;
  char q0[200];
  std::snprintf(q0, sizeof q0, "[0, 0, %.17g, 1, 0, 0, 0]", h);
  const Model mod = study_model(study_parse_model_text(tire_effect_wheel(tire_effect_linear_fields, q0, "[0, 0, 0, 0, 0, 0]", m), "wheel.json"));
  ASSERT_EQ(mod.tires.size(), 1u);
  bool on = false;
  TireContact<double> c = tire_effect_contact_at(mod, mod.q0, mod.v0, &on);
  ASSERT_TRUE(on);
  EXPECT_NEAR(c.force.z(), m * g, 1e-9 * m * g);
  EXPECT_EQ(c.force.x(), 0.0);
  EXPECT_EQ(c.force.y(), 0.0);
  EXPECT_NEAR(c.point.z(), 0.0, 1e-15);
  Data d(mod);
  const Eigen::VectorXd qdd = forward_dynamics<double>(mod, d, mod.q0, mod.v0, mod.u_nominal());
  EXPECT_LT(qdd.cwiseAbs().maxCoeff(), 1e-9);
  // rolling forward at 10 m/s, Omega = V / R0 about the axle (free joint rates in body axes)
  Eigen::VectorXd v = Eigen::VectorXd::Zero(6);
  v[1] = 10.0 / R0;
  v[3] = 10.0;
  c = tire_effect_contact_at(mod, mod.q0, v, &on);
  ASSERT_TRUE(on);
  EXPECT_NEAR(c.input.kappa, 0.0, 1e-15);
  EXPECT_NEAR(c.input.alpha, 0.0, 1e-15);
  EXPECT_NEAR(c.force.x(), 0.0, 1e-9);
  EXPECT_NEAR(c.force.y(), 0.0, 1e-9);
  EXPECT_NEAR(c.force.z(), m * g, 1e-9 * m * g);
  // lifted off the road: no force at all
  Eigen::VectorXd q = mod.q0;
  q[2] = R0 + 0.01;
  c = tire_effect_contact_at(mod, q, v, &on);
  EXPECT_FALSE(on);
  EXPECT_EQ(c.force.norm(), 0.0);
  // sliding to the left, the tire pushes to the right (ISO-W: alpha > 0, Fy < 0)
  v[4] = 1.0;
  c = tire_effect_contact_at(mod, mod.q0, v, &on);
  EXPECT_GT(c.input.alpha, 0.0);
  EXPECT_LT(c.force.y(), 0.0);
}

// a cambered wheel turned about the vertical, off the body origin, rolling with slip on the book's
// Magic Formula tire: the contact point, slips, forces and the moment about the body origin by hand
TEST(TireEffect, TheWrenchOnTheWheelEqualsAHandComputation) {
  const double gamma = 0.04, psi = 0.3, h = 0.3;  // camber, heading, centre height
  const Eigen::Vector3d center_local(0.02, -0.05, 0.01);
  // body orientation: heading psi about z, then camber gamma about the wheel's x
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(gamma, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Quaterniond qr(R);
  const Eigen::Vector3d c_world(1.0, 2.0, h);
  const Eigen::Vector3d p_body = c_world - R * center_local;
  char q0[300], fields[600];
  std::snprintf(q0, sizeof q0, "[%.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g]", p_body.x(), p_body.y(), p_body.z(), qr.w(),
                qr.x(), qr.y(), qr.z());
  std::snprintf(fields, sizeof fields,
                R"("center": [%.17g, %.17g, %.17g], "spin_axis": [0, 1, 0], "law": "magic_formula", "file": "%s")",
                center_local.x(), center_local.y(), center_local.z(), tire_effect_tir.c_str());
  const Model mod = study_model(study_parse_model_text(tire_effect_wheel(fields, q0, "[0, 0, 0, 0, 0, 0]"), "wheel.json"));
  const TireModel& t = mod.tires.at(0);
  const MagicFormulaParameters mf = read_tir_file(tire_effect_tir);
  EXPECT_EQ(t.unloaded_radius, mf.UNLOADED_RADIUS);
  EXPECT_EQ(t.vertical_stiffness, mf.VERTICAL_STIFFNESS);
  // the velocity: the centre moves at (Vx, Vy) along the heading axes, the wheel spins at Omega
  // about its axle (no other rotation, so the carrier does not turn and V is the centre's)
  const double Vx = 15.0, Vy = -0.6, Omega = 15.0 * 1.03 / t.unloaded_radius;
  const Eigen::Vector3d xh(std::cos(psi), std::sin(psi), 0), yh(-std::sin(psi), std::cos(psi), 0);
  const Eigen::Vector3d axis_world = R * Eigen::Vector3d::UnitY();
  const Eigen::Vector3d w_world = Omega * axis_world;
  const Eigen::Vector3d vc_world = Vx * xh + Vy * yh;
  const Eigen::Vector3d vo_world = vc_world - w_world.cross(c_world - p_body);
  Eigen::VectorXd v(6);
  v << R.transpose() * w_world, R.transpose() * vo_world;  // free joint: body-axis rates
  // by hand: the contact point P = c + (h / cos gamma)(sin gamma y_h - cos gamma z); ISO-W axes
  // x_h, y_h, z; deflection R0 - h / cos gamma; kappa, alpha from the centre's velocity
  const Eigen::Vector3d P = c_world + (h / std::cos(gamma)) * (std::sin(gamma) * yh - std::cos(gamma) * Eigen::Vector3d::UnitZ());
  const double pen = t.unloaded_radius - h / std::cos(gamma);
  TireInput<double> in;
  in.Fz = t.vertical_stiffness * pen;
  in.kappa = -(Vx - Omega * t.unloaded_radius) / Vx;
  in.alpha = std::atan(Vy / Vx);
  in.gamma = gamma;
  in.Vx = Vx;
  const TireForces<double> f = magic_formula<double>(mf, in);
  bool on = false;
  const TireContact<double> c = tire_effect_contact_at(mod, mod.q0, v, &on);
  ASSERT_TRUE(on);
  EXPECT_LT((c.point - P).norm(), 1e-14);
  EXPECT_NEAR(c.penetration, pen, 1e-15);
  EXPECT_NEAR(c.penetration_rate, 0.0, 1e-12);
  EXPECT_NEAR(c.input.kappa, in.kappa, 1e-13);
  EXPECT_NEAR(c.input.alpha, in.alpha, 1e-13);
  EXPECT_NEAR(c.input.gamma, gamma, 1e-14);
  const Eigen::Vector3d F = f.Fx * xh + f.Fy * yh + in.Fz * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d M = f.Mx * xh + f.My * yh + f.Mz * Eigen::Vector3d::UnitZ();
  EXPECT_GT(std::abs(f.My), 1.0);
  EXPECT_GT(std::abs(f.Mz), 1.0);
  // the generalized force of the free joint: the torque about the body origin and the force, body axes
  Data d(mod);
  forward_kinematics<double>(mod, d, mod.q0, v);
  const Eigen::VectorXd u = mod.u_nominal();
  const Eigen::VectorXd Q = applied_forces<double>(mod, d, mod.q0, v, u);
  Eigen::Matrix<double, 6, 1> expected;
  expected << R.transpose() * (M + (P - p_body).cross(F)), R.transpose() * F;
  // gravity is not an applied force (rnea/aba take it as a base acceleration)
  const double scale = F.norm();
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(Q[k], expected[k], 1e-12 * scale) << k;
}

// the force at Vx from -1 to 1 m/s (through 0 and through +-v_low): continuous, and its derivative
// (automatic differentiation through the regularized slips) equal to central differences everywhere
TEST(TireEffect, TheForceIsContinuousAndDifferentiableThroughStandstill) {
  for (const char* law : {"linear", "fiala"}) {
    SCOPED_TRACE(law);
    const std::string fields = std::string(R"("unloaded_radius": 0.3, "law": ")") + law +
                               R"(", "longitudinal_stiffness": 60000, "cornering_stiffness": 50000, "friction": 1.0,
                               "vertical_stiffness": 200000, "low_speed": 0.2)";
    const Model mod = study_model(study_parse_model_text(tire_effect_wheel(fields, "[0, 0, 0.29, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), "w.json"));
    const TireModel& t = mod.tires.at(0);
    using AD1 = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
    // F(Vx) with a little lateral velocity and spin, Vx seeded
    const auto force = [&](double vx, Eigen::Vector3d* dF) {
      Mat3T<AD1> R = Eigen::Matrix3d::Identity().cast<AD1>();
      Vec3T<AD1> p(AD1(0.0), AD1(0.0), AD1(0.29)), w(AD1(0.0), AD1(0.4), AD1(0.0)), vv(AD1(vx, Eigen::Matrix<double, 1, 1>(1.0)), AD1(0.03), AD1(0.0));
      const Mat3T<AD1> Rg = Eigen::Matrix3d::Identity().cast<AD1>();
      const Vec3T<AD1> zero = Vec3T<AD1>::Constant(AD1(0.0));
      TireContact<AD1> c;
      EXPECT_TRUE(tire_contact<AD1>(t, R, p, w, vv, Rg, zero, zero, zero, c));
      Eigen::Vector3d F;
      for (int k = 0; k < 3; ++k) {
        F[k] = c.force[k].value();
        if (dF) (*dF)[k] = c.force[k].derivatives()[0];
      }
      return F;
    };
    double largest_jump = 0;
    Eigen::Vector3d previous = force(-1.0, nullptr);
    const int n = 20000;  // steps of 1e-4 m/s
    for (int i = 1; i <= n; ++i) {
      const Eigen::Vector3d F = force(-1.0 + 2.0 * i / n, nullptr);
      largest_jump = std::max(largest_jump, (F - previous).cwiseAbs().maxCoeff());
      previous = F;
    }
    // the steepest slope is about C_kappa / (v_low / 2) = 6e5 N per m/s: 60 N per step; a jump would be far more
    EXPECT_LT(largest_jump, 80.0);
    double worst = 0;
    for (double vx : {-0.7, -0.2 - 1e-3, -0.2 + 1e-3, -0.05, 0.0, 1e-4, 0.05, 0.2 - 1e-3, 0.2 + 1e-3, 0.7}) {
      Eigen::Vector3d dF;
      force(vx, &dF);
      const double hstep = 1e-6;
      const Eigen::Vector3d fd = (force(vx + hstep, nullptr) - force(vx - hstep, nullptr)) / (2 * hstep);
      const double err = (dF - fd).cwiseAbs().maxCoeff() / std::max(1.0, fd.cwiseAbs().maxCoeff());
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-6) << "Vx = " << vx << ": " << dF.transpose() << " vs " << fd.transpose();
    }
    std::printf("[ TireEffect ] %s: largest step of F over the sweep %.3g N, derivative vs central differences %.2e\n", law,
                largest_jump, worst);
    // at standstill, at rest: nothing but the load
    const Eigen::Vector3d F0 = force(0.0, nullptr);
    EXPECT_TRUE(std::isfinite(F0.norm()));
  }
}

// a wheel in a vertical plane (planar joint: x, height, spin). Dropped 5 mm above its static
// height at rest, it settles at the static deflection m g / k and stays where it fell. Sliding at
// 5 m/s at that height without spin, the tire spins it up to free rolling (kappa -> 0) while the
// angular momentum about a point of the road is kept (the load stays m g, the linear tire makes no
// rolling resistance): V = m h V0 / (m h + I / R0)
std::string tire_effect_planar_wheel(double z0, double V0) {
  char text[3000];
  std::snprintf(text, sizeof text, R"({"name": "planar_wheel",
    "bodies": [{"name": "wheel", "mass": 20, "inertia": [0.5, 0.5, 0.9]}],
    "joints": [{"name": "J", "type": "planar", "parent": "ground", "child": "wheel",
                "parent_frame": {"rotation": {"axis": [1, 0, 0], "angle": 1.5707963267948966}},
                "q0": [0, %.17g, 0], "v0": [%.17g, 0, 0]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
                {"name": "tire", "type": "tire", "body": "wheel", "spin_axis": [0, 0, -1], "unloaded_radius": 0.3,
                 "law": "linear", "longitudinal_stiffness": 60000, "cornering_stiffness": 50000,
                 "vertical_stiffness": 200000, "vertical_damping": 2000}],
    "solver": {"t_end": 2, "output_step": 0.01}})",
                z0, V0);
  return text;
}

TEST(TireEffect, ADroppedWheelSettlesAndASlidingWheelSpinsUpToRolling) {
  const double m = 20, I = 0.9, k = 200000, R0 = 0.3, g = 9.81, V0 = 5;
  const double h = R0 - m * g / k;
  {
    const Model mod = study_model(study_parse_model_text(tire_effect_planar_wheel(h + 0.005, 0.0), "dropped_wheel.json"));
    const SimulationResult r = study_simulate(mod, study_simulation(mod));
    ASSERT_TRUE(r.completed) << r.failure;
    const Eigen::Index last = r.q.rows() - 1;
    EXPECT_NEAR(r.q(last, 1), h, 1e-9);
    EXPECT_LT(r.q.col(0).cwiseAbs().maxCoeff(), 1e-12);  // no slip, no force along the road
    EXPECT_LT(r.q.col(2).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT(r.q.col(1).minCoeff(), h);  // it did bounce into the tire
  }
  const Model mod = study_model(study_parse_model_text(tire_effect_planar_wheel(h, V0), "sliding_wheel.json"));
  const SimulationResult r = study_simulate(mod, study_simulation(mod));
  ASSERT_TRUE(r.completed) << r.failure;
  const Eigen::Index last = r.q.rows() - 1;
  const double V = r.v(last, 0), height = r.q(last, 1), Omega = -r.v(last, 2);  // the angle is about -y
  EXPECT_NEAR(height, h, 1e-9);
  EXPECT_NEAR(Omega * R0, V, 1e-6 * V);  // free rolling: kappa = 0
  const double expected = m * h * V0 / (m * h + I / R0);
  EXPECT_NEAR(V, expected, 1e-6 * expected);
  std::printf("[ TireEffect ] sliding wheel: final V %.9f m/s (angular momentum: %.9f), kappa %.2e\n", V, expected,
              -(V - Omega * R0) / V);
}

// ------------------------------------------------------------------ the Jacobian of a car with tires

// a car on a free joint with four wheels spinning on revolute joints (front ones on steered
// knuckles held by stiff joint springs at `steer`), a drive torque on the rear wheels; the front
// tires linear with a friction circle, camber stiffness and trail, the rear ones Fiala
std::string tire_effect_car(double steer, double yaw_rate, double U, double drive, double slip) {
  const double R0 = 0.3, h = 0.28, a = 1.2, b = 1.5, tr = 0.8;
  char text[9000];
  const double spin = U / R0 * (1 + slip);
  std::snprintf(text, sizeof text, R"({"name": "car",
    "bodies": [{"name": "chassis", "mass": 1200, "inertia": [400, 1500, 1700]},
               {"name": "kl", "mass": 5, "inertia": [0.1, 0.1, 0.1]}, {"name": "kr", "mass": 5, "inertia": [0.1, 0.1, 0.1]},
               {"name": "fl", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "fr", "mass": 15, "inertia": [0.4, 0.8, 0.4]},
               {"name": "rl", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "rr", "mass": 15, "inertia": [0.4, 0.8, 0.4]}],
    "joints": [{"name": "body", "type": "free", "parent": "ground", "child": "chassis",
                "q0": [0, 0, %.17g, 1, 0, 0, 0], "v0": [0.01, -0.02, %.17g, %.17g, 0.3, 0.05]},
               {"name": "steer_l", "type": "revolute", "parent": "chassis", "child": "kl", "axis": [0, 0, 1],
                "parent_frame": {"position": [%.17g, %.17g, 0]}, "q0": %.17g},
               {"name": "steer_r", "type": "revolute", "parent": "chassis", "child": "kr", "axis": [0, 0, 1],
                "parent_frame": {"position": [%.17g, %.17g, 0]}, "q0": %.17g},
               {"name": "spin_fl", "type": "revolute", "parent": "kl", "child": "fl", "axis": [0, 1, 0], "v0": %.17g},
               {"name": "spin_fr", "type": "revolute", "parent": "kr", "child": "fr", "axis": [0, 1, 0], "v0": %.17g},
               {"name": "spin_rl", "type": "revolute", "parent": "chassis", "child": "rl", "axis": [0, 1, 0],
                "parent_frame": {"position": [%.17g, %.17g, 0]}, "v0": %.17g},
               {"name": "spin_rr", "type": "revolute", "parent": "chassis", "child": "rr", "axis": [0, 1, 0],
                "parent_frame": {"position": [%.17g, %.17g, 0]}, "v0": %.17g}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
      {"name": "hold_l", "type": "joint_spring_damper", "joint": "steer_l", "stiffness": 20000, "damping": 50, "rest_position": %.17g},
      {"name": "hold_r", "type": "joint_spring_damper", "joint": "steer_r", "stiffness": 20000, "damping": 50, "rest_position": %.17g},
      {"name": "tire_fl", "type": "tire", "body": "fl", "unloaded_radius": 0.3, "law": "linear", "longitudinal_stiffness": 80000,
       "cornering_stiffness": 70000, "camber_stiffness": 2000, "friction": 1.1, "trail": 0.03, "vertical_stiffness": 250000,
       "vertical_damping": 800},
      {"name": "tire_fr", "type": "tire", "body": "fr", "unloaded_radius": 0.3, "law": "linear", "longitudinal_stiffness": 80000,
       "cornering_stiffness": 70000, "camber_stiffness": 2000, "friction": 1.1, "trail": 0.03, "vertical_stiffness": 250000,
       "vertical_damping": 800},
      {"name": "tire_rl", "type": "tire", "body": "rl", "unloaded_radius": 0.3, "law": "fiala", "longitudinal_stiffness": 90000,
       "cornering_stiffness": 60000, "friction": 1.0, "sliding_friction": 0.8, "width": 0.2, "rolling_resistance": 0.01,
       "vertical_stiffness": 250000, "vertical_damping": 800},
      {"name": "tire_rr", "type": "tire", "body": "rr", "unloaded_radius": 0.3, "law": "fiala", "longitudinal_stiffness": 90000,
       "cornering_stiffness": 60000, "friction": 1.0, "sliding_friction": 0.8, "width": 0.2, "rolling_resistance": 0.01,
       "vertical_stiffness": 250000, "vertical_damping": 800}],
    "actuators": [{"name": "drive_l", "type": "joint_force", "joint": "spin_rl", "u0": %.17g},
                  {"name": "drive_r", "type": "joint_force", "joint": "spin_rr", "u0": %.17g}],
    "sensors": [{"name": "yaw_rate", "type": "joint_velocity", "joint": "body", "dof": 2}],
    "plant": {"inputs": ["drive_l", "drive_r"], "outputs": ["yaw_rate"]},
    "analysis": {"operating_point": "initial"}})",
                h, yaw_rate, U, a, tr / 2, steer, a, -tr / 2, steer, spin, spin, -b, tr / 2, spin, -b, -tr / 2, spin, steer,
                steer, drive, drive);
  return text;
}

TEST(TireEffect, TheExactJacobianOfACarWithTiresEqualsCentralDifferencesAndAutodiff) {
  struct Case {
    const char* label;
    double steer, yaw_rate, U, drive, slip;
  };
  for (const Case& k : {Case{"straight", 0.0, 0.0, 20.0, 0.0, 0.0}, Case{"turning", 0.06, 0.35, 15.0, 0.0, 0.002},
                        Case{"braking", 0.02, 0.1, 12.0, -300.0, -0.01}}) {
    SCOPED_TRACE(k.label);
    const Model mod = study_model(study_parse_model_text(tire_effect_car(k.steer, k.yaw_rate, k.U, k.drive, k.slip), "car.json"));
    ASSERT_EQ(mod.tires.size(), 4u);
    const CoordinatePartition p = partition_coordinates(mod, mod.q0);
    const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
    // the state at the operating point (no position deviation: the analytic path), velocities as given
    const Eigen::VectorXd x = f.qv_to_state(mod.q0, mod.v0);
    Eigen::VectorXd u(f.nu());
    for (int i = 0; i < f.nu(); ++i) u[i] = mod.u_nominal()[mod.plant_inputs[static_cast<std::size_t>(i)]];
    // every tire touches and slips
    Data d(mod);
    forward_kinematics<double>(mod, d, mod.q0, mod.v0);
    for (const TireModel& t : mod.tires) {
      TireContact<double> c;
      ASSERT_TRUE(tire_contact<double>(t, d.oMi[t.body].R, d.oMi[t.body].p, angular_velocity<double>(d, t.body),
                                       point_velocity<double>(d, t.body, Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity(),
                                       Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), c))
          << t.name;
      EXPECT_GT(std::abs(c.out.Fy), 10.0) << t.name;
      if (k.drive != 0.0 || k.slip != 0.0) EXPECT_GT(std::abs(c.out.Fx), 10.0) << t.name;
    }
    Eigen::MatrixXd Ja;
    ASSERT_TRUE(f.analytic_jacobian(x, u, Ja));
    const Eigen::MatrixXd Jf = plant_jacobian_fd_full(f, x, u, true);
    const double scale = Ja.cwiseAbs().maxCoeff();
    const double worst = (Ja - Jf).cwiseAbs().maxCoeff() / scale;
    // column by column, relative to the column's own size (columns below 1e-3 of the largest entry
    // measured against that floor: their differences are round-off of the large entries)
    double worst_column = 0;
    for (Eigen::Index j = 0; j < Ja.cols(); ++j) {
      const double s = std::max(Ja.col(j).cwiseAbs().maxCoeff(), 1e-3 * scale);
      worst_column = std::max(worst_column, (Ja.col(j) - Jf.col(j)).cwiseAbs().maxCoeff() / s);
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_LT(worst_column, 1e-6);
    const double ad_scale = test::expect_analytic_equals_autodiff(f, x, u, k.label, 1e-12);
    EXPECT_GT(ad_scale, 1.0);
    std::printf("[ TireEffect ] car %s: |exact - central| / max|J| = %.2e (worst column, own scale: %.2e), max|J| = %.3g\n",
                k.label, worst, worst_column, scale);
  }
}

// A car on the road with its dampers and its tires' slip forces off (no slip stiffness, no
// vertical damping) keeps its energy: the chassis on a free joint heaves and pitches on the four
// tires' vertical springs at 20 m/s, the wheels spinning; the energy is the kinetic and
// gravitational one plus the tires' k pen^2 / 2 (pen from study_tire_contacts). Upright wheels (no
// roll: the motion stays in the car's plane of symmetry) make the contact force along the road's
// normal the gradient of that potential (a cambered wheel's is not: docs/tires.md).
TEST(TireEffect, ACarOnTheRoadKeepsItsEnergyWithItsDampersAndSlipsOff) {
  const double k = 250000, U = 20, R0 = 0.3;
  char text[6000];
  std::snprintf(text, sizeof text, R"({"name": "car",
    "bodies": [{"name": "chassis", "mass": 1200, "inertia": [400, 1500, 1700]},
               {"name": "fl", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "fr", "mass": 15, "inertia": [0.4, 0.8, 0.4]},
               {"name": "rl", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "rr", "mass": 15, "inertia": [0.4, 0.8, 0.4]}],
    "joints": [{"name": "body", "type": "free", "parent": "ground", "child": "chassis",
                "q0": [0, 0, 0.29, 1, 0, 0, 0], "v0": [0, 0.2, 0, %.17g, 0, 0.1]},
               {"name": "spin_fl", "type": "revolute", "parent": "chassis", "child": "fl", "axis": [0, 1, 0],
                "parent_frame": {"position": [1.2, 0.8, 0]}, "v0": %.17g},
               {"name": "spin_fr", "type": "revolute", "parent": "chassis", "child": "fr", "axis": [0, 1, 0],
                "parent_frame": {"position": [1.2, -0.8, 0]}, "v0": %.17g},
               {"name": "spin_rl", "type": "revolute", "parent": "chassis", "child": "rl", "axis": [0, 1, 0],
                "parent_frame": {"position": [-1.5, 0.8, 0]}, "v0": %.17g},
               {"name": "spin_rr", "type": "revolute", "parent": "chassis", "child": "rr", "axis": [0, 1, 0],
                "parent_frame": {"position": [-1.5, -0.8, 0]}, "v0": %.17g}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
      {"name": "tire_fl", "type": "tire", "body": "fl", "unloaded_radius": 0.3, "law": "linear", "vertical_stiffness": %.17g},
      {"name": "tire_fr", "type": "tire", "body": "fr", "unloaded_radius": 0.3, "law": "linear", "vertical_stiffness": %.17g},
      {"name": "tire_rl", "type": "tire", "body": "rl", "unloaded_radius": 0.3, "law": "linear", "vertical_stiffness": %.17g},
      {"name": "tire_rr", "type": "tire", "body": "rr", "unloaded_radius": 0.3, "law": "linear", "vertical_stiffness": %.17g}],
    "analysis": {"operating_point": "initial"}})",
                U, U / R0, U / R0, U / R0, U / R0, k, k, k, k);
  const Model mod = study_model(study_parse_model_text(text, "car.json"));
  SimulationOptions so;
  so.t_end = 3.0;
  so.output_step = 0.01;
  so.integrator.method = "cvode-bdf";
  so.integrator.rtol = 1e-11;
  so.integrator.atol = 1e-12;
  const SimulationResult r = simulate(mod, nullptr, nullptr, so);
  ASSERT_TRUE(r.completed) << r.failure;
  double E0 = 0, drift = 0, tire_low = 1e300, tire_high = 0;
  for (int i = 0; i < r.samples(); ++i) {
    double tire = 0;
    for (const TireContactReport& c : study_tire_contacts(mod, r.q.row(i).transpose(), r.v.row(i).transpose())) {
      if (c.in_contact) tire += 0.5 * k * c.penetration * c.penetration;
      EXPECT_EQ(c.Fx, 0.0);  // no slip force
      EXPECT_EQ(c.Fy, 0.0);
      EXPECT_LT(std::abs(c.gamma), 1e-12);  // upright
    }
    const double E = r.kinetic_energy[static_cast<std::size_t>(i)] + r.potential_energy[static_cast<std::size_t>(i)] + tire;
    if (i == 0) E0 = E;
    drift = std::max(drift, std::abs(E - E0));
    tire_low = std::min(tire_low, tire);
    tire_high = std::max(tire_high, tire);
  }
  // the tires' energy swings (the car heaves and pitches on them) while the total stays
  EXPECT_GT(tire_high - tire_low, 10.0);
  EXPECT_LT(drift, 1e-6 * (tire_high - tire_low));
  std::printf("[ TireEffect ] car with dampers and slips off, 3 s at 20 m/s: the tires' energy swings %.4g J, the total "
              "drifts %.2e J\n",
              tire_high - tire_low, drift);
}

// a Magic Formula tire on the ground and a Fiala tire on a road carried by a moving platform (a
// vertical slider, tilted road normal): the exact Jacobian (the road body's derivatives too) equals
// central differences and automatic differentiation, and the road takes the tire's reaction
TEST(TireEffect, AMagicFormulaTireAndARoadOnAMovingBodyDifferentiateExactly) {
  char text[5000];
  std::snprintf(text, sizeof text, R"({"name": "tires",
    "bodies": [{"name": "platform", "mass": 50, "inertia": [1, 1, 1]},
               {"name": "w1", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "w2", "mass": 15, "inertia": [0.4, 0.8, 0.4]}],
    "joints": [{"name": "lift", "type": "prismatic", "parent": "ground", "child": "platform", "axis": [0, 0, 1], "v0": 0.1},
               {"name": "j1", "type": "free", "parent": "ground", "child": "w1", "q0": [0, 0, 0.305, 0.9998, 0.02, 0, 0.01],
                "v0": [0.1, 42, 0.2, 12, 0.5, 0.01]},
               {"name": "j2", "type": "free", "parent": "ground", "child": "w2", "q0": [2, 0, 0.39, 0.999, 0.03, 0, 0.02],
                "v0": [0.05, 38, 0.1, 11, -0.4, 0.02]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
                {"name": "t1", "type": "tire", "body": "w1", "law": "magic_formula", "file": "%s"},
                {"name": "t2", "type": "tire", "body": "w2", "unloaded_radius": 0.3, "law": "fiala", "longitudinal_stiffness": 9e4,
                 "cornering_stiffness": 6e4, "friction": 1, "sliding_friction": 0.8, "width": 0.2, "rolling_resistance": 0.01,
                 "vertical_stiffness": 2.5e5, "vertical_damping": 500,
                 "road": {"body": "platform", "point": [2, 0, 0.1], "normal": [0.02, 0.01, 1]}}],
    "actuators": [{"name": "push", "type": "joint_force", "joint": "lift"}],
    "sensors": [{"name": "h", "type": "joint_position", "joint": "lift"}],
    "plant": {"inputs": ["push"], "outputs": ["h"]}})",
                tire_effect_tir.c_str());
  const Model mod = study_model(study_parse_model_text(text, "tires.json"));
  ASSERT_EQ(mod.tires.size(), 2u);
  ASSERT_EQ(mod.tires[1].road_body, mod.find_body("platform"));
  // the road's reaction: the slider takes minus the tire force along its axis
  Data d(mod);
  forward_kinematics<double>(mod, d, mod.q0, mod.v0);
  TireContact<double> c;
  for (const TireModel& t : mod.tires) {
    ASSERT_TRUE(tire_contact<double>(t, d.oMi[t.body].R, d.oMi[t.body].p, angular_velocity<double>(d, t.body),
                                     point_velocity<double>(d, t.body, Eigen::Vector3d::Zero()), d.oMi[t.road_body].R,
                                     d.oMi[t.road_body].p, angular_velocity<double>(d, t.road_body),
                                     point_velocity<double>(d, t.road_body, Eigen::Vector3d::Zero()), c))
        << t.name;
    EXPECT_GT(c.force.z(), 1000.0) << t.name;
    EXPECT_GT(std::abs(c.out.Fx), 10.0) << t.name;
    EXPECT_GT(std::abs(c.out.Fy), 10.0) << t.name;
  }
  // c: the Fiala tire on the platform
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(mod.nu());
  const Eigen::VectorXd Q = applied_forces<double>(mod, d, mod.q0, mod.v0, u);
  EXPECT_NEAR(Q[mod.joints[mod.find_joint("lift")].idx_v], -c.force.z(), 1e-9 * c.force.z());
  EXPECT_GT(std::abs(c.penetration_rate), 0.01);  // the platform rises under the wheel
  const CoordinatePartition p = partition_coordinates(mod, mod.q0);
  const PlantFunction f(mod, mod.q0, mod.u_nominal(), p);
  const Eigen::VectorXd x = f.qv_to_state(mod.q0, mod.v0);
  const Eigen::VectorXd up = Eigen::VectorXd::Constant(f.nu(), 0.3);
  Eigen::MatrixXd Ja;
  ASSERT_TRUE(f.analytic_jacobian(x, up, Ja));
  const Eigen::MatrixXd Jf = plant_jacobian_fd_full(f, x, up, true);
  const double scale = Ja.cwiseAbs().maxCoeff();
  const double worst = (Ja - Jf).cwiseAbs().maxCoeff() / scale;
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(test::expect_analytic_equals_autodiff(f, x, up, "tires on a moving road", 1e-12), 1.0);
  std::printf("[ TireEffect ] magic formula and moving road: |exact - central| / max|J| = %.2e, max|J| = %.3g\n", worst, scale);
}

// the book's .tir tire on a model equals magic_formula evaluated directly at the slips the contact
// hands it, and the file's [VERTICAL] gives the load
TEST(TireEffect, ATirTireEqualsTheMagicFormulaAtTheSameSlips) {
  char fields[400];
  std::snprintf(fields, sizeof fields, R"("spin_axis": [0, 1, 0], "law": "magic_formula", "file": "%s")", tire_effect_tir.c_str());
  const Model mod = study_model(study_parse_model_text(tire_effect_wheel(fields, "[0, 0, 0.29, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), "w.json"));
  const MagicFormulaParameters mf = read_tir_file(tire_effect_tir);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond qr(Eigen::AngleAxisd(0.05 * U(rng), Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.5 * U(rng), Eigen::Vector3d::UnitZ()));
    Eigen::VectorXd q = mod.q0, v(6);
    q[2] = 0.3 - 0.01 - 0.005 * U(rng);
    q.segment<4>(3) << qr.w(), qr.x(), qr.y(), qr.z();
    v << 0.5 * U(rng), 50 + 20 * U(rng), 0.5 * U(rng), 15 + 5 * U(rng), 2 * U(rng), 0.1 * U(rng);
    bool on = false;
    const TireContact<double> c = tire_effect_contact_at(mod, q, v, &on);
    ASSERT_TRUE(on);
    TireInput<double> in = c.input;
    const TireForces<double> direct = magic_formula<double>(mf, in);
    EXPECT_EQ(c.out.Fx, direct.Fx);
    EXPECT_EQ(c.out.Fy, direct.Fy);
    EXPECT_EQ(c.out.Mz, direct.Mz);
    EXPECT_NEAR(c.force.dot(c.ex), direct.Fx, 1e-12 * std::abs(direct.Fx) + 1e-9);
    EXPECT_NEAR(c.force.dot(c.ey), direct.Fy, 1e-12 * std::abs(direct.Fy) + 1e-9);
    EXPECT_NEAR(c.force.dot(c.ez), mf.VERTICAL_STIFFNESS * c.penetration + mf.VERTICAL_DAMPING * c.penetration_rate, 1e-9);
    EXPECT_NEAR(c.moment.dot(c.ez), direct.Mz, 1e-12 * std::abs(direct.Mz) + 1e-9);
  }
  // mounted on the left: MFeval's MF 6.1 file describes a right tire (TYRESIDE, with lateral shifts),
  // so it is mirrored
  const std::string file61 = std::string(CODYNA_TEST_DATA_DIR) + "/tires/MagicFormula61_Paramerters.tir";
  const MagicFormulaParameters mf61 = read_tir_file(file61);
  ASSERT_EQ(mf61.TYRESIDE, TireSide::Right);
  char left[500];
  std::snprintf(left, sizeof left, R"("spin_axis": [0, 1, 0], "law": "magic_formula", "file": "%s", "side": "left")", file61.c_str());
  const Model mirrored = study_model(study_parse_model_text(tire_effect_wheel(left, "[0, 0, 0.38, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), "w.json"));
  Eigen::VectorXd v(6);
  v << 0.1, 40, 0.2, 15, 1.5, 0;
  bool on = false;
  const TireContact<double> c = tire_effect_contact_at(mirrored, mirrored.q0, v, &on);
  ASSERT_TRUE(on);
  MagicFormulaOptions options;
  options.mount = TireMount::Left;
  const TireForces<double> direct = magic_formula<double>(mf61, c.input, options);
  EXPECT_EQ(c.out.Fy, direct.Fy);
  EXPECT_EQ(c.out.Mz, direct.Mz);
  EXPECT_GT(std::abs(c.out.Fy - magic_formula<double>(mf61, c.input).Fy), 1.0);
}

// ------------------------------------------------------------------ the model file

ModelError tire_effect_refusal(const std::string& tire_fields, const std::string& label = "bad.json") {
  try {
    (void)study_model(study_parse_model_text(tire_effect_wheel(tire_fields, "[0, 0, 0.29, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), label),
                      label);
  } catch (const ModelError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted: " << tire_fields;
  return ModelError("", "", "");
}

TEST(TireEffect, BadInputIsRefusedAtTheField) {
  const std::string base = R"("unloaded_radius": 0.3, "vertical_stiffness": 200000, )";
  ModelError e = tire_effect_refusal(base + R"("spin_axis": [0, 0, 0], "law": "linear")");
  EXPECT_EQ(e.file(), "bad.json");
  EXPECT_EQ(e.path(), "/effects/1/spin_axis");
  e = tire_effect_refusal(base + R"("law": "linear", "cornering_stiffness": -5)");
  EXPECT_EQ(e.path(), "/effects/1/cornering_stiffness");
  e = tire_effect_refusal(R"("unloaded_radius": 0.3, "vertical_stiffness": -200000, "law": "linear")");
  EXPECT_EQ(e.path(), "/effects/1/vertical_stiffness");
  e = tire_effect_refusal(base + R"("law": "brush")");
  EXPECT_EQ(e.path(), "/effects/1/law");
  EXPECT_NE(std::string(e.what()).find("linear, fiala, magic_formula"), std::string::npos) << e.what();
  e = tire_effect_refusal(base + R"("law": "linear", "file": "x.tir")");
  EXPECT_EQ(e.path(), "/effects/1/file");
  e = tire_effect_refusal(base + R"("law": "linear", "side": "left")");
  EXPECT_EQ(e.path(), "/effects/1/side");
  e = tire_effect_refusal(R"("vertical_stiffness": 200000, "law": "linear")");
  EXPECT_EQ(e.path(), "/effects/1");
  EXPECT_NE(std::string(e.what()).find("unloaded_radius"), std::string::npos) << e.what();
  e = tire_effect_refusal(base + R"("law": "linear", "road": {"normal": [0, 0, 0]})");
  EXPECT_EQ(e.path(), "/effects/1/road/normal");
  // a .tir that is not there, and one that does not read: the reader's message after the field
  e = tire_effect_refusal(R"("law": "magic_formula", "file": "no_such_tire.tir")");
  EXPECT_EQ(e.path(), "/effects/1/file");
  EXPECT_NE(std::string(e.what()).find("no_such_tire.tir"), std::string::npos) << e.what();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "codyna_tire_effect_test";
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir / "broken.tir");
    out << "[UNITS]\nLENGTH = 'meter'\n[MODEL]\nFITTYP = 99\n";
  }
  const std::string model_file = (dir / "car.json").string();
  e = tire_effect_refusal(R"("law": "magic_formula", "file": "broken.tir")", model_file);
  EXPECT_EQ(e.file(), model_file);
  EXPECT_EQ(e.path(), "/effects/1/file");
  EXPECT_NE(std::string(e.what()).find("broken.tir"), std::string::npos) << e.what();
  std::printf("[ TireEffect ] %s\n", e.what());
  // the file's own values are not given twice
  char fields[400];
  std::snprintf(fields, sizeof fields, R"("law": "magic_formula", "file": "%s", "unloaded_radius": 0.3)", tire_effect_tir.c_str());
  e = tire_effect_refusal(fields);
  EXPECT_EQ(e.path(), "/effects/1/unloaded_radius");
  std::filesystem::remove_all(dir);
  // a spec built in code: the compiler refuses what the reader would
  ModelSpec spec = study_parse_model_text(tire_effect_wheel(base + R"("law": "linear")", "[0, 0, 0.29, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), "code");
  spec.effects[1].spin_axis.setZero();
  try {
    (void)study_model(spec);
    ADD_FAILURE() << "a zero spin axis was accepted";
  } catch (const ModelError& x) {
    EXPECT_EQ(x.path(), "/effects/1/spin_axis");
  }
  spec.effects[1].spin_axis = Eigen::Vector3d::UnitY();
  spec.effects[1].law = "brush";
  try {
    (void)study_model(spec);
    ADD_FAILURE() << "an unknown law was accepted";
  } catch (const ModelError& x) {
    EXPECT_EQ(x.path(), "/effects/1/law");
  }
}

TEST(TireEffect, TheModelFileRoundTripsEveryLaw) {
  char mf_fields[400];
  std::snprintf(mf_fields, sizeof mf_fields, R"("law": "magic_formula", "file": "%s", "road": {"body": "ground", "point": [0, 0, -0.01], "normal": [0, 0.1, 1]})",
                tire_effect_tir.c_str());
  for (const std::string& fields :
       {std::string(tire_effect_linear_fields) + R"(, "friction": 0.9, "trail": 0.02, "rolling_radius": 0.29, "low_speed": 0.3)",
        std::string(R"("unloaded_radius": 0.31, "law": "fiala", "longitudinal_stiffness": 1e5, "cornering_stiffness": 8e4,
                       "friction": 1.1, "sliding_friction": 0.9, "width": 0.2, "rolling_resistance": 0.012, "vertical_stiffness": 2e5)"),
        std::string(mf_fields), std::string(mf_fields) + R"(, "side": "left")"}) {
    const ModelSpec a = study_parse_model_text(tire_effect_wheel(fields, "[0, 0, 0.29, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]"), "a.json");
    const nlohmann::json j = study_model_json(a);
    const ModelSpec b = study_parse_model(j, "b.json");
    EXPECT_EQ(study_model_json(b), j);
    const EffectSpec &ea = a.effects[1], &eb = b.effects[1];
    EXPECT_EQ(eb.type, EffectType::Tire);
    EXPECT_EQ(eb.law, ea.law);
    EXPECT_EQ(eb.file, ea.file);
    EXPECT_EQ(eb.side, ea.side);
    EXPECT_EQ(eb.unloaded_radius, ea.unloaded_radius);
    EXPECT_EQ(eb.rolling_radius, ea.rolling_radius);
    EXPECT_EQ(eb.cornering_stiffness, ea.cornering_stiffness);
    EXPECT_EQ(eb.sliding_friction, ea.sliding_friction);
    EXPECT_EQ(eb.vertical_stiffness, ea.vertical_stiffness);
    EXPECT_EQ(eb.road.normal, ea.road.normal);
    EXPECT_EQ(eb.low_speed, ea.low_speed);
    // and compiles to the same tire
    const Model ma = study_model(a), mb = study_model(b);
    EXPECT_EQ(ma.tires.at(0).C_alpha, mb.tires.at(0).C_alpha);
    EXPECT_EQ(ma.tires.at(0).road_normal, mb.tires.at(0).road_normal);
  }
}

// ------------------------------------------------------------------ the single-track car

// Rajamani's linear single-track model (VEHICLES.md): states v, r; input delta
struct TireEffectBicycle {
  double m = 1573, Iz = 2873, a = 1.1, b = 1.58, Cf = 160000, Cr = 160000, U = 30;
  double L() const { return a + b; }
  double K() const { return m / L() * (b / Cf - a / Cr); }
  // r / delta and v / delta at s
  std::complex<double> yaw(std::complex<double> s) const {
    const auto [A, B] = matrices();
    Eigen::Matrix2cd M = s * Eigen::Matrix2cd::Identity() - A.cast<std::complex<double>>();
    return (M.inverse() * B.cast<std::complex<double>>())(1);
  }
  std::complex<double> lateral(std::complex<double> s) const {
    const auto [A, B] = matrices();
    Eigen::Matrix2cd M = s * Eigen::Matrix2cd::Identity() - A.cast<std::complex<double>>();
    return (M.inverse() * B.cast<std::complex<double>>())(0);
  }
  // a_y = v' + U r
  std::complex<double> lateral_acceleration(std::complex<double> s) const { return s * lateral(s) + U * yaw(s); }
  std::pair<Eigen::Matrix2d, Eigen::Vector2d> matrices() const {
    Eigen::Matrix2d A;
    A << -(Cf + Cr) / (m * U), -(a * Cf - b * Cr) / (m * U) - U,  //
        -(a * Cf - b * Cr) / (Iz * U), -(a * a * Cf + b * b * Cr) / (Iz * U);
    return {A, Eigen::Vector2d(Cf / m, a * Cf / Iz)};
  }
};

TEST(TireEffect, SingleTrackCarIsTheBicycleModel) {
  const ModelSpec spec = study_read_model(test::example_path("single_track_car.json"));
  const Model mod = study_model(spec);
  ASSERT_EQ(mod.tires.size(), 2u);
  const LinearSystem s = study_linearize(mod).system;
  ASSERT_EQ(s.B.cols(), 1);
  ASSERT_EQ(s.C.rows(), 3);
  ASSERT_EQ(s.output_names[0], "yaw_rate");
  ASSERT_EQ(s.output_names[1], "lateral_velocity");
  ASSERT_EQ(s.output_names[2], "lateral_acceleration");  // an acceleration sensor (issue 39)
  EXPECT_EQ(s.output_units[2], "m/s^2");
  // the steer input enters by its value only (massless wheels: no rate or acceleration columns)
  if (s.state_rate_shift.size() > 0) EXPECT_EQ(s.state_rate_shift.cwiseAbs().maxCoeff(), 0.0);
  const TireEffectBicycle bike;
  const int n = static_cast<int>(s.A.rows());
  const auto model_tf = [&](std::complex<double> sc, int output) {
    const Eigen::MatrixXcd M = sc * Eigen::MatrixXcd::Identity(n, n) - s.A.cast<std::complex<double>>();
    const Eigen::VectorXcd xs = M.partialPivLu().solve(s.B.cast<std::complex<double>>());
    return (s.C.row(output).cast<std::complex<double>>() * xs)(0) + s.D(output, 0);
  };
  double worst_r = 0, worst_v = 0, worst_ay = 0, worst_sensor = 0;
  for (int i = 0; i <= 60; ++i) {
    const double w = 0.1 * std::pow(1000.0, i / 60.0);  // 0.1 .. 100 rad/s
    const std::complex<double> sc(0.0, w);
    const std::complex<double> r = model_tf(sc, 0), v = model_tf(sc, 1);
    const std::complex<double> ay = sc * v + bike.U * r;  // a_y = v' + U r
    const std::complex<double> ay_sensor = model_tf(sc, 2);  // the chassis CG's acceleration, its own y
    worst_r = std::max(worst_r, std::abs(r - bike.yaw(sc)) / std::abs(bike.yaw(sc)));
    worst_v = std::max(worst_v, std::abs(v - bike.lateral(sc)) / std::abs(bike.lateral(sc)));
    worst_ay = std::max(worst_ay, std::abs(ay - bike.lateral_acceleration(sc)) / std::abs(bike.lateral_acceleration(sc)));
    worst_sensor = std::max(worst_sensor, std::abs(ay_sensor - bike.lateral_acceleration(sc)) / std::abs(bike.lateral_acceleration(sc)));
  }
  EXPECT_LT(worst_r, 1e-8);
  EXPECT_LT(worst_v, 1e-8);
  EXPECT_LT(worst_ay, 1e-8);
  EXPECT_LT(worst_sensor, 1e-8);
  // the steer reaches the lateral acceleration directly: D = C_f / m, the closed form's s -> infinity
  // limit (s v(s) -> B_v = C_f / m, U r(s) -> 0); the yaw rate and lateral velocity have none
  EXPECT_NEAR(s.D(2, 0), bike.Cf / bike.m, 1e-8 * bike.Cf / bike.m);
  EXPECT_EQ(s.D(0, 0), 0.0);
  EXPECT_EQ(s.D(1, 0), 0.0);
  // the same D by automatic differentiation and by central differences of the plant function
  LinearizeOptions central;
  central.method = JacobianMethod::CentralDifference;
  const LinearSystem sc = linearize(mod, study_operating_point(mod), central).system;
  EXPECT_NEAR(sc.D(2, 0), s.D(2, 0), 1e-6 * s.D(2, 0));
  // the steady state: understeer gradient and the yaw-rate gain U / (L + K U^2)
  const double K = bike.K(), L = bike.L(), U = bike.U;
  const double gain = U / (L + K * U * U);
  EXPECT_NEAR(std::abs(bike.yaw(std::complex<double>(0.0, 0.0))), gain, 1e-12 * gain);
  const double dc = model_tf(std::complex<double>(0.0, 1e-5), 0).real();
  EXPECT_NEAR(dc, gain, 1e-6 * gain);
  std::printf("[ TireEffect ] single track: largest relative TF difference over 0.1..100 rad/s: r %.2e, v %.2e, a_y %.2e, "
              "a_y sensor %.2e; D(a_y, steer) = %.12g (C_f / m = %.12g)\n",
              worst_r, worst_v, worst_ay, worst_sensor, s.D(2, 0), bike.Cf / bike.m);
  std::printf("[ TireEffect ] K = %.6g rad/(m/s^2) (%.4g deg/g), characteristic speed %.4g m/s, yaw-rate gain %.6g 1/s (model %.6g)\n",
              K, K * 180 / M_PI * 9.81, K > 0 ? std::sqrt(L / K) : 0.0, gain, dc);
}

}  // namespace
}  // namespace codyna
