// The spatial transforms and cross products in double (written out component by component for
// speed) against the 6 x 6 matrices they stand for, and against the block expressions they
// replaced, bit for bit.
#include "spatial/spatial.hpp"

#include <random>

#include <gtest/gtest.h>

namespace codyna {
namespace {

struct SpatialCase {
  SE3 X;
  Vec6T<double> a, b;
};

SpatialCase random_spatial_case(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  const Eigen::Quaterniond quat = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
  SpatialCase c;
  c.X = SE3(quat.toRotationMatrix(), Eigen::Vector3d(u(rng), u(rng), u(rng)));
  for (int k = 0; k < 6; ++k) {
    c.a[k] = u(rng);
    c.b[k] = u(rng);
  }
  return c;
}

// [w]x and the 6 x 6 motion cross product matrix [[w] 0; [v] [w]]
Mat6T<double> motion_cross_matrix(const Vec6T<double>& m) {
  Mat6T<double> X = Mat6T<double>::Zero();
  const Eigen::Matrix3d W = skew<double>(m.head<3>()), V = skew<double>(m.tail<3>());
  X.topLeftCorner<3, 3>() = W;
  X.bottomRightCorner<3, 3>() = W;
  X.bottomLeftCorner<3, 3>() = V;
  return X;
}

TEST(Spatial, TransformsAreTheirSixBySixMatrices) {
  std::mt19937 rng(7);
  for (int t = 0; t < 200; ++t) {
    const SpatialCase c = random_spatial_case(rng);
    const Mat6T<double> Xm = c.X.motion_matrix();             // B -> A, motions
    const Mat6T<double> Xf = Xm.inverse().transpose();        // B -> A, forces
    const double tol = 1e-14;
    EXPECT_LT((c.X.act_motion(c.a) - Xm * c.a).norm(), tol);
    EXPECT_LT((c.X.inv_act_motion(c.a) - Xm.inverse() * c.a).norm(), tol);
    EXPECT_LT((c.X.act_force(c.a) - Xf * c.a).norm(), tol);
    EXPECT_LT((c.X.inv_act_force(c.a) - Xf.inverse() * c.a).norm(), tol);
    EXPECT_LT((cross_motion<double>(c.a, c.b) - motion_cross_matrix(c.a) * c.b).norm(), tol);
    EXPECT_LT((cross_force<double>(c.a, c.b) + motion_cross_matrix(c.a).transpose() * c.b).norm(), tol);
    // power is frame independent: (X* f) . (X m) = f . m
    EXPECT_NEAR(c.X.act_force(c.b).dot(c.X.act_motion(c.a)), c.b.dot(c.a), tol);
  }
}

TEST(Spatial, TransformsAreTheBlockExpressionsBitForBit) {
  std::mt19937 rng(11);
  for (int t = 0; t < 1000; ++t) {
    const SpatialCase c = random_spatial_case(rng);
    const Eigen::Matrix3d& R = c.X.R;
    const Eigen::Vector3d& p = c.X.p;
    const Eigen::Vector3d w = c.a.head<3>(), v = c.a.tail<3>(), w2 = c.b.head<3>(), v2 = c.b.tail<3>();
    Vec6T<double> e;
    e.head<3>() = R * w;
    e.tail<3>() = R * v + p.cross(Eigen::Vector3d(e.head<3>()));
    EXPECT_EQ(c.X.act_motion(c.a), e);
    e.head<3>() = R.transpose() * w;
    e.tail<3>() = R.transpose() * (v - p.cross(w));
    EXPECT_EQ(c.X.inv_act_motion(c.a), e);
    e.tail<3>() = R * v;
    e.head<3>() = R * w + p.cross(Eigen::Vector3d(e.tail<3>()));
    EXPECT_EQ(c.X.act_force(c.a), e);
    e.tail<3>() = R.transpose() * v;
    e.head<3>() = R.transpose() * (w - p.cross(v));
    EXPECT_EQ(c.X.inv_act_force(c.a), e);
    e.head<3>() = w.cross(w2);
    e.tail<3>() = w.cross(v2) + v.cross(w2);
    EXPECT_EQ(cross_motion<double>(c.a, c.b), e);
    e.head<3>() = w.cross(w2) + v.cross(v2);
    e.tail<3>() = w.cross(v2);
    EXPECT_EQ(cross_force<double>(c.a, c.b), e);
    const double k = c.b[1];  // a joint's motion s qd: s = a, qd = k
    EXPECT_EQ(cross_motion_scaled<double>(c.b, c.a.data(), k), cross_motion<double>(c.b, Vec6T<double>(c.a * k)));
    RigidInertiaT<double> I;  // (not written out; against its matrix) a rigid inertia: mass, first moment, symmetric rotational inertia
    I.m = 1.0 + c.b[0] * c.b[0];
    I.h = c.b.tail<3>();
    I.I = R * Eigen::Vector3d(2.0, 3.0, 4.0).asDiagonal() * R.transpose();
    EXPECT_LT((I.apply(c.a) - I.matrix() * c.a).norm(), 1e-13);
  }
}

}  // namespace
}  // namespace codyna
