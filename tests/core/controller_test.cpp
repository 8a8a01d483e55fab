// Controllers (simulation/controller.hpp): PID anti-windup on a saturating actuator. A PID loop
// (poles -1, -2, -3) on a spring-mass whose force is limited to +-4 N takes a 1 m step (3 N
// hold it there): without anti-windup the integral winds up while the force sits at its limit
// and the block overshoots 23 cm, far beyond the 12.9 cm the unlimited loop overshoots by
// itself; back-calculation (tracking time 0.2 s) does not overshoot at all, conditional
// integration 4.6 cm. While the force is saturated the block follows the closed-form response
// to a constant 4 N, whatever the controller does.
#include "simulation/controller.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

constexpr double kCartMass = 2, kCartSpring = 3, kCartDamping = 0.5, kUmax = 4;

ModelSpec saturating_pi(const std::string& anti_windup, double tracking_time = 0) {
  const std::string text = R"({"name": "slider",
    "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
    "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0]}],
    "effects": [{"name": "spring", "type": "joint_spring_damper", "joint": "x", "stiffness": 3, "damping": 0.5}],
    "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N", "min": -4, "max": 4}],
    "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
    "plant": {"inputs": ["force"], "outputs": ["pos"]},
    "controller": {"type": "pid", "kp": [[19]], "ki": [[12]], "kd": [[11.5]], "operating_point": "initial"},
    "solver": {"integrator": "cvode-bdf", "rtol": 1e-10, "atol": 1e-12, "t_end": 15, "output_step": 0.01},
    "analysis": {"operating_point": "initial",
                 "references": [{"output": "pos", "type": "step", "time": 0, "value": 1}]}})";
  ModelSpec spec = parse_model_spec_text(text, "slider.json");
  spec.analysis.anti_windup = anti_windup;
  spec.analysis.compare_linear = true;  // the linear loop (the same plant: it is linear) beside it
  spec.analysis.tracking_time = tracking_time;
  return spec;
}

// y(t) of m y'' + c y' + k y = F from rest
double constant_force_response(double F, double t) {
  const double s = kCartDamping / (2 * kCartMass), wd = std::sqrt(kCartSpring / kCartMass - s * s);
  return F / kCartSpring * (1 - std::exp(-s * t) * (std::cos(wd * t) + s / wd * std::sin(wd * t)));
}

struct AwRun {
  double overshoot;      // max y - 1 (m)
  double saturated_for;  // s, first stretch at the limit
  double settle;         // s, last time |y - 1| > 1 cm
  double worst_closed_form;  // max |y - closed form| while saturated
  SimulationResult r;
};

AwRun run_controller(const ModelSpec& spec) {
  const Model m = study_model(spec);
  const StudySimulation setup = study_simulation(m);
  AwRun out{0, 0, 0, 0, study_simulate(m, setup)};
  const SimulationResult& r = out.r;
  EXPECT_TRUE(r.completed) << r.failure;
  int k = 0;
  while (k < r.samples() && r.u(k, 0) == kUmax) {
    out.worst_closed_form = std::max(out.worst_closed_form, std::abs(r.y(k, 0) - constant_force_response(kUmax, r.t[k])));
    ++k;
  }
  out.saturated_for = r.t[k];
  for (int i = 0; i < r.samples(); ++i) {
    out.overshoot = std::max(out.overshoot, r.y(i, 0) - 1);
    if (std::abs(r.y(i, 0) - 1) > 0.01) out.settle = r.t[i];
  }
  return out;
}

}  // namespace

