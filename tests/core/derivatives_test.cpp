// Analytic derivatives of the tree dynamics (dynamics/derivatives.hpp) against
// forward-mode automatic differentiation of the same dynamics (an independent
// second method: the AD path differentiates the body-frame algorithms line by
// line, the analytic one uses world-frame recursions of its own).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "core/test_util.hpp"
#include "models/speed_models.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/sensors.hpp"
#include "dynamics/prepare.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {
namespace {

double rel_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

Eigen::MatrixXd derivatives_jac(const ADVec& f, int col0, int ncols) {
  Eigen::MatrixXd J(f.size(), ncols);
  for (Eigen::Index r = 0; r < f.size(); ++r)
    for (int c = 0; c < ncols; ++c)
      J(r, c) = f[r].derivatives().size() ? f[r].derivatives()[col0 + c] : 0.0;
  return J;
}

// random tree with every joint type plus every kind of applied force, actuator and sensor
ModelSpec rich_tree(unsigned seed, int n = 10) {
  ModelSpec s = test::random_tree_spec(seed, n);
  std::mt19937 rng(seed + 1000);
  auto effect = [&](const std::string& name, EffectType t) {
    EffectSpec e;
    e.name = name;
    e.type = t;
    return e;
  };
  EffectSpec e = effect("jspring", EffectType::JointSpringDamper);
  e.joint = "j1", e.stiffness = 7.0, e.damping = 0.3, e.rest_position = 0.2;
  s.effects.push_back(e);
  e = effect("jfric", EffectType::JointFriction);
  e.joint = "j2", e.dof = 1, e.damping = 0.4;
  s.effects.push_back(e);
  e = effect("ball_damper", EffectType::JointDamper);  // j2 is spherical: one value, three coordinates
  e.joint = "j2", e.damping = 0.25;
  s.effects.push_back(e);
  e = effect("free_damper", EffectType::JointDamper);  // j0 is free: six coordinates
  e.joint = "j0", e.damping = 0.05;
  s.effects.push_back(e);
  e = effect("spring36", EffectType::SpringDamper);
  e.body_a = "b3", e.body_b = "b6", e.point_a = test::random_vec(rng, 0.2), e.point_b = test::random_vec(rng, 0.2);
  e.stiffness = 30.0, e.damping = 1.5, e.rest_length = 0.3;
  s.effects.push_back(e);
  e = effect("spring_g4", EffectType::SpringDamper);
  e.body_a = std::string(kGroundName), e.body_b = "b4", e.point_a = test::random_vec(rng, 1.0);
  e.point_b = test::random_vec(rng, 0.2), e.stiffness = 12.0, e.damping = 0.7, e.rest_length = 0.5;
  s.effects.push_back(e);
  e = effect("push_world", EffectType::BodyForce);
  e.body_a = "b5", e.point_a = test::random_vec(rng, 0.3), e.force = test::random_vec(rng, 3.0);
  e.torque = test::random_vec(rng, 1.0), e.in_world = true;
  s.effects.push_back(e);
  e = effect("push_body", EffectType::BodyForce);
  e.body_a = "b8", e.point_a = test::random_vec(rng, 0.3), e.force = test::random_vec(rng, 3.0);
  e.torque = test::random_vec(rng, 1.0), e.in_world = false;
  s.effects.push_back(e);

  auto actuator = [&](const std::string& name, ActuatorType t) {
    ActuatorSpec a;
    a.name = name;
    a.type = t;
    return a;
  };
  ActuatorSpec a = actuator("m1", ActuatorType::JointForce);
  a.joint = "j1", a.gain = 2.0;
  s.actuators.push_back(a);
  a = actuator("m2", ActuatorType::JointForce);
  a.joint = "j2", a.dof = 2, a.gain = 0.5;
  s.actuators.push_back(a);
  a = actuator("f4", ActuatorType::BodyForce);
  a.body = "b4", a.point = test::random_vec(rng, 0.3), a.direction = test::random_vec(rng).normalized(), a.gain = 3.0;
  a.in_world = true;
  s.actuators.push_back(a);
  a = actuator("f9", ActuatorType::BodyForce);
  a.body = "b9", a.point = test::random_vec(rng, 0.3), a.direction = test::random_vec(rng).normalized(), a.gain = 1.5;
  a.in_world = false;
  s.actuators.push_back(a);
  a = actuator("t3", ActuatorType::BodyTorque);
  a.body = "b3", a.direction = test::random_vec(rng).normalized(), a.gain = 0.8, a.in_world = true;
  s.actuators.push_back(a);
  a = actuator("t7", ActuatorType::BodyTorque);
  a.body = "b7", a.direction = test::random_vec(rng).normalized(), a.gain = 1.2, a.in_world = false;
  s.actuators.push_back(a);

  auto sensor = [&](const std::string& name, SensorType t) {
    SensorSpec x;
    x.name = name;
    x.type = t;
    return x;
  };
  SensorSpec y = sensor("q1", SensorType::JointPosition);
  y.joint = "j1";
  s.sensors.push_back(y);
  y = sensor("w2", SensorType::JointVelocity);
  y.joint = "j2", y.dof = 0;
  s.sensors.push_back(y);
  y = sensor("p6_in_3", SensorType::PointPosition);
  y.body = "b6", y.point = test::random_vec(rng, 0.3), y.component = 1, y.frame = "b3";
  s.sensors.push_back(y);
  y = sensor("v9", SensorType::PointVelocity);
  y.body = "b9", y.point = test::random_vec(rng, 0.3), y.component = 2;
  s.sensors.push_back(y);
  y = sensor("v7_in_4", SensorType::PointVelocity);
  y.body = "b7", y.point = test::random_vec(rng, 0.3), y.component = 0, y.frame = "b4";
  s.sensors.push_back(y);
  y = sensor("angle5", SensorType::BodyAngle);
  y.body = "b5", y.axis = Eigen::Vector3d(0.0, 1.0, 1.0).normalized();
  s.sensors.push_back(y);
  y = sensor("angle9", SensorType::BodyAngle);  // j9 is spherical
  y.body = "b9", y.axis = Eigen::Vector3d(1.0, 0.0, 0.0);
  s.sensors.push_back(y);
  y = sensor("dist28", SensorType::Distance);
  y.body_a = "b2", y.body_b = "b8", y.point_a = test::random_vec(rng, 0.3), y.point_b = test::random_vec(rng, 0.3);
  s.sensors.push_back(y);
  for (const auto& x : s.actuators) s.plant.inputs.push_back(x.name);
  for (const auto& x : s.sensors) s.plant.outputs.push_back(x.name);
  return s;
}

TEST(TreeDerivatives, RneaMatchesAutodiffOnRandomTrees) {
  for (unsigned seed : {3u, 4u, 5u, 6u}) {
    const Model m = compile(test::random_tree_spec(seed, 12));
    std::mt19937 rng(seed);
    TreeDerivatives td(m);
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng, 2.0), a = test::random_v(m, rng, 3.0);
      td.rnea_derivatives(q, v, a);
      // AD: q = q (+) dz, the plant's tangent coordinates
      const int nv = m.nv;
      const ADVec dz = ad_seed(Eigen::VectorXd::Zero(nv), 2 * nv, 0), va = ad_seed(v, 2 * nv, nv);
      DataT<ADScalar> d(m);
      const ADVec qa = integrate<ADScalar>(m, q.cast<ADScalar>(), dz);
      const ADVec tau = rnea<ADScalar>(m, d, qa, va, ad_constant(a, 2 * nv));
      Eigen::VectorXd tv(nv);
      for (int i = 0; i < nv; ++i) tv[i] = tau[i].value();
      EXPECT_LT(rel_error(td.tau, tv), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dtau_dq, derivatives_jac(tau, 0, nv)), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dtau_dv, derivatives_jac(tau, nv, nv)), 1e-12) << "seed " << seed;
    }
  }
}

