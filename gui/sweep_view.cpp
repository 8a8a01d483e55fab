#include "gui/sweep_view.hpp"

#include <QChart>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QPainter>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QScatterSeries>
#include <QSpinBox>
#include <QSplitter>
#include <QTabWidget>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <limits>
#include <map>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"
#include "model/spec_edit.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"

namespace codyna::gui {

namespace {

constexpr int kLevels = 64;  // colour levels of the pole map (one scatter series each)

enum Figure { ClosedMaxReal = 0, OpenMaxReal, PeakInput, FinalError };

QString number(double x) { return QString::number(x, 'g', 10); }

// a round range about [lo, hi] with a margin
void fit_axis(QValueAxis* a, double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = -1, hi = 1;
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    const double d = std::max(1e-3, 0.1 * std::abs(hi));
    lo -= d, hi += d;
  }
  const double m = 0.06 * (hi - lo);
  a->setRange(lo - m, hi + m);
  a->applyNiceNumbers();
}

}  // namespace

// ---------------------------------------------------------------------------
// ColourBar

ColourBar::ColourBar(QWidget* parent) : QWidget(parent) {
  setObjectName("sweepColourBar");
  setMinimumWidth(100);
}

void ColourBar::setRange(const QString& title, double low, double high) {
  title_ = title, low_ = low, high_ = high, shown_ = true;
  update();
}

void ColourBar::clear() {
  shown_ = false;
  title_.clear();
  update();
}

QColor ColourBar::colourAt(double t) {
  // viridis at six stops, linearly between them
  static const double stops[6][3] = {{68, 1, 84}, {65, 68, 135}, {42, 120, 142}, {34, 168, 132}, {122, 209, 81}, {253, 231, 37}};
  if (!std::isfinite(t)) t = 0;
  t = std::clamp(t, 0.0, 1.0) * 5.0;
  const int k = std::min(4, static_cast<int>(t));
  const double f = t - k;
  auto mix = [&](int c) { return static_cast<int>(std::lround(stops[k][c] + f * (stops[k + 1][c] - stops[k][c]))); };
  return QColor(mix(0), mix(1), mix(2));
}

void ColourBar::paintEvent(QPaintEvent*) {
  if (!shown_) return;
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  const QFontMetrics fm(font());
  const int top = fm.height() * 2 + 8, bottom = height() - fm.height() - 4;
  const QRect bar(6, top, 18, std::max(10, bottom - top));
  QLinearGradient g(bar.bottomLeft(), bar.topLeft());
  for (int k = 0; k <= 10; ++k) g.setColorAt(k / 10.0, colourAt(k / 10.0));
  p.fillRect(bar, g);
  p.setPen(palette().color(QPalette::WindowText));
  p.drawRect(bar);
  // the title over the bar (wrapped), the values at its ends and middle
  p.drawText(QRect(2, 2, width() - 4, top - 6), Qt::AlignLeft | Qt::AlignBottom | Qt::TextWordWrap, title_);
  const int x = bar.right() + 6;
  p.drawText(QPoint(x, bar.top() + fm.ascent() / 2), number(high_));
  p.drawText(QPoint(x, bar.center().y() + fm.ascent() / 2), number(0.5 * (low_ + high_)));
  p.drawText(QPoint(x, bar.bottom() + fm.ascent() / 2), number(low_));
}

// ---------------------------------------------------------------------------
// SweepView

SweepView::SweepView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  setObjectName("sweepView");
  buildUi();
  timer_ = new QTimer(this);
  timer_->setInterval(100);
  connect(timer_, &QTimer::timeout, this, &SweepView::tick);
  // another model: its fields mean nothing here
  connect(doc_, &Document::replaced, this, [this] {
    if (isRunning()) drop_result_ = true;  // the running study's result belongs to the old model
    cancel();
    fields_->setRowCount(0);
    clearResult();
    updateButtons();
  });
  updateButtons();
}

SweepView::~SweepView() = default;

