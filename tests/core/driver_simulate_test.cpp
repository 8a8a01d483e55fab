// A sampled controller on a motion input inside simulate(): the driver steers the single-track
// car's steer (a motion input) through simulate() itself, held between its samples as the
// Stepper's co-simulation holds it. Checked against that second method (the maneuvers' stepper
// loop, written out here) and against the steady turn the driver must settle on.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "model/errors.hpp"
#include "simulation/controller.hpp"
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

// The single-track car with a yaw moment on the chassis (a body torque about its z axis, N m) as
// its only Plant/In and the yaw rate its only Plant/Out: what a yaw-moment controller acts on
// while the driver steers and holds the speed beside it
Model car_with_yaw_moment(const std::string& file) {
  nlohmann::json j = study_model_json(study_read_model(file));
  j["actuators"].push_back({{"name", "yaw_moment"}, {"type", "body_torque"}, {"body", "chassis"},
                            {"direction", {0, 0, 1}}, {"frame", "body"}, {"unit", "N m"}});
  j["plant"]["inputs"] = {"yaw_moment"};
  j["plant"]["outputs"] = {"yaw_rate"};
  j.erase("controller");
  return study_model(study_parse_model(j, file), file);
}

int name_index(const std::vector<std::string>& names, const std::string& name) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<int>(k);
  ADD_FAILURE() << "no " << name;
  return -1;
}

// A sampled controller beside the first (SimulationOptions::beside): the driver steers and holds
// the speed through the sensors and actuators it names while a P controller on the yaw rate acts
// on the yaw moment through Plant/In.
//  - with the P gain zero the run is the driver's own run as the first controller (the sampled
//    path DriverInSimulate checks against the Stepper), to round-off;
//  - with a gain, the yaw moment recorded at every sample is the P law on the yaw rate recorded
//    there (the first controller acts continuously, between the driver's samples too: the moment
//    is not held), it opposes the turn (-kp U / R once on the circle), and the driver's integral
//    still settles the car on the circle (lateral error below 1e-4 m over the last 5 s of 60 s)
//    with more steer than without it.
TEST(DriverInSimulate, ADriverBesideAYawMomentControllerInOneRun) {
  const std::string file = driver_data("single_track_car_driver.json");
  const Model alone = study_model(study_read_model(file), file);
  const OperatingPoint op_alone = study_operating_point(alone, "steady");
  SimulationOptions o;
  const Model run_alone = held_at(alone, op_alone, o);
  Eigen::VectorXd u0(2);
  u0 << op_alone.u[0], op_alone.u[1];
  const DriverSettings ds = model_driver_settings(run_alone, u0);
  const std::unique_ptr<Controller> driver = make_driver(ds);
  o.t_end = 60;
  o.output_step = ds.sample_time;
  o.integrator.method = "cvode-bdf";
  o.integrator.rtol = 1e-10;
  o.integrator.atol = 1e-12;
  const SimulationResult first = simulate(run_alone, driver.get(), nullptr, o);
  ASSERT_TRUE(first.completed) << first.failure;

  const Model car = car_with_yaw_moment(file);
  const OperatingPoint op = study_operating_point(car, "steady");
  SimulationOptions ob = o;
  const Model run = held_at(car, op, ob);
  std::vector<std::string> sensors, actuators;
  for (const SensorModel& x : run.sensors) sensors.push_back(x.name);
  for (const ActuatorModel& a : run.actuators) actuators.push_back(a.name);
  // the driver's four outputs (x, y, yaw, speed) and two inputs (steer, drive), as it was made
  ob.beside.controller = driver.get();
  // the driver was made on run_alone's Plant/Out: the same names among the sensors, in that order
  std::vector<std::string> read;
  for (int k : run_alone.plant_outputs) read.push_back(run_alone.sensors[static_cast<std::size_t>(k)].name);
  for (const std::string& n : read) ob.beside.sensors.push_back(name_index(sensors, n));
  ob.beside.actuators = {name_index(actuators, "steer"), name_index(actuators, "drive")};
  const int iyaw = name_index(actuators, "yaw_moment"), isteer = name_index(actuators, "steer");
  const double y0 = 0;  // the reference: the straight run's yaw rate

  const auto run_with = [&](double kp) {
    const Eigen::MatrixXd Kp = Eigen::MatrixXd::Constant(1, 1, kp);
    const std::unique_ptr<Controller> p =
        make_pid(Kp, {}, {}, Eigen::VectorXd::Constant(1, y0), Eigen::VectorXd::Constant(1, op.u[iyaw]));
    const SimulationResult r = simulate(run, p.get(), nullptr, ob);
    EXPECT_TRUE(r.completed) << r.failure;
    return r;
  };
  const SimulationResult zero = run_with(0.0);
  ASSERT_EQ(zero.samples(), first.samples());
  double dq = 0;
  for (int k = 0; k < zero.samples(); ++k) dq = std::max(dq, (zero.q.row(k) - first.q.row(k)).cwiseAbs().maxCoeff());
  EXPECT_LT(dq, 1e-9) << "the driver beside is not the driver's own run";
  // the driver's two integrals are recorded after the first controller's (none)
  ASSERT_EQ(zero.xc.cols(), 2);
  EXPECT_EQ(zero.controller_state_names, driver->state_names());
  EXPECT_LT((zero.xc - first.xc).cwiseAbs().maxCoeff(), 1e-7);

  const double kp = 2.0e4;  // N m per rad/s: u = kp (0 - r), a moment against the yaw rate
  const SimulationResult with = run_with(kp);
  ASSERT_EQ(with.samples(), first.samples());
  double law = 0, largest = 0, late = 0;
  for (int k = 0; k < with.samples(); ++k) {
    law = std::max(law, std::abs(with.u(k, iyaw) - kp * (y0 - with.y(k, 0))));
    largest = std::max(largest, std::abs(with.u(k, iyaw)));
    if (k >= with.samples() - 500) {
      const Eigen::Vector2d p(with.q(k, 0), with.q(k, 1));
      late = std::max(late, std::abs(driver_law(ds, p.x(), p.y(), with.q(k, 2)).lateral));
    }
  }
  const int last = with.samples() - 1;
  std::cout << "beside: |dq| at gain 0 " << dq << "; P law " << law << " N m of " << largest
            << " N m; late lateral error " << late << " m; steer " << with.u(last, isteer) << " (alone "
            << first.u(last, isteer) << ")\n";
  EXPECT_LT(law, 1e-9 * largest);
  EXPECT_GT(largest, 1000.0);  // it acts
  // on the 120 m circle at the held 30 m/s the yaw rate is U / R: the moment there is -kp U / R
  EXPECT_NEAR(with.u(last, iyaw), -kp * 30.0 / 120.0, 5.0);
  EXPECT_LT(late, 1e-4);
  EXPECT_GT(with.u(last, isteer), first.u(last, isteer) * 1.05);  // the driver steers more against it
}

