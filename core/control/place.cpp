#include "control/place.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "control/lqr.hpp"

namespace codyna {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXcd;
using Complex = std::complex<double>;

constexpr double kRankTol = 1e-10;        // relative, staircase rank decisions
constexpr double kPoleTol = 1e-10;        // relative to the largest |pole|: equal / real / conjugate
constexpr double kSeparationTol = 1e-4;   // relative distance from eig(A) that needs a pre-feedback
constexpr double kPlacementTol = 1e-6;    // accepted relative error of the placed poles
constexpr int kTrialsSingleInput = 4;     // K is unique: only a failed solve needs another G
constexpr int kTrialsMultiInput = 16;

std::string place_size(const MatrixXd& M) { return std::to_string(M.rows()) + "x" + std::to_string(M.cols()); }

std::string place_number(Complex z) {
  std::ostringstream s;
  s.precision(6);
  s << z.real();
  if (z.imag() != 0) s << (z.imag() < 0 ? " - " : " + ") << std::abs(z.imag()) << "i";
  return s.str();
}

[[noreturn]] void place_fail(const std::string& what) { throw std::invalid_argument("place: " + what); }

double place_norm1(const MatrixXd& M) { return M.size() == 0 ? 0.0 : M.cwiseAbs().colwise().sum().maxCoeff(); }

void check_inputs(const MatrixXd& A, const MatrixXd& B, const VectorXcd& poles) {
  const Index n = A.rows();
  if (A.cols() != n || n == 0) place_fail("A is " + place_size(A) + ", expected a non-empty square matrix");
  if (B.rows() != n || B.cols() == 0)
    place_fail("B is " + place_size(B) + ", expected " + std::to_string(n) + " rows to match A (" + place_size(A) +
         ") and at least one column");
  if (poles.size() != n)
    place_fail("poles has " + std::to_string(poles.size()) + " entries, expected " + std::to_string(n) + " (one per state)");
  if (!A.allFinite()) place_fail("A has NaN or Inf entries");
  if (!B.allFinite()) place_fail("B has NaN or Inf entries");
  if (!poles.allFinite()) place_fail("poles has NaN or Inf entries");
}

// ------------------------------------------------------------------ controllability

struct Staircase {
  Index rank_B = 0;                // independent input directions
  Index controllable = 0;          // dimension of the controllable subspace
  VectorXcd uncontrollable_modes;  // eigenvalues of the part no input reaches
};

// Orthogonal staircase reduction: rotate the range of each coupling block to
// the front; when a block has rank zero, the trailing part of the rotated A is
// decoupled from the inputs and its eigenvalues cannot be moved.
Staircase staircase(const MatrixXd& A, const MatrixXd& B) {
  const Index n = A.rows();
  MatrixXd At = A, block = B;
  Staircase out;
  Index k = 0;
  for (bool first = true; k < n; first = false) {
    const Eigen::JacobiSVD<MatrixXd> svd(block, Eigen::ComputeFullU);
    const double tol = kRankTol * (first ? place_norm1(B) : std::max(place_norm1(A), place_norm1(B)));
    const Index r = (svd.singularValues().array() > tol).count();
    if (first) out.rank_B = r;
    if (r == 0) break;
    const MatrixXd& U = svd.matrixU();
    At.bottomRows(n - k) = U.transpose() * At.bottomRows(n - k);
    At.rightCols(n - k) = At.rightCols(n - k) * U;
    k += r;
    if (k < n) block = At.block(k, k - r, n - k, r);
  }
  out.controllable = k;
  if (k < n) out.uncontrollable_modes = At.bottomRightCorner(n - k, n - k).eigenvalues();
  return out;
}

// ------------------------------------------------------------------ the requested poles

// Lambda: real block-diagonal with the requested poles as its eigenvalues.
// Also checks pairing and multiplicity.
MatrixXd real_block_form(const VectorXcd& poles, Index rank_B) {
  const Index n = poles.size();
  const double tol = kPoleTol * poles.cwiseAbs().maxCoeff();
  for (Index i = 0; i < n; ++i) {
    Index repeats = 0;
    for (Index j = 0; j < n; ++j) repeats += std::abs(poles[j] - poles[i]) <= tol;
    if (repeats > rank_B)
      place_fail("pole " + place_number(poles[i]) + " is repeated " + std::to_string(repeats) + " times, more than rank(B) = " +
           std::to_string(rank_B) + " (each copy needs its own input direction)");
  }
  MatrixXd Lambda = MatrixXd::Zero(n, n);
  std::vector<bool> used(n, false);
  Index at = 0;
  for (Index i = 0; i < n; ++i) {
    if (used[i]) continue;
    used[i] = true;
    const Complex p = poles[i];
    if (std::abs(p.imag()) <= tol) {
      Lambda(at, at) = p.real();
      at += 1;
      continue;
    }
    Index partner = -1;
    for (Index j = 0; j < n; ++j)
      if (!used[j] && std::abs(poles[j] - std::conj(p)) <= tol) {
        partner = j;
        break;
      }
    if (partner < 0)
      place_fail("poles must come in complex-conjugate pairs: " + place_number(p) + " has no partner " + place_number(std::conj(p)));
    used[partner] = true;
    const double s = 0.5 * (p.real() + poles[partner].real()), w = 0.5 * std::abs(p.imag() - poles[partner].imag());
    Lambda.block(at, at, 2, 2) << s, w, -w, s;
    at += 2;
  }
  return Lambda;
}

// the smallest distance between an eigenvalue of A and a requested pole
double separation(const MatrixXd& A, const VectorXcd& poles) {
  const VectorXcd eig = A.eigenvalues();
  double d = std::numeric_limits<double>::infinity();
  for (const Complex& a : eig)
    for (const Complex& p : poles) d = std::min(d, std::abs(a - p));
  return d;
}

// ------------------------------------------------------------------ the Sylvester method

struct Trial {
  MatrixXd K;
  double condition_X = std::numeric_limits<double>::infinity();
};

// A0 X - X Lambda = B G, K1 = G X^-1; empty when X is singular (a nearly
// singular X shows up in the final check of the placed poles)
std::optional<Trial> sylvester_gain(const MatrixXd& A0, const MatrixXd& B, const MatrixXd& Lambda, const MatrixXd& G) {
  MatrixXd X;
  try {
    X = sylvester(A0, -Lambda, B * G);
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
  const Eigen::VectorXd sv = Eigen::JacobiSVD<MatrixXd>(X).singularValues();
  Trial t;
  t.condition_X = sv[0] / sv[sv.size() - 1];
  if (!std::isfinite(t.condition_X)) return std::nullopt;
  t.K = X.transpose().partialPivLu().solve(G.transpose()).transpose();  // K X = G
  return t;
}

MatrixXd random_matrix(Index rows, Index cols, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  MatrixXd M(rows, cols);
  for (Index i = 0; i < M.size(); ++i) M.data()[i] = normal(rng);
  return M;
}

// the largest distance from a requested pole to its nearest placed pole
// (greedy matching), relative to the size of the problem
double placement_error(const MatrixXd& closed_loop, const VectorXcd& poles, double scale) {
  VectorXcd placed = closed_loop.eigenvalues();
  std::vector<bool> taken(placed.size(), false);
  double worst = 0;
  for (const Complex& p : poles) {
    Index best = -1;
    for (Index j = 0; j < placed.size(); ++j)
      if (!taken[j] && (best < 0 || std::abs(placed[j] - p) < std::abs(placed[best] - p))) best = j;
    taken[best] = true;
    worst = std::max(worst, std::abs(placed[best] - p) / scale);
  }
  return worst;
}

}  // namespace

Eigen::MatrixXd place(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::VectorXcd& poles) {
  check_inputs(A, B, poles);
  const Index n = A.rows(), m = B.cols();

  const Staircase s = staircase(A, B);
  if (s.controllable < n) {
    std::string modes;
    for (const Complex& z : s.uncontrollable_modes) modes += (modes.empty() ? "" : ", ") + place_number(z);
    place_fail("(A, B) is not controllable: " + std::to_string(n - s.controllable) +
         " mode(s) cannot be moved by any feedback (at " + modes + ")");
  }
  const MatrixXd Lambda = real_block_form(poles, s.rank_B);

  // a fixed seed keeps the gain reproducible from run to run
  std::mt19937 rng(20240611u);
  const double scale = std::max({place_norm1(A), poles.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min()});
  const int trials = m == 1 ? kTrialsSingleInput : kTrialsMultiInput;
  // move A's spectrum off the requested poles, else the Sylvester equation is singular
  const bool pre_feedback = separation(A, poles) <= kSeparationTol * scale;
  std::optional<Trial> best;
  for (int t = 0; t < trials; ++t) {
    MatrixXd K0 = MatrixXd::Zero(m, n);
    if (pre_feedback) K0 = random_matrix(m, n, rng) * (scale / place_norm1(B));
    const MatrixXd G = random_matrix(m, n, rng);
    std::optional<Trial> trial = sylvester_gain(A - B * K0, B, Lambda, G);
    if (!trial) continue;
    trial->K += K0;
    if (!best || trial->condition_X < best->condition_X) best = std::move(trial);
    if (m == 1) break;
  }
  if (!best) throw std::runtime_error("place: every trial gave a singular eigenvector matrix; the placement is ill-conditioned");

  const double error = placement_error(A - B * best->K, poles, scale);
  if (!(error <= kPlacementTol))
    throw std::runtime_error("place: the placed poles miss the requested ones by " + place_number(error) +
                             " (relative; eigenvector matrix condition number " + place_number(best->condition_X) +
                             "); the placement is numerically ill-conditioned");
  return best->K;
}

}  // namespace codyna
