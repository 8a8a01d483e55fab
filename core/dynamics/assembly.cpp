#include "dynamics/assembly.hpp"

#include <Eigen/QR>
#include <algorithm>

#include "dynamics/constraints.hpp"
#include "dynamics/joint.hpp"

namespace codyna {

namespace {
// minimum-norm least-squares solve that treats nearly dependent rows as dependent:
// off the manifold a redundant constraint row is only almost dependent, and a
// plain solve would divide by its tiny singular value
Eigen::VectorXd min_norm_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& b) {
  // nothing to move (every joint fixed or driven) or nothing to meet: Eigen's decompositions are not
  // defined on an empty matrix (ColPivHouseholderQR read out of bounds on 3 x 0)
  if (J.cols() == 0 || J.rows() == 0) return Eigen::VectorXd::Zero(J.cols());
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(1e-9);
  cod.compute(J);
  return cod.solve(b);
}
}  // namespace

AssemblyResult assemble(const Model& model, const Eigen::VectorXd& q_guess, const Eigen::VectorXd& v_guess,
                        const AssemblyOptions& opt) {
  AssemblyResult r;
  r.q = q_guess;
  r.v = v_guess;
  normalize(model, r.q);
  if (model.nc == 0) {
    r.converged = true;
    return r;
  }
  Data d(model);
  const Eigen::VectorXd zero_v = Eigen::VectorXd::Zero(model.nv);
  // a motion input's coordinate is where its motion puts it, and so is its rate: the loops close
  // on the other coordinates
  std::vector<int> locked_q = opt.locked_positions, locked_v = opt.locked_velocities;
  for (int k : model.motions) {
    locked_q.push_back(model.actuators[static_cast<std::size_t>(k)].iv);
    locked_v.push_back(model.actuators[static_cast<std::size_t>(k)].iv);
  }
  auto residual = [&](const Eigen::VectorXd& q) { return Eigen::VectorXd(constraint_residual<double>(model, d, q)); };
  Eigen::VectorXd phi = residual(r.q);
  for (r.iterations = 0; r.iterations < opt.max_iterations; ++r.iterations) {
    if (phi.lpNorm<Eigen::Infinity>() <= opt.tolerance) break;
    constraint_terms<double>(model, d, r.q, zero_v);
    Eigen::MatrixXd J = d.Jc;
    for (int k : locked_q) J.col(k).setZero();  // a zero column gets a zero step (minimum norm)
    for (int r : model.velocity_rows) J.row(r).setZero();  // no condition on q (phi is 0 there)
    const Eigen::VectorXd step = -min_norm_solve(J, phi);
    double t = 1.0;
    bool improved = false;
    for (int k = 0; k < 30; ++k, t *= 0.5) {
      Eigen::VectorXd qn = integrate<double>(model, r.q, Eigen::VectorXd(t * step));
      normalize(model, qn);
      const Eigen::VectorXd pn = residual(qn);
      if (pn.norm() < phi.norm()) {
        r.q = qn;
        phi = pn;
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  phi = residual(r.q);
  r.position_residual = phi.size() ? phi.lpNorm<Eigen::Infinity>() : 0.0;
  if (phi.size()) phi.cwiseAbs().maxCoeff(&r.worst_row);
  constraint_terms<double>(model, d, r.q, zero_v);
  const Eigen::MatrixXd J = d.Jc;
  Eigen::MatrixXd J_free = J;
  for (int k : locked_v) J_free.col(k).setZero();
  r.v = r.v - min_norm_solve(J_free, J * r.v);
  r.velocity_residual = (J * r.v).lpNorm<Eigen::Infinity>();
  r.converged = r.position_residual <= std::max(opt.tolerance, 1e-10) && r.velocity_residual <= 1e-8 * (1.0 + r.v.norm());
  return r;
}

RowPartition partition_rows(const Eigen::MatrixXd& Jc, double relative_tolerance, int fixed_rank) {
  RowPartition p;
  if (Jc.rows() == 0) return p;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Jc.transpose());
  qr.setThreshold(relative_tolerance);
  const Eigen::Index rank = fixed_rank >= 0 ? fixed_rank : qr.rank();
  const auto& perm = qr.colsPermutation().indices();
  for (Eigen::Index k = 0; k < perm.size(); ++k) (k < rank ? p.independent : p.redundant).push_back(perm[k]);
  std::sort(p.independent.begin(), p.independent.end());
  std::sort(p.redundant.begin(), p.redundant.end());
  return p;
}

std::vector<int> rows_adding_rank(const Eigen::MatrixXd& Jc, const std::vector<int>& held,
                                  const std::vector<int>& candidates, int max) {
  std::vector<int> kept = held, out;
  for (int r : candidates) {
    if (max >= 0 && static_cast<int>(out.size()) == max) break;
    Eigen::MatrixXd J(static_cast<Eigen::Index>(kept.size()) + 1, Jc.cols());
    for (std::size_t k = 0; k < kept.size(); ++k) J.row(static_cast<Eigen::Index>(k)) = Jc.row(kept[k]);
    J.row(J.rows() - 1) = Jc.row(r);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J.transpose());
    qr.setThreshold(1e-9);
    if (qr.rank() == J.rows()) {
      kept.push_back(r);
      out.push_back(r);
    }
  }
  return out;
}

}  // namespace codyna
