// The Linearize and Simulate views and the simulation worker, through their real
// widgets, offscreen (QT_QPA_PLATFORM=offscreen):
//  - the study widgets write the Document (one undo step each) and follow it back;
//  - Linearize at the cart-pendulum's upright equilibrium gives the paper's closed
//    form; mode selection is shared by the table and the pole map and announced;
//  - Export writes what `codyna linearize --out DIR` writes (byte-equal NAME.m,
//    equal matrices in NAME.mat);
//  - a run plots exactly the simulated samples, the integrator runs on the worker
//    thread, batches arrive at a bounded rate and lose nothing; cancel keeps the
//    partial result; a failing setup is reported, not a crash; results save;
//  - the steady-state search set in the Linearize view (a coordinate held, an input
//    solved) gives what the core gives for the same study; the core's refusals are
//    shown, not taken; a reference set in the Simulate view is saved, reloaded,
//    undone and redone.
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QProcess>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalSpy>
#include <QTableView>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QPlainTextEdit>
#include <QTabWidget>
#include <QTest>
#include <QThread>
#include <QUndoStack>
#include <cmath>
#include <functional>

#include "drive.hpp"
#include "gui/document.hpp"
#include "gui/wheel_guard.hpp"
#include "gui/linearize_view.hpp"
#include "gui/matrix_models.hpp"
#include "gui/pole_map.hpp"
#include "gui/result_plots.hpp"
#include "gui/sim_worker.hpp"
#include "gui/simulate_view.hpp"
#include "gui/study_widgets.hpp"
#include "io/model_file.hpp"
#include "study/files.hpp"
#include "study/jobs.hpp"
#include "study/tools.hpp"
#include "study/workflow.hpp"
#include "io/mat_export.hpp"
#include "io/results_file.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");
const QString kBricard = QStringLiteral(CODYNA_EXAMPLES_DIR "/bricard.json");
const QString kFourBar = QStringLiteral(CODYNA_EXAMPLES_DIR "/four_bar.json");

bool waitFor(const std::function<bool()>& done, int ms = 60000) {
  QElapsedTimer t;
  t.start();
  while (!done() && t.elapsed() < ms) QTest::qWait(10);
  return done();
}

int headerRow(const QAbstractItemModel* m, const QString& name, Qt::Orientation o) {
  const int n = o == Qt::Vertical ? m->rowCount() : m->columnCount();
  for (int i = 0; i < n; ++i)
    if (m->headerData(i, o, Qt::DisplayRole).toString() == name) return i;
  return -1;
}

double entry(const MatrixTableModel* m, const QString& row, const QString& col) {
  const int r = headerRow(m, row, Qt::Vertical), c = col.isEmpty() ? 0 : headerRow(m, col, Qt::Horizontal);
  if (r < 0 || c < 0) return std::nan("");
  return m->data(m->index(r, c), Qt::UserRole).toDouble();
}

bool relClose(double a, double b, double rel = 1e-9) { return std::abs(a - b) <= rel * std::abs(b); }

const BodySpec& body(const ModelSpec& s, const std::string& name) {
  for (const auto& b : s.bodies)
    if (b.name == name) return b;
  throw std::runtime_error("no body " + name);
}

void setLine(QLineEdit* e, const QString& text) {
  e->setText(text);
  emit e->editingFinished();
}

QByteArray readAll(const QString& path) {
  QFile f(path);
  return f.open(QIODevice::ReadOnly) ? f.readAll() : QByteArray();
}

}  // namespace

class ViewsTest : public QObject {
  Q_OBJECT
  QTemporaryDir tmp;

 private slots:
  void initTestCase() { QVERIFY(tmp.isValid()); }

  // ---------------------------------------------------------------- Linearize

