// alf: the index-3 augmented Lagrangian formulation with mass-orthogonal projections of the
// velocities and accelerations (Bayo and Ledesma 1996; Cuadrado, Cardenal, Bayo 1997, "ALI3-P"),
// integrated by the trapezoidal rule. It never inverts the constraint Jacobian alone: the Newton
// matrix holds M + (h^2/4) Jc^T alpha Jc, regular while M is, whatever the rank of Jc, so it
// passes singular positions (a four-bar's flat position, IFToMM A02) and takes redundant
// constraints (Bricard) as they are. Per step h, from (q_n, v_n, a_n):
//   q^ = q_n + h v_n + h^2/2 a_n,  v = 2/h q - (2/h q_n + v_n),  a = 4/h^2 q - (4/h^2 q_n + 4/h v_n + a_n)
//   f(q) = h^2/4 (M a + nle - Q + Jc^T (lambda* + alpha phi)),  Newton on f = 0,
//   lambda* += alpha phi after each iteration (the multipliers, kept from step to step);
// then v and a projected onto the constraints' tangent (mass-orthogonally):
//   (M + h^2/4 Jc^T alpha Jc) v = M v*,   (M + h^2/4 Jc^T alpha Jc) a = M a* - h^2/4 Jc^T alpha gamma
// (M and Jc at the step's end, factored for these two solves), each solved for its correction,
// v = v* - (M + h^2/4 Jc^T alpha Jc)^-1 h^2/4 Jc^T alpha Jc v* (and a alike): the matrix is a
// million times |M| along the loops, and its factorization's rounding, solved whole, reached the
// free motion as a phase drift that grew with alpha (A02: 1.4e-5 rad over 20 s at 5 ms).
// The Newton matrix is the full tangent of f (issue 41): M + h/2 C + h^2/4 (K + Jc^T alpha Jc),
// K = d(M a + nle - Q)/dq at fixed a, C = d(nle - Q)/dv, from the analytic derivatives of the
// open tree (TreeDerivatives::compute_balance with zero multipliers, the balance's derivatives
// without the accelerations' solve: the loop closures enter only through the penalty; their
// reactions' turning, d(Jc^T lambda)/dq, is left out: on Bricard's redundant loops it made Newton
// diverge). Where the derivatives throw (an effect or constraint they do not take) C = K = 0.
// Modified Newton, with rules: C and K are kept for up to 20 steps (formed again when Newton's
// corrections shrink by less than 1/2 per iteration, and after a failed step); the matrix is
// combined at each step's h and factored at its first iterate (on trees only when h changes or
// the tangent is new; with loops every step, with M and Jc there: the penalty's weight makes it
// follow Jc so closely that a matrix from the last step's end left Newton's error test blind),
// and again at any iterate whose correction shrank by less than 1/2.
// Newton stops when the error left, theta / (1 - theta) |dq| with theta the contraction rate
// (the first correction taken at face value), is within 1e-3 of the error weights, or within
// 1e-14 (1 + |q_i|), whichever is larger. The weights: atol + rtol |q_i| with error control; at
// fixed steps, where no error test watches the step, also those in v, min(atol + rtol |q_i|,
// h/2 (atol + rtol |v_i|)) (an error in q reaches v = 2/h q - ... as 2/h of itself: with the
// weights in q alone, A02's errors at fixed steps stopped falling below 2e-4 rad whatever the
// step). Near a singular position the
// multipliers' iteration creeps (each iteration shrinks phi along a row of small singular value
// s only by 1/(1 + h^2/4 alpha s^2/m)): an iteration whose correction shrinks by less than 0.8
// (two or more after a factorization) is a stall, accepted when the correction is within a tenth
// of the weights in q and in v (whatever the step control); otherwise the penalty is raised tenfold
// for the rest of the step (up to 1e13). A stalled step's accelerations carry its error in q
// times 4/h^2 in directions the projections leave: the error test does not judge it or the step
// after it. The Newton and projection matrices are factored dense, or sparse (SparseLU in COLAMD
// order) for 24 coordinates and more when at most a fifth of the entries can be nonzero: the
// structural pattern of M (pairs on one path to the ground) and Jc^T Jc (pairs in one
// constraint's support), grown by the nonzeros of C and K when they are formed.
// Inputs that jump at a stop (a reference's step): the step ending at the stop reads them 1e-9 s
// before it, and the next advance() restarts a and the multipliers from the dynamics after the
// jump (as reset() does), so the error estimate does not see a's jump.
// The step: error control by default. The trapezoidal rule's local error in q is h^3/12 q''',
// estimated as h^2/12 (a_n+1 - a_n) with the projected accelerations and taken per unit step
// (divided by h: the global error of a second-order method is that sum); a step is accepted
// when h/12 |a_n+1 - a_n| is within the weights atol + rtol |q_i| everywhere, and the next step
// is h 0.9 err^(-1/2) (between 0.2 h and 2 h, at most max_step when max_step > 0); a rejected
// step is retried at 0.1..0.5 of itself, one whose Newton does not converge at a quarter.
// The penalty: at fixed steps alf_penalty; with error control alf_penalty for steps of 10 ms and
// longer, alf_penalty (10 ms / h)^2 for shorter ones (the weight h^2/4 alpha of Jc^T Jc against M held; with alpha itself the multipliers'
// iteration stalls at short steps, each iteration shrinking the error only by 1/(1 + h^2/4 alpha s^2 / m)). IntegratorSettings::alf_fixed_step:
// every step max_step (default 1 ms), no error control, Newton at rtol, atol of at most 1e-6.
// IntegratorSettings::alf_extrapolate: at fixed steps each step H is also taken as two of H/2 and
// the ends combined, x2 + (x2 - x1)/3; with error control each step H is taken as two of H/2 (x1)
// and four of H/4 (x2), combined the same way, the error |x2 - x1|/3 per unit step, the next step
// H 0.9 err^(-1/2) (extrapolated_pair below: why halves and quarters, not the step and its halves);
// extrapolated, Newton works at rtol, atol of at most 1e-6 as at fixed steps.
// Ball and free joints: the rule steps on the group, its unknown the step dl in the tangent space
// (q = q_n (+) dl, v = 2/h dl - v_n, a = 4/h^2 dl - 4/h v_n - a_n), Newton's matrix the tangent's
// at q (the retraction's Jacobian taken as the identity: a modified Newton), the error weights in
// a rotation's rates atol + rtol times its angle. Motion inputs: each driven coordinate is its
// signal's (value, rate, acceleration) at the step's end; its rows of the Newton and projection
// matrices are its own coordinate alone, so Newton and the projections solve the others (the
// balance's row there holds the motion's reaction). First-order states z (a tire's transient
// slip, a controller's continuous states): the trapezoidal rule z = z_n + h/2 (g_n + g(z)) by
// Newton on their own block, I - h/2 dg/dz (central differences, kept as the positions' tangent
// is), beside the positions' (a block Jacobi iteration: both corrections at the same iterate);
// their error h^2/12 |z^(3)| from the rates' divided differences over two steps. No rolling
// constraints (conditions on the velocities alone): refused by name. The penalty and the
// iterations are alf_penalty and alf_iterations.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "dynamics/constraints.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "simulation/closed_loop.hpp"
#include "simulation/integrator.hpp"

namespace codyna {

namespace {

std::string alf_number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

// A Newton or projection matrix of alf, factored. Three ways, chosen from the matrices'
// structural nonzeros (the pattern: M's pairs on one path to the ground, Jc^T Jc's pairs in one
// loop's support, and what C and K add when formed):
//  * banded: where the pattern in reverse Cuthill-McKee order has a narrow band (a row of loops,
//    A02: bandwidth 2 of 81), LU without pivoting in that band, n b^2 flops (~1 us for A02). The
//    matrices are M + h/2 C + h^2/4 (K + alpha Jc^T Jc), M positive definite and C, K small beside
//    it at the steps alf takes, and M + h^2/4 alpha Jc^T Jc (positive definite): no pivoting is
//    needed, and a pivot below kBandPivot of its diagonal sends that matrix to the sparse LU;
//  * sparse: Eigen's SparseLU in COLAMD order, its pattern analysed once and again only when a
//    nonzero appears outside it (A02 N = 40: 12 us against 53 us dense);
//  * dense, partial pivoting: small or dense matrices.
class FactoredMatrix {
 public:
  // the structural nonzeros (column-major n x n flags) that every matrix given may have
  void set_pattern(std::vector<char> mask) {
    mask_ = std::move(mask);
    analysed_ = false;
  }
  // scan: K may have nonzeros outside the pattern (they are added to it); false: not finite, or
  // singular to the sparse factorization
  bool compute(const Eigen::MatrixXd& K, bool scan) {
    const Eigen::Index n = K.rows();
    // (the band's factorization checks its pivots: a NaN or infinity in the band reaches one)
    const bool checked = band_ < 0 || n < kSparseMin || dense_only_ || scan || !analysed_;
    if (checked && !K.allFinite()) return false;
    if (n < kSparseMin || dense_only_) {
      kind_ = Kind::Dense;
      dense_.compute(K);
      return true;
    }
    bool grown = !analysed_;
    if (static_cast<Eigen::Index>(mask_.size()) != n * n) {
      mask_.assign(static_cast<std::size_t>(n * n), 0);
      scan = grown = true;
    }
    if (scan)
      for (Eigen::Index j = 0; j < n; ++j)
        for (Eigen::Index i = 0; i < n; ++i)
          if (K(i, j) != 0 && !mask_[static_cast<std::size_t>(j * n + i)]) {
            mask_[static_cast<std::size_t>(j * n + i)] = 1;
            grown = true;
          }
    if (grown) {
      std::size_t count = 0;
      for (Eigen::Index j = 0; j < n; ++j)
        for (Eigen::Index i = 0; i < n; ++i) count += mask_[static_cast<std::size_t>(j * n + i)] || i == j;
      if (static_cast<double>(count) > kSparseDensity * static_cast<double>(n * n)) {  // dense enough: dense from now on
        dense_only_ = true;
        return compute(K, false);
      }
      order_band(n);
      sparse_analysed_ = false;
      analysed_ = true;
    }
    if (band_ >= 0 && factor_band(K)) {
      kind_ = Kind::Band;
      return true;
    }
    // the sparse LU (no narrow band, or a small pivot in it; K not yet checked when the band was tried)
    if (!checked && !K.allFinite()) return false;
    if (!sparse_analysed_) {
      std::vector<Eigen::Triplet<double>> entries;
      for (Eigen::Index j = 0; j < n; ++j)
        for (Eigen::Index i = 0; i < n; ++i)
          if (mask_[static_cast<std::size_t>(j * n + i)] || i == j) entries.emplace_back(static_cast<int>(i), static_cast<int>(j), 0.0);
      S_.resize(n, n);
      S_.setFromTriplets(entries.begin(), entries.end());
      S_.makeCompressed();
      slu_.analyzePattern(S_);
      sparse_analysed_ = true;
    }
    for (Eigen::Index j = 0; j < S_.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(S_, j); it; ++it) it.valueRef() = K(it.row(), it.col());
    slu_.factorize(S_);
    kind_ = Kind::Sparse;
    return slu_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) {
    switch (kind_) {
      case Kind::Band: return solve_band(b);
      case Kind::Sparse: return slu_.solve(b);
      case Kind::Dense: break;
    }
    return dense_.solve(b);
  }

