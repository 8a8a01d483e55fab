// The two-point actuator (line_force: a hydraulic cylinder, a suspension strut; issue 19) and the
// rate of a distance (distance_rate, the strut's extension rate), checked against a closed form: a
// rod on a pivot lifted by a cylinder from a ground point below the pivot, linearized where the
// cylinder pushes (so that the turning of its line enters A), and the exact Jacobians against
// central differences on a moving state.
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

constexpr double kGrav = 9.81, kBarM = 3.0, kL = 0.8, kIc = 0.05, kA = 0.5, kH = 0.3, kU0 = 40.0;

// rod: pivot at the origin (revolute z), centre of mass at kL along its x; the cylinder from the
// ground point (0, -kH) to the rod point at kA along its x
std::string lifted_rod(double theta0, double omega0, const std::string& method = "exact") {
  char text[2400];
  std::snprintf(text, sizeof text, R"({"name": "lifted_rod",
    "bodies": [{"name": "rod", "mass": %.17g, "com": [%.17g, 0, 0], "inertia": [0.001, %.17g, %.17g]}],
    "joints": [{"name": "pivot", "type": "revolute", "parent": "ground", "child": "rod", "axis": [0, 0, 1],
                "q0": %.17g, "v0": %.17g}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "cylinder", "type": "line_force", "body_a": "ground", "point_a": [0, %.17g, 0],
                   "body_b": "rod", "point_b": [%.17g, 0, 0], "u0": %.17g}],
    "sensors": [{"name": "stroke", "type": "distance", "body_a": "ground", "point_a": [0, %.17g, 0],
                 "body_b": "rod", "point_b": [%.17g, 0, 0]},
                {"name": "stroke_rate", "type": "distance_rate", "body_a": "ground", "point_a": [0, %.17g, 0],
                 "body_b": "rod", "point_b": [%.17g, 0, 0]}],
    "plant": {"inputs": ["cylinder"], "outputs": ["stroke", "stroke_rate"]},
    "analysis": {"operating_point": "initial", "method": "%s"}})",
                kBarM, kL, kIc, kIc, theta0, omega0, -kH, kA, kU0, -kH, kA, -kH, kA, method.c_str());
  return text;
}

TEST(LineForce, LiftedRodMatchesTheClosedForm) {
  const double th = 0.4;
  const Model m = study_model(study_parse_model_text(lifted_rod(th, 0.0), "lifted_rod.json"));
  const LinearSystem& s = study_linearize(m).system;
  // I th'' = -m g l cos(th) + u a h cos(th) / L(th),  L = sqrt(a^2 + h^2 + 2 a h sin(th))
  const double I = kIc + kBarM * kL * kL;
  const double L = std::sqrt(kA * kA + kH * kH + 2 * kA * kH * std::sin(th));
  const double dL = kA * kH * std::cos(th) / L;  // dL/dth
  const double d_cos_over_L = (-std::sin(th) * L - std::cos(th) * dL) / (L * L);
  Eigen::MatrixXd A(2, 2), B(2, 1), C(2, 2), xdot(2, 1);
  A << 0, 1, (kBarM * kGrav * kL * std::sin(th) + kU0 * kA * kH * d_cos_over_L) / I, 0;
  B << 0, kA * kH * std::cos(th) / (L * I);
  C << dL, 0, 0, dL;  // the stroke and its rate dL/dth th'
  xdot << 0, (-kBarM * kGrav * kL * std::cos(th) + kU0 * kA * kH * std::cos(th) / L) / I;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  EXPECT_TRUE(MatrixNear(s.C, C, 1e-12));
  EXPECT_TRUE(MatrixNear(s.xdot0, xdot, 1e-12));
  EXPECT_NEAR(s.y0[0], L, 1e-14);
  EXPECT_NEAR(s.y0[1], 0.0, 1e-14);
}

TEST(LineForce, ExactJacobiansAgreeWithCentralDifferencesOnAMovingState) {
  const Model exact = study_model(study_parse_model_text(lifted_rod(-0.7, 1.3), "a.json"));
  const Model fd = study_model(study_parse_model_text(lifted_rod(-0.7, 1.3, "fd-central"), "b.json"));
  const LinearSystem e = study_linearize(exact).system, f = study_linearize(fd).system;
  EXPECT_GT(std::abs(e.y0[1]), 0.1);  // the stroke is moving
  EXPECT_TRUE(MatrixNear(e.A, f.A, 1e-7));
  EXPECT_TRUE(MatrixNear(e.B, f.B, 1e-7));
  EXPECT_TRUE(MatrixNear(e.C, f.C, 1e-7));
}

TEST(LineForce, ItsBodiesAreCheckedAndFollowRenames) {
  std::string text = lifted_rod(0.4, 0.0);
  const auto at = text.find(R"("body_b": "rod")");
  ASSERT_NE(at, std::string::npos);
  std::string bad = text;
  bad.replace(at, std::string(R"("body_b": "rod")").size(), R"("body_b": "ground")");
  try {
    (void)study_model(study_parse_model_text(bad, "bad.json"));
    ADD_FAILURE() << "accepted a cylinder from ground to ground";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/actuators/0/body_b");
  }
  const ModelSpec spec = study_parse_model_text(text, "ok.json");
  EXPECT_EQ(study_model_json(study_parse_model(study_model_json(spec), "again")), study_model_json(spec));
}

}  // namespace
}  // namespace codyna
