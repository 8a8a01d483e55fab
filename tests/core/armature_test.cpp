// Joint armature (issues 19 and 20): rotor inertia on a coordinate, added to the diagonal of the
// joint-space mass matrix (MuJoCo's dof_armature; a geared motor's reflected rotor inertia).
// Checked against closed forms (a pendulum's (m l^2/3 + Ja) theta'', a geared rotor reflected as
// N^2 Jm through a coupler), between the three tree algorithms (CRBA's M, ABA's accelerations,
// RNEA's inverse dynamics), between the exact Jacobian, autodiff and central differences, and by
// the energy a passive simulation keeps.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/aba.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/energy.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/rnea.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "simulation/reference_integrator.hpp"
#include "spatial/autodiff.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

constexpr double kG = 9.81;

double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

ModelSpec parse(const std::string& text) { return study_parse_model_text(text, "armature_test.json"); }

// a number as JSON text, every digit kept
std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

// a uniform rod (m, l) pivoted at its end about z, hanging along -y; armature Ja on the pivot
std::string pendulum(double m, double l, const std::string& armature) {
  const double I = m * l * l / 12;
  return R"({"name": "rod",
    "bodies": [{"name": "rod", "mass": )" + num(m) + R"(, "com": [0, )" + num(-l / 2) +
         R"(, 0], "inertia": [)" + num(I) + ", " + num(1e-4) + ", " + num(I) + R"(]}],
    "joints": [{"name": "theta", "type": "revolute", "parent": "ground", "child": "rod", "axis": [0, 0, 1)" +
         (armature.empty() ? "]" : "], \"armature\": " + armature) + R"(}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "tau", "type": "joint_force", "joint": "theta"}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "theta"}],
    "plant": {"inputs": ["tau"], "outputs": ["angle"]},
    "analysis": {"operating_point": "initial"}})";
}

TEST(Armature, PendulumClosedForm) {
  // (m l^2/3 + Ja) theta'' = -m g (l/2) theta + tau about the hanging equilibrium
  const double m = 0.5, l = 0.4, Ja = 0.0125;
  const ModelSpec spec = parse(pendulum(m, l, "0.0125"));
  ASSERT_EQ(spec.joints[0].armature.size(), 1);
  EXPECT_EQ(spec.joints[0].armature[0], Ja);
  const Model model = study_model(spec);
  const double J = m * l * l / 3 + Ja;
  Data d(model);
  EXPECT_NEAR(crba<double>(model, d, model.q0)(0, 0), J, 1e-15);
  const LinearSystem s = study_linearize(model).system;
  Eigen::MatrixXd A(2, 2), B(2, 1);
  A << 0, 1, -m * kG * (l / 2) / J, 0;
  B << 0, 1 / J;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  // the same rod without armature: m l^2/3 alone (the field is what makes the difference)
  const LinearSystem s0 = study_linearize(study_model(parse(pendulum(m, l, "")))).system;
  EXPECT_NEAR(s0.A(1, 0), -m * kG * (l / 2) / (m * l * l / 3), 1e-12);
  EXPECT_GT(std::abs(s0.A(1, 0) - s.A(1, 0)), 1.0);
}

TEST(Armature, ReadWrittenAndRefusedAtTheField) {
  // scalar and per-coordinate forms survive a write and a read
  ModelSpec spec = parse(pendulum(0.5, 0.4, "0.25"));
  JointSpec ball;
  ball.name = "ball";
  ball.type = JointType::Spherical;
  ball.parent = "rod";
  ball.child = "bob";
  ball.armature = Eigen::Vector3d(0.1, 0.2, 0.3);
  BodySpec bob;
  bob.name = "bob";
  bob.mass = 1;
  bob.inertia = Eigen::Matrix3d::Identity() * 0.01;
  spec.bodies.push_back(bob);
  spec.joints.push_back(ball);
  const ModelSpec back = parse(study_model_json(spec).dump());
  ASSERT_EQ(back.joints[0].armature.size(), 1);
  EXPECT_EQ(back.joints[0].armature[0], 0.25);
  ASSERT_EQ(back.joints[1].armature.size(), 3);
  EXPECT_EQ(back.joints[1].armature, Eigen::VectorXd(Eigen::Vector3d(0.1, 0.2, 0.3)));
  const Model m = compile(back);
  ASSERT_EQ(m.armature.size(), 4);
  EXPECT_EQ(m.armature, Eigen::VectorXd(Eigen::Vector4d(0.25, 0.1, 0.2, 0.3)));
  // no armature anywhere: the Model holds none (the algorithms add nothing)
  EXPECT_EQ(compile(parse(pendulum(0.5, 0.4, ""))).armature.size(), 0);

  auto refused_at = [](const std::string& text, const std::string& path, const std::string& part) {
    try {
      (void)study_model(parse(text));
      ADD_FAILURE() << "accepted: " << path;
    } catch (const ModelError& e) {
      EXPECT_EQ(e.path(), path) << e.what();
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused_at(pendulum(0.5, 0.4, "-0.1"), "/joints/0/armature", "expected a number >= 0");
  refused_at(pendulum(0.5, 0.4, "\"big\""), "/joints/0/armature", "expected a number >= 0");
  refused_at(pendulum(0.5, 0.4, "[0.1, 0.2]"), "/joints/0/armature", "expected a number >= 0");
  refused_at(pendulum(0.5, 0.4, "[-0.1]"), "/joints/0/armature", "expected a number >= 0");
  // an array of one is one value (what the GUI's field gives): written back as a number
  const ModelSpec one = parse(pendulum(0.5, 0.4, "[0.125]"));
  ASSERT_EQ(one.joints[0].armature.size(), 1);
  EXPECT_EQ(study_model_json(one)["joints"][0]["armature"], 0.125);
  const nlohmann::json written = study_model_json(spec);
  EXPECT_EQ(written["joints"][0]["armature"], 0.25);  // one value: a number
  EXPECT_EQ(written["joints"][1]["armature"].size(), 3u) << written.dump();
  // a ball joint: three values, each >= 0
  ModelSpec bad = spec;
  bad.joints[1].armature = Eigen::Vector2d(0.1, 0.2);
  refused_at(study_model_json(bad).dump(), "/joints/1/armature", "3 numbers");
  bad.joints[1].armature = Eigen::Vector3d(0.1, -0.2, 0.3);
  refused_at(study_model_json(bad).dump(), "/joints/1/armature/1", "expected a number >= 0");
  // a fixed joint has no coordinate to carry it
  bad = spec;
  bad.joints[1].type = JointType::Fixed;
  bad.joints[1].armature = Eigen::VectorXd::Constant(1, 0.1);
  try {
    (void)compile(bad);
    ADD_FAILURE() << "armature on a fixed joint accepted";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/joints/1/armature") << e.what();
  }
  bad.joints[1].armature = Eigen::VectorXd::Constant(1, std::nan(""));
  bad.joints[1].type = JointType::Spherical;
  try {
    (void)compile(bad);
    ADD_FAILURE() << "a NaN armature accepted";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/joints/1/armature") << e.what();
  }
}

// a random tree of every joint type with armature on every joint that has coordinates: scalar on
// even joints, one value per coordinate on odd ones
ModelSpec armed_tree(unsigned seed, int n = 10) {
  ModelSpec s = test::random_tree_spec(seed, n);
  std::mt19937 rng(seed + 77);
  std::uniform_real_distribution<double> u(0.01, 0.5);
  for (std::size_t k = 0; k < s.joints.size(); ++k) {
    JointSpec& j = s.joints[k];
    const int nv = joint_nv(j.type);
    if (nv == 0) continue;
    if (k % 2 == 0 || nv == 1) j.armature = Eigen::VectorXd::Constant(1, u(rng));
    else {
      j.armature.resize(nv);
      for (int c = 0; c < nv; ++c) j.armature[c] = u(rng);
    }
  }
  return s;
}

TEST(Armature, CrbaAbaRneaAgreeAndMGainsExactlyTheDiagonal) {
  for (unsigned seed : {31u, 32u, 33u}) {
    const ModelSpec spec = armed_tree(seed, 12);
    ModelSpec bare = spec;
    for (JointSpec& j : bare.joints) j.armature.resize(0);
    const Model m = compile(spec), m0 = compile(bare);
    ASSERT_EQ(m.armature.size(), m.nv);
    std::mt19937 rng(seed);
    Data d(m), d0(m0);
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng, 2.0), tau = test::random_v(m, rng, 5.0);
      const Eigen::MatrixXd M = crba<double>(m, d, q);
      const Eigen::MatrixXd M0 = crba<double>(m0, d0, q);
      // the armature is the difference, on the diagonal only (each entry computed the same way)
      EXPECT_EQ((M - M0 - Eigen::MatrixXd(m.armature.asDiagonal())).cwiseAbs().maxCoeff() <= 1e-15 * M.cwiseAbs().maxCoeff(), true);
      // M from RNEA's columns: rnea(q, v, e_k) - rnea(q, v, 0)
      const Eigen::VectorXd bias = rnea<double>(m, d, q, v, Eigen::VectorXd::Zero(m.nv));
      Eigen::MatrixXd Mr(m.nv, m.nv);
      for (int k = 0; k < m.nv; ++k) Mr.col(k) = rnea<double>(m, d, q, v, Eigen::VectorXd::Unit(m.nv, k)) - bias;
      EXPECT_LT(rel_err(Mr, M), 1e-12) << "seed " << seed;
      // ABA's accelerations: RNEA gives tau back, and M qdd + bias = tau
      const Eigen::VectorXd qdd = aba<double>(m, d, q, v, tau);
      EXPECT_LT(rel_err(rnea<double>(m, d, q, v, qdd), tau), 1e-11) << "seed " << seed;
      EXPECT_LT(rel_err(M.ldlt().solve(tau - bias), qdd), 1e-11) << "seed " << seed;
      // without the armature ABA gives other accelerations (it is in D = S^T U + armature)
      EXPECT_GT(rel_err(aba<double>(m0, d0, q, v, tau), qdd), 1e-3);
      // kinetic energy = 1/2 v^T M v, M with the armature
      EXPECT_NEAR(kinetic_energy<double>(m, d, q, v), 0.5 * v.dot(M * v), 1e-12 * v.dot(M * v));
    }
  }
}

Eigen::MatrixXd jac(const ADVec& f, int col0, int ncols) {
  Eigen::MatrixXd J(f.size(), ncols);
  for (Eigen::Index r = 0; r < f.size(); ++r)
    for (int c = 0; c < ncols; ++c) J(r, c) = f[r].derivatives().size() ? f[r].derivatives()[col0 + c] : 0.0;
  return J;
}

// a 3-link chain: revolute (scalar armature), ball (one per coordinate), prismatic; a joint spring,
// motors on each joint and sensors
std::string chain3() {
  return R"({"name": "chain3",
    "bodies": [{"name": "l1", "mass": 1.2, "com": [0.2, 0.01, 0], "inertia": [0.002, 0.016, 0.017]},
               {"name": "l2", "mass": 0.8, "com": [0.15, 0, 0.02], "inertia": [[0.004, 0.001, 0], [0.001, 0.009, 0], [0, 0, 0.008]]},
               {"name": "l3", "mass": 0.5, "com": [0.05, 0.02, 0], "inertia": [0.001, 0.002, 0.0025]}],
    "joints": [{"name": "shoulder", "type": "revolute", "parent": "ground", "child": "l1", "axis": [0, 0, 1], "armature": 0.04},
               {"name": "elbow", "type": "spherical", "parent": "l1", "child": "l2", "parent_frame": {"position": [0.4, 0, 0]},
                "armature": [0.011, 0.023, 0.007]},
               {"name": "slide", "type": "prismatic", "parent": "l2", "child": "l3", "axis": [1, 0, 0],
                "parent_frame": {"position": [0.3, 0, 0]}, "armature": 1.7}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]},
                {"name": "spring", "type": "joint_spring_damper", "joint": "slide", "stiffness": 40, "damping": 0.3}],
    "actuators": [{"name": "m1", "type": "joint_force", "joint": "shoulder"},
                  {"name": "m2", "type": "joint_force", "joint": "elbow", "dof": 1, "gain": 2},
                  {"name": "m3", "type": "joint_force", "joint": "slide"},
                  {"name": "push", "type": "body_force", "body": "l3", "point": [0.1, 0, 0], "direction": [0, 1, 0]}],
    "sensors": [{"name": "q1", "type": "joint_position", "joint": "shoulder"},
                {"name": "tip", "type": "point_position", "body": "l3", "point": [0.1, 0, 0], "component": "y"},
                {"name": "tip_v", "type": "point_velocity", "body": "l3", "point": [0.1, 0, 0], "component": "x"}],
    "plant": {"inputs": ["m1", "m2", "m3", "push"], "outputs": ["q1", "tip", "tip_v"]}})";
}

