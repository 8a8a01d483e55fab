#include "gui/linearize_view.hpp"
#include "study/files.hpp"
#include "study/jobs.hpp"
#include "study/tools.hpp"

#include <QComboBox>
#include <QFontDatabase>
#include <QPlainTextEdit>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QItemSelectionModel>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QScrollArea>
#include <QStyle>
#include <QSignalBlocker>
#include <QSplitter>
#include <QTabWidget>
#include <QTableView>
#include <QTableWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "gui/document.hpp"
#include "gui/matrix_models.hpp"
#include "gui/matrix_view.hpp"
#include "gui/pole_map.hpp"
#include "gui/study_widgets.hpp"

namespace codyna::gui {

namespace {

// merge keys of the spin boxes (consecutive steps of one spin box are one undo step)
constexpr int kMergeOpTime = 0x4c5a01;
constexpr int kMergeTs = 0x4c5a02;
constexpr int kMergeSet = 0x4c5a03;      // values stepped in the coordinates-set table
constexpr int kMergeTargets = 0x4c5a04;  // and in the output targets

QStringList toQStringList(const std::vector<std::string>& v) {
  QStringList l;
  l.reserve(static_cast<qsizetype>(v.size()));
  for (const auto& s : v) l << qs(s);
  return l;
}

QString num(double x) { return QString::number(x, 'g', 6); }

// a spin box that keeps what the study says (a QDoubleSpinBox rounds its value to its decimals:
// with four, a lateral acceleration of 3.92266 became 3.9227 and a yaw rate of 0.00004 became 0,
// written back to the study at the next edit of the steady motion) and shows it without trailing
// zeros ("25 m/s", "3.92266")
class ExactSpinBox : public QDoubleSpinBox {
 public:
  explicit ExactSpinBox(QWidget* parent) : QDoubleSpinBox(parent) { setDecimals(12); }
  QString textFromValue(double v) const override {
    QString t = locale().toString(v, 'g', 15);
    if (t.contains(QLatin1Char('e'), Qt::CaseInsensitive)) t = locale().toString(v, 'f', decimals());
    if (t.contains(locale().decimalPoint())) {  // no trailing zeros, no lone decimal point
      while (t.endsWith(QLatin1Char('0'))) t.chop(1);
      if (t.endsWith(locale().decimalPoint())) t.chop(locale().decimalPoint().size());
    }
    t.remove(locale().groupSeparator());
    return t;
  }
};

}  // namespace

namespace {
// what a linearization depends on: the spec without where and how its export is written (a new
// export name or folder does not make A, B, C, D out of date)
std::string linearization_key(const ModelSpec& spec, const QString& file) {
  ModelSpec s = spec;
  s.analysis.export_name.clear();
  s.analysis.export_dir.clear();
  s.analysis.mat_version = "5";
  return file.toStdString() + "\n" + study_model_json(s).dump();  // the file: relative paths, the export's header
}
}  // namespace

LinearizeView::LinearizeView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  qRegisterMetaType<Eigen::VectorXcd>("Eigen::VectorXcd");
  qRegisterMetaType<std::complex<double>>("std::complex<double>");
  buildUi();
  connect(doc_, &Document::specChanged, this, &LinearizeView::refreshFromDocument);
  connect(doc_, &Document::replaced, this, &LinearizeView::clearResult);
  connect(doc_, &Document::modelChanged, this, [this] {
    refreshIndependent();
    refreshSteadyState();
    updateStaleness();
  });
  refreshFromDocument();
  refreshIndependent();
  updateStaleness();
}

LinearizeView::~LinearizeView() = default;

