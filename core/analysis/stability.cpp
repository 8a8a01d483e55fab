#include "analysis/stability.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace codyna {

const char* to_string(Stability s) {
  switch (s) {
    case Stability::Stable: return "stable";
    case Stability::Marginal: return "marginal";
    case Stability::Unstable: return "unstable";
  }
  return "unstable";
}

double stability_tolerance(const Eigen::MatrixXd& A) { return 1e-9 * std::max(1.0, A.norm()); }

Stability classify_pole(std::complex<double> pole, bool discrete, double tolerance) {
  const double margin = discrete ? std::abs(pole) - 1.0 : pole.real();
  if (!std::isfinite(margin)) return Stability::Unstable;  // NaN or Inf: never called stable
  if (margin < -tolerance) return Stability::Stable;
  if (margin > tolerance) return Stability::Unstable;
  return Stability::Marginal;
}

PoleCount classify_poles(const Eigen::VectorXcd& poles, bool discrete, double tolerance) {
  PoleCount c;
  for (Eigen::Index k = 0; k < poles.size(); ++k) {
    switch (classify_pole(poles[k], discrete, tolerance)) {
      case Stability::Stable: ++c.stable; break;
      case Stability::Marginal: ++c.marginal; break;
      case Stability::Unstable: ++c.unstable; break;
    }
  }
  return c;
}

Eigen::VectorXcd unstable_poles(const Eigen::VectorXcd& poles, bool discrete, double tolerance) {
  std::vector<std::complex<double>> out;
  for (Eigen::Index k = 0; k < poles.size(); ++k)
    if (classify_pole(poles[k], discrete, tolerance) == Stability::Unstable) out.push_back(poles[k]);
  return Eigen::Map<const Eigen::VectorXcd>(out.data(), static_cast<Eigen::Index>(out.size()));
}

}  // namespace codyna
