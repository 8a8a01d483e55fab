#include "control/controllability.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace codyna {

namespace {

// the right eigenvector's dominant states
std::vector<std::string> dominant(const Eigen::VectorXcd& v, const std::vector<std::string>& names) {
  const double top = v.cwiseAbs().maxCoeff();
  std::vector<std::pair<double, int>> idx;
  for (int i = 0; i < v.size(); ++i)
    if (top > 0 && std::abs(v[i]) >= 0.5 * top) idx.emplace_back(std::abs(v[i]), i);
  std::sort(idx.begin(), idx.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> out;
  for (const auto& [mag, i] : idx) out.push_back(i < static_cast<int>(names.size()) ? names[i] : "x" + std::to_string(i + 1));
  return out;
}

// PBH: [A - lambda I, X] (controllability, X = B) or its transpose form (observability, X = C^T on A^T)
std::vector<HiddenMode> hidden(const Eigen::MatrixXd& A, const Eigen::MatrixXd& X, const std::vector<std::string>& names,
                               double rel_tol, bool observability) {
  const Eigen::Index n = A.rows();
  std::vector<HiddenMode> out;
  if (n == 0) return out;
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  const Eigen::VectorXcd lambda = es.eigenvalues();
  const double scale = std::max({A.norm(), X.norm(), 1e-300});
  std::vector<bool> done(n, false);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (done[k]) continue;
    // one test per distinct eigenvalue (a conjugate pair is one mode)
    for (Eigen::Index j = k; j < n; ++j)
      if (std::abs(lambda[j] - lambda[k]) <= 1e-9 * std::max(1.0, std::abs(lambda[k])) ||
          std::abs(lambda[j] - std::conj(lambda[k])) <= 1e-9 * std::max(1.0, std::abs(lambda[k])))
        done[j] = true;
    Eigen::MatrixXcd P(n, n + (observability ? X.rows() : X.cols()));
    const Eigen::MatrixXcd shifted = (observability ? Eigen::MatrixXd(A.transpose()) : A).cast<std::complex<double>>() -
                                     lambda[k] * Eigen::MatrixXcd::Identity(n, n);
    P << shifted, (observability ? Eigen::MatrixXd(X.transpose()) : X).cast<std::complex<double>>();
    // the singular values alone first: a mode well inside the tolerance (most) needs no U
    if (Eigen::JacobiSVD<Eigen::MatrixXcd>(P).singularValues()[n - 1] / scale >= 100 * rel_tol) continue;
    const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(P, Eigen::ComputeFullU);
    const Eigen::VectorXd sv = svd.singularValues();
    const double margin = sv[n - 1] / scale;
    if (margin < rel_tol) {
      HiddenMode m;
      m.eigenvalue = std::abs(lambda[k].imag()) < 1e-12 * std::max(1.0, std::abs(lambda[k])) ? std::complex<double>(lambda[k].real(), 0)
                     : lambda[k].imag() < 0 ? std::conj(lambda[k]) : lambda[k];
      // the direction that is hidden: the left null vector of the PBH matrix (for repeated
      // eigenvalues, the one combination the inputs cannot reach or the outputs cannot see)
      m.states = dominant(svd.matrixU().col(n - 1), names);
      m.margin = margin;
      out.push_back(m);
    }
  }
  return out;
}

}  // namespace

std::vector<HiddenMode> uncontrollable_modes(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                             const std::vector<std::string>& names, double rel_tol) {
  return hidden(A, B, names, rel_tol, false);
}

std::vector<HiddenMode> unobservable_modes(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C,
                                           const std::vector<std::string>& names, double rel_tol) {
  return hidden(A, C, names, rel_tol, true);
}

std::string describe(const std::vector<HiddenMode>& modes) {
  // a repeated mode (a double pole at 0 may come out of the decomposition once or twice) is said once
  std::vector<std::string> said;
  for (const auto& m : modes) {
    std::ostringstream os;
    os.precision(6);
    os << "lambda = " << m.eigenvalue.real();
    if (m.eigenvalue.imag() != 0) os << " +/- " << std::abs(m.eigenvalue.imag()) << "i";
    os << " (";
    for (std::size_t k = 0; k < m.states.size(); ++k) os << (k ? ", " : "") << m.states[k];
    os << ")";
    if (std::find(said.begin(), said.end(), os.str()) == said.end()) said.push_back(os.str());
  }
  std::string out;
  for (const std::string& t : said) out += (out.empty() ? "" : "; ") + t;
  return out;
}

}  // namespace codyna
