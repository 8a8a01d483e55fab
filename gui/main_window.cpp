#include "gui/main_window.hpp"

#include "gui/issues_panel.hpp"

#include <QAction>
#include <QApplication>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDesktopServices>
#include <QIcon>
#include <QUrl>
#include <Eigen/Core>
#include <QDockWidget>
#include <QFileDialog>
#include <QFile>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSettings>
#include <QSlider>
#include <QSplitter>
#include <QStatusBar>
#include <QTabWidget>
#include <QToolBar>
#include <QTreeView>
#include <QVBoxLayout>
#include <cmath>
#include <nlohmann/json.hpp>

#include "study/files.hpp"
#include "study/import.hpp"

#include "gui/autosave.hpp"
#include "gui/control_view.hpp"
#include "gui/sweep_view.hpp"
#include "gui/kc_view.hpp"
#include "gui/maneuver_view.hpp"
#include "gui/tire_view.hpp"
#include "gui/linearize_view.hpp"
#include "gui/plant_panel.hpp"
#include "gui/property_editor.hpp"
#include "gui/result_plots.hpp"
#include "gui/simulate_view.hpp"
#include "gui/view3d.hpp"
#include "gui/wheel_guard.hpp"
#include "study/maneuver_job.hpp"
#include "study/tools.hpp"
#include "study/workflow.hpp"

// the icon lives in codyna_gui, a static library: its resources must be registered by name
static void init_codyna_resources() { Q_INIT_RESOURCE(codyna); }

namespace codyna::gui {

namespace {
constexpr int kMaxRecent = 8;
constexpr int kFrameMs = 33;
const char* kFilter = "codyna models (*.json);;All files (*)";
}  // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), doc_(new Document(this)) {
  WheelGuard::install();  // before any field is polished
  init_codyna_resources();
  setWindowIcon(QIcon(QStringLiteral(":/codyna/codyna.svg")));
  setObjectName("codynaMainWindow");
  resize(1600, 1000);

  // centre: 3-D view with playback, and below it the Linearize / Simulate views
  view_ = new View3D(this);
  slider_ = new QSlider(Qt::Horizontal, this);
  slider_->setObjectName("playbackSlider");
  slider_->setRange(0, 0);
  slider_->setEnabled(false);
  play_ = new QPushButton(tr("Play"), this);
  play_->setObjectName("playButton");
  play_->setEnabled(false);
  speed_ = new QComboBox(this);
  for (double s : {0.1, 0.25, 0.5, 1.0, 2.0, 4.0}) speed_->addItem(QStringLiteral("%1x").arg(s), s);
  speed_->setCurrentIndex(3);
  time_label_ = new QLabel(tr("no result"), this);
  time_label_->setMinimumWidth(120);
  auto* playback = new QHBoxLayout;
  playback->addWidget(play_);
  playback->addWidget(slider_, 1);
  playback->addWidget(time_label_);
  playback->addWidget(new QLabel(tr("speed"), this));
  playback->addWidget(speed_);
  auto* top = new QWidget(this);
  auto* top_lay = new QVBoxLayout(top);
  top_lay->setContentsMargins(0, 0, 0, 0);
  top_lay->addWidget(view_, 1);
  top_lay->addLayout(playback);

  lin_view_ = new LinearizeView(doc_, this);
  sim_view_ = new SimulateView(doc_, this);
  tabs_ = new QTabWidget(this);
  tabs_->addTab(lin_view_, tr("Linearize"));
  tabs_->addTab(sim_view_, tr("Simulate"));
  control_view_ = new ControlView(doc_, this);
  tabs_->addTab(control_view_, tr("Control"));
  tabs_->setTabToolTip(0, tr("Operating point, A, B, C, D, modes; export for MATLAB and GNU Octave"));
  tabs_->setTabToolTip(1, tr("The controller on the nonlinear mechanism: run, plots, results"));
  tabs_->setTabToolTip(2, tr("The linear plant and closed loop: gain K, closed-loop poles, Bode and step responses"));
  sweep_view_ = new SweepView(doc_, this);
  tabs_->addTab(sweep_view_, tr("Sweep"));
  tabs_->setTabToolTip(3, tr("A parameter study: the closed-loop poles and figures of every variant of the model"));
  tire_view_ = new TireView(doc_, this);
  tabs_->addTab(tire_view_, tr("Tire"));
  tabs_->setTabToolTip(4, tr("The tire test rig: Fy, Fx and Mz over the slips at several loads, and combined slip, for a "
                             "tire of the model or a .tir file (codyna tire)"));
  maneuver_view_ = new ManeuverView(doc_, this);
  tabs_->addTab(maneuver_view_, tr("Maneuvers"));
  kc_view_ = new KcView(doc_, this);
  kc_view_->setObjectName("kcView");
  tabs_->addTab(kc_view_, tr("K&&C"));
  tabs_->setTabToolTip(5, tr("Standard handling maneuvers on the car: step steer, sine with dwell, swept sine, double "
                             "lane change, constant radius, constant speed, slowly increasing steer and the fishhook, "
                             "with their metrics (codyna maneuver)"));
  tabs_->setTabToolTip(6, tr("The suspension K&C rig: a corner or an axle held at its body, swept through wheel travel, "
                             "steer, roll and contact-patch loads: camber, toe, kingpin, bump steer, compliance (codyna kc)"));
  auto* centre = new QSplitter(Qt::Vertical, this);
  centre->setObjectName("centreSplitter");
  centre->addWidget(top);
  centre->addWidget(tabs_);
  centre->setStretchFactor(0, 1);
  centre->setStretchFactor(1, 1);
  centre->setSizes({330, 570});  // the analysis views hold tables and plots: the larger share
  setCentralWidget(centre);

  // left: model tree + properties
  tree_model_ = new ModelTreeModel(doc_, this);
  tree_ = new QTreeView(this);
  tree_->setObjectName("modelTree");
  tree_->setModel(tree_model_);
  tree_->setEditTriggers(QAbstractItemView::EditKeyPressed | QAbstractItemView::DoubleClicked);
  tree_->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
  connect(tree_model_, &QAbstractItemModel::modelReset, tree_, &QTreeView::expandAll);
  tree_->setContextMenuPolicy(Qt::CustomContextMenu);
  connect(tree_, &QWidget::customContextMenuRequested, this, &MainWindow::showTreeMenu);
  props_ = new PropertyEditor(doc_, this);
  auto* left = new QSplitter(Qt::Vertical, this);
  left->setObjectName("modelSplitter");
  auto* tree_box = new QWidget(this);
  auto* tree_lay = new QVBoxLayout(tree_box);
  tree_lay->setContentsMargins(0, 0, 0, 0);
  tree_lay->setSpacing(0);
  add_bar_ = new QToolBar(tr("Add"), tree_box);
  add_bar_->setObjectName("addToolbar");
  tree_lay->addWidget(add_bar_);
  tree_lay->addWidget(tree_, 1);
  left->addWidget(tree_box);
  left->addWidget(props_);
  auto* left_dock = new QDockWidget(tr("Model"), this);
  left_dock->setObjectName("modelDock");
  left_dock->setWidget(left);
  addDockWidget(Qt::LeftDockWidgetArea, left_dock);

