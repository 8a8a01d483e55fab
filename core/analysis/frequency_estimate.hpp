// The frequency response of a sampled run at one excitation frequency (codyna freqresp, the
// sinestream of Simulink Control Design's frestimate): each signal is fitted, by linear least
// squares over a window of whole periods, with
//   x(t) ~ c0 + c1 (t - tm) + sum_{k=1..K} Re(X_k exp(j k w t))
// (an offset, a drift such as a car's heading, and the first K harmonics of w; tm the window's
// middle). X_1 is the response at w; |X_k|, k >= 2, the harmonics a nonlinear plant adds; the
// residual what neither explains (sub-harmonics, a response that has not settled, chaos).
// With the plant's inputs U (nu x nu: column j the fundamental of every input in the run that
// excites input j) and its outputs Y (ny x nu) the estimate is G(jw) = Y U^-1: open loop U is
// diagonal; in a closed loop the controller moves the other inputs too, and the estimate is still
// the plant's (no noise: the direct method of closed-loop identification).
#pragma once

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace codyna {

struct HarmonicFit {
  double offset = 0, drift = 0;                  // c0, c1 (per second)
  std::vector<std::complex<double>> harmonics;   // X_1 ... X_K
  double residual_rms = 0;                       // of x minus the fit
  // sqrt(sum_{k>=2} |X_k|^2) / |X_1| (0 when X_1 is 0)
  double distortion() const;
};

// t: the samples' times over the window (at least 2 K + 3 of them); w > 0 rad/s; K >= 1.
// Throws std::invalid_argument for too few samples or a bad w or K.
HarmonicFit fit_harmonics(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double w, int K);

// Every column of X (samples x signals) at once (one factorization).
std::vector<HarmonicFit> fit_harmonics(const Eigen::VectorXd& t, const Eigen::MatrixXd& X, double w, int K);

// The frequency response of a transient run (a swept sine, a step): the ratio of the Fourier
// transforms Y(w) / U(w) of the output's and the input's deviations, each by the trapezoid rule
// over the samples, at each w (rad/s). Exact for a linear plant when the run starts at rest and
// has settled by its end (both deviations then vanish at the ends), to the quadrature's error on
// the samples; where |U(w)| is small the ratio is not to be trusted (share: |U(w)| over the
// largest |U| of the ws). Throws std::invalid_argument for fewer than 2 samples or unequal sizes.
struct TransformRatio {
  std::vector<std::complex<double>> H;
  std::vector<double> input_share;
};
TransformRatio transform_ratio(const std::vector<double>& t, const std::vector<double>& du,
                               const std::vector<double>& dy, const std::vector<double>& w);

}  // namespace codyna
