#include "analysis/frequency_estimate.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace codyna {

double HarmonicFit::distortion() const {
  if (harmonics.empty() || std::abs(harmonics[0]) == 0) return 0;
  double s = 0;
  for (std::size_t k = 1; k < harmonics.size(); ++k) s += std::norm(harmonics[k]);
  return std::sqrt(s) / std::abs(harmonics[0]);
}

std::vector<HarmonicFit> fit_harmonics(const Eigen::VectorXd& t, const Eigen::MatrixXd& X, double w, int K) {
  if (!(w > 0) || !std::isfinite(w)) throw std::invalid_argument("fit_harmonics: expected a frequency > 0 rad/s");
  if (K < 1) throw std::invalid_argument("fit_harmonics: expected at least one harmonic");
  const Eigen::Index N = t.size(), p = 2 + 2 * K;
  if (N < p + 1) throw std::invalid_argument("fit_harmonics: too few samples for the harmonics asked");
  if (X.rows() != N) throw std::invalid_argument("fit_harmonics: the signals' samples do not match the times");
  const double tm = 0.5 * (t[0] + t[N - 1]);
  Eigen::MatrixXd A(N, p);
  for (Eigen::Index i = 0; i < N; ++i) {
    A(i, 0) = 1;
    A(i, 1) = t[i] - tm;
    for (int k = 1; k <= K; ++k) {
      // Re(X e^{j k w t}) = Re X cos - Im X sin
      A(i, 2 * k) = std::cos(k * w * t[i]);
      A(i, 2 * k + 1) = -std::sin(k * w * t[i]);
    }
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd c = qr.solve(X);
  const Eigen::MatrixXd residual = X - A * c;
  std::vector<HarmonicFit> out(static_cast<std::size_t>(X.cols()));
  for (Eigen::Index j = 0; j < X.cols(); ++j) {
    HarmonicFit& f = out[static_cast<std::size_t>(j)];
    f.offset = c(0, j);
    f.drift = c(1, j);
    for (int k = 1; k <= K; ++k) f.harmonics.emplace_back(c(2 * k, j), c(2 * k + 1, j));
    f.residual_rms = std::sqrt(residual.col(j).squaredNorm() / static_cast<double>(N));
  }
  return out;
}

HarmonicFit fit_harmonics(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double w, int K) {
  return fit_harmonics(t, Eigen::MatrixXd(x), w, K)[0];
}

TransformRatio transform_ratio(const std::vector<double>& t, const std::vector<double>& du,
                               const std::vector<double>& dy, const std::vector<double>& w) {
  if (t.size() < 2 || du.size() != t.size() || dy.size() != t.size())
    throw std::invalid_argument("transform_ratio: expected at least 2 samples of the time, the input and the output");
  TransformRatio r;
  std::vector<std::complex<double>> U(w.size());
  const std::size_t n = t.size();
  for (std::size_t i = 0; i < w.size(); ++i) {
    std::complex<double> su = 0, sy = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const double h = 0.5 * ((k + 1 < n ? t[k + 1] - t[k] : 0.0) + (k > 0 ? t[k] - t[k - 1] : 0.0));
      const std::complex<double> e = std::polar(h, -w[i] * t[k]);
      su += du[k] * e;
      sy += dy[k] * e;
    }
    U[i] = su;
    r.H.push_back(su != 0.0 ? sy / su : std::complex<double>(std::nan(""), std::nan("")));
  }
  double largest = 0;
  for (const auto& u : U) largest = std::max(largest, std::abs(u));
  for (const auto& u : U) r.input_share.push_back(largest > 0 ? std::abs(u) / largest : 0.0);
  return r;
}

}  // namespace codyna
