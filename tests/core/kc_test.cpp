// The K&C rig (study/kc_job, codyna kc): camber, toe and kingpin over travel and steer on the
// sedan's double-wishbone corner against an independent solve of the same point geometry written
// here (arms turning about their pivot axes, the upright rigid between its two balls and the tie
// rod's end, the tie rod's length fixed); compliance of a wheel held by one bushing against the
// static solution of that spring written here; bad requests refused naming the option.
#include "study/kc_job.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "model/errors.hpp"
#include "study/files.hpp"

namespace codyna {
namespace {

constexpr double kc_test_deg = 180.0 / 3.14159265358979323846;

// ---- the double wishbone as points (examples/kc_double_wishbone.json's numbers, chassis frame) ----
struct KcTestCorner {
  Eigen::Vector3d lower_pivot{1.2, 0.35, -0.30}, lower_ball{1.2, 0.70, -0.30};
  Eigen::Vector3d upper_pivot{1.2, 0.40, 0.06}, upper_ball{1.2, 0.66, 0.05};
  Eigen::Vector3d rod_in{1.08, 0.35, -0.15}, rod_out{1.08, 0.70, -0.15};
  Eigen::Vector3d wheel{1.2, 0.775, std::round((0.393581 - 4100 / 322913.0 - 0.55) * 1e9) / 1e9};
  Eigen::Vector3d axis{0, 1, 0};
};

Eigen::Vector3d kc_test_swing(const Eigen::Vector3d& pivot, const Eigen::Vector3d& p0, double angle) {
  return pivot + Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()) * (p0 - pivot);
}

// the upright's frame from its two balls and the tie rod's end
Eigen::Matrix3d kc_test_frame(const Eigen::Vector3d& lb, const Eigen::Vector3d& ub, const Eigen::Vector3d& t) {
  const Eigen::Vector3d e1 = (ub - lb).normalized();
  const Eigen::Vector3d e2 = ((t - lb) - (t - lb).dot(e1) * e1).normalized();
  Eigen::Matrix3d E;
  E << e1, e2, e1.cross(e2);
  return E;
}

struct KcTestPose {
  Eigen::Vector3d lb, ub, t, wheel, axis;
};

// x = (lower angle, upper angle, tie rod end); rack: the rack's slide (m, left)
KcTestPose kc_test_pose(const KcTestCorner& c, const Eigen::VectorXd& x) {
  KcTestPose p;
  p.lb = kc_test_swing(c.lower_pivot, c.lower_ball, x(0));
  p.ub = kc_test_swing(c.upper_pivot, c.upper_ball, x(1));
  p.t = x.tail<3>();
  const Eigen::Matrix3d E0 = kc_test_frame(c.lower_ball, c.upper_ball, c.rod_out);
  const Eigen::Matrix3d E = kc_test_frame(p.lb, p.ub, p.t);
  p.wheel = p.lb + E * (E0.transpose() * (c.wheel - c.lower_ball));
  p.axis = E * (E0.transpose() * c.axis);
  return p;
}

Eigen::VectorXd kc_test_equations(const KcTestCorner& c, const Eigen::VectorXd& x, double travel, double rack) {
  const KcTestPose p = kc_test_pose(c, x);
  const Eigen::Vector3d rod_in = c.rod_in + Eigen::Vector3d(0, rack, 0);
  Eigen::VectorXd f(5);
  f << (p.ub - p.lb).norm() - (c.upper_ball - c.lower_ball).norm(), (p.t - p.lb).norm() - (c.rod_out - c.lower_ball).norm(),
      (p.t - p.ub).norm() - (c.rod_out - c.upper_ball).norm(), (p.t - rod_in).norm() - (c.rod_out - c.rod_in).norm(),
      p.wheel.z() - c.wheel.z() - travel;
  return f;
}

// Newton with a central-difference Jacobian, from x
Eigen::VectorXd kc_test_solve(const KcTestCorner& c, Eigen::VectorXd x, double travel, double rack) {
  for (int it = 0; it < 50; ++it) {
    const Eigen::VectorXd f = kc_test_equations(c, x, travel, rack);
    if (f.lpNorm<Eigen::Infinity>() < 1e-15) break;
    Eigen::MatrixXd J(5, 5);
    for (int j = 0; j < 5; ++j) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(5);
      e(j) = 1e-7;
      J.col(j) = (kc_test_equations(c, x + e, travel, rack) - kc_test_equations(c, x - e, travel, rack)) / 2e-7;
    }
    x -= J.partialPivLu().solve(f);
  }
  EXPECT_LT(kc_test_equations(c, x, travel, rack).lpNorm<Eigen::Infinity>(), 1e-14);
  return x;
}

