// Motion inputs on a coordinate of a closed loop (issue 19: Adams' MOTION on a crank): the
// driven slider-crank of examples/slider_crank_driven.json, its crank turned by a motion input,
// a follower on a spring riding the slider (the one degree of freedom left). Checked against
// closed forms derived by hand:
//   the slider x(theta) = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)),
//   the drive torque from virtual work along d/dtheta at fixed s (inertia of crank, rod, slider,
//   the follower's m2 (x'' + s'') = -k s, the rod's weight),
//   the impulse when the crank starts turning (the follower keeps its velocity: s' = -x_theta w),
//   the power the motion supplies integrated against the change of mechanical energy,
//   the linearization S(s)/Theta(s) = -x_theta s^2 / (s^2 + k/m2) and X/Theta = x_theta,
// with the exact Jacobian against central differences and automatic differentiation; models whose
// motions over-drive a loop, or hold it where it cannot close, refused naming the motion and loop.
#include <gtest/gtest.h>

#include <functional>

#include <array>

#include <Eigen/Dense>
#include <algorithm>
#include <tuple>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

using cd = std::complex<double>;

// the example's numbers
constexpr double r = 0.1, l = 0.3, a = 0.15, Ic = 0.002, mr = 0.4, Ir = 0.003, m1 = 1.0, m2 = 0.5, k = 200.0,
                 g = 9.81;

// the mechanism's geometry as a function of the crank angle: the value and its first two
// derivatives with respect to theta
struct Geometry {
  double x, x1, x2;               // slider position
  Eigen::Vector2d p1, p2;         // rod's centre of mass (d/dtheta, d2/dtheta2)
  double psi1, psi2;              // rod's absolute angle
};

Geometry geometry(double th) {
  const double S = std::sin(th), C = std::cos(th);
  const double D = std::sqrt(l * l - r * r * S * S);
  const double D1 = -r * r * S * C / D;
  const double D2 = -r * r * std::cos(2 * th) / D - std::pow(r, 4) * S * S * C * C / std::pow(D, 3);
  Geometry G;
  G.x = r * C + D;
  G.x1 = -r * S + D1;
  G.x2 = -r * C + D2;
  // the rod's centre of mass: crank pin + (a / l) (slider - crank pin)
  G.p1 = Eigen::Vector2d(-r * S + (a / l) * D1, r * (1 - a / l) * C);
  G.p2 = Eigen::Vector2d(-r * C + (a / l) * D2, -r * (1 - a / l) * S);
  // the rod's angle psi = -asin(r sin(theta) / l)
  G.psi1 = -r * C / D;
  G.psi2 = r * S / D + r * C * D1 / (D * D);
  return G;
}

// the torque the crank's motion supplies: virtual work of the inertia forces and the rod's weight
// along d/dtheta at fixed s (the spring and the follower's slide are internal to that motion but
// for m2 (x'' + s'') = -k s, the follower's own balance)
double drive_torque(double th, double thd, double thdd, double s) {
  const Geometry G = geometry(th);
  const double xdd = G.x2 * thd * thd + G.x1 * thdd;
  const Eigen::Vector2d acom = G.p2 * thd * thd + G.p1 * thdd;
  const double psidd = G.psi2 * thd * thd + G.psi1 * thdd;
  return Ic * thdd + mr * acom.dot(G.p1) + Ir * psidd * G.psi1 + mr * g * G.p1.y() + m1 * xdd * G.x1 - k * s * G.x1;
}

ModelSpec example() { return study_read_model(test::example_path("slider_crank_driven.json")); }

int motion_column(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<int>(it - names.begin());
}

TEST(MotionLoop, TheModelCompilesWithOneDegreeOfFreedomAndTheCrankWhereItsMotionPutsIt) {
  const Model m = study_model(example());
  EXPECT_EQ(m.dof(), 1);
  const int crank = m.joints[static_cast<std::size_t>(m.find_body("crank"))].idx_q;
  const int slide = m.joints[static_cast<std::size_t>(m.find_body("slider"))].idx_q;
  EXPECT_EQ(m.q0[crank], 0.5);  // assembly held the driven coordinate
  EXPECT_NEAR(m.q0[slide], geometry(0.5).x, 1e-13);
  // the independent coordinate is the follower's (the driven crank is neither)
  const CoordinatePartition p = partition_coordinates(m, m.q0);
  ASSERT_EQ(p.independent.size(), 1u);
  EXPECT_EQ(m.v_names[static_cast<std::size_t>(p.independent[0])], "follower_slide");
  EXPECT_EQ(p.dependent.size(), 2u);
}

