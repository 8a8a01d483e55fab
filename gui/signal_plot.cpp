#include "gui/signal_plot.hpp"

#include <QChart>
#include <QHBoxLayout>
#include <QLineSeries>
#include <QListWidget>
#include <QPen>
#include <QPushButton>
#include <QSplitter>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"

namespace codyna::gui {

namespace {
constexpr int kMaxKept = 4;
constexpr int kMaxPoints = 4000;  // per curve: every k-th sample beyond that

QString unitSuffix(const std::vector<std::string>& units, std::size_t k) {
  return k < units.size() && !units[k].empty() ? QStringLiteral(" [%1]").arg(qs(units[k])) : QString();
}
}  // namespace

SignalPlot::SignalPlot(QWidget* parent) : QWidget(parent) {
  list_ = new QListWidget(this);
  list_->setObjectName("signalList");
  list_->setToolTip(tr("Tick the recorded quantities to plot over time"));
  keep_ = new QPushButton(tr("Keep for comparison"), this);
  keep_->setObjectName("keepRun");
  keep_->setToolTip(tr("Pin this run: its ticked signals stay drawn dashed under the next runs (up to four)"));
  clear_ = new QPushButton(tr("Clear kept"), this);
  chart_ = new QChart;
  chart_->setMargins(QMargins(2, 0, 6, 0));
  chart_->setBackgroundRoundness(0);
  chart_->setAnimationOptions(QChart::NoAnimation);
  chart_->legend()->setAlignment(Qt::AlignRight);
  auto* tx = new QValueAxis;
  tx->setTitleText(tr("t [s]"));
  tx->setLabelFormat("%g");
  auto* ty = new QValueAxis;
  ty->setLabelFormat("%.4g");
  chart_->addAxis(tx, Qt::AlignBottom);
  chart_->addAxis(ty, Qt::AlignLeft);
  view_ = new ChartView(chart_, this);
  view_->setObjectName("signalChart");
  view_->setMinimumSize(200, 100);

  auto* side = new QWidget(this);
  auto* sl = new QVBoxLayout(side);
  sl->setContentsMargins(0, 0, 0, 0);
  sl->addWidget(list_, 1);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(keep_);
  buttons->addWidget(clear_);
  sl->addLayout(buttons);
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->addWidget(side);
  split->addWidget(view_);
  split->setStretchFactor(1, 1);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(split);

  connect(list_, &QListWidget::itemChanged, this, [this] { redraw(); });
  connect(keep_, &QPushButton::clicked, this, &SignalPlot::keepCurrent);
  connect(clear_, &QPushButton::clicked, this, &SignalPlot::clearKept);
  setResult(nullptr);
}

namespace {

// every recorded quantity of a result, named as the list shows it, with the way to read it:
// one walk that both the names and the values come from
struct Entry {
  QString name;
  const Eigen::MatrixXd* matrix = nullptr;  // a column of it
  int column = 0;
  const std::vector<double>* series = nullptr;
  int sum = 0;  // 1: total energy (kinetic + potential)
};

std::vector<Entry> entries(const SimulationResult& r) {
  std::vector<Entry> e;
  const auto columns = [&](const Eigen::MatrixXd& m, const std::vector<std::string>& names, const QString& prefix,
                           const QString& suffix, const std::vector<std::string>* units) {
    for (std::size_t k = 0; k < names.size() && static_cast<Eigen::Index>(k) < m.cols(); ++k)
      e.push_back({prefix + qs(names[k]) + suffix + (units ? unitSuffix(*units, k) : QString()), &m, static_cast<int>(k)});
  };
  columns(r.q, r.q_names, {}, {}, nullptr);
  columns(r.v, r.v_names, {}, {}, nullptr);
  columns(r.u, r.input_names, {}, {}, &r.input_units);
  columns(r.y, r.output_names, QStringLiteral("y: "), {}, &r.output_units);
  columns(r.y_reference, r.output_names, QStringLiteral("r: "), {}, &r.output_units);
  columns(r.y_linear, r.output_names, QStringLiteral("y: "), QStringLiteral(" (linear)"), &r.output_units);
  columns(r.u_disturbance, r.input_names, QStringLiteral("d: "), {}, &r.input_units);
  columns(r.xc, r.controller_state_names, QStringLiteral("controller: "), {}, nullptr);
  if (!r.kinetic_energy.empty()) {
    e.push_back({QStringLiteral("kinetic energy [J]"), nullptr, 0, &r.kinetic_energy});
    e.push_back({QStringLiteral("potential energy [J]"), nullptr, 0, &r.potential_energy});
    e.push_back({QStringLiteral("total energy [J]"), nullptr, 0, nullptr, 1});
  }
  if (!r.constraint_violation.empty()) {
    e.push_back({QStringLiteral("constraint drift |phi|"), nullptr, 0, &r.constraint_violation});
    e.push_back({QStringLiteral("velocity drift |Jc v|"), nullptr, 0, &r.velocity_violation});
  }
  return e;
}

}  // namespace

QStringList SignalPlot::signalNames(const SimulationResult& r) {
  QStringList n;
  for (const Entry& e : entries(r)) n << e.name;
  return n;
}

std::vector<double> SignalPlot::signal(const SimulationResult& r, const QString& name) {
  std::vector<double> out;
  for (const Entry& e : entries(r)) {
    if (e.name != name) continue;
    if (e.matrix) {
      for (int i = 0; i < r.samples() && i < e.matrix->rows(); ++i) out.push_back((*e.matrix)(i, e.column));
    } else if (e.series) {
      out = *e.series;
    } else if (e.sum == 1) {
      for (std::size_t i = 0; i < r.kinetic_energy.size() && i < r.potential_energy.size(); ++i)
        out.push_back(r.kinetic_energy[i] + r.potential_energy[i]);
    }
    break;
  }
  return out;
}

void SignalPlot::setResult(std::shared_ptr<const SimulationResult> r) {
  const QStringList was = checked();
  current_ = std::move(r);
  {
    const QSignalBlocker b(list_);
    list_->clear();
    if (current_) {
      const QStringList names = signalNames(*current_);
      for (const QString& n : names) {
        auto* item = new QListWidgetItem(n, list_);
        item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable | Qt::ItemIsSelectable);
        item->setCheckState(was.contains(n) ? Qt::Checked : Qt::Unchecked);
      }
      // a first run shows the outputs
      if (was.isEmpty())
        for (int i = 0; i < list_->count(); ++i)
          if (list_->item(i)->text().startsWith("y: ")) list_->item(i)->setCheckState(Qt::Checked);
    }
  }
  keep_->setEnabled(current_ && current_->samples() > 0);
  redraw();
}

