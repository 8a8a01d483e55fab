#include "gui/chart_view.hpp"

#include <QApplication>
#include <QChart>
#include <QLegend>
#include <QClipboard>
#include <QContextMenuEvent>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGraphicsLayout>
#include <QGraphicsScene>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QMessageBox>
#include <QPainter>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QSpinBox>
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

#include "gui/image_export.hpp"

namespace codyna::gui {

QChart* ChartView::compactChart(const QString& title) {
  auto* c = new QChart;
  c->setTitle(title);
  QFont tf = c->titleFont();
  tf.setBold(true);
  tf.setPointSizeF(9);
  c->setTitleFont(tf);
  c->setBackgroundRoundness(0);
  c->setMargins(QMargins(2, 0, 6, 0));
  c->setAnimationOptions(QChart::NoAnimation);
  c->legend()->setAlignment(Qt::AlignRight);
  QFont lf = c->legend()->font();
  lf.setPointSizeF(8);
  c->legend()->setFont(lf);
  return c;
}

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

bool ChartView::saveImage(const QString& path, const QSize& size, QString* error) {
  if (!chart() || !chart()->scene()) {
    if (error) *error = QStringLiteral("%1: no chart to save").arg(path);
    return false;
  }
  QChart* c = chart();
  const QRectF before = c->geometry();
  // lay the chart out at the asked size (axes, labels and legend placed for it), draw it, put it back
  const auto layoutAt = [c](const QRectF& r) {
    c->setGeometry(r);
    if (c->layout()) c->layout()->activate();
    QCoreApplication::sendPostedEvents(nullptr, QEvent::LayoutRequest);
  };
  const bool sized = size.width() >= 16 && size.height() >= 16 && size.width() <= 10000 && size.height() <= 10000;
  if (sized) layoutAt(QRectF(before.topLeft(), QSizeF(size)));
  const QString title = c->title().isEmpty() ? QStringLiteral("codyna chart") : c->title();
  const bool ok = save_painted_image(path, size, title, [&](QPainter& p) {
    c->scene()->render(&p, QRectF(QPointF(0, 0), QSizeF(size)), QRectF(before.topLeft(), QSizeF(size)));
  }, error);
  if (sized) layoutAt(before);
  return ok;
}

QString ChartView::saveImageInteractive() {
  QSettings settings;
  const QString folder = settings.value(QStringLiteral("charts/imageFolder"), QDir::currentPath()).toString();
  QString base = chart() ? chart()->title() : QString();
  base.replace(QRegularExpression(QStringLiteral("[^A-Za-z0-9_-]+")), QStringLiteral("_"));
  if (base.isEmpty()) base = QStringLiteral("chart");

  QDialog dialog(this);
  dialog.setWindowTitle(tr("Save chart image"));
  auto* form = new QFormLayout(&dialog);
  auto* path = new QLineEdit(QDir(folder).filePath(base + QStringLiteral(".png")), &dialog);
  path->setObjectName("imagePath");
  path->setToolTip(tr("The file to write: .png (pixels) or .svg (vectors)"));
  auto* browse = new QPushButton(tr("Browse..."), &dialog);
  auto* row = new QHBoxLayout;
  row->addWidget(path, 1);
  row->addWidget(browse);
  form->addRow(tr("File"), row);
  auto* w = new QSpinBox(&dialog);
  auto* h = new QSpinBox(&dialog);
  w->setObjectName("imageWidth");
  h->setObjectName("imageHeight");
  for (QSpinBox* b : {w, h}) {
    b->setRange(16, 10000);
    b->setSuffix(tr(" px"));
  }
  w->setValue(settings.value(QStringLiteral("charts/imageWidth"), 1200).toInt());
  h->setValue(settings.value(QStringLiteral("charts/imageHeight"), 600).toInt());
  w->setToolTip(tr("Width of the picture in pixels (the chart is laid out again at this size)"));
  h->setToolTip(tr("Height of the picture in pixels"));
  form->addRow(tr("Width"), w);
  form->addRow(tr("Height"), h);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Save | QDialogButtonBox::Cancel, &dialog);
  form->addRow(buttons);
  connect(buttons, &QDialogButtonBox::accepted, &dialog, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  connect(browse, &QPushButton::clicked, &dialog, [&] {
    const QString p = QFileDialog::getSaveFileName(&dialog, tr("Save chart image"), path->text(),
                                                   tr("PNG image (*.png);;SVG drawing (*.svg)"));
    if (!p.isEmpty()) path->setText(p);
  });
  if (dialog.exec() != QDialog::Accepted) return {};
  QString file = path->text().trimmed();
  if (!file.isEmpty() && !is_image_path(file)) file += QStringLiteral(".png");
  QString why;
  if (file.isEmpty() || !saveImage(file, QSize(w->value(), h->value()), &why)) {
    QMessageBox::warning(this, tr("Save chart image"), file.isEmpty() ? tr("No file name given.") : why);
    return {};
  }
  settings.setValue(QStringLiteral("charts/imageFolder"), QFileInfo(file).absolutePath());
  settings.setValue(QStringLiteral("charts/imageWidth"), w->value());
  settings.setValue(QStringLiteral("charts/imageHeight"), h->value());
  return file;
}

void ChartView::contextMenuEvent(QContextMenuEvent* e) {
  QMenu menu(this);
  menu.addAction(tr("Copy data (CSV)"), this, [this] { QApplication::clipboard()->setText(dataCsv()); });
  menu.addAction(tr("Save image..."), this, [this] { saveImageInteractive(); });
  QAction* reset = menu.addAction(tr("Reset zoom"), this, [this] { resetZoom(); });
  reset->setEnabled(isZoomed());
  menu.exec(e->globalPos());
}

}  // namespace codyna::gui
