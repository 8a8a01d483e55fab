#include "analysis/modal.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
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

// An orthonormal basis of the generalized null space of M: null(M), then {x : M x in the span so
// far}, until it stops growing (each step one SVD of (I - P) M, rank tolerance 1e-9 max(1, max|M_ij|))
Eigen::MatrixXd generalized_null_space(const Eigen::MatrixXd& M) {
  const Eigen::Index n = M.rows();
  const double tol = 1e-9 * std::max(1.0, M.cwiseAbs().maxCoeff());
  Eigen::MatrixXd basis(n, 0);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);  // projector onto the span so far
  for (Eigen::Index step = 0; step < n; ++step) {
    const Eigen::MatrixXd R = (Eigen::MatrixXd::Identity(n, n) - P) * M;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
    Eigen::Index rank = 0;
    while (rank < n && svd.singularValues()(rank) > tol) ++rank;
    if (n - rank <= basis.cols()) break;
    basis = svd.matrixV().rightCols(n - rank);
    P = basis * basis.transpose();
  }
  return basis;
}

}  // namespace

ModalAnalysis modal_analysis(const LinearSystem& sys) {
  if (sys.A.rows() != sys.A.cols()) throw std::invalid_argument("modal_analysis: A is not square");
  if (!sys.A.allFinite()) throw std::invalid_argument("modal_analysis: A has NaN or Inf entries");
  ModalAnalysis out;
  out.state_names = sys.state_names;
  out.Ts = sys.Ts;
  out.stability_tolerance = stability_tolerance(sys.A);
  if (sys.A.size() == 0) return out;

  Eigen::EigenSolver<Eigen::MatrixXd> es(sys.A, /*computeEigenvectors=*/true);
  if (es.info() != Eigen::Success) throw std::runtime_error("modal_analysis: eigen decomposition did not converge");
  for (Eigen::Index i = 0; i < sys.A.rows(); ++i) {
    out.modes.push_back(make_mode(es.eigenvalues()(i), es.eigenvectors().col(i), sys.Ts));
    out.modes.back().stability = classify_pole(out.modes.back().eigenvalue, sys.Ts > 0, out.stability_tolerance);
  }
  std::sort(out.modes.begin(), out.modes.end(), mode_order);
  const Eigen::MatrixXd N = generalized_null_space(
      sys.Ts > 0.0 ? Eigen::MatrixXd(sys.A - Eigen::MatrixXd::Identity(sys.A.rows(), sys.A.cols())) : sys.A);
  out.zero_count = static_cast<int>(N.cols());
  for (Eigen::Index i = 0; i < N.rows(); ++i)
    if (N.cols() > 0 && N.row(i).squaredNorm() >= 0.5) out.zero_states.push_back(static_cast<int>(i));
  // the modes that stand for s = 0 (z = 1) are on the boundary, however their computed
  // eigenvalues scatter (by eps^(1/k) for a k-fold zero, beyond the round-off tolerance)
  for (int k = 0; k < out.zero_count && k < static_cast<int>(out.modes.size()); ++k)
    out.modes[static_cast<std::size_t>(k)].stability = Stability::Marginal;
  return out;
}

std::string format_modes(const ModalAnalysis& m) {
  const bool discrete = m.Ts > 0.0;
  const int s_width = discrete ? 29 : 0;  // the s column only for discrete systems
  char line[512];
  const std::size_t zeros = std::min<std::size_t>(static_cast<std::size_t>(m.zero_count), m.modes.size());
  const std::string number = zeros == 1 ? "1" : "1-" + std::to_string(zeros);
  const int n_width = zeros > 1 ? std::max(5, static_cast<int>(number.size())) : 3;  // "1-12" needs more than "12"
  std::snprintf(line, sizeof line, "%-*s %-28s %-*s%-13s %-13s %-9s ", n_width, "#", discrete ? "z" : "eigenvalue",
                s_width, discrete ? "s = log(z)/Ts" : "", "wn (rad/s)", "f (Hz)", "damping");
  std::string out = std::string(line) + "dominant states\n";
  if (zeros > 0) {
    // one row for the zero eigenvalue, however often it is repeated: its states, not one arbitrary vector each
    std::string states;
    for (int i : m.zero_states) states += (states.empty() ? "" : ", ") + state_name(m, i);
    const std::string value = std::string(discrete ? "1" : "0") + (zeros > 1 ? " (x" + std::to_string(zeros) + ")" : "");
    std::snprintf(line, sizeof line, "%-*s %-28s %-*s%-13s %-13s %-9s ", n_width, number.c_str(), value.c_str(), s_width,
                  discrete ? "0" : "", "0", "0", "-");
    out += std::string(line) + states + "\n";
  }
  for (std::size_t k = zeros; k < m.modes.size(); ++k) {
    const Mode& mode = m.modes[k];
    std::snprintf(line, sizeof line, "%-*zu %-28s %-*s%-13.6g %-13.6g %-9.4f ", n_width, k + 1,
                  format_complex(mode.eigenvalue).c_str(), s_width, discrete ? format_complex(mode.s).c_str() : "",
                  mode.natural_frequency, mode.natural_frequency / (2.0 * std::numbers::pi),
                  std::abs(mode.damping_ratio) < 5e-5 ? 0.0 : mode.damping_ratio);  // no "-0.0000"
    out += std::string(line) + dominant_states(m, mode.shape) + "\n";
  }
  if (zeros > 0)
    out += std::string(discrete ? "z = 1" : "0") + ": a rigid-body motion or an integrator (its damping is undefined: -)\n";
  if (discrete) {
    std::snprintf(line, sizeof line, "discrete, Ts = %g s\n", m.Ts);
    out += line;
  }
  return out;
}

PoleCount count_stability(const ModalAnalysis& m) {
  PoleCount c;
  for (const Mode& md : m.modes) {
    c.stable += md.stability == Stability::Stable;
    c.marginal += md.stability == Stability::Marginal;
    c.unstable += md.stability == Stability::Unstable;
  }
  return c;
}

}  // namespace codyna
