// Consistent edits of a ModelSpec (model/spec_edit.hpp): renames follow every reference.
#include "model/spec_edit.hpp"

#include <gtest/gtest.h>

#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

TEST(SpecEdit, RenameBodyUpdatesJointsAndSensors) {
  ModelSpec s = load_model_spec(example_path("cart_pendulum.json"));
  const int cart = find_element(s, ElementKind::Body, "cart");
  ASSERT_GE(cart, 0);
  const auto before = references_to(s, ElementKind::Body, "cart");
  EXPECT_FALSE(before.empty());
  rename_element(s, ElementKind::Body, cart, "trolley");
  EXPECT_TRUE(references_to(s, ElementKind::Body, "cart").empty());
  EXPECT_EQ(references_to(s, ElementKind::Body, "trolley").size(), before.size());
  EXPECT_NO_THROW(compile(s));
  EXPECT_THROW(rename_element(s, ElementKind::Body, cart, "rod"), std::invalid_argument);
  EXPECT_THROW(rename_element(s, ElementKind::Body, cart, "ground"), std::invalid_argument);
  EXPECT_THROW(rename_element(s, ElementKind::Body, cart, ""), std::invalid_argument);
}

TEST(SpecEdit, RenameActuatorSensorAndJointUpdatePlantAndStudy) {
  ModelSpec s = load_model_spec(example_path("cart_pendulum.json"));
  s.analysis.set = {{"rod_pivot", 0.1}};
  s.analysis.independent = {"rod_pivot"};
  rename_element(s, ElementKind::Actuator, find_element(s, ElementKind::Actuator, "force"), "push");
  rename_element(s, ElementKind::Sensor, find_element(s, ElementKind::Sensor, "theta"), "angle");
  rename_element(s, ElementKind::Joint, find_element(s, ElementKind::Joint, "rod_pivot"), "hinge");
  EXPECT_EQ(s.plant.inputs, std::vector<std::string>{"push"});
  EXPECT_EQ(s.plant.outputs, (std::vector<std::string>{"h", "angle"}));
  EXPECT_EQ(s.analysis.set[0].first, "hinge");
  EXPECT_EQ(s.analysis.independent[0], "hinge");
  const Model m = compile(s);
  EXPECT_EQ(m.sensors[m.find_sensor("angle")].iv, m.joints[m.find_joint("hinge")].idx_v);
}

TEST(SpecEdit, RemoveDropsPlantEntriesAndAddDuplicateMakeUniqueNames) {
  ModelSpec s = load_model_spec(example_path("cart_pendulum.json"));
  const int h = find_element(s, ElementKind::Sensor, "h");
  EXPECT_EQ(references_to(s, ElementKind::Sensor, "h"), std::vector<std::string>{"Plant/Out"});
  remove_element(s, ElementKind::Sensor, h);
  EXPECT_EQ(s.plant.outputs, std::vector<std::string>{"theta"});
  const int d = duplicate_element(s, ElementKind::Body, find_element(s, ElementKind::Body, "rod"));
  EXPECT_EQ(element_name(s, ElementKind::Body, d), "rod_copy");
  EXPECT_EQ(s.bodies[d].mass, s.bodies[find_element(s, ElementKind::Body, "rod")].mass);
  const int d2 = duplicate_element(s, ElementKind::Body, find_element(s, ElementKind::Body, "rod"));
  EXPECT_EQ(element_name(s, ElementKind::Body, d2), "rod_copy_2");
  const int a = add_element(s, ElementKind::Actuator);
  EXPECT_EQ(element_name(s, ElementKind::Actuator, a), "motor");
  EXPECT_EQ(unique_name(s, ElementKind::Body, "ground"), "ground_2");
}

TEST(SpecEdit, FieldPathsPointAtElements) {
  const auto r = element_at_path("/joints/2/parent_frame/position");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kind, ElementKind::Joint);
  EXPECT_EQ(r->index, 2);
  EXPECT_EQ(r->field, "parent_frame/position");
  EXPECT_TRUE(element_at_path("/bodies/0"));
  EXPECT_EQ(element_at_path("/bodies/0")->field, "");
  EXPECT_FALSE(element_at_path("/solver/rtol"));
  EXPECT_FALSE(element_at_path("/joints/x/name"));
  EXPECT_FALSE(element_at_path(""));
}
