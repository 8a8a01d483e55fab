#include "gui/document.hpp"

#include <QFileInfo>
#include <QUndoCommand>
#include <nlohmann/json.hpp>

#include "study/files.hpp"
#include "model/compile.hpp"
#include "model/errors.hpp"
#include "study/model_issues.hpp"
#include "study/workflow.hpp"

namespace codyna::gui {

QString qs(const std::string& s) { return QString::fromStdString(s); }
std::string ss(const QString& s) { return s.toStdString(); }

namespace {

// Before and after of one edit: the spec is small, so whole copies keep undo simple and exact.
class SpecCommand : public QUndoCommand {
 public:
  SpecCommand(Document* doc, ModelSpec before, ModelSpec after, const QString& text, int key)
      : QUndoCommand(text), doc_(doc), before_(std::move(before)), after_(std::move(after)), key_(key) {}
  void undo() override { doc_->restore(before_); }
  void redo() override { doc_->restore(after_); }
  int id() const override { return key_; }
  // the model moved from file `from` to `to` (Save As into another folder): its relative file
  // references in both states name the same files from there (else an Undo after the move would
  // read a tire's .tir, or a namesake of it, relative to the new folder)
  void rebase(const std::string& from, const std::string& to) {
    before_ = study_rebase_paths(std::move(before_), from, to);
    after_ = study_rebase_paths(std::move(after_), from, to);
  }
  bool mergeWith(const QUndoCommand* other) override {
    const auto* o = static_cast<const SpecCommand*>(other);
    if (o->key_ != key_ || key_ < 0) return false;
    after_ = o->after_;
    return true;
  }

