// The Fiala (core/vehicle/fiala.hpp) and linear (core/vehicle/linear_tire.hpp) tire laws: their
// closed forms written out independently here, continuity at the critical slips, the friction
// circle of the linear law, and derivatives by automatic differentiation.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>

#include "vehicle/fiala.hpp"
#include "vehicle/linear_tire.hpp"

using namespace codyna;

namespace {

using TmAD = Eigen::AutoDiffScalar<Eigen::VectorXd>;

FialaParameters tm_test_fiala() {
  FialaParameters p;
  p.C_kappa = 80000;
  p.C_alpha = 60000;
  p.mu_max = 1.0;
  p.mu_min = 0.8;
  p.width = 0.2;
  p.rolling_resistance = 0.01;
  p.unloaded_radius = 0.3;
  return p;
}

TireInput<double> tm_test_in(double Fz, double kappa, double alpha) {
  TireInput<double> in;
  in.Fz = Fz;
  in.kappa = kappa;
  in.alpha = alpha;
  in.Vx = 20;
  return in;
}

}  // namespace

// Fiala against the formulas of Adams and Chrono, written out for each regime.
TEST(TireModels, FialaClosedForm) {
  const FialaParameters p = tm_test_fiala();
  const double Fz = 4000;
  for (double kappa : {-0.5, -0.05, -0.01, 0.0, 0.004, 0.02, 0.2, 0.9})
    for (double alpha : {-0.6, -0.1, -0.02, 0.0, 0.01, 0.05, 0.3}) {
      const TireForces<double> f = fiala_tire(p, tm_test_in(Fz, kappa, alpha));
      const double S = std::min(1.0, std::sqrt(kappa * kappa + std::tan(alpha) * std::tan(alpha)));
      const double mu = 1.0 - 0.2 * S;
      const double kc = mu * Fz / (2 * 80000), ac = std::atan(3 * mu * Fz / 60000);
      const double sk = (kappa > 0) - (kappa < 0), sa = (alpha > 0) - (alpha < 0);
      const double Fx = std::abs(kappa) < kc ? 80000 * kappa
                                             : sk * (mu * Fz - (mu * Fz) * (mu * Fz) / (4 * std::abs(kappa) * 80000));
      double Fy, Mz;
      if (std::abs(alpha) <= ac) {
        const double H = 1 - 60000 * std::abs(std::tan(alpha)) / (3 * mu * Fz);
        Fy = -mu * Fz * (1 - H * H * H) * sa;
        Mz = mu * Fz * 0.2 * (1 - H) * H * H * H * sa;
      } else {
        Fy = -mu * Fz * sa;
        Mz = 0;
      }
      EXPECT_NEAR(f.Fx, Fx, 1e-9 * Fz) << kappa << " " << alpha;
      EXPECT_NEAR(f.Fy, Fy, 1e-9 * Fz) << kappa << " " << alpha;
      EXPECT_NEAR(f.Mz, Mz, 1e-9 * Fz) << kappa << " " << alpha;
      EXPECT_NEAR(f.My, -0.01 * Fz, 1e-12);
      EXPECT_NEAR(f.mux, mu, 1e-15);
      EXPECT_EQ(f.Kxk, 80000);
      EXPECT_EQ(f.Kya, -60000);
    }
  // small slips: the linear law; saturation at mu Fz
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, 0, 1e-6)).Fy, -60000 * 1e-6, 1e-6);
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, 0, 1.2)).Fy, -0.8 * Fz, 1e-9);
  // a negative load is no load
  EXPECT_EQ(fiala_tire(p, tm_test_in(-10, 0.1, 0.1)).Fy, 0.0);
}

// Continuous through the critical slips (where the regimes meet).
TEST(TireModels, FialaIsContinuousAtTheCriticalSlips) {
  FialaParameters p = tm_test_fiala();
  p.mu_min = p.mu_max;  // constant mu: the critical slips are fixed numbers
  const double Fz = 3000, mu = 1.0;
  const double kc = mu * Fz / (2 * p.C_kappa), ac = std::atan(3 * mu * Fz / p.C_alpha);
  const double e = 1e-9;
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, kc - e, 0)).Fx, fiala_tire(p, tm_test_in(Fz, kc + e, 0)).Fx, 1e-3);
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, kc, 0)).Fx, mu * Fz / 2, 1e-6);
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, 0, ac - e)).Fy, fiala_tire(p, tm_test_in(Fz, 0, ac + e)).Fy, 1e-3);
  EXPECT_NEAR(fiala_tire(p, tm_test_in(Fz, 0, ac - e)).Mz, 0.0, 1e-3);
}

