// codyna-gui rendered for real (xvfb-run, Mesa's software OpenGL): the main window
// of every example with the mechanism in the 3-D view, the panels, the linearize
// view with its pole map, a simulation plot and a playback frame, written as PNGs
// under build/screenshots; the study's steady-state search and references filled in
// through their widgets (linearize_steady_state.png, simulate_references.png). A blank 3-D view fails (pixel statistics, not file existence).
#include <QApplication>
#include <QContextMenuEvent>
#include <QDir>
#include <QMenu>
#include <QTreeView>
#include <QCheckBox>
#include <QComboBox>
#include <QElapsedTimer>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QListWidget>
#include <QPushButton>
#include <QPlainTextEdit>
#include <QScrollArea>
#include <QScreen>
#include <QLabel>
#include <QSplitter>
#include <QTableWidget>
#include <QSet>
#include <QSignalSpy>
#include <QTabWidget>
#include <QTableView>
#include <QLineEdit>
#include <QTabWidget>
#include <QTest>
#include <QWindow>

#include "gui/linearize_view.hpp"
#include "gui/issues_panel.hpp"
#include "gui/main_window.hpp"
#include "model/spec_edit.hpp"
#include "gui/pole_map.hpp"
#include <QChart>
#include "gui/result_plots.hpp"
#include "gui/simulate_view.hpp"
#include "gui/study_widgets.hpp"
#include "gui/control_view.hpp"
#include "gui/property_editor.hpp"
#include "gui/chart_view.hpp"
#include "gui/sweep_view.hpp"
#include "gui/kc_view.hpp"
#include "gui/maneuver_view.hpp"
#include "gui/tire_view.hpp"
#include "gui/view3d.hpp"
#include "simulation/result.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kShots = QStringLiteral(CODYNA_SCREENSHOT_DIR);
const std::string kManeuverModel = CODYNA_TEST_DATA_DIR "/single_track_car_driver.json";

// what a person sees: the X server's pixels of the window (GL content included)
QImage screenOf(QWidget* w) {
  QCoreApplication::processEvents();
  return w->window()->windowHandle()->screen()->grabWindow(w->winId()).toImage().convertToFormat(QImage::Format_RGB32);
}

QImage screenOfChild(QWidget* top, QWidget* child) {
  const QImage all = screenOf(top);
  const QPoint p = child->mapTo(top, QPoint(0, 0));
  return all.copy(QRect(p, child->size()));
}

struct Stats {
  double foreground = 0;  // fraction of pixels away from the most common colour
  int colours = 0;
};

Stats stats(const QImage& img) {
  QHash<QRgb, int> count;
  for (int y = 0; y < img.height(); y += 2)
    for (int x = 0; x < img.width(); x += 2) ++count[img.pixel(x, y) & 0xffffff];
  QRgb bg = 0;
  int most = 0, total = 0;
  for (auto it = count.begin(); it != count.end(); ++it) {
    total += it.value();
    if (it.value() > most) most = it.value(), bg = it.key();
  }
  int far = 0;
  for (int y = 0; y < img.height(); y += 2)
    for (int x = 0; x < img.width(); x += 2) {
      const QRgb c = img.pixel(x, y);
      const int d = std::abs(qRed(c) - qRed(bg)) + std::abs(qGreen(c) - qGreen(bg)) + std::abs(qBlue(c) - qBlue(bg));
      if (d > 60) ++far;
    }
  return {total ? double(far) / total : 0.0, static_cast<int>(count.size())};
}

double difference(const QImage& a, const QImage& b) {
  if (a.size() != b.size()) return 1.0;
  long diff = 0, n = 0;
  for (int y = 0; y < a.height(); y += 2)
    for (int x = 0; x < a.width(); x += 2, ++n) {
      const QRgb p = a.pixel(x, y), q = b.pixel(x, y);
      if (std::abs(qRed(p) - qRed(q)) + std::abs(qGreen(p) - qGreen(q)) + std::abs(qBlue(p) - qBlue(q)) > 30) ++diff;
    }
  return double(diff) / n;
}

void save(const QImage& img, const QString& name) {
  QDir().mkpath(kShots);
  QVERIFY2(img.save(kShots + "/" + name), qPrintable(name));
}

