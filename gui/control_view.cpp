#include "gui/control_view.hpp"

#include <QChart>
#include <QChartView>
#include <QComboBox>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QProgressBar>
#include <QPushButton>
#include <QScatterSeries>
#include <QSplitter>
#include <QTimer>
#include <QTabWidget>
#include <QTableView>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <numbers>

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
  timer_ = new QTimer(this);
  timer_->setInterval(100);
  connect(timer_, &QTimer::timeout, this, [this] {
    const int started = runs_started_.load();
    const double t = run_t_.load(), te = run_t_end_.load();
    if (started < 1 || runs_total_ < 1 || !freq_nu_) return;
    const double done = (started - 1 + (te > 0 ? std::clamp(t / te, 0.0, 1.0) : 0.0)) / runs_total_;
    estimate_progress_->setRange(0, 1000);
    estimate_progress_->setValue(static_cast<int>(std::clamp(done, 0.0, 1.0) * 1000));
    const int k = std::min(started, runs_total_) - 1;
    estimate_progress_->setFormat(tr("frequency %1 of %2, input %3").arg(k / freq_nu_ + 1).arg(runs_total_ / freq_nu_).arg(k % freq_nu_ + 1));
  });
  connect(doc_, &Document::replaced, this, [this] {
    if (isEstimating()) drop_estimate_ = true;  // the running estimate belongs to the model that left
    clearResult();
  });
  connect(doc_, &Document::modelChanged, this, &ControlView::updateStaleness);
  clearResult();
  updateEstimateButtons();
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
  // the nonlinear plant's points over the linear curves
  mag_points_ = new QScatterSeries;
  phase_points_ = new QScatterSeries;
  for (auto [chart, line, points] : {std::tuple{mag_chart_, mag_series_, mag_points_}, std::tuple{phase_chart_, phase_series_, phase_points_}}) {
    line->setName(tr("linear model"));
    points->setName(tr("nonlinear plant"));
    points->setMarkerShape(QScatterSeries::MarkerShapeCircle);
    points->setMarkerSize(8);
    points->setColor(QColor(0xc0, 0x30, 0x20));
    points->setBorderColor(QColor(0x60, 0x10, 0x08));
    chart->addSeries(points);
    points->attachAxis(chart->axes(Qt::Horizontal).value(0));
    points->attachAxis(chart->axes(Qt::Vertical).value(0));
  }
  // over the plot, not beside it: the two charts' frequency axes stay aligned
  mag_chart_->legend()->setAlignment(Qt::AlignTop);
  amplitude_edit_ = new QLineEdit(this);
  amplitude_edit_->setObjectName("freqAmplitude");
  amplitude_edit_->setPlaceholderText(QStringLiteral("0.01"));
  amplitude_edit_->setToolTip(tr("The sine's amplitude on each Plant/In input in turn, in the input's units: one value for all, "
                                 "or one per input separated by commas (codyna freqresp --amplitude)"));
  frequencies_edit_ = new QLineEdit(this);
  frequencies_edit_->setObjectName("freqFrequencies");
  frequencies_edit_->setToolTip(tr("rad/s: W1,W2,... or A:B:N (N frequencies from A to B, log-spaced); empty: 10 over the middle "
                                   "of the plot's range (codyna freqresp --frequencies)"));
  estimate_button_ = new QPushButton(tr("Estimate"), this);
  estimate_button_->setObjectName("freqEstimate");
  estimate_button_->setToolTip(tr("Run the nonlinear model with a sine on each Plant/In input in turn, at each frequency, and draw "
                                  "the gain and phase measured on each Plant/Out over the linear model's (codyna freqresp)"));
  cancel_button_ = new QPushButton(tr("Cancel"), this);
  cancel_button_->setObjectName("freqCancel");
  estimate_progress_ = new QProgressBar(this);
  estimate_progress_->setObjectName("freqProgress");
  estimate_progress_->setTextVisible(true);
  estimate_progress_->setFormat(QString());
  estimate_progress_->setRange(0, 1);
  estimate_progress_->setValue(0);
  freq_status_ = new QLabel(this);
  freq_status_->setObjectName("freqStatus");
  freq_status_->setWordWrap(true);
  freq_status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  auto* est_row = new QHBoxLayout;
  est_row->addWidget(new QLabel(tr("Nonlinear plant: amplitude"), this));
  est_row->addWidget(amplitude_edit_);
  est_row->addWidget(new QLabel(tr("frequencies"), this));
  est_row->addWidget(frequencies_edit_, 1);
  est_row->addWidget(estimate_button_);
  est_row->addWidget(cancel_button_);
  est_row->addWidget(estimate_progress_, 1);
  auto* bode_page = new QWidget(this);
  auto* bode_lay = new QVBoxLayout(bode_page);
  bode_lay->setContentsMargins(0, 0, 0, 0);
  bode_lay->addWidget(bode, 1);
  bode_lay->addLayout(est_row);
  bode_lay->addWidget(freq_status_);

  auto* plots = new QTabWidget(this);
  plots->setObjectName("controlPlots");
  plots->addTab(bode_page, tr("Bode"));
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
  connect(estimate_button_, &QPushButton::clicked, this, [this] { estimate(); });
  connect(cancel_button_, &QPushButton::clicked, this, [this] { cancelEstimate(); });
  for (QLineEdit* e : {amplitude_edit_, frequencies_edit_}) connect(e, &QLineEdit::returnPressed, this, [this] { estimate(); });
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
  // an estimate of the same model stays
  std::pair<std::shared_ptr<const FreqRespJob>, std::shared_ptr<const Model>> keep_freq{freq_, freq_model_};
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
  if (keep_freq.second == m) {
    freq_ = std::move(keep_freq.first);
    freq_model_ = std::move(keep_freq.second);
  }
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
  freq_.reset();
  freq_model_.reset();
  if (!isEstimating()) setFreqStatus(QString(), false);
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
  mag_points_->clear();
  phase_points_->clear();
  mag_chart_->legend()->hide();
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
  // the nonlinear plant's points, over the open-loop plant's curves
  double wlo = f->w.front(), whi = f->w.back();
  QList<QPointF> nmag, nphase;
  if (which == Plant && freq_ && freq_model_ == model_ && in < static_cast<int>(freq_->input_names.size()) &&
      out < static_cast<int>(freq_->output_names.size()) && freq_->input_names[in] == sys->input_names[in] &&
      freq_->output_names[out] == sys->output_names[out]) {
    // the linear curve's (unwrapped) phase at w, interpolated over log w
    const auto line_phase = [&](double w) {
      const auto it = std::lower_bound(f->w.begin(), f->w.end(), w);
      const std::size_t k = std::clamp<std::size_t>(it - f->w.begin(), 1, f->w.size() - 1);
      const double w0 = f->w[k - 1], w1 = f->w[k];
      const double p0 = f->phase_deg[k - 1](out, in), p1 = f->phase_deg[k](out, in);
      if (f->w.size() < 2 || !(w1 > w0)) return p0;
      const double a = std::clamp(std::log(w / w0) / std::log(w1 / w0), 0.0, 1.0);
      return p0 + a * (p1 - p0);
    };
    for (const FreqRespPoint& p : freq_->points) {
      const std::complex<double> g = p.G(out, in);
      const double db = 20.0 * std::log10(std::abs(g));
      double ph = std::arg(g) * 180 / std::numbers::pi;
      const double ref = line_phase(p.w);
      if (std::isfinite(ref)) ph += 360.0 * std::round((ref - ph) / 360.0);  // on the curve's branch
      if (!std::isfinite(db) || !std::isfinite(ph)) continue;
      nmag << QPointF(p.w, db);
      nphase << QPointF(p.w, ph);
      mlo = std::min(mlo, db);
      mhi = std::max(mhi, db);
      plo = std::min(plo, ph);
      phi = std::max(phi, ph);
      wlo = std::min(wlo, p.w);
      whi = std::max(whi, p.w);
    }
  }
  mag_points_->replace(nmag);
  phase_points_->replace(nphase);
  mag_chart_->legend()->setVisible(!nmag.isEmpty());
  decadeAxis(mx, wlo, whi);
  decadeAxis(px, wlo, whi);
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
QList<QPointF> ControlView::nonlinearMagnitudePoints() const { return mag_points_->points(); }
QList<QPointF> ControlView::nonlinearPhasePoints() const { return phase_points_->points(); }

