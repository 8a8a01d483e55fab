// Linearization against the paper's closed forms (docs MISSION.md), exact
// against finite differences, and a closed loop against an energy method.
#include "analysis/linearize.hpp"

#include <cmath>

#include "analysis/operating_point.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/energy.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;
constexpr double g_lin = 9.81;

// A spring-damper whose two points coincide at the operating point. Rest length 0 and no
// damping: the force k (x_b - x_a) is smooth through the coincidence and exact and central
// differences agree with the closed form k / m (before, exact dropped the spring there and the
// two methods disagreed); a rest length or a damping has no direction there: refused, naming
// the element. The same spring 1 mm off coincidence gives the same A to 1e-9.
TEST(Linearize, CoincidentSpringDamperPoints) {
  const auto slider = [](double damping, double rest, double x0) {
    const std::string text = R"({"name": "slider",
      "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
      "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0], "q0": )" +
                             std::to_string(x0) + R"(}],
      "effects": [{"name": "tie", "type": "spring_damper", "body_a": "ground", "point_a": [0, 0, 0],
                   "body_b": "block", "point_b": [0, 0, 0], "stiffness": 250, "damping": )" +
                             std::to_string(damping) + R"(, "rest_length": )" + std::to_string(rest) + R"(}],
      "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N"}],
      "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
      "plant": {"inputs": ["force"], "outputs": ["pos"]}})";
    return compile(parse_model_spec_text(text, "slider.json"), "slider.json");
  };
  const Model m = slider(0.0, 0.0, 0.0);
  const OperatingPoint op = initial_point(m);
  LinearizeOptions exact, central;
  central.method = JacobianMethod::CentralDifference;
  const Linearization le = linearize(m, op, exact), lc = linearize(m, op, central);
  EXPECT_NEAR(le.system.A(1, 0), -250.0 / 2.0, 1e-12);
  EXPECT_NEAR(lc.system.A(1, 0), -250.0 / 2.0, 1e-6);
  const Model off = slider(0.0, 0.0, 1e-3);
  EXPECT_NEAR(linearize(off, initial_point(off), exact).system.A(1, 0), le.system.A(1, 0), 1e-9);
  for (const auto& [damping, rest] : {std::pair{3.0, 0.0}, std::pair{0.0, 0.5}}) {
    const Model bad = slider(damping, rest, 0.0);
    try {
      (void)linearize(bad, initial_point(bad), exact);
      FAIL() << "accepted damping " << damping << ", rest length " << rest;
    } catch (const ModelError& e) {
      EXPECT_EQ(e.path(), "/effects/0");
      EXPECT_NE(std::string(e.what()).find("\"tie\": its two points coincide"), std::string::npos) << e.what();
    }
  }
}

TEST(Linearize, PaperPendulumUpright) {
  const Model m = test::load_example("pendulum.json");
  const OperatingPoint op = static_equilibrium(m, initial_point(m));  // starts 10 deg off upright
  ASSERT_NEAR(op.q[0], M_PI / 2, 1e-12);
  const double mass = 10, l = 2;
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2), D = Eigen::MatrixXd::Zero(1, 1);
  A << 0, 1, 3 * g_lin / (2 * l), 0;
  B << 0, 3 / (mass * l * l);
  C << 1, 0;
  const LinearSystem s = linearize(m, op).system;
  EXPECT_TRUE(MatrixNear(s.A, A, 1e-10));
  EXPECT_TRUE(MatrixNear(s.B, B, 1e-10));
  EXPECT_TRUE(MatrixNear(s.C, C, 1e-10));
  EXPECT_TRUE(MatrixNear(s.D, D, 1e-10));
  EXPECT_NEAR(s.A(1, 0), 3 * g_lin / 4, 1e-10 * 3 * g_lin / 4);
  EXPECT_NEAR(s.B(1, 0), 0.075, 1e-12);
  EXPECT_NEAR(s.x0[0], M_PI / 2, 1e-12);
  EXPECT_NEAR(s.y0[0], M_PI / 2, 1e-12);
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"pivot", "pivot_dot"}));
  EXPECT_EQ(s.input_names, std::vector<std::string>{"torque"});
  EXPECT_EQ(s.output_names, std::vector<std::string>{"theta"});
}

