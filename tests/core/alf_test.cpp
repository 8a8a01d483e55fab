// The index-3 augmented Lagrangian integrator (simulation/alf.cpp) on the hard closed loops.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "dynamics/prepare.hpp"
#include "models/iftomm_a02.hpp"
#include "simulation/simulator.hpp"

namespace codyna {
namespace {

struct AlfA02 {
  bool completed = false;
  double err = 0, drift = 0, wall = 0;
  long steps = 0, iterations = 0;
};

// h > 0: fixed steps of h; h = 0: error control at rtol = atol = tol
AlfA02 alf_a02(int N, double h, double t_end, double alpha = 1e8, double tol = 1e-6) {
  const Model m = compile(iftomm::a02_spec(N));
  SimulationOptions o;
  o.integrator.method = "alf";
  o.integrator.max_step = h;
  o.integrator.alf_fixed_step = h > 0;
  o.integrator.rtol = o.integrator.atol = tol;
  o.integrator.alf_penalty = alpha;
  o.t_end = t_end;
  o.output_step = 0.01;
  const auto t0 = std::chrono::steady_clock::now();
  const SimulationResult r = simulate(m, nullptr, nullptr, o);
  AlfA02 a;
  a.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  a.completed = r.completed;
  const Eigen::VectorXd exact = iftomm::a02_exact(N, r.t);
  for (int k = 0; k <= N; ++k) {  // every crank turns as phi(t)
    const int c = m.joints[static_cast<std::size_t>(m.find_joint("pivot" + std::to_string(k)))].idx_q;
    for (int i = 0; i < r.samples(); ++i) a.err = std::max(a.err, std::abs(r.q(i, c) - exact[i]));
  }
  for (int i = 0; i < r.samples(); ++i) a.drift = std::max(a.drift, r.constraint_violation[i]);
  a.steps = r.stats.steps;
  a.iterations = r.stats.nonlinear_iterations;
  std::cout << "alf A02 N = " << N << ", h = " << h << ", tol = " << tol << ", alpha = " << alpha << ": " << (r.completed ? "completed" : r.failure)
            << "; |phi - exact| " << a.err << " rad, max |phi| " << a.drift << "; " << a.steps << " steps, " << a.iterations
            << " iterations, " << a.wall << " s\n";
  return a;
}

TEST(Alf, Explore) {
  const char* env = std::getenv("ALF_EXPLORE");
  if (!env) GTEST_SKIP();
  const int N = std::atoi(env);
  const double alpha = std::getenv("ALF_ALPHA") ? std::atof(std::getenv("ALF_ALPHA")) : 1e8;
  if (!std::getenv("ALF_NOFIXED"))
    for (double h : {1e-2, 5e-3, 2e-3, 1e-3, 5e-4}) alf_a02(N, h, 20.0, alpha);
  if (const char* one = std::getenv("ALF_H")) {
    alf_a02(N, std::atof(one), std::getenv("ALF_TEND") ? std::atof(std::getenv("ALF_TEND")) : 20.0, alpha);
    return;
  }
  if (const char* one = std::getenv("ALF_TOL")) {
    alf_a02(N, 0, std::getenv("ALF_TEND") ? std::atof(std::getenv("ALF_TEND")) : 20.0, alpha, std::atof(one));
    return;
  }
  for (double tol : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9}) alf_a02(N, 0, 20.0, alpha, tol);
}

}  // namespace
}  // namespace codyna
