#include "analysis/frequency_estimate.hpp"

#include <Eigen/QR>
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

}  // namespace codyna
