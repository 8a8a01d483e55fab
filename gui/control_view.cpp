#include "gui/control_view.hpp"

#include <QChart>
#include <QChartView>
#include <QComboBox>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QPushButton>
#include <QSplitter>
#include <QTabWidget>
#include <QTableView>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"
#include "gui/matrix_models.hpp"
#include "gui/matrix_view.hpp"
#include "gui/pole_map.hpp"
#include "gui/result_plots.hpp"
#include "study/tools.hpp"

namespace codyna::gui {

namespace {

QStringList qlist(const std::vector<std::string>& v) {
  QStringList l;
  for (const auto& s : v) l << qs(s);
  return l;
}

QChart* makeChart(const QString& title) { return ChartView::compactChart(title); }

// small fonts and few ticks, so that the labels fit a short chart (no "..." for a number)
void styleAxis(QAbstractAxis* a, const QString& title) {
  QFont f = a->labelsFont();
  f.setPointSizeF(8);
  a->setLabelsFont(f);
  QFont tf = f;
  tf.setPointSizeF(8.5);
  a->setTitleFont(tf);
  a->setTitleText(title);
  if (auto* v = qobject_cast<QValueAxis*>(a)) {
    v->setLabelFormat("%.4g");
    v->setTickCount(4);
  }
}

// axis range with a little room; a flat curve gets +-1 around its value
void fitAxis(QValueAxis* a, double lo, double hi) {
  if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) {
    a->setRange(-1, 1);
    return;
  }
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    lo -= 1;
    hi += 1;
  }
  const double pad = 0.05 * (hi - lo);
  a->setRange(lo - pad, hi + pad);
  a->applyNiceNumbers();
}

// A Bode axis on round values, as a control engineer reads one: ticks from 0 at the smallest of
// `steps` whose whole-step range holds at most kBodeIntervals of them (so that six labels fit a
// short chart: more were drawn as "..."); a flat curve gets one step on either side
constexpr double kBodeIntervals = 5;
void bodeAxis(QValueAxis* a, double lo, double hi, std::initializer_list<double> steps) {
  if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) {
    fitAxis(a, 0, 0);
    return;
  }
  double step = *(steps.end() - 1);
  for (double s : steps)
    if (std::ceil(hi / s) - std::floor(lo / s) <= kBodeIntervals) {
      step = s;
      break;
    }
  double from = std::floor(lo / step) * step, to = std::ceil(hi / step) * step;
  if (to - from < step * 0.5) from -= step, to += step;
  a->setTickType(QValueAxis::TicksDynamic);
  setAxisRange(a, from, to, step);
}

// a logarithmic frequency axis from decade to decade (its ticks and labels at the decades)
void decadeAxis(QLogValueAxis* a, double lo, double hi) {
  if (!(lo > 0 && hi >= lo) || !std::isfinite(hi)) return;
  const double from = std::pow(10.0, std::floor(std::log10(lo) + 1e-9));
  double to = std::pow(10.0, std::ceil(std::log10(hi) - 1e-9));
  if (to <= from) to = from * 10;
  a->setRange(from, to);
}

}  // namespace

ControlView::ControlView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  buildUi();
  connect(doc_, &Document::replaced, this, &ControlView::clearResult);
  connect(doc_, &Document::modelChanged, this, &ControlView::updateStaleness);
  clearResult();
}

ControlView::~ControlView() = default;

