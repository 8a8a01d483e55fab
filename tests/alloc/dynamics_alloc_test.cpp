// No heap allocation in forward dynamics and in one plant evaluation after the
// first call on a Data / PlantFunction: the counting allocator of
// counting_allocator.hpp around the second call of forward_dynamics<double>,
// crba<double>, PlantFunction::eval<double> and PlantFunction::fd_jacobian
// (finite differences), on the MuJoCo benchmark's
// chains (2 to 90 links) and ball-joint tree, and on every example
// (forward_dynamics also on the closed loops).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "counting_allocator.hpp"
#include "tire_models.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "models/speed_models.hpp"

namespace codyna {
namespace {

using alloc_test::Count;

Model load(const std::string& name) {
  const std::string path = std::string(CODYNA_EXAMPLES_DIR) + "/" + name;
  return compile(load_model_spec(path), path);
}

// a state away from the reference: every coordinate moved, every velocity and input non-zero
struct State {
  Eigen::VectorXd q, v, u;
  explicit State(const Model& m, const Eigen::VectorXd& q_ref) {
    std::mt19937 rng(11 + m.nv);
    std::uniform_real_distribution<double> u1(-1.0, 1.0);
    Eigen::VectorXd dq(m.nv);
    for (int i = 0; i < m.nv; ++i) dq[i] = 0.5 * u1(rng);
    q = integrate<double>(m, q_ref, dq);
    v.resize(m.nv);
    for (int i = 0; i < m.nv; ++i) v[i] = u1(rng);
    u.resize(m.nu());
    for (int i = 0; i < m.nu(); ++i) u[i] = u1(rng);
  }
};

long forward_dynamics_allocations(const Model& m) {
  const State s(m, m.q0);
  Data d(m);
  forward_dynamics<double>(m, d, s.q, s.v, s.u);  // warm-up
  Count c;
  forward_dynamics<double>(m, d, s.q, s.v, s.u);
  return c.n();
}

long crba_allocations(const Model& m) {
  const State s(m, m.q0);
  Data d(m);
  crba<double>(m, d, s.q);
  Count c;
  crba<double>(m, d, s.q);
  return c.n();
}

// PlantFunction::eval<double> at a state off the reference (position deviation and velocity)
long plant_eval_allocations(const Model& m) {
  const OperatingPoint op = initial_point(m);
  const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
  Eigen::VectorXd x(f.nx());
  for (int k = 0; k < f.nx(); ++k) x[k] = 0.05 + 0.02 * k;
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(f.nu(), 0.7);
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);  // warm-up: the workspace is made here
  x[0] += 0.01;
  Count c;
  f.eval<double>(x, u, xd, y);
  return c.n();
}

// PlantFunction::fd_jacobian into a J of the right size, central and forward
long fd_jacobian_allocations(const Model& m) {
  const OperatingPoint op = initial_point(m);
  const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
  Eigen::VectorXd x(f.nx());
  for (int k = 0; k < f.nx(); ++k) x[k] = 0.05 + 0.02 * k;
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(f.nu(), 0.7);
  Eigen::MatrixXd J;
  f.fd_jacobian(x, u, true, J);
  f.fd_jacobian(x, u, false, J);
  Count c;
  f.fd_jacobian(x, u, true, J);
  f.fd_jacobian(x, u, false, J);
  return c.n();
}

TEST(NoAllocation, ForwardDynamicsAndPlantOnChains) {
  for (int n : {1, 2, 7, 30, 90}) {
    const Model m = compile(speed_models::chain(n));
    EXPECT_EQ(forward_dynamics_allocations(m), 0) << "chain_" << n << ": forward_dynamics";
    EXPECT_EQ(crba_allocations(m), 0) << "chain_" << n << ": crba";
    EXPECT_EQ(plant_eval_allocations(m), 0) << "chain_" << n << ": PlantFunction::eval<double>";
    if (n <= 30) EXPECT_EQ(fd_jacobian_allocations(m), 0) << "chain_" << n << ": PlantFunction::fd_jacobian";
  }
}

TEST(NoAllocation, ForwardDynamicsAndPlantOnBallJointTree) {
  const Model m = compile(speed_models::tree28());
  EXPECT_EQ(forward_dynamics_allocations(m), 0) << "tree28: forward_dynamics";
  EXPECT_EQ(crba_allocations(m), 0) << "tree28: crba";
  EXPECT_EQ(plant_eval_allocations(m), 0) << "tree28: PlantFunction::eval<double>";
  EXPECT_EQ(fd_jacobian_allocations(m), 0) << "tree28: PlantFunction::fd_jacobian";
}

TEST(NoAllocation, ForwardDynamicsAndPlantOnEveryTreeExample) {
  int trees = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().filename().string();
    const Model m = load(name);
    if (m.nc != 0) continue;
    ++trees;
    EXPECT_EQ(forward_dynamics_allocations(m), 0) << name << ": forward_dynamics";
    EXPECT_EQ(plant_eval_allocations(m), 0) << name << ": PlantFunction::eval<double>";
    EXPECT_EQ(fd_jacobian_allocations(m), 0) << name << ": PlantFunction::fd_jacobian";
  }
  EXPECT_GE(trees, 3);
}

