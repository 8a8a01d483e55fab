#include "gui/property_editor.hpp"

#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QLabel>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QMenu>
#include <QPushButton>
#include <QLocale>
#include <QRegularExpression>
#include <QScrollArea>
#include <QVBoxLayout>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <nlohmann/json.hpp>

#include "study/files.hpp"
#include "model/errors.hpp"

namespace codyna::gui {

using nlohmann::json;

namespace {

const QStringList kBodyRefs{"parent", "child", "body", "body_a", "body_b", "frame"};
// a magic_formula tire's side as its .tir file says (the field left out)
const QString kAsTheFile = QStringLiteral("as the file");

QStringList type_names(ElementKind k) {
  switch (k) {
    case ElementKind::Joint: return {"revolute", "prismatic", "fixed", "spherical", "universal", "cylindrical", "planar", "free"};
    case ElementKind::Constraint: return {"ball", "revolute", "planar_revolute", "coupler", "rolling_ball", "rolling_disc"};
    case ElementKind::Effect:
      return {"gravity", "spring_damper", "joint_spring_damper", "joint_friction", "joint_damper", "body_force", "bushing", "tire"};
    case ElementKind::Actuator: return {"joint_force", "body_force", "body_torque", "line_force", "mix", "motion"};
    case ElementKind::Sensor:
      return {"joint_position", "joint_velocity", "point_position", "point_velocity", "body_angle", "distance", "distance_rate", "motion_force",
              "angular_velocity", "acceleration", "tire"};
    default: return {};
  }
}

// numbers as the model file writes them (shortest text that reads back exactly)
QString number_text(const json& v) { return QString::fromStdString(v.dump()); }

bool is_number_array(const json& v) {
  return v.is_array() && !v.empty() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_number(); });
}
bool is_matrix(const json& v) {
  return v.is_array() && !v.empty() && std::all_of(v.begin(), v.end(), [](const json& e) { return is_number_array(e); });
}

QString value_text(const json& v) {
  if (v.is_number()) return number_text(v);
  if (v.is_string()) return QString::fromStdString(v.get<std::string>());
  if (is_number_array(v)) {
    QStringList l;
    for (const auto& e : v) l << number_text(e);
    return l.join(", ");
  }
  if (v.is_array() && !v.empty() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_string(); })) {
    QStringList l;  // names (a mix's drives): "motor, jet"
    for (const auto& e : v) l << QString::fromStdString(e.get<std::string>());
    return l.join(", ");
  }
  if (is_matrix(v)) {
    QStringList rows;
    for (const auto& r : v) rows << value_text(r);
    return rows.join("; ");
  }
  return QString::fromStdString(v.dump());
}

// reads what the user typed, in the shape of the old value
json parse_text(const QString& text, const json& old) {
  const QString t = text.trimmed();
  auto number = [](const QString& s) -> json {
    bool ok = false;
    const double x = QLocale::c().toDouble(s.trimmed(), &ok);
    // inf, nan and numbers beyond double's range (1e400) are no values a model can hold
    if (!ok || !std::isfinite(x)) throw std::invalid_argument("\"" + s.trimmed().toStdString() + "\" is not a finite number");
    return x;
  };
  auto numbers = [&](const QString& s) {
    json a = json::array();
    for (const QString& p : s.split(QRegularExpression("[,\\s]+"), Qt::SkipEmptyParts)) a.push_back(number(p));
    return a;
  };
  if (old.is_number()) return number(t);
  if (old.is_string()) return t.toStdString();
  if (is_matrix(old)) {
    json m = json::array();
    for (const QString& r : t.split(';', Qt::SkipEmptyParts)) m.push_back(numbers(r));
    return m;
  }
  if (old.is_array() && !old.empty() && std::all_of(old.begin(), old.end(), [](const json& e) { return e.is_string(); })) {
    json a = json::array();
    for (const QString& p : t.split(',', Qt::SkipEmptyParts)) a.push_back(p.trimmed().toStdString());
    return a;
  }
  if (is_number_array(old) || (old.is_array() && old.empty())) return numbers(t);
  return json::parse(t.toStdString());  // objects, lists of objects: JSON text
}

// sets /a/b/c in j
void set_at(json& j, const QString& path, json value) { j[json::json_pointer(path.toStdString())] = std::move(value); }

// A rotation is shown and typed as roll, pitch, yaw in degrees (R = Rz(yaw) Ry(pitch) Rx(roll),
// the reader's "rpy"), whatever form the file holds.
bool is_rotation_key(const QString& key) { return key.section('/', -1) == QLatin1String("rotation"); }

QString rotation_text(const json& v) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (v.is_object() && v.contains("matrix") && is_matrix(v["matrix"]) && v["matrix"].size() == 3) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3 && c < static_cast<int>(v["matrix"][r].size()); ++c) R(r, c) = v["matrix"][r][c].get<double>();
  }
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  QStringList l;
  for (double a : {roll, pitch, yaw}) {
    double deg = a * 180.0 / std::numbers::pi;
    if (std::abs(deg) < 1e-12) deg = 0.0;
    l << QString::number(deg, 'g', 15);
  }
  return l.join(", ");
}

json rotation_value(const QString& text) {
  const QStringList parts = text.split(QRegularExpression("[,\\s]+"), Qt::SkipEmptyParts);
  if (parts.size() != 3) throw std::invalid_argument("expected roll, pitch, yaw in degrees (three numbers)");
  json rpy = json::array();
  for (const QString& p : parts) {
    bool ok = false;
    const double d = QLocale::c().toDouble(p, &ok);
    if (!ok || !std::isfinite(d)) throw std::invalid_argument("\"" + p.toStdString() + "\" is not a finite number");
    rpy.push_back(d * std::numbers::pi / 180.0);
  }
  return json{{"rpy", rpy}};
}

// A tire's numbers that may be left out: a magic_formula tire takes them from its .tir file, a
// rolling radius left out is the unloaded radius
const QStringList kTireOptional{"unloaded_radius", "rolling_radius", "vertical_stiffness", "vertical_damping"};

bool is_tire(const ModelSpec& spec, ElementKind k, int index) {
  return k == ElementKind::Effect && index >= 0 && index < static_cast<int>(spec.effects.size()) &&
         spec.effects[static_cast<std::size_t>(index)].type == EffectType::Tire;
}

