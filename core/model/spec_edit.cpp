#include "model/spec_edit.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace codyna {

namespace {

template <class F>
decltype(auto) visit_list(ModelSpec& s, ElementKind k, F&& f) {
  switch (k) {
    case ElementKind::Body: return f(s.bodies);
    case ElementKind::Joint: return f(s.joints);
    case ElementKind::Constraint: return f(s.constraints);
    case ElementKind::Effect: return f(s.effects);
    case ElementKind::Actuator: return f(s.actuators);
    case ElementKind::Sensor: return f(s.sensors);
  }
  throw std::logic_error("element kind");
}

template <class F>
decltype(auto) visit_list(const ModelSpec& s, ElementKind k, F&& f) {
  return visit_list(const_cast<ModelSpec&>(s), k, [&](const auto& v) -> decltype(auto) { return f(v); });
}

void check_index(const ModelSpec& s, ElementKind k, int i) {
  if (i < 0 || i >= element_count(s, k))
    throw std::out_of_range(std::string("no ") + to_string(k) + " at index " + std::to_string(i));
}

// name == old, or a coordinate of it ("old.x")
bool names_coordinate_of(const std::string& name, const std::string& old) {
  return name == old || (name.size() > old.size() && name.compare(0, old.size(), old) == 0 && name[old.size()] == '.');
}

std::string renamed_coordinate(const std::string& name, const std::string& old, const std::string& now) {
  return names_coordinate_of(name, old) ? now + name.substr(old.size()) : name;
}

std::string at(const char* section, std::size_t i, const char* field) {
  return std::string("/") + section + "/" + std::to_string(i) + "/" + field;
}

// f(std::string& ref, const std::string& where, const std::string& path): every field that names a
// body, described ("joint pivot: child") and as its model-file path ("/joints/0/child")
template <class F>
void for_each_body_ref(ModelSpec& s, F&& f) {
  for (std::size_t i = 0; i < s.joints.size(); ++i) {
    auto& j = s.joints[i];
    f(j.parent, "joint " + j.name + ": parent", at("joints", i, "parent"));
    f(j.child, "joint " + j.name + ": child", at("joints", i, "child"));
  }
  for (std::size_t i = 0; i < s.constraints.size(); ++i) {
    auto& c = s.constraints[i];
    if (c.type == ConstraintType::Coupler) continue;  // joints, not bodies
    f(c.body_a, "constraint " + c.name + ": body_a", at("constraints", i, "body_a"));
    f(c.body_b, "constraint " + c.name + ": body_b", at("constraints", i, "body_b"));
  }
  for (std::size_t i = 0; i < s.effects.size(); ++i) {
    auto& e = s.effects[i];
    if (e.type == EffectType::SpringDamper || e.type == EffectType::Bushing) {
      f(e.body_a, "effect " + e.name + ": body_a", at("effects", i, "body_a"));
      f(e.body_b, "effect " + e.name + ": body_b", at("effects", i, "body_b"));
    } else if (e.type == EffectType::BodyForce) {
      f(e.body_a, "effect " + e.name + ": body", at("effects", i, "body"));
    } else if (e.type == EffectType::Tire) {
      f(e.body_a, "effect " + e.name + ": body", at("effects", i, "body"));
      if (e.road.body != kGroundName) f(e.road.body, "effect " + e.name + ": road body", at("effects", i, "road/body"));
    }
  }
  for (std::size_t i = 0; i < s.actuators.size(); ++i) {
    auto& a = s.actuators[i];
    if (a.type == ActuatorType::BodyForce || a.type == ActuatorType::BodyTorque)
      f(a.body, "actuator " + a.name + ": body", at("actuators", i, "body"));
    if (a.type == ActuatorType::LineForce) {
      f(a.body_a, "actuator " + a.name + ": body_a", at("actuators", i, "body_a"));
      f(a.body_b, "actuator " + a.name + ": body_b", at("actuators", i, "body_b"));
    }
  }
  for (std::size_t i = 0; i < s.sensors.size(); ++i) {
    auto& x = s.sensors[i];
    switch (x.type) {
      case SensorType::PointPosition:
      case SensorType::PointVelocity:
      case SensorType::AngularVelocity:
      case SensorType::Acceleration:
        f(x.body, "sensor " + x.name + ": body", at("sensors", i, "body"));
        f(x.frame, "sensor " + x.name + ": frame", at("sensors", i, "frame"));
        break;
      case SensorType::BodyAngle: f(x.body, "sensor " + x.name + ": body", at("sensors", i, "body")); break;
      case SensorType::Distance:
      case SensorType::DistanceRate:
        f(x.body_a, "sensor " + x.name + ": body_a", at("sensors", i, "body_a"));
        f(x.body_b, "sensor " + x.name + ": body_b", at("sensors", i, "body_b"));
        break;
      default: break;
    }
  }
}

// the same for every field that names a joint
template <class F>
void for_each_joint_ref(ModelSpec& s, F&& f) {
  for (std::size_t i = 0; i < s.constraints.size(); ++i) {
    auto& c = s.constraints[i];
    if (c.type == ConstraintType::Coupler) {
      f(c.joint_a, "constraint " + c.name + ": joint_a", at("constraints", i, "joint_a"));
      f(c.joint_b, "constraint " + c.name + ": joint_b", at("constraints", i, "joint_b"));
      if (!c.joint_c.empty()) f(c.joint_c, "constraint " + c.name + ": joint_c", at("constraints", i, "joint_c"));
    }
  }
  for (std::size_t i = 0; i < s.effects.size(); ++i) {
    auto& e = s.effects[i];
    if (e.type == EffectType::JointSpringDamper || e.type == EffectType::JointFriction || e.type == EffectType::JointDamper)
      f(e.joint, "effect " + e.name + ": joint", at("effects", i, "joint"));
  }
  for (std::size_t i = 0; i < s.actuators.size(); ++i)
    if (s.actuators[i].type == ActuatorType::JointForce || s.actuators[i].type == ActuatorType::Motion)
      f(s.actuators[i].joint, "actuator " + s.actuators[i].name + ": joint", at("actuators", i, "joint"));
  for (std::size_t i = 0; i < s.sensors.size(); ++i) {
    auto& x = s.sensors[i];
    if (x.type == SensorType::JointPosition || x.type == SensorType::JointVelocity || x.type == SensorType::MotionForce)
      f(x.joint, "sensor " + x.name + ": joint", at("sensors", i, "joint"));
  }
}

}  // namespace

