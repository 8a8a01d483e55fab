// Forward dynamics of the whole model: accelerations qdd and loop-closure
// multipliers lambda for state (q, v) and actuator values u (one per actuator):
//   M qdd + nle(q, v) = Q(q, v, u) - Jc^T lambda,   Jc qdd + gamma = -stab
// Trees use ABA (O(n)); closed loops use CRBA + the constraint terms and the
// Schur complement on the rows that are independent at (q) (chosen anew at each
// call: redundancy can move between rows along a motion). Redundant rows get
// lambda = 0. `stab` is an optional Baumgarte term 2 alpha Jc v + beta^2 phi.
// Writes everything the algorithms it calls write; returns data.qdd.
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

struct Baumgarte {
  double alpha = 0.0, beta = 0.0;
};

template <class S>
const VecXT<S>& forward_dynamics(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v,
                                 const VecXT<S>& u, const Baumgarte& stab = {});

// Motion inputs whose rates jump by `jump` (one per Model::motions entry: a ramp starting, a
// table's knot) move the other coordinates impulsively: their velocity change dv_f follows from
// the impulse balance on the free coordinates, M_ff dv_f = -M_fd jump - J_f^T Lambda with
// J_f dv_f = -J_d jump on the loops' independent rows at q (J_d: the driven coordinates' columns).
// Returns dv (nv; jump on the driven coordinates).
Eigen::VectorXd prescribed_velocity_jump(const Model& model, Data& data, const Eigen::VectorXd& q,
                                         const Eigen::VectorXd& jump);

}  // namespace codyna