bool waitFor(const std::function<bool()>& done, int ms = 120000) {
  QElapsedTimer t;
  t.start();
  while (!done() && t.elapsed() < ms) QTest::qWait(20);
  return done();
}

}  // namespace

class MainWindowXvfb : public QObject {
  Q_OBJECT
 private slots:
  void initTestCase() {
    QCoreApplication::setOrganizationName("codyna-test");
    QCoreApplication::setApplicationName("main_window_xvfb");
    QVERIFY2(View3D::openGLAvailable(), "OpenGL is expected under xvfb-run with Mesa");
  }

  void everyExampleShowsItsMechanism_data() {
    QTest::addColumn<QString>("file");
    const QStringList files = QDir(CODYNA_EXAMPLES_DIR).entryList({"*.json"}, QDir::Files, QDir::Name);
    QVERIFY(files.size() >= 8);
    for (const QString& f : files) QTest::newRow(qPrintable(f)) << f;
  }

  void everyExampleShowsItsMechanism() {
    QFETCH(QString, file);
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/") + file));
    QTest::qWait(300);
    QVERIFY(w.view3d()->hasGL());
    const QImage view = screenOfChild(&w, w.view3d());
    const Stats s = stats(view);
    QVERIFY2(s.foreground > 0.01, qPrintable(QString("%1: only %2 of the 3-D view differs from the background").arg(file).arg(s.foreground)));
    QVERIFY2(s.colours > 50, qPrintable(QString("%1: %2 colours").arg(file).arg(s.colours)));
    save(screenOf(&w), "main_" + QFileInfo(file).baseName() + ".png");
    w.document()->undoStack()->setClean();
  }