TEST(PidAntiWindup, SaturatingPiOvershootsOnlyWithoutAntiWindup) {
  const AwRun none = run_controller(saturating_pi("none"));
  const AwRun back = run_controller(saturating_pi("back_calculation", 0.2));
  const AwRun cond = run_controller(saturating_pi("conditional"));
  for (const auto& [name, x] : {std::pair{"none", &none}, std::pair{"back_calculation", &back}, std::pair{"conditional", &cond}})
    std::printf("%-17s overshoot %.6f m, saturated for %.3f s, settled (1 cm) at %.2f s, max |y - closed form| while saturated %.2g\n",
                name, x->overshoot, x->saturated_for, x->settle, x->worst_closed_form);
  // while the force is at its 4 N limit the block is the closed-form spring-mass, in all three runs
  for (const AwRun* x : {&none, &back, &cond}) {
    EXPECT_GT(x->saturated_for, 0.3);
    EXPECT_LT(x->worst_closed_form, 1e-9);
  }
  // the same loop without limits overshoots by itself (its zero at -ki/kp): y = 1 + 1.75 e^-t
  // - 6.5 e^-2t + 3.75 e^-3t peaks at e^-t = (13 - sqrt(90.25)) / 22.5
  const double x = (13 - std::sqrt(90.25)) / 22.5, linear = 1.75 * x - 6.5 * x * x + 3.75 * x * x * x;
  std::printf("unsaturated loop (closed form): overshoot %.6f m\n", linear);
  // windup: the integral of r - y over the saturated stretch adds to that; anti-windup removes it
  EXPECT_NEAR(none.overshoot, 0.2296, 1e-3);  // measured 0.229597
  EXPECT_NEAR(back.overshoot, 0.0, 1e-4);     // measured 0: no overshoot at all
  EXPECT_NEAR(cond.overshoot, 0.0462, 1e-3);  // measured 0.046226
  EXPECT_GT(none.overshoot, linear + 0.09);
  EXPECT_LT(std::max(back.overshoot, cond.overshoot), linear - 0.08);
  EXPECT_GT(none.settle, 1.25 * std::max(back.settle, cond.settle));
  // the linear comparison runs the same saturation and anti-windup (RK4, 20 substeps per 0.01 s):
  // the plant is linear, so it agrees with the nonlinear run_controller up to RK4's error where the rates
  // jump (measured 1.3e-8, 3.2e-8 and 1.2e-5 m; with half the step 6.9e-10, 1.8e-9, 1.6e-6 m:
  // converging, conditional integration's switched integral the slowest)
  const double bound[3] = {1e-7, 1e-7, 3e-5};
  int i = 0;
  for (const AwRun* x : {&none, &back, &cond}) {
    ASSERT_EQ(x->r.y_linear.rows(), x->r.samples());
    const double gap = (x->r.y - x->r.y_linear).cwiseAbs().maxCoeff();
    std::printf("max |y - y_linear| %.3g m\n", gap);
    EXPECT_LT(gap, bound[i++]);
  }
  // conditional integration holds the integral exactly while the force pushes against its max
  const SimulationResult& c = cond.r;
  for (int k = 0; k < c.samples() && c.u(k, 0) == kUmax; ++k) EXPECT_EQ(c.xc(k, 0), 0.0) << c.t[k];
  // all three settle on the target: the steady force is k * 1 m = 3 N
  for (const AwRun* x : {&none, &back, &cond}) {
    const int N = x->r.samples();
    EXPECT_NEAR(x->r.y(N - 1, 0), 1.0, 1e-3);
    EXPECT_NEAR(x->r.u(N - 1, 0), kCartSpring * x->r.y(N - 1, 0), 1e-3);
  }
}

// Without saturation the anti-windup does nothing: the same run_controller to the integrator's precision
TEST(PidAntiWindup, NoEffectWhileNothingSaturates) {
  ModelSpec a = saturating_pi("none"), b = saturating_pi("back_calculation", 0.2), c = saturating_pi("conditional");
  for (ModelSpec* s : {&a, &b, &c}) s->analysis.references[0].value = 0.1;  // 1.9 N at most: never at 8 N
  const AwRun ra = run_controller(a), rb = run_controller(b), rc = run_controller(c);
  EXPECT_LT(ra.r.u.col(0).cwiseAbs().maxCoeff(), kUmax);
  EXPECT_LT((ra.r.y - rb.r.y).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ra.r.y - rc.r.y).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(PidAntiWindup, BadChoicesAreNamed) {
  try {
    study_simulation(study_model(saturating_pi("back_calculation")));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/tracking_time");
    EXPECT_NE(std::string(e.what()).find("tracking time > 0"), std::string::npos) << e.what();
  }
  ModelSpec p = saturating_pi("conditional");
  p.controller.ki = Eigen::MatrixXd();
  try {
    study_simulation(study_model(p));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/anti_windup");
    EXPECT_NE(std::string(e.what()).find("no integral action"), std::string::npos) << e.what();
  }
  ModelSpec lqr = saturating_pi("conditional");
  lqr.analysis.controller = "lqr";
  try {
    study_simulation(study_model(lqr));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/anti_windup");
    EXPECT_NE(std::string(e.what()).find("applies to a PID controller"), std::string::npos) << e.what();
  }
}
