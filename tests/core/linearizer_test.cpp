// Linearizer (analysis/linearizer.hpp): its fast path on trees computes linearize()'s numbers
// again from the kept workspaces. Checked bit for bit (x0dot's accelerations and y0: to 1e-12,
// see below) against the plant function's own route
// (PlantFunction::analytic_jacobian through plant_jacobian, eval, state_offset, state_names:
// what linearize() did before the fast path), at several operating points in turn through one
// Linearizer written into one Linearization (nothing of one point may leak into the next), on a
// random 3-D tree with every joint type, body-force inputs and sensors of several kinds, and on
// every tree example; and the general path (closed loops, finite differences) through it equals
// linearize().
#include "analysis/linearizer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>

#include "analysis/operating_point.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

// bit for bit, sizes included (-0.0 and 0.0 differ)
::testing::AssertionResult Same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    return ::testing::AssertionFailure() << a.rows() << "x" << a.cols() << " against " << b.rows() << "x" << b.cols();
  if (a.size() && std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) != 0)
    return ::testing::AssertionFailure() << "largest difference " << (a - b).cwiseAbs().maxCoeff();
  return ::testing::AssertionSuccess();
}

// to round-off: max |a - b| <= 1e-12 max(1, max |b|), sizes included
::testing::AssertionResult Close(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " against " << b.size();
  const double scale = std::max(1.0, b.size() ? b.cwiseAbs().maxCoeff() : 0.0);
  for (Eigen::Index k = 0; k < a.size(); ++k)
    if (!(std::abs(a[k] - b[k]) <= 1e-12 * scale))
      return ::testing::AssertionFailure() << "entry " << k << ": " << a[k] << " against " << b[k] << " (largest "
                                           << scale << ")";
  return ::testing::AssertionSuccess();
}

// what linearize() computed before the Linearizer, from the plant function's public interface
void expect_plant_function_numbers(const Model& m, const OperatingPoint& op, const Linearization& l,
                                   const std::string& label) {
  const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx());
  for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = op.v[f.partition().independent[k]];
  Eigen::VectorXd u(f.nu());
  for (int k = 0; k < f.nu(); ++k) u[k] = op.u[m.plant_inputs[k]];
  const Eigen::MatrixXd J = plant_jacobian(f, x, u, JacobianMethod::Exact);
  const int nx = f.nx(), nu = f.nu(), ny = f.ny();
  const LinearSystem& s = l.system;
  EXPECT_TRUE(Same(s.A, J.topLeftCorner(nx, nx))) << label << ": A";
  EXPECT_TRUE(Same(s.B, J.block(0, nx, nx, nu))) << label << ": B";
  EXPECT_TRUE(Same(s.C, J.bottomLeftCorner(ny, nx))) << label << ": C";
  EXPECT_TRUE(Same(s.D, J.block(nx, nx, ny, nu))) << label << ": D";
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);
  // x0dot and y0 are the Jacobian's own accelerations (CRBA and Cholesky) and sensor values,
  // the plant function's come from ABA: equal to round-off, the positions' rates bit for bit
  const int nz = f.nz();
  EXPECT_TRUE(Same(s.xdot0.head(nz), xd.head(nz))) << label << ": xdot0";
  EXPECT_TRUE(Close(s.xdot0, xd)) << label << ": xdot0";
  EXPECT_TRUE(Close(s.y0, y)) << label << ": y0";
  EXPECT_TRUE(Same(s.x0, f.state_offset(op.v))) << label << ": x0";
  EXPECT_TRUE(Same(s.u0, u)) << label << ": u0";
  EXPECT_EQ(s.state_names, f.state_names()) << label;
  EXPECT_EQ(s.state_units, f.state_units()) << label;
  ASSERT_EQ(s.input_names.size(), m.plant_inputs.size()) << label;
  for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) {
    EXPECT_EQ(s.input_names[k], m.actuators[m.plant_inputs[k]].name) << label;
    EXPECT_EQ(s.input_units[k], m.actuators[m.plant_inputs[k]].unit) << label;
  }
  ASSERT_EQ(s.output_names.size(), m.plant_outputs.size()) << label;
  for (std::size_t k = 0; k < m.plant_outputs.size(); ++k) {
    EXPECT_EQ(s.output_names[k], m.sensors[m.plant_outputs[k]].name) << label;
    EXPECT_EQ(s.output_units[k], m.sensors[m.plant_outputs[k]].unit) << label;
  }
  EXPECT_EQ(s.operating_point, op.kind) << label;
  EXPECT_EQ(s.time, op.t) << label;
  EXPECT_EQ(s.method, "exact") << label;
  EXPECT_EQ(s.model_name, m.name) << label;
  EXPECT_EQ(l.partition.independent, f.partition().independent) << label;
  EXPECT_EQ(l.fd_error, 0.0) << label;
}

