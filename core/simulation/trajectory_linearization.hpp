// Linearization along a trajectory: the plant (Plant/In -> Plant/Out)
// linearized about every sample of a simulation result, each about its own
// state and inputs (so xdot0 is not zero), all in one state order (the
// coordinate partition of the first sample, for closed loops).
#pragma once

#include <vector>

#include "analysis/linearize.hpp"
#include "simulation/result.hpp"

namespace codyna {

// every `stride`-th sample of r (r.q, r.v, r.u, r.t); throws std::invalid_argument if the
// state order cannot be kept (a closed loop whose first partition becomes singular)
std::vector<Linearization> linearize_along(const Model& model, const SimulationResult& r, LinearizeOptions options = {},
                                           int stride = 1);

}  // namespace codyna
