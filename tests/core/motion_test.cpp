// Motion inputs (issue 19): a joint coordinate that follows a Plant/In u (a beam angle, the road
// under a tire) with its rate u' and acceleration u''. The linearization takes the Jacobian over
// [u; u'; u''] and removes the derivatives by the change of state xi = x - B2 u' - (A B2 + B1) u
// (core/analysis/linearize.cpp), so that the exported A, B, C, D reproduce the transfer function
// from the displacement input exactly. Checked against closed forms derived by hand: the CTMS
// ball and beam (a feedthrough the CTMS form drops), the CTMS bus suspension's two published
// transfer functions, and a pendulum on a shaker (a support's acceleration); the exact Jacobian
// over u' and u'' against central differences at random states; bad models refused at the field.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using cd = std::complex<double>;
using test::MatrixNear;

// G(s) = C (sI - A)^-1 B + D, entry (i, j)
cd transfer(const LinearSystem& s, cd z, int i, int j) {
  const Eigen::MatrixXcd M = z * Eigen::MatrixXcd::Identity(s.nx(), s.nx()) - s.A.cast<cd>();
  const Eigen::VectorXcd x = M.partialPivLu().solve(s.B.col(j).cast<cd>());
  return (s.C.row(i).cast<cd>() * x)(0) + s.D(i, j);
}

const double kFrequencies[10] = {0.05, 0.2, 0.7, 1.5, 3.0, 6.0, 10.0, 25.0, 60.0, 200.0};  // rad/s

ModelSpec parse_motion(const std::string& text) { return study_parse_model_text(text, "motion_test.json"); }

TEST(Motion, BallAndBeamKeepsTheFeedthroughOfTheBeamsAcceleration) {
  const Model m = test::load_example("ball_beam.json");
  EXPECT_EQ(m.dof(), 1);
  const LinearSystem s = study_linearize(m).system;
  ASSERT_EQ(s.nx(), 2);
  ASSERT_EQ(s.nu(), 1);
  const double mb = 0.111, R = 0.015, J = 9.99e-6, g = 9.8, Me = mb + J / (R * R);
  double worst = 0;
  for (double w : kFrequencies) {
    const cd z(0, w);
    const cd expected = ((J / R) * z * z - mb * g) / (Me * z * z);
    worst = std::max(worst, std::abs(transfer(s, z, 0, 0) - expected) / std::abs(expected));
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(s.D(0, 0), (J / R) / Me, 1e-15);
  // the state is the ball's position and rate, shifted by the beam's motion (docs: motion), and
  // named so: r~ is r - (J/R)/Me theta (the beam's angle), not the ball's position alone
  EXPECT_EQ(s.state_names[0], "r~");
  EXPECT_NEAR(s.state_shift(0, 0), (J / R) / Me, 1e-15);
  EXPECT_EQ(state_meaning(s, 0).rfind("r - ", 0), 0u) << state_meaning(s, 0);
  EXPECT_NEAR(s.x0[0], 0.5, 1e-15);
}

TEST(Motion, BusSuspensionReproducesBothPublishedTransferFunctions) {
  const Model m = test::load_example("bus_suspension.json");
  EXPECT_EQ(m.dof(), 2);
  const StudyLinearization sl = study_linearize(m);
  const LinearSystem& s = sl.system;
  ASSERT_EQ(s.nx(), 4);
  ASSERT_EQ(s.nu(), 2);
  ASSERT_EQ(s.input_names[0], "U");
  ASSERT_EQ(s.input_names[1], "W");
  const double m1 = 2500, m2 = 320, k1 = 80000, k2 = 500000, b1 = 350, b2 = 15020;
  double worst_u = 0, worst_w = 0;
  for (double w : kFrequencies) {
    const cd z(0, w);
    const cd delta = (m1 * z * z + b1 * z + k1) * (m2 * z * z + (b1 + b2) * z + (k1 + k2)) - (b1 * z + k1) * (b1 * z + k1);
    const cd gu = ((m1 + m2) * z * z + b2 * z + k2) / delta;
    const cd gw = (-m1 * b2 * z * z * z - m1 * k2 * z * z) / delta;
    worst_u = std::max(worst_u, std::abs(transfer(s, z, 0, 0) - gu) / std::abs(gu));
    worst_w = std::max(worst_w, std::abs(transfer(s, z, 0, 1) - gw) / std::abs(gw));
  }
  EXPECT_LT(worst_u, 1e-9);
  EXPECT_LT(worst_w, 1e-9);
  // about the static equilibrium: nothing accelerates, the springs carry the weights
  EXPECT_LT(s.xdot0.cwiseAbs().maxCoeff(), 1e-9);
}

// a uniform rod (mass m, length l) hanging from a pivot on a table that slides along x, the
// table's position a motion input: I theta'' = -m g c sin(theta) - m c cos(theta) x'' (c = l/2,
// I = m l^2/3 about the pivot), so Theta(s)/X(s) = -m c s^2 / (I s^2 + m g c)
std::string shaker(const std::string& outputs) {
  return R"({"name": "shaker",
    "bodies": [{"name": "table", "mass": 0, "inertia": [0, 0, 0]},
               {"name": "rod", "mass": 0.8, "com": [0, -0.3, 0], "inertia": [0.024, 1e-6, 0.024]}],
    "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "table", "axis": [1, 0, 0], "q0": 0.1},
               {"name": "theta", "type": "revolute", "parent": "table", "child": "rod", "axis": [0, 0, 1]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "table", "type": "motion", "joint": "x"}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "theta"},
                {"name": "rate", "type": "joint_velocity", "joint": "theta"},
                {"name": "tip_x", "type": "point_position", "body": "rod", "point": [0, -0.6, 0], "component": 0}],
    "plant": {"inputs": ["table"], "outputs": )" + outputs + R"(},
    "analysis": {"operating_point": "initial"}})";
}