void ControlView::buildUi() {
  analyse_button_ = new QPushButton(tr("Analyse"), this);
  analyse_button_->setObjectName("analyseButton");
  analyse_button_->setToolTip(tr("Linearize the plant and close the loop with the study's controller (as the Simulate view sets it): "
                                 "gain, closed-loop poles, Bode and step responses"));
  status_ = new QLabel(this);
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  stale_ = new QLabel(tr("<b>Out of date:</b> the model or the study changed since: analyse again."), this);
  stale_->setObjectName("controlStale");
  stale_->setStyleSheet("QLabel { background: #fff0c0; color: #6a4a00; padding: 3px; }");
  stale_->setVisible(false);

  system_combo_ = new QComboBox(this);
  system_combo_->setObjectName("controlSystem");
  system_combo_->addItem(tr("open-loop plant"));
  system_combo_->addItem(tr("closed loop"));
  system_combo_->setToolTip(tr("The plant as linearized (inputs: Plant/In; outputs: Plant/Out), or the loop closed by the controller "
                               "(inputs: references r_ and disturbances d_; outputs: Plant/Out and the efforts u_)"));
  input_combo_ = new QComboBox(this);
  input_combo_->setObjectName("controlInput");
  input_combo_->setToolTip(tr("The input of the Bode plot and of the step"));
  output_combo_ = new QComboBox(this);
  output_combo_->setObjectName("controlOutput");
  output_combo_->setToolTip(tr("The output of the Bode plot"));

  auto* top = new QHBoxLayout;
  top->addWidget(analyse_button_);
  top->addWidget(new QLabel(tr("system"), this));
  top->addWidget(system_combo_);
  top->addWidget(new QLabel(tr("input"), this));
  top->addWidget(input_combo_, 1);
  top->addWidget(new QLabel(tr("output"), this));
  top->addWidget(output_combo_, 1);

  // left: K and the closed-loop poles
  gain_model_ = new MatrixTableModel(this);
  auto* gv = new MatrixView(QStringLiteral("K"), this);
  gv->setMatrixModel(gain_model_);
  gain_view_ = gv;
  gain_view_->setToolTip(tr("The gain of a controller without states (u = u0 - K dx), read off the closed loop; "
                            "Ctrl+C copies the selection, right click copies K as MATLAB or CSV"));
  pole_model_ = new ModeTableModel(this);
  pole_view_ = new QTableView(this);
  pole_view_->setModel(pole_model_);
  pole_view_->setToolTip(tr("The poles of the linear closed loop (plant and controller) with their frequency and damping"));
  pole_view_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  pole_view_->setColumnHidden(ModeTableModel::DominantStates, true);
  auto* gain_box = new QGroupBox(tr("Gain K (u = u0 - K dx)"), this);
  (new QVBoxLayout(gain_box))->addWidget(gain_view_);
  auto* pole_box = new QGroupBox(tr("Closed-loop poles"), this);
  (new QVBoxLayout(pole_box))->addWidget(pole_view_);
  auto* left = new QSplitter(Qt::Vertical, this);
  left->addWidget(gain_box);
  left->addWidget(pole_box);

  // right: Bode (magnitude over phase) and step
  mag_chart_ = makeChart(tr("Magnitude"));
  phase_chart_ = makeChart(tr("Phase"));
  step_chart_ = makeChart(tr("Step response"));
  mag_series_ = new QLineSeries;
  phase_series_ = new QLineSeries;
  mag_chart_->addSeries(mag_series_);
  phase_chart_->addSeries(phase_series_);
  mag_chart_->legend()->hide();
  phase_chart_->legend()->hide();
  for (auto [chart, series, unit] : {std::tuple{mag_chart_, mag_series_, tr("dB")}, std::tuple{phase_chart_, phase_series_, tr("deg")}}) {
    auto* x = new QLogValueAxis;
    x->setBase(10);
    x->setLabelFormat("%g");
    x->setMinorTickCount(8);
    styleAxis(x, chart == phase_chart_ ? tr("frequency [rad/s]") : QString());
    auto* y = new QValueAxis;
    styleAxis(y, unit);
    chart->addAxis(x, Qt::AlignBottom);
    chart->addAxis(y, Qt::AlignLeft);
    series->attachAxis(x);
    series->attachAxis(y);
  }
  auto* tx = new QValueAxis;
  styleAxis(tx, tr("t [s]"));
  auto* ty = new QValueAxis;
  styleAxis(ty, QString());
  step_chart_->addAxis(tx, Qt::AlignBottom);
  step_chart_->addAxis(ty, Qt::AlignLeft);
  auto view = [this](QChart* c, const QString& name) {
    auto* v = new ChartView(c, this);
    v->setObjectName(name);
    v->setMinimumSize(200, 90);
    v->setFrameShape(QFrame::NoFrame);
    return v;
  };
  auto* bode = new QSplitter(Qt::Vertical, this);
  bode->setObjectName("bodeView");
  bode->addWidget(view(mag_chart_, "bodeMagnitude"));
  bode->addWidget(view(phase_chart_, "bodePhase"));
  auto* plots = new QTabWidget(this);
  plots->addTab(bode, tr("Bode"));
  plots->addTab(view(step_chart_, "stepView"), tr("Step"));
  pz_map_ = new PoleMap(this);
  pz_map_->setObjectName("poleZeroMap");
  pz_map_->setToolTip(tr("The chosen system's poles (x) and the zeros (o) of the chosen input-output pair: where "
                         "its transfer function vanishes (MATLAB's zero(sys(out, in)))"));
  plots->addTab(pz_map_, tr("Pole-zero map"));

  auto* body = new QSplitter(Qt::Horizontal, this);
  body->addWidget(left);
  body->addWidget(plots);
  body->setStretchFactor(0, 1);
  body->setStretchFactor(1, 3);

  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->addWidget(status_);
  layout->addWidget(stale_);
  layout->addWidget(body, 1);

  connect(analyse_button_, &QPushButton::clicked, this, [this] { analyse(); });
  connect(system_combo_, &QComboBox::currentIndexChanged, this, [this] {
    fillPairs();
    redraw();
  });
  connect(input_combo_, &QComboBox::currentIndexChanged, this, [this] { redraw(); });
  connect(output_combo_, &QComboBox::currentIndexChanged, this, [this] { redraw(); });
}

