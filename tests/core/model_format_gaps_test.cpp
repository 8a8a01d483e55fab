// Model-format elements a user met writing 3-D models from the docs alone:
// the body_torque actuator, the joint_damper effect (one value for every
// coordinate of a joint, a spherical joint among them), bodies whose inertia
// is only positive semi-definite (a slender rod), and body_angle for 3-D
// rotations. Each is checked against something independent: a couple of two
// body forces, closed forms, Eigen's own axis-angle decomposition.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "core/test_util.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "model/errors.hpp"

namespace codyna {
namespace {

std::string fmt17(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

Model from_text(const std::string& text) { return compile(parse_model_spec_text(text, "gaps.json"), "gaps.json"); }

template <class F>
std::string model_error(F&& f, std::string* path = nullptr) {
  try {
    f();
  } catch (const ModelError& e) {
    if (path) *path = e.path();
    return e.what();
  }
  return "(no error)";
}

// A body on a spherical joint at the origin, with its centre of mass off the
// joint, a full inertia, gravity, and the actuators and effects given.
const std::string kInertia = "[[0.4, 0.05, -0.02], [0.05, 0.3, 0.03], [-0.02, 0.03, 0.5]]";
const std::string kCom = "[0.1, -0.4, 0.05]";

std::string ball_body(const std::string& actuators, const std::string& effects = "[]",
                      const std::string& inertia = "[[0.4, 0.05, -0.02], [0.05, 0.3, 0.03], [-0.02, 0.03, 0.5]]",
                      const std::string& com = "[0.1, -0.4, 0.05]", const std::string& plant = "") {
  return R"({"codyna_model": 1, "name": "ball",
    "bodies": [{"name": "box", "mass": 2.0, "com": )" + com + R"(, "inertia": )" + inertia + R"(}],
    "joints": [{"name": "ball", "type": "spherical", "parent": "ground", "child": "box"}],
    "effects": )" + effects + R"(,
    "actuators": )" + actuators + R"(,
    "sensors": [{"name": "tilt_x", "type": "body_angle", "body": "box", "axis": [1, 0, 0]},
                {"name": "tilt_y", "type": "body_angle", "body": "box", "axis": [0, 1, 0]},
                {"name": "tilt_z", "type": "body_angle", "body": "box", "axis": [0, 0, 1]}])" +
         (plant.empty() ? "" : R"(, "plant": )" + plant) + "}";
}

Eigen::VectorXd accel(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u) {
  Data d(m);
  return forward_dynamics<double>(m, d, q, v, u);
}

// --- body_torque ---------------------------------------------------------

// A torque T (body axes) equals the couple of F at r and -F at -r with T = 2 r x F:
// the same accelerations at any state, and the same linearization.
TEST(BodyTorque, EqualsACoupleOfBodyForcesInBodyAxes) {
  const Eigen::Vector3d r(0.3, -0.1, 0.2), e = Eigen::Vector3d(0.2, 0.9, -0.4).normalized();
  const Eigen::Vector3d T = 2.0 * r.cross(e);
  auto v3 = [](const Eigen::Vector3d& x) {
    return "[" + fmt17(x[0]) + ", " + fmt17(x[1]) + ", " + fmt17(x[2]) + "]";
  };
  const std::string gravity = R"([{"name": "g", "type": "gravity", "g": [0, -9.81, 0]}])";
  const Model mt = from_text(ball_body(R"([{"name": "twist", "type": "body_torque", "body": "box", "frame": "body",
      "direction": )" + v3(T.normalized()) + R"(, "gain": )" + fmt17(T.norm()) + "}]", gravity, kInertia, kCom,
      R"({"inputs": ["twist"], "outputs": ["tilt_x", "tilt_y"]})"));
  const Model mf = from_text(ball_body(R"([{"name": "plus", "type": "body_force", "body": "box", "frame": "body",
      "point": )" + v3(r) + R"(, "direction": )" + v3(e) + R"(},
      {"name": "minus", "type": "body_force", "body": "box", "frame": "body", "point": )" + v3(-r) +
                                       R"(, "direction": )" + v3(-e) + "}]",
                                       gravity, kInertia, kCom, R"({"inputs": ["plus", "minus"], "outputs": ["tilt_x", "tilt_y"]})"));
  ASSERT_EQ(mt.actuators[0].unit, "N m");
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd q = test::random_q(mt, rng), v = test::random_v(mt, rng, 2.0);
    const double u = 1.7 - trial;
    const Eigen::VectorXd a_t = accel(mt, q, v, Eigen::VectorXd::Constant(1, u));
    const Eigen::VectorXd a_f = accel(mf, q, v, Eigen::VectorXd::Constant(2, u));
    EXPECT_LT((a_t - a_f).cwiseAbs().maxCoeff(), 1e-12 * (1 + a_f.norm())) << "trial " << trial;
  }
  // linearized about a tilted, spinning state with the input on
  OperatingPoint pt = initial_point(mt), pf = initial_point(mf);
  std::mt19937 rng2(11);
  pt.q = pf.q = test::random_q(mt, rng2);
  pt.v = pf.v = test::random_v(mt, rng2, 1.0);
  pt.u = Eigen::VectorXd::Constant(1, 0.6);
  pf.u = Eigen::VectorXd::Constant(2, 0.6);
  const LinearSystem lt = linearize(mt, pt).system;
  const LinearSystem lf = linearize(mf, pf).system;
  EXPECT_TRUE(test::MatrixNear(lt.A, lf.A, 1e-11));
  EXPECT_TRUE(test::MatrixNear(lt.B.col(0), lf.B.col(0) + lf.B.col(1), 1e-12));
  EXPECT_TRUE(test::MatrixNear(lt.C, lf.C, 1e-14));
}

