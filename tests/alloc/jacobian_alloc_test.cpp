// No heap allocation in one exact plant Jacobian after the first call: a
// counting global operator new/delete (this executable only) around the
// second call of PlantFunction::analytic_jacobian (trees and closed loops) and
// TreeDerivatives::compute.
#include <gtest/gtest.h>

#include <filesystem>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "dynamics/derivatives.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "models/speed_models.hpp"
#include "counting_allocator.hpp"
#include "tire_models.hpp"

namespace codyna {
namespace {

using alloc_test::Count;
using alloc_test::kTires;

Model load(const std::string& name) {
  const std::string path = std::string(CODYNA_EXAMPLES_DIR) + "/" + name;
  return compile(load_model_spec(path), path);
}

void expect_no_allocation(const Model& m, const std::string& label) {
  const OperatingPoint op = initial_point(m);
  const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx());
  for (int k = 0; k < f.nw(); ++k) x[f.nz() + k] = 0.3 + 0.1 * k;
  Eigen::VectorXd u = Eigen::VectorXd::Constant(f.nu(), 0.7);
  // motion inputs: at their operating values (the analytic path differentiates there)
  for (int j = 0; j < f.nm(); ++j) u[f.motion_inputs()[j]] = op.u[m.plant_inputs[f.motion_inputs()[j]]];
  Eigen::MatrixXd J;
  ASSERT_TRUE(f.analytic_jacobian(x, u, J)) << label;  // warm-up: the workspace is made here
  long n = 0;
  {
    Count c;
    f.analytic_jacobian(x, u, J);
    n = c.n();
  }
  EXPECT_EQ(n, 0) << label << ": heap allocations in one exact Jacobian after warm-up";
}

TEST(NoAllocation, ExactJacobianCartPendulum) { expect_no_allocation(load("cart_pendulum.json"), "cart_pendulum"); }

// trees and closed loops (the constrained derivatives and the velocity maps of the loops)
TEST(NoAllocation, ExactJacobianEveryExample) {
  int trees = 0, loops = 0, motions = 0, rolling = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    // a motion's reaction as an output is differentiated automatically (it reads the
    // accelerations): left out here, the analytic path is what this counts
    const std::string path = entry.path().string();
    ModelSpec spec = load_model_spec(path);
    std::erase_if(spec.plant.outputs, [&](const std::string& name) {
      for (const SensorSpec& s : spec.sensors)
        if (s.name == name) return s.type == SensorType::MotionForce;
      return false;
    });
    const Model m = compile(spec, path);
    if (!m.velocity_rows.empty()) ++rolling;
    if (!m.motions.empty()) ++motions;
    (m.nc == 0 ? trees : loops) += 1;
    expect_no_allocation(m, entry.path().filename().string());
  }
  EXPECT_GE(trees, 3);
  EXPECT_GE(loops, 4);
  // motion inputs: the bus suspension (a tree), the ball and beam (a loop row), the driven
  // slider-crank (a motion on a loop's coordinate)
  EXPECT_GE(motions, 3);
  // examples/ball_plate.json and rolling_disc.json: rolling's no-slip rows and their velocity map
  EXPECT_EQ(rolling, 2);
}

// the speed benchmarks' 28-coordinate tree takes M^-1 from its tree-sparse factors (tree_inverse)
// and the 30-link chain from the articulated bodies: neither allocates
TEST(NoAllocation, ExactJacobianTree28AndChain30) {
  expect_no_allocation(compile(speed_models::tree28()), "tree28");
  expect_no_allocation(compile(speed_models::chain(30)), "chain_30");
}

// rotor inertia (armature) on every joint of a branched tree (ball joints among them) and of a
// closed loop: the exact Jacobian stays on the stack
TEST(NoAllocation, ExactJacobianWithArmature) {
  for (const std::string name : {"double_pendulum.json", "four_bar.json", "heavy_top.json"}) {
    ModelSpec s = load_model_spec(std::string(CODYNA_EXAMPLES_DIR) + "/" + name);
    for (JointSpec& j : s.joints)
      if (joint_nv(j.type) > 0) j.armature = Eigen::VectorXd::LinSpaced(joint_nv(j.type), 0.02, 0.05);
    const Model m = compile(s);
    ASSERT_EQ(m.armature.size(), m.nv) << name;
    expect_no_allocation(m, name + " with armature");
  }
}

