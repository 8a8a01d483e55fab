#include "analysis/zeros.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace codyna {

ChannelZeros transmission_zeros(const LinearSystem& sys, int input, int output) {
  const Eigen::Index n = sys.A.rows();
  if (input < 0 || input >= sys.B.cols() || output < 0 || output >= sys.C.rows())
    throw std::invalid_argument("transmission_zeros: input " + std::to_string(input) + " or output " +
                                std::to_string(output) + " out of range (" + std::to_string(sys.B.cols()) +
                                " inputs, " + std::to_string(sys.C.rows()) + " outputs)");
  ChannelZeros out;
  const double d = sys.D.size() ? sys.D(output, input) : 0.0;
  // the channel's Markov parameters C A^k B (k < n) and D all zero: H is zero everywhere
  {
    Eigen::VectorXd v = sys.B.col(input);
    double markov = std::abs(d), scale = std::abs(d);
    for (Eigen::Index k = 0; k < n; ++k) {
      markov = std::max(markov, std::abs(sys.C.row(output).dot(v)));
      scale = std::max(scale, sys.C.row(output).norm() * v.norm());
      v = sys.A * v;
    }
    if (!(markov > 1e-13 * std::max(scale, 1e-300))) {
      out.identically_zero = true;
      return out;
    }
  }
  Eigen::MatrixXd M(n + 1, n + 1), N = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = sys.A;
  M.topRightCorner(n, 1) = sys.B.col(input);
  M.bottomLeftCorner(1, n) = sys.C.row(output);
  M(n, n) = d;
  N.topLeftCorner(n, n).setIdentity();
  Eigen::GeneralizedEigenSolver<Eigen::MatrixXd> qz(M, N, false);
  if (qz.info() != Eigen::Success) throw std::runtime_error("transmission_zeros: the QZ iteration did not converge");
  const Eigen::VectorXcd alpha = qz.alphas();
  const Eigen::VectorXd beta = qz.betas();
  const double norm = std::max(M.cwiseAbs().maxCoeff(), 1.0);
  std::vector<std::complex<double>> z;
  for (Eigen::Index k = 0; k < alpha.size(); ++k) {
    // an infinite eigenvalue: beta at round-off against the pencil's size
    if (!(std::abs(beta[k]) > 1e-10 * std::max(norm, std::abs(alpha[k])))) continue;
    std::complex<double> s = alpha[k] / beta[k];
    if (std::abs(s.imag()) <= 1e-12 * std::max(1.0, std::abs(s))) s.imag(0.0);
    z.push_back(s);
  }
  std::sort(z.begin(), z.end(), [](const auto& a, const auto& b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  out.zeros = Eigen::Map<const Eigen::VectorXcd>(z.data(), static_cast<Eigen::Index>(z.size()));
  return out;
}

}  // namespace codyna
