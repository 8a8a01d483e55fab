// Shared by the subcommands: loading a model with file-attributed errors,
// turning flags into the study's choices (the flags override the model file's
// "analysis" section), and turning exceptions into messages and exit codes.
// What the study means is decided in core (study/workflow.hpp), not here.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "model/compile.hpp"
#include "study/workflow.hpp"

namespace codyna::cli {

// load + compile; ModelError names the file
Model load_model(const std::string& path);

// reads the model file (errors name it)
ModelSpec load_spec(const std::string& path);

// --hold (alias --set) NAME=VALUE ... added to the study's held coordinates (a name given again
// replaces its value)
void apply_set(StudySpec& study, const std::vector<std::string>& set);
// --initial NAME=VALUE ... added to the study's initial state (StudySpec::initial)
void apply_initial(StudySpec& study, const std::vector<std::string>& initial);
// the same for --target NAME=VALUE (StudySpec::output_targets)
void apply_targets(StudySpec& study, const std::vector<std::string>& targets);

// The plant selection and the study's signals for one run, over the model file's (each list
// given replaces the file's): --inputs/--outputs (actuator and sensor names, in order),
// --disable-effect (effect names), --reference and --disturbance (each either a JSON object
// with the fields of the file's "references"/"disturbances" entries, or the step shorthand
// NAME=VALUE[@TIME]). Unknown names are refused naming the flag and listing what exists; the
// signals go through the model file's reader, so their errors name the flag and the field.
struct PlantFlags {
  std::vector<std::string> inputs, outputs, disabled_effects, references, disturbances;
};
void add_plant_flags(CLI::App* cmd, PlantFlags& f);
void apply_plant_flags(ModelSpec& spec, const PlantFlags& f, const CLI::App* cmd);

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

// "crank 2.0944 -> 2.09842 (moved by 0.00402 rad), ..." for Model::assembly_moves; "" when none
std::string assembly_moves_text(const Model& m);

// true when the option was given on the command line (so it overrides the file)
bool given(const CLI::App* cmd, const std::string& option);

// runs f; prints "codyna: error: ..." for exceptions and returns the exit code
// (0 ok, 1 bad input such as a ModelError or std::invalid_argument, 2 other failures)
int run_guarded(const std::function<void()>& f);

}  // namespace codyna::cli
