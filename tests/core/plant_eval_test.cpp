// PlantFunction::eval<double> with motion inputs or rolling's no-slip rows runs in the plant
// function's workspace (eval_driven: no heap after the first call, tests/alloc); eval<ADScalar>
// keeps the generic path, written apart (a second Newton from the motions' coordinates, one more
// Newton step in the scalar type, the velocities by its own LU). The two must give the same state
// derivative and outputs on every example that has either, at random states, inputs and motion
// rates and accelerations, and again after the workspace has served another state.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "analysis/operating_point.hpp"
#include "analysis/plant_function.hpp"
#include "spatial/autodiff.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

void eval_generic(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xd,
                  Eigen::VectorXd& y) {
  VecXT<ADScalar> xa(x.size()), ua(u.size()), xda, ya;
  for (Eigen::Index k = 0; k < x.size(); ++k) xa[k] = ADScalar(x[k], Eigen::VectorXd());
  for (Eigen::Index k = 0; k < u.size(); ++k) ua[k] = ADScalar(u[k], Eigen::VectorXd());
  f.eval<ADScalar>(xa, ua, xda, ya);
  xd.resize(xda.size());
  y.resize(ya.size());
  for (Eigen::Index k = 0; k < xda.size(); ++k) xd[k] = xda[k].value();
  for (Eigen::Index k = 0; k < ya.size(); ++k) y[k] = ya[k].value();
}

::testing::AssertionResult close(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tol) {
  if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
  const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
  const double err = a.size() ? (a - b).cwiseAbs().maxCoeff() : 0.0;
  if (err <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "differ by " << err << " (scale " << scale << ")\n"
                                       << a.transpose() << "\n" << b.transpose();
}

TEST(PlantEval, TheWorkspacePathEqualsTheGenericPathWithMotionsAndRolling) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int models = 0, with_rates = 0, rolling = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string name = entry.path().filename().string();
    const Model m = test::load_example(name);
    if (m.motions.empty() && m.velocity_rows.empty()) continue;
    SCOPED_TRACE(name);
    ++models;
    rolling += !m.velocity_rows.empty();
    const OperatingPoint op = initial_point(m);
    const PlantFunction f(m, op.q, op.u, partition_coordinates(m, op.q));
    for (int trial = 0; trial < 6; ++trial) {
      Eigen::VectorXd x(f.nx());
      for (Eigen::Index k = 0; k < x.size(); ++k) x[k] = 0.05 * U(rng);
      // with the motion inputs' rates and accelerations on odd trials
      const bool rates = f.nm() > 0 && trial % 2 == 1;
      Eigen::VectorXd u(f.nu() + (rates ? 2 * f.nm() : 0));
      for (int k = 0; k < f.nu(); ++k) u[k] = op.u[m.plant_inputs[static_cast<std::size_t>(k)]] + 0.02 * U(rng);
      for (Eigen::Index k = f.nu(); k < u.size(); ++k) u[k] = 0.3 * U(rng);
      with_rates += rates;
      Eigen::VectorXd xd, y, xd_ref, y_ref;
      f.eval<double>(x, u, xd, y);
      eval_generic(f, x, u, xd_ref, y_ref);
      EXPECT_TRUE(close(xd, xd_ref, 1e-12)) << "xdot, trial " << trial;
      EXPECT_TRUE(close(y, y_ref, 1e-12)) << "y, trial " << trial;
      // a fresh plant function (a fresh workspace) gives the same numbers bit for bit
      const PlantFunction g(m, op.q, op.u, partition_coordinates(m, op.q));
      Eigen::VectorXd xd_fresh, y_fresh;
      g.eval<double>(x, u, xd_fresh, y_fresh);
      EXPECT_EQ(xd, xd_fresh) << "trial " << trial;
      EXPECT_EQ(y, y_fresh) << "trial " << trial;
    }
  }
  EXPECT_GE(models, 5);  // bus suspension, ball and beam, driven slider-crank, ball and plate, rolling disc
  EXPECT_GE(with_rates, 3);
  EXPECT_GE(rolling, 2);
}

}  // namespace
}  // namespace codyna
