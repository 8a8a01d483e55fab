#include "gui/pole_map.hpp"

#include "gui/image_export.hpp"

#include <QBuffer>
#include <QChart>
#include <QChartView>
#include <QCoreApplication>
#include <QFileInfo>
#include <QHelpEvent>
#include <QImage>
#include <QLabel>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QPixmap>
#include <QSaveFile>
#include <QScatterSeries>
#include <QSvgGenerator>
#include <QToolTip>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "gui/result_plots.hpp"  // niceRange, setAxisRange

namespace codyna::gui {
namespace {

constexpr double kMarker = 13.0;          // size of a pole's cross, pixels
constexpr double kSelectedMarker = 24.0;  // ring around the selected pole

// a cross ("x", the usual pole symbol) as a texture for a square scatter marker
QImage crossImage(const QColor& colour) {
  const int n = static_cast<int>(kMarker);
  QImage img(n, n, QImage::Format_ARGB32_Premultiplied);
  img.fill(Qt::transparent);
  QPainter p(&img);
  p.setRenderHint(QPainter::Antialiasing);
  QPen pen(colour);
  pen.setWidthF(2.2);
  pen.setCapStyle(Qt::RoundCap);
  p.setPen(pen);
  const double a = 2.0, b = n - 2.0;
  p.drawLine(QPointF(a, a), QPointF(b, b));
  p.drawLine(QPointF(a, b), QPointF(b, a));
  return img;
}

QScatterSeries* makePoleSeries(const QString& name, const QColor& colour) {
  auto* s = new QScatterSeries;
  s->setName(name);
  s->setMarkerShape(QScatterSeries::MarkerShapeRectangle);
  s->setMarkerSize(kMarker);
  s->setBrush(crossImage(colour));  // the marker is a square textured with the cross
  s->setPen(QColor(Qt::transparent));
  return s;
}

QString complexText(double re, double im, char unit) {
  const QString sign = im < 0 ? QStringLiteral("\u2212") : QStringLiteral("+");
  const QString reText = re < 0 ? QStringLiteral("\u2212") + QString::number(-re, 'g', 6) : QString::number(re, 'g', 6);
  if (im == 0.0) return reText;
  return QStringLiteral("%1 %2 %3%4").arg(reText, sign, QString::number(std::abs(im), 'g', 6), QChar(unit));
}

void hideLegendEntry(QChart* chart, QAbstractSeries* s) {
  for (QLegendMarker* m : chart->legend()->markers(s)) m->setVisible(false);
}

void stylePoleAxis(QValueAxis* axis) {
  QFont f = axis->labelsFont();
  f.setPointSizeF(8.5);
  axis->setLabelsFont(f);
  f.setPointSizeF(9);
  axis->setTitleFont(f);
  axis->setLabelFormat(QStringLiteral("%.6g"));
  axis->setTickType(QValueAxis::TicksDynamic);
  axis->setTickAnchor(0.0);
  axis->setMinorTickCount(0);
  axis->setGridLineColor(QColor(0xdd, 0xdd, 0xdd));
  axis->setLinePenColor(QColor(0x60, 0x60, 0x60));
  axis->setLabelsColor(QColor(0x20, 0x20, 0x20));
  axis->setTitleBrush(QColor(0x20, 0x20, 0x20));
}

}  // namespace

PoleMap::PoleMap(QWidget* parent) : QWidget(parent) {
  chart_ = new QChart;
  chart_->setBackgroundRoundness(0);
  chart_->setMargins(QMargins(4, 2, 8, 2));
  chart_->setAnimationOptions(QChart::NoAnimation);
  QFont tf = chart_->titleFont();
  tf.setBold(true);
  tf.setPointSizeF(10);
  chart_->setTitleFont(tf);
  chart_->legend()->hide();

  axis_re_ = new QValueAxis;
  axis_im_ = new QValueAxis;
  stylePoleAxis(axis_re_);
  stylePoleAxis(axis_im_);
  chart_->addAxis(axis_re_, Qt::AlignBottom);
  chart_->addAxis(axis_im_, Qt::AlignLeft);

  const auto addLine = [this](const QColor& colour, Qt::PenStyle style, double width) {
    auto* s = new QLineSeries;
    QPen pen(colour);
    pen.setWidthF(width);
    pen.setStyle(style);
    s->setPen(pen);
    chart_->addSeries(s);
    s->attachAxis(axis_re_);
    s->attachAxis(axis_im_);
    hideLegendEntry(chart_, s);
    return s;
  };
  re_axis_line_ = addLine(QColor(0x50, 0x50, 0x50), Qt::SolidLine, 1.0);
  im_axis_line_ = addLine(QColor(0x50, 0x50, 0x50), Qt::SolidLine, 1.0);
  unit_circle_ = addLine(QColor(0x50, 0x50, 0x50), Qt::DashLine, 1.2);
  unit_circle_->setName(QStringLiteral("unit circle"));
  unit_circle_->setVisible(false);

  stable_ = makePoleSeries(QStringLiteral("stable"), QColor(0x1f, 0x77, 0xb4));
  marginal_ = makePoleSeries(QStringLiteral("marginally stable"), QColor(0xe0, 0x8a, 0x00));
  unstable_ = makePoleSeries(QStringLiteral("unstable"), QColor(0xd6, 0x27, 0x28));
  selected_series_ = new QScatterSeries;
  selected_series_->setName(QStringLiteral("selected"));
  selected_series_->setMarkerShape(QScatterSeries::MarkerShapeCircle);
  selected_series_->setMarkerSize(kSelectedMarker);
  selected_series_->setColor(QColor(255, 200, 0, 90));
  QPen ring(QColor(0xff, 0x8c, 0x00));
  ring.setWidthF(2.2);
  selected_series_->setPen(ring);
  // zeros: open circles, the usual symbol
  zero_series_ = new QScatterSeries;
  zero_series_->setName(QStringLiteral("zeros"));
  zero_series_->setMarkerShape(QScatterSeries::MarkerShapeCircle);
  zero_series_->setMarkerSize(kMarker - 2);
  zero_series_->setBrush(Qt::NoBrush);
  QPen zpen(QColor(0x2c, 0xa0, 0x2c));
  zpen.setWidthF(2.0);
  zero_series_->setPen(zpen);
  for (QScatterSeries* s : {zero_series_, selected_series_, stable_, marginal_, unstable_}) {
    chart_->addSeries(s);
    s->attachAxis(axis_re_);
    s->attachAxis(axis_im_);
  }

  view_ = new QChartView(chart_);
  view_->setRenderHint(QPainter::Antialiasing, true);
  view_->setRenderHint(QPainter::TextAntialiasing, true);
  view_->setFrameShape(QFrame::NoFrame);
  view_->setBackgroundBrush(Qt::white);
  view_->viewport()->installEventFilter(this);
  view_->viewport()->setMouseTracking(false);
  legend_ = new QLabel(this);
  legend_->setTextFormat(Qt::RichText);
  legend_->setAlignment(Qt::AlignCenter);
  legend_->setWordWrap(true);
  legend_->setAutoFillBackground(true);
  QPalette pal = legend_->palette();
  pal.setColor(QPalette::Window, Qt::white);
  pal.setColor(QPalette::WindowText, QColor(0x20, 0x20, 0x20));
  legend_->setPalette(pal);
  QFont lf = legend_->font();
  lf.setPointSizeF(8.5);
  legend_->setFont(lf);
  legend_->setContentsMargins(4, 0, 4, 6);
  box_ = new QBoxLayout(QBoxLayout::TopToBottom, this);
  box_->setContentsMargins(0, 0, 0, 0);
  box_->setSpacing(0);
  box_->addWidget(view_, 1);
  box_->addWidget(legend_);

  connect(axis_re_, &QValueAxis::rangeChanged, this, [this](qreal, qreal) { updateAxisLines(); });
  connect(axis_im_, &QValueAxis::rangeChanged, this, [this](qreal, qreal) { updateAxisLines(); });
  // the discrete map keeps equal scales, which depends on the plot area
  connect(chart_, &QChart::plotAreaChanged, this, [this](const QRectF&) {
    if (discrete_) updateRanges();
  });
  setMinimumSize(160, 120);
  rebuild();
}

PoleMap::~PoleMap() = default;

void PoleMap::setModes(const codyna::ModalAnalysis& modal) {
  modal_ = modal;
  discrete_ = modal.Ts > 0.0;
  poles_.clear();
  for (const codyna::Mode& m : modal_.modes) poles_.emplace_back(m.eigenvalue.real(), m.eigenvalue.imag());
  selected_ = -1;
  rebuild();
}

void PoleMap::setZeros(const Eigen::VectorXcd& zeros) {
  zeros_.clear();
  for (const std::complex<double>& z : zeros)
    if (std::isfinite(z.real()) && std::isfinite(z.imag())) zeros_.emplace_back(z.real(), z.imag());
  rebuild();
}

void PoleMap::rebuild() {
  zero_series_->replace(QList<QPointF>(zeros_.begin(), zeros_.end()));
  QList<QPointF> stable, marginal, unstable;
  for (std::size_t i = 0; i < modal_.modes.size(); ++i) {
    // as the core classifies it (Mode::stability, analysis/stability.hpp): a discrete pole on the
    // unit circle, or a continuous one on the imaginary axis, within rounding, is marginal
    switch (modal_.modes[i].stability) {
      case codyna::Stability::Stable: stable.append(poles_[i]); break;
      case codyna::Stability::Marginal: marginal.append(poles_[i]); break;
      case codyna::Stability::Unstable: unstable.append(poles_[i]); break;
    }
  }
  stable_->replace(stable);
  marginal_->replace(marginal);
  unstable_->replace(unstable);
  selectMode(selected_);

  if (discrete_) {
    QList<QPointF> circle;
    const int n = 240;
    for (int k = 0; k <= n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      circle.append(QPointF(std::cos(a), std::sin(a)));
    }
    unit_circle_->replace(circle);
  }
  unit_circle_->setVisible(discrete_);

  if (discrete_) {
    chart_->setTitle(QStringLiteral("%1, z-plane (discrete, Ts = %2 s)")
                         .arg(zeros_.empty() ? QStringLiteral("Poles") : QStringLiteral("Poles and zeros"),
                              QString::number(modal_.Ts, 'g', 6)));
    axis_re_->setTitleText(QStringLiteral("Re(z)"));
    axis_im_->setTitleText(QStringLiteral("Im(z)"));
  } else {
    chart_->setTitle(zeros_.empty() ? QStringLiteral("Poles, s-plane (continuous)")
                                    : QStringLiteral("Poles and zeros, s-plane (continuous)"));
    axis_re_->setTitleText(QStringLiteral("Re(\u03bb) [1/s]"));
    axis_im_->setTitleText(QStringLiteral("Im(\u03bb) [rad/s]"));
  }
  updateRanges();
  updateLegend();
}

// The data box: every pole and the origin (and the unit circle when
// discrete), padded; continuous maps keep Im symmetric. Discrete maps use
// equal scales on both axes so that the unit circle is round.
void PoleMap::updateRanges() {
  if (updating_ranges_) return;
  updating_ranges_ = true;
  double xlo = 0, xhi = 0, ylo = 0, yhi = 0;
  std::vector<QPointF> shown = poles_;
  shown.insert(shown.end(), zeros_.begin(), zeros_.end());
  for (const QPointF& p : shown) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    xlo = std::min(xlo, p.x());
    xhi = std::max(xhi, p.x());
    ylo = std::min(ylo, p.y());
    yhi = std::max(yhi, p.y());
  }
  if (discrete_) {
    xlo = std::min(xlo, -1.0);
    xhi = std::max(xhi, 1.0);
    ylo = std::min(ylo, -1.0);
    yhi = std::max(yhi, 1.0);
    const double pad = 0.08 * std::max(xhi - xlo, yhi - ylo);
    xlo -= pad;
    xhi += pad;
    ylo -= pad;
    yhi += pad;
    // equal scales: widen the axis that has room to spare
    const QRectF area = chart_->plotArea();
    double w = xhi - xlo, h = yhi - ylo;
    if (area.width() > 10 && area.height() > 10) {
      const double scale = std::max(w / area.width(), h / area.height());  // units per pixel
      const double cx = 0.5 * (xlo + xhi), cy = 0.5 * (ylo + yhi);
      w = scale * area.width();
      h = scale * area.height();
      xlo = cx - 0.5 * w;
      xhi = cx + 0.5 * w;
      ylo = cy - 0.5 * h;
      yhi = cy + 0.5 * h;
    }
    const double step = niceRange(0.0, std::max(w, h), 6).step;
    setAxisRange(axis_re_, xlo, xhi, step);
    setAxisRange(axis_im_, ylo, yhi, step);
  } else {
    const double im = std::max(std::abs(ylo), std::abs(yhi));
    double span = std::max(xhi - xlo, 2.0 * im);
    // nothing to show: a range on binary steps (0.5), whose ticks Qt adds up to exactly 0 (steps of
    // 0.1 summed from -0.3 labelled the origin -2.8e-17, elided to "-2...")
    if (span == 0.0) span = 10.0;
    // neither axis squashed to nothing; a bit of both half planes in view
    xlo = std::min(xlo, -0.1 * span);
    xhi = std::max(xhi, 0.1 * span);
    const double imHalf = std::max(im, 0.15 * span);
    const double padX = 0.08 * (xhi - xlo), padY = 0.1 * imHalf;
    const NiceRange rx = niceRange(xlo - padX, xhi + padX, 6);
    const NiceRange ry = niceRange(-imHalf - padY, imHalf + padY, 6);
    const double ymax = std::max(std::abs(ry.min), std::abs(ry.max));
    setAxisRange(axis_re_, rx.min, rx.max, rx.step);
    setAxisRange(axis_im_, -ymax, ymax, ry.step);
  }
  updateAxisLines();
  updating_ranges_ = false;
}

