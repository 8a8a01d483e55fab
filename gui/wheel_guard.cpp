#include "gui/wheel_guard.hpp"

#include <QAbstractScrollArea>
#include <QAbstractSpinBox>
#include <QApplication>
#include <QComboBox>
#include <QEvent>
#include <QWheelEvent>

namespace codyna::gui {

namespace {

// the combo or spin box `w` belongs to (itself, or the line edit inside one), or nullptr
QWidget* guarded_field(QObject* o) {
  for (int depth = 0; o && depth < 2; ++depth, o = o->parent()) {
    if (qobject_cast<QComboBox*>(o) || qobject_cast<QAbstractSpinBox*>(o)) return static_cast<QWidget*>(o);
  }
  return nullptr;
}

}  // namespace

void WheelGuard::install() {
  if (!qApp || qApp->findChild<WheelGuard*>(QString(), Qt::FindDirectChildrenOnly)) return;
  qApp->installEventFilter(new WheelGuard(qApp));
}

bool WheelGuard::eventFilter(QObject* watched, QEvent* event) {
  if (event->type() == QEvent::Polish) {
    if (auto* w = qobject_cast<QWidget*>(watched);
        w && (qobject_cast<QComboBox*>(w) || qobject_cast<QAbstractSpinBox*>(w)) && w->focusPolicy() == Qt::WheelFocus) {
      w->setFocusPolicy(Qt::StrongFocus);
    }
    return false;
  }
  if (event->type() != QEvent::Wheel) return false;
  QWidget* field = guarded_field(watched);
  if (!field || field->hasFocus() || (field->focusProxy() && field->focusProxy()->hasFocus())) return false;
  // not focused: the turn belongs to the panel around the field
  for (QWidget* p = field->parentWidget(); p; p = p->parentWidget()) {
    if (auto* area = qobject_cast<QAbstractScrollArea*>(p)) {
      auto* wheel = static_cast<QWheelEvent*>(event);
      const QPointF at = area->viewport()->mapFromGlobal(wheel->globalPosition());
      QWheelEvent moved(at, wheel->globalPosition(), wheel->pixelDelta(), wheel->angleDelta(), wheel->buttons(),
                        wheel->modifiers(), wheel->phase(), wheel->inverted(), wheel->source());
      QCoreApplication::sendEvent(area->viewport(), &moved);
      break;
    }
  }
  return true;  // the field itself never sees it
}

}  // namespace codyna::gui
