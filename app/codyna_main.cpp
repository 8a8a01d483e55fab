// codyna: the headless command line. main() and argument parsing only; all
// work is done by codyna_core (the commands live in app/cmd_*.cpp).
//
// Exit codes: 0 success, 1 bad input (model, flags, files), 2 a failure of the
// work itself (solver, disk); nothing else.
#include <CLI/CLI.hpp>
#include <csignal>
#include <iostream>
#include <unistd.h>

#include "commands.hpp"
#include "study/files.hpp"

namespace {

// SIGINT / SIGTERM: remove the temporary files of writes in progress (the final
// files are only ever renamed into place complete), then end as the signal would.
extern "C" void on_signal(int sig) {
  codyna::study_remove_temporary_files();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  CLI::App app{"codyna: multibody dynamics with a control module (linearize, export, closed-loop simulation)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("codyna ") + CODYNA_VERSION);
  codyna::cli::add_info(app);
  codyna::cli::add_linearize(app);
  codyna::cli::add_simulate(app);
  codyna::cli::add_import(app);
  codyna::cli::add_export_mjcf(app);
  codyna::cli::add_sweep(app);
  codyna::cli::add_tire(app);
  codyna::cli::add_maneuver(app);
  codyna::cli::add_freqresp(app);
  codyna::cli::add_kc(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-')
      std::cerr << "codyna: error: unknown command \"" << argv[1] << "\"\n";
    else
      std::cerr << "codyna: error: " << e.what() << "\n";
    if (app.get_subcommands().empty())
      std::cerr << "commands: info, linearize, simulate, import, export-mjcf, sweep, sweep-merge (codyna COMMAND --help for each)\n";
    else
      std::cerr << "see codyna " << app.get_subcommands().front()->get_name() << " --help\n";
    return 1;
  }
  return codyna::cli::exit_code();
}