// issue 19's elements where no example has them: a bushing (off the centre of mass, turned, both
// of its frames on moving bodies) and a line_force driven through a mix, on a two-body tree
const char* kBushingAndMix = R"({"name": "elements",
  "bodies": [{"name": "a", "mass": 2, "com": [0.1, 0, 0], "inertia": [0.1, 0.2, 0.3]},
             {"name": "b", "mass": 3, "com": [0, 0.2, 0], "inertia": [0.2, 0.1, 0.3]}],
  "joints": [{"name": "ja", "type": "revolute", "parent": "ground", "child": "a", "axis": [0, 0, 1], "q0": 0.3},
             {"name": "jb", "type": "free", "parent": "a", "child": "b", "q0": [0.1, 0.2, 0.05, 0.98, 0.1, 0.1, 0.1]}],
  "effects": [{"name": "gravity", "type": "gravity"},
              {"name": "mount", "type": "bushing", "body_a": "a", "frame_a": {"position": [0.2, 0, 0]},
               "body_b": "b", "frame_b": {"position": [0, 0.1, 0], "rotation": {"axis": [0, 0, 1], "angle": 0.4}},
               "translational_stiffness": [400, 900, 1600], "translational_damping": [2, 3, 4],
               "rotational_stiffness": [30, 50, 70], "rotational_damping": [0.3, 0.5, 0.7]}],
  "actuators": [{"name": "strut", "type": "line_force", "body_a": "ground", "point_a": [0, 1, 0],
                 "body_b": "b", "point_b": [0.1, 0, 0]},
                {"name": "motor", "type": "joint_force", "joint": "ja"},
                {"name": "both", "type": "mix", "drives": ["strut", "motor"], "weights": [1, 0.2]}],
  "sensors": [{"name": "gap", "type": "distance", "body_a": "ground", "point_a": [0, 1, 0], "body_b": "b", "point_b": [0.1, 0, 0]},
              {"name": "gap_rate", "type": "distance_rate", "body_a": "ground", "point_a": [0, 1, 0], "body_b": "b", "point_b": [0.1, 0, 0]}],
  "plant": {"inputs": ["both", "strut"], "outputs": ["gap", "gap_rate"]}})";

TEST(NoAllocation, ExactJacobianWithBushingLineForceAndMix) {
  const Model m = compile(parse_model_spec_text(kBushingAndMix, "elements.json"));
  expect_no_allocation(m, "bushing, line_force and mix");
}


TEST(NoAllocation, ExactJacobianWithTires) {
  // compiled as if read from examples/ (the .tir path is relative to the model file)
  const Model m = compile(parse_model_spec_text(kTires, "tires.json"), std::string(CODYNA_EXAMPLES_DIR) + "/tires.json");
  ASSERT_EQ(m.tires.size(), 3u);
  expect_no_allocation(m, "tires");
}
// a long chain: blocked factorizations and solves stay on the stack too
TEST(NoAllocation, ExactJacobianNinetyLinkChain) {
  ModelSpec s;
  s.name = "chain90";
  for (int i = 0; i < 90; ++i) {
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 1.0 + 0.01 * i;
    b.com = Eigen::Vector3d(0.2, 0.01, 0.0);
    b.inertia = Eigen::Vector3d(0.01, 0.02, 0.025).asDiagonal();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.type = JointType::Revolute;
    j.parent = i ? "b" + std::to_string(i - 1) : std::string(kGroundName);
    j.child = b.name;
    j.axis = i % 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    j.parent_frame.position = Eigen::Vector3d(i ? 0.4 : 0.0, 0.0, 0.0);
    s.joints.push_back(j);
    ActuatorSpec a;
    a.name = "m" + std::to_string(i);
    a.joint = j.name;
    s.actuators.push_back(a);
    s.plant.inputs.push_back(a.name);
  }
  EffectSpec g;
  g.name = "gravity";
  g.type = EffectType::Gravity;
  s.effects.push_back(g);
  SensorSpec y;
  y.name = "tip_x";
  y.type = SensorType::PointPosition;
  y.body = "b89";
  s.sensors.push_back(y);
  s.plant.outputs.push_back("tip_x");
  expect_no_allocation(compile(s), "chain90");
}

// the counter itself sees both kinds of allocation
TEST(NoAllocation, CounterSeesAnAllocation) {
  long n_new = 0, n_eigen = 0;
  {
    Count c;
    std::vector<double>* v = new std::vector<double>(100);
    delete v;
    n_new = c.n();
  }
  {
    Count c;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(1000);
    n_eigen = c.n() + (x[0] == 1.0);
  }
  EXPECT_GE(n_new, 2);
  EXPECT_GE(n_eigen, 1);
}

}  // namespace
}  // namespace codyna
