// Couplers (issue 19): a linear relation among two or three scalar joint coordinates, handled by
// the loop machinery (minimal coordinates, independent coordinate choice, redundancy detection).
// Checked against closed forms derived by hand (Lagrange's equations of the reduced system):
// a geared motor (the rotor inertia reflected as N^2 Jm), a differential, and the ball and beam
// whose ball rolls without slip (the J/R^2 and the -(J/R) alpha'' r'' coupling exactly), and the
// exact Jacobians against central differences away from equilibrium, where the coupler's
// reaction is not zero.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "model/errors.hpp"
#include "model/spec_edit.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

constexpr double kGravity = 9.81;

ModelSpec parse_coupler(const std::string& text) { return study_parse_model_text(text, "coupler_test.json"); }

// ground -> motor (disc Jm about z), ground -> wheel (disc Jl about z), motor = N wheel
std::string gear_model(double Jm, double Jl, double N, const std::string& extra_constraint = "") {
  return R"({"name": "gear",
    "bodies": [{"name": "rotor", "mass": 1, "inertia": [1, 1, )" + std::to_string(Jm) + R"(]},
               {"name": "load", "mass": 2, "inertia": [1, 1, )" + std::to_string(Jl) + R"(]}],
    "joints": [{"name": "motor", "type": "revolute", "parent": "ground", "child": "rotor", "axis": [0, 0, 1]},
               {"name": "wheel", "type": "revolute", "parent": "ground", "child": "load", "axis": [0, 0, 1],
                "parent_frame": {"position": [1, 0, 0]}}],
    "constraints": [{"name": "gear", "type": "coupler", "joint_a": "motor", "ratio_a": 1,
                     "joint_b": "wheel", "ratio_b": )" + std::to_string(-N) + "}" + extra_constraint + R"(],
    "actuators": [{"name": "torque", "type": "joint_force", "joint": "motor"}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "wheel"}],
    "plant": {"inputs": ["torque"], "outputs": ["angle"]},
    "analysis": {"operating_point": "initial", "independent": ["wheel"]}})";
}

TEST(Coupler, GearReflectsTheRotorInertiaAsNSquared) {
  const double Jm = 0.02, Jl = 0.5, N = 7;
  const Model m = study_model(parse_coupler(gear_model(Jm, Jl, N)));
  EXPECT_EQ(m.dof(), 1);
  const StudyLinearization sl = study_linearize(m);
  const LinearSystem& s = sl.system;
  ASSERT_EQ(s.A.rows(), 2);
  // (Jl + N^2 Jm) wheel'' = N torque: the motor's torque is multiplied by N, its inertia by N^2
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2);
  A << 0, 1, 0, 0;
  B << 0, N / (Jl + N * N * Jm);
  C << 1, 0;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-13));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-13));
  EXPECT_TRUE(MatrixNear(s.C, C, 1e-13));
  EXPECT_EQ(s.state_names[0], "wheel");
}

TEST(Coupler, ARepeatedCouplerIsFoundRedundantAndNamed) {
  const std::string twice = R"(, {"name": "gear_again", "type": "coupler", "joint_a": "wheel", "ratio_a": 14,
                                  "joint_b": "motor", "ratio_b": -2})";
  const Model m = study_model(parse_coupler(gear_model(0.02, 0.5, 7, twice)));
  ASSERT_EQ(m.nc, 2);
  ASSERT_EQ(m.redundant_rows.size(), 1u);  // one of the two, named (the pivoting keeps the better scaled)
  const std::string redundant = m.row_names[m.redundant_rows[0]];
  EXPECT_TRUE(redundant == "gear" || redundant == "gear_again") << redundant;
  EXPECT_EQ(m.dof(), 1);
  // the dynamics are those of the single gear
  const LinearSystem& s = study_linearize(m).system;
  EXPECT_NEAR(s.B(1, 0), 7 / (0.5 + 49 * 0.02), 1e-13);
}

TEST(Coupler, DifferentialOfThreeCoordinates) {
  // carrier c = (a + b) / 2, torque on the carrier; KE = (Ja a'^2 + Jb b'^2 + Jc c'^2) / 2
  const double Ja = 0.3, Jb = 0.7, Jc = 1.1;
  const std::string text = R"({"name": "differential",
    "bodies": [{"name": "A", "mass": 1, "inertia": [1, 1, 0.3]}, {"name": "B", "mass": 1, "inertia": [1, 1, 0.7]},
               {"name": "C", "mass": 1, "inertia": [1, 1, 1.1]}],
    "joints": [{"name": "a", "type": "revolute", "parent": "ground", "child": "A", "axis": [0, 0, 1]},
               {"name": "b", "type": "revolute", "parent": "ground", "child": "B", "axis": [0, 0, 1]},
               {"name": "c", "type": "revolute", "parent": "ground", "child": "C", "axis": [0, 0, 1]}],
    "constraints": [{"name": "diff", "type": "coupler", "joint_a": "a", "ratio_a": 0.5, "joint_b": "b",
                     "ratio_b": 0.5, "joint_c": "c", "ratio_c": -1}],
    "actuators": [{"name": "drive", "type": "joint_force", "joint": "c"}],
    "sensors": [{"name": "left", "type": "joint_position", "joint": "a"}],
    "plant": {"inputs": ["drive"], "outputs": ["left"]},
    "analysis": {"operating_point": "initial", "independent": ["a", "b"]}})";
  const Model m = study_model(parse_coupler(text));
  EXPECT_EQ(m.dof(), 2);
  const LinearSystem& s = study_linearize(m).system;
  Eigen::Matrix2d M;
  M << Ja + Jc / 4, Jc / 4, Jc / 4, Jb + Jc / 4;
  const Eigen::Vector2d b = M.inverse() * Eigen::Vector2d(0.5, 0.5);
  EXPECT_TRUE(MatrixNear(s.B.bottomRows(2), b, 1e-13));
  EXPECT_TRUE(MatrixNear(s.A.bottomRows(2), Eigen::MatrixXd::Zero(2, 4), 1e-13));
}

