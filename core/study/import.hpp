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

// codyna export-mjcf MODEL.json --out FILE.xml: the model as MJCF that MuJoCo loads as the same
// mechanism (io/export_mjcf.hpp says what maps; an element without an exact MJCF equivalent
// refuses the export, naming it: std::invalid_argument).
struct ExportMjcfRequest {
  std::string model;  // the codyna model file
  std::string out;    // the MJCF file written
};
struct ExportMjcfResult {
  std::string xml;                       // the MJCF text (what is written)
  std::vector<std::string> written;      // what was written, one line per kind
  std::vector<std::string> not_written;  // what MJCF does not hold (no effect on the dynamics)
  std::vector<std::string> notes;        // the model file reader's notes
  int nbodies = 0, njoints = 0, nactuators = 0, nequalities = 0;  // MuJoCo's counts
  std::string checked_by;                // "MuJoCo 2.2.2" when MuJoCo loaded the text, else ""
};
// The MJCF of a model, not written anywhere (the GUI, tests); `label` names the model in messages
// and in the text's first line. Throws ModelError for a model that does not compile,
// std::invalid_argument naming every element without an MJCF equivalent, and
// std::invalid_argument with MuJoCo's message if this build has MuJoCo and MuJoCo does not load it.
ExportMjcfResult study_mjcf(const ModelSpec& spec, const std::string& label = "");
// Checks the output first (never the model file itself, never an existing file that is not an
// MJCF codyna wrote: std::invalid_argument), reads and compiles the model, exports it, loads
// the text with MuJoCo where this build has it, then writes the file atomically (a reader sees
// the old file or the whole new one).
ExportMjcfResult study_export_mjcf(const ExportMjcfRequest& request);

// Refuses (std::invalid_argument) a model-file output that is one of `inputs` (the same file,
// through links too), not a regular file, or an existing file that is not a codyna model file.
void study_guard_model_output(const std::string& path, const std::vector<std::string>& inputs);

}  // namespace codyna
