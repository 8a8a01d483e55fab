// The frequency response of the nonlinear plant (study/freqresp_job, analysis/frequency_estimate):
// the harmonic fit against a signal made of known parts; the single-track car's estimate against
// its linearization's C (jwI - A)^-1 B + D, with the gap shrinking as the amplitude squared (the
// plant's own nonlinearity, not the estimator's error); the inverted cart-pendulum (an unstable
// plant) measured in closed loop under its LQR equals the plant's linear response (the excitation
// adds to the controller's command: the direct method of closed-loop identification); refusals
// name the option.
#include "study/freqresp_job.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "analysis/frequency_estimate.hpp"
#include "io/model_file.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

TEST(FrequencyEstimate, FitRecoversAKnownSignal) {
  const double w = 2.5, T = 2 * std::numbers::pi / w;
  const int n = 4 * 64;
  Eigen::VectorXd t(n), x(n);
  for (int i = 0; i < n; ++i) {
    t[i] = 3 * T + i * T / 64;
    // offset, drift, fundamental 1.5 at phase 0.4, third harmonic 0.1 (cosine), second 0.02 (sine)
    x[i] = 0.3 + 0.02 * (t[i] - 5 * T) + 1.5 * std::sin(w * t[i] + 0.4) + 0.1 * std::cos(3 * w * t[i]) +
           0.02 * std::sin(2 * w * t[i]);
  }
  const HarmonicFit f = fit_harmonics(t, x, w, 5);
  // 1.5 sin(wt + 0.4) = Re(-1.5 j e^{j 0.4} e^{jwt})
  const std::complex<double> X1 = std::complex<double>(0, -1.5) * std::exp(std::complex<double>(0, 0.4));
  EXPECT_LT(std::abs(f.harmonics[0] - X1), 1e-12);
  EXPECT_LT(std::abs(f.harmonics[1] - std::complex<double>(0, -0.02)), 1e-12);
  EXPECT_LT(std::abs(f.harmonics[2] - std::complex<double>(0.1, 0)), 1e-12);
  EXPECT_LT(std::abs(f.harmonics[3]), 1e-12);
  EXPECT_NEAR(f.drift, 0.02, 1e-12);
  EXPECT_NEAR(f.offset - f.drift * (0.5 * (t[0] + t[n - 1]) - 5 * T), 0.3, 1e-12);  // the offset is at the middle
  EXPECT_LT(f.residual_rms, 1e-12);
  EXPECT_NEAR(f.distortion(), std::hypot(0.02, 0.1) / 1.5, 1e-12);
  EXPECT_THROW(fit_harmonics(Eigen::VectorXd(t.head(10)), Eigen::VectorXd(x.head(10)), w, 5), std::invalid_argument);
  EXPECT_THROW(fit_harmonics(t, x, -1, 5), std::invalid_argument);
}

FreqRespRequest car_request(double amplitude) {
  FreqRespRequest r;
  r.run.model = test::example_path("single_track_car.json");
  r.frequencies = {0.5, 3.0, 20.0};
  r.amplitudes = {amplitude};
  return r;
}

TEST(FreqResp, SingleTrackCarEqualsItsLinearizationToTheAmplitudeSquared) {
  const ModelSpec spec = load_model_spec(test::example_path("single_track_car.json"));
  const FreqRespJob small = study_freqresp_job(car_request(1e-4), spec);
  ASSERT_EQ(small.points.size(), 3u);
  EXPECT_EQ(small.operating_point, "steady");
  EXPECT_EQ(small.controller, "none (open loop)");
  EXPECT_EQ(small.input_names, std::vector<std::string>{"steer"});
  // measured: 1.25e-5 of the linear response (lateral velocity at 0.5 rad/s)
  EXPECT_LT(small.largest_gap, 3e-5);
  for (const FreqRespPoint& p : small.points) {
    EXPECT_LT(p.distortion.maxCoeff(), 1e-5);  // measured 2.3e-6: the integration at rtol 1e-8 and the plant
    for (Eigen::Index i = 0; i < p.G.rows(); ++i) EXPECT_LT(std::abs(p.G(i, 0) - p.G_linear(i, 0)), 3e-5 * std::abs(p.G_linear(i, 0)));
  }
  // ten times the amplitude, a hundred times the gap: a cubic nonlinearity of the plant (the
  // steer's cosine, the speed the cornering drag takes), not the estimate's error
  const FreqRespJob large = study_freqresp_job(car_request(1e-3), spec);
  const double ratio = large.largest_gap / small.largest_gap;
  EXPECT_GT(ratio, 80);
  EXPECT_LT(ratio, 120);
}