  // right: the Control Plant/In and Plant/Out panels
  plant_in_ = new PlantPanel(doc_, PlantSide::In, this);
  plant_out_ = new PlantPanel(doc_, PlantSide::Out, this);
  auto* in_dock = new QDockWidget(tr("Control Plant/In"), this);
  in_dock->setObjectName("plantInDock");
  in_dock->setWidget(plant_in_);
  auto* out_dock = new QDockWidget(tr("Plant/Out"), this);
  out_dock->setObjectName("plantOutDock");
  out_dock->setWidget(plant_out_);
  addDockWidget(Qt::RightDockWidgetArea, in_dock);
  addDockWidget(Qt::RightDockWidgetArea, out_dock);

  // bottom: messages
  messages_ = new QPlainTextEdit(this);
  messages_->setObjectName("messages");
  messages_->setReadOnly(true);
  messages_->setMaximumBlockCount(2000);
  auto* msg_dock = new QDockWidget(tr("Messages"), this);
  msg_dock->setObjectName("messageDock");
  msg_dock->setWidget(messages_);
  addDockWidget(Qt::BottomDockWidgetArea, msg_dock);
  // bottom, beside the messages: every problem of the model at once
  issues_ = new IssuesPanel(doc_, this);
  issues_dock_ = new QDockWidget(tr("Issues"), this);
  issues_dock_->setObjectName("issuesDock");
  issues_dock_->setWidget(issues_);
  addDockWidget(Qt::BottomDockWidgetArea, issues_dock_);
  splitDockWidget(msg_dock, issues_dock_, Qt::Horizontal);
  connect(issues_, &IssuesPanel::countChanged, this, [this](int n) {
    issues_dock_->setWindowTitle(n == 0 ? tr("Issues") : tr("Issues (%1)").arg(n));
  });
  resizeDocks({left_dock, in_dock}, {290, 310}, Qt::Horizontal);
  resizeDocks({msg_dock}, {90}, Qt::Vertical);
  connect(issues_, &IssuesPanel::elementChosen, this, [this](ElementId id) { selectElement(id); });
  connect(issues_, &IssuesPanel::otherChosen, this, [this](const QString& path) {
    if (path.startsWith("/plant/inputs")) plant_in_->parentWidget()->raise();
    else if (path.startsWith("/plant/outputs")) plant_out_->parentWidget()->raise();
  });

  buildMenus();
  autosave_ = new Autosave(doc_, this);
  restoreLayout();

  connect(doc_, &Document::fileChanged, this, &MainWindow::updateTitle);
  connect(doc_, &Document::modelChanged, this, &MainWindow::onModelChanged);
  connect(doc_, &Document::replaced, this, [this] {
    // the results on screen belonged to the model that left
    setPlaying(false);
    onResult(nullptr);
    play_t_ = 0;
    time_label_->setText(tr("no result"));
    sim_view_->plots()->setTimeCursor(std::nan(""));
  });
  connect(doc_, &Document::errorChanged, this, [this](const QString& text, const QString& path) {
    if (text.isEmpty()) {
      // fixed: the old error leaves the status bar
      if (statusBar()->currentMessage().startsWith(tr("Error:"))) statusBar()->clearMessage();
      logged_error_.clear();
      return;
    }
    // said, listed in the Issues panel and marked at its fields; the selection stays where the
    // user put it (the next value typed goes where the user is looking). The log has it once while
    // it stays (three bodies added before any joint are one line, not three)
    Q_UNUSED(path);
    if (text == logged_error_) {
      statusBar()->showMessage(tr("Error: %1").arg(text.section('\n', 0, 0)), 15000);
      return;
    }
    logged_error_ = text;
    message(text, true);
  });
  connect(doc_, &Document::specChanged, this, [this] {
    // an accepted change: an error shown for an earlier, refused one is over
    if (doc_->errorText().isEmpty() && statusBar()->currentMessage().startsWith(tr("Error:"))) statusBar()->clearMessage();
    // the tree was reset: keep the property editor's element selected
    if (const auto id = props_->element()) tree_->setCurrentIndex(tree_model_->indexOf(*id));
  });
  connect(tree_->selectionModel(), &QItemSelectionModel::currentChanged, this, [this](const QModelIndex& cur) {
    const auto id = tree_model_->elementAt(cur);
    if (id != props_->element()) props_->setElement(id);
    QString body;
    if (id && id->kind == ElementKind::Body) body = qs(doc_->spec().bodies[id->index].name);
    if (id && id->kind == ElementKind::Joint) body = qs(doc_->spec().joints[id->index].child);
    // a tire selected: the Tire view shows its curves (its wheel is tinted)
    if (id && id->kind == ElementKind::Effect && doc_->spec().effects[id->index].type == EffectType::Tire) {
      tire_view_->showTire(qs(doc_->spec().effects[id->index].name));
      body = qs(doc_->spec().effects[id->index].body_a);
    }
    view_->setHighlight(body);
  });
  connect(tree_model_, &ModelTreeModel::renameFailed, this, [this](const QString& m) { message(m, true); });
  connect(props_, &PropertyEditor::message, this, [this](const QString& m) { message(m, true); });
  connect(view_, &View3D::bodyPicked, this, [this](const QString& name) {
    const int k = find_element(doc_->spec(), ElementKind::Body, ss(name));
    if (k >= 0) selectElement(ElementId{ElementKind::Body, k});
  });
  connect(lin_view_, &LinearizeView::message, this, [this](const QString& m) { message(m); });
  connect(lin_view_, &LinearizeView::exported, this, [this](const QString& mat, const QString& m) {
    const QString text = tr("Exported %1 and %2").arg(mat, m);
    message(text);
    statusBar()->showMessage(text, 15000);
  });
  connect(lin_view_, &LinearizeView::linearized, this, [this] {
    // the 3-D view shows the operating point it was linearized about
    const auto* r = lin_view_->result();
    const auto m = doc_->model();
    if (r && m && r->op.q.size() == m->nq && !isPlaying()) animateMode(-1, {});  // shows r->op.q
  });
  connect(lin_view_, &LinearizeView::modeSelected, this,
          [this](int index, const Eigen::VectorXcd& shape, std::complex<double>) { animateMode(index, shape); });
  connect(sim_view_, &SimulateView::message, this, [this](const QString& m) { message(m); });
  connect(control_view_, &ControlView::message, this, [this](const QString& m) { message(m); });
  connect(sweep_view_, &SweepView::message, this, [this](const QString& m) { message(m); });
  connect(tire_view_, &TireView::message, this, [this](const QString& m) { message(m); });
  connect(maneuver_view_, &ManeuverView::message, this, [this](const QString& m) { message(m); });
  connect(kc_view_, &KcView::message, this, [this](const QString& m) { message(m); });
  connect(props_, &PropertyEditor::varyRequested, this, [this](const QString& pointer) {
    sweep_view_->addField(pointer);
    tabs_->setCurrentWidget(sweep_view_);
  });
  connect(sim_view_, &SimulateView::runFinished, this, &MainWindow::onResult);
  connect(sim_view_, &SimulateView::runStarted, this, [this] {
    animateMode(-1, {});
    // a maneuver's lane and track are not this run's
    view_->setPaths({});
    view_->setFollowBody(-1);
  });
  connect(maneuver_view_, &ManeuverView::finished, this, &MainWindow::onManeuverFinished);

