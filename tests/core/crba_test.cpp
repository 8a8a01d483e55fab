// CRBA: symmetric positive definite, and the kinetic energy it implies.
#include "dynamics/crba.hpp"

#include <Eigen/Eigenvalues>

#include "dynamics/energy.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

TEST(Crba, SymmetricPositiveDefiniteOnRandomTrees) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const Model m = compile(test::random_tree_spec(seed, 12));
    std::mt19937 rng(seed);
    Data d(m);
    for (int k = 0; k < 4; ++k) {
      const Eigen::MatrixXd M = crba<double>(m, d, test::random_q(m, rng));
      EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff());
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0.0);
    }
  }
}

// 1/2 v^T M v equals the kinetic energy summed body by body (an independent path)
TEST(Crba, QuadraticFormIsKineticEnergy) {
  const Model m = compile(test::random_tree_spec(21, 12));
  std::mt19937 rng(21);
  Data d(m);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd q = test::random_q(m, rng), v = test::random_v(m, rng, 2);
    const Eigen::MatrixXd M = crba<double>(m, d, q);
    const double T = kinetic_energy<double>(m, d, q, v);
    EXPECT_NEAR(0.5 * v.dot(M * v), T, 1e-12 * std::max(1.0, T));
  }
}

}  // namespace
}  // namespace codyna
