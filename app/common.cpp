#include <cmath>
#include "common.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

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

std::string assembly_moves_text(const Model& m) {
  std::ostringstream os;
  os.precision(6);
  for (const Model::AssemblyMove& a : m.assembly_moves) {
    const auto iv = std::find(m.v_names.begin(), m.v_names.end(), a.name);
    const auto ir = std::find(m.rate_names.begin(), m.rate_names.end(), a.name);
    const std::size_t i = iv != m.v_names.end() ? static_cast<std::size_t>(iv - m.v_names.begin())
                                                : static_cast<std::size_t>(ir - m.rate_names.begin());
    const std::string unit = i < m.v_units.size() ? m.v_units[i] + (iv != m.v_names.end() ? "" : "/s") : "";
    os << (os.tellp() > 0 ? ", " : "") << a.name << " ";
    if (std::isfinite(a.from)) os << a.from << " -> " << a.to << " ";
    os << "(moved by " << a.by << " " << unit << ")";
  }
  return os.str();
}

double shown(double x, double scale) { return std::abs(x) <= 1e-12 * std::max(1.0, scale) ? 0.0 : x; }

std::string name_values(const std::vector<std::string>& names, const Eigen::VectorXd& v, bool one_line, int precision) {
  const double scale = v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
  std::ostringstream os;
  os.precision(precision);
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    const std::string& name = static_cast<std::size_t>(k) < names.size() ? names[static_cast<std::size_t>(k)] : "?";
    if (one_line) os << (k ? ", " : "") << name << " = " << shown(v[k], scale);
    else os << "  " << name << " = " << shown(v[k], scale) << "\n";
  }
  return os.str();
}

void print_matrix(const char* label, const Eigen::MatrixXd& M, const std::vector<std::string>& rows,
                  const std::vector<std::string>& cols, int width) {
  std::cout << label << " (" << M.rows() << " x " << M.cols() << ")\n";
  if (M.size() == 0) return;
  const double scale = M.cwiseAbs().maxCoeff();
  std::size_t w = 8;
  for (const auto& r : rows) w = std::max(w, r.size() + 1);
  constexpr int kColumn = 14;
  const Eigen::Index per_block = std::max<Eigen::Index>(1, (width - static_cast<int>(w)) / kColumn);
  for (Eigen::Index first = 0; first < M.cols(); first += per_block) {
    const Eigen::Index last = std::min(M.cols(), first + per_block);
    if (first > 0 || last < M.cols())
      std::cout << (first > 0 ? "\n" : "") << "  columns " << first + 1 << " to " << last << " of " << M.cols() << "\n";
    std::cout << std::setw(static_cast<int>(w)) << "";
    for (Eigen::Index j = first; j < last; ++j) {
      const std::string& c = static_cast<std::size_t>(j) < cols.size() ? cols[static_cast<std::size_t>(j)] : "?";
      std::cout << std::setw(kColumn) << c.substr(0, kColumn - 1);
    }
    std::cout << "\n";
    for (Eigen::Index i = 0; i < M.rows(); ++i) {
      const std::string& r = static_cast<std::size_t>(i) < rows.size() ? rows[static_cast<std::size_t>(i)] : "?";
      std::cout << std::left << std::setw(static_cast<int>(w)) << r << std::right;
      for (Eigen::Index j = first; j < last; ++j) std::cout << std::setw(kColumn) << std::setprecision(6) << shown(M(i, j), scale);
      std::cout << "\n";
    }
  }
}

bool given(const CLI::App* cmd, const std::string& option) { return cmd->count(option) > 0; }

void add_plant_flags(CLI::App* cmd, PlantFlags& f) {
  cmd->add_option("--inputs", f.inputs, "Plant/In for this run: actuator names, in order (comma-separated; replaces the file's plant.inputs)")->delimiter(',');
  cmd->add_option("--outputs", f.outputs, "Plant/Out for this run: sensor names, in order (comma-separated; replaces the file's plant.outputs)")->delimiter(',');
  cmd->add_option("--disable-effect", f.disabled_effects, "effects left out of this run (comma-separated names; replaces the file's analysis.disabled_effects)")->delimiter(',');
  cmd->add_option("--reference", f.references, "a reference on a Plant/Out: OUTPUT=VALUE[@TIME] (r steps from y0 to VALUE at TIME, default 0) or a JSON object as in the file's analysis.references (repeatable; replaces the file's)");
  cmd->add_option("--disturbance", f.disturbances, "a disturbance on an actuator that is not Plant/In: ACTUATOR=VALUE[@TIME] (a step adding VALUE at TIME, default 0) or a JSON object as in the file's analysis.disturbances (repeatable; replaces the file's)");
}

