// compile_structure(spec) -> Model: validates a ModelSpec, orders the joint tree, assigns
// indices, resolves names, and sets the initial state as the joints' q0/v0 write it. It calls
// nothing of the dynamics: dynamics/prepare.hpp's compile() adds what needs the algorithms
// (loops assembled, redundant rows, the mass-matrix check), and study_model (study/workflow.hpp)
// is what front ends call.
// Any problem throws ModelError naming `file` (may be empty), the JSON path of
// the offending field (e.g. "/joints/2/parent") and what was expected.
#pragma once

#include <string>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"

namespace codyna {

Model compile_structure(const ModelSpec& spec, const std::string& file = "");

// The solver section's own checks (compile_structure makes them): the integrator's name, positive
// tolerances, times and steps, alf's penalty and iterations, alf's step no longer than the run;
// ModelError naming the field (/solver/...) otherwise. The GUI checks an edit of it with this.
void check_solver_spec(const SolverSpec& solver, const std::string& file = "");

// What compile_structure says of a body no joint moves (study/model_issues.hpp lists every one).
std::string unattached_body_detail(const std::string& body);

// What a parameter study's variant changes in a compiled model without changing its tree, names or
// indices: the bodies' mass, com and inertia; the effects (gravity, springs and dampers, bushings,
// forces: any of their fields, since nothing else refers to them); the joints' q0 and v0 (the
// initial state, and what follows from it: the motion inputs' nominal values, the couplers' offsets
// when the file gives none); the actuators' numbers (gain, u0, min, max, point, direction, point_a,
// point_b, a mix's weights) and the sensors' (point, axis, point_a, point_b), whose names, types and
// the joints and bodies they name stay the structure's (the plant's inputs and outputs keep their
// indices).
struct NumbersChanged {
  bool bodies = false;
  bool effects = false;
  bool initial = false;
  bool actuators = false;
  bool sensors = false;
};

// The model of `spec` from `structure`, compile_structure's model of a spec that differs from `spec`
// only in what `what` names: those are checked and made again as compile_structure does (the same
// code), the rest is copied (the structure's spec need not be kept: the model gets `spec`). Member
// for member compile_structure(spec, file), with its errors (Compile.*NumbersOnTheStructure*). Throws
// std::invalid_argument if `spec` has another number of bodies (or joints, with `initial`).
Model compile_numbers(const Model& structure, const ModelSpec& spec, NumbersChanged what, const std::string& file = "");

}  // namespace codyna