std::vector<double> ControlView::defaultEstimateFrequencies() const {
  if (!job_ || job_->plant_frequency.w.size() < 2) return {};
  // the middle half of the plot's range in log w
  const double a = std::log10(job_->plant_frequency.w.front()), b = std::log10(job_->plant_frequency.w.back());
  return log_grid(std::pow(10.0, a + 0.25 * (b - a)), std::pow(10.0, b - 0.25 * (b - a)), 10);
}

namespace {
// "0.01" or "0.01, 2" (one per Plant/In); throws std::invalid_argument naming the field
std::vector<double> read_amplitudes(const QString& text) {
  std::vector<double> v;
  if (text.trimmed().isEmpty()) return v;
  for (const QString& part : text.split(',')) {
    bool ok = false;
    const double a = part.trimmed().toDouble(&ok);
    if (!ok || !std::isfinite(a) || !(a > 0))
      throw std::invalid_argument("amplitude \"" + ss(part.trimmed()) + "\": expected a number > 0 (one, or one per Plant/In input)");
    v.push_back(a);
  }
  return v;
}
}  // namespace

bool ControlView::estimate() {
  if (isEstimating()) return false;
  FreqRespRequest r;
  try {
    r.amplitudes = read_amplitudes(amplitude_edit_->text());
    if (!frequencies_edit_->text().trimmed().isEmpty())
      r.frequencies = study_frequency_grid(ss(frequencies_edit_->text().trimmed()), "frequencies");
  } catch (const std::exception& e) {
    setFreqStatus(qs(e.what()), true);
    emit message(tr("Estimate: %1").arg(qs(e.what())));
    return false;
  }
  if (!job_ || isStale()) {
    if (!analyse()) {
      setFreqStatus(tr("The plant could not be analysed: see above"), true);
      return false;
    }
  }
  if (r.frequencies.empty()) r.frequencies = defaultEstimateFrequencies();
  if (r.frequencies.empty()) {
    setFreqStatus(tr("frequencies: none to estimate at"), true);
    return false;
  }
  r.run.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : ss(doc_->filePath());
  freq_.reset();  // the points on screen are of the estimate that runs now
  freq_model_.reset();
  redraw();
  runs_started_.store(0);
  run_t_.store(0);
  run_t_end_.store(0);
  freq_nu_ = std::max<int>(1, static_cast<int>(job_->plant.system.nu()));
  runs_total_ = static_cast<int>(r.frequencies.size()) * freq_nu_;
  drop_estimate_ = false;
  const ModelSpec spec = doc_->spec();
  const std::shared_ptr<const Model> model = model_;
  auto result = std::make_shared<std::shared_ptr<const FreqRespJob>>();
  freq_job_.start(
      [this, r, spec, result](const std::atomic<bool>& cancel, const StudyMessages& tell) {
        SimulationCallbacks cb;
        cb.cancel = &cancel;
        double last = -1;
        cb.progress = [this, &last](double t, double t_end) {  // on this thread: atomics only
          if (t < last || last < 0) runs_started_.fetch_add(1);  // a run starts again from 0
          last = t;
          run_t_.store(t);
          run_t_end_.store(t_end);
        };
        *result = std::make_shared<const FreqRespJob>(study_freqresp_job(r, spec, cb, tell));
      },
      [this, result, model](const JobOutcome& out) {
        if (*result && !drop_estimate_) freq_model_ = model;
        onEstimated(*result, out);
      });
  estimate_progress_->setRange(0, 0);  // busy until the first run reports
  estimate_progress_->setFormat(tr("setting up..."));
  setFreqStatus(tr("Estimating at %1 frequencies...").arg(r.frequencies.size()), false);
  updateEstimateButtons();
  timer_->start();
  return true;
}