void SweepView::buildUi() {
  auto* outer = new QHBoxLayout(this);
  outer->setContentsMargins(4, 4, 4, 4);
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->setObjectName("sweepSplitter");
  outer->addWidget(split);

  // left: the study
  auto* left = new QWidget(split);
  auto* lv = new QVBoxLayout(left);
  lv->setContentsMargins(0, 0, 0, 0);
  auto* hint = new QLabel(tr("Varied fields (right-click a number in the property editor: <i>Vary in sweep</i>)"), left);
  hint->setWordWrap(true);
  lv->addWidget(hint);
  fields_ = new QTableWidget(0, 3, left);
  fields_->setObjectName("sweepFields");
  fields_->setHorizontalHeaderLabels({tr("Field"), tr("Values"), tr("Is")});
  fields_->horizontalHeader()->setSectionResizeMode(0, QHeaderView::Stretch);
  fields_->horizontalHeader()->setSectionResizeMode(1, QHeaderView::Stretch);
  fields_->horizontalHeader()->setSectionResizeMode(2, QHeaderView::ResizeToContents);
  fields_->verticalHeader()->setVisible(false);
  fields_->setSelectionBehavior(QAbstractItemView::SelectRows);
  // no delayed edit on a click into a selected cell: a double click, F2 or typing opens the editor
  fields_->setEditTriggers(QAbstractItemView::DoubleClicked | QAbstractItemView::EditKeyPressed |
                           QAbstractItemView::AnyKeyPressed);
  fields_->setToolTip(tr("Field: a JSON pointer into the model file (/bodies/1/mass, /joints/0/q0/0).\n"
                         "Values: a:b:n (n values from a to b), [v1,v2,...], normal(mu,sigma) or uniform(a,b).\n"
                         "Several grids make the full grid; several distributions joint random samples.\n"
                         "Is: the field as the model tree names it (rod.mass), or why the pointer names nothing."));
  fields_->setMinimumHeight(90);
  lv->addWidget(fields_, 1);
  auto* rows = new QHBoxLayout;
  add_row_ = new QPushButton(tr("Add field"), left);
  add_row_->setObjectName("sweepAddField");
  add_row_->setToolTip(tr("A new row: type the field's JSON pointer and its values"));
  remove_row_ = new QPushButton(tr("Remove"), left);
  remove_row_->setObjectName("sweepRemoveField");
  remove_row_->setToolTip(tr("Remove the selected fields from the study"));
  rows->addWidget(add_row_);
  rows->addWidget(remove_row_);
  rows->addStretch(1);
  lv->addLayout(rows);

  auto* form = new QFormLayout;
  samples_ = new QSpinBox(left);
  samples_->setObjectName("sweepSamples");
  samples_->setRange(1, 1000000);
  samples_->setValue(100);
  samples_->setToolTip(tr("Random studies (normal, uniform): the number of variants"));
  seed_ = new QSpinBox(left);
  seed_->setObjectName("sweepSeed");
  seed_->setRange(0, 2147483647);
  seed_->setValue(1);
  seed_->setToolTip(tr("Random studies: the same seed gives the same variants"));
  auto* random = new QHBoxLayout;
  random->addWidget(samples_, 1);
  random->addWidget(new QLabel(tr("seed"), left));
  random->addWidget(seed_, 1);
  form->addRow(tr("Samples"), random);
  threads_ = new QSpinBox(left);
  threads_->setObjectName("sweepThreads");
  threads_->setRange(0, 256);
  threads_->setSpecialValueText(tr("all cores"));
  threads_->setToolTip(tr("Worker threads (all cores: one per core)"));
  form->addRow(tr("Threads"), threads_);
  redesign_ = new QComboBox(left);
  redesign_->setObjectName("sweepRedesign");
  redesign_->addItem(tr("K fixed (nominal design)"), QString());
  redesign_->addItem(tr("LQR redesigned per variant"), QStringLiteral("lqr"));
  redesign_->setToolTip(tr("The closed loop of every variant: the gain designed on the nominal model kept (a robustness "
                           "study), or the LQR designed again on each variant"));
  form->addRow(tr("Controller"), redesign_);
  simulate_ = new QCheckBox(tr("nonlinear run per variant"), left);
  simulate_->setObjectName("sweepSimulate");
  simulate_->setToolTip(tr("Also simulate each variant's nonlinear closed loop: peak |input|, final error"));
  form->addRow(tr("Simulate"), simulate_);
  lv->addLayout(form);

  auto* buttons = new QHBoxLayout;
  run_button_ = new QPushButton(tr("Run"), left);
  run_button_->setObjectName("sweepRun");
  run_button_->setToolTip(tr("Run the study on the model as it is in the window"));
  cancel_button_ = new QPushButton(tr("Cancel"), left);
  cancel_button_->setObjectName("sweepCancel");
  save_button_ = new QPushButton(tr("Save results..."), left);
  save_button_->setObjectName("sweepSave");
  save_button_->setToolTip(tr("HDF5 (.h5), CSV (.csv) or MAT + .m for MATLAB/Octave (.mat)"));
  buttons->addWidget(run_button_);
  buttons->addWidget(cancel_button_);
  buttons->addWidget(save_button_);
  lv->addLayout(buttons);
  progress_ = new QProgressBar(left);
  progress_->setObjectName("sweepProgress");
  progress_->setRange(0, 1);
  progress_->setValue(0);
  progress_->setFormat(tr("not run yet"));  // "0 of 1 variants" said what was not so
  lv->addWidget(progress_);
  status_ = new QLabel(tr("Pick the fields to vary, then Run"), left);
  status_->setObjectName("sweepStatus");
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  lv->addWidget(status_);
  split->addWidget(left);

  // right: the results
  tabs_ = new QTabWidget(split);
  tabs_->setObjectName("sweepResults");
  auto* poles = new QWidget(tabs_);
  auto* ph = new QHBoxLayout(poles);
  ph->setContentsMargins(0, 0, 0, 0);
  pole_chart_ = new QChart;
  pole_chart_->legend()->hide();
  pole_chart_->setTitle(tr("Poles of every variant"));
  pole_view_ = new ChartView(pole_chart_, poles);
  pole_view_->setObjectName("sweepPoleMap");
  pole_view_->setRenderHint(QPainter::Antialiasing);
  ph->addWidget(pole_view_, 1);
  colour_bar_ = new ColourBar(poles);
  ph->addWidget(colour_bar_);
  tabs_->addTab(poles, tr("Poles"));

  auto* fig = new QWidget(tabs_);
  auto* fv = new QVBoxLayout(fig);
  fv->setContentsMargins(0, 0, 0, 0);
  auto* pick = new QHBoxLayout;
  figure_combo_ = new QComboBox(fig);
  figure_combo_->setObjectName("sweepFigure");
  figure_combo_->addItem(tr("largest closed-loop real part"), ClosedMaxReal);
  figure_combo_->addItem(tr("largest open-loop real part"), OpenMaxReal);
  figure_combo_->addItem(tr("peak |input| (nonlinear run)"), PeakInput);
  figure_combo_->addItem(tr("final error (nonlinear run)"), FinalError);
  parameter_combo_ = new QComboBox(fig);
  parameter_combo_->setObjectName("sweepParameter");
  pick->addWidget(figure_combo_, 1);
  pick->addWidget(new QLabel(tr("against"), fig));
  pick->addWidget(parameter_combo_, 1);
  fv->addLayout(pick);
  figure_chart_ = new QChart;
  figure_chart_->legend()->setAlignment(Qt::AlignBottom);
  figure_view_ = new ChartView(figure_chart_, fig);
  figure_view_->setObjectName("sweepFigureChart");
  figure_view_->setRenderHint(QPainter::Antialiasing);
  fv->addWidget(figure_view_, 1);
  tabs_->addTab(fig, tr("Figure of merit"));

  failed_ = new QTableWidget(0, 4, tabs_);
  failed_->setObjectName("sweepFailed");
  failed_->setHorizontalHeaderLabels({tr("Variant"), tr("Values"), tr("Status"), tr("Reason")});
  failed_->horizontalHeader()->setSectionResizeMode(3, QHeaderView::Stretch);
  failed_->verticalHeader()->setVisible(false);
  failed_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  failed_->setWordWrap(true);
  tabs_->addTab(failed_, tr("Failed"));

  summary_ = new QPlainTextEdit(tabs_);
  summary_->setObjectName("sweepSummary");
  summary_->setReadOnly(true);
  summary_->setLineWrapMode(QPlainTextEdit::NoWrap);
  QFont mono(QStringLiteral("monospace"));
  mono.setStyleHint(QFont::TypeWriter);
  summary_->setFont(mono);
  tabs_->addTab(summary_, tr("Summary"));
  split->addWidget(tabs_);
  split->setStretchFactor(0, 0);
  split->setStretchFactor(1, 1);
  split->setSizes({360, 900});

  connect(add_row_, &QPushButton::clicked, this, [this] {
    const int r = fields_->rowCount();
    fields_->insertRow(r);
    fields_->setItem(r, 0, new QTableWidgetItem(QStringLiteral("/bodies/0/mass")));
    fields_->setItem(r, 1, new QTableWidgetItem(QStringLiteral("1:2:5")));
    updateButtons();
  });
  connect(remove_row_, &QPushButton::clicked, this, [this] {
    std::vector<int> rows;
    for (const QModelIndex& i : fields_->selectionModel()->selectedRows()) rows.push_back(i.row());
    if (rows.empty() && fields_->currentRow() >= 0) rows.push_back(fields_->currentRow());
    std::sort(rows.rbegin(), rows.rend());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (int r : rows) fields_->removeRow(r);
    updateButtons();
  });
  // the Is column follows the pointer typed and the model's names
  connect(fields_, &QTableWidget::itemChanged, this, [this](QTableWidgetItem* it) {
    if (it && it->column() == 0) refreshFieldName(it->row());
  });
  connect(doc_, &Document::specChanged, this, [this] {
    for (int r = 0; r < fields_->rowCount(); ++r) refreshFieldName(r);
  });
  connect(run_button_, &QPushButton::clicked, this, [this] { run(); });
  connect(cancel_button_, &QPushButton::clicked, this, &SweepView::cancel);
  connect(save_button_, &QPushButton::clicked, this, &SweepView::saveDialog);
  connect(figure_combo_, &QComboBox::currentIndexChanged, this, [this] { drawFigure(); });
  connect(parameter_combo_, &QComboBox::currentIndexChanged, this, [this] { drawFigure(); });
}

