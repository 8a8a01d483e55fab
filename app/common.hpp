// Shared by the subcommands: loading a model with file-attributed errors and
// turning exceptions into messages and exit codes.
#pragma once

#include <functional>
#include <string>

#include "model/compile.hpp"

namespace codyna::cli {

// load + compile; ModelError names the file
Model load_model(const std::string& path);

// runs f; prints "codyna: error: ..." for exceptions and returns the exit code
// (0 ok, 1 bad input such as a ModelError or std::invalid_argument, 2 other failures)
int run_guarded(const std::function<void()>& f);

}  // namespace codyna::cli