void PoleMap::updateAxisLines() {
  re_axis_line_->replace(QList<QPointF>{{axis_re_->min(), 0.0}, {axis_re_->max(), 0.0}});
  im_axis_line_->replace(QList<QPointF>{{0.0, axis_im_->min()}, {0.0, axis_im_->max()}});
}

void PoleMap::selectMode(int index) {
  if (index < 0 || index >= poleCount()) index = -1;
  selected_ = index;
  if (index < 0)
    selected_series_->clear();
  else
    selected_series_->replace(QList<QPointF>{poles_[index]});
  updateLegend();
}

QString PoleMap::legendText() const { return legend_->text(); }

void PoleMap::updateLegend() {
  const auto entry = [](const QString& symbol, const QColor& colour, const QString& text) {
    return QStringLiteral("<span style=\"color:%1; font-weight:bold; font-size:large\">%2</span>&nbsp;%3").arg(colour.name(), symbol, text);
  };
  QStringList parts;
  if (stable_->count() > 0) parts << entry(QStringLiteral("\u00d7"), QColor(0x1f, 0x77, 0xb4), tr("stable"));
  if (marginal_->count() > 0) parts << entry(QStringLiteral("\u00d7"), QColor(0xe0, 0x8a, 0x00), tr("marginally stable"));
  if (unstable_->count() > 0) parts << entry(QStringLiteral("\u00d7"), QColor(0xd6, 0x27, 0x28), tr("unstable"));
  if (!zeros_.empty()) parts << entry(QStringLiteral("\u25cb"), QColor(0x2c, 0xa0, 0x2c), tr("zeros"));
  if (discrete_) parts << entry(QStringLiteral("- -"), QColor(0x50, 0x50, 0x50), tr("unit circle"));
  QString html = parts.isEmpty() ? tr("no poles")
                                 : parts.join(legend_aside_ ? QStringLiteral("<br>") : QStringLiteral("&nbsp;&nbsp;&nbsp;&nbsp;"));
  if (selected_ >= 0) {
    const codyna::Mode& m = modal_.modes[selected_];
    const std::complex<double> e = m.eigenvalue;
    html += QStringLiteral("<br>") +
            entry(QStringLiteral("\u25cb"), QColor(0xff, 0x8c, 0x00),
                  tr("mode %1: %2 = %3, \u03c9n = %4 rad/s, \u03b6 = %5")
                      .arg(selected_ + 1)
                      .arg(discrete_ ? QStringLiteral("z") : QStringLiteral("\u03bb"),
                           complexText(e.real(), e.imag(), 'j'), QString::number(m.natural_frequency, 'g', 4),
                           QString::number(m.damping_ratio, 'g', 3)));
  }
  legend_->setText(html);
}

