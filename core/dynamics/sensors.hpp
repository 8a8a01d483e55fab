// Sensor outputs: one scalar per sensor (see SensorType). Needs
// forward_kinematics(q, v) on data. sensor_outputs evaluates only the sensors
// listed in `which` (indices into Model::sensors), so outputs nobody asked
// for are never computed.
#pragma once

#include <vector>

#include "model/data.hpp"

namespace codyna {

template <class S>
S sensor_value(const Model& model, const DataT<S>& data, const SensorModel& sensor, const VecXT<S>& q,
               const VecXT<S>& v);

template <class S>
VecXT<S> sensor_outputs(const Model& model, const DataT<S>& data, const std::vector<int>& which, const VecXT<S>& q,
                        const VecXT<S>& v);

}  // namespace codyna
