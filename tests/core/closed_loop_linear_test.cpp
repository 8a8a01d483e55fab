// The linear closed loop (analysis/closed_loop_linear.hpp) through the study workflow:
// poles against eig(A - B K) and against poles placed by design, a PID loop against its
// closed-form transfer function, the step response against the nonlinear simulation of the
// paper's cart-pendulum, and a disturbance step against the linear prediction.
#include "analysis/closed_loop_linear.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>
#include <algorithm>
#include <complex>
#include <numbers>

#include "control/place.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

using cd = std::complex<double>;

std::vector<cd> sorted(const Eigen::VectorXcd& v) {
  std::vector<cd> s(v.data(), v.data() + v.size());
  std::sort(s.begin(), s.end(), [](cd a, cd b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
  return s;
}

std::vector<cd> poles_of(const ModalAnalysis& m) {
  Eigen::VectorXcd v(static_cast<Eigen::Index>(m.modes.size()));
  for (std::size_t k = 0; k < m.modes.size(); ++k) v[static_cast<Eigen::Index>(k)] = m.modes[k].eigenvalue;
  return sorted(v);
}

double max_distance(const std::vector<cd>& a, const std::vector<cd>& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) d = std::max(d, std::abs(a[k] - b[k]));
  return d;
}

int index_of(const std::vector<std::string>& names, const std::string& n) {
  const auto it = std::find(names.begin(), names.end(), n);
  EXPECT_NE(it, names.end()) << n;
  return static_cast<int>(it - names.begin());
}

ModelSpec cart_lqr() {
  ModelSpec spec = load_model_spec(example_path("cart_pendulum.json"));
  spec.analysis.set = {{"rod_pivot", 0.0}};  // start upright at rest
  spec.analysis.controller = "lqr";
  spec.analysis.q_weights = {10, 100, 1, 1};
  spec.analysis.r_weights = {0.01};
  return spec;
}

// A 2 kg slider on a spring (k = 3 N/m) and damper (c = 0.5 N s/m) under PID on its position,
// gains chosen so that m s^3 + (c + kd) s^2 + (k + kp) s + ki = m (s + 1)(s + 2)(s + 3).
constexpr double kM = 2, kK = 3, kC = 0.5;
constexpr double kKd = 6 * kM - kC, kKp = 11 * kM - kK, kKi = 6 * kM;

ModelSpec slider_pid() {
  const std::string text = R"({"name": "slider",
    "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
    "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0]}],
    "effects": [{"name": "spring", "type": "joint_spring_damper", "joint": "x", "stiffness": 3, "damping": 0.5}],
    "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N"},
                  {"name": "push", "type": "joint_force", "joint": "x", "unit": "N"}],
    "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
    "plant": {"inputs": ["force"], "outputs": ["pos"]},
    "analysis": {"operating_point": "initial"}})";
  ModelSpec spec = parse_model_spec_text(text, "slider.json");
  spec.controller.type = ControllerType::Pid;
  spec.controller.kp = Eigen::MatrixXd::Constant(1, 1, kKp);
  spec.controller.ki = Eigen::MatrixXd::Constant(1, 1, kKi);
  spec.controller.kd = Eigen::MatrixXd::Constant(1, 1, kKd);
  spec.controller.operating_point = "initial";
  return spec;
}

}  // namespace