const LinearSystem* ControlView::system(System s) const {
  if (!job_) return nullptr;
  if (s == Plant) return &job_->plant.system;
  return job_->closed_loop ? &job_->closed_loop->loop.system : nullptr;
}
const FrequencyResponse* ControlView::frequency(System s) const {
  if (!job_) return nullptr;
  if (s == Plant) return &job_->plant_frequency;
  return job_->closed_loop ? &job_->closed_loop->frequency : nullptr;
}
const StepResponse* ControlView::step(System s) const {
  if (!job_) return nullptr;
  if (s == Plant) return &job_->plant_step;
  return job_->closed_loop ? &job_->closed_loop->step : nullptr;
}

bool ControlView::analyse() {
  const std::shared_ptr<const Model> m = doc_->model();
  if (!m) {
    emit message(tr("Analyse: the model does not compile: %1").arg(doc_->errorText()));
    return false;
  }
  clearResult();
  try {
    ControlRequest request;
    request.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : ss(doc_->filePath());
    job_ = study_control_job(request, doc_->spec());
  } catch (const std::exception& e) {
    job_.reset();
    status_->setText(tr("The plant could not be linearized: %1").arg(qs(e.what())));
    emit message(tr("Analyse: %1").arg(qs(e.what())));
    return false;
  }
  model_ = m;
  const ControlJob& job = *job_;
  const LinearSystem& plant = job.plant.system;
  QString text = tr("<b>Plant</b> about %1: %2 states, %3 inputs, %4 outputs.")
                     .arg(qs(job.plant.op.kind).toHtmlEscaped())
                     .arg(plant.nx())
                     .arg(plant.nu())
                     .arg(plant.ny());
  if (const auto& cl = job.closed_loop) {
    const PoleCount& c = job.closed_loop_count;  // as the core classifies the poles
    QString verdict = c.unstable ? tr("<span style='color:#b00000'>%1 unstable</span>").arg(c.unstable) : QString();
    if (c.marginal) verdict += (verdict.isEmpty() ? QString() : tr(", ")) + tr("%1 on the stability boundary").arg(c.marginal);
    text += tr(" <b>Closed loop</b> with %1: %2 poles, %3.")
                .arg(qs(cl->loop.controller).toHtmlEscaped())
                .arg(cl->poles.modes.size())
                .arg(verdict.isEmpty() ? tr("all stable") : verdict);
    pole_model_->setModes(cl->poles);
    if (job.gain.size() > 0) gain_model_->setMatrix(job.gain, qlist(job.gain_inputs), qlist(job.gain_states));
  }
  QStringList notes;
  for (const std::string& n : job.notes) notes << qs(n);
  if (!notes.isEmpty()) text += QStringLiteral("<br>") + notes.join(QStringLiteral("<br>")).toHtmlEscaped();
  status_->setText(text);
  system_combo_->setEnabled(true);
  {
    const QSignalBlocker b(system_combo_);
    system_combo_->setCurrentIndex(job.closed_loop ? ClosedLoop : Plant);
  }
  fillPairs();
  redraw();
  updateStaleness();
  emit message(job.closed_loop ? tr("Analysed the plant and the closed loop (%1)").arg(qs(job.closed_loop->loop.controller))
                               : tr("Analysed the plant (no closed loop)"));
  return true;
}

