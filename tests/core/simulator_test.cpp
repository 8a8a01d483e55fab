// Closed-loop nonlinear simulation: the paper's examples held upright, the
// integrators against each other and against closed forms, constraint drift,
// energy, linear vs nonlinear, cancellation and failures.
#include "simulation/simulator.hpp"

#include <cmath>
#include <iostream>

#include "analysis/operating_point.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

constexpr double g_sim = 9.81;
constexpr double deg = M_PI / 180;

SimulationOptions sim_options(const std::string& method, double t_end, double rtol = 1e-8, double atol = 1e-10) {
  SimulationOptions o;
  o.integrator.method = method;
  o.integrator.rtol = rtol;
  o.integrator.atol = atol;
  o.t_end = t_end;
  o.output_step = 0.01;
  return o;
}

LinearPlant plant_at_equilibrium(const Model& m) {
  LinearPlant p;
  p.op = static_equilibrium(m, initial_point(m));
  p.lin = linearize(m, p.op);
  return p;
}

// Paper 4.1: a PD law on the joint torque holds the rod upright from 10 degrees off
TEST(Simulate, PaperPendulumHeldUprightByPd) {
  const Model m = test::load_example("pendulum.json");
  ASSERT_NEAR(m.q0[0], 80 * deg, 1e-12);
  const LinearPlant p = plant_at_equilibrium(m);
  // closed loop s^2 + 0.075 Kd s + 0.075 Kp - 3g/4: wn = 3 rad/s, zeta = 0.8
  const double Kp = (9 + 3 * g_sim / 4) / 0.075, Kd = 4.8 / 0.075;
  const auto pd = make_pid(Eigen::MatrixXd::Constant(1, 1, Kp), Eigen::MatrixXd(), Eigen::MatrixXd::Constant(1, 1, Kd),
                           Eigen::VectorXd::Constant(1, M_PI / 2), Eigen::VectorXd::Zero(1));
  for (const char* method : {"ida", "cvode-bdf"}) {
    const SimulationResult r = simulate(m, pd.get(), &p, sim_options(method, 5.0));
    ASSERT_TRUE(r.completed) << r.failure;
    EXPECT_NEAR(r.y(r.samples() - 1, 0), M_PI / 2, 0.5 * deg) << method;
    // settled: after 3 s (five time constants of 1/(zeta wn)) it stays within 0.5 degree
    for (int i = 0; i < r.samples(); ++i)
      if (r.t[i] >= 3.0) EXPECT_NEAR(r.y(i, 0), M_PI / 2, 0.5 * deg) << "t = " << r.t[i];
    EXPECT_LT(r.u.cwiseAbs().maxCoeff(), Kp * 10 * deg + 1.0);  // bounded: at most the initial P action
    EXPECT_NEAR(r.u(0, 0), Kp * 10 * deg, 1e-9);
  }
}

// The same loop with a sampled (ZOH) LTI controller: backward-difference PD, Ts = 5 ms
TEST(Simulate, PaperPendulumHeldUprightByDiscreteController) {
  const Model m = test::load_example("pendulum.json");
  const LinearPlant p = plant_at_equilibrium(m);
  const double Kp = (9 + 3 * g_sim / 4) / 0.075, Kd = 4.8 / 0.075, Ts = 0.005;
  // xc[k+1] = e[k]; u = -Kp e - Kd (e - xc) / Ts, e = y - y0
  const auto c = make_lti(Eigen::MatrixXd::Zero(1, 1), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Constant(1, 1, Kd / Ts),
                          Eigen::MatrixXd::Constant(1, 1, -(Kp + Kd / Ts)), Ts, p.lin.system.y0, p.lin.system.u0);
  SimulationOptions o = sim_options("ida", 4.0);
  const SimulationResult r = simulate(m, c.get(), &p, o);
  ASSERT_TRUE(r.completed) << r.failure;
  EXPECT_NEAR(r.y(r.samples() - 1, 0), M_PI / 2, 0.5 * deg);
  EXPECT_GE(r.stats.restarts, 799);  // one restart per sample
  // zero-order hold: the input is piecewise constant between samples
  EXPECT_EQ(r.xc.cols(), 1);
}