TEST(TreeDerivatives, ForwardDynamicsEffectsSensorsMatchAutodiff) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const Model m = compile(rich_tree(seed));
    std::mt19937 rng(seed);
    TreeDerivatives td(m);
    const int nv = m.nv, nu = m.nu();
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng, 2.0);
      Eigen::VectorXd u = test::random_v(m, rng, 1.0).head(nu);
      td.compute(q, v, u, m.plant_outputs);
      const int n = 2 * nv + nu;
      const ADVec dz = ad_seed(Eigen::VectorXd::Zero(nv), n, 0), va = ad_seed(v, n, nv), ua = ad_seed(u, n, 2 * nv);
      DataT<ADScalar> d(m);
      const ADVec qa = integrate<ADScalar>(m, q.cast<ADScalar>(), dz);
      const ADVec qdd = forward_dynamics<ADScalar>(m, d, qa, va, ua);
      forward_kinematics<ADScalar>(m, d, qa, va);
      const ADVec y = sensor_outputs<ADScalar>(m, d, m.plant_outputs, qa, va);
      Eigen::VectorXd qv(nv), yv(y.size());
      for (int i = 0; i < nv; ++i) qv[i] = qdd[i].value();
      for (Eigen::Index i = 0; i < y.size(); ++i) yv[i] = y[i].value();
      EXPECT_LT(rel_error(td.qdd, qv), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dqdd_dq, derivatives_jac(qdd, 0, nv)), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dqdd_dv, derivatives_jac(qdd, nv, nv)), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dqdd_du, derivatives_jac(qdd, 2 * nv, nu)), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.y, yv), 1e-13) << "seed " << seed;
      EXPECT_LT(rel_error(td.dy_dq, derivatives_jac(y, 0, nv)), 1e-12) << "seed " << seed;
      EXPECT_LT(rel_error(td.dy_dv, derivatives_jac(y, nv, nv)), 1e-12) << "seed " << seed;
    }
  }
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// linearize()'s exact Jacobian (analytic on trees) against autodiff of the plant function
void expect_plant_agrees(const Model& m, const OperatingPoint& op, const std::string& label) {
  const CoordinatePartition part = partition_coordinates(m, op.q);
  const PlantFunction f(m, op.q, op.u, part);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx());
  // the state's rates (as many as the coordinates, fewer with rolling's no-slip rows)
  for (int k = 0; k < f.nw(); ++k) x[f.nz() + k] = op.v[f.rates()[static_cast<std::size_t>(k)]];
  Eigen::VectorXd u(f.nu());
  for (int k = 0; k < f.nu(); ++k) u[k] = op.u[m.plant_inputs[k]];
  Eigen::MatrixXd J;
  ASSERT_TRUE(f.analytic_jacobian(x, u, J)) << label;
  const Eigen::MatrixXd Jad = plant_jacobian_autodiff(f, x, u);
  const Eigen::MatrixXd Jex = plant_jacobian(f, x, u, JacobianMethod::Exact);
  EXPECT_LT(rel_error(Jex, Jad), 1e-12) << label;
  // a second call reuses the workspace and gives the same numbers
  const Eigen::MatrixXd Jex2 = plant_jacobian(f, x, u, JacobianMethod::Exact);
  EXPECT_EQ((Jex2 - Jex).cwiseAbs().maxCoeff(), 0.0) << label;
}

