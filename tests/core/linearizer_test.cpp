// Linearizer (analysis/linearizer.hpp): its fast path on trees computes linearize()'s numbers
// again from the kept workspaces. Checked bit for bit (x0dot's accelerations and y0: to 1e-12,
// see below) against the plant function's own route
// (PlantFunction::analytic_jacobian through plant_jacobian, eval, state_offset, state_names:
// what linearize() did before the fast path), at several operating points in turn through one
// Linearizer written into one Linearization (nothing of one point may leak into the next), on a
// random 3-D tree with every joint type, body-force inputs and sensors of several kinds, and on
// every tree example; and the general path (closed loops, finite differences) through it equals
// linearize(). A Linearizer bound again (bind) to other models in turn, and linearize() alone
// (its workspaces kept per thread) on a model changed in place or made at a freed one's address,
// give what a new Linearizer gives, bit for bit: nothing of an earlier model is read.
#include "analysis/linearizer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <algorithm>
#include <functional>
#include <optional>
#include <random>
#include <tuple>

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
    const ModelSpec s = test::random_plant(seed);
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

// everything a Linearization holds, bit for bit
void expect_same(const Linearization& a, const Linearization& b, const std::string& label) {
  const LinearSystem &s = a.system, &t = b.system;
  for (auto [x, y, what] : {std::tuple{&s.A, &t.A, "A"}, {&s.B, &t.B, "B"}, {&s.C, &t.C, "C"}, {&s.D, &t.D, "D"}})
    EXPECT_TRUE(Same(*x, *y)) << label << ": " << what;
  for (auto [x, y, what] : {std::tuple{&s.x0, &t.x0, "x0"}, {&s.u0, &t.u0, "u0"}, {&s.y0, &t.y0, "y0"},
                            {&s.xdot0, &t.xdot0, "xdot0"}})
    EXPECT_TRUE(Same(*x, *y)) << label << ": " << what;
  EXPECT_EQ(s.state_names, t.state_names) << label;
  EXPECT_EQ(s.state_units, t.state_units) << label;
  EXPECT_EQ(s.input_names, t.input_names) << label;
  EXPECT_EQ(s.input_units, t.input_units) << label;
  EXPECT_EQ(s.output_names, t.output_names) << label;
  EXPECT_EQ(s.output_units, t.output_units) << label;
  EXPECT_EQ(s.positions, t.positions) << label;
  EXPECT_EQ(s.model_name, t.model_name) << label;
  EXPECT_EQ(s.operating_point, t.operating_point) << label;
  EXPECT_EQ(a.partition.independent, b.partition.independent) << label;
  EXPECT_EQ(a.partition.dependent, b.partition.dependent) << label;
  EXPECT_EQ(a.fd_error, b.fd_error) << label;
}

// the examples' models, each at a moved point (velocities and inputs)
struct LinearizerCase {
  std::string name;
  Model m;
  OperatingPoint op;
};
std::vector<LinearizerCase> example_cases() {
  std::vector<LinearizerCase> cases;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    LinearizerCase c{entry.path().filename().string(), test::load_example(entry.path().filename().string()), {}};
    c.op = initial_point(c.m);
    if (c.m.nc == 0 && c.m.motions.empty())
      for (int k = 0; k < c.m.nv; ++k) c.op.v[k] += 0.2 + 0.05 * k;
    for (int i : c.m.plant_inputs) c.op.u[i] += 0.3;
    cases.push_back(std::move(c));
  }
  std::sort(cases.begin(), cases.end(), [](const LinearizerCase& a, const LinearizerCase& b) { return a.name < b.name; });
  return cases;
}

// One Linearizer bound in turn to every example (trees and closed loops, sizes changing and
// repeating), forwards then backwards, and linearize() alone on each: what a new Linearizer gives
TEST(Linearizer, BoundInTurnToEveryExampleEqualsANewOne) {
  const std::vector<LinearizerCase> cases = example_cases();
  ASSERT_GE(cases.size(), 15u);
  Linearizer lz(cases[0].m);
  Linearization into;
  int n = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const LinearizerCase& c = cases[pass == 0 ? i : cases.size() - 1 - i];
      const Linearization fresh = Linearizer(c.m).linearize(c.op);
      lz.bind(c.m);
      lz.linearize(c.op, {}, into);
      expect_same(into, fresh, c.name + " (bound)");
      expect_same(linearize(c.m, c.op), fresh, c.name + " (linearize alone)");
      ++n;
    }
  EXPECT_EQ(n, 2 * static_cast<int>(cases.size()));
}

