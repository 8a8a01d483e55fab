// The model summary: what `codyna info`, Python's Study.model_info() and the GUI's overview show of
// a compiled model, walked once. Front ends print or convert it; none walks the Model again.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

struct ModelSummary {
  struct Body {
    std::string name;
    double mass = 0;
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    std::string joint, joint_type, parent;  // its joint (name, type) and the body the joint hangs it on
  };
  struct Joint {
    std::string name, type, parent, child;
    std::vector<std::string> coordinates, rates, q_names;
  };
  struct Constraint {
    std::string name, type, body_a, body_b;
    std::vector<std::string> equations;  // its rows' names
  };
  struct Effect {
    std::string name, type;
  };
  struct Actuator {
    std::string name, type, unit;
    double gain = 1, u0 = 0, min = 0, max = 0;
    bool plant = false;  // a Plant/In input
  };
  struct Sensor {
    std::string name, type, unit;
    bool plant = false;  // a Plant/Out output
  };

  std::string name, file;
  int dof = 0, rate_dof = 0, nq = 0, nv = 0;
  int nonholonomic_rows = 0;  // rolling: equations that remove rates, not coordinates
  std::vector<Body> bodies;   // without the ground
  std::vector<Joint> joints;
  std::vector<std::string> coordinates, units, rates, rate_units, q_names;
  std::vector<std::string> effect_states, effect_state_units;  // a tire's deflections (transient slip)
  std::vector<Constraint> constraints;
  int constraint_equations = 0, independent_equations = 0, velocity_only_equations = 0;
  std::vector<std::string> redundant_equations;
  double assembly_residual = 0;
  std::string assembly_moves;  // study_assembly_moves_text ("" when nothing moved)
  std::vector<Effect> effects;
  bool gravity_on = false;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  // elements per kind (a joint damper counts once, whatever its joint's coordinates)
  int spring_dampers = 0, joint_springs = 0, joint_frictions = 0, joint_dampers = 0, body_forces = 0, tires = 0;
  std::vector<Actuator> actuators;
  std::vector<Sensor> sensors;
  std::vector<std::string> plant_inputs, plant_outputs;
  std::string controller;  // the model file's controller type
  Eigen::VectorXd initial_coordinates, initial_rates;  // named by coordinates and rates
};

ModelSummary model_summary(const Model& m);

}  // namespace codyna
