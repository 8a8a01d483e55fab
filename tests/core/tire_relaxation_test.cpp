// Transient slip (issue 39): a tire's relaxation lengths make its contact's deflections states of
// the plant and of every simulation (dynamics/tire_effect.hpp, docs/tires.md). What is checked,
// each against something independent of the path that computed it:
//   the single-track car with tire lag (Rajamani's bicycle, both axles' lateral deflections as
//     states) has the closed form's transfer functions and eigenvalues (a 4-state model written
//     out below), its steer reaches the lateral acceleration only through the lag (D = 0);
//   a free response from a sideslip, simulated by every integrator, follows the closed form's
//     matrix exponential; a run started on a steady turn stays on it, the deflections steady;
//   the sedan with Magic Formula tires and both relaxations: automatic differentiation of the
//     plant equals central differences off the steady deflections; its steady turn holds;
//   the fields' bad values are refused naming them, and a saved model keeps them.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/data.hpp"
#include "dynamics/effects.hpp"
#include "model/errors.hpp"
#include "simulation/simulator.hpp"
#include "study/files.hpp"
#include "study/tire_contacts.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"
#include "vehicle/magic_formula_relaxation.hpp"
#include "vehicle/tir_file.hpp"

using namespace codyna;

namespace {

// Rajamani's single-track car (examples/single_track_car.json) with a lateral relaxation length
// sigma on both axles' tires, straight at U: states [v, r, u_f, u_r] (lateral velocity, yaw rate,
// the tires' lateral deflections), input the steer delta:
//   m (v' + U r) = F_f + F_r,  Iz r' = a F_f - b F_r,  F_i = -C_i u_i / sigma
//   u_f' = v + a r - U delta - (U / sigma) u_f,  u_r' = v - b r - (U / sigma) u_r
// (sigma -> 0: u_f = sigma (v + a r - U delta) / U, the bicycle's F_f = C_f (delta - (v + a r) / U))
struct LaggedBicycle {
  double m = 1573, Iz = 2873, a = 1.1, b = 1.58, Cf = 160000, Cr = 160000, U = 30, sigma = 0.6;
  Eigen::Matrix4d A() const {
    Eigen::Matrix4d A;
    A << 0, -U, -Cf / (m * sigma), -Cr / (m * sigma),  //
        0, 0, -a * Cf / (Iz * sigma), b * Cr / (Iz * sigma),  //
        1, a, -U / sigma, 0,  //
        1, -b, 0, -U / sigma;
    return A;
  }
  Eigen::Vector4d B() const { return Eigen::Vector4d(0, 0, -U, 0); }
  // outputs: yaw rate, lateral velocity, lateral acceleration (F_f + F_r) / m
  Eigen::Matrix<double, 3, 4> C() const {
    Eigen::Matrix<double, 3, 4> C;
    C << 0, 1, 0, 0,  //
        1, 0, 0, 0,  //
        0, 0, -Cf / (m * sigma), -Cr / (m * sigma);
    return C;
  }
};

ModelSpec single_track_with_lag(double sigma_y, double sigma_x = 0) {
  ModelSpec spec = study_read_model(test::example_path("single_track_car.json"));
  for (EffectSpec& e : spec.effects)
    if (e.type == EffectType::Tire) {
      e.lateral_relaxation_length = sigma_y;
      e.longitudinal_relaxation_length = sigma_x;
    }
  return spec;
}

std::complex<double> lag_transfer(const LinearSystem& s, std::complex<double> sc, int output) {
  const int n = static_cast<int>(s.A.rows());
  const Eigen::MatrixXcd M = sc * Eigen::MatrixXcd::Identity(n, n) - s.A.cast<std::complex<double>>();
  const Eigen::VectorXcd xs = M.partialPivLu().solve(s.B.col(0).cast<std::complex<double>>());
  return (s.C.row(output).cast<std::complex<double>>() * xs)(0) + s.D(output, 0);
}

}  // namespace

