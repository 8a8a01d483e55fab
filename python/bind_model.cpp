// codyna.Study's C++ half, _Study: a model file read (or a JSON text parsed) by the core's
// study_read_model / study_parse_model_text, model_info (what `codyna info` shows: the core's
// model_summary of study_compile, as a dict) and to_json (study_model_json).
#include "bind_common.hpp"

namespace codyna::python {

namespace {

Study study_from_file(const py::object& path_object) {
  const std::string path = fspath(path_object);
  Study s;
  s.spec = std::make_shared<const ModelSpec>(study_read_model(path));
  s.file = path;
  return s;
}

Study study_from_json(const std::string& text, const py::object& base_dir_object) {
  const std::string base_dir = fspath(base_dir_object);
  // the label names the text in messages; its folder is where relative paths of the model lead
  const std::string label = base_dir == "." || base_dir.empty() ? "<json>" : base_dir + "/<json>";
  Study s;
  s.spec = std::make_shared<const ModelSpec>(study_parse_model_text(text, label));
  s.file = label;
  s.text = text;
  return s;
}

py::dict model_info(const Study& s) {
  const ModelSummary m = model_summary(study_compile(*s.spec, s.file));
  py::list bodies, joints, constraints, effects, actuators, sensors;
  for (const ModelSummary::Body& b : m.bodies)
    bodies.append(py::dict("name"_a = b.name, "mass"_a = b.mass, "com"_a = b.com, "joint"_a = b.joint, "parent"_a = b.parent));
  for (const ModelSummary::Joint& j : m.joints)
    joints.append(py::dict("name"_a = j.name, "type"_a = j.type, "parent"_a = j.parent, "child"_a = j.child,
                           "coordinates"_a = j.coordinates, "rates"_a = j.rates, "q_names"_a = j.q_names));
  for (const ModelSummary::Constraint& c : m.constraints)
    constraints.append(py::dict("name"_a = c.name, "type"_a = c.type, "body_a"_a = c.body_a, "body_b"_a = c.body_b,
                                "equations"_a = c.equations));
  for (const ModelSummary::Effect& e : m.effects) effects.append(py::dict("name"_a = e.name, "type"_a = e.type));
  for (const ModelSummary::Actuator& a : m.actuators)
    actuators.append(py::dict("name"_a = a.name, "type"_a = a.type, "unit"_a = a.unit, "gain"_a = a.gain, "u0"_a = a.u0,
                              "min"_a = a.min, "max"_a = a.max));
  for (const ModelSummary::Sensor& y : m.sensors) sensors.append(py::dict("name"_a = y.name, "type"_a = y.type, "unit"_a = y.unit));
  return py::dict("name"_a = m.name, "file"_a = m.file, "dof"_a = m.dof, "rate_dof"_a = m.rate_dof, "nq"_a = m.nq,
                  "nv"_a = m.nv, "bodies"_a = bodies, "joints"_a = joints, "coordinates"_a = m.coordinates, "units"_a = m.units,
                  "rates"_a = m.rates, "q_names"_a = m.q_names, "effect_states"_a = m.effect_states, "constraints"_a = constraints,
                  "constraint_equations"_a = m.constraint_equations, "independent_equations"_a = m.independent_equations,
                  "redundant_equations"_a = m.redundant_equations, "assembly_residual"_a = m.assembly_residual,
                  "assembly_moves"_a = m.assembly_moves, "effects"_a = effects, "gravity"_a = m.gravity,
                  "actuators"_a = actuators, "sensors"_a = sensors, "plant_inputs"_a = m.plant_inputs,
                  "plant_outputs"_a = m.plant_outputs, "controller"_a = m.controller,
                  "initial_coordinates"_a = named(m.coordinates, m.initial_coordinates),
                  "initial_rates"_a = named(m.rates, m.initial_rates));
}

}  // namespace

void register_model(py::module_& m) {
  py::class_<Study>(m, "_Study", "A model file as read (codyna.Study wraps it).")
      .def(py::init(&study_from_file), "path"_a, "Reads and checks a model file (ModelError names the file and the field).")
      .def_static("from_json", &study_from_json, "text"_a, "base_dir"_a = ".",
                  "A model from a JSON text; relative paths in it are relative to base_dir.")
      .def_readonly("file", &Study::file, "the model file (or the label of a JSON text)")
      .def_property_readonly("notes", [](const Study& s) { return s.spec->notes; }, "the model reader's notes")
      .def("model_info", &model_info, "What `codyna info` shows, as a dict (see codyna.Study.model_info).")
      .def("to_json", [](const Study& s) { return study_model_json(*s.spec).dump(2); },
           "The model as the file format writes it (JSON text).");
}

}  // namespace codyna::python