// forward dynamics with the crank's acceleration prescribed: the loop's rows carry J_d a_d, and
// the reaction J_d^T lambda; against the closed-form torque at random states on the manifold
TEST(MotionLoop, ForwardDynamicsKeepsTheLoopAndGivesTheVirtualWorkTorque) {
  const Model m = study_model(example());
  Data d(m);
  const int ic = m.joints[static_cast<std::size_t>(m.find_body("crank"))].idx_v;
  const int is = m.joints[static_cast<std::size_t>(m.find_body("follower"))].idx_v;
  for (const auto& [th, thd, thdd, s] : {std::tuple{0.5, 0.0, 0.0, 0.0}, std::tuple{1.3, 2.0, -3.0, 0.02},
                                         std::tuple{-2.4, -6.3, 11.0, -0.04}, std::tuple{3.0, 9.0, 0.5, 0.01}}) {
    // the configuration: the crank and the follower given, the loop closed on the others
    Eigen::VectorXd q = m.q0, v = Eigen::VectorXd::Zero(m.nv);
    q[ic] = th;
    q[is] = s;
    // near the branch of the example (the slider right of the crank), where Newton converges
    q[m.joints[static_cast<std::size_t>(m.find_body("slider"))].idx_q] = geometry(th).x + 0.01;
    q[m.joints[static_cast<std::size_t>(m.find_body("rod"))].idx_q] = -std::asin(r * std::sin(th) / l) - th + 0.02;
    v[ic] = thd;
    v[is] = 0.3;
    const AssemblyResult A = assemble(m, q, v);
    ASSERT_TRUE(A.converged);
    EXPECT_EQ(A.q[ic], th);
    EXPECT_EQ(A.v[ic], thd);
    d.motion_acc[0] = thdd;
    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, A.q, A.v, m.u_nominal());
    EXPECT_EQ(qdd[ic], thdd);
    // the loop's acceleration rows hold: Jc qdd + gamma = 0
    constraint_terms<double>(m, d, A.q, A.v);
    EXPECT_LT((d.Jc * qdd + d.gamma).cwiseAbs().maxCoeff(), 1e-12) << th;
    // the slider's acceleration is x'' of the closed form, the follower's balance m2 (x'' + s'') = -k s
    const Geometry G = geometry(th);
    const int ix = m.joints[static_cast<std::size_t>(m.find_body("slider"))].idx_v;
    EXPECT_NEAR(qdd[ix], G.x2 * thd * thd + G.x1 * thdd, 1e-11 * (1 + std::abs(qdd[ix])));
    EXPECT_NEAR(m2 * (qdd[ix] + qdd[is]), -k * s, 1e-11);
    forward_dynamics<double>(m, d, A.q, A.v, m.u_nominal());
    const double tau = drive_torque(th, thd, thdd, s);
    EXPECT_NEAR(d.motion_force[0], tau, 1e-12 * std::max(1.0, std::abs(tau))) << th;
  }
}

// a run: the crank turned at 1 rev/s from rest (a ramp: the follower takes the impulse), or
// swung by a sine; the slider, the drive torque and the energy against the closed forms
SimulationResult run(ModelSpec spec) {
  spec.plant.outputs = {"slider_x", "follower_s", "drive_torque"};
  const Model m = study_model(spec);
  const SimulationResult r = study_simulate(m, study_simulation(m));
  EXPECT_TRUE(r.completed) << r.failure;
  return r;
}