void SweepView::setStatus(const QString& text, bool error) {
  status_->setText(text);
  status_->setStyleSheet(error ? QStringLiteral("QLabel { color: #a00000; }") : QString());
}

void SweepView::updateButtons() {
  run_button_->setEnabled(!isRunning());
  cancel_button_->setEnabled(isRunning());
  save_button_->setEnabled(!isRunning() && job_ != nullptr);
  add_row_->setEnabled(!isRunning());
  remove_row_->setEnabled(!isRunning() && fields_->rowCount() > 0);
}

void SweepView::addField(const QString& pointer, const QString& spec) {
  QString values = spec;
  if (values.isEmpty()) {
    double x = 0;
    try {
      const nlohmann::json j = study_model_json(doc_->spec());
      const nlohmann::json::json_pointer p(ss(pointer));
      if (j.contains(p) && j[p].is_number()) x = j[p].get<double>();
    } catch (const std::exception&) {
    }
    values = x != 0 ? QStringLiteral("%1:%2:11").arg(number(0.5 * x), number(1.5 * x)) : QStringLiteral("-1:1:11");
  }
  for (int r = 0; r < fields_->rowCount(); ++r) {
    if (fields_->item(r, 0) && fields_->item(r, 0)->text().trimmed() == pointer) {
      if (!spec.isEmpty() && fields_->item(r, 1)) fields_->item(r, 1)->setText(spec);
      fields_->setCurrentCell(r, 1);
      return;
    }
  }
  const int r = fields_->rowCount();
  fields_->insertRow(r);
  fields_->setItem(r, 0, new QTableWidgetItem(pointer));
  fields_->setItem(r, 1, new QTableWidgetItem(values));
  fields_->setCurrentCell(r, 1);
  updateButtons();
  emit message(tr("Sweep: %1 = %2 (edit the values in the Sweep view)").arg(pointer, values));
}

