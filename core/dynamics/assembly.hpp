// Assembly: from a user's approximate initial state, find q on the
// constraint manifold phi(q) = 0 closest (least change, in the tangent
// space) to it by damped Gauss-Newton with minimum-norm steps, then project v
// onto the velocity constraint Jc v = 0 (least change). Redundant rows are
// tolerated (minimum-norm steps through a complete orthogonal decomposition).
#pragma once

#include <vector>

#include "dynamics/data.hpp"

namespace codyna {

struct AssemblyOptions {
  double tolerance = 1e-12;    // on max |phi| (and max |Jc v|)
  int max_iterations = 100;
  // coordinates the user set (Adams' locked initial conditions): tangent indices whose
  // position stays exactly as guessed, and velocity indices whose rate does; the others move.
  // The coordinates of motion inputs (Model::motions) are always held, position and rate
  std::vector<int> locked_positions, locked_velocities;
};

struct AssemblyResult {
  Eigen::VectorXd q, v;
  double position_residual = 0.0;  // max |phi(q)|
  double velocity_residual = 0.0;  // max |Jc(q) v|
  int worst_row = -1;              // row with the largest position residual
  int iterations = 0;
  bool converged = false;
};

AssemblyResult assemble(const Model& model, const Eigen::VectorXd& q_guess, const Eigen::VectorXd& v_guess,
                        const AssemblyOptions& options = {});

// Rows of Jc (nc x nv) that are linearly independent (kept) and those that
// depend on them (redundant), by QR with column pivoting of Jc^T. With rank >= 0
// the best `rank` rows are kept whatever the numerical rank: off the constraint
// manifold a redundant row is only nearly dependent, and taking it would make
// the dynamics ill-conditioned, so the dynamics keep the rank found at assembly.
struct RowPartition {
  std::vector<int> independent, redundant;
};
RowPartition partition_rows(const Eigen::MatrixXd& Jc, double relative_tolerance = 1e-9, int rank = -1);

// Of the rows `candidates` of Jc, in their order, those that add to the rank of the rows `held`
// and of the candidates kept before them (column-pivoted QR, relative tolerance 1e-9), at most
// `max` of them (-1: no limit): rolling's no-slip rows beside the holonomic ones
std::vector<int> rows_adding_rank(const Eigen::MatrixXd& Jc, const std::vector<int>& held,
                                  const std::vector<int>& candidates, int max = -1);

}  // namespace codyna
