#include "analysis/handling.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <vector>

namespace codyna {

namespace {

constexpr double kStandardGravity = 9.80665;  // m/s^2 per g
constexpr double kPi = 3.14159265358979323846;

// the steady-state response of the outputs to a unit step of input `in`: A x + B e = 0 solved
// with the smallest x; refused when no x solves it or when the outputs depend on which one does
Eigen::VectorXd steady_gain(const LinearSystem& s, int in, const std::vector<int>& outputs) {
  const Eigen::Index n = s.A.rows();
  const Eigen::VectorXd b = s.B.col(in);
  Eigen::VectorXd y(static_cast<Eigen::Index>(outputs.size()));
  if (n == 0) {
    for (std::size_t k = 0; k < outputs.size(); ++k) y[static_cast<Eigen::Index>(k)] = s.D(outputs[k], in);
    return y;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double tol = 1e-10 * std::max(sv[0], 1e-300);
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv[rank] > tol) ++rank;
  const Eigen::MatrixXd U = svd.matrixU(), V = svd.matrixV();
  const Eigen::VectorXd c = U.leftCols(rank).transpose() * b;
  const Eigen::VectorXd x = -V.leftCols(rank) * c.cwiseQuotient(sv.head(rank));
  const double scale = std::max(b.norm(), 1e-300);
  if ((s.A * x + b).norm() > 1e-8 * scale)
    throw std::invalid_argument("the steer input has no steady state: a constant steer keeps some states moving (A x + B u = 0 has no solution)");
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const Eigen::RowVectorXd crow = s.C.row(outputs[k]);
    const double on_null = rank < n ? (crow * V.rightCols(n - rank)).cwiseAbs().maxCoeff() : 0.0;
    if (on_null > 1e-8 * std::max(crow.cwiseAbs().maxCoeff(), 1e-300))
      throw std::invalid_argument("the steady-state value of output \"" + s.output_names[static_cast<std::size_t>(outputs[k])] +
                                  "\" is not defined: it depends on a state that stays where it is put (a neutral mode)");
    y[static_cast<Eigen::Index>(k)] = crow * x + s.D(outputs[k], in);
  }
  return y;
}

// The states that do not reach the outputs `rows` of C: the largest set S with A[not S, S] = 0 and
// C[rows, S] = 0 (the position on the road, the heading, a coasting speed: what advances freely
// without changing the response). The others, in order.
std::vector<int> reaching_states(const LinearSystem& s, const std::vector<int>& rows) {
  const Eigen::Index n = s.A.rows();
  const double scale = std::max(s.A.size() ? s.A.cwiseAbs().maxCoeff() : 0.0, 1e-300);
  const double cscale = std::max(s.C.size() ? s.C.cwiseAbs().maxCoeff() : 0.0, 1e-300);
  std::vector<bool> in_s(static_cast<std::size_t>(n), true);
  for (bool changed = true; changed;) {
    changed = false;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!in_s[static_cast<std::size_t>(j)]) continue;
      bool reaches = false;
      for (int r : rows) reaches |= std::abs(s.C(r, j)) > 1e-13 * cscale;
      for (Eigen::Index i = 0; i < n && !reaches; ++i)
        reaches = !in_s[static_cast<std::size_t>(i)] && std::abs(s.A(i, j)) > 1e-13 * scale;
      if (reaches) {
        in_s[static_cast<std::size_t>(j)] = false;
        changed = true;
      }
    }
  }
  std::vector<int> keep;
  for (Eigen::Index j = 0; j < n; ++j)
    if (!in_s[static_cast<std::size_t>(j)]) keep.push_back(static_cast<int>(j));
  return keep;
}

LinearSystem kept_states(const LinearSystem& s, const std::vector<int>& keep) {
  LinearSystem r;
  const Eigen::Index m = static_cast<Eigen::Index>(keep.size());
  r.A.resize(m, m);
  r.B.resize(m, s.B.cols());
  r.C.resize(s.C.rows(), m);
  r.D = s.D;
  for (Eigen::Index i = 0; i < m; ++i) {
    r.B.row(i) = s.B.row(keep[static_cast<std::size_t>(i)]);
    r.C.col(i) = s.C.col(keep[static_cast<std::size_t>(i)]);
    for (Eigen::Index j = 0; j < m; ++j) r.A(i, j) = s.A(keep[static_cast<std::size_t>(i)], keep[static_cast<std::size_t>(j)]);
  }
  r.output_names = s.output_names;
  return r;
}

}  // namespace

