// The sensors a vehicle engineer reads (issue 39): angular_velocity (a gyro: a body's angular
// velocity in a frame's axes), acceleration (an accelerometer: a point's acceleration in a frame's
// axes, kinematic or the specific force a - g) and tire (a tire effect's slips, camber, forces and
// aligning moment in its ISO-W axes). Each against a closed form; their rows of the plant's
// Jacobian (C and the acceleration's D) against central differences and automatic
// differentiation; the analytic derivatives (TreeDerivatives) against automatic differentiation;
// the refusals, naming the file and the field; the model file's round trip.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/data.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "model/spec_edit.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "jacobian_check.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

// every sensor of the model as Plant/Out, evaluated by the plant function at (q0, v0, u)
struct SensorTypesPlant {
  Model model;
  CoordinatePartition partition;
  std::unique_ptr<PlantFunction> f;
  Eigen::VectorXd x, u;
  explicit SensorTypesPlant(const std::string& text, const std::string& label = "sensors.json")
      : model(study_model(study_parse_model_text(text, label))) {
    partition = partition_coordinates(model, model.q0);
    f = std::make_unique<PlantFunction>(model, model.q0, model.u_nominal(), partition);
    x = f->qv_to_state(model.q0, model.v0);
    u.resize(f->nu());
    for (int i = 0; i < f->nu(); ++i) u[i] = model.u_nominal()[model.plant_inputs[static_cast<std::size_t>(i)]];
  }
  Eigen::VectorXd outputs() const {
    Eigen::VectorXd xd, y;
    f->eval<double>(x, u, xd, y);
    return y;
  }
  double output(const std::string& name) const {
    for (std::size_t k = 0; k < model.plant_outputs.size(); ++k)
      if (model.sensors[static_cast<std::size_t>(model.plant_outputs[k])].name == name) return outputs()[static_cast<Eigen::Index>(k)];
    ADD_FAILURE() << "no output " << name;
    return 0;
  }
};

// "sensors": [...] and "plant" of every sensor named in `names`
std::string sensor_types_plant(const std::vector<std::string>& names) {
  std::string s = "\"plant\": {\"inputs\": [], \"outputs\": [";
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", \"" : "\"") + names[i] + "\"";
  return s + "]}";
}

TEST(SensorTypes, AngularVelocityIsTheBodysRateInTheFramesAxes) {
  // a free body turned by the quaternion qr, spinning at w (its own axes): angular_velocity reads w
  // in its own axes, R w in the ground's, and R_o^T R w in another body's (o, on a revolute joint)
  const Eigen::Quaterniond qr = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  const Eigen::Vector3d w(0.3, -0.2, 1.5);
  const double th = 0.4;
  char text[4000];
  std::snprintf(text, sizeof text, R"({"name": "spin",
    "bodies": [{"name": "b", "mass": 2, "inertia": [0.1, 0.2, 0.3]}, {"name": "o", "mass": 1, "inertia": [0.1, 0.1, 0.1]}],
    "joints": [{"name": "J", "type": "free", "parent": "ground", "child": "b",
                "q0": [0, 0, 1, %.17g, %.17g, %.17g, %.17g], "v0": [%.17g, %.17g, %.17g, 0, 0, 0]},
               {"name": "K", "type": "revolute", "parent": "ground", "child": "o", "axis": [1, 0, 0], "q0": [%.17g]}],
    "sensors": [{"name": "bx", "type": "angular_velocity", "body": "b", "component": "x", "frame": "b"},
                {"name": "by", "type": "angular_velocity", "body": "b", "component": "y", "frame": "b"},
                {"name": "bz", "type": "angular_velocity", "body": "b", "component": "z", "frame": "b"},
                {"name": "gx", "type": "angular_velocity", "body": "b", "component": 0},
                {"name": "gy", "type": "angular_velocity", "body": "b", "component": 1, "frame": "ground"},
                {"name": "gz", "type": "angular_velocity", "body": "b", "component": "z"},
                {"name": "oy", "type": "angular_velocity", "body": "b", "component": "y", "frame": "o"}],
    %s})",
                qr.w(), qr.x(), qr.y(), qr.z(), w[0], w[1], w[2], th,
                sensor_types_plant({"bx", "by", "bz", "gx", "gy", "gz", "oy"}).c_str());
  const SensorTypesPlant p(text);
  EXPECT_EQ(p.model.sensors[0].unit, "rad/s");
  const Eigen::Vector3d wg = qr.toRotationMatrix() * w;
  const Eigen::Vector3d wo = Eigen::AngleAxisd(th, Eigen::Vector3d::UnitX()).toRotationMatrix().transpose() * wg;
  const Eigen::VectorXd y = p.outputs();
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(y[k], w[k], 1e-14);
    EXPECT_NEAR(y[3 + k], wg[k], 1e-14);
  }
  EXPECT_NEAR(y[6], wo[1], 1e-14);
}