 private:
  // the reverse Cuthill-McKee order of the pattern (symmetrized) and its bandwidth; no band
  // (band_ < 0) where it would hold more than kBandShare of the matrix
  void order_band(Eigen::Index n) {
    const auto N = static_cast<std::size_t>(n);
    std::vector<std::vector<int>> adj(N);
    for (std::size_t j = 0; j < N; ++j)
      for (std::size_t i = 0; i < N; ++i)
        if (i != j && (mask_[j * N + i] || mask_[i * N + j])) adj[j].push_back(static_cast<int>(i));
    for (auto& a : adj)
      std::stable_sort(a.begin(), a.end(), [&](int x, int y) { return adj[static_cast<std::size_t>(x)].size() < adj[static_cast<std::size_t>(y)].size(); });
    std::vector<int> order;
    order.reserve(N);
    std::vector<char> seen(N, 0);
    while (order.size() < N) {  // each connected part breadth first from a node of least degree
      std::size_t start = N;
      for (std::size_t i = 0; i < N; ++i)
        if (!seen[i] && (start == N || adj[i].size() < adj[start].size())) start = i;
      seen[start] = 1;
      order.push_back(static_cast<int>(start));
      for (std::size_t head = order.size() - 1; head < order.size(); ++head)
        for (const int j : adj[static_cast<std::size_t>(order[head])])
          if (!seen[static_cast<std::size_t>(j)]) {
            seen[static_cast<std::size_t>(j)] = 1;
            order.push_back(j);
          }
    }
    std::reverse(order.begin(), order.end());
    perm_ = order;
    std::vector<int> place(N);
    for (std::size_t k = 0; k < N; ++k) place[static_cast<std::size_t>(perm_[k])] = static_cast<int>(k);
    Eigen::Index width = 0;
    for (std::size_t j = 0; j < N; ++j)
      for (const int i : adj[j]) width = std::max<Eigen::Index>(width, std::abs(place[j] - place[static_cast<std::size_t>(i)]));
    band_ = static_cast<double>((2 * width + 1) * n) <= kBandShare * static_cast<double>(n * n) ? width : -1;
  }

  // LU without pivoting in the band (perm_'s order); false where a pivot is not finite or below
  // kBandPivot of its diagonal (the sparse LU takes that matrix)
  bool factor_band(const Eigen::MatrixXd& K) {
    const Eigen::Index n = K.rows(), b = band_, w = 2 * band_ + 1;
    B_.resize(n, w);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = std::max<Eigen::Index>(0, i - b); j <= std::min(n - 1, i + b); ++j)
        B_(i, j - i + b) = K(perm_[static_cast<std::size_t>(i)], perm_[static_cast<std::size_t>(j)]);
    for (Eigen::Index k = 0; k < n; ++k) {
      const double p = B_(k, b);
      if (!std::isfinite(p) || !(std::abs(p) > kBandPivot * std::abs(K(perm_[static_cast<std::size_t>(k)], perm_[static_cast<std::size_t>(k)]))))
        return false;
      const Eigen::Index last = std::min(n - 1, k + b);
      for (Eigen::Index i = k + 1; i <= last; ++i) {
        double& l = B_(i, k - i + b);
        if (l == 0) continue;
        l /= p;
        for (Eigen::Index j = k + 1; j <= last; ++j) B_(i, j - i + b) -= l * B_(k, j - k + b);
      }
    }
    return true;
  }
  Eigen::VectorXd solve_band(const Eigen::VectorXd& rhs) {
    const Eigen::Index n = rhs.size(), b = band_;
    y_.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      double s = rhs[perm_[static_cast<std::size_t>(i)]];
      for (Eigen::Index k = std::max<Eigen::Index>(0, i - b); k < i; ++k) s -= B_(i, k - i + b) * y_[k];
      y_[i] = s;
    }
    for (Eigen::Index i = n - 1; i >= 0; --i) {
      double s = y_[i];
      for (Eigen::Index j = i + 1; j <= std::min(n - 1, i + b); ++j) s -= B_(i, j - i + b) * y_[j];
      y_[i] = s / B_(i, b);
    }
    Eigen::VectorXd x(n);
    for (Eigen::Index i = 0; i < n; ++i) x[perm_[static_cast<std::size_t>(i)]] = y_[i];
    return x;
  }

  enum class Kind { Dense, Sparse, Band };
  static constexpr Eigen::Index kSparseMin = 24;  // below this many coordinates dense is as fast
  static constexpr double kSparseDensity = 0.2;   // above this share of nonzeros, dense
  static constexpr double kBandShare = 0.25, kBandPivot = 1e-10;
  Kind kind_ = Kind::Dense;
  bool dense_only_ = false, analysed_ = false, sparse_analysed_ = false;
  Eigen::Index band_ = -1;  // the bandwidth in perm_'s order; -1: not banded
  std::vector<int> perm_;   // perm_[k]: the coordinate at place k of the band's order
  // the band, n x (2 band_ + 1), row by row: B_(i, j - i + band_) = K(perm_ i, perm_ j), then its LU
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> B_;
  Eigen::VectorXd y_;
  Eigen::PartialPivLU<Eigen::MatrixXd> dense_;
  std::vector<char> mask_;
  Eigen::SparseMatrix<double> S_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> slu_;
};

