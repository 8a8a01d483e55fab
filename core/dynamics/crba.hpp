// Composite-rigid-body algorithm: the joint-space mass matrix M(q)
// (= B^T M B of the velocity transformation method), symmetric, full.
// Writes liMi, oMi, Sb, Ic, Sw, M; returns data.M. O(n d) for tree depth d.
// M is allocated by the first call on a Data; later calls do not allocate.
#pragma once

#include "model/data.hpp"

namespace codyna {

template <class S>
const MatXT<S>& crba(const Model& model, DataT<S>& data, const VecXT<S>& q);

// the same, reusing the positions (liMi, oMi, Sb) that forward_kinematics(q)
// already wrote into data
template <class S>
const MatXT<S>& crba_after_kinematics(const Model& model, DataT<S>& data);

}  // namespace codyna
