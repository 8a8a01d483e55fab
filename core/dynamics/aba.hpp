// Articulated-body algorithm (Featherstone): forward dynamics of the tree,
//   qdd = M(q)^-1 (tau - C(q, v) v - g(q)),  O(n).
// tau are generalized forces (use effects.hpp to assemble them).
// Writes liMi, oMi, Sb, v, cJ, IA, pA, U, Dinv, u, a, qdd; returns data.qdd.
#pragma once

#include "model/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& aba(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& tau);

// the same, reusing the kinematics (liMi, oMi, Sb, v, cJ) that
// forward_kinematics(q, v) already wrote into data
template <class S>
const VecXT<S>& aba_after_kinematics(const Model& model, DataT<S>& data, const VecXT<S>& v, const VecXT<S>& tau);

}  // namespace codyna
