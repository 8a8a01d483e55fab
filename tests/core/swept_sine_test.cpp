// The swept-sine maneuver (study/maneuver_swept.cpp) and its pieces, each against an independent
// reference: the transforms' ratio against a first-order lag's response computed by fine RK4; ISO
// 7401's characteristic values against a second-order system's closed forms; the single-track car
// against the closed-form bicycle model; the sedan against its linearization at small amplitude.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/frequency_estimate.hpp"
#include "analysis/maneuver_metrics.hpp"
#include "study/files.hpp"
#include "study/maneuver_job.hpp"

using namespace codyna;

namespace {

const double kPiSwept = 3.14159265358979323846;

std::string swept_example(const std::string& name) { return std::string(CODYNA_EXAMPLES_DIR) + "/" + name; }

std::string swept_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

// the single-track bicycle (Rajamani; examples/single_track_car.json): steer -> yaw rate and
// lateral acceleration a_y = v' + U r, from its state-space form at s = j w
void bicycle(double w, std::complex<double>& yaw, std::complex<double>& lateral) {
  const double m = 1573, Iz = 2873, a = 1.1, b = 1.58, Cf = 160000, Cr = 160000, U = 30;
  using C = std::complex<double>;
  const C s(0, w);
  // m (v' + U r) = Cf (delta - (v + a r) / U) - Cr (v - b r) / U; Iz r' = a Cf (...) + b Cr (v - b r) / U
  const C a11 = s * m + (Cf + Cr) / U, a12 = m * U + (a * Cf - b * Cr) / U;
  const C a21 = (a * Cf - b * Cr) / U, a22 = s * Iz + (a * a * Cf + b * b * Cr) / U;
  const C det = a11 * a22 - a12 * a21;
  const C v = (Cf * a22 - a12 * a * Cf) / det, r = (a11 * a * Cf - a21 * Cf) / det;
  yaw = r;
  lateral = s * v + U * r;
}

}  // namespace