TEST(Motion, PendulumOnAShakerFollowsTheSupportsAcceleration) {
  const LinearSystem s = study_linearize(study_model(parse_motion(shaker(R"(["angle", "tip_x"])")))).system;
  const double m = 0.8, l = 0.6, c = l / 2, g = 9.81, I = m * l * l / 3;
  ASSERT_EQ(s.nx(), 2);
  double worst = 0;
  for (double w : kFrequencies) {
    const cd z(0, w);
    const cd theta = -m * c * z * z / (I * z * z + m * g * c);
    // the tip: the table's motion plus l theta (small angles)
    const cd tip = 1.0 + l * theta;
    worst = std::max(worst, std::abs(transfer(s, z, 0, 0) - theta) / std::abs(theta));
    worst = std::max(worst, std::abs(transfer(s, z, 1, 0) - tip) / std::abs(tip));
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(s.y0[1], 0.1, 1e-15);  // the table stands at its q0
}

TEST(Motion, AnOutputThatFeelsTheInputsRateIsRefusedNamingBoth) {
  try {
    study_linearize(study_model(parse_motion(shaker(R"(["rate"])"))));
    FAIL() << "expected a refusal";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\"rate\""), std::string::npos) << what;
    EXPECT_NE(what.find("\"table\""), std::string::npos) << what;
    EXPECT_NE(what.find("improper"), std::string::npos) << what;
  }
}