TEST(Linearize, PaperPendulumAwayFromEquilibrium) {
  const Model m = test::load_example("pendulum.json");
  const OperatingPoint op = initial_point(m);
  const double th = op.q[0], l = 2;
  const LinearSystem s = linearize(m, op).system;
  EXPECT_NEAR(s.A(1, 0), 3 * g_lin / (2 * l) * std::sin(th), 1e-10);
  EXPECT_NEAR(s.xdot0[1], -3 * g_lin / (2 * l) * std::cos(th), 1e-10);  // not at rest: xdot0 != 0
  EXPECT_NEAR(s.xdot0[0], 0.0, 1e-15);
}

TEST(Linearize, PaperCartPendulumUpright) {
  const Model m = test::load_example("cart_pendulum.json");
  const OperatingPoint op = static_equilibrium(m, initial_point(m));
  ASSERT_NEAR(op.q[1], 0.0, 1e-12);
  const double m2 = 20, m3 = 10, l3 = 2, den = 4 * m2 + m3;
  // states [h, theta, h_dot, theta_dot] (positions first); the paper orders them
  // [h, h', theta, theta']: compare through the permutation
  Eigen::MatrixXd Ap(4, 4), Bp(4, 1), Cp(2, 4);
  Ap << 0, 1, 0, 0, 0, 0, -3 * m3 * g_lin / den, 0, 0, 0, 0, 1, 0, 0, 6 * (m2 + m3) * g_lin / (den * l3), 0;
  Bp << 0, 4 / den, 0, -6 / (l3 * den);
  Cp << 1, 0, 0, 0, 0, 0, 1, 0;
  Eigen::PermutationMatrix<4> P;  // ours = P * paper
  P.indices() << 0, 2, 1, 3;      // paper index -> our index
  const LinearSystem s = linearize(m, op).system;
  EXPECT_TRUE(MatrixNear(s.A, P * Ap * P.transpose(), 1e-10));
  EXPECT_TRUE(MatrixNear(s.B, P * Bp, 1e-10));
  EXPECT_TRUE(MatrixNear(s.C, Cp * P.transpose(), 1e-10));
  EXPECT_TRUE(MatrixNear(s.D, Eigen::MatrixXd::Zero(2, 1), 1e-10));
  EXPECT_EQ(s.state_names, (std::vector<std::string>{"cart_slider", "rod_pivot", "cart_slider_dot", "rod_pivot_dot"}));
  EXPECT_EQ(s.output_names, (std::vector<std::string>{"h", "theta"}));
}

TEST(Linearize, FiniteDifferencesAgreeWithinTheirReportedAccuracy) {
  const Model m = test::load_example("cart_pendulum.json");
  const OperatingPoint op = static_equilibrium(m, initial_point(m));
  const LinearSystem exact = linearize(m, op).system;
  for (JacobianMethod method : {JacobianMethod::ForwardDifference, JacobianMethod::CentralDifference}) {
    LinearizeOptions o;
    o.method = method;
    const Linearization fd = linearize(m, op, o);
    EXPECT_GT(fd.fd_error, 0.0);
    EXPECT_LT(fd.fd_error, method == JacobianMethod::CentralDifference ? 1e-8 : 1e-5);
    const double tol = 1.01 * fd.fd_error;
    EXPECT_TRUE(MatrixNear(fd.system.A, exact.A, tol * std::max(1.0, exact.A.cwiseAbs().maxCoeff())));
    EXPECT_TRUE(MatrixNear(fd.system.B, exact.B, tol * std::max(1.0, exact.A.cwiseAbs().maxCoeff())));
  }
}

TEST(Linearize, ExactMatchesCentralDifferencesOnRandom3DTree) {
  for (unsigned seed : {91u, 92u}) {
    const Model m = compile(test::random_plant(seed));
    std::mt19937 rng(seed);
    OperatingPoint op = initial_point(m);
    op.q = test::random_q(m, rng);
    op.v = test::random_v(m, rng, 1.0);
    op.u << 0.7, -1.3, 0.4;
    const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
    // at a point with non-zero tangent deviation too, where the rotation maps are not identity
    Eigen::VectorXd x(f.nx());
    for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = op.v[k];
    x.head(f.nz()) = test::random_v(m, rng, 0.3);
    const Eigen::VectorXd u = Eigen::Vector3d(0.7, -1.3, 0.4);
    const Eigen::MatrixXd Je = plant_jacobian(f, x, u, JacobianMethod::Exact);
    const Eigen::MatrixXd Jc = plant_jacobian(f, x, u, JacobianMethod::CentralDifference);
    EXPECT_TRUE(MatrixNear(Jc, Je, 1e-7)) << "seed " << seed;
  }
}

