// What a study reads and writes, for every front end: model files (read, parsed from a JSON
// text, written back), simulation results (HDF5, CSV), and the rule that an output never
// replaces an input or a file codyna did not write. Front ends call these, never io/.
//
// Errors: ModelError (model/errors.hpp) naming the file and the field for a bad model,
// std::invalid_argument for a path that may not be written, std::runtime_error for the disk.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/output_guard.hpp"
#include "model/model_spec.hpp"
#include "simulation/result.hpp"

namespace codyna {

// Reads and validates the syntax of a model file (notes of the reader in spec.notes).
ModelSpec study_read_model(const std::string& path);
// The same from a JSON value or text; `label` names it in messages (a file name, "--reference").
ModelSpec study_parse_model(const nlohmann::json& j, const std::string& label);
ModelSpec study_parse_model_text(const std::string& text, const std::string& label);
// The model as the file format writes it.
nlohmann::json study_model_json(const ModelSpec& spec);
// Writes the model file atomically (a temporary file renamed into place).
void study_save_model(const ModelSpec& spec, const std::string& path);
// The model's references to other files are relative to the model file's folder (a tire's .tir
// `file`, the study's `controller_file` and `export_dir`, a reference's or disturbance's `file`):
// the model moved from the file `from` to the file `to` (Save As into another folder) names the
// same files again. Relative paths are rewritten relative to `to`'s folder (lexically, as short
// as they come: "../examples/tires/x.tir"); absolute ones and empty ones stay. `from` empty: as is.
ModelSpec study_rebase_paths(ModelSpec spec, const std::string& from, const std::string& to);

// Results: HDF5 and/or CSV (an empty path is skipped), each atomically.
void study_write_results(const SimulationResult& r, const std::string& hdf5_path, const std::string& csv_path = "");
void study_write_results_hdf5(const SimulationResult& r, const std::string& path);
void study_write_results_csv(const SimulationResult& r, const std::string& path);
SimulationResult study_read_results(const std::string& path);

// Refuses (std::invalid_argument) an output that would replace one of `inputs` or a file that
// is not of `kind` (io/output_guard.hpp); true when two paths name the same file.
void study_guard_output(const std::string& path, OutputKind kind, const std::vector<std::string>& inputs);
bool study_same_file(const std::string& path, const std::string& other);
// Removes the temporary files of writes in progress (from a signal handler: the final files are
// only ever renamed into place complete).
void study_remove_temporary_files();

// `s` as a MATLAB identifier (what an export is named after).
std::string study_matlab_identifier(const std::string& s);

}  // namespace codyna
