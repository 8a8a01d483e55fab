// model_issues: every problem of a model that does not compile, at once, for an
// editor's Issues list (codyna-gui) and `codyna check`-like front ends. study_model
// stops at its first error; an editor needs them all (a body deleted while three
// elements still name it is three problems, in three fields). So, besides the
// compile's own first error, the spec's cross-references are checked one by one:
// every field that names a body, a joint, an actuator or a sensor that is not there,
// and every body that no joint moves. Each problem is a ModelError (file, field
// path "/joints/2/parent", what was expected), in the model file's order.
//
// A model being built does not compile for a while (three bodies added before any
// joint), yet an editor should show what is there. The draft is the model as far as
// it goes: a body that no joint moves is held where it is drawn (a fixed joint to the
// ground, in a row beside the others), and each element the compile still refuses is
// left out, one at a time, until the rest compiles. It is for drawing, never for a
// study (its plant and analysis sections are empty).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

// the draft of a model that does not compile (see above)
struct ModelDraft {
  std::shared_ptr<const Model> model;   // null when not even the draft compiles
  std::vector<std::string> leaves_out;  // the elements left out ("joint pivot", ...), in that order
  std::vector<std::string> held;        // the bodies no joint moves, held by the draft's fixed joints
};
ModelDraft draft_model(const ModelSpec& spec, const std::string& file = "");

struct ModelCheck {
  std::shared_ptr<const Model> model;  // study_model(spec, file), or null when it does not compile
  std::vector<ModelError> issues;      // empty exactly when the model compiles; in the file's order
  std::size_t first = 0;               // which of them study_model itself reports (its first error)
  ModelDraft draft;                    // when the model does not compile
};

ModelCheck check_model(const ModelSpec& spec, const std::string& file = "");

}  // namespace codyna