TEST(Armature, TreeDerivativesMatchAutodiffOnAChain) {
  const Model m = compile(parse(chain3()));
  ASSERT_EQ(m.nv, 5);
  ASSERT_EQ(m.armature.size(), 5);
  std::mt19937 rng(41);
  TreeDerivatives td(m);
  const int nv = m.nv, nu = m.nu();
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng, 2.0);
    const Eigen::VectorXd u = test::random_v(m, rng, 3.0).head(nu);
    td.compute(q, v, u, m.plant_outputs);
    td.fill_mass_matrix();
    const int n = 2 * nv + nu;
    const ADVec dz = ad_seed(Eigen::VectorXd::Zero(nv), n, 0), va = ad_seed(v, n, nv), ua = ad_seed(u, n, 2 * nv);
    DataT<ADScalar> d(m);
    const ADVec qa = integrate<ADScalar>(m, q.cast<ADScalar>(), dz);
    const ADVec qdd = forward_dynamics<ADScalar>(m, d, qa, va, ua);
    Eigen::VectorXd qv(nv);
    for (int i = 0; i < nv; ++i) qv[i] = qdd[i].value();
    Data dd(m);
    EXPECT_LT(rel_err(td.M, crba<double>(m, dd, q)), 1e-14);
    EXPECT_LT(rel_err(td.qdd, qv), 1e-12);
    EXPECT_LT(rel_err(td.dqdd_dq, jac(qdd, 0, nv)), 1e-12);
    EXPECT_LT(rel_err(td.dqdd_dv, jac(qdd, nv, nv)), 1e-12);
    EXPECT_LT(rel_err(td.dqdd_du, jac(qdd, 2 * nv, nu)), 1e-12);
    // inverse dynamics with its derivatives: tau includes armature a
    const Eigen::VectorXd a = test::random_v(m, rng, 3.0);
    td.rnea_derivatives(q, v, a);
    EXPECT_LT(rel_err(td.tau, rnea<double>(m, dd, q, v, a)), 1e-12);
    const ADVec tau = rnea<ADScalar>(m, d, qa, va, ad_constant(a, n));
    EXPECT_LT(rel_err(td.dtau_dq, jac(tau, 0, nv)), 1e-12);
    EXPECT_LT(rel_err(td.dtau_dv, jac(tau, nv, nv)), 1e-12);
  }
}