QPointF PoleMap::polePosition(int index) const {
  return index >= 0 && index < poleCount() ? poles_[index] : QPointF();
}

QPoint PoleMap::poleWidgetPosition(int index) const {
  if (index < 0 || index >= poleCount()) return {};
  const QPointF inChart = chart_->mapToPosition(poles_[index], selected_series_);
  const QPoint inViewport = view_->mapFromScene(chart_->mapToScene(inChart));
  return view_->viewport()->mapTo(this, inViewport);
}

int PoleMap::poleAt(const QPoint& widgetPos, int radius) const {
  int best = -1;
  double bestDist = radius;
  for (int i = 0; i < poleCount(); ++i) {
    const QPoint d = poleWidgetPosition(i) - widgetPos;
    const double dist = std::hypot(d.x(), d.y());
    // (conjugate pairs far apart, coincident poles: the first, or the selected one, wins)
    if (dist < bestDist || (dist == bestDist && i == selected_)) {
      best = i;
      bestDist = dist;
    }
  }
  return best;
}

void PoleMap::clickAt(const QPoint& widgetPos) {
  const int i = poleAt(widgetPos);
  if (i < 0) return;
  selectMode(i);
  emit modeSelected(i);
}

bool PoleMap::eventFilter(QObject* watched, QEvent* event) {
  if (watched == view_->viewport()) {
    if (event->type() == QEvent::MouseButtonPress) {
      auto* me = static_cast<QMouseEvent*>(event);
      if (me->button() == Qt::LeftButton) clickAt(view_->viewport()->mapTo(this, me->position().toPoint()));
    } else if (event->type() == QEvent::ToolTip) {
      auto* he = static_cast<QHelpEvent*>(event);
      const int i = poleAt(view_->viewport()->mapTo(this, he->pos()));
      if (i >= 0)
        QToolTip::showText(he->globalPos(), poleText(i), view_->viewport());
      else
        QToolTip::hideText();
      return true;
    }
  }
  return QWidget::eventFilter(watched, event);
}

