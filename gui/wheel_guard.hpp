// WheelGuard: a mouse wheel turned over a drop-down or a spin box that the user
// has not clicked into scrolls the panel around it, and changes nothing.
// Qt's default gives such a field the focus on a wheel turn (Qt::WheelFocus)
// and then changes its value, one undo step per notch: scrolling the Simulate
// panel turned its integrator from auto to rk4. The guard, an application-wide
// event filter, takes the wheel focus away from every QComboBox and
// QAbstractSpinBox as it is polished (they keep the click and Tab focus), and
// passes a wheel turn over an unfocused one to the scroll area that holds it.
#pragma once

#include <QObject>

namespace codyna::gui {

class WheelGuard : public QObject {
  Q_OBJECT
 public:
  explicit WheelGuard(QObject* parent = nullptr) : QObject(parent) {}
  // installs one guard on the application (again: nothing)
  static void install();

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;
};

}  // namespace codyna::gui
