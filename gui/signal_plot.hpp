// SignalPlot: any quantity a run recorded, over time, beside the Plant/In and
// Plant/Out plots: every joint coordinate and rate, every actuator's effort,
// every output, the controller's states, the kinetic, potential and total
// energy, and the constraint drift (position and velocity) of closed loops.
// Tick signals in the list to draw them; "Keep for comparison" pins the run
// on screen, and the ticked signals of kept runs are drawn dashed under the
// current one (up to four runs). The chart is a ChartView (zoom, pan,
// readout, copy as CSV).
#pragma once

#include <QWidget>
#include <memory>
#include <vector>

#include "study/workflow.hpp"

QT_BEGIN_NAMESPACE
class QChart;
class QListWidget;
class QPushButton;
QT_END_NAMESPACE

namespace codyna::gui {

class ChartView;

class SignalPlot : public QWidget {
  Q_OBJECT
 public:
  explicit SignalPlot(QWidget* parent = nullptr);

  // the run to show (null: none); the ticked names stay ticked where the new run has them
  void setResult(std::shared_ptr<const codyna::SimulationResult> r);
  void keepCurrent();     // pin the shown run for comparison
  void clearKept();
  int keptCount() const { return static_cast<int>(kept_.size()); }

  // every signal name of a result, in the list's order, and its samples
  static QStringList signalNames(const codyna::SimulationResult& r);
  static std::vector<double> signal(const codyna::SimulationResult& r, const QString& name);

  QListWidget* list() const { return list_; }
  ChartView* chartView() const { return view_; }
  void setChecked(const QString& name, bool on);
  QStringList checked() const;
  int curveCount() const;  // series drawn (current and kept)

 private:
  void redraw();
  std::shared_ptr<const codyna::SimulationResult> current_;
  std::vector<std::shared_ptr<const codyna::SimulationResult>> kept_;
  QListWidget* list_ = nullptr;
  QPushButton* keep_ = nullptr;
  QPushButton* clear_ = nullptr;
  QChart* chart_ = nullptr;
  ChartView* view_ = nullptr;
};

}  // namespace codyna::gui