// The transforms' ratio of a first-order lag's input and output (tau = 0.3 s) is 1 / (1 + j w tau):
// the response to a tapered chirp from fine RK4 (1e-4 s), sampled every 5 ms, to 2e-5
TEST(FrequencyEstimate, TransformRatioOfAFirstOrderLagIsItsFrequencyResponse) {
  const double tau = 0.3, dt = 1e-4, t_end = 14;
  // a chirp from 0.2 to 1.8 Hz over 8 s under a Hann window (smooth at both ends)
  const auto u = [](double t) {
    const double x = t - 1;
    if (x <= 0 || x >= 8) return 0.0;
    return std::pow(std::sin(kPiSwept * x / 8), 2) * std::sin(2 * kPiSwept * (0.2 * x + 0.1 * x * x));
  };
  std::vector<double> t, du, dy;
  double y = 0;
  const int every = 50;
  for (int k = 0; k * dt <= t_end + 1e-12; ++k) {
    const double tk = k * dt;
    if (k % every == 0) {
      t.push_back(tk);
      du.push_back(u(tk));
      dy.push_back(y);
    }
    const auto f = [&](double tt, double yy) { return (u(tt) - yy) / tau; };
    const double k1 = f(tk, y), k2 = f(tk + dt / 2, y + dt / 2 * k1), k3 = f(tk + dt / 2, y + dt / 2 * k2),
                 k4 = f(tk + dt, y + dt * k3);
    y += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  const std::vector<double> w = {3.0, 4.0, 6.0, 8.0};
  const TransformRatio r = transform_ratio(t, du, dy, w);
  for (std::size_t i = 0; i < w.size(); ++i) {
    const std::complex<double> exact = 1.0 / std::complex<double>(1.0, w[i] * tau);
    EXPECT_LT(std::abs(r.H[i] - exact), 2e-5 * std::abs(exact)) << w[i] << ": " << r.H[i] << " vs " << exact;
    EXPECT_GT(r.input_share[i], 0.05) << w[i];
  }
  EXPECT_THROW(transform_ratio({0.0}, {0.0}, {0.0}, w), std::invalid_argument);
}

// ISO 7401's values of H = wn^2 / (s^2 + 2 zeta wn s + wn^2) (fn = 0.8 Hz, zeta = 0.3) on 200 points
// of 0.05 .. 4 Hz: the resonance wn sqrt(1 - 2 zeta^2), the peak 1 / (2 zeta sqrt(1 - zeta^2))
// over the gain at 0.05 Hz, the phase at 1 Hz -atan2(2 zeta r, 1 - r^2)
TEST(ManeuverMetrics, SweptSineCharacteristicsAreTheSecondOrdersClosedForms) {
  const double fn = 0.8, zeta = 0.3;
  const std::vector<double> f = log_grid(0.05, 4.0, 200);
  std::vector<std::complex<double>> H, L;
  const auto h = [&](double fq) {
    const std::complex<double> s(0, fq / fn);
    return 1.0 / (s * s + 2 * zeta * s + 1.0);
  };
  for (double fq : f) {
    H.push_back(h(fq));
    L.push_back(2.0 * h(fq));
  }
  const SweptSineCharacteristics c = swept_sine_characteristics(f, H, L);
  EXPECT_NEAR(c.resonance_hz, fn * std::sqrt(1 - 2 * zeta * zeta), 2e-4);
  EXPECT_NEAR(c.yaw_gain_low, std::abs(h(0.05)), 1e-15);
  // the parabola through grid points 2.2 % apart: 3e-5 of the peak (measured)
  EXPECT_NEAR(c.peak_ratio, 1 / (2 * zeta * std::sqrt(1 - zeta * zeta)) / std::abs(h(0.05)), 1e-4);
  const double r1 = 1.0 / fn, phase = -std::atan2(2 * zeta * r1, 1 - r1 * r1) * 180 / kPiSwept;
  EXPECT_NEAR(c.yaw_phase_1hz, phase, 0.05);  // linear interpolation between grid points 2 % apart
  EXPECT_NEAR(c.lateral_phase_1hz, phase, 0.05);
  EXPECT_NEAR(c.lateral_gain_low, 2 * std::abs(h(0.05)), 1e-15);
  // no resonance inside a grid whose gain falls from its first point
  std::vector<std::complex<double>> lag;
  for (double fq : f) lag.push_back(1.0 / std::complex<double>(1.0, fq));
  EXPECT_EQ(swept_sine_characteristics(f, lag).resonance_hz, 0.0);
  EXPECT_THROW(swept_sine_characteristics({1.0, 0.5, 2.0}, lag), std::invalid_argument);
}

// The single-track car's swept sine (0.001 rad, 0.1 .. 2 Hz over 30 s) is the closed-form bicycle's
// response to 1e-3 (measured: 4e-5) in yaw rate and lateral acceleration at every table frequency
TEST(Maneuver, SweptSineOnTheSingleTrackCarIsTheClosedFormBicycle) {
  const std::string file = swept_example("single_track_car.json");
  ManeuverRequest r;
  r.model = file;
  r.type = "swept-sine";
  r.steer = 0.001;
  const ManeuverReport rep = study_maneuver_job(r, study_read_model(file));
  ASSERT_TRUE(rep.valid) << rep.invalid_reason;
  ASSERT_EQ(rep.sw_frequency.size(), 12u);
  ASSERT_EQ(rep.sw_lateral.size(), 12u);
  ASSERT_TRUE(rep.sw_has_linear);
  double worst = 0;
  for (std::size_t k = 0; k < rep.sw_frequency.size(); ++k) {
    std::complex<double> yaw, lat;
    bicycle(2 * kPiSwept * rep.sw_frequency[k], yaw, lat);
    worst = std::max({worst, std::abs(rep.sw_yaw[k] - yaw) / std::abs(yaw), std::abs(rep.sw_lateral[k] - lat) / std::abs(lat)});
    EXPECT_LT(std::abs(rep.sw_yaw_linear[k] - yaw), 1e-9 * std::abs(yaw)) << k;
    EXPECT_LT(std::abs(rep.sw_lateral_linear[k] - lat), 1e-9 * std::abs(lat)) << k;
    EXPECT_GT(rep.sw_input_share[k], 0.1) << k;
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_LT(rep.sw_gap_yaw, 1e-3);
  EXPECT_NEAR(rep.sw_metrics.resonance_hz, rep.sw_metrics_linear.resonance_hz, 1e-3 * rep.sw_metrics_linear.resonance_hz);
  EXPECT_NEAR(rep.sw_metrics.yaw_gain_low, rep.sw_metrics_linear.yaw_gain_low, 1e-3 * rep.sw_metrics_linear.yaw_gain_low);
  std::cout << "largest relative difference from the closed form " << worst << ", resonance " << rep.sw_metrics.resonance_hz
            << " Hz\n";
}

// The sedan at 0.005 rad of steering wheel (0.02 deg at the road wheels), 0.3 .. 2 Hz over 8 s:
// the estimate is the linearization's to 1e-3 of its largest; at 1 rad the gap is tens of percent
// (the tires' nonlinearity), and the report says where
TEST(Maneuver, SweptSineOnTheSedanIsItsLinearModelAtSmallSteer) {
  const std::string file = swept_example("sedan.json");
  const ModelSpec spec = study_read_model(file);
  ManeuverRequest r;
  r.model = file;
  r.type = "swept-sine";
  r.steer = 0.005;
  r.frequency_min = 0.3;
  r.sweep_time = 8;
  r.t_end = 0.5 + 8 + 1.5;  // the yaw modes decay at 10 1/s: 1.5 s at rest settles them to 3e-7
  r.points = 5;
  const ManeuverReport small = study_maneuver_job(r, spec);
  ASSERT_TRUE(small.valid) << small.invalid_reason;
  ASSERT_TRUE(small.sw_has_linear);
  EXPECT_LT(small.sw_gap_yaw, 1e-3);
  EXPECT_LT(small.sw_gap_lateral, 1e-3);
  std::cout << "gaps at 0.005 rad: yaw rate " << small.sw_gap_yaw << " at " << small.sw_gap_yaw_hz << " Hz, a_y "
            << small.sw_gap_lateral << "\n";
}

TEST(Maneuver, SweptSineRefusalsNameTheFlag) {
  const std::string file = swept_example("single_track_car.json");
  const ModelSpec spec = study_read_model(file);
  const auto refusal = [&](auto set) {
    ManeuverRequest r;
    r.model = file;
    r.type = "swept-sine";
    set(r);
    return swept_error([&] { study_maneuver_job(r, spec); });
  };
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.frequency_max = 0.05; }), "--frequency-max: expected a frequency above --frequency-min");
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.frequency_min = -1; }), "--frequency-min: expected a number > 0, got -1");
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.sweep_time = 5; }), "--sweep-time: the sweep must last at least 2 periods of --frequency-min");
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.points = 2; }), "--points: expected 3 to 1000 frequencies");
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.t_end = 10; }),
            "--t-end: the run must last at least 1 s past the sweep's end (the response settles)");
  EXPECT_EQ(refusal([](ManeuverRequest& r) { r.steer = 0; }), "--steer: expected a steer amplitude other than 0");
}
