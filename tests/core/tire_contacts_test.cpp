// study/tire_contacts.hpp: the contact of every tire at a state, as the 3-D view draws it.
// Checked against what does not go through the tire law: the balance of the whole car. On the
// sedan's steady motions (examples/sedan.json) the only external forces are gravity and the four
// tires, and every body's centre of mass moves on a circle (or a line) at constant speed, so
//   sum of the tire forces + m g = sum m_i a_i,  a_i = r ez x v_i  (r the yaw rate, 0 straight)
// and, straight ahead, where no angular momentum changes, the moments about the origin balance too.
// The tire sensors (the same contact, read through sensor_outputs) give the same load and slip angle.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "study/files.hpp"
#include "study/tire_contacts.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;

namespace {

struct SedanAt {
  Model model;
  OperatingPoint op;
};

SedanAt sedan_steady(double lateral_acceleration) {
  const std::string path = test::example_path("sedan.json");
  ModelSpec spec = study_read_model(path);
  if (lateral_acceleration != 0) spec.analysis.steady.lateral_acceleration = lateral_acceleration;
  SedanAt s{study_model(spec, path), {}};
  s.op = study_operating_point(s.model);
  return s;
}

// sum over bodies of m_i a_i for a steady motion turning at r about world z (a_i = r ez x v_i), and
// m g; from the kinematics alone
void car_balance(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double r, Eigen::Vector3d* ma,
                 Eigen::Vector3d* weight, Eigen::Vector3d* weight_moment) {
  Data d(m);
  forward_kinematics(m, d, q, v);
  ma->setZero(), weight->setZero(), weight_moment->setZero();
  for (int i = 1; i < m.nbodies; ++i) {
    const double mi = m.mass[static_cast<std::size_t>(i)];
    const Eigen::Vector3d c = point_position<double>(d, i, m.com[static_cast<std::size_t>(i)]);
    const Eigen::Vector3d vc = point_velocity<double>(d, i, m.com[static_cast<std::size_t>(i)]);
    *ma += mi * r * Eigen::Vector3d::UnitZ().cross(vc);
    *weight += mi * m.gravity;
    *weight_moment += c.cross(mi * m.gravity);
  }
}

}  // namespace

