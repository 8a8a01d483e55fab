#include "gui/result_plots.hpp"

#include "gui/chart_view.hpp"
#include "gui/image_export.hpp"

#include <QApplication>
#include <QBuffer>
#include <QChart>
#include <QChartView>
#include <QFileInfo>
#include <QImage>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QPainter>
#include <QPixmap>
#include <QSaveFile>
#include <QSplitter>
#include <QSvgGenerator>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <limits>

namespace codyna::gui {

// ---------------------------------------------------------------------------
// helpers shared with PoleMap (declared in the header)

NiceRange niceRange(double lo, double hi, int ticks) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = hi = 0.0;
  if (lo > hi) std::swap(lo, hi);
  ticks = std::max(ticks, 1);
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {  // a single value (or all zero)
    const double half = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    lo -= half;
    hi += half;
  }
  const double raw = (hi - lo) / ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  const double nice = f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 2.5 ? 2.5 : f <= 5.0 ? 5.0 : 10.0;
  NiceRange r;
  r.step = nice * mag;
  // (the small tolerance keeps a bound that is already a multiple of step from moving a whole step)
  r.min = std::floor(lo / r.step + 1e-9) * r.step;
  r.max = std::ceil(hi / r.step - 1e-9) * r.step;
  if (r.max <= r.min) r.max = r.min + r.step;
  // -0 prints as "-0"
  if (r.min == 0.0) r.min = 0.0;
  if (r.max == 0.0) r.max = 0.0;
  return r;
}

void setAxisRange(QValueAxis* axis, double min, double max, double step) {
  if (!(max > min) || !(step > 0.0) || !std::isfinite(min) || !std::isfinite(max)) return;
  step = std::max(step, (max - min) / 50.0);  // never more than ~50 ticks
  const double coarse = std::max({max - min, axis->max() - axis->min(), step});
  axis->setTickAnchor(0.0);
  axis->setTickInterval(coarse);  // value_at most a few ticks in either range
  axis->setRange(min, max);
  axis->setTickInterval(step);
}

void fitAxesToLines(QChart* c, const QString& x_title, const QString& y_title) {
  double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
  for (QAbstractSeries* s : c->series())
    if (auto* l = qobject_cast<QLineSeries*>(s))
      for (const QPointF& p : l->points()) {
        xlo = std::min(xlo, p.x()), xhi = std::max(xhi, p.x());
        ylo = std::min(ylo, p.y()), yhi = std::max(yhi, p.y());
      }
  auto* x = qobject_cast<QValueAxis*>(c->axes(Qt::Horizontal).value(0));
  auto* y = qobject_cast<QValueAxis*>(c->axes(Qt::Vertical).value(0));
  if (!x || !y) return;
  x->setTitleText(x_title);
  y->setTitleText(y_title);
  if (!(xlo <= xhi)) xlo = -1, xhi = 1;
  if (!(ylo <= yhi)) ylo = -1, yhi = 1;
  const NiceRange rx = niceRange(xlo, xhi, 6), ry = niceRange(ylo, yhi, 6);
  // the ticks' labels with the step's decimals: Qt adds the step to the first tick, so a tick at 0
  // after -0.3 + 3 x 0.1 is 5.6e-17, which "%g" would print as such
  for (auto [a, r] : {std::pair{x, rx}, std::pair{y, ry}}) {
    const double big = std::max(std::abs(r.min), std::abs(r.max));
    // as many decimals as the step has (0.625: 3), so that no label is rounded
    int decimals = 0;
    for (double m = r.step; decimals < 6 && std::abs(m - std::round(m)) > 1e-6 * m; m *= 10) ++decimals;
    if (r.step >= 1e-4 && big < 1e7) a->setLabelFormat(QStringLiteral("%.%1f").arg(decimals));
    else a->setLabelFormat("%.4g");
    setAxisRange(a, r.min, r.max, r.step);
  }
}