const char* to_string(ElementKind k) {
  switch (k) {
    case ElementKind::Body: return "body";
    case ElementKind::Joint: return "joint";
    case ElementKind::Constraint: return "constraint";
    case ElementKind::Effect: return "effect";
    case ElementKind::Actuator: return "actuator";
    case ElementKind::Sensor: return "sensor";
  }
  return "?";
}

const char* section_of(ElementKind k) {
  switch (k) {
    case ElementKind::Body: return "bodies";
    case ElementKind::Joint: return "joints";
    case ElementKind::Constraint: return "constraints";
    case ElementKind::Effect: return "effects";
    case ElementKind::Actuator: return "actuators";
    case ElementKind::Sensor: return "sensors";
  }
  return "?";
}

std::optional<ElementKind> kind_of_section(const std::string& section) {
  for (ElementKind k : kElementKinds)
    if (section == section_of(k)) return k;
  return std::nullopt;
}

int element_count(const ModelSpec& s, ElementKind k) {
  return visit_list(s, k, [](const auto& v) { return static_cast<int>(v.size()); });
}

const std::string& element_name(const ModelSpec& s, ElementKind k, int i) {
  check_index(s, k, i);
  return visit_list(s, k, [i](const auto& v) -> const std::string& { return v[i].name; });
}

std::vector<std::string> element_names(const ModelSpec& s, ElementKind k) {
  return visit_list(s, k, [](const auto& v) {
    std::vector<std::string> n;
    for (const auto& e : v) n.push_back(e.name);
    return n;
  });
}

