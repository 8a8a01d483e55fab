// Linearization along a trajectory against the pendulum's closed form at
// every point (A(2,1) = 3g/(2l) sin(theta(t)), B(2) = 3/(m l^2)) and against
// the nonlinear rates (xdot0 = [theta'; theta''] of the trajectory).
#include "simulation/trajectory_linearization.hpp"

#include <cmath>

#include "analysis/operating_point.hpp"
#include "simulation/model_controller.hpp"
#include "simulation/simulator.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

TEST(TrajectoryLinearization, PendulumMatchesClosedFormAtEveryPoint) {
  const Model m = test::load_example("pendulum.json");  // carries the paper's PD law
  const LinearPlant p = controller_plant(m);
  const auto pd = make_model_controller(m, p);
  SimulationOptions o;
  o.integrator.method = "cvode-bdf";
  o.integrator.rtol = 1e-10;
  o.integrator.atol = 1e-12;
  o.t_end = 2.0;
  o.output_step = 0.1;
  const SimulationResult r = simulate(m, pd.get(), &p, o);
  ASSERT_TRUE(r.completed);
  const std::vector<Linearization> lin = linearize_along(m, r);
  ASSERT_EQ(static_cast<int>(lin.size()), r.samples());
  const double g = 9.81, l = 2, mass = 10;
  for (int k = 0; k < r.samples(); ++k) {
    const LinearSystem& s = lin[k].system;
    const double th = r.q(k, 0), w = r.v(k, 0), u = r.u(k, 0);
    EXPECT_NEAR(s.A(1, 0), 3 * g / (2 * l) * std::sin(th), 1e-10) << "t = " << r.t[k];
    EXPECT_NEAR(s.B(1, 0), 3 / (mass * l * l), 1e-12);
    EXPECT_NEAR(s.x0[0], th, 1e-15);
    EXPECT_NEAR(s.xdot0[0], w, 1e-12);
    EXPECT_NEAR(s.xdot0[1], 3 * u / (mass * l * l) - 3 * g / (2 * l) * std::cos(th), 1e-9);  // paper 4.1's equation
    EXPECT_NEAR(s.u0[0], u, 0.0);
    EXPECT_NEAR(s.time, r.t[k], 0.0);
  }
}

TEST(TrajectoryLinearization, ClosedLoopKeepsOneStateOrder) {
  const Model m = test::load_example("four_bar.json");
  SimulationOptions o;
  o.integrator.method = "cvode-bdf";
  o.t_end = 1.0;
  o.output_step = 0.1;
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  ASSERT_TRUE(r.completed);
  const std::vector<Linearization> lin = linearize_along(m, r, {}, 2);
  ASSERT_EQ(lin.size(), 6u);
  for (const Linearization& l : lin) EXPECT_EQ(l.system.state_names, lin[0].system.state_names);
}

}  // namespace
}  // namespace codyna
