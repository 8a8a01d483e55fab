#include "gui/simulate_view.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QSignalBlocker>
#include <QSplitter>
#include <QStackedWidget>
#include <QTabWidget>
#include <QTableWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>

#include "gui/document.hpp"
#include "gui/result_plots.hpp"
#include "gui/signal_plot.hpp"
#include "gui/study_widgets.hpp"
#include "study/files.hpp"
#include "model/model_spec.hpp"

namespace codyna::gui {

namespace {

constexpr int kMergeTEnd = 0x53490001;
constexpr int kMergeInitial = 0x53490a;  // values stepped in the initial-state table
constexpr int kMergeOutputStep = 0x53490002;
constexpr int kMergeTracking = 0x53490003;
constexpr int kMergeReferences = 0x53490004;    // numbers stepped in the references table
constexpr int kMergeDisturbances = 0x53490005;  // and in the disturbances table
// points per plotted series while a run is live (ResultPlots decimates beyond it):
// a Qt Charts redraw costs ~10 us per point on the GUI thread, so the live view
// stays light; the finished result is shown at the plots' own limit
constexpr int kLivePlotPoints = 2000;


QString simNumber(double x, int digits = 6) { return QString::number(x, 'g', digits); }

QString joinNumbers(const std::vector<double>& v) {
  QStringList l;
  for (double x : v) l << QString::number(x, 'g', 15);
  return l.join(QStringLiteral(", "));
}

// "10, 100 1;1" -> numbers; false on anything else
bool parseNumbers(const QString& text, std::vector<double>* out) {
  out->clear();
  const QStringList parts = text.split(QRegularExpression(QStringLiteral("[,;\\s]+")), Qt::SkipEmptyParts);
  for (const QString& p : parts) {
    bool ok = false;
    const double x = p.toDouble(&ok);
    if (!ok || !std::isfinite(x)) return false;
    out->push_back(x);
  }
  return true;
}

QString matrixText(const Eigen::MatrixXd& M) {
  QStringList rows;
  for (Eigen::Index r = 0; r < M.rows(); ++r) {
    QStringList cols;
    for (Eigen::Index c = 0; c < M.cols(); ++c) cols << simNumber(M(r, c), 4);
    rows << cols.join(QLatin1Char(' '));
  }
  return QLatin1Char('[') + rows.join(QStringLiteral("; ")) + QLatin1Char(']');
}

QString describeController(const ModelSpec& s) {
  const ControllerSpec& c = s.controller;
  const QString at = QObject::tr("about the %1 point").arg(qs(c.operating_point));
  switch (c.type) {
    case ControllerType::None:
      return QObject::tr("The model file declares no controller: the run is open loop (actuators at their nominal values).");
    case ControllerType::Pid: {
      QString t = QObject::tr("PID on Plant/Out, %1: u = u0 + Kp (r - y) + Ki \u222b(r - y) - Kd dy/dt, r = %2.")
                      .arg(at, c.setpoint.size() ? matrixText(c.setpoint.transpose()) : QObject::tr("y0"));
      return t + QObject::tr(" Gains (Plant/In x Plant/Out):");
    }
    case ControllerType::StateFeedback:
      return QObject::tr("State feedback u = u0 - K (x - x0), %1, K = %2.").arg(at, matrixText(c.K));
    case ControllerType::Lti:
      return QObject::tr("LTI controller with %1 states, %2, %3.")
          .arg(c.Ac.rows())
          .arg(c.Ts > 0 ? QObject::tr("sampled (Ts = %1 s, zero-order hold)").arg(simNumber(c.Ts)) : QObject::tr("continuous"))
          .arg(at);
    case ControllerType::Lqr:
      return QObject::tr("LQR designed on the plant linearized %1; Q = diag(%2), R = diag(%3).")
          .arg(at, c.q_weights.empty() ? QObject::tr("1 ... 1") : joinNumbers(c.q_weights),
               c.r_weights.empty() ? QObject::tr("1 ... 1") : joinNumbers(c.r_weights));
    case ControllerType::Driver:
      return QObject::tr("Driver: pure pursuit on a %1 path (preview %2 m) steering %3%4, sampled every %5 s; "
                         "its maneuvers run from the command line (codyna maneuver).")
          .arg(qs(c.path), simNumber(c.preview), qs(c.steer),
               c.drive.empty() ? QString() : QObject::tr(", a PI on speed driving %1").arg(qs(c.drive)),
               simNumber(c.sample_time));
  }
  return {};
}

}  // namespace

SimulateView::SimulateView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  worker_ = new SimWorker(this);
  buildUi();
  connect(worker_, &SimWorker::samples, this, &SimulateView::onSamples);
  connect(worker_, &SimWorker::progress, this, &SimulateView::onProgress);
  connect(worker_, &SimWorker::finished, this, &SimulateView::onFinished);
  connect(worker_, &SimWorker::failed, this, &SimulateView::onFailed);
  connect(worker_, &SimWorker::setupDone, this, [this](const QString& source) {
    status_ = tr("running (controller: %1)…").arg(source);
    status_label_->setText(status_);
    for (const QString& n : worker_->notes()) emit message(n.startsWith(QLatin1String("warning: ")) ? n : tr("note: %1").arg(n));
  });
  connect(doc_, &Document::specChanged, this, &SimulateView::refreshFromDocument);
  connect(doc_, &Document::replaced, this, &SimulateView::clearResult);
  connect(doc_, &Document::modelChanged, this, [this] {
    updateStaleness();
    refreshInitialChoices();
  });
  refreshFromDocument();
  setRunning(false);
}

void SimulateView::refreshInitialChoices() {
  // the names offered: the compiled model's coordinates and rates (kept while it does not compile)
  const auto m = doc_->model();
  if (!m) return;
  QStringList coords;
  for (const auto& n : m->v_names) coords << qs(n);
  for (const auto& n : m->rate_names) coords << qs(n);
  initial_->setChoices(coords);
}

bool SimulateView::isStale() const { return result_ && result_model_ != doc_->model(); }

void SimulateView::updateStaleness() { stale_label_->setVisible(isStale() && !isRunning()); }

