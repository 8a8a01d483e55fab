// Co-simulation stepping: the same answers as simulate() when the caller does
// what simulate() does, and a loop closed from outside that holds the rod up.
#include "simulation/stepper.hpp"

#include <cmath>

#include "analysis/operating_point.hpp"
#include "dynamics/constraints.hpp"
#include "simulation/simulator.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

constexpr double g_step = 9.81;

IntegratorSettings settings(const std::string& method) {
  IntegratorSettings s;
  s.method = method;
  s.rtol = 1e-9;
  s.atol = 1e-11;
  return s;
}

// constant input from outside == the same input as the actuator's nominal value
TEST(Stepper, ConstantInputMatchesSimulate) {
  ModelSpec spec = load_model_spec(test::example_path("pendulum.json"));
  spec.controller = {};
  spec.actuators[0].u0 = 5.0;
  const Model m = compile(spec);
  SimulationOptions o;
  o.integrator = settings("cvode-bdf");
  o.t_end = 1.0;
  o.output_step = 0.01;
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  Stepper st(m, settings("cvode-bdf"));
  for (int i = 1; i < r.samples(); ++i) {
    const Eigen::VectorXd y = st.step(Eigen::VectorXd::Constant(1, 5.0), 0.01);
    EXPECT_NEAR(y[0], r.y(i, 0), 1e-6) << "t = " << r.t[i];  // same problem, different step sequences (restart per step)
  }
  EXPECT_NEAR(st.time(), 1.0, 1e-12);
}

// a sampled PD closed from outside (Ts = 5 ms) == the simulator's discrete LTI controller
TEST(Stepper, LoopClosedOutsideMatchesDiscreteControllerInSimulate) {
  const Model m = test::load_example("pendulum.json");
  LinearPlant p;
  p.op = static_equilibrium(m, initial_point(m));
  p.lin = linearize(m, p.op);
  const double Kp = (9 + 3 * g_step / 4) / 0.075, Kd = 4.8 / 0.075, Ts = 0.005, y0 = M_PI / 2;
  const auto c = make_lti(Eigen::MatrixXd::Zero(1, 1), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Constant(1, 1, Kd / Ts),
                          Eigen::MatrixXd::Constant(1, 1, -(Kp + Kd / Ts)), Ts, p.lin.system.y0, p.lin.system.u0);
  SimulationOptions o;
  o.integrator = settings("ida");
  o.t_end = 2.0;
  o.output_step = Ts;
  const SimulationResult r = simulate(m, c.get(), &p, o);
  ASSERT_TRUE(r.completed);

  Stepper st(m, settings("ida"));
  double xc = 0;  // the previous error
  for (int i = 1; i < r.samples(); ++i) {
    const double e = st.outputs()[0] - y0;
    const double u = -(Kp + Kd / Ts) * e + Kd / Ts * xc;
    xc = e;
    const Eigen::VectorXd y = st.step(Eigen::VectorXd::Constant(1, u), Ts);
    EXPECT_NEAR(y[0], r.y(i, 0), 1e-6) << "t = " << r.t[i];
  }
  EXPECT_NEAR(st.outputs()[0], y0, 0.5 * M_PI / 180);
}

TEST(Stepper, ClosedLoopMechanismStaysAssembled) {
  const Model m = test::load_example("four_bar.json");
  Stepper st(m, settings("ida"));
  for (int i = 0; i < 200; ++i) st.step(Eigen::VectorXd::Constant(st.nu(), 2.0 * std::sin(0.05 * i)), 0.01);
  Data d(m);
  EXPECT_LT(constraint_residual<double>(m, d, st.q()).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(Stepper, BadInputIsAClearError) {
  const Model m = test::load_example("pendulum.json");
  Stepper st(m, settings("ida"));
  EXPECT_THROW(st.step(Eigen::VectorXd::Zero(2), 0.01), std::invalid_argument);
  EXPECT_THROW(st.step(Eigen::VectorXd::Zero(1), -0.01), std::invalid_argument);
  EXPECT_THROW(st.step(Eigen::VectorXd::Constant(1, NAN), 0.01), std::invalid_argument);
  EXPECT_NEAR(st.time(), 0.0, 0.0);  // nothing happened
}

}  // namespace
}  // namespace codyna
