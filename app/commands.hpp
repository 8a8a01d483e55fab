// The codyna subcommands. Each add_* registers a subcommand whose callback
// runs it and records the exit code (0 = success, 1 = bad input, 2 = failure).
#pragma once

#include <CLI/CLI.hpp>

namespace codyna::cli {

void add_info(CLI::App& app);
void add_linearize(CLI::App& app);
void add_simulate(CLI::App& app);
void add_import(CLI::App& app);
void add_export_mjcf(CLI::App& app);
void add_sweep(CLI::App& app);
void add_tire(CLI::App& app);
void add_maneuver(CLI::App& app);
void add_freqresp(CLI::App& app);
void add_kc(CLI::App& app);
int exit_code();
void set_exit_code(int code);

}  // namespace codyna::cli