void SimulateView::clearResult() {
  if (isRunning()) {
    discard_run_ = true;  // what it still delivers belongs to the old model
    cancel();
  }
  result_.reset();
  result_model_.reset();
  plant_inputs_.clear();
  restorePlotLimit();
  plots_->reset({}, {}, {}, {}, 1.0);
  signal_plot_->setResult(nullptr);
  signal_plot_->clearKept();  // runs of another model are no comparison
  progress_->setValue(0);
  status_ = tr("Not run yet.");
  status_label_->setText(status_);
  setRunning(isRunning());
  updateStaleness();
}

SimulateView::~SimulateView() {
  // the worker (a child) cancels and joins its thread in its destructor; disconnect
  // first so that nothing it still delivers reaches this half-destroyed widget
  worker_->disconnect(this);
}

void SimulateView::buildUi() {
  // ---- controller
  auto* ctrl_box = new QGroupBox(tr("Controller"), this);
  auto* ctrl_layout = new QVBoxLayout(ctrl_box);
  controller_combo_ = new QComboBox(ctrl_box);
  controller_combo_->addItem(tr("None (open loop)"), QStringLiteral("none"));
  controller_combo_->addItem(tr("The model file's controller"), QStringLiteral("model"));
  controller_combo_->addItem(tr("From a .mat file (K, Kp/Ki/Kd or Ac..Dc)"), QStringLiteral("file"));
  controller_combo_->addItem(tr("LQR designed on the linearized plant"), QStringLiteral("lqr"));
  controller_combo_->setToolTip(tr("The controller of the run: none (actuators at u0), the model file's, one read "
                                   "from a .mat file, or an LQR designed on the plant linearized as in the Linearize tab"));
  ctrl_layout->addWidget(controller_combo_);
  controller_pages_ = new QStackedWidget(ctrl_box);
  ctrl_layout->addWidget(controller_pages_);
  auto* aw_form = new QFormLayout;
  anti_windup_ = new QComboBox(ctrl_box);
  anti_windup_->addItem(tr("none (the integral runs on)"), QStringLiteral("none"));
  anti_windup_->addItem(tr("back-calculation"), QStringLiteral("back_calculation"));
  anti_windup_->addItem(tr("conditional integration"), QStringLiteral("conditional"));
  anti_windup_->setToolTip(tr("PID with integral action, when an actuator sits at its min/max: back-calculation "
                              "bleeds the integral with the tracking time; conditional holds an integral that would "
                              "push a saturated input further"));
  tracking_time_ = new QDoubleSpinBox(ctrl_box);
  tracking_time_->setRange(0.0, 1e6);
  tracking_time_->setDecimals(4);
  tracking_time_->setSingleStep(0.01);
  tracking_time_->setSuffix(QStringLiteral(" s"));
  tracking_time_->setSpecialValueText(tr("not set"));
  tracking_time_->setKeyboardTracking(false);
  tracking_time_->setToolTip(tr("Back-calculation's time constant (> 0), e.g. the integral time Kp/Ki"));
  aw_form->addRow(tr("PID anti-windup"), anti_windup_);
  aw_form->addRow(tr("Tracking time"), tracking_time_);
  ctrl_layout->addLayout(aw_form);

  auto* none_page = new QLabel(tr("Actuators at their nominal values u0."), controller_pages_);
  none_page->setWordWrap(true);
  controller_pages_->addWidget(none_page);

  auto* model_page = new QWidget(controller_pages_);
  auto* model_layout = new QVBoxLayout(model_page);
  model_layout->setContentsMargins(0, 0, 0, 0);
  controller_desc_ = new QLabel(model_page);
  controller_desc_->setWordWrap(true);
  pid_table_ = new QTableWidget(model_page);
  pid_table_->setMaximumHeight(130);
  pid_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  pid_table_->setToolTip(tr("PID gains: one row per Plant/In, one column per Plant/Out for each of Kp, Ki, Kd"));
  model_layout->addWidget(controller_desc_);
  model_layout->addWidget(pid_table_);
  controller_pages_->addWidget(model_page);

  auto* file_page = new QWidget(controller_pages_);
  auto* file_layout = new QHBoxLayout(file_page);
  file_layout->setContentsMargins(0, 0, 0, 0);
  file_edit_ = new QLineEdit(file_page);
  file_edit_->setPlaceholderText(tr("controller.mat (relative to the model file)"));
  file_edit_->setToolTip(tr("A controller saved as a .mat (K, or the LTI Ac, Bc, Cc, Dc), e.g. from the exported "
                            "NAME.m's design in MATLAB or Octave"));
  file_browse_ = new QPushButton(tr("…"), file_page);
  file_browse_->setToolTip(tr("Choose the controller file"));
  file_layout->addWidget(file_edit_, 1);
  file_layout->addWidget(file_browse_);
  controller_pages_->addWidget(file_page);

  auto* lqr_page = new QWidget(controller_pages_);
  auto* lqr_form = new QFormLayout(lqr_page);
  lqr_form->setContentsMargins(0, 0, 0, 0);
  q_weights_ = new QLineEdit(lqr_page);
  q_weights_->setPlaceholderText(tr("identity"));
  q_weights_->setToolTip(tr("LQR state weights: the diagonal of Q, one number per state (A's order), separated by "
                            "spaces or commas; empty = identity"));
  r_weights_ = new QLineEdit(lqr_page);
  r_weights_->setToolTip(tr("LQR input weights: the diagonal of R, one positive number per Plant/In input; empty = identity"));
  r_weights_->setPlaceholderText(tr("identity"));
  lqr_hint_ = new QLabel(lqr_page);
  lqr_hint_->setWordWrap(true);
  lqr_form->addRow(tr("Q diagonal"), q_weights_);
  lqr_form->addRow(tr("R diagonal"), r_weights_);
  lqr_controllable_ = new QCheckBox(tr("Design on the controllable part only"), lqr_page);
  lqr_controllable_->setToolTip(tr("A plant that is not stabilizable: the modes no input moves are named and left as "
                                   "they are (without this, such a plant is refused)"));
  lqr_form->addRow(lqr_controllable_);
  lqr_form->addRow(lqr_hint_);
  controller_pages_->addWidget(lqr_page);

  // ---- solver
  auto* solver_box = new QGroupBox(tr("Simulation"), this);
  auto* form = new QFormLayout(solver_box);
  t_end_ = new QDoubleSpinBox(solver_box);
  t_end_->setRange(1e-4, 1e7);  // the smallest value the 4 decimals show (not 0: the reader refuses it)
  t_end_->setDecimals(4);
  t_end_->setSuffix(QStringLiteral(" s"));
  t_end_->setKeyboardTracking(false);
  t_end_->setToolTip(tr("End time of the run in s"));
  form->addRow(tr("End time"), t_end_);
  start_ = new QComboBox(solver_box);
  start_->setObjectName("startCombo");
  start_->addItem(tr("the model's state"), QStringLiteral("model"));
  start_->addItem(tr("the operating point (x0)"), QStringLiteral("operating-point"));
  start_->setToolTip(tr("Where the run starts (the file's analysis.start, codyna simulate --initial operating-point): "
                        "the model's own state, or the operating point the controller's plant is linearized about, "
                        "where a regulator is designed to hold the mechanism. The initial-state table below sets "
                        "coordinates on top of either."));
  form->addRow(tr("Start at"), start_);
  initial_ = new NameValueTable(tr("Coordinate"), tr("Start value (m, rad, /s)"), solver_box);
  initial_->setObjectName("initialState");
  initial_->setToolTip(tr("Where the run starts, apart from the operating point (the file's analysis.initial, "
                          "codyna simulate --initial): coordinates and rates (NAME_dot) set on the model's state, "
                          "the loops closed with them held. The operating point is searched as before."));
  form->addRow(tr("Initial state"), initial_);
  output_step_ = new QDoubleSpinBox(solver_box);
  output_step_->setRange(1e-6, 1e5);
  output_step_->setDecimals(6);
  output_step_->setSingleStep(0.001);
  output_step_->setSuffix(QStringLiteral(" s"));
  output_step_->setKeyboardTracking(false);
  output_step_->setToolTip(tr("Time between recorded samples in s (the integrator chooses its own steps)"));
  form->addRow(tr("Output step"), output_step_);
  integrator_ = new QComboBox(solver_box);
  for (const char* name : codyna::kIntegratorNames) integrator_->addItem(QLatin1String(name), QLatin1String(name));
  integrator_->setToolTip(tr("auto chooses from the eigenvalues at the start (stiff: alf extrapolated at rtol 1e-4 or "
                             "looser, cvode-bdf tighter; otherwise cvode-adams for trees, arkode for closed loops; the "
                             "choice is reported); or ida, cvode-bdf, "
                             "cvode-adams, arkode, the fixed-step rk4, alf (closed loops through singular positions)"));
  form->addRow(tr("Integrator"), integrator_);
  solver_form_ = form;
  // a number field of the solver section: its object name, its label (also the name its refusals
  // give it), what empty means, its tooltip
  const auto numberField = [&](const char* name, const QString& label, const QString& empty, const QString& tip) {
    auto* e = new QLineEdit(solver_box);
    e->setObjectName(QLatin1String(name));
    e->setPlaceholderText(empty);
    e->setToolTip(tip);
    form->addRow(label, e);
    return e;
  };
  rtol_ = numberField("rtol", tr("Relative tolerance"), QString(), tr("Relative tolerance of the integrator (e.g. 1e-8)"));
  atol_ = numberField("atol", tr("Absolute tolerance"), QString(),
                      tr("Absolute tolerance of the integrator, in the states' units (e.g. 1e-10)"));
  max_step_ = numberField("maxStep", tr("Maximum step"), tr("no limit"),
                          tr("The longest step the integrator may take, in s (empty: no limit); the step of rk4 and of "
                             "alf at fixed steps (the file's solver.max_step, codyna simulate --max-step)"));
  // alf's own settings: editable when alf is the integrator (the file keeps them either way)
  alf_fixed_ = new QCheckBox(tr("alf at fixed steps of the maximum step"), solver_box);
  alf_fixed_->setObjectName("alfFixedStep");
  alf_fixed_->setToolTip(tr("alf steps at the maximum step (1 ms when none is given) instead of choosing its steps "
                            "by its error estimate; Newton then works to rtol, atol of at most 1e-6 (solver.alf_fixed_step, "
                            "--alf-fixed-step)"));
  form->addRow(alf_fixed_);
  alf_extrapolate_ = new QCheckBox(tr("alf: each step extrapolated from two halves"), solver_box);
  alf_extrapolate_->setObjectName("alfExtrapolate");
  alf_extrapolate_->setToolTip(tr("alf combines each step from finer trapezoidal steps (Richardson's extrapolation): "
                                  "fourth order instead of second on smooth motion. At fixed steps two halves, three "
                                  "steps' work (a model whose fastest mode is too fast for the step is refused, with the "
                                  "longest step that passes); with error control two halves and four quarters, six "
                                  "steps' work, their difference the error estimate (stable on stiff springs) "
                                  "(solver.alf_extrapolate, --alf-extrapolate)"));
  form->addRow(alf_extrapolate_);
  alf_penalty_ = numberField("alfPenalty", tr("alf penalty"), tr("1e11 (alf's default)"),
                             tr("alf's penalty alpha on the loop closures, a number > 0 (empty: the default 1e11; "
                                "solver.alf_penalty, --alf-penalty)"));
  alf_iterations_ = numberField("alfIterations", tr("alf iterations"), tr("100 (alf's default)"),
                                tr("alf's most Newton iterations a step, a whole number >= 1 (empty: the default 100; "
                                   "solver.alf_iterations, --alf-iterations)"));
  compare_linear_ = new QCheckBox(tr("Compare with the linear closed loop"), solver_box);
  compare_linear_->setToolTip(tr("Also run the linear plant with the same controller from the same start; its outputs "
                                 "are drawn dashed (codyna simulate --compare-linear)"));
  form->addRow(compare_linear_);
  closed_loop_ = new QCheckBox(tr("Export the linear closed loop with the plant"), solver_box);
  closed_loop_->setToolTip(tr("codyna linearize also writes NAME_cl.m/.mat (Acl, Bcl, Ccl, Dcl) and the step and "
                              "frequency responses"));
  form->addRow(closed_loop_);

  // ---- references and disturbances (under the plots: the table needs the width)
  auto* signals_box = new QTabWidget(this);
  auto* ref_page = new QWidget(signals_box);
  auto* ref_col = new QVBoxLayout(ref_page);
  auto* ref_note = new QLabel(tr("r(t) on Plant/Out, one per output (r = y0 before the time); every controller "
                                   "follows it: PID on r - y, state feedback through Nbar, LTI on y - r"), ref_page);
  ref_note->setWordWrap(true);
  ref_col->addWidget(ref_note);
  references_ = new SignalTable(tr("Plant/Out"), ref_page);
  ref_col->addWidget(references_);
  signals_box->addTab(ref_page, tr("References r(t)"));
  auto* dist_page = new QWidget(signals_box);
  auto* dist_col = new QVBoxLayout(dist_page);
  auto* dist_note = new QLabel(tr("d(t) added to an actuator that is not Plant/In (d = 0 before the time), then "
                                    "limited like the actuator"), dist_page);
  dist_note->setWordWrap(true);
  dist_col->addWidget(dist_note);
  disturbances_ = new SignalTable(tr("Actuator"), dist_page);
  dist_col->addWidget(disturbances_);
  signals_box->addTab(dist_page, tr("Disturbances d(t)"));

  // ---- run
  run_button_ = new QPushButton(tr("Run"), this);
  run_button_->setToolTip(tr("Simulate the nonlinear model with this controller (F5); plots follow live"));
  run_button_->setDefault(true);
  cancel_button_ = new QPushButton(tr("Cancel"), this);
  progress_ = new QProgressBar(this);
  progress_->setRange(0, 1000);
  progress_->setTextVisible(false);
  status_label_ = new QLabel(tr("Not run yet."), this);
  status_label_->setWordWrap(true);
  status_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  stale_label_ = new QLabel(tr("<b>Out of date:</b> the model changed since this run: run again."), this);
  stale_label_->setObjectName("simulateStale");
  stale_label_->setStyleSheet("QLabel { background: #fff0c0; color: #6a4a00; padding: 3px; }");
  stale_label_->setWordWrap(true);
  stale_label_->setVisible(false);
  save_results_ = new QPushButton(tr("Save results…"), this);
  save_plot_ = new QPushButton(tr("Save plot…"), this);
  save_plot_->setToolTip(tr("Save the Plant/In and Plant/Out plots as PNG or SVG"));
  auto* run_row = new QHBoxLayout;
  run_row->addWidget(run_button_);
  run_row->addWidget(cancel_button_);
  auto* save_row = new QHBoxLayout;
  save_row->addWidget(save_results_);
  save_row->addWidget(save_plot_);

  auto* left = new QWidget(this);
  auto* left_layout = new QVBoxLayout(left);
  left_layout->addWidget(ctrl_box);
  left_layout->addWidget(solver_box);
  left_layout->addLayout(run_row);
  left_layout->addWidget(progress_);
  left_layout->addWidget(status_label_);
  left_layout->addWidget(stale_label_);
  left_layout->addLayout(save_row);
  left_layout->addStretch(1);

  plots_ = new ResultPlots(this);
  signal_plot_ = new SignalPlot(this);
  plot_tabs_ = new QTabWidget(this);
  plot_tabs_->addTab(plots_, tr("Plant/In, Plant/Out"));
  plot_tabs_->addTab(signal_plot_, tr("Any signal"));
  plot_tabs_->setTabToolTip(1, tr("Every recorded quantity: coordinates, rates, efforts, outputs, controller states, "
                                  "energy, constraint drift; runs kept for comparison"));
  auto* right = new QSplitter(Qt::Vertical, this);
  right->addWidget(plot_tabs_);
  right->addWidget(signals_box);
  right->setStretchFactor(0, 1);
  right->setStretchFactor(1, 0);
  right->setSizes({400, 120});  // the plots first; the reference and disturbance tables below, smaller
  auto* left_scroll = new QScrollArea(this);
  left_scroll->setWidget(left);
  left_scroll->setWidgetResizable(true);
  left_scroll->setFrameShape(QFrame::NoFrame);
  left_scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  // as wide as its fields want, but a small screen (1024 px) may squeeze it
  left_scroll->setMinimumWidth(std::min(left->sizeHint().width() + 20, 300));
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->addWidget(left_scroll);
  split->addWidget(right);
  split->setStretchFactor(0, 0);
  split->setStretchFactor(1, 1);
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(split);

  // ---- widgets -> document
  connect(controller_combo_, &QComboBox::currentIndexChanged, this, [this](int i) {
    controller_pages_->setCurrentIndex(std::max(0, i));
    if (i < 0) return;
    const std::string c = ss(controller_combo_->itemData(i).toString());
    // an LQR designed here is designed about the operating point: a regulator's run starts there
    // (the usual choice), in the same undoable step; the Start-at drop-down shows it and takes the
    // model's own state back. The model file's controller keeps the file's choice.
    const StudySpec& now = doc_->spec().analysis;
    const bool start_there = !syncing_ && c == "lqr" && now.controller != "lqr" && now.start == "model";
    writeStudy([&](StudySpec& s) {
      s.controller = c;
      if (start_there) s.start = "operating-point";
    }, start_there ? tr("Change the controller (and start at the operating point)") : tr("Change the controller"));
    if (start_there && doc_->spec().analysis.start == "operating-point")
      emit message(tr("The LQR is designed about the operating point: the run starts there now (Start at; "
                      "the initial-state table sets an offset from it)."));
  });
  connect(pid_table_, &QTableWidget::cellChanged, this, &SimulateView::pidEdited);
  connect(file_edit_, &QLineEdit::editingFinished, this, [this] {
    const std::string f = ss(file_edit_->text().trimmed());
    writeStudy([&](StudySpec& s) { s.controller_file = f; }, tr("Change the controller file"));
  });
  connect(file_browse_, &QPushButton::clicked, this, &SimulateView::browseControllerFile);
  connect(q_weights_, &QLineEdit::editingFinished, this, [this] { weightsEdited(true); });
  connect(r_weights_, &QLineEdit::editingFinished, this, [this] { weightsEdited(false); });
  connect(start_, &QComboBox::activated, this, [this] {
    const std::string v = ss(start_->currentData().toString());
    writeStudyChecked([&](StudySpec& s) { s.start = v; }, tr("Change where the run starts"), -1);
  });
  connect(initial_, &NameValueTable::edited, this, [this](bool number) {
    const auto v = initial_->pairs();
    writeStudyChecked([&](StudySpec& s) { s.initial = v; }, tr("Change the initial state"), number ? kMergeInitial : -1);
  });
  connect(t_end_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    writeSolver([&](SolverSpec& s) { s.t_end = v; }, tr("Change the end time"), kMergeTEnd);
  });
  connect(output_step_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    writeSolver([&](SolverSpec& s) { s.output_step = v; }, tr("Change the output step"), kMergeOutputStep);
  });
  connect(integrator_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (i < 0) return;
    const std::string m = ss(integrator_->itemData(i).toString());
    writeSolver([&](SolverSpec& s) { s.integrator = m; }, tr("Change the integrator"));
  });
  // the solver's number fields: what each takes, what empty means, where it goes (one parser, one
  // refusal message naming the field, the value and what was expected)
  using Opt = std::optional<double>;
  solver_numbers_ = {
      {rtol_, tr("a number > 0"), NumberRule::Positive, false,
       [](SolverSpec& s, Opt v) { s.rtol = *v; }, tr("Change the relative tolerance")},
      {atol_, tr("a number > 0"), NumberRule::Positive, false,
       [](SolverSpec& s, Opt v) { s.atol = *v; }, tr("Change the absolute tolerance")},
      {max_step_, tr("a number of seconds >= 0 (empty: no limit)"), NumberRule::NonNegative, true,
       [](SolverSpec& s, Opt v) { s.max_step = v.value_or(0.0); }, tr("Change the maximum step")},
      {alf_penalty_, tr("a number > 0 (empty: 1e11)"), NumberRule::Positive, true,
       [](SolverSpec& s, Opt v) { s.alf_penalty = v; }, tr("Change alf's penalty")},
      {alf_iterations_, tr("a whole number >= 1 (empty: 100)"), NumberRule::Count, true,
       [](SolverSpec& s, Opt v) { s.alf_iterations = v ? std::optional<int>(static_cast<int>(*v)) : std::nullopt; },
       tr("Change alf's iterations")},
  };
  for (std::size_t i = 0; i < solver_numbers_.size(); ++i)
    connect(solver_numbers_[i].edit, &QLineEdit::editingFinished, this, [this, i] { solverNumberEdited(solver_numbers_[i]); });
  connect(alf_fixed_, &QCheckBox::toggled, this, [this](bool on) {
    writeSolver([&](SolverSpec& s) { s.alf_fixed_step = on; },
                on ? tr("alf at fixed steps") : tr("alf with error control"));
  });
  connect(alf_extrapolate_, &QCheckBox::toggled, this, [this](bool on) {
    writeSolver([&](SolverSpec& s) { s.alf_extrapolate = on; }, on ? tr("alf extrapolated") : tr("alf not extrapolated"));
  });
  connect(compare_linear_, &QCheckBox::toggled, this, [this](bool on) {
    writeStudy([&](StudySpec& s) { s.compare_linear = on; }, on ? tr("Compare with the linear loop") : tr("Do not compare with the linear loop"));
  });

  connect(closed_loop_, &QCheckBox::toggled, this, [this](bool on) {
    writeStudyChecked([&](StudySpec& s) { s.closed_loop.enabled = on; },
                      on ? tr("Export the linear closed loop") : tr("Do not export the linear closed loop"));
  });
  connect(lqr_controllable_, &QCheckBox::toggled, this, [this](bool on) {
    writeStudyChecked([&](StudySpec& s) { s.lqr_controllable_part = on; },
                      on ? tr("LQR on the controllable part") : tr("LQR on the whole plant"));
  });
  connect(anti_windup_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (i < 0) return;
    const std::string a = ss(anti_windup_->itemData(i).toString());
    tracking_time_->setEnabled(a == "back_calculation");
    writeStudyChecked([&](StudySpec& s) { s.anti_windup = a; }, tr("Change the anti-windup"));
  });
  connect(tracking_time_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    writeStudyChecked([&](StudySpec& s) { s.tracking_time = v; }, tr("Change the tracking time"), kMergeTracking);
  });
  connect(references_, &SignalTable::edited, this, [this](bool number) { signalsEdited(true, number); });
  connect(disturbances_, &SignalTable::edited, this, [this](bool number) { signalsEdited(false, number); });

  connect(run_button_, &QPushButton::clicked, this, &SimulateView::run);
  connect(cancel_button_, &QPushButton::clicked, this, &SimulateView::cancel);
  connect(save_results_, &QPushButton::clicked, this, &SimulateView::saveResultsDialog);
  connect(save_plot_, &QPushButton::clicked, this, &SimulateView::savePlotDialog);
}