// every integrator against the fixed-step reference on a passive double pendulum
TEST(Simulate, IntegratorsAgreeWithTheReference) {
  const Model m = test::load_example("double_pendulum.json");
  SimulationOptions ref = sim_options("rk4", 2.0);
  ref.integrator.max_step = 1e-4;
  const SimulationResult r0 = simulate(m, nullptr, nullptr, ref);
  ASSERT_TRUE(r0.completed);
  for (const char* method : {"ida", "cvode-bdf", "cvode-adams", "arkode"}) {
    const SimulationResult r = simulate(m, nullptr, nullptr, sim_options(method, 2.0, 1e-10, 1e-12));
    ASSERT_TRUE(r.completed) << method << ": " << r.failure;
    ASSERT_EQ(r.samples(), r0.samples());
    EXPECT_LT((r.q - r0.q).cwiseAbs().maxCoeff(), 1e-7) << method;
    EXPECT_GT(r.stats.steps, 0) << method;
    EXPECT_GT(r.stats.rhs_evals, 0) << method;
  }
}

// IFToMM A01-like check: small-amplitude pendulum period against 2 pi sqrt(2 l / 3 g) with the
// finite-amplitude correction; here the exact period from the complete elliptic integral
TEST(Simulate, PendulumPeriodMatchesEllipticIntegral) {
  ModelSpec s = load_model_spec(test::example_path("pendulum.json"));
  s.joints[0].q0 = Eigen::VectorXd::Constant(1, -M_PI / 2 + 0.5);  // 0.5 rad from hanging straight down
  s.plant = {};
  const Model m = compile(s);
  // period of a compound pendulum (rod about its end): T = 4 sqrt(2 l / (3 g)) K(sin(a/2))
  const double a = 0.5, k = std::sin(a / 2), l = 2;
  double K = 0;  // complete elliptic integral of the first kind by the arithmetic-geometric mean
  {
    double x = 1, y = std::sqrt(1 - k * k);
    for (int i = 0; i < 30; ++i) {
      const double xn = (x + y) / 2;
      y = std::sqrt(x * y);
      x = xn;
    }
    K = M_PI / (2 * x);
  }
  const double T = 4 * std::sqrt(2 * l / (3 * g_sim)) * K;
  SimulationOptions o = sim_options("ida", 1.5 * T, 1e-10, 1e-12);
  o.output_step = 1e-3;
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(r.completed);
  // the angle returns to its starting maximum after one period: the sample maximum near T
  int best = -1;
  for (int i = 1; i + 1 < r.samples(); ++i)
    if (std::abs(r.t[i] - T) < 0.05 && (best < 0 || r.q(i, 0) > r.q(best, 0))) best = i;
  ASSERT_GT(best, 0);
  // refine by a parabola through the three samples around the maximum
  const double y0 = r.q(best - 1, 0), y1 = r.q(best, 0), y2 = r.q(best + 1, 0);
  const double t_peak = r.t[best] + o.output_step * (y0 - y2) / (2 * (y0 - 2 * y1 + y2));
  EXPECT_NEAR(t_peak, T, 1e-5);
}

TEST(Simulate, ConstraintDriftStaysBelowToleranceOnLoops) {
  for (const char* name : {"four_bar.json", "bricard.json"}) {
    const Model m = test::load_example(name);
    for (const char* method : {"ida", "cvode-bdf"}) {
      const SimulationResult r = simulate(m, nullptr, nullptr, sim_options(method, 3.0));
      ASSERT_TRUE(r.completed) << name << " " << method << ": " << r.failure;
      const double drift = *std::max_element(r.constraint_violation.begin(), r.constraint_violation.end());
      EXPECT_LT(drift, 1e-8) << name << " " << method;
      // passive: energy conserved to the integration tolerance
      const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
      for (int i = 0; i < r.samples(); ++i)
        EXPECT_NEAR(r.kinetic_energy[i] + r.potential_energy[i], E0, 1e-5 * std::max(1.0, std::abs(E0))) << name;
    }
  }
}