void LinearizeView::buildUi() {
  // ---- study settings
  auto* settings = new QGroupBox(tr("Linearization"), this);
  auto* form = new QFormLayout(settings);

  op_combo_ = new QComboBox(settings);
  op_combo_->addItem(tr("initial (the model's initial state)"), QStringLiteral("initial"));
  op_combo_->addItem(tr("equilibrium (static, at rest)"), QStringLiteral("equilibrium"));
  op_combo_->addItem(tr("trim (inputs that hold the initial configuration)"), QStringLiteral("trim"));
  op_combo_->addItem(tr("steady (a motion: speed and turn)"), QStringLiteral("steady"));
  op_combo_->addItem(tr("time=T (state of an open-loop run at T)"), QStringLiteral("time"));
  op_combo_->setToolTip(tr("Where A, B, C, D are taken: the model's initial state, a static equilibrium (at rest, "
                           "accelerations zero), a trim (the inputs that hold the initial configuration) or the "
                           "state of an open-loop run at time T"));
  op_time_ = new QDoubleSpinBox(settings);
  op_time_->setToolTip(tr("time=T: the run's end time T in s (open loop, actuators at u0)"));
  op_time_->setRange(0.0, 1e6);
  op_time_->setDecimals(4);
  op_time_->setSingleStep(0.1);
  op_time_->setSuffix(QStringLiteral(" s"));
  op_time_->setKeyboardTracking(false);
  op_time_->setPrefix(QStringLiteral("T = "));
  auto* op_row = new QHBoxLayout;
  op_row->addWidget(op_combo_, 1);
  op_row->addWidget(op_time_);
  form->addRow(tr("Operating point"), op_row);

  method_combo_ = new QComboBox(settings);
  method_combo_->addItem(tr("exact (analytic derivatives)"), QStringLiteral("exact"));
  method_combo_->addItem(tr("fd-forward (forward differences)"), QStringLiteral("fd-forward"));
  method_combo_->addItem(tr("fd-central (central differences)"), QStringLiteral("fd-central"));
  method_combo_->setToolTip(tr("How the Jacobians are computed: exact analytic derivatives of the recursive "
                               "algorithms, or forward/central finite differences (a check)"));
  form->addRow(tr("Jacobians"), method_combo_);

  ts_spin_ = new QDoubleSpinBox(settings);
  ts_spin_->setRange(0.0, 1e3);
  ts_spin_->setDecimals(6);
  ts_spin_->setSingleStep(0.001);
  ts_spin_->setSpecialValueText(tr("continuous"));
  ts_spin_->setSuffix(QStringLiteral(" s"));
  ts_spin_->setKeyboardTracking(false);
  ts_spin_->setToolTip(tr("Sample time of an exact zero-order-hold discrete model; 0 = continuous"));
  form->addRow(tr("Sample time Ts"), ts_spin_);

  mat_combo_ = new QComboBox(settings);
  mat_combo_->addItem(tr("MAT v5 (MATLAB, Octave, SciPy)"), QStringLiteral("5"));
  mat_combo_->addItem(tr("MAT v7.3 (HDF5)"), QStringLiteral("7.3"));
  mat_combo_->setToolTip(tr("Format of NAME.mat: v5 loads everywhere (MATLAB, GNU Octave, SciPy); v7.3 is HDF5 "
                            "(Octave reads its matrices, not its name lists)"));
  form->addRow(tr("MAT version"), mat_combo_);

  export_dir_ = new QLineEdit(settings);
  export_dir_->setPlaceholderText(tr("asked at export"));
  export_dir_->setToolTip(tr("Folder of NAME.mat + NAME.m; a relative path is relative to the model file"));
  export_browse_ = new QPushButton(tr("…"), settings);
  export_browse_->setToolTip(tr("Choose the export folder"));
  auto* dir_row = new QHBoxLayout;
  dir_row->addWidget(export_dir_, 1);
  dir_row->addWidget(export_browse_);
  form->addRow(tr("Export folder"), dir_row);

  export_name_ = new QLineEdit(settings);
  export_name_->setToolTip(tr("Plant name (a MATLAB identifier); empty = the model name"));
  form->addRow(tr("Plant name"), export_name_);

  independent_box_ = new QGroupBox(tr("Independent coordinates"), this);
  independent_box_->setToolTip(tr("Closed loops: the coordinates kept as states; none checked = automatic choice"));
  auto* ind_layout = new QVBoxLayout(independent_box_);
  independent_ = new QListWidget(independent_box_);
  independent_->setMaximumHeight(120);
  independent_->setToolTip(independent_box_->toolTip());
  ind_layout->addWidget(independent_);

  // the steady-state search (operspec): what an equilibrium or a trim holds, solves and reaches
  steady_box_ = new QGroupBox(tr("Steady-state search (equilibrium, trim, steady)"), this);
  auto* steady = new QFormLayout(steady_box_);
  steady->setRowWrapPolicy(QFormLayout::WrapAllRows);
  set_table_ = new NameValueTable(tr("Coordinate"), tr("Value (m, rad, /s)"), steady_box_);
  set_table_->setToolTip(tr("Coordinates set in the initial state and held exactly by the equilibrium or trim "
                            "(positions by name, rates as NAME_dot); the loops are closed around them"));
  steady->addRow(tr("Coordinates set (held)"), set_table_);
  free_inputs_ = new QListWidget(steady_box_);
  free_inputs_->setMaximumHeight(70);
  free_inputs_->setToolTip(tr("Plant/In inputs the steady state solves for, within their limits "
                              "(none checked: a trim solves all of Plant/In, an equilibrium none)"));
  steady->addRow(tr("Inputs solved for (Plant/In)"), free_inputs_);
  targets_ = new NameValueTable(tr("Plant/Out"), tr("Target"), steady_box_);
  targets_->setToolTip(tr("Values the Plant/Out outputs must reach at the steady state"));
  steady->addRow(tr("Output targets"), targets_);
  trim_free_ = new QListWidget(steady_box_);
  trim_free_->setMaximumHeight(70);
  trim_free_->setToolTip(tr("Trim only: coordinates the trim solves instead of holding them at the initial state"));
  steady->addRow(tr("Coordinates a trim solves"), trim_free_);
  // operating point steady: the motion held (a car straight or turning, a rolling disc)
  steady_speed_ = new ExactSpinBox(steady_box_);
  steady_speed_->setRange(-1e4, 1e4);
  steady_speed_->setSuffix(QStringLiteral(" m/s"));
  steady_speed_->setSpecialValueText(tr("as at the start"));
  steady_speed_->setKeyboardTracking(false);
  steady_speed_->setToolTip(tr("Steady motion: the forward speed of the steady body's centre of mass (0 = as at the start)"));
  steady->addRow(tr("Steady motion: speed"), steady_speed_);
  steady_turn_ = new QComboBox(steady_box_);
  steady_turn_->addItem(tr("straight"), QStringLiteral("straight"));
  steady_turn_->addItem(tr("yaw rate (rad/s)"), QStringLiteral("yaw_rate"));
  steady_turn_->addItem(tr("path radius (m)"), QStringLiteral("radius"));
  steady_turn_->addItem(tr("lateral acceleration (m/s^2)"), QStringLiteral("lateral_acceleration"));
  steady_turn_->setToolTip(tr("Steady motion: straight, or a turn given by its yaw rate, path radius or lateral "
                              "acceleration (> 0 turns left)"));
  steady_turn_value_ = new ExactSpinBox(steady_box_);
  steady_turn_value_->setRange(-1e6, 1e6);
  steady_turn_value_->setKeyboardTracking(false);
  steady_turn_value_->setToolTip(tr("The turn's yaw rate, radius or lateral acceleration"));
  auto* turn_row = new QHBoxLayout;
  turn_row->addWidget(steady_turn_, 1);
  turn_row->addWidget(steady_turn_value_);
  steady->addRow(tr("Steady motion: turn"), turn_row);

  linearize_button_ = new QPushButton(tr("Linearize"), this);
  linearize_button_->setDefault(true);
  linearize_button_->setToolTip(tr("Find the operating point and compute A, B, C, D there (Ctrl+L)"));
  export_button_ = new QPushButton(tr("Export…"), this);
  export_button_->setToolTip(tr("Write NAME.mat + NAME.m (as codyna linearize --out DIR)"));
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(linearize_button_);
  buttons->addWidget(export_button_);
  buttons->addStretch(1);

  // ---- results
  op_label_ = new QLabel(tr("Not linearized yet."), this);
  op_label_->setWordWrap(true);
  op_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  stale_label_ = new QLabel(tr("<b>Out of date:</b> the model or the study changed since these results: linearize again."), this);
  stale_label_->setObjectName("linearizeStale");
  stale_label_->setStyleSheet("QLabel { background: #fff0c0; color: #6a4a00; padding: 3px; }");
  stale_label_->setWordWrap(true);
  stale_label_->setVisible(false);

  tabs_ = new QTabWidget(this);
  const char* names[4] = {"A", "B", "C", "D"};
  for (int k = 0; k < 4; ++k) {
    matrix_models_[k] = new MatrixTableModel(this);
    auto* mv = new MatrixView(QLatin1String(names[k]), tabs_);
    mv->setMatrixModel(matrix_models_[k]);
    matrix_views_[k] = mv;
    matrix_views_[k]->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    matrix_views_[k]->setObjectName(QStringLiteral("matrix_%1").arg(QLatin1String(names[k])));
    tabs_->addTab(matrix_views_[k], QLatin1String(names[k]));
  }
  offsets_ = new QTableWidget(0, 4, tabs_);
  offsets_->setHorizontalHeaderLabels({tr("Vector"), tr("Name"), tr("Value"), tr("Unit")});
  offsets_->verticalHeader()->setVisible(false);
  offsets_->setToolTip(tr("The operating point: x0 (states), u0 (Plant/In), y0 (Plant/Out) and xdot0 (zero at an "
                          "equilibrium); the linear model is in deviations from these"));
  offsets_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  offsets_->horizontalHeader()->setStretchLastSection(true);
  tabs_->addTab(offsets_, tr("Offsets x0, u0, y0"));
  // the handling numbers of a steady motion: their own tab, so that the operating point's text
  // above the matrices stays short enough never to be cut off by the splitter
  handling_ = new QPlainTextEdit(tabs_);
  handling_->setObjectName("handlingText");
  handling_->setReadOnly(true);
  handling_->setLineWrapMode(QPlainTextEdit::NoWrap);
  handling_->setFont(QFontDatabase::systemFont(QFontDatabase::FixedFont));
  handling_->setToolTip(tr("A car's handling numbers at the steady motion, from the linear model's steady-state gains "
                           "from steer (docs/vehicles.md), as codyna linearize prints them"));
  tabs_->addTab(handling_, tr("Handling"));
  tabs_->setTabVisible(tabs_->indexOf(handling_), false);

  mode_model_ = new ModeTableModel(this);
  mode_view_ = new QTableView(this);
  mode_view_->setModel(mode_model_);
  mode_view_->setToolTip(tr("The eigenvalues of A with their natural frequency, damping, time constant or period and "
                            "the states that dominate the mode's shape; select one to animate it in the 3-D view"));
  mode_view_->setSelectionBehavior(QAbstractItemView::SelectRows);
  mode_view_->setSelectionMode(QAbstractItemView::SingleSelection);
  mode_view_->horizontalHeader()->setStretchLastSection(true);
  mode_view_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  pole_map_ = new PoleMap(this);

  auto* modes_split = new QSplitter(Qt::Horizontal, this);
  modes_split->addWidget(mode_view_);
  modes_split->addWidget(pole_map_);
  modes_split->setObjectName("modesSplitter");
  // the pole map as wide as the table: a plot of ~150 px cannot be read
  modes_split->setStretchFactor(0, 1);
  modes_split->setStretchFactor(1, 1);

  hidden_label_ = new QLabel(this);
  hidden_label_->setObjectName("controllabilityLabel");
  hidden_label_->setWordWrap(true);
  hidden_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  hidden_label_->setToolTip(tr("The modes the Plant/In inputs cannot move (A, B) and the Plant/Out outputs cannot see "
                               "(A, C), named by their dominant states, as codyna linearize prints them"));
  auto* results = new QWidget(this);
  auto* res_layout = new QVBoxLayout(results);
  res_layout->setContentsMargins(0, 0, 0, 0);
  res_layout->addWidget(op_label_);
  res_layout->addWidget(stale_label_);
  res_layout->addWidget(tabs_, 1);
  res_layout->addWidget(hidden_label_);

  auto* vsplit = new QSplitter(Qt::Vertical, this);
  vsplit->setObjectName("linearizeSplitter");
  vsplit->addWidget(results);
  vsplit->addWidget(modes_split);
  // the matrices of most plants fit in half the height; the modes and the pole map take the rest
  vsplit->setStretchFactor(0, 1);
  vsplit->setStretchFactor(1, 1);
  vsplit->setSizes({1000, 1000});
  modes_split->setSizes({1000, 1000});

  // the settings keep a narrow column: the matrices, modes and pole map need the room
  auto* left_widget = new QWidget(this);
  auto* left = new QVBoxLayout(left_widget);
  left->setContentsMargins(0, 0, 0, 0);
  left->addWidget(settings);
  left->addWidget(independent_box_);
  left->addWidget(steady_box_);
  left->addLayout(buttons);
  left->addStretch(1);
  auto* left_scroll = new QScrollArea(this);
  left_scroll->setWidget(left_widget);
  left_scroll->setWidgetResizable(true);
  left_scroll->setFrameShape(QFrame::NoFrame);
  left_scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  // a narrow column (long combo entries are elided), the scroll bar beside it
  left_widget->setMaximumWidth(390);
  // at most that wide, and narrower on a small screen (1024 px): the fields shrink, the results keep room
  left_scroll->setMaximumWidth(390 + left_scroll->style()->pixelMetric(QStyle::PM_ScrollBarExtent) + 4);
  left_scroll->setMinimumWidth(300);
  auto* layout = new QHBoxLayout(this);
  layout->addWidget(left_scroll, 0);
  layout->addWidget(vsplit, 1);

  // ---- widgets -> study (each change one undo step)
  connect(op_combo_, &QComboBox::currentIndexChanged, this, [this] { opChanged(); });
  connect(op_time_, &QDoubleSpinBox::valueChanged, this, [this] { opChanged(); });
  connect(steady_speed_, &QDoubleSpinBox::valueChanged, this, [this] { steadyChanged(); });
  connect(steady_turn_, &QComboBox::currentIndexChanged, this, [this] { steadyChanged(); });
  connect(steady_turn_value_, &QDoubleSpinBox::valueChanged, this, [this] { steadyChanged(); });
  connect(method_combo_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (i < 0) return;
    const std::string m = ss(method_combo_->itemData(i).toString());
    writeStudy([&](StudySpec& s) { s.method = m; }, tr("Change the Jacobian method"));
  });
  connect(ts_spin_, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    writeStudy([&](StudySpec& s) { s.discrete = v; }, tr("Change the sample time"), kMergeTs);
  });
  connect(mat_combo_, &QComboBox::currentIndexChanged, this, [this](int i) {
    if (i < 0) return;
    const std::string v = ss(mat_combo_->itemData(i).toString());
    writeStudy([&](StudySpec& s) { s.mat_version = v; }, tr("Change the MAT version"));
  });
  connect(export_dir_, &QLineEdit::editingFinished, this, [this] {
    const std::string v = ss(export_dir_->text().trimmed());
    writeStudy([&](StudySpec& s) { s.export_dir = v; }, tr("Change the export folder"));
  });
  connect(export_name_, &QLineEdit::editingFinished, this, [this] {
    const std::string v = ss(export_name_->text().trimmed());
    writeStudy([&](StudySpec& s) { s.export_name = v; }, tr("Change the plant name"));
  });
  connect(export_browse_, &QPushButton::clicked, this, &LinearizeView::browseExport);
  connect(independent_, &QListWidget::itemChanged, this, &LinearizeView::independentChanged);
  // the steady-state search goes through setStudyChecked: the core refuses what it cannot
  // use (an unknown name, a value the loops cannot hold), the widgets then show the study again
  auto writeChecked = [this](const std::function<void(StudySpec&)>& change, const QString& text, int key = -1) {
    if (syncing_) return;
    StudySpec s = doc_->spec().analysis;
    change(s);
    if (s == doc_->spec().analysis) return;
    QString error;
    if (!doc_->setStudyChecked(s, text, &error, key)) {
      emit message(tr("Refused: %1").arg(error));
      refreshSteadyState();
    }
  };
  connect(set_table_, &NameValueTable::edited, this, [this, writeChecked](bool number) {
    const auto v = set_table_->pairs();
    writeChecked([&](StudySpec& s) { s.set = v; }, tr("Change the coordinates set"), number ? kMergeSet : -1);
  });
  connect(targets_, &NameValueTable::edited, this, [this, writeChecked](bool number) {
    const auto v = targets_->pairs();
    writeChecked([&](StudySpec& s) { s.output_targets = v; }, tr("Change the output targets"), number ? kMergeTargets : -1);
  });
  connect(free_inputs_, &QListWidget::itemChanged, this, [this, writeChecked] {
    const auto v = checkedNames(free_inputs_);
    writeChecked([&](StudySpec& s) { s.free_inputs = v; }, tr("Change the inputs solved for"));
  });
  connect(trim_free_, &QListWidget::itemChanged, this, [this, writeChecked] {
    const auto v = checkedNames(trim_free_);
    writeChecked([&](StudySpec& s) { s.trim_free = v; }, tr("Change the coordinates a trim solves"));
  });

  connect(linearize_button_, &QPushButton::clicked, this, [this] { linearize(); });
  connect(export_button_, &QPushButton::clicked, this, [this] {
    if (export_dir_->text().trimmed().isEmpty()) {
      browseExport();
      if (export_dir_->text().trimmed().isEmpty()) return;  // cancelled
    }
    QString err;
    exportTo(QString(), &err);  // the study's folder (message() reports errors)
  });

  // ---- mode selection, kept in sync between the table and the pole map
  connect(mode_view_->selectionModel(), &QItemSelectionModel::currentRowChanged, this,
          [this] { modeRowChanged(); });
  connect(pole_map_, &PoleMap::modeSelected, this, &LinearizeView::poleClicked);
}