TEST(TireRelaxation, TheSingleTrackCarWithTireLagIsTheClosedForm) {
  const LaggedBicycle bike;
  const Model mod = study_model(single_track_with_lag(bike.sigma));
  ASSERT_EQ(mod.ns, 2);
  EXPECT_EQ(mod.s_names[0], "front_tire.deflection_y");
  EXPECT_EQ(mod.s_names[1], "rear_tire.deflection_y");
  const LinearSystem s = study_linearize(mod).system;
  // the deflections are states of the plant, named, last
  ASSERT_GE(s.nx(), 4);
  EXPECT_EQ(s.state_names[static_cast<std::size_t>(s.nx() - 2)], "front_tire.deflection_y");
  EXPECT_EQ(s.state_names[static_cast<std::size_t>(s.nx() - 1)], "rear_tire.deflection_y");
  EXPECT_EQ(s.state_units[static_cast<std::size_t>(s.nx() - 1)], "m");
  EXPECT_EQ(s.x0.tail(2).cwiseAbs().maxCoeff(), 0.0);  // straight: no deflection
  const Eigen::Matrix4d A = bike.A();
  const Eigen::Vector4d B = bike.B();
  const Eigen::Matrix<double, 3, 4> C = bike.C();
  double worst = 0;
  for (int i = 0; i <= 60; ++i) {
    const double w = 0.1 * std::pow(1000.0, i / 60.0);  // 0.1 .. 100 rad/s
    const std::complex<double> sc(0.0, w);
    const Eigen::Vector4cd xs = (sc * Eigen::Matrix4cd::Identity() - A.cast<std::complex<double>>())
                                    .partialPivLu()
                                    .solve(B.cast<std::complex<double>>());
    for (int o = 0; o < 3; ++o) {
      const std::complex<double> want = (C.row(o).cast<std::complex<double>>() * xs)(0);
      worst = std::max(worst, std::abs(lag_transfer(s, sc, o) - want) / std::abs(want));
    }
  }
  EXPECT_LT(worst, 1e-8);
  // the steer reaches the lateral acceleration only through the deflections: no feedthrough
  EXPECT_LT(std::abs(s.D(2, 0)), 1e-9 * bike.Cf / bike.m);
  // the closed form's four eigenvalues are among the plant's (the others: the road position, the
  // heading and the speed, which the tires without longitudinal stiffness leave at 0)
  const Eigen::VectorXcd want = Eigen::EigenSolver<Eigen::Matrix4d>(A).eigenvalues();
  const Eigen::VectorXcd got = Eigen::EigenSolver<Eigen::MatrixXd>(s.A).eigenvalues();
  for (Eigen::Index k = 0; k < want.size(); ++k) {
    double nearest = 1e300;
    for (Eigen::Index j = 0; j < got.size(); ++j) nearest = std::min(nearest, std::abs(got[j] - want[k]));
    EXPECT_LT(nearest, 1e-8 * std::abs(want[k])) << want[k];
  }
  // and the lag matters: at 10 rad/s the yaw-rate response differs from the steady tires' by > 5 %
  const LinearSystem steady = study_linearize(study_model(single_track_with_lag(0))).system;
  const std::complex<double> at10(0.0, 10.0);
  const double change = std::abs(lag_transfer(s, at10, 0) - lag_transfer(steady, at10, 0)) / std::abs(lag_transfer(steady, at10, 0));
  EXPECT_GT(change, 0.05);
  std::printf("[ TireRelaxation ] single track, sigma %.2f m: largest relative TF difference %.2e over 0.1..100 rad/s; "
              "eigenvalues %s; the lag changes r/delta at 10 rad/s by %.1f %%\n",
              bike.sigma, worst, [&] {
                std::string t;
                for (Eigen::Index k = 0; k < want.size(); ++k) {
                  char buf[64];
                  std::snprintf(buf, sizeof buf, "%s%.4g%+.4gj", k ? ", " : "", want[k].real(), want[k].imag());
                  t += buf;
                }
                return t;
              }().c_str(),
              100 * change);
}

