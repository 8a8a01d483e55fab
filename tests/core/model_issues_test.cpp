// Every problem of a model at once (study/model_issues.hpp), the values a model cannot hold refused
// where they are read (io/model_file), default names that follow the type (model/spec_edit), and a
// run that starts at the operating point (StudySpec::start).
#include "study/model_issues.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "io/model_file.hpp"
#include "model/spec_edit.hpp"
#include "study/files.hpp"
#include "study/tools.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

std::vector<std::string> issue_paths(const ModelCheck& c) {
  std::vector<std::string> p;
  for (const ModelError& e : c.issues) p.push_back(e.path());
  return p;
}

// the example's JSON with one value replaced, read: the reader's refusal (path and words), or ""
std::string read_refusal(const std::string& example, const std::string& pointer, const nlohmann::json& value) {
  nlohmann::json j = study_model_json(load_model_spec(example_path(example)));
  j[nlohmann::json::json_pointer(pointer)] = value;
  try {
    parse_model_spec(j, "m.json");
  } catch (const ModelError& e) {
    return e.path() + ": " + e.detail();
  }
  return "";
}

}  // namespace

TEST(ModelIssues, ACompilingModelHasNone) {
  const ModelCheck c = check_model(load_model_spec(example_path("bus_suspension.json")));
  ASSERT_TRUE(c.model);
  EXPECT_TRUE(c.issues.empty());
  EXPECT_EQ(c.model->nv, study_model(load_model_spec(example_path("bus_suspension.json"))).nv);
}

TEST(ModelIssues, ADeletedBodyIsAProblemInEveryFieldThatNamesIt) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  remove_element(s, ElementKind::Body, find_element(s, ElementKind::Body, "wheel"));
  const ModelCheck c = check_model(s, "bus.json");
  EXPECT_FALSE(c.model);
  // the joint that moved it, the suspension, the tire, the actuator and the sensor between
  // wheel and body: five fields, in the file's order
  EXPECT_EQ(issue_paths(c), (std::vector<std::string>{"/joints/1/child", "/effects/1/body_a", "/effects/2/body_b",
                                                    "/actuators/0/body_a", "/sensors/0/body_a"}));
  for (const ModelError& e : c.issues) {
    EXPECT_NE(e.detail().find("unknown body \"wheel\""), std::string::npos) << e.what();
    EXPECT_EQ(e.file(), "bus.json");
  }
  // the one study_model reports is among them, with its own words
  try {
    study_model(s, "bus.json");
    FAIL() << "compiled without the wheel";
  } catch (const ModelError& e) {
    ASSERT_LT(c.first, c.issues.size());
    EXPECT_EQ(c.issues[c.first].path(), e.path());
    EXPECT_EQ(std::string(c.issues[c.first].what()), std::string(e.what()));
  }
}

TEST(ModelIssues, EveryBodyNoJointMovesIsListed) {
  ModelSpec s;
  s.name = "new";
  for (int k = 0; k < 3; ++k) add_element(s, ElementKind::Body);
  s.bodies[1].name = "wheel";
  add_element(s, ElementKind::Joint);  // moves the last body
  const ModelCheck c = check_model(s);
  EXPECT_EQ(issue_paths(c), (std::vector<std::string>{"/bodies/0", "/bodies/1"}));
  EXPECT_NE(c.issues[1].detail().find("\"wheel\" is not the child of any joint"), std::string::npos);
  EXPECT_EQ(c.first, 0u);
}