  connect(slider_, &QSlider::valueChanged, this, [this](int k) {
    if (result_ && k >= 0 && k < result_->samples()) setPlaybackTime(result_->t[k]);
  });
  connect(play_, &QPushButton::clicked, this, [this] { setPlaying(!isPlaying()); });
  anim_.setInterval(kFrameMs);
  connect(&anim_, &QTimer::timeout, this, &MainWindow::stepAnimation);

  rebuildRecentMenu();
  updateTitle();
  statusBar()->showMessage(tr("Open a model (File > Open) to begin"));
}

MainWindow::~MainWindow() {
  anim_.stop();
  sim_view_->cancel();
  // The widgets go before the Document they edit: QObject deletes children in the order
  // they were made, and the Document came first; a floating dock closed on the way
  // moves the focus, and a field that loses it applies its text to the Document.
  const QList<QWidget*> widgets = findChildren<QWidget*>(QString(), Qt::FindDirectChildrenOnly);
  for (QWidget* w : widgets) delete w;
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  QAction* a_new = file->addAction(tr("&New"), this, [this] { newModel(); });
  a_new->setShortcut(QKeySequence::New);
  QAction* a_open = file->addAction(tr("&Open..."), this, [this] {
    const QString p = chooseFile(tr("Open model"), QFileInfo(doc_->filePath()).absolutePath(), kFilter, false);
    if (!p.isEmpty()) openFile(p);
  });
  a_open->setShortcut(QKeySequence::Open);
  recent_menu_ = file->addMenu(tr("Open &Recent"));
  QAction* a_save = file->addAction(tr("&Save"), this, [this] { saveFile(); });
  a_save->setShortcut(QKeySequence::Save);
  QAction* a_save_as = file->addAction(tr("Save &As..."), this, [this] {
    const QString p = chooseFile(tr("Save model as"), doc_->filePath(), kFilter, true);
    if (!p.isEmpty()) saveFileAs(p);
  });
  a_open->setToolTip(tr("Open a model file (JSON)"));
  a_save->setToolTip(tr("Save the model to its file"));
  a_save_as->setShortcut(QKeySequence::SaveAs);
  file->addSeparator();
  a_import_ = file->addAction(tr("&Import (MJCF, URDF)..."), this, [this] {
    const QString p = chooseFile(tr("Import model"), QFileInfo(doc_->filePath()).absolutePath(),
                                 tr("MJCF and URDF (*.xml *.mjcf *.urdf);;MJCF (*.xml *.mjcf);;URDF (*.urdf);;All files (*)"),
                                 false);
    if (!p.isEmpty()) importFile(p);
  });
  a_import_->setObjectName("actionImport");
  a_import_->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_I));
  a_import_->setToolTip(tr("Read an MJCF (MuJoCo) or URDF (ROS) model into a new, unsaved model; the report says what "
                           "was not modelled (Ctrl+I)"));
  file->addSeparator();
  // as the Linearize view's Export button: into the study's export folder when it is set (asked only
  // when it is not), under its export name
  QAction* a_export = file->addAction(tr("&Export plant (NAME.m + NAME.mat)..."), this, [this] {
    tabs_->setCurrentWidget(lin_view_);
    lin_view_->exportButton()->click();
  });
  a_export->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_E));
  file->addSeparator();
  QAction* a_quit = file->addAction(tr("&Quit"), this, &QWidget::close);
  a_quit->setShortcut(QKeySequence::Quit);

  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  // Undo and Redo keep their short text (what they would undo is their tooltip and in the status
  // bar): a menu whose width follows the last edit's name moves its items from under the pointer
  QUndoStack* stack = doc_->undoStack();
  QAction* undo = new QAction(tr("&Undo"), this);
  undo->setObjectName("actionUndo");
  undo->setShortcut(QKeySequence::Undo);
  undo->setEnabled(stack->canUndo());
  connect(undo, &QAction::triggered, stack, &QUndoStack::undo);
  connect(stack, &QUndoStack::canUndoChanged, undo, &QAction::setEnabled);
  QAction* redo = new QAction(tr("&Redo"), this);
  redo->setObjectName("actionRedo");
  redo->setShortcut(QKeySequence::Redo);
  redo->setEnabled(stack->canRedo());
  connect(redo, &QAction::triggered, stack, &QUndoStack::redo);
  connect(stack, &QUndoStack::canRedoChanged, redo, &QAction::setEnabled);
  auto undo_tips = [undo, redo, stack] {
    undo->setToolTip(stack->canUndo() ? tr("Undo %1 (Ctrl+Z; inside a field Ctrl+Z undoes its text)").arg(stack->undoText()) : tr("Nothing to undo"));
    undo->setStatusTip(undo->toolTip());
    redo->setToolTip(stack->canRedo() ? tr("Redo %1").arg(stack->redoText()) : tr("Nothing to redo"));
    redo->setStatusTip(redo->toolTip());
  };
  connect(stack, &QUndoStack::indexChanged, this, undo_tips);
  connect(stack, &QUndoStack::cleanChanged, this, undo_tips);
  undo_tips();
  edit->addAction(undo);
  edit->addAction(redo);
  edit->addSeparator();
  QMenu* add = edit->addMenu(tr("&Add"));
  for (ElementKind k : kElementKinds) add->addAction(addElementAction(k));
  edit->addAction(tr("&Duplicate"), this, [this] { duplicateSelected(); })->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_D));
  edit->addAction(tr("Re&name"), this, [this] {
    if (tree_->currentIndex().isValid()) tree_->edit(tree_->currentIndex().siblingAtColumn(0));
  })->setShortcut(QKeySequence(Qt::Key_F2));
  edit->addAction(tr("Re&move"), this, [this] { removeSelected(); })->setShortcut(QKeySequence::Delete);

  QMenu* view = menuBar()->addMenu(tr("&View"));
  view->addAction(tr("&Fit 3-D view"), this, [this] { view_->fitView(); })->setShortcut(QKeySequence(Qt::Key_F));
  view->addAction(tr("&Reset 3-D view"), this, [this] { view_->resetView(); });
  QAction* frames = view->addAction(tr("Show &frames and joint axes"));
  frames->setCheckable(true);
  frames->setChecked(true);
  connect(frames, &QAction::toggled, view_, &View3D::setShowFrames);
  QAction* com = view->addAction(tr("Show &centres of mass"));
  com->setCheckable(true);
  com->setChecked(false);
  com->setToolTip(tr("A dark ball at each body's centre of mass"));
  connect(com, &QAction::toggled, view_, &View3D::setShowCom);
  QAction* tire_forces = view->addAction(tr("Show &tire forces"));
  tire_forces->setObjectName("actionShowTireForces");
  tire_forces->setCheckable(true);
  tire_forces->setChecked(true);
  tire_forces->setToolTip(tr("Each tire's contact force at the state shown: the load and the in-plane force, as arrows "
                             "from the contact point (the legend gives the scale)"));
  connect(tire_forces, &QAction::toggled, view_, &View3D::setShowTireForces);

  view->addSeparator();
  for (QDockWidget* d : findChildren<QDockWidget*>()) view->addAction(d->toggleViewAction());

  // the analysis steps, where users look for them (the views' buttons do the same)
  QMenu* analysis = menuBar()->addMenu(tr("&Analysis"));
  a_linearize_ = analysis->addAction(tr("&Linearize"), this, [this] {
    tabs_->setCurrentWidget(lin_view_);
    lin_view_->linearize();
  });
  a_linearize_->setObjectName("actionLinearize");
  a_linearize_->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_L));
  a_linearize_->setToolTip(tr("Linearize the model about its operating point (Ctrl+L)"));
  analysis->addAction(a_export);
  a_export->setToolTip(tr("Write the linear plant as NAME.m + NAME.mat for MATLAB and GNU Octave (Ctrl+E)"));
  analysis->addSeparator();
  a_run_ = analysis->addAction(tr("&Run simulation"), this, [this] {
    tabs_->setCurrentWidget(sim_view_);
    sim_view_->run();
  });
  a_run_->setObjectName("actionRun");
  a_run_->setShortcut(QKeySequence(Qt::Key_F5));
  a_run_->setToolTip(tr("Simulate the controller on the nonlinear model (F5)"));
  a_cancel_ = analysis->addAction(tr("&Cancel simulation"), this, [this] { sim_view_->cancel(); });
  a_cancel_->setObjectName("actionCancel");
  a_cancel_->setShortcut(QKeySequence(Qt::SHIFT | Qt::Key_F5));
  a_cancel_->setToolTip(tr("Stop the running simulation; its partial result is kept (Shift+F5)"));
  a_cancel_->setEnabled(false);
  connect(sim_view_, &SimulateView::runningChanged, this, [this](bool running) {
    a_run_->setEnabled(!running);
    a_cancel_->setEnabled(running);
  });

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  QAction* a_docs = help->addAction(tr("codyna &documentation"), this, [] {
    QDesktopServices::openUrl(documentationUrl());
  });
  a_docs->setShortcut(QKeySequence::HelpContents);
  help->addAction(tr("&About codyna"), this, [this] {
    QMessageBox::about(this, tr("About codyna"), aboutText());
  });
  help->addAction(tr("About &Qt"), qApp, &QApplication::aboutQt);

  QToolBar* tb = addToolBar(tr("Main"));
  tb->setObjectName("mainToolbar");
  tb->addAction(a_open);
  tb->addAction(a_save);
  tb->addAction(undo);
  tb->addAction(redo);
  tb->addSeparator();
  tb->addAction(a_linearize_);
  tb->addAction(a_export);
  tb->addAction(a_run_);
  tb->addAction(a_cancel_);

  // adding, one click away above the model tree (and one key: Ctrl+Shift+B, J, L, E, U, Y)
  add_bar_->setToolButtonStyle(Qt::ToolButtonTextOnly);
  add_bar_->setIconSize(QSize(12, 12));
  for (ElementKind k : kElementKinds) add_bar_->addAction(addElementAction(k));
}

