// One input driving several actuators (actuator type "mix", issue 19): each driven actuator adds
// weight * u to its own input. Checked against the same plant with the actuators as separate
// inputs mixed by hand (B_mix = B [w]), against the closed form of a pendulum driven by a motor and
// a jet, and exact against central differences where the mixed force turns with the body.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <string>

#include "model/errors.hpp"
#include "model/spec_edit.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

constexpr double kMix = 2.0, kMixL = 0.6, kMixIc = 0.04, kJetAt = 0.9;

// a pendulum (revolute z) driven by a motor (gain 1) and a jet at kJetAt along the rod pushing along
// the rod's y (gain 2; in body or world axes), and a mix of both (weights 0.5, 3)
std::string driven_pendulum(const std::string& inputs, const char* jet_frame, double theta0, double omega0,
                            double mix_u0, const char* method = "exact") {
  char text[2600];
  std::snprintf(text, sizeof text, R"({"name": "driven_pendulum",
    "bodies": [{"name": "rod", "mass": %.17g, "com": [%.17g, 0, 0], "inertia": [0.001, %.17g, %.17g]}],
    "joints": [{"name": "pivot", "type": "revolute", "parent": "ground", "child": "rod", "axis": [0, 0, 1],
                "q0": %.17g, "v0": %.17g}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "motor", "type": "joint_force", "joint": "pivot"},
                  {"name": "jet", "type": "body_force", "body": "rod", "point": [%.17g, 0, 0], "direction": [0, 1, 0],
                   "frame": "%s", "gain": 2},
                  {"name": "mix", "type": "mix", "drives": ["motor", "jet"], "weights": [0.5, 3], "u0": %.17g}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "pivot"}],
    "plant": {"inputs": %s, "outputs": ["angle"]},
    "analysis": {"operating_point": "initial", "method": "%s"}})",
                kMix, kMixL, kMixIc, kMixIc, theta0, omega0, kJetAt, jet_frame, mix_u0, inputs.c_str(), method);
  return text;
}

LinearSystem mix_linearized(const std::string& text) {
  return study_linearize(study_model(study_parse_model_text(text, "driven_pendulum.json"))).system;
}

TEST(Mix, EqualsTheActuatorsMixedByHand) {
  for (const char* frame : {"body", "world"}) {
    const LinearSystem mixed = mix_linearized(driven_pendulum(R"(["mix"])", frame, 0.3, 0.5, 1.5));
    const LinearSystem apart = mix_linearized(driven_pendulum(R"(["motor", "jet"])", frame, 0.3, 0.5, 1.5));
    EXPECT_TRUE(MatrixNear(mixed.A, apart.A, 1e-15)) << frame;
    EXPECT_TRUE(MatrixNear(mixed.B, apart.B * Eigen::Vector2d(0.5, 3), 1e-14)) << frame;
    EXPECT_TRUE(MatrixNear(mixed.xdot0, apart.xdot0, 1e-15)) << frame;
  }
}

TEST(Mix, PendulumDrivenByAMotorAndAJetMatchesTheClosedForm) {
  const LinearSystem s = mix_linearized(driven_pendulum(R"(["mix"])", "body", 0.3, 0.0, 0.0));
  // a unit of the mix: 0.5 N m from the motor and 3 * 2 N along the rod's y at kJetAt
  const double I = kMixIc + kMix * kMixL * kMixL;
  EXPECT_NEAR(s.B(1, 0), (0.5 + 6 * kJetAt) / I, 1e-14);
  // with the mix at u0 = 1.5 the pendulum accelerates by that much more
  const LinearSystem pushed = mix_linearized(driven_pendulum(R"(["mix"])", "body", 0.3, 0.0, 1.5));
  EXPECT_NEAR(pushed.xdot0[1] - s.xdot0[1], 1.5 * (0.5 + 6 * kJetAt) / I, 1e-13);
}

TEST(Mix, ExactJacobiansAgreeWithCentralDifferences) {
  // a world-axes jet: the mixed force's moment arm turns with the rod, so A depends on the mix's input
  const LinearSystem e = mix_linearized(driven_pendulum(R"(["mix"])", "world", 0.8, -1.1, 2.5));
  const LinearSystem f = mix_linearized(driven_pendulum(R"(["mix"])", "world", 0.8, -1.1, 2.5, "fd-central"));
  EXPECT_TRUE(MatrixNear(e.A, f.A, 1e-7));
  EXPECT_TRUE(MatrixNear(e.B, f.B, 1e-7));
}

TEST(Mix, BadMixesAreRefusedAtTheFieldAndRenamesFollow) {
  const auto error_path = [](const std::string& text) {
    try {
      (void)study_model(study_parse_model_text(text, "bad.json"));
    } catch (const ModelError& e) {
      return e.path();
    }
    return std::string("no error");
  };
  const std::string ok = driven_pendulum(R"(["mix"])", "body", 0.3, 0.0, 0.0);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = ok;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  EXPECT_EQ(error_path(with(R"(["motor", "jet"])", R"(["motor", "jets"])")), "/actuators/2/drives/1");
  EXPECT_EQ(error_path(with(R"(["motor", "jet"])", R"(["motor", "mix"])")), "/actuators/2/drives/1");
  EXPECT_EQ(error_path(with(R"(["motor", "jet"])", R"(["motor", "motor"])")), "/actuators/2/drives/1");
  EXPECT_EQ(error_path(with(R"([0.5, 3])", R"([0.5])")), "/actuators/2/weights");
  ModelSpec spec = study_parse_model_text(ok, "ok.json");
  rename_element(spec, ElementKind::Actuator, 1, "thruster");
  EXPECT_EQ(spec.actuators[2].drives, (std::vector<std::string>{"motor", "thruster"}));
  const std::vector<std::string> refs = references_to(spec, ElementKind::Actuator, "motor");
  EXPECT_NE(std::find(refs.begin(), refs.end(), "actuator mix: drives"), refs.end());
  EXPECT_EQ(study_model_json(study_parse_model(study_model_json(spec), "again")), study_model_json(spec));
}

}  // namespace
}  // namespace codyna