// Fields that are empty by default (a number that may be left out: an actuator's limits, a tire's
// radius or vertical stiffness given by its .tir file)
bool is_clearable(ElementKind k, const QString& key, bool tire = false) {
  return (k == ElementKind::Actuator && (key == QLatin1String("min") || key == QLatin1String("max"))) ||
         (k == ElementKind::Constraint && key == QLatin1String("offset")) || (tire && kTireOptional.contains(key));
}

// A tire element's first numbers for its law, given where the element has none (a new tire, or
// its law changed): a passenger car's tire of 0.3 m on a linear or Fiala law; a magic_formula tire
// takes its radius and vertical stiffness from the .tir file, so the fields that would override
// them are dropped (its `file` is chosen next, in the file dialog)
// (the same first numbers as PropertyEditor::firstTire)
void give_tire_law_numbers(json& e) {
  if (!e.is_object()) return;
  const std::string law = e.contains("law") && e["law"].is_string() ? e["law"].get<std::string>() : "linear";
  auto positive = [&](const char* key) { return e.contains(key) && e[key].is_number() && e[key].get<double>() > 0; };
  if (law == "magic_formula") {
    for (const char* key : {"unloaded_radius", "vertical_stiffness", "vertical_damping"}) e.erase(key);
    return;
  }
  EffectSpec first;
  PropertyEditor::firstTire(first);
  if (!positive("unloaded_radius")) e["unloaded_radius"] = *first.unloaded_radius;
  if (!positive("vertical_stiffness")) e["vertical_stiffness"] = *first.vertical_stiffness;
  if (!e.contains("vertical_damping")) e["vertical_damping"] = *first.vertical_damping;
  // Fiala's stiffnesses and friction must be positive; a linear tire keeps a 0 it was given
  const bool fiala = law == "fiala";
  if (fiala ? !positive("longitudinal_stiffness") : !e.contains("longitudinal_stiffness"))
    e["longitudinal_stiffness"] = first.longitudinal_stiffness;
  if (fiala ? !positive("cornering_stiffness") : !e.contains("cornering_stiffness")) e["cornering_stiffness"] = first.cornering_stiffness;
  if (fiala && !positive("friction")) e["friction"] = 1.0;
}

// The element as the editor shows it: what the model file writes, and every optional
// field the reader takes for its type that the file leaves out while it holds its
// default (a joint's q0 and v0, units, an actuator's limits, a body's shape list).
json shown_element(const ModelSpec& spec, ElementKind k, int index) {
  json e = study_model_json(spec)[section_of(k)][index];
  switch (k) {
    case ElementKind::Joint: {
      const JointSpec& jt = spec.joints[index];
      if (!e.contains("q0")) {
        json q = json::array();
        const int nq = joint_nq(jt.type);
        const int iq = jt.type == JointType::Spherical ? 0 : jt.type == JointType::Free ? 3 : -1;
        for (int i = 0; i < nq; ++i) q.push_back(i == iq ? 1.0 : 0.0);
        if (nq > 0) e["q0"] = q;
      }
      if (!e.contains("v0") && joint_nv(jt.type) > 0) e["v0"] = json(std::vector<double>(joint_nv(jt.type), 0.0));
      if (!e.contains("armature") && joint_nv(jt.type) > 0) e["armature"] = 0.0;  // none: one value, every coordinate
      break;
    }
    case ElementKind::Body:
      if (!e.contains("com")) e["com"] = json{0.0, 0.0, 0.0};
      if (!e.contains("shapes")) e["shapes"] = json::array();
      break;
    case ElementKind::Actuator:
      for (const char* key : {"min", "max"})
        if (!e.contains(key)) e[key] = nullptr;
      if (!e.contains("unit")) e["unit"] = "";
      break;
    case ElementKind::Sensor:
      if (!e.contains("unit")) e["unit"] = "";
      break;
    case ElementKind::Effect:
      if (spec.effects[static_cast<std::size_t>(index)].type == EffectType::Tire) {
        // the numbers a .tir file gives (or that have a default) as "none" until typed
        for (const QString& key : kTireOptional)
          if (!e.contains(ss(key))) e[ss(key)] = nullptr;
        if (spec.effects[static_cast<std::size_t>(index)].law == "magic_formula") {
          if (!e.contains("side")) e["side"] = "";
          if (!e.contains("file")) e["file"] = "";
        }
      }
      break;
    case ElementKind::Constraint:
      if (spec.constraints[index].type == ConstraintType::Coupler) {
        if (!e.contains("joint_c")) e["joint_c"] = "";
        if (!e.contains("ratio_c")) e["ratio_c"] = 0.0;
        if (!e.contains("offset")) e["offset"] = nullptr;
      }
      break;
    default: break;
  }
  return e;
}

}  // namespace