namespace {
std::string names_of(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& n : v) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "none" : s;
}

// NAME=VALUE[@TIME] -> {"KEY": NAME, "type": "step", "value": VALUE, "time": TIME}, or a JSON object as it is
nlohmann::json signal_json(const std::string& text, const char* key, const std::string& flag) {
  const auto first = text.find_first_not_of(" \t");
  if (first != std::string::npos && text[first] == '{') {
    try {
      return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      throw std::invalid_argument(flag + " " + text + ": not a JSON object (" + e.what() + ")");
    }
  }
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument(flag + " " + text + ": expected NAME=VALUE[@TIME] or a JSON object {\"" + key + "\": ...}");
  const std::string rest = text.substr(eq + 1);
  const auto at = rest.find('@');
  const auto number = [&](const std::string& s, const char* what) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(x))
      throw std::invalid_argument(flag + " " + text + ": expected a finite number for the " + what);
    return x;
  };
  nlohmann::json j = {{key, text.substr(0, eq)}, {"type", "step"}, {"value", number(rest.substr(0, at), "value")}};
  if (at != std::string::npos) j["time"] = number(rest.substr(at + 1), "time after '@'");
  return j;
}
}  // namespace

void apply_plant_flags(ModelSpec& spec, const PlantFlags& f, const CLI::App* cmd) {
  const auto check = [](const std::vector<std::string>& given_names, const std::vector<std::string>& known,
                        const std::string& flag, const char* what) {
    for (const std::string& n : given_names)
      if (std::find(known.begin(), known.end(), n) == known.end())
        throw std::invalid_argument(flag + ": no " + what + " named \"" + n + "\" (" + what + "s: " + names_of(known) + ")");
  };
  std::vector<std::string> actuators, sensors, effects;
  for (const auto& a : spec.actuators) actuators.push_back(a.name);
  for (const auto& s : spec.sensors) sensors.push_back(s.name);
  for (const auto& e : spec.effects) effects.push_back(e.name);
  if (given(cmd, "--inputs")) {
    check(f.inputs, actuators, "--inputs", "actuator");
    spec.plant.inputs = f.inputs;
  }
  if (given(cmd, "--outputs")) {
    check(f.outputs, sensors, "--outputs", "sensor");
    spec.plant.outputs = f.outputs;
  }
  if (given(cmd, "--disable-effect")) {
    check(f.disabled_effects, effects, "--disable-effect", "effect");
    spec.analysis.disabled_effects = f.disabled_effects;
  }
  if (!given(cmd, "--reference") && !given(cmd, "--disturbance")) return;
  // the signals are read by the model file's reader, from the spec with the flags' lists in it
  nlohmann::json j = to_json(spec);
  std::string label = "--reference/--disturbance";
  if (given(cmd, "--reference")) {
    j["analysis"]["references"] = nlohmann::json::array();
    for (const std::string& r : f.references) j["analysis"]["references"].push_back(signal_json(r, "output", "--reference"));
  }
  if (given(cmd, "--disturbance")) {
    j["analysis"]["disturbances"] = nlohmann::json::array();
    for (const std::string& d : f.disturbances)
      j["analysis"]["disturbances"].push_back(signal_json(d, "actuator", "--disturbance"));
  }
  if (given(cmd, "--reference") && !given(cmd, "--disturbance")) label = "--reference";
  if (!given(cmd, "--reference") && given(cmd, "--disturbance")) label = "--disturbance";
  ModelSpec read = parse_model_spec(j, label);
  spec.analysis.references = read.analysis.references;
  spec.analysis.disturbances = read.analysis.disturbances;
}

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
