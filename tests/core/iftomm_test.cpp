// IFToMM multibody benchmarks (Gonzalez, Dopico, Lugris, Cuadrado, "A benchmarking system
// for MBS simulation software", Multibody Syst. Dyn. 16, 2006; docs/BENCHMARKS.md section 2)
// checked against independent references: A01 against its closed-form solution (Jacobi
// elliptic functions, computed here), A05 against exact invariants (energy decay, angular
// momentum about the shaft, symmetry) and between integrators.
#include <chrono>
#include <cmath>
#include <iostream>

#include "dynamics/crba.hpp"
#include "simulation/simulator.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

constexpr double g = 9.81;

SimulationOptions options(const std::string& method, double t_end, double rtol, double atol, double output_step) {
  SimulationOptions o;
  o.integrator.method = method;
  o.integrator.rtol = rtol;
  o.integrator.atol = atol;
  o.t_end = t_end;
  o.output_step = output_step;
  return o;
}

// ---------------------------------------------------------------------------------------
// Complete elliptic integral and Jacobi sn for the parameter m = k^2, 0 <= m < 1, both by the
// arithmetic-geometric mean (Abramowitz and Stegun 17.6 and 16.4, "descending Landen
// transformation"): a0 = 1, b0 = sqrt(1 - m), c0 = sqrt(m); a_n = (a + b)/2, b_n = sqrt(a b),
// c_n = (a - b)/2 until c_N vanishes; K = pi / (2 a_N). For sn: phi_N = 2^N a_N u, then
// phi_{n-1} = (phi_n + asin(c_n / a_n sin phi_n)) / 2 down to phi_0, and sn(u | m) = sin phi_0.
struct Agm {
  std::vector<double> a, c;
  explicit Agm(double m) {
    double an = 1, bn = std::sqrt(1 - m);
    a = {an};
    c = {std::sqrt(m)};
    while (c.back() > 1e-17 && a.size() < 40) {
      const double a1 = (an + bn) / 2, c1 = (an - bn) / 2;
      bn = std::sqrt(an * bn);
      an = a1;
      a.push_back(an);
      c.push_back(c1);
    }
  }
  double K() const { return M_PI / (2 * a.back()); }
  double sn(double u) const {
    const int N = static_cast<int>(a.size()) - 1;
    double phi = std::ldexp(a[N] * u, N);
    for (int n = N; n >= 1; --n) phi = (phi + std::asin(c[n] / a[n] * std::sin(phi))) / 2;
    return std::sin(phi);
  }
};

// ---------------------------------------------------------------------------------------
// A01: simple pendulum released from the horizontal. Exact solution, theta from the downward
// vertical: theta(t) = 2 asin(k sn(K - w0 t, k)), k = sin(theta0 / 2) = sin(pi/4), w0 = sqrt(g/L),
// so the mass is at x = L sin theta, y = -L cos theta; period 4 K / w0.
struct A01Exact {
  static constexpr double L = 1.0;
  double k = std::sin(M_PI / 4), w0 = std::sqrt(g / L);
  Agm agm{k * k};
  double K = agm.K();
  double theta(double t) const { return 2 * std::asin(k * agm.sn(K - w0 * t)); }
  Eigen::Vector2d position(double t) const { return {L * std::sin(theta(t)), -L * std::cos(theta(t))}; }
  double period() const { return 4 * K / w0; }
};

TEST(Iftomm, A01ClosedFormMatchesThePublishedNumbers) {
  // the reference itself: K(sin pi/4), the period and the position at t = 1 s as published
  const A01Exact ex;
  EXPECT_NEAR(ex.K, 1.854074677301372, 1e-14);
  EXPECT_NEAR(ex.period(), 2.36784194757624, 1e-13);
  EXPECT_NEAR(ex.position(1.0)[0], -0.9862917511319, 1e-12);
  EXPECT_NEAR(ex.position(1.0)[1], -0.1650108531255, 1e-12);
  EXPECT_NEAR(ex.theta(0.0), M_PI / 2, 1e-14);  // released from the horizontal at x = +1
  // sn against its known values: sn(0) = 0, sn(K) = 1, and the m = 0 limit sn = sin
  EXPECT_NEAR(ex.agm.sn(0.0), 0.0, 1e-15);
  EXPECT_NEAR(ex.agm.sn(ex.K), 1.0, 1e-15);
  EXPECT_NEAR(Agm(0.0).sn(0.7), std::sin(0.7), 1e-15);
}

