// The frequency response of the nonlinear plant (codyna freqresp; issue 40): each Plant/In input
// excited in turn about the operating point by a sine of the amplitude the user sets (a
// sinestream: one frequency at a time, run until the loop has settled, then measured over whole
// periods), the model simulated as it is (with the study's controller when it has one: the
// excitation adds to the controller's command, and the plant's own inputs and outputs are
// measured), and the gain and phase from every Plant/In to every Plant/Out estimated by a
// least-squares fit of the fundamental and its harmonics (analysis/frequency_estimate.hpp),
// G(jw) = Y U^-1. Set against the linearization's C (jwI - A)^-1 B + D at the same point: the gap
// says where the linear model stops describing the plant (a large amplitude, a saturation, a
// nonlinear tire), the harmonics' share how nonlinear the response is.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "study/jobs.hpp"

namespace codyna {

struct FreqRespRequest {
  SimulateRequest run;                 // the model, the point, the plant, the controller, the solver
                                       // (its t_end, output_step and outputs are the job's own)
  std::vector<double> frequencies;     // rad/s, > 0 (required)
  std::vector<double> amplitudes;      // one per Plant/In, or one for all (input units); default 0.01
  int settle_periods = 5;              // at least this many periods before measuring, and at
                                       // least 8 / (the loop's slowest decay rate)
  int periods = 4;                     // measured
  int samples_per_period = 64;
  int harmonics = 5;                   // fitted (the first is the response)
  std::string csv;                     // the table ("" = none)
  std::string out;                     // the responses as HDF5 ("" = none; study_write_freqresp_hdf5)
};

struct FreqRespPoint {
  double w = 0;                        // rad/s
  Eigen::MatrixXcd G, G_linear;        // Plant/Out x Plant/In
  Eigen::MatrixXd distortion;          // the harmonics' share in each output when each input is excited
  Eigen::MatrixXd gap;                 // |G - G_linear| / |G_linear| (the linear response's scale: see .cpp)
  double settle_time = 0, run_time = 0;  // s of model time
};

struct FreqRespJob {
  Model model;
  std::vector<std::string> notes, warnings;
  std::string operating_point, controller;   // the point's kind; "none" or where the controller comes from
  std::vector<std::string> input_names, output_names, input_units, output_units;
  Eigen::VectorXd amplitudes;                // per Plant/In
  double decay_rate = 0;                     // the slowest the outputs see (1/s; 0: not known), which
                                             // sets the settling: 8 / decay_rate
  std::vector<FreqRespPoint> points;         // in the request's order
  // the largest gap: its value, frequency index, output and input
  double largest_gap = 0;
  int gap_point = -1, gap_output = -1, gap_input = -1;
  std::vector<std::string> written;
};

// Throws std::invalid_argument naming the option for a bad request (--frequencies, --amplitude,
// ...), ModelError for a bad model, std::runtime_error when a run fails (naming the frequency and
// the input), StudyCancelled when cb.cancel is set.
FreqRespJob study_freqresp_job(const FreqRespRequest& r, const ModelSpec& spec, const SimulationCallbacks& cb = {},
                               const StudyMessages& tell = {});

// The frequencies from "W1,W2,..." or "A:B:N" (N from A to B equally spaced in log10), rad/s;
// `option` names it in errors.
std::vector<double> study_frequency_grid(const std::string& text, const std::string& option);

// The job as the command line prints it: the point, the controller, then per frequency and pair
// the nonlinear and the linear gain and phase, the gap and the harmonics' share, and the largest gap.
std::string study_freqresp_text(const FreqRespJob& job);

// The table as CSV: w (rad/s), f (Hz), then per output and input OUT/IN: magnitude, phase (deg),
// the linear model's magnitude and phase, the gap and the distortion.
void study_write_freqresp_csv(const FreqRespJob& job, const std::string& path);

// The responses as HDF5: attributes codyna_version, kind ("frequency_response"), model,
// operating_point, controller on "/"; datasets w (rad/s), input_names, output_names, amplitudes,
// and per frequency, output and input (nw x ny x nu, C order) G_real, G_imag, G_linear_real,
// G_linear_imag, gap, distortion; settle_time, run_time (nw, s).
void study_write_freqresp_hdf5(const FreqRespJob& job, const std::string& path);

}  // namespace codyna
