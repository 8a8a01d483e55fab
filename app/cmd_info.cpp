#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"

namespace codyna::cli {

namespace {
int g_exit = 0;

void print_info(const Model& m) {
  std::cout << "model        " << m.name << "\n";
  if (!m.source_file.empty()) std::cout << "file         " << m.source_file << "\n";
  std::cout << "DOF          " << m.dof();
  if (m.active_velocity_rows > 0)
    std::cout << " coordinates, " << m.rate_dof() << " rates (rolling: " << m.active_velocity_rows
              << " non-holonomic equations remove rates, not coordinates)";
  std::cout << "\n"
            << "nq, nv       " << m.nq << ", " << m.nv << "\n"
            << "bodies       " << m.nbodies - 1 << "\n";
  for (int i = 1; i < m.nbodies; ++i) {
    const JointModel& j = m.joints[i];
    std::cout << "  " << std::left << std::setw(14) << m.body_names[i] << " mass " << std::setw(10) << m.mass[i]
              << " joint " << j.name << " (" << to_string(j.type) << ", parent " << m.body_names[j.parent] << ")\n";
  }
  std::cout << "coordinates  ";
  for (int k = 0; k < m.nv; ++k) std::cout << (k ? ", " : "") << m.v_names[k] << " [" << m.v_units[k] << "]";
  std::cout << "\nrates        ";
  for (int k = 0; k < m.nv; ++k) std::cout << (k ? ", " : "") << m.rate_names[k] << " [" << rate_unit(m.v_units[k]) << "]";
  std::cout << "\nconstraints  " << m.constraints.size() << " (" << m.nc << " equations, "
            << m.active_rows.size() << " independent"
            << (m.velocity_rows.empty() ? std::string()
                                         : ", " + std::to_string(m.velocity_rows.size()) + " on the velocities only")
            << ")\n";
  for (const ConstraintModel& c : m.constraints)
    std::cout << "  " << std::left << std::setw(14) << c.name << " " << to_string(c.type) << " " << m.body_names[c.body_a]
              << " - " << m.body_names[c.body_b] << "\n";
  if (!m.redundant_rows.empty()) {
    std::cout << "redundant    ";
    for (std::size_t k = 0; k < m.redundant_rows.size(); ++k) std::cout << (k ? ", " : "") << m.row_names[m.redundant_rows[k]];
    std::cout << " (dependent on the other equations; kept out of the dynamics)\n";
  }
  if (m.nc) {
    std::cout << "assembly     residual " << m.assembly_residual << "\n";
    if (!m.assembly_moves.empty())
      std::cout << "             moved to close the loops: " << study_assembly_moves_text(m) << "\n";
  }
  std::cout << "effects      " << (m.has_gravity ? "gravity" : "no gravity");
  if (!m.springs.empty()) std::cout << ", " << m.springs.size() << " spring-damper(s)";
  if (!m.joint_springs.empty()) std::cout << ", " << m.joint_springs.size() << " joint spring(s)";
  {
    // a joint_damper acts on every coordinate of its joint: count the elements, not the coordinates
    long frictions = 0, dampers = 0;
    for (const EffectSpec& e : m.spec.effects) {
      if (e.type == EffectType::JointFriction) ++frictions;
      if (e.type == EffectType::JointDamper) ++dampers;
    }
    if (frictions) std::cout << ", " << frictions << " joint friction(s)";
    if (dampers) std::cout << ", " << dampers << " joint damper(s)";
  }
  if (!m.body_forces.empty()) std::cout << ", " << m.body_forces.size() << " body force(s)";
  std::cout << "\ninputs       (candidate plant inputs; * = Plant/In)\n";
  for (int k = 0; k < m.nu(); ++k) {
    const bool sel = std::find(m.plant_inputs.begin(), m.plant_inputs.end(), k) != m.plant_inputs.end();
    std::cout << "  " << (sel ? "* " : "  ") << std::left << std::setw(14) << m.actuators[k].name << " "
              << to_string(m.actuators[k].type) << " [" << m.actuators[k].unit << "]\n";
  }
  std::cout << "outputs      (candidate plant outputs; * = Plant/Out)\n";
  for (int k = 0; k < m.ny(); ++k) {
    const bool sel = std::find(m.plant_outputs.begin(), m.plant_outputs.end(), k) != m.plant_outputs.end();
    std::cout << "  " << (sel ? "* " : "  ") << std::left << std::setw(14) << m.sensors[k].name << " "
              << to_string(m.sensors[k].type) << " [" << m.sensors[k].unit << "]\n";
  }
}
}  // namespace

int exit_code() { return g_exit; }
void set_exit_code(int code) { g_exit = code; }

void add_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Summarize a model: DOF, bodies, joints, constraints, candidate inputs and outputs");
  auto file = std::make_shared<std::string>();
  cmd->add_option("model", *file, "model file (JSON)")->required();
  cmd->callback([file] {
    set_exit_code(run_guarded([&] {
      const Model m = study_compile(load_spec(*file), *file);
      print_info(m);
    }));
  });
}

}  // namespace codyna::cli
