// Articulated-body algorithm (Featherstone): forward dynamics of the tree,
//   qdd = M(q)^-1 (tau - C(q, v) v - g(q)),  O(n).
// tau are generalized forces (use effects.hpp to assemble them).
// Writes liMi, oMi, Sb, v, cJ, IA, Ia, pB, pA, U, Dinv, u, c, a, qdd; returns data.qdd.
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& aba(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& tau);

// the same, reusing the kinematics (liMi, oMi, Sb, v, cJ) that
// forward_kinematics(q, v) already wrote into data
template <class S>
const VecXT<S>& aba_after_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& v, const VecXT<S>& tau);

// the same at the positions of the last aba on this data, after
// velocity_kinematics(q, v): new velocities or forces, the articulated
// inertias (IA, Ia, U, Dinv: they depend on q only) reused. O(n) with a small
// constant; what finite differences in v and u need. double only.
template <class S>
const VecXT<S>& aba_same_positions(const Model& model, DataT<S>& data, const VecXT<S>& v, const VecXT<S>& tau);
// the same at the positions and velocities of the last aba or
// aba_same_positions on this data: new forces tau only (the velocity terms c
// and pB reused). What finite differences in u need. double only.
template <class S>
const VecXT<S>& aba_same_motion(const Model& model, DataT<S>& data, const VecXT<S>& tau, bool reset_bias = true);

}  // namespace codyna