int find_element(const ModelSpec& s, ElementKind k, const std::string& name) {
  const auto names = element_names(s, k);
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

std::string unique_name(const ModelSpec& s, ElementKind k, const std::string& base) {
  auto taken = [&](const std::string& n) { return find_element(s, k, n) >= 0 || (k == ElementKind::Body && n == kGroundName); };
  if (!taken(base)) return base;
  for (int i = 2;; ++i)
    if (!taken(base + "_" + std::to_string(i))) return base + "_" + std::to_string(i);
}

std::optional<ElementRef> element_at_path(const std::string& path) {
  // "/section/index[/field...]"
  if (path.size() < 2 || path[0] != '/') return std::nullopt;
  const auto a = path.find('/', 1);
  if (a == std::string::npos) return std::nullopt;
  const auto kind = kind_of_section(path.substr(1, a - 1));
  if (!kind) return std::nullopt;
  const auto b = path.find('/', a + 1);
  const std::string idx = path.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1);
  if (idx.empty() || !std::all_of(idx.begin(), idx.end(), [](char c) { return c >= '0' && c <= '9'; }) || idx.size() > 9)
    return std::nullopt;
  ElementRef r{*kind, std::stoi(idx), b == std::string::npos ? std::string() : path.substr(b + 1)};
  return r;
}

std::vector<std::string> references_to(const ModelSpec& spec, ElementKind k, const std::string& name) {
  ModelSpec s = spec;  // the visitors take mutable references; nothing is changed
  std::vector<std::string> out;
  auto collect = [&](std::string& ref, const std::string& where, const std::string&) {
    if (ref == name) out.push_back(where);
  };
  switch (k) {
    case ElementKind::Body: for_each_body_ref(s, collect); break;
    case ElementKind::Joint:
      for_each_joint_ref(s, collect);
      for (const auto& [n, v] : s.analysis.set)
        if (names_coordinate_of(n, name)) out.push_back("analysis: coordinate set " + n);
      for (const auto& n : s.analysis.independent)
        if (names_coordinate_of(n, name)) out.push_back("analysis: independent coordinate " + n);
      break;
    case ElementKind::Actuator:
      if (std::count(s.plant.inputs.begin(), s.plant.inputs.end(), name)) out.push_back("Plant/In");
      for (const auto& a : s.actuators)
        if (std::count(a.drives.begin(), a.drives.end(), name)) out.push_back("actuator " + a.name + ": drives");
      break;
    case ElementKind::Sensor:
      if (std::count(s.plant.outputs.begin(), s.plant.outputs.end(), name)) out.push_back("Plant/Out");
      break;
    case ElementKind::Effect:
      if (std::count(s.analysis.disabled_effects.begin(), s.analysis.disabled_effects.end(), name))
        out.push_back("analysis: disabled effects");
      for (const auto& x : s.sensors)
        if (x.type == SensorType::Tire && x.tire == name) out.push_back("sensor " + x.name + ": tire");
      break;
    case ElementKind::Constraint: break;
  }
  return out;
}

std::vector<ReferenceField> reference_fields(const ModelSpec& spec) {
  ModelSpec s = spec;  // the visitors take mutable references; nothing is changed
  std::vector<ReferenceField> out;
  for_each_body_ref(s, [&](std::string& ref, const std::string&, const std::string& path) {
    out.push_back({ElementKind::Body, ref, path});
  });
  for_each_joint_ref(s, [&](std::string& ref, const std::string&, const std::string& path) {
    out.push_back({ElementKind::Joint, ref, path});
  });
  for (std::size_t i = 0; i < s.actuators.size(); ++i)
    for (std::size_t k = 0; k < s.actuators[i].drives.size(); ++k)
      out.push_back({ElementKind::Actuator, s.actuators[i].drives[k], at("actuators", i, "drives") + "/" + std::to_string(k)});
  for (std::size_t i = 0; i < s.sensors.size(); ++i)
    if (s.sensors[i].type == SensorType::Tire) out.push_back({ElementKind::Effect, s.sensors[i].tire, at("sensors", i, "tire")});
  for (std::size_t k = 0; k < s.plant.inputs.size(); ++k)
    out.push_back({ElementKind::Actuator, s.plant.inputs[k], "/plant/inputs/" + std::to_string(k)});
  for (std::size_t k = 0; k < s.plant.outputs.size(); ++k)
    out.push_back({ElementKind::Sensor, s.plant.outputs[k], "/plant/outputs/" + std::to_string(k)});
  return out;
}