// What cannot sit beside is refused before the run, naming what is wrong
TEST(DriverInSimulate, WhatCannotSitBesideIsRefusedNamingIt) {
  const std::string file = driver_data("single_track_car_driver.json");
  const Model car = car_with_yaw_moment(file);
  std::vector<std::string> sensors, actuators;
  for (const SensorModel& x : car.sensors) sensors.push_back(x.name);
  for (const ActuatorModel& a : car.actuators) actuators.push_back(a.name);
  DriverSettings ds;
  ds.path = path_straight({0, 0}, 0, 100);
  ds.u0 = Eigen::VectorXd::Zero(1);
  ds.out_x = 0, ds.out_y = 1, ds.out_yaw = 2, ds.out_speed = 3, ds.in_steer = 0;
  const std::unique_ptr<Controller> driver = make_driver(ds);
  const std::unique_ptr<Controller> p =
      make_pid(Eigen::MatrixXd::Constant(1, 1, 1.0), {}, {}, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1));
  const auto refusal = [&](const SimulationOptions& o) {
    try {
      (void)simulate(car, p.get(), nullptr, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("simulated");
  };
  SimulationOptions o;
  o.t_end = 0.05;
  o.beside.controller = driver.get();
  o.beside.sensors = {name_index(sensors, "x"), name_index(sensors, "y"), name_index(sensors, "yaw"), name_index(sensors, "speed")};
  o.beside.actuators = {name_index(actuators, "yaw_moment")};  // the first controller's Plant/In
  EXPECT_NE(refusal(o).find("sets \"yaw_moment\", a Plant/In input the first controller drives"), std::string::npos) << refusal(o);
  o.beside.actuators = {name_index(actuators, "steer"), name_index(actuators, "steer")};
  EXPECT_NE(refusal(o).find("sets \"steer\" twice"), std::string::npos) << refusal(o);
  o.beside.actuators = {name_index(actuators, "steer"), name_index(actuators, "drive")};  // two values for one
  EXPECT_NE(refusal(o).find("gives 1 values for 2 actuators"), std::string::npos) << refusal(o);
  o.beside.actuators = {99};
  EXPECT_NE(refusal(o).find("names an actuator the model does not have"), std::string::npos) << refusal(o);
  o.beside.actuators = {name_index(actuators, "steer")};
  o.beside.sensors.back() = name_index(sensors, "lateral_acceleration");
  EXPECT_NE(refusal(o).find("reads \"lateral_acceleration\", which depends on the inputs"), std::string::npos) << refusal(o);
  const HoldStill continuous;
  o.beside.controller = &continuous;
  EXPECT_NE(refusal(o).find("must be sampled"), std::string::npos) << refusal(o);
  // and the one that fits runs
  o.beside.controller = driver.get();
  o.beside.sensors.back() = name_index(sensors, "speed");
  EXPECT_EQ(refusal(o), "simulated");
}

}  // namespace
}  // namespace codyna
