// The index-3 augmented Lagrangian integrator (simulation/alf.cpp) on the hard closed loops.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "dynamics/prepare.hpp"
#include "model/errors.hpp"
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

// A02 with N = 4 over 2.2 s (the cranks through the flat position twice), against the exact
// 1-DOF motion: at fixed steps the error falls as h^2 (the trapezoidal rule) and the loops
// stay closed; the singular positions cost nothing special.
TEST(Alf, A02FourBarsSecondOrderAgainstExact) {
  const AlfA02 coarse = alf_a02(4, 2e-3, 2.2), fine = alf_a02(4, 1e-3, 2.2);
  ASSERT_TRUE(coarse.completed && fine.completed);
  EXPECT_LT(fine.err, 4e-6);  // measured 2.2e-6 (h = 2e-3: 8.7e-6)
  EXPECT_GT(coarse.err / fine.err, 3.5);  // h^2: 4
  EXPECT_LT(coarse.err / fine.err, 4.5);
  EXPECT_LT(std::max(coarse.drift, fine.drift), 1e-8);
}

// error control: tighter tolerances, smaller errors, more steps
TEST(Alf, A02FourBarsErrorControl) {
  const double alpha = IntegratorSettings().alf_penalty;
  const AlfA02 loose = alf_a02(4, 0, 2.2, alpha, 1e-5), tight = alf_a02(4, 0, 2.2, alpha, 1e-7);
  ASSERT_TRUE(loose.completed && tight.completed);
  EXPECT_LT(tight.err, 1.5e-5);  // measured 6.9e-6 (1e-5: 3.5e-4)
  EXPECT_LT(tight.err, loose.err);
  EXPECT_GT(tight.steps, loose.steps);
}

// bad settings and models alf does not take are refused, naming the field or the reason
TEST(Alf, Refusals) {
  const Model m = compile(iftomm::a02_spec(2));
  auto refusal = [&](const Model& model, const IntegratorSettings& is) {
    SimulationOptions o;
    o.integrator = is;
    o.integrator.method = "alf";
    o.t_end = 0.1;
    try {
      const SimulationResult r = simulate(model, nullptr, nullptr, o);
      return r.completed ? std::string() : r.failure;
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  };
  IntegratorSettings is;
  is.alf_penalty = 0;
  EXPECT_NE(refusal(m, is).find("alf_penalty"), std::string::npos) << refusal(m, is);
  is.alf_penalty = -1e8;
  EXPECT_NE(refusal(m, is).find("alf_penalty"), std::string::npos);
  is = IntegratorSettings();
  is.alf_iterations = 0;
  EXPECT_NE(refusal(m, is).find("alf_iterations"), std::string::npos) << refusal(m, is);
  EXPECT_EQ(refusal(m, IntegratorSettings()), "");
  // a free body: quaternions are not additive coordinates
  ModelSpec ball;
  BodySpec b;
  b.name = "ball";
  b.mass = 1.0;
  b.inertia = Eigen::Matrix3d::Identity() * 0.1;
  ball.bodies.push_back(b);
  JointSpec j;
  j.name = "float";
  j.type = JointType::Free;
  j.parent = "ground";
  j.child = "ball";
  ball.joints.push_back(j);
  EXPECT_NE(refusal(compile(ball), IntegratorSettings()).find("free joints"), std::string::npos);
  // the model file's solver: an alf step longer than the run
  ModelSpec spec = iftomm::a02_spec(2);
  spec.solver.integrator = "alf";
  spec.solver.t_end = 1.0;
  spec.solver.max_step = 2.0;
  try {
    compile(spec);
    ADD_FAILURE() << "an alf max_step longer than t_end was taken";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/solver/max_step"), std::string::npos) << e.what();
  }
  spec.solver.max_step = 0.5;
  EXPECT_NO_THROW(compile(spec));
}

TEST(Alf, Explore) {
  const char* env = std::getenv("ALF_EXPLORE");
  if (!env) GTEST_SKIP();
  const int N = std::atoi(env);
  const double alpha = std::getenv("ALF_ALPHA") ? std::atof(std::getenv("ALF_ALPHA")) : 1e8;
  if (!std::getenv("ALF_NOFIXED") && !std::getenv("ALF_H"))
    for (double h : {1e-2, 5e-3, 2e-3, 1e-3, 5e-4}) alf_a02(N, h, 20.0, alpha);
  if (const char* one = std::getenv("ALF_H")) {
    alf_a02(N, std::atof(one), std::getenv("ALF_TEND") ? std::atof(std::getenv("ALF_TEND")) : 20.0, alpha,
            std::getenv("ALF_TOL") ? std::atof(std::getenv("ALF_TOL")) : 1e-6);
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