// a body on a revolute joint about z at angle th, rate w, driven by the torque `motor` (u0 = tau);
// gravity along -z (no moment about the axis); the com on the axis, Izz = 0.2
std::string sensor_types_rotor(double th, double w, double tau, const std::string& sensors, const std::string& outputs) {
  char text[4000];
  std::snprintf(text, sizeof text, R"({"name": "rotor",
    "bodies": [{"name": "arm", "mass": 1, "inertia": [0.1, 0.1, 0.2]}],
    "joints": [{"name": "J", "type": "revolute", "parent": "ground", "child": "arm", "axis": [0, 0, 1], "q0": [%.17g], "v0": [%.17g]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]}],
    "actuators": [{"name": "motor", "type": "joint_force", "joint": "J", "u0": %.17g}],
    "sensors": [%s],
    "plant": {"inputs": ["motor"], "outputs": [%s]}})",
                th, w, tau, sensors.c_str(), outputs.c_str());
  return text;
}

TEST(SensorTypes, AccelerationOfAPointOnARotatingBodyIsCentripetalAndTangential) {
  // r = 0.5 on the arm's x: in the arm's axes a = (-w^2 r, alpha r, 0) with alpha = tau / Izz; the
  // specific force a - g adds +9.81 on z (gravity along -z); in the ground's axes a turns by th
  const double th = 0.7, w = 3.0, tau = 0.4, r = 0.5, Izz = 0.2, g = 9.81, alpha = tau / Izz;
  const std::string sensors = R"(
      {"name": "ax", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "x", "frame": "arm"},
      {"name": "ay", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "y", "frame": "arm"},
      {"name": "az", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "z", "frame": "arm"},
      {"name": "fz", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "z", "frame": "arm", "specific_force": true},
      {"name": "gx", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "x"},
      {"name": "gy", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "y", "frame": "ground", "specific_force": true})";
  const SensorTypesPlant p(sensor_types_rotor(th, w, tau, sensors, R"("ax", "ay", "az", "fz", "gx", "gy")"));
  EXPECT_EQ(p.model.sensors[0].unit, "m/s^2");
  const Eigen::VectorXd y = p.outputs();
  const double ax = -w * w * r, ay = alpha * r;
  EXPECT_NEAR(y[0], ax, 1e-13);
  EXPECT_NEAR(y[1], ay, 1e-13);
  EXPECT_NEAR(y[2], 0.0, 1e-13);
  EXPECT_NEAR(y[3], g, 1e-13);
  EXPECT_NEAR(y[4], std::cos(th) * ax - std::sin(th) * ay, 1e-13);
  EXPECT_NEAR(y[5], std::sin(th) * ax + std::cos(th) * ay, 1e-13);  // gravity has no y part
  // D: the tangential acceleration r alpha = r tau / Izz reads the torque directly (r / Izz = 2.5)
  const Eigen::MatrixXd J = plant_jacobian_autodiff(*p.f, p.x, p.u);
  const int nx = p.f->nx();
  EXPECT_NEAR(J(nx + 1, nx), r / Izz, 1e-13);
  EXPECT_NEAR(J(nx + 0, nx), 0.0, 1e-13);
  EXPECT_NEAR(J(nx + 3, nx), 0.0, 1e-13);
  EXPECT_NEAR(J(nx + 4, nx), -std::sin(th) * r / Izz, 1e-13);
  // C: d(ax)/dw = -2 w r
  EXPECT_NEAR(J(nx + 0, 1), -2 * w * r, 1e-13);
}