TEST(Motion, ExactJacobianOverRatesAndAccelerationsAgreesWithCentralDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const char* file : {"ball_beam.json", "bus_suspension.json"}) {
    const Model m = test::load_example(file);
    const CoordinatePartition p = partition_coordinates(m, m.q0);
    const PlantFunction f(m, m.q0, m.u_nominal(), p);
    ASSERT_GT(f.nm(), 0);
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x(f.nx()), u(f.nu() + 2 * f.nm());
      for (int k = 0; k < x.size(); ++k) x[k] = 0.3 * U(rng);
      for (int k = 0; k < u.size(); ++k) u[k] = 0.2 * U(rng);
      const Eigen::MatrixXd exact = plant_jacobian(f, x, u, JacobianMethod::Exact);
      const Eigen::MatrixXd fd = plant_jacobian_fd_full(f, x, u, true);
      const double scale = std::max(1.0, exact.cwiseAbs().maxCoeff());
      EXPECT_LT((exact - fd).cwiseAbs().maxCoeff() / scale, 1e-8) << file << " trial " << trial;
      // the rate and acceleration columns are not all zero: the test can fail
      EXPECT_GT(exact.rightCols(2 * f.nm()).cwiseAbs().maxCoeff(), 1e-3) << file;
    }
  }
}

// The analytic Jacobian (tree derivatives with one held-acceleration row per motion, solved on the
// free coordinates; the loops' velocity maps extended over the motions' coordinates) against
// automatic differentiation of the same dynamics and central differences, at the reference
// configuration with random velocities, force inputs, motion rates and accelerations. The models:
// the bus (a tree; the road body massless), the ball and beam (a coupler: a loop row), the shaker
// pendulum, and the ball and beam with its beam angle outside Plant/In (a motion held at rest).
TEST(Motion, AnalyticJacobianAgreesWithAutodiffAndCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<std::pair<std::string, Model>> models;
  for (const char* file : {"ball_beam.json", "bus_suspension.json"}) models.emplace_back(file, test::load_example(file));
  models.emplace_back("shaker", study_model(parse_motion(shaker(R"(["angle", "tip_x"])"))));
  for (const auto& [name, m] : models) {
    const CoordinatePartition p = partition_coordinates(m, m.q0);
    const PlantFunction f(m, m.q0, m.u_nominal(), p);
    ASSERT_GT(f.nm(), 0) << name;
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), u(f.nu() + 2 * f.nm());
      for (int k = f.nz(); k < x.size(); ++k) x[k] = 0.4 * U(rng);
      for (int k = 0; k < u.size(); ++k) u[k] = 0.3 * U(rng);
      for (int j = 0; j < f.nm(); ++j) u[f.motion_inputs()[j]] = m.u_nominal()[m.plant_inputs[f.motion_inputs()[j]]];
      Eigen::MatrixXd analytic;
      ASSERT_TRUE(f.analytic_jacobian(x, u, analytic)) << name;
      const Eigen::MatrixXd ad = plant_jacobian_autodiff(f, x, u);
      const Eigen::MatrixXd fd = plant_jacobian_fd_full(f, x, u, true);
      ASSERT_EQ(analytic.rows(), ad.rows());
      ASSERT_EQ(analytic.cols(), ad.cols());
      const double scale = std::max(1.0, ad.cwiseAbs().maxCoeff());
      EXPECT_LT((analytic - ad).cwiseAbs().maxCoeff() / scale, 1e-12) << name << " trial " << trial << "\n"
                                                                       << analytic << "\n\n" << ad;
      EXPECT_LT((analytic - fd).cwiseAbs().maxCoeff() / scale, 1e-8) << name << " trial " << trial;
      // the motions' value, rate and acceleration columns are not all zero: the test can fail
      EXPECT_GT(analytic.rightCols(2 * f.nm()).cwiseAbs().maxCoeff(), 1e-3) << name;
      for (int j = 0; j < f.nm(); ++j)
        EXPECT_GT(analytic.col(f.nx() + f.motion_inputs()[j]).cwiseAbs().maxCoeff(), 1e-3) << name;
      // without the rate and acceleration columns (the motions at rest): the first columns of the
      // Jacobian taken with zero rates and accelerations
      Eigen::MatrixXd plain, at_rest;
      Eigen::VectorXd u_rest = u;
      u_rest.tail(2 * f.nm()).setZero();
      ASSERT_TRUE(f.analytic_jacobian(x, u.head(f.nu()), plain)) << name;
      ASSERT_TRUE(f.analytic_jacobian(x, u_rest, at_rest)) << name;
      EXPECT_EQ(plain, at_rest.leftCols(f.nx() + f.nu())) << name;
    }
  }
  // a motion outside Plant/In: held at its nominal value, at rest
  ModelSpec spec = load_model_spec(test::example_path("ball_beam.json"));
  ASSERT_EQ(spec.plant.inputs.size(), 1u);
  spec.plant.inputs.clear();
  const Model m = study_model(spec);
  const PlantFunction f(m, m.q0, m.u_nominal(), partition_coordinates(m, m.q0));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), u(0);
  for (int k = f.nz(); k < x.size(); ++k) x[k] = 0.25 + 0.1 * k;
  Eigen::MatrixXd analytic;
  ASSERT_TRUE(f.analytic_jacobian(x, u, analytic));
  const Eigen::MatrixXd ad = plant_jacobian_autodiff(f, x, u);
  EXPECT_LT((analytic - ad).cwiseAbs().maxCoeff() / std::max(1.0, ad.cwiseAbs().maxCoeff()), 1e-12);
}