// a random moving state with random inputs (moving: rotation tangents couple to the velocities)
OperatingPoint random_moving_point(const Model& m, unsigned seed) {
  std::mt19937 rng(seed);
  OperatingPoint op = initial_point(m);
  op.q = test::random_q(m, rng);
  op.v = test::random_v(m, rng, 1.5);
  op.u = test::random_v(m, rng, 1.0).head(m.nu());
  return op;
}

TEST(TreeDerivatives, PlantJacobianMatchesAutodiffOnRandomTrees) {
  for (unsigned seed : {21u, 22u, 23u}) {
    const Model m = compile(rich_tree(seed));
    expect_plant_agrees(m, random_moving_point(m, seed), "rich tree " + std::to_string(seed));
  }
}

// Branched trees: a star of every joint type on two bodies with every effect,
// actuator and sensor, and the 28-DOF humanoid of the speed benchmarks.
TEST(TreeDerivatives, PlantJacobianMatchesAutodiffOnBranchedTrees) {
  for (unsigned seed : {24u, 25u}) {
    ModelSpec s = rich_tree(seed);
    for (std::size_t i = 2; i < s.joints.size(); ++i) s.joints[i].parent = i % 2 ? "b0" : "b1";
    const Model m = compile(s);
    expect_plant_agrees(m, random_moving_point(m, seed), "branched rich tree " + std::to_string(seed));
  }
  const Model h = compile(speed_models::tree28());
  expect_plant_agrees(h, random_moving_point(h, 5), "tree28");
}

// compute() takes M^-1 from M's root-free Cholesky factors below 16 coordinates and from the
// articulated bodies from 16 on (branched trees of 16 to 31 coordinates from their tree-sparse
// factors: tree28 in PlantJacobianMatchesAutodiffOnBranchedTrees): both sides of that size, on random trees (every joint type; the
// rich one with every effect, actuator and sensor) and on the speed benchmarks' chains (at 31
// links the factors' M^-1 gave 6.5e-12 against autodiff, the articulated bodies 1.6e-12 at 32:
// the bound is kept low)
TEST(TreeDerivatives, PlantJacobianMatchesAutodiffOnBothSidesOfTheDenseSize) {
  bool below = false, above = false;
  for (int n : {5, 6, 7, 10}) {  // every joint type; at 10 bodies the rich tree (effects, sensors)
    const Model m = compile(n < 10 ? test::random_tree_spec(40u + static_cast<unsigned>(n), n) : rich_tree(50u));
    below = below || m.nv < 16;
    above = above || m.nv >= 16;
    expect_plant_agrees(m, random_moving_point(m, static_cast<unsigned>(n)),
                        "random tree of " + std::to_string(n) + " bodies, nv " + std::to_string(m.nv));
  }
  EXPECT_TRUE(below && above) << "the random trees no longer straddle 16 coordinates";
  for (int n : {15, 16}) {
    const Model m = compile(speed_models::chain(n));
    expect_plant_agrees(m, random_moving_point(m, static_cast<unsigned>(n)), "chain_" + std::to_string(n));
  }
}