// ---------------------------------------------------------------------------
// document <-> widgets

void SimulateView::writeStudy(const std::function<void(StudySpec&)>& change, const QString& text, int mergeKey) {
  if (syncing_) return;
  StudySpec s = doc_->spec().analysis;
  change(s);
  if (s == doc_->spec().analysis) return;
  doc_->setStudy(s, text, mergeKey);
}

void SimulateView::writeStudyChecked(const std::function<void(StudySpec&)>& change, const QString& text, int mergeKey) {
  if (syncing_) return;
  StudySpec s = doc_->spec().analysis;
  change(s);
  if (s == doc_->spec().analysis) return;
  QString error;
  if (!doc_->setStudyChecked(s, text, &error, mergeKey)) {
    emit message(tr("Refused: %1").arg(error));
    refreshFromDocument();
  }
}

void SimulateView::signalsEdited(bool references, bool number) {
  SignalTable* t = references ? references_ : disturbances_;
  std::vector<SignalSpec> v;
  QString error;
  if (!t->readSignals(&v, &error)) {
    emit message(tr("%1: %2").arg(references ? tr("References") : tr("Disturbances"), error));
    refreshSignals();
    return;
  }
  writeStudyChecked(
      [&](StudySpec& s) {
        if (references) {
          s.references = v;
          return;
        }
        s.disturbances.clear();
        for (const SignalSpec& x : v) {
          DisturbanceSpec d;
          static_cast<SignalSpec&>(d) = x;
          d.actuator = x.output;
          d.output.clear();
          s.disturbances.push_back(std::move(d));
        }
      },
      references ? tr("Change the references") : tr("Change the disturbances"),
      number ? (references ? kMergeReferences : kMergeDisturbances) : -1);
}