// the plant's exact Jacobian [A B; C D] == autodiff == central differences, at random moving states
void expect_jacobians_agree(const Model& m, const OperatingPoint& op, double tol_fd, const std::string& label) {
  const CoordinatePartition part = partition_coordinates(m, op.q);
  const PlantFunction f(m, op.q, op.u, part);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx());
  for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = op.v[part.independent[k]];
  Eigen::VectorXd u(f.nu());
  for (int k = 0; k < f.nu(); ++k) u[k] = op.u[m.plant_inputs[k]];
  const Eigen::MatrixXd Jex = plant_jacobian(f, x, u, JacobianMethod::Exact);
  const Eigen::MatrixXd Jad = plant_jacobian_autodiff(f, x, u);
  const Eigen::MatrixXd Jfd = plant_jacobian(f, x, u, JacobianMethod::CentralDifference);
  EXPECT_LT(rel_err(Jex, Jad), 1e-12) << label;
  EXPECT_LT(rel_err(Jex, Jfd), tol_fd) << label;
  std::cout << "[armature] " << label << ": exact vs autodiff " << rel_err(Jex, Jad) << ", vs central differences "
            << rel_err(Jex, Jfd) << std::endl;
}

TEST(Armature, ExactJacobianEqualsAutodiffAndCentralDifferences) {
  const Model m = compile(parse(chain3()));
  std::mt19937 rng(43);
  for (int trial = 0; trial < 3; ++trial) {
    OperatingPoint op = initial_point(m);
    op.q = test::random_q(m, rng);
    op.v = test::random_v(m, rng, 1.5);
    op.u = test::random_v(m, rng, 2.0).head(m.nu());
    expect_jacobians_agree(m, op, 1e-7, "chain3 state " + num(trial));
  }
  // every joint type, armature everywhere
  const Model t = compile(armed_tree(44, 10));
  std::mt19937 rng2(44);
  OperatingPoint op = initial_point(t);
  op.q = test::random_q(t, rng2);
  op.v = test::random_v(t, rng2, 1.0);
  expect_jacobians_agree(t, op, 1e-6, "armed tree");
}

