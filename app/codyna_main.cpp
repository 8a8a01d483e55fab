// codyna: the headless command line. main() and argument parsing only; all
// work is done by codyna_core (the commands live in app/cmd_*.cpp).
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"codyna: multibody dynamics with a control module (linearize, export, closed-loop simulation)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("codyna ") + CODYNA_VERSION);
  codyna::cli::add_info(app);
  codyna::cli::add_linearize(app);
  codyna::cli::add_simulate(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return codyna::cli::exit_code();
}
