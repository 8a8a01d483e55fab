// Editing a model through the real widgets, the way a person does it: drop-downs
// picked from their open list with the mouse or the keys, or typed and confirmed
// with Enter; mouse wheels over fields. Regression tests for the crash of issue 18
// (an edit from a drop-down rebuilt the property editor, deleting the drop-down
// inside its own signal: SIGSEGV in QComboBox::textActivated) and for the wheel
// that changed settings while a user scrolled a panel.
#include <QAbstractItemView>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QHeaderView>
#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPointer>
#include <QScrollArea>
#include <QScrollBar>
#include <QTest>
#include <QTreeView>
#include <QUndoStack>
#include <QWheelEvent>

#include <QDockWidget>
#include <QFile>
#include <nlohmann/json.hpp>
#include <QElapsedTimer>
#include <QLabel>
#include <QPushButton>
#include <QSignalSpy>
#include <QSettings>
#include <QSlider>
#include <QSplitter>
#include <QTableView>
#include <QTableWidget>
#include <QTemporaryDir>

#include <QAction>
#include <QClipboard>
#include <QItemSelection>
#include <QMenuBar>
#include <QProgressBar>
#include <QStatusBar>
#include <QToolBar>

#include "analysis/modal.hpp"
#include "gui/control_view.hpp"
#include "gui/linearize_view.hpp"
#include "drive.hpp"
#include "gui/main_window.hpp"
#include "gui/matrix_models.hpp"
#include "gui/matrix_view.hpp"
#include "gui/view3d.hpp"
#include "gui/property_editor.hpp"
#include "gui/result_plots.hpp"
#include "gui/signal_plot.hpp"
#include "gui/simulate_view.hpp"
#include "gui/study_widgets.hpp"

using namespace codyna;
using namespace codyna::gui;
using namespace codyna::gui::drive;

namespace {

// opens `c`'s list with a click on its arrow, as a person does
const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");
const QString kPendulum = QStringLiteral(CODYNA_EXAMPLES_DIR "/pendulum.json");

}  // namespace

class EditingTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  PropertyEditor* props() { return w->propertyEditor(); }
  QComboBox* combo(const QString& field) { return qobject_cast<QComboBox*>(props()->editorFor(field)); }
  const JointSpec& joint(int k) { return w->document()->spec().joints.at(k); }

  // File > New; body, joint, body, joint (both joints on the ground, as added); selects the second joint
  void buildChainOfTwo() {
    QVERIFY(w->newModel());
    QVERIFY(w->addElement(ElementKind::Body));
    QVERIFY(w->addElement(ElementKind::Joint));
    QVERIFY(w->addElement(ElementKind::Body));
    QVERIFY(w->addElement(ElementKind::Joint));
    QCOMPARE(w->document()->spec().joints.size(), std::size_t(2));
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("ground"));
    QCOMPARE(QString::fromStdString(joint(1).child), QString("body_2"));
    QCOMPARE(props()->element()->kind, ElementKind::Joint);
    QCOMPARE(props()->element()->index, 1);
    QVERIFY(combo("parent"));
  }

  // linearizes and runs the open model (0.3 s); both results on screen
  void linearizeAndRun() {
    LinearizeView* lv = w->linearizeView();
    QVERIFY(lv->linearize());
    QVERIFY(lv->result());
    QVERIFY(lv->matrixModel(0)->rowCount() > 0);
    QVERIFY(lv->modeModel()->rowCount() > 0);
    QVERIFY(!lv->isStale());
    SimulateView* sv = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sv);
    sv->endTimeSpin()->setValue(0.3);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return finished.count() == 1; }, 60000));
    QVERIFY(sv->result() && sv->result()->completed);
    QVERIFY(sv->saveResultsButton()->isEnabled());
    QVERIFY(w->playbackSlider()->isEnabled());
    QVERIFY(!sv->isStale());
    QVERIFY(!sv->findChild<QLabel*>("simulateStale")->isVisibleTo(sv));
  }

  // nothing of the old model's results is left on screen
  void verifyNoResult() {
    LinearizeView* lv = w->linearizeView();
    QVERIFY(!lv->result());
    for (int k = 0; k < 4; ++k) QCOMPARE(lv->matrixModel(k)->rowCount(), 0);
    QCOMPARE(lv->modeModel()->rowCount(), 0);
    QCOMPARE(lv->operatingPointLabel()->text(), QString("Not linearized yet."));
    QVERIFY(!lv->findChild<QLabel*>("linearizeStale")->isVisibleTo(lv));
    SimulateView* sv = w->simulateView();
    QVERIFY(!sv->result());
    QVERIFY(!sv->saveResultsButton()->isEnabled());
    QString error;
    QTemporaryDir dir;
    QVERIFY(!sv->saveResults(dir.filePath("r.h5"), &error));  // and the call refuses too
    QVERIFY(!QFileInfo::exists(dir.filePath("r.h5")));
    QCOMPARE(sv->statusText(), QString("Not run yet."));
    QCOMPARE(sv->plots()->inputSeriesCount() + sv->plots()->outputSeriesCount(), 0);
    QVERIFY(!w->playbackSlider()->isEnabled());
    QVERIFY(!w->isAnimatingMode());
  }

 private slots:
  void init() {
    w = drive::window("editing_test");
    QVERIFY(w);
  }
  void cleanup() { drive::close(w); }

  // the reproduction: a joint's parent set from the drop-down's list with the mouse
  void parentPickedWithTheMouseChainsTheJoint() {
    buildChainOfTwo();
    QPointer<QComboBox> c = combo("parent");
    QVERIFY(pickWithMouse(c, "body"));
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body"));
    QVERIFY(w->document()->model());  // a double pendulum now: it compiles
    QCOMPARE(w->document()->model()->nq, 2);
    // the editor was rebuilt with a new drop-down; the old one goes once the event loop runs
    QVERIFY(combo("parent") != c.data());
    QCOMPARE(combo("parent")->currentText(), QString("body"));
    QTRY_VERIFY(c.isNull());
    // the rebuilt editor works as well: back to the ground, with the keys this time
    QVERIFY(pickWithKeys(combo("parent"), "ground"));
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("ground"));
  }

  void parentPickedWithTheArrowKeys() {
    buildChainOfTwo();
    QVERIFY(pickWithKeys(combo("parent"), "body"));
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body"));
    QCOMPARE(w->document()->undoStack()->undoText(), QString("Edit joint_2.parent"));
  }

  // the drop-down closed, focused: Down moves to the next body at once (activated, then textActivated)
  void parentStepsWithDownOnTheClosedDropDown() {
    buildChainOfTwo();
    QComboBox* c = combo("parent");
    c->setFocus();
    QTRY_VERIFY(c->hasFocus());
    QCOMPARE(c->currentText(), QString("ground"));
    QTest::keyClick(c, Qt::Key_Down);
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body"));
    QTest::keyClick(combo("parent"), Qt::Key_Down);  // the new drop-down has the focus path too
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body_2"));  // its own child: refused by compile
    QVERIFY(!w->document()->model());
    QVERIFY(!w->document()->errorText().isEmpty());
  }

  void parentTypedAndConfirmedWithEnter() {
    buildChainOfTwo();
    QComboBox* c = combo("parent");
    QVERIFY(c->isEditable());
    c->lineEdit()->setFocus();
    c->lineEdit()->selectAll();
    QTest::keyClicks(c->lineEdit(), "body");
    QTest::keyClick(c->lineEdit(), Qt::Key_Return);
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body"));
    // one edit, not two (Enter both activates and finishes the line edit)
    QCOMPARE(w->document()->undoStack()->count(), 5);
    QCOMPARE(combo("parent")->currentText(), QString("body"));
  }

  // a broken reference (red) fixed from the list
  void brokenReferenceFixedFromTheList() {
    buildChainOfTwo();
    QComboBox* c = combo("parent");
    c->lineEdit()->setFocus();
    c->lineEdit()->selectAll();
    QTest::keyClicks(c->lineEdit(), "nowhere");
    QTest::keyClick(c->lineEdit(), Qt::Key_Return);
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("nowhere"));
    QVERIFY(!w->document()->model());
    QCOMPARE(props()->markedField(), QString("parent"));
    QVERIFY(pickWithMouse(combo("parent"), "body"));
    QCOMPARE(QString::fromStdString(joint(1).parent), QString("body"));
    QVERIFY(w->document()->model());
  }

  void jointTypeChangedFromTheList() {
    buildChainOfTwo();
    QVERIFY(pickWithMouse(combo("type"), "prismatic"));
    QCOMPARE(joint(1).type, JointType::Prismatic);
    QVERIFY(pickWithKeys(combo("type"), "spherical"));
    QCOMPARE(joint(1).type, JointType::Spherical);
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->model()->nv, 1 + 3);
    QVERIFY(pickWithMouse(combo("type"), "revolute"));
    QCOMPARE(joint(1).type, JointType::Revolute);
  }

  // a joint's armature (rotor inertia) typed in its field: taken into the model's mass matrix,
  // a negative one refused at the field with the reader's reason, dropped by a change to a fixed
  // joint (which has no coordinate to carry it), one value per coordinate on a ball joint
  void jointArmatureTypedInTheField() {
    buildChainOfTwo();  // the second joint selected (revolute)
    QCOMPARE(joint(1).type, JointType::Revolute);
    auto type = [&](const QString& field, const QString& text) {
      QLineEdit* e = qobject_cast<QLineEdit*>(props()->editorFor(field));
      QVERIFY(e);
      e->setFocus();
      e->selectAll();
      QTest::keyClicks(e, text);
      QTest::keyClick(e, Qt::Key_Return);
    };
    QLineEdit* field = qobject_cast<QLineEdit*>(props()->editorFor("armature"));
    QVERIFY(field);  // shown at its default, none
    QCOMPARE(field->text().toDouble(), 0.0);
    QVERIFY(joint(1).armature.size() == 0);
    type("armature", "0.02");
    QCOMPARE(joint(1).armature.size(), Eigen::Index(1));
    QCOMPARE(joint(1).armature[0], 0.02);
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->model()->armature.size(), Eigen::Index(2));
    QCOMPARE(w->document()->model()->armature[1], 0.02);
    const int steps = w->document()->undoStack()->count();
    type("armature", "-1");
    QCOMPARE(joint(1).armature[0], 0.02);
    QCOMPARE(w->document()->undoStack()->count(), steps);
    QCOMPARE(props()->markedField(), QString("armature"));
    QVERIFY2(props()->errorText().contains("expected a number >= 0"), qPrintable(props()->errorText()));
    QVERIFY(pickWithMouse(combo("type"), "spherical"));
    QCOMPARE(joint(1).type, JointType::Spherical);
    QCOMPARE(joint(1).armature[0], 0.02);  // one value: every coordinate of the ball
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->model()->armature.size(), Eigen::Index(4));
    type("armature", "0.01, 0.02, 0.03");
    QCOMPARE(joint(1).armature.size(), Eigen::Index(3));
    QCOMPARE(joint(1).armature[2], 0.03);
    QVERIFY(pickWithMouse(combo("type"), "fixed"));
    QCOMPARE(joint(1).type, JointType::Fixed);
    QVERIFY(joint(1).armature.size() == 0);
    QVERIFY(!props()->editorFor("armature"));
    QVERIFY(w->document()->model());
  }

  // every drop-down of every element kind, each of its entries picked in turn: no crash
  void everyDropDownOfEveryKind() {
    buildChainOfTwo();
    for (ElementKind k : {ElementKind::Effect, ElementKind::Actuator, ElementKind::Sensor, ElementKind::Constraint})
      QVERIFY(w->addElement(k));
    for (ElementKind k : kElementKinds) {
      for (int i = 0; i < element_count(w->document()->spec(), k); ++i) {
        w->selectElement(ElementId{k, i});
        QCOMPARE(props()->element()->index, i);
        QStringList fields;
        for (const QString& f : {"type", "parent", "child", "body", "body_a", "body_b", "joint", "frame"})
          if (combo(f)) fields << f;
        for (const QString& f : fields) {
          w->selectElement(ElementId{k, i});
          if (!combo(f)) continue;  // the type picked last has no such field
          const int n = combo(f)->count();
          for (int item = 0; item < n; ++item) {
            // a refused pick may select the element the model's error is in: come back to this one
            w->selectElement(ElementId{k, i});
            QComboBox* c = combo(f);
            if (!c || c->count() != n) break;  // the pick before changed the type: other fields
            const QString text = c->itemText(item);
            if (item % 2 == 0) QVERIFY2(pickWithKeys(c, text), qPrintable(f + " <- " + text));
            else QVERIFY2(pickWithMouse(c, text), qPrintable(f + " <- " + text));
          }
        }
        w->selectElement(ElementId{k, i});
      }
    }
    // and back through the undo stack, every step
    while (w->document()->undoStack()->canUndo()) w->document()->undoStack()->undo();
    QCOMPARE(w->document()->spec().bodies.size(), std::size_t(0));
  }

  void newAndOpenLeaveNoResultOfTheOldModel() {
    QVERIFY(w->openFile(kCart));
    linearizeAndRun();
    w->linearizeView()->selectMode(0);  // a mode animated in the 3-D view
    QVERIFY(w->isAnimatingMode());
    QVERIFY(w->newModel());
    verifyNoResult();
    // Open
    QVERIFY(w->openFile(kCart));
    linearizeAndRun();
    QVERIFY(w->openFile(kPendulum));
    verifyNoResult();
    // a simulation still running when another model is opened: what it delivers later is dropped
    SimulateView* sv = w->simulateView();
    sv->endTimeSpin()->setValue(5000);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return sv->progressBar()->value() > 0; }, 30000));
    w->document()->undoStack()->setClean();
    QVERIFY(w->openFile(kCart));
    QVERIFY(QTest::qWaitFor([&] { return !sv->isRunning(); }, 30000));
    QTest::qWait(100);
    QCOMPARE(finished.count(), 0);
    verifyNoResult();
    QVERIFY(sv->runButton()->isEnabled());
  }

  void anEditMarksTheResultsOutOfDate() {
    QVERIFY(w->openFile(kCart));
    linearizeAndRun();
    w->selectElement(ElementId{ElementKind::Body, 1});
    QLineEdit* mass = qobject_cast<QLineEdit*>(props()->editorFor("mass"));
    QVERIFY(mass);
    mass->setFocus();
    mass->selectAll();
    QTest::keyClicks(mass, "12");
    QTest::keyClick(mass, Qt::Key_Return);
    QCOMPARE(w->document()->spec().bodies[1].mass, 12.0);
    LinearizeView* lv = w->linearizeView();
    SimulateView* sv = w->simulateView();
    QVERIFY(lv->isStale());
    QVERIFY(lv->findChild<QLabel*>("linearizeStale")->isVisibleTo(lv));
    QVERIFY(!lv->matrixView(0)->isEnabled());  // greyed, still readable
    QVERIFY(sv->isStale());
    QVERIFY(sv->findChild<QLabel*>("simulateStale")->isVisibleTo(sv));
    QVERIFY(sv->saveResultsButton()->isEnabled());  // the run itself can still be saved
    // linearizing again makes it current
    QVERIFY(lv->linearize());
    QVERIFY(!lv->findChild<QLabel*>("linearizeStale")->isVisibleTo(lv));
    QVERIFY(lv->matrixView(0)->isEnabled());
  }

  // typed values the model cannot hold are refused at the field, with the reason, and never reach the model
  void invalidValuesAreRefusedAtTheField() {
    QVERIFY(w->openFile(kCart));
    w->selectElement(ElementId{ElementKind::Body, 1});
    const double mass = w->document()->spec().bodies[1].mass;
    const int steps = w->document()->undoStack()->count();
    auto type = [&](const QString& field, const QString& text) {
      QLineEdit* e = qobject_cast<QLineEdit*>(props()->editorFor(field));
      QVERIFY(e);
      e->setFocus();
      e->selectAll();
      QTest::keyClicks(e, text);
      QTest::keyClick(e, Qt::Key_Return);
    };
    const QStringList bad{"inf", "-inf", "nan", "1e400", "abc", "1, 2", "-3"};
    for (const QString& text : bad) {
      type("mass", text);
      QCOMPARE(w->document()->spec().bodies[1].mass, mass);
      QCOMPARE(w->document()->undoStack()->count(), steps);
      QVERIFY2(w->document()->model(), qPrintable(text));  // the model still compiles: nothing reached it
      QCOMPARE(props()->markedField(), QString("mass"));
      QVERIFY2(props()->errorText().startsWith("mass: "), qPrintable(props()->errorText()));
      QVERIFY(props()->findChild<QLabel*>("propertyError")->isVisibleTo(props()));
      QVERIFY(props()->editorFor("mass")->styleSheet().contains("#ffd0d0"));
      // the field keeps what was typed (to correct it), marked
      QCOMPARE(qobject_cast<QLineEdit*>(props()->editorFor("mass"))->text(), text);
    }
    QVERIFY(props()->errorText().contains("non-negative mass"));  // "-3": the reader's reason
    type("mass", "nan");
    QVERIFY2(props()->errorText().contains("not a finite number"), qPrintable(props()->errorText()));
    // a vector field given the wrong number of values
    type("com", "1, 2");
    QCOMPARE(props()->markedField(), QString("com"));
    QCOMPARE(w->document()->undoStack()->count(), steps);
    // a good value: taken, and every mark and error goes
    type("mass", "12");
    QCOMPARE(w->document()->spec().bodies[1].mass, 12.0);
    QCOMPARE(props()->markedField(), QString());
    QCOMPARE(props()->errorText(), QString());
    QVERIFY(!w->statusBar()->currentMessage().startsWith("Error:"));
  }

  // Linearize, Export, Run and Cancel in a menu and the toolbar, with shortcuts; Help; the icon
  void actionsWhereUsersLook() {
    QVERIFY(w->openFile(kCart));
    QAction* lin = w->linearizeAction();
    QAction* run = w->runAction();
    QAction* cancel = w->cancelAction();
    QVERIFY(lin && run && cancel);
    QCOMPARE(lin->shortcut(), QKeySequence(Qt::CTRL | Qt::Key_L));
    QCOMPARE(run->shortcut(), QKeySequence(Qt::Key_F5));
    QCOMPARE(cancel->shortcut(), QKeySequence(Qt::SHIFT | Qt::Key_F5));
    QToolBar* tb = w->findChild<QToolBar*>("mainToolbar");
    QVERIFY(tb->actions().contains(lin) && tb->actions().contains(run) && tb->actions().contains(cancel));
    QStringList menus;
    for (QAction* a : w->menuBar()->actions()) menus << a->text();
    QVERIFY2(menus.contains("&Analysis") && menus.contains("&Help"), qPrintable(menus.join(",")));
    // the shortcut does what it says (a person pressing Ctrl+L in the window)
    QVERIFY(!w->linearizeView()->result());
    w->activateWindow();
    w->modelTree()->setFocus();
    QTest::keyClick(w.get(), Qt::Key_L, Qt::ControlModifier);
    QTRY_VERIFY(w->linearizeView()->result());
    QVERIFY(w->messages()->toPlainText().contains("Linearized about"));
    // F5 runs, Cancel follows the run
    QVERIFY(!cancel->isEnabled());
    w->simulateView()->endTimeSpin()->setValue(2000);
    QSignalSpy finished(w->simulateView(), &SimulateView::runFinished);
    QTest::keyClick(w.get(), Qt::Key_F5);
    QTRY_VERIFY(w->simulateView()->isRunning() || finished.count() > 0);
    QVERIFY(cancel->isEnabled() && !run->isEnabled());
    QTRY_VERIFY(w->simulateView()->progressBar()->value() > 0);  // integrating (a Cancel in the setup leaves no result)
    cancel->trigger();
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, 30000);
    QVERIFY(w->simulateView()->result() && w->simulateView()->result()->cancelled);
    QVERIFY(!cancel->isEnabled() && run->isEnabled());
    // the window icon comes from the library's resources
    QVERIFY(QFile::exists(":/codyna/codyna.svg"));
    QVERIFY(!w->windowIcon().isNull());
    QVERIFY(QFileInfo(MainWindow::documentationUrl().toLocalFile()).exists());
  }

  // Save As without ".json" writes a file Open's filter shows
  void saveAsAddsTheSuffix() {
    QVERIFY(w->openFile(kCart));
    QTemporaryDir dir;
    QVERIFY(w->saveFileAs(dir.filePath("mine")));
    QVERIFY(QFileInfo::exists(dir.filePath("mine.json")));
    QVERIFY(!QFileInfo::exists(dir.filePath("mine")));
    QCOMPARE(w->document()->filePath(), QFileInfo(dir.filePath("mine.json")).absoluteFilePath());
  }

  // Save As into another folder rewrites a tire's relative .tir path (study_rebase_paths); Undo
  // and Redo after it bring back edits made before it with their paths rewritten too, so that the
  // tire still reads its own file and not a namesake beside the new file (here another tire:
  // PacejkaBook_Defaults.tir, radius 0.3135 m, against the sedan's 0.393581 m)
  void undoAfterSaveAsKeepsTheTireFile() {
    QTemporaryDir tmp;
    QDir root(tmp.path());
    QVERIFY(root.mkpath("a/tires") && root.mkpath("b/deeper/tires"));
    const QString tir = "tires/MagicFormula61_Paramerters.tir";
    QVERIFY(QFile::copy(QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json"), root.filePath("a/sedan.json")));
    QVERIFY(QFile::copy(QStringLiteral(CODYNA_EXAMPLES_DIR "/") + tir, root.filePath("a/" + tir)));
    QVERIFY(QFile::copy(QStringLiteral(CODYNA_TEST_DATA_DIR "/tires/PacejkaBook_Defaults.tir"), root.filePath("b/deeper/" + tir)));
    QVERIFY(w->openFile(root.filePath("a/sedan.json")));
    Document* doc = w->document();
    const auto radius = [doc] { return doc->model() ? doc->model()->tires.at(0).unloaded_radius : -1.0; };
    const auto file = [doc] { return doc->spec().effects.at(3).file; };  // tire_fl
    QCOMPARE(doc->spec().effects.at(3).name, std::string("tire_fl"));
    QCOMPARE(file(), tir.toStdString());
    QCOMPARE(radius(), 0.393581);
    QVERIFY(doc->edit("chassis mass", [](ModelSpec& m) { m.bodies.at(0).mass = 1400; }));
    QVERIFY(doc->edit("wheel_fl mass", [](ModelSpec& m) { m.bodies.at(8).mass = 21; }));
    QVERIFY(w->saveFileAs(root.filePath("b/deeper/sedan.json")));
    const std::string moved = "../../a/" + tir.toStdString();
    QCOMPARE(file(), moved);
    QCOMPARE(radius(), 0.393581);
    doc->undoStack()->undo();  // the wheel's mass back: the tire as it was named before the move
    QCOMPARE(doc->spec().bodies.at(8).mass, 20.0);
    QCOMPARE(file(), moved);
    QCOMPARE(radius(), 0.393581);
    doc->undoStack()->undo();
    QCOMPARE(doc->spec().bodies.at(0).mass, 1350.0);
    QCOMPARE(file(), moved);
    QCOMPARE(radius(), 0.393581);
    doc->undoStack()->redo();
    doc->undoStack()->redo();
    QCOMPARE(doc->spec().bodies.at(8).mass, 21.0);
    QCOMPARE(file(), moved);
    QCOMPARE(radius(), 0.393581);
    QVERIFY(doc->undoStack()->isClean());
    // saved back beside the first file: the path is short again, and Undo still reads it
    doc->undoStack()->undo();
    QVERIFY(w->saveFileAs(root.filePath("a/again.json")));
    QCOMPARE(file(), tir.toStdString());
    doc->undoStack()->undo();
    QCOMPARE(file(), tir.toStdString());
    QCOMPARE(radius(), 0.393581);
    doc->undoStack()->setClean();
  }

  // a zero eigenvalue has no damping ratio: "-" in the mode table, not -1
  void zeroEigenvalueHasNoDamping() {
    LinearSystem s;
    s.A = Eigen::Matrix2d{{0.0, 1.0}, {0.0, -2.0}};  // a free mass with viscous damping: s = 0 and s = -2
    s.B = Eigen::Vector2d(0, 1);
    s.C = Eigen::RowVector2d(1, 0);
    s.D = Eigen::MatrixXd::Zero(1, 1);
    s.state_names = {"x", "xdot"};
    const ModalAnalysis modal = modal_analysis(s);
    ModeTableModel m;
    m.setModes(modal);
    QCOMPARE(m.rowCount(), 2);
    QStringList damping;
    for (int r = 0; r < 2; ++r) damping << m.index(r, ModeTableModel::DampingRatio).data().toString();
    damping.sort();
    QCOMPARE(damping, QStringList({"-", "1"}));
  }

  // the window fits a 1024 x 700 screen; docks and splitters come back as they were left
  void fitsSmallScreensAndRemembersItsLayout() {
    QVERIFY(w->openFile(kCart));
    w->resize(1024, 700);
    QTRY_COMPARE(w->size(), QSize(1024, 700));
    QVERIFY2(w->minimumSizeHint().height() <= 700, qPrintable(QString::number(w->minimumSizeHint().height())));
    QVERIFY2(w->minimumSizeHint().width() <= 1024, qPrintable(QString::number(w->minimumSizeHint().width())));
    w->resize(1500, 950);
    QTRY_COMPARE(w->size(), QSize(1500, 950));
    auto* centre = w->findChild<QSplitter*>("centreSplitter");
    QVERIFY(centre);
    centre->setSizes({200, 600});
    const QList<int> sizes = centre->sizes();
    w->saveLayout();
    auto second = std::make_unique<MainWindow>();
    second->show();
    QVERIFY(QTest::qWaitForWindowExposed(second.get()));
    QCOMPARE(second->size(), QSize(1500, 950));
    QCOMPARE(second->findChild<QSplitter*>("centreSplitter")->sizes(), sizes);
    QSettings().clear();  // the next test starts from the defaults
  }

  // every field a person can change in the analysis views, the panels and the property editor
  // says what it is: a tooltip on it (the meaning and the unit), none left blank
  void everyFieldHasATooltip() {
    QVERIFY(w->openFile(kCart));
    w->selectElement(ElementId{ElementKind::Joint, 0});
    QStringList missing;
    const QList<QWidget*> roots{w->linearizeView(), w->simulateView(), w->findChild<ControlView*>(),
                                w->propertyEditor(), w->findChild<QDockWidget*>("plantInDock"),
                                w->findChild<QDockWidget*>("plantOutDock")};
    for (QWidget* root : roots) {
      QVERIFY(root);
      for (QWidget* c : root->findChildren<QWidget*>()) {
        const bool field = qobject_cast<QLineEdit*>(c) || qobject_cast<QComboBox*>(c) || qobject_cast<QAbstractSpinBox*>(c) ||
                           qobject_cast<QCheckBox*>(c) || qobject_cast<QPushButton*>(c) || qobject_cast<QAbstractItemView*>(c);
        if (!field || c->inherits("QComboBoxListView") || c->inherits("QComboBoxPrivateContainer") ||
            qobject_cast<QHeaderView*>(c) || c->inherits("QTableCornerButton") || !c->isEnabledTo(root->window()))
          continue;
        if (qobject_cast<QLineEdit*>(c) && qobject_cast<QAbstractSpinBox*>(c->parentWidget())) continue;  // a spin box's own editor
        if (qobject_cast<QLineEdit*>(c) && qobject_cast<QComboBox*>(c->parentWidget())) continue;
        // Qt shows the nearest tooltip up the parent chain (a table's cell widget shows the table's)
        bool shown = false;
        for (QWidget* p = c; p && !shown; p = p == root ? nullptr : p->parentWidget()) shown = !p->toolTip().trimmed().isEmpty();
        if (!shown)
          missing << QStringLiteral("%1 %2 '%3' in %4")
                         .arg(QString::fromLatin1(c->metaObject()->className()), c->objectName(),
                              qobject_cast<QAbstractButton*>(c) ? qobject_cast<QAbstractButton*>(c)->text() : QString(),
                              QString::fromLatin1(root->metaObject()->className()));
      }
    }
    for (const QString& m : missing) qWarning("no tooltip: %s", qPrintable(m));
    QVERIFY2(missing.isEmpty(), qPrintable(QString::number(missing.size()) + " fields without a tooltip (listed above)"));
  }

  // a ball joint's mode moves the 3-D view (its rotation states are tangent coordinates,
  // not entries of q): the pose leaves the operating point, quaternion unit, and comes back
  void ballJointModeAnimates() {
    QTemporaryDir dir;
    QFile in(QStringLiteral(CODYNA_EXAMPLES_DIR "/heavy_top.json"));
    QVERIFY(in.open(QIODevice::ReadOnly));
    nlohmann::json j = nlohmann::json::parse(in.readAll().toStdString());
    j["analysis"]["operating_point"] = "initial";  // a spinning top has no equilibrium
    const QString path = dir.filePath("top.json");
    QFile out(path);
    QVERIFY(out.open(QIODevice::WriteOnly));
    out.write(QByteArray::fromStdString(j.dump(2)));
    out.close();
    QVERIFY(w->openFile(path));
    QVERIFY(w->linearizeView()->linearize());
    const Eigen::VectorXd op = w->linearizeView()->result()->op.q;
    // a mode whose rotation part is not small against its rates
    const auto& modes = w->linearizeView()->modes().modes;
    int pick = -1;
    for (int k = 0; k < int(modes.size()) && pick < 0; ++k)
      if (modes[k].shape.head(3).cwiseAbs().maxCoeff() > 0.01) pick = k;
    QVERIFY(pick >= 0);
    w->linearizeView()->selectMode(pick);
    QVERIFY(w->isAnimatingMode());
    double farthest = 0;
    QElapsedTimer t;
    t.start();
    while (t.elapsed() < 1500) {
      QTest::qWait(40);
      const Eigen::VectorXd& q = w->view3d()->configuration();
      QCOMPARE(q.size(), op.size());
      QVERIFY(std::abs(q.norm() - 1.0) < 1e-12);
      farthest = std::max(farthest, (q - op).norm());
    }
    QVERIFY2(farthest > 0.05, qPrintable(QString::number(farthest)));  // 0.3 rad swings move a unit quaternion by ~0.15
    w->animateMode(-1, {});
    QCOMPARE(w->view3d()->configuration(), op);
    w->document()->undoStack()->setClean();
  }

  // the 3-D view shows the operating point after Linearize; the matrices copy as text that reads back exactly
  void operatingPointShownAndMatricesCopied() {
    QVERIFY(w->openFile(kCart));
    const Eigen::VectorXd q0 = w->document()->model()->q0;
    QVERIFY(std::abs(q0[1]) > 0.05);  // the example starts 0.1 rad off upright
    QVERIFY(w->linearizeView()->linearize());
    const Eigen::VectorXd& op = w->linearizeView()->result()->op.q;
    QVERIFY(std::abs(op[1]) < 1e-9);  // the upright equilibrium
    QCOMPARE(w->view3d()->configuration(), op);

    auto* view = qobject_cast<MatrixView*>(w->linearizeView()->matrixView(0));
    QVERIFY(view);
    const Eigen::MatrixXd& A = w->linearizeView()->result()->system.A;
    view->setFocus();
    view->selectAll();
    QTest::keyClick(view, Qt::Key_C, Qt::ControlModifier);
    const QStringList rows = QApplication::clipboard()->text().trimmed().split('\n');
    QCOMPARE(rows.size(), int(A.rows()));
    for (int r = 0; r < A.rows(); ++r) {
      const QStringList cells = rows[r].split('\t');
      QCOMPARE(cells.size(), int(A.cols()));
      for (int c = 0; c < A.cols(); ++c) QCOMPARE(cells[c].toDouble(), A(r, c));  // exact: 17 digits
    }
    // a block of the selection only
    view->clearSelection();
    view->selectionModel()->select(QItemSelection(view->model()->index(1, 2), view->model()->index(2, 3)), QItemSelectionModel::Select);
    QTest::keyClick(view, Qt::Key_C, Qt::ControlModifier);
    QCOMPARE(QApplication::clipboard()->text(), QString("%1\t%2\n%3\t%4\n")
                                                     .arg(A(1, 2), 0, 'g', 17).arg(A(1, 3), 0, 'g', 17)
                                                     .arg(A(2, 2), 0, 'g', 17).arg(A(2, 3), 0, 'g', 17));
    // MATLAB: A = [ ...; ... ]; with the names; CSV with a header of the state names
    const QString m = view->text(MatrixView::Format::Matlab);
    QVERIFY2(m.contains("A = [") && m.contains("];") && m.contains("cart_slider"), qPrintable(m));
    QCOMPARE(m.count(QLatin1Char(0x3b)), int(A.rows()) + 1);  // rows - 1 separators, the closing one, one in the comment
    const QStringList csv = view->text(MatrixView::Format::Csv).trimmed().split('\n');
    QCOMPARE(csv.size(), int(A.rows()) + 1);
    QVERIFY(csv[0].startsWith(",cart_slider,"));
    QCOMPARE(csv[1].split(',').at(1).toDouble(), A(0, 0));
  }

  // any recorded quantity can be plotted, and runs kept for comparison
  void anySignalPlottedAndRunsKept() {
    QVERIFY(w->openFile(kCart));
    SimulateView* sv = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sv);
    sv->endTimeSpin()->setValue(0.4);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return finished.count() == 1; }, 60000));
    const auto r = sv->result();
    SignalPlot* sp = sv->signalPlot();
    const QStringList names = SignalPlot::signalNames(*r);
    for (const char* n : {"cart_slider", "rod_pivot_dot", "kinetic energy [J]", "total energy [J]", "y: theta [rad]"})
      QVERIFY2(names.contains(n), qPrintable(names.join(" | ")));
    // the outputs are ticked at first; add the total energy
    QCOMPARE(sp->checked().size(), int(r->y.cols()));
    sp->setChecked("total energy [J]", true);
    QCOMPARE(sp->curveCount(), int(r->y.cols()) + 1);
    const std::vector<double> e = SignalPlot::signal(*r, "total energy [J]");
    QCOMPARE(int(e.size()), r->samples());
    for (int i = 0; i < r->samples(); i += 7) QCOMPARE(e[i], r->kinetic_energy[i] + r->potential_energy[i]);
    const std::vector<double> q = SignalPlot::signal(*r, "rod_pivot");
    for (int i = 0; i < r->samples(); i += 7) QCOMPARE(q[i], r->q(i, 1));
    // keep this run, run again: the kept run's curves are drawn too
    QTest::mouseClick(sp->findChild<QPushButton*>("keepRun"), Qt::LeftButton);
    QCOMPARE(sp->keptCount(), 1);
    sv->endTimeSpin()->setValue(0.6);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return finished.count() == 2; }, 60000));
    QCOMPARE(sp->checked().size(), int(r->y.cols()) + 1);  // the ticks stay
    QCOMPARE(sp->curveCount(), 2 * (int(r->y.cols()) + 1));
    // another model: nothing kept
    QVERIFY(w->newModel());
    QCOMPARE(sp->keptCount(), 0);
    QCOMPARE(sp->curveCount(), 0);
  }

  // the run's initial state apart from the operating point (issue 21, in the Simulate view)
  void initialStateApartFromTheOperatingPoint() {
    QVERIFY(w->openFile(kCart));
    SimulateView* sv = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sv);
    NameValueTable* init = sv->initialStateTable();
    QTest::mouseClick(init->addButton(), Qt::LeftButton);
    QCOMPARE(init->table()->rowCount(), 1);
    init->nameCombo(0)->setCurrentIndex(init->nameCombo(0)->findText("rod_pivot"));
    init->valueSpin(0)->setValue(0.2);
    const auto& initial = w->document()->spec().analysis.initial;
    QCOMPARE(initial.size(), std::size_t(1));
    QCOMPARE(QString::fromStdString(initial[0].first), QString("rod_pivot"));
    QCOMPARE(initial[0].second, 0.2);
    sv->endTimeSpin()->setValue(0.2);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return finished.count() == 1; }, 60000));
    QVERIFY(sv->result() && sv->result()->completed);
    QCOMPARE(sv->result()->q(0, 1), 0.2);  // the run starts at the initial state
    QVERIFY(w->linearizeView()->linearize());
    QVERIFY(std::abs(w->linearizeView()->result()->op.q[1]) < 1e-9);  // the operating point is still upright
  }

  // a run the window could not hold is refused before it starts, with the numbers (the monkey test
  // once filled 24 GB with runs of ten million samples)
  void aRunTooLongToHoldIsRefused() {
    QVERIFY(w->openFile(kCart));
    SimulateView* sv = w->simulateView();
    sv->endTimeSpin()->setValue(30000);  // at the example's 0.01 s output step: 3,000,001 samples
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(QTest::qWaitFor([&] { return finished.count() == 1; }, 60000));
    QVERIFY(!sv->result());
    QVERIFY2(sv->statusText().contains("more than the limit of 1e+06"), qPrintable(sv->statusText()));
    QVERIFY(sv->runButton()->isEnabled());
  }

  // a wheel turned over a field that was not clicked into scrolls, and changes nothing
  void wheelOverAnUnfocusedFieldChangesNothing() {
    SimulateView* sim = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sim);
    QComboBox* integrator = sim->integratorCombo();
    QTRY_VERIFY(integrator->isVisible());
    QCOMPARE(integrator->focusPolicy(), Qt::StrongFocus);  // a wheel gives it no focus
    const int before = integrator->currentIndex();
    const int edits = w->document()->undoStack()->count();
    w->setFocus();
    wheelOver(integrator, -3);
    wheelOver(integrator, 2);
    QCOMPARE(integrator->currentIndex(), before);
    QCOMPARE(w->document()->undoStack()->count(), edits);
    // spin boxes too
    const QList<QDoubleSpinBox*> spins = sim->findChildren<QDoubleSpinBox*>();
    QVERIFY(!spins.isEmpty());
    for (QDoubleSpinBox* s : spins) {
      if (!s->isVisible()) continue;
      QCOMPARE(s->focusPolicy(), Qt::StrongFocus);
      const double v = s->value();
      wheelOver(s, 1);
      QCOMPARE(s->value(), v);
    }
    QCOMPARE(w->document()->undoStack()->count(), edits);
    // once clicked into, the wheel is the field's again (the test can see a change)
    integrator->setFocus();
    QTRY_VERIFY(integrator->hasFocus());
    wheelOver(integrator, -1);
    QVERIFY(integrator->currentIndex() != before);
  }
};

QTEST_MAIN(EditingTest)
#include "editing_test.moc"
