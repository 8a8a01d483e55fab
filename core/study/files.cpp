#include "study/files.hpp"

#include "io/atomic_file.hpp"
#include "io/mat_export.hpp"
#include "io/model_file.hpp"
#include "io/results_file.hpp"

#include <filesystem>

namespace codyna {

ModelSpec study_read_model(const std::string& path) { return load_model_spec(path); }
ModelSpec study_parse_model(const nlohmann::json& j, const std::string& label) { return parse_model_spec(j, label); }
ModelSpec study_parse_model_text(const std::string& text, const std::string& label) {
  return parse_model_spec_text(text, label);
}
nlohmann::json study_model_json(const ModelSpec& spec) { return to_json(spec); }
void study_save_model(const ModelSpec& spec, const std::string& path) { save_model_spec(spec, path); }

ModelSpec study_rebase_paths(ModelSpec spec, const std::string& from, const std::string& to) {
  namespace fs = std::filesystem;
  if (from.empty() || to.empty()) return spec;
  const fs::path old_dir = fs::absolute(fs::path(from)).parent_path().lexically_normal();
  const fs::path new_dir = fs::absolute(fs::path(to)).parent_path().lexically_normal();
  if (old_dir == new_dir) return spec;
  const auto rebase = [&](std::string& p) {
    if (p.empty() || fs::path(p).is_absolute()) return;
    const fs::path target = (old_dir / p).lexically_normal();
    const fs::path rel = target.lexically_relative(new_dir);
    p = (rel.empty() ? target : rel).generic_string();
  };
  for (EffectSpec& e : spec.effects) rebase(e.file);
  StudySpec& s = spec.analysis;
  rebase(s.controller_file);
  rebase(s.export_dir);
  for (SignalSpec& r : s.references) rebase(r.file);
  for (DisturbanceSpec& d : s.disturbances) rebase(d.file);
  return spec;
}

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