// closed loops: CRBA, the constraint terms and the Schur complement on the
// independent rows, in Data's loop workspace (at the assembled initial state);
// the plant evaluation in the PlantFunction's workspace
TEST(NoAllocation, ForwardDynamicsAndPlantOnEveryClosedLoopExample) {
  int loops = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().filename().string();
    const Model m = load(name);
    if (m.nc == 0) continue;
    ++loops;
    Data d(m);
    const Eigen::VectorXd u = m.u_nominal();
    forward_dynamics<double>(m, d, m.q0, m.v0, u);  // warm-up, without and with stabilization
    forward_dynamics<double>(m, d, m.q0, m.v0, u, Baumgarte{2.0, 3.0});
    long n = 0;
    {
      Count c;
      forward_dynamics<double>(m, d, m.q0, m.v0, u);
      forward_dynamics<double>(m, d, m.q0, m.v0, u, Baumgarte{2.0, 3.0});
      n = c.n();
    }
    EXPECT_EQ(n, 0) << name << ": forward_dynamics";
    // one plant evaluation: Newton for the dependent positions (with the motions' coordinates in
    // place), Jc v = 0 on the velocity rows (rolling's no-slip rows too), the dynamics, the sensors
    EXPECT_EQ(plant_eval_allocations(m), 0) << name << ": PlantFunction::eval<double>";
  }
  EXPECT_GE(loops, 3);
}

// motion inputs (bus suspension: a tree with a massless driven road; ball and beam: a coupler's
// loop row and the driven beam; the driven slider-crank: a motion on a loop's coordinate, J_d a_d
// in the loops' rows and J_d^T lambda in the reaction): the free coordinates' balance, the loops'
// Schur complement and the motions' reactions, in Data's loop workspace
TEST(NoAllocation, ForwardDynamicsWithMotionInputs) {
  int motions = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().filename().string();
    const Model m = load(name);
    if (m.motions.empty()) continue;
    ++motions;
    Data d(m);
    const Eigen::VectorXd u = m.u_nominal();
    Eigen::VectorXd v = m.v0;
    for (int k = 0; k < m.nv; ++k) v[k] += 0.1 + 0.01 * k;
    for (Eigen::Index k = 0; k < d.motion_acc.size(); ++k) d.motion_acc[k] = 0.3 - 0.2 * static_cast<double>(k);
    forward_dynamics<double>(m, d, m.q0, v, u);  // warm-up, without and with stabilization
    forward_dynamics<double>(m, d, m.q0, v, u, Baumgarte{2.0, 3.0});
    long n = 0;
    {
      Count c;
      forward_dynamics<double>(m, d, m.q0, v, u);
      forward_dynamics<double>(m, d, m.q0, v, u, Baumgarte{2.0, 3.0});
      n = c.n();
    }
    EXPECT_EQ(n, 0) << name << ": forward_dynamics";
    // the driven coordinates follow their accelerations; the reactions are M qdd + nle - Q there
    for (std::size_t k = 0; k < m.motions.size(); ++k)
      EXPECT_EQ(d.qdd[m.actuators[static_cast<std::size_t>(m.motions[k])].iv], d.motion_acc[static_cast<Eigen::Index>(k)])
          << name;
  }
  EXPECT_GE(motions, 3);
}

