#include "study/model_summary.hpp"

#include <algorithm>

#include "study/jobs.hpp"
#include "study/workflow.hpp"

namespace codyna {

namespace {
std::vector<std::string> summary_slice(const std::vector<std::string>& v, int first, int n) {
  if (first < 0 || n <= 0 || first + n > static_cast<int>(v.size())) return {};
  return std::vector<std::string>(v.begin() + first, v.begin() + first + n);
}
}  // namespace

ModelSummary model_summary(const Model& m) {
  ModelSummary s;
  const auto body = [&](int i) { return i >= 0 && i < static_cast<int>(m.body_names.size()) ? m.body_names[i] : std::string(); };
  s.name = m.name;
  s.file = m.source_file;
  s.dof = m.dof();
  s.rate_dof = m.rate_dof();
  s.effect_states = m.s_names;
  s.effect_state_units = m.s_units;
  s.nq = m.nq;
  s.nv = m.nv;
  s.nonholonomic_rows = m.active_velocity_rows;
  for (int i = 1; i < m.nbodies; ++i) {
    const JointModel& j = m.joints[i];
    s.bodies.push_back({m.body_names[i], m.mass[i], m.com[i], j.name, to_string(j.type), body(j.parent)});
    s.joints.push_back({j.name, to_string(j.type), body(j.parent), m.body_names[i], summary_slice(m.v_names, j.idx_v, j.nv),
                        summary_slice(m.rate_names, j.idx_v, j.nv), summary_slice(m.q_names, j.idx_q, j.nq)});
  }
  s.coordinates = m.v_names;
  s.units = m.v_units;
  s.rates = m.rate_names;
  for (const std::string& u : m.v_units) s.rate_units.push_back(rate_unit(u));
  s.q_names = m.q_names;
  for (const ConstraintModel& c : m.constraints)
    s.constraints.push_back({c.name, to_string(c.type), body(c.body_a), body(c.body_b), summary_slice(m.row_names, c.row, c.nrows)});
  s.constraint_equations = m.nc;
  s.independent_equations = static_cast<int>(m.active_rows.size());
  s.velocity_only_equations = static_cast<int>(m.velocity_rows.size());
  for (int k : m.redundant_rows) s.redundant_equations.push_back(m.row_names[k]);
  s.assembly_residual = m.assembly_residual;
  s.assembly_moves = study_assembly_moves_text(m);
  for (const EffectSpec& e : m.spec.effects) {
    s.effects.push_back({e.name, to_string(e.type)});
    s.joint_frictions += e.type == EffectType::JointFriction;
    s.joint_dampers += e.type == EffectType::JointDamper;
    s.tires += e.type == EffectType::Tire;
  }
  s.gravity_on = m.has_gravity;
  s.gravity = m.gravity;
  s.spring_dampers = static_cast<int>(m.springs.size());
  s.joint_springs = static_cast<int>(m.joint_springs.size());
  s.body_forces = static_cast<int>(m.body_forces.size());
  for (int k = 0; k < m.nu(); ++k) {
    const ActuatorModel& a = m.actuators[k];
    const bool plant = std::find(m.plant_inputs.begin(), m.plant_inputs.end(), k) != m.plant_inputs.end();
    s.actuators.push_back({a.name, to_string(a.type), a.unit, a.gain, a.u0, a.min, a.max, plant});
  }
  for (int k = 0; k < m.ny(); ++k) {
    const SensorModel& y = m.sensors[k];
    const bool plant = std::find(m.plant_outputs.begin(), m.plant_outputs.end(), k) != m.plant_outputs.end();
    s.sensors.push_back({y.name, to_string(y.type), y.unit, plant});
  }
  for (int k : m.plant_inputs) s.plant_inputs.push_back(m.actuators[k].name);
  for (int k : m.plant_outputs) s.plant_outputs.push_back(m.sensors[k].name);
  s.controller = to_string(m.spec.controller.type);
  s.initial_coordinates = study_coordinates(m, m.q0);
  s.initial_rates = m.v0;
  return s;
}

}  // namespace codyna
