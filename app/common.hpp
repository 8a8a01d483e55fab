// Shared by the subcommands: reading a model file (its notes printed), turning the plant flags
// into the study's request, printing (names and values, matrices, messages), and turning
// exceptions into messages and exit codes. What the flags mean is decided in core
// (study/jobs.hpp), not here.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "model/model_spec.hpp"
#include "study/jobs.hpp"

namespace codyna::cli {

// true when the option was given on the command line (so it overrides the file)
bool given(const CLI::App* cmd, const std::string& option);

// reads the model file (errors name it) and prints its notes
ModelSpec load_spec(const std::string& path);

// "codyna: note: ..." / "codyna: warning: ..." on stderr, as a job tells them
void print_message(const StudyMessage& m);

// The plant selection and the study's signals for one run: --inputs/--outputs (actuator and
// sensor names, in order), --disable-effect (effect names), --reference and --disturbance (each
// a JSON object or NAME=VALUE[@TIME]); each given replaces the file's (study/jobs.hpp checks them).
struct PlantFlags {
  std::vector<std::string> inputs, outputs, disabled_effects, references, disturbances;
};
void add_plant_flags(CLI::App* cmd, PlantFlags& f);
PlantRequest plant_request(const PlantFlags& f, const CLI::App* cmd);

// The operating point's flags, the same for linearize and simulate (study/jobs.hpp's PointRequest):
// --operating-point, --independent, --hold (--set), --initial, --trim-free, --free-input, --target,
// and the steady motion's --steady-body, --speed, --yaw-rate, --radius, --lateral-acceleration.
// `op_help` and `hold_help`/`initial_help` say what they mean for the subcommand.
struct PointFlags {
  std::string op = "equilibrium";
  std::vector<std::string> independent, hold, initial, trim_free, free_inputs, targets;
  std::string steady_body;
  double speed = 0, yaw_rate = 0, radius = 0, lateral_acceleration = 0;
};
void add_point_flags(CLI::App* cmd, PointFlags& f, const std::string& op_help, const std::string& hold_help,
                     const std::string& initial_help);
PointRequest point_request(const PointFlags& f, const CLI::App* cmd);

// The LQR design's flags: --lqr, --lqr-controllable-part, --q-weights, --r-weights
struct LqrFlags {
  bool lqr = false, controllable_part = false;
  std::vector<double> q_weights, r_weights;
};
void add_lqr_flags(CLI::App* cmd, LqrFlags& f, const std::string& lqr_help, const std::string& part_help);
// into a request's lqr, lqr_controllable_part, q_weights, r_weights
template <class Request>
void apply_lqr_flags(const LqrFlags& f, const CLI::App* cmd, Request& r) {
  r.lqr = f.lqr;
  r.lqr_controllable_part = f.controllable_part;
  if (given(cmd, "--q-weights")) r.q_weights = f.q_weights;
  if (given(cmd, "--r-weights")) r.r_weights = f.r_weights;
}

// Printing (docs/linearization.md, "What is printed"): an entry whose magnitude is at most
// 1e-12 times the largest magnitude of its vector or matrix (at least 1) is round-off and prints
// as 0; the exported and saved values keep it.
double shown(double x, double scale);
// "  name = value\n" per entry (or "name = value, " on one line when `one_line`), round-off as 0
std::string name_values(const std::vector<std::string>& names, const Eigen::VectorXd& v, bool one_line = false,
                        int precision = 6);
// a matrix with its row and column names, in blocks of columns that fit `width` characters
// ("columns 7 to 12 of 12" above each block after the first), round-off as 0
void print_matrix(const char* label, const Eigen::MatrixXd& M, const std::vector<std::string>& rows,
                  const std::vector<std::string>& cols, int width = 100);

// runs f; prints "codyna: error: ..." for exceptions and returns the exit code
// (0 ok, 1 bad input such as a ModelError or std::invalid_argument, 2 other failures)
int run_guarded(const std::function<void()>& f);

}  // namespace codyna::cli
