// Model files: a ModelSpec as JSON (format described in docs/model-format.md).
//
// Reading is strict: a wrong type, a missing required field, an unknown field
// or enum string, or a malformed value (zero axis, non-orthonormal rotation
// matrix, q0 of the wrong length, ...) throws ModelError naming the file, the
// JSON-pointer path of the offending field ("/joints/0/type") and what was
// expected. Names are not resolved here; compile() does that.
//
// Writing produces a file that reads back to an identical ModelSpec (doubles
// bit-exact). Fields that do not apply to an element's type are not written.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "model/model_spec.hpp"

namespace codyna {

// Reads and parses the file at `path`; errors are attributed to `path`.
ModelSpec load_model_spec(const std::string& path);

// Parses a JSON document; `file_label` names it in error messages.
ModelSpec parse_model_spec(const nlohmann::json& j, const std::string& file_label);

// Reads one element of a model file's arrays ("bodies", "joints", "constraints", "effects",
// "actuators", "sensors") from its JSON into spec.<section>[index], as parse_model_spec reads
// it (errors name /section/index/...). A parameter study varies a number of one element: the
// rest of the nominal spec is kept, not read again. Returns false, changing nothing, for a
// section that is not one of these arrays or an index outside it.
bool parse_model_element(ModelSpec& spec, const std::string& section, std::size_t index, const nlohmann::json& element,
                         const std::string& file_label);

// Parses JSON text; malformed JSON gives a ModelError with line and column.
ModelSpec parse_model_spec_text(const std::string& text, const std::string& file_label);

// The JSON document for `spec` (rotations as matrices, inertia as 6 numbers).
nlohmann::json to_json(const ModelSpec& spec);

// Writes `spec` to `path` atomically (io/atomic_file.hpp): a temporary file in
// the same directory is written, flushed and renamed over `path`, so `path`
// holds either the old or the new content. Throws std::runtime_error naming
// `path` on failure and leaves no temporary file behind.
void save_model_spec(const ModelSpec& spec, const std::string& path);

}  // namespace codyna