void LinearizeView::writeStudy(const std::function<void(StudySpec&)>& change, const QString& text, int mergeKey) {
  if (syncing_) return;
  StudySpec s = doc_->spec().analysis;
  change(s);
  if (s == doc_->spec().analysis) return;
  doc_->setStudy(s, text, mergeKey);
}

void LinearizeView::opChanged() {
  const QString kind = op_combo_->currentData().toString();
  op_time_->setEnabled(kind == QLatin1String("time"));
  if (kind.isEmpty()) return;
  std::string op = ss(kind);
  int key = -1;
  if (kind == QLatin1String("time")) {
    op = "time=" + ss(QString::number(op_time_->value(), 'g', 15));
    if (doc_->spec().analysis.operating_point.rfind("time=", 0) == 0) key = kMergeOpTime;  // stepping T
  }
  writeStudy([&](StudySpec& s) { s.operating_point = op; }, tr("Change the operating point"), key);
}

void LinearizeView::steadyChanged() {
  if (syncing_) return;
  const double speed = steady_speed_->value();
  const QString turn = steady_turn_->currentData().toString();
  const double value = steady_turn_value_->value();
  steady_turn_value_->setEnabled(turn != QLatin1String("straight"));
  writeStudy(
      [&](StudySpec& s) {
        s.steady.speed = speed != 0.0 ? std::optional<double>(speed) : std::nullopt;
        s.steady.yaw_rate.reset();
        s.steady.radius.reset();
        s.steady.lateral_acceleration.reset();
        if (turn == QLatin1String("yaw_rate")) s.steady.yaw_rate = value;
        if (turn == QLatin1String("radius")) s.steady.radius = value;
        if (turn == QLatin1String("lateral_acceleration")) s.steady.lateral_acceleration = value;
      },
      tr("Change the steady motion"));
}