// State feedback: the closed-loop poles are eig(A - B K), for codyna's LQR on the cart-pendulum,
// and exactly the poles asked of a pole-placement design
TEST(ClosedLoopLinear, StateFeedbackPolesAreEigOfAMinusBK) {
  const Model m = study_model(cart_lqr());
  const StudyClosedLoop cl = study_closed_loop(m);
  const LinearSystem& p = cl.setup.plant->lin.system;
  const Eigen::MatrixXd& K = cl.setup.lqr_gain;
  ASSERT_EQ(cl.loop.nxc, 0);
  const std::vector<cd> expected = sorted(Eigen::MatrixXd(p.A - p.B * K).eigenvalues());
  EXPECT_LT(max_distance(poles_of(cl.poles), expected), 1e-10);
  EXPECT_TRUE(MatrixNear(cl.loop.system.A, p.A - p.B * K, 1e-14));
  // damping and frequency of each pole as modal_analysis defines them
  for (const Mode& md : cl.poles.modes) {
    EXPECT_NEAR(md.natural_frequency, std::abs(md.eigenvalue), 1e-12);
    EXPECT_NEAR(md.damping_ratio, -md.eigenvalue.real() / std::abs(md.eigenvalue), 1e-12);
  }
  // the reference input on h (Nbar for h, the first output) has unit DC gain to h and none to theta
  ASSERT_EQ(cl.loop.system.input_names[0], "r_h");
  const LinearSystem& s = cl.loop.system;
  const Eigen::MatrixXd dc = s.D - s.C * s.A.partialPivLu().solve(s.B);
  EXPECT_NEAR(dc(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(dc(1, 0), 0.0, 1e-12);
  EXPECT_EQ(cl.notes.size(), 1u);  // says which output Nbar tracks

  // poles placed at -1, -2, -3 +- 1i come back exactly
  Eigen::VectorXcd want(4);
  want << cd(-1, 0), cd(-2, 0), cd(-3, 1), cd(-3, -1);
  const Eigen::MatrixXd Kp = place(p.A, p.B, want);
  ModelSpec spec = cart_lqr();
  spec.analysis.controller = "model";
  spec.controller = ControllerSpec{};
  spec.controller.type = ControllerType::StateFeedback;
  spec.controller.K = Kp;
  const StudyClosedLoop placed = study_closed_loop(study_model(spec));
  EXPECT_LT(max_distance(poles_of(placed.poles), sorted(want)), 1e-8);
}

// The same loop as PID on (h, theta) with kp = K(1:2), kd = K(3:4) (derivative on the measured
// rates): a second way to form it, the same poles
TEST(ClosedLoopLinear, PidWithTheLqrGainsHasTheSamePoles) {
  const Model m = study_model(cart_lqr());
  const StudyClosedLoop sf = study_closed_loop(m);
  const Eigen::MatrixXd K = sf.setup.lqr_gain;
  ModelSpec spec = cart_lqr();
  spec.analysis.controller = "model";
  spec.controller = ControllerSpec{};
  spec.controller.type = ControllerType::Pid;
  spec.controller.kp = K.leftCols(2);
  spec.controller.kd = K.rightCols(2);
  const StudyClosedLoop pid = study_closed_loop(study_model(spec));
  EXPECT_LT(max_distance(poles_of(pid.poles), poles_of(sf.poles)), 1e-9);
}

// The step and frequency responses of the LQR loop against a second computation: each step sample
// from one matrix exponential of [[A, B], [0, 0]] t (y(t) = C int_0^t e^(A s) ds B + D, no
// recursion over the samples), and H(jw) from the eigen decomposition A = V diag(p) V^-1
// (H = C V diag(1 / (jw - p)) V^-1 B + D, no linear solve with jw I - A)
TEST(ClosedLoopLinear, ResponsesEqualMatrixExponentialAndModalSum) {
  ModelSpec spec = cart_lqr();
  spec.analysis.closed_loop.step_time = 5;
  spec.analysis.closed_loop.step_points = 251;
  spec.analysis.closed_loop.frequency_min = 0.01;
  spec.analysis.closed_loop.frequency_max = 1000;
  spec.analysis.closed_loop.frequency_points = 101;
  const StudyClosedLoop cl = study_closed_loop(study_model(spec));
  const LinearSystem& s = cl.loop.system;
  const int n = s.nx(), m = s.nu();
  ASSERT_EQ(m, 2);  // r_h, r_theta
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = s.A;
  M.topRightCorner(n, m) = s.B;
  double worst = 0, peak = 0;
  for (std::size_t k = 0; k < cl.step.t.size(); ++k) {
    const Eigen::MatrixXd E = Eigen::MatrixXd(M * cl.step.t[k]).exp();
    const Eigen::MatrixXd Y = s.C * E.topRightCorner(n, m) + s.D;  // outputs x inputs
    for (int j = 0; j < m; ++j) {
      worst = std::max(worst, (cl.step.y[j].row(static_cast<Eigen::Index>(k)).transpose() - Y.col(j)).cwiseAbs().maxCoeff());
      peak = std::max(peak, Y.col(j).cwiseAbs().maxCoeff());
    }
  }
  std::printf("LQR loop step vs expm: max difference %.3g of peak %.3g\n", worst, peak);
  EXPECT_LT(worst, 1e-10 * peak);
  Eigen::ComplexEigenSolver<Eigen::MatrixXcd> es(s.A.cast<cd>());
  const Eigen::MatrixXcd V = es.eigenvectors(), Vi = V.inverse();
  double worst_f = 0;
  for (std::size_t k = 0; k < cl.frequency.w.size(); ++k) {
    const cd jw(0, cl.frequency.w[k]);
    Eigen::VectorXcd g(n);
    for (int i = 0; i < n; ++i) g[i] = 1.0 / (jw - es.eigenvalues()[i]);
    const Eigen::MatrixXcd H = s.C.cast<cd>() * V * g.asDiagonal() * Vi * s.B.cast<cd>() + s.D.cast<cd>();
    worst_f = std::max(worst_f, (cl.frequency.H[k] - H).cwiseAbs().maxCoeff() / std::max(1e-300, H.cwiseAbs().maxCoeff()));
    for (Eigen::Index i = 0; i < H.rows(); ++i)
      for (Eigen::Index j = 0; j < H.cols(); ++j)
        EXPECT_NEAR(cl.frequency.magnitude[k](i, j), std::abs(H(i, j)), 1e-9 * H.cwiseAbs().maxCoeff());
  }
  std::printf("LQR loop H(jw) vs modal sum: max relative difference %.3g\n", worst_f);
  EXPECT_LT(worst_f, 1e-9);
}

// PID on a spring-mass: poles -1, -2, -3 by construction; the frequency response from r to y is
// (kp s + ki) / (m s^3 + (c + kd) s^2 + (k + kp) s + ki) and the step response its partial fractions
TEST(ClosedLoopLinear, PidLoopMatchesItsTransferFunction) {
  ModelSpec spec = slider_pid();
  spec.analysis.closed_loop.step_time = 6;
  spec.analysis.closed_loop.step_points = 61;
  spec.analysis.closed_loop.frequency_min = 0.01;
  spec.analysis.closed_loop.frequency_max = 100;
  spec.analysis.closed_loop.frequency_points = 41;
  const StudyClosedLoop cl = study_closed_loop(study_model(spec));
  ASSERT_EQ(cl.loop.nxc, 1);
  EXPECT_LT(max_distance(poles_of(cl.poles), {cd(-3, 0), cd(-2, 0), cd(-1, 0)}), 1e-12);
  const LinearSystem& s = cl.loop.system;
  ASSERT_EQ(s.input_names, (std::vector<std::string>{"r_pos"}));
  ASSERT_EQ(s.output_names, (std::vector<std::string>{"pos", "u_force"}));
  auto den = [](cd x) { return kM * x * x * x + (kC + kKd) * x * x + (kK + kKp) * x + kKi; };
  auto num = [](cd x) { return kKp * x + kKi; };
  double worst = 0;
  for (std::size_t k = 0; k < cl.frequency.w.size(); ++k) {
    const cd jw(0, cl.frequency.w[k]);
    const cd H = num(jw) / den(jw);
    worst = std::max(worst, std::abs(cl.frequency.H[k](0, 0) - H) / std::abs(H));
    EXPECT_NEAR(cl.frequency.magnitude[k](0, 0), std::abs(H), 1e-12 * std::abs(H) + 1e-15);
  }
  EXPECT_LT(worst, 1e-12);
  // phase, unwrapped: the zero's angle less the three poles' (continuous in w, from 0 towards -180)
  for (std::size_t k = 0; k < cl.frequency.w.size(); ++k) {
    const double w = cl.frequency.w[k];
    const double phase = std::atan2(kKp * w, kKi) - std::atan2(w, 1.0) - std::atan2(w, 2.0) - std::atan2(w, 3.0);
    EXPECT_NEAR(cl.frequency.phase_deg[k](0, 0), phase * 180 / std::numbers::pi, 1e-9);
  }
  // y(t) = 1 + sum_i N(p_i) / (p_i D'(p_i)) exp(p_i t)
  const double p[3] = {-1, -2, -3};
  double worst_step = 0;
  for (std::size_t k = 0; k < cl.step.t.size(); ++k) {
    const double t = cl.step.t[k];
    double y = 1;
    for (int i = 0; i < 3; ++i) {
      double dprime = kM;
      for (int j = 0; j < 3; ++j)
        if (j != i) dprime *= p[i] - p[j];
      y += num(p[i]).real() / (p[i] * dprime) * std::exp(p[i] * t);
    }
    worst_step = std::max(worst_step, std::abs(cl.step.y[0](static_cast<Eigen::Index>(k), 0) - y));
  }
  EXPECT_LT(worst_step, 1e-12);
  EXPECT_NEAR(cl.step.t.back(), 6.0, 1e-15);

  // the same PI part as an LTI controller (it sees y - r): Ac = 0, Bc = 1, Cc = -ki, Dc = -kp; with
  // kd = 0 in both the two loops have the same poles and the same response from r
  spec.controller.kd = Eigen::MatrixXd();
  const StudyClosedLoop pi = study_closed_loop(study_model(spec));
  ModelSpec lti_spec = spec;
  lti_spec.controller = ControllerSpec{};
  lti_spec.controller.type = ControllerType::Lti;
  lti_spec.controller.Ac = Eigen::MatrixXd::Zero(1, 1);
  lti_spec.controller.Bc = Eigen::MatrixXd::Ones(1, 1);
  lti_spec.controller.Cc = Eigen::MatrixXd::Constant(1, 1, -kKi);
  lti_spec.controller.Dc = Eigen::MatrixXd::Constant(1, 1, -kKp);
  lti_spec.controller.operating_point = "initial";
  const StudyClosedLoop lti = study_closed_loop(study_model(lti_spec));
  EXPECT_LT(max_distance(poles_of(lti.poles), poles_of(pi.poles)), 1e-10);
  for (std::size_t k = 0; k < pi.frequency.w.size(); ++k)
    EXPECT_LT(std::abs(lti.frequency.H[k](0, 0) - pi.frequency.H[k](0, 0)), 1e-12 * std::abs(pi.frequency.H[k](0, 0)));
}

// A sampled LTI controller closes the loop around the plant's ZOH model: its poles are those of
// the discrete loop, and the step response at the samples equals the hybrid simulation's
TEST(ClosedLoopLinear, SampledControllerGivesTheDiscreteLoop) {
  ModelSpec spec = slider_pid();
  spec.controller = ControllerSpec{};
  spec.controller.type = ControllerType::Lti;  // discrete P: u[k] = -20 (y[k] - r[k])
  spec.controller.Ac = Eigen::MatrixXd::Zero(1, 1);
  spec.controller.Bc = Eigen::MatrixXd::Zero(1, 1);
  spec.controller.Cc = Eigen::MatrixXd::Zero(1, 1);
  spec.controller.Dc = Eigen::MatrixXd::Constant(1, 1, -20);
  spec.controller.Ts = 0.05;
  spec.controller.operating_point = "initial";
  spec.analysis.closed_loop.step_time = 3;
  SignalSpec step;
  step.output = "pos";
  step.type = "step";
  step.time = 0;
  step.value = 0.01;
  spec.analysis.references = {step};
  spec.solver.t_end = 3;
  spec.solver.output_step = 0.05;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.solver.integrator = "cvode-adams";
  const Model m = study_model(spec);
  const StudyClosedLoop cl = study_closed_loop(m);
  EXPECT_EQ(cl.loop.system.Ts, 0.05);
  ASSERT_EQ(cl.step.t.size(), 61u);
  const SimulationResult r = study_simulate(m, study_simulation(m));
  ASSERT_TRUE(r.completed) << r.failure;
  ASSERT_EQ(r.samples(), 61);
  double worst = 0;
  for (int k = 0; k < 61; ++k) worst = std::max(worst, std::abs(r.y(k, 0) - 0.01 * cl.step.y[0](k, 0)));
  EXPECT_LT(worst, 1e-9);  // a linear plant: only the integrator's error
  // the discrete poles inside the unit circle, reported with their continuous equivalents
  for (const Mode& md : cl.poles.modes) EXPECT_LT(std::abs(md.eigenvalue), 1.0);
}

// The step response from r_h equals the nonlinear cart-pendulum's response to a small step on h
// (LQR + Nbar). What is left is the pendulum's nonlinearity, quadratic in the step: doubling the
// step quadruples the gap relative to the step (measured: 7.6e-8 of the peak for 1 cm, 3.1e-7 for
// 2 cm, ratio 4.04), far above the integrator's tolerance (rtol 1e-11), so the bound 1e-6 for
// 1 cm holds the loop to the nonlinear plant within what the linearization itself allows.
TEST(ClosedLoopLinear, StepResponseEqualsTheNonlinearRunForASmallStep) {
  ModelSpec spec = cart_lqr();
  spec.solver.t_end = 8;
  spec.solver.output_step = 0.01;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.analysis.closed_loop.step_time = 8;
  spec.analysis.closed_loop.step_points = 801;
  double gap[2];
  for (int run = 0; run < 2; ++run) {
    const double a = run == 0 ? 0.01 : 0.02;
    SignalSpec step;
    step.output = "h";
    step.type = "step";
    step.time = 0;
    step.value = a;
    spec.analysis.references = {step};
    const Model m = study_model(spec);
    const StudyClosedLoop cl = study_closed_loop(m);
    EXPECT_TRUE(cl.notes.empty());  // the study's reference decides Nbar
    const SimulationResult r = study_simulate(m, cl.setup);
    ASSERT_TRUE(r.completed) << r.failure;
    ASSERT_EQ(r.samples(), 801);
    const Eigen::MatrixXd& Y = cl.step.y[0];  // h, theta, u_force for a unit step on r_h
    const int iu = index_of(r.input_names, "force");
    double worst = 0, range = 0;
    for (int k = 0; k < 801; ++k) {
      EXPECT_NEAR(cl.step.t[k], r.t[k], 1e-12);
      const double u0 = cl.loop.system.y0[2];
      const Eigen::Vector3d nonlinear(r.y(k, 0), r.y(k, 1), r.u(k, iu) - u0);
      const Eigen::Vector3d linear = a * Y.row(k).transpose();
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(nonlinear[i] - linear[i]) / (a * Y.col(i).cwiseAbs().maxCoeff()));
      range = std::max(range, std::abs(linear[0]));
    }
    gap[run] = worst;
    EXPECT_NEAR(range, a, 0.3 * a);  // the cart does go to the reference
  }
  std::printf("step on h, max |nonlinear - linear| / peak: 1 cm %.3g, 2 cm %.3g (ratio %.2f)\n", gap[0], gap[1], gap[1] / gap[0]);
  EXPECT_LT(gap[0], 1e-6);
  EXPECT_GT(gap[1] / gap[0], 3.5);  // quadruples with twice the step: the nonlinearity, not an error of the loop
  EXPECT_LT(gap[1] / gap[0], 4.5);
}

// A constant disturbance force on the cart (an actuator that is not Plant/In) under LQR: the
// nonlinear run, the linear comparison (its B column) and the closed loop's d_push step agree for a
// small step, down to the steady offset -Ccl Acl^-1 Bcl that state feedback without integral leaves
TEST(ClosedLoopLinear, DisturbanceStepMatchesTheLinearPrediction) {
  ModelSpec spec = cart_lqr();
  ActuatorSpec push;
  push.name = "push";
  push.type = ActuatorType::BodyForce;
  push.body = "cart";
  push.direction = Eigen::Vector3d::UnitX();
  push.unit = "N";
  spec.actuators.push_back(push);
  DisturbanceSpec d;
  d.actuator = "push";
  d.type = "step";
  d.time = 0.5;
  d.value = 2.0;  // N
  spec.analysis.disturbances = {d};
  spec.analysis.compare_linear = true;
  spec.solver.t_end = 10;
  spec.solver.output_step = 0.01;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.analysis.closed_loop.step_time = 9.5;
  spec.analysis.closed_loop.step_points = 951;
  const Model m = study_model(spec);
  const StudyClosedLoop cl = study_closed_loop(m);
  const LinearSystem& s = cl.loop.system;
  const int jd = index_of(s.input_names, "d_push");
  // the disturbance's B column is the force's (same joint, same direction)
  EXPECT_TRUE(MatrixNear(cl.setup.plant->Bw, cl.setup.plant->lin.system.B, 1e-12));
  const SimulationResult r = study_simulate(m, cl.setup);
  ASSERT_TRUE(r.completed) << r.failure;
  ASSERT_EQ(r.y_linear.rows(), r.samples());
  const int N = r.samples();
  const int ipush = index_of(r.input_names, "push");
  EXPECT_EQ(r.u(40, ipush), 0.0);  // t = 0.4 s: not yet
  EXPECT_EQ(r.u(60, ipush), 2.0);
  // the result records d(t) itself, one column per actuator, zero on the undisturbed
  ASSERT_EQ(r.u_disturbance.rows(), N);
  ASSERT_EQ(r.u_disturbance.cols(), r.u.cols());
  EXPECT_EQ(r.u_disturbance(40, ipush), 0.0);
  EXPECT_EQ(r.u_disturbance(60, ipush), 2.0);
  EXPECT_EQ(r.u_disturbance.col(index_of(r.input_names, "force")).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(r.y_reference.size(), 0);  // no reference in this study
  double worst_lin = 0, worst_cl = 0, peak = 0;
  for (int k = 50; k < N; ++k) {  // from the step at t = 0.5 s
    for (int i = 0; i < 2; ++i) {
      const double predicted = 2.0 * cl.step.y[jd](k - 50, i);
      worst_lin = std::max(worst_lin, std::abs(r.y(k, i) - r.y_linear(k, i)));
      worst_cl = std::max(worst_cl, std::abs(r.y(k, i) - predicted));
      peak = std::max(peak, std::abs(predicted));
    }
  }
  const Eigen::MatrixXd dc = s.D - s.C * s.A.partialPivLu().solve(s.B);
  std::printf("disturbance 2 N: max |y - y_lin| %.3g, max |y - closed-loop step| %.3g, peak %.3g, DC h %.6g m/N\n", worst_lin,
              worst_cl, peak, dc(0, jd));
  EXPECT_LT(worst_lin, 1e-4 * peak);  // measured 3.5e-5 of the peak: RK4 of the comparison (20 substeps)
  EXPECT_LT(worst_cl, 1e-5 * peak);   // measured 1.2e-6: the nonlinearity of a 2 N push
  EXPECT_NEAR(r.y(N - 1, 0), 2.0 * dc(0, jd), 2e-3 * std::abs(2.0 * dc(0, jd)));
  EXPECT_GT(std::abs(dc(0, jd)), 1e-3);  // a real offset, not zero

  // a disturbance on a Plant/In actuator, or on no actuator, is named
  spec.analysis.disturbances[0].actuator = "force";
  try {
    study_simulation(study_model(spec));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/disturbances/0/actuator");
    EXPECT_NE(std::string(e.what()).find("Plant/In"), std::string::npos) << e.what();
  }
  spec.analysis.disturbances[0].actuator = "push";
  spec.analysis.disturbances.push_back(spec.analysis.disturbances[0]);
  try {
    study_simulation(study_model(spec));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/disturbances/1/actuator");
    EXPECT_NE(std::string(e.what()).find("a second disturbance on \"push\""), std::string::npos) << e.what();
  }
  spec.analysis.disturbances.pop_back();
  spec.analysis.disturbances[0].actuator = "wind";
  try {
    study_simulation(study_model(spec));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("no actuator named \"wind\""), std::string::npos) << e.what();
  }
}

// The nonlinear cart-pendulum under LQR against the loop's d_push step response, for pushes of
// 1, 2 and 4 N: what is left is the nonlinearity, cubic in the push (the dynamics are odd: a
// mirrored push gives the mirrored motion, so there is no quadratic term), so the gap relative to
// the peak quadruples with twice the push and the linear prediction is exact for small pushes
TEST(ClosedLoopLinear, DisturbanceGapShrinksWithTheAmplitude) {
  double gap[3];
  const double push_N[3] = {1, 2, 4};
  for (int run = 0; run < 3; ++run) {
    ModelSpec spec = cart_lqr();
    ActuatorSpec push;
    push.name = "push";
    push.type = ActuatorType::BodyForce;
    push.body = "cart";
    push.direction = Eigen::Vector3d::UnitX();
    push.unit = "N";
    spec.actuators.push_back(push);
    DisturbanceSpec d;
    d.actuator = "push";
    d.type = "step";
    d.time = 0;
    d.value = push_N[run];
    spec.analysis.disturbances = {d};
    spec.solver.t_end = 8;
    spec.solver.output_step = 0.02;
    spec.solver.rtol = 1e-11;
    spec.solver.atol = 1e-13;
    spec.analysis.closed_loop.step_time = 8;
    spec.analysis.closed_loop.step_points = 401;
    const Model m = study_model(spec);
    const StudyClosedLoop cl = study_closed_loop(m);
    const int jd = index_of(cl.loop.system.input_names, "d_push");
    const SimulationResult r = study_simulate(m, cl.setup);
    ASSERT_TRUE(r.completed) << r.failure;
    ASSERT_EQ(r.samples(), 401);
    double worst = 0, peak = 0;
    for (int k = 0; k < 401; ++k)
      for (int i = 0; i < 2; ++i) {
        const double predicted = push_N[run] * cl.step.y[jd](k, i);
        worst = std::max(worst, std::abs(r.y(k, i) - predicted));
        peak = std::max(peak, std::abs(predicted));
      }
    gap[run] = worst / peak;
  }
  std::printf("push on the cart, max |nonlinear - linear| / peak: 1 N %.3g, 2 N %.3g, 4 N %.3g\n", gap[0], gap[1], gap[2]);
  EXPECT_LT(gap[0], 1e-6);
  for (int k = 1; k < 3; ++k) {
    EXPECT_GT(gap[k] / gap[k - 1], 3.5);
    EXPECT_LT(gap[k] / gap[k - 1], 4.5);
  }
}

TEST(ClosedLoopLinear, NeedsAController) {
  ModelSpec spec = cart_lqr();
  spec.analysis.controller = "none";
  try {
    study_closed_loop(study_model(spec));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/controller");
  }
}

// PID on the spring-mass rejects a constant disturbance force on "push" (an actuator that is not
// Plant/In): from d to y the loop is s / (m s^3 + (c + kd) s^2 + (k + kp) s + ki), zero at DC, so
// y(t) = d sum_i exp(p_i t) / D'(p_i) returns to 0 and the controller's force settles at -d
// (integral state -d / ki). The plant is linear: the nonlinear run equals the closed form to the
// integrator's precision, and the loop's d_push step response equals it exactly.
TEST(ClosedLoopLinear, PidRejectsAConstantDisturbance) {
  constexpr double d = 0.5, t_d = 1.0;
  ModelSpec spec = slider_pid();
  DisturbanceSpec dist;
  dist.actuator = "push";
  dist.type = "step";
  dist.time = t_d;
  dist.value = d;
  spec.analysis.disturbances = {dist};
  spec.solver.integrator = "cvode-bdf";
  spec.solver.t_end = 12;
  spec.solver.output_step = 0.05;
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  spec.analysis.closed_loop.step_time = 11;
  spec.analysis.closed_loop.step_points = 221;
  spec.analysis.closed_loop.frequency_min = 0.01;
  spec.analysis.closed_loop.frequency_max = 100;
  spec.analysis.closed_loop.frequency_points = 41;
  const Model m = study_model(spec);
  const StudyClosedLoop cl = study_closed_loop(m);
  const LinearSystem& s = cl.loop.system;
  ASSERT_EQ(s.input_names, (std::vector<std::string>{"r_pos", "d_push"}));
  ASSERT_EQ(s.output_names, (std::vector<std::string>{"pos", "u_force"}));
  const double p[3] = {-1, -2, -3};
  // y, y', y'' of the unit-step response from d (residues of 1 / D(s) at its simple poles)
  auto y_of = [&](double t, int order) {
    double y = 0;
    for (int i = 0; i < 3; ++i) {
      double dprime = kM;
      for (int j = 0; j < 3; ++j)
        if (j != i) dprime *= p[i] - p[j];
      y += std::pow(p[i], order) * std::exp(p[i] * t) / dprime;
    }
    return y;
  };
  double worst_y = 0, worst_u = 0;
  for (std::size_t k = 0; k < cl.step.t.size(); ++k) {
    const double t = cl.step.t[k];
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    worst_y = std::max(worst_y, std::abs(cl.step.y[1](i, 0) - y_of(t, 0)));
    // the controller's force: m y'' + c y' + k y - d (Newton with the unit push)
    worst_u = std::max(worst_u, std::abs(cl.step.y[1](i, 1) - (kM * y_of(t, 2) + kC * y_of(t, 1) + kK * y_of(t, 0) - 1)));
  }
  EXPECT_LT(worst_y, 1e-13);
  EXPECT_LT(worst_u, 1e-12);
  for (std::size_t k = 0; k < cl.frequency.w.size(); ++k) {
    const cd jw(0, cl.frequency.w[k]);
    const cd H = jw / (kM * jw * jw * jw + (kC + kKd) * jw * jw + (kK + kKp) * jw + kKi);
    EXPECT_LT(std::abs(cl.frequency.H[k](0, 1) - H), 1e-12 * std::abs(H));
  }
  const Eigen::MatrixXd dc = s.D - s.C * s.A.partialPivLu().solve(s.B);
  EXPECT_NEAR(dc(0, 1), 0.0, 1e-14);   // no steady error
  EXPECT_NEAR(dc(1, 1), -1.0, 1e-13);  // the force cancels the push

  const SimulationResult r = study_simulate(m, cl.setup);
  ASSERT_TRUE(r.completed) << r.failure;
  const int N = r.samples(), ipush = index_of(r.input_names, "push"), iforce = index_of(r.input_names, "force");
  double worst_run = 0, peak = 0;
  for (int k = 0; k < N; ++k) {
    const double t = r.t[k];
    const double y = t < t_d ? 0.0 : d * y_of(t - t_d, 0);
    worst_run = std::max(worst_run, std::abs(r.y(k, 0) - y));
    peak = std::max(peak, std::abs(y));
    EXPECT_EQ(r.u(k, ipush), t < t_d ? 0.0 : d) << t;
  }
  std::printf("PID vs a 0.5 N push: peak %.4g m, max |y - closed form| %.3g m, final y %.3g m, force %.12g N, xi %.12g\n", peak,
              worst_run, r.y(N - 1, 0), r.u(N - 1, iforce), r.xc(N - 1, 0));
  EXPECT_LT(worst_run, 1e-10);  // measured 4.8e-12 m (peak 1.9e-2 m): the integrator only
  EXPECT_NEAR(r.y(N - 1, 0), 0.0, 1e-5);
  EXPECT_NEAR(r.u(N - 1, iforce), -d, 1e-4);
  EXPECT_NEAR(r.xc(N - 1, 0), -d / kKi, 1e-5);
}

// The automatic grids: the step responses last 8 / (the slowest decay rate) within [1, 1000] s
// (10 s when nothing decays); the frequencies run from a decade below the slowest pole's
// frequency to a decade above the fastest, out to whole decades, capped at pi / Ts when discrete
TEST(ClosedLoopLinear, DefaultGrids) {
  auto poles = [](std::vector<double> p, double Ts = 0) {
    ModalAnalysis a;
    a.Ts = Ts;
    for (double x : p) {
      Mode md;
      md.eigenvalue = md.s = x;
      md.natural_frequency = std::abs(x);
      a.modes.push_back(md);
    }
    return a;
  };
  EXPECT_DOUBLE_EQ(default_step_time(poles({-0.5, -20})), 16.0);
  EXPECT_DOUBLE_EQ(default_step_time(poles({-100})), 1.0);
  EXPECT_DOUBLE_EQ(default_step_time(poles({-0.001})), 1000.0);
  EXPECT_DOUBLE_EQ(default_step_time(poles({0.0, 2.0})), 10.0);
  EXPECT_EQ(default_frequency_range(poles({-0.5, -20}), 0), std::make_pair(0.01, 1000.0));
  EXPECT_EQ(default_frequency_range(poles({0.0}), 0), std::make_pair(0.01, 100.0));
  const auto [lo, hi] = default_frequency_range(poles({-0.5, -20}), 0.01);
  EXPECT_EQ(lo, 0.01);
  EXPECT_DOUBLE_EQ(hi, std::numbers::pi / 0.01);
  const std::vector<double> w = log_grid(0.1, 1000, 5);
  ASSERT_EQ(w.size(), 5u);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(w[k], std::pow(10.0, k - 1), 1e-12 * w[k]);
  EXPECT_THROW(log_grid(0, 1, 5), std::invalid_argument);
  EXPECT_THROW(step_response(LinearSystem{}, -1, 5), std::invalid_argument);
}

// A disturbed actuator keeps its limits: a 0.5 N step on "push" limited to 0.3 N pushes with
// 0.3 N, and the PID's force settles at -0.3 N
TEST(ClosedLoopLinear, DisturbanceIsLimitedLikeAnyActuator) {
  ModelSpec spec = slider_pid();
  for (ActuatorSpec& a : spec.actuators)
    if (a.name == "push") a.max = 0.3;
  DisturbanceSpec dist;
  dist.actuator = "push";
  dist.type = "step";
  dist.time = 1;
  dist.value = 0.5;
  spec.analysis.disturbances = {dist};
  spec.solver.t_end = 15;
  spec.solver.output_step = 0.05;
  spec.solver.rtol = 1e-10;
  spec.solver.atol = 1e-12;
  const Model m = study_model(spec);
  const SimulationResult r = study_simulate(m, study_simulation(m));
  ASSERT_TRUE(r.completed) << r.failure;
  const int N = r.samples(), ipush = index_of(r.input_names, "push"), iforce = index_of(r.input_names, "force");
  for (int k = 0; k < N; ++k) EXPECT_EQ(r.u(k, ipush), r.t[k] < 1 ? 0.0 : 0.3) << r.t[k];
  EXPECT_NEAR(r.u(N - 1, iforce), -0.3, 1e-5);
  EXPECT_NEAR(r.y(N - 1, 0), 0.0, 1e-6);
}

// close_loop on its own, with everything a plant can have: a random plant with feedthrough D
// (so the algebraic loop u = ... + Dy D u is there), a dynamic LTI controller with feedthrough,
// and disturbance columns. Checked in the frequency domain against the loop composed from
// transfer functions: y = P u + Pw w, u = K (y - r)  =>  y = (I - P K)^-1 (Pw w - P K r), u = K (y - r)
TEST(ClosedLoopLinear, AlgebraicLoopMatchesTransferFunctionComposition) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  auto random = [&](int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) M(i, j) = g(rng);
    return M;
  };
  const int nx = 4, nu = 2, ny = 2, nd = 1, nxc = 3;
  LinearSystem p;
  p.A = random(nx, nx) - 3 * Eigen::MatrixXd::Identity(nx, nx);
  p.B = random(nx, nu);
  p.C = random(ny, nx);
  p.D = 0.3 * random(ny, nu);
  p.state_names = {"a", "b", "a_dot", "b_dot"};
  p.input_names = {"u1", "u2"};
  p.output_names = {"y1", "y2"};
  LinearLaw law;
  law.Ak = random(nxc, nxc) - 2 * Eigen::MatrixXd::Identity(nxc, nxc);
  law.By = random(nxc, ny);
  law.Br = -law.By;
  law.Bx = Eigen::MatrixXd::Zero(nxc, nx);
  law.Bv = Eigen::MatrixXd::Zero(nxc, ny);
  law.Ck = random(nu, nxc);
  law.Dy = 0.5 * random(nu, ny);
  law.Dr = -law.Dy;
  law.Dx = Eigen::MatrixXd::Zero(nu, nx);
  law.Dv = Eigen::MatrixXd::Zero(nu, ny);
  DisturbanceInputs w;
  w.Bw = random(nx, nd);
  w.Dw = random(ny, nd);
  w.names = {"gust"};
  const ClosedLoopLinear cl = close_loop(p, law, w);
  const LinearSystem& s = cl.system;
  ASSERT_EQ(s.input_names, (std::vector<std::string>{"r_y1", "r_y2", "d_gust"}));
  ASSERT_EQ(s.output_names, (std::vector<std::string>{"y1", "y2", "u_u1", "u_u2"}));
  const std::vector<double> freqs{0.0, 0.1, 1.0, 7.0, 100.0};
  const FrequencyResponse f = frequency_response(s, freqs);
  auto tf = [](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C, const Eigen::MatrixXd& D, cd x) {
    const Eigen::MatrixXcd M = x * Eigen::MatrixXcd::Identity(A.rows(), A.cols()) - A.cast<cd>();
    return Eigen::MatrixXcd(C.cast<cd>() * M.fullPivLu().solve(B.cast<cd>()) + D.cast<cd>());
  };
  double worst = 0;
  for (std::size_t k = 0; k < freqs.size(); ++k) {
    const cd x(0, freqs[k]);
    const Eigen::MatrixXcd P = tf(p.A, p.B, p.C, p.D, x), Pw = tf(p.A, w.Bw, p.C, w.Dw, x);
    const Eigen::MatrixXcd K = tf(law.Ak, law.By, law.Ck, law.Dy, x);
    const Eigen::MatrixXcd S = (Eigen::MatrixXcd::Identity(ny, ny) - P * K).inverse();
    Eigen::MatrixXcd H(ny + nu, ny + nd);
    H.topLeftCorner(ny, ny) = -S * P * K;                       // r -> y
    H.topRightCorner(ny, nd) = S * Pw;                          // w -> y
    H.bottomLeftCorner(nu, ny) = K * (H.topLeftCorner(ny, ny) - Eigen::MatrixXcd::Identity(ny, ny));  // r -> u
    H.bottomRightCorner(nu, nd) = K * H.topRightCorner(ny, nd);  // w -> u
    worst = std::max(worst, (f.H[k] - H).cwiseAbs().maxCoeff() / H.cwiseAbs().maxCoeff());
  }
  std::printf("closed loop with D and controller feedthrough vs transfer functions: %.3g\n", worst);
  EXPECT_LT(worst, 1e-12);
  // a singular algebraic loop (I - Dy D = 0) is refused
  LinearSystem q = p;
  q.D = Eigen::MatrixXd::Identity(ny, nu);
  LinearLaw l2 = law;
  l2.Dy = Eigen::MatrixXd::Identity(nu, ny);
  l2.Dr = -l2.Dy;
  EXPECT_THROW(close_loop(q, l2, w), std::invalid_argument);
}