// every sample of a run against the closed forms, the crank's angle, rate and acceleration
// given by crank(t): the crank on its signal to 1e-12, the slider's x(theta) to `tol` (1e-12: the
// ODE integrators project onto the loop), the drive torque to 1e-8 of its largest value, the loop
// closed to `tol`
void expect_closed_forms(const SimulationResult& r, const std::function<std::array<double, 3>(double)>& crank,
                         double tol = 1e-12, double torque_tol = 1e-8) {
  const int ic = motion_column(r.q_names, "crank_pivot"), iy = motion_column(r.output_names, "slider_x");
  const int is = motion_column(r.q_names, "follower_slide"), it = motion_column(r.output_names, "drive_torque");
  double worst_x = 0, worst_tau = 0, largest_tau = 0, worst_phi = 0;
  for (int i = 0; i < r.samples(); ++i) {
    const auto [th, rate, acc] = crank(r.t[i]);
    EXPECT_NEAR(r.q(i, ic), th, 1e-12);
    worst_x = std::max(worst_x, std::abs(r.y(i, iy) - geometry(th).x));
    const double tau = drive_torque(th, rate, acc, r.q(i, is));
    worst_tau = std::max(worst_tau, std::abs(r.y(i, it) - tau));
    largest_tau = std::max(largest_tau, std::abs(tau));
    worst_phi = std::max(worst_phi, r.constraint_violation[static_cast<std::size_t>(i)]);
  }
  EXPECT_LT(worst_x, tol);
  EXPECT_LT(worst_tau, torque_tol * largest_tau) << largest_tau;
  EXPECT_LT(worst_phi, tol);
}

TEST(MotionLoop, ACrankTurnedByARampFollowsTheClosedFormsAndTheEnergyBalance) {
  ModelSpec spec = example();
  spec.solver.output_step = 0.001;
  spec.solver.t_end = 1.0;
  const SimulationResult r = run(spec);
  const double w = 2 * std::numbers::pi;
  const int is = motion_column(r.q_names, "follower_slide"), it = motion_column(r.output_names, "drive_torque");
  const int vs = motion_column(r.v_names, "follower_slide_dot");
  const int N = r.samples();
  ASSERT_EQ(N, 1001);
  // the crank follows its signal exactly
  expect_closed_forms(r, [&](double t) { return std::array<double, 3>{0.5 + w * t, w, 0.0}; });
  EXPECT_GT(r.q.col(is).cwiseAbs().maxCoeff(), 1e-2);  // the follower moves: the test can fail
  // the start: the slider jumps to x_theta w, the follower keeps its absolute velocity (0)
  EXPECT_NEAR(r.v(0, vs), -geometry(0.5).x1 * w, 1e-12);
  EXPECT_LT(r.velocity_violation[0], 1e-12);
  // the power the crank supplies, tau w, integrated (Simpson on the 1 ms samples) against
  // the change of kinetic plus potential energy (gravity, the spring)
  ASSERT_EQ((N - 1) % 2, 0);
  double work = 0;
  for (int i = 0; i + 2 < N; i += 2) {
    const double h = r.t[i + 1] - r.t[i];
    work += h / 3 * (r.y(i, it) + 4 * r.y(i + 1, it) + r.y(i + 2, it)) * w;
  }
  const double dE = r.kinetic_energy.back() + r.potential_energy.back() - r.kinetic_energy[0] - r.potential_energy[0];
  EXPECT_GT(std::abs(dE), 0.05);
  EXPECT_NEAR(work, dE, 1e-8) << work << " " << dE;
}

// the crank swung by a sine from 0.5 rad (0.8 rad at 0.7 Hz) for 1.5 s, and its angle, rate and
// acceleration at t
ModelSpec swung() {
  ModelSpec spec = example();
  DisturbanceSpec& d = spec.analysis.disturbances.at(0);
  d.type = "sine";
  d.amplitude = 0.8;
  d.frequency = 0.7;
  spec.solver.t_end = 1.5;
  spec.solver.output_step = 0.01;
  return spec;
}
std::array<double, 3> swung_crank(double t) {
  const double w = 2 * std::numbers::pi * 0.7;
  return {0.5 + 0.8 * std::sin(w * t), 0.8 * w * std::cos(w * t), -0.8 * w * w * std::sin(w * t)};
}

TEST(MotionLoop, ACrankSwungByASineFollowsTheClosedForms) { expect_closed_forms(run(swung()), swung_crank); }