QString nameWithUnit(const QString& name, const QString& unit) {
  return unit.trimmed().isEmpty() ? name : QStringLiteral("%1 [%2]").arg(name, unit.trimmed());
}

namespace {

// a palette that prints well and stays distinguishable (the "tab10" colours)
QColor seriesColor(int k) {
  static const QRgb colours[] = {0x1f77b4, 0xd62728, 0x2ca02c, 0xff7f0e, 0x9467bd,
                                 0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf};
  return QColor(colours[k % 10]);
}

QString value_at(const QStringList& list, int k) { return k < list.size() ? list[k] : QString(); }

void hidePlotLegendEntry(QChart* chart, QAbstractSeries* s) {
  for (QLegendMarker* m : chart->legend()->markers(s)) m->setVisible(false);
}

// y axis title: the common unit when all series share one ("[rad]", with the
// names when they are few), otherwise the generic symbol only.
QString yTitle(const QString& symbol, const QStringList& names, const QStringList& units) {
  if (names.isEmpty()) return symbol;
  QString unit = value_at(units, 0).trimmed();
  for (int k = 1; k < names.size(); ++k)
    if (value_at(units, k).trimmed() != unit) return symbol;
  const QString label = names.size() <= 2 ? names.join(QStringLiteral(", ")) : symbol;
  return nameWithUnit(label, unit);
}

void stylePlotAxis(QValueAxis* axis, const QString& title) {
  QFont f = axis->labelsFont();
  f.setPointSizeF(8.5);
  axis->setLabelsFont(f);
  QFont tf = f;
  tf.setPointSizeF(9);
  axis->setTitleFont(tf);
  axis->setTitleText(title);
  axis->setLabelFormat(QStringLiteral("%.6g"));
  axis->setTickType(QValueAxis::TicksDynamic);
  axis->setTickAnchor(0.0);
  axis->setMinorTickCount(0);
  axis->setGridLineColor(QColor(0xdd, 0xdd, 0xdd));
  axis->setLinePenColor(QColor(0x60, 0x60, 0x60));
  axis->setLabelsColor(QColor(0x20, 0x20, 0x20));
  axis->setTitleBrush(QColor(0x20, 0x20, 0x20));
}

void applyNice(QValueAxis* axis, const NiceRange& r) { setAxisRange(axis, r.min, r.max, r.step); }

}  // namespace

// ---------------------------------------------------------------------------

ResultPlots::ResultPlots(QWidget* parent)
    : QWidget(parent), cursor_t_(std::numeric_limits<double>::quiet_NaN()) {
  clock_.start();
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  auto* splitter = new QSplitter(Qt::Vertical, this);
  splitter->setChildrenCollapsible(false);
  layout->addWidget(splitter);
  buildPanel(in_, QStringLiteral("Plant/In"));
  buildPanel(out_, QStringLiteral("Plant/Out"));
  splitter->addWidget(in_.view);
  splitter->addWidget(out_.view);

  // the two t axes line up (the y labels and the legends differ in width)
  align_timer_ = new QTimer(this);
  align_timer_->setSingleShot(true);
  align_timer_->setInterval(0);
  connect(align_timer_, &QTimer::timeout, this, [this] { alignPlotAreas(); });
  for (Panel* p : {&in_, &out_})
    connect(p->chart, &QChart::plotAreaChanged, align_timer_, qOverload<>(&QTimer::start));

  timer_ = new QTimer(this);
  timer_->setSingleShot(true);
  connect(timer_, &QTimer::timeout, this, &ResultPlots::redraw);

  updateTimeAxis(1.0);
  updateYRange(in_, true);
  updateYRange(out_, true);
  setMinimumSize(240, 180);  // the window fits 1024 x 700
}

ResultPlots::~ResultPlots() = default;