void SimulateView::refreshSignals() {
  const ModelSpec& spec = doc_->spec();
  references_->setChoices([&] {
    QStringList l;
    for (const auto& n : spec.plant.outputs) l << qs(n);
    return l;
  }());
  references_->setSignals(spec.analysis.references);
  QStringList actuators;
  for (const auto& a : spec.actuators)
    if (!std::count(spec.plant.inputs.begin(), spec.plant.inputs.end(), a.name)) actuators << qs(a.name);
  disturbances_->setChoices(actuators);
  std::vector<SignalSpec> d;
  for (const DisturbanceSpec& x : spec.analysis.disturbances) {
    SignalSpec s = x;
    s.output = x.actuator;
    d.push_back(std::move(s));
  }
  disturbances_->setSignals(d);
}

void SimulateView::writeSolver(const std::function<void(SolverSpec&)>& change, const QString& text, int mergeKey) {
  if (syncing_) return;
  SolverSpec s = doc_->spec().solver;
  change(s);
  QString why;  // (an edit that changes nothing is no edit: Document::setSolver checks nothing then)
  if (!doc_->setSolver(s, text, mergeKey, &why)) {  // refused: said, and the model's value shown again
    emit message(why);
    refreshFromDocument();
  }
}

void SimulateView::refreshFromDocument() {
  syncing_ = true;
  const ModelSpec& spec = doc_->spec();
  const StudySpec& st = spec.analysis;
  const SolverSpec& so = spec.solver;
  refreshInitialChoices();
  initial_->setPairs(st.initial);
  {
    const QSignalBlocker b(start_);
    start_->setCurrentIndex(std::max(0, start_->findData(qs(st.start))));
  }
  {
    const QSignalBlocker b(controller_combo_);
    const int i = controller_combo_->findData(qs(st.controller));
    controller_combo_->setCurrentIndex(i);
    controller_pages_->setCurrentIndex(std::max(0, i));
  }
  {
    const QSignalBlocker b(file_edit_);
    if (file_edit_->text() != qs(st.controller_file)) file_edit_->setText(qs(st.controller_file));
  }
  {
    const QSignalBlocker b1(q_weights_), b2(r_weights_);
    q_weights_->setText(joinNumbers(st.q_weights));
    r_weights_->setText(joinNumbers(st.r_weights));
  }
  {
    const QSignalBlocker b1(t_end_), b2(output_step_), b3(integrator_), b4(rtol_), b5(atol_), b6(compare_linear_);
    t_end_->setValue(so.t_end);
    output_step_->setValue(so.output_step);
    int i = integrator_->findData(qs(so.integrator));
    if (i < 0) {  // not one of ours (the run reports it): shown as it is
      integrator_->addItem(qs(so.integrator), qs(so.integrator));
      i = integrator_->count() - 1;
    }
    integrator_->setCurrentIndex(i);
    rtol_->setText(simNumber(so.rtol));
    atol_->setText(simNumber(so.atol));
    max_step_->setText(so.max_step > 0 ? QString::number(so.max_step, 'g', 17) : QString());
    const bool alf = so.integrator == "alf";
    const QSignalBlocker b7(alf_fixed_);
    alf_fixed_->setChecked(so.alf_fixed_step);
    const QSignalBlocker b8(alf_extrapolate_);
    alf_extrapolate_->setChecked(so.alf_extrapolate);
    alf_penalty_->setText(so.alf_penalty ? QString::number(*so.alf_penalty, 'g', 17) : QString());
    alf_iterations_->setText(so.alf_iterations ? QString::number(*so.alf_iterations) : QString());
    for (QWidget* w : std::initializer_list<QWidget*>{alf_fixed_, alf_penalty_, alf_iterations_}) w->setEnabled(alf);
    alf_extrapolate_->setEnabled(alf);
    compare_linear_->setChecked(st.compare_linear);
  }
  {
    const QSignalBlocker b1(closed_loop_), b2(lqr_controllable_), b3(anti_windup_), b4(tracking_time_);
    closed_loop_->setChecked(st.closed_loop.enabled);
    lqr_controllable_->setChecked(st.lqr_controllable_part);
    anti_windup_->setCurrentIndex(anti_windup_->findData(qs(st.anti_windup)));
    tracking_time_->setValue(st.tracking_time);
    tracking_time_->setEnabled(st.anti_windup == "back_calculation");
  }
  const int dof2 = doc_->model() ? doc_->model()->dof() + doc_->model()->rate_dof() : -1;
  const int nu = static_cast<int>(spec.plant.inputs.size());
  lqr_hint_->setText(dof2 >= 0 ? tr("Q: %1 weights in state order (positions, then velocities); R: %2 weights, one per "
                                    "Plant/In. Empty = identity.")
                                     .arg(dof2)
                                     .arg(nu)
                               : tr("Q: one weight per state; R: one per Plant/In. Empty = identity."));
  syncing_ = false;
  refreshSignals();
  refreshController();
}

