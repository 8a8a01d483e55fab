#include "analysis/handling.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
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

// null(M) as columns: the right singular vectors of singular values at most `tol` (absolute)
Eigen::MatrixXd null_space(const Eigen::MatrixXd& M, double tol) {
  if (M.rows() == 0 || M.cols() == 0) return Eigen::MatrixXd::Identity(M.cols(), M.cols());
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv[rank] > tol) ++rank;
  return svd.matrixV().rightCols(M.cols() - rank);
}

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

// The same with some inputs free and some outputs held at zero: [A B_h; C_z D_zh] [x; u_h] =
// -[b; d_z], the smallest [x; u_h] (a drive torque that holds the speed: u_h the drive, the held
// output the speed's change)
Eigen::VectorXd held_steady_gain(const LinearSystem& s, int in, const std::vector<int>& outputs, const std::vector<int>& free_in,
                                 const std::vector<int>& held_out) {
  const Eigen::Index n = s.A.rows(), nh = static_cast<Eigen::Index>(free_in.size()), nz = static_cast<Eigen::Index>(held_out.size());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + nz, n + nh);
  Eigen::VectorXd rhs(n + nz);
  M.topLeftCorner(n, n) = s.A;
  rhs.head(n) = -s.B.col(in);
  for (Eigen::Index j = 0; j < nh; ++j) M.block(0, n + j, n, 1) = s.B.col(free_in[static_cast<std::size_t>(j)]);
  for (Eigen::Index i = 0; i < nz; ++i) {
    const int r = held_out[static_cast<std::size_t>(i)];
    M.block(n + i, 0, 1, n) = s.C.row(r);
    for (Eigen::Index j = 0; j < nh; ++j) M(n + i, n + j) = s.D(r, free_in[static_cast<std::size_t>(j)]);
    rhs[n + i] = -s.D(r, in);
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  svd.setThreshold(1e-10);
  const Eigen::VectorXd xu = svd.solve(rhs);
  if ((M * xu - rhs).norm() > 1e-8 * std::max(rhs.norm(), 1e-300))
    throw std::invalid_argument("the steer input has no steady state with the speed held (the free inputs cannot hold it)");
  const Eigen::Index rank = svd.rank();
  const Eigen::MatrixXd N = svd.matrixV().rightCols(M.cols() - rank);
  Eigen::VectorXd y(static_cast<Eigen::Index>(outputs.size()));
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    Eigen::RowVectorXd row(n + nh);
    row.head(n) = s.C.row(outputs[k]);
    for (Eigen::Index j = 0; j < nh; ++j) row[n + j] = s.D(outputs[k], free_in[static_cast<std::size_t>(j)]);
    if (N.cols() > 0 && (row * N).cwiseAbs().maxCoeff() > 1e-8 * std::max(row.cwiseAbs().maxCoeff(), 1e-300))
      throw std::invalid_argument("the steady-state value of output \"" + s.output_names[static_cast<std::size_t>(outputs[k])] +
                                  "\" is not defined: it depends on a state that stays where it is put (a neutral mode)");
    y[static_cast<Eigen::Index>(k)] = row.dot(xu) + s.D(outputs[k], in);
  }
  return y;
}

// The part of the state a steady motion may leave drifting: the largest subspace S of positions
// (no velocity part) that the outputs `rows` do not read (C S = 0) and that the dynamics keep (A S
// inside S): the road position, the heading, the wheels' spin angles, in whatever combination of
// coordinates the chart gives them (a pitched chassis' forward position is its body x and z
// together; its heading about the road's normal, its own z and x). Found as the unobservable
// subspace of (A, [C_rows; the velocities]): S0 = ker, S_k+1 = {z in S_k : A z in S_k}.
// Returns an orthonormal basis of S's orthogonal complement: the states that matter.
Eigen::MatrixXd kept_directions(const LinearSystem& s, const std::vector<int>& rows) {
  const Eigen::Index n = s.A.rows(), np = std::min<Eigen::Index>(s.npositions(), n);
  const double ascale = std::max(s.A.size() ? s.A.norm() : 0.0, 1e-300);
  const double cscale = std::max(s.C.size() ? s.C.norm() : 0.0, 1e-300);
  Eigen::MatrixXd H(static_cast<Eigen::Index>(rows.size()) + (n - np), n);
  H.setZero();
  for (std::size_t k = 0; k < rows.size(); ++k) H.row(static_cast<Eigen::Index>(k)) = s.C.row(rows[k]) / cscale;
  for (Eigen::Index i = 0; i < n - np; ++i) H(static_cast<Eigen::Index>(rows.size()) + i, np + i) = 1.0;
  Eigen::MatrixXd S = null_space(H, 1e-12);
  for (Eigen::Index dim = -1; S.cols() > 0 && S.cols() != dim;) {
    dim = S.cols();
    const Eigen::MatrixXd AS = s.A * S / ascale;
    const Eigen::MatrixXd out = AS - S * (S.transpose() * AS);  // A S's part outside S
    S = S * null_space(out, 1e-10);
  }
  // the complement
  if (S.cols() == 0) return Eigen::MatrixXd::Identity(n, n);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(S);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  return Q.rightCols(n - S.cols());
}