void ResultPlots::buildPanel(Panel& p, const QString& title) {
  p.chart = new QChart;
  p.chart->setTitle(title);
  QFont tf = p.chart->titleFont();
  tf.setBold(true);
  tf.setPointSizeF(10);
  p.chart->setTitleFont(tf);
  p.chart->setBackgroundRoundness(0);
  p.chart->setMargins(QMargins(4, 2, 8, 2));  // (= kChartMargins)
  p.chart->setAnimationOptions(QChart::NoAnimation);
  p.chart->legend()->setAlignment(Qt::AlignRight);
  QFont lf = p.chart->legend()->font();
  lf.setPointSizeF(8.5);
  p.chart->legend()->setFont(lf);
  p.chart->legend()->setMarkerShape(QLegend::MarkerShapeFromSeries);

  p.axis_t = new QValueAxis;
  p.axis_y = new QValueAxis;
  stylePlotAxis(p.axis_t, QStringLiteral("t [s]"));
  stylePlotAxis(p.axis_y, QString());
  p.chart->addAxis(p.axis_t, Qt::AlignBottom);
  p.chart->addAxis(p.axis_y, Qt::AlignLeft);

  p.cursor = new QLineSeries;
  p.cursor->setName(QStringLiteral("t"));
  QPen pen(QColor(0x40, 0x40, 0x40));
  pen.setWidthF(1.0);
  pen.setStyle(Qt::DashDotLine);
  p.cursor->setPen(pen);
  p.chart->addSeries(p.cursor);
  p.cursor->attachAxis(p.axis_t);
  p.cursor->attachAxis(p.axis_y);
  p.cursor->setVisible(false);
  hidePlotLegendEntry(p.chart, p.cursor);

  p.view = new ChartView(p.chart);  // takes ownership of the chart; zoom, pan, readout, copy
  p.view->setRenderHint(QPainter::Antialiasing, true);
  p.view->setRenderHint(QPainter::TextAntialiasing, true);
  p.view->setMinimumHeight(85);
  p.view->setBackgroundBrush(Qt::white);
  p.view->setFrameShape(QFrame::NoFrame);

  // keep the cursor spanning the y axis when its range changes
  connect(p.axis_y, &QValueAxis::rangeChanged, this, [this, &p](qreal, qreal) { updateCursor(p); });
}

namespace {
const QMargins kChartMargins(4, 2, 8, 2);
}

// Pads the charts' margins so that both plot areas span the same x pixels:
// the natural edges (without the padding) are compared and the narrower
// chart padded; converges in one more layout pass.
bool ResultPlots::alignPlotAreas() {
  if (aligning_) return false;
  aligning_ = true;
  bool changed = false;
  const double left0 = in_.chart->plotArea().left() - in_.extra_left;
  const double left1 = out_.chart->plotArea().left() - out_.extra_left;
  const double right0 = in_.chart->plotArea().right() + in_.extra_right;
  const double right1 = out_.chart->plotArea().right() + out_.extra_right;
  const double left = std::max(left0, left1), right = std::min(right0, right1);
  const auto apply = [&changed](Panel& p, double extraLeft, double extraRight) {
    extraLeft = std::max(0.0, std::round(extraLeft));
    extraRight = std::max(0.0, std::round(extraRight));
    if (extraLeft == p.extra_left && extraRight == p.extra_right) return;
    changed = true;
    p.extra_left = extraLeft;
    p.extra_right = extraRight;
    p.chart->setMargins(kChartMargins + QMargins(int(extraLeft), 0, int(extraRight), 0));
  };
  if (in_.chart->plotArea().width() > 10 && out_.chart->plotArea().width() > 10) {
    apply(in_, left - left0, right0 - right);
    apply(out_, left - left1, right1 - right);
  }
  aligning_ = false;
  return changed;
}

