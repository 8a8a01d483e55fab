#include "commands.hpp"

namespace codyna::cli {

void add_linearize(CLI::App& app) { (void)app; }

}  // namespace codyna::cli