// operating points in turn: the initial one, then moved positions, velocities and inputs
std::vector<OperatingPoint> points(const Model& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<OperatingPoint> ops{initial_point(m)};
  for (int k = 1; k <= 3; ++k) {
    OperatingPoint op = ops[0];
    op.q = test::random_q(m, rng);
    op.v = test::random_v(m, rng, 1.0);
    std::uniform_real_distribution<double> r(-2, 2);
    for (int i : m.plant_inputs) op.u[i] = r(rng);
    op.kind = "time=" + std::to_string(k);
    op.t = k;
    ops.push_back(op);
  }
  return ops;
}

void check_tree(const Model& m, unsigned seed, const std::string& name) {
  Linearizer lz(m);
  Linearization into;
  const std::vector<OperatingPoint> ops = points(m, seed);
  for (std::size_t i = 0; i < ops.size(); ++i) {
    const std::string label = name + " point " + std::to_string(i);
    lz.linearize(ops[i], {}, into);
    expect_plant_function_numbers(m, ops[i], into, label);
    const Linearization once = linearize(m, ops[i]);
    EXPECT_TRUE(Same(once.system.A, into.system.A)) << label;
    EXPECT_TRUE(Same(once.system.xdot0, into.system.xdot0)) << label;
  }
}

TEST(Linearizer, TreesBitForBitThePlantFunctionsNumbersAtEveryPointInTurn) {
  for (unsigned seed : {31u, 32u}) {
    ModelSpec s = test::random_tree_spec(seed, 10);
    ActuatorSpec a;
    a.name = "tau1";
    a.joint = "j1";
    s.actuators.push_back(a);
    a.name = "push";
    a.type = ActuatorType::BodyForce;
    a.body = "b4";
    a.point = Eigen::Vector3d(0.1, 0.2, 0.3);
    a.direction = Eigen::Vector3d(1, 2, 3);
    s.actuators.push_back(a);
    SensorSpec y;
    y.name = "p5";
    y.type = SensorType::PointPosition;
    y.body = "b5";
    y.point = Eigen::Vector3d(0.3, 0, 0);
    y.component = 2;
    y.frame = "b1";
    s.sensors.push_back(y);
    y.name = "w1";
    y.type = SensorType::JointVelocity;
    y.joint = "j1";
    s.sensors.push_back(y);
    y.name = "ang2";
    y.type = SensorType::BodyAngle;
    y.body = "b2";
    y.axis = Eigen::Vector3d(0, 0, 1);
    s.sensors.push_back(y);
    s.plant.inputs = {"tau1", "push"};
    s.plant.outputs = {"p5", "w1", "ang2"};
    const Model m = compile(s);
    ASSERT_EQ(m.nc, 0);
    check_tree(m, seed, s.name);
  }
}

TEST(Linearizer, EveryTreeExampleBitForBit) {
  int trees = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const Model m = test::load_example(entry.path().filename().string());
    if (m.nc != 0 || !m.motions.empty()) continue;
    ++trees;
    check_tree(m, 7u, entry.path().filename().string());
  }
  EXPECT_GE(trees, 6);
}

// closed loops and finite differences take the general path; through a Linearizer too
TEST(Linearizer, GeneralPathThroughItEqualsLinearize) {
  for (const char* name : {"four_bar.json", "bricard.json", "double_pendulum.json"}) {
    const Model m = test::load_example(name);
    const OperatingPoint op = initial_point(m);
    Linearizer lz(m);
    Linearization into;
    for (JacobianMethod method : {JacobianMethod::CentralDifference, JacobianMethod::Exact}) {
      LinearizeOptions o;
      o.method = method;
      lz.linearize(op, o, into);
      const Linearization once = linearize(m, op, o);
      EXPECT_TRUE(Same(once.system.A, into.system.A)) << name;
      EXPECT_TRUE(Same(once.system.B, into.system.B)) << name;
      EXPECT_TRUE(Same(once.system.C, into.system.C)) << name;
      EXPECT_TRUE(Same(once.system.xdot0, into.system.xdot0)) << name;
      EXPECT_EQ(once.fd_error, into.fd_error) << name;
      EXPECT_EQ(into.system.method, to_string(method)) << name;
    }
  }
}

}  // namespace
}  // namespace codyna
