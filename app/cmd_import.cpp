// codyna import FILE --out MODEL.json [--ignore KIND ...]: an MJCF or URDF file as a codyna model
// file, with the report of what mapped and what did not (core/study/import.hpp, docs/import.md).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "study/import.hpp"

namespace codyna::cli {

namespace {

struct ImportArgs {
  std::string file, out;
  std::vector<std::string> ignore;
};

void run_import(const ImportArgs& a) {
  ImportRequest r;
  r.file = a.file;
  r.out = a.out;
  r.ignore = a.ignore;
  try {
    const ImportJobResult j = study_import_job(r);
    for (const std::string& n : j.spec.notes) std::cerr << "codyna: note: " << n << "\n";
    std::cout << j.report.text();
    std::cout << "wrote " << a.out << ": " << j.spec.bodies.size() << " bodies, " << j.spec.joints.size() << " joints, DOF "
              << j.dof << " (nq " << j.nq << ", nv " << j.nv << "), " << j.spec.plant.inputs.size() << " Plant/In, "
              << j.spec.plant.outputs.size() << " Plant/Out\n";
  } catch (const ImportRefused& e) {
    if (!e.report().mapped.empty()) std::cout << e.report().text() << std::flush;  // what was read, before the refusal
    throw;
  }
}

}  // namespace

void add_import(CLI::App& app) {
  auto* cmd = app.add_subcommand("import", "Import an MJCF (.xml, read by MuJoCo) or URDF (.urdf) model as a codyna model file");
  auto a = std::make_shared<ImportArgs>();
  cmd->add_option("file", a->file, "the MJCF or URDF file")->required();
  cmd->add_option("--out", a->out, "the codyna model file to write (JSON)")->required();
  std::string kinds;
  for (const auto& [k, line] : import_kinds()) kinds += "\n  " + k + ": " + line;
  cmd->add_option("--ignore", a->ignore, "import without elements of this kind (repeatable or comma-separated):" + kinds)
      ->delimiter(',');
  cmd->callback([a] { set_exit_code(run_guarded([&] { run_import(*a); })); });
}

}  // namespace codyna::cli