// A geared motor (issue 19): the rotor is a coordinate with only its armature Jm (a massless frame),
// geared N:1 to a pendulum by a coupler; the closed loop's CRBA path carries the armature:
// (m l^2/3 + N^2 Jm) theta'' = -m g (l/2) theta + N tau_m
// (rotor_body: the rotor a body of inertia Jm about the axis instead, no armature)
std::string geared(double Jm, double N, double m, double l, bool rotor_body = false) {
  const double I = m * l * l / 12;
  return R"({"name": "geared",
    "bodies": [{"name": "rotor", "mass": )" + std::string(rotor_body ? "1" : "0") + R"(, "inertia": [)" +
         num(rotor_body ? Jm : 0) + ", " + num(rotor_body ? Jm : 0) + ", " + num(rotor_body ? Jm : 0) + R"(]},
               {"name": "rod", "mass": )" + num(m) + R"(, "com": [0, )" + num(-l / 2) +
         R"(, 0], "inertia": [)" + num(I) + ", 1e-4, " + num(I) + R"(]}],
    "joints": [{"name": "motor", "type": "revolute", "parent": "ground", "child": "rotor", "axis": [0, 0, 1], "armature": )" +
         num(rotor_body ? 0 : Jm) + R"(},
               {"name": "theta", "type": "revolute", "parent": "ground", "child": "rod", "axis": [0, 0, 1]}],
    "constraints": [{"name": "gear", "type": "coupler", "joint_a": "motor", "ratio_a": 1, "joint_b": "theta", "ratio_b": )" +
         num(-N) + R"(}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "tau_m", "type": "joint_force", "joint": "motor"}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "theta"}],
    "plant": {"inputs": ["tau_m"], "outputs": ["angle"]},
    "analysis": {"operating_point": "initial", "independent": ["theta"]}})";
}

TEST(Armature, GearedMotorRotorReflectsAsNSquaredThroughACoupler) {
  const double Jm = 1e-4, N = 50, m = 0.5, l = 0.4;
  const Model model = study_model(parse(geared(Jm, N, m, l)));
  ASSERT_EQ(model.dof(), 1);
  const LinearSystem s = study_linearize(model).system;
  const double J = m * l * l / 3 + N * N * Jm;
  Eigen::MatrixXd A(2, 2), B(2, 1);
  A << 0, 1, -m * kG * (l / 2) / J, 0;
  B << 0, N / J;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-12));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-12));
  // the closed loop's exact Jacobian away from equilibrium, where the gear's reaction is not zero
  std::mt19937 rng(45);
  OperatingPoint op = initial_point(model);
  op.q << N * 0.3, 0.3;
  op.v << N * -1.1, -1.1;
  op.u << 0.2;
  expect_jacobians_agree(model, op, 1e-7, "geared rotor (closed loop)");
  const Model body = study_model(parse(geared(Jm, N, m, l, true)));
  expect_jacobians_agree(body, op, 1e-7, "geared rotor body (closed loop, no armature)");
}

