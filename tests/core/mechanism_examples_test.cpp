// The mechanisms issue 19 names, as shipped in examples/ (checked from outside by their names):
// the geared pendulum (a rotor coupled through a gear: N^2 J_m and N tau_m, and its energy,
// rotor included, conserved in a nonlinear run) and the quadrotor at hover (four mixed rotors:
// the trim solves each to m g / 4, and A, B equal the standard hover model). The ball and beam
// and the bus suspension, which need motion inputs, are checked in motion_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

TEST(MechanismExamples, GearedPendulumReflectsTheRotorThroughTheGear) {
  const Model m = test::load_example("geared_pendulum.json");
  EXPECT_EQ(m.dof(), 1);
  const LinearSystem s = study_linearize(m).system;
  const double Jm = 1e-4, N = 50, mr = 0.5, l = 0.4, g = 9.81;
  const double I = mr * l * l / 3 + N * N * Jm;
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2), D(1, 1);
  A << 0, 1, -mr * g * (l / 2) / I, 0;
  B << 0, N / I;
  C << 1, 0;
  D << 0;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  EXPECT_TRUE(MatrixNear(s.C, C, 1e-15));
  EXPECT_TRUE(MatrixNear(s.D, D, 1e-15));
}

TEST(MechanismExamples, GearedPendulumConservesItsEnergyRotorIncluded) {
  ModelSpec spec = study_read_model(test::example_path("geared_pendulum.json"));
  for (JointSpec& j : spec.joints) {
    if (j.name == "theta") j.q0 = Eigen::VectorXd::Constant(1, 0.6);
    if (j.name == "motor") j.q0 = Eigen::VectorXd::Constant(1, 30.0);  // the gear: motor = 50 theta
  }
  spec.analysis.controller = "none";
  spec.solver.rtol = 1e-10;
  spec.solver.atol = 1e-12;
  spec.solver.t_end = 2.0;
  const Model m = study_model(spec);
  const SimulationResult r = study_simulate(m, study_simulation(m));
  ASSERT_TRUE(r.completed) << r.failure;
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  double drift = 0, swing = 0;
  for (int i = 0; i < r.samples(); ++i) {
    drift = std::max(drift, std::abs(r.kinetic_energy[i] + r.potential_energy[i] - E0));
    swing = std::max(swing, r.kinetic_energy[i]);
  }
  // the rotor carries N^2 Jm / (m l^2/3 + N^2 Jm) = 90 % of the kinetic energy: leaving it out
  // would break the balance by far more than the tolerance
  EXPECT_GT(swing, 0.1);
  EXPECT_LT(drift, 1e-7 * swing);
}

TEST(MechanismExamples, QuadrotorTrimsEachRotorToAQuarterOfItsWeightAndMatchesTheHoverModel) {
  const Model m = test::load_example("quadrotor.json");
  const StudyLinearization sl = study_linearize(m);
  const LinearSystem& s = sl.system;
  const double mass = 1.2, g = 9.81, Ixx = 0.012, Iyy = 0.012, Izz = 0.022, arm = 0.2, c = 0.016;
  ASSERT_EQ(s.nu(), 4);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(s.u0[k], mass * g / 4, 1e-12) << "rotor" << k + 1;
  ASSERT_EQ(s.nx(), 12);
  // states: base.rx ry rz x y z, then base.wx wy wz vx vy vz (body axes, level at hover)
  EXPECT_EQ(s.state_names[1], "base.ry");
  EXPECT_EQ(s.state_names[9], "base.vx");
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(12, 12), B = Eigen::MatrixXd::Zero(12, 4);
  A.topRightCorner(6, 6).setIdentity();
  A(9, 1) = g;   // x'' = g pitch
  A(10, 0) = -g;  // y'' = -g roll
  // rotors at (arm, 0), (0, arm), (-arm, 0), (0, -arm); yaw reaction +c, -c, +c, -c
  const double x[4] = {arm, 0, -arm, 0}, y[4] = {0, arm, 0, -arm}, yaw[4] = {c, -c, c, -c};
  for (int k = 0; k < 4; ++k) {
    B(6, k) = y[k] / Ixx;
    B(7, k) = -x[k] / Iyy;
    B(8, k) = yaw[k] / Izz;
    B(11, k) = 1 / mass;
  }
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(6, 12);
  C(0, 3) = C(1, 4) = C(2, 5) = 1;  // x, y, z
  C(3, 0) = C(4, 1) = C(5, 2) = 1;  // roll, pitch, yaw
  EXPECT_TRUE(MatrixNear(s.C, C, 1e-12));
  EXPECT_TRUE(MatrixNear(s.D, Eigen::MatrixXd::Zero(6, 4), 1e-15));
}

}  // namespace
}  // namespace codyna