void SimulateView::refreshController() {
  const ModelSpec& spec = doc_->spec();
  const ControllerSpec& c = spec.controller;
  controller_desc_->setText(describeController(spec));
  const bool pid = c.type == ControllerType::Pid;
  pid_table_->setVisible(pid);
  if (!pid) return;
  syncing_ = true;
  const QSignalBlocker b(pid_table_);
  const int nu = static_cast<int>(spec.plant.inputs.size()), ny = static_cast<int>(spec.plant.outputs.size());
  pid_table_->clear();
  pid_table_->setRowCount(nu);
  pid_table_->setColumnCount(3 * ny);
  QStringList rows, cols;
  for (const auto& n : spec.plant.inputs) rows << qs(n);
  const char* gains[3] = {"Kp", "Ki", "Kd"};
  const Eigen::MatrixXd* mats[3] = {&c.kp, &c.ki, &c.kd};
  for (int g = 0; g < 3; ++g)
    for (const auto& n : spec.plant.outputs) cols << QStringLiteral("%1: %2").arg(QLatin1String(gains[g]), qs(n));
  pid_table_->setVerticalHeaderLabels(rows);
  pid_table_->setHorizontalHeaderLabels(cols);
  for (int g = 0; g < 3; ++g) {
    const Eigen::MatrixXd& M = *mats[g];
    for (int r = 0; r < nu; ++r)
      for (int k = 0; k < ny; ++k) {
        const bool set = r < M.rows() && k < M.cols();
        auto* item = new QTableWidgetItem(set ? QString::number(M(r, k), 'g', 12) : QStringLiteral("0"));
        if (!set) item->setForeground(Qt::gray);
        pid_table_->setItem(r, g * ny + k, item);
      }
  }
  syncing_ = false;
}