class Alf final : public Integrator {
 public:
  Alf(ClosedLoopSystem& sys, const IntegratorSettings& s)
      : sys_(sys), m_(sys.model()), d_(sys.model()), h_(s.max_step), alpha_given_(s.alf_penalty), iterations_(s.alf_iterations),
        rtol_(s.rtol), atol_(s.atol), fixed_(s.alf_fixed_step), extrapolate_(s.alf_extrapolate), trace_(std::getenv("ALF_TRACE") != nullptr) {
    if (!(alpha_given_ > 0) || !std::isfinite(alpha_given_))
      throw std::invalid_argument("integrator alf: alf_penalty: expected a number > 0, got " + alf_number(alpha_given_));
    if (iterations_ < 1)
      throw std::invalid_argument("integrator alf: alf_iterations: expected at least 1, got " + std::to_string(iterations_));
    if (!(h_ >= 0) || !std::isfinite(h_))
      throw std::invalid_argument("integrator alf: max_step: expected a number >= 0, got " + alf_number(h_));
    if (!(rtol_ > 0) || !(atol_ > 0))
      throw std::invalid_argument("integrator alf: rtol and atol: expected numbers > 0");
    if (fixed_ && h_ == 0) h_ = 1e-3;
    if (!m_.velocity_rows.empty())
      throw std::invalid_argument("integrator alf: the model has rolling constraints (conditions on the velocities alone): not integrated by alf yet");
    for (const int k : m_.motions) {
      driven_q_.push_back(m_.actuators[static_cast<std::size_t>(k)].iq);
      driven_v_.push_back(m_.actuators[static_cast<std::size_t>(k)].iv);
    }
    // the matrices' structural nonzeros: M's (pairs of coordinates on one path to the ground) and
    // Jc^T Jc's (pairs in one constraint's support), the diagonal
    const auto n = static_cast<std::size_t>(m_.nv);
    std::vector<char> mask(n * n, 0);
    for (int a = 0; a < m_.nv; ++a)
      for (int b = a; b >= 0; b = d_.constants.dof_parent[static_cast<std::size_t>(b)])
        mask[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)] = mask[static_cast<std::size_t>(b) * n + static_cast<std::size_t>(a)] = 1;
    for (const std::vector<int>& cols : d_.constants.constraint_cols)
      for (const int a : cols)
        for (const int b : cols) mask[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)] = 1;
    lu_.set_pattern(mask);
    lup_.set_pattern(std::move(mask));
  }

  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    shown_ = false;
    knots_ = 0;
    start_mass_ = stalled_before_ = false;  // (a new start: no projection's M there, no stall before it)
    jerk_ = false;                           // (nor a step before it for the predictor)
    theta_step_ = 0;                         // (nor Newton's rate)
    q_ = y.head(m_.nq);
    v_ = y.segment(m_.nq, m_.nv);
    z_ = y.tail(nz_);
    zslope_ok_ = false;  // (no step before it for the first-order states' error estimate)
    // the accelerations and multipliers of the constrained dynamics there (the motions' coordinates
    // and rates where their signals are)
    drive_state(t);
    set_effect_states(z_);
    const Eigen::VectorXd u = sys_.inputs(t, q_, v_, z_.tail(nxc_));
    a_ = forward_dynamics<double>(m_, d_, q_, v_, u);
    g_ = first_order_rates(t, q_, v_, z_);
    lambda_ = m_.nc ? Eigen::VectorXd(d_.lambda) : Eigen::VectorXd();
    if (!a_.allFinite()) throw IntegratorFailure(t, "alf: the accelerations at the start are not finite");
    if (extrapolate_ && fixed_ && !stability_checked_) check_extrapolation_is_stable(t);  // (at the run's start)
    if (next_ <= 0) {  // the first step: a small fraction of what the accelerations allow
      const Eigen::ArrayXd w = atol_ + rtol_ * magnitude(q_);
      const double acc = (a_.array().abs() / w).maxCoeff();
      next_ = acc > 0 ? 0.5 * std::sqrt(1.0 / acc) : 1e-3;
      next_ = std::clamp(next_, 1e-6, 1e-2);
      if (h_ > 0) next_ = std::min(next_, h_);
    }
  }

  // at fixed steps: on in steps of (at most) h_ toward the stop, each stop's interval in equal
  // steps, past t_out when a step ends beyond it; the state there is the cubic Hermite
  // interpolation of (q, v) and of (v, a) over that step (an error of order h^4, beside the
  // rule's h^2), so that the steps do not bend to the output times (before: every output a stop,
  // a 10 ms output step and 4 ms steps made three steps an interval, not 2.5)
  void advance_output(double t_out, double t_stop) override {
    if (!fixed_ || !(t_stop > t_out)) {
      advance(t_out);
      return;
    }
    shown_ = false;
    const double eps = 1e-12 * std::max(1.0, std::abs(t_stop));
    // (every step reads its inputs at its end's left limit and the next restarts a where they
    // jumped: a reference's step at a step's end enters at the next step, as at a stop; one inside
    // a step is smeared over it, the fixed step's own error)
    while (t_ < t_out - eps) {
      restart_at_input_jump();
      const int n = std::max(1, static_cast<int>(std::ceil((t_stop - t_) / h_ - 1e-9)));
      knots_ = 0;
      fixed_step(n == 1 ? t_stop : t_ + (t_stop - t_) / n, true, 0);
    }
    if (t_ > t_out + eps) show(t_out);  // (inside the last step, this call's or an earlier one's)
  }

  void advance(double t_out) override {
    shown_ = false;
    const double eps = 1e-12 * std::max(1.0, std::abs(t_out));
    if (t_ > t_out + eps) {  // stepped past it already (advance_output)
      show(t_out);
      return;
    }
    if (t_ >= t_out - eps) return;  // there already (advance_output's last step ended at its stop)
    restart_at_input_jump();
    if (fixed_) {  // the interval in equal steps of at most h_
      const int n = std::max(1, static_cast<int>(std::ceil((t_out - t_) / h_ - 1e-9)));
      const double h = (t_out - t_) / n, t0 = t_;
      for (int i = 0; i < n; ++i) {
        knots_ = 0;
        fixed_step(i + 1 == n ? t_out : t0 + (i + 1) * h, i + 1 == n, 0);
      }
      return;
    }
    while (t_ < t_out) {
      // to the stop in one step, or two equal ones when one would leave a sliver
      const double rest = t_out - t_;
      double h = rest <= next_ * (1 + 1e-3) ? rest : rest < 2 * next_ ? rest / 2 : next_;
      for (int tries = 0;; ++tries) {
        if (tries > 60 || h < 1e-12 * std::max(1.0, std::abs(t_)))
          throw IntegratorFailure(t_, "alf: no step down to " + alf_number(h) +
                                          " s passes the Newton iteration and the error test (" +
                                          (extrapolate_ ? "alf extrapolated" : "alf is second order") + ": at "
                                          "rtol " + alf_number(rtol_) + ", atol " + alf_number(atol_) + " its steps became too short" +
                                          (m_.nc ? " for its penalty to hold the loops" : "") +
                                          "; a looser rtol and atol, such as 1e-4 and 1e-6, or fixed steps: alf_fixed_step "
                                          "with max_step)");
        const bool last = t_out - t_ - h <= 1e-12 * std::max(1.0, std::abs(t_out));
        double err = 0;
        if (extrapolate_) {
          if (!extrapolated_pair(last ? t_out : t_ + h, h >= rest, err)) {
            h *= 0.25;
            continue;
          }
        } else {
          if (!step(h, h >= rest)) {
            h *= 0.25;
            continue;
          }
          err = error_estimate(h);
          // a stalled step's accelerations (and so the next one's estimate) carry the stall's error
          // in q times 4/h^2, in directions the projections leave (near a singular position): not a
          // measure of the step's error; such a step is accepted, and the next one is no longer
          if (stalled_ || stalled_before_) err = std::min(err, 1.0);
          if (trace_) {
            const Eigen::ArrayXd w = atol_ + rtol_ * magnitude(q_).max(magnitude(qn_));
            Eigen::Index imax;
            ((h / 12) * (an_ - a_).array().abs() / w).maxCoeff(&imax);
            std::fprintf(stderr, "err t %.9g h %g err %g at %d (a %g -> %g)\n", t_ + h, h, err, static_cast<int>(imax), a_[imax], an_[imax]);
          }
        }
        if (err > 1) {
          ++rejected_;
          if (extrapolate_) restore_start(), steps_ = pair_steps_;
          h *= std::clamp(0.9 * std::pow(err, -0.5), 0.1, 0.5);
          continue;
        }
        if (!extrapolate_) accept(last ? t_out : t_ + h);
        // the next step from this one's error; the step cut only to reach the stop is not a limit
        next_ = std::max(next_ * (last ? 1.0 : 0.0), h * std::clamp(0.9 * std::pow(std::max(err, 1e-8), -0.5), 0.2, 2.0));
        if (h_ > 0) next_ = std::min(next_, h_);
        break;
      }
    }
  }

  Eigen::VectorXd state() const override {
    if (shown_) return shown_y_;
    Eigen::VectorXd y(m_.nq + m_.nv + nz_);
    y << q_, v_, z_;
    return y;
  }
  bool projects() const override { return true; }
  void add_stats(SolverStats& s) const override {
    s.steps += steps_;
    s.rhs_evals += evaluations_;
    s.jac_evals += factorizations_;
    s.nonlinear_iterations += iterations_done_;
    s.nonlinear_failures += failures_;
    s.error_test_failures += rejected_;
  }

 private:
  // a state on the way: a fixed step's substeps' starts (one, or more where Newton made it halve
  // the step), for show()
  struct Knot {
    double t = 0;
    Eigen::VectorXd q, v, a, z, g;
  };

  // f_ = h^2/4 (M a + nle - Q + Jc^T (lambda + alpha phi)) at (q, v, a) and time t: M a + nle by
  // the inverse dynamics (no mass matrix); u_ the inputs there
  // (with pending, the multipliers' update after the last correction, lambda += alpha phi, is made
  // here, with phi at q: one evaluation of the constraints per iteration)
  // (and gz_, the first-order states' rates at z)
  void residual(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a, const Eigen::VectorXd& z,
                Eigen::VectorXd& lambda, double alpha, bool pending) {
    ++evaluations_;
    set_effect_states(z);
    u_ = sys_.inputs(t, q, v, z.tail(nxc_));
    f_ = rnea<double>(m_, d_, q, v, a);  // forward kinematics at (q, v, a) included
    f_ -= applied_forces<double>(m_, d_, q, v, u_);
    if (nz_) {
      gz_.resize(nz_);
      gz_.head(m_.ns) = d_.sdot;
      if (nxc_) gz_.tail(nxc_) = sys_.controller_rates(t, q, v, z.tail(nxc_), u_);
    }
    if (m_.nc) {
      constraint_jacobian_after_kinematics(m_, d_, q);  // (rnea's kinematics at q)
      if (pending) lambda += alpha * d_.phi;
      add_jc_transpose(f_, lambda + alpha * d_.phi, 1.0);
    }
    f_ *= h_now_ * h_now_ / 4;
    for (const int i : driven_v_) f_[i] = 0;  // (a motion's balance holds its unknown force: not solved)
  }

  // one trapezoidal step of h from (t_, q_, v_, a_, lambda_) into (qn_, vn_, an_, lambdan_);
  // false when Newton does not converge; projecting: v and a projected onto the loops at the end
  // (all but an extrapolated pair's inner substeps)
  bool step(double h, bool to_stop, bool projecting = true) {
    const double t1 = t_ + h, c = h * h / 4;
    // the inputs of a step that ends at a stop are read just before it (their left limit): a
    // reference or disturbance that jumps there enters the next step, from a restarted a
    const double t_inputs = to_stop ? t1 - kLeftLimit * std::max(1.0, std::abs(t1)) : t1;
    h_now_ = h;
    // the penalty as given for steps of kPenaltyStep and longer, alpha (kPenaltyStep / h)^2 below:
    // h^2/4 alpha, its weight against M in the Newton matrix, no smaller than at kPenaltyStep
    // and never above kRuleMax by that rule (lambda += alpha phi: phi's rounding times alpha; at
    // 1e13, kPenaltyMax, the double wishbone's K&C rig and the sedan at rtol 1e-6 took steps of a
    // few us at their start and lost their loops there, the weight h^2/4 alpha beside M ~1:
    // "no step passes"; at 1e15 and 1e17 both run, and A02, Andrews, Bricard and A05, whose steps
    // stay above 1 ms or whose failures are elsewhere, take the same steps to the last one. At
    // 1e15 the runs at rtol 1e-8 to 1e-10, whose steps at a start's transient fall below 1e-7 s,
    // lost their loops in the same way: the weight h^2/4 alpha 2.5e-4 at 1e-9 s. With 1e20 (the
    // rule's own alpha down to 3e-7 s) the sedan, the K&C rig, Andrews' squeezer and the driven
    // slider-crank run at their files' tolerances. phi's rounding times alpha reaches lambda,
    // but Newton's matrix carries the same h^2/4 alpha on Jc^T Jc, so its share in q stays at
    // phi's rounding)
    // (at fixed steps the penalty as given: there the rule's growth, 100-fold at 1 ms, amplified
    // phi's rounding into an error floor on A02, ~3e-4 rad below 3 ms steps, and a stall raises
    // the penalty for its own step anyway)
    double alpha = alpha_now_ = fixed_ ? alpha_given_ :
        std::max(alpha_given_, std::min(kRuleMax, alpha_given_ * (kPenaltyStep / h) * (kPenaltyStep / h)));
    // the unknown is the step itself, dl, with q = q_n + dl (additive coordinates) or q_n (+) dl
    // (on the group), and v = 2/h dl - v_n, a = 4/h^2 dl - 4/h v_n - a_n from it. (Taken from q
    // itself, 4/h^2 q - 4/h^2 q_n rounded to 4/h^2 eps |q|: at h = 1e-10 and |q| ~ 1, accelerations
    // in powers of two up to 1e5, which the error test read as the step's error, so that every
    // step below ~1e-8 s failed it at rtol 1e-8 and a run that needed one (the four-bar at 0.93 s,
    // a start's transient) failed; from dl the rounding is 4 eps |v| / h, and the error test's
    // share of it, eps |v| / 3, does not grow as the step shrinks)
    const Eigen::VectorXd ahat = (4 / h) * v_ + a_;
    // the predictor: the trapezoidal rule's own q_n+1 = q_n + h v_n + h^2/4 (a_n + a_n+1) with
    // a_n+1 extrapolated from the last step's change of a: its first correction is h^4 where a
    // is smooth, against h^3 with a_n+1 = a_n (A02 at 10 ms: 5e-8 rad against 3.3e-6)
    Eigen::VectorXd q, dl, v, a;
    dl = h * v_ + (h * h / 2) * a_;
    if (jerk_) dl.noalias() += (h * h * h / 4) * jerk_rate_;
    if (additive_) q = q_ + dl;
    else q = integrate<double>(m_, q_, dl);
    // the motion inputs' coordinates where their signals are at the step's end (held there by
    // Newton: their rows are u's, not the balance), their rates and accelerations too
    drive(t_inputs, q);
    // the first-order states (effect states, a controller's): the trapezoidal rule
    // z = z_n + h/2 (g_n + g(z)), from z_n + h g_n, by Newton on their own block (I - h/2 dg/dz)
    // beside the positions' (a block Jacobi iteration: each block's correction at the same iterate)
    Eigen::VectorXd z = nz_ ? Eigen::VectorXd(z_ + h * g_) : Eigen::VectorXd();
    const Eigen::VectorXd zhat = nz_ ? Eigen::VectorXd(z_ + (h / 2) * g_) : Eigen::VectorXd();
    // v = 2/h dl - v_n, a = 4/h^2 dl - 4/h v_n - a_n (the motions' from their signals)
    auto rates = [&] {
      v = (2 / h) * dl - v_;
      a = (4 / (h * h)) * dl - ahat;
      for (std::size_t k = 0; k < driven_v_.size(); ++k) {
        v[driven_v_[k]] = driven_rate_[static_cast<Eigen::Index>(k)];
        a[driven_v_[k]] = driven_acc_[static_cast<Eigen::Index>(k)];
      }
    };
    Eigen::VectorXd lambda = lambda_;
    // Newton's test (per coordinate, in the weights w): the error left in q, estimated from the
    // corrections' rate of contraction theta as theta / (1 - theta) |dq| (the first correction
    // taken at face value), within kNewton of the error weight atol + rtol |q_i|, but no tighter
    // than kNewtonFloor (1 + |q_i|). At fixed steps rtol and atol no looser than kFixedNewton, for
    // this test and for a stall's: the step alone sets the error there (with Newton and stalls at
    // rtol = atol = 3.2e-3, A02 at 5.6 ms ended 7.3e-3 rad off, at 1e-6 3.5e-4; at 10 ms the loose
    // Newton's error happened to help, 8.9e-4 against the rule's own 1.1e-3). The price: steps of
    // 0.56 ms and shorter no longer pass A02's flat positions (loose stalls let 0.56 ms through).
    // Extrapolated with error control the same (the halves' and quarters' Newton error would pass
    // into the combination and its estimate: at Newton's 1e-3 of rtol = atol = 1e-2 and crank
    // angles of 40 rad a step's Newton left 4e-5 rad, and A02 ended 0.45 to 2.1 rad off at 1e-2 to
    // 1e-3, 1.3e-2 with this; A05 reached 1e-6 in 21 ms, 5 ms with this; work-precision tenth round)
    const bool tight = fixed_ || extrapolate_;
    const double rt = tight ? std::min(rtol_, kFixedNewton) : rtol_, at = tight ? std::min(atol_, kFixedNewton) : atol_;
    const Eigen::ArrayXd wz = nz_ ? Eigen::ArrayXd(kNewton * (at + rt * z_.array().abs())) : Eigen::ArrayXd();  // (z's Newton test)
    const Eigen::ArrayXd qmag = magnitude(q_);
    const Eigen::ArrayXd floor = kNewtonFloor * (1 + qmag);
    const Eigen::ArrayXd wq = at + rt * qmag, wv = (h / 2) * (at + rt * v_.array().abs());
    // (with error control the weights in q alone: the error test judges the step's accelerations,
    // and the weights in v made A05 take two iterations a step instead of one, 2.5 times the CPU)
    const Eigen::ArrayXd wqv = wq.min(wv), wn = fixed_ ? wqv : wq;
    const Eigen::ArrayXd w = (kNewton * wn).max(floor), wl = (kStallTolerance * wqv).max(floor);
    // the matrix is factored at the first iterate (on a tree: kept while h is the same); with loop
    // closures always, as the penalty's weight makes it follow Jc closely
    stalled_ = false;
    bool converged = false, refreshed = false, refactor = m_.nc > 0 || !factored_ || h != h_factored_;
    double last = 0, previous = 0;
    int since_factor = 0;
    for (int it = 0; it < iterations_; ++it) {
      rates();
      residual(t_inputs, q, v, a, z, lambda, alpha, it > 0);
      Eigen::VectorXd dz;
      if (nz_) {
        const Eigen::VectorXd rz = z - zhat - (h / 2) * gz_;
        if (!z_jacobian_ok_ || z_jacobian_age_ >= kTangentAge || tangent_stale_) form_z_jacobian(t_inputs, q, v, z);
        if (h != h_z_) {
          luz_.compute(Eigen::MatrixXd::Identity(nz_, nz_) - (h / 2) * Gz_);
          h_z_ = h;
        }
        dz = -luz_.solve(rz);
        if (!dz.allFinite()) break;
      }
      if (refactor || tangent_stale_) {
        // the matrix: the tangent kept (formed again when stale) at this step's h, with this
        // iterate's Jc in the penalty
        if (tangent_stale_ || !have_tangent_) {
          form_tangent(t_inputs, q, v, a, lambda, alpha);
          refreshed = true;
        }
        if (!factor(h, alpha, q)) break;
        refactor = false;
        previous = 0;
        since_factor = 0;
      }
      const Eigen::VectorXd dq = -lu_.solve(f_);
      if (!dq.allFinite()) break;
      dl += dq;
      if (additive_) q = q_ + dl;
      else integrate_into<double>(m_, q_, dl, q);
      hold_driven(q);  // (exactly its signal's value: its row of dq is zero up to rounding)
      if (nz_) z += dz;
      ++iterations_done_;
      ++since_factor;
      last = (dq.array().abs() / w).maxCoeff();
      if (nz_) last = std::max(last, (dz.array().abs() / wz.max(kNewtonFloor)).maxCoeff());
      const double theta = previous > 0 ? last / previous : 0;
      previous = last;
      if (trace_)
        std::fprintf(stderr, "t %.9g h %g it %d |dq|/w %g theta %g |dq| %g |phi| %g%s\n", t1, h, it, last, theta,
                     dq.cwiseAbs().maxCoeff(), m_.nc ? d_.phi.cwiseAbs().maxCoeff() : 0.0,  // (phi before the correction)
                     since_factor == 1 ? (refreshed ? " (new tangent)" : " (new factorization)") : "");
      // (at fixed steps, the first correction after a factorization: the contraction rate of the
      // last step that measured one, when it had this step's length, raised to the power 0.8 for every step that used it instead
      // (it drifts towards 1, so that a second iteration measures it again now and then: RADAU5's
      // rule), where it was below kTrustTheta. Not with error control: there the Newton error it
      // leaves reaches the error estimate, h/12 |a_n+1 - a_n|, and Bricard's error at rtol 3e-5
      // grew tenfold, 2.6e-5 -> 1.4e-4 rad)
      const double rate = theta > 0 ? theta
                          : fixed_ && since_factor == 1 && theta_step_ > 0 && theta_step_ < kTrustTheta &&
                                    std::abs(h - h_theta_) <= 1e-9 * h
                              ? theta_step_
                              : 0;
      const double left = rate > 0 && rate < 1 ? last * rate / (1 - rate) : last;
      if (left <= 1 && (theta < 1 || last <= 1)) {
        converged = true;
        if (theta > 0) theta_step_ = theta;
        else if (rate > 0) theta_step_ = std::pow(rate, 0.8);
        h_theta_ = h;
        break;
      }
      // a stall (the multipliers' iteration creeping near a singular position): accepted within a
      // tenth of the weights in q and v (wl); otherwise the penalty raised for the rest of the step
      if (theta >= kStall && since_factor >= 2) {
        if (left_loose(dq, wl) <= 1) {
          ++stalls_;
          stalled_ = true;
          if (trace_) std::fprintf(stderr, "alf: stall accepted at t %.9g\n", t1);
          converged = true;
          break;
        }
        if (alpha * kBoost <= kPenaltyMax) {
          alpha *= kBoost;
          refactor = true;
          ++boosts_;
          if (trace_) std::fprintf(stderr, "alf: penalty raised to %g at t %.9g\n", alpha, t1);
          continue;
        }
      }
      // the modified Newton's rule: where the corrections shrink by less than kRate per
      // iteration, the matrix is factored again at this iterate (its Jc; the penalty's weight
      // makes the matrix follow Jc closely), and if that was just done, the tangent is formed
      // again too (once a step; after that the iteration goes on: the multipliers' iteration
      // may creep near a singular position)
      if (theta > kRate) {
        refactor = true;
        if (since_factor <= 2 && !refreshed) tangent_stale_ = true;
      }
    }
    ++tangent_age_;
    if (tangent_age_ >= kTangentAge) tangent_stale_ = true;
    if (!converged) {
      ++failures_;
      theta_step_ = 0;
      last_failure_ = last;
      tangent_stale_ = true;  // the retry forms the tangent again (this one's may be from a wild iterate)
      return false;
    }
    // v and a projected onto the constraints at q
    rates();
    projected_ = m_.nc > 0 && projecting;
    if (projected_ && !project(q, v, a, lambda, c, alpha)) return false;
    if (!q.allFinite() || !v.allFinite() || !a.allFinite()) return false;
    qn_ = q;
    vn_ = v;
    an_ = a;
    lambdan_ = lambda;
    if (nz_) {  // (the rates the rule implies, as a's: no evaluation more)
      zn_ = z;
      gn_ = (2 / h) * (z - z_) - g_;
    }
    return true;
  }

  // the mass-orthogonal projections of v and a onto the constraints at q:
  //   (M + c alpha Jc^T Jc) v = M v*,   (M + c alpha Jc^T Jc) a = M a* - c alpha Jc^T gamma,
  // M and Jc at q (their own factorization; c = h^2/4), and the multipliers' last update
  bool project(const Eigen::VectorXd& q, Eigen::VectorXd& v, Eigen::VectorXd& a, Eigen::VectorXd& lambda, double c, double alpha) {
    Mp_ = crba<double>(m_, d_, q);
    constraint_jacobian_after_kinematics(m_, d_, q);  // Jc at q (crba's kinematics), and phi: the multipliers' last update
    lambda += alpha * d_.phi;
    Kp_ = Mp_;
    add_penalty(Kp_, c * alpha);
    hold_rows(Kp_);  // (a motion's row: its rate and acceleration are its signal's)
    if (!lup_.compute(Kp_, false)) return false;  // (M + c alpha Jc^T Jc: the structural pattern)
    ++factorizations_;
    // each solved for its correction, v = v* - K^-1 (c alpha Jc^T Jc v*) (and a alike): the same
    // numbers in exact arithmetic, but the factorization's rounding (of the order of eps |K|, and
    // |K| is c alpha |Jc|^2, a million times |M|) then acts on the small correction alone, not on
    // v*: solved whole, it put a relative error of eps c alpha |Jc|^2 / |M| into the free motion
    // at every step (A02's phase drift grew with alpha: 4.6e-9 rad at 0.8 s with alpha 1e12, 1e-10
    // with 1e10). The residual's rounding lies along Jc^T, where K is stiff.
    Eigen::VectorXd r = Eigen::VectorXd::Zero(m_.nv);
    add_jc_transpose(r, jc_times(v), c * alpha);
    for (const int i : driven_v_) r[i] = 0;
    v -= lup_.solve(r);
    constraint_gamma_after_positions(m_, d_, q, v);  // gamma at the projected velocities (crba's positions)
    r.setZero();
    add_jc_transpose(r, jc_times(a) + d_.gamma, c * alpha);
    for (const int i : driven_v_) r[i] = 0;
    a -= lup_.solve(r);
    return true;
  }

  // at a stop: where the inputs jump there (u(t) against its left limit, at the same state),
  // a and the multipliers are those of the dynamics after the jump (as reset() makes them); the
  // trapezoidal rule would otherwise carry a's jump into its error estimate, h/12 |a_n+1 - a_n|,
  // which no step short of ~1e-8 s passes at tight tolerances
  void restart_at_input_jump() {
    if (steps_ == 0) return;  // reset() has just made a
    set_effect_states(z_);
    const Eigen::VectorXd u = sys_.inputs(t_, q_, v_, z_.tail(nxc_));
    const Eigen::VectorXd before = sys_.inputs(t_ - kLeftLimit * std::max(1.0, std::abs(t_)), q_, v_, z_.tail(nxc_));
    if (u.size() == 0 || (u - before).cwiseAbs().maxCoeff() <= 1e-9 * (1 + u.cwiseAbs().maxCoeff())) return;
    drive_state(t_);  // (a motion's signal that jumps moves its coordinate and rate here)
    const Eigen::VectorXd a = forward_dynamics<double>(m_, d_, q_, v_, u);
    if (!a.allFinite()) return;
    a_ = a;
    if (m_.nc) lambda_ = d_.lambda;
    g_ = first_order_rates(t_, q_, v_, z_);
    jerk_ = zslope_ok_ = false;  // (a jumped: the last step's change of a says nothing of the next)
    ++input_restarts_;
  }

  // a fixed step to t1, or where Newton does not pass it, two
  // of half the length (down to 1/2^kHalvings of it): a stall at a singular position that the
  // penalty's raise does not rescue passes at a shorter step (A02 at 9 ms: one step at t = 16.45 s
  // diverged after the raise to 1e13; before, the run failed there)
  // (each substep's start is kept as a knot of the step, for show())
  void fixed_step(double t1, bool to_stop, int depth) {
    const double h = t1 - t_;
    if (extrapolate_) {
      if (extrapolated_step(t1, to_stop)) {
        if (knots_ == static_cast<int>(knot_.size())) knot_.emplace_back();
        knot_[static_cast<std::size_t>(knots_++)] = start_.at;
        return;
      }
    } else if (step(h, to_stop)) {
      if (knots_ == static_cast<int>(knot_.size())) knot_.emplace_back();
      Knot& k = knot_[static_cast<std::size_t>(knots_++)];  // (assigned in place: no heap once sized)
      save_start(k);
      accept(t1);
      return;
    }
    if (depth >= kHalvings) fail_newton(t1, h);
    ++halvings_;
    fixed_step(t_ + h / 2, to_stop, depth + 1);
    fixed_step(t1, to_stop, depth + 1);
  }

  void save_start(Knot& k) const {
    k.t = t_;
    k.q = q_;
    k.v = v_;
    k.a = a_;
    k.z = z_;
    k.g = g_;
  }

  // the state before an extrapolated step, for restore_start() (both pairs of steps)
  void save_pair_start() {
    start_.lambda = lambda_, start_.jerk = jerk_rate_, start_.zslope = zslope_;
    start_.jerk_ok = jerk_, start_.zslope_ok = zslope_ok_, start_.stalled = stalled_before_, start_.h_last = h_last_;
    save_start(start_.at);
  }
  // one step to t1 by Richardson's extrapolation: the step of h from the start (x1), two of h/2
  // (x2), and x2 + (x2 - x1)/3 (on the group q2 (+) (q2 (-) q1)/3). The trapezoidal rule is
  // symmetric: its error's expansion has even powers of h alone, so the h^2 terms cancel and the
  // combination is of fourth order (the projections of v and a break the symmetry by little:
  // A02's four-bars before their flat position, 20, 10 and 5 ms, errors 5.8e-8, 4.3e-9, 3.0e-10
  // rad, 13.6 and 14.3 per halving; the plain rule at 2.5 ms 1.0e-5). The two ends meet the
  // constraints to rounding, and so does their combination to O(h^6) (phi is smooth; x2 - x1 is
  // O(h^3)). Where the loops pass a flat position the penalty's rounding sets a floor that no
  // step removes (A02, N = 40, 20 s: ~1e-5 rad at steps of 16 to 2.5 ms; N = 1, 6 s at 2.5 ms,
  // alpha 1e8, 1e10, 1e12: 3.8e-8, 1.8e-7, 3.5e-6). False: one of the three did not pass Newton
  // (the start restored)
  bool extrapolated_step(double t1, bool to_stop) {
    const double t0 = t_, h = t1 - t0;
    save_pair_start();
    swap_theta(h);
    const bool big = step(h, to_stop);
    swap_theta(h / 2);
    if (!big) return false;
    ++steps_;
    x1q_ = qn_, x1v_ = vn_, x1a_ = an_, x1l_ = lambdan_, x1z_ = zn_, x1g_ = gn_;
    start_mass_ = false;  // (Mp_ is M at the long step's end)
    if (!step(h / 2, false)) {
      restore_start();
      return false;
    }
    accept(t0 + h / 2);
    if (!step(t1 - t_, to_stop)) {
      restore_start();
      return false;
    }
    accept(t1);
    const Eigen::VectorXd dq = additive_ ? Eigen::VectorXd(q_ - x1q_) : difference(m_, x1q_, q_);
    // the two ends agree to O(h^3), the step moved O(h): where they differ by a tenth of the
    // step's own motion or more, and by more than the tolerance atol + rtol |q|, one of them went
    // astray (A05's flyball at 50 ms: a long step 1e19 times the tolerance away; the extrapolation
    // would carry it on): the step is too long (a step from rest moves by little: the tolerance)
    const Eigen::VectorXd moved = additive_ ? Eigen::VectorXd(q_ - start_.at.q) : difference(m_, start_.at.q, q_);
    const double disagree = dq.cwiseAbs().maxCoeff() / (moved.cwiseAbs().maxCoeff() + 1e-300),
                 beyond = (dq.array().abs() / (atol_ + rtol_ * magnitude(q_))).maxCoeff();
    if (trace_) std::fprintf(stderr, "extrapolation t %.9g |x2 - x1| / |x2 - x0| %g, in the tolerance %g\n", t1, disagree, beyond);
    if (!(disagree <= kDisagree) && !(beyond <= 1)) {
      ++disagreements_;
      restore_start();
      return false;
    }
    combine_richardson(dq);
    start_mass_ = false;  // (Mp_: M at the half steps' end, not at the combination)
    if (++since_check_ >= kCheckSteps) check_extrapolation_is_stable(t1, false);
    return true;
  }
  // Richardson's combination of the finer end (the state now) with the coarser x1: x2 + (x2 - x1)/3
  // (q on the group: q2 (+) dq/3 with dq = q2 (-) q1), for both pairs of steps
  void combine_richardson(const Eigen::VectorXd& dq) {
    if (additive_)
      q_ += dq / 3;
    else
      q_ = integrate<double>(m_, q_, Eigen::VectorXd(dq / 3));
    v_ += (v_ - x1v_) / 3;
    a_ += (a_ - x1a_) / 3;
    if (m_.nc) lambda_ += (lambda_ - x1l_) / 3;
    if (nz_) {
      z_ += (z_ - x1z_) / 3;
      g_ += (g_ - x1g_) / 3;
    }
  }
  // With error control (alf_extrapolate without alf_fixed_step), one step to t1 of H = t1 - t_n
  // as two steps of H/2 (x1) and four of H/4 (x2), combined as x2 + (x2 - x1)/3 (on the group
  // q2 (+) (q2 (-) q1)/3). Even counts on both sides: the combination's factor on a mode
  // y' = lambda y is (4 R(z/4)^4 - R(z/2)^2)/3 with z = H lambda, at most 1 on the whole negative
  // axis (0.9992 at z = -1e5; it tends to 1, as the plain rule's R tends to -1) and wherever the
  // mode's damping ratio is 0.3 or more (|Im z| <= 3 |Re z|); the (1, 2) sequence of the fixed
  // steps tends to 5/3 there, and a stiff mode grew (A05, Andrews: refused at fixed steps). Where
  // a lightly damped mode is too fast for H (|T| up to 1.25 at damping 0.1, 1.66 undamped) the two
  // ends differ by the mode's amplitude and the error test shortens the step. Twice the work per
  // H of the (1, 2) sequence at fixed steps (six substeps against three).
  // The projections of v and a onto the loops end each sequence only, not its inner substeps: a
  // projection is not a step of the trapezoidal rule and breaks the error expansion in even powers
  // of h that the combination cancels (projected at every substep, the loops' errors fell as h^2
  // to h^3: Bricard at rtol 1e-6 6.3e-6 rad, now 1.9e-8; work-precision, thirteenth round).
  // The error test: x2's error, |x2 - x1| / 3 in q (and in the first-order states), per unit
  // step (divided by H, as the plain rule's: the global error of the unextrapolated x2 is that
  // sum), in the weights atol + rtol |q|; the step taken is the extrapolated x2, of fourth order,
  // whose error is well below that (local extrapolation, as ODEX's). H's next length from that
  // estimate, which goes as H^2: H 0.9 err^(-1/2).
  // (Before: the (1, 2) sequence with its difference as a local error in q, not per unit step:
  // the global error stayed far above the tolerance, A01 1.1e-5 m at rtol 1e-6, A02 2.9 rad at
  // 1e-2, and stiff modes grew.) False: a substep did not pass Newton (the start restored).
  bool extrapolated_pair(double t1, bool to_stop, double& err) {
    const double t0 = t_, H = t1 - t0;
    save_pair_start();
    pair_steps_ = steps_;
    bool stalled = false;
    // n substeps of H/n from the start; false: one did not pass Newton (the start restored)
    const auto substeps = [&](int n) {
      for (int k = 1; k <= n; ++k) {
        const double tk = k == n ? t1 : t0 + k * (H / n);
        if (!step(tk - t_, to_stop && k == n, k == n)) {
          restore_start();
          return false;
        }
        stalled = stalled || stalled_;
        accept(tk);
      }
      return true;
    };
    if (!substeps(2)) return false;
    x1q_ = q_, x1v_ = v_, x1a_ = a_, x1l_ = lambda_, x1z_ = z_, x1g_ = g_;
    restore_start();
    if (!substeps(4)) return false;
    const Eigen::VectorXd dq = additive_ ? Eigen::VectorXd(q_ - x1q_) : difference(m_, x1q_, q_);
    const Eigen::ArrayXd qmag = magnitude(q_).max(magnitude(x1q_)), w = atol_ + rtol_ * qmag;
    // (what Newton may leave in q at the six substeps' ends, kNewtonFloor (1 + |q|) each, is not
    // the step's error: see above_noise)
    err = above_noise(dq.array().abs() / 3, 2 * kNewtonFloor * (1 + qmag), H * w);
    if (nz_) {
      const Eigen::ArrayXd wz = atol_ + rtol_ * z_.array().abs().max(x1z_.array().abs());
      err = std::max(err, ((z_ - x1z_).array().abs() / (3 * H) / wz).maxCoeff());
    }
    if (!std::isfinite(err)) err = 1e300;
    // a stalled substep (near a singular position) leaves its error in q at a tenth of the
    // weights and its accelerations carry it times 4/h^2: the estimate then is not the step's
    // error; such a step is accepted, and the next one is no longer (as with the plain rule)
    if (stalled || start_.stalled) err = std::min(err, 1.0);
    if (trace_) std::fprintf(stderr, "extrapolated pair t %.9g H %g err %g%s\n", t1, H, err, stalled ? " (stalled)" : "");
    combine_richardson(dq);
    stalled_before_ = stalled;
    start_mass_ = false;  // (Mp_: M at the fine steps' end, not at the combination)
    // (the predictor's change of a: over the last fine step, as accept() left it)
    return true;
  }
  // The extrapolated rule's factor on a mode y' = lambda y is (4 R(z/2)^2 - R(z))/3, z = h lambda,
  // R(z) = (1 + z/2)/(1 - z/2): on the imaginary axis (an undamped oscillation) |.|^2 =
  // 1 + 8 (1 - cos(4 atan(y/4) - 2 atan(y/2)))/9 for z = i y, 1 + y^6/576 and so the rule's own
  // error below y ~ 1, 1.077 a step at y = 3; on the negative axis it passes 1 near z = -30 and
  // tends to 5/3 (the plain rule's factor is at most 1 in both). So the fastest mode of the
  // linearization, [0 I; -M^-1 K  -M^-1 C] with K, C the balance's derivatives on the tree with
  // the loops' reactions at their multipliers (their turning: Andrews' squeezer 389 1/s without,
  // 1749 with; its runs that passed the first ended 1e-3 off), and the first-order states'
  // dg/dz, must have h |lambda| <= kStableZ: checked at the start (a refusal, naming the mode's
  // rate and the step that would pass) and every kCheckSteps steps (the run ends there; 7% of
  // A02's time). A05's flyball (a spring of 1e6 N/m, 8117 1/s) before: its runs went on to 1e18
  // rad/s or, at 16 to 21 ms, ended 0.02 to 0.06 m off where the plain rule at 10 ms is 2e-3 off
  // (at the run's start: a refusal; on the way, every kCheckSteps extrapolated steps at the
  // state reached, as K and C change with the motion: the run ends there)
  void check_extrapolation_is_stable(double t, bool start = true) {
    stability_checked_ = true;
    since_check_ = 0;
    double fastest = 0;
    try {
      if (!td_) {
        td_ = std::make_unique<TreeDerivatives>(m_);
        zero_multipliers_.setZero(m_.nc);
      }
      set_effect_states(z_);
      const Eigen::VectorXd u = sys_.inputs(t, q_, v_, z_.tail(nxc_));
      td_->compute_balance(q_, v_, u, a_, m_.nc ? lambda_ : zero_multipliers_);  // (the loops' reactions turning)
      Eigen::MatrixXd M = td_->M, K = td_->dtau_dq - td_->dQ_dq, C = td_->dtau_dv - td_->dQ_dv;
      for (const int i : driven_v_) {  // (a motion's coordinate is its signal's: no mode)
        M.row(i).setZero(), M.col(i).setZero(), K.row(i).setZero(), K.col(i).setZero(), C.row(i).setZero(), C.col(i).setZero();
        M(i, i) = 1;
      }
      fastest = fastest_mode(M, K, C);
    } catch (const std::exception& e) {
      if (trace_) std::fprintf(stderr, "alf: no tangent for the extrapolation's check (%s)\n", e.what());
    }
    if (nz_ && start) {
      form_z_jacobian(t, q_, v_, z_);
      if (z_jacobian_ok_) fastest = std::max(fastest, Eigen::EigenSolver<Eigen::MatrixXd>(Gz_, false).eigenvalues().cwiseAbs().maxCoeff());
    }
    if (trace_) std::fprintf(stderr, "alf: fastest mode %g 1/s at t %.9g (h |lambda| = %g)\n", fastest, t, h_ * fastest);
    if (!(h_ * fastest > kStableZ)) return;
    if (start) throw std::invalid_argument("integrator alf: " + too_fast(fastest, "at the start"));
    throw IntegratorFailure(t, "alf: " + too_fast(fastest, "here"));
  }
  std::string too_fast(double fastest, const char* where) const {
    std::ostringstream os;
    os << "alf_extrapolate: the model's fastest mode " << where << ", " << alf_number(fastest) << " 1/s, makes h |lambda| = "
       << alf_number(h_ * fastest) << " at max_step " << alf_number(h_) << " s, where the extrapolated rule is unstable (above "
       << kStableZ << "); max_step at most " << alf_number(kStableZ / fastest)
       << " s, or alf without alf_extrapolate (the plain rule damps it)";
    return os.str();
  }
  // |lambda| of the fastest mode of x'' = -M^-1 (K x + C x'), by the power iteration on
  // [0 I; -M^-1 K  -M^-1 C] (the growth of its 40th power, each an O(n^2) product and solve)
  static double fastest_mode(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, const Eigen::MatrixXd& C) {
    const Eigen::LLT<Eigen::MatrixXd> llt(M);
    if (llt.info() != Eigen::Success) return 0;
    const Eigen::Index n = M.rows();
    Eigen::VectorXd x(n), y(n);
    for (Eigen::Index i = 0; i < n; ++i) x[i] = std::sin(1.0 + i), y[i] = std::cos(2.0 + i);
    double grown = 0;
    constexpr int kIterations = 40, kSettle = 10;
    for (int k = 0; k < kIterations; ++k) {
      const Eigen::VectorXd x1 = y, y1 = -llt.solve(K * x + C * y);
      const double s = std::sqrt(x1.squaredNorm() + y1.squaredNorm()), before = std::sqrt(x.squaredNorm() + y.squaredNorm());
      if (!(s > 0) || !std::isfinite(s)) return s > 0 ? 1e300 : 0;
      if (k >= kSettle) grown += std::log(s / before);
      x = x1 / s, y = y1 / s;
    }
    return std::exp(grown / (kIterations - kSettle));
  }

  // back to the extrapolated step's start (a half step failed, or the error test)
  void restore_start() {
    const Knot& k = start_.at;
    t_ = k.t, q_ = k.q, v_ = k.v, a_ = k.a, z_ = k.z, g_ = k.g, lambda_ = start_.lambda;
    jerk_rate_ = start_.jerk, jerk_ = start_.jerk_ok, zslope_ = start_.zslope, zslope_ok_ = start_.zslope_ok;
    h_last_ = start_.h_last, stalled_before_ = start_.stalled;
    start_mass_ = false;  // (Mp_ is no longer M at the start)
  }
  // Newton's last contraction rate is kept per step length (the extrapolation alternates h and h/2)
  void swap_theta(double h) {
    if (std::abs(h - h_theta_) > 1e-9 * h && std::abs(h - h_theta_other_) <= 1e-9 * h) {
      std::swap(theta_step_, theta_other_);
      std::swap(h_theta_, h_theta_other_);
    }
  }

  // state() at t inside the last fixed step (its substeps' knots, then the state reached): cubic
  // Hermite in (q, v) and in (v, a) over the substep that holds t
  void show(double t) {
    if (knots_ == 0) return;  // (not after a fixed step: state() is the state reached)
    int k = knots_ - 1;
    while (k > 0 && knot_[static_cast<std::size_t>(k)].t > t) --k;
    const Knot& a = knot_[static_cast<std::size_t>(k)];
    const bool last = k + 1 == knots_;
    const Knot& b = last ? Knot{} : knot_[static_cast<std::size_t>(k + 1)];
    const double tb = last ? t_ : b.t;
    const Eigen::VectorXd &qb = last ? q_ : b.q, &vb = last ? v_ : b.v, &ab = last ? a_ : b.a;
    const Eigen::VectorXd &zb = last ? z_ : b.z, &gb = last ? g_ : b.g;
    const double h = tb - a.t, s = std::clamp((t - a.t) / h, 0.0, 1.0), s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = (s3 - 2 * s2 + s) * h, h01 = -2 * s3 + 3 * s2, h11 = (s3 - s2) * h;
    shown_y_.resize(m_.nq + m_.nv + nz_);
    if (additive_) {
      shown_y_.head(m_.nq) = h00 * a.q + h10 * a.v + h01 * qb + h11 * vb;
    } else {  // on the group: q_a (+) (h10 v_a + h01 (q_b (-) q_a) + h11 v_b), as h00 + h01 = 1
      const Eigen::VectorXd dl = h10 * a.v + h01 * difference(m_, a.q, qb) + h11 * vb;
      shown_y_.head(m_.nq) = integrate<double>(m_, a.q, dl);
    }
    shown_y_.segment(m_.nq, m_.nv) = h00 * a.v + h10 * a.a + h01 * vb + h11 * ab;
    if (nz_) shown_y_.tail(nz_) = h00 * a.z + h10 * a.g + h01 * zb + h11 * gb;
    shown_ = true;
  }

  // An error test per unit step: the largest e_i / scale_i, e the step's error estimate in q and
  // scale = h (atol + rtol |q|). Where that is above 1/2, the part of e that Newton's floor may
  // account for (noise: e.g. its 2 kNewtonFloor (1 + |q|) for the two ends) is taken off, down to
  // 1/2 at least. Per unit step that floor alone grows as 1/h: at rtol 1e-8 to 1e-10 the sedan,
  // the K&C rig, Andrews' squeezer and the driven slider-crank failed at their starts' short steps
  // ("no step down to 1e-12 s passes"). Below 1/2 the estimate is used as it is, so that the
  // steps grow as before (taken off there too, it read 0 on runs whose Newton went far below its
  // floor, their steps doubled and were rejected: twice the evaluations on A05 and the heavy top)
  static double above_noise(const Eigen::ArrayXd& e, const Eigen::ArrayXd& noise, const Eigen::ArrayXd& scale) {
    double err = 0;
    for (Eigen::Index i = 0; i < e.size(); ++i) {
      const double raw = e[i] / scale[i];
      err = std::max(err, raw <= 0.5 ? raw : std::max(0.5, (e[i] - noise[i]) / scale[i]));
    }
    return err;
  }
  // the local error in q, h^2/12 (a_n+1 - a_n), in the weights atol + rtol |q| (<= 1: accepted)
  double error_estimate(double h) const {
    const Eigen::ArrayXd qmag = magnitude(q_).max(magnitude(qn_)), w = atol_ + rtol_ * qmag;
    // (what Newton may leave in q at either end, kNewtonFloor (1 + |q|) each, 4/h^2 times that in
    // a, is not the step's error: see above_noise)
    double err = above_noise((h * h / 12) * (an_ - a_).array().abs(), 2 * kNewtonFloor * (1 + qmag), h * w);
    // the first-order states': h^2/12 |z^(3)| per unit step, z^(3) from the rates' divided
    // differences over this step and the last (none after a start or a restart)
    if (nz_ && zslope_ok_) {
      const Eigen::ArrayXd wz = atol_ + rtol_ * z_.array().abs().max(zn_.array().abs());
      const Eigen::ArrayXd z3 = ((gn_ - g_) / h - zslope_).array() / ((h + h_last_) / 2);
      err = std::max(err, ((h * h / 12) * z3.abs() / wz).maxCoeff());
    }
    return err;
  }

  void accept(double t1) {
    stalled_before_ = stalled_;
    start_mass_ = projected_;  // (Mp_: M at qn_, where the step projected)
    // the step's change of a, per unit time, for the next step's predictor
    jerk_rate_ = (an_ - a_) / (t1 - t_);
    jerk_ = true;
    if (nz_) {
      zslope_ = (gn_ - g_) / (t1 - t_);
      h_last_ = t1 - t_;
      zslope_ok_ = true;
      z_ = zn_;
      g_ = gn_;
      ++z_jacobian_age_;
    }
    q_ = qn_;
    v_ = vn_;
    a_ = an_;
    lambda_ = lambdan_;
    t_ = t1;
    ++steps_;
  }

  [[noreturn]] void fail_newton(double t1, double h) {
    std::ostringstream os;
    os << "alf: Newton did not converge in " << iterations_ << " iterations at step " << h << " s (the last correction "
       << last_failure_ << " times its tolerance; alf_iterations; a smaller step, max_step, or another alf_penalty)";
    // (extrapolated: the stiffness hint only where steps' two ends disagreed, as where a stiff mode
    // grows; a failure at a singular position's stall with no disagreement is not that)
    if (extrapolate_ && disagreements_ > 0)
      os << "; extrapolated (alf_extrapolate): " << disagreements_ << " steps' two ends disagreed, as where a stiff "
            "mode grows (the rule so combined is not A-stable, the plain rule damps such modes): alf without "
            "alf_extrapolate";
    else if (extrapolate_)
      os << "; extrapolated (alf_extrapolate), no step's two ends disagreed";
    throw IntegratorFailure(t1, os.str());
  }

  // The tangent at (q, v, a): the parts of the full tangent of f,
  //   M + h/2 C + h^2/4 (K + Jc^T alpha Jc),  K = d(M a + nle - Q)/dq at fixed a, C = d(nle - Q)/dv
  // (the reactions' turning left out), kept as Mt_, Ct_, Kt_ (so a step of another h combines
  // them again), from the analytic derivatives (TreeDerivatives::compute_balance: the open tree's
  // derivatives, no solve for the accelerations'). Where they do not apply (they throw: an effect
  // or constraint they do not differentiate; or a derivative that is not finite) the mass matrix
  // alone (C = K = 0), and after kTangentFailures such failures the mass matrix from then on.
  void form_tangent(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                    const Eigen::VectorXd& lambda, double alpha) {
    bool tangent = false;
    if (use_tangent_) {
      try {
        if (!td_) {
          td_ = std::make_unique<TreeDerivatives>(m_);
          zero_multipliers_.setZero(m_.nc);
        }
        // (d_ holds the residual's evaluation at this iterate: phi and the inputs u_)
        td_->compute_balance(q, v, u_, a, zero_multipliers_);
        Mt_ = td_->M;
        Ct_ = td_->dtau_dv - td_->dQ_dv;
        Kt_ = td_->dtau_dq - td_->dQ_dq;
        tangent = Mt_.allFinite() && Ct_.allFinite() && Kt_.allFinite();
      } catch (const std::exception& e) {
        if (trace_) std::fprintf(stderr, "alf: no tangent at t %.9g (%s): the mass matrix alone\n", t, e.what());
      }
      if (!tangent && ++tangent_failures_ >= kTangentFailures) use_tangent_ = false;  // not again
    }
    if (!tangent) {
      Mt_ = crba<double>(m_, d_, q);  // (crba leaves Jc)
      Ct_.setZero(m_.nv, m_.nv);
      Kt_.setZero(m_.nv, m_.nv);
    } else {
      ++tangents_;
    }
    have_tangent_ = true;
    scan_newton_ = true;  // (C and K may have nonzeros outside the structural pattern: springs across branches)
    fresh_mass_ = true;  // (Mt_ is at this iterate)
    tangent_stale_ = false;
    tangent_age_ = 0;
  }

  // the Newton matrix Mt + h/2 Ct + h^2/4 (Kt + alpha Jc^T Jc) of this step (Jc: d_.Jc, the
  // residual's last evaluation), factored; false: not finite
  bool factor(double h, double alpha, const Eigen::VectorXd& q) {
    const double c = h * h / 4;
    // M at this iterate (C and K kept; crba leaves Jc), or at a step's first factorization the
    // projection's M at the step's start (h v away from the predictor: Newton's matrix, not its
    // residual; one mass matrix a step fewer)
    if (m_.nc && !fresh_mass_) {
      if (start_mass_)
        Mt_ = Mp_;
      else
        Mt_ = crba<double>(m_, d_, q);
    }
    fresh_mass_ = start_mass_ = false;
    K_ = Mt_;
    if (use_tangent_ || tangents_ > 0) {
      K_.noalias() += (h / 2) * Ct_;
      K_.noalias() += c * Kt_;
    }
    if (m_.nc) add_penalty(K_, c * alpha);
    hold_rows(K_);  // (Newton leaves a motion's coordinate where its signal is)
    if (!lu_.compute(K_, scan_newton_)) return false;  // (C and K: nonzeros seen when formed)
    scan_newton_ = false;
    ++factorizations_;
    factored_ = true;
    h_factored_ = h;
    return true;
  }

  // K += s Jc^T Jc (Jc: d_.Jc), row by row on each constraint's support (ModelConstants::
  // constraint_cols: Jc is zero elsewhere), so a loop of k columns costs k^2 per row, not nv^2
  void add_penalty(Eigen::MatrixXd& K, double s) const {
    for (std::size_t ci = 0; ci < m_.constraints.size(); ++ci) {
      const ConstraintModel& c = m_.constraints[ci];
      const std::vector<int>& cols = d_.constants.constraint_cols[ci];
      for (int r = c.row; r < c.row + c.nrows; ++r)
        for (const int a : cols) {
          const double x = s * d_.Jc(r, a);
          if (x == 0) continue;
          for (const int b : cols) K(b, a) += x * d_.Jc(r, b);
        }
    }
  }

  // y += s Jc^T x, on the constraints' supports (Jc is zero elsewhere)
  void add_jc_transpose(Eigen::VectorXd& y, const Eigen::VectorXd& x, double s) const {
    for (std::size_t ci = 0; ci < m_.constraints.size(); ++ci) {
      const ConstraintModel& c = m_.constraints[ci];
      const std::vector<int>& cols = d_.constants.constraint_cols[ci];
      for (int r = c.row; r < c.row + c.nrows; ++r) {
        const double xr = s * x[r];
        if (xr == 0) continue;
        for (const int a : cols) y[a] += d_.Jc(r, a) * xr;
      }
    }
  }

  // Jc x, row by row over the columns each constraint touches
  Eigen::VectorXd jc_times(const Eigen::VectorXd& x) const {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(m_.nc);
    for (std::size_t ci = 0; ci < m_.constraints.size(); ++ci) {
      const ConstraintModel& c = m_.constraints[ci];
      const std::vector<int>& cols = d_.constants.constraint_cols[ci];
      for (int r = c.row; r < c.row + c.nrows; ++r) {
        double s = 0;
        for (const int a : cols) s += d_.Jc(r, a) * x[a];
        y[r] = s;
      }
    }
    return y;
  }

  // the effect states in z (its head) where applied_forces and the sensors read them
  void set_effect_states(const Eigen::VectorXd& z) {
    if (m_.ns == 0) return;
    d_.s = z.head(m_.ns);
    sys_.set_effect_states(d_.s);
  }
  // the first-order states' rates at (t, q, v, z): the effect states' (applied_forces), the
  // controller's (its state equation at the inputs there)
  Eigen::VectorXd first_order_rates(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& z) {
    Eigen::VectorXd g(nz_);
    if (nz_ == 0) return g;
    set_effect_states(z);
    const Eigen::VectorXd u = sys_.inputs(t, q, v, z.tail(nxc_));
    forward_kinematics<double>(m_, d_, q, v);
    applied_forces<double>(m_, d_, q, v, u);
    g.head(m_.ns) = d_.sdot;
    if (nxc_) g.tail(nxc_) = sys_.controller_rates(t, q, v, z.tail(nxc_), u);
    return g;
  }
  // dg/dz at (t, q, v, z) by central differences (nz small: a tire's two deflections, a
  // controller's states), kept for kTangentAge steps as the positions' tangent is; the block's
  // matrix I - h/2 dg/dz is factored again at the next step
  void form_z_jacobian(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& z) {
    Gz_.resize(nz_, nz_);
    Eigen::VectorXd zp = z;
    for (int j = 0; j < nz_; ++j) {
      const double dz = 1e-6 * std::max(1.0, std::abs(z[j]));
      zp[j] = z[j] + dz;
      const Eigen::VectorXd gp = first_order_rates(t, q, v, zp);
      zp[j] = z[j] - dz;
      Gz_.col(j) = (gp - first_order_rates(t, q, v, zp)) / (2 * dz);
      zp[j] = z[j];
    }
    set_effect_states(z);  // (the iterate's again, for what follows in this iteration)
    z_jacobian_ok_ = Gz_.allFinite();
    if (!z_jacobian_ok_) Gz_.setZero();
    z_jacobian_age_ = 0;
    h_z_ = 0;  // (factored again)
  }

  // the motion inputs at t: their coordinates in q (their values), their rates and accelerations
  // kept for the step (driven_rate_, driven_acc_); nothing without motions
  void drive(double t, Eigen::VectorXd& q) {
    if (driven_v_.empty()) return;
    Eigen::VectorXd v = v_;
    sys_.apply_motions(t, q, v, &driven_acc_);
    driven_value_.resize(static_cast<Eigen::Index>(driven_q_.size()));
    driven_rate_.resize(static_cast<Eigen::Index>(driven_v_.size()));
    for (std::size_t k = 0; k < driven_v_.size(); ++k) {
      driven_value_[static_cast<Eigen::Index>(k)] = q[driven_q_[k]];
      driven_rate_[static_cast<Eigen::Index>(k)] = v[driven_v_[k]];
    }
  }
  // the state's motion coordinates and rates at t, and their accelerations in d_ (for
  // forward_dynamics)
  void drive_state(double t) {
    if (driven_v_.empty()) return;
    Eigen::VectorXd acc;
    sys_.apply_motions(t, q_, v_, &acc);
    d_.motion_acc = acc;
  }
  void hold_driven(Eigen::VectorXd& q) const {
    for (std::size_t k = 0; k < driven_q_.size(); ++k) q[driven_q_[k]] = driven_value_[static_cast<Eigen::Index>(k)];
  }
  // a motion's row of a Newton or projection matrix: its own coordinate alone (the unknown is
  // known: its signal)
  void hold_rows(Eigen::MatrixXd& K) const {
    for (const int i : driven_v_) {
      K.row(i).setZero();
      K(i, i) = 1;
    }
  }
  // the size of each coordinate, for the error weights atol + rtol |q|, in the velocities' places:
  // |q_i| for additive coordinates; a ball's or free joint's rotation angle for its three rates,
  // a free joint's position components for its linear rates
  Eigen::ArrayXd magnitude(const Eigen::VectorXd& q) const {
    if (additive_) return q.array().abs();
    Eigen::ArrayXd r(m_.nv);
    for (int b = 1; b < m_.nbodies; ++b) {
      const JointModel& j = m_.joints[static_cast<std::size_t>(b)];
      const int iq = j.idx_q, iv = j.idx_v;
      switch (j.type) {
        case JointType::Spherical:
          r.segment<3>(iv).setConstant(rotation_log(q.segment<4>(iq)).norm());
          break;
        case JointType::Free:
          r.segment<3>(iv).setConstant(rotation_log(q.segment<4>(iq + 3)).norm());
          r.segment<3>(iv + 3) = q.segment<3>(iq).array().abs();
          break;
        default:
          for (int k = 0; k < j.nv; ++k) r[iv + k] = std::abs(q[iq + k]);
      }
    }
    return r;
  }

  static double left_loose(const Eigen::VectorXd& dq, const Eigen::ArrayXd& wl) { return (dq.array().abs() / wl).maxCoeff(); }

  static constexpr double kStall = 0.8, kBoost = 10, kStallTolerance = 0.1;
  static constexpr int kHalvings = 4;
  static constexpr double kNewton = 1e-3, kNewtonFloor = 1e-14, kLeftLimit = 1e-9;
  // the last step's contraction rate stands for the first correction's below this
  static constexpr double kTrustTheta = 0.01;
  // at fixed steps Newton's rtol and atol are at most this (the step, not Newton, sets the error)
  static constexpr double kFixedNewton = 1e-6;
  // the modified Newton: the tangent is kept over steps while Newton's corrections shrink by
  // kRate at least per iteration, for kTangentAge steps at most; the matrix is factored each step
  static constexpr double kRate = 0.5;
  static constexpr int kTangentAge = 20, kTangentFailures = 3;
  // the penalty: the error control's rule up to kRuleMax; a stall's raise up to kPenaltyMax
  static constexpr double kPenaltyStep = 1e-2, kPenaltyMax = 1e13, kRuleMax = 1e20;
  ClosedLoopSystem& sys_;
  const Model& m_;
  Data d_;
  // additive coordinates (no ball or free joint): q itself is the trapezoidal rule's unknown;
  // otherwise the step in the tangent space, q = q_n (+) dl
  const bool additive_ = m_.nq == m_.nv;
  // the motion inputs' coordinates (q and v places), and at the step's end their values, rates
  // and accelerations (from their signals)
  std::vector<int> driven_q_, driven_v_;
  Eigen::VectorXd driven_value_, driven_rate_, driven_acc_;
  // the first-order states z = [s; xc] (the effect states, the controller's), at the step's start
  // and end, their rates g there (the end's implied by the rule), the rates' slope over the last
  // step (zslope_ok_: there was one) and its length; dg/dz and the block's factored matrix
  const int nxc_ = sys_.nxc(), nz_ = m_.ns + nxc_;
  Eigen::VectorXd z_, zn_, g_, gn_, gz_, zslope_;
  bool zslope_ok_ = false, z_jacobian_ok_ = false;
  double h_last_ = 0, h_z_ = 0;
  int z_jacobian_age_ = 0;
  Eigen::MatrixXd Gz_;
  Eigen::PartialPivLU<Eigen::MatrixXd> luz_;
  double h_, alpha_given_, alpha_now_ = 0;
  int iterations_;
  double rtol_, atol_;
  bool fixed_, extrapolate_, trace_;  // trace_: ALF_TRACE set, each Newton iteration printed
  bool projected_ = false;  // the last step() projected v and a (Mp_ is M at its end)
  double next_ = 0, last_failure_ = 0, h_now_ = 0, t_ = 0;
  Eigen::VectorXd q_, v_, a_, lambda_, qn_, vn_, an_, lambdan_, f_, u_;
  Eigen::VectorXd jerk_rate_;  // (a_n - a_n-1) / h_n-1 of the last accepted step (jerk_: valid)
  bool jerk_ = false;
  double theta_step_ = 0;  // Newton's contraction rate in the last step that measured it (0: none)
  double h_theta_ = 0;     // that step's length (the rate stands for another step's of this length only)
  // a fixed step's substeps' starts (one, or more where Newton made it halve the step), for show()
  std::vector<Knot> knot_;
  struct Start {  // the extrapolated step's start, as it was
    Knot at;
    Eigen::VectorXd lambda, jerk, zslope;
    bool jerk_ok = false, zslope_ok = false, stalled = false;
    double h_last = 0;
  } start_;
  Eigen::VectorXd x1q_, x1v_, x1a_, x1l_, x1z_, x1g_;  // (the extrapolation's long step's end)
  double theta_other_ = 0, h_theta_other_ = 0;         // (Newton's rate at the other step length)
  bool stability_checked_ = false;
  int since_check_ = 0;  // (extrapolated steps since the last check of the fastest mode)
  static constexpr int kCheckSteps = 20;
  static constexpr double kStableZ = 2;  // the extrapolation's limit on h |lambda| (1.077 a step at 3 on the imaginary axis)
  long disagreements_ = 0;  // (extrapolated steps whose two ends disagreed: halved)
  long pair_steps_ = 0;     // (steps_ before an error-controlled extrapolated step, for its rejection)
  static constexpr double kDisagree = 0.1;
  int knots_ = 0;
  Eigen::VectorXd shown_y_;
  bool shown_ = false;  // state() is shown_y_, interpolated inside the last step
  Eigen::MatrixXd K_, Mt_, Ct_, Kt_;  // the Newton matrix; the tangent's parts
  Eigen::MatrixXd Kp_, Mp_;           // the projections' matrix, and M, at the step's end
  FactoredMatrix lup_;  // the projections' matrix
  std::unique_ptr<TreeDerivatives> td_;
  Eigen::VectorXd zero_multipliers_;
  bool use_tangent_ = true, have_tangent_ = false, tangent_stale_ = true;
  int tangent_age_ = 0;
  bool factored_ = false, fresh_mass_ = false, scan_newton_ = true;
  bool start_mass_ = false;  // Mp_ is M at the step's start, not yet used by its first factorization
  double h_factored_ = 0;
  bool stalled_ = false, stalled_before_ = false;
  long boosts_ = 0, stalls_ = 0, tangents_ = 0, tangent_failures_ = 0, input_restarts_ = 0, halvings_ = 0;
  FactoredMatrix lu_;  // the Newton matrix
  long steps_ = 0, evaluations_ = 0, factorizations_ = 0, iterations_done_ = 0, failures_ = 0, rejected_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_alf_integrator(ClosedLoopSystem& system, const IntegratorSettings& settings) {
  return std::make_unique<Alf>(system, settings);
}

}  // namespace codyna