void LinearizeView::refreshFromDocument() {
  syncing_ = true;
  const StudySpec& s = doc_->spec().analysis;
  {
    const QSignalBlocker b1(op_combo_), b2(op_time_);
    const QString op = qs(s.operating_point);
    if (op.startsWith(QLatin1String("time="))) {
      op_combo_->setCurrentIndex(op_combo_->findData(QStringLiteral("time")));
      bool ok = false;
      const double t = op.mid(5).toDouble(&ok);
      if (ok) op_time_->setValue(t);
    } else {
      op_combo_->setCurrentIndex(op_combo_->findData(op));  // -1 for an unknown word (compile reports it)
    }
    op_time_->setEnabled(op_combo_->currentData().toString() == QLatin1String("time"));
  }
  {
    const QSignalBlocker b(method_combo_);
    method_combo_->setCurrentIndex(method_combo_->findData(qs(s.method)));
  }
  {
    const QSignalBlocker b(ts_spin_);
    ts_spin_->setValue(s.discrete);
  }
  {
    const QSignalBlocker b(mat_combo_);
    mat_combo_->setCurrentIndex(mat_combo_->findData(qs(s.mat_version)));
  }
  {
    const QSignalBlocker b(export_dir_);
    if (export_dir_->text() != qs(s.export_dir)) export_dir_->setText(qs(s.export_dir));
  }
  {
    const QSignalBlocker b(export_name_);
    if (export_name_->text() != qs(s.export_name)) export_name_->setText(qs(s.export_name));
    export_name_->setPlaceholderText(qs(study_matlab_identifier(doc_->spec().name)));
  }
  syncing_ = false;
  refreshIndependent();
  refreshSteadyState();
}