// In world axes the torque keeps its world direction as the body turns: at any
// pose it equals the body-axes actuator whose direction is R^T d there.
TEST(BodyTorque, WorldAxesKeepTheirDirection) {
  const Eigen::Vector3d dw = Eigen::Vector3d(0.5, -0.2, 0.8).normalized();
  const Model mw = from_text(ball_body(R"([{"name": "t", "type": "body_torque", "body": "box", "frame": "world",
      "direction": [0.5, -0.2, 0.8], "gain": 3.0}])"));
  std::mt19937 rng(3);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = test::random_q(mw, rng), v = test::random_v(mw, rng, 1.5);
    Data d(mw);
    forward_kinematics<double>(mw, d, q);
    const Eigen::Vector3d db = d.oMi[1].R.transpose() * dw;
    const Model mb = from_text(ball_body(R"([{"name": "t", "type": "body_torque", "body": "box", "frame": "body",
        "direction": [)" + fmt17(db[0]) + ", " + fmt17(db[1]) + ", " + fmt17(db[2]) +
                                         R"(], "gain": 3.0}])"));
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, -0.9);
    EXPECT_LT((accel(mw, q, v, u) - accel(mb, q, v, u)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(BodyTorque, DrivesAHingeLikeAJointTorque) {
  // torque about the hinge axis: B = gain / (moment of inertia about the pivot)
  const Model m = from_text(R"({"codyna_model": 1, "name": "wheel",
    "bodies": [{"name": "arm", "mass": 1.5, "com": [0.4, 0, 0], "inertia": [0.01, 0.02, 0.03]}],
    "joints": [{"name": "pivot", "type": "revolute", "parent": "ground", "child": "arm", "axis": [0, 0, 1]}],
    "actuators": [{"name": "t", "type": "body_torque", "body": "arm", "direction": [0, 0, 1], "gain": 2.5}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "pivot"}],
    "plant": {"inputs": ["t"], "outputs": ["angle"]}})");
  const LinearSystem s = linearize(m, initial_point(m)).system;
  EXPECT_NEAR(s.B(1, 0), 2.5 / (0.03 + 1.5 * 0.4 * 0.4), 1e-14);
}

