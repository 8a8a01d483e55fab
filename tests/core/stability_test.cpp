// The one stability rule (analysis/stability.hpp), fed poles on both sides of the boundary and on
// it, continuous and sampled, against the classes written down by hand; the modal analysis (what
// the GUI's pole map and mode table show) and the simulate job's unstable-pole list (what the CLI
// and Python print) decide each pole the same way.
#include "analysis/stability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analysis/modal.hpp"
#include "model/model.hpp"

using namespace codyna;

namespace {

// a real block-diagonal A with these eigenvalues (a complex one brings its conjugate: a 2 x 2 block)
Eigen::MatrixXd with_eigenvalues(const std::vector<std::complex<double>>& p) {
  int n = 0;
  for (const auto& e : p) n += e.imag() != 0 ? 2 : 1;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  int k = 0;
  for (const auto& e : p) {
    if (e.imag() != 0) {
      A.block<2, 2>(k, k) << e.real(), e.imag(), -e.imag(), e.real();
      k += 2;
    } else {
      A(k, k) = e.real();
      ++k;
    }
  }
  return A;
}

struct PoleCase {
  std::complex<double> pole;
  Stability expected;
};

}  // namespace

TEST(Stability, ContinuousPolesAroundTheImaginaryAxis) {
  const std::vector<PoleCase> cases = {
      {{-1e-12, 0}, Stability::Marginal}, {{0, 0}, Stability::Marginal},     {{1e-12, 0}, Stability::Marginal},
      {{-1, 0}, Stability::Stable},       {{0.5, 0}, Stability::Unstable},   {{-1e-6, 0}, Stability::Stable},
      {{1e-6, 0}, Stability::Unstable},   {{0, 2}, Stability::Marginal},     {{-0.2, 3}, Stability::Stable},
      {{0.1, 1}, Stability::Unstable},
  };
  std::vector<std::complex<double>> poles;
  for (const PoleCase& c : cases) poles.push_back(c.pole);
  LinearSystem sys;
  sys.A = with_eigenvalues(poles);
  const double tol = stability_tolerance(sys.A);
  EXPECT_DOUBLE_EQ(tol, 1e-9 * std::max(1.0, sys.A.norm()));
  for (const PoleCase& c : cases) EXPECT_EQ(classify_pole(c.pole, false, tol), c.expected) << c.pole;
  // the modal analysis (the GUI's pole map and mode table) says the same of each
  const ModalAnalysis modal = modal_analysis(sys);
  ASSERT_EQ(modal.modes.size(), 13u);
  for (const Mode& m : modal.modes) {
    const PoleCase* nearest = nullptr;
    for (const PoleCase& c : cases)
      if (!nearest || std::abs(std::abs(c.pole.imag()) - std::abs(m.eigenvalue.imag())) + std::abs(c.pole.real() - m.eigenvalue.real()) <
                          std::abs(std::abs(nearest->pole.imag()) - std::abs(m.eigenvalue.imag())) +
                              std::abs(nearest->pole.real() - m.eigenvalue.real()))
        nearest = &c;
    EXPECT_EQ(m.stability, nearest->expected) << m.eigenvalue;
  }
  // the counts and the unstable list (the simulate job's Report)
  Eigen::VectorXcd p(static_cast<Eigen::Index>(poles.size()));
  for (std::size_t k = 0; k < poles.size(); ++k) p[static_cast<Eigen::Index>(k)] = poles[k];
  const PoleCount n = classify_poles(p, false, tol);
  EXPECT_EQ(n.stable, 3);
  EXPECT_EQ(n.marginal, 4);
  EXPECT_EQ(n.unstable, 3);
  EXPECT_FALSE(n.asymptotically_stable());
  const Eigen::VectorXcd bad = unstable_poles(p, false, tol);
  ASSERT_EQ(bad.size(), 3);
  EXPECT_EQ(bad[0], std::complex<double>(0.5, 0));
  EXPECT_EQ(bad[2], std::complex<double>(0.1, 1));
  // a NaN pole is never stable
  EXPECT_EQ(classify_pole({std::nan(""), 0}, false, tol), Stability::Unstable);
}

