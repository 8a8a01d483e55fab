#include "common.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "model/errors.hpp"
#include "study/files.hpp"

namespace codyna::cli {

ModelSpec load_spec(const std::string& path) {
  ModelSpec spec = study_read_model(path);
  for (const std::string& n : spec.notes) std::cerr << "codyna: note: " << n << "\n";
  return spec;
}

void print_message(const StudyMessage& m) {
  std::cerr << (m.kind == StudyMessage::Warning ? "codyna: warning: " : "codyna: note: ") << m.text << "\n";
}

PlantRequest plant_request(const PlantFlags& f, const CLI::App* cmd) {
  PlantRequest r;
  if (given(cmd, "--inputs")) r.inputs = f.inputs;
  if (given(cmd, "--outputs")) r.outputs = f.outputs;
  if (given(cmd, "--disable-effect")) r.disabled_effects = f.disabled_effects;
  if (given(cmd, "--reference")) r.references = f.references;
  if (given(cmd, "--disturbance")) r.disturbances = f.disturbances;
  return r;
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

void add_point_flags(CLI::App* cmd, PointFlags& f, const std::string& op_help, const std::string& hold_help,
                     const std::string& initial_help) {
  cmd->add_option("--operating-point", f.op, op_help)->capture_default_str();
  cmd->add_option("--independent", f.independent, "closed loops: independent coordinate names")->delimiter(',');
  cmd->add_option("--hold,--set", f.hold, hold_help);
  cmd->add_option("--initial", f.initial, initial_help);
  cmd->add_option("--trim-free", f.trim_free, "trim: coordinates the trim solves instead of holding (comma-separated)")->delimiter(',');
  cmd->add_option("--free-input", f.free_inputs, "equilibrium/trim: Plant/In inputs solved for (comma-separated; trim default: all)")->delimiter(',');
  cmd->add_option("--target", f.targets, "NAME=VALUE: a Plant/Out value the equilibrium/trim/steady motion must reach (repeatable)");
  cmd->add_option("--steady-body", f.steady_body, "steady: the body whose speed and turn are given (default: the first on a free or planar joint to ground)");
  cmd->add_option("--speed", f.speed, "steady: forward speed of that body's centre of mass, m/s (default: as at the start)");
  cmd->add_option("--yaw-rate", f.yaw_rate, "steady: yaw rate, rad/s (> 0 turns left)");
  cmd->add_option("--radius", f.radius, "steady: radius of the path of its centre of mass, m (> 0 left, < 0 right)");
  cmd->add_option("--lateral-acceleration", f.lateral_acceleration, "steady: lateral acceleration, m/s^2 (> 0 left)");
}

PointRequest point_request(const PointFlags& f, const CLI::App* cmd) {
  PointRequest p;
  if (given(cmd, "--operating-point")) p.operating_point = f.op;
  if (given(cmd, "--independent")) p.independent = f.independent;
  if (given(cmd, "--trim-free")) p.trim_free = f.trim_free;
  if (given(cmd, "--free-input")) p.free_inputs = f.free_inputs;
  p.hold = f.hold;
  p.initial = f.initial;
  p.targets = f.targets;
  if (given(cmd, "--steady-body")) p.steady_body = f.steady_body;
  if (given(cmd, "--speed")) p.speed = f.speed;
  if (given(cmd, "--yaw-rate")) p.yaw_rate = f.yaw_rate;
  if (given(cmd, "--radius")) p.radius = f.radius;
  if (given(cmd, "--lateral-acceleration")) p.lateral_acceleration = f.lateral_acceleration;
  return p;
}

void add_lqr_flags(CLI::App* cmd, LqrFlags& f, const std::string& lqr_help, const std::string& part_help) {
  cmd->add_flag("--lqr", f.lqr, lqr_help);
  cmd->add_flag("--lqr-controllable-part", f.controllable_part, part_help);
  cmd->add_option("--q-weights", f.q_weights, "LQR state weights (diagonal of Q), in state order")->delimiter(',');
  cmd->add_option("--r-weights", f.r_weights, "LQR input weights (diagonal of R)")->delimiter(',');
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