TEST(SensorTypes, ASimulationRecordsTheAccelerationAtEachSample) {
  // the simulator computes the accelerations for an acceleration output at every sample (as for a
  // motion's reaction): the rotor at constant torque reads r tau / Izz on y all along
  const ModelSpec spec = study_parse_model_text(
      sensor_types_rotor(0.0, 1.0, 0.4, R"({"name": "ay", "type": "acceleration", "body": "arm", "point": [0.5, 0, 0], "component": "y", "frame": "arm"})",
                         R"("ay")"),
      "rotor.json");
  ModelSpec s = spec;
  s.solver.t_end = 0.2;
  s.solver.output_step = 0.05;
  s.solver.integrator = "rk4";
  s.solver.max_step = 1e-3;
  const Model m = study_model(s);
  const SimulationResult run = study_simulate(m, study_simulation(m));
  ASSERT_GE(run.y.rows(), 4);
  ASSERT_EQ(run.y.cols(), 1);
  for (Eigen::Index i = 0; i < run.y.rows(); ++i) EXPECT_NEAR(run.y(i, 0), 0.5 * 0.4 / 0.2, 1e-9) << i;
  // a controller measuring it closes an algebraic loop through D: refused, naming it (here by the
  // exact linearization the controller's offsets are taken from, which cannot take the torque's D,
  // before the simulator's own refusal of the loop)
  ModelSpec c = s;
  c.controller.type = ControllerType::Pid;
  c.controller.kp = Eigen::MatrixXd::Constant(1, 1, 0.1);
  c.controller.operating_point = "initial";
  const Model mc = study_model(c);
  try {
    study_simulate(mc, study_simulation(mc));
    ADD_FAILURE() << "no refusal";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("\"ay\""), std::string::npos) << e.what();
  }
}

