// Models users already have: MJCF (read by MuJoCo's own compiler) and URDF (read by urdfdom)
// imported as a ModelSpec with a report of what mapped and what did not (docs/import.md).
// The one door of the core for every front end's import (codyna import, codyna-gui's
// File > Import).
#pragma once

#include <string>
#include <vector>

#include "io/import_report.hpp"
#include "model/model_spec.hpp"

namespace codyna {

// The format of a file: "MJCF" or "URDF", by its extension (.xml, .mjcf; .urdf), else by its first
// element (<mujoco>, <robot>); "" when neither.
std::string study_import_format(const std::string& path);

// Reads an MJCF or URDF file into a ModelSpec and its report. Throws ImportRefused
// (std::invalid_argument: bad input) for a file that is not a model codyna can import and for
// elements that would change the dynamics and cannot be represented (unless options.ignore names
// their kind), std::runtime_error when codyna was built without the library the format needs.
// The spec is compiled once to check it (a ModelError from that is a failure of the import).
ImportResult study_import(const std::string& path, const ImportOptions& options = {});

// Whether each format can be read by this build ("MJCF": MuJoCo, "URDF": urdfdom).
bool study_import_available(const std::string& format);

// codyna import FILE --out MODEL.json [--ignore KIND ...]: one call.
struct ImportRequest {
  std::string file;                 // the MJCF or URDF file
  std::string out;                  // the model file written
  std::vector<std::string> ignore;  // kinds accepted as not modelled (import_kinds())
};
struct ImportJobResult {
  ModelSpec spec;
  ImportReport report;
  int dof = 0, nq = 0, nv = 0;      // of the compiled model
};
// Checks the output first (never the input itself, never a file that is not a codyna model:
// std::invalid_argument), imports, compiles, writes the model file atomically.
ImportJobResult study_import_job(const ImportRequest& request);

// Refuses (std::invalid_argument) a model-file output that is one of `inputs` (the same file,
// through links too), not a regular file, or an existing file that is not a codyna model file.
void study_guard_model_output(const std::string& path, const std::vector<std::string>& inputs);

}  // namespace codyna
