#include "analysis/discretize.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

namespace codyna {

LinearSystem discretize_zoh(const LinearSystem& c, double Ts) {
  if (!(Ts > 0.0) || !std::isfinite(Ts))
    throw std::invalid_argument("discretize_zoh: sample time must be positive and finite, got " +
                                std::to_string(Ts));
  if (c.Ts > 0.0)
    throw std::invalid_argument("discretize_zoh: the system is already discrete (Ts = " +
                                std::to_string(c.Ts) + ")");
  const Eigen::Index nx = c.A.rows(), nu = c.B.cols();
  if (c.A.cols() != nx || c.B.rows() != nx)
    throw std::invalid_argument("discretize_zoh: A must be square and B must have as many rows as A");

  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(nx + nu, nx + nu);
  M.topLeftCorner(nx, nx) = c.A * Ts;
  M.topRightCorner(nx, nu) = c.B * Ts;
  const Eigen::MatrixXd E = M.size() == 0 ? M : Eigen::MatrixXd(M.exp());  // Eigen's exp asserts on 0x0

  LinearSystem d = c;
  d.A = E.topLeftCorner(nx, nx);
  d.B = E.topRightCorner(nx, nu);
  d.Ts = Ts;
  return d;
}

}  // namespace codyna
