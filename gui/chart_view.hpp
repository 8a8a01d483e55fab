// ChartView: a QChartView a person can read and explore. Left drag zooms into
// the rectangle, the wheel zooms about the pointer, the middle button (or
// Shift + left) drags the view, a double click or the context menu resets it;
// the value under the pointer is shown in the corner (x, y in the axes' units);
// the context menu copies every curve as CSV (x, then one column per curve,
// full precision), saves the chart as PNG or SVG at a chosen size, and resets
// the zoom.
#pragma once

#include <QChartView>

class QLabel;

namespace codyna::gui {

class ChartView : public QChartView {
  Q_OBJECT
 public:
  explicit ChartView(QChart* chart, QWidget* parent = nullptr);
  // a chart laid out for the small panels of the views: a bold 9 pt title, no rounding, narrow
  // margins, no animation, the legend on the right in 8 pt (no axes)
  static QChart* compactChart(const QString& title);

  QString dataCsv() const;  // the curves as plotted (visible series with a name or the only one)
  QString readout() const;  // what the corner shows ("" outside the plot area)
  bool isZoomed() const;
  void resetZoom();
  // after a zoom, every axis with dynamic ticks gets a round step (1, 2 or 5 times a
  // power of ten) with about five ticks; zooms stop at 1e12 wide (out) and at nine
  // significant digits (in)
  void fitTicks();
  bool canZoom(double factor) const;  // factor > 1 zooms in
  static double roundStep(double width, int ticks);

  // the chart alone (as zoomed, no readout) laid out at `size` pixels into a .png or
  // .svg file, written atomically; the view on screen is left as it was
  bool saveImage(const QString& path, const QSize& size, QString* error = nullptr);
  // the context menu's "Save image...": a dialog for the file and the size, then saveImage
  // (errors in a message box); returns the path written or ""
  QString saveImageInteractive();

 protected:
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void leaveEvent(QEvent* e) override;
  void contextMenuEvent(QContextMenuEvent* e) override;

 private:
  void showReadout(const QPointF& widgetPos);
  QLabel* readout_ = nullptr;
  bool panning_ = false;
  QPoint last_;
};

}  // namespace codyna::gui