// PlantFunction::fd_jacobian (velocity and input columns on the position stage
// of x) against differencing a full evaluation per column: the same numbers
TEST(Linearize, ReusingFiniteDifferencesEqualFullEvaluations) {
  auto check = [](const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                  const Eigen::VectorXd& dz, const std::string& label) {
    const PlantFunction f(m, q, u_all, partition_coordinates(m, q));
    Eigen::VectorXd x(f.nx());
    x << dz, v;
    Eigen::VectorXd u(f.nu());
    for (int k = 0; k < f.nu(); ++k) u[k] = u_all[m.plant_inputs[k]];
    for (bool central : {false, true}) {
      const Eigen::MatrixXd full = plant_jacobian_fd_full(f, x, u, central);
      Eigen::MatrixXd reuse;
      ASSERT_TRUE(f.fd_jacobian(x, u, central, reuse)) << label;
      const double scale = std::max(1.0, full.cwiseAbs().maxCoeff());
      EXPECT_LE((reuse - full).cwiseAbs().maxCoeff(), 1e-12 * scale) << label << (central ? " central" : " forward");
      const JacobianMethod method = central ? JacobianMethod::CentralDifference : JacobianMethod::ForwardDifference;
      EXPECT_EQ(plant_jacobian(f, x, u, method), reuse) << label;
    }
  };
  for (unsigned seed : {91u, 92u, 93u}) {
    const Model m = compile(test::random_plant(seed));
    std::mt19937 rng(seed);
    Eigen::VectorXd u_all(3);
    u_all << 0.7, -1.3, 0.4;
    check(m, test::random_q(m, rng), test::random_v(m, rng, 1.0), u_all, test::random_v(m, rng, 0.3),
          "random tree " + std::to_string(seed));
  }
  for (const char* name : {"pendulum.json", "double_pendulum.json", "cart_pendulum.json", "heavy_top.json",
                           "iftomm_a05_flyball.json"}) {
    const Model m = test::load_example(name);
    const OperatingPoint op = initial_point(m);
    Eigen::VectorXd v = op.v;
    for (int k = 0; k < m.nv; ++k) v[k] += 0.2 + 0.1 * k;
    check(m, op.q, v, op.u, Eigen::VectorXd::Constant(m.nv, 0.05), name);
  }
}

TEST(Linearize, ExactMatchesCentralDifferencesOnFourBar) {
  const Model m = test::load_example("four_bar.json");
  const PlantFunction f(m, m.q0, m.u_nominal(), partition_coordinates(m, m.q0));
  ASSERT_EQ(f.nz(), 1);
  for (double z : {0.0, 0.2}) {
    const Eigen::VectorXd x = Eigen::Vector2d(z, 1.3), u = Eigen::VectorXd::Constant(f.nu(), 0.4);
    EXPECT_TRUE(MatrixNear(plant_jacobian(f, x, u, JacobianMethod::CentralDifference),
                           plant_jacobian(f, x, u, JacobianMethod::Exact), 1e-7));
  }
}

TEST(Linearize, ChoosableIndependentCoordinates) {
  const Model m = test::load_example("four_bar.json");
  LinearizeOptions o;
  o.independent = {m.v_names[2]};
  const Linearization a = linearize(m, initial_point(m), o);
  EXPECT_EQ(a.system.state_names[0], m.v_names[2]);
  o.independent = {"nonexistent"};
  EXPECT_THROW(linearize(m, initial_point(m), o), std::invalid_argument);
}

