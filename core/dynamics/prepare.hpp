// compile(spec) -> Model, ready for the algorithms: compile_structure (model/compile.hpp:
// validation, the joint tree, indices, names) followed by prepare_model, what compiling needs of
// the dynamics: the body_angle sensors' reference orientation, the joints' q0/v0 assembled onto
// the loop-closure constraints (Model::assembly_moves says what moved), the redundant constraint
// rows, and the check that the mass matrix is positive definite at the initial state.
// Any problem throws ModelError naming the model's file and the field.
#pragma once

#include <string>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

void prepare_model(Model& model);

Model compile(const ModelSpec& spec, const std::string& file = "");

}  // namespace codyna
