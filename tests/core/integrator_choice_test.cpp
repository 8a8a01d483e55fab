// The default integrator "auto" (simulation/integrator_choice.hpp): the
// stiffness measure against the exact linearization's eigenvalues (a second
// method), the choice on each class of reference problem, and what a run
// reports.
#include "simulation/integrator_choice.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "analysis/linearize.hpp"
#include "core/test_util.hpp"
#include "simulation/simulator.hpp"
#include "simulation/stepper.hpp"

namespace codyna {
namespace {

IntegratorChoice choice_for(const Model &m, double span, double rtol = 1e-8) {
  ClosedLoopSystem sys(m, nullptr, nullptr, Eigen::VectorXd(), m.u_nominal());
  Eigen::VectorXd y(sys.ode_size());
  const OperatingPoint op = initial_point(m);
  y << op.q, op.v;
  return choose_integrator(sys, 0.0, y, span, rtol);
}

// max -Re(lambda) of the exact linearization at the initial state (minimal
// coordinates)
double fastest_decay_exact(const Model &m) {
  const Linearization lin = linearize(m, initial_point(m));
  const Eigen::VectorXcd l = Eigen::EigenSolver<Eigen::MatrixXd>(lin.system.A, false).eigenvalues();
  double d = 0;
  for (int i = 0; i < l.size(); ++i) d = std::max(d, -l[i].real());
  return d;
}

TEST(IntegratorChoice, StiffFlyballGetsBdfAndItsDecayRateMatchesTheExactLinearization) {
  const Model m = test::load_example("iftomm_a05_flyball.json");
  const IntegratorChoice c = choice_for(m, 10.0);
  std::cout << c.reason << "\n";
  EXPECT_TRUE(c.analysed);
  EXPECT_TRUE(c.stiff);
  EXPECT_EQ(c.method, "cvode-bdf");
  const double exact = fastest_decay_exact(m);
  EXPECT_NEAR(c.fastest_decay, exact,
              1e-5 * exact);  // central differences against analytic derivatives
  EXPECT_GT(c.fastest_decay / c.slow_rate, 100.0);
  EXPECT_NE(c.reason.find("stiff"), std::string::npos);
  EXPECT_FALSE(c.alf_extrapolate);
}

// Stiff at loose accuracy (rtol >= kAlfLooseRtol): alf, extrapolated, on a tree
// (the flyball) as on closed loops (the K&C rig); tighter: cvode-bdf
TEST(IntegratorChoice, StiffModelsAtLooseAccuracyGetExtrapolatedAlf) {
  for (const char *file : {"iftomm_a05_flyball.json", "kc_double_wishbone.json"}) {
    const Model m = test::load_example(file);
    for (const double rtol : {1e-2, 1e-3, kAlfLooseRtol}) {
      const IntegratorChoice c = choice_for(m, 5.0, rtol);
      EXPECT_TRUE(c.stiff) << file << ": " << c.reason;
      EXPECT_EQ(c.method, "alf") << file << " at " << rtol << ": " << c.reason;
      EXPECT_TRUE(c.alf_extrapolate) << file;
      EXPECT_EQ(c.reason.rfind("auto: alf (extrapolated), stiff", 0), 0u) << c.reason;
    }
    for (const double rtol : {0.5 * kAlfLooseRtol, 1e-6, 1e-8}) {
      const IntegratorChoice c = choice_for(m, 5.0, rtol);
      EXPECT_EQ(c.method, "cvode-bdf") << file << " at " << rtol << ": " << c.reason;
      EXPECT_FALSE(c.alf_extrapolate) << file;
    }
  }
}

// What the rule buys, against a second method: the flyball (a tree, 2 s) and
// the K&C rig (closed loops, 2 s) at rtol 1e-3 by auto (alf extrapolated) and
// by cvode-bdf at the same tolerance, both against ida at rtol 1e-11. Measured:
// the flyball 8.2e-7 (auto) against 1.3e-4 (cvode-bdf), the rig 1.4e-8
// against 7.0e-7 (largest gap in q over the samples).
void expect_auto_far_closer(const char *file, double bound, double ratio) {
  const Model m = test::load_example(file);
  SimulationOptions o;
  o.t_end = 2.0;
  o.output_step = 0.05;
  o.integrator.rtol = 1e-11;
  o.integrator.atol = 1e-13;
  o.integrator.method = "ida";
  const SimulationResult ref = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(ref.completed) << ref.failure;
  const auto gap = [&](const SimulationResult &r) { return (r.q - ref.q).cwiseAbs().maxCoeff(); };
  o.integrator.rtol = 1e-3;
  o.integrator.atol = 1e-5;
  o.integrator.method = "auto";
  const SimulationResult a = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(a.completed) << a.failure;
  EXPECT_EQ(a.stats.integrator, "alf");
  EXPECT_EQ(a.stats.integrator_choice.rfind("auto: alf (extrapolated)", 0), 0u) << a.stats.integrator_choice;
  o.integrator.method = "cvode-bdf";
  const SimulationResult b = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(b.completed) << b.failure;
  ASSERT_EQ(a.q.rows(), ref.q.rows());
  ASSERT_EQ(b.q.rows(), ref.q.rows());
  const double ea = gap(a), eb = gap(b);
  std::cout << file << " at rtol 1e-3: auto " << ea << ", cvode-bdf " << eb << "\n";
  EXPECT_LT(ea, bound) << file;
  EXPECT_LT(ea, ratio * eb) << file;
}

TEST(IntegratorChoice, AutoOnStiffModelsAtLooseAccuracyIsFarCloserThanBdfAtTheSameTolerance) {
  expect_auto_far_closer("iftomm_a05_flyball.json", 3e-6, 0.02);
  expect_auto_far_closer("kc_double_wishbone.json", 5e-8, 0.1);
}

// A stepped run (simulation/stepper.hpp: the MEX gateway, the GUI's interactive mode) makes the
// same choice and steps alf, extrapolated, 2 s in 200 steps of 10 ms: the flyball at rtol 1e-3
// stays within 2e-5 of ida at rtol 1e-11 (measured 2.3e-6; cvode-bdf in one run at that rtol: 1.3e-4).
TEST(IntegratorChoice, AStepperTakesAutosAlfAndStaysAsClose) {
  const Model m = test::load_example("iftomm_a05_flyball.json");
  SimulationOptions o;
  o.t_end = 2.0;
  o.output_step = 0.01;
  o.integrator.method = "ida";
  o.integrator.rtol = 1e-11;
  o.integrator.atol = 1e-13;
  const SimulationResult ref = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(ref.completed) << ref.failure;
  IntegratorSettings s;
  s.method = "auto";
  s.rtol = 1e-3;
  s.atol = 1e-5;
  Stepper st(m, s);
  EXPECT_EQ(st.stats().integrator, "alf");
  EXPECT_EQ(st.stats().integrator_choice.rfind("auto: alf (extrapolated)", 0), 0u) << st.stats().integrator_choice;
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(st.nu());
  double worst = 0;
  for (int i = 1; i < ref.samples(); ++i) {
    st.step(u, 0.01);
    worst = std::max(worst, (st.q() - ref.q.row(i).transpose()).cwiseAbs().maxCoeff());
  }
  std::cout << "stepped flyball at rtol 1e-3 by auto: " << worst << "\n";
  EXPECT_NEAR(st.time(), 2.0, 1e-12);
  EXPECT_LT(worst, 2e-5);
}

TEST(IntegratorChoice, NonStiffTreesGetAdamsAndLoopsGetProjectedRungeKutta) {
  for (const char *file : {"double_pendulum.json", "heavy_top.json", "iftomm_a01_pendulum.json", "pendulum.json"}) {
    const IntegratorChoice c = choice_for(test::load_example(file), 10.0);
    EXPECT_TRUE(c.analysed) << file;
    EXPECT_FALSE(c.stiff) << file << ": " << c.reason;
    EXPECT_EQ(c.method, "cvode-adams") << file;
  }
  for (const char *file : {"andrews_squeezer.json", "bricard.json", "iftomm_a02_four_bars.json", "four_bar.json"}) {
    const IntegratorChoice c = choice_for(test::load_example(file), 10.0);
    EXPECT_TRUE(c.analysed) << file;
    EXPECT_FALSE(c.stiff) << file << ": " << c.reason;
    EXPECT_EQ(c.method, "arkode") << file;
  }
}

TEST(IntegratorChoice, ARunWithAutoSaysWhatItChoseAndWhy) {
  const Model m = test::load_example("iftomm_a05_flyball.json");
  SimulationOptions o;
  ASSERT_EQ(o.integrator.method, "auto");  // the default
  o.t_end = 0.05;
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(r.completed) << r.failure;
  EXPECT_EQ(r.stats.integrator, "cvode-bdf");
  EXPECT_EQ(r.stats.integrator_choice.rfind("auto: cvode-bdf, stiff", 0), 0u) << r.stats.integrator_choice;
  o.integrator.method = "ida";  // asked for by name: no choice made
  EXPECT_TRUE(simulate(m, nullptr, nullptr, o).stats.integrator_choice.empty());
}

TEST(IntegratorChoice, AutoMustBeResolvedBeforeMakingAnIntegrator) {
  const Model m = test::load_example("pendulum.json");
  ClosedLoopSystem sys(m, nullptr, nullptr, Eigen::VectorXd(), m.u_nominal());
  IntegratorSettings s;
  EXPECT_INVALID_ARGUMENT_WITH(make_integrator(sys, s), "auto", "choose_integrator");
}

}  // namespace
}  // namespace codyna
