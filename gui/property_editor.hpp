// PropertyEditor: the fields of one element, typed (numbers, vectors, matrices,
// names of other elements, the type, switches), with units. An edit is applied
// by writing the element's field into the model's JSON form and reading it back
// through core's strict reader, so every value is checked exactly as a model
// file is; a rejected value is marked and reported, the Document keeps its spec.
// A name edit renames through the Document (references follow).
#pragma once

#include <QWidget>
#include <map>
#include <optional>
#include <utility>

#include "gui/model_tree.hpp"

class QFormLayout;
class QLabel;

namespace codyna::gui {

class PropertyEditor : public QWidget {
  Q_OBJECT
 public:
  explicit PropertyEditor(Document* doc, QWidget* parent = nullptr);
  void setElement(std::optional<ElementId> id);
  std::optional<ElementId> element() const { return id_; }

  // marks a field (its key path below the element, e.g. "parent" or "parent_frame/position") as wrong
  void markField(const QString& field, const QString& message);
  QString markedField() const { return marked_; }  // the first marked (a refused value's, else the model's error's)
  QStringList markedFields() const;                // every field shown marked
  QString errorText() const;  // the reason shown at the fields ("" when none is marked)
  QWidget* editorFor(const QString& field) const;  // for tests: the editor of a field

  // applies `text` as the new value of `field` (what typing + Enter does); false with *error when rejected
  bool applyText(const QString& field, const QString& text, QString* error = nullptr);

  // a new tire's first numbers (a linear passenger-car tire of 0.3 m: cornering stiffness 80000 N/rad,
  // longitudinal slip stiffness 100000 N, vertical stiffness 200000 N/m, damping 500 N s/m), as a
  // type changed to tire gets them
  static void firstTire(EffectSpec& e);

  // a tire's "..." beside its file: a file dialog (objectName "tireFileDialog", Qt's own, window-modal)
  // whose chosen .tir is stored relative to the model file
  void chooseTireFile();

  static QString unitOf(const QString& key);
  // the tooltip of a field: what it means, with its unit (`type`: the element's type, where a
  // field means something of its own for it: a rolling_ball's axis_a is its plane's normal)
  static QString fieldHelp(ElementKind kind, const QString& key, const QString& unit, const QString& type = QString());

 signals:
  void message(const QString& text);
  // the context menu's "Vary in sweep" on a numeric field: its JSON pointer in the model file
  // (/bodies/1/mass; an entry of a vector: /bodies/0/com/1)
  void varyRequested(const QString& pointer);

 private:
  void rebuild();
  void retireEditors();                                             // takes the rows out, deletes them later
  bool isCurrent(const QString& key, const QWidget* editor) const;  // false for a retired editor
  // an editable list of names (bodies, joints, tires) showing `value`, applied to `key` when
  // one is picked or typed text is confirmed
  QWidget* nameCombo(const QStringList& names, const QString& value, const QString& key);
  void refreshMarks();
  void applyMarks();
  QFormLayout* form_ = nullptr;
  QLabel* title_ = nullptr;
  QLabel* error_ = nullptr;  // the marked field's reason
  QWidget* body_ = nullptr;
  Document* doc_;
  std::optional<ElementId> id_;
  std::map<QString, QWidget*> editors_;
  QString marked_;
  std::pair<QString, QString> refusal_;   // a value just refused: field, reason
  std::pair<QString, QString> involved_;  // the field whose edit made a problem appear in another one
};

}  // namespace codyna::gui