void ResultPlots::clearPanel(Panel& p) {
  for (QLineSeries* s : p.series) {
    p.chart->removeSeries(s);
    delete s;
  }
  for (const auto* list : {&p.linear, &p.reference})
    for (QLineSeries* s : *list) {
      p.chart->removeSeries(s);
      delete s;
    }
  p.series.clear();
  p.linear.clear();
  p.reference.clear();
  p.data.clear();
  p.linear_data.clear();
  p.reference_data.clear();
  p.y_lo = 1.0;
  p.y_hi = 0.0;
  p.shown_lo = 1.0;
  p.shown_hi = 0.0;
}

void ResultPlots::setupSeries(Panel& p, const QStringList& names, const QStringList& units, bool withLinear,
                              bool withReference) {
  clearPanel(p);
  // attaching a series re-initializes the axes' ranges with the tick interval they have: after a
  // zoom far in, that interval laid out billions of labels (the monkey test's 32 GB request under
  // ASan, caught in gdb value_at ChartValueAxisY::calculateLayout from attachAxis). Coarse until the
  // ranges are set again (setAxisRange sets the step).
  for (QValueAxis* a : {p.axis_t, p.axis_y}) a->setTickInterval(std::numeric_limits<double>::max() / 4);
  // the cursor is re-added last so that it is drawn over the data
  p.chart->removeSeries(p.cursor);
  const int n = static_cast<int>(names.size());
  // one curve of output k: the run's (solid), the linear prediction (dashed), the reference (dotted)
  const auto curve = [&p](const QString& name, const QPen& pen, std::vector<QLineSeries*>& series,
                          std::vector<QList<QPointF>>& data) {
    auto* s = new QLineSeries;
    s->setName(name);
    s->setPen(pen);
    p.chart->addSeries(s);
    s->attachAxis(p.axis_t);
    s->attachAxis(p.axis_y);
    series.push_back(s);
    data.emplace_back();
  };
  for (int k = 0; k < n; ++k) {
    const QColor colour = seriesColor(k);
    QPen pen(colour);
    pen.setWidthF(1.8);
    pen.setCapStyle(Qt::RoundCap);
    pen.setJoinStyle(Qt::RoundJoin);
    curve(nameWithUnit(names[k], value_at(units, k)), pen, p.series, p.data);
    if (withLinear) {
      QPen lpen(colour);
      lpen.setWidthF(1.6);
      lpen.setStyle(Qt::CustomDashLine);
      lpen.setDashPattern({5.0, 3.0});
      curve(nameWithUnit(names[k] + QStringLiteral(" (linear)"), value_at(units, k)), lpen, p.linear, p.linear_data);
    }
    if (withReference) {
      QPen rpen(colour.darker(160));
      rpen.setWidthF(1.3);
      rpen.setStyle(Qt::CustomDashLine);
      rpen.setDashPattern({1.0, 2.5});
      rpen.setCapStyle(Qt::RoundCap);
      curve(nameWithUnit(names[k] + QStringLiteral(" (reference)"), value_at(units, k)), rpen, p.reference, p.reference_data);
    }
  }
  p.chart->addSeries(p.cursor);
  p.cursor->attachAxis(p.axis_t);
  p.cursor->attachAxis(p.axis_y);
  hidePlotLegendEntry(p.chart, p.cursor);
  p.chart->legend()->setVisible(n > 0);
}

void ResultPlots::reset(const QStringList& inputNames, const QStringList& inputUnits, const QStringList& outputNames,
                        const QStringList& outputUnits, double tEnd) {
  timer_->stop();
  dirty_ = false;
  setupSeries(in_, inputNames, inputUnits, false);
  setupSeries(out_, outputNames, outputUnits, false);
  in_.axis_y->setTitleText(yTitle(QStringLiteral("u"), inputNames, inputUnits));
  out_.axis_y->setTitleText(yTitle(QStringLiteral("y"), outputNames, outputUnits));
  t_end_ = std::isfinite(tEnd) && tEnd > 0.0 ? tEnd : 1.0;
  t_max_seen_ = 0.0;
  updateTimeAxis(t_end_);
  updateYRange(in_, true);
  updateYRange(out_, true);
  ++redraws_;
}

