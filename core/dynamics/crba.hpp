// Composite-rigid-body algorithm: the joint-space mass matrix M(q)
// (= B^T M B of the velocity transformation method), symmetric, full.
// Writes liMi, oMi, Sb, Iw, Ic, Sw, M; returns data.M. O(n d) for tree depth d.
// M is allocated by the first call on a Data; later calls do not allocate.
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const MatXT<S>& crba(const Model& model, DataT<S>& data, const VecXT<S>& q);

// the same, reusing the positions (liMi, oMi, Sb) that forward_kinematics(q)
// already wrote into data
template <class S>
const MatXT<S>& crba_after_kinematics(const Model& model, DataT<S>& data);

// crba_after_kinematics in its two stages (the split MuJoCo makes between
// mj_comPos and mj_crb): crba_world_terms writes each body's inertia Iw and
// each velocity index's motion axis Sw in the tree-root frame (reads oMi, Sb);
// crba_composite sums them into the composite inertias Ic and fills M from Ic
// and Sw (reads Iw, Sw; may be called again on the same inputs).
template <class S>
void crba_world_terms(const Model& model, DataT<S>& data);
template <class S>
const MatXT<S>& crba_composite(const Model& model, DataT<S>& data);

}  // namespace codyna
