// Smoke tests of codyna-gui through its real widgets, offscreen (no OpenGL: the
// 3-D view shows its placeholder). Dialogs are answered through the window's hooks.
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QProgressBar>
#include <QStatusBar>
#include <QDir>
#include <QLineEdit>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QSignalSpy>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QThread>
#include <QTimer>
#include "gui/sim_worker.hpp"
#include <QTreeView>

#include "gui/linearize_view.hpp"
#include "gui/main_window.hpp"
#include "gui/matrix_models.hpp"
#include "gui/plant_panel.hpp"
#include "gui/property_editor.hpp"
#include "gui/result_plots.hpp"
#include "gui/simulate_view.hpp"
#include "gui/view3d.hpp"
#include "io/mat_export.hpp"
#include "simulation/result.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");

// toggles the check box of row `row` of a plant panel the way a user does: select it, press Space
void toggle(PlantPanel* p, int row) {
  QTreeView* v = p->view();
  v->setFocus();
  v->setCurrentIndex(p->listModel()->index(row, 0));
  QTest::keyClick(v, Qt::Key_Space);
}

int rowOf(PlantPanel* p, const QString& name) { return static_cast<int>(p->listModel()->rows().indexOf(name)); }

bool waitFor(const std::function<bool()>& done, int ms = 60000) {
  QElapsedTimer t;
  t.start();
  while (!done() && t.elapsed() < ms) QTest::qWait(20);
  return done();
}

}  // namespace

class MainWindowTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;
  QTemporaryDir tmp;
  int answer = QMessageBox::Cancel;
  QStringList asked;

  void openCart() {
    QVERIFY(w->openFile(kCart));
    QCOMPARE(w->document()->filePath(), QFileInfo(kCart).absoluteFilePath());
    QVERIFY(w->document()->model());
  }

 private slots:
  void init() {
    QCoreApplication::setOrganizationName("codyna-test");
    QCoreApplication::setApplicationName("main_window_test");
    w = std::make_unique<MainWindow>();
    w->setQuestionHook([this](const QString& title, const QString&, int) {
      asked << title;
      return answer;
    });
    w->setFileHook([](const QString&, const QString&, const QString&, bool) { return QString(); });
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  }
  void cleanup() {
    w->document()->undoStack()->setClean();  // nothing to ask when closing
    w.reset();
  }

  void opensTheCartPendulum() {
    openCart();
    QVERIFY(w->windowTitle().startsWith("cart_pendulum.json"));
    QVERIFY(!w->isWindowModified());
    QVERIFY(!View3D::openGLAvailable());  // offscreen: the placeholder, no crash
    QVERIFY(!w->view3d()->grabImage().isNull());
    // the tree lists the bodies; selecting one shows its properties
    const QModelIndex rod = w->treeModel()->indexOf({ElementKind::Body, 1});
    QCOMPARE(rod.data().toString(), QString("rod"));
    w->modelTree()->setCurrentIndex(rod);
    QVERIFY(w->propertyEditor()->editorFor("mass"));
    QCOMPARE(qobject_cast<QLineEdit*>(w->propertyEditor()->editorFor("mass"))->text().toDouble(), 10.0);
    QVERIFY(w->recentFiles().contains(QFileInfo(kCart).absoluteFilePath()));
  }

  void panelsTickReorderAndExportEqualsTheCli() {
    openCart();
    PlantPanel* in = w->plantInPanel();
    PlantPanel* out = w->plantOutPanel();
    // start from nothing selected: untick what the example selects
    toggle(in, rowOf(in, "force"));
    toggle(out, rowOf(out, "h"));
    toggle(out, rowOf(out, "theta"));
    QVERIFY(w->document()->spec().plant.inputs.empty());
    QVERIFY(w->document()->spec().plant.outputs.empty());
    // tick one input and two outputs: h then theta_dot, then move theta_dot up
    toggle(in, rowOf(in, "force"));
    toggle(out, rowOf(out, "h"));
    toggle(out, rowOf(out, "theta_dot"));
    QCOMPARE(w->document()->spec().plant.inputs, std::vector<std::string>{"force"});
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"h", "theta_dot"}));
    out->view()->setCurrentIndex(out->listModel()->index(rowOf(out, "theta_dot"), 0));
    QTest::mouseClick(out->upButton(), Qt::LeftButton);
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"theta_dot", "h"}));
    QCOMPARE(out->listModel()->rows().mid(0, 2), (QStringList{"theta_dot", "h"}));
    QVERIFY(w->isWindowModified());

    // linearize at equilibrium through the Linearize view
    LinearizeView* lv = w->linearizeView();
    lv->operatingPointCombo()->setCurrentIndex(lv->operatingPointCombo()->findText("equilibrium", Qt::MatchContains));
    QCOMPARE(w->document()->spec().analysis.operating_point, std::string("equilibrium"));
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    const LinearSystem& sys = lv->result()->system;
    QCOMPARE(sys.ny(), 2);
    QCOMPARE(sys.output_names[0], std::string("theta_dot"));
    QCOMPARE(lv->matrixModel(2)->rowCount(), 2);  // C: outputs x states

    // save the selection, press Export, and compare with `codyna linearize` of the saved file
    const QString model = tmp.filePath("cart_selected.json");
    QVERIFY(w->saveFileAs(model));
    const QString gui_dir = tmp.filePath("gui_export"), cli_dir = tmp.filePath("cli_export");
    QSignalSpy exported(lv, &LinearizeView::exported);
    lv->exportDirEdit()->setText(gui_dir);
    emit lv->exportDirEdit()->editingFinished();
    QTest::mouseClick(lv->exportButton(), Qt::LeftButton);
    QCOMPARE(exported.count(), 1);
    QVERIFY(QFile::exists(gui_dir + "/cart_pendulum.mat"));
    QVERIFY(QFile::exists(gui_dir + "/cart_pendulum.m"));
    QVERIFY(w->statusBar()->currentMessage().contains("cart_pendulum.mat"));
    w->saveFile();  // the export folder is part of the study now
    QProcess cli;
    cli.start(CODYNA_CLI, {"linearize", model, "--out", cli_dir});
    QVERIFY(cli.waitForFinished(60000));
    QCOMPARE(cli.exitCode(), 0);
    const MatVariables a = read_mat_file((gui_dir + "/cart_pendulum.mat").toStdString());
    const MatVariables b = read_mat_file((cli_dir + "/cart_pendulum.mat").toStdString());
    for (const char* k : {"A", "B", "C", "D", "x0", "u0", "y0", "xdot0", "Ts"}) {
      QVERIFY2(a.matrices.at(k).size() == b.matrices.at(k).size(), k);
      QVERIFY2((a.matrices.at(k) - b.matrices.at(k)).cwiseAbs().maxCoeff() == 0.0, k);
    }
    QCOMPARE(a.strings.at("output_names"), (std::vector<std::string>{"theta_dot", "h"}));
    QCOMPARE(a.strings.at("output_names"), b.strings.at("output_names"));
    QCOMPARE(a.strings.at("state_names"), b.strings.at("state_names"));
    QFile ma(gui_dir + "/cart_pendulum.m"), mb(cli_dir + "/cart_pendulum.m");
    QVERIFY(ma.open(QIODevice::ReadOnly) && mb.open(QIODevice::ReadOnly));
    QCOMPARE(ma.readAll(), mb.readAll());
  }

  void simulationPlotsTheSamplesAndCancelKeepsThePartialResult() {
    openCart();
    SimulateView* sv = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sv);
    sv->endTimeSpin()->setValue(0.5);
    QCOMPARE(w->document()->spec().solver.t_end, 0.5);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    const auto r = sv->result();
    QVERIFY(r && r->completed);
    QCOMPARE(r->t.back(), 0.5);
    sv->plots()->flush();
    for (int k = 0; k < static_cast<int>(r->y.cols()); ++k) {
      const QList<QPointF> p = sv->plots()->outputPoints(k);
      QCOMPARE(p.size(), r->samples());
      for (int i = 0; i < r->samples(); ++i) {
        QCOMPARE(p[i].x(), r->t[i]);
        QCOMPARE(p[i].y(), r->y(i, k));
      }
    }
    // playback follows the result
    QVERIFY(w->playbackSlider()->isEnabled());
    QCOMPARE(w->playbackSlider()->maximum(), r->samples() - 1);
    w->playbackSlider()->setValue(10);
    QCOMPARE(w->playbackTime(), r->t[10]);

    // a long run, cancelled: the partial result stays
    sv->endTimeSpin()->setValue(5000);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return sv->progressBar()->value() > 0 || !sv->isRunning(); }));
    QTest::qWait(200);
    QTest::mouseClick(sv->cancelButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 2; }));
    const auto c = sv->result();
    QVERIFY(c && c->cancelled && !c->completed);
    QVERIFY(c->samples() > 1);
    QVERIFY(c->t.back() < 5000);
    QCOMPARE(w->playbackSlider()->maximum(), c->samples() - 1);
  }

  // the 3-D view's tire forces are those of the state it shows: the initial state on opening, the
  // operating point after Linearize (the sedan straight at 25 m/s: the four loads carry the weight,
  // the rear tires drive), and each playback sample's q and v
  void sedanTireForcesFollowTheStateShown() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json")));
    const auto m = w->document()->model();
    QVERIFY(m);
    View3D* view = w->view3d();
    QCOMPARE(view->velocities(), m->v0);
    QCOMPARE(view->tireContacts().size(), size_t(4));
    LinearizeView* lv = w->linearizeView();
    w->analysisTabs()->setCurrentWidget(lv);
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    const auto& op = lv->result()->op;
    QVERIFY(op.motion.has_value());
    QCOMPARE(view->configuration(), op.q);
    QCOMPARE(view->velocities(), op.v);
    double mass = 0, Fz = 0;
    for (int i = 1; i < m->nbodies; ++i) mass += m->mass[static_cast<size_t>(i)];
    for (const auto& c : view->tireContacts()) {
      QVERIFY(c.in_contact);
      Fz += c.Fz;
      // straight at 25 m/s: the fronts roll (drag, Fx < 0), the rears drive (Fx > 0), 20 to 200 N
      const bool rear = c.name == "tire_rl" || c.name == "tire_rr";
      QVERIFY2((rear ? c.Fx : -c.Fx) > 20 && std::abs(c.Fx) < 200, qPrintable(QString::fromStdString(c.name)));
    }
    const double mg = mass * m->gravity.norm();
    QVERIFY2(std::abs(Fz - mg) < 1e-6 * mg, qPrintable(QString::number(Fz, 'g', 12)));
    // a short run from the operating point (the file's study: the run starts there), played back
    SimulateView* sv = w->simulateView();
    w->analysisTabs()->setCurrentWidget(sv);
    sv->endTimeSpin()->setValue(0.05);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }, 120000));
    const auto r = sv->result();
    QVERIFY(r && r->completed && r->samples() > 3);
    w->playbackSlider()->setValue(2);
    QCOMPARE(w->playbackTime(), r->t[2]);
    QCOMPARE(view->configuration(), Eigen::VectorXd(r->q.row(2).transpose()));
    QCOMPARE(view->velocities(), Eigen::VectorXd(r->v.row(2).transpose()));
    QCOMPARE(view->tireContacts().size(), size_t(4));
  }

  void undoRedoAndRenameUpdatesThePlantLists() {
    openCart();
    QUndoStack* undo = w->document()->undoStack();
    // a property edit, undone and redone
    w->selectElement(ElementId{ElementKind::Body, 0});
    QVERIFY(w->propertyEditor()->applyText("mass", "25"));
    QCOMPARE(w->document()->spec().bodies[0].mass, 25.0);
    undo->undo();
    QCOMPARE(w->document()->spec().bodies[0].mass, 20.0);
    undo->redo();
    QCOMPARE(w->document()->spec().bodies[0].mass, 25.0);
    // rename the sensor theta in the tree (in-place editing): Plant/Out follows, in one undo step
    const int theta = find_element(w->document()->spec(), ElementKind::Sensor, "theta");
    const QModelIndex idx = w->treeModel()->indexOf({ElementKind::Sensor, theta});
    const int steps = undo->count();
    QVERIFY(w->treeModel()->setData(idx, "angle", Qt::EditRole));
    QCOMPARE(undo->count(), steps + 1);
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"h", "angle"}));
    QVERIFY(w->plantOutPanel()->listModel()->rows().contains("angle"));
    undo->undo();
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"h", "theta"}));
    QVERIFY(w->plantOutPanel()->listModel()->rows().contains("theta"));
    undo->redo();
    QCOMPARE(w->document()->spec().sensors[theta].name, std::string("angle"));
    // a duplicate name is refused with a message, nothing changes
    QVERIFY(!w->treeModel()->setData(idx, "h", Qt::EditRole));
    QVERIFY(w->messages()->toPlainText().contains("already named"));
    // removing a referenced element asks first; No keeps it
    w->selectElement(ElementId{ElementKind::Sensor, theta});
    answer = QMessageBox::No;
    QVERIFY(!w->removeSelected());
    QVERIFY(asked.last().contains("Remove"));
    QCOMPARE(find_element(w->document()->spec(), ElementKind::Sensor, "angle"), theta);
    answer = QMessageBox::Yes;
    QVERIFY(w->removeSelected());
    QCOMPARE(w->document()->spec().plant.outputs, std::vector<std::string>{"h"});
    undo->undo();
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"h", "angle"}));
  }

  void aModelErrorSelectsTheOffendingField() {
    openCart();
    const int pivot = find_element(w->document()->spec(), ElementKind::Joint, "rod_pivot");
    w->selectElement(ElementId{ElementKind::Joint, pivot});
    // a parent that does not exist reads fine but does not compile: the joint and its field are marked
    QVERIFY(w->propertyEditor()->applyText("parent", "nowhere"));
    QVERIFY(!w->document()->model());
    QCOMPARE(w->document()->errorPath(), QStringLiteral("/joints/%1/parent").arg(pivot));
    QCOMPARE(w->selectedElement(), (std::optional<ElementId>{ElementId{ElementKind::Joint, pivot}}));
    QCOMPARE(w->propertyEditor()->markedField(), QString("parent"));
    QVERIFY(w->messages()->toPlainText().contains("nowhere"));
    // a value the reader refuses is not applied at all
    QString error;
    QVERIFY(!w->propertyEditor()->applyText("axis", "0, 0, 0", &error));
    QVERIFY(error.contains("/axis"));
    w->document()->undoStack()->undo();
    QVERIFY(w->document()->model());
  }

  void unsavedChangesGuard() {
    openCart();
    w->selectElement(ElementId{ElementKind::Body, 0});
    QVERIFY(w->propertyEditor()->applyText("mass", "21"));
    QVERIFY(w->isWindowModified());
    asked.clear();
    answer = QMessageBox::Cancel;  // cancel: nothing happens
    QVERIFY(!w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/pendulum.json")));
    QCOMPARE(asked.size(), 1);
    QCOMPARE(w->document()->spec().bodies[0].mass, 21.0);
    QVERIFY(!w->close());  // closing asks too, and Cancel keeps the window
    QVERIFY(w->isVisible());
    answer = QMessageBox::Discard;  // discard: the other model opens
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/pendulum.json")));
    QCOMPARE(w->document()->spec().name, std::string("pendulum"));
  }

  void malformedFileLeavesTheDocumentIntact() {
    openCart();
    const QString bad = tmp.filePath("bad.json");
    QFile f(bad);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write("{\"name\": \"broken\", \"bodies\": [ }");
    f.close();
    QVERIFY(!w->openFile(bad));
    QCOMPARE(w->document()->spec().name, std::string("cart_pendulum"));
    QCOMPARE(w->document()->filePath(), QFileInfo(kCart).absoluteFilePath());
    QVERIFY(w->messages()->toPlainText().contains("bad.json"));
    QVERIFY(w->messages()->toPlainText().contains("invalid JSON"));
  }

  void saveAsCloseReopenRestoresTheSession() {
    openCart();
    toggle(w->plantOutPanel(), rowOf(w->plantOutPanel(), "theta_dot"));
    LinearizeView* lv = w->linearizeView();
    lv->methodCombo()->setCurrentIndex(lv->methodCombo()->findText("fd-central", Qt::MatchContains));
    lv->operatingPointCombo()->setCurrentIndex(lv->operatingPointCombo()->findText("trim", Qt::MatchContains));
    SimulateView* sv = w->simulateView();
    sv->controllerCombo()->setCurrentIndex(sv->controllerCombo()->findText("LQR", Qt::MatchContains));
    sv->endTimeSpin()->setValue(3.5);
    const StudySpec study = w->document()->spec().analysis;
    QCOMPARE(study.method, std::string("fd-central"));
    QCOMPARE(study.operating_point, std::string("trim"));
    QCOMPARE(study.controller, std::string("lqr"));
    const QString path = tmp.filePath("session.json");
    QVERIFY(w->saveFileAs(path));
    QVERIFY(!w->isWindowModified());
    QVERIFY(w->close());
    w = std::make_unique<MainWindow>();
    w->show();
    QVERIFY(w->openFile(path));
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"h", "theta", "theta_dot"}));
    QCOMPARE(w->document()->spec().analysis, study);
    QCOMPARE(w->document()->spec().solver.t_end, 3.5);
    QVERIFY(w->linearizeView()->methodCombo()->currentText().contains("fd-central"));
    QVERIFY(w->linearizeView()->operatingPointCombo()->currentText().contains("trim"));
    QVERIFY(w->simulateView()->controllerCombo()->currentText().contains("LQR"));
    QCOMPARE(w->simulateView()->endTimeSpin()->value(), 3.5);
  }

  // the GUI never blocks: a Bricard run integrates on the worker thread while the GUI thread's
  // event loop keeps turning (its longest stall is what codyna_gui_stall_bench reports)
  void eventLoopRunsDuringALongBricardSimulation() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/bricard.json")));
    SimulateView* sv = w->simulateView();
    sv->endTimeSpin()->setValue(10);
    QSignalSpy finished(sv, &SimulateView::runFinished);
    QTimer tick;
    int ticks = 0;
    qint64 longest = 0, last = 0;
    QElapsedTimer clock;
    connect(&tick, &QTimer::timeout, [&] {
      const qint64 now = clock.elapsed();
      longest = std::max(longest, now - last);
      last = now;
      ++ticks;
    });
    clock.start();
    tick.start(5);
    QTest::mouseClick(sv->runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }, 120000));
    tick.stop();
    const auto r = sv->result();
    QVERIFY(r && r->completed);
    QCOMPARE(r->t.back(), 10.0);
    QVERIFY(sv->worker()->integratorThread() != nullptr);
    QVERIFY(sv->worker()->integratorThread() != QThread::currentThread());
    // the timer kept firing through the run: at least a fifth of the 5 ms ticks that fit in it
    QVERIFY2(ticks >= clock.elapsed() / 25, qPrintable(QString("%1 ticks in %2 ms").arg(ticks).arg(clock.elapsed())));
    qInfo("Bricard 10 s: %d timer ticks in %lld ms, longest gap %lld ms", ticks, clock.elapsed(), longest);
    sv->plots()->flush();
    QCOMPARE(sv->plots()->outputPoints(0).size(), r->samples());
  }

  void failedSaveKeepsTheDocumentModified() {
    openCart();
    w->selectElement(ElementId{ElementKind::Body, 0});
    QVERIFY(w->propertyEditor()->applyText("mass", "22"));
    QVERIFY(!w->saveFileAs("/nonexistent-folder/x.json"));
    QVERIFY(w->isWindowModified());
    QVERIFY(w->messages()->toPlainText().contains("Not saved"));
  }
};

QTEST_MAIN(MainWindowTest)
#include "main_window_test.moc"