void ResultPlots::extend(Panel& p, double y) {
  if (p.y_lo > p.y_hi) {
    p.y_lo = p.y_hi = y;
  } else {
    p.y_lo = std::min(p.y_lo, y);
    p.y_hi = std::max(p.y_hi, y);
  }
}

void ResultPlots::appendSample(double t, const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  if (!std::isfinite(t)) return;
  const auto push = [t](Panel& p, const Eigen::VectorXd& v) {
    const Eigen::Index n = std::min<Eigen::Index>(v.size(), static_cast<Eigen::Index>(p.data.size()));
    for (Eigen::Index k = 0; k < n; ++k) {
      if (!std::isfinite(v(k))) continue;
      p.data[k].append(QPointF(t, v(k)));
      extend(p, v(k));
    }
  };
  push(in_, u);
  push(out_, y);
  t_max_seen_ = std::max(t_max_seen_, t);
  dirty_ = true;
  scheduleRedraw();
}

void ResultPlots::scheduleRedraw() {
  if (timer_->isActive()) return;
  const qint64 since = clock_.elapsed() - last_redraw_ms_;
  timer_->start(static_cast<int>(std::clamp<qint64>(refresh_ms_ - since, 0, refresh_ms_)));
}

void ResultPlots::flush() {
  timer_->stop();
  if (dirty_) redraw();
}

void ResultPlots::redraw() {
  if (!dirty_) return;
  dirty_ = false;
  last_redraw_ms_ = clock_.elapsed();
  for (Panel* p : {&in_, &out_}) {
    for (std::size_t k = 0; k < p->series.size(); ++k) p->series[k]->replace(plotted(p->data[k]));
    for (std::size_t k = 0; k < p->linear.size(); ++k) p->linear[k]->replace(plotted(p->linear_data[k]));
    for (std::size_t k = 0; k < p->reference.size(); ++k) p->reference[k]->replace(plotted(p->reference_data[k]));
    updateYRange(*p, false);
  }
  if (t_max_seen_ > in_.axis_t->max() * (1.0 + 1e-12)) updateTimeAxis(t_max_seen_);
  ++redraws_;
}

void ResultPlots::setRefreshIntervalMs(int ms) { refresh_ms_ = std::max(ms, 1); }

void ResultPlots::setMaxPlotPoints(int n) {
  max_points_ = std::max(n, 16);
  dirty_ = true;
  flush();
}

// all samples up to max_points_; beyond, per bucket of consecutive samples the
// first, the minimum, the maximum and the last one, in time order
QList<QPointF> ResultPlots::plotted(const QList<QPointF>& all) const {
  const qsizetype n = all.size();
  if (n <= max_points_) return all;
  const qsizetype buckets = std::max<qsizetype>(max_points_ / 4, 1);
  QList<QPointF> out;
  out.reserve(buckets * 4);
  for (qsizetype b = 0; b < buckets; ++b) {
    const qsizetype first = b * n / buckets, last = (b + 1) * n / buckets - 1;
    if (last < first) continue;
    qsizetype lo = first, hi = first;
    for (qsizetype i = first; i <= last; ++i) {
      if (all[i].y() < all[lo].y()) lo = i;
      if (all[i].y() > all[hi].y()) hi = i;
    }
    qsizetype idx[4] = {first, std::min(lo, hi), std::max(lo, hi), last};
    for (int j = 0; j < 4; ++j)
      if (j == 0 || idx[j] != idx[j - 1]) out.append(all[idx[j]]);
  }
  return out;
}

void ResultPlots::updateTimeAxis(double tEnd) {
  const NiceRange r = niceRange(0.0, tEnd, 8);
  // a run's time axis ends value_at t_end itself (not a rounded-up value); live
  // samples beyond it extend it to the next nice number
  const double max = tEnd > t_end_ ? r.max : tEnd;
  for (Panel* p : {&in_, &out_}) {
    setAxisRange(p->axis_t, 0.0, max, r.step);
  }
}