TEST(Stability, SampledPolesAroundTheUnitCircle) {
  const double th = 0.7;
  const std::vector<PoleCase> cases = {
      {{1 - 1e-12, 0}, Stability::Marginal}, {{1, 0}, Stability::Marginal},   {{1 + 1e-12, 0}, Stability::Marginal},
      {{0.5, 0}, Stability::Stable},         {{-0.9, 0}, Stability::Stable},  {{1.5, 0}, Stability::Unstable},
      {{-1.01, 0}, Stability::Unstable},     {{std::cos(th), std::sin(th)}, Stability::Marginal},
      {{0.5 * std::cos(th), 0.5 * std::sin(th)}, Stability::Stable},           {{1.1 * std::cos(th), 1.1 * std::sin(th)}, Stability::Unstable},
  };
  std::vector<std::complex<double>> poles;
  for (const PoleCase& c : cases) poles.push_back(c.pole);
  LinearSystem sys;
  sys.A = with_eigenvalues(poles);
  sys.Ts = 0.01;
  const double tol = stability_tolerance(sys.A);
  for (const PoleCase& c : cases) EXPECT_EQ(classify_pole(c.pole, true, tol), c.expected) << c.pole;
  // Re(z) > 0 is not what decides a sampled pole: z = 0.5 is stable
  EXPECT_EQ(classify_pole({0.5, 0}, false, tol), Stability::Unstable);
  const ModalAnalysis modal = modal_analysis(sys);
  int stable = 0, marginal = 0, unstable = 0;
  for (const Mode& m : modal.modes) {
    stable += m.stability == Stability::Stable;
    marginal += m.stability == Stability::Marginal;
    unstable += m.stability == Stability::Unstable;
    EXPECT_EQ(m.stability, classify_pole(m.eigenvalue, true, tol)) << m.eigenvalue;
  }
  EXPECT_EQ(stable, 4);    // 0.5, -0.9, the pair inside
  EXPECT_EQ(marginal, 5);  // 1 - 1e-12, 1, 1 + 1e-12, the pair on the circle
  EXPECT_EQ(unstable, 4);  // 1.5, -1.01, the pair outside
}

// a free mass with a spring of 1e-14 N/m (a double integrator, to round-off): its computed
// eigenvalues are +-1e-7, beyond the round-off tolerance, yet they stand for one repeated zero;
// the modal analysis (which finds the generalized null space) calls both modes marginal
TEST(Stability, ARepeatedZeroIsMarginal) {
  LinearSystem sys;
  sys.A = (Eigen::MatrixXd(2, 2) << 0, 1, 1e-14, 0).finished();
  const ModalAnalysis modal = modal_analysis(sys);
  ASSERT_EQ(modal.zero_count, 2);
  bool rule_alone_says_unstable = false;
  for (const Mode& m : modal.modes) {
    EXPECT_EQ(m.stability, Stability::Marginal) << m.eigenvalue;
    rule_alone_says_unstable = rule_alone_says_unstable || classify_pole(m.eigenvalue, false, modal.stability_tolerance) == Stability::Unstable;
  }
  EXPECT_TRUE(rule_alone_says_unstable);
}

// the one rate-unit rule (model/model.hpp), which codyna info, the simulate job's notes, the plant's
// rate outputs and the GUI's xdot0 offsets all print with
TEST(RateUnit, OfEachKindOfUnit) {
  EXPECT_EQ(rate_unit("rad"), "rad/s");
  EXPECT_EQ(rate_unit("m"), "m/s");
  EXPECT_EQ(rate_unit("m/s"), "m/s^2");
  EXPECT_EQ(rate_unit("rad/s"), "rad/s^2");
  EXPECT_EQ(rate_unit("m/s^2"), "m/s^3");
  EXPECT_EQ(rate_unit(""), "1/s");
  EXPECT_EQ(rate_unit("N"), "N/s");
}
