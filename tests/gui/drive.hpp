// Driving codyna-gui's widgets as a person does, for the GUI tests: drop-downs
// opened with a click on their arrow and an entry picked from the open list with
// the mouse or the arrow keys, the window made and closed with its dialogs
// answered, wheel notches delivered to the widget under the pointer.
#pragma once

#include <QAbstractItemView>
#include <QApplication>
#include <QAction>
#include <QComboBox>
#include <QLineEdit>
#include <QMainWindow>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QTest>
#include <QTreeView>
#include <QUndoStack>
#include <QWheelEvent>
#include <memory>

#include "gui/main_window.hpp"
#include "gui/model_tree.hpp"
#include "gui/property_editor.hpp"

namespace codyna::gui::drive {

// opens `c`'s list with a click on its arrow
inline QAbstractItemView* openPopup(QComboBox* c) {
  QTest::mouseClick(c, Qt::LeftButton, {}, QPoint(c->width() - 6, c->height() / 2));
  QAbstractItemView* v = c->view();
  if (!QTest::qWaitFor([v] { return v->isVisible(); }, 2000)) return nullptr;
  // a release right after the opening press is ignored by the popup: wait as a person would
  QTest::qWait(QApplication::doubleClickInterval() + 50);
  return v;
}

// the row of `text` in `c`: the entry itself, or the one that starts with "text " (a label with a note)
inline int rowOf(const QComboBox* c, const QString& text) {
  for (int i = 0; i < c->count(); ++i)
    if (c->itemText(i) == text || c->itemText(i).startsWith(text + " ")) return i;
  return -1;
}

// picks `text` from `c`'s open list with the mouse: move onto the item, click it
inline bool pickWithMouse(QComboBox* c, const QString& text) {
  if (!c) return false;
  const int row = rowOf(c, text);
  if (row < 0) return false;
  QAbstractItemView* v = openPopup(c);
  if (!v) return false;
  const QPoint at = v->visualRect(v->model()->index(row, c->modelColumn())).center();
  QTest::mouseMove(v->viewport(), at);
  QTest::mouseClick(v->viewport(), Qt::LeftButton, {}, at);
  return QTest::qWaitFor([v] { return !v->isVisible(); }, 2000);
}

// picks `text` from `c`'s open list with the arrow keys and Enter
inline bool pickWithKeys(QComboBox* c, const QString& text) {
  if (!c) return false;
  const int row = rowOf(c, text);
  if (row < 0) return false;
  QAbstractItemView* v = openPopup(c);
  if (!v) return false;
  for (int guard = 0; v->currentIndex().row() != row && guard < 50; ++guard)
    QTest::keyClick(v, v->currentIndex().row() < row ? Qt::Key_Down : Qt::Key_Up);
  QTest::keyClick(v, Qt::Key_Return);
  return QTest::qWaitFor([v] { return !v->isVisible(); }, 2000);
}

// the window's Edit > Add > KIND action (nullptr when there is none); `kind` as the model file
// says it: "body", "joint", "constraint", "effect", "actuator", "sensor"
inline QAction* addAction(QMainWindow* w, const QString& kind) {
  for (QAction* top : w->menuBar()->actions()) {
    if (top->text() != "&Edit" || !top->menu()) continue;
    for (QAction* a : top->menu()->actions()) {
      if (!a->menu()) continue;
      for (QAction* b : a->menu()->actions())
        if (b->objectName() == "actionAdd:" + kind) return b;
    }
  }
  return nullptr;
}

// The element's row of the model tree clicked (its kind's node opened first), and the property
// editor then showing it: "" when so, else what went wrong
inline QString clickElement(MainWindow* w, ElementKind kind, int index) {
  QTreeView* t = w->modelTree();
  const QModelIndex i = w->treeModel()->indexOf({kind, index});
  if (!i.isValid()) return QStringLiteral("no row for element %1").arg(index);
  t->expand(i.parent());
  t->scrollTo(i);
  const QRect r = t->visualRect(i);
  if (r.isEmpty()) return QStringLiteral("row %1 not shown").arg(index);
  QTest::mouseClick(t->viewport(), Qt::LeftButton, {}, r.center());
  const auto e = w->propertyEditor()->element();
  if (!e || e->kind != kind || e->index != index) return QStringLiteral("the editor does not show element %1").arg(index);
  return {};
}

// Edit > Add > "Add KIND" triggered from the window's menu, the new element in the editor: "" when so
inline QString addElement(MainWindow* w, const QString& kind) {
  QAction* found = addAction(w, kind);
  if (!found) return "no action Add " + kind;
  found->trigger();
  return w->propertyEditor()->element() ? QString() : "nothing selected after Add " + kind;
}

// `text` typed into the field's line edit (an editable drop-down's too) and Enter pressed: "" when
// there was one to type into
inline QString typeInto(MainWindow* w, const QString& field, const QString& text) {
  QWidget* ed = w->propertyEditor()->editorFor(field);
  QLineEdit* e = qobject_cast<QLineEdit*>(ed);
  if (auto* c = qobject_cast<QComboBox*>(ed)) e = c->lineEdit();
  if (!e) return "no line edit for " + field;
  e->setFocus();
  e->selectAll();
  QTest::keyClicks(e, text);
  QTest::keyClick(e, Qt::Key_Return);
  return {};
}

// typed and taken: nothing marked, no reason shown ("" when so)
inline QString typeTaken(MainWindow* w, const QString& field, const QString& text) {
  const QString why = typeInto(w, field, text);
  if (!why.isEmpty()) return why;
  const PropertyEditor* p = w->propertyEditor();
  if (!p->markedField().isEmpty() || !p->errorText().isEmpty()) return field + " = " + text + " not taken: " + p->errorText();
  return {};
}

// a wheel notch over the middle of `w` (delivered as Qt delivers one: to the widget under the mouse)
inline void wheelOver(QWidget* w, int notches) {
  const QPointF at(w->width() / 2.0, w->height() / 2.0);
  QWheelEvent e(at, w->mapToGlobal(at), QPoint(), QPoint(0, 120 * notches), Qt::NoButton, Qt::NoModifier,
                Qt::NoScrollPhase, false);
  QApplication::sendEvent(w, &e);
}

// a shown main window whose questions answer Discard and whose file dialogs are cancelled
inline std::unique_ptr<MainWindow> window(const char* testName) {
  QCoreApplication::setOrganizationName("codyna-test");
  QCoreApplication::setApplicationName(testName);
  auto w = std::make_unique<MainWindow>();
  w->setQuestionHook([](const QString&, const QString&, int) { return int(QMessageBox::Discard); });
  w->setFileHook([](const QString&, const QString&, const QString&, bool) { return QString(); });
  w->show();
  if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
  return w;
}

// closes it without a question
inline void close(std::unique_ptr<MainWindow>& w) {
  if (!w) return;
  w->document()->undoStack()->setClean();
  w.reset();
}

}  // namespace codyna::gui::drive