// the system on the directions T (orthonormal columns): x = T z
LinearSystem on_directions(const LinearSystem& s, const Eigen::MatrixXd& T) {
  LinearSystem r;
  r.A = T.transpose() * s.A * T;
  r.B = T.transpose() * s.B;
  r.C = s.C * T;
  r.D = s.D;
  r.output_names = s.output_names;
  return r;
}

}  // namespace

HandlingNumbers handling_numbers(const LinearSystem& sys, int steer, int yaw_rate, int lateral_acceleration, int sideslip,
                                 double speed, double wheelbase, double steering_ratio, const SpeedHold* hold) {
  if (steer < 0 || steer >= sys.B.cols()) throw std::invalid_argument("handling: no steer input among Plant/In");
  if (yaw_rate < 0 || yaw_rate >= sys.C.rows()) throw std::invalid_argument("handling: no yaw-rate output among Plant/Out");
  if (!(speed > 0)) throw std::invalid_argument("handling: the forward speed must be > 0 (it is " + std::to_string(speed) + " m/s)");
  if (!(wheelbase > 0)) throw std::invalid_argument("handling: the wheelbase must be > 0 (it is " + std::to_string(wheelbase) + " m)");
  HandlingNumbers h;
  h.speed = speed;
  h.wheelbase = wheelbase;
  if (!(std::abs(steering_ratio) > 0) || !std::isfinite(steering_ratio))
    throw std::invalid_argument("handling: the steering ratio must be a number other than 0");
  h.steering_ratio = steering_ratio;
  std::vector<int> outs{yaw_rate};
  if (lateral_acceleration >= 0) outs.push_back(lateral_acceleration);
  if (sideslip >= 0) outs.push_back(sideslip);
  // less what may drift unseen (the road position, the heading, the spin angles)
  Eigen::VectorXd g;
  if (hold && hold->B.cols() > 0) {
    // the speed held by the free inputs: the system with their columns and the speed's row
    const Eigen::Index n = sys.A.rows(), nu = sys.B.cols(), nh = hold->B.cols(), ny = sys.C.rows();
    if (hold->B.rows() != n || hold->D.rows() != ny || hold->D.cols() != nh || hold->speed.size() != n)
      throw std::invalid_argument("handling: the speed hold's matrices do not fit the plant");
    LinearSystem aug = sys;
    aug.B.resize(n, nu + nh);
    aug.B << sys.B, hold->B;
    aug.C.resize(ny + 1, n);
    aug.C << sys.C, hold->speed;
    aug.D = Eigen::MatrixXd::Zero(ny + 1, nu + nh);
    aug.D.topLeftCorner(ny, nu) = sys.D;
    aug.D.topRightCorner(ny, nh) = hold->D;
    aug.output_names.push_back("speed");
    std::vector<int> seen = outs, free_in;
    seen.push_back(static_cast<int>(ny));
    for (Eigen::Index j = 0; j < nh; ++j) free_in.push_back(static_cast<int>(nu + j));
    const LinearSystem red = on_directions(aug, kept_directions(aug, seen));
    g = held_steady_gain(red, steer, outs, free_in, {static_cast<int>(ny)});
    h.speed_held = true;
  } else {
    g = steady_gain(on_directions(sys, kept_directions(sys, outs)), steer, outs);
  }
  const LinearSystem red = on_directions(sys, kept_directions(sys, outs));
  h.yaw_rate_gain = g[0];
  h.lateral_acceleration_output = lateral_acceleration >= 0;
  h.lateral_acceleration_gain = lateral_acceleration >= 0 ? g[1] : speed * g[0];
  h.sideslip_given = sideslip >= 0;
  if (sideslip >= 0) h.sideslip_gain = g[static_cast<Eigen::Index>(outs.size()) - 1];
  if (!(std::abs(h.lateral_acceleration_gain) > 0))
    throw std::invalid_argument("handling: the steer does not reach the lateral acceleration (its gain is 0)");
  h.understeer_gradient = 1.0 / (steering_ratio * h.lateral_acceleration_gain) - wheelbase / (speed * speed);
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
