#include "study/files.hpp"

#include "io/atomic_file.hpp"
#include "io/mat_export.hpp"
#include "io/model_file.hpp"
#include "io/results_file.hpp"

namespace codyna {

ModelSpec study_read_model(const std::string& path) { return load_model_spec(path); }
ModelSpec study_parse_model(const nlohmann::json& j, const std::string& label) { return parse_model_spec(j, label); }
ModelSpec study_parse_model_text(const std::string& text, const std::string& label) {
  return parse_model_spec_text(text, label);
}
nlohmann::json study_model_json(const ModelSpec& spec) { return to_json(spec); }
void study_save_model(const ModelSpec& spec, const std::string& path) { save_model_spec(spec, path); }

void study_write_results(const SimulationResult& r, const std::string& hdf5_path, const std::string& csv_path) {
  write_results(r, hdf5_path, csv_path);
}
void study_write_results_hdf5(const SimulationResult& r, const std::string& path) { write_results_hdf5(r, path); }
void study_write_results_csv(const SimulationResult& r, const std::string& path) { write_results_csv(r, path); }
SimulationResult study_read_results(const std::string& path) { return read_results_hdf5(path); }

void study_guard_output(const std::string& path, OutputKind kind, const std::vector<std::string>& inputs) {
  guard_output(path, kind, inputs);
}
bool study_same_file(const std::string& path, const std::string& other) { return same_file(path, other); }
void study_remove_temporary_files() { remove_temporary_files(); }

std::string study_matlab_identifier(const std::string& s) { return matlab_identifier(s); }

}  // namespace codyna
