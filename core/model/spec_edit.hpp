// Edits of a ModelSpec that keep it consistent, for editors (codyna-gui) and
// scripts: add, duplicate, rename and remove elements by kind and index.
// A rename updates every reference to the element (joints' parent/child,
// constraint and effect bodies, actuator/sensor joints and bodies, the
// Plant/In and Plant/Out lists, the study's disabled effects, coordinates set
// and independent coordinates) in the same call; references_to() lists what a
// removal would leave dangling, so an editor can ask first.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "model/model_spec.hpp"

namespace codyna {

enum class ElementKind { Body, Joint, Constraint, Effect, Actuator, Sensor };
inline constexpr ElementKind kElementKinds[] = {ElementKind::Body,   ElementKind::Joint,    ElementKind::Constraint,
                                                ElementKind::Effect, ElementKind::Actuator, ElementKind::Sensor};

const char* to_string(ElementKind k);    // "body", ...
const char* section_of(ElementKind k);   // the model file's array: "bodies", "joints", ...
std::optional<ElementKind> kind_of_section(const std::string& section);

int element_count(const ModelSpec& spec, ElementKind k);
const std::string& element_name(const ModelSpec& spec, ElementKind k, int index);
std::vector<std::string> element_names(const ModelSpec& spec, ElementKind k);
int find_element(const ModelSpec& spec, ElementKind k, const std::string& name);  // -1 if absent

// `base`, or base_2, base_3, ... : a name no element of that kind has
std::string unique_name(const ModelSpec& spec, ElementKind k, const std::string& base);

// Where a model file's field path ("/joints/2/parent") points: element and field ("parent").
struct ElementRef {
  ElementKind kind;
  int index = 0;
  std::string field;  // the rest of the path below the element, "" for the element itself
};
std::optional<ElementRef> element_at_path(const std::string& path);

// Human-readable descriptions of the references to an element ("joint pivot: child",
// "Plant/In", ...); empty when nothing refers to it.
std::vector<std::string> references_to(const ModelSpec& spec, ElementKind k, const std::string& name);

// Every field that names another element: the kind it names, the name, and the field's
// model-file path ("/joints/0/child", "/actuators/2/drives/1", "/plant/inputs/0"). Sensors'
// axes frames name a body too; ground is a body name here, and an empty optional name
// (a coupler's joint_c) is left out.
struct ReferenceField {
  ElementKind target;
  std::string name;
  std::string path;
};
std::vector<ReferenceField> reference_fields(const ModelSpec& spec);

// Throws std::invalid_argument for an empty name, "ground" for a body, or a name
// another element of the kind already has.
void rename_element(ModelSpec& spec, ElementKind k, int index, const std::string& new_name);

// The name a new element of kind k and type `type` (as the model file spells it: "spring_damper")
// gets, before add_element numbers it: "body", "joint", "closure", "gravity", "spring", "damper",
// "motor", "force", "sensor", ... Such a default name follows the element's type: an editor that
// changes the type of an element still called "gravity_2" renames it ("spring") in the same step.
std::string default_name(ElementKind k, const std::string& type);
// `name` is default_name(k, type) or that with a number (_2, _3, ...)
bool is_default_name(ElementKind k, const std::string& type, const std::string& name);
// the element's type as the model file spells it ("" for a body)
std::string element_type(const ModelSpec& spec, ElementKind k, int index);

// Appends a default element (joints: a revolute joint of a new body to ground needs
// the body to exist; the default joint connects the last body to ground; an effect is the
// gravity while the model has none, then a spring-damper from ground to the last body).
// Returns its index.
int add_element(ModelSpec& spec, ElementKind k);

// Appends a copy under a unique name; returns its index.
int duplicate_element(ModelSpec& spec, ElementKind k, int index);

// Removes it, and its entries in the Plant/In, Plant/Out and disabled-effects lists.
// Other references (a joint's child body, ...) are left for compile() to report.
void remove_element(ModelSpec& spec, ElementKind k, int index);

}  // namespace codyna