// linearize() alone keeps its workspaces per thread and prepares them again unless the model is
// the one prepared last with every field it read unchanged: a model changed in place, field by
// field, is linearized as a new Linearizer linearizes it, and differently from before the change
// (so that each change is seen to matter)
TEST(Linearizer, LinearizeAloneOnAModelChangedInPlaceEqualsANewLinearizer) {
  const ModelSpec s = test::random_plant(33);
  Model m = compile(s);
  ASSERT_EQ(m.nc, 0);
  OperatingPoint op = initial_point(m);
  std::mt19937 rng(5);
  op.v = test::random_v(m, rng, 1.0);
  op.u[0] = 0.4;
  op.u[1] = -0.3;
  const int b = 3;  // a body whose numbers change
  int hinge = 0;    // a body on a revolute or prismatic joint: its axis changes
  for (int i = 1; i < m.nbodies && !hinge; ++i)
    if (m.joints[i].type == JointType::Revolute || m.joints[i].type == JointType::Prismatic) hinge = i;
  ASSERT_GT(hinge, 0);
  const std::vector<std::pair<std::string, std::function<void(Model&)>>> changes{
      {"mass", [&](Model& x) { x.mass[b] *= 1.5; }},
      {"inertia", [&](Model& x) { x.inertia[b](0, 0) *= 1.5; }},
      {"com", [&](Model& x) { x.com[b].x() += 0.1; }},
      {"joint placement", [&](Model& x) { x.joints[b].X_PF.p.y() += 0.1; }},
      {"joint frame in the child", [&](Model& x) { x.joints[b].X_CM.p.z() -= 0.1; }},
      {"joint axis", [&](Model& x) { x.joints[hinge].axis = Eigen::Vector3d(1, 1, 0).normalized(); }},
      {"gravity", [&](Model& x) { x.gravity.z() *= 2; x.has_gravity = true; }},
      {"input name", [&](Model& x) { x.actuators[x.plant_inputs[0]].name = "a longer name than a short string holds"; }},
      {"input unit", [&](Model& x) { x.actuators[x.plant_inputs[0]].unit = "N"; }},
      {"output name", [&](Model& x) { x.sensors[x.plant_outputs[1]].name = "w"; }},
      {"coordinate name", [&](Model& x) { x.v_names[0] = "renamed"; }},
      {"rate name", [&](Model& x) { x.rate_names[0] = "renamed_dot"; }},
      {"outputs reordered", [&](Model& x) { std::swap(x.plant_outputs[0], x.plant_outputs[1]); }},
      {"an input dropped", [&](Model& x) { x.plant_inputs.pop_back(); }},
  };
  for (const auto& [what, change] : changes) {
    const Linearization before = linearize(m, op);
    expect_same(before, Linearizer(m).linearize(op), what + ": before");
    change(m);
    const Linearization after = linearize(m, op);
    expect_same(after, Linearizer(m).linearize(op), what);
    const bool numbers = !Same(after.system.A, before.system.A) || !Same(after.system.B, before.system.B) ||
                         !Same(after.system.C, before.system.C) || !Same(after.system.xdot0, before.system.xdot0);
    const bool names = after.system.state_names != before.system.state_names ||
                       after.system.input_names != before.system.input_names ||
                       after.system.input_units != before.system.input_units ||
                       after.system.output_names != before.system.output_names;
    EXPECT_TRUE(numbers || names) << what << ": the change made no difference, the test checks nothing";
  }
}

// a model freed and another made at its address, of the same shape: the other's numbers
TEST(Linearizer, LinearizeAloneOnAnotherModelAtAFreedOnesAddress) {
  const Model a = test::load_example("double_pendulum.json");
  Model b = a;
  b.mass[2] *= 2;
  b.inertia[2] *= 2;
  std::optional<Model> slot;
  slot.emplace(a);
  const Model* where = &*slot;
  const OperatingPoint op = initial_point(a);
  const Linearization la = linearize(*slot, op);
  slot.emplace(b);
  ASSERT_EQ(&*slot, where);
  const Linearization lb = linearize(*slot, op);
  expect_same(la, Linearizer(a).linearize(op), "a");
  expect_same(lb, Linearizer(b).linearize(op), "b");
  EXPECT_FALSE(Same(la.system.A, lb.system.A));
}

}  // namespace
}  // namespace codyna
