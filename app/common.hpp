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

// true when the option was given on the command line (so it overrides the file)
bool given(const CLI::App* cmd, const std::string& option);

// runs f; prints "codyna: error: ..." for exceptions and returns the exit code
// (0 ok, 1 bad input such as a ModelError or std::invalid_argument, 2 other failures)
int run_guarded(const std::function<void()>& f);

}  // namespace codyna::cli