// One action per kind, shared by the Edit > Add menu, the Add toolbar and the tree's context menu.
QAction* MainWindow::addElementAction(ElementKind k) {
  if (auto it = add_actions_.find(k); it != add_actions_.end()) return it->second;
  static const std::map<ElementKind, std::pair<const char*, Qt::Key>> words = {
      {ElementKind::Body, {QT_TR_NOOP("Body"), Qt::Key_B}},         {ElementKind::Joint, {QT_TR_NOOP("Joint"), Qt::Key_J}},
      {ElementKind::Constraint, {QT_TR_NOOP("Loop closure"), Qt::Key_L}}, {ElementKind::Effect, {QT_TR_NOOP("Effect"), Qt::Key_E}},
      {ElementKind::Actuator, {QT_TR_NOOP("Actuator"), Qt::Key_U}}, {ElementKind::Sensor, {QT_TR_NOOP("Sensor"), Qt::Key_Y}}};
  const auto& [word, key] = words.at(k);
  auto* a = new QAction(tr(word), this);
  a->setObjectName(QStringLiteral("actionAdd:%1").arg(to_string(k)));
  a->setShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | key));
  a->setToolTip(tr("Add a %1 (%2)").arg(to_string(k), a->shortcut().toString(QKeySequence::NativeText)));
  a->setStatusTip(a->toolTip());
  connect(a, &QAction::triggered, this, [this, k] { addElement(k); });
  add_actions_[k] = a;
  return a;
}

QString MainWindow::aboutText() const {
  return tr("<h3>codyna %1</h3>"
            "<p>Multibody dynamics pre/post-processor with a control module: "
            "linearization into A, B, C, D, export to MATLAB and GNU Octave, "
            "closed-loop simulation on the nonlinear mechanism.</p>"
            "<p>Qt %2 (built with %3), Eigen %4.%5.%6</p>"
            "<p>Documentation: <a href=\"%7\">%7</a></p>")
      .arg(QCoreApplication::applicationVersion().isEmpty() ? tr("(development)") : QCoreApplication::applicationVersion(),
           QString::fromLatin1(qVersion()), QStringLiteral(QT_VERSION_STR))
      .arg(EIGEN_WORLD_VERSION)
      .arg(EIGEN_MAJOR_VERSION)
      .arg(EIGEN_MINOR_VERSION)
      .arg(documentationUrl().toString());
}

