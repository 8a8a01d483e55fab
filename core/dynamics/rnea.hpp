// Recursive Newton-Euler inverse dynamics (Featherstone, RNEA):
//   tau = M(q) a + C(q, v) v + g(q)
// with gravity only if the model declares it; applied forces (springs,
// actuators, ...) are not included (see effects.hpp). O(n).
// Writes liMi, oMi, Sb, v, cJ, a, f, tau; returns data.tau.
// nonlinear_effects = rnea(q, v, 0), written to data.nle.
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& rnea(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v, const VecXT<S>& a);

template <class S>
const VecXT<S>& nonlinear_effects(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v);

// Maps the external body forces data.fext (body coordinates) to generalized
// forces: returns J^T fext summed over bodies. Needs liMi and Sb.
template <class S>
VecXT<S> body_forces_to_generalized(const Model& model, DataT<S>& data);
// the same, added to Q (size nv) without allocating; uses data.fsum as scratch
template <class S>
void add_body_forces_to_generalized(const Model& model, DataT<S>& data, VecXT<S>& Q);

}  // namespace codyna
