// Kinematic Jacobians against finite differences of forward kinematics.
#include "dynamics/kinematics.hpp"

#include "dynamics/joint.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

TEST(Kinematics, PointJacobianMatchesCentralDifferences) {
  const Model m = compile(test::random_tree_spec(51, 12));
  std::mt19937 rng(51);
  Data d(m);
  for (int body = 1; body < m.nbodies; ++body) {
    const Eigen::VectorXd q = test::random_q(m, rng);
    const Eigen::Vector3d p = test::random_vec(rng, 0.4);
    forward_kinematics<double>(m, d, q);
    const Eigen::MatrixXd J = point_jacobian<double>(m, d, body, p);
    const Eigen::MatrixXd Jw = body_jacobian_world<double>(m, d, body).topRows(3);
    Eigen::MatrixXd Jfd(3, m.nv), Jwfd(3, m.nv);
    const double h = 1e-6;
    for (int k = 0; k < m.nv; ++k) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(m.nv, k) * h;
      forward_kinematics<double>(m, d, integrate<double>(m, q, e));
      const Eigen::Vector3d pp = point_position<double>(d, body, p);
      const Eigen::Matrix3d Rp = d.oMi[body].R;
      forward_kinematics<double>(m, d, integrate<double>(m, q, Eigen::VectorXd(-e)));
      const Eigen::Vector3d pm = point_position<double>(d, body, p);
      const Eigen::Matrix3d Rm = d.oMi[body].R;
      Jfd.col(k) = (pp - pm) / (2 * h);
      // world angular velocity from dR/dt R^T
      const Eigen::Matrix3d W = (Rp - Rm) / (2 * h) * ((Rp + Rm) / 2).transpose();
      Jwfd.col(k) = Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)) / 2;
    }
    EXPECT_TRUE(MatrixNear(J, Jfd, 1e-8)) << "body " << body;
    EXPECT_TRUE(MatrixNear(Jw, Jwfd, 1e-8)) << "body " << body;
  }
}

TEST(Kinematics, PointVelocityIsJacobianTimesV) {
  const Model m = compile(test::random_tree_spec(52, 12));
  std::mt19937 rng(52);
  Data d(m);
  const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng);
  forward_kinematics<double>(m, d, q, v);
  for (int body = 1; body < m.nbodies; ++body) {
    const Eigen::Vector3d p = test::random_vec(rng, 0.4);
    EXPECT_TRUE(MatrixNear(point_velocity<double>(d, body, p), point_jacobian<double>(m, d, body, p) * v, 1e-12));
    EXPECT_TRUE(MatrixNear(angular_velocity<double>(d, body), body_jacobian_world<double>(m, d, body).topRows(3) * v, 1e-12));
  }
}

// classical point acceleration against a central difference of the point velocity
// along a motion with constant coordinate rates (qdd = 0), on joints whose q is additive
TEST(Kinematics, PointAccelerationMatchesDifferenceOfVelocity) {
  const Model m = test::load_example("double_pendulum.json");
  Data d(m);
  Eigen::VectorXd q(2), v(2), qdd(2);
  q << 0.4, -1.1;
  v << 1.3, -0.7;
  qdd << 2.0, -3.0;
  forward_kinematics<double>(m, d, q, v, qdd);
  const Eigen::Vector3d p(0.1, -0.8, 0.05);
  const Eigen::Vector3d acc = point_acceleration<double>(d, 2, p);
  const double h = 1e-5;
  auto vel = [&](double t) {
    Data e(m);
    forward_kinematics<double>(m, e, Eigen::VectorXd(q + v * t + 0.5 * qdd * t * t), Eigen::VectorXd(v + qdd * t));
    return Eigen::Vector3d(point_velocity<double>(e, 2, p));
  };
  EXPECT_TRUE(MatrixNear(acc, (vel(h) - vel(-h)) / (2 * h), 1e-8));
}

// forward kinematics' shortcuts (a hinge's R0 and p0, a ball or free joint's frames; the products
// by exact identities skipped) give the placements of the generic composition X_PF X_FM(q) X_MC,
// bit for bit, with rotated frames, with the parent frame's rotation the identity, with the child
// frame the identity, and with both
TEST(Kinematics, ShortcutPlacementsAreTheGenericCompositionBitForBit) {
  for (int variant = 0; variant < 4; ++variant) {
    ModelSpec s = test::random_tree_spec(77, 20);
    for (JointSpec& j : s.joints) {
      if (variant & 1) j.parent_frame.rotation.setIdentity();
      if (variant & 2) j.child_frame = FrameSpec{};
    }
    const Model m = compile(s);
    std::mt19937 rng(78 + variant);
    Data d(m);
    int shortcuts = 0;
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd q = test::random_q(m, rng);
      forward_kinematics<double>(m, d, q);
      for (int i = 1; i < m.nbodies; ++i) {
        const JointModel& j = m.joints[i];
        SE3 X_FM;
        Mat6xT<double> S_M;
        joint_transform<double>(j, q, X_FM, S_M);
        const SE3 X = j.X_PF * X_FM * j.X_CM.inverse();
        const bool shortcut = j.type == JointType::Revolute || j.type == JointType::Spherical || j.type == JointType::Free;
        shortcuts += shortcut;
        if (j.type == JointType::Revolute) {  // the revolute path rotates about the axis in F: rounding differs
          EXPECT_TRUE(MatrixNear(d.liMi[i].R, X.R, 1e-15)) << "variant " << variant << " body " << i;
          EXPECT_TRUE(MatrixNear(d.liMi[i].p, X.p, 1e-15)) << "variant " << variant << " body " << i;
        } else {
          EXPECT_EQ(d.liMi[i].R, X.R) << "variant " << variant << " body " << i;
          EXPECT_EQ(d.liMi[i].p, X.p) << "variant " << variant << " body " << i;
        }
      }
    }
    EXPECT_GE(shortcuts, 3 * 10) << "variant " << variant;  // (every other joint of the tree)
  }
}

}  // namespace
}  // namespace codyna