QUrl MainWindow::documentationUrl() {
  // the installed docs when there are any, else the source tree's (a build run in place)
  for (const QString& d : {QCoreApplication::applicationDirPath() + "/../share/doc/codyna/gui.md",
                           QStringLiteral(CODYNA_SOURCE_DOCS "/gui.md")}) {
    if (QFileInfo::exists(d)) return QUrl::fromLocalFile(QFileInfo(d).absoluteFilePath());
  }
  return QUrl::fromLocalFile(QStringLiteral(CODYNA_SOURCE_DOCS "/gui.md"));
}

int MainWindow::ask(const QString& title, const QString& text, int buttons) {
  if (ask_) return ask_(title, text, buttons);
  return QMessageBox::question(this, title, text, QMessageBox::StandardButtons(buttons));
}

QString MainWindow::chooseFile(const QString& title, const QString& dir, const QString& filter, bool save) {
  if (file_) return file_(title, dir, filter, save);
  return save ? QFileDialog::getSaveFileName(this, title, dir, filter) : QFileDialog::getOpenFileName(this, title, dir, filter);
}

void MainWindow::message(const QString& text, bool error) {
  const QString stamp = QDateTime::currentDateTime().toString("HH:mm:ss");
  messages_->appendPlainText(QStringLiteral("[%1] %2%3").arg(stamp, error ? tr("error: ") : QString(), text));
  statusBar()->showMessage(error ? tr("Error: %1").arg(text.section('\n', 0, 0)) : text.section('\n', 0, 0), 15000);
}

void MainWindow::updateTitle() {
  setWindowTitle(QStringLiteral("%1[*] - codyna").arg(doc_->displayName()));
  setWindowModified(doc_->isModified());
}

bool MainWindow::maybeSave() {
  if (!doc_->isModified()) return true;
  const int b = ask(tr("Unsaved changes"), tr("%1 has unsaved changes. Save them?").arg(doc_->displayName()),
                    QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
  // only Save writes the file: any other answer (the dialog closed, a button it does not know) is a no
  if (b == QMessageBox::Discard) return true;
  if (b != QMessageBox::Save) return false;
  if (doc_->filePath().isEmpty()) {
    const QString p = chooseFile(tr("Save model as"), QString(), kFilter, true);
    return !p.isEmpty() && saveFileAs(p);
  }
  return saveFile();
}

bool MainWindow::openFile(const QString& path) {
  if (!maybeSave()) return false;
  sim_view_->cancel();
  QString error;
  if (!doc_->load(path, &error)) {
    message(tr("Cannot open %1: %2").arg(path, error), true);
    return false;
  }
  addRecent(doc_->filePath());
  result_.reset();
  slider_->setRange(0, 0);
  slider_->setEnabled(false);
  play_->setEnabled(false);
  time_label_->setText(tr("no result"));
  view_->fitView();
  message(tr("Opened %1").arg(doc_->filePath()));
  for (const std::string& n : doc_->spec().notes) message(tr("note: %1").arg(qs(n)));
  return true;
}

bool MainWindow::saveFile() {
  if (doc_->filePath().isEmpty()) {
    const QString p = chooseFile(tr("Save model as"), QString(), kFilter, true);
    return !p.isEmpty() && saveFileAs(p);
  }
  QString error;
  if (!doc_->save(&error)) {
    message(tr("Not saved: %1").arg(error), true);
    return false;
  }
  message(tr("Saved %1").arg(doc_->filePath()));
  return true;
}

bool MainWindow::saveFileAs(const QString& chosen) {
  // a name typed without its suffix gets ".json" (else Open's filter would hide the file)
  QString path = chosen;
  if (QFileInfo(path).suffix().isEmpty()) path += QStringLiteral(".json");
  QString error;
  if (!doc_->saveAs(path, &error)) {
    message(tr("Not saved: %1").arg(error), true);
    return false;
  }
  addRecent(doc_->filePath());
  message(tr("Saved %1").arg(doc_->filePath()));
  return true;
}

bool MainWindow::newModel() {
  if (!maybeSave()) return false;
  sim_view_->cancel();
  doc_->clear();
  return true;
}

int MainWindow::showReport(const QString& title, const QString& intro, const QString& report, int buttons) {
  if (ask_) return ask_(title, intro + QStringLiteral("\n\n") + report, buttons);
  QDialog dlg(this);
  dlg.setObjectName("importReportDialog");
  dlg.setWindowTitle(title);
  auto* lay = new QVBoxLayout(&dlg);
  auto* label = new QLabel(intro, &dlg);
  label->setWordWrap(true);
  label->setTextInteractionFlags(Qt::TextSelectableByMouse);
  lay->addWidget(label);
  auto* text = new QPlainTextEdit(report, &dlg);
  text->setObjectName("importReport");
  text->setReadOnly(true);
  text->setLineWrapMode(QPlainTextEdit::WidgetWidth);
  lay->addWidget(text, 1);
  auto* box = new QDialogButtonBox(QDialogButtonBox::StandardButtons(buttons), &dlg);
  int pressed = QMessageBox::Cancel;
  connect(box, &QDialogButtonBox::clicked, &dlg, [&](QAbstractButton* b) {
    pressed = int(box->standardButton(b));
    dlg.accept();
  });
  lay->addWidget(box);
  dlg.resize(820, 520);
  dlg.exec();
  return pressed;
}

bool MainWindow::importFile(const QString& path) {
  if (!maybeSave()) return false;
  return importNow(path, {});
}

bool MainWindow::importNow(const QString& path, const QStringList& ignore) {
  ImportOptions options;
  for (const QString& k : ignore) options.ignore.insert(ss(k));
  ImportResult r;
  try {
    r = study_import(ss(path), options);
  } catch (const ImportRefused& e) {
    QStringList kinds;
    for (const ImportFinding* f : e.report().refusals())
      if (!kinds.contains(qs(f->kind))) kinds << qs(f->kind);
    message(tr("Not imported: %1").arg(qs(e.what())), true);
    if (kinds.isEmpty()) {  // the file itself: missing, malformed, not a model
      showReport(tr("Cannot import"), tr("%1 cannot be imported:").arg(QFileInfo(path).fileName()), qs(e.what()),
                 QMessageBox::Ok);
      return false;
    }
    const QString intro =
        tr("%1 holds elements that change the dynamics and that codyna cannot represent: %2. Import it again "
           "without them (as codyna import --ignore %3)?")
            .arg(QFileInfo(path).fileName(), kinds.join(", "), kinds.join(","));
    const QString report = qs(e.what()) + (e.report().mapped.empty() ? QString() : "\n\n" + qs(e.report().text()));
    if (showReport(tr("Import refused"), intro, report, QMessageBox::Yes | QMessageBox::No) != QMessageBox::Yes) return false;
    return importNow(path, ignore + kinds);
  } catch (const std::exception& e) {
    message(tr("Not imported: %1").arg(qs(e.what())), true);
    showReport(tr("Cannot import"), tr("%1 cannot be imported:").arg(QFileInfo(path).fileName()), qs(e.what()),
               QMessageBox::Ok);
    return false;
  }
  // a new document that has no file: the source is never written, Save asks for a name
  sim_view_->cancel();
  doc_->clear();
  QString error;
  if (!doc_->edit(tr("Import %1").arg(QFileInfo(path).fileName()), [&](ModelSpec& s) { s = r.spec; }, &error)) {
    message(tr("Not imported: %1").arg(error), true);
    return false;
  }
  result_.reset();
  slider_->setRange(0, 0);
  slider_->setEnabled(false);
  play_->setEnabled(false);
  time_label_->setText(tr("no result"));
  view_->fitView();
  message(tr("Imported %1 (%2, %3): %4 bodies, %5 joints; not saved yet")
              .arg(path, qs(r.report.format), qs(r.report.reader))
              .arg(r.spec.bodies.size())
              .arg(r.spec.joints.size()));
  for (const std::string& n : r.spec.notes) message(tr("note: %1").arg(qs(n)));
  showReport(tr("Import report"),
             tr("%1 was imported as a new, unsaved model (Save asks for a file name; %1 is not changed).")
                 .arg(QFileInfo(path).fileName()),
             qs(r.report.text()), QMessageBox::Ok);
  return true;
}

bool MainWindow::exportPlant(const QString& dir) {
  QString error;
  if (!lin_view_->exportTo(dir, &error)) {
    message(tr("Export failed: %1").arg(error), true);
    return false;
  }
  return true;
}

QStringList MainWindow::recentFiles() const { return QSettings().value("recentFiles").toStringList(); }

void MainWindow::addRecent(const QString& path) {
  QStringList l = recentFiles();
  l.removeAll(path);
  l.prepend(path);
  while (l.size() > kMaxRecent) l.removeLast();
  QSettings().setValue("recentFiles", l);
  rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
  if (!recent_menu_) return;
  recent_menu_->clear();
  for (const QString& p : recentFiles()) recent_menu_->addAction(p, this, [this, p] { openFile(p); });
  recent_menu_->setEnabled(!recent_menu_->isEmpty());
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!maybeSave()) return e->ignore();
  anim_.stop();
  sim_view_->cancel();
  autosave_->remove();  // saved or discarded: nothing to recover
  saveLayout();
  e->accept();
}