// y range: the data range padded by 5 %, rounded out to nice numbers. While
// a run is live it only grows (no jumping axes); allowShrink refits.
void ResultPlots::updateYRange(Panel& p, bool allowShrink) {
  double lo = p.y_lo, hi = p.y_hi;
  if (lo > hi) {  // no data yet
    lo = -1.0;
    hi = 1.0;
  } else {
    const double span = hi - lo;
    const double pad = span > 0.0 ? 0.05 * span : std::max(std::abs(hi) * 0.1, 1e-3);
    lo -= pad;
    hi += pad;
  }
  if (!allowShrink && p.shown_lo <= p.shown_hi) {
    if (lo >= p.shown_lo && hi <= p.shown_hi) return;  // still fits
    lo = std::min(lo, p.shown_lo);
    hi = std::max(hi, p.shown_hi);
  }
  const NiceRange r = niceRange(lo, hi, 5);
  applyNice(p.axis_y, r);
  const bool hasData = p.y_lo <= p.y_hi;
  p.shown_lo = hasData ? r.min : 1.0;  // (the default range of an empty chart does not count as fitted)
  p.shown_hi = hasData ? r.max : 0.0;
  updateCursor(p);
}

void ResultPlots::setResult(const codyna::SimulationResult& r, const std::vector<int>& plantInputs) {
  timer_->stop();
  dirty_ = false;
  const auto qstr = [](const std::vector<std::string>& v, std::size_t k) {
    return k < v.size() ? QString::fromStdString(v[k]) : QString();
  };
  QStringList inNames, inUnits, outNames, outUnits;
  std::vector<int> cols;
  for (int c : plantInputs) {
    if (c < 0 || c >= r.u.cols()) continue;  // not in the result: skipped
    cols.push_back(c);
    const QString name = qstr(r.input_names, c);
    inNames << (name.isEmpty() ? QStringLiteral("u%1").arg(c + 1) : name);
    inUnits << qstr(r.input_units, c);
  }
  for (Eigen::Index c = 0; c < r.y.cols(); ++c) {
    const QString name = qstr(r.output_names, c);
    outNames << (name.isEmpty() ? QStringLiteral("y%1").arg(c + 1) : name);
    outUnits << qstr(r.output_units, c);
  }
  const Eigen::Index n = std::min<Eigen::Index>(static_cast<Eigen::Index>(r.t.size()), r.y.rows());
  const bool linear = r.y_linear.size() > 0 && r.y_linear.cols() == r.y.cols() && r.y_linear.rows() >= n;
  setupSeries(in_, inNames, inUnits, false);
  const bool reference = r.y_reference.size() > 0 && r.y_reference.cols() == r.y.cols() && r.y_reference.rows() >= n;
  setupSeries(out_, outNames, outUnits, linear, reference);
  in_.axis_y->setTitleText(yTitle(QStringLiteral("u"), inNames, inUnits));
  out_.axis_y->setTitleText(yTitle(QStringLiteral("y"), outNames, outUnits));

  const auto fill = [&](QList<QPointF>& pts, Panel& p, const Eigen::MatrixXd& m, Eigen::Index col, Eigen::Index rows) {
    pts.reserve(rows);
    for (Eigen::Index i = 0; i < rows; ++i) {
      const double t = r.t[i], v = m(i, col);
      if (!std::isfinite(t) || !std::isfinite(v)) continue;
      pts.append(QPointF(t, v));
      extend(p, v);
    }
  };
  const Eigen::Index nu = std::min<Eigen::Index>(static_cast<Eigen::Index>(r.t.size()), r.u.rows());
  for (std::size_t k = 0; k < cols.size(); ++k) fill(in_.data[k], in_, r.u, cols[k], nu);
  for (Eigen::Index k = 0; k < r.y.cols(); ++k) fill(out_.data[k], out_, r.y, k, n);
  if (linear)
    for (Eigen::Index k = 0; k < r.y.cols(); ++k) fill(out_.linear_data[k], out_, r.y_linear, k, n);
  if (reference)
    for (Eigen::Index k = 0; k < r.y.cols(); ++k) fill(out_.reference_data[k], out_, r.y_reference, k, n);

  for (Panel* p : {&in_, &out_}) {
    for (std::size_t k = 0; k < p->series.size(); ++k) p->series[k]->replace(plotted(p->data[k]));
    for (std::size_t k = 0; k < p->linear.size(); ++k) p->linear[k]->replace(plotted(p->linear_data[k]));
    for (std::size_t k = 0; k < p->reference.size(); ++k) p->reference[k]->replace(plotted(p->reference_data[k]));
    updateYRange(*p, true);
  }
  double t0 = 0.0, t1 = 0.0;
  for (double t : r.t)
    if (std::isfinite(t)) {
      t0 = std::min(t0, t);
      t1 = std::max(t1, t);
    }
  t_end_ = t1 > t0 ? t1 : 1.0;
  t_max_seen_ = t1;
  updateTimeAxis(t_end_);
  if (t0 < 0.0)
    for (Panel* p : {&in_, &out_}) setAxisRange(p->axis_t, t0, p->axis_t->max(), niceRange(t0, t_end_, 8).step);
  last_redraw_ms_ = clock_.elapsed();
  ++redraws_;
}

