// Document: the model being edited (a ModelSpec, its "analysis" study included)
// with its undo stack, file and compiled form. Every change is a QUndoCommand
// (edit()), so every change can be undone; the compiled model is refreshed after
// each change, and a spec that does not compile keeps the document editable and
// reports the ModelError (file, field path, what was expected).
//
// Widgets never keep copies of the spec: they read spec()/model() and listen to
// specChanged()/modelChanged().
#pragma once

#include <QObject>
#include <QList>
#include <QString>
#include <QUndoStack>
#include <functional>
#include <memory>
#include <optional>

#include "model/model.hpp"
#include "model/model_spec.hpp"
#include "model/spec_edit.hpp"

namespace codyna::gui {

class Document : public QObject {
  Q_OBJECT
 public:
  explicit Document(QObject* parent = nullptr);

  const ModelSpec& spec() const { return spec_; }
  QString filePath() const { return path_; }
  QString displayName() const;  // file name, or "untitled"
  bool isModified() const { return !undo_.isClean(); }
  QUndoStack* undoStack() { return &undo_; }

  // The study model (study_model(spec)): null when the spec does not compile.
  std::shared_ptr<const Model> model() const { return model_; }
  // The last compile error ("" when the model compiles), and its field path ("/joints/2/parent").
  QString errorText() const { return error_; }
  QString errorPath() const { return error_path_; }
  // Every problem of a spec that does not compile (study/model_issues.hpp), in the file's order;
  // the error above is one of them. Empty when the model compiles.
  struct Issue {
    QString path;    // "/joints/2/parent" ("" when no field is to blame)
    QString text;    // the whole message (file: path: what was expected)
    QString detail;  // what was expected, alone
  };
  const QList<Issue>& issues() const { return issues_; }
  // While the model does not compile: its draft, for the 3-D view (what compiles of it, the bodies
  // no joint moves held in a row; study/model_issues.hpp), and what the draft leaves out
  // ("joint pivot"). Null and empty when the model compiles.
  std::shared_ptr<const Model> draft() const { return draft_; }
  const QStringList& draftLeavesOut() const { return draft_leaves_out_; }
  const QStringList& draftHeld() const { return draft_held_; }  // bodies no joint moves, held by the draft

  // File operations. load() leaves the document untouched when the file does not load
  // (error set to the ModelError's text). save() writes atomically; a failed save keeps
  // the document modified and says why.
  bool load(const QString& path, QString* error = nullptr);
  bool save(QString* error = nullptr);
  bool saveAs(const QString& path, QString* error = nullptr);
  void clear();  // a new, empty model

  // One undoable edit: `change` modifies a copy of the spec; nothing happens when it
  // throws (the message goes to *error) or changes nothing. Edits with the same
  // mergeKey (>= 0, e.g. typing in one field) right after each other merge into one step.
  bool edit(const QString& text, const std::function<void(ModelSpec&)>& change, QString* error = nullptr, int mergeKey = -1);

  // Common edits, each one undo step
  bool rename(ElementKind k, int index, const QString& name, QString* error = nullptr);  // updates every reference
  bool setPlantInputs(const QStringList& names);
  bool setPlantOutputs(const QStringList& names);
  bool setStudy(const StudySpec& study, const QString& text = "Change analysis settings", int mergeKey = -1);
  // setStudy checked by the core first: the model file reader's checks (the spec written
  // and read back, as a save and a load would) and study_model's (coordinates set,
  // independent coordinates; only when the model compiled before). A refusal changes
  // nothing and gives the core's message (file, field path, what was expected).
  bool setStudyChecked(const StudySpec& study, const QString& text, QString* error, int mergeKey = -1);
  // false: refused by the model file's checks on the solver section (error: why, naming the field)
  bool setSolver(const SolverSpec& solver, const QString& text = "Change solver settings", int mergeKey = -1,
                 QString* error = nullptr);

  // replaces the spec without an undo step (used by the undo commands)
  void restore(const ModelSpec& spec);

 signals:
  void specChanged();                 // after any change of the spec (edit, undo, redo, load)
  void modelChanged();                // after the compiled model was refreshed (model() may be null)
  void fileChanged();                 // path or modified state changed (window title)
  void errorChanged(const QString& text, const QString& path);
  // another model took the document's place (load, clear): every result of the old one must go
  void replaced();

 private:
  void recompile();
  ModelSpec spec_;
  QString path_;
  QUndoStack undo_;
  std::shared_ptr<const Model> model_;
  QString error_, error_path_;
  QList<Issue> issues_;
  std::shared_ptr<const Model> draft_;
  QStringList draft_leaves_out_, draft_held_;
};

QString qs(const std::string& s);
std::string ss(const QString& s);

}  // namespace codyna::gui
