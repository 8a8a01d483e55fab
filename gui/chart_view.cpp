#include "gui/chart_view.hpp"

#include <QApplication>
#include <QChart>
#include <QClipboard>
#include <QContextMenuEvent>
#include <QLabel>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QValueAxis>
#include <QMenu>
#include <QMouseEvent>
#include <QWheelEvent>
#include <cmath>
#include <limits>
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

namespace {

// QValueAxis with dynamic ticks keeps its tick interval whatever the range: a view
// zoomed out a hundred times would lay out 1.25^100 labels (the monkey test once
// asked for 32 GB that way), and a reset from a deep zoom as many. Before a zoom
// the interval is made coarser than any range, after it a round step with about
// five ticks is chosen for the new range.
QList<QValueAxis*> dynamicAxes(QChart* chart) {
  QList<QValueAxis*> out;
  if (!chart) return out;
  for (QAbstractAxis* a : chart->axes())
    if (auto* v = qobject_cast<QValueAxis*>(a); v && v->tickType() == QValueAxis::TicksDynamic) out << v;
  return out;
}

struct SavedTicks {
  QValueAxis* axis;
  double min, max, interval;
};

QList<SavedTicks> coarsenTicks(QChart* chart) {
  QList<SavedTicks> saved;
  for (QValueAxis* v : dynamicAxes(chart)) {
    saved << SavedTicks{v, v->min(), v->max(), v->tickInterval()};
    v->setTickInterval(std::numeric_limits<double>::max() / 4);
  }
  return saved;
}

// an axis whose range did not change gets its own interval back, the others a round step
void refitTicks(const QList<SavedTicks>& saved) {
  for (const SavedTicks& s : saved)
    s.axis->setTickInterval(s.axis->min() == s.min && s.axis->max() == s.max
                                ? s.interval
                                : ChartView::roundStep(s.axis->max() - s.axis->min(), 5));
}

}  // namespace

double ChartView::roundStep(double width, int ticks) {
  if (!(width > 0.0) || !std::isfinite(width) || ticks < 1) return 1.0;
  const double raw = width / ticks, p10 = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p10;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p10;
}

void ChartView::fitTicks() {
  for (QValueAxis* v : dynamicAxes(chart())) v->setTickInterval(roundStep(v->max() - v->min(), 5));
}

bool ChartView::canZoom(double factor) const {
  if (!chart()) return false;
  for (QAbstractAxis* a : chart()->axes()) {
    if (auto* v = qobject_cast<QValueAxis*>(a)) {
      const double w = v->max() - v->min(), size = std::max(std::abs(v->min()), std::abs(v->max()));
      if (factor < 1.0 && (w > 1e12 || size > 1e12)) return false;                  // far enough out
      if (factor > 1.0 && (w < 1e-9 * size || w < 1e-200)) return false;           // the digits run out
    } else if (auto* l = qobject_cast<QLogValueAxis*>(a)) {
      const double decades = std::log10(l->max()) - std::log10(l->min());
      if (factor < 1.0 && (decades > 30 || l->min() < 1e-100 || l->max() > 1e100)) return false;
      if (factor > 1.0 && decades < 1e-6) return false;
    }
  }
  return true;
}

void ChartView::resetZoom() {
  if (!chart()) return;
  const auto saved = coarsenTicks(chart());
  chart()->zoomReset();
  refitTicks(saved);
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
  // a left release may end a rubber-band zoom
  if (e->button() == Qt::LeftButton && chart()) {
    const auto saved = coarsenTicks(chart());
    QChartView::mouseReleaseEvent(e);
    refitTicks(saved);
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
  e->accept();
  if (!canZoom(factor)) return;
  const auto saved = coarsenTicks(chart());
  chart()->zoomIn(r);
  refitTicks(saved);
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