  void linearizeGivesThePapersClosedForm() {
    Document doc;
    QString err;
    QVERIFY2(doc.load(kCart, &err), qPrintable(err));
    LinearizeView view(&doc);
    view.resize(1400, 900);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));

    // the paper's values, as the example file has them
    const ModelSpec& spec = doc.spec();
    const double m2 = body(spec, "cart").mass, m3 = body(spec, "rod").mass, l3 = 2 * body(spec, "rod").com.y();
    const double g = -spec.effects.at(0).g.y();
    QCOMPARE(m2, 20.0);
    QCOMPARE(m3, 10.0);
    QCOMPARE(l3, 2.0);
    QCOMPARE(g, 9.81);

    // operating point through the combo: initial, then equilibrium (each one undo step)
    QComboBox* op = view.operatingPointCombo();
    const int before = doc.undoStack()->count();
    op->setCurrentIndex(op->findData("initial"));
    QCOMPARE(doc.spec().analysis.operating_point, std::string("initial"));
    op->setCurrentIndex(op->findData("equilibrium"));
    QCOMPARE(doc.spec().analysis.operating_point, std::string("equilibrium"));
    QCOMPARE(doc.undoStack()->count(), before + 2);

    QSignalSpy linearized(&view, &LinearizeView::linearized);
    QTest::mouseClick(view.linearizeButton(), Qt::LeftButton);
    QCOMPARE(linearized.count(), 1);
    QVERIFY(view.result());
    QVERIFY(!view.isStale());
    QCOMPARE(view.result()->op.kind, std::string("equilibrium"));
    QVERIFY(view.operatingPointLabel()->text().contains("equilibrium"));

    // A, B as shown in the tables, found by state names
    const MatrixTableModel* A = view.matrixModel(0);
    const MatrixTableModel* B = view.matrixModel(1);
    QCOMPARE(A->rowCount(), 4);
    QCOMPARE(A->columnCount(), 4);
    const double den = 4 * m2 + m3;
    const double a23 = entry(A, "cart_slider_dot", "rod_pivot"), a43 = entry(A, "rod_pivot_dot", "rod_pivot");
    QVERIFY2(relClose(a23, -3 * m3 * g / den), qPrintable(QString::number(a23, 'g', 17)));
    QVERIFY2(relClose(a43, 6 * (m2 + m3) * g / (den * l3)), qPrintable(QString::number(a43, 'g', 17)));
    QVERIFY(relClose(entry(B, "cart_slider_dot", "force"), 4 / den));
    QVERIFY(relClose(entry(B, "rod_pivot_dot", "force"), -6 / (l3 * den)));
    QVERIFY(std::abs(entry(A, "cart_slider_dot", "cart_slider")) < 1e-12);  // a neutral cart position
    QCOMPARE(view.matrixModel(2)->rowCount(), 2);                         // C: h, theta
    QCOMPARE(view.matrixModel(3)->columnCount(), 1);                      // D: 1 input

    // the result follows the document: a change marks it stale, undo does not bring it back
    view.methodCombo()->setCurrentIndex(view.methodCombo()->findData("fd-central"));
    QCOMPARE(doc.spec().analysis.method, std::string("fd-central"));
    QVERIFY(view.isStale());
    doc.undoStack()->undo();
    QCOMPARE(doc.spec().analysis.method, std::string("exact"));
    QCOMPARE(view.methodCombo()->currentData().toString(), QString("exact"));
  }

  // operating point steady on the single-track car: a turn set in the view's fields (typed, as a
  // person does), the drive force freed by its check box; the result says the motion and the
  // handling numbers, the same as the study's
  void aSteadyTurnIsSetInTheFieldsAndLinearized() {
    WheelGuard::install();  // as codyna-gui's main window does
    Document doc;
    QVERIFY(doc.load(QStringLiteral(CODYNA_EXAMPLES_DIR "/single_track_car.json")));
    LinearizeView view(&doc);
    view.show();
    QCOMPARE(view.operatingPointCombo()->currentData().toString(), QString("steady"));
    QVERIFY(view.steadySpeedSpin()->isEnabled());
    QCOMPARE(view.steadySpeedSpin()->value(), 30.0);
    QVERIFY(!view.steadyTurnValueSpin()->isEnabled());  // straight
    // a wheel turned over the closed combo does not change it (the view's wheel guard), the popup picks
    const int before_wheel = view.steadyTurnCombo()->currentIndex();
    drive::wheelOver(view.steadyTurnCombo(), -2);
    QCOMPARE(view.steadyTurnCombo()->currentIndex(), before_wheel);
    QVERIFY(drive::pickWithMouse(view.steadyTurnCombo(), QStringLiteral("path radius (m)")));
    QCOMPARE(view.steadyTurnCombo()->currentData().toString(), QString("radius"));
    QVERIFY(view.steadyTurnValueSpin()->isEnabled());
    QDoubleSpinBox* value = view.steadyTurnValueSpin();
    value->setFocus();
    value->selectAll();
    QTest::keyClicks(value, "120");
    QTest::keyClick(value, Qt::Key_Return);
    QVERIFY(doc.spec().analysis.steady.radius.has_value());
    QCOMPARE(*doc.spec().analysis.steady.radius, 120.0);
    // the free inputs offer every actuator at a steady motion: check steer and drive
    QListWidget* free = view.freeInputsList();
    for (const char* name : {"steer", "drive"}) {
      const auto items = free->findItems(QString::fromLatin1(name), Qt::MatchExactly);
      QCOMPARE(items.size(), 1);
      items.front()->setCheckState(Qt::Checked);
    }
    QCOMPARE(doc.spec().analysis.free_inputs, (std::vector<std::string>{"steer", "drive"}));
    QVERIFY(view.linearize());
    QVERIFY(view.result()->handling.has_value());
    QVERIFY(view.result()->lin.about_motion);
    const QString label = view.operatingPointLabel()->text();
    QVERIFY2(label.contains("Motion") && label.contains("understeer gradient"), qPrintable(label));
    // the same numbers as the study without the view
    const StudyLinearization direct = study_linearize(*doc.model());
    QCOMPARE(view.result()->handling->understeer_gradient, direct.handling->understeer_gradient);
    QCOMPARE(view.result()->op.u, direct.op.u);
    // every handling number in the Handling tab, as codyna linearize prints them; the tab goes with
    // a result that has none
    QTabWidget* tabs = view.resultTabs();
    const int handling = tabs->indexOf(view.handlingText());
    QVERIFY(tabs->isTabVisible(handling));
    QCOMPARE(view.handlingText()->toPlainText(), QString::fromStdString(study_handling_text(*direct.handling)));
    QVERIFY(view.handlingText()->toPlainText().contains("characteristic speed"));
    QVERIFY(doc.load(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    QVERIFY(!tabs->isTabVisible(handling));
    QVERIFY(view.handlingText()->toPlainText().isEmpty());
    QVERIFY(view.linearize());
    QVERIFY(!view.result()->handling.has_value());
    QVERIFY(!tabs->isTabVisible(handling));
  }

  // the steady motion's fields keep what the study says to the last digit: a lateral acceleration
  // of 3.92266 m/s^2 (0.4 g) and a yaw rate of 0.00012345 rad/s are shown and written back as they
  // are when another field of the steady motion changes (four decimals made them 3.9227 and 0.0001)
  void steadyFieldsKeepEveryDigit() {
    Document doc;
    QVERIFY(doc.load(QStringLiteral(CODYNA_EXAMPLES_DIR "/single_track_car.json")));
    StudySpec study = doc.spec().analysis;
    study.steady.lateral_acceleration = 3.92266;
    QVERIFY(doc.setStudy(study));
    LinearizeView view(&doc);
    view.show();
    QCOMPARE(view.steadyTurnValueSpin()->value(), 3.92266);
    QCOMPARE(view.steadyTurnValueSpin()->text(), QString("3.92266"));
    view.steadySpeedSpin()->setValue(31.25);
    QCOMPARE(doc.spec().analysis.steady.speed.value_or(0), 31.25);
    QCOMPARE(view.steadySpeedSpin()->text(), QString("31.25 m/s"));
    QCOMPARE(doc.spec().analysis.steady.lateral_acceleration.value_or(0), 3.92266);
    study = doc.spec().analysis;
    study.steady.lateral_acceleration.reset();
    study.steady.yaw_rate = 0.00012345;
    QVERIFY(doc.setStudy(study));
    QCOMPARE(view.steadyTurnValueSpin()->text(), QString("0.00012345"));
    view.steadySpeedSpin()->setValue(30);
    QCOMPARE(doc.spec().analysis.steady.yaw_rate.value_or(0), 0.00012345);
    // typed, as a person does
    QDoubleSpinBox* value = view.steadyTurnValueSpin();
    value->setFocus();
    value->selectAll();
    QTest::keyClicks(value, "0.000123456");
    QTest::keyClick(value, Qt::Key_Return);
    QCOMPARE(doc.spec().analysis.steady.yaw_rate.value_or(0), 0.000123456);
  }

  // The Linearize view says controllability and observability as codyna linearize prints them
  // (the same job): the heavy top about its initial state has modes its support's inputs cannot
  // move and its outputs cannot see (the CLI's text pinned in tests/data/pinned_outputs.json,
  // lin_initial_heavy_top); the cart-pendulum is controllable and observable
  void controllabilityAsTheCommandLineSaysIt() {
    Document doc;
    QVERIFY(doc.load(QStringLiteral(CODYNA_EXAMPLES_DIR "/heavy_top.json")));
    StudySpec study = doc.spec().analysis;
    study.operating_point = "initial";
    QVERIFY(doc.setStudy(study));
    LinearizeView view(&doc);
    view.show();
    QTest::mouseClick(view.linearizeButton(), Qt::LeftButton);
    QVERIFY(view.result());
    const QString shown = view.controllabilityLabel()->text();
    LinearizeRequest r;
    r.model = CODYNA_EXAMPLES_DIR "/heavy_top.json";
    const LinearizeJob job = study_linearize_job(r, doc.spec());
    QCOMPARE(shown, QString("Controllable from Plant/In: %1\nObservable from Plant/Out: %2")
                        .arg(QString::fromStdString(study_hidden_modes_text(job.uncontrollable)),
                             QString::fromStdString(study_hidden_modes_text(job.unobservable))));
    QVERIFY2(shown.contains("Controllable from Plant/In: no: lambda = 0 +/- 75.0334i (support.rx, support.rz)"), qPrintable(shown));
    QVERIFY(shown.contains("Observable from Plant/Out: no: "));
    Document cart;
    QVERIFY(cart.load(kCart));
    LinearizeView cart_view(&cart);
    QVERIFY(cart_view.linearize());
    QCOMPARE(cart_view.controllabilityLabel()->text(),
             QString("Controllable from Plant/In: yes, every mode\nObservable from Plant/Out: yes, every mode"));
  }

  // The run status says which actuators sat at a limit, as codyna simulate does (the same job,
  // saturation_text): the quarter bus's LQR force U saturates under a 5000 N road force step at
  // 0.1 s (tests/cli/compare_linear_exact.sh runs the same)
  void saturationIsSaid() {
    Document doc;
    QVERIFY(doc.load(QStringLiteral(CODYNA_TEST_DATA_DIR "/bus_suspension.json")));
    StudySpec study = doc.spec().analysis;
    DisturbanceSpec d;
    d.actuator = "road_force";
    d.time = 0.1;
    d.value = 5000;
    study.disturbances = {d};
    QVERIFY(doc.setStudy(study));
    SimulateView view(&doc);
    view.show();
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    QVERIFY(view.result() && view.result()->completed);
    SimulateRequest r;
    r.model = CODYNA_TEST_DATA_DIR "/bus_suspension.json";
    const SimulateJob job = study_simulate_job(r, doc.spec());
    QVERIFY(!job.saturation.empty());
    for (const Saturation& s : job.saturation) {
      const QString line = QStringLiteral("; saturation: ") + QString::fromStdString(saturation_text(s));
      QVERIFY2(view.statusText().contains(line), qPrintable(view.statusText() + "\nlacks " + line));
    }
    QVERIFY(view.statusText().contains("saturation: U at its limit from t = "));
  }

  void modeSelectionIsSharedByTheTableAndThePoleMap() {
    Document doc;
    QVERIFY(doc.load(kCart));
    LinearizeView view(&doc);
    view.resize(1400, 900);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    QVERIFY(view.linearize());
    const int n = static_cast<int>(view.modes().modes.size());
    QCOMPARE(n, 4);
    QCOMPARE(view.modeModel()->rowCount(), 4);
    QCOMPARE(view.poleMap()->poleCount(), 4);

    QSignalSpy spy(&view, &LinearizeView::modeSelected);
    // a click on the last row of the mode table
    QTableView* table = view.modeView();
    const QModelIndex last = view.modeModel()->index(n - 1, 1);
    table->scrollTo(last);
    QTest::mouseClick(table->viewport(), Qt::LeftButton, {}, table->visualRect(last).center());
    QCOMPARE(spy.count(), 1);
    const int idx = spy.at(0).at(0).toInt();
    QCOMPARE(idx, view.modeModel()->index(n - 1, 0).data(Qt::UserRole).toInt());
    const auto shape = spy.at(0).at(1).value<Eigen::VectorXcd>();
    const auto s = spy.at(0).at(2).value<std::complex<double>>();
    QCOMPARE(shape.size(), 4);
    QVERIFY((shape - view.modes().modes[idx].shape).norm() == 0.0);
    QCOMPARE(s, view.modes().modes[idx].s);
    QCOMPARE(view.poleMap()->selectedMode(), idx);
    QCOMPARE(view.selectedMode(), idx);

    // a click on another pole selects its row
    const int other = idx == 0 ? 1 : 0;
    // the four poles of the upright pendulum are distinct points (+-sqrt, 0, 0 are two at 0: pick a non-zero one)
    int target = -1;
    for (int i = 0; i < n && target < 0; ++i)
      if (i != idx && std::abs(view.modes().modes[i].eigenvalue) > 1e-6 &&
          view.poleMap()->poleAt(view.poleMap()->poleWidgetPosition(i), 3) == i)
        target = i;
    if (target < 0) target = other;
    QTest::mouseClick(view.poleMap(), Qt::LeftButton, {}, view.poleMap()->poleWidgetPosition(target));
    QCOMPARE(spy.count(), 2);
    QCOMPARE(spy.at(1).at(0).toInt(), target);
    QCOMPARE(view.modeView()->selectionModel()->currentIndex().row(), target);
    QCOMPARE(view.selectedMode(), target);

    // programmatic selection keeps both in sync too
    view.selectMode(idx);
    QCOMPARE(spy.count(), 3);
    QCOMPARE(view.poleMap()->selectedMode(), idx);
    QCOMPARE(view.modeView()->selectionModel()->currentIndex().row(), idx);
  }

  void exportEqualsTheCommandLine() {
    Document doc;
    QVERIFY(doc.load(kCart));
    LinearizeView view(&doc);
    view.show();
    QVERIFY(QFileInfo::exists(CODYNA_CLI));
    const QString guiDir = tmp.filePath("gui_export"), cliDir = tmp.filePath("cli_export");
    QSignalSpy exported(&view, &LinearizeView::exported);
    QString err;
    QVERIFY2(view.exportTo(guiDir, &err), qPrintable(err));  // stale (never linearized): linearizes first
    QVERIFY(view.result());
    QCOMPARE(exported.count(), 1);
    QCOMPARE(exported.at(0).at(0).toString(), guiDir + "/cart_pendulum.mat");
    QCOMPARE(exported.at(0).at(1).toString(), guiDir + "/cart_pendulum.m");

    QProcess cli;
    cli.start(CODYNA_CLI, {"linearize", QFileInfo(kCart).absoluteFilePath(), "--out", cliDir});
    QVERIFY(cli.waitForFinished(120000));
    QVERIFY2(cli.exitCode() == 0, cli.readAllStandardError().constData());

    const QByteArray ma = readAll(guiDir + "/cart_pendulum.m"), mb = readAll(cliDir + "/cart_pendulum.m");
    QVERIFY(!ma.isEmpty());
    QCOMPARE(ma, mb);
    const MatVariables a = read_mat_file((guiDir + "/cart_pendulum.mat").toStdString());
    const MatVariables b = read_mat_file((cliDir + "/cart_pendulum.mat").toStdString());
    for (const char* k : {"A", "B", "C", "D", "x0", "u0", "y0", "xdot0", "Ts"}) {
      QVERIFY2(a.matrices.count(k) && b.matrices.count(k), k);
      QVERIFY2(a.matrices.at(k).rows() == b.matrices.at(k).rows() && a.matrices.at(k).cols() == b.matrices.at(k).cols(), k);
      QVERIFY2(a.matrices.at(k) == b.matrices.at(k), k);
    }
    QCOMPARE(a.matrices.at("A").rows(), 4);
    QCOMPARE(a.strings.at("state_names"), b.strings.at("state_names"));
    QCOMPARE(a.strings.at("output_names"), b.strings.at("output_names"));
    // the exported A is the one shown
    QVERIFY(a.matrices.at("A") == view.matrixModel(0)->matrix());

    // a study change makes the shown result stale: export linearizes again, with Ts
    view.sampleTimeSpin()->setValue(0.01);
    QCOMPARE(doc.spec().analysis.discrete, 0.01);
    QVERIFY(view.isStale());
    const QString zohDir = tmp.filePath("zoh_export");
    QVERIFY(view.exportTo(zohDir, &err));
    QVERIFY(!view.isStale());
    QCOMPARE(view.result()->system.Ts, 0.01);
    QCOMPARE(read_mat_file((zohDir + "/cart_pendulum.mat").toStdString()).matrices.at("Ts")(0, 0), 0.01);
    QVERIFY(view.poleMap()->isDiscrete());

    // a failing export says why
    QFile blocker(tmp.filePath("not_a_dir"));
    QVERIFY(blocker.open(QIODevice::WriteOnly));
    blocker.close();
    QSignalSpy messages(&view, &LinearizeView::message);
    QVERIFY(!view.exportTo(tmp.filePath("not_a_dir/sub"), &err));
    QVERIFY(!err.isEmpty());
    QVERIFY(messages.count() >= 1);
  }

  void linearizeWidgetsWriteTheStudyAndFollowUndo() {
    Document doc;
    QVERIFY(doc.load(kCart));
    LinearizeView view(&doc);
    view.show();
    QUndoStack* undo = doc.undoStack();
    const StudySpec original = doc.spec().analysis;
    const int base = undo->count();

    // spin box steps merge into one undo step
    view.sampleTimeSpin()->setValue(0.1);
    view.sampleTimeSpin()->setValue(0.2);
    QCOMPARE(doc.spec().analysis.discrete, 0.2);
    QCOMPARE(undo->count(), base + 1);

    view.matVersionCombo()->setCurrentIndex(view.matVersionCombo()->findData("7.3"));
    QCOMPARE(doc.spec().analysis.mat_version, std::string("7.3"));
    view.operatingPointCombo()->setCurrentIndex(view.operatingPointCombo()->findData("time"));
    view.operatingTimeSpin()->setValue(1.5);
    QCOMPARE(doc.spec().analysis.operating_point, std::string("time=1.5"));
    QVERIFY(view.operatingTimeSpin()->isEnabled());
    setLine(view.exportDirEdit(), "out/plant");
    QCOMPARE(doc.spec().analysis.export_dir, std::string("out/plant"));
    setLine(view.exportNameEdit(), "cartpole");
    QCOMPARE(doc.spec().analysis.export_name, std::string("cartpole"));
    QVERIFY(!view.independentList()->isVisibleTo(&view));  // a tree: no choice of coordinates

    // undo all: the document and the widgets are back
    while (undo->count() > base && undo->canUndo() && undo->index() > base) undo->undo();
    QCOMPARE(doc.spec().analysis, original);
    QCOMPARE(view.sampleTimeSpin()->value(), 0.0);
    QCOMPARE(view.matVersionCombo()->currentData().toString(), QString("5"));
    QCOMPARE(view.operatingPointCombo()->currentData().toString(), QString("equilibrium"));
    QVERIFY(!view.operatingTimeSpin()->isEnabled());
    QCOMPARE(view.exportDirEdit()->text(), QString());
    // and redo brings the time point back into the widgets
    while (undo->canRedo()) undo->redo();
    QCOMPARE(view.operatingPointCombo()->currentData().toString(), QString("time"));
    QCOMPARE(view.operatingTimeSpin()->value(), 1.5);
    QCOMPARE(view.exportNameEdit()->text(), QString("cartpole"));
  }

  void closedLoopsOfferTheIndependentCoordinates() {
    Document doc;
    QVERIFY(doc.load(kFourBar));
    QVERIFY(doc.model());
    LinearizeView view(&doc);
    view.show();
    QListWidget* list = view.independentList();
    QVERIFY(list->isVisibleTo(&view));
    const std::vector<std::string> names = doc.model()->v_names;  // a copy: each edit recompiles the model
    QCOMPARE(list->count(), static_cast<int>(names.size()));
    QCOMPARE(doc.model()->dof(), 1);
    // choose the last coordinate as the independent one (a user's click on its check box)
    const QString chosen = QString::fromStdString(names.back());
    QListWidgetItem* item = list->item(list->count() - 1);
    QCOMPARE(item->text(), chosen);
    item->setCheckState(Qt::Checked);
    QCOMPARE(doc.spec().analysis.independent, std::vector<std::string>{names.back()});
    view.operatingPointCombo()->setCurrentIndex(view.operatingPointCombo()->findData("initial"));
    QVERIFY(view.linearize());
    QCOMPARE(view.result()->system.state_names.at(0), names.back());
    QCOMPARE(view.matrixModel(0)->headerData(0, Qt::Vertical).toString(), chosen);
    doc.undoStack()->undo();  // operating point
    doc.undoStack()->undo();  // independent
    QVERIFY(doc.spec().analysis.independent.empty());
    QCOMPARE(list->item(list->count() - 1)->checkState(), Qt::Unchecked);
  }


  // A person types a value into a row, then clicks Remove while the typing has the focus: the
  // row's spin box reports its last edit as it goes (the monkey found the handler reading the
  // half-removed row under ASan); the other row and the study stay whole.
  void removingTheRowBeingTypedIntoKeepsTheOthers() {
    Document doc;
    QVERIFY(doc.load(kCart));  // two coordinates: two rows can be held
    LinearizeView view(&doc);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(&view));  // focus is real: leaving the spin box commits its text
    NameValueTable* set = view.setTable();
    QTest::mouseClick(set->addButton(), Qt::LeftButton);
    QTest::mouseClick(set->addButton(), Qt::LeftButton);
    QCOMPARE(set->table()->rowCount(), 2);
    const QString kept = set->nameCombo(0)->currentText(), removed = set->nameCombo(1)->currentText();
    QVERIFY(kept != removed);
    QDoubleSpinBox* spin = set->valueSpin(1);
    set->table()->setCurrentCell(1, 1);
    spin->setFocus();
    QTRY_VERIFY(spin->hasFocus());
    spin->selectAll();
    QTest::keyClicks(spin, "0.7");  // typed, not yet committed: it commits as the focus leaves
    QVERIFY2(spin->text().contains("0.7"), qPrintable(spin->text()));
    QCOMPARE(doc.spec().analysis.set.size(), std::size_t(2));
    QTest::mouseClick(set->removeButton(), Qt::LeftButton);
    QCOMPARE(set->table()->rowCount(), 1);
    QCOMPARE(set->nameCombo(0)->currentText(), kept);
    const auto& held = doc.spec().analysis.set;
    QCOMPARE(held.size(), std::size_t(1));
    QCOMPARE(QString::fromStdString(held[0].first), kept);
    // and the remaining row still takes a typed value with Enter
    set->valueSpin(0)->setFocus();
    set->valueSpin(0)->selectAll();
    QTest::keyClicks(set->valueSpin(0), "1.25");
    QTest::keyClick(set->valueSpin(0), Qt::Key_Return);
    QCOMPARE(doc.spec().analysis.set[0].second, 1.25);
  }

  // The four-bar's crank held at 1.3 rad, its torque solved: the widgets write the study,
  // and Linearize gives what the core computes headless for the same study.
  void steadyStateSearchEqualsTheCore() {
    Document doc;
    QVERIFY(doc.load(kFourBar));
    LinearizeView view(&doc);
    view.show();
    QSignalSpy messages(&view, &LinearizeView::message);
    QCOMPARE(view.operatingPointCombo()->currentData().toString(), QString("equilibrium"));
    const int base = doc.undoStack()->index();

    NameValueTable* set = view.setTable();
    QTest::mouseClick(set->addButton(), Qt::LeftButton);
    QCOMPARE(set->table()->rowCount(), 1);
    QComboBox* name = set->nameCombo(0);
    QVERIFY(name->findText("pivot_A") >= 0);
    QVERIFY(name->findText("pivot_A_dot") >= 0);  // rates are offered too
    name->setCurrentIndex(name->findText("pivot_A"));
    const int stepsBefore = doc.undoStack()->index();
    set->valueSpin(0)->setValue(1.2);
    set->valueSpin(0)->setValue(1.3);  // stepping the value: one undo step
    QCOMPARE(doc.undoStack()->index(), stepsBefore + 1);
    QListWidget* inputs = view.freeInputsList();
    QCOMPARE(inputs->count(), 1);
    QCOMPARE(inputs->item(0)->text(), QString("crank_torque"));
    inputs->item(0)->setCheckState(Qt::Checked);

    const StudySpec& st = doc.spec().analysis;
    QCOMPARE(st.set, (std::vector<std::pair<std::string, double>>{{"pivot_A", 1.3}}));
    QCOMPARE(st.free_inputs, std::vector<std::string>{"crank_torque"});
    QCOMPARE(messages.count(), 0);

    // the core, headless, on the same study
    ModelSpec spec = load_model_spec(kFourBar.toStdString());
    spec.analysis.set = {{"pivot_A", 1.3}};
    spec.analysis.free_inputs = {"crank_torque"};
    const Model m = study_model(spec, kFourBar.toStdString());
    const StudyLinearization core = study_linearize(m);
    const int k = m.find_actuator("crank_torque");
    QVERIFY(k >= 0);
    const double torque = core.op.u[k];
    QVERIFY2(std::abs(torque) > 1.0, "holding the crank mid-stroke takes a torque");

    QVERIFY(view.linearize());
    const StudyLinearization& gui = *view.result();
    QCOMPARE(gui.op.kind, std::string("equilibrium"));
    QVERIFY2(relClose(gui.op.u[k], torque, 1e-9), qPrintable(QString("%1 vs %2").arg(gui.op.u[k], 0, 'g', 17).arg(torque, 0, 'g', 17)));
    const int iq = static_cast<int>(std::find(m.q_names.begin(), m.q_names.end(), "pivot_A") - m.q_names.begin());
    QCOMPARE(gui.op.q[iq], 1.3);  // held exactly
    QCOMPARE(gui.system.A.rows(), core.system.A.rows());
    QVERIFY((gui.system.A - core.system.A).cwiseAbs().maxCoeff() <= 1e-9 * (1 + core.system.A.cwiseAbs().maxCoeff()));
    QVERIFY((gui.system.B - core.system.B).cwiseAbs().maxCoeff() <= 1e-9 * (1 + core.system.B.cwiseAbs().maxCoeff()));
    // the offsets tab shows the torque solved
    QCOMPARE(gui.system.u0[0], gui.op.u[k]);

    // a second coordinate the loop cannot hold with the first: the core refuses, with its message
    const StudySpec before = doc.spec().analysis;
    const int steps = doc.undoStack()->index();
    QVERIFY(messages.count() >= 1 && messages.last().at(0).toString().startsWith("Linearized about"));  // the log
    messages.clear();
    QTest::mouseClick(set->addButton(), Qt::LeftButton);
    QCOMPARE(doc.spec().analysis, before);
    QCOMPARE(doc.undoStack()->index(), steps);
    QCOMPARE(set->table()->rowCount(), 1);
    QCOMPARE(messages.count(), 1);
    QVERIFY2(messages.at(0).at(0).toString().contains("/analysis/set"), qPrintable(messages.at(0).at(0).toString()));

    // output target and trim_free write the study too; undo takes everything back, the widgets follow
    QTest::mouseClick(view.targetsTable()->addButton(), Qt::LeftButton);
    QCOMPARE(doc.spec().analysis.output_targets.size(), std::size_t(1));
    QCOMPARE(doc.spec().analysis.output_targets[0].first, std::string("rocker_angle"));
    view.operatingPointCombo()->setCurrentIndex(view.operatingPointCombo()->findData("trim"));
    QVERIFY(view.trimFreeList()->isEnabled());
    view.trimFreeList()->item(0)->setCheckState(Qt::Checked);
    QCOMPARE(doc.spec().analysis.trim_free, std::vector<std::string>{view.trimFreeList()->item(0)->text().toStdString()});
    while (doc.undoStack()->index() > base) doc.undoStack()->undo();
    QCOMPARE(doc.spec().analysis, StudySpec{});
    QCOMPARE(set->table()->rowCount(), 0);
    QCOMPARE(view.targetsTable()->table()->rowCount(), 0);
    QCOMPARE(inputs->item(0)->checkState(), Qt::Unchecked);
    QCOMPARE(view.trimFreeList()->item(0)->checkState(), Qt::Unchecked);
    while (doc.undoStack()->canRedo()) doc.undoStack()->redo();
    QCOMPARE(set->table()->rowCount(), 1);
    QCOMPARE(set->nameCombo(0)->currentText(), QString("pivot_A"));
    QCOMPARE(set->valueSpin(0)->value(), 1.3);
    QCOMPARE(inputs->item(0)->checkState(), Qt::Checked);
  }

  // A step reference on the cart's position h: in the study, in the saved file, undone and redone;
  // the other controller settings land in the study too.
  void referencesAndControllerSettingsAreSavedAndUndone() {
    const QString path = tmp.filePath("cart_ref.json");
    QFile::remove(path);
    QVERIFY(QFile::copy(kCart, path));
    Document doc;
    QVERIFY(doc.load(path));
    SimulateView view(&doc);
    view.show();
    QSignalSpy messages(&view, &SimulateView::message);
    QUndoStack* undo = doc.undoStack();
    const int base = undo->index();

    SignalTable* refs = view.referencesTable();
    QTest::mouseClick(refs->addButton(), Qt::LeftButton);
    QCOMPARE(refs->table()->rowCount(), 1);
    QCOMPARE(refs->targetCombo(0)->currentText(), QString("h"));
    QCOMPARE(refs->typeCombo(0)->currentText(), QString("step"));
    QVERIFY(!refs->spin(0, SignalTable::Frequency)->isEnabled());
    refs->spin(0, SignalTable::Time)->setValue(1.0);
    refs->spin(0, SignalTable::Value)->setValue(0.2);
    SignalSpec step;
    step.output = "h";
    step.type = "step";
    step.time = 1.0;
    step.value = 0.2;
    QCOMPARE(doc.spec().analysis.references, std::vector<SignalSpec>{step});
    QCOMPARE(undo->index(), base + 2);  // the row added; the numbers typed merge into one step
    QCOMPARE(messages.count(), 0);
    // the core takes it: the run's setup follows h's reference
    QVERIFY(doc.model());
    const StudySimulation setup = study_simulation(*doc.model());
    QVERIFY(setup.controller);
    QVERIFY(setup.options.reference);
    QCOMPARE(setup.options.reference(2.0)[0], 0.2);  // h is the first Plant/Out: 0.2 after t = 1 s
    QCOMPARE(setup.options.reference(2.0)[1], setup.options.reference(0.5)[1]);  // theta stays at y0

    // the cart has no actuator outside Plant/In: nothing to disturb
    QTest::mouseClick(view.disturbancesTable()->addButton(), Qt::LeftButton);
    QCOMPARE(view.disturbancesTable()->table()->rowCount(), 0);
    // a table whose points do not parse is refused
    refs->typeCombo(0)->setCurrentIndex(refs->typeCombo(0)->findText("table"));
    QVERIFY(refs->dataEdit(0)->isEnabled());
    QCOMPARE(doc.spec().analysis.references.at(0).type, std::string("table"));
    refs->dataEdit(0)->setText("0 0; 1 x");
    refs->dataEdit(0)->setModified(true);
    emit refs->dataEdit(0)->editingFinished();
    QCOMPARE(messages.count(), 1);
    QVERIFY(doc.spec().analysis.references.at(0).points.empty());
    // times that do not increase: the core's reader refuses, its message (and field) is shown
    refs->dataEdit(0)->setText("0 0; 2 0.1; 1 0.2");
    refs->dataEdit(0)->setModified(true);
    emit refs->dataEdit(0)->editingFinished();
    QCOMPARE(messages.count(), 2);
    QVERIFY2(messages.at(1).at(0).toString().contains("/analysis/references/0/points/2"), qPrintable(messages.at(1).at(0).toString()));
    QVERIFY2(messages.at(1).at(0).toString().contains("increase"), qPrintable(messages.at(1).at(0).toString()));
    QVERIFY(doc.spec().analysis.references.at(0).points.empty());
    refs->dataEdit(0)->setText("0 0; 1 0.2");
    refs->dataEdit(0)->setModified(true);
    emit refs->dataEdit(0)->editingFinished();
    QCOMPARE(doc.spec().analysis.references.at(0).points, (std::vector<std::pair<double, double>>{{0, 0}, {1, 0.2}}));
    undo->undo();  // the points
    // a file signal is written once its file is named (the core refuses an empty one)
    const int before_file = undo->index();
    refs->typeCombo(0)->setCurrentIndex(refs->typeCombo(0)->findText("file"));
    QCOMPARE(undo->index(), before_file);
    QCOMPARE(messages.count(), 2);
    refs->dataEdit(0)->setText("ref.csv");
    refs->dataEdit(0)->setModified(true);
    emit refs->dataEdit(0)->editingFinished();
    QCOMPARE(doc.spec().analysis.references.at(0).type, std::string("file"));
    QCOMPARE(doc.spec().analysis.references.at(0).file, std::string("ref.csv"));
    undo->undo();  // the file
    undo->undo();  // back to the step
    QCOMPARE(doc.spec().analysis.references, std::vector<SignalSpec>{step});
    QCOMPARE(refs->typeCombo(0)->currentText(), QString("step"));

    view.antiWindupCombo()->setCurrentIndex(view.antiWindupCombo()->findData("back_calculation"));
    QVERIFY(view.trackingTimeSpin()->isEnabled());
    view.trackingTimeSpin()->setValue(0.5);
    view.lqrControllablePartCheck()->setChecked(true);
    view.closedLoopCheck()->setChecked(true);
    const StudySpec& st = doc.spec().analysis;
    QCOMPARE(st.anti_windup, std::string("back_calculation"));
    QCOMPARE(st.tracking_time, 0.5);
    QVERIFY(st.lqr_controllable_part);
    QVERIFY(st.closed_loop.enabled);

    // saved and read back (by the core's reader and by a second view)
    QString error;
    QVERIFY2(doc.save(&error), qPrintable(error));
    const ModelSpec reread = load_model_spec(path.toStdString());
    QCOMPARE(reread.analysis, doc.spec().analysis);
    Document doc2;
    QVERIFY(doc2.load(path));
    SimulateView view2(&doc2);
    QCOMPARE(view2.referencesTable()->table()->rowCount(), 1);
    QCOMPARE(view2.referencesTable()->spin(0, SignalTable::Value)->value(), 0.2);
    QCOMPARE(view2.referencesTable()->spin(0, SignalTable::Time)->value(), 1.0);
    QCOMPARE(view2.antiWindupCombo()->currentData().toString(), QString("back_calculation"));
    QCOMPARE(view2.trackingTimeSpin()->value(), 0.5);
    QVERIFY(view2.lqrControllablePartCheck()->isChecked());
    QVERIFY(view2.closedLoopCheck()->isChecked());

    // a reload refreshes the view: the example without references, then the saved file again
    QVERIFY(doc2.load(kCart));
    QCOMPARE(view2.referencesTable()->table()->rowCount(), 0);
    QCOMPARE(view2.antiWindupCombo()->currentData().toString(), QString("none"));
    QVERIFY(doc2.load(path));
    QCOMPARE(view2.referencesTable()->table()->rowCount(), 1);
    QVERIFY(view2.closedLoopCheck()->isChecked());

    // undo to the start: the widgets follow; redo brings it all back
    while (undo->index() > base) undo->undo();
    QVERIFY(doc.spec().analysis.references.empty());
    QCOMPARE(refs->table()->rowCount(), 0);
    QCOMPARE(view.antiWindupCombo()->currentData().toString(), QString("none"));
    QVERIFY(!view.trackingTimeSpin()->isEnabled());
    QVERIFY(!view.closedLoopCheck()->isChecked());
    while (undo->canRedo()) undo->redo();
    QCOMPARE(doc.spec().analysis, reread.analysis);
    QCOMPARE(refs->table()->rowCount(), 1);
    QCOMPARE(refs->spin(0, SignalTable::Value)->value(), 0.2);
    QVERIFY(view.closedLoopCheck()->isChecked());
  }

  // A disturbance on an actuator that is not Plant/In (the cart's force, once unticked):
  // offered, written, and what the core's run setup adds to that actuator.
  void disturbanceOnAnActuatorOutsidePlantIn() {
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    SignalTable* dist = view.disturbancesTable();
    QTest::mouseClick(dist->addButton(), Qt::LeftButton);
    QCOMPARE(dist->table()->rowCount(), 0);  // force is Plant/In: nothing offered
    QVERIFY(doc.setPlantInputs({}));
    view.controllerCombo()->setCurrentIndex(view.controllerCombo()->findData("none"));
    QTest::mouseClick(dist->addButton(), Qt::LeftButton);
    QCOMPARE(dist->table()->rowCount(), 1);
    QCOMPARE(dist->targetCombo(0)->currentText(), QString("force"));
    dist->typeCombo(0)->setCurrentIndex(dist->typeCombo(0)->findText("sine"));
    dist->spin(0, SignalTable::Time)->setValue(0.5);
    dist->spin(0, SignalTable::Value)->setValue(5.0);
    dist->spin(0, SignalTable::Frequency)->setValue(2.0);
    QCOMPARE(doc.spec().analysis.disturbances.size(), std::size_t(1));
    const DisturbanceSpec& d = doc.spec().analysis.disturbances[0];
    QCOMPARE(d.actuator, std::string("force"));
    QVERIFY(d.output.empty());
    QCOMPARE(d.type, std::string("sine"));
    QCOMPARE(d.amplitude, 5.0);
    QCOMPARE(d.frequency, 2.0);
    QVERIFY(doc.model());
    const StudySimulation setup = study_simulation(*doc.model());
    QVERIFY(setup.options.disturbance);
    const int k = doc.model()->find_actuator("force");
    const double t = 0.5 + 0.125;  // a quarter period after the start: the sine's peak
    QVERIFY(std::abs(setup.options.disturbance(t)[k] - 5.0) < 1e-12);
    QCOMPARE(setup.options.disturbance(0.4)[k], 0.0);
  }

  // ---------------------------------------------------------------- Simulate

  void runPlotsExactlyTheSimulatedSamples() {
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    view.resize(1400, 900);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.endTimeSpin()->setValue(0.5);
    QCOMPARE(doc.spec().solver.t_end, 0.5);

    // what the worker delivers live, batch by batch
    std::vector<double> liveT;
    std::vector<Eigen::VectorXd> liveY;
    connect(view.worker(), &SimWorker::samples, this, [&](const SampleBatch& b) {
      for (const Snapshot& s : b) {
        liveT.push_back(s.t);
        liveY.push_back(s.y);
      }
    });
    QSignalSpy started(&view, &SimulateView::runStarted);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QSignalSpy batches(view.worker(), &SimWorker::samples);
    view.run();
    QCOMPARE(started.count(), 1);
    QVERIFY(view.isRunning());
    QVERIFY(!view.runButton()->isEnabled());
    QVERIFY(view.cancelButton()->isEnabled());
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    QVERIFY(!view.isRunning());

    const auto r = view.result();
    QVERIFY(r);
    QCOMPARE(finished.at(0).at(0).value<std::shared_ptr<const SimulationResult>>(), r);
    QVERIFY(r->completed);
    QCOMPARE(r->samples(), 51);
    QCOMPARE(r->t.back(), 0.5);
    QCOMPARE(view.progressBar()->value(), view.progressBar()->maximum());
    QVERIFY(view.statusText().contains("completed"));

    // the integrator ran on the worker thread, not on the GUI thread
    QVERIFY(view.worker()->integratorThread() != nullptr);
    QVERIFY(view.worker()->integratorThread() != QThread::currentThread());
    QVERIFY(view.worker()->integratorThread() != qApp->thread());
    QCOMPARE(view.worker()->integratorThread(), view.worker()->workerThread());

    // batched: nothing lost, in order, at most one emission per 50 ms (+ the last)
    QCOMPARE(static_cast<int>(liveT.size()), r->samples());
    for (int i = 0; i < r->samples(); ++i) {
      QCOMPARE(liveT[i], r->t[i]);
      QVERIFY(liveY[i] == r->y.row(i).transpose());
    }
    QVERIFY(batches.count() >= 1);
    QVERIFY2(batches.count() <= 2 + static_cast<int>(view.worker()->wallTime() / 0.05),
             qPrintable(QString("%1 batches in %2 s").arg(batches.count()).arg(view.worker()->wallTime())));

    // the plots hold exactly the samples (outputs and the Plant/In column of u)
    view.plots()->flush();
    QCOMPARE(view.plots()->outputSeriesCount(), static_cast<int>(r->y.cols()));
    for (int k = 0; k < static_cast<int>(r->y.cols()); ++k) {
      const QList<QPointF> p = view.plots()->outputPoints(k);
      QCOMPARE(p.size(), r->samples());
      for (int i = 0; i < r->samples(); ++i) {
        QCOMPARE(p[i].x(), r->t[i]);
        QCOMPARE(p[i].y(), r->y(i, k));
      }
    }
    const int uc = doc.model()->plant_inputs.at(0);
    const QList<QPointF> u = view.plots()->inputPoints(0);
    QCOMPARE(u.size(), r->samples());
    for (int i = 0; i < r->samples(); ++i) QCOMPARE(u[i].y(), r->u(i, uc));
    QVERIFY(view.plots()->redrawCount() > 0);

    // results files through core's writers
    QString err;
    const QString h5 = tmp.filePath("run.h5"), csv = tmp.filePath("run.csv");
    QVERIFY2(view.saveResults(h5, &err), qPrintable(err));
    QVERIFY2(view.saveResults(csv, &err), qPrintable(err));
    const SimulationResult back = read_results_hdf5(h5.toStdString());
    QCOMPARE(back.samples(), r->samples());
    QVERIFY(back.y == r->y);
    QCOMPARE(readAll(csv).count('\n'), r->samples() + 1);
    QVERIFY(!view.saveResults(tmp.filePath("run.txt"), &err));
    QVERIFY(err.contains(".h5"));
    QVERIFY2(view.savePlot(tmp.filePath("plot.png"), &err), qPrintable(err));
    QVERIFY(QFileInfo(tmp.filePath("plot.png")).size() > 0);
  }

  // "Start at" in the Simulate view, as a person uses it: a wheel turned over the closed drop-down
  // changes nothing; "the operating point (x0)" picked from its list with the mouse is the study's
  // start; the run then begins where core's study_simulation puts it, the equilibrium, not the
  // model's 0.1 rad off upright; and the drop-down follows the document (undo)
  void startAtTheOperatingPointFromTheSimulateView() {
    WheelGuard::install();  // as codyna-gui's window installs it, before any field is polished
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    QComboBox* start = view.startCombo();
    QCOMPARE(start->currentData().toString(), QString("model"));
    drive::wheelOver(start, -1);
    QCOMPARE(doc.spec().analysis.start, std::string("model"));
    QVERIFY(drive::pickWithMouse(start, "the operating point (x0)"));
    QCOMPARE(doc.spec().analysis.start, std::string("operating-point"));
    view.endTimeSpin()->setValue(0.2);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    const auto r = view.result();
    QVERIFY(r && r->completed && r->samples() > 1);
    const Model m = study_model(doc.spec(), ss(kCart));
    const StudySimulation setup = study_simulation(m);
    QCOMPARE(setup.start, std::string("equilibrium"));
    QVERIFY((setup.options.q0 - m.q0).cwiseAbs().maxCoeff() > 0.05);  // the model's own start is elsewhere
    for (int k = 0; k < m.nq; ++k) QVERIFY2(std::abs(r->q(0, k) - setup.options.q0[k]) <= 1e-12, qPrintable(QString::number(k)));
    QVERIFY(view.worker()->notes().join("\n").contains("the run starts at the equilibrium point"));
    // undo the end time and the start: the drop-down shows the model's state again
    doc.undoStack()->undo();
    doc.undoStack()->undo();
    QCOMPARE(doc.spec().analysis.start, std::string("model"));
    QCOMPARE(start->currentData().toString(), QString("model"));
  }

  void lqrWithTheLinearComparisonIsPlottedToo() {
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    view.show();
    QSignalSpy said(&view, &SimulateView::message);
    view.controllerCombo()->setCurrentIndex(view.controllerCombo()->findData("lqr"));
    // an LQR designed here starts the run at its operating point by default, said and shown
    QCOMPARE(doc.spec().analysis.start, std::string("operating-point"));
    QCOMPARE(view.startCombo()->currentData().toString(), QString("operating-point"));
    QVERIFY(!said.isEmpty() && said.last().at(0).toString().contains("the run starts there now"));
    // one undo takes both back; redo, then the model's own state (0.1 rad off upright) picked by hand
    doc.undoStack()->undo();
    QCOMPARE(doc.spec().analysis.controller, std::string("model"));
    QCOMPARE(doc.spec().analysis.start, std::string("model"));
    doc.undoStack()->redo();
    QCOMPARE(doc.spec().analysis.start, std::string("operating-point"));
    QVERIFY(drive::pickWithMouse(view.startCombo(), "the model's state"));
    QCOMPARE(doc.spec().analysis.start, std::string("model"));
    QCOMPARE(doc.spec().analysis.controller, std::string("lqr"));
    setLine(view.qWeightsEdit(), "10, 100, 1, 1");
    setLine(view.rWeightsEdit(), "0.01");
    QTest::mouseClick(view.compareLinearCheck(), Qt::LeftButton);
    QVERIFY(doc.spec().analysis.compare_linear);
    view.endTimeSpin()->setValue(1.0);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    const auto r = view.result();
    QVERIFY(r && r->completed);
    QCOMPARE(view.worker()->controllerSource(), QString("lqr"));
    QCOMPARE(r->y_linear.rows(), r->y.rows());
    QCOMPARE(view.plots()->linearPoints(1).size(), r->samples());
    // the LQR brings theta (0.1 rad at the start) back toward upright
    QVERIFY(std::abs(r->y(r->samples() - 1, 1)) < 0.5 * std::abs(r->y(0, 1)));
  }

  // The run's status says, as the command line does, when the state left the region where the
  // linear model holds (core's study_linear_region against the study's linear_region): the
  // cart-pendulum starts 0.1 rad off upright, beyond a bound of 0.01 rad, and the LQR brings it back
  void leavingTheLinearRegionIsSaid() {
    Document doc;
    QVERIFY(doc.load(kCart));
    StudySpec study = doc.spec().analysis;
    study.controller = "lqr";
    study.linear_region = 0.01;
    QVERIFY(doc.setStudy(study));
    SimulateView view(&doc);
    view.show();
    view.endTimeSpin()->setValue(1.0);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    QVERIFY(view.result() && view.result()->completed);
    QVERIFY2(view.statusText().contains("; warning: the state left the region where the linear model holds: |rod_pivot - its operating-point value| > 0.01 at t = 0 s"),
             qPrintable(view.statusText()));
    QVERIFY2(!view.statusText().contains("unstable"), qPrintable(view.statusText()));
    // within the default 0.5 rad nothing is said
    study.linear_region = 0.5;
    QVERIFY(doc.setStudy(study));
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 2; }));
    QVERIFY2(!view.statusText().contains("linear region"), qPrintable(view.statusText()));
  }

  // An LQR on the controllable part of the spherical pendulum (the study field set through the
  // Document): the run stabilizes the tilt, and the note naming the yaw reaches the status line
  // and the messages
  void lqrOnTheControllablePartSaysWhatItLeaves() {
    Document doc;
    QVERIFY(doc.load(QStringLiteral(CODYNA_TEST_DATA_DIR "/spherical_pendulum.json")));
    StudySpec study = doc.spec().analysis;
    study.controller = "lqr";
    study.lqr_controllable_part = true;
    QVERIFY(doc.setStudy(study));
    SimulateView view(&doc);
    view.show();
    QSignalSpy messages(&view, &SimulateView::message);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QTest::mouseClick(view.runButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    const auto r = view.result();
    QVERIFY(r && r->completed);
    const QString note = "lqr on the controllable part (4 of 6 states): the Plant/In inputs cannot move lambda = 0 (ball.wz)";
    QVERIFY2(view.statusText().contains("; note: " + note), qPrintable(view.statusText()));
    bool said = false;
    for (const auto& m : messages) said = said || m.at(0).toString().startsWith("note: " + note);
    QVERIFY(said);
    const int N = r->samples();
    QVERIFY(std::hypot(r->y(N - 1, 0), r->y(N - 1, 1)) < 1e-4);
  }

  void cancelKeepsThePartialResult() {
    Document doc;
    QVERIFY(doc.load(kBricard));
    SimulateView view(&doc);
    view.show();
    view.endTimeSpin()->setValue(1000);
    QCOMPARE(doc.spec().solver.t_end, 1000.0);
    QSignalSpy progress(view.worker(), &SimWorker::progress);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    view.run();
    QVERIFY(waitFor([&] { return view.progressBar()->value() > 0 || (!progress.isEmpty() && progress.last().at(0).toDouble() > 0.5); }));
    QVERIFY(view.isRunning());
    QTest::mouseClick(view.cancelButton(), Qt::LeftButton);
    QVERIFY(waitFor([&] { return finished.count() == 1; }, 30000));
    const auto r = view.result();
    QVERIFY(r);
    QVERIFY(r->cancelled);
    QVERIFY(!r->completed);
    QVERIFY(r->samples() > 1);
    QVERIFY(r->t.back() < 1000.0);
    QVERIFY(r->t.back() > 0.0);
    QVERIFY(view.statusText().contains("cancelled at t ="));
    view.plots()->flush();
    QCOMPARE(view.plots()->outputPoints(0).size(), std::min(r->samples(), view.plots()->maxPlotPoints()));
    QVERIFY(view.runButton()->isEnabled());
    QVERIFY(!view.cancelButton()->isEnabled());
  }

  void failingSetupIsReportedNotFatal() {
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    view.controllerCombo()->setCurrentIndex(view.controllerCombo()->findData("file"));
    setLine(view.controllerFileEdit(), "no_such_controller.mat");
    QCOMPARE(doc.spec().analysis.controller_file, std::string("no_such_controller.mat"));
    QSignalSpy failed(view.worker(), &SimWorker::failed);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    QSignalSpy messages(&view, &SimulateView::message);
    view.run();
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    QCOMPARE(failed.count(), 1);
    QVERIFY(!finished.at(0).at(0).value<std::shared_ptr<const SimulationResult>>());
    QVERIFY(!view.result());
    QVERIFY(view.statusText().startsWith("failed"));
    QVERIFY(view.statusText().contains("no_such_controller.mat"));
    QVERIFY(messages.count() >= 1);
    QString err;
    QVERIFY(!view.saveResults(tmp.filePath("none.h5"), &err));
    // the worker is usable again
    view.controllerCombo()->setCurrentIndex(view.controllerCombo()->findData("none"));
    view.endTimeSpin()->setValue(0.1);
    view.run();
    QVERIFY(waitFor([&] { return finished.count() == 2; }));
    QVERIFY(view.result() && view.result()->completed);
  }

  void simulateWidgetsWriteTheStudyAndFollowUndo() {
    Document doc;
    QVERIFY(doc.load(kCart));
    SimulateView view(&doc);
    view.show();
    QUndoStack* undo = doc.undoStack();
    const ModelSpec original = doc.spec();
    const int base = undo->index();

    view.controllerCombo()->setCurrentIndex(view.controllerCombo()->findData("lqr"));
    QCOMPARE(doc.spec().analysis.controller, std::string("lqr"));
    setLine(view.qWeightsEdit(), "1 2 3 4");
    QCOMPARE(doc.spec().analysis.q_weights, (std::vector<double>{1, 2, 3, 4}));
    setLine(view.rWeightsEdit(), "nonsense");  // refused, the field shows the study again
    QVERIFY(doc.spec().analysis.r_weights.empty());
    QCOMPARE(view.rWeightsEdit()->text(), QString());
    view.integratorCombo()->setCurrentIndex(view.integratorCombo()->findData("cvode-bdf"));
    QCOMPARE(doc.spec().solver.integrator, std::string("cvode-bdf"));
    setLine(view.rtolEdit(), "1e-6");
    QCOMPARE(doc.spec().solver.rtol, 1e-6);
    setLine(view.atolEdit(), "-1");  // refused
    QCOMPARE(doc.spec().solver.atol, original.solver.atol);
    view.outputStepSpin()->setValue(0.02);
    view.outputStepSpin()->setValue(0.05);  // merged with the step before
    QCOMPARE(doc.spec().solver.output_step, 0.05);
    view.compareLinearCheck()->setChecked(true);
    QVERIFY(doc.spec().analysis.compare_linear);
    QCOMPARE(undo->index(), base + 6);

    undo->undo();
    QVERIFY(!doc.spec().analysis.compare_linear);
    QVERIFY(!view.compareLinearCheck()->isChecked());
    undo->undo();
    QCOMPARE(doc.spec().solver.output_step, original.solver.output_step);
    QCOMPARE(view.outputStepSpin()->value(), original.solver.output_step);
    undo->undo();
    QCOMPARE(view.rtolEdit()->text().toDouble(), original.solver.rtol);
    while (undo->index() > base) undo->undo();
    QCOMPARE(doc.spec().analysis, original.analysis);
    QCOMPARE(view.controllerCombo()->currentData().toString(), QString("model"));
    QCOMPARE(view.integratorCombo()->currentData().toString(), QString("auto"));
    QCOMPARE(view.qWeightsEdit()->text(), QString());

    // the model file's controller is described (an LQR here)
    QVERIFY(view.controllerDescription()->text().contains("LQR"));
    QVERIFY(!view.pidTable()->isVisibleTo(&view));
  }

  // alf's settings and the maximum step, typed as a person does (select, type, Return): each lands
  // in the model's solver section and in the run; a value that is not of the field's kind, and one
  // the model file's checks refuse (alf with a step longer than the run), is said and not taken
  void alfSettingsAndTheMaximumStepAreTypedIntoTheRun() {
    Document doc;
    QVERIFY(doc.load(kFourBar));
    SimulateView view(&doc);
    view.show();
    QSignalSpy messages(&view, &SimulateView::message);
    const auto type = [](QLineEdit* e, const QString& text) {
      e->setFocus();
      e->selectAll();
      if (text.isEmpty()) QTest::keyClick(e, Qt::Key_Backspace);
      else QTest::keyClicks(e, text);
      QTest::keyClick(e, Qt::Key_Return);
    };
    const auto said = [&](const QString& what) {
      return messages.count() > 0 && messages.last().at(0).toString().contains(what);
    };
    // alf's own fields wait for alf
    QVERIFY(!view.alfPenaltyEdit()->isEnabled() && !view.alfIterationsEdit()->isEnabled() && !view.alfFixedCheck()->isEnabled());
    QCOMPARE(view.maxStepEdit()->text(), QString());  // no limit
    QVERIFY(drive::pickWithKeys(view.integratorCombo(), "alf"));  // the list opened, arrow keys, Enter
    QCOMPARE(doc.spec().solver.integrator, std::string("alf"));
    QVERIFY(view.alfPenaltyEdit()->isEnabled() && view.alfIterationsEdit()->isEnabled() && view.alfFixedCheck()->isEnabled());

    type(view.maxStepEdit(), "0.002");
    QCOMPARE(doc.spec().solver.max_step, 0.002);
    // extrapolation with error control and at fixed steps alike: each box its own field
    QVERIFY(view.alfExtrapolateCheck()->isEnabled() && !doc.spec().solver.alf_extrapolate);
    QTest::mouseClick(view.alfExtrapolateCheck(), Qt::LeftButton, {}, QPoint(6, view.alfExtrapolateCheck()->height() / 2));
    QVERIFY(doc.spec().solver.alf_extrapolate && !doc.spec().solver.alf_fixed_step);
    QCOMPARE(doc.undoStack()->undoText(), QString("alf extrapolated"));
    QTest::mouseClick(view.alfFixedCheck(), Qt::LeftButton, {}, QPoint(6, view.alfFixedCheck()->height() / 2));
    QVERIFY(doc.spec().solver.alf_fixed_step && doc.spec().solver.alf_extrapolate);
    QVERIFY(view.alfExtrapolateCheck()->isChecked());
    type(view.alfPenaltyEdit(), "lots");
    QVERIFY(said("alf penalty: expected a number > 0"));
    QVERIFY(!doc.spec().solver.alf_penalty);
    QCOMPARE(view.alfPenaltyEdit()->text(), QString());
    type(view.alfPenaltyEdit(), "-5");
    QVERIFY(said("alf penalty"));
    QVERIFY(!doc.spec().solver.alf_penalty);
    type(view.alfPenaltyEdit(), "1e9");
    QCOMPARE(doc.spec().solver.alf_penalty.value_or(0), 1e9);
    type(view.alfIterationsEdit(), "2.5");
    QVERIFY(said("alf iterations: expected a whole number >= 1"));
    QVERIFY(!doc.spec().solver.alf_iterations);
    type(view.alfIterationsEdit(), "30");
    QCOMPARE(doc.spec().solver.alf_iterations.value_or(0), 30);
    // the model file's rule: alf's step no longer than the run (the field, the end time)
    const int before = static_cast<int>(messages.count());
    type(view.maxStepEdit(), "100");
    QCOMPARE(static_cast<int>(messages.count()), before + 1);
    QVERIFY(said("/solver/max_step") && said("longer than the run"));
    QCOMPARE(doc.spec().solver.max_step, 0.002);
    QCOMPARE(view.maxStepEdit()->text(), QString("0.002"));
    const int refusals = static_cast<int>(messages.count());
    type(view.maxStepEdit(), "-1");
    QCOMPARE(static_cast<int>(messages.count()), refusals + 1);  // said once
    QVERIFY(said("Maximum step: expected a number of seconds >= 0 (empty: no limit), got \"-1\""));
    QCOMPARE(doc.spec().solver.max_step, 0.002);
    // the tolerances take the same rule: a value that is not > 0 is refused with the field named
    type(view.rtolEdit(), "0");
    QVERIFY(said("Relative tolerance: expected a number > 0, got \"0\""));
    QCOMPARE(view.rtolEdit()->text().toDouble(), doc.spec().solver.rtol);
    // leaving a field as it is: no edit, nothing said
    const int undo = doc.undoStack()->index(), said_before = static_cast<int>(messages.count());
    type(view.alfIterationsEdit(), "30");
    type(view.maxStepEdit(), "0.002");
    QCOMPARE(doc.undoStack()->index(), undo);
    QCOMPARE(static_cast<int>(messages.count()), said_before);

    // the run takes them: 0.5 s at fixed steps of 2 ms is 250 steps, each extrapolated from
    // three trapezoidal steps (750)
    view.endTimeSpin()->setValue(0.5);
    QSignalSpy finished(&view, &SimulateView::runFinished);
    view.run();
    QVERIFY(waitFor([&] { return finished.count() == 1; }));
    QVERIFY(view.result() && view.result()->completed);
    QCOMPARE(view.result()->stats.integrator, std::string("alf"));
    QCOMPARE(view.result()->stats.steps, 750L);
    QVERIFY(view.result()->constraint_violation.back() < 1e-9);

    // emptied: alf's default again; undone: the typed value back in the field
    type(view.alfPenaltyEdit(), "");
    QVERIFY(!doc.spec().solver.alf_penalty);
    doc.undoStack()->undo();
    QCOMPARE(doc.spec().solver.alf_penalty.value_or(0), 1e9);
    QCOMPARE(view.alfPenaltyEdit()->text(), QString("1000000000"));
    // saved and read back: the file holds what was typed
    const QString path = tmp.filePath("four_bar_alf.json");
    QString err;
    QVERIFY2(doc.saveAs(path, &err), qPrintable(err));
    const ModelSpec back = study_read_model(path.toStdString());
    QCOMPARE(back.solver.max_step, 0.002);
    QVERIFY(back.solver.alf_fixed_step && back.solver.alf_extrapolate);
    QCOMPARE(back.solver.alf_penalty.value_or(0), 1e9);
    QCOMPARE(back.solver.alf_iterations.value_or(0), 30);
    // another integrator: alf's fields kept in the file, not editable
    QVERIFY(drive::pickWithMouse(view.integratorCombo(), "arkode"));
    QCOMPARE(doc.spec().solver.integrator, std::string("arkode"));
    QVERIFY(!view.alfPenaltyEdit()->isEnabled());
    QCOMPARE(view.alfIterationsEdit()->text(), QString("30"));

    // a file whose integrator codyna does not know: leaving a field unchanged says nothing (it used
    // to be refused each time a field lost focus); a change is refused, naming the integrator
    QVERIFY(doc.edit("an unknown integrator", [](ModelSpec& s) { s.solver.integrator = "euler"; }));
    const int quiet = static_cast<int>(messages.count());
    type(view.rtolEdit(), view.rtolEdit()->text());
    type(view.maxStepEdit(), view.maxStepEdit()->text());
    QCOMPARE(static_cast<int>(messages.count()), quiet);
    type(view.rtolEdit(), "1e-5");
    QVERIFY(said("/solver/integrator"));
    QCOMPARE(doc.spec().solver.integrator, std::string("euler"));
  }

  void pidGainsAreEditableInTheTable() {
    Document doc;
    QVERIFY(doc.load(kCart));
    QVERIFY(doc.edit("PID", [](ModelSpec& s) {
      s.controller = ControllerSpec{};
      s.controller.type = ControllerType::Pid;
      s.controller.kp = Eigen::MatrixXd(1, 2);
      s.controller.kp << -5, 300;
    }));
    SimulateView view(&doc);
    view.show();
    QTableWidget* t = view.pidTable();
    QVERIFY(t->isVisibleTo(&view));
    QCOMPARE(t->rowCount(), 1);
    QCOMPARE(t->columnCount(), 6);  // Kp, Ki, Kd x (h, theta)
    QCOMPARE(t->horizontalHeaderItem(1)->text(), QString("Kp: theta"));
    QCOMPARE(t->item(0, 1)->text().toDouble(), 300.0);
    QVERIFY(view.controllerDescription()->text().contains("PID"));
    const int base = doc.undoStack()->index();
    t->item(0, 5)->setText("25");  // Kd on theta: from none to a 1 x 2 matrix
    QCOMPARE(doc.spec().controller.kd.rows(), 1);
    QCOMPARE(doc.spec().controller.kd.cols(), 2);
    QCOMPARE(doc.spec().controller.kd(0, 1), 25.0);
    QCOMPARE(doc.spec().controller.kd(0, 0), 0.0);
    QCOMPARE(doc.undoStack()->index(), base + 1);
    t->item(0, 0)->setText("oops");  // refused and shown as before
    QCOMPARE(doc.spec().controller.kp(0, 0), -5.0);
    QCOMPARE(t->item(0, 0)->text().toDouble(), -5.0);
    doc.undoStack()->undo();
    QCOMPARE(doc.spec().controller.kd.size(), 0);
    QCOMPARE(t->item(0, 5)->text().toDouble(), 0.0);
  }
};

QTEST_MAIN(ViewsTest)
#include "views_test.moc"
