// Exact Jacobians for the implicit integrators (issue 11): ClosedLoopSystem::ode_jacobian and
// dae_jacobian against central differences of rhs() / residual() (a second method), on every
// example model at random
// states (closed loops: assembled, consistent ones); and cvode-bdf / ida with them against the
// difference-quotient runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <vector>

#include "core/test_util.hpp"
#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include <Eigen/SVD>
#include "dynamics/joint.hpp"
#include "dynamics/prepare.hpp"
#include "simulation/closed_loop.hpp"
#include "simulation/simulator.hpp"

namespace codyna {
namespace {

double rel_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  if (ref.size() == 0) return 0.0;
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-12);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

Eigen::MatrixXd fd_ode(ClosedLoopSystem& s, const Eigen::VectorXd& y) {
  const int n = static_cast<int>(y.size());
  Eigen::MatrixXd J(n, n);
  Eigen::VectorXd fp, fm;
  for (int j = 0; j < n; ++j) {
    // the accelerations are quadratic in v (velocity products, gamma, linear dampers), where
    // central differences are exact at any step: a long step there keeps the round-off of an
    // ill-conditioned loop (Andrews' squeezer: an error growing as 1/h, 2e-5 at 1e-4) small
    const double h = (j >= s.nq() && j < s.nq() + s.nv() ? 1e-2 : 1e-4) * std::max(1.0, std::abs(y[j]));
    Eigen::VectorXd yp = y, ym = y;
    yp[j] += h, ym[j] -= h;
    s.rhs(0.0, yp, fp);
    s.rhs(0.0, ym, fm);
    J.col(j) = (fp - fm) / (2 * h);
  }
  return J;
}

// dF/dY + cj dF/dY'
Eigen::MatrixXd fd_dae(ClosedLoopSystem& s, const Eigen::VectorXd& Y, const Eigen::VectorXd& Yp, double cj) {
  const int n = static_cast<int>(Y.size());
  Eigen::MatrixXd J(n, n);
  Eigen::VectorXd fp, fm;
  for (int j = 0; j < n; ++j) {
    const double h = 1e-5 * std::max(1.0, std::abs(Y[j]));
    Eigen::VectorXd a = Y, b = Y;
    a[j] += h, b[j] -= h;
    s.residual(0.0, a, Yp, fp);
    s.residual(0.0, b, Yp, fm);
    J.col(j) = (fp - fm) / (2 * h);
    const double hp = 1e-5 * std::max(1.0, std::abs(Yp[j]));
    a = Yp, b = Yp;
    a[j] += hp, b[j] -= hp;
    s.residual(0.0, Y, a, fp);
    s.residual(0.0, Y, b, fm);
    J.col(j) += cj * (fp - fm) / (2 * hp);
  }
  return J;
}

// a random state near the model's initial one, assembled on the loops
Eigen::VectorXd random_state(const Model& m, std::mt19937& rng, bool near_initial) {
  Eigen::VectorXd q = near_initial ? integrate<double>(m, m.q0, test::random_v(m, rng, 0.2)) : test::random_q(m, rng);
  Eigen::VectorXd v = test::random_v(m, rng, 1.5);
  if (m.nc > 0) {
    const AssemblyResult r = assemble(m, q, v);
    q = r.q, v = r.v;
  }
  Eigen::VectorXd y(m.nq + m.nv);
  y << q, v;
  return y;
}

void check_model(const Model& m, const std::string& name, std::mt19937& rng, bool near_initial, int states) {
  ClosedLoopSystem sys(m, nullptr, nullptr, Eigen::VectorXd(), m.u_nominal());
  ASSERT_TRUE(sys.exact_ode_jacobian()) << name;
  ASSERT_TRUE(sys.exact_dae_jacobian()) << name;
  const int nq = m.nq, nv = m.nv;
  for (int k = 0; k < states; ++k) {
    const Eigen::VectorXd y = random_state(m, rng, near_initial);
    Eigen::MatrixXd J;
    ASSERT_TRUE(sys.ode_jacobian(0.0, y, J));
    if (sys.na() < m.nc) {
      // redundant rows (Bricard): off the constraint manifold rhs() solves all rows in the least-squares
      // sense and the kept rows differ from it; on the manifold they agree: compare along its
      // tangent directions (q and v in the null space of Jc)
      Data d(m);
      constraint_terms<double>(m, d, y.head(nq), Eigen::VectorXd::Zero(nv));
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(d.Jc, Eigen::ComputeFullV);
      const Eigen::MatrixXd N = svd.matrixV().rightCols(nv - sys.na());
      ASSERT_EQ(nq, nv);
      for (int c = 0; c < N.cols(); ++c)
        for (int part = 0; part < 2; ++part) {
          Eigen::VectorXd dir = Eigen::VectorXd::Zero(nq + nv);
          dir.segment(part * nq, nv) = N.col(c);
          const double h = 1e-6;
          Eigen::VectorXd fp, fm;
          sys.rhs(0.0, y + h * dir, fp);
          sys.rhs(0.0, y - h * dir, fm);
          const Eigen::VectorXd fd = (fp - fm) / (2 * h), ex = J * dir;
          EXPECT_LT((ex - fd).cwiseAbs().maxCoeff() / std::max(1.0, fd.cwiseAbs().maxCoeff()), 1e-6)
              << name << " tangent direction " << c << " part " << part << ", state " << k;
        }
    } else {
    const Eigen::MatrixXd Jfd = fd_ode(sys, y);
    EXPECT_LT(rel_difference(J, Jfd), 1e-6) << name << " ODE, state " << k;
    // the accelerations' rows on their own (they would hide under the qdot rows' scale)
    EXPECT_LT(rel_difference(J.block(nq, 0, nv, nq), Jfd.block(nq, 0, nv, nq)), 1e-6) << name << " da/dq, state " << k;
    EXPECT_LT(rel_difference(J.block(nq, nq, nv, nv), Jfd.block(nq, nq, nv, nv)), 1e-6) << name << " da/dv, state " << k;
    EXPECT_LT(rel_difference(J.block(0, 0, nq, nq), Jfd.block(0, 0, nq, nq)), 1e-6) << name << " dqdot/dq, state " << k;
    }

    // the DAE form: consistent Y, Y', then moved off them as Newton iterates are
    Eigen::VectorXd Y, Yp;
    sys.consistent(0.0, y, Y, Yp);
    Y.tail(sys.na()) += test::random_v(m, rng, 1.0).head(sys.na());
    Yp += 0.1 * Eigen::VectorXd::Random(Yp.size());
    const double cj = 123.0;
    Eigen::MatrixXd G;
    ASSERT_TRUE(sys.dae_jacobian(0.0, Y, Yp, cj, G));
    const Eigen::MatrixXd Gfd = fd_dae(sys, Y, Yp, cj);
    EXPECT_LT(rel_difference(G, Gfd), 1e-6) << name << " DAE, state " << k;
    const int m_ = sys.ode_size();
    EXPECT_LT(rel_difference(G.block(nq, 0, nv, nq), Gfd.block(nq, 0, nv, nq)), 1e-6) << name << " dyn/dq, state " << k;
    EXPECT_LT(rel_difference(G.block(nq, nq, nv, nv), Gfd.block(nq, nq, nv, nv)), 1e-6) << name << " dyn/dv, state " << k;
    if (sys.na())
      EXPECT_LT(rel_difference(G.bottomLeftCorner(sys.na(), m_), Gfd.bottomLeftCorner(sys.na(), m_)), 1e-6)
          << name << " closure rows, state " << k;
  }
}

TEST(IntegratorJacobian, ExactAgreesWithCentralDifferencesOnEveryExample) {
  int loops = 0, quaternions = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().filename().string();
    const Model m = test::load_example(name);
    // motion inputs: no exact integrator Jacobian (difference quotients; motion_test.cpp runs them)
    if (!m.motions.empty()) continue;
    // rolling's no-slip rows: no exact integrator Jacobian yet either (ClosedLoopSystem says so;
    // rolling_test.cpp and rolling_disc_test.cpp check the plant's exact Jacobian)
    if (!m.velocity_rows.empty()) continue;
    loops += m.nc > 0;
    quaternions += m.nq > m.nv;
    // each example's states from its own name, so that adding an example changes no other's
    std::uint32_t seed = 2166136261u;
    for (char c : name) seed = (seed ^ static_cast<unsigned char>(c)) * 16777619u;
    std::mt19937 own(seed);
    check_model(m, name, own, true, 3);
  }
  EXPECT_GE(loops, 4);
  EXPECT_GE(quaternions, 1);
}