QString PropertyEditor::fieldHelp(ElementKind kind, const QString& key, const QString& unit, const QString& type) {
  // a rolling ball's fields mean what they are for it: a plane on body_a, a ball on body_b
  if (kind == ElementKind::Constraint && type == QLatin1String("rolling_ball")) {
    static const std::map<QString, QString> rolling{
        {"body_a", "The body that carries the plane the ball rolls on"},
        {"point_a", "A point of the plane, on the first body, in its frame"},
        {"axis_a", "Normal of the plane, on the first body, in its frame (the ball is on the side it points to)"},
        {"body_b", "The ball's body"},
        {"point_b", "Centre of the ball, on the second body, in its frame"},
    };
    if (key == QLatin1String("radius")) return QStringLiteral("Radius of the rolling ball (m, > 0)");
    const auto r = rolling.find(key);
    if (r != rolling.end()) return unit.isEmpty() ? r->second : QStringLiteral("%1 [%2]").arg(r->second, unit);
  }
  // a rolling disc's: a plane on body_a, a disc (a wheel, a coin) on body_b about its axle axis_b
  if (kind == ElementKind::Constraint && type == QLatin1String("rolling_disc")) {
    static const std::map<QString, QString> rolling{
        {"body_a", "The body that carries the plane the disc rolls on"},
        {"point_a", "A point of the plane, on the first body, in its frame"},
        {"axis_a", "Normal of the plane, on the first body, in its frame (the disc is on the side it points to)"},
        {"body_b", "The disc's body"},
        {"point_b", "Centre of the disc, on the second body, in its frame"},
        {"axis_b", "The disc's axle, on the second body, in its frame (not along the plane's normal: the disc "
                   "would lie flat)"},
    };
    if (key == QLatin1String("radius")) return QStringLiteral("Radius of the rolling disc (m, > 0)");
    const auto r = rolling.find(key);
    if (r != rolling.end()) return unit.isEmpty() ? r->second : QStringLiteral("%1 [%2]").arg(r->second, unit);
  }
  // a tire's fields (docs/model-format.md, "Tires"; docs/tires.md: ISO-W axes)
  if (kind == ElementKind::Effect && type == QLatin1String("tire")) {
    static const std::map<QString, QString> tire{
        {"body", "The wheel body the tire is on (not the ground)"},
        {"center", "The wheel centre, in the wheel body's frame"},
        {"spin_axis", "The axle, in the wheel body's frame, pointing to the wheel's left (rolling forward is a "
                      "positive spin about it)"},
        {"unloaded_radius", "Radius of the unloaded tire (> 0; a magic_formula tire takes the .tir file's)"},
        {"rolling_radius", "Effective rolling radius Re in the longitudinal slip (empty: the unloaded radius)"},
        {"law", "The force law: linear (stiffnesses), fiala (the brush model) or magic_formula (a .tir file)"},
        {"file", "The .tir property file (MF 5.2, 6.1, 6.2), relative to the model file"},
        {"side", "The side of the car the tire is on; a file made for the other side is mirrored"},
        {"longitudinal_stiffness", "Longitudinal slip stiffness: Fx per unit slip kappa (>= 0; fiala > 0)"},
        {"cornering_stiffness", "Cornering stiffness: Fy = -C alpha (ISO-W; >= 0; fiala > 0)"},
        {"camber_stiffness", "Camber stiffness (linear)"},
        {"friction", "Friction coefficient: linear, the friction circle's mu (0: none); fiala, mu at zero slip"},
        {"sliding_friction", "Fiala: mu at full slip (0: the friction)"},
        {"trail", "Linear: pneumatic trail, Mz = -trail Fy"},
        {"width", "Fiala: tread width, for the aligning moment"},
        {"rolling_resistance", "Fiala: My = -rolling_resistance Fz sign(Omega)"},
        {"vertical_stiffness", "Vertical stiffness: Fz = k deflection + c rate (>= 0; magic_formula: the .tir "
                               "file's when it gives one)"},
        {"vertical_damping", "Vertical damping (>= 0; magic_formula: the .tir file's when it gives one)"},
        {"low_speed", "Below this forward speed the slips' denominator is regularized (> 0)"},
        {"longitudinal_relaxation_length", "Transient slip: the longitudinal slip builds up over this rolled distance "
                                           "(a state per tire; 0: at once)"},
        {"lateral_relaxation_length", "Transient slip: the slip angle builds up over this rolled distance (a state per "
                                      "tire; 0: at once)"},
        {"road/body", "The body that carries the road plane (ground: the world)"},
        {"road/point", "A point of the road plane, in its body's frame"},
        {"road/normal", "The road's normal, in its body's frame (the wheel rolls on the side it points to)"},
    };
    const auto r = tire.find(key);
    if (r != tire.end()) return unit.isEmpty() ? r->second : QStringLiteral("%1 [%2]").arg(r->second, unit);
  }
  static const std::map<QString, QString> meaning{
      {"name", "The element's name; references to it follow a rename"},
      {"type", "The element's type; fields the new type does not take are dropped"},
      {"mass", "Mass of the body (>= 0)"},
      {"com", "Centre of mass in the body frame (x, y, z)"},
      {"inertia", "Inertia about the centre of mass, body axes: Ixx, Iyy, Izz[, Ixy, Ixz, Iyz]"},
      {"parent", "The body the joint is fixed on (ground: the world)"},
      {"child", "The body the joint moves"},
      {"position", "Origin of the frame (x, y, z)"},
      {"rotation", "Orientation of the frame: roll, pitch, yaw about x, y, z (R = Rz Ry Rx)"},
      {"axis", "Axis in the joint frame (normalized when read)"},
      {"axis2", "Second axis of a universal joint"},
      {"q0", "Initial joint coordinates (rad for rotations, m for translations; quaternion w, x, y, z for ball joints)"},
      {"v0", "Initial joint rates (rad/s, m/s)"},
      {"armature", "Rotor inertia on the joint's coordinates, added to the mass matrix's diagonal (>= 0; one value for "
                   "every coordinate, or one per coordinate)"},
      {"g", "Gravity acceleration vector (x, y, z)"},
      {"stiffness", "Spring stiffness"},
      {"damping", "Damping coefficient"},
      {"rest_length", "Length at which the spring exerts no force"},
      {"rest_position", "Joint coordinate at which the spring exerts no torque or force"},
      {"joint", "The joint it acts on or measures"},
      {"dof", "Which coordinate of a joint with several (0 = the first)"},
      {"body", "The body it acts on or measures"},
      {"body_a", "First body"},
      {"body_b", "Second body"},
      {"point", "Point in the body frame"},
      {"point_a", "Point on the first body, in its frame"},
      {"point_b", "Point on the second body, in its frame"},
      {"force", "Force vector"},
      {"torque", "Torque vector"},
      {"direction", "Direction of the force or torque"},
      {"frame", "Frame the vectors are given in"},
      {"gain", "Effort per unit of the plant input (effort = gain * u)"},
      {"u0", "Nominal input (used when the actuator is not driven)"},
      {"min", "Lower limit of the input (empty: none)"},
      {"max", "Upper limit of the input (empty: none)"},
      {"unit", "Unit shown with the input or output"},
      {"component", "Which component is measured"},
      {"size", "Box edge lengths x, y, z"},
      {"radius", "Radius"},
      {"length", "Length along the shape frame's z"},
      {"color", "Colour: red, green, blue, alpha in 0..1"},
      {"axis_a", "Axis on the first body, in its frame"},
      {"axis_b", "Axis on the second body, in its frame"},
      {"joint_a", "Coupler: first joint (revolute or prismatic)"},
      {"joint_b", "Coupler: second joint (revolute or prismatic)"},
      {"joint_c", "Coupler: an optional third joint (a differential; empty: none)"},
      {"ratio_a", "Coupler: ratio_a q_a + ratio_b q_b + ratio_c q_c = offset"},
      {"ratio_b", "Coupler: the second joint's ratio (a gear N:1 is ratio_a 1, ratio_b -N)"},
      {"ratio_c", "Coupler: the third joint's ratio (0 without a third joint)"},
      {"offset", "Coupler: the relation's constant (empty: the joints' q0 satisfy it)"},
      {"drives", "Mix: the actuators its input drives, comma-separated"},
      {"frame_a", "Bushing: its frame on the first body (at rest it coincides with frame_b)"},
      {"frame_b", "Bushing: its frame on the second body"},
      {"translational_stiffness", "Bushing: stiffness along frame_a's x, y, z"},
      {"translational_damping", "Bushing: damping along frame_a's x, y, z"},
      {"rotational_stiffness", "Bushing: stiffness about frame_a's x, y, z (small rotations)"},
      {"rotational_damping", "Bushing: damping about frame_a's x, y, z"},
      {"weights", "Mix: each driven actuator's input grows by weight * u"},
  };
  const auto it = meaning.find(key.section('/', -1));
  QString text = it == meaning.end() ? QString(key).replace('/', '.') : it->second;
  if (!unit.isEmpty()) text += QStringLiteral(" [%1]").arg(unit);
  return text;
}

