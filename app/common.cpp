#include <cmath>
#include "common.hpp"

#include <iostream>
#include <stdexcept>

#include "io/model_file.hpp"

namespace codyna::cli {

Model load_model(const std::string& path) { return compile(load_spec(path), path); }

ModelSpec load_spec(const std::string& path) {
  ModelSpec spec = load_model_spec(path);
  for (const std::string& n : spec.notes) std::cerr << "codyna: note: " << n << "\n";
  return spec;
}

namespace {
void apply_pairs(std::vector<std::pair<std::string, double>>& into, const std::vector<std::string>& given_pairs,
                 const std::string& flag) {
  for (const std::string& s : given_pairs) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw std::invalid_argument(flag + " " + s + ": expected NAME=VALUE");
    const std::string name = s.substr(0, eq);
    double value;
    try {
      std::size_t used = 0;
      value = std::stod(s.substr(eq + 1), &used);
      if (used != s.size() - eq - 1) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw std::invalid_argument(flag + " " + s + ": expected a number after '='");
    }
    if (!std::isfinite(value)) throw std::invalid_argument(flag + " " + s + ": expected a finite number");
    auto it = std::find_if(into.begin(), into.end(), [&](const auto& p) { return p.first == name; });
    if (it != into.end()) it->second = value;
    else into.emplace_back(name, value);
  }
}
}  // namespace

void apply_set(StudySpec& study, const std::vector<std::string>& set) { apply_pairs(study.set, set, "--hold"); }

void apply_initial(StudySpec& study, const std::vector<std::string>& initial) {
  apply_pairs(study.initial, initial, "--initial");
}

void apply_targets(StudySpec& study, const std::vector<std::string>& targets) {
  apply_pairs(study.output_targets, targets, "--target");
}

bool given(const CLI::App* cmd, const std::string& option) { return cmd->count(option) > 0; }

int run_guarded(const std::function<void()>& f) {
  try {
    f();
    return 0;
  } catch (const ModelError& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace codyna::cli