// a three-body 3-D tree (ball, universal, revolute joints), gravity, two torque inputs; sensors of
// the new types in moving frames
std::string sensor_types_tree(const std::string& outputs) {
  return std::string(R"({"name": "tree3",
    "bodies": [{"name": "a", "mass": 2, "com": [0.1, 0.05, -0.3], "inertia": [0.2, 0.15, 0.1]},
               {"name": "b", "mass": 1.5, "com": [0, 0.1, -0.25], "inertia": [0.1, 0.12, 0.05]},
               {"name": "c", "mass": 0.7, "com": [0.05, 0, -0.2], "inertia": [0.03, 0.04, 0.02]}],
    "joints": [{"name": "ja", "type": "spherical", "parent": "ground", "child": "a",
                "q0": [0.95, 0.2, -0.1, 0.2], "v0": [0.4, -0.7, 1.1]},
               {"name": "jb", "type": "universal", "parent": "a", "child": "b", "axis": [1, 0, 0], "axis2": [0, 1, 0],
                "parent_frame": {"position": [0.1, 0, -0.6]}, "q0": [0.3, -0.4], "v0": [0.9, -0.5]},
               {"name": "jc", "type": "revolute", "parent": "b", "child": "c", "axis": [0, 1, 0],
                "parent_frame": {"position": [0, 0.2, -0.5]}, "q0": [0.8], "v0": [-1.3]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]}],
    "actuators": [{"name": "tb", "type": "joint_force", "joint": "jb", "dof": 1, "u0": 0.7},
                  {"name": "tc", "type": "joint_force", "joint": "jc", "u0": -0.4}],
    "sensors": [{"name": "wc_b", "type": "angular_velocity", "body": "c", "component": "x", "frame": "b"},
                {"name": "wb_g", "type": "angular_velocity", "body": "b", "component": "z"},
                {"name": "wa_c", "type": "angular_velocity", "body": "a", "component": "y", "frame": "c"},
                {"name": "acc_c", "type": "acceleration", "body": "c", "point": [0.1, -0.05, -0.3], "component": "y", "frame": "a"},
                {"name": "sf_c", "type": "acceleration", "body": "c", "point": [0.1, -0.05, -0.3], "component": "z", "frame": "c", "specific_force": true},
                {"name": "acc_b", "type": "acceleration", "body": "b", "point": [0, 0.1, -0.5], "component": "x", "frame": "ground"}],
    "plant": {"inputs": ["tb", "tc"], "outputs": [)") +
         outputs + "]}}";
}

// |a - b| relative to the largest entry of b, and where
double sensor_types_worst(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, Eigen::Index& ir, Eigen::Index& ic) {
  return (a - b).cwiseAbs().maxCoeff(&ir, &ic) / std::max(1.0, b.cwiseAbs().maxCoeff());
}

TEST(SensorTypes, TheirJacobianRowsEqualCentralDifferencesAndAutodiff) {
  const SensorTypesPlant p(sensor_types_tree(R"("wc_b", "wb_g", "wa_c", "acc_c", "sf_c", "acc_b")"));
  const int nx = p.f->nx(), ny = p.f->ny(), nu = p.f->nu();
  ASSERT_EQ(ny, 6);
  const Eigen::MatrixXd Jad = plant_jacobian_autodiff(*p.f, p.x, p.u);
  const Eigen::MatrixXd Jfd = plant_jacobian_fd_full(*p.f, p.x, p.u, true);
  Eigen::Index ir = 0, ic = 0;
  // the output rows, C and D, row by row against their own size
  for (int r = 0; r < ny; ++r) {
    const Eigen::MatrixXd a = Jad.row(nx + r), f = Jfd.row(nx + r);
    const double e = sensor_types_worst(f, a, ir, ic);
    EXPECT_LT(e, 1e-6) << p.model.sensors[static_cast<std::size_t>(r)].name << " column " << ic;
    std::printf("[ SensorTypes ] %-6s |central - autodiff| / max(1, |row|) = %.2e\n",
                p.model.sensors[static_cast<std::size_t>(r)].name.c_str(), e);
  }
  // the accelerations read the torques directly: D is not zero there, and zero for the gyros
  EXPECT_GT(Jad.block(nx + 3, nx, 3, nu).cwiseAbs().maxCoeff(), 0.1);
  EXPECT_EQ(Jad.block(nx, nx, 3, nu).cwiseAbs().maxCoeff(), 0.0);
  // the analytic derivatives (TreeDerivatives, with dy_du read) equal autodiff's C and D
  TreeDerivatives td(p.model);
  td.feedthrough_read = true;
  Eigen::VectorXd u_all = p.model.u_nominal();
  td.compute(p.model.q0, p.model.v0, u_all, p.model.plant_outputs);
  const int n = p.model.nv;
  Eigen::MatrixXd Can(ny, 2 * n), Dan(ny, nu);
  Can << td.dy_dq, td.dy_dv;
  for (int k = 0; k < nu; ++k) Dan.col(k) = td.dy_du.col(p.model.plant_inputs[static_cast<std::size_t>(k)]);
  const double ec = sensor_types_worst(Can, Jad.block(nx, 0, ny, nx), ir, ic);
  EXPECT_LT(ec, 1e-10) << "C at (" << ir << ", " << ic << ")";
  const double ed = sensor_types_worst(Dan, Jad.block(nx, nx, ny, nu), ir, ic);
  EXPECT_LT(ed, 1e-10) << "D at (" << ir << ", " << ic << ")";
  EXPECT_LT((td.y - p.outputs()).cwiseAbs().maxCoeff(), 1e-12);
  std::printf("[ SensorTypes ] analytic against autodiff: C %.2e, D %.2e\n", ec, ed);
}

TEST(SensorTypes, TheExactPathTakesGyrosAndAnAccelerometersFeedthrough) {
  // gyros only: the plant function's analytic Jacobian equals autodiff
  // (at the operating point itself: no position deviation, as linearize takes it)
  SensorTypesPlant gyros(sensor_types_tree(R"("wc_b", "wb_g", "wa_c")"));
  gyros.x.head(gyros.f->nz()).setZero();
  test::expect_analytic_equals_autodiff(*gyros.f, gyros.x, gyros.u, "gyros", 1e-12);
  // accelerometers on a tree driven by torques (Plant/In joint_force): their D column comes from
  // the accelerations' dependence on the inputs (dy_du), not through the coordinates; the exact
  // path equals autodiff there too, D included
  SensorTypesPlant acc(sensor_types_tree(R"("wb_g", "acc_c", "sf_c", "acc_b")"));
  acc.x.head(acc.f->nz()).setZero();
  test::expect_analytic_equals_autodiff(*acc.f, acc.x, acc.u, "accelerometers", 1e-10);
  const int nx = acc.f->nx(), nu = acc.f->nu();
  const Eigen::MatrixXd Jex = plant_jacobian(*acc.f, acc.x, acc.u, JacobianMethod::Exact);
  const Eigen::MatrixXd Jfd = plant_jacobian(*acc.f, acc.x, acc.u, JacobianMethod::CentralDifference);
  const Eigen::MatrixXd Dex = Jex.block(nx, nx, 4, nu), Dfd = Jfd.block(nx, nx, 4, nu);
  EXPECT_GT(Dex.bottomRows(3).cwiseAbs().maxCoeff(), 0.1);  // not zero: the test can fail
  Eigen::Index ir = 0, ic = 0;
  EXPECT_LT(sensor_types_worst(Dex, Dfd, ir, ic), 1e-6) << "D at (" << ir << ", " << ic << ")";
  // and linearize's own exact path (TreeDerivatives directly) gives the same D
  const Linearization lin = linearize(acc.model, study_operating_point(acc.model, "initial"));
  ASSERT_EQ(lin.system.D.rows(), 4);
  EXPECT_LT(sensor_types_worst(lin.system.D, Dfd, ir, ic), 1e-6) << "linearize's D at (" << ir << ", " << ic << ")";
  std::printf("[ SensorTypes ] accelerometers' D: exact vs central %.2e\n", sensor_types_worst(Dex, Dfd, ir, ic));
}

// one wheel of 20 kg on a free joint over the ground road, linear tire, at (Vx, Vy) with longitudinal
// slip kappa (spin (1 + kappa) Vx / R0), its centre at rest height R0 - m g / k
std::string sensor_types_wheel(double Vx, double Vy, double kappa, const std::string& sensors, const std::string& outputs) {
  const double m = 20, g = 9.81, k = 200000, R0 = 0.3;
  const double h = R0 - m * g / k, spin = (1 + kappa) * Vx / R0;
  char text[5000];
  std::snprintf(text, sizeof text, R"({"name": "wheel",
    "bodies": [{"name": "wheel", "mass": %.17g, "inertia": [0.5, 0.9, 0.5]}],
    "joints": [{"name": "J", "type": "free", "parent": "ground", "child": "wheel",
                "q0": [0, 0, %.17g, 1, 0, 0, 0], "v0": [0, %.17g, 0, %.17g, %.17g, 0]}],
    "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
                {"name": "gravel", "type": "body_force", "body": "wheel", "force": [0, 0, 0]},
                {"name": "front_left", "type": "tire", "body": "wheel", "center": [0, 0, 0], "spin_axis": [0, 1, 0],
                 "unloaded_radius": 0.3, "law": "linear", "longitudinal_stiffness": 60000, "cornering_stiffness": 50000,
                 "camber_stiffness": 3000, "trail": 0.02, "vertical_stiffness": %.17g, "vertical_damping": 500}],
    "sensors": [%s],
    "plant": {"inputs": [], "outputs": [%s]}})",
                m, h, spin, Vx, Vy, k, sensors.c_str(), outputs.c_str());
  return text;
}