QString SweepView::fieldName(const QString& pointer) const {
  const std::string p = ss(pointer.trimmed());
  if (p.empty()) return QString();
  const auto ref = element_at_path(p);
  if (!ref || ref->index < 0 || ref->index >= element_count(doc_->spec(), ref->kind) || ref->field.empty())
    return tr("(not a field of an element)");
  try {
    const nlohmann::json j = study_model_json(doc_->spec());
    const nlohmann::json::json_pointer jp(p);
    if (!j.contains(jp)) return tr("(not in the model file)");
    if (!j[jp].is_number()) return tr("(not a number)");
  } catch (const std::exception&) {
    return tr("(not a JSON pointer)");
  }
  // the name the model tree gives it ("rod.mass" for /bodies/1/mass)
  return QStringLiteral("%1.%2").arg(qs(element_name(doc_->spec(), ref->kind, ref->index)), qs(ref->field).replace('/', '.'));
}

QString SweepView::shownField(const std::string& pointer) const {
  const QString name = fieldName(qs(pointer));
  return name.isEmpty() || name.startsWith('(') ? qs(pointer) : name;
}

void SweepView::refreshFieldName(int row) {
  if (row < 0 || row >= fields_->rowCount()) return;
  const QString pointer = fields_->item(row, 0) ? fields_->item(row, 0)->text() : QString();
  const QString name = fieldName(pointer);
  QTableWidgetItem* is = fields_->item(row, 2);
  if (!is) {
    is = new QTableWidgetItem;
    is->setFlags(is->flags() & ~Qt::ItemIsEditable);
    fields_->setItem(row, 2, is);
  }
  if (is->text() != name) is->setText(name);
  is->setForeground(name.startsWith('(') ? QBrush(QColor(170, 40, 30)) : QBrush());
  if (fields_->item(row, 0)) fields_->item(row, 0)->setToolTip(name.isEmpty() ? QString() : name + "  (" + pointer.trimmed() + ")");
}