HandlingNumbers handling_numbers(const LinearSystem& sys, int steer, int yaw_rate, int lateral_acceleration, int sideslip,
                                 double speed, double wheelbase) {
  if (steer < 0 || steer >= sys.B.cols()) throw std::invalid_argument("handling: no steer input among Plant/In");
  if (yaw_rate < 0 || yaw_rate >= sys.C.rows()) throw std::invalid_argument("handling: no yaw-rate output among Plant/Out");
  if (!(speed > 0)) throw std::invalid_argument("handling: the forward speed must be > 0 (it is " + std::to_string(speed) + " m/s)");
  if (!(wheelbase > 0)) throw std::invalid_argument("handling: the wheelbase must be > 0 (it is " + std::to_string(wheelbase) + " m)");
  HandlingNumbers h;
  h.speed = speed;
  h.wheelbase = wheelbase;
  std::vector<int> outs{yaw_rate};
  if (lateral_acceleration >= 0) outs.push_back(lateral_acceleration);
  if (sideslip >= 0) outs.push_back(sideslip);
  // the states that reach these outputs (the road position and heading do not, in body axes)
  const LinearSystem red = kept_states(sys, reaching_states(sys, outs));
  const Eigen::VectorXd g = steady_gain(red, steer, outs);
  h.yaw_rate_gain = g[0];
  h.lateral_acceleration_output = lateral_acceleration >= 0;
  h.lateral_acceleration_gain = lateral_acceleration >= 0 ? g[1] : speed * g[0];
  h.sideslip_given = sideslip >= 0;
  if (sideslip >= 0) h.sideslip_gain = g[static_cast<Eigen::Index>(outs.size()) - 1];
  if (!(std::abs(h.lateral_acceleration_gain) > 0))
    throw std::invalid_argument("handling: the steer does not reach the lateral acceleration (its gain is 0)");
  h.understeer_gradient = 1.0 / h.lateral_acceleration_gain - wheelbase / (speed * speed);
  h.understeer_gradient_deg_per_g = h.understeer_gradient * 180.0 / kPi * kStandardGravity;
  if (h.understeer_gradient > 0) h.characteristic_speed = std::sqrt(wheelbase / h.understeer_gradient);
  if (h.understeer_gradient < 0) h.critical_speed = std::sqrt(-wheelbase / h.understeer_gradient);
  // the yaw mode: the poles that carry most of the yaw-rate response to steer
  const Eigen::Index n = red.A.rows();
  if (n > 0) {
    const Eigen::EigenSolver<Eigen::MatrixXd> es(red.A);
    const Eigen::MatrixXcd Vm = es.eigenvectors();
    const Eigen::VectorXcd lam = es.eigenvalues();
    const Eigen::FullPivLU<Eigen::MatrixXcd> lu(Vm);
    if (lu.isInvertible()) {
      const Eigen::VectorXcd bm = lu.solve(red.B.col(steer).cast<std::complex<double>>());
      const Eigen::RowVectorXcd cm = red.C.row(yaw_rate).cast<std::complex<double>>() * Vm;
      const double lam_scale = std::max(lam.cwiseAbs().maxCoeff(), 1e-300);
      std::vector<std::pair<double, Eigen::Index>> share;
      for (Eigen::Index i = 0; i < n; ++i)
        if (std::abs(lam[i]) > 1e-9 * lam_scale) share.emplace_back(std::abs(cm[i] * bm[i] / lam[i]), i);
      std::sort(share.begin(), share.end(), [](auto a, auto b) { return a.first > b.first; });
      if (!share.empty()) {
        const std::complex<double> p1 = lam[share[0].second];
        std::complex<double> p2 = std::conj(p1);
        if (std::abs(p1.imag()) <= 1e-12 * std::abs(p1)) {
          p2 = p1;
          for (std::size_t k = 1; k < share.size(); ++k)
            if (std::abs(lam[share[k].second].imag()) <= 1e-12 * std::abs(lam[share[k].second])) {
              p2 = lam[share[k].second];
              break;
            }
          if (p2 == p1 && share.size() < 2) p2 = p1;
        }
        const double prod = (p1 * p2).real();
        if (prod > 0) {
          h.yaw_natural_frequency = std::sqrt(prod);
          h.yaw_damping_ratio = -(p1 + p2).real() / (2 * h.yaw_natural_frequency);
        }
      }
    }
  }
  return h;
}

}  // namespace codyna