TEST(Simulate, AndrewsSqueezerMatchesTheTestSetReference) {
  const Model m = test::load_example("andrews_squeezer.json");
  SimulationOptions o = sim_options("ida", 0.03, 1e-10, 1e-10);
  o.output_step = 1e-3;
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(r.completed) << r.failure;
  const std::pair<const char*, double> ref[] = {
      {"beta", 15.81077119629904}, {"Theta", -15.75637105984298}, {"gamma", 0.04082224013073101},
      {"Phi", -0.5347301163226948}, {"delta", 0.5244099658805304}, {"Omega", 0.5347301163226948},
      {"epsilon", 1.048080741042263}};
  double scd_err = 0;
  for (const auto& [name, value] : ref) {
    const double y = r.q(r.samples() - 1, m.joints[m.find_joint(name)].idx_q);
    scd_err = std::max(scd_err, std::abs(y - value) / std::abs(value));
  }
  EXPECT_GT(-std::log10(scd_err), 5.0) << "significant correct digits " << -std::log10(scd_err);
  std::cout << "Andrews at t = 0.03 (ida, rtol = atol = 1e-10): SCD " << -std::log10(scd_err) << ", "
            << r.stats.steps << " steps\n";
  const double drift = *std::max_element(r.constraint_violation.begin(), r.constraint_violation.end());
  EXPECT_LT(drift, 1e-8);
}

TEST(Simulate, LinearAndNonlinearAgreeForSmallOffsets) {
  const Model m = test::load_example("pendulum.json");
  const LinearPlant p = plant_at_equilibrium(m);
  const double Kp = (9 + 3 * g_sim / 4) / 0.075, Kd = 4.8 / 0.075;
  const auto pd = make_pid(Eigen::MatrixXd::Constant(1, 1, Kp), Eigen::MatrixXd(), Eigen::MatrixXd::Constant(1, 1, Kd),
                           Eigen::VectorXd::Constant(1, M_PI / 2), Eigen::VectorXd::Zero(1));
  auto divergence = [&](double offset) {
    SimulationOptions o = sim_options("ida", 3.0);
    o.compare_linear = true;
    o.q0 = Eigen::VectorXd::Constant(1, M_PI / 2 - offset);
    o.v0 = Eigen::VectorXd::Zero(1);
    const SimulationResult r = simulate(m, pd.get(), &p, o);
    EXPECT_EQ(r.y_linear.rows(), r.samples());
    return (r.y - r.y_linear).cwiseAbs().maxCoeff() / offset;  // relative to the initial offset
  };
  const double small = divergence(1 * deg), large = divergence(60 * deg);
  EXPECT_LT(small, 0.01);        // within 1% of the offset
  EXPECT_GT(large, 0.02);        // a large offset leaves the linear range
  EXPECT_GT(large, 10 * small);  // and the gap grows faster than the offset
  std::cout << "linear vs nonlinear, max |y - y_lin| / offset: 1 deg " << small << ", 60 deg " << large << "\n";
}

TEST(Simulate, CancelKeepsThePartialResult) {
  const Model m = test::load_example("double_pendulum.json");
  std::atomic<bool> cancel{false};
  SimulationCallbacks cb;
  int seen = 0;
  cb.on_sample = [&](const Snapshot& s) {
    if (++seen == 50) cancel = true;
    EXPECT_EQ(s.q.size(), m.nq);
  };
  cb.cancel = &cancel;
  const SimulationResult r = simulate(m, nullptr, nullptr, sim_options("ida", 5.0), cb);
  EXPECT_TRUE(r.cancelled);
  EXPECT_FALSE(r.completed);
  EXPECT_EQ(r.samples(), 50);
  EXPECT_NEAR(r.t.back(), 0.49, 1e-12);
}

// A cancel stops the integrator inside a long output interval (a stiff run may spend minutes in
// one), not only between samples: a controller that sets the flag at its 500th evaluation, one
// output interval of 1000 s. The run ends there, cancelled, not failed, with its first sample.
namespace {
struct CancellingController : Controller {
  std::atomic<bool>* flag = nullptr;
  mutable long calls = 0, after = 0;
  Eigen::VectorXd output(const ControllerInput&, const Eigen::VectorXd&) const override {
    if (flag->load()) ++after;
    if (++calls == 500) *flag = true;
    return Eigen::VectorXd::Zero(1);
  }
  std::string describe() const override { return "sets the cancel flag"; }
};
}  // namespace