SweepRequest SweepView::request() const {
  SweepRequest r;
  r.style = OptionStyle::Keyword;
  r.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : ss(doc_->filePath());
  r.model_text = study_model_json(doc_->spec()).dump(1);
  bool random = false;
  for (int row = 0; row < fields_->rowCount(); ++row) {
    const QString f = fields_->item(row, 0) ? fields_->item(row, 0)->text().trimmed() : QString();
    const QString s = fields_->item(row, 1) ? fields_->item(row, 1)->text().trimmed() : QString();
    if (f.isEmpty() && s.isEmpty()) continue;
    random = random || study_sweep_spec_is_random(ss(s));  // the core's grammar says
    r.vary.push_back(ss(f + "=" + s));
  }
  if (random) {
    r.samples = samples_->value();
    r.seed = static_cast<std::uint64_t>(seed_->value());
  }
  r.threads = threads_->value();
  r.redesign = ss(redesign_->currentData().toString());
  r.simulate = simulate_->isChecked();
  r.resume = false;
  return r;
}

bool SweepView::run() {
  if (isRunning()) return false;
  auto refuse = [this](const QString& why) {
    setStatus(why, true);
    emit message(tr("Sweep: %1").arg(why));
    return false;
  };
  SweepRequest r;
  try {
    r = request();
    if (r.vary.empty()) return refuse(tr("no field to vary: right-click a number in the property editor, Vary in sweep"));
    // the specs checked here, at once (the core's message names the field)
    (void)study_sweep_plan(r, nlohmann::json::parse(r.model_text));
  } catch (const std::exception& e) {
    return refuse(qs(e.what()));
  }
  done_.store(0);
  total_.store(0);
  auto result = std::make_shared<std::shared_ptr<const SweepJob>>();
  worker_.start(
      [this, r, result](const std::atomic<bool>& cancel, const StudyMessages& tell) {
        SweepProgress progress;
        progress.cancel = &cancel;
        progress.done = [this](long long done, long long total) {  // on the workers' threads: atomics only
          done_.store(done);
          total_.store(total);
        };
        *result = std::make_shared<const SweepJob>(study_sweep_job(r, tell, progress));
      },
      [this, result](const JobOutcome& out) { onFinished(*result, out); });
  progress_->setRange(0, 1);
  progress_->setValue(0);
  progress_->setFormat(tr("starting..."));
  setStatus(tr("Running..."), false);
  updateButtons();
  timer_->start();
  emit started();
  return true;
}

void SweepView::cancel() { worker_.cancel(); }

void SweepView::tick() {
  const long long total = total_.load(), done = done_.load();
  if (total > 0) {
    progress_->setFormat(tr("%v of %m variants"));
    progress_->setRange(0, static_cast<int>(std::min<long long>(total, std::numeric_limits<int>::max())));
    progress_->setValue(static_cast<int>(std::min(done, total)));
  }
}

void SweepView::onFinished(std::shared_ptr<const SweepJob> job, const JobOutcome& out) {
  const QString& error = out.error;
  timer_->stop();
  tick();
  if (drop_result_) {
    drop_result_ = false;
    setStatus(tr("The study of the previous model was stopped"), false);
    updateButtons();
    emit finished();
    return;
  }
  for (const QString& n : out.notes) emit message(tr("Sweep: %1").arg(n));
  if (job) {
    job_ = std::move(job);
    showResult();
    setStatus(tr("%1 of %2 variants completed, %3 failed; %4 stable")
                  .arg(job_->variants.size() - job_->failed)
                  .arg(job_->variants.size())
                  .arg(job_->failed)
                  .arg(job_->stable),
              false);
    emit message(tr("Sweep: %1").arg(status_->text()));
  } else {
    setStatus(error, true);
    emit message(tr("Sweep: %1").arg(error));
  }
  updateButtons();
  emit finished();
}

void SweepView::clearResult() {
  job_.reset();
  drawn_.clear();
  pole_chart_->removeAllSeries();
  for (QAbstractAxis* a : pole_chart_->axes()) {
    pole_chart_->removeAxis(a);
    delete a;
  }
  figure_chart_->removeAllSeries();
  for (QAbstractAxis* a : figure_chart_->axes()) {
    figure_chart_->removeAxis(a);
    delete a;
  }
  colour_bar_->clear();
  failed_->setRowCount(0);
  summary_->clear();
  parameter_combo_->clear();
  progress_->setValue(0);
  progress_->setFormat(tr("not run yet"));
  updateButtons();
}

