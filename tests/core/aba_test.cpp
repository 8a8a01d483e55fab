// ABA inverts RNEA, and agrees with the mass-matrix route.
#include "dynamics/aba.hpp"

#include <Eigen/Cholesky>

#include "dynamics/crba.hpp"
#include "dynamics/rnea.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

TEST(Aba, InvertsRneaOnRandomTrees) {
  for (unsigned seed : {31u, 32u, 33u, 34u}) {
    const Model m = compile(test::random_tree_spec(seed, 14));
    std::mt19937 rng(seed);
    Data d(m);
    for (int k = 0; k < 4; ++k) {
      const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng), a = test::random_v(m, rng, 5);
      const Eigen::VectorXd tau = rnea<double>(m, d, q, v, a);
      EXPECT_TRUE(MatrixNear(aba<double>(m, d, q, v, tau), a, 1e-10)) << "seed " << seed;
    }
  }
}

TEST(Aba, EqualsMassMatrixSolve) {
  const Model m = compile(test::random_tree_spec(41, 10));
  std::mt19937 rng(41);
  Data d(m);
  const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng), tau = test::random_v(m, rng, 3);
  const Eigen::MatrixXd M = crba<double>(m, d, q);
  const Eigen::VectorXd h = nonlinear_effects<double>(m, d, q, v);
  const Eigen::VectorXd expected = M.llt().solve(tau - h);
  EXPECT_TRUE(MatrixNear(aba<double>(m, d, q, v, tau), expected, 1e-10));
}

}  // namespace
}  // namespace codyna