void SimulateView::pidEdited(int row, int column) {
  if (syncing_) return;
  const ModelSpec& spec = doc_->spec();
  const int nu = static_cast<int>(spec.plant.inputs.size()), ny = static_cast<int>(spec.plant.outputs.size());
  if (ny == 0 || row < 0 || row >= nu) return;
  const int g = column / ny, k = column % ny;
  bool ok = false;
  const double v = pid_table_->item(row, column)->text().trimmed().toDouble(&ok);
  if (!ok || !std::isfinite(v)) {
    emit message(tr("PID gain: \"%1\" is not a number").arg(pid_table_->item(row, column)->text()));
    refreshController();
    return;
  }
  const char* names[3] = {"Kp", "Ki", "Kd"};
  QString error;
  const bool done = doc_->edit(
      tr("Change %1(%2, %3)").arg(QLatin1String(names[g]), qs(spec.plant.inputs[row]), qs(spec.plant.outputs[k])),
      [&](ModelSpec& s) {
        Eigen::MatrixXd& M = g == 0 ? s.controller.kp : g == 1 ? s.controller.ki : s.controller.kd;
        if (M.rows() != nu || M.cols() != ny) {  // empty (no such action) or stale size: zeros, keeping what fits
          Eigen::MatrixXd R = Eigen::MatrixXd::Zero(nu, ny);
          const Eigen::Index rr = std::min<Eigen::Index>(M.rows(), nu), cc = std::min<Eigen::Index>(M.cols(), ny);
          R.topLeftCorner(rr, cc) = M.topLeftCorner(rr, cc);
          M = R;
        }
        M(row, k) = v;
      },
      &error);
  if (!done) {
    emit message(tr("PID gain: %1").arg(error));
    refreshController();
  }
}

