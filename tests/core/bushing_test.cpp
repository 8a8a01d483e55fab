// The bushing (issue 19; Adams' BUSHING): a linear 6-component spring-damper between a frame on
// each of two bodies. Checked against closed forms (a free body held by a bushing at its centre of
// mass: six uncoupled oscillators sqrt(k/m), sqrt(kr/I) with their dampings; two carts joined by
// one: the relative mode) and the exact Jacobians against central differences with the bushing off
// the centre of mass, turned and moving, where every coupling of the 6 x 6 law is active.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <string>

#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

const Eigen::Vector3d kKt(400, 900, 1600), kCt(2, 3, 4), kKr(30, 50, 70), kCr(0.3, 0.5, 0.7), kI(0.2, 0.3, 0.4);
constexpr double kMass = 4.0;

// a free body (no gravity) held to ground by a bushing; frame_b at `at` on the body, frame_a where
// frame_b is at q0 (the ground frame turned by `turn` about z)
std::string held_body(const std::string& at, const std::string& q0, const std::string& v0, double turn,
                      const char* method = "exact") {
  char text[3000];
  std::snprintf(text, sizeof text, R"({"name": "held_body",
    "bodies": [{"name": "block", "mass": %.17g, "inertia": [%.17g, %.17g, %.17g]}],
    "joints": [{"name": "J", "type": "free", "parent": "ground", "child": "block", "q0": %s, "v0": %s}],
    "effects": [{"name": "mount", "type": "bushing", "body_a": "ground",
                 "frame_a": {"position": %s, "rotation": {"axis": [0, 0, 1], "angle": %.17g}},
                 "body_b": "block", "frame_b": {"position": %s, "rotation": {"axis": [0, 0, 1], "angle": %.17g}},
                 "translational_stiffness": [%.17g, %.17g, %.17g], "translational_damping": [%.17g, %.17g, %.17g],
                 "rotational_stiffness": [%.17g, %.17g, %.17g], "rotational_damping": [%.17g, %.17g, %.17g]}],
    "analysis": {"operating_point": "initial", "method": "%s"}})",
                kMass, kI[0], kI[1], kI[2], q0.c_str(), v0.c_str(), at.c_str(), turn, at.c_str(), turn, kKt[0], kKt[1],
                kKt[2], kCt[0], kCt[1], kCt[2], kKr[0], kKr[1], kKr[2], kCr[0], kCr[1], kCr[2], method);
  return text;
}

LinearSystem linearized(const std::string& text) {
  return study_linearize(study_model(study_parse_model_text(text, "bushing.json"))).system;
}

TEST(Bushing, AtTheCentreOfMassItIsSixUncoupledOscillators) {
  const LinearSystem s = linearized(held_body("[0, 0, 0]", "[0, 0, 0, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]", 0.0));
  ASSERT_EQ(s.A.rows(), 12);
  // states: J.rx J.ry J.rz J.x J.y J.z, then their rates
  const std::vector<std::string> names{"J.rx", "J.ry", "J.rz", "J.x", "J.y", "J.z"};
  for (int k = 0; k < 6; ++k) ASSERT_EQ(s.state_names[static_cast<std::size_t>(k)], names[static_cast<std::size_t>(k)]);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(12, 12);
  A.topRightCorner(6, 6).setIdentity();
  for (int k = 0; k < 3; ++k) {
    A(6 + k, k) = -kKr[k] / kI[k];
    A(6 + k, 6 + k) = -kCr[k] / kI[k];
    A(9 + k, 3 + k) = -kKt[k] / kMass;
    A(9 + k, 9 + k) = -kCt[k] / kMass;
  }
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
}

TEST(Bushing, TwoCartsJoinedByOneOscillateApart) {
  // carts m1, m2 on x, joined by a bushing along x (k, c): the relative mode s^2 + c/mu s + k/mu = 0
  const double m1 = 2, m2 = 3, k = 500, c = 1.5;
  char text[2000];
  std::snprintf(text, sizeof text, R"({"name": "carts",
    "bodies": [{"name": "c1", "mass": %g, "inertia": [1, 1, 1]}, {"name": "c2", "mass": %g, "inertia": [1, 1, 1]}],
    "joints": [{"name": "x1", "type": "prismatic", "parent": "ground", "child": "c1", "axis": [1, 0, 0]},
               {"name": "x2", "type": "prismatic", "parent": "ground", "child": "c2", "axis": [1, 0, 0],
                "parent_frame": {"position": [1, 0, 0]}}],
    "effects": [{"name": "link", "type": "bushing", "body_a": "c1", "frame_a": {"position": [1, 0, 0]},
                 "body_b": "c2", "translational_stiffness": [%g, 7, 7], "translational_damping": [%g, 0, 0]}],
    "analysis": {"operating_point": "initial"}})",
                m1, m2, k, c);
  const LinearSystem s = linearized(text);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(4, 4);
  A.topRightCorner(2, 2).setIdentity();
  A.bottomLeftCorner(2, 2) << -k / m1, k / m1, k / m2, -k / m2;
  A.bottomRightCorner(2, 2) << -c / m1, c / m1, c / m2, -c / m2;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
}

TEST(Bushing, ExactJacobiansAgreeWithCentralDifferencesOffTheCentreTurnedAndMoving) {
  // frame_b 0.3 m from the centre of mass, the frames turned 0.4 rad about z; the body displaced,
  // tilted and moving: translation and rotation couple, the frame's turning enters the force
  const std::string q0 = "[0.06, 0.02, -0.03, 0.99549, 0.05, -0.08, 0.01]", v0 = "[0.4, -0.7, 0.3, 0.2, -0.1, 0.5]";
  const LinearSystem e = linearized(held_body("[0.3, -0.1, 0.2]", q0, v0, 0.4));
  const LinearSystem f = linearized(held_body("[0.3, -0.1, 0.2]", q0, v0, 0.4, "fd-central"));
  EXPECT_GT(e.xdot0.norm(), 1.0);
  EXPECT_TRUE(MatrixNear(e.A, f.A, 1e-7));
}

TEST(Bushing, BadValuesAreRefusedAtTheField) {
  std::string text = held_body("[0, 0, 0]", "[0, 0, 0, 1, 0, 0, 0]", "[0, 0, 0, 0, 0, 0]", 0.0);
  const auto at = text.find("\"rotational_stiffness\": [30");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("\"rotational_stiffness\": [30").size(), "\"rotational_stiffness\": [-30");
  try {
    (void)study_model(study_parse_model_text(text, "bad.json"));
    ADD_FAILURE() << "a negative stiffness was accepted";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/effects/0/rotational_stiffness");
  }
}

}  // namespace
}  // namespace codyna