// The window's size, docks and splitters as the user left them (QSettings)
void MainWindow::saveLayout() const {
  QSettings s;
  s.setValue("window/geometry", saveGeometry());
  s.setValue("window/state", saveState());
  for (const QSplitter* sp : findChildren<QSplitter*>())
    if (!sp->objectName().isEmpty()) s.setValue("splitters/" + sp->objectName(), sp->saveState());
}

void MainWindow::restoreLayout() {
  QSettings s;
  if (s.contains("window/geometry")) restoreGeometry(s.value("window/geometry").toByteArray());
  if (s.contains("window/state")) restoreState(s.value("window/state").toByteArray());
  for (QSplitter* sp : findChildren<QSplitter*>())
    if (!sp->objectName().isEmpty() && s.contains("splitters/" + sp->objectName()))
      sp->restoreState(s.value("splitters/" + sp->objectName()).toByteArray());
}

bool MainWindow::offerRecovery() {
  for (const Autosave::Recovered& r : Autosave::orphans()) {
    const QString what = r.model_file.isEmpty() ? tr("an untitled model") : r.model_file;
    const int b = ask(tr("Recover unsaved work"),
                      tr("codyna stopped before the changes to %1 were saved (last autosave %2).\n"
                         "Recover them? The model file is not changed until you save.")
                          .arg(what, r.saved_at),
                      QMessageBox::Yes | QMessageBox::No);
    if (b != QMessageBox::Yes) {
      QFile::remove(r.recovery_file);
      message(tr("Discarded the unsaved changes to %1").arg(what));
      continue;
    }
    ModelSpec spec;
    try {
      spec = study_parse_model(nlohmann::json::parse(r.model_json.toStdString()), ss(r.model_file));
    } catch (const std::exception& e) {
      message(tr("Cannot recover %1 (%2): %3").arg(what, r.recovery_file, qs(e.what())), true);
      continue;  // the recovery file stays for a look by hand
    }
    // the file as saved, then the recovered edits as one undoable, unsaved step
    if (r.model_file.isEmpty() || !QFileInfo::exists(r.model_file) || !openFile(r.model_file)) {
      sim_view_->cancel();
      doc_->clear();
    }
    doc_->edit(tr("Recover unsaved changes"), [&](ModelSpec& s) { s = spec; });
    QFile::remove(r.recovery_file);
    autosave_->writeNow();
    message(tr("Recovered the unsaved changes to %1 (autosaved %2)").arg(what, r.saved_at));
    return true;  // one at a time: the others are offered at the next start
  }
  return false;
}

void MainWindow::selectElement(std::optional<ElementId> id) {
  if (!id) {
    tree_->clearSelection();
    props_->setElement(std::nullopt);
    return;
  }
  const QModelIndex i = tree_model_->indexOf(*id);
  tree_->expand(i.parent());
  tree_->setCurrentIndex(i);
  tree_->scrollTo(i);
}

std::optional<ElementId> MainWindow::selectedElement() const { return tree_model_->elementAt(tree_->currentIndex()); }

bool MainWindow::removeSelected() {
  const auto id = selectedElement();
  if (!id) return false;
  const std::string name = element_name(doc_->spec(), id->kind, id->index);
  const auto refs = references_to(doc_->spec(), id->kind, name);
  if (!refs.empty()) {
    QStringList l;
    for (const auto& r : refs) l << "  " + qs(r);
    const int b = ask(tr("Remove %1").arg(qs(name)),
                      tr("%1 %2 is referenced by:\n%3\nRemove it anyway?").arg(to_string(id->kind), qs(name), l.join('\n')),
                      QMessageBox::Yes | QMessageBox::No);
    if (b != QMessageBox::Yes) return false;
  }
  props_->setElement(std::nullopt);
  return doc_->edit(tr("Remove %1").arg(qs(name)), [&](ModelSpec& s) { remove_element(s, id->kind, id->index); });
}

bool MainWindow::duplicateSelected() {
  const auto id = selectedElement();
  if (!id) return false;
  int made = -1;
  const bool ok = doc_->edit(tr("Duplicate %1").arg(qs(element_name(doc_->spec(), id->kind, id->index))),
                             [&](ModelSpec& s) { made = duplicate_element(s, id->kind, id->index); });
  if (ok && made >= 0) selectElement(ElementId{id->kind, made});
  return ok;
}