// The ball and beam: the beam turns about z at the origin (torque input); the ball's centre slides
// along the beam (r) and the ball turns on it (spin, relative to the beam); rolling without slip on a
// line: r + R spin = 0. Gravity -y.
std::string ball_and_beam(double q_beam, double q_r, double v_beam, double v_r) {
  const double R = 0.015, m = 0.11, J = 0.4 * m * R * R, Ib = 0.05;
  char buf[2600];
  std::snprintf(buf, sizeof buf, R"({"name": "ball_and_beam",
    "bodies": [{"name": "beam", "mass": 0.5, "inertia": [0.001, %.17g, %.17g]},
               {"name": "carrier", "mass": 0, "inertia": [0, 0, 0]},
               {"name": "ball", "mass": %.17g, "inertia": [%.17g, %.17g, %.17g]}],
    "joints": [{"name": "alpha", "type": "revolute", "parent": "ground", "child": "beam", "axis": [0, 0, 1],
                "q0": %.17g, "v0": %.17g},
               {"name": "r", "type": "prismatic", "parent": "beam", "child": "carrier", "axis": [1, 0, 0],
                "q0": %.17g, "v0": %.17g},
               {"name": "spin", "type": "revolute", "parent": "carrier", "child": "ball", "axis": [0, 0, 1],
                "q0": %.17g, "v0": %.17g}],
    "constraints": [{"name": "rolling", "type": "coupler", "joint_a": "r", "ratio_a": 1, "joint_b": "spin",
                     "ratio_b": %.17g, "offset": 0}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "tau", "type": "joint_force", "joint": "alpha"}],
    "sensors": [{"name": "position", "type": "joint_position", "joint": "r"}],
    "plant": {"inputs": ["tau"], "outputs": ["position"]},
    "analysis": {"operating_point": "initial", "independent": ["alpha", "r"]}})",
                Ib, Ib, m, J, J, J, q_beam, v_beam, q_r, v_r, -q_r / R, -v_r / R, R);
  return buf;
}

TEST(Coupler, BallRollingOnABeamMatchesLagrangesEquations) {
  const double R = 0.015, m = 0.11, J = 0.4 * m * R * R, Ib = 0.05;
  const Model model = study_model(parse_coupler(ball_and_beam(0, 0, 0, 0)));
  EXPECT_EQ(model.dof(), 2);
  const LinearSystem& s = study_linearize(model).system;
  // T = (Ib alpha'^2 + m (r'^2 + r^2 alpha'^2) + J (alpha' - r'/R)^2) / 2, V = m g r sin(alpha):
  // at alpha = r = 0, M = [Ib + J, -J/R; -J/R, m + J/R^2], K = [0, m g; m g, 0]
  Eigen::Matrix2d M, K;
  M << Ib + J, -J / R, -J / R, m + J / (R * R);
  K << 0, m * kGravity, m * kGravity, 0;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4, 4), B = Eigen::MatrixXd::Zero(4, 1);
  A.topRightCorner(2, 2).setIdentity();
  A.bottomLeftCorner(2, 2) = -M.inverse() * K;
  B.bottomRows(2) = M.inverse() * Eigen::Vector2d(1, 0);
  ASSERT_EQ(s.state_names[0], "alpha");
  ASSERT_EQ(s.state_names[1], "r");
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  // the rolling ball accelerates at g alpha / (1 + J/(m R^2)) = 5/7 g alpha on a held beam: the
  // r row of A against alpha is that of M^-1 K with the coupling term
  const double held = -(m * kGravity) / (m + J / (R * R));
  EXPECT_NEAR(held, -5.0 / 7.0 * kGravity, 1e-12);
}

TEST(Coupler, ExactJacobiansAgreeWithCentralDifferencesWhereTheReactionActs) {
  // away from equilibrium, moving: the rolling constraint carries a reaction
  ModelSpec spec = parse_coupler(ball_and_beam(0.2, 0.3, -0.4, 0.7));
  const Model exact_model = study_model(spec);
  spec.analysis.method = "fd-central";
  const Model fd_model = study_model(spec);
  const LinearSystem e = study_linearize(exact_model).system, f = study_linearize(fd_model).system;
  EXPECT_GT(e.xdot0.norm(), 0.1);  // not an equilibrium
  EXPECT_TRUE(MatrixNear(e.A, f.A, 1e-7));
  EXPECT_TRUE(MatrixNear(e.B, f.B, 1e-7));
}