// A free response from a small sideslip, every integrator: the nonlinear run's yaw rate and
// deflections follow x(t) = exp(A t) x(0) of the closed form (x(0)'s deflections at rest there,
// as the simulator starts them)
TEST(TireRelaxation, EveryIntegratorCarriesTheDeflections) {
  const LaggedBicycle bike;
  const Model mod = study_model(single_track_with_lag(bike.sigma));
  const int body = mod.find_joint("body");
  ASSERT_GE(body, 0);
  const int iv = mod.joints[static_cast<std::size_t>(body)].idx_v;
  const double v0 = 0.02;  // m/s lateral (the planar joint's y, heading 0)
  Eigen::VectorXd q0 = mod.q0, vv0 = mod.v0;
  vv0[iv + 1] = v0;
  // the closed form from the same start: deflections at rest, u = sigma V_y / U
  const Eigen::Vector4d x0(v0, 0, bike.sigma * v0 / bike.U, bike.sigma * v0 / bike.U);
  const Eigen::Matrix4d A = bike.A();
  for (const char* method : {"cvode-bdf", "cvode-adams", "ida", "arkode", "rk4"}) {
    SimulationOptions so;
    so.q0 = q0;
    so.v0 = vv0;
    so.t_end = 1.0;
    so.output_step = 0.05;
    so.integrator.method = method;
    so.integrator.rtol = 1e-10;
    so.integrator.atol = 1e-12;
    if (std::string(method) == "rk4") so.integrator.max_step = 1e-4;
    const SimulationResult r = simulate(mod, nullptr, nullptr, so);
    ASSERT_TRUE(r.completed) << method << ": " << r.failure;
    ASSERT_EQ(r.s.cols(), 2);
    EXPECT_EQ(r.s_names[0], "front_tire.deflection_y");
    EXPECT_NEAR(r.s(0, 0), x0[2], 1e-15);
    double worst_r = 0, worst_s = 0, peak_r = 0;
    for (int k = 0; k < r.samples(); ++k) {
      const Eigen::Vector4d x = (A * r.t[static_cast<std::size_t>(k)]).exp() * x0;
      worst_r = std::max(worst_r, std::abs(r.v(k, iv + 2) - x[1]));
      worst_s = std::max(worst_s, std::max(std::abs(r.s(k, 0) - x[2]), std::abs(r.s(k, 1) - x[3])));
      peak_r = std::max(peak_r, std::abs(x[1]));
    }
    // the nonlinear terms are of the order of the sideslip angle squared (v0 / U)^2 ~ 4e-7
    EXPECT_LT(worst_r, 1e-5 * peak_r) << method;
    EXPECT_LT(worst_s, 1e-5 * x0[2]) << method;
    std::printf("[ TireRelaxation ] %-11s free response over 1 s: |r - closed form| %.2e (peak %.3g rad/s), "
                "|deflection - closed form| %.2e m\n",
                method, worst_r, peak_r, worst_s);
  }
}

TEST(TireRelaxation, ARunStartedOnASteadyTurnStaysOnItWithTheDeflectionsSteady) {
  ModelSpec spec = single_track_with_lag(0.6);
  spec.analysis.steady.radius = 120;
  spec.analysis.free_inputs = {"steer", "drive"};
  const Model mod = study_model(spec);
  const StudyLinearization sl = study_linearize(mod);
  ASSERT_TRUE(sl.op.motion.has_value());
  EXPECT_LT(sl.op.residual, 1e-8);
  EXPECT_LT(sl.lin.motion_residual, 1e-8);  // the deflections' rates included
  EXPECT_LT(sl.lin.motion_drift, 1e-9);
  // the same motion as the car with steady tires (the deflections at rest carry the steady slips):
  // the steer and the drive force that hold it, the velocities
  ModelSpec plain = single_track_with_lag(0);
  plain.analysis.steady.radius = 120;
  plain.analysis.free_inputs = {"steer", "drive"};
  const StudyLinearization sp = study_linearize(study_model(plain));
  EXPECT_NEAR(sl.op.u[0], sp.op.u[0], 1e-10 * std::abs(sp.op.u[0]));
  EXPECT_NEAR(sl.op.u[1], sp.op.u[1], 1e-8 * std::abs(sp.op.u[1]));
  EXPECT_LT((sl.op.v - sp.op.v).cwiseAbs().maxCoeff(), 1e-10);
  // the deflections at the turn: steady and not zero (the tires carry the turn's side forces)
  const Eigen::VectorXd s_turn = sl.lin.system.x0.tail(2);
  EXPECT_GT(s_turn.cwiseAbs().minCoeff(), 1e-4);
  SimulationOptions so;
  const Model run = held_at(mod, sl.op, so);
  so.t_end = 2.0;
  so.output_step = 0.1;
  so.integrator.rtol = 1e-10;
  so.integrator.atol = 1e-12;
  const SimulationResult res = simulate(run, nullptr, nullptr, so);
  ASSERT_TRUE(res.completed) << res.failure;
  const int iv = mod.joints[static_cast<std::size_t>(mod.find_joint("body"))].idx_v;
  double worst_s = 0, worst_r = 0;
  for (int k = 0; k < res.samples(); ++k) {
    worst_s = std::max(worst_s, (res.s.row(k).transpose() - s_turn).cwiseAbs().maxCoeff());
    worst_r = std::max(worst_r, std::abs(res.v(k, iv + 2) - sl.op.v[iv + 2]));
  }
  EXPECT_LT(worst_s, 1e-7 * s_turn.cwiseAbs().maxCoeff());
  EXPECT_LT(worst_r, 1e-8);
  std::printf("[ TireRelaxation ] 120 m turn: deflections %.4g, %.4g mm; 2 s from the steady state: |ds| %.2e m, |dr| %.2e rad/s\n",
              1e3 * s_turn[0], 1e3 * s_turn[1], worst_s, worst_r);
}