TEST(Simulate, CancelStopsInsideALongOutputInterval) {
  const Model m = test::load_example("pendulum.json");
  ASSERT_EQ(m.plant_inputs.size(), 1u);
  const LinearPlant p = plant_at_equilibrium(m);
  std::atomic<bool> cancel{false};
  CancellingController c;
  c.flag = &cancel;
  SimulationCallbacks cb;
  cb.cancel = &cancel;
  for (const char* method : {"cvode-bdf", "ida", "arkode", "rk4"}) {
    cancel = false;
    c.calls = c.after = 0;
    SimulationOptions o = sim_options(method, 1000.0);
    o.output_step = 1000.0;
    o.integrator.rtol = o.integrator.atol = 1e-10;
    if (std::string(method) == "rk4") o.integrator.max_step = 1e-3;
    const SimulationResult r = simulate(m, &c, &p, o, cb);
    EXPECT_TRUE(r.cancelled) << method;
    EXPECT_FALSE(r.completed) << method;
    EXPECT_TRUE(r.failure.empty()) << method << ": " << r.failure;
    EXPECT_EQ(r.samples(), 1) << method;
    EXPECT_LE(c.after, 10) << method;  // the controller's evaluations after the flag: none or a few
  }
}

TEST(Simulate, SolverFailureIsReportedWithTimeAndReason) {
  const Model m = test::load_example("pendulum.json");
  const LinearPlant p = plant_at_equilibrium(m);
  // positive feedback with an absurd gain: the fixed-step reference blows up, and the run ends
  // at the first output time past the divergence bound, naming the coordinate
  const auto bad = make_pid(Eigen::MatrixXd::Constant(1, 1, -1e9), Eigen::MatrixXd(), Eigen::MatrixXd(),
                            Eigen::VectorXd::Constant(1, M_PI / 2), Eigen::VectorXd::Zero(1));
  SimulationOptions o = sim_options("rk4", 5.0);
  o.integrator.max_step = 0.01;
  const SimulationResult r = simulate(m, bad.get(), &p, o);
  EXPECT_FALSE(r.completed);
  EXPECT_NE(r.failure.find("t = "), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("diverged: pivot"), std::string::npos) << r.failure;
  EXPECT_GT(r.samples(), 0);
  EXPECT_LT(r.t.back(), 0.1);
}

TEST(Simulate, UnknownIntegratorIsAClearError) {
  const Model m = test::load_example("pendulum.json");
  try {
    simulate(m, nullptr, nullptr, sim_options("euler", 1.0));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown integrator \"euler\""), std::string::npos);
  }
}

}  // namespace
}  // namespace codyna

#include "control/lqr.hpp"
#include "dynamics/effects.hpp"