QString PropertyEditor::unitOf(const QString& key) {
  static const std::map<QString, QString> units{
      {"mass", "kg"}, {"inertia", "kg m²"}, {"com", "m"}, {"position", "m"}, {"point", "m"}, {"point_a", "m"},
      {"point_b", "m"}, {"size", "m"}, {"radius", "m"}, {"length", "m"}, {"rest_length", "m"},
      {"stiffness", "N/m | N m/rad"}, {"damping", "N s/m | N m s/rad"}, {"rest_position", "rad | m"},
      {"force", "N"}, {"torque", "N m"}, {"g", "m/s²"}, {"q0", "rad | m"}, {"v0", "rad/s | m/s"}, {"armature", "kg m² | kg"},
      {"rotation", "matrix | axis-angle"}, {"axis", "unit vector"}, {"axis2", "unit vector"}, {"direction", "unit vector"},
      {"color", "rgba 0..1"}, {"center", "m"}, {"spin_axis", "unit vector"}, {"normal", "unit vector"},
      {"unloaded_radius", "m"}, {"rolling_radius", "m"}, {"longitudinal_stiffness", "N"}, {"cornering_stiffness", "N/rad"},
      {"camber_stiffness", "N/rad"}, {"trail", "m"}, {"width", "m"}, {"rolling_resistance", "m"},
      {"vertical_stiffness", "N/m"}, {"vertical_damping", "N s/m"}, {"low_speed", "m/s"},
      {"longitudinal_relaxation_length", "m"}, {"lateral_relaxation_length", "m"}};
  const QString last = key.section('/', -1);
  const auto it = units.find(last);
  return it == units.end() ? QString() : it->second;
}

PropertyEditor::PropertyEditor(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  auto* outer = new QVBoxLayout(this);
  outer->setContentsMargins(4, 4, 4, 4);
  title_ = new QLabel(tr("Select an element in the model tree"), this);
  title_->setWordWrap(true);
  outer->addWidget(title_);
  error_ = new QLabel(this);
  error_->setObjectName("propertyError");
  error_->setWordWrap(true);
  error_->setStyleSheet("QLabel { color: #a00000; background: #ffe8e8; padding: 3px; }");
  error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_->hide();
  auto* scroll = new QScrollArea(this);
  scroll->setWidgetResizable(true);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  body_ = new QWidget;
  form_ = new QFormLayout(body_);
  form_->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  // a long label puts its field on the next line: the dock is narrow, the fields must stay in view
  form_->setRowWrapPolicy(QFormLayout::WrapLongRows);
  scroll->setWidget(body_);
  outer->addWidget(scroll, 1);
  outer->addWidget(error_);
  connect(doc, &Document::specChanged, this, &PropertyEditor::rebuild);
  connect(doc, &Document::errorChanged, this, &PropertyEditor::refreshMarks);
}

void PropertyEditor::setElement(std::optional<ElementId> id) {
  id_ = id;
  marked_.clear();
  refusal_ = {};
  involved_ = {};
  rebuild();
}

void PropertyEditor::firstTire(EffectSpec& e) {
  e.type = EffectType::Tire;
  e.law = "linear";
  e.unloaded_radius = 0.3;
  e.vertical_stiffness = 200000.0;
  e.vertical_damping = 500.0;
  e.longitudinal_stiffness = 100000.0;
  e.cornering_stiffness = 80000.0;
}

// The tire's .tir file chosen in a file dialog (Qt's own, window-modal: the same everywhere, and a
// test drives it as a person does); stored relative to the model file, as the core reads it (an
// unsaved model: the absolute path). The path goes through applyText, so a file that does not read
// is the compile's error at the field, with the reader's message naming the file, section and key.
void PropertyEditor::chooseTireFile() {
  if (!id_ || !is_tire(doc_->spec(), id_->kind, id_->index)) return;
  const ElementId id = *id_;
  const QString model_dir = doc_->filePath().isEmpty() ? QString() : QFileInfo(doc_->filePath()).absolutePath();
  QString start = model_dir.isEmpty() ? QDir::currentPath() : model_dir;
  const std::string now = doc_->spec().effects[static_cast<std::size_t>(id.index)].file;
  if (!now.empty()) {
    const QFileInfo f(QDir(start), qs(now));
    if (f.absoluteDir().exists()) start = f.absoluteFilePath();
  }
  auto* d = new QFileDialog(this, tr("Tire property file"), start, tr("Tire property files (*.tir);;All files (*)"));
  d->setObjectName("tireFileDialog");
  d->setOption(QFileDialog::DontUseNativeDialog);
  d->setFileMode(QFileDialog::ExistingFile);
  d->setAcceptMode(QFileDialog::AcceptOpen);
  d->setAttribute(Qt::WA_DeleteOnClose);
  connect(d, &QFileDialog::fileSelected, this, [this, id, model_dir](const QString& path) {
    if (!id_ || !(*id_ == id) || path.isEmpty()) return;  // another element shown meanwhile
    const QString stored = model_dir.isEmpty() ? QFileInfo(path).absoluteFilePath() : QDir(model_dir).relativeFilePath(path);
    applyText("file", stored);
  });
  d->open();
}

