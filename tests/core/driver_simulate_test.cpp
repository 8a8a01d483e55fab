// A sampled controller on a motion input inside simulate(): the driver steers the single-track
// car's steer (a motion input) through simulate() itself, held between its samples as the
// Stepper's co-simulation holds it. Checked against that second method (the maneuvers' stepper
// loop, written out here) and against the steady turn the driver must settle on.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <string>

#include "model/errors.hpp"
#include "simulation/driver.hpp"
#include "simulation/simulator.hpp"
#include "simulation/stepper.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"

namespace codyna {
namespace {

std::string driver_data(const std::string& name) { return std::string(CODYNA_TEST_DATA_DIR) + "/" + name; }

// simulate() with the driver, sampled every 0.01 s, equals the same driver stepped from outside
// through the Stepper (zero-order hold on the steer and drive) at every sample over 40 s to the
// integrators' accuracy, and holds the car on the 120 m circle: the lateral error over the last
// 5 s below 1e-5 m. (The steer's coordinate itself steps at each sample: simulate() records it
// after the step, the Stepper's q() before; it is compared with the held input instead.)
TEST(DriverInSimulate, TheSampledDriverOnAMotionInputIsTheSteppersRunAndHoldsTheCircle) {
  const std::string file = driver_data("single_track_car_driver.json");
  const ModelSpec spec = study_read_model(file);
  const Model m = study_model(spec, file);
  const OperatingPoint op = study_operating_point(m, "steady");
  SimulationOptions o;
  const Model run = held_at(m, op, o);
  Eigen::VectorXd u0(2);
  u0 << op.u[0], op.u[1];
  const DriverSettings ds = model_driver_settings(run, u0);
  ASSERT_GT(ds.sample_time, 0);
  const std::unique_ptr<Controller> driver = make_driver(ds);
  ASSERT_EQ(run.actuators[static_cast<std::size_t>(run.plant_inputs[static_cast<std::size_t>(ds.in_steer)])].type,
            ActuatorType::Motion);

  const int steps = 4000;  // 40 s
  o.t0 = 0;
  o.t_end = steps * ds.sample_time;
  o.output_step = ds.sample_time;
  o.integrator.method = "cvode-bdf";
  o.integrator.rtol = 1e-10;
  o.integrator.atol = 1e-12;
  const SimulationResult res = simulate(run, driver.get(), nullptr, o);
  ASSERT_TRUE(res.completed) << res.failure;
  ASSERT_EQ(res.samples(), steps + 1);

  // the second method: the driver stepped from outside
  const std::unique_ptr<Controller> outside = make_driver(ds);
  IntegratorSettings is;
  is.method = "cvode-bdf";
  is.rtol = 1e-10;
  is.atol = 1e-12;
  Stepper st(run, is);
  st.reset(0, o.q0, o.v0);
  Eigen::VectorXd xc = Eigen::VectorXd::Zero(outside->nxc());
  ControllerInput in;
  const int steer = run.plant_inputs[static_cast<std::size_t>(ds.in_steer)];
  const int steer_q = run.actuators[static_cast<std::size_t>(steer)].iq;
  double dq = 0, dy = 0, late_error = 0, held = 0;
  for (int k = 0; k <= steps; ++k) {
    in.t = st.time();
    in.y = st.outputs();
    const Eigen::VectorXd u = outside->output(in, xc);
    Eigen::VectorXd diff = res.q.row(k).transpose() - st.q();
    diff[steer_q] = 0;
    dq = std::max(dq, diff.cwiseAbs().maxCoeff());
    held = std::max(held, std::abs(res.q(k, steer_q) - res.u(k, steer)));
    dy = std::max(dy, (res.y.row(k).transpose() - in.y).cwiseAbs().maxCoeff());
    // simulate()'s own samples: the lateral error from its recorded outputs
    if (k >= steps - 500) {
      const Eigen::VectorXd y = res.y.row(k).transpose();
      late_error = std::max(late_error, std::abs(driver_law(ds, y[ds.out_x], y[ds.out_y], y[ds.out_yaw]).lateral));
    }
    if (k == steps) break;
    xc = outside->update(in, xc);
    st.step(u, ds.sample_time);
  }
  std::cout << "simulate() against the stepper: |dq| " << dq << ", |dy| " << dy << "; lateral error over the last 5 s "
            << late_error << " m\n";
  // positions of order 100 m after 25 s at 30 m/s, and the two runs restart their integrators at
  // the same samples: they agree to far below a millimetre
  EXPECT_LT(dq, 1e-6);
  EXPECT_LT(dy, 1e-6);
  EXPECT_LT(late_error, 1e-5);
  // the steer's coordinate is the held sample's input at every sample, and it moves
  EXPECT_EQ(held, 0.0);
  EXPECT_NE(res.u(10, steer), res.u(0, steer));
}

// A continuous controller on a motion input is still refused, naming the input and what would do
struct HoldStill final : Controller {
  Eigen::VectorXd output(const ControllerInput&, const Eigen::VectorXd&) const override { return Eigen::VectorXd::Zero(2); }
  std::string describe() const override { return "zero, continuous"; }
};
TEST(DriverInSimulate, AContinuousControllerOnAMotionInputIsRefusedNamingIt) {
  const std::string file = driver_data("single_track_car_driver.json");
  const Model m = study_model(study_read_model(file), file);
  const HoldStill zero;
  SimulationOptions o;
  o.t_end = 0.1;
  try {
    (void)simulate(m, &zero, nullptr, o);
    FAIL() << "a continuous controller on the steer was simulated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the continuous controller drives the motion input \"steer\""), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("sample_time > 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace codyna