const char* const sensor_types_tire_sensors = R"(
    {"name": "alpha", "type": "tire", "tire": "front_left", "quantity": "slip_angle"},
    {"name": "kappa", "type": "tire", "tire": "front_left", "quantity": "longitudinal_slip"},
    {"name": "gamma", "type": "tire", "tire": "front_left", "quantity": "camber"},
    {"name": "Fx", "type": "tire", "tire": "front_left", "quantity": "Fx"},
    {"name": "Fy", "type": "tire", "tire": "front_left", "quantity": "Fy"},
    {"name": "Fz", "type": "tire", "tire": "front_left", "quantity": "Fz"},
    {"name": "Mz", "type": "tire", "tire": "front_left", "quantity": "Mz"})";
const char* const sensor_types_tire_outputs = R"("alpha", "kappa", "gamma", "Fx", "Fy", "Fz", "Mz")";

TEST(SensorTypes, ATireAtKnownSlipReadsTheLinearTiresClosedForm) {
  // ISO-W: alpha = atan(Vy / |Vx|), Fy = -C_alpha alpha (a positive slip angle pushes the tire to
  // its right), Fx = C_kappa kappa, Fz = m g at rest height, Mz = -trail Fy, camber 0
  const double Vx = 10, Vy = -0.8, kappa = 0.03;
  const SensorTypesPlant p(sensor_types_wheel(Vx, Vy, kappa, sensor_types_tire_sensors, sensor_types_tire_outputs));
  EXPECT_EQ(p.model.sensors[0].unit, "rad");
  EXPECT_EQ(p.model.sensors[1].unit, "");
  EXPECT_EQ(p.model.sensors[3].unit, "N");
  EXPECT_EQ(p.model.sensors[6].unit, "N m");
  const Eigen::VectorXd y = p.outputs();
  const double alpha = std::atan(Vy / Vx), Fy = -50000 * alpha;
  EXPECT_NEAR(y[0], alpha, 1e-14);
  EXPECT_NEAR(y[1], kappa, 1e-14);
  EXPECT_NEAR(y[2], 0.0, 1e-14);
  EXPECT_NEAR(y[3], 60000 * kappa, 1e-9);
  EXPECT_NEAR(y[4], Fy, 1e-9);
  EXPECT_GT(y[4], 0.0);  // sliding to the right (Vy < 0), pushed back to the left
  EXPECT_NEAR(y[5], 20 * 9.81, 1e-9);
  EXPECT_NEAR(y[6], -0.02 * Fy, 1e-10);
  // off the road: nothing
  ModelSpec up = study_parse_model_text(sensor_types_wheel(Vx, Vy, kappa, sensor_types_tire_sensors, sensor_types_tire_outputs), "w.json");
  up.joints[0].q0[2] = 0.5;
  const Model mu = study_model(up);
  Data d(mu);
  forward_kinematics<double>(mu, d, mu.q0, mu.v0);
  for (const SensorModel& s : mu.sensors) EXPECT_EQ(sensor_value<double>(mu, d, s, mu.q0, mu.v0), 0.0) << s.name;
}