// A model being built shows what is there: the draft holds the bodies no joint moves in a row
// along x (centres of mass 1.5 (r_i + r_j) apart, r the largest semi-axis of the ellipsoid of
// equal mass and inertia), and leaves out what still refers to nothing.
TEST(ModelIssues, TheDraftHoldsUnattachedBodiesInARow) {
  ModelSpec s;
  s.name = "new";
  for (int k = 0; k < 3; ++k) add_element(s, ElementKind::Body);
  s.bodies[1].mass = 4.0;                                              // r = sqrt(2.5 * 0.01 / 4)
  s.bodies[2].com = Eigen::Vector3d(0.3, -0.2, 0.1);
  s.bodies[2].inertia = Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal();  // r^2 = 2.5 (0.07 - 0.02) / 1
  const ModelCheck c = check_model(s);
  ASSERT_FALSE(c.model);
  ASSERT_TRUE(c.draft.model);
  EXPECT_TRUE(c.draft.leaves_out.empty());
  const Model& m = *c.draft.model;
  EXPECT_EQ(c.draft.held, (std::vector<std::string>{"body", "body_2", "body_3"}));
  ASSERT_EQ(m.nbodies, 4);
  EXPECT_EQ(m.nv, 0);
  // a default body (1 kg, 0.01 kg m^2 about every axis): r^2 = 2.5 (0.01 + 0.01 - 0.01) / 1
  const double r0 = std::sqrt(2.5 * 0.01), r1 = std::sqrt(2.5 * 0.01 / 4), r2 = std::sqrt(2.5 * 0.05);
  const double x[3] = {0, 1.5 * (r0 + r1), 1.5 * (r0 + r1) + 1.5 * (r1 + r2)};
  StudyPoses poses(m);
  const auto& oMi = poses.at(m.q0);
  for (int k = 0; k < 3; ++k) {
    const int i = m.find_body(s.bodies[static_cast<std::size_t>(k)].name);
    ASSERT_GT(i, 0);
    EXPECT_LT((oMi[static_cast<std::size_t>(i)].act_point(m.com[static_cast<std::size_t>(i)]) - Eigen::Vector3d(x[k], 0, 0)).norm(), 1e-14) << k;
  }
  // the spec itself is untouched: the holders are the draft's
  EXPECT_TRUE(s.joints.empty());
}

TEST(ModelIssues, TheDraftLeavesOutWhatRefersToNothingAndKeepsTheBodies) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  s.joints[1].parent = "chassis";  // not there: the joint is left out (and the sensor of its slide), its body (the wheel) held
  const ModelCheck c = check_model(s);
  ASSERT_FALSE(c.model);
  ASSERT_TRUE(c.draft.model);
  EXPECT_EQ(c.draft.leaves_out, (std::vector<std::string>{"joint X2", "sensor X2"}));
  EXPECT_EQ(c.draft.held, std::vector<std::string>{"wheel"});
  EXPECT_EQ(c.draft.model->nbodies, 4);  // ground, body, wheel, road: nothing of the user's is lost from sight
  EXPECT_EQ(c.draft.model->springs.size(), 2u);
  EXPECT_EQ(c.draft.model->nv, c.model ? -1 : study_model(load_model_spec(example_path("bus_suspension.json"))).nv - 1);  // the wheel held
  // an element naming a body that is gone is left out
  remove_element(s, ElementKind::Body, find_element(s, ElementKind::Body, "wheel"));
  const ModelCheck d = check_model(s);
  ASSERT_TRUE(d.draft.model);
  EXPECT_EQ(d.draft.model->nbodies, 3);
  EXPECT_GE(d.draft.leaves_out.size(), 3u);
  // a compiling model has no draft: it is its own picture
  EXPECT_FALSE(check_model(load_model_spec(example_path("bus_suspension.json"))).draft.model);
}

TEST(ModelIssues, PlantAndMixNamesThatAreGoneAreListed) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  s.plant.inputs = {"U", "nothing"};
  s.plant.outputs = {"gone", "X1"};
  const ModelCheck c = check_model(s);
  EXPECT_EQ(issue_paths(c), (std::vector<std::string>{"/plant/inputs/1", "/plant/outputs/0"}));
  EXPECT_NE(c.issues[0].detail().find("unknown actuator \"nothing\" (actuators: U, W)"), std::string::npos) << c.issues[0].detail();
}

TEST(ModelIssues, ValuesAModelCannotHoldAreRefusedWhereTheyAreRead) {
  // a spring-damper's stiffness, damping and rest length
  EXPECT_EQ(read_refusal("bus_suspension.json", "/effects/1/damping", -350),
            "/effects/1/damping: expected a non-negative number (a negative stiffness, damping or length would feed energy in), got number -350");
  EXPECT_NE(read_refusal("bus_suspension.json", "/effects/2/stiffness", -1).find("/effects/2/stiffness: expected a non-negative"), std::string::npos);
  EXPECT_NE(read_refusal("bus_suspension.json", "/effects/2/rest_length", -0.1).find("/effects/2/rest_length: expected a non-negative"),
            std::string::npos);
  EXPECT_EQ(read_refusal("bus_suspension.json", "/effects/1/damping", 0), "");  // 0 is a spring alone
  // a rolling ball's radius
  const std::string r = read_refusal("ball_plate.json", "/constraints/0/radius", 0);
  EXPECT_NE(r.find("/constraints/0/radius: expected a positive radius (m)"), std::string::npos) << r;
}

