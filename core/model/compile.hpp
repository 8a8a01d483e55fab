// compile(spec) -> Model: validates a ModelSpec, orders the joint tree,
// assigns indices, resolves names, assembles the initial state onto the
// loop-closure constraints and finds redundant constraint rows.
// Any problem throws ModelError naming `file` (may be empty), the JSON path of
// the offending field (e.g. "/joints/2/parent") and what was expected.
#pragma once

#include <string>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

Model compile(const ModelSpec& spec, const std::string& file = "");

}  // namespace codyna