// One coordinate: M^-1 is 1 / M exactly (no square root on the way), so a pendulum's B is the
// reciprocal of its inertia about the pin to the last bit
TEST(TreeDerivatives, OneCoordinateInverseIsTheReciprocal) {
  const Model m = compile(speed_models::chain(1));
  TreeDerivatives td(m);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.3), v = Eigen::VectorXd::Constant(1, -0.7);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(m.nu());
  td.compute(q, v, u, {});
  td.fill_mass_matrix();
  ASSERT_EQ(m.nu(), 1);
  EXPECT_EQ(td.dqdd_du(0, 0), m.actuators[0].gain * (1.0 / td.M(0, 0)));
}

TEST(TreeDerivatives, PlantJacobianMatchesAutodiffOnEveryExample) {
  int trees = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const Model m = test::load_example(entry.path().filename().string());
    // motion inputs have no analytic path: their exact Jacobian is autodiff's (motion_test.cpp
    // checks it over u, u', u'' against central differences)
    if (!m.motions.empty()) continue;
    trees += m.nc == 0;
    expect_plant_agrees(m, initial_point(m), entry.path().filename().string());
  }
  EXPECT_GE(trees, 2);
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// Closed loops: the exact (autodiff) Jacobian against central differences at
// the initial state of every example. Regression: planar_revolute rows mixed
// autodiff constants (empty derivative vectors) with variables inside one
// expression, and A02's exact Jacobian was off by a factor 11 (relative 11.25).
TEST(ClosedLoopJacobian, ExactAgreesWithCentralDifferencesOnEveryLoopExample) {
  int loops = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const Model m = test::load_example(entry.path().filename().string());
    if (m.nc == 0) continue;
    // the sedan's start (off equilibrium, stiff tires): central differences come within 4.4e-6
    // only; its exact Jacobian equals autodiff there (1e-14) and central differences at its
    // steady motions (5e-9): tests/core/sedan_test.cpp; sedan_esc.json is the same car
    if (entry.path().filename() == "sedan.json" || entry.path().filename() == "sedan_esc.json") continue;
    ++loops;
    const OperatingPoint op = initial_point(m);
    LinearizeOptions o;
    o.method = JacobianMethod::CentralDifference;
    const Linearization lin = linearize(m, op, o);
    EXPECT_LT(lin.fd_error, 1e-7) << entry.path().filename().string();
  }
  EXPECT_GE(loops, 4);
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// A random rich tree (every joint type, effect, actuator and sensor) closed by
// one loop of each constraint type between bodies in different branches, made
// consistent at a random configuration q: the closure points (and the revolute
// axes) are where body_a's are at q. Returns the model and q.
Model random_loop_model(unsigned seed, Eigen::VectorXd& q) {
  ModelSpec s = rich_tree(seed);
  const Model tree = compile(s);
  std::mt19937 rng(seed + 77);
  q = test::random_q(tree, rng);
  Data d(tree);
  forward_kinematics<double>(tree, d, q);
  auto body_index = [&](const std::string& name) {
    for (int b = 0; b < tree.nbodies; ++b)
      if (tree.body_names[b] == name) return b;
    return 0;
  };
  struct Pair {
    const char* a;
    const char* b;
    ConstraintType type;
  };
  for (const Pair& p : {Pair{"b4", "b9", ConstraintType::Ball}, Pair{"b6", "ground", ConstraintType::Revolute},
                        Pair{"b3", "b7", ConstraintType::PlanarRevolute}}) {
    ConstraintSpec c;
    c.name = std::string("loop_") + p.a + "_" + p.b;
    c.type = p.type;
    c.body_a = p.a;
    c.body_b = p.b;
    const int ia = body_index(p.a), ib = body_index(p.b);
    c.point_a = test::random_vec(rng, 0.3);
    const Eigen::Vector3d x = d.oMi[ia].act_point(c.point_a);
    c.point_b = d.oMi[ib].inverse().act_point(x);
    c.axis_a = test::random_vec(rng).normalized();
    c.axis_b = d.oMi[ib].R.transpose() * (d.oMi[ia].R * c.axis_a);
    s.constraints.push_back(c);
  }
  return compile(s);
}