// Automatic differentiation: the slopes at zero slip are C_kappa and -C_alpha, and elsewhere the
// derivatives equal central differences.
TEST(TireModels, FialaAutodiff) {
  const FialaParameters p = tm_test_fiala();
  TireInput<TmAD> in;
  in.Fz = TmAD(4000);
  in.kappa = TmAD(0.0, Eigen::VectorXd::Unit(2, 0));
  in.alpha = TmAD(0.0, Eigen::VectorXd::Unit(2, 1));
  in.Vx = TmAD(20);
  TireForces<TmAD> f = fiala_tire(p, in);
  EXPECT_NEAR(f.Fx.derivatives()[0], 80000, 1e-9);
  EXPECT_NEAR(f.Fy.derivatives()[1], -60000, 1e-6);
  in.kappa.value() = 0.003;
  in.alpha.value() = 0.04;
  f = fiala_tire(p, in);
  const double h = 1e-6;
  const double dFy = (fiala_tire(p, tm_test_in(4000, 0.003, 0.04 + h)).Fy - fiala_tire(p, tm_test_in(4000, 0.003, 0.04 - h)).Fy) / (2 * h);
  const double dMz = (fiala_tire(p, tm_test_in(4000, 0.003, 0.04 + h)).Mz - fiala_tire(p, tm_test_in(4000, 0.003, 0.04 - h)).Mz) / (2 * h);
  const double dFyk = (fiala_tire(p, tm_test_in(4000, 0.003 + h, 0.04)).Fy - fiala_tire(p, tm_test_in(4000, 0.003 - h, 0.04)).Fy) / (2 * h);
  EXPECT_NEAR(f.Fy.derivatives()[1], dFy, 1e-6 * std::abs(dFy));
  EXPECT_NEAR(f.Mz.derivatives()[1], dMz, 1e-6 * std::abs(dMz));
  EXPECT_NEAR(f.Fy.derivatives()[0], dFyk, 1e-6 * std::abs(dFyk));
}

// The linear law is exact, with its friction circle, and its derivatives are the stiffnesses.
TEST(TireModels, LinearLawExact) {
  LinearTireParameters p;
  p.C_kappa = 70000;
  p.C_alpha = 50000;
  p.C_gamma = 3000;
  p.trail = 0.03;
  TireInput<double> in = tm_test_in(4000, 0.01, 0.02);
  in.gamma = 0.05;
  TireForces<double> f = linear_tire(p, in);
  EXPECT_EQ(f.Fx, 70000 * 0.01);
  EXPECT_EQ(f.Fy, -50000 * 0.02 + 3000 * 0.05);
  EXPECT_EQ(f.Mz, -0.03 * f.Fy);
  EXPECT_EQ(f.Kxk, 70000);
  EXPECT_EQ(f.Kya, -50000);
  // friction circle: (700, -850) has magnitude 1101.1; limited to mu Fz = 400 N
  p.mu = 0.1;
  f = linear_tire(p, in);
  EXPECT_NEAR(std::hypot(f.Fx, f.Fy), 400, 1e-9);
  EXPECT_NEAR(f.Fx / f.Fy, 700.0 / -850.0, 1e-12);
  p.mu = 1.0;  // inside the circle: unchanged
  EXPECT_EQ(linear_tire(p, in).Fx, 700);
  // derivatives
  TireInput<TmAD> a;
  a.Fz = TmAD(4000);
  a.kappa = TmAD(0.01, Eigen::VectorXd::Unit(3, 0));
  a.alpha = TmAD(0.02, Eigen::VectorXd::Unit(3, 1));
  a.gamma = TmAD(0.05, Eigen::VectorXd::Unit(3, 2));
  a.Vx = TmAD(20);
  p.mu = 0;
  const TireForces<TmAD> g = linear_tire(p, a);
  EXPECT_EQ(g.Fx.derivatives()[0], 70000);
  EXPECT_EQ(g.Fy.derivatives()[1], -50000);
  EXPECT_EQ(g.Fy.derivatives()[2], 3000);
  EXPECT_NEAR(g.Mz.derivatives()[1], 0.03 * 50000, 1e-9);
}