void SignalPlot::keepCurrent() {
  if (!current_ || current_->samples() == 0) return;
  if (std::find(kept_.begin(), kept_.end(), current_) != kept_.end()) return;
  kept_.push_back(current_);
  if (static_cast<int>(kept_.size()) > kMaxKept) kept_.erase(kept_.begin());
  redraw();
}

void SignalPlot::clearKept() {
  kept_.clear();
  redraw();
}

void SignalPlot::setChecked(const QString& name, bool on) {
  for (int i = 0; i < list_->count(); ++i)
    if (list_->item(i)->text() == name) list_->item(i)->setCheckState(on ? Qt::Checked : Qt::Unchecked);
}

QStringList SignalPlot::checked() const {
  QStringList l;
  for (int i = 0; i < list_->count(); ++i)
    if (list_->item(i)->checkState() == Qt::Checked) l << list_->item(i)->text();
  return l;
}

int SignalPlot::curveCount() const { return static_cast<int>(chart_->series().size()); }

void SignalPlot::redraw() {
  chart_->removeAllSeries();
  clear_->setEnabled(!kept_.empty());
  auto* tx = static_cast<QValueAxis*>(chart_->axes(Qt::Horizontal).value(0));
  auto* ty = static_cast<QValueAxis*>(chart_->axes(Qt::Vertical).value(0));
  double t0 = INFINITY, t1 = -INFINITY, lo = INFINITY, hi = -INFINITY;
  const QStringList names = checked();
  auto draw = [&](const SimulationResult& r, const QString& name, bool dashed, int run, int colour) {
    const std::vector<double> y = signal(r, name);
    if (y.empty()) return;
    auto* s = new QLineSeries;
    s->setName(dashed ? QStringLiteral("%1 (kept %2)").arg(name).arg(run + 1) : name);
    QPen pen(QColor::fromHsv((colour * 67) % 360, 200, dashed ? 170 : 210));
    pen.setWidthF(dashed ? 1.2 : 1.8);
    if (dashed) pen.setStyle(Qt::DashLine);
    s->setPen(pen);
    const int N = std::min<int>(static_cast<int>(y.size()), r.samples());
    const int stride = std::max(1, N / kMaxPoints);
    QList<QPointF> p;
    for (int i = 0; i < N; i += stride) {
      if (!std::isfinite(y[i])) continue;
      p << QPointF(r.t[i], y[i]);
      lo = std::min(lo, y[i]), hi = std::max(hi, y[i]);
      t0 = std::min(t0, r.t[i]), t1 = std::max(t1, r.t[i]);
    }
    s->replace(p);
    chart_->addSeries(s);
    s->attachAxis(tx);
    s->attachAxis(ty);
  };
  for (int run = 0; run < static_cast<int>(kept_.size()); ++run)
    if (kept_[run] != current_)
      for (int c = 0; c < names.size(); ++c) draw(*kept_[run], names[c], true, run, c);
  if (current_)
    for (int c = 0; c < names.size(); ++c) draw(*current_, names[c], false, 0, c);
  if (!(t0 < t1)) t0 = 0, t1 = 1;
  tx->setRange(t0, t1);
  if (!(lo <= hi)) lo = -1, hi = 1;
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) lo -= 1, hi += 1;
  const double pad = 0.05 * (hi - lo);
  ty->setRange(lo - pad, hi + pad);
}

}  // namespace codyna::gui