// the DAE integrator (ida: the multipliers as unknowns, the driven coordinates' balance replaced
// by v_d' = u'') on the crank swung by a sine: the same closed forms, the loop held by Baumgarte's
// stabilization rather than projections, so to 1e-8 (m, and of the largest torque)
TEST(MotionLoop, TheDaeIntegratorTakesMotionInputs) {
  ModelSpec spec = swung();
  spec.solver.integrator = "ida";
  spec.solver.rtol = 1e-11;
  spec.solver.atol = 1e-13;
  const SimulationResult r = run(spec);
  EXPECT_EQ(r.stats.integrator, "ida");
  expect_closed_forms(r, swung_crank, 1e-8, 1e-8);
  // and the ramp, whose start is an impulse: the follower keeps its absolute velocity
  ModelSpec ramp = example();
  ramp.solver.integrator = "ida";
  ramp.solver.rtol = 1e-11;
  ramp.solver.atol = 1e-13;
  ramp.solver.t_end = 0.5;
  const SimulationResult rr = run(ramp);
  const double W = 2 * std::numbers::pi;
  expect_closed_forms(rr, [&](double t) { return std::array<double, 3>{0.5 + W * t, W, 0.0}; }, 1e-8, 1e-8);
  EXPECT_NEAR(rr.v(0, motion_column(rr.v_names, "follower_slide_dot")), -geometry(0.5).x1 * W, 1e-12);
}

// the crank as a Plant/In: S(s)/Theta(s) = -x_theta s^2 / (s^2 + k/m2), X/Theta = x_theta
TEST(MotionLoop, TheCrankAsAPlantInputLinearizesAsTheClosedForm) {
  ModelSpec spec = example();
  spec.plant.inputs = {"crank_drive"};
  spec.plant.outputs = {"follower_s", "slider_x"};
  const Model m = study_model(spec);
  const LinearSystem s = study_linearize(m).system;
  ASSERT_EQ(s.nx(), 2);
  ASSERT_EQ(s.nu(), 1);
  // shifted by the crank's motion (its acceleration drives the follower): named so
  EXPECT_EQ(s.state_names[0], "follower_slide~");
  const double x1 = geometry(0.5).x1;
  double worst = 0;
  for (double w : {0.1, 1.0, 5.0, 19.0, 21.0, 80.0, 500.0}) {
    const cd z(0, w);
    const Eigen::MatrixXcd M = z * Eigen::MatrixXcd::Identity(2, 2) - s.A.cast<cd>();
    const Eigen::VectorXcd xs = M.partialPivLu().solve(s.B.col(0).cast<cd>());
    const cd gs = (s.C.row(0).cast<cd>() * xs)(0) + s.D(0, 0), gx = (s.C.row(1).cast<cd>() * xs)(0) + s.D(1, 0);
    const cd es = -x1 * z * z / (z * z + k / m2);
    worst = std::max({worst, std::abs(gs - es) / std::abs(es), std::abs(gx - x1) / std::abs(x1)});
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_NEAR(s.D(0, 0), -x1, 1e-12);
  // the exact Jacobian over [u; u'; u''] (analytic) against autodiff and central differences,
  // away from rest with the crank turning and accelerating
  const PlantFunction f(m, m.q0, m.u_nominal(), partition_coordinates(m, m.q0));
  Eigen::VectorXd x(2), u(3);
  x << 0.0, 0.4;
  u << 0.5, 3.0, -7.0;
  Eigen::MatrixXd analytic;
  ASSERT_TRUE(f.analytic_jacobian(x, u, analytic));
  const Eigen::MatrixXd ad = plant_jacobian_autodiff(f, x, u);
  const Eigen::MatrixXd fd = plant_jacobian_fd_full(f, x, u, true);
  const double scale = ad.cwiseAbs().maxCoeff();
  EXPECT_LT((analytic - ad).cwiseAbs().maxCoeff() / scale, 1e-12) << analytic << "\n\n" << ad;
  EXPECT_LT((analytic - fd).cwiseAbs().maxCoeff() / scale, 1e-7) << analytic << "\n\n" << fd;
  EXPECT_GT(analytic.rightCols(3).cwiseAbs().maxCoeff(), 1e-2);
  // off the reference configuration (the follower displaced, the crank elsewhere): autodiff
  // against central differences
  x << 0.03, -0.2;
  u << 0.9, -2.0, 4.0;
  const Eigen::MatrixXd ad2 = plant_jacobian_autodiff(f, x, u);
  const Eigen::MatrixXd fd2 = plant_jacobian_fd_full(f, x, u, true);
  EXPECT_LT((ad2 - fd2).cwiseAbs().maxCoeff() / ad2.cwiseAbs().maxCoeff(), 1e-7) << ad2 << "\n\n" << fd2;
  // and its rows against the closed form: s'' = -(k/m2) s - x'' at the crank's u, u', u''
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);
  const Geometry G = geometry(0.9);
  EXPECT_NEAR(xd[1], -(k / m2) * 0.03 - (G.x2 * 4.0 + G.x1 * 4.0), 1e-11);
  EXPECT_NEAR(y[1], G.x, 1e-12);
}