TEST(Iftomm, A01PendulumFollowsTheExactSolution) {
  const Model m = test::load_example("iftomm_a01_pendulum.json");
  ASSERT_EQ(m.dof(), 1);
  ASSERT_EQ(m.plant_outputs.size(), 2u);  // x, y of the mass
  const A01Exact ex;
  for (const char* method : {"cvode-bdf", "ida", "cvode-adams", "arkode"}) {
    const SimulationResult r = simulate(m, nullptr, nullptr, options(method, 10.0, 1e-10, 1e-12, 0.01));
    ASSERT_TRUE(r.completed) << method << ": " << r.failure;
    ASSERT_EQ(r.samples(), 1001);
    // the published point: t = 1 s
    ASSERT_NEAR(r.t[100], 1.0, 1e-12);
    EXPECT_NEAR(r.y(100, 0), -0.9862917511319, 1e-7) << method;
    EXPECT_NEAR(r.y(100, 1), -0.1650108531255, 1e-7) << method;
    // the whole 10 s trajectory at the output times
    double err = 0;
    for (int i = 0; i < r.samples(); ++i) {
      const Eigen::Vector2d p = ex.position(r.t[i]);
      err = std::max({err, std::abs(r.y(i, 0) - p[0]), std::abs(r.y(i, 1) - p[1])});
    }
    EXPECT_LT(err, 1e-6) << method;
    std::cout << "A01 " << method << " rtol 1e-10: |x, y - exact| at t = 1: "
              << std::abs(r.y(100, 0) - ex.position(1)[0]) << ", " << std::abs(r.y(100, 1) - ex.position(1)[1])
              << "; max over 10 s " << err << "; "
              << r.stats.steps << " steps, " << r.stats.wall_time << " s\n";
  }
}

TEST(Iftomm, A01PendulumPeriod) {
  // sample at multiples of the exact period: the pendulum is back at rest at x = +1 each time.
  // Near the turning point the angular rate is v(T + dt) = -(g/L) dt, so |v| / g bounds the
  // period error dt. At rtol 1e-10 the integrator's own phase error after 4 periods scatters
  // between about -3e-8 and 3e-8 s as the rounding of f or rtol (0.8e-10 .. 1.25e-10) changes
  // (measured), so the bound is 5e-8 s: 5e-9 of the 9.5 s simulated.
  const Model m = test::load_example("iftomm_a01_pendulum.json");
  const double T = 2.36784194757624;
  const SimulationResult r = simulate(m, nullptr, nullptr, options("cvode-bdf", 4 * T, 1e-10, 1e-12, T / 100));
  ASSERT_TRUE(r.completed) << r.failure;
  ASSERT_EQ(r.samples(), 401);
  for (int n = 1; n <= 4; ++n) {
    const int i = 100 * n;
    ASSERT_NEAR(r.t[i], n * T, 1e-12);
    const double dt = r.v(i, 0) / g;  // time from the turning point to the sample
    EXPECT_LT(std::abs(dt), 5e-8) << "period " << n;
    EXPECT_NEAR(r.y(i, 0), 1.0, 1e-10) << "period " << n;
    EXPECT_NEAR(r.y(i, 1), 0.0, 1e-7) << "period " << n;
    if (n == 4) std::cout << "A01 after 4 periods: time off the turning point " << dt << " s\n";
  }
}

