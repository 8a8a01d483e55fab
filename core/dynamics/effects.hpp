// Generalized applied forces Q(q, v, u) from the force elements a model
// declares (springs, dampers, friction, constant body forces) and from its
// actuators; gravity is not here (rnea/aba treat it as a base acceleration).
// Only the lists the model holds are visited: a model without springs never
// evaluates a spring. u holds one value per actuator (Model::actuators).
// Needs forward_kinematics(q, v) on data; writes fext, Q; returns data.Q.
#pragma once

#include <string>

#include "dynamics/data.hpp"

namespace codyna {

template <class S>
const VecXT<S>& applied_forces(const Model& model, DataT<S>& data, const VecXT<S>& q, const VecXT<S>& v,
                               const VecXT<S>& u);

// Effect states (Model::ns: a tire's transient slip): applied_forces reads their values from
// data.s and writes their rates to data.sdot. effect_states_steady gives the values at which they
// rest at (q, v) (data.sdot = 0 there: a tire's deflections that carry its steady slips; 0 off the
// road); it runs forward_kinematics(q, v) on data. Empty when the model has none.
Eigen::VectorXd effect_states_steady(const Model& model, DataT<double>& data, const Eigen::VectorXd& q,
                                     const Eigen::VectorXd& v);
// The same model without effect states (the tires' relaxation lengths 0): its forces are those
// of the model with its states at rest (a steady motion's, for instance).
Model without_effect_states(const Model& model);

// Counts of effect evaluations since start (test hook proving absent effects cost nothing).
struct EffectCounters {
  long springs = 0, joint_springs = 0, joint_frictions = 0, body_forces = 0, actuators = 0, tires = 0;
};
EffectCounters& effect_counters();

}  // namespace codyna
