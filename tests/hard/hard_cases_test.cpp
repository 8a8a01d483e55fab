// Hard cases run in the default CTest set (label `hard`, issue 11): long runs whose exact
// invariants must hold at the integrators' default tolerances (rtol 1e-8, atol 1e-10).
//   Bricard (redundant loop, 1 DOF, conservative): 100 s, energy and drift bounded.
//   Double pendulum (chaotic, conservative): 1000 s, energy bounded.
//   Heavy top (spherical joint, quaternion state, fast spin): 100 s, energy and |quaternion|
//   (the SUNDIALS integrators do not renormalize it: 1e-5 after 100 s, measured).
// Bounds are about three times what was measured (printed), so a regression of a few
// times in the integrator setup fails them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "core/test_util.hpp"
#include "simulation/simulator.hpp"

namespace codyna {
namespace {

SimulationOptions options(const std::string& method, double t_end, double output_step) {
  SimulationOptions o;
  o.integrator.method = method;  // default tolerances: rtol 1e-8, atol 1e-10
  o.t_end = t_end;
  o.output_step = output_step;
  return o;
}

struct Drift {
  double energy = 0, constraint = 0;  // max |E - E0| / |E0|, max |phi|
};

Drift drift_of(const SimulationResult& r) {
  Drift d;
  const double E0 = r.kinetic_energy[0] + r.potential_energy[0];
  for (int i = 0; i < r.samples(); ++i) {
    d.energy = std::max(d.energy, std::abs(r.kinetic_energy[i] + r.potential_energy[i] - E0) / std::abs(E0));
    d.constraint = std::max(d.constraint, r.constraint_violation[i]);
  }
  return d;
}

struct Case {
  const char* method;
  double energy_bound, other_bound;  // other: max |phi|, or | |quaternion| - 1 |
};

TEST(Hard, BricardRedundantLoop100s) {
  const Model m = test::load_example("bricard.json");
  ASSERT_EQ(m.dof(), 1);
  ASSERT_FALSE(m.redundant_rows.empty());  // the Bricard mechanism's overconstraint
  for (const Case& c : {Case{"ida", 1.5e-6, 1e-13}, Case{"cvode-bdf", 2e-7, 3e-12}}) {
    const SimulationResult r = simulate(m, nullptr, nullptr, options(c.method, 100.0, 0.1));
    ASSERT_TRUE(r.completed) << c.method << ": " << r.failure;
    const Drift d = drift_of(r);
    std::cout << "Bricard 100 s " << c.method << ": |dE|/E0 " << d.energy << ", max |phi| " << d.constraint << ", "
              << r.stats.steps << " steps\n";
    EXPECT_LT(d.energy, c.energy_bound) << c.method;
    EXPECT_LT(d.constraint, c.other_bound) << c.method;
  }
}

TEST(Hard, DoublePendulum1000s) {
  const Model m = test::load_example("double_pendulum.json");
  for (const Case& c : {Case{"ida", 5e-6, 0}, Case{"cvode-bdf", 3e-6, 0}}) {
    const SimulationResult r = simulate(m, nullptr, nullptr, options(c.method, 1000.0, 0.1));
    ASSERT_TRUE(r.completed) << c.method << ": " << r.failure;
    const Drift d = drift_of(r);
    std::cout << "double pendulum 1000 s " << c.method << ": |dE|/E0 " << d.energy << ", " << r.stats.steps
              << " steps\n";
    EXPECT_LT(d.energy, c.energy_bound) << c.method;
    EXPECT_EQ(d.constraint, 0.0);  // a tree
  }
}

TEST(Hard, HeavyTop100s) {
  const Model m = test::load_example("heavy_top.json");
  ASSERT_EQ(m.nbodies, 2);  // ground and the top
  const JointModel& top = m.joints[1];
  ASSERT_EQ(top.nq, 4);  // a unit quaternion
  for (const Case& c : {Case{"ida", 1.2e-4, 3e-5}, Case{"cvode-bdf", 4e-5, 1e-5}}) {
    const SimulationResult r = simulate(m, nullptr, nullptr, options(c.method, 100.0, 0.1));
    ASSERT_TRUE(r.completed) << c.method << ": " << r.failure;
    const Drift d = drift_of(r);
    double norm = 0;
    for (int i = 0; i < r.samples(); ++i) norm = std::max(norm, std::abs(r.q.row(i).segment(top.idx_q, 4).norm() - 1));
    std::cout << "heavy top 100 s " << c.method << ": |dE|/E0 " << d.energy << ", | |quat| - 1 | " << norm << ", "
              << r.stats.steps << " steps\n";
    EXPECT_LT(d.energy, c.energy_bound) << c.method;
    EXPECT_LT(norm, c.other_bound) << c.method;
  }
}

// IFToMM A02, N = 4 (tests/core/iftomm_test.cpp holds cvode-bdf to the exact motion): IDA at
// its default tolerances keeps to the rigid branch through all 20 singular passages now that
// the projection threshold follows atol (measured defect 9e-11 rad; iftomm_test.cpp's note
// says ida left the branch before, not re-measured here).
// Every integrator, and N = 40: tests/hard/singular_stiff_test.cpp.
TEST(Hard, A02FourBarsIdaStaysOnTheRigidBranch) {
  const Model m = test::load_example("iftomm_a02_four_bars.json");
  const int N = 4;
  const SimulationResult r = simulate(m, nullptr, nullptr, options("ida", 20.0, 0.01));
  ASSERT_TRUE(r.completed) << r.failure;
  const int phi = m.joints[m.find_joint("pivot0")].idx_q;
  double rigid = 0;
  int passages = 0;
  for (int i = 0; i < r.samples(); ++i) {
    for (int c = 1; c <= N; ++c)
      rigid = std::max(rigid, std::abs(r.q(i, m.joints[m.find_joint("pivot" + std::to_string(c))].idx_q) - r.q(i, phi)));
    if (i > 0 && std::cos(r.q(i, phi)) * std::cos(r.q(i - 1, phi)) <= 0) ++passages;
  }
  const Drift d = drift_of(r);
  std::cout << "A02 N = 4 ida 20 s: " << passages << " passages, rigid-rotation defect " << rigid << " rad, |dE|/E0 "
            << d.energy << ", max |phi| " << d.constraint << "\n";
  EXPECT_EQ(passages, 20);
  EXPECT_LT(rigid, 1e-8);
  EXPECT_LT(d.energy, 4e-6);
  EXPECT_LT(d.constraint, 3e-11);
}

}  // namespace
}  // namespace codyna