void SweepView::showResult() {
  if (!job_) return;
  {
    const QSignalBlocker block(parameter_combo_);
    parameter_combo_->clear();
    for (const SweepVary& v : job_->plan.vary) parameter_combo_->addItem(shownField(v.field));
  }
  drawPoles();
  drawFigure();
  fillFailed();
  summary_->setPlainText(qs(study_sweep_summary(*job_)));
  tabs_->setTabText(2, job_->failed > 0 ? tr("Failed (%1)").arg(job_->failed) : tr("Failed"));
}

void SweepView::drawPoles() {
  drawn_.assign(job_ ? job_->variants.size() : 0, Drawn{});
  pole_chart_->removeAllSeries();
  for (QAbstractAxis* a : pole_chart_->axes()) {
    pole_chart_->removeAxis(a);
    delete a;
  }
  colour_bar_->clear();
  if (!job_ || job_->plan.vary.empty()) return;
  const bool closed = job_->closed_loop;
  // the first field's values give the colour
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const SweepVariant& v : job_->variants) {
    if (v.status != SweepStatus::Ok || v.values.empty() || !std::isfinite(v.values[0])) continue;
    lo = std::min(lo, v.values[0]);
    hi = std::max(hi, v.values[0]);
  }
  auto* ax = new QValueAxis;
  auto* ay = new QValueAxis;
  ax->setTitleText(tr("Re (1/s)"));
  ay->setTitleText(tr("Im (rad/s)"));
  ax->setLabelFormat("%.3g");
  ay->setLabelFormat("%.3g");
  pole_chart_->addAxis(ax, Qt::AlignBottom);
  pole_chart_->addAxis(ay, Qt::AlignLeft);
  std::vector<QScatterSeries*> levels(kLevels, nullptr);
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  auto extend = [&](double x, double y) {
    xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  };
  for (std::size_t i = 0; i < job_->variants.size(); ++i) {
    const SweepVariant& v = job_->variants[i];
    const Eigen::VectorXcd& p = closed ? v.closed_poles : v.open_poles;
    if (v.status != SweepStatus::Ok || p.size() == 0 || v.values.empty()) continue;
    const double t = hi > lo ? (v.values[0] - lo) / (hi - lo) : 0.5;
    const int level = std::clamp(static_cast<int>(std::floor(t * (kLevels - 1) + 0.5)), 0, kLevels - 1);
    const QColor colour = ColourBar::colourAt(level / double(kLevels - 1));
    QScatterSeries*& s = levels[level];
    if (!s) {
      s = new QScatterSeries;
      s->setMarkerShape(QScatterSeries::MarkerShapeCircle);
      s->setMarkerSize(7);
      s->setColor(colour);
      s->setBorderColor(colour.darker(130));
      pole_chart_->addSeries(s);
      s->attachAxis(ax);
      s->attachAxis(ay);
    }
    Drawn& d = drawn_[i];
    d.series = s;
    d.first = s->count();
    d.count = static_cast<int>(p.size());
    d.colour = colour;
    QList<QPointF> pts;
    for (Eigen::Index k = 0; k < p.size(); ++k) {
      pts << QPointF(p[k].real(), p[k].imag());
      extend(p[k].real(), p[k].imag());
    }
    s->append(pts);
  }
  // the nominal model's poles: black rings
  const Eigen::VectorXcd& nominal = closed ? job_->nominal_closed_poles : job_->nominal_open_poles;
  if (nominal.size() > 0) {
    auto* s = new QScatterSeries;
    s->setName(tr("nominal"));
    s->setMarkerSize(12);
    s->setColor(Qt::transparent);
    s->setBorderColor(Qt::black);
    s->setPen(QPen(Qt::black, 1.5));
    for (Eigen::Index k = 0; k < nominal.size(); ++k) {
      s->append(nominal[k].real(), nominal[k].imag());
      extend(nominal[k].real(), nominal[k].imag());
    }
    pole_chart_->addSeries(s);
    s->attachAxis(ax);
    s->attachAxis(ay);
  }
  if (!std::isfinite(xmin)) xmin = -1, xmax = 1, ymin = -1, ymax = 1;
  // the imaginary axis (Re = 0, the stability boundary) when in view, and the real axis
  xmax = std::max(xmax, 0.0);
  fit_axis(ax, xmin, xmax);
  fit_axis(ay, std::min(ymin, -1e-3), std::max(ymax, 1e-3));
  auto* im_axis = new QLineSeries;
  im_axis->setPen(QPen(QColor(150, 0, 0), 1, Qt::DashLine));
  im_axis->append(0, ay->min());
  im_axis->append(0, ay->max());
  auto* re_axis = new QLineSeries;
  re_axis->setPen(QPen(Qt::gray, 1));
  re_axis->append(ax->min(), 0);
  re_axis->append(ax->max(), 0);
  for (QLineSeries* l : {im_axis, re_axis}) {
    pole_chart_->addSeries(l);
    l->attachAxis(ax);
    l->attachAxis(ay);
  }
  const SweepVary& first = job_->plan.vary.front();
  pole_chart_->setTitle(tr("%1 poles of %2 variants, %3 (rings: nominal)")
                            .arg(closed ? tr("Closed-loop") : tr("Open-loop"))
                            .arg(job_->variants.size() - job_->failed)
                            .arg(closed ? (job_->redesigned ? tr("LQR redesigned") : tr("K fixed")) : tr("no state feedback")));
  pole_chart_->setToolTip(tr("Coloured by %1 (the colour bar)").arg(shownField(first.field)));
  if (std::isfinite(lo)) colour_bar_->setRange(shownField(first.field), lo, hi);
}