// velocities on the loops: v projected onto the null space of Jc
Eigen::VectorXd consistent_v(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  const Eigen::MatrixXd Jc = d.Jc;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jc, Eigen::ComputeFullV);
  const int rank = static_cast<int>((svd.singularValues().array() > 1e-10).count());
  const Eigen::MatrixXd N = svd.matrixV().rightCols(m.nv - rank);
  return N * (N.transpose() * v);
}

TEST(ClosedLoopDerivatives, ReactionsAndClosureRowsMatchConstraintTerms) {
  for (unsigned seed : {31u, 32u}) {
    Eigen::VectorXd q;
    const Model m = random_loop_model(seed, q);
    std::mt19937 rng(seed);
    const Eigen::VectorXd v = test::random_v(m, rng, 1.5), a = test::random_v(m, rng, 2.0);
    const Eigen::VectorXd lam = test::random_v(m, rng, 3.0).head(m.nc);
    Data d(m);
    constraint_terms<double>(m, d, q, v);  // gamma at qdd = 0
    const Eigen::MatrixXd Jc = d.Jc;
    const Eigen::VectorXd gamma = d.gamma;
    TreeDerivatives td(m);
    std::vector<int> rows(m.nc);
    for (int r = 0; r < m.nc; ++r) rows[r] = r;
    Eigen::VectorXd lam0 = Eigen::VectorXd::Zero(m.nc);
    // Jc, c = Jc a + gamma, and the reactions Q(lambda) - Q(0) = -Jc^T lambda
    td.compute_constrained(q, v, Eigen::VectorXd::Zero(m.nu()), a, lam0, {}, {});
    const Eigen::VectorXd Q0 = td.Q;
    EXPECT_LT(rel_error(td.Jc, Jc), 1e-13) << seed;
    EXPECT_LT(rel_error(td.c, Jc * a + gamma), 1e-13) << seed;
    td.compute_constrained(q, v, Eigen::VectorXd::Zero(m.nu()), a, lam, {}, {});
    EXPECT_LT(rel_error(td.Q - Q0, -Jc.transpose() * lam), 1e-13) << seed;
    // their derivatives against autodiff of constraint_terms (tangent seeds: q = q Exp(dq))
    const int nv = m.nv;
    ADVec dq = ad_seed(Eigen::VectorXd::Zero(nv), 2 * nv, 0), va = ad_seed(v, 2 * nv, nv);
    DataT<ADScalar> da(m);
    constraint_terms<ADScalar>(m, da, integrate<ADScalar>(m, q.cast<ADScalar>(), dq), va);
    const ADVec cad = da.Jc * a.cast<ADScalar>() + da.gamma;
    const ADVec phid = da.Jc * va;
    EXPECT_LT(rel_error(td.dc_dq, derivatives_jac(cad, 0, nv)), 1e-12) << seed;
    EXPECT_LT(rel_error(td.dc_dv, derivatives_jac(cad, nv, nv)), 1e-12) << seed;
    EXPECT_LT(rel_error(td.dphid_dq, derivatives_jac(phid, 0, nv)), 1e-12) << seed;
    const ADVec react = -(da.Jc.transpose() * lam.cast<ADScalar>());
    td.compute_constrained(q, v, Eigen::VectorXd::Zero(m.nu()), a, lam, {}, {});
    const Eigen::MatrixXd dreact = td.dQ_dq;
    td.compute_constrained(q, v, Eigen::VectorXd::Zero(m.nu()), a, lam0, {}, {});
    EXPECT_LT(rel_error(dreact - td.dQ_dq, derivatives_jac(react, 0, nv)), 1e-12) << seed;
  }
}

TEST(ClosedLoopDerivatives, PlantJacobianMatchesAutodiffOnRandomLoops) {
  for (unsigned seed : {31u, 32u, 33u}) {
    Eigen::VectorXd q;
    const Model m = random_loop_model(seed, q);
    ASSERT_GT(m.nc, 0);
    std::mt19937 rng(seed);
    OperatingPoint op = initial_point(m);
    op.q = q;
    op.v = consistent_v(m, q, test::random_v(m, rng, 1.5));
    op.u = test::random_v(m, rng, 1.0).head(m.nu());
    expect_plant_agrees(m, op, "random loops " + std::to_string(seed));
  }
}

}  // namespace
}  // namespace codyna