Eigen::VectorXd kc_test_design(const KcTestCorner& c) {
  Eigen::VectorXd x(5);
  x << 0, 0, c.rod_out;
  return x;
}

// camber (top outward positive) and toe (toe-in positive) of the left wheel, degrees
double kc_test_camber(const Eigen::Vector3d& a) { return std::asin(-a.z()) * kc_test_deg; }
double kc_test_toe(const Eigen::Vector3d& a) { return std::atan2(a.x(), a.y()) * kc_test_deg; }
double kc_test_kingpin(const KcTestPose& p) {
  const Eigen::Vector3d k = p.ub - p.lb;
  return std::atan2(-k.y(), k.z()) * kc_test_deg;
}

TEST(KcJob, CamberAndToeOverTravelEqualAnIndependentSolveOfTheLinkage) {
  const KcTestCorner corner;
  KcRequest r;
  r.model = CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json";
  r.travel = KcRange{-0.08, 0.08, 9};
  const KcReport rep = study_kc_job(r);
  ASSERT_EQ(rep.wheels.size(), 1u);
  EXPECT_EQ(rep.wheels[0].name, "wheel");
  EXPECT_EQ(rep.held, "chassis");
  EXPECT_EQ(rep.steer, "rack");
  EXPECT_NEAR(rep.wheels[0].radius, 0.393581, 1e-15);
  ASSERT_EQ(rep.points.size(), 9u);
  // the design point: caster 0, kingpin atan(0.04 / 0.35), camber and toe 0 (the axle along y)
  EXPECT_NEAR(rep.wheels[0].design.caster, 0.0, 1e-10);
  EXPECT_NEAR(rep.wheels[0].design.kingpin, std::atan(0.04 / 0.35) * kc_test_deg, 1e-10);
  EXPECT_NEAR(rep.wheels[0].design.camber, 0.0, 1e-10);
  EXPECT_NEAR(rep.wheels[0].design.toe, 0.0, 1e-10);
  // the balls' line meets the contact's height zc at y = 0.70 + 0.04 (-0.30 - zc) / 0.35 (0.730 m): 45 mm of scrub
  const double zc = rep.wheels[0].design.contact.z();
  EXPECT_NEAR(rep.wheels[0].design.scrub_radius, 0.775 - (0.70 + 0.04 * (-0.30 - zc) / 0.35), 1e-12);
  EXPECT_NEAR(rep.wheels[0].design.caster_trail, 0.0, 1e-12);
  Eigen::VectorXd x = kc_test_design(corner);
  double camber_span = 0, toe_span = 0;
  // from the design point up, then down: each from its neighbour
  for (int dir : {1, -1}) {
    x = kc_test_design(corner);
    for (int k = 4; k >= 0 && k <= 8; k += dir) {
      const KcPoint& p = rep.points[static_cast<std::size_t>(k)];
      EXPECT_EQ(p.sweep, "travel");
      EXPECT_NEAR(p.travel, -0.08 + 0.02 * k, 1e-15);
      x = kc_test_solve(corner, x, p.travel, 0.0);
      const KcTestPose pose = kc_test_pose(corner, x);
      EXPECT_NEAR(p.camber, kc_test_camber(pose.axis), 1e-9) << "travel " << p.travel;
      EXPECT_NEAR(p.toe, kc_test_toe(pose.axis), 1e-9) << "travel " << p.travel;
      EXPECT_NEAR(p.kingpin, kc_test_kingpin(pose), 1e-9) << "travel " << p.travel;
      EXPECT_NEAR((p.wheel_centre - pose.wheel).lpNorm<Eigen::Infinity>(), 0.0, 1e-11) << "travel " << p.travel;
      {
        // the kingpin (the balls' line) at the contact's height: scrub radius and caster trail
        const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
        const Eigen::Vector3d contact = pose.wheel - 0.393581 * (ez - ez.dot(pose.axis) * pose.axis).normalized();
        const Eigen::Vector3d k = pose.ub - pose.lb;
        const Eigen::Vector3d ground = pose.lb + k * ((contact.z() - pose.lb.z()) / k.z());
        EXPECT_NEAR(p.scrub_radius, contact.y() - ground.y(), 1e-11) << "travel " << p.travel;
        EXPECT_NEAR(p.caster_trail, ground.x() - contact.x(), 1e-11) << "travel " << p.travel;
      }
      camber_span = std::max(camber_span, std::abs(p.camber));
      toe_span = std::max(toe_span, std::abs(p.toe));
    }
  }
  // the comparison is not between zeros: the corner cambers and steers over 8 cm of travel
  EXPECT_GT(camber_span, 0.5);
  EXPECT_GT(toe_span, 0.05);
  // bump steer and camber at design: the table's central difference about design
  const KcPoint& up = rep.points[5];
  const KcPoint& down = rep.points[3];
  EXPECT_NEAR(rep.wheels[0].gradients.bump_steer, (up.toe - down.toe) / 0.04, 0.02 * std::abs(rep.wheels[0].gradients.bump_steer) + 1e-6);
  EXPECT_NEAR(rep.wheels[0].gradients.bump_camber, (up.camber - down.camber) / 0.04, 0.02 * std::abs(rep.wheels[0].gradients.bump_camber));
  // the gradients against the independent solve's central differences (h = 1e-4 m: truncation ~1e-8)
  {
    const double h = 1e-4, R = 0.393581;
    const KcTestPose up_pose = kc_test_pose(corner, kc_test_solve(corner, kc_test_design(corner), h, 0.0));
    const KcTestPose down_pose = kc_test_pose(corner, kc_test_solve(corner, kc_test_design(corner), -h, 0.0));
    const auto contact = [R](const KcTestPose& p) {
      const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
      return Eigen::Vector3d(p.wheel - R * (ez - ez.dot(p.axis) * p.axis).normalized());
    };
    const double steer = (kc_test_toe(up_pose.axis) - kc_test_toe(down_pose.axis)) / (2 * h);
    const double camber = (kc_test_camber(up_pose.axis) - kc_test_camber(down_pose.axis)) / (2 * h);
    const Eigen::Vector3d dcontact = (contact(up_pose) - contact(down_pose)) / (2 * h);
    const KcGradients& g = rep.wheels[0].gradients;
    EXPECT_NEAR(g.bump_steer, steer, 1e-6 * std::abs(steer));
    EXPECT_NEAR(g.bump_camber, camber, 1e-6 * std::abs(camber));
    EXPECT_NEAR(g.track_per_travel, 2 * dcontact.y() / dcontact.z(), 1e-6);
    EXPECT_NEAR(g.roll_centre_height, corner.wheel.y() * dcontact.y() / dcontact.z(), 1e-7);
    EXPECT_NEAR(g.roll_steer, -corner.wheel.y() * steer / kc_test_deg, 1e-6 * std::abs(g.roll_steer));
  }
  // a rigid linkage does not comply
  EXPECT_NEAR(rep.wheels[0].gradients.fy_steer, 0.0, 1e-9);
  EXPECT_NEAR(rep.wheels[0].gradients.fy_camber, 0.0, 1e-9);
}