void rename_element(ModelSpec& s, ElementKind k, int index, const std::string& now) {
  check_index(s, k, index);
  const std::string old = element_name(s, k, index);
  if (now == old) return;
  if (now.empty()) throw std::invalid_argument(std::string("a ") + to_string(k) + " needs a name");
  if (k == ElementKind::Body && now == kGroundName) throw std::invalid_argument("\"ground\" is the name of the fixed world body");
  if (find_element(s, k, now) >= 0)
    throw std::invalid_argument(std::string("another ") + to_string(k) + " is already named \"" + now + "\"");
  auto swap = [&](std::string& ref, const std::string&, const std::string&) {
    if (ref == old) ref = now;
  };
  switch (k) {
    case ElementKind::Body: for_each_body_ref(s, swap); break;
    case ElementKind::Joint:
      for_each_joint_ref(s, swap);
      for (auto& [n, v] : s.analysis.set) n = renamed_coordinate(n, old, now);
      for (auto& n : s.analysis.independent) n = renamed_coordinate(n, old, now);
      break;
    case ElementKind::Actuator:
      std::replace(s.plant.inputs.begin(), s.plant.inputs.end(), old, now);
      for (auto& a : s.actuators) std::replace(a.drives.begin(), a.drives.end(), old, now);
      break;
    case ElementKind::Sensor: std::replace(s.plant.outputs.begin(), s.plant.outputs.end(), old, now); break;
    case ElementKind::Effect:
      std::replace(s.analysis.disabled_effects.begin(), s.analysis.disabled_effects.end(), old, now);
      for (auto& x : s.sensors)
        if (x.type == SensorType::Tire && x.tire == old) x.tire = now;
      break;
    case ElementKind::Constraint: break;
  }
  visit_list(s, k, [&](auto& v) { v[index].name = now; });
}

std::string default_name(ElementKind k, const std::string& type) {
  static const std::map<std::string, std::string> effects = {
      {"gravity", "gravity"}, {"spring_damper", "spring"}, {"joint_spring_damper", "joint_spring"},
      {"joint_friction", "friction"}, {"joint_damper", "damper"}, {"body_force", "load"}, {"bushing", "bushing"},
      {"tire", "tire"}};
  static const std::map<std::string, std::string> actuators = {
      {"joint_force", "motor"}, {"body_force", "force"}, {"body_torque", "torque"},
      {"line_force", "strut"},  {"mix", "mix"},          {"motion", "motion"}};
  static const std::map<std::string, std::string> sensors = {
      {"joint_position", "sensor"}, {"joint_velocity", "rate"},     {"point_position", "position"},
      {"point_velocity", "velocity"}, {"body_angle", "angle"},       {"distance", "distance"},
      {"distance_rate", "distance_rate"}, {"motion_force", "motion_force"}, {"angular_velocity", "rate_gyro"},
      {"acceleration", "accelerometer"}, {"tire", "tire_sensor"}};
  auto from = [&](const std::map<std::string, std::string>& m, const char* fallback) {
    const auto it = m.find(type);
    return it == m.end() ? std::string(fallback) : it->second;
  };
  switch (k) {
    case ElementKind::Body: return "body";
    case ElementKind::Joint: return "joint";
    case ElementKind::Constraint: return "closure";
    case ElementKind::Effect: return from(effects, "effect");
    case ElementKind::Actuator: return from(actuators, "actuator");
    case ElementKind::Sensor: return from(sensors, "sensor");
  }
  return "element";
}

