// codyna export-mjcf MODEL.json --out FILE.xml: a codyna model as MJCF that MuJoCo loads as the
// same mechanism (core/study/import.hpp, core/io/export_mjcf.hpp; docs/import.md "Export to MJCF").
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/import.hpp"

namespace codyna::cli {

namespace {

struct ExportMjcfArgs {
  std::string model, out;
};

void run_export_mjcf(const ExportMjcfArgs& a) {
  ExportMjcfRequest r;
  r.model = a.model;
  r.out = a.out;
  const ExportMjcfResult j = study_export_mjcf(r);
  for (const std::string& n : j.notes) std::cerr << "codyna: note: " << n << "\n";
  std::cout << "written:\n";
  for (const std::string& l : j.written) std::cout << "  " << l << "\n";
  if (!j.not_written.empty()) {
    std::cout << "not in MJCF (no effect on the dynamics):\n";
    for (const std::string& l : j.not_written) std::cout << "  " << l << "\n";
  }
  std::cout << "wrote " << a.out << ": " << j.nbodies << " bodies, " << j.njoints << " joints, " << j.nactuators
            << " actuators, " << j.nequalities << " equalities"
            << (j.checked_by.empty() ? " (not loaded: codyna was built without MuJoCo)" : "; " + j.checked_by + " loads it")
            << "\n";
}

}  // namespace

void add_export_mjcf(CLI::App& app) {
  auto* cmd = app.add_subcommand("export-mjcf", "Write a codyna model as MJCF (MuJoCo's format), the same mechanism");
  auto a = std::make_shared<ExportMjcfArgs>();
  cmd->add_option("model", a->model, "the codyna model file (JSON)")->required();
  cmd->add_option("--out", a->out, "the MJCF file to write (.xml)")->required();
  cmd->callback([a] { set_exit_code(run_guarded([&] { run_export_mjcf(*a); })); });
}

}  // namespace codyna::cli