void LinearizeView::refreshSteadyState() {
  const ModelSpec& spec = doc_->spec();
  const StudySpec& s = spec.analysis;
  syncing_ = true;
  // the names offered come from the compiled model (kept while it does not compile)
  if (const std::shared_ptr<const Model> m = doc_->model()) {
    QStringList coords = toQStringList(m->v_names) + toQStringList(m->rate_names);
    set_table_->setChoices(coords);
    setCheckList(trim_free_, toQStringList(m->v_names), s.trim_free);
  } else {
    setCheckList(trim_free_, {}, s.trim_free);
  }
  set_table_->setPairs(s.set);
  // a steady motion may solve any actuator (a drive force that is not a plant input); the others Plant/In
  QStringList offered = toQStringList(spec.plant.inputs);
  if (s.operating_point == "steady")
    for (const ActuatorSpec& a : spec.actuators)
      if (!offered.contains(qs(a.name))) offered << qs(a.name);
  setCheckList(free_inputs_, offered, s.free_inputs);
  targets_->setChoices(toQStringList(spec.plant.outputs));
  targets_->setPairs(s.output_targets);
  const QString op = qs(s.operating_point);
  trim_free_->setEnabled(op == QLatin1String("trim") || !s.trim_free.empty());
  {
    const QSignalBlocker b1(steady_speed_), b2(steady_turn_), b3(steady_turn_value_);
    steady_speed_->setValue(s.steady.speed.value_or(0.0));
    QString turn = QStringLiteral("straight");
    double value = 0.0;
    if (s.steady.yaw_rate) turn = QStringLiteral("yaw_rate"), value = *s.steady.yaw_rate;
    if (s.steady.radius) turn = QStringLiteral("radius"), value = *s.steady.radius;
    if (s.steady.lateral_acceleration) turn = QStringLiteral("lateral_acceleration"), value = *s.steady.lateral_acceleration;
    steady_turn_->setCurrentIndex(steady_turn_->findData(turn));
    steady_turn_value_->setValue(value);
    const bool steady = op == QLatin1String("steady");
    steady_speed_->setEnabled(steady);
    steady_turn_->setEnabled(steady);
    steady_turn_value_->setEnabled(steady && turn != QLatin1String("straight"));
  }
  syncing_ = false;
}