bool MainWindow::addElement(ElementKind k, const std::function<void(ModelSpec&, int)>& setup, const QString& text) {
  int made = -1;
  const bool ok = doc_->edit(text.isEmpty() ? tr("Add %1").arg(to_string(k)) : text, [&](ModelSpec& s) {
    made = add_element(s, k);
    if (setup) setup(s, made);
  });
  if (ok && made >= 0) selectElement(ElementId{k, made});
  return ok;
}

// The model tree's context menu: Add of the kind under the pointer (every kind on empty space), and
// on a body or a joint the elements one attaches to it, made already attached; then Rename,
// Duplicate and Remove of the element.
void MainWindow::showTreeMenu(const QPoint& at) {
  const QModelIndex index = tree_->indexAt(at);
  const auto kind = tree_model_->kindAt(index);
  const auto id = tree_model_->elementAt(index);
  if (id) selectElement(*id);
  auto* menu = new QMenu(this);
  menu->setObjectName("treeMenu");
  menu->setAttribute(Qt::WA_DeleteOnClose);
  if (!kind) {
    for (ElementKind k : kElementKinds) menu->addAction(addElementAction(k));
  } else {
    menu->addAction(addElementAction(*kind));
  }
  const ModelSpec& spec = doc_->spec();
  auto item = [&](const QString& name, const QString& text, ElementKind k, std::function<void(ModelSpec&, int)> setup) {
    QAction* a = menu->addAction(text);
    a->setObjectName(name);
    connect(a, &QAction::triggered, this, [this, k, setup, text] { addElement(k, setup, text); });
  };
  if (id && id->kind == ElementKind::Body && id->index < static_cast<int>(spec.bodies.size())) {
    const std::string body = spec.bodies[id->index].name;
    const QString b = qs(body);
    menu->addSeparator();
    bool moved = false;
    for (const JointSpec& j : spec.joints) moved = moved || j.child == body;
    if (!moved)
      item("addJointMoving", tr("Add joint moving %1 (from ground)").arg(b), ElementKind::Joint, [body](ModelSpec& s, int k) {
        s.joints[k].name = unique_name(s, ElementKind::Joint, body + "_joint");
        s.joints[k].parent = kGroundName;
        s.joints[k].child = body;
      });
    item("addBodyOn", tr("Add body jointed to %1").arg(b), ElementKind::Body, [body](ModelSpec& s, int k) {
      const std::string child = s.bodies[k].name;
      const int j = add_element(s, ElementKind::Joint);
      s.joints[j].name = unique_name(s, ElementKind::Joint, child + "_joint");
      s.joints[j].parent = body;
      s.joints[j].child = child;
    });
    item("addSpringTo", tr("Add spring-damper from ground to %1").arg(b), ElementKind::Effect, [body](ModelSpec& s, int k) {
      EffectSpec& e = s.effects[k];
      e.type = EffectType::SpringDamper;
      e.name = unique_name(s, ElementKind::Effect, body + "_spring");
      e.body_a = kGroundName;
      e.body_b = body;
    });
    item("addTireOn", tr("Add tire on %1").arg(b), ElementKind::Effect, [body](ModelSpec& s, int k) {
      EffectSpec& e = s.effects[k];
      PropertyEditor::firstTire(e);
      e.name = unique_name(s, ElementKind::Effect, body + "_tire");
      e.body_a = body;
    });
    item("addForceOn", tr("Add force actuator on %1").arg(b), ElementKind::Actuator, [body](ModelSpec& s, int k) {
      ActuatorSpec& a = s.actuators[k];
      a.type = ActuatorType::BodyForce;
      a.name = unique_name(s, ElementKind::Actuator, body + "_force");
      a.body = body;
    });
    item("addSensorOn", tr("Add position sensor on %1").arg(b), ElementKind::Sensor, [body](ModelSpec& s, int k) {
      SensorSpec& x = s.sensors[k];
      x.type = SensorType::PointPosition;
      x.name = unique_name(s, ElementKind::Sensor, body + "_x");
      x.body = body;
    });
  }
  if (id && id->kind == ElementKind::Joint && id->index < static_cast<int>(spec.joints.size())) {
    const std::string joint = spec.joints[id->index].name;
    const QString j = qs(joint);
    menu->addSeparator();
    item("addActuatorOn", tr("Add actuator on %1").arg(j), ElementKind::Actuator, [joint](ModelSpec& s, int k) {
      ActuatorSpec& a = s.actuators[k];
      a.type = ActuatorType::JointForce;
      a.name = unique_name(s, ElementKind::Actuator, joint + "_drive");
      a.joint = joint;
    });
    item("addSensorOf", tr("Add position sensor of %1").arg(j), ElementKind::Sensor, [joint](ModelSpec& s, int k) {
      SensorSpec& x = s.sensors[k];
      x.type = SensorType::JointPosition;
      x.name = unique_name(s, ElementKind::Sensor, joint + "_q");
      x.joint = joint;
    });
    item("addDamperOn", tr("Add damper on %1").arg(j), ElementKind::Effect, [joint](ModelSpec& s, int k) {
      EffectSpec& e = s.effects[k];
      e.type = EffectType::JointDamper;
      e.name = unique_name(s, ElementKind::Effect, joint + "_damper");
      e.joint = joint;
    });
  }
  if (id) {
    menu->addSeparator();
    QAction* rename = menu->addAction(tr("Rename"), this, [this, index] { tree_->edit(index.siblingAtColumn(0)); });
    rename->setObjectName("treeRename");
    menu->addAction(tr("Duplicate"), this, [this] { duplicateSelected(); })->setObjectName("treeDuplicate");
    menu->addAction(tr("Remove"), this, [this] { removeSelected(); })->setObjectName("treeRemove");
  }
  menu->popup(tree_->viewport()->mapToGlobal(at));
}

void MainWindow::onModelChanged() {
  animateMode(-1, {});
  if (doc_->model() || !doc_->draft()) {
    view_->setModel(doc_->model());
  } else {
    const int n = static_cast<int>(doc_->issues().size());
    QString note = n == 1 ? tr("Draft: the model does not compile yet (1 issue, see Issues).")
                          : tr("Draft: the model does not compile yet (%1 issues, see Issues).").arg(n);
    const QStringList& out = doc_->draftLeavesOut();
    if (!out.isEmpty()) note += tr("\nNot drawn: %1.").arg(out.size() > 4 ? out.mid(0, 4).join(", ") + tr(", ...") : out.join(", "));
    view_->setDraft(doc_->draft(), note, doc_->draftHeld());
  }
  if (!doc_->model()) statusBar()->showMessage(tr("The model does not compile: %1").arg(doc_->errorText().section('\n', 0, 0)));
}

