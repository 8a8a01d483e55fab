// The MJCF export's refusals and its output guard (io/export_mjcf, study_export_mjcf). What it
// writes is checked against MuJoCo in tests/peers_mujoco/export_peer_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "dynamics/prepare.hpp"
#include "io/export_mjcf.hpp"
#include "io/model_file.hpp"
#include "study/files.hpp"
#include "study/import.hpp"
#include "test_util.hpp"

namespace codyna::test {
namespace {

namespace fs = std::filesystem;

// three pendulums side by side, hanging from the ground on parallel hinges
ModelSpec three_pendulums() {
  ModelSpec s;
  s.name = "three";
  for (int i = 0; i < 3; ++i) {
    BodySpec b;
    b.name = "p" + std::to_string(i);
    b.mass = 1;
    b.com = Eigen::Vector3d(0, -0.5, 0);
    b.inertia = Eigen::Vector3d(0.1, 0.01, 0.1).asDiagonal();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "h" + std::to_string(i);
    j.parent = kGroundName;
    j.child = b.name;
    j.parent_frame.position = Eigen::Vector3d(i, 0, 0);
    s.joints.push_back(j);
  }
  EffectSpec g;
  g.name = "gravity";
  s.effects.push_back(g);
  return s;
}

std::string refusal(const ModelSpec& s) {
  try {
    (void)export_mjcf(compile(s), "three.json");
  } catch (const MjcfExportRefused& e) {
    return e.what();
  }
  return "";
}

TEST(ExportMjcf, TreeOfHingesExports) {
  const MjcfExport e = export_mjcf(compile(three_pendulums()), "three.json");
  EXPECT_EQ(e.xml.rfind(kMjcfHeader, 0), 0u);
  EXPECT_EQ(e.nbodies, 3);
  EXPECT_EQ(e.njoints, 3);
  EXPECT_NE(e.xml.find("<joint name=\"h2\" type=\"hinge\""), std::string::npos) << e.xml;
}

TEST(ExportMjcf, ElementsWithoutAnMjcfEquivalentAreRefusedEachNamed) {
  ModelSpec s = three_pendulums();
  EffectSpec b;
  b.name = "mount";
  b.type = EffectType::Bushing;
  b.body_a = "p0";
  b.body_b = "p1";
  b.translational_stiffness = Eigen::Vector3d::Constant(100);
  s.effects.push_back(b);
  EffectSpec f;
  f.name = "push";
  f.type = EffectType::BodyForce;
  f.body_a = "p2";
  f.force = Eigen::Vector3d(1, 0, 0);
  s.effects.push_back(f);
  ConstraintSpec c;
  c.name = "differential";
  c.type = ConstraintType::Coupler;
  c.joint_a = "h0";
  c.joint_b = "h1";
  c.joint_c = "h2";
  c.ratio_a = 1;
  c.ratio_b = -0.5;
  c.ratio_c = -0.5;
  s.constraints.push_back(c);
  for (const char* n : {"m0", "m1"}) {
    ActuatorSpec a;
    a.name = n;
    a.joint = n == std::string("m0") ? "h0" : "h1";
    s.actuators.push_back(a);
  }
  ActuatorSpec mix;
  mix.name = "collective";
  mix.type = ActuatorType::Mix;
  mix.drives = {"m0", "m1"};
  mix.weights = Eigen::Vector2d(1, -1);
  s.actuators.push_back(mix);
  ActuatorSpec jet;
  jet.name = "jet";
  jet.type = ActuatorType::BodyForce;
  jet.body = "p2";
  jet.in_world = true;
  s.actuators.push_back(jet);
  const std::string w = refusal(s);
  ASSERT_FALSE(w.empty()) << "the export should be refused";
  EXPECT_NE(w.find("three.json: cannot export to MJCF without changing the dynamics"), std::string::npos) << w;
  EXPECT_NE(w.find("bushing mount: a 6-component spring-damper"), std::string::npos) << w;
  EXPECT_NE(w.find("body_force push: a constant applied force"), std::string::npos) << w;
  EXPECT_NE(w.find("coupler differential: 3 joints"), std::string::npos) << w;
  EXPECT_NE(w.find("mix collective: one input driving several actuators"), std::string::npos) << w;
  EXPECT_NE(w.find("body_force jet: in world axes"), std::string::npos) << w;
}

TEST(ExportMjcf, NonPlanarHingeClosureIsRefused) {
  const std::string w = refusal(load_example("bricard.json").spec);
  EXPECT_NE(w.find("revolute closure joint_F: the loop is not planar"), std::string::npos) << w;
}

TEST(ExportMjcf, FreeJointWithFramesIsRefused) {
  ModelSpec s = three_pendulums();
  s.joints[1].type = JointType::Free;
  const std::string w = refusal(s);
  EXPECT_NE(w.find("free joint h1: its frames are not the identity"), std::string::npos) << w;
}

TEST(ExportMjcf, UnequalDampingsOnABallAreRefused) {
  ModelSpec s = three_pendulums();
  s.joints[0].type = JointType::Spherical;
  EffectSpec e;
  e.name = "wx";
  e.type = EffectType::JointFriction;
  e.joint = "h0";
  e.dof = 0;
  e.damping = 0.3;
  s.effects.push_back(e);
  const std::string w = refusal(s);
  EXPECT_NE(w.find("joint h0: dampings that differ between the coordinates of a spherical joint (0.3 0 0"),
            std::string::npos) << w;
}

TEST(ExportMjcf, UnequalArmaturesOnABallAreRefused) {
  ModelSpec s = three_pendulums();
  s.joints[0].type = JointType::Spherical;
  s.joints[0].armature = Eigen::Vector3d(0.1, 0.1, 0.2);
  const std::string w = refusal(s);
  EXPECT_NE(w.find("joint h0: armatures that differ between the coordinates of a spherical joint (0.1 0.1 0.2"),
            std::string::npos) << w;
  s.joints[0].armature = Eigen::VectorXd::Constant(1, 0.1);  // one value: the same on all three
  const MjcfExport e = export_mjcf(compile(s), "three.json");
  EXPECT_NE(e.xml.find("<joint name=\"h0\" type=\"ball\" pos=\"0 0 0\" armature=\"0.1\"/>"), std::string::npos) << e.xml;
}

// --- the study call: the output guard ----------------------------------------------------------

class ExportMjcfFiles : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("codyna_export_mjcf_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    save_model_spec(three_pendulums(), (dir / "three.json").string());
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string p(const char* n) const { return (dir / n).string(); }
  static std::string read(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
};

TEST_F(ExportMjcfFiles, WritesAndReplacesItsOwnFile) {
  ExportMjcfRequest r{p("three.json"), p("three.xml")};
  const ExportMjcfResult a = study_export_mjcf(r);
  EXPECT_EQ(read(p("three.xml")), a.xml);
  EXPECT_NO_THROW(study_export_mjcf(r));  // an MJCF codyna wrote is replaced
}

TEST_F(ExportMjcfFiles, TheInputIsNeverTheOutput) {
  const std::string before = read(p("three.json"));
  try {
    study_export_mjcf({p("three.json"), p("three.json")});
    ADD_FAILURE() << "the model file was accepted as the output";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("this is the input file"), std::string::npos) << e.what();
  }
  fs::create_symlink(p("three.json"), p("link.xml"));
  EXPECT_THROW(study_export_mjcf({p("three.json"), p("link.xml")}), std::invalid_argument);
  EXPECT_EQ(read(p("three.json")), before);
}

TEST_F(ExportMjcfFiles, AFileCodynaDidNotWriteIsKept) {
  {
    std::ofstream f(p("scene.xml"));
    f << "<mujoco model=\"mine\"/>\n";
  }
  try {
    study_export_mjcf({p("three.json"), p("scene.xml")});
    ADD_FAILURE() << "a user's MJCF was replaced";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is not an MJCF export written by codyna"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read(p("scene.xml")), "<mujoco model=\"mine\"/>\n");
}

TEST_F(ExportMjcfFiles, ARefusedExportWritesNothing) {
  ModelSpec s = three_pendulums();
  EffectSpec b;
  b.name = "mount";
  b.type = EffectType::Bushing;
  b.body_a = "p0";
  b.body_b = "p1";
  s.effects.push_back(b);
  save_model_spec(s, p("bushing.json"));
  try {
    study_export_mjcf({p("bushing.json"), p("bushing.xml")});
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bushing mount"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(p("bushing.xml")));
  for (const auto& f : fs::directory_iterator(dir))  // no temporary file left behind
    EXPECT_EQ(f.path().filename().string().find(".tmp"), std::string::npos) << f.path();
}

}  // namespace
}  // namespace codyna::test