void LinearizeView::refreshIndependent() {
  const std::shared_ptr<const Model> m = doc_->model();
  if (!m) {
    independent_box_->setEnabled(false);
    return;
  }
  independent_box_->setEnabled(true);
  const bool closed = !m->constraints.empty() || m->dof() < m->nv;
  independent_box_->setVisible(closed);
  if (!closed) return;
  independent_box_->setTitle(tr("Independent coordinates (%1 DOF; none checked = automatic)").arg(m->dof()));
  syncing_ = true;
  const QSignalBlocker b(independent_);
  const QStringList names = toQStringList(m->v_names);
  bool same = independent_->count() == names.size();
  for (int i = 0; same && i < names.size(); ++i) same = independent_->item(i)->text() == names[i];
  if (!same) {
    independent_->clear();
    for (const QString& n : names) {
      auto* item = new QListWidgetItem(n, independent_);
      item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable | Qt::ItemIsSelectable);
    }
  }
  const auto& chosen = doc_->spec().analysis.independent;
  for (int i = 0; i < independent_->count(); ++i) {
    const bool on = std::find(chosen.begin(), chosen.end(), ss(independent_->item(i)->text())) != chosen.end();
    independent_->item(i)->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  }
  syncing_ = false;
}

void LinearizeView::independentChanged(QListWidgetItem*) {
  if (syncing_) return;
  std::vector<std::string> names;
  for (int i = 0; i < independent_->count(); ++i)
    if (independent_->item(i)->checkState() == Qt::Checked) names.push_back(ss(independent_->item(i)->text()));
  writeStudy([&](StudySpec& s) { s.independent = names; }, tr("Change the independent coordinates"));
}

void LinearizeView::browseExport() {
  const std::shared_ptr<const Model> m = doc_->model();
  const QString modelDir = doc_->filePath().isEmpty() ? QDir::currentPath() : QFileInfo(doc_->filePath()).absolutePath();
  QString start = export_dir_->text().trimmed();
  if (start.isEmpty()) start = modelDir;
  else if (QDir::isRelativePath(start)) start = QDir(modelDir).absoluteFilePath(start);
  const QString dir = QFileDialog::getExistingDirectory(this, tr("Export folder"), start);
  if (dir.isEmpty()) return;
  // inside the model's folder: stored relative to the model file, so the study moves with it
  QString stored = dir;
  if (!doc_->filePath().isEmpty()) {
    const QString rel = QDir(modelDir).relativeFilePath(dir);
    if (!rel.startsWith(QLatin1String(".."))) stored = rel.isEmpty() ? QStringLiteral(".") : rel;
  }
  export_dir_->setText(stored);
  const std::string v = ss(stored);
  writeStudy([&](StudySpec& s) { s.export_dir = v; }, tr("Change the export folder"));
}