// ---------------------------------------------------------------------------------------
// A05: stiff flyball governor (our geometry, see the model's description): shaft, slider and
// two arms, a tree of 4 DOF; the couplers are spring-dampers k = 8e5, c = 4e4.
struct Flyball {
  Model m = test::load_example("iftomm_a05_flyball.json");
  int spin = m.joints[m.find_joint("spin")].idx_v;
  // generalized momentum of the shaft angle: (M(q) v)_spin = angular momentum of the whole
  // system about the (vertical) shaft axis
  double shaft_momentum(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
    Data d(m);
    crba(m, d, q);
    return d.M.row(spin).dot(v);
  }
};

TEST(Iftomm, A05FlyballModel) {
  const Flyball f;
  const Model& m = f.m;
  EXPECT_EQ(m.nq, 4);
  EXPECT_EQ(m.dof(), 4);
  EXPECT_EQ(m.nc, 0);
  ASSERT_EQ(m.springs.size(), 2u);
  EXPECT_NEAR(m.v0[f.spin], 2 * M_PI, 1e-15);
  // springs at rest length, slider at 0.5, arms 30 deg below the horizontal, mirror images
  const SimulationResult r = simulate(m, nullptr, nullptr, options("cvode-bdf", 0.01, 1e-8, 1e-10, 0.01));
  ASSERT_TRUE(r.completed) << r.failure;
  EXPECT_NEAR(r.y(0, 0), 0.5, 1e-15);  // slider_y
  EXPECT_NEAR(r.y(0, 2), 0.5, 1e-15);  // spring lengths
  EXPECT_NEAR(r.y(0, 3), 0.5, 1e-15);
  Data d(m);
  crba(m, d, m.q0);
  for (const char* arm : {"right_arm", "left_arm"}) {
    const int b = m.find_body(arm);
    const Eigen::Vector3d tip = d.oMi[b].act_point(Eigen::Vector3d(1, 0, 0));
    EXPECT_NEAR(std::abs(tip.x()), std::cos(M_PI / 6), 1e-15) << arm;
    EXPECT_NEAR(tip.y(), 1 - std::sin(M_PI / 6), 1e-15) << arm;
  }
  // initial angular momentum about the shaft: 2 pi (I_shaft + I_slider + 2 I_arm about y)
  const double I_arm = 5e-6 * std::pow(std::sin(M_PI / 6), 2) + 0.09575721698113207 * std::pow(std::cos(M_PI / 6), 2) +
                       5.3 * std::pow(0.9716981132075473 * std::cos(M_PI / 6), 2);
  EXPECT_NEAR(f.shaft_momentum(m.q0, m.v0), 2 * M_PI * (5e-6 + 0.005 + 2 * I_arm), 1e-12);
}

TEST(Iftomm, A05FlyballStiffInvariants) {
  const Flyball f;
  const Model& m = f.m;
  const double t_end = 2.0;
  const SimulationResult r = simulate(m, nullptr, nullptr, options("cvode-bdf", t_end, 1e-8, 1e-10, 0.01));
  ASSERT_TRUE(r.completed) << r.failure;
  // a tree: no constraints to drift from
  EXPECT_EQ(*std::max_element(r.constraint_violation.begin(), r.constraint_violation.end()), 0.0);
  // mechanical energy (kinetic + gravity + springs) never increases: the only non-conservative
  // forces are the dampers, which dissipate c (dL/dt)^2 >= 0
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  double rise = 0, E_prev = E0;
  for (int i = 1; i < r.samples(); ++i) {
    const double E = r.kinetic_energy[i] + r.potential_energy[i];
    rise = std::max(rise, E - E_prev);
    E_prev = E;
  }
  EXPECT_LT(rise, 1e-7 * std::abs(E0));
  EXPECT_LT(E_prev, E0);  // something was dissipated
  // angular momentum about the shaft axis: no torque on the shaft coordinate and T, V do not
  // depend on the shaft angle, so (M v)_spin is conserved
  const double p0 = f.shaft_momentum(r.q.row(0).transpose(), r.v.row(0).transpose());
  double p_err = 0;
  for (int i = 0; i < r.samples(); ++i)
    p_err = std::max(p_err, std::abs(f.shaft_momentum(r.q.row(i).transpose(), r.v.row(i).transpose()) - p0));
  EXPECT_LT(p_err, 1e-6 * p0);
  // mirror symmetry: both arms move alike
  const int right = m.joints[m.find_joint("right_pin")].idx_q, left = m.joints[m.find_joint("left_pin")].idx_q;
  const double asym = (r.q.col(right) - r.q.col(left)).cwiseAbs().maxCoeff();
  EXPECT_LT(asym, 1e-10);
  std::cout << "A05 cvode-bdf 2 s: energy " << E0 << " -> " << E_prev << " J (largest rise " << rise
            << "), |p - p0| / p0 = " << p_err / p0 << ", arms differ by " << asym << " rad, " << r.stats.steps
            << " steps, " << r.stats.wall_time << " s\n";
}