// The sedan (Magic Formula 6.1, closed-loop suspensions) with both relaxations on its four tires:
// the exact Jacobian (automatic differentiation of the plant) equals central differences, at the
// steady turn and with the deflections moved off their rest
namespace {
void sedan_jacobian_check(bool from_file) {
  const std::string path = test::example_path("sedan.json");
  ModelSpec spec = study_read_model(path);
  for (EffectSpec& e : spec.effects)
    if (e.type == EffectType::Tire) {
      if (from_file) {
        e.relaxation_from_file = true;
      } else {
        e.longitudinal_relaxation_length = 0.15;
        e.lateral_relaxation_length = 0.45;
      }
    }
  spec.analysis.steady.lateral_acceleration = 0.4 * 9.80665;
  const Model mod = study_model(spec, path);
  ASSERT_EQ(mod.ns, 8);
  const StudyLinearization sl = study_linearize(mod);
  EXPECT_LT(sl.op.residual, 1e-8);
  EXPECT_LT(sl.lin.motion_residual, 1e-8);
  const LinearSystem& s = sl.lin.system;
  ASSERT_EQ(s.nx(), 38);  // the sedan's 30 and 8 deflections
  // the deflections' rows: each decays at U / sigma at fixed motion (its own diagonal entry)
  const double U = 25.0;
  for (int k = 0; k < 8 && !from_file; ++k) {
    const double sigma = k % 2 ? 0.45 : 0.15;
    const int i = 30 + k;
    EXPECT_NEAR(s.A(i, i), -U / sigma, 0.02 * U / sigma) << s.state_names[static_cast<std::size_t>(i)];
  }
  // central differences of the same plant function, at the turn and off it
  PlantFunction f(mod, sl.op.q, sl.op.u, sl.lin.partition);
  f.set_motion(*sl.op.motion);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx());
  for (int k = 0; k < f.nw(); ++k) x[f.nz() + k] = sl.op.v[f.rates()[static_cast<std::size_t>(k)]];
  x.tail(8) = s.x0.tail(8);
  Eigen::VectorXd u(f.nu());
  for (int k = 0; k < f.nu(); ++k) u[k] = sl.op.u[mod.plant_inputs[static_cast<std::size_t>(k)]];
  for (int moved = 0; moved < 2; ++moved) {
    if (moved) x.tail(8) += Eigen::VectorXd::LinSpaced(8, -2e-3, 3e-3);  // deflections off their rest
    const Eigen::MatrixXd Je = plant_jacobian(f, x, u, JacobianMethod::Exact);
    const Eigen::MatrixXd Jc = plant_jacobian_fd_full(f, x, u, true);
    const double scale = Je.cwiseAbs().maxCoeff();
    // every column but the deflections' (whose central differences carry the Magic Formula's
    // curvature near kappa = 0 over the step of 6e-6 m, ~1e-6 of the entry: smaller steps and
    // Richardson's extrapolation below)
    Eigen::MatrixXd D = Je - Jc;
    D.middleCols(30, 8).setZero();
    const double e_all = D.cwiseAbs().maxCoeff() / scale;
    // the deflections' columns: central differences at 1e-6 and 5e-7 m, extrapolated (error O(h^4))
    const auto column = [&](int k, double h) {
      Eigen::VectorXd xp = x, xm = x, fp, fm, yp, ym;
      xp[k] += h;
      xm[k] -= h;
      f.eval<double>(xp, u, fp, yp);
      f.eval<double>(xm, u, fm, ym);
      Eigen::VectorXd c(fp.size() + yp.size());
      c << (fp - fm) / (2 * h), (yp - ym) / (2 * h);
      return c;
    };
    Eigen::MatrixXd Jr(Je.rows(), 8);
    for (int k = 0; k < 8; ++k) Jr.col(k) = (4 * column(30 + k, 5e-7) - column(30 + k, 1e-6)) / 3;
    const double e_s = (Je.middleCols(30, 8) - Jr).cwiseAbs().maxCoeff() / Je.middleCols(30, 8).cwiseAbs().maxCoeff();
    EXPECT_LT(e_all, 1e-6) << (moved ? "off rest" : "at rest");
    EXPECT_LT(e_s, 1e-9) << (moved ? "off rest" : "at rest");
    std::printf("[ TireRelaxation ] sedan (%s) in the 0.4 g turn%s: exact vs central differences %.2e (the deflections' columns vs extrapolated differences %.2e)\n",
                from_file ? "lengths from the .tir" : "0.15 / 0.45 m", moved ? ", deflections moved" : "", e_all, e_s);
  }
}

}  // namespace