TEST(Coupler, BadCouplersAreRefusedAtTheField) {
  const auto error_path = [](const std::string& text) {
    try {
      (void)study_model(study_parse_model_text(text, "bad.json"));
    } catch (const ModelError& e) {
      return e.path() + ": " + e.detail();
    }
    return std::string("no error");
  };
  std::string text = gear_model(0.02, 0.5, 7);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  EXPECT_EQ(error_path(with(R"("joint_b": "wheel")", R"("joint_b": "whee1")")).substr(0, 30),
            "/constraints/0/joint_b: unknow");
  EXPECT_NE(error_path(with(R"("joint_b": "wheel")", R"("joint_b": "motor")")).find("/constraints/0/joint_b"), std::string::npos);
  EXPECT_NE(error_path(with(R"("ratio_b": -7)", R"("ratio_b": 0)")).find("at least two non-zero ratios"), std::string::npos);
  EXPECT_NE(error_path(with(R"("ratio_b": -7)", R"("ratio_b": -7, "ratio_c": 2)")).find("/constraints/0/ratio_c"),
            std::string::npos);
  EXPECT_NE(error_path(with(R"("type": "revolute", "parent": "ground", "child": "load")",
                            R"("type": "cylindrical", "parent": "ground", "child": "load")"))
                .find("/constraints/0/joint_b: a coupler relates scalar coordinates; \"wheel\" is cylindrical"),
            std::string::npos);
}

TEST(Coupler, RoundTripsThroughTheFileAndFollowsARename) {
  ModelSpec spec = parse_coupler(gear_model(0.02, 0.5, 7));
  const ModelSpec again = study_parse_model(study_model_json(spec), "again");
  EXPECT_EQ(study_model_json(again), study_model_json(spec));
  EXPECT_EQ(study_model_json(spec)["constraints"][0].count("offset"), 0u);  // left out: from q0
  rename_element(spec, ElementKind::Joint, find_element(spec, ElementKind::Joint, "wheel"), "output_shaft");
  EXPECT_EQ(spec.constraints[0].joint_b, "output_shaft");
  const std::vector<std::string> refs = references_to(spec, ElementKind::Joint, "motor");
  EXPECT_NE(std::find(refs.begin(), refs.end(), "constraint gear: joint_a"), refs.end());
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// A ball released on a fixed incline rolls without slip: r(t) = -(1/2) g sin(a) t^2 / (1 + J/(m R^2)),
// 5/7 of the sliding value for a solid ball; simulated on the nonlinear model (the coupler holds the
// rolling; its reaction is the friction force).
TEST(Coupler, BallRollsDownAnInclineAtFiveSeventhsOfTheSlidingAcceleration) {
  const double a = 0.3, R = 0.02, m = 0.2, J = 0.4 * m * R * R;
  char text[2000];
  std::snprintf(text, sizeof text, R"({"name": "incline",
    "bodies": [{"name": "carrier", "mass": 0, "inertia": [0, 0, 0]},
               {"name": "ball", "mass": %.17g, "inertia": [%.17g, %.17g, %.17g]}],
    "joints": [{"name": "r", "type": "prismatic", "parent": "ground", "child": "carrier", "axis": [1, 0, 0],
                "parent_frame": {"rotation": {"axis": [0, 0, 1], "angle": %.17g}}},
               {"name": "spin", "type": "revolute", "parent": "carrier", "child": "ball", "axis": [0, 0, 1]}],
    "constraints": [{"name": "rolling", "type": "coupler", "joint_a": "r", "ratio_a": 1, "joint_b": "spin",
                     "ratio_b": %.17g}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "sensors": [{"name": "position", "type": "joint_position", "joint": "r"},
                {"name": "turned", "type": "joint_position", "joint": "spin"}],
    "plant": {"outputs": ["position", "turned"]},
    "analysis": {"controller": "none"},
    "solver": {"t_end": 1.0, "output_step": 0.25, "rtol": 1e-10, "atol": 1e-12}})",
                m, J, J, J, a, R);
  const Model model = study_model(study_parse_model_text(text, "incline.json"));
  const StudySimulation setup = study_simulation(model);
  const SimulationResult r = study_simulate(model, setup);
  ASSERT_TRUE(r.completed) << r.failure;
  const double accel = -kGravity * std::sin(a) / (1 + J / (m * R * R));
  EXPECT_NEAR(accel, -5.0 / 7.0 * kGravity * std::sin(a), 1e-12);
  for (int i = 0; i < r.samples(); ++i) {
    const double t = r.t[i];
    EXPECT_NEAR(r.y(i, 0), 0.5 * accel * t * t, 1e-8) << "t = " << t;
    EXPECT_NEAR(r.y(i, 0) + R * r.y(i, 1), 0.0, 1e-9) << "rolling at t = " << t;
  }
}

}  // namespace
}  // namespace codyna