TEST(SensorTypes, TireSensorRowsOfTheExactJacobianEqualCentralDifferencesAndAutodiff) {
  // the wheel turned (yaw, camber) and moving with slip: every quantity depends on the state
  ModelSpec spec = study_parse_model_text(sensor_types_wheel(12, 0.9, -0.04, sensor_types_tire_sensors, sensor_types_tire_outputs), "w.json");
  const Eigen::Quaterniond qr = (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()));
  spec.joints[0].q0.segment<4>(3) << qr.w(), qr.x(), qr.y(), qr.z();
  spec.joints[0].v0[0] = 0.3;
  spec.joints[0].v0[2] = -0.2;
  spec.joints[0].v0[5] = 0.05;
  const Model m = study_model(spec);
  const PlantFunction f(m, m.q0, m.u_nominal(), partition_coordinates(m, m.q0));
  const Eigen::VectorXd x = f.qv_to_state(m.q0, m.v0), u(0);
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);
  for (int k = 0; k < 7; ++k)
    if (k != 2) EXPECT_GT(std::abs(y[k]), 1e-3) << m.sensors[static_cast<std::size_t>(k)].name;
  EXPECT_GT(std::abs(y[2]), 0.01);  // camber
  test::expect_analytic_equals_autodiff(f, x, u, "tire sensors", 1e-10);
  Eigen::MatrixXd Ja;
  ASSERT_TRUE(f.analytic_jacobian(x, u, Ja));
  const Eigen::MatrixXd Jf = plant_jacobian_fd_full(f, x, u, true);
  const int nx = f.nx();
  for (int r = 0; r < f.ny(); ++r) {
    Eigen::Index ir = 0, ic = 0;
    const double e = sensor_types_worst(Eigen::MatrixXd(Jf.row(nx + r)), Eigen::MatrixXd(Ja.row(nx + r)), ir, ic);
    EXPECT_LT(e, 1e-6) << m.sensors[static_cast<std::size_t>(r)].name << " column " << ic;
  }
}

