// The steady-state search with known and unknown parts (operspec): coordinates
// set by the user are held exactly, chosen coordinates and inputs are solved,
// Plant/Out targets are reached, actuator limits are respected or named.
// Each result is checked against something independent: a closed form, or
// the derivative of the potential energy along the loop.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dynamics/energy.hpp"
#include "io/model_file.hpp"
#include "dynamics/data.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

ModelSpec steady_example(const std::string& name) { return load_model_spec(example_path(name)); }

double coordinate(const Model& m, const Eigen::VectorXd& q, const std::string& name) {
  for (std::size_t i = 0; i < m.q_names.size(); ++i)
    if (m.q_names[i] == name) return q[static_cast<Eigen::Index>(i)];
  ADD_FAILURE() << "no coordinate " << name;
  return 0;
}

std::string steady_error_of(const Model& m) {
  try {
    study_operating_point(m);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// the potential energy of the four-bar assembled with its crank at theta
double four_bar_potential(double theta) {
  ModelSpec spec = steady_example("four_bar.json");
  spec.analysis.set = {{"pivot_A", theta}};
  const Model m = study_model(spec);
  Data d(m);
  return potential_energy<double>(m, d, m.q0);
}

}  // namespace

// A crank held mid-stroke by a trim torque: pivot_A stays at the value set, to the bit, while
// the loop closes; the torque equals dV/dtheta along the loop (central differences of the
// potential energy of assembled configurations).
TEST(SteadyState, FourBarEquilibriumHoldsTheSetCrankWithAFreeInput) {
  ModelSpec spec = steady_example("four_bar.json");
  spec.analysis.set = {{"pivot_A", 1.3}};
  spec.analysis.operating_point = "equilibrium";
  spec.analysis.free_inputs = {"crank_torque"};
  const Model m = study_model(spec);
  const OperatingPoint op = study_operating_point(m);
  EXPECT_EQ(coordinate(m, op.q, "pivot_A"), 1.3);
  EXPECT_LT(op.residual, 1e-10);
  const double h = 1e-5;
  const double dV = (four_bar_potential(1.3 + h) - four_bar_potential(1.3 - h)) / (2 * h);
  EXPECT_NEAR(op.u[m.find_actuator("crank_torque")], dV, 1e-7 * (1 + std::abs(dV)));
  EXPECT_GT(std::abs(dV), 1.0);  // gravity does act: the check is not vacuous
}

// Without a free input nothing can hold the crank against gravity: refused, naming what is held,
// instead of drifting the crank to the hanging equilibrium as before.
// The Bricard linkage (overconstrained, one redundant loop equation): the equilibrium search's
// Newton steps cross configurations where the kept loop equations are singular; such trial
// steps are shortened instead of ending the search ("matrix is not positive definite" before).
// The equilibrium found (joint_C = pi/2, residual ~1e-15) is checked by a second method: a small
// nonlinear oscillation about it has the period 2 pi / w of the linearization's A.
TEST(SteadyState, BricardEquilibriumThroughSingularTrialSteps) {
  ModelSpec spec = steady_example("bricard.json");
  spec.analysis.operating_point = "equilibrium";
  const Model m = study_model(spec);
  const StudyLinearization l = study_linearize(m);
  EXPECT_LT(l.op.residual, 1e-12);
  const auto& names = l.lin.system.state_names;
  ASSERT_EQ(names.size(), 2u);
  const double a10 = l.lin.system.A(1, 0);
  ASSERT_LT(a10, 0.0);  // a stable oscillation about the equilibrium
  const double w = std::sqrt(-a10);
  // the nonlinear run: 0.005 rad off the equilibrium in the independent coordinate, at rest
  const int iq = static_cast<int>(std::find(m.q_names.begin(), m.q_names.end(), names[0]) - m.q_names.begin());
  const double eq = l.op.q[iq];
  spec.analysis.set.clear();
  spec.analysis.initial = {{names[0], eq + 0.005}};
  spec.analysis.controller = "none";
  spec.solver.t_end = 6 * 2 * M_PI / w;
  spec.solver.output_step = 1e-3;
  spec.solver.rtol = 1e-10;
  spec.solver.atol = 1e-12;
  const Model mr = study_model(spec);
  const SimulationResult r = study_simulate(mr, study_simulation(mr));
  ASSERT_TRUE(r.completed) << r.failure;
  // downward zero crossings of q - eq, interpolated: five full periods
  std::vector<double> crossings;
  for (int i = 1; i < r.samples(); ++i) {
    const double a = r.q(i - 1, iq) - eq, b = r.q(i, iq) - eq;
    if (a > 0 && b <= 0) crossings.push_back(r.t[i - 1] + (r.t[i] - r.t[i - 1]) * a / (a - b));
  }
  ASSERT_GE(crossings.size(), 5u);
  const double period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(period, 2 * M_PI / w, 2e-3 * period) << "w = " << w;
}

TEST(SteadyState, HeldCoordinateWithoutAFreeInputIsRefused) {
  ModelSpec spec = steady_example("four_bar.json");
  spec.analysis.set = {{"pivot_A", 1.3}};
  spec.analysis.operating_point = "equilibrium";
  const std::string e = steady_error_of(study_model(spec));
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
  EXPECT_NE(e.find("held: pivot_A"), std::string::npos) << e;
}

// Trim with a coordinate left free: the double pendulum's shoulder held at 0.5 rad by its
// torque, the elbow free. The second link hangs vertically (elbow = -0.5) and the torque carries
// both links: g (m1 l1/2 + m2 l1) sin(0.5).
TEST(SteadyState, DoublePendulumTrimWithTheElbowFree) {
  ModelSpec spec = steady_example("double_pendulum.json");
  spec.analysis.set = {{"shoulder", 0.5}, {"elbow", 0.2}};
  spec.analysis.operating_point = "trim";
  spec.analysis.trim_free = {"elbow"};
  const Model m = study_model(spec);
  const OperatingPoint op = study_operating_point(m);
  EXPECT_EQ(coordinate(m, op.q, "shoulder"), 0.5);
  EXPECT_NEAR(coordinate(m, op.q, "elbow"), -0.5, 1e-10);
  EXPECT_NEAR(std::abs(op.u[m.find_actuator("shoulder_torque")]), 9.81 * (1.0 * 0.5 + 1.0 * 1.0) * std::sin(0.5), 1e-9);
  EXPECT_LT(op.residual, 1e-10);
}

// An output target with the input free: the pendulum brought to theta = 0.3 by the torque that
// holds it there, m g (l/2... here the com at 1 m) cos(0.3); the coordinate is solved, not set.
TEST(SteadyState, OutputTargetReachedWithAFreeInput) {
  ModelSpec spec = steady_example("pendulum.json");
  spec.analysis.operating_point = "equilibrium";
  spec.analysis.free_inputs = {"torque"};
  spec.analysis.output_targets = {{"theta", 0.3}};
  const Model m = study_model(spec);
  const OperatingPoint op = study_operating_point(m);
  EXPECT_NEAR(coordinate(m, op.q, "pivot"), 0.3, 1e-12);
  EXPECT_NEAR(op.u[m.find_actuator("torque")], 10 * 9.81 * 1.0 * std::cos(0.3), 1e-9);
}

// The limit binds: the torque is held at its max and the error names it with what was needed.
TEST(SteadyState, BindingLimitIsNamedWithTheValueNeeded) {
  ModelSpec spec = steady_example("pendulum.json");
  spec.analysis.operating_point = "equilibrium";
  spec.analysis.free_inputs = {"torque"};
  spec.analysis.output_targets = {{"theta", 0.3}};
  spec.actuators[0].max = 50;
  spec.actuators[0].min = -50;
  const std::string e = steady_error_of(study_model(spec));
  EXPECT_NE(e.find("torque at its max 50"), std::string::npos) << e;
  EXPECT_NE(e.find("it would need 93.7"), std::string::npos) << e;
  EXPECT_NE(e.find("/analysis/operating_point"), std::string::npos) << e;
}

// Two inputs, one limited: the limited one stops at its limit and the other carries the rest,
// so a steady state is still found within the limits.
TEST(SteadyState, ALimitedInputLeavesTheRestToAnother) {
  ModelSpec spec = steady_example("pendulum.json");
  ActuatorSpec second = spec.actuators[0];
  second.name = "torque2";
  spec.actuators.push_back(second);
  spec.actuators[0].max = 50;
  spec.plant.inputs = {"torque", "torque2"};
  spec.controller = ControllerSpec{};
  spec.analysis.operating_point = "trim";
  spec.analysis.set = {{"pivot", 0.3}};
  const Model m = study_model(spec);
  const OperatingPoint op = study_operating_point(m);
  const double needed = 10 * 9.81 * std::cos(0.3);
  // the minimum-norm split asks 46.85 of each: within the limit, nothing binds
  EXPECT_NEAR(op.u[m.find_actuator("torque")] + op.u[m.find_actuator("torque2")], needed, 1e-9);
  spec.actuators[0].max = 20;
  spec.analysis.free_inputs = {"torque", "torque2"};
  const Model limited_free = study_model(spec);
  const OperatingPoint op2 = study_operating_point(limited_free);
  EXPECT_EQ(op2.u[limited_free.find_actuator("torque")], 20.0);
  EXPECT_NEAR(op2.u[limited_free.find_actuator("torque2")], needed - 20, 1e-9);
}

// Names are checked where they enter.
TEST(SteadyState, UnknownNamesAreRefusedWithTheList) {
  ModelSpec spec = steady_example("pendulum.json");
  spec.analysis.operating_point = "equilibrium";
  spec.analysis.free_inputs = {"motor"};
  std::string e = steady_error_of(study_model(spec));
  EXPECT_NE(e.find("\"motor\" is not in Plant/In (torque)"), std::string::npos) << e;
  spec.analysis.free_inputs = {"torque"};
  spec.analysis.output_targets = {{"tip_z", 1.0}};
  e = steady_error_of(study_model(spec));
  EXPECT_NE(e.find("\"tip_z\" is not in Plant/Out (theta)"), std::string::npos) << e;
}