TEST(TireRelaxation, TheSedansJacobianWithDeflectionsEqualsCentralDifferences) { sedan_jacobian_check(false); }

// the lengths from the .tir file depend on the load: their derivative is in the exact Jacobian too
TEST(TireRelaxation, TheSedansJacobianWithTheTirFilesLengthsEqualsCentralDifferences) { sedan_jacobian_check(true); }

TEST(TireRelaxation, BadLengthsAreRefusedNamingTheFieldAndASavedModelKeepsThem) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "codyna_tire_relaxation_test";
  std::filesystem::create_directories(dir);
  const ModelSpec good = single_track_with_lag(0.6, 0.2);
  const std::string saved = (dir / "lag.json").string();
  study_save_model(good, saved);
  const ModelSpec back = study_read_model(saved);
  int tires = 0;
  for (const EffectSpec& e : back.effects)
    if (e.type == EffectType::Tire) {
      ++tires;
      EXPECT_EQ(e.lateral_relaxation_length, 0.6);
      EXPECT_EQ(e.longitudinal_relaxation_length, 0.2);
    }
  EXPECT_EQ(tires, 2);
  EXPECT_EQ(study_model(back).ns, 4);
  // a negative length: refused naming the file's field
  std::ifstream in(saved);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "\"lateral_relaxation_length\": 0.6";
  const std::size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos) << text.substr(0, 400);
  text.replace(at, key.size(), "\"lateral_relaxation_length\": -0.6");
  try {
    study_parse_model_text(text, "lag.json");
    ADD_FAILURE() << "a negative relaxation length was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("lateral_relaxation_length"), std::string::npos) << e.what();
  }
  // the .tir's lengths asked of a linear tire: refused naming the field and the law
  std::string linear = text;
  linear.replace(linear.find("\"lateral_relaxation_length\": -0.6"), std::string("\"lateral_relaxation_length\": -0.6").size(),
                 "\"relaxation_from_file\": true");
  try {
    study_parse_model_text(linear, "lag.json");
    ADD_FAILURE() << "relaxation_from_file on a linear tire was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("relaxation_from_file"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("magic_formula"), std::string::npos) << e.what();
  }
  // on the sedan's Magic Formula tires with a length given as well: refused
  const std::string sedan = test::example_path("sedan.json");
  ModelSpec both = study_read_model(sedan);
  for (EffectSpec& e : both.effects)
    if (e.type == EffectType::Tire) {
      e.relaxation_from_file = true;
      e.lateral_relaxation_length = 0.4;
    }
  try {
    study_model(both, sedan);
    ADD_FAILURE() << "relaxation_from_file with a lateral_relaxation_length was accepted";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("relaxation_from_file"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// the deflections reach the results files (HDF5 /s, /names/effect_states; the CSV's last columns)
// and come back; a model without them writes neither
TEST(TireRelaxation, TheDeflectionsAreInTheResultsFiles) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "codyna_tire_relaxation_results";
  std::filesystem::create_directories(dir);
  const Model mod = study_model(single_track_with_lag(0.6));
  Eigen::VectorXd v0 = mod.v0;
  v0[mod.joints[static_cast<std::size_t>(mod.find_joint("body"))].idx_v + 1] = 0.02;
  SimulationOptions so;
  so.v0 = v0;
  so.t_end = 0.2;
  so.output_step = 0.05;
  const SimulationResult r = simulate(mod, nullptr, nullptr, so);
  ASSERT_TRUE(r.completed);
  const std::string h5 = (dir / "lag.h5").string(), csv = (dir / "lag.csv").string();
  study_write_results(r, h5, csv);
  const SimulationResult back = study_read_results(h5);
  ASSERT_EQ(back.s.rows(), r.s.rows());
  ASSERT_EQ(back.s.cols(), 2);
  EXPECT_EQ((back.s - r.s).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(back.s_names, r.s_names);
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  const std::string tail = ",front_tire.deflection_y,rear_tire.deflection_y";
  ASSERT_GE(header.size(), tail.size());
  EXPECT_EQ(header.substr(header.size() - tail.size()), tail) << header;
  // without relaxation: no /s
  const SimulationResult plain = simulate(study_model(single_track_with_lag(0)), nullptr, nullptr, so);
  const std::string h5b = (dir / "plain.h5").string();
  study_write_results(plain, h5b);
  EXPECT_EQ(study_read_results(h5b).s.cols(), 0);
  std::filesystem::remove_all(dir);
}

// The .tir file's relaxation lengths (vehicle/magic_formula_relaxation.hpp) against the formulas
// written out with the files' numbers: the book file's closed forms (Kxk = PKX1 Fz, Kya = PKY1 Fz0
// sin(2 atan(Fz / (PKY2 Fz0)))), MF 5.2's PTX, PTY formulas, and MF 6.1's slip stiffnesses from
// MFeval's table over its carcass stiffnesses
TEST(TireRelaxation, TheTirFilesLengthsAreTheFormulasWithTheFilesNumbers) {
  const std::string dir = std::string(CODYNA_TEST_DATA_DIR) + "/tires/";
  // book file (MF 6.1, PCFX/PCFY 0): at 4000 N sigma_kappa = 64000 / 400000, sigma_alpha = 48000 / 100000
  const MagicFormulaParameters book = read_tir_file(dir + "PacejkaBook_Defaults.tir");
  const auto [bx, by] = magic_formula_relaxation_lengths<double>(book, 4000.0, 0.0, 16.7);
  EXPECT_NEAR(bx, 0.16, 1e-12);
  EXPECT_NEAR(by, 0.48, 1e-12);
  // MF 5.2: R0 0.4, FNOMIN 9416.6, PTX1 1.1898, PTX2 -6.148e-4, PTX3 -0.3717, PTY1 1.6245, PTY2 2.8506, PKY3 0.944
  const MagicFormulaParameters mf52 = read_tir_file(dir + "MagicFormula52_Paramerters.tir");
  for (const auto& [n, g] : {std::pair{1.0, 0.0}, std::pair{2.0, 0.05}, std::pair{0.5, -0.03}}) {
    const double Fz = n * 9416.6, dfz = n - 1;
    const auto [sx, sy] = magic_formula_relaxation_lengths<double>(mf52, Fz, g, 16.7);
    EXPECT_NEAR(sx, (1.1898 - 6.148e-4 * dfz) * std::exp(0.3717 * dfz) * 0.4 * n, 1e-12) << n;
    EXPECT_NEAR(sy, (1 - 0.944 * std::abs(g)) * 1.6245 * std::sin(2 * std::atan(n / 2.8506)) * 0.4, 1e-12) << n;
  }
  // MF 6.1: Kxk, Kya from MFeval's table (Fz 3376, 6752, 10128 N), over LONGITUDINAL_STIFFNESS 407611.8
  // (1 + PCFX1 dfz + PCFX2 dfz^2)(1 + PCFX3 dpi) and LATERAL_STIFFNESS 235336.8 (...)
  const MagicFormulaParameters mf61 = read_tir_file(dir + "MagicFormula61_Paramerters.tir");
  std::ifstream table(std::string(CODYNA_TEST_DATA_DIR) + "/tires/mfeval/MagicFormula61_Paramerters.csv");
  ASSERT_TRUE(table.good());
  std::string line;
  std::getline(table, line);  // Fz,kappa,alpha,gamma,Vx,Fx,Fy,Mz,Mx,My,Kxk,Kya,Re
  int checked = 0;
  double worst = 0;
  while (std::getline(table, line)) {
    std::vector<double> v;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) v.push_back(std::stod(cell));
    if (v.size() < 13 || std::abs(v[1]) > 1e-12 || std::abs(v[2]) > 1e-12) continue;  // the rows at zero slip
    const double Fz = v[0], gamma = v[3], dfz = (Fz - 6752) / 6752;
    const double dpi = (mf61.INFLPRES - mf61.NOMPRES) / mf61.NOMPRES;
    const double CFx = 407611.8 * (1 + mf61.PCFX1 * dfz + mf61.PCFX2 * dfz * dfz) * (1 + mf61.PCFX3 * dpi);
    const double CFy = 235336.8 * (1 + mf61.PCFY1 * dfz + mf61.PCFY2 * dfz * dfz) * (1 + mf61.PCFY3 * dpi);
    const auto [sx, sy] = magic_formula_relaxation_lengths<double>(mf61, Fz, gamma, v[4]);
    worst = std::max({worst, std::abs(sx - v[10] / CFx) / sx, std::abs(sy - std::abs(v[11]) / CFy) / sy});
    ++checked;
  }
  EXPECT_GE(checked, 6);
  EXPECT_LT(worst, 1e-9);
  std::printf("[ TireRelaxation ] .tir lengths: book file 0.16 / 0.48 m at 4000 N; MF 5.2 the PTX/PTY formulas; MF 6.1 "
              "MFeval's Kxk, Kya over the carcass stiffnesses at %d loads and cambers: %.2e relative\n",
              checked, worst);
}

// What the 3-D view draws (study_tire_contacts): the force the deflections carry, at rest by
// default; a sample's deflections move it (none: no side force), as the simulation applies it
TEST(TireRelaxation, TheContactsShownCarryTheDeflections) {
  const Model mod = study_model(single_track_with_lag(0.6));
  Eigen::VectorXd v0 = mod.v0;
  v0[mod.joints[static_cast<std::size_t>(mod.find_joint("body"))].idx_v + 1] = 0.3;  // sideslip
  const std::vector<TireContactReport> rest = study_tire_contacts(mod, mod.q0, v0);
  Data d(mod);
  const Eigen::VectorXd s = effect_states_steady(mod, d, mod.q0, v0);
  const std::vector<TireContactReport> given = study_tire_contacts(mod, mod.q0, v0, s);
  const std::vector<TireContactReport> none = study_tire_contacts(mod, mod.q0, v0, Eigen::VectorXd::Zero(mod.ns));
  ASSERT_EQ(rest.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    // at rest: the steady tire's force, -C alpha with tan(alpha) = 0.3 / 30
    EXPECT_NEAR(rest[k].Fy, -160000 * std::atan(0.3 / 30), 1e-9 * 1600) << k;
    EXPECT_EQ(given[k].Fy, rest[k].Fy) << k;
    EXPECT_EQ(none[k].Fy, 0.0) << k;
    EXPECT_EQ(none[k].alpha, 0.0) << k;
  }
  EXPECT_THROW(study_tire_contacts(mod, mod.q0, v0, Eigen::VectorXd::Zero(3)), std::invalid_argument);
}
