#include "gui/chart_view.hpp"

#include <QApplication>
#include <QChart>
#include <QClipboard>
#include <QContextMenuEvent>
#include <QLabel>
#include <QLineSeries>
#include <QMenu>
#include <QMouseEvent>
#include <QWheelEvent>
#include <map>

namespace codyna::gui {

ChartView::ChartView(QChart* chart, QWidget* parent) : QChartView(chart, parent) {
  setRubberBand(QChartView::RectangleRubberBand);
  setMouseTracking(true);
  setRenderHint(QPainter::Antialiasing, true);
  readout_ = new QLabel(this);
  readout_->setObjectName("chartReadout");
  readout_->setStyleSheet("QLabel { background: rgba(255, 255, 255, 210); color: #202020; padding: 1px 4px; }");
  readout_->setAttribute(Qt::WA_TransparentForMouseEvents);
  readout_->hide();
  setToolTip(tr("Drag to zoom into a rectangle, wheel to zoom, middle drag to pan, double click to reset; "
                "right click to copy the data"));
}

bool ChartView::isZoomed() const { return chart() && chart()->isZoomed(); }

void ChartView::resetZoom() {
  if (chart()) chart()->zoomReset();
}

void ChartView::mousePressEvent(QMouseEvent* e) {
  if (e->button() == Qt::MiddleButton || (e->button() == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier))) {
    panning_ = true;
    last_ = e->position().toPoint();
    setCursor(Qt::ClosedHandCursor);
    e->accept();
    return;
  }
  QChartView::mousePressEvent(e);
}

void ChartView::mouseMoveEvent(QMouseEvent* e) {
  if (panning_ && chart()) {
    const QPoint d = e->position().toPoint() - last_;
    last_ = e->position().toPoint();
    chart()->scroll(-d.x(), d.y());
    e->accept();
  } else {
    QChartView::mouseMoveEvent(e);
  }
  showReadout(e->position());
}

void ChartView::mouseReleaseEvent(QMouseEvent* e) {
  if (panning_) {
    panning_ = false;
    unsetCursor();
    e->accept();
    return;
  }
  if (e->button() == Qt::RightButton) {  // QChartView zooms out on a right click: the menu does that here
    e->accept();
    return;
  }
  QChartView::mouseReleaseEvent(e);
}

void ChartView::mouseDoubleClickEvent(QMouseEvent* e) {
  resetZoom();
  e->accept();
}

void ChartView::wheelEvent(QWheelEvent* e) {
  if (!chart() || e->angleDelta().y() == 0) return QChartView::wheelEvent(e);
  // zoom about the pointer: scale the plot area around it
  const double factor = e->angleDelta().y() > 0 ? 1.25 : 0.8;
  const QRectF area = chart()->plotArea();
  const QPointF at = chart()->mapFromScene(mapToScene(e->position().toPoint()));
  QRectF r(area.topLeft(), area.size() / factor);
  r.moveCenter(at - (at - area.center()) / factor);
  chart()->zoomIn(r);
  e->accept();
}

void ChartView::leaveEvent(QEvent* e) {
  readout_->hide();
  QChartView::leaveEvent(e);
}

void ChartView::showReadout(const QPointF& pos) {
  if (!chart()) return;
  const QPointF scene = mapToScene(pos.toPoint());
  const QPointF inChart = chart()->mapFromScene(scene);
  if (!chart()->plotArea().contains(inChart) || chart()->series().isEmpty()) {
    readout_->hide();
    return;
  }
  const QPointF v = chart()->mapToValue(inChart, chart()->series().front());
  readout_->setText(QStringLiteral("x = %1   y = %2").arg(v.x(), 0, 'g', 6).arg(v.y(), 0, 'g', 6));
  readout_->adjustSize();
  readout_->move(width() - readout_->width() - 6, 4);
  readout_->show();
}

QString ChartView::readout() const { return readout_->isVisible() ? readout_->text() : QString(); }

QString ChartView::dataCsv() const {
  if (!chart()) return {};
  // x values of all curves, then one column per curve (empty where a curve has no point at that x)
  QList<QLineSeries*> curves;
  for (QAbstractSeries* s : chart()->series()) {
    auto* l = qobject_cast<QLineSeries*>(s);
    if (l && l->isVisible() && l->count() > 0 && (!l->name().isEmpty() || chart()->series().size() == 1)) curves << l;
  }
  std::map<double, std::vector<QString>> rows;
  for (int k = 0; k < curves.size(); ++k)
    for (const QPointF& p : curves[k]->points()) {
      auto& row = rows[p.x()];
      row.resize(curves.size());
      row[k] = QString::number(p.y(), 'g', 17);
    }
  QStringList head{QStringLiteral("x")};
  for (QLineSeries* l : curves) head << (l->name().isEmpty() ? QStringLiteral("y") : l->name());
  QStringList lines{head.join(',')};
  for (auto& [x, cells] : rows) {
    cells.resize(curves.size());
    QStringList row{QString::number(x, 'g', 17)};
    for (const QString& c : cells) row << c;
    lines << row.join(',');
  }
  return lines.join('\n') + '\n';
}

void ChartView::contextMenuEvent(QContextMenuEvent* e) {
  QMenu menu(this);
  menu.addAction(tr("Copy data (CSV)"), this, [this] { QApplication::clipboard()->setText(dataCsv()); });
  QAction* reset = menu.addAction(tr("Reset zoom"), this, [this] { resetZoom(); });
  reset->setEnabled(isZoomed());
  menu.exec(e->globalPos());
}

}  // namespace codyna::gui