void MainWindow::onResult(std::shared_ptr<const SimulationResult> r) {
  result_ = std::move(r);
  const int n = result_ ? result_->samples() : 0;
  slider_->setRange(0, std::max(0, n - 1));
  slider_->setEnabled(n > 0);
  play_->setEnabled(n > 1);
  if (n > 0) {
    slider_->setValue(n - 1);
    setPlaybackTime(result_->t.back());
  }
}

void MainWindow::onManeuverFinished() {
  const std::shared_ptr<const ManeuverReport> rep = maneuver_view_->sharedReport();
  const std::shared_ptr<const Model> model = doc_->model();
  if (!rep || !model || rep->result.samples() < 2 || rep->result.q.cols() != model->nq) return;  // a steady diagram: no run
  setPlaying(false);
  animateMode(-1, {});
  // the track of the body the maneuver reads (its centre of mass) and the lane, on the ground
  std::vector<ScenePath> paths;
  int body = -1;
  try {
    body = study_maneuver_body(*model);
  } catch (const std::exception&) {
    body = -1;
  }
  const double L = view_->scene().length();
  if (!rep->lane_path.empty()) {
    ScenePath lane{"lane", {}, Eigen::Vector3f(0.25f, 0.55f, 0.85f), 0.04 * L, false};
    for (const Eigen::Vector2d& p : rep->lane_path) lane.points.emplace_back(p.x(), p.y(), 0.0);
    paths.push_back(std::move(lane));
    ScenePath cones{"cones", {}, Eigen::Vector3f(0.95f, 0.45f, 0.05f), 0.06 * L, true};
    for (const Eigen::Vector2d& p : rep->lane_cones) cones.points.emplace_back(p.x(), p.y(), 0.0);
    paths.push_back(std::move(cones));
  }
  if (body > 0) {
    ScenePath track{"track", {}, Eigen::Vector3f(0.80f, 0.15f, 0.10f), 0.04 * L, false};
    StudyPoses poses(*model);
    const SimulationResult& r = rep->result;
    const int n = r.samples(), stride = std::max(1, n / 4000);  // at most ~4000 points
    const Eigen::Vector3d c = model->com[static_cast<std::size_t>(body)];
    for (int k = 0; k < n; k += stride) track.points.push_back(poses.at(r.q.row(k).transpose())[static_cast<std::size_t>(body)].act_point(c));
    if ((n - 1) % stride != 0) track.points.push_back(poses.at(r.q.row(n - 1).transpose())[static_cast<std::size_t>(body)].act_point(c));
    paths.push_back(std::move(track));
  }
  // the run from its start, the camera following the car
  view_->setPaths(std::move(paths));
  onResult(std::shared_ptr<const SimulationResult>(rep, &rep->result));
  setPlaybackTime(rep->result.t.front());
  view_->setFollowBody(body);
  view_->frameBody(body, 0.8 * L);  // the car and the lane about it
  message(tr("The maneuver's run is in the 3-D view: Play (%1 s%2)")
              .arg(rep->result.t.back() - rep->result.t.front(), 0, 'g', 4)
              .arg(body > 0 ? tr(", the track of %1 drawn, the camera following it").arg(qs(model->body_names[static_cast<std::size_t>(body)])) : QString()));
}

void MainWindow::setPlaybackTime(double t) {
  if (!result_ || result_->samples() == 0) return;
  const auto& ts = result_->t;
  const auto it = std::lower_bound(ts.begin(), ts.end(), t);
  const int k = std::clamp(static_cast<int>(it - ts.begin()), 0, result_->samples() - 1);
  play_t_ = ts[k];
  const auto model = doc_->model();
  if (model && result_->q.cols() == model->nq) {
    if (result_->v.cols() == model->nv && result_->v.rows() == result_->q.rows())
      view_->setState(result_->q.row(k).transpose(), result_->v.row(k).transpose(),
                      model->ns > 0 && result_->s.cols() == model->ns && result_->s.rows() == result_->q.rows()
                          ? Eigen::VectorXd(result_->s.row(k).transpose())
                          : Eigen::VectorXd());
    else
      view_->setConfiguration(result_->q.row(k).transpose());
  }
  sim_view_->plots()->setTimeCursor(play_t_);
  time_label_->setText(QStringLiteral("t = %1 s").arg(play_t_, 0, 'f', 3));
  if (slider_->value() != k) {
    const QSignalBlocker block(slider_);
    slider_->setValue(k);
  }
}

void MainWindow::setPlaying(bool on) {
  if (on && (!result_ || result_->samples() < 2)) on = false;
  if (on) {
    mode_ = -1;
    if (play_t_ >= result_->t.back()) setPlaybackTime(result_->t.front());
    anim_.start();
  } else if (mode_ < 0) {
    anim_.stop();
  }
  play_->setText(on ? tr("Pause") : tr("Play"));
}

bool MainWindow::isPlaying() const { return anim_.isActive() && mode_ < 0; }

void MainWindow::animateMode(int index, const Eigen::VectorXcd& shape) {
  mode_ = index;
  mode_shape_ = shape;
  mode_phase_ = 0;
  if (index >= 0) {
    play_->setText(tr("Play"));
    anim_.start();
  } else {
    anim_.stop();
    play_->setText(tr("Play"));
    // back to the operating point of a current linearization, else the initial state
    if (const auto m = doc_->model()) {
      const auto* r = lin_view_->result();
      const bool at_op = r && !lin_view_->isStale() && r->op.q.size() == m->nq && r->op.v.size() == m->nv;
      view_->setState(at_op ? r->op.q : m->q0, at_op ? r->op.v : m->v0);
    }
  }
}

bool MainWindow::isAnimatingMode() const { return anim_.isActive() && mode_ >= 0; }

void MainWindow::stepAnimation() {
  if (mode_ < 0) {
    // playback: advance by the frame time times the speed
    if (!result_ || result_->samples() < 2) return setPlaying(false);
    const double t = play_t_ + kFrameMs * 1e-3 * speed_->currentData().toDouble();
    if (t >= result_->t.back()) {
      setPlaybackTime(result_->t.back());
      return setPlaying(false);
    }
    return setPlaybackTime(t);
  }
  // mode shape: the linearization's operating point moved along Re(shape e^{i phase}) on its
  // position states (joint coordinates, and the rotations and translations of ball and free
  // joints on their manifold), loops re-assembled
  const auto model = doc_->model();
  const auto* lin = lin_view_->result();
  if (!model || !lin || lin->op.q.size() != model->nq) return;
  mode_phase_ += 2 * M_PI * kFrameMs / 1500.0;  // one period in 1.5 s whatever the frequency
  const Eigen::VectorXd q = study_mode_pose(*model, lin->op.q, lin->system.state_names, mode_shape_, mode_phase_);
  // the tire forces follow the pose, at the operating point's velocities
  if (lin->op.v.size() == model->nv) view_->setState(q, lin->op.v);
  else view_->setConfiguration(q);
}

}  // namespace codyna::gui