TEST(BodyTorque, FieldsAreCheckedAndRoundTrip) {
  std::string path;
  // a couple has no point of application
  const std::string msg = model_error(
      [] {
        from_text(ball_body(R"([{"name": "t", "type": "body_torque", "body": "box", "point": [1, 0, 0]}])"));
      },
      &path);
  EXPECT_EQ(path, "/actuators/0/point") << msg;
  EXPECT_NE(model_error([] { from_text(ball_body(R"([{"name": "t", "type": "body_torque", "body": "ground"}])")); },
                        &path)
                .find("ground"),
            std::string::npos);
  EXPECT_EQ(path, "/actuators/0/body");
  model_error([] { from_text(ball_body(R"([{"name": "t", "type": "body_torque", "body": "box", "direction": [0, 0, 0]}])")); },
              &path);
  EXPECT_EQ(path, "/actuators/0/direction");
  const ModelSpec s = parse_model_spec_text(
      ball_body(R"([{"name": "t", "type": "body_torque", "body": "box", "frame": "body", "direction": [0, 1, 0],
                    "gain": 2, "min": -1, "max": 1}])"),
      "gaps.json");
  const ModelSpec back = parse_model_spec(to_json(s), "again.json");
  EXPECT_EQ(to_json(back), to_json(s));
  EXPECT_EQ(back.actuators[0].type, ActuatorType::BodyTorque);
  EXPECT_FALSE(back.actuators[0].in_world);
}

// --- joint_damper ----------------------------------------------------------

// A spherical joint at the centre of mass, no gravity: the damper's torque is
// -c omega, so about rest A's velocity block is -c I^-1, and with an isotropic
// inertia (no gyroscopic torque) omega' = -(c / I) omega at any state.
TEST(JointDamper, OneValueDampsEveryAxisOfASphericalJoint) {
  const double c = 0.35;
  const std::string damper = R"([{"name": "bearing", "type": "joint_damper", "joint": "ball", "damping": 0.35}])";
  const Eigen::Matrix3d I = (Eigen::Matrix3d() << 0.4, 0.05, -0.02, 0.05, 0.3, 0.03, -0.02, 0.03, 0.5).finished();
  const Model m = from_text(ball_body("[]", damper, kInertia, "[0, 0, 0]", R"({"inputs": [], "outputs": ["tilt_x"]})"));
  ASSERT_EQ(m.joint_frictions.size(), 3u);
  const LinearSystem s = linearize(m, initial_point(m)).system;
  ASSERT_EQ(s.A.rows(), 6);
  EXPECT_TRUE(test::MatrixNear(s.A.bottomRightCorner(3, 3), -c * I.inverse(), 1e-13));

  const Model iso = from_text(ball_body("[]", damper, "[0.2, 0.2, 0.2]", "[0, 0, 0]"));
  std::mt19937 rng(5);
  const Eigen::VectorXd q = test::random_q(iso, rng), v = test::random_v(iso, rng, 3.0);
  EXPECT_LT((accel(iso, q, v, Eigen::VectorXd()) + (c / 0.2) * v).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(JointDamper, ActsOnEveryCoordinateOfAFreeJointLikeMuJoCosDamping) {
  // a free body without gravity: each velocity coordinate decays as -c / (its inertia)
  const Model m = from_text(R"({"codyna_model": 1, "name": "floating",
    "bodies": [{"name": "box", "mass": 2.0, "inertia": [0.1, 0.1, 0.1]}],
    "joints": [{"name": "float", "type": "free", "parent": "ground", "child": "box"}],
    "effects": [{"name": "drag", "type": "joint_damper", "joint": "float", "damping": 0.5}],
    "sensors": [{"name": "x", "type": "point_position", "body": "box"}],
    "plant": {"inputs": [], "outputs": ["x"]}})");
  ASSERT_EQ(m.nv, 6);
  const LinearSystem s = linearize(m, initial_point(m)).system;
  for (int k = 0; k < 6; ++k) {
    const bool angular = m.v_units[k] == "rad";
    EXPECT_NEAR(s.A(6 + k, 6 + k), -0.5 / (angular ? 0.1 : 2.0), 1e-13) << m.v_names[k];
  }
}

TEST(JointDamper, BadFieldsAreNamed) {
  std::string path;
  std::string msg = model_error(
      [] {
        from_text(ball_body("[]", R"([{"name": "d", "type": "joint_damper", "joint": "ball", "dof": 1, "damping": 1}])"));
      },
      &path);
  EXPECT_EQ(path, "/effects/0/dof") << msg;
  msg = model_error(
      [] { from_text(ball_body("[]", R"([{"name": "d", "type": "joint_damper", "joint": "ball", "damping": -1}])")); },
      &path);
  EXPECT_EQ(path, "/effects/0/damping") << msg;
  msg = model_error(
      [] { from_text(ball_body("[]", R"([{"name": "d", "type": "joint_damper", "joint": "hinge", "damping": 1}])")); },
      &path);
  EXPECT_EQ(path, "/effects/0/joint") << msg;
  msg = model_error(
      [] {
        from_text(R"({"codyna_model": 1, "name": "welded",
          "bodies": [{"name": "a", "mass": 1, "inertia": [1, 1, 1]}, {"name": "b", "mass": 1, "inertia": [1, 1, 1]}],
          "joints": [{"name": "hinge", "type": "revolute", "parent": "ground", "child": "a"},
                     {"name": "weld", "type": "fixed", "parent": "a", "child": "b"}],
          "effects": [{"name": "d", "type": "joint_damper", "joint": "weld", "damping": 1}]})");
      },
      &path);
  EXPECT_EQ(path, "/effects/0/joint") << msg;
  EXPECT_NE(msg.find("fixed"), std::string::npos) << msg;
}