// The shaker with its table's reaction as a sensor, the table moved by a disturbance signal (or
// held), a motor on the rod as the Plant/In
std::string shaker_with_reaction(const std::string& inputs, const std::string& outputs, const std::string& extra) {
  std::string t = shaker(outputs);
  const auto put = [&](const std::string& from, const std::string& to) {
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
  };
  put(R"({"name": "table", "type": "motion", "joint": "x"})",
      R"({"name": "table", "type": "motion", "joint": "x"}, {"name": "motor", "type": "joint_force", "joint": "theta"})");
  put(R"({"name": "rate", "type": "joint_velocity", "joint": "theta"},)",
      R"({"name": "rate", "type": "joint_velocity", "joint": "theta"}, {"name": "force", "type": "motion_force", "joint": "x"},)");
  put(R"("inputs": ["table"])", R"("inputs": )" + inputs);
  put(R"("analysis": {"operating_point": "initial"})", R"("analysis": {"operating_point": "initial")" + extra + "}");
  return t;
}

// The reaction a motion input supplies (sensor motion_force): the table is massless, so it is the
// horizontal force that accelerates the rod's centre, F = m (x'' + c (theta'' cos - theta'^2 sin)),
// with the rod's own equation about the moving pivot, I theta'' = -m c (g sin theta + x'' cos theta).
// In a run with the table shaken by a sine, sample by sample; linearized with the table held, the
// proper model F = m c theta'' (a feedthrough from the motor); with the table as Plant/In refused
// (F responds to its acceleration: improper); on a coordinate no motion drives, refused at the field.
TEST(Motion, TheReactionOfAMotionIsASensor) {
  const double m = 0.8, l = 0.6, c = l / 2, g = 9.81, I = m * l * l / 3, A = 0.05, w = 2 * std::numbers::pi * 0.7;
  const Model run = study_model(parse_motion(shaker_with_reaction(
      "[]", R"(["angle", "rate", "force"])",
      R"(, "controller": "none", "disturbances": [{"actuator": "table", "type": "sine", "amplitude": 0.05, "frequency": 0.7}])")));
  ModelSpec spec = run.spec;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.solver.t_end = 2.0;
  spec.solver.output_step = 0.02;
  const Model tight = study_model(spec);
  const SimulationResult r = study_simulate(tight, study_simulation(tight));
  ASSERT_TRUE(r.completed) << r.failure;
  double worst = 0, largest = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[i], th = r.y(i, 0), thd = r.y(i, 1);
    const double xdd = -A * w * w * std::sin(w * t);
    const double thdd = -(m * c / I) * (g * std::sin(th) + xdd * std::cos(th));
    const double F = m * (xdd + c * (thdd * std::cos(th) - thd * thd * std::sin(th)));
    worst = std::max(worst, std::abs(r.y(i, 2) - F));
    largest = std::max(largest, std::abs(F));
  }
  EXPECT_GT(largest, 0.3);  // the table was shaken hard enough to need a force
  EXPECT_LT(worst, 1e-9 * largest) << "largest " << largest;

  // held table, the motor as Plant/In: F = m c theta'' = (m c / I) (tau - m g c theta)
  const LinearSystem s =
      study_linearize(study_model(parse_motion(shaker_with_reaction(R"(["motor"])", R"(["angle", "force"])", "")))).system;
  ASSERT_EQ(s.nx(), 2);
  EXPECT_NEAR(s.C(1, 0), -(m * c / I) * m * g * c, 1e-12);
  EXPECT_NEAR(s.C(1, 1), 0.0, 1e-12);
  EXPECT_NEAR(s.D(1, 0), m * c / I, 1e-12);
  EXPECT_NEAR(s.A(1, 0), -m * g * c / I, 1e-12);
  // the table as Plant/In: the reaction responds to its acceleration
  try {
    study_linearize(study_model(parse_motion(shaker_with_reaction(R"(["table"])", R"(["force"])", ""))));
    FAIL() << "expected a refusal";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\"force\""), std::string::npos) << what;
    EXPECT_NE(what.find("acceleration"), std::string::npos) << what;
  }
  // a controller that measures the reaction: an algebraic loop, refused naming it
  try {
    std::string text = shaker_with_reaction(R"(["motor"])", R"(["force"])", "");
    text.replace(text.find(R"("plant":)"), 8, R"("controller": {"type": "pid", "kp": [[0.1]]}, "plant":)");
    const Model pid = study_model(parse_motion(text));
    study_simulate(pid, study_simulation(pid));
    FAIL() << "expected a refusal";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\"force\""), std::string::npos) << what;
    EXPECT_NE(what.find("algebraic loop"), std::string::npos) << what;
  }
  // on a coordinate no motion drives
  std::string bad = shaker_with_reaction("[]", R"(["angle"])", "");
  const std::string from = R"("type": "motion_force", "joint": "x")";
  bad.replace(bad.find(from), from.size(), R"("type": "motion_force", "joint": "theta")");
  try {
    parse_motion(bad);
    study_model(parse_motion(bad));
    FAIL() << "expected a refusal";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path().rfind("/sensors/2/joint", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("x (by \"table\")"), std::string::npos) << e.what();
  }
}