QWidget* PropertyEditor::editorFor(const QString& field) const {
  const auto it = editors_.find(field);
  return it == editors_.end() ? nullptr : it->second;
}

bool PropertyEditor::applyText(const QString& field, const QString& text, QString* error) {
  if (!id_) return false;
  const ModelSpec& spec = doc_->spec();
  if (id_->index >= element_count(spec, id_->kind)) return false;
  auto reject = [&](const QString& why) {
    markField(field, why);
    emit message(why);
    if (error) *error = why;
    return false;
  };
  if (field == "name") {
    QString e;
    if (!doc_->rename(id_->kind, id_->index, text.trimmed(), &e)) return reject(e);
    return true;
  }
  json j = study_model_json(spec);
  const QString base = QStringLiteral("/%1/%2").arg(section_of(id_->kind)).arg(id_->index);
  const json shown = shown_element(spec, id_->kind, id_->index);
  const json::json_pointer at(("/" + field).toStdString());
  const json old = shown.contains(at) ? shown[at] : json();
  json value;
  bool clear = false;
  const bool tire = is_tire(spec, id_->kind, id_->index);
  try {
    if (is_rotation_key(field)) value = rotation_value(text);
    else if (is_clearable(id_->kind, field, tire) && text.trimmed().isEmpty()) clear = true;
    else if (tire && field == QLatin1String("side") && (text.trimmed().isEmpty() || text == kAsTheFile)) clear = true;
    else if (old.is_null() && is_clearable(id_->kind, field, tire)) value = parse_text(text, json(0.0));
    else if (field == QLatin1String("armature")) value = parse_text(text, json::array());  // one value, or one per coordinate
    else value = parse_text(text, old);
  } catch (const std::exception& e) {
    return reject(tr("%1: %2").arg(field, qs(e.what())));
  }
  if (clear) {
    json& parent = j[json::json_pointer((base + "/" + field).toStdString()).parent_pointer()];
    if (parent.is_object()) parent.erase(ss(field.section('/', -1)));
  } else {
    set_at(j, base + "/" + field, value);
  }
  // a tire's law changed: its fields as for a type change (the old law's dropped, the new one's given)
  const bool tire_law = tire && field == QLatin1String("law");
  if (field.section('/', -1) == QLatin1String("type") || tire_law) {
    // keep only what the new type accepts: drop the fields the reader calls unknown, and
    // initial values sized for the old type (a joint's q0, v0); give the fields the new type
    // requires and the old one lacked a first value (a coupler's joints: the model's first two;
    // its ratios 1 and -1; a rolling ball's radius 0.05 m), which the user then picks
    for (int tries = 0; tries < 40; ++tries) {
      try {
        study_parse_model(j, ss(doc_->filePath()));
        break;
      } catch (const ModelError& e) {
        const std::string p = e.path();
        if (p == ss(base) && e.kind() == ModelError::Kind::MissingField) {
          const std::string& key = e.field();
          json& element = j[json::json_pointer(p)];
          if (!element.is_object() || element.contains(key)) break;
          if (key.rfind("joint", 0) == 0) {
            const std::size_t nth = key == "joint_b" ? 1 : 0;
            element[key] = nth < spec.joints.size() ? spec.joints[nth].name : std::string();
          } else if (key == "body_a") {
            element[key] = kGroundName;
          } else if (key == "body" || key == "body_b") {
            element[key] = spec.bodies.empty() ? std::string(kGroundName) : spec.bodies.front().name;
          } else if (key == "ratio_a" || key == "ratio_b") {
            element[key] = key == "ratio_a" ? 1.0 : -1.0;
          } else if (key == "drives") {  // a mix: the first other actuator, weight 1
            json names = json::array();
            for (const auto& a : spec.actuators)
              if (a.name != element_name(spec, id_->kind, id_->index) && a.type != ActuatorType::Mix &&
                  a.type != ActuatorType::Motion) {
                names.push_back(a.name);
                break;
              }
            element[key] = names;
          } else if (key == "weights") {
            element[key] = json::array({1.0});
          } else if (key == "radius") {  // a rolling ball or disc: 5 cm
            element[key] = 0.05;
          } else if (key == "law") {  // a tire: linear until another law is picked
            element[key] = "linear";
          } else if (key == "tire" && id_->kind == ElementKind::Sensor) {  // a tire sensor: the first tire
            std::string first;
            for (const auto& e : spec.effects)
              if (e.type == EffectType::Tire && first.empty()) first = e.name;
            element[key] = first;
          } else if (key == "quantity") {
            element[key] = kTireQuantityNames[0];
          } else {
            break;
          }
          continue;
        }
        if (p.rfind(ss(base) + "/", 0) != 0) break;
        const std::string last = p.substr(p.rfind('/') + 1);
        // a field the new type does not know, or one of another tire law than the new one's
        const bool unknown = e.kind() == ModelError::Kind::UnknownField;
        const bool sized = last == "q0" || last == "v0" || last == "armature";
        if (!unknown && !sized) break;
        json& parent = j[json::json_pointer(p).parent_pointer()];
        if (!parent.is_object() || !parent.contains(last)) break;
        parent.erase(last);
      }
    }
    // a rolling disc's axle (axis_b, z when not given, as is the plane's normal axis_a) must not be
    // along the normal, where the disc lies flat: then a direction normal to it
    json& element = j[json::json_pointer(ss(base))];
    if ((id_->kind == ElementKind::Effect && field == QLatin1String("type") && value == json("tire")) || tire_law)
      give_tire_law_numbers(element);
    if (value == json("rolling_disc") && element.is_object()) {
      auto vec = [&](const char* key) {
        const json& a = element.contains(key) ? element[key] : json::array({0.0, 0.0, 1.0});
        return a.is_array() && a.size() == 3 && a[0].is_number() && a[1].is_number() && a[2].is_number()
                   ? Eigen::Vector3d(a[0].get<double>(), a[1].get<double>(), a[2].get<double>())
                   : Eigen::Vector3d::Zero();
      };
      const Eigen::Vector3d n = vec("axis_a"), a = vec("axis_b");
      if (n.norm() > 0 && a.normalized().cross(n.normalized()).norm() < 1e-3) {
        const Eigen::Vector3d u = n.unitOrthogonal();
        element["axis_b"] = json::array({u.x(), u.y(), u.z()});
      }
    }
  }
  ModelSpec next;
  try {
    next = study_parse_model(j, ss(doc_->filePath()));
  } catch (const ModelError& e) {
    const QString p = qs(e.path());
    const QString f = p.startsWith(base + "/") ? p.mid(base.size() + 1) : field;
    markField(f, qs(e.detail()));
    emit message(qs(e.what()));
    if (error) *error = qs(e.what());
    return false;
  }
  const QString what = qs(element_name(spec, id_->kind, id_->index)) + "." + field;
  auto own_issues = [this] {
    QStringList paths;
    for (const Document::Issue& issue : doc_->issues()) {
      const auto ref = element_at_path(ss(issue.path));
      if (ref && id_ && ref->kind == id_->kind && ref->index == id_->index) paths << issue.path;
    }
    return paths;
  };
  const QStringList before = own_issues();
  const ElementId edited = *id_;
  refusal_ = {};
  // a type changed under a name the element got by default ("gravity_2"): the name follows the type
  const std::string old_type = element_type(spec, id_->kind, id_->index);
  const std::string old_name = element_name(spec, id_->kind, id_->index);
  const ElementKind kind = id_->kind;
  const int index = id_->index;
  doc_->edit(tr("Edit %1").arg(what), [&](ModelSpec& s) {
    const StudySpec study = s.analysis;  // the reader gives the same; keep the exact study anyway
    s = next;
    s.analysis = study;
    if (field == QLatin1String("type") && is_default_name(kind, old_type, old_name)) {
      const std::string now = element_type(s, kind, index);
      if (now != old_type && default_name(kind, now) != default_name(kind, old_type))
        rename_element(s, kind, index, unique_name(s, kind, default_name(kind, now)));
    }
  });
  // taken: a refusal marked here before goes (an edit that changes nothing rebuilds nothing); the
  // document's issues on this element stay marked, and when this edit made one appear in another
  // of its fields, the field edited is marked with it (both are involved)
  involved_ = {};
  if (id_ && *id_ == edited) {
    for (const Document::Issue& issue : doc_->issues()) {
      const auto ref = element_at_path(ss(issue.path));
      if (!ref || ref->kind != edited.kind || ref->index != edited.index || before.contains(issue.path)) continue;
      if (qs(ref->field) != field && !qs(ref->field).startsWith(field + "/")) involved_ = {field, issue.detail};
    }
  }
  refreshMarks();
  return true;
}

