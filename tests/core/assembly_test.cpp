// Assembly onto loop closures and detection of redundant constraints.
#include "dynamics/assembly.hpp"

#include "dynamics/constraints.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

TEST(Assembly, BricardHasOneRedundantEquationAndOneDof) {
  const Model m = test::load_example("bricard.json");
  EXPECT_EQ(m.nv, 5);
  EXPECT_EQ(m.nc, 5);
  ASSERT_EQ(m.redundant_rows.size(), 1u);  // Grubler says 0 DOF; the mechanism has 1
  EXPECT_EQ(m.dof(), 1);
  EXPECT_FALSE(m.row_names[m.redundant_rows[0]].empty());
  // the remaining rows have full rank and the redundant one is a combination of them
  Data d(m);
  constraint_terms<double>(m, d, m.q0, m.v0);
  Eigen::MatrixXd Ja(m.active_rows.size(), m.nv);
  for (std::size_t k = 0; k < m.active_rows.size(); ++k) Ja.row(k) = d.Jc.row(m.active_rows[k]);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(Ja);
  EXPECT_EQ(lu.rank(), 4);
  Eigen::FullPivLU<Eigen::MatrixXd> all(d.Jc);
  EXPECT_EQ(all.rank(), 4);
}

TEST(Assembly, BricardMovesAlongItsOneDofAndReassembles) {
  const Model m = test::load_example("bricard.json");
  Eigen::VectorXd q = m.q0;
  q[0] = 0.3;  // turn joint A; the others must follow
  const AssemblyResult r = assemble(m, q, Eigen::VectorXd::Zero(m.nv));
  ASSERT_TRUE(r.converged);
  EXPECT_LT(r.position_residual, 1e-12);
  EXPECT_GT((r.q - m.q0).norm(), 0.1);
}

TEST(Assembly, FourBarFromARoughGuess) {
  const Model m = test::load_example("four_bar.json");
  Eigen::VectorXd q = m.q0 + Eigen::VectorXd::Constant(m.nq, 0.05);
  Eigen::VectorXd v = Eigen::VectorXd::Constant(m.nv, 1.0);
  const AssemblyResult r = assemble(m, q, v);
  ASSERT_TRUE(r.converged);
  Data d(m);
  EXPECT_LT(constraint_residual<double>(m, d, r.q).cwiseAbs().maxCoeff(), 1e-12);
  constraint_terms<double>(m, d, r.q, r.v);
  EXPECT_LT((d.Jc * r.v).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(r.v.norm(), 0.1);  // projected, not zeroed
}

TEST(Assembly, PartitionRowsFindsDependentRows) {
  Eigen::MatrixXd J(3, 3);
  J << 1, 0, 0, 0, 1, 0, 1, 1, 0;
  const RowPartition p = partition_rows(J);
  EXPECT_EQ(p.independent.size(), 2u);
  EXPECT_EQ(p.redundant.size(), 1u);
}

}  // namespace
}  // namespace codyna