TEST(Iftomm, A05FlyballImplicitBeatsExplicit) {
  const Flyball f;
  const double t_end = 2.0;
  const SimulationResult bdf = simulate(f.m, nullptr, nullptr, options("cvode-bdf", t_end, 1e-8, 1e-10, 0.01));
  const SimulationResult ida = simulate(f.m, nullptr, nullptr, options("ida", t_end, 1e-8, 1e-10, 0.01));
  const SimulationResult erk = simulate(f.m, nullptr, nullptr, options("arkode", t_end, 1e-8, 1e-10, 0.01));
  for (const SimulationResult* r : {&bdf, &ida, &erk}) ASSERT_TRUE(r->completed) << r->failure;
  // the three agree on the reference quantity, the slider height
  const double d_bdf = (bdf.y.col(0) - erk.y.col(0)).cwiseAbs().maxCoeff();
  const double d_ida = (ida.y.col(0) - erk.y.col(0)).cwiseAbs().maxCoeff();
  EXPECT_LT(d_bdf, 1e-6);
  EXPECT_LT(d_ida, 1e-6);
  // stiff: the explicit method is held to its stability limit
  EXPECT_LT(bdf.stats.steps * 5, erk.stats.steps);
  EXPECT_LT(ida.stats.steps * 5, erk.stats.steps);
  std::cout << "A05 2 s steps: cvode-bdf " << bdf.stats.steps << " (" << bdf.stats.wall_time << " s), ida "
            << ida.stats.steps << " (" << ida.stats.wall_time << " s), arkode " << erk.stats.steps << " ("
            << erk.stats.wall_time << " s); slider_y vs arkode: cvode-bdf " << d_bdf << ", ida " << d_ida << " m\n";
}

