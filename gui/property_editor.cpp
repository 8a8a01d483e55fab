#include "gui/property_editor.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QLabel>
#include <QLineEdit>
#include <QLocale>
#include <QRegularExpression>
#include <QScrollArea>
#include <QVBoxLayout>
#include <cmath>
#include <nlohmann/json.hpp>

#include "io/model_file.hpp"
#include "model/errors.hpp"

namespace codyna::gui {

using nlohmann::json;

namespace {

const QStringList kBodyRefs{"parent", "child", "body", "body_a", "body_b", "frame"};

QStringList type_names(ElementKind k) {
  switch (k) {
    case ElementKind::Joint: return {"revolute", "prismatic", "fixed", "spherical", "universal", "cylindrical", "planar", "free"};
    case ElementKind::Constraint: return {"ball", "revolute", "planar_revolute"};
    case ElementKind::Effect: return {"gravity", "spring_damper", "joint_spring_damper", "joint_friction", "joint_damper", "body_force"};
    case ElementKind::Actuator: return {"joint_force", "body_force", "body_torque"};
    case ElementKind::Sensor: return {"joint_position", "joint_velocity", "point_position", "point_velocity", "body_angle", "distance"};
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
  if (is_number_array(old) || (old.is_array() && old.empty())) return numbers(t);
  return json::parse(t.toStdString());  // objects, lists of objects: JSON text
}

// sets /a/b/c in j
void set_at(json& j, const QString& path, json value) { j[json::json_pointer(path.toStdString())] = std::move(value); }

}  // namespace

QString PropertyEditor::unitOf(const QString& key) {
  static const std::map<QString, QString> units{
      {"mass", "kg"}, {"inertia", "kg m²"}, {"com", "m"}, {"position", "m"}, {"point", "m"}, {"point_a", "m"},
      {"point_b", "m"}, {"size", "m"}, {"radius", "m"}, {"length", "m"}, {"rest_length", "m"},
      {"stiffness", "N/m | N m/rad"}, {"damping", "N s/m | N m s/rad"}, {"rest_position", "rad | m"},
      {"force", "N"}, {"torque", "N m"}, {"g", "m/s²"}, {"q0", "rad | m"}, {"v0", "rad/s | m/s"},
      {"rotation", "matrix | axis-angle"}, {"axis", "unit vector"}, {"axis2", "unit vector"}, {"direction", "unit vector"},
      {"color", "rgba 0..1"}};
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
  outer->addWidget(error_);
  auto* scroll = new QScrollArea(this);
  scroll->setWidgetResizable(true);
  body_ = new QWidget;
  form_ = new QFormLayout(body_);
  form_->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  scroll->setWidget(body_);
  outer->addWidget(scroll, 1);
  connect(doc, &Document::specChanged, this, &PropertyEditor::rebuild);
  connect(doc, &Document::errorChanged, this, &PropertyEditor::refreshMarks);
}

void PropertyEditor::setElement(std::optional<ElementId> id) {
  id_ = id;
  marked_.clear();
  rebuild();
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
  json j = to_json(spec);
  const QString base = QStringLiteral("/%1/%2").arg(section_of(id_->kind)).arg(id_->index);
  const json& old = j[json::json_pointer((base + "/" + field).toStdString())];
  json value;
  try {
    value = parse_text(text, old);
  } catch (const std::exception& e) {
    return reject(tr("%1: %2").arg(field, qs(e.what())));
  }
  set_at(j, base + "/" + field, value);
  if (field == "type") {
    // keep only what the new type accepts: drop fields the reader calls unknown
    for (int tries = 0; tries < 40; ++tries) {
      try {
        parse_model_spec(j, ss(doc_->filePath()));
        break;
      } catch (const ModelError& e) {
        const std::string p = e.path();
        if (e.detail().find("unknown field") == std::string::npos || p.rfind(ss(base), 0) != 0) break;
        j[json::json_pointer(ss(base))].erase(p.substr(p.rfind('/') + 1));
      }
    }
  }
  ModelSpec next;
  try {
    next = parse_model_spec(j, ss(doc_->filePath()));
  } catch (const ModelError& e) {
    const QString p = qs(e.path());
    const QString f = p.startsWith(base + "/") ? p.mid(base.size() + 1) : field;
    markField(f, qs(e.detail()));
    emit message(qs(e.what()));
    if (error) *error = qs(e.what());
    return false;
  }
  const QString what = qs(element_name(spec, id_->kind, id_->index)) + "." + field;
  doc_->edit(tr("Edit %1").arg(what), [&](ModelSpec& s) {
    const StudySpec study = s.analysis;  // the reader gives the same; keep the exact study anyway
    s = next;
    s.analysis = study;
  });
  return true;
}

void PropertyEditor::markField(const QString& field, const QString& message) {
  marked_ = field;
  // the reason, in words, at the top of the fields (and as the field's tooltip)
  error_->setText(field.isEmpty() || message.isEmpty() ? QString() : QStringLiteral("%1: %2").arg(QString(field).replace('/', '.'), message));
  error_->setVisible(!error_->text().isEmpty());
  for (auto& [key, w] : editors_) {
    const bool bad = key == field || field.startsWith(key + "/");
    w->setStyleSheet(bad ? "background: #ffd0d0;" : "");
    w->setToolTip(bad ? message : QString());
  }
}

QString PropertyEditor::errorText() const { return error_->text(); }

void PropertyEditor::refreshMarks() {
  if (!id_) return;
  const auto ref = element_at_path(ss(doc_->errorPath()));
  if (ref && ref->kind == id_->kind && ref->index == id_->index) markField(qs(ref->field), doc_->errorText());
  else if (!marked_.isEmpty()) markField(QString(), QString());
}

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

bool PropertyEditor::isCurrent(const QString& key, const QWidget* editor) const {
  const auto it = editors_.find(key);
  return it != editors_.end() && it->second == editor;
}

void PropertyEditor::rebuild() {
  retireEditors();
  error_->clear();
  error_->hide();
  const ModelSpec& spec = doc_->spec();
  if (!id_ || id_->index >= element_count(spec, id_->kind)) {
    title_->setText(tr("Select an element in the model tree"));
    return;
  }
  const json j = to_json(spec)[section_of(id_->kind)][id_->index];
  title_->setText(QStringLiteral("<b>%1</b> (%2)").arg(qs(element_name(spec, id_->kind, id_->index)).toHtmlEscaped(), to_string(id_->kind)));

  QStringList bodies{QString::fromLatin1(kGroundName)};
  for (const auto& b : spec.bodies) bodies << qs(b.name);
  QStringList joints;
  for (const auto& jt : spec.joints) joints << qs(jt.name);

  auto add_row = [&](const QString& key, const json& v) {
    QWidget* editor = nullptr;
    const QString last = key.section('/', -1);
    if (key == "type") {
      auto* c = new QComboBox;
      c->addItems(type_names(id_->kind));
      c->setCurrentText(qs(v.get<std::string>()));
      connect(c, &QComboBox::activated, this, [this, c] {
        if (isCurrent("type", c)) applyText("type", c->currentText());
      });
      editor = c;
    } else if (v.is_string() && (kBodyRefs.contains(last) || last == "joint")) {
      auto* c = new QComboBox;
      c->setEditable(true);
      c->addItems(last == "joint" ? joints : bodies);
      c->setCurrentText(qs(v.get<std::string>()));
      // a pick from the list (activated) and typed text confirmed (editingFinished) both
      // apply; the second of the two sees the value already applied and does nothing
      auto apply = [this, c, key] {
        if (isCurrent(key, c) && c->currentText() != c->property("value").toString()) applyText(key, c->currentText());
      };
      connect(c, &QComboBox::activated, this, apply);
      connect(c->lineEdit(), &QLineEdit::editingFinished, this, apply);
      c->setProperty("value", qs(v.get<std::string>()));
      editor = c;
    } else if (v.is_boolean()) {
      auto* c = new QCheckBox;
      c->setChecked(v.get<bool>());
      connect(c, &QCheckBox::toggled, this, [this, c, key](bool on) {
        if (isCurrent(key, c)) applyText(key, on ? "true" : "false");
      });
      editor = c;
    } else {
      auto* e = new QLineEdit(value_text(v));
      e->setProperty("value", e->text());
      connect(e, &QLineEdit::editingFinished, this, [this, e, key] {
        if (isCurrent(key, e) && e->text() != e->property("value").toString()) applyText(key, e->text());
      });
      editor = e;
    }
    editor->setObjectName("field:" + key);
    editors_[key] = editor;
    const QString unit = unitOf(key);
    QString label = key;
    label.replace('/', '.');
    form_->addRow(unit.isEmpty() ? label : QStringLiteral("%1 [%2]").arg(label, unit), editor);
  };
  // name and type first, then the rest; frames (objects) one level down
  if (j.contains("name")) add_row("name", j["name"]);
  if (j.contains("type")) add_row("type", j["type"]);
  for (const auto& [key, v] : j.items()) {
    if (key == "name" || key == "type") continue;
    if (v.is_object()) {
      for (const auto& [sub, sv] : v.items()) add_row(qs(key) + "/" + qs(sub), sv);
    } else {
      add_row(qs(key), v);
    }
  }
  refreshMarks();
}

}  // namespace codyna::gui