  // The control workflow's widgets as a user sees them, the analysis area dragged taller:
  // the four-bar's crank held at 1.3 rad with its torque solved, then the cart-pendulum's
  // LQR following a step of the cart position.
  void controlWorkflowWidgets() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/four_bar.json")));
    auto* centre = qobject_cast<QSplitter*>(w.analysisTabs()->parentWidget());
    QVERIFY(centre);
    centre->setSizes({250, 10000});
    LinearizeView* lv = w.linearizeView();
    w.analysisTabs()->setCurrentWidget(lv);
    NameValueTable* set = lv->setTable();
    QTest::mouseClick(set->addButton(), Qt::LeftButton);
    set->nameCombo(0)->setCurrentIndex(set->nameCombo(0)->findText("pivot_A"));
    set->valueSpin(0)->setValue(1.3);
    lv->freeInputsList()->item(0)->setCheckState(Qt::Checked);
    QVERIFY(lv->linearize());
    auto* results = lv->findChild<QTabWidget*>();  // A, B, C, D, offsets: show the torque solved (u0)
    QVERIFY(results);
    results->setCurrentIndex(results->count() - 1);
    QTest::qWait(300);
    const QImage lin = screenOfChild(&w, w.analysisTabs());
    QVERIFY2(stats(lin).foreground > 0.02, "the linearize view shows its widgets");
    save(lin, "linearize_steady_state.png");
    w.document()->undoStack()->setClean();

    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    SimulateView* sv = w.simulateView();
    w.analysisTabs()->setCurrentWidget(sv);
    SignalTable* refs = sv->referencesTable();
    QTest::mouseClick(refs->addButton(), Qt::LeftButton);
    refs->spin(0, SignalTable::Time)->setValue(1.0);
    refs->spin(0, SignalTable::Value)->setValue(0.2);
    QCOMPARE(w.document()->spec().analysis.references.size(), std::size_t(1));
    QSignalSpy done(sv, &SimulateView::runFinished);
    sv->run();
    QVERIFY(waitFor([&] { return done.count() == 1; }));
    QVERIFY(sv->result() && sv->result()->completed);
    // the cart follows the step: h ends near 0.2
    const auto& r = *sv->result();
    QVERIFY2(std::abs(r.y(r.y.rows() - 1, 0) - 0.2) < 0.02, qPrintable(QString::number(r.y(r.y.rows() - 1, 0))));
    QTest::qWait(300);
    save(screenOfChild(&w, w.analysisTabs()), "simulate_references.png");
    w.document()->undoStack()->setClean();
  }

  void cartPendulumWorkflow() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    QTest::qWait(300);
    save(screenOf(&w), "main_window.png");
    // the two panels
    for (const char* dock : {"plantInDock", "plantOutDock"}) {
      auto* d = w.findChild<QDockWidget*>(dock);
      QVERIFY(d);
      save(screenOfChild(&w, d), QString(dock).replace("Dock", "_panel.png"));
    }
    const QImage rest = screenOfChild(&w, w.view3d());

    // linearize at equilibrium, select the unstable mode: the pole map and the mode animation
    LinearizeView* lv = w.linearizeView();
    lv->operatingPointCombo()->setCurrentIndex(lv->operatingPointCombo()->findText("equilibrium", Qt::MatchContains));
    QVERIFY(lv->linearize());
    int unstable = -1;
    for (int k = 0; k < static_cast<int>(lv->modes().modes.size()); ++k)
      if (lv->modes().modes[k].eigenvalue.real() > 0.1) unstable = k;
    QVERIFY(unstable >= 0);
    lv->selectMode(unstable);
    QVERIFY(w.isAnimatingMode());
    QTest::qWait(400);
    const QImage moving = screenOfChild(&w, w.view3d());
    QVERIFY2(difference(rest, moving) > 0.002, "the mode shape animation moves the mechanism");
    save(screenOf(&w), "linearize_view.png");
    save(screenOfChild(&w, lv->poleMap()), "pole_map.png");
    // the pole map is a readable plot, and it grows with the window
    const QRectF small = lv->poleMap()->chart()->plotArea();
    QVERIFY2(small.height() >= 90 && small.width() >= 150,
             qPrintable(QString("%1 x %2").arg(small.width()).arg(small.height())));
    w.resize(2560, 1440);
    QTest::qWait(400);
    const QRectF large = lv->poleMap()->chart()->plotArea();
    QVERIFY2(large.height() >= 1.3 * small.height() && large.width() >= 1.3 * small.width(),
             qPrintable(QString("%1 x %2 at 2560 x 1440").arg(large.width()).arg(large.height())));
    save(screenOf(&w), "linearize_view_2560.png");
    w.resize(1600, 1000);
    QTest::qWait(300);
    lv->selectMode(-1);
    w.animateMode(-1, {});

    // simulate the model's LQR from its initial offset, with the linear prediction
    SimulateView* sv = w.simulateView();
    w.analysisTabs()->setCurrentWidget(sv);
    sv->compareLinearCheck()->setChecked(true);
    QSignalSpy done(sv, &SimulateView::runFinished);
    sv->run();
    QVERIFY(waitFor([&] { return done.count() == 1; }));
    QVERIFY(sv->result() && sv->result()->completed);
    QTest::qWait(300);
    save(screenOf(&w), "simulate_view.png");
    save(screenOfChild(&w, sv->plots()), "simulation_plot.png");
    const Stats ps = stats(screenOfChild(&w, sv->plots()));
    QVERIFY2(ps.foreground > 0.01, "the plot shows curves");

    // a playback frame early in the run differs from the end
    w.setPlaybackTime(0.3);
    QTest::qWait(200);
    const QImage early = screenOfChild(&w, w.view3d());
    save(screenOf(&w), "playback_frame.png");
    w.setPlaybackTime(sv->result()->t.back());
    QTest::qWait(200);
    QVERIFY2(difference(early, screenOfChild(&w, w.view3d())) > 0.001, "playback moves the mechanism");
    w.document()->undoStack()->setClean();
  }

  // the views of issue 18: the Control view (closed-loop poles, gain, Bode, step), a joint's
  // typed fields in the property editor, a refused value, results out of date
  void controlViewAndEditing() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    ControlView* cv = w.controlView();
    w.analysisTabs()->setCurrentWidget(cv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({330, 610});  // the plots taller, as a user drags it
    QVERIFY(cv->analyse());
    cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    cv->inputCombo()->setCurrentText("force");
    cv->outputCombo()->setCurrentText("theta");
    QTest::qWait(300);
    auto* bode = w.findChild<QWidget*>("bodeView");
    QVERIFY(bode && bode->isVisible());
    const Stats bs = stats(screenOfChild(&w, bode));
    QVERIFY2(bs.foreground > 0.005, "the Bode plot shows curves");
    save(screenOf(&w), "bode.png");
    cv->systemCombo()->setCurrentIndex(ControlView::ClosedLoop);
    cv->inputCombo()->setCurrentIndex(0);
    auto* tabs = bode->parentWidget();
    while (tabs && !qobject_cast<QTabWidget*>(tabs)) tabs = tabs->parentWidget();
    QVERIFY(tabs);
    qobject_cast<QTabWidget*>(tabs)->setCurrentIndex(1);
    QTest::qWait(300);
    save(screenOf(&w), "step_response.png");
    // the plant's pole-zero map for force -> h: the non-minimum-phase zero pair
    cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    cv->inputCombo()->setCurrentText("force");
    cv->outputCombo()->setCurrentText("h");
    qobject_cast<QTabWidget*>(tabs)->setCurrentIndex(2);
    QTest::qWait(300);
    QCOMPARE(cv->poleZeroMap()->zeroCount(), 2);
    save(screenOfChild(&w, cv->poleZeroMap()), "pole_zero_map.png");

    // the rod's joint, its fields typed; a refused mass, marked with the reason
    w.selectElement(ElementId{ElementKind::Joint, 1});
    QTest::qWait(200);
    save(screenOfChild(&w, w.propertyEditor()), "property_editor_joint.png");
    w.selectElement(ElementId{ElementKind::Body, 1});
    auto* mass = qobject_cast<QLineEdit*>(w.propertyEditor()->editorFor("mass"));
    QVERIFY(mass);
    mass->setFocus();
    mass->selectAll();
    QTest::keyClicks(mass, "-3");
    QTest::keyClick(mass, Qt::Key_Return);
    QVERIFY(!w.propertyEditor()->errorText().isEmpty());
    QTest::qWait(200);
    save(screenOfChild(&w, w.propertyEditor()), "property_editor_refused.png");
    // an accepted edit: the Control view's results are out of date
    mass->selectAll();
    QTest::keyClicks(mass, "11");
    QTest::keyClick(mass, Qt::Key_Return);
    QVERIFY(cv->isStale());
    QTest::qWait(200);
    save(screenOf(&w), "control_stale.png");

    // the cart removed while its slider and the rod's pivot still name it: every problem in the Issues
    // list at once, the slider's child field marked where the user looks; and the tree's context
    // menu on a body, as a right click opens it (the whole screen: the menu is a window of its own)
    w.document()->edit("Remove cart", [](ModelSpec& s) { remove_element(s, ElementKind::Body, 0); });
    QVERIFY(w.issuesPanel()->count() >= 2);
    w.selectElement(ElementId{ElementKind::Joint, 0});
    QVERIFY(w.propertyEditor()->markedFields().contains("child"));
    QTest::qWait(200);
    save(screenOf(&w), "issues_panel.png");
    w.document()->undoStack()->undo();
    QTreeView* tree = w.modelTree();
    const QModelIndex rod = w.treeModel()->indexOf({ElementKind::Body, 1});
    const QPoint at = tree->visualRect(rod).center();
    QContextMenuEvent menu_event(QContextMenuEvent::Mouse, at, tree->viewport()->mapToGlobal(at));
    QApplication::sendEvent(tree->viewport(), &menu_event);
    auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
    QVERIFY(menu);
    QTest::qWait(300);
    const QRect area = QRect(w.mapToGlobal(QPoint(0, 0)), w.size()).united(menu->geometry());
    save(w.windowHandle()->screen()->grabWindow(0, area.x(), area.y(), area.width(), area.height()).toImage(),
         "tree_context_menu.png");
    menu->close();
    w.document()->undoStack()->setClean();
  }

  // a model being built from File > New: a car body (a 1500 kg box's inertia), a wheel (a disc's),
  // a driver's seat (equal moments); no joint yet, so the model does not compile, and the 3-D view
  // shows its draft: each body the ellipsoid of its mass and inertia, side by side, under a note
  void draftOfANewModel() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.newModel());
    struct Part { const char* name; double mass; Eigen::Vector3d inertia; };
    // box 4.5 x 1.4 x 1.8 m: I = m (b^2 + c^2) / 12 ...; disc r 0.3, width 0.2; a 70 kg seat
    const Part parts[] = {{"car", 1500, Eigen::Vector3d(1500 * (1.4 * 1.4 + 1.8 * 1.8) / 12, 1500 * (4.5 * 4.5 + 1.8 * 1.8) / 12,
                                                         1500 * (4.5 * 4.5 + 1.4 * 1.4) / 12)},
                          {"wheel", 20, Eigen::Vector3d(20 * (3 * 0.09 + 0.04) / 12, 20 * 0.09 / 2, 20 * (3 * 0.09 + 0.04) / 12)},
                          {"seat", 70, Eigen::Vector3d(2.5, 2.5, 2.5)}};
    for (const Part& p : parts)
      w.document()->edit("Add body", [&p](ModelSpec& s) {
        const int i = add_element(s, ElementKind::Body);
        s.bodies[static_cast<std::size_t>(i)].name = p.name;
        s.bodies[static_cast<std::size_t>(i)].mass = p.mass;
        s.bodies[static_cast<std::size_t>(i)].inertia = p.inertia.asDiagonal();
      });
    QVERIFY(!w.document()->model());
    QCOMPARE(w.issuesPanel()->count(), 3);
    View3D* view = w.view3d();
    QVERIFY(view->draftNote().contains("Draft"));
    w.selectElement(ElementId{ElementKind::Body, 1});
    QTest::qWait(300);
    for (const char* name : {"car", "wheel", "seat"}) {
      QPointF at;
      QVERIFY2(view->bodyScreenPos(name, &at) && view->rect().contains(at.toPoint()), name);
    }
    const QImage shot = screenOf(&w);
    QVERIFY(stats(screenOfChild(&w, view)).foreground > 0.05);
    save(shot, "default_shapes.png");
    w.document()->undoStack()->setClean();
  }

  // the Sweep view of issue 22: the rod mass from 5 to 15 kg, K fixed; the pole map coloured by it
  void sweepView() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    SweepView* sv = w.sweepView();
    w.analysisTabs()->setCurrentWidget(sv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({300, 640});
    w.selectElement(ElementId{ElementKind::Body, 1});
    sv->addField("/bodies/1/mass", "5:15:11");
    QVERIFY(sv->run());
    QVERIFY(waitFor([sv] { return !sv->isRunning(); }));
    QVERIFY2(sv->result(), qPrintable(sv->statusLabel()->text()));
    QTest::qWait(300);
    const Stats ps = stats(screenOfChild(&w, sv->poleChartView()));
    QVERIFY2(ps.foreground > 0.005, "the pole map shows poles");
    save(screenOf(&w), "sweep_view.png");
    sv->resultTabs()->setCurrentIndex(1);
    QTest::qWait(300);
    save(screenOfChild(&w, sv), "sweep_figure.png");
    w.document()->undoStack()->setClean();
  }

  // the sedan of issue 39 in its steady 0.4 g left turn, set in the Linearize view's steady motion
  // fields: the motion, the handling numbers, the modes, and the tire forces in the 3-D view
  void sedanSteadyTurn() {
    MainWindow w;
    w.resize(1920, 1200);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json")));
    LinearizeView* lv = w.linearizeView();
    w.analysisTabs()->setCurrentWidget(lv);
    QCOMPARE(lv->steadySpeedSpin()->value(), 25.0);
    lv->steadyTurnCombo()->setCurrentIndex(lv->steadyTurnCombo()->findData(QStringLiteral("lateral_acceleration")));
    lv->steadyTurnValueSpin()->setValue(0.4 * 9.80665);
    QCOMPARE(w.document()->spec().analysis.steady.lateral_acceleration.value_or(0), 0.4 * 9.80665);
    QVERIFY(lv->linearize());
    const auto* r = lv->result();
    QVERIFY(r && r->op.motion && r->handling);
    // the turn asked for: r V = a_y, and an understeering car
    const auto& jm = r->op.motion->joints.at(0);
    QVERIFY2(std::abs(jm.yaw_rate * jm.velocity.norm() - 0.4 * 9.80665) < 1e-6, qPrintable(QString::number(jm.yaw_rate)));
    QVERIFY(r->handling->understeer_gradient > 0);
    QCOMPARE(w.view3d()->velocities(), r->op.v);
    QCOMPARE(w.view3d()->tireContacts().size(), std::size_t(4));
    // the handling numbers' tab, and the steady motion's fields in sight in the settings column
    QTabWidget* results = lv->resultTabs();
    QVERIFY(results->isTabVisible(results->indexOf(lv->handlingText())));
    results->setCurrentWidget(lv->handlingText());
    QVERIFY(lv->handlingText()->toPlainText().contains("understeer gradient"));
    auto* column = lv->findChild<QScrollArea*>();
    QVERIFY(column);
    w.view3d()->setShowFrames(false);
    QTest::qWait(400);
    column->ensureWidgetVisible(lv->steadyTurnValueSpin(), 10, 60);
    QTest::qWait(100);
    QPoint at = lv->steadyTurnValueSpin()->mapTo(column->viewport(), QPoint(0, 0));
    QVERIFY2(column->viewport()->rect().contains(QRect(at, lv->steadyTurnValueSpin()->size())), "the turn's field is in sight");
    at = lv->steadySpeedSpin()->mapTo(column->viewport(), QPoint(0, 0));
    QVERIFY2(column->viewport()->rect().contains(QRect(at, lv->steadySpeedSpin()->size())), "the speed's field is in sight");
    const QImage shot = screenOf(&w);
    QVERIFY2(stats(screenOfChild(&w, w.view3d())).foreground > 0.02, "the car is drawn");
    save(shot, "linearize_sedan_turn.png");
    w.view3d()->setShowFrames(true);
    w.document()->undoStack()->setClean();
  }

  // the Tire view of issue 39: the MF 6.1 file of tests/data opened beside the single-track car
  void tireView() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/single_track_car.json")));
    TireView* tv = w.tireView();
    w.analysisTabs()->setCurrentWidget(tv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({300, 640});
    w.selectElement(ElementId{ElementKind::Effect, 1});  // front_tire
    tv->showTirFile(QStringLiteral(CODYNA_TEST_DATA_DIR "/tires/MagicFormula61_Paramerters.tir"));
    QVERIFY2(tv->errorText().isEmpty(), qPrintable(tv->errorText()));
    QTest::qWait(300);
    for (ChartView* c : {tv->lateralView(), tv->longitudinalView(), tv->aligningView(), tv->combinedView()}) {
      QCOMPARE(c->chart()->series().isEmpty(), false);
      QVERIFY2(stats(screenOfChild(&w, c)).foreground > 0.003, qPrintable(c->objectName()));
    }
    save(screenOf(&w), "tire_view.png");
    save(screenOfChild(&w, tv), "tire_curves.png");
    w.document()->undoStack()->setClean();
  }

  // the Maneuvers tab of issue 40: the sedan's understeer diagram at 25 m/s (constant speed)
  void maneuverView() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json")));
    ManeuverView* mv = w.maneuverView();
    w.analysisTabs()->setCurrentWidget(mv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({200, 740});
    mv->typeBox()->setCurrentIndex(mv->typeBox()->findData(QStringLiteral("constant-speed")));
    mv->field("ay-min")->setText(QStringLiteral("0.2"));
    mv->field("ay-max")->setText(QStringLiteral("7"));
    mv->field("points")->setText(QStringLiteral("12"));
    QVERIFY(mv->run());
    QTRY_VERIFY_WITH_TIMEOUT(!mv->isRunning(), 60000);
    QCOMPARE(mv->statusText(), QStringLiteral("Done"));
    QTest::qWait(300);
    QVERIFY2(stats(screenOfChild(&w, mv->chartView())).foreground > 0.003, "the understeer diagram is drawn");
    save(screenOf(&w), "maneuver_view.png");
    w.document()->undoStack()->setClean();
  }

  // the K&C tab on the sedan's front corner: travel and steer swept, the curves and the report
  void kcView() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json")));
    KcView* kc = w.kcView();
    w.analysisTabs()->setCurrentWidget(kc);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({200, 740});
    kc->field("travel")->setText(QStringLiteral("-0.08:0.08:17"));
    kc->field("steer-range")->setText(QStringLiteral("-0.03:0.03:13"));
    QVERIFY2(kc->run(), qPrintable(kc->errorText()));
    QTest::qWait(300);
    QVERIFY2(stats(screenOfChild(&w, kc->travelView())).foreground > 0.003, "the camber and toe curves are drawn");
    save(screenOf(&w), "kc_view.png");
  }
  // the nonlinear plant's frequency response over the linear Bode plot: the cart-pendulum pushed
  // with 200 N, the rod's angle parts from the linear model where it swings most
  void frequencyResponseOverlay() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    ControlView* cv = w.controlView();
    w.analysisTabs()->setCurrentWidget(cv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({250, 690});
    QVERIFY(cv->analyse());
    cv->inputCombo()->setCurrentText("force");
    cv->outputCombo()->setCurrentText("theta");
    cv->amplitudeEdit()->setText(QStringLiteral("200"));
    cv->frequenciesEdit()->setText(QStringLiteral("0.5:30:12"));
    QSignalSpy done(cv, &ControlView::estimateFinished);
    QVERIFY(cv->estimate());
    QVERIFY(done.wait(60000));
    QVERIFY2(cv->freqResp(), qPrintable(cv->freqStatusLabel()->text()));
    QCOMPARE(cv->nonlinearMagnitudePoints().size(), 12);
    QTest::qWait(300);
    save(screenOf(&w), "bode_nonlinear.png");
  }
  // a maneuver's run played in the 3-D view: the double lane change of a car with a driver, at
  // the second lane, its cones and the track it left drawn on the ground, the camera following it
  void maneuverPlayback() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QString::fromStdString(kManeuverModel)));
    ManeuverView* mv = w.maneuverView();
    w.analysisTabs()->setCurrentWidget(mv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({560, 380});
    mv->typeBox()->setCurrentIndex(mv->typeBox()->findData(QStringLiteral("double-lane-change")));
    mv->field("speed")->setText(QStringLiteral("16.7"));
    QVERIFY(mv->run());
    QTRY_VERIFY_WITH_TIMEOUT(!mv->isRunning(), 120000);
    QCOMPARE(mv->statusText(), QStringLiteral("Done"));
    const SimulationResult* r = w.playbackResult();
    QVERIFY(r && r->samples() > 10);
    // in the second lane, where the cones of section 3 stand beside the car
    const auto& names = r->output_names;
    const int ix = static_cast<int>(std::find(names.begin(), names.end(), "x") - names.begin());
    QVERIFY(ix < static_cast<int>(names.size()));
    int k = 0;
    while (k + 1 < r->samples() && r->y(k, ix) < 50 + 15 + 30 + 6) ++k;
    w.setPlaybackTime(r->t[k]);
    QTest::qWait(400);
    save(screenOf(&w), "maneuver_playback.png");
    w.document()->undoStack()->setClean();
  }
  // the sedan's fishhook played back at its largest roll: the car leaning out of the turn on its
  // tires' forces, the track it left behind it
  void sedanFishhookPlayback() {
    MainWindow w;
    w.resize(1600, 1000);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json")));
    ManeuverView* mv = w.maneuverView();
    w.analysisTabs()->setCurrentWidget(mv);
    w.findChild<QSplitter*>("centreSplitter")->setSizes({560, 380});
    mv->typeBox()->setCurrentIndex(mv->typeBox()->findData(QStringLiteral("fishhook")));
    mv->field("speed")->setText(QStringLiteral("22.2"));
    QVERIFY(mv->run());
    QTRY_VERIFY_WITH_TIMEOUT(!mv->isRunning(), 120000);
    QVERIFY2(mv->report(), qPrintable(mv->statusText()));
    const double t = mv->report()->fh_max_roll_time;
    w.setPlaybackTime(t);
    QTest::qWait(400);
    save(screenOf(&w), "maneuver_playback_sedan.png");
    w.document()->undoStack()->setClean();
  }
};

QTEST_MAIN(MainWindowXvfb)
#include "main_window_xvfb.moc"