bool LinearizeView::linearize() {
  const std::shared_ptr<const Model> m = doc_->model();
  if (!m) {
    emit message(tr("Linearize: the model does not compile: %1").arg(doc_->errorText()));
    return false;
  }
  try {
    // the job codyna linearize runs (computing only: the export is the Export button's), so the
    // view shows what the command line prints: the modes, controllability and observability, the
    // notes and warnings
    LinearizeRequest request;
    request.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : ss(doc_->filePath());
    LinearizeJob job = study_linearize_job(request, doc_->spec());
    for (const std::string& n : job.notes) emit message(tr("Linearize: %1").arg(qs(n)));
    for (const std::string& w : job.warnings) emit message(tr("Linearize: warning: %1").arg(qs(w)));
    hidden_label_->setText(tr("Controllable from Plant/In: %1\nObservable from Plant/Out: %2")
                               .arg(qs(study_hidden_modes_text(job.uncontrollable)), qs(study_hidden_modes_text(job.unobservable))));
    result_ = std::move(job.linearization);
    result_model_ = m;
    result_key_ = linearization_key(doc_->spec(), doc_->filePath());
    modal_ = std::move(job.modes);
  } catch (const std::exception& e) {
    emit message(tr("Linearize: %1").arg(qs(e.what())));
    updateStaleness();
    return false;
  }
  showResult();
  updateStaleness();
  {
    const LinearSystem& sys = result_->system;
    QString note = tr("Linearized about %1: %2 states, %3 inputs, %4 outputs (%5)")
                       .arg(qs(result_->op.kind))
                       .arg(sys.nx())
                       .arg(sys.nu())
                       .arg(sys.ny())
                       .arg(qs(sys.method));
    emit message(note);
  }
  emit linearized();
  return true;
}

bool LinearizeView::isStale() const {
  return !result_ || !doc_->model() || (result_model_ != doc_->model() && result_key_ != linearization_key(doc_->spec(), doc_->filePath()));
}

void LinearizeView::updateStaleness() {
  const bool stale = result_ && isStale();
  stale_label_->setVisible(stale);
  // the matrices and modes stay readable, greyed, beside the note
  for (QTableView* v : matrix_views_) v->setEnabled(!stale);
  mode_view_->setEnabled(!stale);
}

void LinearizeView::clearResult() {
  const bool had = result_.has_value();
  result_.reset();
  result_model_.reset();
  modal_ = ModalAnalysis{};
  selected_mode_ = -1;
  syncing_ = true;
  const char* names[4] = {"A", "B", "C", "D"};
  for (int k = 0; k < 4; ++k) {
    matrix_models_[k]->clear();
    tabs_->setTabText(k, QLatin1String(names[k]));
  }
  offsets_->setRowCount(0);
  handling_->clear();
  tabs_->setTabVisible(tabs_->indexOf(handling_), false);
  hidden_label_->clear();
  mode_model_->setModes(modal_);
  pole_map_->setModes(modal_);
  syncing_ = false;
  op_label_->setText(tr("Not linearized yet."));
  updateStaleness();
  if (had) emit modeSelected(-1, Eigen::VectorXcd(), std::complex<double>());
}