void PropertyEditor::markField(const QString& field, const QString& message) {
  refusal_ = field.isEmpty() || message.isEmpty() ? std::pair<QString, QString>() : std::pair(field, message);
  applyMarks();
}

// Marks every field that has a problem: a value just refused (refusal_), the document's issues on
// this element, and the field whose edit made a problem appear in another field of it (involved_:
// a joint made its own parent is reported at its child). The reasons, one per line, in the band
// under the fields (under, so that it never pushes a field away from the pointer).
void PropertyEditor::applyMarks() {
  std::vector<std::pair<QString, QString>> marks;
  if (!refusal_.first.isEmpty()) marks.push_back(refusal_);
  if (id_) {
    const auto primary = element_at_path(ss(doc_->errorPath()));
    for (const Document::Issue& issue : doc_->issues()) {
      const auto ref = element_at_path(ss(issue.path));
      // the element's own problems without a field (a body no joint moves) are the Issues panel's
      if (!ref || ref->kind != id_->kind || ref->index != id_->index || ref->field.empty()) continue;
      // the compile's own error with its whole text, as the status bar and messages show it
      const bool is_primary = primary && primary->kind == ref->kind && primary->index == ref->index && primary->field == ref->field;
      if (is_primary) marks.insert(marks.begin() + (refusal_.first.isEmpty() ? 0 : 1), {qs(ref->field), doc_->errorText()});
      else marks.emplace_back(qs(ref->field), issue.detail);
    }
    if (!involved_.first.isEmpty() && marks.size() > (refusal_.first.isEmpty() ? 0u : 1u)) marks.push_back(involved_);
  }
  marked_ = marks.empty() ? QString() : marks.front().first;
  QStringList lines;
  for (const auto& [field, message] : marks) {
    const QString line = field.isEmpty() ? message : QStringLiteral("%1: %2").arg(QString(field).replace('/', '.'), message);
    if (!lines.contains(line)) lines << line;
  }
  error_->setText(lines.join('\n'));
  error_->setVisible(!lines.isEmpty());
  for (auto& [key, w] : editors_) {
    QStringList why;
    for (const auto& [field, message] : marks)
      if (!field.isEmpty() && (key == field || field.startsWith(key + "/"))) why << message;
    w->setStyleSheet(why.isEmpty() ? "" : "background: #ffd0d0;");
    w->setToolTip(why.isEmpty() ? w->property("help").toString() : why.join('\n'));
  }
}

QStringList PropertyEditor::markedFields() const {
  QStringList out;
  for (const auto& [key, w] : editors_)
    if (!w->styleSheet().isEmpty()) out << key;
  return out;
}

QString PropertyEditor::errorText() const { return error_->text(); }

void PropertyEditor::refreshMarks() { applyMarks(); }