// --- positive semi-definite inertia ---------------------------------------

std::string rod_on(const std::string& joint_type, const std::string& axis, const std::string& inertia) {
  return R"({"codyna_model": 1, "name": "rod",
    "bodies": [{"name": "rod", "mass": 10.0, "com": [1, 0, 0], "inertia": )" + inertia + R"(}],
    "joints": [{"name": "pivot", "type": ")" + joint_type + R"(", "parent": "ground", "child": "rod")" +
         (joint_type == "spherical" ? std::string() : R"(, "axis": )" + axis) + R"(}],
    "effects": [{"name": "g", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "u", "type": "joint_force", "joint": "pivot"}],
    "sensors": [{"name": "w", "type": "joint_velocity", "joint": "pivot"}],
    "plant": {"inputs": ["u"], "outputs": ["w"]}})";
}

TEST(SemiDefiniteInertia, ASlenderRodIsAcceptedWhereTheMassMatrixStaysDefinite) {
  // the paper's pendulum with an exactly zero axial moment: m = 10, l = 2,
  // I_pivot = m l^2 / 3; upright (theta = 90 deg): A(2,1) = 3 g / (2 l), B(2) = 3 / (m l^2)
  const double Ic = 10.0 * 4.0 / 12.0;
  const Model m = from_text(rod_on("revolute", "[0, 0, 1]", "[0, " + fmt17(Ic) + ", " + fmt17(Ic) + "]"));
  OperatingPoint op = initial_point(m);
  op.q[0] = M_PI / 2;
  const LinearSystem s = linearize(m, op).system;
  EXPECT_NEAR(s.A(1, 0), 3.0 * 9.81 / 4.0, 1e-12);
  EXPECT_NEAR(s.B(1, 0), 3.0 / 40.0, 1e-15);
}

TEST(SemiDefiniteInertia, TurningTheRodAboutItsOwnAxisIsRefusedWithTheReason) {
  for (const char* joint : {"revolute", "spherical"}) {
    std::string path;
    const std::string msg =
        model_error([&] { from_text(rod_on(joint, "[1, 0, 0]", "[0, 3.3333333333333335, 3.3333333333333335]")); }, &path);
    EXPECT_EQ(path, "/bodies") << joint << ": " << msg;
    EXPECT_NE(msg.find("mass matrix is singular"), std::string::npos) << msg;
    EXPECT_NE(msg.find("body \"rod\" has no inertia about one of its axes"), std::string::npos) << msg;
  }
  std::string path;
  const std::string msg = model_error([] { from_text(rod_on("revolute", "[0, 0, 1]", "[-0.1, 3, 3]")); }, &path);
  EXPECT_EQ(path, "/bodies/0/inertia") << msg;
  EXPECT_NE(msg.find("positive semi-definite"), std::string::npos) << msg;
}