void ControlView::clearResult() {
  model_.reset();
  job_.reset();
  gain_model_->clear();
  pole_model_->clear();
  status_->setText(tr("Not analysed yet: Analyse linearizes the plant and closes the loop with the study's controller."));
  fillPairs();
  redraw();
  updateStaleness();
}

bool ControlView::isStale() const { return model_ && model_ != doc_->model(); }

void ControlView::updateStaleness() {
  const bool stale = isStale();
  stale_->setVisible(stale);
  gain_view_->setEnabled(!stale);
  pole_view_->setEnabled(!stale);
}

void ControlView::fillPairs() {
  const QSignalBlocker bi(input_combo_), bo(output_combo_);
  const QString in = input_combo_->currentText(), out = output_combo_->currentText();
  input_combo_->clear();
  output_combo_->clear();
  if (const LinearSystem* s = system(System(system_combo_->currentIndex()))) {
    input_combo_->addItems(qlist(s->input_names));
    output_combo_->addItems(qlist(s->output_names));
    if (input_combo_->findText(in) >= 0) input_combo_->setCurrentText(in);
    if (output_combo_->findText(out) >= 0) output_combo_->setCurrentText(out);
  }
  system_combo_->setItemData(ClosedLoop, hasClosedLoop() ? QVariant() : QVariant(0), Qt::UserRole - 1);  // disabled without a loop
}

