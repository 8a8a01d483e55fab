#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "study/model_summary.hpp"

namespace codyna::cli {

namespace {
int g_exit = 0;

void print_info(const ModelSummary& m) {
  std::cout << "model        " << m.name << "\n";
  if (!m.file.empty()) std::cout << "file         " << m.file << "\n";
  std::cout << "DOF          " << m.dof;
  if (m.nonholonomic_rows > 0)
    std::cout << " coordinates, " << m.rate_dof << " rates (rolling: " << m.nonholonomic_rows
              << " non-holonomic equations remove rates, not coordinates)";
  std::cout << "\n"
            << "nq, nv       " << m.nq << ", " << m.nv << "\n"
            << "bodies       " << m.bodies.size() << "\n";
  for (const ModelSummary::Body& b : m.bodies)
    std::cout << "  " << std::left << std::setw(14) << b.name << " mass " << std::setw(10) << b.mass << " joint " << b.joint
              << " (" << b.joint_type << ", parent " << b.parent << ")\n";
  std::cout << "coordinates  ";
  for (std::size_t k = 0; k < m.coordinates.size(); ++k) std::cout << (k ? ", " : "") << m.coordinates[k] << " [" << m.units[k] << "]";
  std::cout << "\nrates        ";
  for (std::size_t k = 0; k < m.rates.size(); ++k) std::cout << (k ? ", " : "") << m.rates[k] << " [" << m.rate_units[k] << "]";
  if (!m.effect_states.empty()) {  // (a line only for the models that have them)
    std::cout << "\neffect states ";
    for (std::size_t k = 0; k < m.effect_states.size(); ++k)
      std::cout << (k ? ", " : "") << m.effect_states[k] << " [" << m.effect_state_units[k] << "]";
    std::cout << " (the tires' transient slip)";
  }
  std::cout << "\nconstraints  " << m.constraints.size() << " (" << m.constraint_equations << " equations, "
            << m.independent_equations << " independent"
            << (m.velocity_only_equations == 0 ? std::string()
                                               : ", " + std::to_string(m.velocity_only_equations) + " on the velocities only")
            << ")\n";
  for (const ModelSummary::Constraint& c : m.constraints)
    std::cout << "  " << std::left << std::setw(14) << c.name << " " << c.type << " " << c.body_a << " - " << c.body_b << "\n";
  if (!m.redundant_equations.empty()) {
    std::cout << "redundant    ";
    for (std::size_t k = 0; k < m.redundant_equations.size(); ++k) std::cout << (k ? ", " : "") << m.redundant_equations[k];
    std::cout << " (dependent on the other equations; kept out of the dynamics)\n";
  }
  if (m.constraint_equations) {
    std::cout << "assembly     residual " << m.assembly_residual << "\n";
    if (!m.assembly_moves.empty()) std::cout << "             moved to close the loops: " << m.assembly_moves << "\n";
  }
  std::cout << "effects      " << (m.gravity_on ? "gravity" : "no gravity");
  if (m.spring_dampers) std::cout << ", " << m.spring_dampers << " spring-damper(s)";
  if (m.joint_springs) std::cout << ", " << m.joint_springs << " joint spring(s)";
  if (m.joint_frictions) std::cout << ", " << m.joint_frictions << " joint friction(s)";
  if (m.joint_dampers) std::cout << ", " << m.joint_dampers << " joint damper(s)";
  if (m.body_forces) std::cout << ", " << m.body_forces << " body force(s)";
  if (m.tires) std::cout << ", " << m.tires << " tire(s)";
  std::cout << "\ninputs       (candidate plant inputs; * = Plant/In)\n";
  for (const ModelSummary::Actuator& a : m.actuators)
    std::cout << "  " << (a.plant ? "* " : "  ") << std::left << std::setw(14) << a.name << " " << a.type << " [" << a.unit << "]\n";
  std::cout << "outputs      (candidate plant outputs; * = Plant/Out)\n";
  for (const ModelSummary::Sensor& y : m.sensors)
    std::cout << "  " << (y.plant ? "* " : "  ") << std::left << std::setw(14) << y.name << " " << y.type << " [" << y.unit << "]\n";
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
      print_info(model_summary(study_compile(load_spec(*file), *file)));
    }));
  });
}

}  // namespace codyna::cli
