// Mechanical energy. kinetic = 1/2 sum v_i^T I_i v_i; potential = gravity
// (-m g . c) + point-to-point springs 1/2 k (L - L0)^2 + joint springs
// 1/2 k (q - q_rest)^2. Each runs forward_kinematics itself; the _after_kinematics forms read the
// kinematics already in data (forward_kinematics at q, with v for the kinetic energy): the same
// numbers, for a caller that has just made them (the simulator's samples).
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
S kinetic_energy(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v);
template <class S>
S potential_energy(const Model& model, DataT<S>& data, const VecXT<S>& q);
double kinetic_energy_after_kinematics(const Model& model, const Data& data, const Eigen::VectorXd& v);
double potential_energy_after_kinematics(const Model& model, const Data& data, const Eigen::VectorXd& q);

}  // namespace codyna
