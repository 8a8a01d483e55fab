// Generalized applied forces Q(q, v, u) from the force elements a model
// declares (springs, dampers, friction, constant body forces) and from its
// actuators; gravity is not here (rnea/aba treat it as a base acceleration).
// Only the lists the model holds are visited: a model without springs never
// evaluates a spring. u holds one value per actuator (Model::actuators).
// Needs forward_kinematics(q, v) on data; writes fext, Q; returns data.Q.
#pragma once

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& applied_forces(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v,
                               const VecXT<S>& u);

// Counts of effect evaluations since start (test hook proving absent effects cost nothing).
struct EffectCounters {
  long springs = 0, joint_springs = 0, joint_frictions = 0, body_forces = 0, actuators = 0, tires = 0;
};
EffectCounters& effect_counters();

}  // namespace codyna