void ResultPlots::setTimeCursor(double t) {
  cursor_t_ = t;
  updateCursor(in_);
  updateCursor(out_);
}

void ResultPlots::updateCursor(Panel& p) {
  if (!p.cursor) return;
  if (!std::isfinite(cursor_t_)) {
    p.cursor->setVisible(false);
    return;
  }
  p.cursor->replace(QList<QPointF>{{cursor_t_, p.axis_y->min()}, {cursor_t_, p.axis_y->max()}});
  p.cursor->setVisible(true);
  hidePlotLegendEntry(p.chart, p.cursor);
}

QList<QPointF> ResultPlots::inputPoints(int k) const {
  return k >= 0 && k < inputSeriesCount() ? in_.series[k]->points() : QList<QPointF>();
}
QList<QPointF> ResultPlots::outputPoints(int k) const {
  return k >= 0 && k < outputSeriesCount() ? out_.series[k]->points() : QList<QPointF>();
}
QList<QPointF> ResultPlots::referencePoints(int k) const {
  return k >= 0 && k < static_cast<int>(out_.reference.size()) ? out_.reference[k]->points() : QList<QPointF>();
}
QList<QPointF> ResultPlots::linearPoints(int k) const {
  return k >= 0 && k < static_cast<int>(out_.linear.size()) ? out_.linear[k]->points() : QList<QPointF>();
}

bool ResultPlots::saveImage(const QString& path, QString* error) {
  if (!is_image_path(path)) return save_widget_image(this, path, {}, {}, error);  // the error message
  flush();
  ensurePolished();
  if (layout()) layout()->activate();
  // chart layouts are posted events; the alignment of the plot areas takes another pass
  for (int pass = 0; pass < 6; ++pass) {
    QCoreApplication::sendPostedEvents(nullptr, QEvent::LayoutRequest);
    if (!alignPlotAreas() && pass > 0) break;
  }

  return save_widget_image(this, path, QStringLiteral("codyna simulation plots"), [this](QPainter& painter) {
    for (const Panel* p : {&in_, &out_}) {
      if (!p->view->isVisibleTo(this)) continue;
      const QRect target(p->view->mapTo(this, QPoint(0, 0)), p->view->size());
      p->view->render(&painter, QRectF(target), p->view->viewport()->rect());
    }
  }, error);
}

}  // namespace codyna::gui