// ---------------------------------------------------------------------------------------
// A02: N four-bar mechanism, N = 4 (the benchmark has N = 40; the same model with N = 40 takes
// 12 s with cvode-bdf): N + 1 cranks and N couplers, a chain of parallelograms, 1 DOF, that
// flattens (singular: the constraint Jacobian loses N of its rank) each time the cranks pass
// the horizontal. Exact motion: all cranks turn together, phi(t), the couplers translate, and
// a phi'' = b g sin(phi) with a = (N+1)/3 + N, b = (N+1)/2 + N, i.e. T = 1/2 a phi'^2 and
// V = b g cos(phi). cvode-bdf at rtol 1e-8 keeps to this branch through all 20 passages. Before
// the singular-aware closed-loop accelerations of the ODE form, tighter tolerances and the
// other integrators left it at one of the singular passages for a branch where some loops fold
// (the model's description tells that history); tests/hard/singular_stiff_test.cpp now holds
// every integrator to the rigid branch at its default tolerance.
TEST(Iftomm, A02FourBarsStayARigidRotationThroughTheSingularPassages) {
  const Model m = test::load_example("iftomm_a02_four_bars.json");
  const int N = 4;
  ASSERT_EQ(m.nbodies, 2 * N + 2);  // 2N + 1 links and ground
  ASSERT_EQ(m.dof(), 1);
  const double a = (N + 1) / 3.0 + N, b = (N + 1) / 2.0 + N;
  const double t_end = 20.0;
  const SimulationResult r = simulate(m, nullptr, nullptr, options("cvode-bdf", t_end, 1e-8, 1e-10, 0.01));
  ASSERT_TRUE(r.completed) << r.failure;
  std::vector<int> crank, pin;
  for (int i = 0; i <= N; ++i) crank.push_back(m.joints[m.find_joint("pivot" + std::to_string(i))].idx_q);
  for (int j = 1; j <= N; ++j) pin.push_back(m.joints[m.find_joint("pin" + std::to_string(j))].idx_q);
  const int phi_v = m.joints[m.find_joint("pivot0")].idx_v;
  // the exact phi(t): the 1-DOF equation by classical RK4 at 1e-4 s (error ~1e-12 rad)
  auto rhs = [&](const Eigen::Vector2d& y) { return Eigen::Vector2d(y[1], b * g * std::sin(y[0]) / a); };
  Eigen::Vector2d y(0.0, -1.0);  // B0 at 1 m/s in +x: phi' = -1 rad/s
  double t = 0;
  double rigid = 0, dT = 0, dV = 0, dE = 0, dphi = 0;
  int passages = 0;
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  for (int i = 0; i < r.samples(); ++i) {
    while (t < r.t[i] - 1e-12) {
      const double h = std::min(1e-4, r.t[i] - t);
      const Eigen::Vector2d k1 = rhs(y), k2 = rhs(y + h / 2 * k1), k3 = rhs(y + h / 2 * k2), k4 = rhs(y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += h;
    }
    const double phi = r.q(i, crank[0]), dphi_dt = r.v(i, phi_v);
    for (int c = 1; c <= N; ++c) rigid = std::max(rigid, std::abs(r.q(i, crank[c]) - phi));      // cranks together
    for (int c = 0; c < N; ++c) rigid = std::max(rigid, std::abs(r.q(i, crank[c]) + r.q(i, pin[c])));  // couplers level
    dT = std::max(dT, std::abs(r.kinetic_energy[i] - 0.5 * a * dphi_dt * dphi_dt));
    dV = std::max(dV, std::abs(r.potential_energy[i] - b * g * std::cos(phi)));
    dE = std::max(dE, std::abs(r.kinetic_energy[i] + r.potential_energy[i] - E0));
    dphi = std::max(dphi, std::abs(phi - y[0]));
    if (i > 0 && std::cos(phi) * std::cos(r.q(i - 1, crank[0])) <= 0) ++passages;
  }
  EXPECT_EQ(passages, 20);  // through the horizontal 20 times
  EXPECT_LT(rigid, 1e-8);
  EXPECT_LT(dT, 5e-5);  // T reaches 130 J; 1.7e-5 measured since the ODE form's singular-aware loop accelerations (under 1e-5 before)
  EXPECT_LT(dV, 1e-8);
  EXPECT_LT(dE, 1e-5 * std::abs(E0));
  EXPECT_LT(dphi, 1e-3);  // phase against the exact solution, after 10 turns (63.5 rad)
  const double drift = *std::max_element(r.constraint_violation.begin(), r.constraint_violation.end());
  EXPECT_LT(drift, 1e-8);
  std::cout << "A02 N = 4 cvode-bdf rtol 1e-8, 20 s: " << passages << " singular passages; rigid-rotation defect "
            << rigid << " rad, |T - T_exact| " << dT << ", |V - V_exact| " << dV << ", |E - E0| " << dE
            << " J, |phi - phi_exact| " << dphi << " rad, drift " << drift << "; " << r.stats.steps << " steps, "
            << r.stats.wall_time << " s\n";
}

}  // namespace
}  // namespace codyna
