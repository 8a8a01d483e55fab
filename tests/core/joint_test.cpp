// Configuration-space operations: integrate/difference and qdot.
#include "dynamics/joint.hpp"

#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

TEST(Joint, DifferenceInvertsIntegrate) {
  const Model m = compile(test::random_tree_spec(61, 10));
  std::mt19937 rng(61);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd q = test::random_q(m, rng), dv = test::random_v(m, rng, 1.0);
    const Eigen::VectorXd q1 = integrate<double>(m, q, dv);
    EXPECT_TRUE(MatrixNear(difference(m, q, q1), dv, 1e-12));
  }
}

TEST(Joint, QdotIsTheDerivativeOfIntegrate) {
  const Model m = compile(test::random_tree_spec(62, 10));
  std::mt19937 rng(62);
  const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng);
  const double h = 1e-6;
  const Eigen::VectorXd fd = (integrate<double>(m, q, Eigen::VectorXd(h * v)) - integrate<double>(m, q, Eigen::VectorXd(-h * v))) / (2 * h);
  EXPECT_TRUE(MatrixNear(qdot<double>(m, q, v), fd, 1e-8));
}

TEST(Joint, IntegrateKeepsQuaternionsUnit) {
  const Model m = compile(test::random_tree_spec(63, 10));
  std::mt19937 rng(63);
  const Eigen::VectorXd q = integrate<double>(m, test::random_q(m, rng), test::random_v(m, rng, 3.0));
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (j.type == JointType::Spherical) EXPECT_NEAR(q.segment<4>(j.idx_q).norm(), 1.0, 1e-14);
    if (j.type == JointType::Free) EXPECT_NEAR(q.segment<4>(j.idx_q + 3).norm(), 1.0, 1e-14);
  }
}

}  // namespace
}  // namespace codyna

// The one quaternion log and exp (joint.hpp): inverse of each other for |r| < pi down to 1e-14 rad,
// the shorter way round for a quaternion with w < 0, a scaled quaternion normalized first, and the
// same as the angle-axis rotation Eigen builds
TEST(Joint, RotationLogAndExpAreInverse) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 200; ++k) {
    Eigen::Vector3d r(u(rng), u(rng), u(rng));
    r *= (k < 100 ? 3.0 : std::pow(10.0, -14 + k % 14)) / std::max(1.0, r.norm());
    if (r.norm() >= M_PI) continue;
    const Eigen::Vector4d h = codyna::rotation_exp(r);
    EXPECT_NEAR(h.norm(), 1.0, 1e-15);
    const Eigen::Vector3d back = codyna::rotation_log(h);
    EXPECT_LE((back - r).norm(), 1e-15 * std::max(1.0, r.norm()) * 4) << r.transpose();
    const Eigen::Quaterniond e(Eigen::AngleAxisd(r.norm(), r.norm() > 0 ? Eigen::Vector3d(r.normalized()) : Eigen::Vector3d::UnitX()));
    EXPECT_LE((Eigen::Vector4d(e.w(), e.x(), e.y(), e.z()) - h).norm(), 1e-15 * 4);
    // -h is the same rotation; 3 h is h scaled
    EXPECT_LE((codyna::rotation_log(-h) - r).norm(), 1e-15 * std::max(1.0, r.norm()) * 4);
    EXPECT_LE((codyna::rotation_log(3.0 * h) - r).norm(), 1e-15 * std::max(1.0, r.norm()) * 4);
  }
  EXPECT_EQ(codyna::rotation_log(Eigen::Vector4d::Zero()), Eigen::Vector3d::Zero());
}
