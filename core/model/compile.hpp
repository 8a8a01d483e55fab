// compile_structure(spec) -> Model: validates a ModelSpec, orders the joint tree, assigns
// indices, resolves names, and sets the initial state as the joints' q0/v0 write it. It calls
// nothing of the dynamics: dynamics/prepare.hpp's compile() adds what needs the algorithms
// (loops assembled, redundant rows, the mass-matrix check), and study_model (study/workflow.hpp)
// is what front ends call.
// Any problem throws ModelError naming `file` (may be empty), the JSON path of
// the offending field (e.g. "/joints/2/parent") and what was expected.
#pragma once

#include <string>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

Model compile_structure(const ModelSpec& spec, const std::string& file = "");

}  // namespace codyna