// the model file with one sensor replaced by `sensor`; the ModelError's message
std::string sensor_types_error(const std::string& sensor) {
  const std::string text = sensor_types_wheel(10, 0, 0, sensor, R"("s")");
  try {
    study_model(study_parse_model_text(text, "car.json"), "car.json");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SensorTypes, BadSensorsAreRefusedNamingTheFileAndTheField) {
  struct Bad {
    const char* sensor;
    std::vector<std::string> parts;
  };
  const Bad bad[] = {
      {R"({"name": "s", "type": "angular_velocity", "body": "chassis", "component": "z"})",
       {"car.json", "/sensors/0/body", "unknown body \"chassis\"", "wheel"}},
      {R"({"name": "s", "type": "angular_velocity", "body": "wheel", "component": "z", "frame": "road"})",
       {"car.json", "/sensors/0/frame", "unknown body \"road\""}},
      {R"({"name": "s", "type": "acceleration", "body": "wheel", "component": "w"})", {"car.json", "/sensors/0/component", "\"x\""}},
      {R"({"name": "s", "type": "acceleration", "body": "wheel", "component": 3})", {"car.json", "/sensors/0/component"}},
      {R"({"name": "s", "type": "acceleration", "body": "wheel", "component": "x", "specific_force": "yes"})",
       {"car.json", "/sensors/0/specific_force", "true or false"}},
      {R"({"name": "s", "type": "acceleration", "body": "wheel", "component": "x", "quantity": "Fy"})",
       {"car.json", "/sensors/0", "quantity"}},
      {R"({"name": "s", "type": "tire", "tire": "rear_left", "quantity": "Fy"})",
       {"car.json", "/sensors/0/tire", "unknown tire \"rear_left\"", "front_left"}},
      {R"({"name": "s", "type": "tire", "tire": "gravel", "quantity": "Fy"})",
       {"car.json", "/sensors/0/tire", "\"gravel\" is an effect but not a tire"}},
      {R"({"name": "s", "type": "tire", "tire": "front_left", "quantity": "Fq"})",
       {"car.json", "/sensors/0/quantity", "unknown tire quantity \"Fq\"", "slip_angle", "Mz"}},
      {R"({"name": "s", "type": "tire", "tire": "front_left"})", {"car.json", "/sensors/0", "quantity"}},
      {R"({"name": "s", "type": "tire", "quantity": "Fy"})", {"car.json", "/sensors/0", "tire"}},
  };
  for (const Bad& b : bad) {
    const std::string msg = sensor_types_error(b.sensor);
    for (const std::string& part : b.parts) EXPECT_NE(msg.find(part), std::string::npos) << b.sensor << "\n -> " << msg;
  }
}

TEST(SensorTypes, TheModelFileWritesThemAndReadsThemBackAndRenamesFollow) {
  const ModelSpec spec = study_parse_model_text(
      sensor_types_wheel(10, 0.5, 0.01,
                         std::string(sensor_types_tire_sensors) +
                             R"(, {"name": "yaw", "type": "angular_velocity", "body": "wheel", "component": "z", "frame": "wheel"},
                                {"name": "ay", "type": "acceleration", "body": "wheel", "point": [0, 0.1, 0], "component": "y", "frame": "wheel", "specific_force": true})",
                         R"("alpha", "yaw", "ay")"),
      "w.json");
  const nlohmann::json j = to_json(spec);
  const nlohmann::json& s = j.at("sensors");
  EXPECT_EQ(s.at(4).at("quantity"), "Fy");
  EXPECT_EQ(s.at(4).at("tire"), "front_left");
  EXPECT_FALSE(s.at(4).contains("body"));
  EXPECT_EQ(s.at(7).at("component"), "z");
  EXPECT_FALSE(s.at(7).contains("specific_force"));
  EXPECT_EQ(s.at(8).at("specific_force"), true);
  const ModelSpec back = parse_model_spec(j, "back.json");
  EXPECT_EQ(to_json(back), j);
  ASSERT_EQ(back.sensors.size(), 9u);
  EXPECT_EQ(back.sensors[8].type, SensorType::Acceleration);
  EXPECT_TRUE(back.sensors[8].specific_force);
  EXPECT_EQ(back.sensors[5].quantity, "Fz");
  // renaming the tire effect renames the sensors' references; they are its references
  ModelSpec renamed = back;
  const int tire = find_element(renamed, ElementKind::Effect, "front_left");
  ASSERT_GE(tire, 0);
  const std::vector<std::string> refs = references_to(renamed, ElementKind::Effect, "front_left");
  EXPECT_EQ(refs.size(), 7u);
  rename_element(renamed, ElementKind::Effect, tire, "fl");
  for (int k = 0; k < 7; ++k) EXPECT_EQ(renamed.sensors[static_cast<std::size_t>(k)].tire, "fl");
  EXPECT_NO_THROW(study_model(renamed));
  // and the body's rename reaches the gyro and the accelerometer
  rename_element(renamed, ElementKind::Body, find_element(renamed, ElementKind::Body, "wheel"), "rim");
  EXPECT_EQ(renamed.sensors[7].body, "rim");
  EXPECT_EQ(renamed.sensors[7].frame, "rim");
  EXPECT_EQ(renamed.sensors[8].frame, "rim");
}

}  // namespace
}  // namespace codyna
