// PoleMap: the eigenvalues of a linearized system in the complex plane.
//
// Continuous systems (Ts = 0) show lambda in the s-plane; discrete systems
// (Ts > 0) show z in the z-plane with the unit circle (drawn to equal scale
// on both axes). The real and imaginary axes through 0 are drawn. Poles are
// crosses, coloured by stability: stable (Re s < 0), marginal (Re s = 0
// within rounding, e.g. an integrator) and unstable. A click near a pole
// selects its mode (modeSelected is emitted); the selected pole is drawn
// larger, highlighted. Hovering a pole shows its eigenvalue, frequency and
// damping in a tooltip.
#pragma once

#include <Eigen/Core>

#include <QPoint>
#include <QPointF>
#include <QString>
#include <QWidget>
#include <vector>

#include "study/tools.hpp"

QT_BEGIN_NAMESPACE
class QBoxLayout;
class QChart;
class QLabel;
class QChartView;
class QLineSeries;
class QScatterSeries;
class QValueAxis;
QT_END_NAMESPACE

namespace codyna::gui {

class PoleMap : public QWidget {
  Q_OBJECT
 public:
  explicit PoleMap(QWidget* parent = nullptr);
  ~PoleMap() override;

  // Shows the modes (the selection is cleared).
  void setModes(const codyna::ModalAnalysis& modal);
  // Zeros drawn as circles with the poles (a pole-zero map); empty: none. Kept by setModes.
  void setZeros(const Eigen::VectorXcd& zeros);
  int zeroCount() const { return static_cast<int>(zeros_.size()); }
  QPointF zeroPosition(int k) const { return k >= 0 && k < zeroCount() ? zeros_[k] : QPointF(); }
  // Highlights mode `index` (-1 or out of range: none). Does not emit modeSelected.
  void selectMode(int index);
  int selectedMode() const { return selected_; }

  int poleCount() const { return static_cast<int>(poles_.size()); }
  // how many poles are drawn stable, marginal (on the boundary) and unstable
  int drawnStable() const;
  int drawnMarginal() const;
  int drawnUnstable() const;
  bool isDiscrete() const { return discrete_; }
  // Chart coordinates (Re, Im) of pole `index`: lambda, or z when discrete.
  QPointF polePosition(int index) const;
  // Where pole `index` is drawn, in this widget's coordinates.
  QPoint poleWidgetPosition(int index) const;
  // The pole drawn within `radius` pixels of `widgetPos` (the nearest), or -1.
  int poleAt(const QPoint& widgetPos, int radius = 10) const;

  // .png (widget grab) or .svg (vector), by suffix.
  bool saveImage(const QString& path, QString* error = nullptr);

  QChart* chart() const { return chart_; }
  // The legend line under the chart (categories present, the selected mode).
  QString legendText() const;

 signals:
  // The user clicked pole `index`.
  void modeSelected(int index);

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void resizeEvent(QResizeEvent* event) override;

 private:
  void rebuild();
  void updateRanges();
  void updateAxisLines();
  void clickAt(const QPoint& widgetPos);
  QString poleText(int index) const;
  void updateLegend();

  QChart* chart_ = nullptr;
  QChartView* view_ = nullptr;
  QBoxLayout* box_ = nullptr;
  bool legend_aside_ = false;  // a wide map keeps its legend at the side: the plot keeps its height
  QLabel* legend_ = nullptr;  // (the Qt Charts legend mislays scatter markers that come and go)
  QValueAxis* axis_re_ = nullptr;
  QValueAxis* axis_im_ = nullptr;
  QLineSeries* re_axis_line_ = nullptr;   // Im = 0
  QLineSeries* im_axis_line_ = nullptr;   // Re = 0
  QLineSeries* unit_circle_ = nullptr;
  QScatterSeries* stable_ = nullptr;
  QScatterSeries* marginal_ = nullptr;
  QScatterSeries* unstable_ = nullptr;
  QScatterSeries* selected_series_ = nullptr;

  codyna::ModalAnalysis modal_;
  std::vector<QPointF> poles_;
  std::vector<QPointF> zeros_;
  QScatterSeries* zero_series_ = nullptr;
  bool discrete_ = false;
  int selected_ = -1;
  bool updating_ranges_ = false;
};

}  // namespace codyna::gui