void PoleMap::mousePressEvent(QMouseEvent* event) {
  if (event->button() == Qt::LeftButton) clickAt(event->position().toPoint());
  QWidget::mousePressEvent(event);
}

void PoleMap::resizeEvent(QResizeEvent* event) {
  QWidget::resizeEvent(event);
  // wider than tall: the legend goes to the side, one entry per line, and the plot keeps the height
  const bool aside = width() > 1.4 * height() && width() >= 320;
  if (aside != legend_aside_) {
    legend_aside_ = aside;
    box_->setDirection(aside ? QBoxLayout::LeftToRight : QBoxLayout::TopToBottom);
    legend_->setAlignment(aside ? Qt::AlignLeft | Qt::AlignVCenter : Qt::AlignCenter);
    updateLegend();
  }
  legend_->setFixedWidth(aside ? std::clamp(width() / 3, 120, 220) : QWIDGETSIZE_MAX);
  if (!aside) legend_->setMinimumWidth(0);
  if (discrete_) updateRanges();
}

QString PoleMap::poleText(int index) const {
  const codyna::Mode& m = modal_.modes[index];
  QString text = QStringLiteral("Mode %1\n").arg(index + 1);
  if (discrete_) {
    text += QStringLiteral("z = %1\n").arg(complexText(m.eigenvalue.real(), m.eigenvalue.imag(), 'j'));
    text += QStringLiteral("s = ln(z)/Ts = %1\n").arg(complexText(m.s.real(), m.s.imag(), 'j'));
  } else {
    text += QStringLiteral("\u03bb = %1\n").arg(complexText(m.eigenvalue.real(), m.eigenvalue.imag(), 'j'));
  }
  text += QStringLiteral("\u03c9n = %1 rad/s (%2 Hz)\n\u03b6 = %3")
              .arg(QString::number(m.natural_frequency, 'g', 6),
                   QString::number(m.natural_frequency / (2.0 * std::numbers::pi), 'g', 6),
                   QString::number(m.damping_ratio, 'g', 4));
  return text;
}

bool PoleMap::saveImage(const QString& path, QString* error) {
  if (!is_image_path(path)) return save_widget_image(this, path, {}, {}, error);  // the error message
  ensurePolished();
  if (layout()) layout()->activate();
  QCoreApplication::sendPostedEvents(nullptr, QEvent::LayoutRequest);
  return save_widget_image(this, path, QStringLiteral("codyna pole map"), [this](QPainter& painter) {
    view_->render(&painter, QRectF(QRect(view_->mapTo(this, QPoint(0, 0)), view_->size())), view_->viewport()->rect());
    if (legend_->isVisibleTo(this)) legend_->render(&painter, legend_->mapTo(this, QPoint(0, 0)));
  }, error);
}

int PoleMap::drawnStable() const { return static_cast<int>(stable_->count()); }
int PoleMap::drawnMarginal() const { return static_cast<int>(marginal_->count()); }
int PoleMap::drawnUnstable() const { return static_cast<int>(unstable_->count()); }

}  // namespace codyna::gui
