// Loop-closure terms against finite differences.
#include "dynamics/constraints.hpp"

#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using test::MatrixNear;

// Jc against central differences of phi, at a state off the constraint manifold too
void check_jacobian(const Model& m, const Eigen::VectorXd& q) {
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  const Eigen::MatrixXd J = d.Jc;
  Eigen::MatrixXd Jfd(m.nc, m.nv);
  const double h = 1e-6;
  for (int k = 0; k < m.nv; ++k) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(m.nv, k) * h;
    const Eigen::VectorXd pp = constraint_residual<double>(m, d, integrate<double>(m, q, e));
    const Eigen::VectorXd pm = constraint_residual<double>(m, d, integrate<double>(m, q, Eigen::VectorXd(-e)));
    Jfd.col(k) = (pp - pm) / (2 * h);
  }
  EXPECT_TRUE(MatrixNear(J, Jfd, 1e-8)) << m.name;
}

// gamma = d/dt(Jc) v along q(t) = q + v t (additive coordinates, so qdd = 0)
void check_gamma(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Data d(m);
  constraint_terms<double>(m, d, q, v);
  const Eigen::VectorXd gamma = d.gamma;
  const double h = 1e-5;
  constraint_terms<double>(m, d, Eigen::VectorXd(q + h * v), v);
  const Eigen::VectorXd jp = d.Jc * v;
  constraint_terms<double>(m, d, Eigen::VectorXd(q - h * v), v);
  const Eigen::VectorXd jm = d.Jc * v;
  EXPECT_TRUE(MatrixNear(gamma, (jp - jm) / (2 * h), 1e-6)) << m.name;
}

TEST(Constraints, JacobianAndGammaMatchFiniteDifferences) {
  for (const char* name : {"four_bar.json", "andrews_squeezer.json", "bricard.json"}) {
    const Model m = test::load_example(name);
    std::mt19937 rng(7);
    const Eigen::VectorXd q = m.q0 + test::random_v(m, rng, 0.2);  // off the manifold
    check_jacobian(m, q);
    check_gamma(m, q, test::random_v(m, rng, 2.0));
  }
}

// gamma from the positions already made (alf's projection: no second pass of the positions'
// trigonometry) is constraint_terms' gamma to the last bit, on every row type: planar revolute,
// revolute, coupler, rolling ball, rolling disc
TEST(Constraints, GammaAfterPositionsIsConstraintTermsGamma) {
  int rows = 0;
  for (const char* name : {"four_bar.json", "andrews_squeezer.json", "bricard.json", "ball_beam.json", "ball_plate.json",
                           "rolling_disc.json"}) {
    const Model m = test::load_example(name);
    std::mt19937 rng(11);
    const Eigen::VectorXd q = integrate<double>(m, m.q0, test::random_v(m, rng, 0.2)), v = test::random_v(m, rng, 2.0);
    Data full(m), after(m);
    constraint_terms<double>(m, full, q, v);
    forward_kinematics<double>(m, after, q);  // positions only (crba's, rnea's)
    constraint_gamma_after_positions(m, after, q, v);
    ASSERT_EQ(after.gamma.size(), m.nc) << name;
    if (std::string(name) != "ball_beam.json")  // (a coupler's gamma is zero)
      EXPECT_GT(full.gamma.cwiseAbs().maxCoeff(), 1e-3) << name;  // a term that can be wrong
    for (int r = 0; r < m.nc; ++r) {
      EXPECT_EQ(after.gamma[r], full.gamma[r]) << name << " row " << r;
      EXPECT_EQ(after.phi[r], full.phi[r]) << name << " row " << r;
    }
    rows += m.nc;
  }
  EXPECT_EQ(rows, 20);  // 2 + 6 + 5 + 1 + 3 + 3: every row of the six models compared
}

// a ball closure on a random 3-D chain with spherical joints
TEST(Constraints, BallAndRevoluteClosuresOnSpatialChains) {
  ModelSpec s = test::random_tree_spec(71, 6, false);
  for (auto& j : s.joints) j.type = JointType::Spherical;
  for (std::size_t i = 1; i < s.joints.size(); ++i) s.joints[i].parent = s.bodies[i - 1].name;
  ConstraintSpec c;
  c.name = "close";
  c.type = ConstraintType::Ball;
  c.body_a = s.bodies.back().name;
  c.body_b = kGroundName;
  c.point_a = Eigen::Vector3d(0.1, 0.2, 0.0);
  c.point_b = Eigen::Vector3d(0.4, -0.3, 0.2);
  s.constraints.push_back(c);
  for (ConstraintType t : {ConstraintType::Ball, ConstraintType::Revolute}) {
    s.constraints[0].type = t;
    const Model m = compile(s);
    EXPECT_LT(m.assembly_residual, 1e-10);
    std::mt19937 rng(71);
    check_jacobian(m, integrate<double>(m, m.q0, test::random_v(m, rng, 0.1)));
  }
}

}  // namespace
}  // namespace codyna