TEST(Motion, BadMotionInputsAreRefusedAtTheField) {
  const auto error_path = [](const std::string& text) {
    try {
      study_model(parse_motion(text));
    } catch (const ModelError& e) {
      return e.path() + ": " + e.what();
    }
    return std::string("no error");
  };
  const std::string base = shaker(R"(["angle"])");
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  const std::string motion = R"({"name": "table", "type": "motion", "joint": "x"})";
  EXPECT_EQ(error_path(with(motion, R"({"name": "table", "type": "motion", "joint": "nope"})")).rfind("/actuators/0/joint", 0), 0u);
  EXPECT_EQ(error_path(with(motion, R"({"name": "table", "type": "motion", "joint": "x", "gain": 2})")).rfind("/actuators/0/gain", 0), 0u);
  EXPECT_EQ(error_path(with(motion, R"({"name": "table", "type": "motion", "joint": "x", "u0": 0.3})")).rfind("/actuators/0/", 0), 0u);
  EXPECT_EQ(error_path(with(motion, motion + R"(, {"name": "again", "type": "motion", "joint": "x"})")).rfind("/actuators/1/joint", 0), 0u);
  EXPECT_EQ(error_path(with(motion, motion + R"(, {"name": "m", "type": "mix", "drives": ["table"], "weights": [1]})")).rfind("/actuators/1/drives/0", 0), 0u);
  EXPECT_EQ(error_path(with(R"("q0": 0.1})", R"("q0": 0.1, "v0": 0.5})")).rfind("/joints/0/v0", 0), 0u);
  // a loop over-driven: the table coupled to the rod's angle, and both driven (a motion on a
  // loop's coordinate is fine while the loop leaves the others free: tests/core/motion_loop_test.cpp)
  const std::string looped = with(R"("effects")", R"("constraints": [{"name": "link", "type": "coupler", "joint_a": "x", "ratio_a": 1, "joint_b": "theta", "ratio_b": 0.5}], "effects")");
  EXPECT_EQ(error_path(looped), "no error");
  std::string overdriven = with(motion, motion + R"(, {"name": "rod", "type": "motion", "joint": "theta"})");
  overdriven.replace(overdriven.find(R"("effects")"), 9, R"("constraints": [{"name": "link", "type": "coupler", "joint_a": "x", "ratio_a": 1, "joint_b": "theta", "ratio_b": 0.5}], "effects")");
  const std::string err = error_path(overdriven);
  EXPECT_EQ(err.rfind("/actuators/0/joint", 0), 0u) << err;
  EXPECT_NE(err.find("\"link\""), std::string::npos) << err;
}