// --- body_angle in 3-D ------------------------------------------------------

double sensor(const Model& m, const Eigen::VectorXd& q, const std::string& name) {
  Data d(m);
  forward_kinematics<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  return sensor_value<double>(m, d, m.sensors[m.find_sensor(name)], q, Eigen::VectorXd::Zero(m.nv));
}

TEST(BodyAngle3D, IsTheAxisComponentOfTheRotationVector) {
  const Model m = from_text(ball_body("[]"));
  // 8 deg about (1, 0, 1): the two tilt components alike, theta / sqrt(2) each (the issue's case)
  const double th = 8.0 * M_PI / 180.0;
  const Eigen::Vector3d n = Eigen::Vector3d(1, 0, 1).normalized();
  const Eigen::VectorXd q = integrate<double>(m, m.q0, Eigen::VectorXd(th * n));
  EXPECT_NEAR(sensor(m, q, "tilt_x"), th / std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(sensor(m, q, "tilt_z"), th / std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(sensor(m, q, "tilt_y"), 0.0, 1e-16);
  // against Eigen's axis-angle of the body's rotation, for random rotations up to pi
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> angle(0.0, M_PI);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d axis = test::random_vec(rng).normalized();
    const double a = trial < 20 ? M_PI - 1e-3 * trial : angle(rng);  // the first ones near pi
    const Eigen::VectorXd qr = integrate<double>(m, m.q0, Eigen::VectorXd(a * axis));
    Data d(m);
    forward_kinematics<double>(m, d, qr);
    const Eigen::AngleAxisd aa(d.oMi[1].R);
    const Eigen::Vector3d phi = aa.angle() * aa.axis();
    EXPECT_NEAR(sensor(m, qr, "tilt_x"), phi[0], 1e-12) << "trial " << trial << " angle " << a;
    EXPECT_NEAR(sensor(m, qr, "tilt_y"), phi[1], 1e-12) << "trial " << trial;
    EXPECT_NEAR(sensor(m, qr, "tilt_z"), phi[2], 1e-12) << "trial " << trial;
  }
}

TEST(BodyAngle3D, AboutItsOwnAxisItIsTheSignedAngle) {
  // rotations about z itself: the signed angle in (-pi, pi), the planar definition unchanged
  const Model m = from_text(ball_body("[]"));
  for (double deg : {-179.0, -170.0, -120.0, -30.0, 0.0, 1e-6, 45.0, 119.0, 121.0, 170.0, 179.9}) {
    const double a = deg * M_PI / 180.0;
    const Eigen::VectorXd q = integrate<double>(m, m.q0, Eigen::VectorXd(Eigen::Vector3d(0, 0, a)));
    EXPECT_NEAR(sensor(m, q, "tilt_z"), a, 1e-13) << deg << " deg";
    EXPECT_NEAR(sensor(m, q, "tilt_x"), 0.0, 1e-13) << deg << " deg";
  }
}

TEST(BodyAngle3D, ItsLinearizationIsTheSmallRotationAboutTheAxis) {
  // about the reference pose, C maps the ball joint's rotation coordinates to
  // the axis components: the rows for x, y, z form the identity
  const Model m =
      from_text(ball_body("[]", "[]", kInertia, kCom, R"({"inputs": [], "outputs": ["tilt_x", "tilt_y", "tilt_z"]})"));
  const LinearSystem s = linearize(m, initial_point(m)).system;
  EXPECT_TRUE(test::MatrixNear(s.C.leftCols(3), Eigen::Matrix3d::Identity(), 1e-14));
  EXPECT_TRUE(test::MatrixNear(s.C.rightCols(3), Eigen::Matrix3d::Zero(), 1e-14));
}

}  // namespace
}  // namespace codyna
