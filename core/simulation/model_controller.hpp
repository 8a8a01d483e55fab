// The controller a model file declares (ModelSpec::controller), made into a
// runnable Controller for the plant it was designed on. Sizes are checked
// against that plant here: nu x ny for PID gains, nu x nx for K, and the LTI
// matrices against nu, ny; a mismatch is a ModelError naming the field.
#pragma once

#include <memory>

#include "simulation/controller.hpp"
#include "simulation/simulator.hpp"

namespace codyna {

// true if the model declares a controller
bool has_model_controller(const Model& model);

// linearizes the model at the controller's operating point (for its offsets and state order)
LinearPlant controller_plant(const Model& model);

// nullptr if the model declares none; LQR weights are designed here (continuous LQR)
std::unique_ptr<Controller> make_model_controller(const Model& model, const LinearPlant& plant);

}  // namespace codyna