bool is_default_name(ElementKind k, const std::string& type, const std::string& name) {
  const std::string base = default_name(k, type);
  if (name == base) return true;
  if (name.size() <= base.size() + 1 || name.compare(0, base.size(), base) != 0 || name[base.size()] != '_') return false;
  const std::string n = name.substr(base.size() + 1);
  return n.size() < 6 && std::all_of(n.begin(), n.end(), [](char c) { return c >= '0' && c <= '9'; }) && n[0] != '0';
}

std::string element_type(const ModelSpec& s, ElementKind k, int i) {
  check_index(s, k, i);
  switch (k) {
    case ElementKind::Body: return "";
    case ElementKind::Joint: return to_string(s.joints[i].type);
    case ElementKind::Constraint: return to_string(s.constraints[i].type);
    case ElementKind::Effect: return to_string(s.effects[i].type);
    case ElementKind::Actuator: return to_string(s.actuators[i].type);
    case ElementKind::Sensor: return to_string(s.sensors[i].type);
  }
  return "";
}

int add_element(ModelSpec& s, ElementKind k) {
  switch (k) {
    case ElementKind::Body: {
      BodySpec b;
      b.name = unique_name(s, k, "body");
      b.mass = 1.0;
      b.inertia = Eigen::Matrix3d::Identity() * 0.01;
      s.bodies.push_back(b);
      break;
    }
    case ElementKind::Joint: {
      JointSpec j;
      j.name = unique_name(s, k, "joint");
      j.parent = kGroundName;
      j.child = s.bodies.empty() ? std::string() : s.bodies.back().name;
      s.joints.push_back(j);
      break;
    }
    case ElementKind::Constraint: {
      ConstraintSpec c;
      c.name = unique_name(s, k, "closure");
      c.body_a = kGroundName;
      c.body_b = s.bodies.empty() ? std::string(kGroundName) : s.bodies.back().name;
      s.constraints.push_back(c);
      break;
    }
    case ElementKind::Effect: {
      // gravity once; after it, what a model gets most: a spring-damper (a second gravity would be
      // an error the moment it is added)
      EffectSpec e;
      const bool has_gravity = std::any_of(s.effects.begin(), s.effects.end(), [](const EffectSpec& x) { return x.type == EffectType::Gravity; });
      if (has_gravity) {
        e.type = EffectType::SpringDamper;
        e.body_a = kGroundName;
        e.body_b = s.bodies.empty() ? std::string() : s.bodies.back().name;
      }
      e.name = unique_name(s, k, default_name(k, to_string(e.type)));
      s.effects.push_back(e);
      break;
    }
    case ElementKind::Actuator: {
      ActuatorSpec a;
      a.name = unique_name(s, k, "motor");
      a.joint = s.joints.empty() ? std::string() : s.joints.front().name;
      s.actuators.push_back(a);
      break;
    }
    case ElementKind::Sensor: {
      SensorSpec x;
      x.name = unique_name(s, k, "sensor");
      x.joint = s.joints.empty() ? std::string() : s.joints.front().name;
      s.sensors.push_back(x);
      break;
    }
  }
  return element_count(s, k) - 1;
}

int duplicate_element(ModelSpec& s, ElementKind k, int index) {
  check_index(s, k, index);
  const std::string name = unique_name(s, k, element_name(s, k, index) + "_copy");
  visit_list(s, k, [&](auto& v) {
    auto copy = v[index];
    copy.name = name;
    v.push_back(copy);
  });
  return element_count(s, k) - 1;
}

void remove_element(ModelSpec& s, ElementKind k, int index) {
  check_index(s, k, index);
  const std::string name = element_name(s, k, index);
  auto drop = [&](std::vector<std::string>& list) { list.erase(std::remove(list.begin(), list.end(), name), list.end()); };
  if (k == ElementKind::Actuator) drop(s.plant.inputs);
  if (k == ElementKind::Sensor) drop(s.plant.outputs);
  if (k == ElementKind::Effect) drop(s.analysis.disabled_effects);
  visit_list(s, k, [&](auto& v) { v.erase(v.begin() + index); });
}

}  // namespace codyna
