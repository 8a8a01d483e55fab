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

QStringList SignalPlot::signalNames(const SimulationResult& r) {
  QStringList n;
  for (std::size_t k = 0; k < r.q_names.size() && static_cast<Eigen::Index>(k) < r.q.cols(); ++k) n << qs(r.q_names[k]);
  for (std::size_t k = 0; k < r.v_names.size() && static_cast<Eigen::Index>(k) < r.v.cols(); ++k) n << qs(r.v_names[k]);
  for (std::size_t k = 0; k < r.input_names.size() && static_cast<Eigen::Index>(k) < r.u.cols(); ++k)
    n << qs(r.input_names[k]) + unitSuffix(r.input_units, k);
  for (std::size_t k = 0; k < r.output_names.size() && static_cast<Eigen::Index>(k) < r.y.cols(); ++k)
    n << QStringLiteral("y: ") + qs(r.output_names[k]) + unitSuffix(r.output_units, k);
  for (std::size_t k = 0; k < r.controller_state_names.size() && static_cast<Eigen::Index>(k) < r.xc.cols(); ++k)
    n << QStringLiteral("controller: ") + qs(r.controller_state_names[k]);
  if (!r.kinetic_energy.empty()) n << QStringLiteral("kinetic energy [J]") << QStringLiteral("potential energy [J]")
                                   << QStringLiteral("total energy [J]");
  if (!r.constraint_violation.empty()) n << QStringLiteral("constraint drift |phi|") << QStringLiteral("velocity drift |Jc v|");
  return n;
}

std::vector<double> SignalPlot::signal(const SimulationResult& r, const QString& name) {
  const QStringList names = signalNames(r);
  const int at = static_cast<int>(names.indexOf(name));
  std::vector<double> out;
  if (at < 0) return out;
  const int N = r.samples();
  auto column = [&](const Eigen::MatrixXd& m, int c) {
    for (int i = 0; i < N && i < m.rows(); ++i) out.push_back(m(i, c));
  };
  int k = at;
  const int nq = std::min<int>(static_cast<int>(r.q_names.size()), static_cast<int>(r.q.cols()));
  if (k < nq) return column(r.q, k), out;
  k -= nq;
  const int nv = std::min<int>(static_cast<int>(r.v_names.size()), static_cast<int>(r.v.cols()));
  if (k < nv) return column(r.v, k), out;
  k -= nv;
  const int nu = std::min<int>(static_cast<int>(r.input_names.size()), static_cast<int>(r.u.cols()));
  if (k < nu) return column(r.u, k), out;
  k -= nu;
  const int ny = std::min<int>(static_cast<int>(r.output_names.size()), static_cast<int>(r.y.cols()));
  if (k < ny) return column(r.y, k), out;
  k -= ny;
  const int nxc = std::min<int>(static_cast<int>(r.controller_state_names.size()), static_cast<int>(r.xc.cols()));
  if (k < nxc) return column(r.xc, k), out;
  k -= nxc;
  if (!r.kinetic_energy.empty()) {
    if (k == 0) return r.kinetic_energy;
    if (k == 1) return r.potential_energy;
    if (k == 2) {
      for (std::size_t i = 0; i < r.kinetic_energy.size() && i < r.potential_energy.size(); ++i)
        out.push_back(r.kinetic_energy[i] + r.potential_energy[i]);
      return out;
    }
    k -= 3;
  }
  if (k == 0) return r.constraint_violation;
  if (k == 1) return r.velocity_violation;
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