// Four-bar with a crank spring about its static equilibrium: the frequency
// from A equals sqrt(V''/m) computed from the potential and kinetic energy
// along the one-parameter family of assembled configurations.
TEST(Linearize, FourBarFrequencyMatchesEnergyMethod) {
  const Model m = test::load_example("four_bar.json");
  const OperatingPoint op = static_equilibrium(m, initial_point(m));
  ASSERT_LT(op.residual, 1e-10);
  const LinearSystem s = linearize(m, op).system;
  ASSERT_EQ(s.nx(), 2);
  const double w2_lin = -s.A(1, 0);
  ASSERT_GT(w2_lin, 0.0);

  // energy method, independent of the dynamics: solve the loop for a crank angle
  // (Newton with a finite-difference Jacobian on the two other joints)
  const int crank = m.joints[m.find_joint(s.state_names[0])].idx_q;
  auto configuration = [&](double th) {
    Eigen::VectorXd q = op.q;
    q[crank] = th;
    Data d(m);
    std::vector<int> other;
    for (int i = 0; i < m.nq; ++i)
      if (i != crank) other.push_back(i);
    for (int it = 0; it < 30; ++it) {
      const Eigen::VectorXd phi = constraint_residual<double>(m, d, q);
      Eigen::MatrixXd J(phi.size(), 2);
      for (int k = 0; k < 2; ++k) {
        Eigen::VectorXd qp = q;
        qp[other[k]] += 1e-7;
        J.col(k) = (constraint_residual<double>(m, d, qp) - phi) / 1e-7;
      }
      const Eigen::VectorXd dx = J.colPivHouseholderQr().solve(phi);
      q[other[0]] -= dx[0];
      q[other[1]] -= dx[1];
    }
    return q;
  };
  auto V = [&](double th) {
    Data d(m);
    return potential_energy<double>(m, d, configuration(th));
  };
  const double th0 = op.q[crank], h = 1e-4;
  EXPECT_NEAR((V(th0 + h) - V(th0 - h)) / (2 * h), 0.0, 1e-6);  // it is an equilibrium
  const double Vpp = (V(th0 + h) - 2 * V(th0) + V(th0 - h)) / (h * h);
  const Eigen::VectorXd v = (configuration(th0 + 1e-6) - configuration(th0 - 1e-6)) / 2e-6;  // unit crank rate
  Data d(m);
  const double mass = 2 * kinetic_energy<double>(m, d, op.q, v);
  EXPECT_NEAR(w2_lin, Vpp / mass, 1e-5 * w2_lin);
}

TEST(OperatingPoint, TrimHoldsThePendulumAtEightyDegrees) {
  const Model m = test::load_example("pendulum.json");
  const OperatingPoint op = trim(m, initial_point(m));
  const double mass = 10, l = 2;
  EXPECT_NEAR(op.u[0], mass * g_lin * l / 2 * std::cos(op.q[0]), 1e-10);
  EXPECT_LT(op.residual, 1e-12);
  EXPECT_NEAR(op.q[0], m.q0[0], 0.0);
}

TEST(OperatingPoint, EquilibriumKeepsNeutralCoordinates) {
  const Model m = test::load_example("cart_pendulum.json");
  OperatingPoint start = initial_point(m);
  start.q[0] = 0.75;  // cart position is neutral: any h is an equilibrium
  const OperatingPoint op = static_equilibrium(m, start);
  EXPECT_NEAR(op.q[0], 0.75, 1e-12);
  EXPECT_NEAR(op.q[1], 0.0, 1e-12);
}

}  // namespace
}  // namespace codyna

namespace codyna {

// Found by the GUI's monkey building from File > New: a model without degrees of freedom linearized
// by finite differences took the largest entry of an empty Jacobian (undefined: it crashed), and so
// did a motion input with no Plant/Out (an empty C). Both give their empty or exact blocks.
TEST(Linearize, EmptyBlocksAreNoLargestEntry) {
  for (const char* method : {"fd-forward", "fd-central", "exact"}) {
    ModelSpec empty = study_parse_model_text(
        std::string(R"({"codyna_model": 1, "name": "e", "bodies": [], "joints": [], "analysis": {"method": ")") + method + "\"}}",
        "empty.json");
    const StudyLinearization l = study_linearize(study_model(empty));
    EXPECT_EQ(l.system.nx(), 0) << method;
  }
  ModelSpec bus = load_model_spec(test::example_path("bus_suspension.json"));
  bus.plant.outputs.clear();
  bus.analysis.method = "fd-central";
  const StudyLinearization l = study_linearize(study_model(bus));
  EXPECT_EQ(l.system.ny(), 0);
  EXPECT_EQ(l.system.nx(), 4);
  EXPECT_NEAR(l.system.state_shift(3, 1), 15020.0 / 320.0, 1e-6);
}

}  // namespace codyna