TEST(TireContacts, StraightAheadTheTiresCarryTheCarsWeightAndItsMoment) {
  const SedanAt s = sedan_steady(0);
  ASSERT_LT(s.op.residual, 1e-8);
  const std::vector<TireContactReport> tires = study_tire_contacts(s.model, s.op.q, s.op.v);
  ASSERT_EQ(tires.size(), 4u);
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
  double Fz = 0;
  for (const TireContactReport& t : tires) {
    ASSERT_TRUE(t.in_contact) << t.name;
    F += t.force;
    M += t.point.cross(t.force) + t.moment;
    Fz += t.Fz;
    // flat road at z = 0: the contact on it, the axes the road's
    EXPECT_NEAR(t.point.z(), 0.0, 1e-12) << t.name;
    EXPECT_NEAR((t.ez - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15) << t.name;
    EXPECT_NEAR(t.force.dot(t.ez), t.Fz, 1e-9 * t.Fz) << t.name;
    EXPECT_NEAR(t.force.dot(t.ex), t.Fx, 1e-9 * t.Fz) << t.name;
    EXPECT_NEAR(t.force.dot(t.ey), t.Fy, 1e-9 * t.Fz) << t.name;
    EXPECT_NEAR(t.Vx, 25.0, 0.05) << t.name;  // rolling straight at the car's speed
    EXPECT_GT(t.penetration, 0.0) << t.name;
  }
  Eigen::Vector3d ma, W, MW;
  car_balance(s.model, s.op.q, s.op.v, 0.0, &ma, &W, &MW);
  const double mg = W.norm();
  EXPECT_GT(mg, 1e4);
  // the four loads are the weight, to the search's residual
  EXPECT_NEAR(Fz, mg, 1e-6 * mg);
  EXPECT_LT((F + W).norm(), 1e-6 * mg) << "tires " << F.transpose() << ", weight " << W.transpose();
  // and their moment about the origin the weight's (the car's length as the lever)
  EXPECT_LT((M + MW).norm(), 1e-6 * mg * 2.7) << "tires " << M.transpose() << ", weight " << MW.transpose();
  std::printf("[ TireContacts ] straight at 25 m/s: Fz %.6g %.6g %.6g %.6g N, sum %.9g N, m g %.9g N; Fx %.4g %.4g %.4g %.4g N\n",
              tires[0].Fz, tires[1].Fz, tires[2].Fz, tires[3].Fz, Fz, mg, tires[0].Fx, tires[1].Fx, tires[2].Fx,
              tires[3].Fx);
}

TEST(TireContacts, InASteadyTurnTheTiresPullTheCarRound) {
  const double ay = 0.4 * 9.80665;
  const SedanAt s = sedan_steady(ay);
  ASSERT_LT(s.op.residual, 1e-8);
  ASSERT_TRUE(s.op.motion.has_value());
  const double r = s.op.motion->joints.at(0).yaw_rate;
  const std::vector<TireContactReport> tires = study_tire_contacts(s.model, s.op.q, s.op.v);
  ASSERT_EQ(tires.size(), 4u);
  Eigen::Vector3d F = Eigen::Vector3d::Zero();
  for (const TireContactReport& t : tires) {
    ASSERT_TRUE(t.in_contact) << t.name;
    F += t.force;
  }
  Eigen::Vector3d ma, W, MW;
  car_balance(s.model, s.op.q, s.op.v, r, &ma, &W, &MW);
  const double mg = W.norm();
  // the tires' lateral forces hold the centripetal acceleration: about 0.4 m g
  EXPECT_NEAR(ma.norm(), 0.4 * mg, 0.02 * mg);
  EXPECT_LT((F + W - ma).norm(), 1e-6 * mg) << "tires + weight " << (F + W).transpose() << ", m a " << ma.transpose();
  // a left turn: the outer (right) tires carry more than the inner
  const auto load = [&](const std::string& name) {
    for (const TireContactReport& t : tires)
      if (t.name == name) return t.Fz;
    ADD_FAILURE() << "no tire " << name;
    return 0.0;
  };
  EXPECT_GT(load("tire_fr"), load("tire_fl") + 500);
  EXPECT_GT(load("tire_rr"), load("tire_rl") + 500);
  // the tire sensors read the same contact
  std::vector<int> which;
  for (std::size_t k = 0; k < s.model.sensors.size(); ++k)
    if (s.model.sensors[k].type == SensorType::Tire) which.push_back(static_cast<int>(k));
  ASSERT_EQ(which.size(), 8u);
  Data d(s.model);
  forward_kinematics(s.model, d, s.op.q, s.op.v);
  const Eigen::VectorXd y = sensor_outputs<double>(s.model, d, which, s.op.q, s.op.v);
  int checked = 0;
  for (std::size_t k = 0; k < which.size(); ++k) {
    const SensorModel& sm = s.model.sensors[static_cast<std::size_t>(which[k])];
    const TireContactReport& t = tires[static_cast<std::size_t>(sm.tire)];
    const double read = y[static_cast<Eigen::Index>(k)];
    if (sm.quantity == TireQuantity::Fz) {
      EXPECT_NEAR(read, t.Fz, 1e-9 * t.Fz) << sm.name;
      ++checked;
    } else if (sm.quantity == TireQuantity::SlipAngle) {
      EXPECT_NEAR(read, t.alpha, 1e-12) << sm.name;
      EXPECT_GT(std::abs(t.alpha), 1e-3) << sm.name;  // a turn: every tire slips
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8);
  std::printf("[ TireContacts ] 0.4 g left turn: Fz fl %.5g fr %.5g rl %.5g rr %.5g N, Fy %.5g %.5g %.5g %.5g N, |F + m g - m a| %.2e N\n",
              tires[0].Fz, tires[1].Fz, tires[2].Fz, tires[3].Fz, tires[0].Fy, tires[1].Fy, tires[2].Fy, tires[3].Fy,
              (F + W - ma).norm());
}

TEST(TireContacts, OffTheRoadNothingAndWrongSizesRefused) {
  const std::string path = test::example_path("sedan.json");
  const Model m = study_model(study_read_model(path), path);
  Eigen::VectorXd q = m.q0;
  const JointModel& j = m.joints[static_cast<std::size_t>(m.find_body("chassis"))];
  q[j.idx_q + 2] += 1.0;  // the car a metre higher: every wheel off the road
  const std::vector<TireContactReport> tires = study_tire_contacts(m, q, m.v0);
  ASSERT_EQ(tires.size(), 4u);
  for (const TireContactReport& t : tires) {
    EXPECT_FALSE(t.in_contact) << t.name;
    EXPECT_EQ(t.force.norm(), 0.0) << t.name;
    EXPECT_EQ(t.Fz, 0.0) << t.name;
    EXPECT_EQ((t.point - t.center).norm(), 0.0) << t.name;
    EXPECT_GT(t.center.z(), 1.0) << t.name;
  }
  EXPECT_INVALID_ARGUMENT_WITH(study_tire_contacts(m, m.q0.head(3), m.v0), "tire contacts", "3 values");
}
