#include <cmath>
#include "common.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>
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