void ControlView::cancelEstimate() { freq_job_.cancel(); }

void ControlView::onEstimated(std::shared_ptr<const FreqRespJob> job, const JobOutcome& out) {
  const QString& error = out.error;
  const bool cancelled = out.cancelled;
  timer_->stop();
  estimate_progress_->setRange(0, 1);
  estimate_progress_->setValue(cancelled || !error.isEmpty() || !job ? 0 : 1);
  estimate_progress_->setFormat(QString());
  updateEstimateButtons();
  if (drop_estimate_) {
    drop_estimate_ = false;
    setFreqStatus(tr("The estimate of the previous model was stopped"), false);
    emit estimateFinished();
    return;
  }
  for (const QString& n : out.notes) emit message(tr("Estimate: %1").arg(n));
  if (cancelled) {
    setFreqStatus(tr("Cancelled"), false);
  } else if (!job) {
    setFreqStatus(error, true);
    emit message(tr("Estimate: %1").arg(error));
  } else {
    freq_ = std::move(job);
    const FreqRespJob& j = *freq_;
    double harmonics = 0;
    for (const FreqRespPoint& p : j.points) harmonics = std::max(harmonics, p.distortion.maxCoeff());
    QString amps;
    for (Eigen::Index k = 0; k < j.amplitudes.size(); ++k)
      amps += (k ? QStringLiteral(", ") : QString()) + QStringLiteral("%1 %2").arg(qs(j.input_names[k])).arg(j.amplitudes[k], 0, 'g', 4) +
              (j.input_units[k].empty() ? QString() : QStringLiteral(" ") + qs(j.input_units[k]));
    QString text = tr("<b>Nonlinear plant</b> (%1, amplitude %2, %3 frequencies): largest gap <b>%4 %</b> of the linear "
                      "response, %5/%6 at %7 rad/s; harmonics at most %8 % of a response.")
                       .arg(qs(j.controller).toHtmlEscaped(), amps.toHtmlEscaped())
                       .arg(j.points.size())
                       .arg(100 * j.largest_gap, 0, 'g', 3)
                       .arg(qs(j.output_names[j.gap_output]).toHtmlEscaped(), qs(j.input_names[j.gap_input]).toHtmlEscaped())
                       .arg(j.points[j.gap_point].w, 0, 'g', 4)
                       .arg(100 * harmonics, 0, 'g', 3);
    if (!j.warnings.empty())
      text += tr(" <span style='color:#b00000'>%1 warning(s): see Messages.</span>").arg(j.warnings.size());
    freq_status_->setStyleSheet(QString());
    freq_status_->setText(text);
    // the points are the open-loop plant's
    if (system_combo_->currentIndex() != Plant) {
      system_combo_->setCurrentIndex(Plant);
    } else {
      redraw();
    }
    emit message(tr("Estimated the nonlinear plant's frequency response: largest gap %1 %").arg(100 * j.largest_gap, 0, 'g', 3));
  }
  emit estimateFinished();
}

void ControlView::setFreqStatus(const QString& text, bool error) {
  freq_status_->setStyleSheet(error ? QStringLiteral("QLabel { color: #b00000; }") : QString());
  freq_status_->setText(text.toHtmlEscaped());
}

void ControlView::updateEstimateButtons() {
  estimate_button_->setEnabled(!isEstimating());
  cancel_button_->setEnabled(isEstimating());
}
QList<QPointF> ControlView::phasePoints() const { return phase_series_->points(); }
int ControlView::stepSeriesCount() const { return static_cast<int>(step_series_.size()); }
QList<QPointF> ControlView::stepPoints(int output) const {
  const auto it = std::find(step_outputs_.begin(), step_outputs_.end(), output);
  return it == step_outputs_.end() ? QList<QPointF>() : step_series_[it - step_outputs_.begin()]->points();
}

}  // namespace codyna::gui