QList<QPointF> SweepView::plottedPoles(int variant) const {
  QList<QPointF> out;
  if (variant < 0 || variant >= static_cast<int>(drawn_.size())) return out;
  const Drawn& d = drawn_[variant];
  if (!d.series) return out;
  const QList<QPointF> all = d.series->points();
  for (int k = d.first; k < d.first + d.count && k < all.size(); ++k) out << all[k];
  return out;
}

QColor SweepView::variantColour(int variant) const {
  if (variant < 0 || variant >= static_cast<int>(drawn_.size()) || !drawn_[variant].series) return {};
  return drawn_[variant].series->color();
}

QList<QPointF> SweepView::figurePoints() const {
  QList<QPointF> out;
  for (QAbstractSeries* s : figure_chart_->series())
    if (auto* sc = qobject_cast<QScatterSeries*>(s)) out << sc->points();
  std::sort(out.begin(), out.end(), [](const QPointF& a, const QPointF& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  return out;
}

void SweepView::drawFigure() {
  figure_chart_->removeAllSeries();
  for (QAbstractAxis* a : figure_chart_->axes()) {
    figure_chart_->removeAxis(a);
    delete a;
  }
  figure_chart_->setTitle(QString());
  if (!job_ || job_->plan.vary.empty()) return;
  const int param = std::clamp(parameter_combo_->currentIndex(), 0, static_cast<int>(job_->plan.vary.size()) - 1);
  const int figure = figure_combo_->currentData().toInt();
  const bool needs_run = figure == PeakInput || figure == FinalError;
  if (needs_run && !job_->simulated) {
    figure_chart_->setTitle(tr("%1: the study ran no nonlinear runs (tick Simulate and Run again)").arg(figure_combo_->currentText()));
    return;
  }
  auto value = [&](const SweepVariant& v, bool* ok) {
    *ok = true;
    switch (figure) {
      case ClosedMaxReal: return job_->closed_loop ? v.closed_max_real : v.open_max_real;
      case OpenMaxReal: return v.open_max_real;
      case PeakInput:
        *ok = v.sim_status == 0 && v.peak_input.size() > 0;
        return *ok ? v.peak_input.cwiseAbs().maxCoeff() : 0.0;
      default: *ok = v.sim_status == 0; return v.final_error;
    }
  };
  auto* good = new QScatterSeries;
  auto* bad = new QScatterSeries;
  const bool stability = figure == ClosedMaxReal || figure == OpenMaxReal;
  good->setName(stability ? tr("stable") : tr("variant"));
  bad->setName(tr("not stable"));
  good->setColor(QColor(31, 119, 180));
  bad->setColor(QColor(214, 39, 40));
  for (QScatterSeries* s : {good, bad}) {
    s->setMarkerSize(8);
    s->setBorderColor(s->color().darker(130));
  }
  // with one field on a grid, a line through the points in the field's order
  const bool line = job_->plan.vary.size() == 1 && !job_->plan.random;
  auto* through = line ? new QLineSeries : nullptr;
  std::vector<std::pair<double, double>> pts;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const SweepVariant& v : job_->variants) {
    if (v.status != SweepStatus::Ok || param >= static_cast<int>(v.values.size())) continue;
    bool ok = false;
    const double y = value(v, &ok);
    const double x = v.values[param];
    if (!ok || !std::isfinite(x) || !std::isfinite(y)) continue;
    // the core's classification (analysis/stability.hpp): of the loop the figure shows
    const bool unstable = figure == OpenMaxReal ? !v.open_stable : !v.stable;
    (stability && unstable ? bad : good)->append(x, y);
    pts.emplace_back(x, y);
    xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  }
  auto* ax = new QValueAxis;
  auto* ay = new QValueAxis;
  ax->setTitleText(shownField(job_->plan.vary[param].field));
  ay->setTitleText(figure_combo_->currentText());
  ax->setLabelFormat("%.4g");
  ay->setLabelFormat("%.4g");
  figure_chart_->addAxis(ax, Qt::AlignBottom);
  figure_chart_->addAxis(ay, Qt::AlignLeft);
  if (stability) ymax = std::max(ymax, 0.0);  // the boundary in view
  fit_axis(ax, xmin, xmax);
  fit_axis(ay, ymin, ymax);
  if (through) {
    std::sort(pts.begin(), pts.end());
    for (const auto& [x, y] : pts) through->append(x, y);
    through->setPen(QPen(QColor(31, 119, 180, 140), 1.5));
    through->setName(QString());
    figure_chart_->addSeries(through);
    through->attachAxis(ax);
    through->attachAxis(ay);
  }
  if (stability) {
    auto* zero = new QLineSeries;
    zero->setPen(QPen(QColor(150, 0, 0), 1, Qt::DashLine));
    zero->append(ax->min(), 0);
    zero->append(ax->max(), 0);
    figure_chart_->addSeries(zero);
    zero->attachAxis(ax);
    zero->attachAxis(ay);
  }
  for (QScatterSeries* s : {good, bad}) {
    figure_chart_->addSeries(s);
    s->attachAxis(ax);
    s->attachAxis(ay);
  }
  // the legend names the scatter series only
  for (QLegendMarker* m : figure_chart_->legend()->markers())
    m->setVisible(qobject_cast<QScatterSeries*>(m->series()) != nullptr && static_cast<QScatterSeries*>(m->series())->count() > 0);
  figure_chart_->setTitle(tr("%1 against %2").arg(figure_combo_->currentText(), shownField(job_->plan.vary[param].field)));
}

void SweepView::fillFailed() {
  failed_->setRowCount(0);
  if (!job_) return;
  auto values = [&](const SweepVariant& v) {
    QStringList l;
    for (std::size_t k = 0; k < v.values.size() && k < job_->plan.vary.size(); ++k)
      l << QStringLiteral("%1 = %2").arg(shownField(job_->plan.vary[k].field), number(v.values[k]));
    return l.join(QStringLiteral(", "));
  };
  auto add = [&](std::size_t i, const QString& status, const QString& reason) {
    const int r = failed_->rowCount();
    failed_->insertRow(r);
    failed_->setItem(r, 0, new QTableWidgetItem(QString::number(i)));
    failed_->setItem(r, 1, new QTableWidgetItem(values(job_->variants[i])));
    failed_->setItem(r, 2, new QTableWidgetItem(status));
    auto* why = new QTableWidgetItem(reason);
    why->setToolTip(reason);
    failed_->setItem(r, 3, why);
  };
  for (std::size_t i = 0; i < job_->variants.size(); ++i) {
    const SweepVariant& v = job_->variants[i];
    if (v.status != SweepStatus::Ok) add(i, qs(to_string(v.status)), qs(v.reason));
    else if (v.sim_status > 0) add(i, tr("run failed"), qs(v.sim_reason));
  }
  failed_->resizeColumnsToContents();
  failed_->horizontalHeader()->setSectionResizeMode(3, QHeaderView::Stretch);
  failed_->resizeRowsToContents();
}

// ---------------------------------------------------------------------------
// saving

bool SweepView::saveResults(const QString& path, QString* error) {
  auto fail = [&](const QString& why) {
    if (error) *error = why;
    emit message(tr("Save sweep results: %1").arg(why));
    return false;
  };
  if (!job_) return fail(tr("no results to save (run a study first)"));
  if (isRunning()) return fail(tr("a study is running"));
  try {
    study_save_sweep(*job_, ss(path));  // the format from the suffix, every output guarded (as codyna sweep's)
  } catch (const std::exception& e) {
    return fail(qs(e.what()));
  }
  emit message(tr("Wrote %1").arg(path));
  return true;
}

void SweepView::saveDialog() {
  if (!job_) return;
  const QString dir = doc_->filePath().isEmpty() ? QDir::currentPath() : QFileInfo(doc_->filePath()).absolutePath();
  const QString path = QFileDialog::getSaveFileName(this, tr("Save sweep results"),
                                                    QDir(dir).filePath(qs(doc_->spec().name) + QStringLiteral("_sweep.h5")),
                                                    tr("HDF5 (*.h5 *.hdf5);;CSV (*.csv);;MATLAB/Octave (*.mat)"));
  if (path.isEmpty()) return;
  saveResults(path);
}

}  // namespace codyna::gui