// the ball and beam as a run sees it: the beam's angle moved by a disturbance signal (alpha
// taken out of Plant/In), no controller, tight tolerances
ModelSpec ball_beam_run(double r0, double alpha0, const std::vector<DisturbanceSpec>& moves) {
  ModelSpec spec = study_read_model(test::example_path("ball_beam.json"));
  for (JointSpec& j : spec.joints) {
    if (j.name == "r") j.q0 = Eigen::VectorXd::Constant(1, r0);
    if (j.name == "beam_pivot") j.q0 = Eigen::VectorXd::Constant(1, alpha0);
  }
  spec.plant.inputs.clear();
  spec.analysis.controller = "none";
  spec.analysis.disturbances = moves;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.solver.t_end = 1.0;
  spec.solver.output_step = 0.05;
  return spec;
}

TEST(Motion, BallOnABeamHeldAtAnAngleRollsAsTheClosedForm) {
  const double mb = 0.111, R = 0.015, J = 9.99e-6, g = 9.8, Me = mb + J / (R * R);
  const Model m = study_model(ball_beam_run(0.3, 0.05, {}));
  const SimulationResult r = study_simulate(m, study_simulation(m));
  ASSERT_TRUE(r.completed) << r.failure;
  double worst = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[i];
    worst = std::max(worst, std::abs(r.y(i, 0) - (0.3 - mb * g * std::sin(0.05) * t * t / (2 * Me))));
    EXPECT_NEAR(r.q(i, 0), 0.05, 1e-15) << "the beam is held, t = " << t;
  }
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(r.y(r.samples() - 1, 0), 0.3 - 0.01);  // it did roll
}

