#include "analysis/modal.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace codyna {
namespace {

// Scales v so that its largest entry (the first one, among entries equal
// to the largest within rounding) becomes exactly 1.
Eigen::VectorXcd normalize_shape(const Eigen::VectorXcd& v) {
  const double largest = v.cwiseAbs().maxCoeff();
  if (largest == 0.0) return v;
  Eigen::Index k = 0;
  while (std::abs(v(k)) < largest * (1.0 - 1e-12)) ++k;
  Eigen::VectorXcd shape = v / v(k);
  shape(k) = 1.0;
  return shape;
}

Mode make_mode(std::complex<double> eigenvalue, const Eigen::VectorXcd& v, double Ts) {
  Mode m;
  m.eigenvalue = eigenvalue;
  m.s = Ts > 0.0 ? std::log(eigenvalue) / Ts : eigenvalue;
  m.natural_frequency = std::abs(m.s);
  m.damping_ratio = m.natural_frequency > 0.0 ? -m.s.real() / m.natural_frequency : -1.0;
  m.shape = normalize_shape(v);
  return m;
}

bool mode_order(const Mode& a, const Mode& b) {
  if (a.natural_frequency != b.natural_frequency) return a.natural_frequency < b.natural_frequency;
  if (a.s.imag() != b.s.imag()) return a.s.imag() < b.s.imag();
  return a.s.real() < b.s.real();
}

std::string format_complex(std::complex<double> c) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g %c %.6gj", c.real(), c.imag() < 0 ? '-' : '+', std::abs(c.imag()));
  return buf;
}

std::string state_name(const ModalAnalysis& m, Eigen::Index i) {
  if (i < static_cast<Eigen::Index>(m.state_names.size())) return m.state_names[i];
  std::string name = "x";  // (not "x" + to_string(): GCC 12 warns falsely on that, -Wrestrict)
  return name += std::to_string(i + 1);
}

// "theta (1.00), theta_dot (0.44)": states with |entry| >= 0.5, largest first
std::string dominant_states(const ModalAnalysis& m, const Eigen::VectorXcd& shape) {
  std::vector<Eigen::Index> idx;
  for (Eigen::Index i = 0; i < shape.size(); ++i)
    if (std::abs(shape(i)) >= 0.5) idx.push_back(i);
  std::stable_sort(idx.begin(), idx.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return std::abs(shape(a)) > std::abs(shape(b)); });
  std::string out;
  for (Eigen::Index i : idx) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " (%.2f)", std::abs(shape(i)));
    out += (out.empty() ? "" : ", ") + state_name(m, i) + buf;
  }
  return out;
}

}  // namespace

ModalAnalysis modal_analysis(const LinearSystem& sys) {
  if (sys.A.rows() != sys.A.cols()) throw std::invalid_argument("modal_analysis: A is not square");
  if (!sys.A.allFinite()) throw std::invalid_argument("modal_analysis: A has NaN or Inf entries");
  ModalAnalysis out;
  out.state_names = sys.state_names;
  out.Ts = sys.Ts;
  if (sys.A.size() == 0) return out;

  Eigen::EigenSolver<Eigen::MatrixXd> es(sys.A, /*computeEigenvectors=*/true);
  if (es.info() != Eigen::Success) throw std::runtime_error("modal_analysis: eigen decomposition did not converge");
  for (Eigen::Index i = 0; i < sys.A.rows(); ++i)
    out.modes.push_back(make_mode(es.eigenvalues()(i), es.eigenvectors().col(i), sys.Ts));
  std::sort(out.modes.begin(), out.modes.end(), mode_order);
  return out;
}

std::string format_modes(const ModalAnalysis& m) {
  const bool discrete = m.Ts > 0.0;
  const int s_width = discrete ? 29 : 0;  // the s column only for discrete systems
  char line[256];
  std::snprintf(line, sizeof line, "%-3s %-28s %-*s%-13s %-13s %-9s ", "#", discrete ? "z" : "eigenvalue",
                s_width, discrete ? "s = log(z)/Ts" : "", "wn (rad/s)", "f (Hz)", "damping");
  std::string out = std::string(line) + "dominant states\n";
  for (std::size_t k = 0; k < m.modes.size(); ++k) {
    const Mode& mode = m.modes[k];
    std::snprintf(line, sizeof line, "%-3zu %-28s %-*s%-13.6g %-13.6g %-9.4f ", k + 1,
                  format_complex(mode.eigenvalue).c_str(), s_width, discrete ? format_complex(mode.s).c_str() : "",
                  mode.natural_frequency, mode.natural_frequency / (2.0 * std::numbers::pi),
                  std::abs(mode.damping_ratio) < 5e-5 ? 0.0 : mode.damping_ratio);  // no "-0.0000"
    out += std::string(line) + dominant_states(m, mode.shape) + "\n";
  }
  if (discrete) {
    std::snprintf(line, sizeof line, "discrete, Ts = %g s\n", m.Ts);
    out += line;
  }
  return out;
}

}  // namespace codyna