TEST(KcJob, SteerSweepEqualsTheIndependentSolve) {
  const KcTestCorner corner;
  KcRequest r;
  r.model = CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json";
  r.steer_range = KcRange{-0.02, 0.02, 5};
  const KcReport rep = study_kc_job(r);
  ASSERT_EQ(rep.points.size(), 5u);
  for (int dir : {1, -1}) {
    Eigen::VectorXd x = kc_test_design(corner);
    for (int k = 2; k >= 0 && k <= 4; k += dir) {
      const KcPoint& p = rep.points[static_cast<std::size_t>(k)];
      EXPECT_EQ(p.sweep, "steer");
      x = kc_test_solve(corner, x, 0.0, p.steer);
      const KcTestPose pose = kc_test_pose(corner, x);
      EXPECT_NEAR(p.toe, kc_test_toe(pose.axis), 1e-9) << "rack " << p.steer;
      EXPECT_NEAR(p.camber, kc_test_camber(pose.axis), 1e-9) << "rack " << p.steer;
      EXPECT_NEAR(p.wheel_centre.z(), corner.wheel.z(), 1e-12);
    }
  }
  // the rack to the left pushes the tie rod's end (behind the kingpin) outward: the left wheel's
  // front turns inward (toe-in), by several degrees for 2 cm
  EXPECT_GT(rep.points[4].toe, 5.0);
}