// Rebuilds run inside the signals of the very editors they replace (a combo
// box's activated -> applyText -> Document::edit -> specChanged -> rebuild), and
// Qt goes on using the sender after the slot returns (QComboBox emits
// textActivated after activated). So an editor is never deleted here: it is
// cut off from this editor first (so that hiding it, which moves the focus and
// finishes its line edit, edits nothing), hidden, and deleted once control is
// back in the event loop.
void PropertyEditor::retireEditors() {
  while (form_->rowCount() > 0) {
    const QFormLayout::TakeRowResult row = form_->takeRow(0);
    for (QLayoutItem* item : {row.labelItem, row.fieldItem}) {
      if (!item) continue;
      if (QWidget* w = item->widget()) {
        QObject::disconnect(w, nullptr, this, nullptr);
        for (QObject* child : w->findChildren<QObject*>()) QObject::disconnect(child, nullptr, this, nullptr);
        w->hide();
        w->deleteLater();
      }
      delete item;  // the layout item only, not its widget
    }
  }
  editors_.clear();
}

QWidget* PropertyEditor::nameCombo(const QStringList& names, const QString& value, const QString& key) {
  auto* c = new QComboBox;
  c->setEditable(true);
  c->addItems(names);
  // the entry itself when it is one (so that arrow keys step from it), else the text as typed
  const int at = c->findText(value);
  if (at >= 0) c->setCurrentIndex(at);
  else c->setEditText(value);
  // a pick from the list (activated) and typed text confirmed (editingFinished) both apply; the
  // second of the two sees the value already applied and does nothing
  auto apply = [this, c, key] {
    if (isCurrent(key, c) && c->currentText() != c->property("value").toString()) applyText(key, c->currentText());
  };
  connect(c, &QComboBox::activated, this, apply);
  connect(c->lineEdit(), &QLineEdit::editingFinished, this, apply);
  c->setProperty("value", value);
  return c;
}

bool PropertyEditor::isCurrent(const QString& key, const QWidget* editor) const {
  const auto it = editors_.find(key);
  return it != editors_.end() && it->second == editor;
}