 private:
  Document* doc_;
  ModelSpec before_, after_;
  int key_;
};

bool same(const ModelSpec& a, const ModelSpec& b) { return study_model_json(a) == study_model_json(b); }

}  // namespace

Document::Document(QObject* parent) : QObject(parent) {
  connect(&undo_, &QUndoStack::cleanChanged, this, &Document::fileChanged);
  recompile();
}

QString Document::displayName() const { return path_.isEmpty() ? QStringLiteral("untitled") : QFileInfo(path_).fileName(); }

void Document::recompile() {
  // the compile's own error first (errorText, errorPath), and every other problem check_model
  // finds (issues(): all of them, in the model file's order)
  const ModelCheck check = check_model(spec_, ss(path_));
  model_ = check.model;
  draft_ = check.draft.model;
  draft_leaves_out_.clear();
  draft_held_.clear();
  for (const std::string& e : check.draft.leaves_out) draft_leaves_out_.push_back(qs(e));
  for (const std::string& b : check.draft.held) draft_held_.push_back(qs(b));
  QList<Issue> issues;
  for (const ModelError& e : check.issues) issues.push_back({qs(e.path()), qs(e.what()), qs(e.detail())});
  const QString text = issues.isEmpty() ? QString() : issues[static_cast<qsizetype>(check.first)].text;
  const QString path = issues.isEmpty() ? QString() : issues[static_cast<qsizetype>(check.first)].path;
  const bool changed = text != error_ || path != error_path_;
  error_ = text;
  error_path_ = path;
  issues_ = std::move(issues);
  emit modelChanged();
  if (changed || !text.isEmpty()) emit errorChanged(error_, error_path_);
}

void Document::restore(const ModelSpec& spec) {
  spec_ = spec;
  emit specChanged();
  recompile();
}

bool Document::edit(const QString& text, const std::function<void(ModelSpec&)>& change, QString* error, int mergeKey) {
  ModelSpec next = spec_;
  try {
    change(next);
  } catch (const std::exception& e) {
    if (error) *error = qs(e.what());
    return false;
  }
  if (same(next, spec_)) return true;
  undo_.push(new SpecCommand(this, spec_, std::move(next), text, mergeKey));  // push() runs redo()
  return true;
}

bool Document::rename(ElementKind k, int index, const QString& name, QString* error) {
  const QString text = QStringLiteral("Rename %1 to %2").arg(to_string(k), name);
  return edit(text, [&](ModelSpec& s) { rename_element(s, k, index, ss(name)); }, error);
}

static std::vector<std::string> to_std(const QStringList& l) {
  std::vector<std::string> v;
  for (const QString& s : l) v.push_back(ss(s));
  return v;
}

bool Document::setPlantInputs(const QStringList& names) {
  return edit(tr("Change Plant/In"), [&](ModelSpec& s) { s.plant.inputs = to_std(names); });
}

bool Document::setPlantOutputs(const QStringList& names) {
  return edit(tr("Change Plant/Out"), [&](ModelSpec& s) { s.plant.outputs = to_std(names); });
}

bool Document::setStudy(const StudySpec& study, const QString& text, int mergeKey) {
  return edit(text, [&](ModelSpec& s) { s.analysis = study; }, nullptr, mergeKey);
}

bool Document::setStudyChecked(const StudySpec& study, const QString& text, QString* error, int mergeKey) {
  const bool compiled = model_ != nullptr;
  return edit(
      text,
      [&](ModelSpec& s) {
        s.analysis = study;
        // only the study's own errors refuse the edit: a model being fixed elsewhere stays editable
        const auto check = [](const std::function<void()>& f) {
          try {
            f();
          } catch (const ModelError& e) {
            if (e.path().rfind("/analysis", 0) == 0) throw;
          }
        };
        check([&] { (void)study_parse_model(study_model_json(s), ss(displayName())); });  // the reader's checks
        if (compiled) check([&] { (void)study_model(s, ss(path_)); });          // names, coordinates held
      },
      error, mergeKey);
}

bool Document::setSolver(const SolverSpec& solver, const QString& text, int mergeKey, QString* error) {
  {  // the same section: no edit, and no checks (a file whose section the checks refuse is not
     // refused again each time a field loses focus)
    ModelSpec next = spec_;
    next.solver = solver;
    if (same(next, spec_)) return true;
  }
  return edit(
      text,
      [&](ModelSpec& s) {
        s.solver = solver;
        // the reader's checks on the solver section (an end time of 0 would save a file that does not load)
        try {
          (void)study_parse_model(study_model_json(s), ss(displayName()));
        } catch (const ModelError& e) {
          if (e.path().rfind("/solver", 0) == 0) throw;
        }
        check_solver_spec(s.solver, ss(displayName()));  // and compile's (alf's step within the run)
      },
      error, mergeKey);
}

bool Document::load(const QString& path, QString* error) {
  ModelSpec spec;
  try {
    spec = study_read_model(ss(path));
  } catch (const std::exception& e) {
    if (error) *error = qs(e.what());
    return false;  // the open document stays as it was
  }
  path_ = QFileInfo(path).absoluteFilePath();
  undo_.clear();
  restore(spec);
  undo_.setClean();
  emit fileChanged();
  emit replaced();
  return true;
}

bool Document::save(QString* error) {
  if (path_.isEmpty()) {
    if (error) *error = tr("the model has no file yet: use Save As");
    return false;
  }
  return saveAs(path_, error);
}

bool Document::saveAs(const QString& path, QString* error) {
  try {
    // the model's relative file references (a tire's .tir, the study's files) keep naming the
    // same files from the new folder
    const ModelSpec moved_spec = study_rebase_paths(spec_, ss(path_), ss(path));
    // a file that would not load again is not written (the one on disk stays as it was)
    (void)study_parse_model(study_model_json(moved_spec), ss(path));
    study_save_model(moved_spec, ss(path));
    if (study_model_json(moved_spec) != study_model_json(spec_)) restore(moved_spec);
  } catch (const std::exception& e) {
    if (error) *error = qs(e.what());
    return false;  // still modified
  }
  const QString abs = QFileInfo(path).absoluteFilePath();
  const bool moved = abs != path_;
  if (moved && !path_.isEmpty()) {
    // the edits before the move keep naming the files they named (every command is a SpecCommand,
    // owned by the stack, which hands them out const)
    for (int i = 0; i < undo_.count(); ++i)
      const_cast<SpecCommand*>(static_cast<const SpecCommand*>(undo_.command(i)))->rebase(ss(path_), ss(abs));
  }
  path_ = abs;
  undo_.setClean();
  if (moved) recompile();  // relative paths of the study now resolve against the new folder
  emit fileChanged();
  return true;
}

void Document::clear() {
  path_.clear();
  undo_.clear();
  ModelSpec empty;
  empty.name = "untitled";
  restore(empty);
  undo_.setClean();
  emit fileChanged();
  emit replaced();
}

}  // namespace codyna::gui
