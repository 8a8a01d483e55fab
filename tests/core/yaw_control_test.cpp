// The vehicle control example end to end (docs/vehicles.md, "A yaw-rate controller"):
// examples/sedan_esc.json is the sedan with a P yaw-rate controller on its front brakes. Its gain
// is designed again here from the car linearized at 25 m/s (crossover of the loop at 1 Hz) and
// checked against the file's; the sine with dwell (FMVSS 126) at a steer where the car spins out
// without it is run with and without it; the handling numbers of a car whose steer is not a
// Plant/In equal those of the same car with the steer as its Plant/In; a maneuver refuses a
// controller that would act on the steer it drives, and a comparison with the open-loop linear model.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <string>

#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/maneuver_job.hpp"
#include "study/workflow.hpp"

using namespace codyna;

namespace {

const double kPiYawControlTest = 3.14159265358979323846;

std::string yaw_control_example(const std::string& name) { return std::string(CODYNA_EXAMPLES_DIR) + "/" + name; }

std::string yaw_control_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

// the yaw rate's response to a differential front brake torque (brake_fl = -d, brake_fr = +d),
// from the linearization, at w rad/s
std::complex<double> yaw_control_response(const LinearSystem& s, double w) {
  const Eigen::Vector2d diff(-1.0, 1.0);
  const Eigen::Index n = s.A.rows();
  const Eigen::MatrixXcd M = std::complex<double>(0, w) * Eigen::MatrixXcd::Identity(n, n) - s.A.cast<std::complex<double>>();
  const Eigen::VectorXcd x = M.partialPivLu().solve((s.B * diff).cast<std::complex<double>>());
  return (s.C.row(0).cast<std::complex<double>>() * x)(0) + (s.D.row(0) * diff)(0);
}

}  // namespace