// (m + J/R^2) r'' = (J/R) alpha'' + m r alpha'^2 - m g sin(alpha), the beam level and the ball at
// rest until t0, then turning at `slope`: at t0 the ball's rate jumps by (J/R) slope / (m + J/R^2)
// (the impulse of alpha''), after which alpha'' = 0; classical RK4 at a fine fixed step
double ball_on_turning_beam(double r0, double t0, double slope, double t_end) {
  const double mb = 0.111, R = 0.015, J = 9.99e-6, g = 9.8, Me = mb + J / (R * R);
  const auto accel = [&](double t, double r) {
    const double alpha = slope * (t - t0);
    return (mb * r * slope * slope - mb * g * std::sin(alpha)) / Me;
  };
  double r = r0, rd = (J / R) * slope / Me;
  const int n = 400000;
  const double h = (t_end - t0) / n;
  for (int k = 0; k < n; ++k) {
    const double t = t0 + k * h;
    const double k1x = rd, k1v = accel(t, r);
    const double k2x = rd + 0.5 * h * k1v, k2v = accel(t + 0.5 * h, r + 0.5 * h * k1x);
    const double k3x = rd + 0.5 * h * k2v, k3v = accel(t + 0.5 * h, r + 0.5 * h * k2x);
    const double k4x = rd + h * k3v, k4v = accel(t + h, r + h * k3x);
    r += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    rd += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
  return r;
}

TEST(Motion, BallOnABeamThatStartsTurningTakesTheImpulseOfItsRate) {
  DisturbanceSpec ramp;
  ramp.actuator = "alpha";
  ramp.type = "ramp";
  ramp.time = 0.2;
  ramp.slope = 0.1;
  const Model m = study_model(ball_beam_run(0.3, 0.0, {ramp}));
  const SimulationResult r = study_simulate(m, study_simulation(m));
  ASSERT_TRUE(r.completed) << r.failure;
  const int last = r.samples() - 1;
  EXPECT_NEAR(r.t[last], 1.0, 1e-12);
  EXPECT_NEAR(r.q(last, 0), 0.1 * 0.8, 1e-12);  // the beam where the ramp put it
  const double expected = ball_on_turning_beam(0.3, 0.2, 0.1, 1.0);
  // (without the impulse, (J/R) 0.1 / (m + J/R^2) = 4.3e-4 m/s over 0.8 s, the ball would be
  // 3.4e-4 m elsewhere: far beyond the tolerance)
  EXPECT_NEAR(r.y(last, 0), expected, 1e-8);
}

TEST(Motion, BusOverARoadBumpFromACsvFileMatchesTheLinearClosedLoop) {
  const std::string dir = ::testing::TempDir() + "/motion_bus";
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/bump.csv";
  {
    std::ofstream out(csv);
    out << "t,W\n";
    for (int k = 0; k <= 2000; ++k) {
      const double t = 0.001 * k;
      const double w = t > 0.5 && t < 1.0 ? 0.05 * 0.5 * (1 - std::cos(2 * std::numbers::pi * (t - 0.5) / 0.5)) : 0.0;
      out << t << "," << w << "\n";
    }
  }
  ModelSpec spec = study_read_model(test::example_path("bus_suspension.json"));
  spec.plant.inputs = {"U"};
  spec.analysis.controller = "lqr";
  spec.analysis.q_weights = {1e6, 1e6, 1, 1};
  spec.analysis.r_weights = {1e-4};
  DisturbanceSpec road;
  road.actuator = "W";
  road.type = "file";
  road.file = csv;
  spec.analysis.disturbances = {road};
  spec.analysis.compare_linear = true;
  spec.solver.t_end = 3.0;
  spec.solver.output_step = 0.01;
  const Model m = study_model(spec);
  const StudySimulation setup = study_simulation(m);
  ASSERT_EQ(setup.controller_source, "lqr");
  const SimulationResult r = study_simulate(m, setup);
  ASSERT_TRUE(r.completed) << r.failure;
  ASSERT_EQ(r.y_linear.rows(), r.y.rows());
  double gap = 0, swing = 0;
  for (int i = 0; i < r.samples(); ++i) {
    gap = std::max(gap, std::abs(r.y(i, 0) - r.y_linear(i, 0)));
    swing = std::max(swing, std::abs(r.y(i, 0) - r.y(0, 0)));
  }
  EXPECT_GT(swing, 1e-3);       // the bump moved the suspension
  EXPECT_LT(gap, 1e-6 * swing);  // the mechanism is linear here: the gap is the integrators'
}

TEST(Motion, AControllerDrivingAMotionInputIsRefusedNamingIt) {
  ModelSpec spec = study_read_model(test::example_path("ball_beam.json"));
  spec.analysis.controller = "lqr";
  const Model m = study_model(spec);
  try {
    study_simulate(m, study_simulation(m));
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("motion input \"alpha\""), std::string::npos) << e.what();
  }
}

TEST(Motion, AStepOnAMotionInputIsRefusedAtTheField) {
  DisturbanceSpec step;
  step.actuator = "alpha";
  step.type = "step";
  step.time = 0.1;
  step.value = 0.05;
  const Model m = study_model(ball_beam_run(0.3, 0.0, {step}));
  try {
    study_simulation(m);
    FAIL() << "expected a refusal";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/disturbances/0/type") << e.what();
  }
}

}  // namespace
}  // namespace codyna