namespace codyna {
namespace {

// Paper 4.2: an LQR law on the cart force holds the rod upright while the cart settles
TEST(Simulate, PaperCartPendulumHeldUprightByLqr) {
  const Model m = test::load_example("cart_pendulum.json");
  ASSERT_NEAR(m.q0[1], 0.1, 1e-12);
  const LinearPlant p = plant_at_equilibrium(m);
  const LinearSystem& s = p.lin.system;
  Eigen::VectorXd qw(4);
  qw << 10, 100, 1, 1;
  const LqrResult d = lqr(s.A, s.B, qw.asDiagonal(), Eigen::MatrixXd::Constant(1, 1, 0.01));
  const auto c = make_state_feedback(d.K, s.u0);
  for (const char* method : {"ida", "cvode-bdf", "arkode"}) {
    const SimulationResult r = simulate(m, c.get(), &p, sim_options(method, 8.0));
    ASSERT_TRUE(r.completed) << method << ": " << r.failure;
    for (int i = 0; i < r.samples(); ++i)
      if (r.t[i] >= 5.0) {
        EXPECT_NEAR(r.y(i, 1), 0.0, 0.5 * deg) << method << " t = " << r.t[i];  // theta
        EXPECT_NEAR(r.y(i, 0), 0.0, 0.05) << method << " t = " << r.t[i];       // cart settles back
      }
    // bounded input: no more than the initial state-feedback kick
    EXPECT_LE(r.u.cwiseAbs().maxCoeff(), std::abs(d.K(0, 1)) * 0.1 + 1e-6) << method;
  }
}

// Only declared effects are evaluated: the pendulum has no springs or friction
TEST(Simulate, AbsentEffectsAreNeverEvaluated) {
  const Model m = test::load_example("pendulum.json");
  ASSERT_TRUE(m.springs.empty() && m.joint_springs.empty() && m.joint_frictions.empty() && m.body_forces.empty());
  effect_counters() = {};
  const SimulationResult r = simulate(m, nullptr, nullptr, sim_options("cvode-bdf", 0.5));
  ASSERT_TRUE(r.completed);
  EXPECT_EQ(effect_counters().springs, 0);
  EXPECT_EQ(effect_counters().joint_springs, 0);
  EXPECT_EQ(effect_counters().joint_frictions, 0);
  EXPECT_EQ(effect_counters().body_forces, 0);
  EXPECT_GT(effect_counters().actuators, 0);  // the torque actuator is declared
  // and a declared spring is: the four-bar's crank spring, once per evaluation
  const Model fb = test::load_example("four_bar.json");
  effect_counters() = {};
  const SimulationResult r2 = simulate(fb, nullptr, nullptr, sim_options("cvode-bdf", 0.2));
  ASSERT_TRUE(r2.completed);
  EXPECT_GT(effect_counters().joint_springs, r2.stats.rhs_evals / 2);
  EXPECT_EQ(effect_counters().springs, 0);
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// Actuator limits saturate the controller's command: the pendulum's PD asks for
// 38 N m at the start, the motor gives at most 20 and still lifts the rod
TEST(Simulate, ActuatorLimitsSaturateTheCommand) {
  ModelSpec s = load_model_spec(test::example_path("pendulum.json"));
  s.actuators[0].min = -20.0;
  s.actuators[0].max = 20.0;
  const Model m = compile(s);
  const LinearPlant p = plant_at_equilibrium(m);
  const double Kp = (9 + 3 * g_sim / 4) / 0.075, Kd = 4.8 / 0.075;
  const auto pd = make_pid(Eigen::MatrixXd::Constant(1, 1, Kp), Eigen::MatrixXd(), Eigen::MatrixXd::Constant(1, 1, Kd),
                           Eigen::VectorXd::Constant(1, M_PI / 2), Eigen::VectorXd::Zero(1));
  const SimulationResult r = simulate(m, pd.get(), &p, sim_options("ida", 6.0));
  ASSERT_TRUE(r.completed) << r.failure;
  EXPECT_DOUBLE_EQ(r.u(0, 0), 20.0);                 // clamped at the start (unclamped: 38.07)
  EXPECT_LE(r.u.cwiseAbs().maxCoeff(), 20.0 + 1e-12);
  EXPECT_NEAR(r.y(r.samples() - 1, 0), M_PI / 2, 0.5 * deg);
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// Saturation that binds is reported: which actuator, how long, from when.
TEST(Simulate, SaturationThatBindsIsReported) {
  ModelSpec spec = load_model_spec(test::example_path("pendulum.json"));
  spec.actuators[0].max = 20;
  spec.actuators[0].min = -20;
  const Model m = compile(spec);
  const LinearPlant p = plant_at_equilibrium(m);
  // a stiff P gain from the 10 degree offset asks for far more than 20 N m at first
  const auto pd = make_pid(Eigen::MatrixXd::Constant(1, 1, 500), Eigen::MatrixXd(), Eigen::MatrixXd::Constant(1, 1, 100),
                           p.lin.system.y0, p.lin.system.u0);
  const SimulationResult r = simulate(m, pd.get(), &p, sim_options("ida", 3.0));
  ASSERT_TRUE(r.completed) << r.failure;
  EXPECT_LE(r.u.col(0).maxCoeff(), 20.0 + 1e-12);
  const auto sat = saturation_report(m, r);
  ASSERT_EQ(sat.size(), 1u);
  EXPECT_EQ(sat[0].actuator, "torque");
  EXPECT_EQ(sat[0].first, 0.0);
  EXPECT_GT(sat[0].at_max + sat[0].at_min, 0.05);
  EXPECT_LT(sat[0].at_max + sat[0].at_min, 3.0);
  // without limits nothing is reported
  EXPECT_TRUE(saturation_report(test::load_example("pendulum.json"), r).empty());
}

}  // namespace
}  // namespace codyna