double total_energy(const Model& m, const State& x) {
  Data d(m);
  return kinetic_energy<double>(m, d, x.q, x.v) + potential_energy<double>(m, d, x.q);
}

TEST(Armature, PassiveSimulationConservesEnergy) {
  // chain3 without its damper and motors; RK4 at h = 1e-4 for 2 s
  ModelSpec spec = parse(chain3());
  spec.effects[1].damping = 0;
  const Model m = compile(spec);
  std::mt19937 rng(47);
  State x{test::random_q(m, rng), test::random_v(m, rng, 2.0)};
  const double E0 = total_energy(m, x);
  Data d(m);
  const double T0 = kinetic_energy<double>(m, d, x.q, x.v);
  double worst = 0;
  for (int chunk = 0; chunk < 20; ++chunk) {
    x = rk4_integrate(m, x, Eigen::VectorXd::Zero(m.nu()), 1e-4, 1000);
    worst = std::max(worst, std::abs(total_energy(m, x) - E0));
  }
  std::cout << "[armature] chain3 energy " << E0 << " J (kinetic " << T0 << "), worst drift over 2 s " << worst << std::endl;
  EXPECT_LT(worst, 1e-9 * std::abs(E0));
  // the rotors hold a share of the kinetic energy large enough that leaving them out would show
  EXPECT_GT(0.5 * x.v.dot(m.armature.asDiagonal() * x.v), 1e-3 * std::abs(E0));

  // the geared pendulum through the closed-loop path (rotor energy included)
  const Model g = study_model(parse(geared(1e-4, 50, 0.5, 0.4)));
  State y{g.q0, g.v0};
  y.q << 50 * 0.5, 0.5;
  y.v << 50 * 0.8, 0.8;
  const double G0 = total_energy(g, y);
  double gworst = 0;
  for (int chunk = 0; chunk < 10; ++chunk) {
    y = rk4_integrate(g, y, Eigen::VectorXd::Zero(g.nu()), 1e-4, 1000);
    gworst = std::max(gworst, std::abs(total_energy(g, y) - G0));
  }
  std::cout << "[armature] geared pendulum energy " << G0 << " J, worst drift over 1 s " << gworst << std::endl;
  EXPECT_LT(gworst, 1e-8 * std::abs(G0));
}

}  // namespace
}  // namespace codyna