// cvode-bdf and ida with the exact Jacobian: the same trajectory as with difference quotients,
// for far fewer evaluations, counted over runs to each of t_ends: one run's count moves with the
// Jacobian's round-off (a new summation order in the derivative pass, the same plant A to 7e-21
// of its largest entry, took the flyball's ida run to 2 s from a ratio above 1.4 to 1.22, while
// the runs to 1.7 .. 2.5 s stayed between 1.5 and 1.66)
void compare_runs(const std::string& example, const std::string& method, const std::vector<double>& t_ends, double tol,
                  double min_ratio) {
  const Model m = test::load_example(example);
  long exact_evals = 0, dq_evals = 0, exact_jac = 0, dq_jac = 0, exact_steps = 0, dq_steps = 0;
  for (double t_end : t_ends) {
    SimulationOptions o;
    o.integrator.method = method;
    o.t_end = t_end;
    o.output_step = t_end / 10;
    if (tol > 0) o.integrator.rtol = o.integrator.atol = tol;
    const SimulationResult exact = simulate(m, nullptr, nullptr, o);
    o.integrator.exact_jacobian = false;
    const SimulationResult dq = simulate(m, nullptr, nullptr, o);
    ASSERT_EQ(exact.q.rows(), dq.q.rows());
    const double scale = std::max(1.0, dq.q.cwiseAbs().maxCoeff());
    EXPECT_LT((exact.q.bottomRows(1) - dq.q.bottomRows(1)).cwiseAbs().maxCoeff() / scale, 1e3 * std::max(tol, 1e-8))
        << example << " " << method << " to " << t_end;
    EXPECT_GT(exact.stats.jac_evals, 0);
    exact_evals += exact.stats.rhs_evals;
    dq_evals += dq.stats.rhs_evals;
    exact_jac += exact.stats.jac_evals;
    dq_jac += dq.stats.jac_evals;
    exact_steps += exact.stats.steps;
    dq_steps += dq.stats.steps;
  }
  const double ratio = double(dq_evals) / double(exact_evals);
  EXPECT_GT(ratio, min_ratio) << example << " " << method << ": " << dq_evals << " vs " << exact_evals;
  std::printf("%s %s: rhs evals %ld -> %ld, jac %ld -> %ld, steps %ld -> %ld\n", example.c_str(), method.c_str(),
              dq_evals, exact_evals, dq_jac, exact_jac, dq_steps, exact_steps);
}

TEST(IntegratorJacobian, CvodeBdfAndIdaAgreeWithDifferenceQuotientsForFewerEvaluations) {
  // measured: Andrews cvode-bdf 1655 -> 1389, ida 6297 -> 2057; flyball cvode-bdf 1606 -> 1436,
  // ida 7859 -> 5277 over its five runs (CVODE re-uses its Jacobian for many steps: on these small systems the
  // difference quotients cost it little; the gain grows with n, docs/work-precision.md)
  // (cvode-bdf keeps difference quotients on closed loops: integrators.cpp says why)
  compare_runs("andrews_squeezer.json", "ida", {0.03}, 1e-8, 2.5);
  compare_runs("iftomm_a05_flyball.json", "cvode-bdf", {2.0}, 0, 1.0);
  compare_runs("iftomm_a05_flyball.json", "ida", {1.8, 1.9, 2.0, 2.1, 2.2}, 0, 1.4);
}

}  // namespace
}  // namespace codyna
