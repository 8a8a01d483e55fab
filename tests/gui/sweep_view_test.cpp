// The Sweep view (issue 22), offscreen, driven as a person drives it: the rod's mass picked
// into the study from the property editor's context menu, its values typed into the table, Run
// clicked. What it draws is checked against core's study_sweep_job run directly on the model file
// with the same request: every variant's plotted poles equal the core's closed-loop poles to 1e-12,
// the colours follow the mass (viridis: lighter as the mass grows), the figure of merit is the
// core's largest closed-loop real part. A variant made to fail (a mass of -1) is listed with the
// core's reason; a spec the core refuses is reported naming the field; Cancel stops a long study
// and closing the window while one runs does not crash.
#include <QAction>
#include <QApplication>
#include <QContextMenuEvent>
#include <QElapsedTimer>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QCheckBox>
#include <QComboBox>
#include <QTabWidget>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QPointer>
#include <QTest>
#include <cmath>

#include "drive.hpp"
#include "gui/main_window.hpp"
#include "gui/property_editor.hpp"
#include "gui/sweep_view.hpp"
#include "model/spec_edit.hpp"
#include <QUndoStack>
#include "study/sweep.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {
const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");

double luminance(const QColor& c) { return 0.2126 * c.redF() + 0.7152 * c.greenF() + 0.0722 * c.blueF(); }
}  // namespace

class SweepViewTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  SweepView* view() { return w->sweepView(); }

  // right-click on the rod's mass in the property editor, "Vary in sweep" clicked in the menu
  bool pickRodMass() {
    w->selectElement(ElementId{ElementKind::Body, 1});
    auto* mass = qobject_cast<QLineEdit*>(w->propertyEditor()->editorFor("mass"));
    if (!mass) return false;
    const QPoint at(mass->width() / 2, mass->height() / 2);
    QTest::mouseClick(mass, Qt::RightButton, {}, at);
    if (!QTest::qWaitFor([] { return qobject_cast<QMenu*>(QApplication::activePopupWidget()) != nullptr; }, 500)) {
      // a platform that opens context menus on the release only: the event the press would give
      QContextMenuEvent e(QContextMenuEvent::Mouse, at, mass->mapToGlobal(at));
      QApplication::sendEvent(mass, &e);
    }
    if (!QTest::qWaitFor([] { return qobject_cast<QMenu*>(QApplication::activePopupWidget()) != nullptr; }, 2000)) return false;
    auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
    QAction* vary = menu->findChild<QAction*>("varyInSweep");
    if (!vary || !vary->isEnabled()) return false;
    QTest::qWait(QApplication::doubleClickInterval() + 50);
    const QPoint p = menu->actionGeometry(vary).center();
    QTest::mouseMove(menu, p);
    QTest::mouseClick(menu, Qt::LeftButton, {}, p);
    return QTest::qWaitFor([menu] { return !menu->isVisible(); }, 2000);
  }

  // the values of row `row` typed in: a click on the cell, its editor opened, Ctrl+A, the text, Enter
  void typeSpec(int row, const QString& text) {
    QTableWidget* t = view()->fieldTable();
    w->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(w.get()));  // focus is real: the editor keeps it while typed into
    const QModelIndex cell = t->model()->index(row, 1);
    QTest::mouseClick(t->viewport(), Qt::LeftButton, {}, t->visualRect(cell).center());
    QCOMPARE(t->currentIndex(), cell);
    // the cell's editor opened as F2 or a double click opens it (the editor a person then types into)
    const QList<QLineEdit*> before = t->viewport()->findChildren<QLineEdit*>();
    t->editItem(t->item(row, 1));
    QLineEdit* editor = nullptr;
    for (QLineEdit* e : t->viewport()->findChildren<QLineEdit*>())
      if (!before.contains(e) && e->isVisible()) editor = e;
    QVERIFY2(editor, "the cell's editor is open");
    QTest::keyClick(editor, Qt::Key_A, Qt::ControlModifier);
    QTest::keyClicks(editor, text);
    QTest::keyClick(editor, Qt::Key_Return);
    QTRY_VERIFY(!t->indexWidget(cell));  // the delegate commits and closes the editor from the event loop
    QCOMPARE(t->item(row, 1)->text(), text);
  }

  bool runAndWait(int ms = 120000) {
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    return QTest::qWaitFor([this] { return !view()->isRunning(); }, ms);
  }

 private slots:
  void init() {
    w = drive::window("sweep_view_test");
    QVERIFY(w);
    QVERIFY(w->openFile(kCart));
    w->analysisTabs()->setCurrentWidget(view());
  }
  void cleanup() { drive::close(w); }

  // the choices below the table driven as a person drives them: a wheel over the unfocused drop-down
  // and spin boxes changes nothing; the controller picked from the open list with the mouse, the
  // simulate box clicked, the figure picked from its list with the keys; the run then equals the
  // core's study with the same choices (LQR redesigned per variant, peak |input| of each run)
  void choicesDrivenAsAPersonDrivesThem() {
    QVERIFY(pickRodMass());
    typeSpec(0, "8:12:3");
    drive::wheelOver(view()->redesignCombo(), -2);
    drive::wheelOver(view()->samplesSpin(), 3);
    drive::wheelOver(view()->threadsSpin(), 2);
    QCOMPARE(view()->redesignCombo()->currentIndex(), 0);
    QCOMPARE(view()->samplesSpin()->value(), 100);
    QCOMPARE(view()->threadsSpin()->value(), 0);
    QVERIFY(drive::pickWithMouse(view()->redesignCombo(), "LQR redesigned per variant"));
    QCOMPARE(view()->redesignCombo()->currentData().toString(), QStringLiteral("lqr"));
    QTest::mouseClick(view()->simulateCheck(), Qt::LeftButton, {}, QPoint(8, view()->simulateCheck()->height() / 2));
    QVERIFY(view()->simulateCheck()->isChecked());
    QVERIFY(runAndWait());
    const SweepJob* shown = view()->result();
    QVERIFY2(shown, qPrintable(view()->statusLabel()->text()));
    QVERIFY(shown->redesigned);
    QVERIFY(shown->simulated);
    QVERIFY(drive::pickWithKeys(view()->figureCombo(), "peak |input| (nonlinear run)"));
    SweepRequest r;
    r.model = kCart.toStdString();
    r.vary = {"/bodies/1/mass=8:12:3"};
    r.threads = 1;
    r.redesign = "lqr";
    r.simulate = true;
    const SweepJob direct = study_sweep_job(r);
    QCOMPARE(direct.variants.size(), std::size_t(3));
    const QList<QPointF> points = view()->figurePoints();
    QCOMPARE(points.size(), 3);
    for (int i = 0; i < 3; ++i) {
      const SweepVariant& v = direct.variants[static_cast<std::size_t>(i)];
      QCOMPARE(v.sim_status, 0);
      QCOMPARE(points[i].x(), v.values[0]);
      QVERIFY2(std::abs(points[i].y() - v.peak_input.cwiseAbs().maxCoeff()) <= 1e-12 * std::max(1.0, points[i].y()),
               qPrintable(QString("variant %1: drawn %2, core %3").arg(i).arg(points[i].y()).arg(v.peak_input.cwiseAbs().maxCoeff())));
      QVERIFY(v.peak_input.cwiseAbs().maxCoeff() > 0);
    }
  }

  void rodMassPolesEqualTheCore() {
    QVERIFY(pickRodMass());
    QCOMPARE(w->analysisTabs()->currentWidget(), static_cast<QWidget*>(view()));
    QTableWidget* t = view()->fieldTable();
    QCOMPARE(t->rowCount(), 1);
    QCOMPARE(t->item(0, 0)->text(), QStringLiteral("/bodies/1/mass"));
    QCOMPARE(t->item(0, 1)->text(), QStringLiteral("5:15:11"));  // the first grid: half to 1.5 times 10 kg
    typeSpec(0, "5:15:11");
    QVERIFY(runAndWait());
    const SweepJob* shown = view()->result();
    QVERIFY2(shown, qPrintable(view()->statusLabel()->text()));

    SweepRequest r;
    r.model = kCart.toStdString();
    r.vary = {"/bodies/1/mass=5:15:11"};
    r.threads = 1;
    const SweepJob direct = study_sweep_job(r);
    QVERIFY(direct.closed_loop);
    QCOMPARE(shown->variants.size(), std::size_t(11));
    QCOMPARE(direct.variants.size(), std::size_t(11));
    double worst = 0;
    for (int i = 0; i < 11; ++i) {
      const SweepVariant& v = direct.variants[i];
      QCOMPARE(int(v.status), int(SweepStatus::Ok));
      QCOMPARE(v.values[0], 5.0 + i);
      const QList<QPointF> drawn = view()->plottedPoles(i);
      QCOMPARE(drawn.size(), int(v.closed_poles.size()));
      QCOMPARE(drawn.size(), 4);
      for (int k = 0; k < drawn.size(); ++k) {
        worst = std::max(worst, std::abs(drawn[k].x() - v.closed_poles[k].real()));
        worst = std::max(worst, std::abs(drawn[k].y() - v.closed_poles[k].imag()));
      }
    }
    QVERIFY2(worst <= 1e-12, qPrintable(QString("largest difference %1").arg(worst)));
    // the colours follow the mass: distinct, and lighter as the mass grows (viridis)
    for (int i = 1; i < 11; ++i) {
      QVERIFY(view()->variantColour(i).isValid());
      QVERIFY2(luminance(view()->variantColour(i)) > luminance(view()->variantColour(i - 1)) + 0.01,
               qPrintable(QString("variant %1 %2 against %3").arg(i).arg(view()->variantColour(i).name(), view()->variantColour(i - 1).name())));
    }
    QCOMPARE(view()->variantColour(0), ColourBar::colourAt(0.0));
    QCOMPARE(view()->variantColour(10), ColourBar::colourAt(1.0));
    QCOMPARE(view()->colourBar()->low(), 5.0);
    QCOMPARE(view()->colourBar()->high(), 15.0);
    // the figure of merit: (mass, largest closed-loop real part), the core's numbers
    const QList<QPointF> fig = view()->figurePoints();
    QCOMPARE(fig.size(), 11);
    for (int i = 0; i < 11; ++i) {
      QCOMPARE(fig[i].x(), 5.0 + i);
      QVERIFY(std::abs(fig[i].y() - direct.variants[i].closed_max_real) <= 1e-12);
      QVERIFY(fig[i].y() < 0);
    }
    QCOMPARE(view()->failedTable()->rowCount(), 0);
    QCOMPARE(view()->progressBar()->value(), 11);
    QVERIFY(view()->statusLabel()->text().startsWith("11 of 11 variants completed, 0 failed; 11 stable"));

    // saved through the core's writers, guarded: never over the model file
    QTemporaryDir dir;
    QString error;
    QVERIFY(view()->saveResults(dir.filePath("rod.csv"), &error));
    QFile csv(dir.filePath("rod.csv"));
    QVERIFY(csv.open(QIODevice::ReadOnly));
    QVERIFY(csv.readLine().startsWith("variant,status,/bodies/1/mass,"));
    QVERIFY(view()->saveResults(dir.filePath("rod.h5"), &error));
    QVERIFY(view()->saveResults(dir.filePath("rod.mat"), &error));
    QVERIFY(QFile::exists(dir.filePath("rod.m")));
    QVERIFY(!view()->saveResults(kCart, &error));
    QVERIFY(!view()->saveResults(dir.filePath("rod.txt"), &error));
    QVERIFY(error.contains(".h5"));
  }

  void failedVariantIsListed() {
    QVERIFY(pickRodMass());
    typeSpec(0, "[-1,10]");
    QVERIFY(runAndWait());
    QVERIFY(view()->result());
    SweepRequest r;
    r.model = kCart.toStdString();
    r.vary = {"/bodies/1/mass=[-1,10]"};
    r.threads = 1;
    const SweepJob direct = study_sweep_job(r);
    QCOMPARE(direct.failed, 1LL);
    QTableWidget* failed = view()->failedTable();
    QCOMPARE(failed->rowCount(), 1);
    QCOMPARE(failed->item(0, 0)->text(), QStringLiteral("0"));
    QCOMPARE(failed->item(0, 1)->text(), QStringLiteral("rod.mass = -1"));  // as the tree names it
    QCOMPARE(failed->item(0, 2)->text(), QString::fromStdString(to_string(direct.variants[0].status)));
    QCOMPARE(failed->item(0, 3)->text(), QString::fromStdString(direct.variants[0].reason));
    QVERIFY(failed->item(0, 3)->text().contains("mass"));
    QCOMPARE(view()->resultTabs()->tabText(2), QStringLiteral("Failed (1)"));
    // the other variant is drawn, the failed one is not
    QCOMPARE(view()->plottedPoles(0).size(), 0);
    QCOMPARE(view()->plottedPoles(1).size(), 4);
  }

  void badSpecNamesTheField() {
    QVERIFY(pickRodMass());
    // the Is column names the field as the model tree does, and follows a rename
    QCOMPARE(view()->fieldTable()->item(0, 2)->text(), QString("rod.mass"));
    QVERIFY(!(view()->fieldTable()->item(0, 2)->flags() & Qt::ItemIsEditable));
    w->document()->edit("Rename", [](ModelSpec& s) { rename_element(s, ElementKind::Body, 1, "arm"); });
    QCOMPARE(view()->fieldTable()->item(0, 2)->text(), QString("arm.mass"));
    w->document()->undoStack()->undo();
    QCOMPARE(view()->fieldTable()->item(0, 2)->text(), QString("rod.mass"));
    typeSpec(0, "5:15:abc");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(!view()->isRunning());
    QVERIFY2(view()->statusLabel()->text().contains("/bodies/1/mass"), qPrintable(view()->statusLabel()->text()));
    // a field that is not in the file
    QTest::mouseClick(view()->addRowButton(), Qt::LeftButton);
    QTableWidget* t = view()->fieldTable();
    QCOMPARE(t->rowCount(), 2);
    typeSpec(0, "5:15:3");
    t->item(1, 0)->setText("/bodies/7/mass");
    QCOMPARE(t->item(1, 2)->text(), QString("(not a field of an element)"));  // said before the run
    t->item(1, 0)->setText("/bodies/1/name");
    QCOMPARE(t->item(1, 2)->text(), QString("(not a number)"));
    t->item(1, 0)->setText("/bodies/7/mass");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(!view()->isRunning());
    QVERIFY2(view()->statusLabel()->text().contains("/bodies/7/mass"), qPrintable(view()->statusLabel()->text()));
    QVERIFY(!view()->result());
  }

  void cancelStopsALongStudy() {
    QVERIFY(pickRodMass());
    typeSpec(0, "5:15:50000");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(view()->isRunning());
    QVERIFY(!view()->runButton()->isEnabled());
    QVERIFY(QTest::qWaitFor([this] { return view()->progressBar()->value() > 0; }, 60000));
    QTest::mouseClick(view()->cancelButton(), Qt::LeftButton);
    QElapsedTimer t;
    t.start();
    QVERIFY(QTest::qWaitFor([this] { return !view()->isRunning(); }, 60000));
    qInfo("stopped %lld ms after Cancel", qlonglong(t.elapsed()));
    QVERIFY2(view()->statusLabel()->text().contains("cancelled"), qPrintable(view()->statusLabel()->text()));
    QVERIFY(view()->progressBar()->value() < 50000);
    QVERIFY(!view()->result());
    QVERIFY(view()->runButton()->isEnabled());
    // and a study runs again after it
    typeSpec(0, "9:11:3");
    QVERIFY(runAndWait());
    QVERIFY(view()->result());
    QCOMPARE(view()->result()->variants.size(), std::size_t(3));
  }

  void closingWhileRunning() {
    QVERIFY(pickRodMass());
    typeSpec(0, "5:15:50000");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(view()->isRunning());
    QTest::qWait(200);
    QElapsedTimer t;
    t.start();
    // the window goes with the study running: the view (and the worker it joins in its destructor)
    // is gone once close returns, and what the worker posted meanwhile is dropped with it, not
    // delivered to a dead object (ASan would see that in the events processed after)
    const QPointer<SweepView> sweep(view());
    const QPointer<Document> doc(w->document());
    drive::close(w);
    qInfo("the window closed in %lld ms", qlonglong(t.elapsed()));
    QVERIFY(sweep.isNull());
    QVERIFY(doc.isNull());
    QTest::qWait(300);
    QVERIFY(t.elapsed() < 60000);  // cancelled, not the 50000 variants run out
  }
};

QTEST_MAIN(SweepViewTest)
#include "sweep_view_test.moc"
