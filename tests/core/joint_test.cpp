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
