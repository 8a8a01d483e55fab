// Shared by the subcommands: loading a model with file-attributed errors and
// turning exceptions into messages and exit codes.
#pragma once

#include <functional>
#include <string>

#include <vector>

#include "analysis/operating_point.hpp"
#include "model/compile.hpp"

namespace codyna::cli {

// load + compile; ModelError names the file
Model load_model(const std::string& path);

// applies --set NAME=VALUE (joint coordinates of the initial state), then re-assembles loops
Model with_settings(Model m, const std::vector<std::string>& set);

// --operating-point: initial | equilibrium | trim | time=T (the state the simulation reaches
// at T with the actuators at their nominal values and the model's solver settings).
// An equilibrium that cannot be found is an error, not a silent best effort.
OperatingPoint operating_point(const Model& m, const std::string& which, const std::vector<std::string>& independent);

// runs f; prints "codyna: error: ..." for exceptions and returns the exit code
// (0 ok, 1 bad input such as a ModelError or std::invalid_argument, 2 other failures)
int run_guarded(const std::function<void()>& f);

}  // namespace codyna::cli
