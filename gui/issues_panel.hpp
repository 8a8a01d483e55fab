// IssuesPanel: every problem of the model at once, as a compiler's error list
// (element, field, what was expected): Document::issues(), which lists what
// study/model_issues.hpp finds. A click on a row selects its element (and the
// property editor marks its field); nothing here ever moves the selection by
// itself: the property editor keeps showing what the user chose.
#pragma once

#include <QWidget>
#include <optional>

#include "gui/model_tree.hpp"

class QTreeWidget;

namespace codyna::gui {

class IssuesPanel : public QWidget {
  Q_OBJECT
 public:
  explicit IssuesPanel(Document* doc, QWidget* parent = nullptr);
  QTreeWidget* list() { return list_; }
  int count() const;
  QString summary() const;  // "3 issues", "no issues"

 signals:
  void elementChosen(ElementId id);              // a row of an element was clicked
  void otherChosen(const QString& path);         // a row of the plant, the solver, the study
  void countChanged(int n);

 private:
  void rebuild();
  Document* doc_;
  QTreeWidget* list_;
  QString summary_;
};

}  // namespace codyna::gui
