#include "analysis/response_figures.hpp"

#include <algorithm>
#include <cmath>

namespace codyna {

void response_figures(const std::vector<double>& t, const Eigen::MatrixXd& e, Eigen::VectorXd& overshoot,
                      Eigen::VectorXd& settling) {
  const Eigen::Index N = e.rows();
  for (Eigen::Index j = 0; j < e.cols(); ++j) {
    const auto col = e.col(j);
    if (N == 0 || !col.allFinite()) continue;
    Eigen::Index peak = 0;
    const double E = col.cwiseAbs().maxCoeff(&peak);
    if (E == 0) {
      overshoot[j] = 0;
      settling[j] = t[0];
      continue;
    }
    const double s = col[peak] > 0 ? 1.0 : -1.0;
    overshoot[j] = 100.0 * std::max(0.0, (-s * col).maxCoeff()) / E;
    const double band = 0.02 * E;
    Eigen::Index k = N - 1;
    if (std::abs(col[k]) > band) continue;
    while (k > 0 && std::abs(col[k - 1]) <= band) --k;
    if (k == 0) {
      settling[j] = t[0];
      continue;
    }
    // e(k-1) is outside the band, e(k) inside: where the line between them meets it
    const double a = col[k - 1], b = col[k], edge = a > 0 ? band : -band;
    const double f = (a - edge) / (a - b);
    const std::size_t i = static_cast<std::size_t>(k);
    settling[j] = t[i - 1] + f * (t[i] - t[i - 1]);
  }
}

LinearGap linear_gap(const std::vector<double>& t, const Eigen::MatrixXd& y, const Eigen::MatrixXd& y_linear) {
  LinearGap g;
  const Eigen::Index N = y.rows();
  if (N == 0 || y_linear.rows() != N || y_linear.cols() != y.cols()) return g;
  const Eigen::Index ny = y.cols();
  g.largest.resize(ny);
  g.percent.resize(ny);
  g.from.resize(ny);
  for (Eigen::Index k = 0; k < ny; ++k) {
    const Eigen::VectorXd d = (y.col(k) - y_linear.col(k)).cwiseAbs();
    const double range = std::max((y.col(k).array() - y(N - 1, k)).abs().maxCoeff(), 1e-12);
    Eigen::Index first = -1;
    for (Eigen::Index i = 0; i < N; ++i)
      if (d[i] > 0.01 * range) {
        first = i;
        break;
      }
    g.largest[k] = d.maxCoeff();
    g.percent[k] = 100 * d.maxCoeff() / range;
    g.from[k] = first < 0 ? -1.0 : t[static_cast<std::size_t>(first)];
  }
  return g;
}

}  // namespace codyna
