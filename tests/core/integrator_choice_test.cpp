// The default integrator "auto" (simulation/integrator_choice.hpp): the stiffness measure
// against the exact linearization's eigenvalues (a second method), the choice on each class
// of reference problem, and what a run reports.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "analysis/linearize.hpp"
#include "core/test_util.hpp"
#include "simulation/integrator_choice.hpp"
#include "simulation/simulator.hpp"

namespace codyna {
namespace {

IntegratorChoice choice_for(const Model& m, double span) {
  ClosedLoopSystem sys(m, nullptr, nullptr, Eigen::VectorXd(), m.u_nominal());
  Eigen::VectorXd y(sys.ode_size());
  const OperatingPoint op = initial_point(m);
  y << op.q, op.v;
  return choose_integrator(sys, 0.0, y, span);
}

// max -Re(lambda) of the exact linearization at the initial state (minimal coordinates)
double fastest_decay_exact(const Model& m) {
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
  EXPECT_NEAR(c.fastest_decay, exact, 1e-5 * exact);  // central differences against analytic derivatives
  EXPECT_GT(c.fastest_decay / c.slow_rate, 100.0);
  EXPECT_NE(c.reason.find("stiff"), std::string::npos);
}

TEST(IntegratorChoice, NonStiffTreesGetAdamsAndLoopsGetProjectedRungeKutta) {
  for (const char* file : {"double_pendulum.json", "heavy_top.json", "iftomm_a01_pendulum.json", "pendulum.json"}) {
    const IntegratorChoice c = choice_for(test::load_example(file), 10.0);
    EXPECT_TRUE(c.analysed) << file;
    EXPECT_FALSE(c.stiff) << file << ": " << c.reason;
    EXPECT_EQ(c.method, "cvode-adams") << file;
  }
  for (const char* file : {"andrews_squeezer.json", "bricard.json", "iftomm_a02_four_bars.json", "four_bar.json"}) {
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