void ControlView::redraw() {
  mag_series_->clear();
  phase_series_->clear();
  for (QLineSeries* s : step_series_) {
    step_chart_->removeSeries(s);
    delete s;
  }
  step_series_.clear();
  const System which = System(system_combo_->currentIndex());
  const FrequencyResponse* f = frequency(which);
  const StepResponse* st = step(which);
  const LinearSystem* sys = system(which);
  const int in = input_combo_->currentIndex(), out = output_combo_->currentIndex();
  // poles of the system, zeros of the pair
  if (sys && in >= 0 && out >= 0 && in < sys->B.cols() && out < sys->C.rows()) {
    pz_map_->setModes(which == Plant ? job_->plant_modes : job_->closed_loop->poles);
    try {
      pz_map_->setZeros(study_control_zeros(*job_, which == ClosedLoop, in, out));
    } catch (const std::exception&) {
      pz_map_->setZeros({});
    }
  } else {
    pz_map_->setModes({});
    pz_map_->setZeros({});
  }
  auto* mx = static_cast<QLogValueAxis*>(mag_chart_->axes(Qt::Horizontal).value(0));
  auto* my = static_cast<QValueAxis*>(mag_chart_->axes(Qt::Vertical).value(0));
  auto* px = static_cast<QLogValueAxis*>(phase_chart_->axes(Qt::Horizontal).value(0));
  auto* py = static_cast<QValueAxis*>(phase_chart_->axes(Qt::Vertical).value(0));
  auto* tx = static_cast<QValueAxis*>(step_chart_->axes(Qt::Horizontal).value(0));
  auto* ty = static_cast<QValueAxis*>(step_chart_->axes(Qt::Vertical).value(0));
  if (!f || !st || !sys || in < 0 || out < 0 || f->w.empty()) {
    mx->setRange(0.01, 100);
    px->setRange(0.01, 100);
    fitAxis(my, 0, 0);
    fitAxis(py, 0, 0);
    tx->setRange(0, 1);
    fitAxis(ty, 0, 0);
    // nothing drawn: no title of an earlier model's curves either
    mag_chart_->setTitle(QString());
    phase_chart_->setTitle(QString());
    step_chart_->setTitle(QString());
    return;
  }
  QList<QPointF> mag, phase;
  double mlo = INFINITY, mhi = -INFINITY, plo = INFINITY, phi = -INFINITY;
  for (std::size_t k = 0; k < f->w.size(); ++k) {
    const double m = f->magnitude[k](out, in);
    const double db = 20.0 * std::log10(m);
    const double ph = f->phase_deg[k](out, in);
    if (!std::isfinite(db) || !std::isfinite(ph)) continue;  // an exact zero of the transfer function
    mag << QPointF(f->w[k], db);
    phase << QPointF(f->w[k], ph);
    mlo = std::min(mlo, db);
    mhi = std::max(mhi, db);
    plo = std::min(plo, ph);
    phi = std::max(phi, ph);
  }
  mag_series_->replace(mag);
  phase_series_->replace(phase);
  decadeAxis(mx, f->w.front(), f->w.back());
  decadeAxis(px, f->w.front(), f->w.back());
  bodeAxis(my, mlo, mhi, {1, 2, 5, 10, 20, 40, 100, 200, 500});
  bodeAxis(py, plo, phi, {5, 15, 45, 90, 180, 360});
  mag_chart_->setTitle(tr("Magnitude, %1 to %2").arg(input_combo_->currentText(), output_combo_->currentText()));
  phase_chart_->setTitle(tr("Phase, %1 to %2").arg(input_combo_->currentText(), output_combo_->currentText()));

  // the step on the chosen input: every output
  double ylo = INFINITY, yhi = -INFINITY;
  step_outputs_.clear();
  if (in < static_cast<int>(st->y.size())) {
    const Eigen::MatrixXd& Y = st->y[in];
    // the outputs of the chosen output's group: the measured outputs, or (closed loop) the efforts,
    // which are far larger and would flatten the outputs on one axis
    int first = 0, last = sys->ny();
    if (which == ClosedLoop && hasClosedLoop()) {
      const int ny = job_->closed_loop->loop.ny;
      if (out < ny) last = ny;
      else first = ny;
    }
    for (int j = first; j < last; ++j) step_outputs_.push_back(j);
    for (const int j : step_outputs_) {
      if (j >= Y.cols()) continue;
      auto* s = new QLineSeries;
      s->setName(qs(j < static_cast<int>(sys->output_names.size()) ? sys->output_names[j] : std::to_string(j + 1)));
      QList<QPointF> p;
      for (Eigen::Index k = 0; k < Y.rows() && k < static_cast<Eigen::Index>(st->t.size()); ++k) {
        if (!std::isfinite(Y(k, j))) continue;
        p << QPointF(st->t[k], Y(k, j));
        ylo = std::min(ylo, Y(k, j));
        yhi = std::max(yhi, Y(k, j));
      }
      s->replace(p);
      step_chart_->addSeries(s);
      s->attachAxis(tx);
      s->attachAxis(ty);
      step_series_.push_back(s);
    }
  }
  const double t_end = st->t.empty() ? 1.0 : st->t.back();
  // ticks at round times (1, 2 or 5 times a power of ten), from 0; setAxisRange keeps the
  // tick count bounded while the range changes
  tx->setTickType(QValueAxis::TicksDynamic);
  setAxisRange(tx, 0, t_end, ChartView::roundStep(t_end, 4));
  fitAxis(ty, ylo, yhi);
  step_chart_->setTitle(tr("Step on %1").arg(input_combo_->currentText()));
}

QList<QPointF> ControlView::magnitudePoints() const { return mag_series_->points(); }
QList<QPointF> ControlView::phasePoints() const { return phase_series_->points(); }
int ControlView::stepSeriesCount() const { return static_cast<int>(step_series_.size()); }
QList<QPointF> ControlView::stepPoints(int output) const {
  const auto it = std::find(step_outputs_.begin(), step_outputs_.end(), output);
  return it == step_outputs_.end() ? QList<QPointF>() : step_series_[it - step_outputs_.begin()]->points();
}

}  // namespace codyna::gui