void LinearizeView::showResult() {
  const StudyLinearization& r = *result_;
  const LinearSystem& s = r.system;
  const QStringList xs = toQStringList(s.state_names), us = toQStringList(s.input_names), ys = toQStringList(s.output_names);
  const QStringList xu = toQStringList(s.state_units), uu = toQStringList(s.input_units), yu = toQStringList(s.output_units);
  matrix_models_[0]->setMatrix(s.A, xs, xs, xu, xu);
  matrix_models_[1]->setMatrix(s.B, xs, us, xu, uu);
  matrix_models_[2]->setMatrix(s.C, ys, xs, yu, xu);
  matrix_models_[3]->setMatrix(s.D, ys, us, yu, uu);
  // a state a motion input's realization shifted (X2_dot~) says what it is where its name is shown
  QStringList meanings;
  for (int i = 0; i < s.nx(); ++i) meanings << qs(state_meaning(s, i));
  matrix_models_[0]->setMeanings(meanings, meanings);
  matrix_models_[1]->setMeanings(meanings, {});
  matrix_models_[2]->setMeanings({}, meanings);
  tabs_->setTabText(0, QStringLiteral("A (%1 x %2)").arg(s.A.rows()).arg(s.A.cols()));
  tabs_->setTabText(1, QStringLiteral("B (%1 x %2)").arg(s.B.rows()).arg(s.B.cols()));
  tabs_->setTabText(2, QStringLiteral("C (%1 x %2)").arg(s.C.rows()).arg(s.C.cols()));
  tabs_->setTabText(3, QStringLiteral("D (%1 x %2)").arg(s.D.rows()).arg(s.D.cols()));

  // offsets
  offsets_->setRowCount(0);
  auto add = [this](const QString& vec, const std::vector<std::string>& names, const std::vector<std::string>& units,
                    const Eigen::VectorXd& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      const int row = offsets_->rowCount();
      offsets_->insertRow(row);
      offsets_->setItem(row, 0, new QTableWidgetItem(vec));
      offsets_->setItem(row, 1, new QTableWidgetItem(i < static_cast<Eigen::Index>(names.size()) ? qs(names[i]) : QString::number(i + 1)));
      auto* value = new QTableWidgetItem(QString::number(v[i], 'g', 10));
      value->setToolTip(QString::number(v[i], 'g', 17));
      value->setData(Qt::UserRole, v[i]);
      offsets_->setItem(row, 2, value);
      offsets_->setItem(row, 3, new QTableWidgetItem(i < static_cast<Eigen::Index>(units.size()) ? qs(units[i]) : QString()));
    }
  };
  std::vector<std::string> rate_units;
  for (const auto& u : s.state_units) rate_units.push_back(rate_unit(u));
  add(QStringLiteral("x0"), s.state_names, s.state_units, s.x0);
  add(QStringLiteral("u0"), s.input_names, s.input_units, s.u0);
  add(QStringLiteral("y0"), s.output_names, s.output_units, s.y0);
  add(QStringLiteral("xdot0"), s.state_names, rate_units, s.xdot0);
  offsets_->resizeColumnsToContents();

  // operating point and provenance
  QString text = tr("<b>Operating point</b> %1").arg(qs(r.op.kind).toHtmlEscaped());
  if (r.op.kind == "equilibrium" || r.op.kind == "trim" || r.op.kind == "steady")
    text += tr(" (residual %1, %2 iterations)").arg(num(r.op.residual)).arg(r.op.iterations);
  if (r.op.motion && result_model_)
    text += tr("<br><b>Motion</b> %1").arg(qs(study_motion_text(*result_model_, r.op)).toHtmlEscaped());
  if (r.lin.about_motion)
    text += tr("<br>Linearized about the motion (the state's deviation from the pose that moves with it)");
  if (r.op.kind.rfind("time=", 0) == 0) text += tr(" (t = %1 s)").arg(num(r.op.t));
  text += tr(" &nbsp; <b>Jacobians</b> %1").arg(qs(s.method));
  if (r.lin.fd_error > 0) text += tr(" (max relative difference from exact %1)").arg(num(r.lin.fd_error));
  text += s.Ts > 0 ? tr(" &nbsp; <b>discrete</b>, Ts = %1 s (zero-order hold)").arg(num(s.Ts))
                   : tr(" &nbsp; <b>continuous</b>");
  text += tr(" &nbsp; %1 states, %2 inputs, %3 outputs").arg(s.nx()).arg(s.nu()).arg(s.ny());
  if (!r.lin.partition.dependent.empty() && result_model_) {
    QStringList ind;
    for (int i : r.lin.partition.independent) ind << qs(result_model_->v_names[i]);
    text += tr("<br><b>Independent coordinates</b> %1").arg(ind.join(QStringLiteral(", ")).toHtmlEscaped());
  }
  if (r.handling) {
    text += tr("<br><b>Handling</b> understeer gradient %1 deg/g, yaw-rate gain %2 1/s (all in the Handling tab)")
                .arg(num(r.handling->understeer_gradient_deg_per_g))
                .arg(num(r.handling->yaw_rate_gain));
    handling_->setPlainText(qs(study_handling_text(*r.handling)));
  } else {
    handling_->clear();
  }
  tabs_->setTabVisible(tabs_->indexOf(handling_), r.handling.has_value());
  op_label_->setText(text);

  // modes
  selected_mode_ = -1;
  syncing_ = true;
  mode_model_->setModes(modal_);
  pole_map_->setModes(modal_);
  syncing_ = false;
}

void LinearizeView::modeRowChanged() {
  if (syncing_) return;
  const QModelIndex cur = mode_view_->selectionModel()->currentIndex();
  if (!cur.isValid()) return;
  bool ok = false;
  const int index = mode_model_->index(cur.row(), ModeTableModel::Eigenvalue).data(Qt::UserRole).toInt(&ok);
  if (!ok) return;
  pole_map_->selectMode(index);
  announceMode(index);
}

void LinearizeView::poleClicked(int index) {
  if (syncing_) return;
  selectMode(index);
}

void LinearizeView::selectMode(int index) {
  if (index < 0 || index >= static_cast<int>(modal_.modes.size())) {
    syncing_ = true;
    mode_view_->clearSelection();
    pole_map_->selectMode(-1);
    selected_mode_ = -1;
    syncing_ = false;
    return;
  }
  syncing_ = true;
  for (int row = 0; row < mode_model_->rowCount(); ++row) {
    const QModelIndex i = mode_model_->index(row, ModeTableModel::Eigenvalue);
    if (i.data(Qt::UserRole).toInt() == index) {
      mode_view_->selectionModel()->setCurrentIndex(
          i, QItemSelectionModel::ClearAndSelect | QItemSelectionModel::Rows);
      mode_view_->scrollTo(i);
      break;
    }
  }
  pole_map_->selectMode(index);
  syncing_ = false;
  announceMode(index);
}

void LinearizeView::announceMode(int index) {
  if (index < 0 || index >= static_cast<int>(modal_.modes.size())) return;
  selected_mode_ = index;
  const Mode& m = modal_.modes[index];
  emit modeSelected(index, m.shape, m.s);
}

bool LinearizeView::exportTo(const QString& dir, QString* error) {
  auto fail = [&](const QString& why) {
    if (error) *error = why;
    emit message(tr("Export: %1").arg(why));
    return false;
  };
  if (isStale() && !linearize()) return fail(tr("the model could not be linearized"));
  try {
    // the document's model now: the same linearization, with the export name and folder as they are now
    const Model& now = doc_->model() && result_model_ != doc_->model() ? *doc_->model() : *result_model_;
    const ExportPaths p = study_export_linearization(now, result_->system, ss(dir));  // relative: to the model file
    const QString mat = qs(p.mat_file), m = qs(p.m_file);
    emit exported(mat, m);
    return true;
  } catch (const std::exception& e) {
    return fail(qs(e.what()));
  }
}

}  // namespace codyna::gui