// the example's own study: the crank held (a motion outside Plant/In, at rest), the follower
// pushed; the drive torque as an output, at rest tau = m_r g p_y' + x_theta (F - k s)
TEST(MotionLoop, TheDriveTorqueLinearizesAsTheVirtualWorkAtRest) {
  const LinearSystem s = study_linearize(study_model(example())).system;
  ASSERT_EQ(s.nx(), 2);
  ASSERT_EQ(s.output_names.size(), 3u);
  EXPECT_EQ(s.output_names[2], "drive_torque");
  const Geometry G = geometry(0.5);
  EXPECT_NEAR(s.A(1, 0), -k / m2, 1e-10);
  EXPECT_NEAR(s.B(1, 0), 1 / m2, 1e-12);
  EXPECT_NEAR(s.C(2, 0), -k * G.x1, 1e-10);
  EXPECT_NEAR(s.C(2, 1), 0.0, 1e-12);
  EXPECT_NEAR(s.D(2, 0), G.x1, 1e-12);
  EXPECT_NEAR(s.y0[2], drive_torque(0.5, 0, 0, 0), 1e-12);
  EXPECT_NEAR(s.y0[0], G.x, 1e-13);
}

std::string error_of(const ModelSpec& spec) {
  try {
    study_model(spec);
  } catch (const ModelError& e) {
    return e.path() + ": " + e.what();
  }
  return "no error";
}

TEST(MotionLoop, MotionsThatOverDriveOrCannotCloseTheLoopAreRefusedNamingIt) {
  // the slider driven too: the loop fixes it from the crank
  ModelSpec spec = example();
  ActuatorSpec slide;
  slide.name = "slide_drive";
  slide.type = ActuatorType::Motion;
  slide.joint = "slide";
  spec.actuators.push_back(slide);
  for (JointSpec& j : spec.joints)  // where the loop closes with the crank at 0.5
    if (j.name == "slide") j.q0 = Eigen::VectorXd::Constant(1, geometry(0.5).x);
  std::string err = error_of(spec);
  EXPECT_EQ(err.rfind("/actuators/", 0), 0u) << err;
  EXPECT_NE(err.find("\"wrist_pin\""), std::string::npos) << err;
  EXPECT_NE(err.find("over-drives"), std::string::npos) << err;
  // ... and where the two motions' q0 do not close the loop: the same reason, not the residual
  for (JointSpec& j : spec.joints)
    if (j.name == "slide") j.q0 = Eigen::VectorXd::Constant(1, 0.39);
  err = error_of(spec);
  EXPECT_EQ(err.rfind("/actuators/", 0), 0u) << err;
  EXPECT_NE(err.find("\"wrist_pin\""), std::string::npos) << err;
  EXPECT_NE(err.find("over-drives"), std::string::npos) << err;
  // the slider driven alone, held where the rod cannot reach (x > r + l)
  spec = example();
  spec.actuators[0].joint = "slide";
  spec.sensors.erase(spec.sensors.begin() + motion_column({"slider_x", "follower_s", "drive_torque"}, "drive_torque"));
  spec.plant.outputs = {"slider_x"};
  for (JointSpec& j : spec.joints)
    if (j.name == "slide") j.q0 = Eigen::VectorXd::Constant(1, 0.45);
  err = error_of(spec);
  EXPECT_EQ(err.rfind("/constraints/0", 0), 0u) << err;
  EXPECT_NE(err.find("\"crank_drive\""), std::string::npos) << err;
  // ... and where it can, a slider-driven crank: two coordinates free, one degree of freedom
  for (JointSpec& j : spec.joints)
    if (j.name == "slide") j.q0 = Eigen::VectorXd::Constant(1, 0.35);
  ASSERT_EQ(error_of(spec), "no error");
  EXPECT_EQ(study_model(spec).dof(), 1);
}

}  // namespace
}  // namespace codyna