void SimulateView::browseControllerFile() {
  const QString modelDir = doc_->filePath().isEmpty() ? QDir::currentPath() : QFileInfo(doc_->filePath()).absolutePath();
  const QString f = QFileDialog::getOpenFileName(this, tr("Controller"), modelDir, tr("MAT files (*.mat);;All files (*)"));
  if (f.isEmpty()) return;
  QString stored = f;
  if (!doc_->filePath().isEmpty()) {
    const QString rel = QDir(modelDir).relativeFilePath(f);
    if (!rel.startsWith(QLatin1String(".."))) stored = rel;
  }
  file_edit_->setText(stored);
  const std::string v = ss(stored);
  writeStudy(
      [&](StudySpec& s) {
        s.controller_file = v;
        s.controller = "file";
      },
      tr("Change the controller file"));
}

void SimulateView::weightsEdited(bool q) {
  QLineEdit* e = q ? q_weights_ : r_weights_;
  std::vector<double> w;
  if (!parseNumbers(e->text(), &w) || std::any_of(w.begin(), w.end(), [](double x) { return x < 0; })) {
    emit message(tr("%1 weights: expected non-negative numbers separated by commas").arg(q ? "Q" : "R"));
    refreshFromDocument();
    return;
  }
  writeStudy(
      [&](StudySpec& s) { (q ? s.q_weights : s.r_weights) = w; },
      q ? tr("Change the LQR state weights") : tr("Change the LQR input weights"));
}

// a number field of the solver section: a value that is not a number of the field's kind is
// refused here, one the model file's checks refuse (a step longer than the run with alf) by
// writeSolver; both say why, once, and the field shows the model's value again
void SimulateView::solverNumberEdited(const NumberRule& r) {
  const QString text = r.edit->text().trimmed();
  std::optional<double> value;
  if (!text.isEmpty() || !r.empty_allowed) {
    bool ok = false;
    const double v = text.toDouble(&ok);
    const bool fits = ok && std::isfinite(v) &&
                      (r.kind == NumberRule::Positive      ? v > 0
                       : r.kind == NumberRule::NonNegative ? v >= 0
                                                           : v >= 1 && v <= 1e9 && v == std::floor(v));
    if (!fits) {
      const auto* label = qobject_cast<QLabel*>(solver_form_->labelForField(r.edit));  // (its row's label)
      emit message(tr("%1: expected %2, got \"%3\"").arg(label ? label->text() : r.edit->objectName(), r.expected, text));
      refreshFromDocument();
      return;
    }
    value = v;
  }
  writeSolver([&](SolverSpec& s) { r.write(s, value); }, r.undo_text);
}

// ---------------------------------------------------------------------------
// running

bool SimulateView::isRunning() const { return worker_->isRunning(); }

void SimulateView::setRunning(bool running) {
  run_button_->setEnabled(!running);
  cancel_button_->setEnabled(running);
  save_results_->setEnabled(!running && result_ != nullptr);
  save_plot_->setEnabled(!running);
  if (stale_label_) updateStaleness();
  emit runningChanged(running);
}

void SimulateView::run() {
  if (worker_->isRunning()) return;
  const std::shared_ptr<const Model> m = doc_->model();
  if (!m) {
    status_ = tr("Cannot run: the model does not compile: %1").arg(doc_->errorText());
    status_label_->setText(status_);
    emit message(status_);
    return;
  }
  result_.reset();
  result_model_ = m;
  plant_inputs_ = m->plant_inputs;
  QStringList in, inUnits, out, outUnits;
  for (int k : m->plant_inputs) {
    in << qs(m->actuators[k].name);
    inUnits << qs(m->actuators[k].unit);
  }
  for (int k : m->plant_outputs) {
    out << qs(m->sensors[k].name);
    outUnits << qs(m->sensors[k].unit);
  }
  plots_->reset(in, inUnits, out, outUnits, m->spec.solver.t_end);
  if (!live_limit_) {
    final_plot_points_ = plots_->maxPlotPoints();
    live_limit_ = true;
  }
  plots_->setMaxPlotPoints(std::min(kLivePlotPoints, final_plot_points_));
  progress_->setValue(0);
  if (!worker_->start(m, doc_->spec(), ss(doc_->filePath()))) return;
  status_ = tr("running: setting up the controller…");
  status_label_->setText(status_);
  setRunning(true);
  emit runStarted();
}