TEST(FreqResp, AnUnstablePlantIsMeasuredInClosedLoop) {
  const ModelSpec spec = load_model_spec(test::example_path("cart_pendulum.json"));
  FreqRespRequest r;
  r.run.model = test::example_path("cart_pendulum.json");
  r.frequencies = {0.3, 2.0, 15.0};
  r.amplitudes = {0.01};
  const FreqRespJob job = study_freqresp_job(r, spec);  // the file's LQR closes the loop
  EXPECT_NE(job.controller.find("lqr"), std::string::npos) << job.controller;
  // the plant's own response (the unstable inverted pendulum's, as its linearization gives it):
  // the controller moves the force too, G = Y U^-1 takes it out; measured 1.2e-5
  EXPECT_LT(job.largest_gap, 1e-4);
  // without the loop the run cannot settle: refused, saying why
  r.run.open_loop = true;
  try {
    study_freqresp_job(r, spec);
    ADD_FAILURE() << "an unstable plant in open loop was not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the plant is unstable about the operating point"), std::string::npos) << e.what();
  }
}

TEST(FreqResp, RefusalsNameTheOption) {
  const ModelSpec spec = load_model_spec(test::example_path("single_track_car.json"));
  const auto refused = [&](FreqRespRequest r, const std::string& start) {
    try {
      study_freqresp_job(r, spec);
      ADD_FAILURE() << "not refused: " << start;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(start, 0), 0u) << e.what();
    }
  };
  FreqRespRequest r = car_request(1e-3);
  r.frequencies = {};
  refused(r, "--frequencies: give the frequencies");
  r.frequencies = {1, -2};
  refused(r, "--frequencies -2: expected frequencies > 0 rad/s");
  r = car_request(0);
  refused(r, "--amplitude 0: expected an amplitude other than 0");
  r = car_request(1e-3);
  r.amplitudes = {1e-3, 2e-3};
  refused(r, "--amplitude: expected one amplitude, or one per Plant/In input (1), got 2");
  r = car_request(1e-3);
  r.samples_per_period = 10;
  refused(r, "--samples-per-period 10: expected at least 24");
  r = car_request(1e-3);
  r.run.style = OptionStyle::Keyword;
  r.periods = 0;
  refused(r, "periods: expected 1 or more");
  EXPECT_THROW(study_frequency_grid("1:0:3", "--frequencies"), std::invalid_argument);
  const std::vector<double> g = study_frequency_grid("0.1:10:3", "--frequencies");
  ASSERT_EQ(g.size(), 3u);
  EXPECT_NEAR(g[1], 1.0, 1e-12);  // log-spaced
}

TEST(FreqResp, TheTableIsWrittenAndNeverReplacesAnotherFile) {
  const ModelSpec spec = load_model_spec(test::example_path("single_track_car.json"));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "codyna_freqresp_test";
  std::filesystem::create_directories(dir);
  const std::string csv = (dir / "car.csv").string();
  std::filesystem::remove(csv);
  FreqRespRequest r = car_request(1e-4);
  r.csv = csv;
  const FreqRespJob job = study_freqresp_job(r, spec);
  std::ifstream in(csv);
  std::string head, row;
  std::getline(in, head);
  std::getline(in, row);
  EXPECT_EQ(head.rfind("w_rad_s,f_Hz,yaw_rate/steer_magnitude,yaw_rate/steer_phase_deg,", 0), 0u) << head;
  EXPECT_EQ(std::stod(row.substr(0, row.find(','))), 0.5);
  const std::string other = (dir / "notes.csv").string();
  std::ofstream(other) << "mine\n";
  r.csv = other;
  EXPECT_THROW(study_freqresp_job(r, spec), std::invalid_argument);
  std::ifstream kept(other);
  std::getline(kept, head);
  EXPECT_EQ(head, "mine");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace codyna