// ---- a wheel held by one bushing: the static solution of that spring, written here ----
const char* kc_test_bushing_model = R"({"codyna_model": 1, "name": "bushed_wheel",
 "bodies": [{"name": "chassis", "mass": 100, "inertia": [1, 1, 1]},
            {"name": "knuckle", "mass": 5, "inertia": [0.1, 0.1, 0.1]},
            {"name": "wheel", "mass": 10, "inertia": [0.4, 0.7, 0.4]}],
 "joints": [{"name": "weld", "type": "fixed", "parent": "ground", "child": "chassis"},
            {"name": "knuckle", "type": "free", "parent": "chassis", "child": "knuckle", "parent_frame": {"position": [0.1, 0.75, 0.2]}},
            {"name": "spin", "type": "revolute", "parent": "knuckle", "child": "wheel", "axis": [0, 1, 0]}],
 "effects": [{"name": "mount", "type": "bushing", "body_a": "chassis", "frame_a": {"position": [0.1, 0.75, 0.2]},
              "body_b": "knuckle", "translational_stiffness": [4e5, 2.5e5, 1e6], "rotational_stiffness": [3e4, 5e4, 8e3]},
             {"name": "tire", "type": "tire", "body": "wheel", "law": "linear", "unloaded_radius": 0.3, "vertical_stiffness": 2e5}]})";