// k = 1 / |G(j 2 pi)|: the loop from the differential brake torque to the yaw rate crosses over at
// 1 Hz (measured 7304.1 N m per rad/s, the file holds 7300); the linear closed loop is stable
// (its slowest poles the neutral ones of the road position and heading) with a phase margin above
// 150 degrees
TEST(YawControl, TheExamplesGainIsItsDesignOnTheCarLinearizedAt25) {
  const std::string file = yaw_control_example("sedan_esc.json");
  const ModelSpec spec = study_read_model(file);
  ASSERT_EQ(spec.analysis.steady.speed, 25.0);
  const Model m = study_model(spec, file);
  const StudyLinearization sl = study_linearize(m);
  const LinearSystem& s = sl.lin.system;
  ASSERT_EQ(s.input_names, (std::vector<std::string>{"brake_fl", "brake_fr"}));
  ASSERT_EQ(s.output_names.front(), "yaw_rate");
  const std::complex<double> g = yaw_control_response(s, 2 * kPiYawControlTest);
  const double k = 1.0 / std::abs(g);
  std::cout << "designed gain " << k << " N m per rad/s, phase at crossover " << std::arg(g) * 180 / kPiYawControlTest
            << " deg\n";
  ASSERT_EQ(spec.controller.kp.rows(), 2);
  const double k_file = spec.controller.kp(1, 0);
  EXPECT_EQ(spec.controller.kp(0, 0), -k_file);
  EXPECT_NEAR(k_file, k, 0.005 * k);
  EXPECT_GT(180 - std::abs(std::arg(g) * 180 / kPiYawControlTest), 150.0);  // phase margin
  // the linear closed loop u = kp (r - y): A - B kp C
  const Eigen::MatrixXd Acl = s.A - s.B * spec.controller.kp * s.C;  // kp D = 0: the yaw rate has no feedthrough
  EXPECT_LT((spec.controller.kp * s.D).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::VectorXcd poles = Acl.eigenvalues();
  double largest = -1e300;
  for (Eigen::Index i = 0; i < poles.size(); ++i) largest = std::max(largest, poles[i].real());
  EXPECT_LT(largest, 1e-6);
}

// The handling numbers of sedan_esc (its steer not a Plant/In: linearized again with it as an
// input) are those of sedan.json (the same car, the steer its Plant/In)
TEST(YawControl, HandlingNumbersNeedNotTheSteerAmongPlantIn) {
  const std::string esc = yaw_control_example("sedan_esc.json"), plain = yaw_control_example("sedan.json");
  const StudyLinearization a = study_linearize(study_model(study_read_model(esc), esc));
  const StudyLinearization b = study_linearize(study_model(study_read_model(plain), plain));
  ASSERT_TRUE(a.handling && b.handling);
  EXPECT_NEAR(a.handling->yaw_rate_gain, b.handling->yaw_rate_gain, 1e-9 * std::abs(b.handling->yaw_rate_gain));
  EXPECT_NEAR(a.handling->understeer_gradient, b.handling->understeer_gradient, 1e-9 * std::abs(b.handling->understeer_gradient));
  EXPECT_NEAR(a.handling->lateral_acceleration_gain, b.handling->lateral_acceleration_gain,
              1e-9 * std::abs(b.handling->lateral_acceleration_gain));
  EXPECT_NEAR(a.handling->yaw_natural_frequency, b.handling->yaw_natural_frequency, 1e-7 * b.handling->yaw_natural_frequency);
}

// FMVSS 126's sine with dwell at 25 m/s and 3 rad at the steering wheel (172 deg, within the
// standard's series up to 270 deg): without the controller the car spins out (its sideslip past
// 20 deg: the metrics invalid, saying so); with it the yaw-rate ratios pass with margin, the
// lateral displacement too, and the sideslip stays below 5 deg; the brakes act within their limits
TEST(YawControl, TheSedanSpinsOutInTheSineWithDwellWithoutItAndPassesWithIt) {
  const std::string file = yaw_control_example("sedan_esc.json");
  const ModelSpec spec = study_read_model(file);
  ManeuverRequest r;
  r.model = file;
  r.type = "sine-with-dwell";
  r.steer = 3.0;
  r.output_step = 0.01;
  r.open_loop = true;
  const ManeuverReport open = study_maneuver_job(r, spec);
  std::cout << study_maneuver_text(open);
  EXPECT_FALSE(open.valid);
  EXPECT_NE(open.invalid_reason.find("spun out"), std::string::npos) << open.invalid_reason;
  EXPECT_GT(open.max_sideslip, 10 * kPiYawControlTest / 180);
  EXPECT_TRUE(open.controller.empty());
  EXPECT_FALSE(open.sine.passes_fmvss126);

  r.open_loop = false;
  const ManeuverReport esc = study_maneuver_job(r, spec);
  std::cout << study_maneuver_text(esc);
  ASSERT_TRUE(esc.valid) << esc.invalid_reason;
  EXPECT_NE(esc.controller.find("pid"), std::string::npos) << esc.controller;
  EXPECT_LT(esc.sine.yrr_1_00, 35.0);
  EXPECT_LT(esc.sine.yrr_1_75, 20.0);
  EXPECT_GE(std::abs(esc.sine.lateral_displacement), 1.83);
  EXPECT_TRUE(esc.sine.passes_fmvss126);
  EXPECT_LT(esc.max_sideslip, 5 * kPiYawControlTest / 180);
  // the reference: the straight run's steady yaw-rate gain, limited by 0.85 g / U
  const Model plain = study_model(study_read_model(yaw_control_example("sedan.json")), yaw_control_example("sedan.json"));
  const StudyLinearization lin = study_linearize(plain);
  ASSERT_TRUE(lin.handling);
  EXPECT_NEAR(esc.reference_gain, lin.handling->yaw_rate_gain, 1e-9 * lin.handling->yaw_rate_gain);
  EXPECT_NEAR(esc.reference_limit, 0.85 * 9.80665 / 25.0, 1e-6);
  ASSERT_EQ(esc.controller_inputs, (std::vector<std::string>{"brake_fl", "brake_fr"}));
  for (double e : esc.controller_effort) {
    EXPECT_GT(e, 500.0);
    EXPECT_LE(e, 3000.0 + 1e-9);
  }
}

// A controller on the steer the maneuver drives, an acceleration the PID reads (an algebraic
// loop), and a swept sine (compared with the open-loop linear model) with a controller: refused
TEST(YawControl, ManeuversRefuseAControllerTheyCannotRun) {
  const std::string file = yaw_control_example("sedan_esc.json");
  const ModelSpec spec = study_read_model(file);
  ManeuverRequest r;
  r.model = file;
  r.type = "swept-sine";
  std::string e = yaw_control_error([&] { study_maneuver_job(r, spec); });
  EXPECT_NE(e.find("--open-loop"), std::string::npos) << e;
  EXPECT_NE(e.find("pid controller"), std::string::npos) << e;

  ModelSpec on_steer = spec;
  on_steer.plant.inputs = {"steer", "brake_fr"};
  r.type = "step-steer";
  e = yaw_control_error([&] { study_maneuver_job(r, on_steer); });
  EXPECT_NE(e.find("/plant/inputs"), std::string::npos) << e;
  EXPECT_NE(e.find("drives the steer \"steer\""), std::string::npos) << e;

  ModelSpec reads_ay = spec;
  reads_ay.controller.kp(1, 1) = 10.0;
  r.t_end = 1.1;
  e = yaw_control_error([&] { study_maneuver_job(r, reads_ay); });
  EXPECT_NE(e.find("algebraic loop"), std::string::npos) << e;
  EXPECT_NE(e.find("lateral_acceleration"), std::string::npos) << e;
}