void SimulateView::cancel() {
  if (!worker_->isRunning()) return;
  worker_->cancel();
  status_ = tr("cancelling…");
  status_label_->setText(status_);
}

void SimulateView::onSamples(const SampleBatch& batch) {
  if (discard_run_) return;
  const Eigen::Index nin = static_cast<Eigen::Index>(plant_inputs_.size());
  Eigen::VectorXd u(nin);
  for (const Snapshot& s : batch) {
    for (Eigen::Index k = 0; k < nin; ++k) {
      const int c = plant_inputs_[k];
      u[k] = c < s.u.size() ? s.u[c] : std::nan("");
    }
    plots_->appendSample(s.t, u, s.y);
  }
}

void SimulateView::onProgress(double t, double tEnd) {
  if (discard_run_) return;
  if (tEnd > 0) progress_->setValue(static_cast<int>(std::clamp(1000.0 * t / tEnd, 0.0, 1000.0)));
  if (!worker_->cancelRequested()) {
    status_ = tr("running: t = %1 s of %2 s").arg(simNumber(t, 4), simNumber(tEnd));
    status_label_->setText(status_);
  }
}

void SimulateView::restorePlotLimit() {
  if (!live_limit_) return;
  live_limit_ = false;
  plots_->reset({}, {}, {}, {}, 1.0);  // empty first, so that the limit change redraws nothing
  plots_->setMaxPlotPoints(final_plot_points_);
}

void SimulateView::onFinished(std::shared_ptr<const SimulationResult> r) {
  if (discard_run_) {
    discard_run_ = false;
    restorePlotLimit();
    plots_->reset({}, {}, {}, {}, 1.0);
    setRunning(false);
    emit message(tr("Simulation of the previous model cancelled"));
    return;
  }
  result_ = r;
  restorePlotLimit();
  plots_->setResult(*r, plant_inputs_);
  signal_plot_->setResult(r);
  const int N = r->samples();
  const double tLast = N ? r->t.back() : 0.0;
  QString head;
  if (r->completed) {
    head = tr("completed: t = 0 .. %1 s").arg(simNumber(tLast));
    progress_->setValue(1000);
  } else if (r->cancelled) {
    head = tr("cancelled at t = %1 s").arg(simNumber(tLast));
  } else {
    head = tr("failed: %1").arg(qs(r->failure));
  }
  status_ = tr("%1; %2 samples, %3 steps (%4), wall time %5 s; controller: %6")
                .arg(head)
                .arg(N)
                .arg(r->stats.steps)
                .arg(qs(r->stats.integrator_choice.empty() ? r->stats.integrator : r->stats.integrator_choice))
                .arg(simNumber(worker_->wallTime(), 3))
                .arg(qs(r->controller.empty() ? worker_->controllerSource().toStdString() : r->controller));
  // the job's notes and warnings, in codyna simulate's words
  for (const QString& n : worker_->notes())
    status_ += n.startsWith(QLatin1String("warning: ")) || n.startsWith(QLatin1String("saturation: ")) ? QStringLiteral("; ") + n
                                                                                                      : tr("; note: %1").arg(n);
  status_label_->setText(status_);
  setRunning(false);
  emit message(tr("Simulation %1").arg(status_));
  emit runFinished(r);
}

void SimulateView::onFailed(const QString& why) {
  result_.reset();
  if (discard_run_) {
    discard_run_ = false;
    restorePlotLimit();
    setRunning(false);
    return;
  }
  restorePlotLimit();
  status_ = tr("failed: %1").arg(why);
  status_label_->setText(status_);
  setRunning(false);
  emit message(tr("Simulation %1").arg(status_));
  emit runFinished(nullptr);
}

QString SimulateView::statusText() const { return status_; }

// ---------------------------------------------------------------------------
// saving

bool SimulateView::saveResults(const QString& path, QString* error) {
  auto fail = [&](const QString& why) {
    if (error) *error = why;
    emit message(tr("Save results: %1").arg(why));
    return false;
  };
  if (!result_) return fail(tr("no results to save (run a simulation first)"));
  const QString suffix = QFileInfo(path).suffix().toLower();
  try {
    if (suffix == QLatin1String("h5") || suffix == QLatin1String("hdf5"))
      study_write_results_hdf5(*result_, ss(path));
    else if (suffix == QLatin1String("csv"))
      study_write_results_csv(*result_, ss(path));
    else
      return fail(tr("%1: choose .h5 (HDF5) or .csv").arg(path));
  } catch (const std::exception& e) {
    return fail(qs(e.what()));
  }
  emit message(tr("Wrote %1").arg(path));
  return true;
}

bool SimulateView::savePlot(const QString& path, QString* error) {
  QString why;
  if (!plots_->saveImage(path, &why)) {
    if (error) *error = why;
    emit message(tr("Save plot: %1").arg(why));
    return false;
  }
  emit message(tr("Wrote %1").arg(path));
  return true;
}

void SimulateView::saveResultsDialog() {
  const QString dir = doc_->filePath().isEmpty() ? QDir::currentPath() : QFileInfo(doc_->filePath()).absolutePath();
  QString selected;
  const QString path = QFileDialog::getSaveFileName(this, tr("Save results"),
                                                    QDir(dir).filePath(qs(doc_->spec().name) + QStringLiteral(".h5")),
                                                    tr("HDF5 (*.h5 *.hdf5);;CSV (*.csv)"), &selected);
  if (path.isEmpty()) return;
  saveResults(path);
}

void SimulateView::savePlotDialog() {
  const QString dir = doc_->filePath().isEmpty() ? QDir::currentPath() : QFileInfo(doc_->filePath()).absolutePath();
  const QString path = QFileDialog::getSaveFileName(this, tr("Save plot"),
                                                    QDir(dir).filePath(qs(doc_->spec().name) + QStringLiteral(".png")),
                                                    tr("PNG image (*.png);;SVG image (*.svg)"));
  if (path.isEmpty()) return;
  savePlot(path);
}

}  // namespace codyna::gui