void PropertyEditor::rebuild() {
  // the field being edited keeps the keyboard focus in its new editor
  QString focused;
  if (QWidget* f = QApplication::focusWidget()) {
    for (const auto& [key, w] : editors_)
      if (w == f || w->isAncestorOf(f)) focused = key;
  }
  retireEditors();
  error_->clear();
  error_->hide();
  const ModelSpec& spec = doc_->spec();
  if (!id_ || id_->index >= element_count(spec, id_->kind)) {
    title_->setText(tr("Select an element in the model tree"));
    return;
  }
  const json j = shown_element(spec, id_->kind, id_->index);
  title_->setText(QStringLiteral("<b>%1</b> (%2)").arg(qs(element_name(spec, id_->kind, id_->index)).toHtmlEscaped(), to_string(id_->kind)));

  QStringList bodies{QString::fromLatin1(kGroundName)};
  for (const auto& b : spec.bodies) bodies << qs(b.name);
  QStringList joints;
  for (const auto& jt : spec.joints) joints << qs(jt.name);
  const ElementKind kind = id_->kind;
  const int index = id_->index;

  const bool tire = is_tire(spec, kind, index);
  QStringList tires;  // a tire sensor's choices
  for (const auto& e : spec.effects)
    if (e.type == EffectType::Tire) tires << qs(e.name);
  auto add_row = [&](const QString& key, const json& v) {
    QWidget* editor = nullptr;
    QWidget* row = nullptr;  // what the form holds, when not the editor alone
    const QString last = key.section('/', -1);
    const bool shape_type = key.startsWith("shapes/") && last == "type";
    if (v.is_string() && ((tire && (key == QLatin1String("law") || key == QLatin1String("side"))) ||
                          (kind == ElementKind::Sensor && key == QLatin1String("quantity")))) {
      // a tire's law and side, a tire sensor's quantity: picked from their lists (the side: as the
      // .tir file says, or one)
      auto* c = new QComboBox;
      if (key == QLatin1String("law")) {
        for (const char* law : kTireLawNames) c->addItem(QString::fromLatin1(law));
      } else if (key == QLatin1String("quantity")) {
        for (const char* q : kTireQuantityNames) c->addItem(QString::fromLatin1(q));
      } else {
        c->addItems({kAsTheFile, "left", "right"});
      }
      const QString now = qs(v.get<std::string>());
      c->setCurrentIndex(std::max(0, c->findText(now)));
      connect(c, &QComboBox::activated, this, [this, c, key, now] {
        if (isCurrent(key, c) && c->currentText() != (now.isEmpty() ? kAsTheFile : now)) applyText(key, c->currentText());
      });
      editor = c;
    } else if (tire && key == QLatin1String("file") && v.is_string()) {
      // the .tir file: typed (relative to the model file), or chosen in a file dialog with "..."
      auto* e = new QLineEdit(qs(v.get<std::string>()));
      e->setPlaceholderText(tr("a .tir file: choose it with ..."));
      e->setProperty("value", e->text());
      connect(e, &QLineEdit::editingFinished, this, [this, e, key] {
        if (isCurrent(key, e) && e->text() != e->property("value").toString()) applyText(key, e->text());
      });
      auto* browse = new QPushButton(QStringLiteral("..."));
      browse->setObjectName("browse:" + key);
      browse->setToolTip(tr("Choose the tire's .tir property file (stored relative to the model file)"));
      browse->setMaximumWidth(32);
      connect(browse, &QPushButton::clicked, this, [this] { chooseTireFile(); });
      row = new QWidget;
      auto* hl = new QHBoxLayout(row);
      hl->setContentsMargins(0, 0, 0, 0);
      hl->setSpacing(2);
      hl->addWidget(e, 1);
      hl->addWidget(browse);
      editor = e;
    } else if (kind == ElementKind::Sensor && key == QLatin1String("tire") && v.is_string()) {
      // a tire sensor's tire: one of the model's tire effects (or a name typed)
      editor = nameCombo(tires, qs(v.get<std::string>()), key);
    } else if (last == "type") {
      auto* c = new QComboBox;
      c->addItems(shape_type ? QStringList{"box", "cylinder", "sphere"} : type_names(kind));
      c->setCurrentText(qs(v.get<std::string>()));
      connect(c, &QComboBox::activated, this, [this, c, key] {
        if (isCurrent(key, c)) applyText(key, c->currentText());
      });
      editor = c;
    } else if (v.is_string() && (kBodyRefs.contains(last) || last == "joint" || last.startsWith("joint_"))) {
      const bool joint_ref = last == "joint" || last.startsWith("joint_");
      editor = nameCombo(joint_ref ? joints : bodies, qs(v.get<std::string>()), key);
    } else if (v.is_boolean()) {
      auto* c = new QCheckBox;
      c->setChecked(v.get<bool>());
      connect(c, &QCheckBox::toggled, this, [this, c, key](bool on) {
        if (isCurrent(key, c)) applyText(key, on ? "true" : "false");
      });
      editor = c;
    } else {
      QString text;
      if (is_rotation_key(key)) text = rotation_text(v);
      else if (!v.is_null()) text = value_text(v);
      auto* e = new QLineEdit(text);
      e->setCursorPosition(0);  // a long vector shows its first entries, not the tail of its last
      if (v.is_null()) {
        const bool from_file = tire && doc_->spec().effects[static_cast<std::size_t>(index)].law == "magic_formula";
        e->setPlaceholderText(from_file ? tr("from the .tir file")
                              : key == QLatin1String("rolling_radius") ? tr("the unloaded radius")
                                                                       : tr("none"));
      }
      e->setProperty("value", e->text());
      // a number, or a vector's entries, can be varied in a parameter study (the Sweep view)
      if (!is_rotation_key(key) && (v.is_number() || (is_number_array(v) && !v.empty()))) {
        const QString pointer = QStringLiteral("/%1/%2/%3").arg(section_of(kind)).arg(index).arg(key);
        const int entries = v.is_number() ? 0 : static_cast<int>(v.size());
        e->setContextMenuPolicy(Qt::CustomContextMenu);
        connect(e, &QLineEdit::customContextMenuRequested, this, [this, e, pointer, entries](const QPoint& at) {
          QMenu* menu = e->createStandardContextMenu();
          menu->setAttribute(Qt::WA_DeleteOnClose);
          menu->addSeparator();
          if (entries == 0) {
            QAction* a = menu->addAction(tr("Vary in sweep"));
            a->setObjectName("varyInSweep");
            connect(a, &QAction::triggered, this, [this, pointer] { emit varyRequested(pointer); });
          } else {
            for (int k = 0; k < entries; ++k) {
              QAction* a = menu->addAction(tr("Vary in sweep: entry %1").arg(k));
              a->setObjectName(QStringLiteral("varyInSweep:%1").arg(k));
              const QString p = pointer + "/" + QString::number(k);
              connect(a, &QAction::triggered, this, [this, p] { emit varyRequested(p); });
            }
          }
          menu->popup(e->mapToGlobal(at));
        });
      }
      connect(e, &QLineEdit::editingFinished, this, [this, e, key] {
        if (isCurrent(key, e) && e->text() != e->property("value").toString()) applyText(key, e->text());
      });
      editor = e;
    }
    editor->setObjectName("field:" + key);
    editors_[key] = editor;
    const QString unit = is_rotation_key(key) ? tr("deg, roll pitch yaw") : unitOf(key);
    QString label = key;
    label.replace('/', '.');
    editor->setProperty("help", fieldHelp(kind, key, unit, j.contains("type") && j["type"].is_string() ? qs(j["type"].get<std::string>()) : QString()));
    editor->setToolTip(editor->property("help").toString());
    form_->addRow(unit.isEmpty() ? label : QStringLiteral("%1 [%2]").arg(label, unit), row ? row : editor);
  };
  // objects one level down (frames), rotations as one field, a body's shapes each with its fields
  std::function<void(const QString&, const json&)> add = [&](const QString& key, const json& v) {
    if (v.is_object() && !is_rotation_key(key)) {
      if (v.contains("type")) add_row(key + "/type", v["type"]);
      for (const auto& [sub, sv] : v.items())
        if (sub != "type") add(key + "/" + qs(sub), sv);
    } else if (key == QLatin1String("shapes") && kind == ElementKind::Body && v.is_array()) {
      for (std::size_t i = 0; i < v.size(); ++i) {
        auto* head = new QWidget;
        auto* hl = new QHBoxLayout(head);
        hl->setContentsMargins(0, 6, 0, 0);
        hl->addWidget(new QLabel(tr("<b>shape %1</b>").arg(i + 1)));
        hl->addStretch(1);
        auto* remove = new QPushButton(tr("Remove shape"));
        remove->setObjectName(QStringLiteral("removeShape:%1").arg(i));
        remove->setToolTip(tr("Remove this display shape (the dynamics do not depend on it)"));
        hl->addWidget(remove);
        const int shape = static_cast<int>(i);
        connect(remove, &QPushButton::clicked, this, [this, index, shape] {
          doc_->edit(tr("Remove shape"), [&](ModelSpec& s) {
            if (index < static_cast<int>(s.bodies.size()) && shape < static_cast<int>(s.bodies[index].shapes.size()))
              s.bodies[index].shapes.erase(s.bodies[index].shapes.begin() + shape);
          });
        });
        form_->addRow(head);
        add(QStringLiteral("shapes/%1").arg(i), v[i]);
      }
      auto* plus = new QPushButton(tr("Add shape"));
      plus->setObjectName("addShape");
      plus->setToolTip(tr("Add a display shape (box, cylinder or sphere) to this body"));
      connect(plus, &QPushButton::clicked, this, [this, index] {
        doc_->edit(tr("Add shape"), [&](ModelSpec& s) {
          if (index < static_cast<int>(s.bodies.size())) s.bodies[index].shapes.push_back(ShapeSpec{});
        });
      });
      form_->addRow(plus);
    } else {
      add_row(key, v);
    }
  };
  // name and type first (a tire: then its wheel, law and file), then the rest
  std::vector<std::string> first{"name", "type"};
  if (tire) first.insert(first.end(), {"body", "law", "file", "side"});
  for (const std::string& key : first)
    if (j.contains(key)) add(qs(key), j[key]);
  for (const auto& [key, v] : j.items()) {
    if (std::find(first.begin(), first.end(), key) != first.end()) continue;
    add(qs(key), v);
  }
  if (!focused.isEmpty()) {
    if (QWidget* e = editorFor(focused)) e->setFocus(Qt::OtherFocusReason);
  }
  refreshMarks();
}

}  // namespace codyna::gui