TEST(ModelIssues, ABushingsAxisIsRefusedByItsEntry) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  nlohmann::json j = study_model_json(s);
  j["effects"].push_back({{"name", "mount"}, {"type", "bushing"}, {"body_a", "ground"}, {"body_b", "body"},
                          {"translational_stiffness", {100, -200, 300}}});
  try {
    parse_model_spec(j, "m.json");
    FAIL() << "took a negative bushing stiffness";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/effects/3/translational_stiffness");
    EXPECT_NE(e.detail().find("non-negative"), std::string::npos);
  }
}

TEST(ModelIssues, RenamingAJointADriveMovesFollows) {
  // a motion input names its joint: a rename reaches it (it did not: the model then failed)
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  rename_element(s, ElementKind::Joint, find_element(s, ElementKind::Joint, "road_height"), "road");
  EXPECT_EQ(s.actuators[static_cast<std::size_t>(find_element(s, ElementKind::Actuator, "W"))].joint, "road");
  EXPECT_TRUE(check_model(s).model);
}

TEST(ModelIssues, DefaultNamesFollowTheType) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  // the model has its gravity: a new effect is a spring-damper from ground to the last body
  const int e = add_element(s, ElementKind::Effect);
  EXPECT_EQ(s.effects[static_cast<std::size_t>(e)].type, EffectType::SpringDamper);
  EXPECT_EQ(s.effects[static_cast<std::size_t>(e)].name, "spring");
  EXPECT_EQ(s.effects[static_cast<std::size_t>(e)].body_b, "road");
  EXPECT_TRUE(check_model(s).model);
  ModelSpec empty;
  add_element(empty, ElementKind::Effect);
  EXPECT_EQ(empty.effects[0].type, EffectType::Gravity);
  EXPECT_EQ(empty.effects[0].name, "gravity");
  EXPECT_TRUE(is_default_name(ElementKind::Effect, "gravity", "gravity_2"));
  EXPECT_TRUE(is_default_name(ElementKind::Effect, "spring_damper", "spring"));
  EXPECT_FALSE(is_default_name(ElementKind::Effect, "spring_damper", "suspension"));
  EXPECT_FALSE(is_default_name(ElementKind::Effect, "spring_damper", "spring_x"));
  EXPECT_FALSE(is_default_name(ElementKind::Effect, "spring_damper", "spring_02"));
  EXPECT_EQ(default_name(ElementKind::Actuator, "joint_force"), "motor");
  EXPECT_EQ(element_type(s, ElementKind::Actuator, 0), "line_force");
}

TEST(ModelIssues, ARunCanStartAtTheOperatingPoint) {
  ModelSpec s = load_model_spec(example_path("bus_suspension.json"));
  s.analysis.controller = "lqr";
  s.analysis.start = "operating-point";
  const Model m = study_model(s);
  const StudySimulation setup = study_simulation(m);
  ASSERT_TRUE(setup.plant);
  EXPECT_EQ(setup.start, "equilibrium");
  EXPECT_EQ(setup.options.q0, setup.plant->op.q);  // bit for bit: the point itself
  EXPECT_EQ(setup.options.v0, setup.plant->op.v);
  // the model's own state is elsewhere (unloaded springs): this is a real difference
  EXPECT_GT((m.q0 - setup.plant->op.q).cwiseAbs().maxCoeff(), 1e-3);
  // coordinates set on top of the point
  s.analysis.initial = {{"X1", 0.05}};
  const Model m2 = study_model(s);
  const StudySimulation kicked = study_simulation(m2);
  EXPECT_EQ(kicked.start, "equilibrium + study initial");
  const int x1 = m2.joints[static_cast<std::size_t>(m2.find_joint("X1"))].idx_q;
  const int x2 = m2.joints[static_cast<std::size_t>(m2.find_joint("X2"))].idx_q;
  EXPECT_EQ(kicked.options.q0[x1], 0.05);
  EXPECT_EQ(kicked.options.q0[x2], kicked.plant->op.q[x2]);
  // the file keeps it, and refuses a start it does not know
  const ModelSpec back = parse_model_spec(study_model_json(s), "m.json");
  EXPECT_EQ(back.analysis.start, "operating-point");
  nlohmann::json j = study_model_json(s);
  j["analysis"]["start"] = "somewhere";
  try {
    parse_model_spec(j, "m.json");
    FAIL() << "took start \"somewhere\"";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/start");
    EXPECT_NE(e.detail().find("model, operating-point"), std::string::npos) << e.detail();
  }
}