// rotor inertia (armature) on every joint with coordinates: one value on odd joints, one per
// coordinate on even ones
using alloc_test::kTires;  // tire_models.hpp

TEST(NoAllocation, ForwardDynamicsAndPlantWithTires) {
  const Model m = compile(parse_model_spec_text(kTires, "tires.json"), std::string(CODYNA_EXAMPLES_DIR) + "/tires.json");
  ASSERT_EQ(m.tires.size(), 3u);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(m.nu(), 0.3);
  Data d(m);
  forward_dynamics<double>(m, d, m.q0, m.v0, u);  // warm-up
  long n = 0;
  {
    Count c;
    forward_dynamics<double>(m, d, m.q0, m.v0, u);
    n = c.n();
  }
  EXPECT_EQ(n, 0) << "forward_dynamics with tires";
  // every tire carries a load (its wheel's vertical force, body axes, upright wheels)
  for (const char* j : {"j1", "j2", "j3"}) EXPECT_GT(d.Q[m.joints[m.find_joint(j)].idx_v + 5], 500.0) << j;
  // the plant at its operating point's velocities (every tire touching)
  const OperatingPoint op = initial_point(m);
  const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
  const Eigen::VectorXd x = f.qv_to_state(m.q0, m.v0);
  const Eigen::VectorXd up = Eigen::VectorXd::Constant(f.nu(), 0.3);
  Eigen::VectorXd xd, y;
  f.eval<double>(x, up, xd, y);
  {
    Count c;
    f.eval<double>(x, up, xd, y);
    n = c.n();
  }
  EXPECT_EQ(n, 0) << "PlantFunction::eval<double> with tires";
}

ModelSpec with_armature(ModelSpec s) {
  for (std::size_t k = 0; k < s.joints.size(); ++k) {
    JointSpec& j = s.joints[k];
    const int nv = joint_nv(j.type);
    if (nv == 0) continue;
    if (k % 2) j.armature = Eigen::VectorXd::Constant(1, 0.01 + 0.001 * k);
    else j.armature = Eigen::VectorXd::LinSpaced(nv, 0.02, 0.05);
  }
  return s;
}

TEST(NoAllocation, WithArmature) {
  for (const auto& [name, spec] : {std::pair<std::string, ModelSpec>{"chain_7", speed_models::chain(7)},
                                   std::pair<std::string, ModelSpec>{"tree28", speed_models::tree28()}}) {
    const Model m = compile(with_armature(spec));
    ASSERT_EQ(m.armature.size(), m.nv) << name;
    EXPECT_EQ(forward_dynamics_allocations(m), 0) << name << " with armature: forward_dynamics";
    EXPECT_EQ(crba_allocations(m), 0) << name << " with armature: crba";
    EXPECT_EQ(plant_eval_allocations(m), 0) << name << " with armature: PlantFunction::eval<double>";
    EXPECT_EQ(fd_jacobian_allocations(m), 0) << name << " with armature: PlantFunction::fd_jacobian";
    const State st(m, m.q0);
    Data d(m);
    rnea<double>(m, d, st.q, st.v, st.v);
    kinetic_energy<double>(m, d, st.q, st.v);
    long n = 0;
    {
      Count c;
      rnea<double>(m, d, st.q, st.v, st.v);
      kinetic_energy<double>(m, d, st.q, st.v);
      n = c.n();
    }
    EXPECT_EQ(n, 0) << name << " with armature: rnea, kinetic_energy";
  }
  // a closed loop through CRBA: the four-bar example with armature on its joints
  const Model m = compile(with_armature(load_model_spec(std::string(CODYNA_EXAMPLES_DIR) + "/four_bar.json")));
  ASSERT_GT(m.nc, 0);
  ASSERT_EQ(m.armature.size(), m.nv);
  Data d(m);
  const Eigen::VectorXd u = m.u_nominal();
  forward_dynamics<double>(m, d, m.q0, m.v0, u);
  long n = 0;
  {
    Count c;
    forward_dynamics<double>(m, d, m.q0, m.v0, u);
    n = c.n();
  }
  EXPECT_EQ(n, 0) << "four_bar with armature: forward_dynamics";
  EXPECT_EQ(plant_eval_allocations(m), 0) << "four_bar with armature: PlantFunction::eval<double>";
}

}  // namespace
}  // namespace codyna