Eigen::Matrix3d kc_test_rotation(const Eigen::Vector3d& theta) {
  const double n = theta.norm();
  if (n == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(n, theta / n).toRotationMatrix();
}

TEST(KcJob, LateralForceComplianceEqualsTheBushingsStaticSolution) {
  const ModelSpec spec = study_parse_model_text(kc_test_bushing_model, "bushed_wheel.json");
  KcRequest r;
  r.model = "bushed_wheel.json";
  r.spec = &spec;
  r.fy = KcRange{-3000, 3000, 5};
  r.mz = KcRange{-200, 200, 3};
  const KcReport rep = study_kc_job(r);
  ASSERT_EQ(rep.points.size(), 8u);
  const double R = 0.3, ky = 2.5e5;
  const Eigen::Vector3d kr(3e4, 5e4, 8e3);
  const Eigen::Vector3d centre(0.1, 0.75, 0.2);
  for (const KcPoint& p : rep.points) {
    // the wheel and knuckle (spin held) turn by theta and move by d: -Kr theta + (contact - centre) x F + M = 0,
    // -K d + F + lambda z = 0 with d_z = 0 (the travel held); the contact under the centre in the wheel plane
    const Eigen::Vector3d F(0, p.fy, 0), M(0, 0, p.mz);
    Eigen::Vector3d theta = Eigen::Vector3d::Zero();
    Eigen::Vector3d arm = Eigen::Vector3d::Zero();
    for (int it = 0; it < 200; ++it) {
      const Eigen::Vector3d a = kc_test_rotation(theta) * Eigen::Vector3d::UnitY();
      const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
      arm = -R * (ez - ez.dot(a) * a).normalized();
      theta = (arm.cross(F) + M).cwiseQuotient(kr);
    }
    const Eigen::Vector3d a = kc_test_rotation(theta) * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d d(0, p.fy / ky, 0);
    const Eigen::Vector3d contact = centre + d + arm;
    EXPECT_NEAR(p.camber, kc_test_camber(a), 1e-9) << p.sweep << " " << p.fy << " " << p.mz;
    EXPECT_NEAR(p.toe, kc_test_toe(a), 1e-9) << p.sweep << " " << p.fy << " " << p.mz;
    EXPECT_NEAR((p.contact - contact).lpNorm<Eigen::Infinity>(), 0.0, 1e-11) << p.sweep << " " << p.fy;
    EXPECT_NEAR(p.track_change, 2 * (contact.y() - centre.y()), 1e-11) << p.sweep << " " << p.fy;
  }
  // not zeros: 3 kN cambers the wheel by R F / krx
  EXPECT_NEAR(rep.points[4].camber, -R * 3000 / kr.x() * kc_test_deg, 1e-3);
  EXPECT_GT(std::abs(rep.points[4].camber), 1.0);
  // the gradients at design: the spring's compliance K^-1, per kN (per kN m)
  EXPECT_NEAR(rep.wheels[0].gradients.fy_camber, -R * 1000 / kr.x() * kc_test_deg, 1e-7);
  EXPECT_NEAR(rep.wheels[0].gradients.fy_steer, 0.0, 1e-9);
  EXPECT_NEAR(rep.wheels[0].gradients.mz_steer, -1000 / kr.z() * kc_test_deg, 1e-7);
  EXPECT_NEAR(rep.wheels[0].gradients.mz_camber, 0.0, 1e-9);
  EXPECT_NEAR(rep.wheels[0].gradients.fx_steer, 0.0, 1e-9);
  EXPECT_NEAR(rep.wheels[0].gradients.fx_camber, 0.0, 1e-9);
}

TEST(KcJob, TheBushingCornerCompliesWhereTheRigidOneDoesNot) {
  KcRequest r;
  r.model = CODYNA_TEST_DATA_DIR "/kc_double_wishbone_bushing.json";
  r.fy = KcRange{-2000, 2000, 3};
  const KcReport rep = study_kc_job(r);
  EXPECT_GT(std::abs(rep.wheels[0].gradients.fy_steer), 1e-3);
  EXPECT_GT(std::abs(rep.wheels[0].gradients.fy_camber), 1e-3);
  // the sweep's own central difference about design agrees with the gradient (small loads: near linear)
  EXPECT_NEAR((rep.points[2].toe - rep.points[0].toe) / 4.0, rep.wheels[0].gradients.fy_steer, 0.05 * std::abs(rep.wheels[0].gradients.fy_steer));
  EXPECT_NEAR((rep.points[2].camber - rep.points[0].camber) / 4.0, rep.wheels[0].gradients.fy_camber, 0.05 * std::abs(rep.wheels[0].gradients.fy_camber));
}

std::string kc_test_refusal(const KcRequest& r) {
  try {
    study_kc_job(r);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(KcJob, BadRequestsAreRefusedNamingTheOption) {
  KcRequest r;
  r.model = CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json";
  r.wheels = {"wheel_fl"};
  EXPECT_NE(kc_test_refusal(r).find("--wheel wheel_fl: no body or tire element of that name in"), std::string::npos) << kc_test_refusal(r);
  r.wheels.clear();
  r.travel = KcRange{0.05, -0.05, 5};
  EXPECT_NE(kc_test_refusal(r).find("expected MIN < MAX"), std::string::npos) << kc_test_refusal(r);
  r.travel = KcRange{-0.05, 0.05, 1};
  EXPECT_NE(kc_test_refusal(r).find("expected a point count N from 2 to 10000"), std::string::npos) << kc_test_refusal(r);
  EXPECT_THROW(study_kc_range("0.05:-0.05:5", "--travel"), std::invalid_argument);
  EXPECT_THROW(study_kc_range("-0.05:0.05:1", "--travel"), std::invalid_argument);
  EXPECT_THROW(study_kc_range("-0.05:0.05", "--travel"), std::invalid_argument);
  EXPECT_THROW(study_kc_range("a:0.05:3", "--travel"), std::invalid_argument);
  EXPECT_EQ(study_kc_range("-0.05:0.05:3", "--travel").points, 3);
  r.steer = "steering_wheel";
  r.travel.reset();
  EXPECT_NE(kc_test_refusal(r).find("--steer steering_wheel: no motion input of that name (motion inputs: rack)"), std::string::npos)
      << kc_test_refusal(r);
  r.steer = "";
  // a travel the linkage cannot reach: refused naming the value, nothing written
  const std::string out = (std::filesystem::temp_directory_path() / "kc_test_unreachable.csv").string();
  std::filesystem::remove(out);
  r.travel = KcRange{0.0, 0.6, 3};
  r.csv = out;
  try {
    study_kc_job(r);
    ADD_FAILURE() << "an unreachable travel was accepted";
  } catch (const ConvergenceError& e) {
    EXPECT_NE(std::string(e.what()).find("--travel 0.6: the suspension cannot reach it"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// The sedan's left front corner in the full car (chassis on its free joint, held): an aligning
// moment turns the upright about its kingpin against the steering column's torsion bushing (2000 N m/rad)
// through the tie rod (0.12 m behind the kingpin, along y), the rack and the 16:1 pinion (0.0075 m of
// rack per rad of shaft): the rack's stiffness is kc / p^2, so d toe / d Mz = -1 / (0.12^2 kc / p^2)
// (toe-out for a moment to the left), the spring network's static solution. The front coil-overs'
// rest lengths are set to their design lengths: with their preload the travel constraint's reaction
// would add the kingpin's jacking (a geometric stiffness) to the network (1.2e-4 of it, measured).
TEST(KcJob, AligningMomentComplianceOfTheSedanIsItsSteeringColumnsSpring) {
  ModelSpec spec = study_read_model(CODYNA_EXAMPLES_DIR "/sedan.json");
  int unloaded = 0;
  for (EffectSpec& e : spec.effects)
    if (e.name == "spring_fl" || e.name == "spring_fr") {
      e.rest_length = std::sqrt(0.05 * 0.05 + 0.55 * 0.55);  // top [1.2, 0.55, 0.25], bottom [1.2, 0.60, -0.30]
      ++unloaded;
    }
  ASSERT_EQ(unloaded, 2);
  KcRequest r;
  r.model = CODYNA_EXAMPLES_DIR "/sedan.json";
  r.spec = &spec;
  r.wheels = {"tire_fl"};
  r.travel = KcRange{-0.01, 0.01, 3};
  const KcReport rep = study_kc_job(r);
  EXPECT_EQ(rep.held, "chassis");
  EXPECT_EQ(rep.wheels[0].name, "wheel_fl");
  const double pinion = 0.12 / 16, column = 2000, arm = 0.12;
  const double rack_stiffness = column / (pinion * pinion);
  const double toe_per_kNm = -1000 / (arm * arm * rack_stiffness) * kc_test_deg;
  EXPECT_NEAR(rep.wheels[0].gradients.mz_steer, toe_per_kNm, 1e-7 * std::abs(toe_per_kNm)) << rep.wheels[0].gradients.mz_steer;
  EXPECT_NEAR(rep.wheels[0].gradients.mz_camber, 0.0, 1e-9);
}

}  // namespace
}  // namespace codyna

namespace codyna {
namespace {

// the corner mirrored to the right (y -> -y, names + "_r") on the same chassis and rack: an axle
ModelSpec kc_test_axle() {
  ModelSpec s = study_read_model(CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json");
  const auto shared = [](const std::string& n) { return n == "chassis" || n == "rack" || n == "ground"; };
  const auto right = [&](const std::string& n) { return shared(n) ? n : n + "_r"; };
  const auto mirror = [](Eigen::Vector3d p) {
    p.y() = -p.y();
    return p;
  };
  const ModelSpec left = s;
  for (BodySpec b : left.bodies)
    if (!shared(b.name)) {
      b.name = right(b.name);
      s.bodies.push_back(b);
    }
  for (JointSpec j : left.joints)
    if (!shared(j.child)) {
      j.name = j.name + "_r";
      j.parent = right(j.parent);
      j.child = right(j.child);
      j.parent_frame.position = mirror(j.parent_frame.position);
      j.child_frame.position = mirror(j.child_frame.position);
      s.joints.push_back(j);
    }
  for (ConstraintSpec c : left.constraints) {
    c.name += "_r";
    c.body_a = right(c.body_a);
    c.body_b = right(c.body_b);
    c.point_a = mirror(c.point_a);
    c.point_b = mirror(c.point_b);
    s.constraints.push_back(c);
  }
  for (EffectSpec e : left.effects)
    if (e.type != EffectType::Gravity) {
      e.name += "_r";
      e.body_a = right(e.body_a);
      e.body_b = right(e.body_b);
      e.point_a = mirror(e.point_a);
      e.point_b = mirror(e.point_b);
      s.effects.push_back(e);
    }
  return s;
}

// the left corner's independent solve at a travel, from design in ten steps
Eigen::VectorXd kc_test_solve_from_design(const KcTestCorner& c, double travel) {
  Eigen::VectorXd x = kc_test_design(c);
  for (int k = 1; k <= 10; ++k) x = kc_test_solve(c, x, travel * k / 10, 0.0);
  return x;
}

TEST(KcJob, AnAxlesRollMovesEachWheelAsTheIndependentSolveAtItsTravel) {
  const KcTestCorner corner;
  const ModelSpec axle = kc_test_axle();
  KcRequest r;
  r.model = "axle.json";
  r.spec = &axle;
  r.wheels = {"wheel", "tire_r"};
  r.roll = KcRange{-4, 4, 5};
  const KcReport rep = study_kc_job(r);
  ASSERT_EQ(rep.wheels.size(), 2u);
  EXPECT_EQ(rep.wheels[1].name, "wheel_r");
  ASSERT_EQ(rep.points.size(), 10u);
  const double half_track = 0.775;
  for (const KcPoint& p : rep.points) {
    EXPECT_EQ(p.sweep, "roll");
    // body roll phi (left side up): the left wheel drops by y tan(phi) relative to the body, the right one rises
    const double y = p.wheel == "wheel" ? half_track : -half_track;
    const double travel = -y * std::tan(p.roll / kc_test_deg);
    const KcTestPose pose = kc_test_pose(corner, kc_test_solve_from_design(corner, travel));
    EXPECT_NEAR(p.camber, kc_test_camber(pose.axis), 1e-9) << p.wheel << " roll " << p.roll;
    EXPECT_NEAR(p.toe, kc_test_toe(pose.axis), 1e-9) << p.wheel << " roll " << p.roll;
    EXPECT_NEAR(p.wheel_centre.z(), corner.wheel.z() + travel, 1e-12) << p.wheel << " roll " << p.roll;
  }
  EXPECT_GT(std::abs(rep.points[0].camber), 0.1);  // 4 deg of roll: not zeros
  // roll steer: -y times bump steer; the axle's roll centre on the centreline at the corners' height
  const KcGradients& gl = rep.wheels[0].gradients;
  const KcGradients& gr = rep.wheels[1].gradients;
  EXPECT_NEAR(gl.roll_steer, -half_track * gl.bump_steer / kc_test_deg, 1e-6 * std::abs(gl.roll_steer));
  EXPECT_NEAR(gr.roll_steer, -gl.roll_steer, 1e-6 * std::abs(gl.roll_steer));
  EXPECT_NEAR(rep.roll_centre_y, 0.0, 1e-9);
  EXPECT_NEAR(rep.roll_centre_z - rep.wheels[0].design.contact.z(), gl.roll_centre_height, 1e-9);
  // refusals: a roll needs two wheels on opposite sides
  KcRequest one = r;
  one.wheels = {"wheel"};
  EXPECT_NE(kc_test_refusal(one).find("--roll: rolls an axle: give its two wheels"), std::string::npos) << kc_test_refusal(one);
  KcRequest same = r;
  same.wheels = {"wheel", "wheel"};
  EXPECT_NE(kc_test_refusal(same).find("the same wheel twice"), std::string::npos) << kc_test_refusal(same);
}

}  // namespace
}  // namespace codyna
