// A randomized "monkey" test of codyna-gui: fixed seeds, thousands of random
// clicks, double clicks, right clicks, wheel turns, keys and typed values on
// whatever widget is visible (the model tree and property editor of every
// element type, the plant panels, the Linearize and Simulate views, their
// drop-downs, spin boxes, line edits, tables and buttons), with popups and
// dialogs closed as they open. What it asserts: the process survives, the
// document stays consistent (its spec reads back through the model file
// reader), and the monkey did reach edits, undo steps and every element kind.
// Built and run under ASan + UBSan by scripts/sanitize.sh as well.
//
// It works on a copy of the cart-pendulum (or of the sedan with its .tir file) in a scratch folder
// with a scratch HOME, and the window's file questions answer "no file", so nothing outside
// that folder can be written or deleted.
//
// CODYNA_MONKEY_EVENTS (default 4000) sets the events per seed; the seeds are 1..5 (the even ones
// build a model from File > New, the odd ones edit the cart-pendulum) and 6..7 on
// examples/sedan.json (issue 39: 25 bodies, closed loops, Magic Formula tires from a .tir file, a
// steady motion as its operating point), half as many events each (every edit compiles the car);
// the sedan is linearized when it is opened (and opened afresh from examples/ now and then), and
// the Linearize, Simulate and Tire tabs come to the front now and then, Linearize pressed, so that
// the steady operating point, its handling numbers, its tire forces and the tire curves are in
// the monkey's reach.
#include <QAbstractItemView>
#include <QAction>
#include <QAbstractSpinBox>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDialog>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QLineEdit>
#include <QMenu>
#include <QMessageBox>
#include <QPointer>
#include <QPushButton>
#include <QRandomGenerator>
#include <QSet>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QTreeView>
#include <QUndoStack>
#include <QWheelEvent>
#include <algorithm>
#include <nlohmann/json.hpp>

#include "gui/control_view.hpp"
#include "gui/kc_view.hpp"
#include "gui/linearize_view.hpp"
#include "gui/maneuver_view.hpp"
#include "gui/main_window.hpp"
#include "gui/property_editor.hpp"
#include "gui/simulate_view.hpp"
#include "gui/tire_view.hpp"
#include "io/model_file.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");
const QString kSedan = QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json");
constexpr quint32 kSedanSeeds[] = {6, 7};
bool onSedan(quint32 seed) { return std::find(std::begin(kSedanSeeds), std::end(kSedanSeeds), seed) != std::end(kSedanSeeds); }

const char* const kTexts[] = {"1",    "-2.5", "0",     "inf",    "nan",  "1e400", "abc",   "1, 2", "",
                              "0.1 0 0", "body", "ground", "rod", "cart", "3; 4", "{}",   "[1]",  "-1e-9",
                              "1e6",  "joint", "force", "x",   "0 0 1",  "true", "  7  ", "1,2,3"};

// closes every popup and dialog that opens while the monkey's own event is being handled
class Closer : public QObject {
 public:
  Closer() {
    timer_.setInterval(5);
    connect(&timer_, &QTimer::timeout, this, [] {
      if (QWidget* p = QApplication::activePopupWidget()) p->close();
      if (QWidget* m = QApplication::activeModalWidget()) {
        if (auto* d = qobject_cast<QDialog*>(m)) d->reject();
        else m->close();
      }
    });
    timer_.start();
  }

 private:
  QTimer timer_;
};

}  // namespace

class MonkeyTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir scratch_;

  static QList<QWidget*> targets(QWidget* root) {
    QList<QWidget*> out;
    for (QWidget* c : root->findChildren<QWidget*>()) {
      if (!c->isVisible() || !c->isEnabled() || c->width() < 2 || c->height() < 2) continue;
      if (c->window() != root) continue;  // not popups (closed by the Closer)
      out << c;
    }
    return out;
  }

  // one run of `events` random events with generator seed `seed`
  void runSeed(quint32 seed, int events) {
    QVERIFY(scratch_.isValid());
    const QString dir = scratch_.filePath(QStringLiteral("seed%1").arg(seed));
    QVERIFY(QDir().mkpath(dir));
    const bool sedan = onSedan(seed);
    const QString model = dir + (sedan ? "/sedan.json" : "/cart_pendulum.json");
    QFile::remove(model);
    QVERIFY(QFile::copy(sedan ? kSedan : kCart, model));
    QFile::setPermissions(model, QFile::ReadOwner | QFile::WriteOwner);
    // the sedan as it is in examples/ (the monkey may have saved over its copy)
    const auto freshSedan = [&] {
      QFile::remove(model);
      return QFile::copy(kSedan, model) && QFile::setPermissions(model, QFile::ReadOwner | QFile::WriteOwner);
    };
    if (sedan) {
      // its tires read tires/MagicFormula61_Paramerters.tir beside it
      QVERIFY(QDir().mkpath(dir + "/tires"));
      const QString tir = dir + "/tires/MagicFormula61_Paramerters.tir";
      QFile::remove(tir);
      QVERIFY(QFile::copy(QStringLiteral(CODYNA_EXAMPLES_DIR "/tires/MagicFormula61_Paramerters.tir"), tir));
      QFile::setPermissions(tir, QFile::ReadOwner | QFile::WriteOwner);
    }
    QDir::setCurrent(dir);

    QRandomGenerator rng(seed);
    auto w = std::make_unique<MainWindow>();
    w->setQuestionHook([&rng](const QString&, const QString&, int buttons) {
      // any of the offered answers
      QList<int> offered;
      for (int b : {int(QMessageBox::Yes), int(QMessageBox::No), int(QMessageBox::Save), int(QMessageBox::Discard),
                    int(QMessageBox::Cancel), int(QMessageBox::Ok)})
        if (buttons & b) offered << b;
      return offered.isEmpty() ? int(QMessageBox::Cancel) : offered[int(rng.bounded(offered.size()))];
    });
    w->setFileHook([](const QString&, const QString&, const QString&, bool) { return QString(); });
    w->resize(1400, 900);
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
    // even seeds build from File > New, as a newcomer does (the model does not compile for a while,
    // its Issues list grows and shrinks, the Add bar and the tree's context menu are in reach);
    // odd seeds work on the finished cart-pendulum
    const bool from_empty = !sedan && seed % 2 == 0;
    if (from_empty) QVERIFY(w->newModel());
    else QVERIFY(w->openFile(model));
    Closer closer;

    int spec_changes = 0, linearized = 0, tire_tab = 0, maneuver_tab = 0, maneuver_runs = 0, maneuvers_done = 0;
    connect(w->maneuverView(), &ManeuverView::finished, w.get(), [&] { ++maneuvers_done; });
    connect(w->document(), &Document::specChanged, w.get(), [&] { ++spec_changes; });
    connect(w->linearizeView(), &LinearizeView::linearized, w.get(), [&] { ++linearized; });
    // the sedan opened as in examples/ is linearized first, as a person would: the steady motion at
    // 25 m/s, its handling numbers and its tire forces in the 3-D view, which the events then meet
    const auto linearizeSedan = [&] {
      w->analysisTabs()->setCurrentWidget(w->linearizeView());
      QTest::mouseClick(w->linearizeView()->linearizeButton(), Qt::LeftButton);
    };
    if (sedan) {
      linearizeSedan();
      QCOMPARE(linearized, 1);
    }
    QSet<QString> classes;
    QSet<int> kinds_edited;
    int max_undo = 0;

    for (int e = 0; e < events; ++e) {
      if (!w->isVisible()) w->show();  // Quit answered "discard" closes it: reopen and go on
      if (e % 300 == 299) {
        // as a person would stop a run that goes on too long (a simulation, a maneuver, an estimate)
        w->simulateView()->cancel();
        w->maneuverView()->cancel();
        w->controlView()->cancelEstimate();
      }
      if (e % 500 == 250) {
        // a person opens the model again now and then (every kind of element comes back)
        w->document()->undoStack()->setClean();
        if (sedan) QVERIFY(freshSedan());
        if (from_empty) QVERIFY(w->newModel());
        else QVERIFY(w->openFile(model));
        if (sedan) linearizeSedan();
      }
      if (sedan && e % 40 == 20) {
        // a person looks at another analysis now and then: Linearize (pressed: the steady motion,
        // the handling numbers, the tires' forces in the 3-D view), Simulate, the tire's curves,
        // the maneuvers (whose Run the events may press: its run then plays in the 3-D view), the
        // Control view (its Estimate too) or K&C
        QTabWidget* tabs = w->analysisTabs();
        QWidget* pages[] = {w->linearizeView(), w->simulateView(), w->tireView(), w->maneuverView(), w->controlView(), w->kcView()};
        // in turn, not drawn: how many draws the random events take depends on the popups they
        // meet, so a drawn page could miss a tab in a run (seed 7 once never showed the Tire tab)
        QWidget* page = pages[(e / 40) % 6];
        tabs->setCurrentWidget(page);
        if (page == w->tireView()) ++tire_tab;
        if (page == w->maneuverView()) ++maneuver_tab;
        // and presses Run there (the maneuver the events left picked: its run then plays in the 3-D
        // view, and the events go on meanwhile), or Analyse in the Control view
        if (page == w->maneuverView() && rng.bounded(2) == 0 && w->maneuverView()->runButton()->isEnabled()) {
          QTest::mouseClick(w->maneuverView()->runButton(), Qt::LeftButton);
          ++maneuver_runs;
        }
        if (page == w->controlView() && rng.bounded(2) == 0) QTest::mouseClick(w->controlView()->analyseButton(), Qt::LeftButton);
        if (page == w->linearizeView() && rng.bounded(2) == 0 && w->linearizeView()->linearizeButton()->isEnabled())
          QTest::mouseClick(w->linearizeView()->linearizeButton(), Qt::LeftButton);
      }
      if (from_empty && e % 10 == 5) {
        // building: an element of any kind added now and then (the Add bar's and Edit > Add's
        // actions, whose shortcuts are Ctrl+Shift+B, J, L, E, U, Y), the random events then edit it
        static const char* kinds[] = {"body", "joint", "constraint", "effect", "actuator", "sensor"};
        if (auto* add = w->findChild<QAction*>(QStringLiteral("actionAdd:%1").arg(kinds[rng.bounded(6)]))) add->trigger();
      }
      if (e % 25 == 0) {
        // a person picks an element in the model tree now and then: a click on one of its rows
        QTreeView* tree = w->modelTree();
        tree->expandAll();
        QList<QModelIndex> rows;
        for (int r = 0; r < tree->model()->rowCount(); ++r) {
          const QModelIndex group = tree->model()->index(r, 0);
          for (int c = 0; c < tree->model()->rowCount(group); ++c) rows << tree->model()->index(c, 0, group);
        }
        if (!rows.isEmpty()) {
          const QModelIndex pick = rows[int(rng.bounded(rows.size()))];
          tree->scrollTo(pick);
          const QRect r = tree->visualRect(pick);
          if (r.isValid()) QTest::mouseClick(tree->viewport(), Qt::LeftButton, {}, r.center());
        }
      }
      QList<QWidget*> all = targets(w.get());
      if (all.isEmpty()) continue;
      // a third of the events go to the model editing half: tree and property editor
      QList<QWidget*> pool = all;
      if (rng.bounded(3) == 0) {
        QList<QWidget*> left;
        for (QWidget* c : all)
          if (w->propertyEditor()->isAncestorOf(c) || c == w->modelTree()->viewport()) left << c;
        if (!left.isEmpty()) pool = left;
      }
      QPointer<QWidget> t = pool[int(rng.bounded(pool.size()))];
      classes << QString::fromLatin1(t->metaObject()->className());
      const QPoint at(int(rng.bounded(t->width())), int(rng.bounded(t->height())));
      const int action = int(rng.bounded(100));
      if (action < 38) {
        QTest::mouseClick(t, Qt::LeftButton, {}, at);
      } else if (action < 42) {
        QTest::mouseDClick(t, Qt::LeftButton, {}, at);
      } else if (action < 45) {
        QTest::mouseClick(t, Qt::RightButton, {}, at);
      } else if (action < 55) {
        const QPointF p(at);
        QWheelEvent wheel(p, t->mapToGlobal(p), QPoint(), QPoint(0, rng.bounded(2) ? 120 : -120), Qt::NoButton,
                          Qt::NoModifier, Qt::NoScrollPhase, false);
        QApplication::sendEvent(t, &wheel);
      } else if (action < 80) {
        static const Qt::Key keys[] = {Qt::Key_Up,     Qt::Key_Down,  Qt::Key_Left,  Qt::Key_Right, Qt::Key_Return,
                                       Qt::Key_Escape, Qt::Key_Tab,   Qt::Key_Space, Qt::Key_Home,  Qt::Key_End,
                                       Qt::Key_PageUp, Qt::Key_PageDown, Qt::Key_F2, Qt::Key_Delete, Qt::Key_Backspace};
        QPointer<QWidget> f = QApplication::focusWidget() ? QApplication::focusWidget() : t.data();
        if (!f) continue;
        Qt::KeyboardModifiers mod = Qt::NoModifier;
        Qt::Key key = keys[rng.bounded(int(std::size(keys)))];
        const int m = int(rng.bounded(20));
        if (m == 0) { mod = Qt::ControlModifier; key = Qt::Key_Z; }            // undo
        else if (m == 1) { mod = Qt::ControlModifier | Qt::ShiftModifier; key = Qt::Key_Z; }  // redo
        else if (m == 2) { mod = Qt::ControlModifier; key = Qt::Key_D; }       // duplicate
        QTest::keyClick(f, key, mod);
      } else {
        // typed text, confirmed with Enter, into the focused field or the target
        QPointer<QWidget> f = QApplication::focusWidget();
        if (!f || !w->isAncestorOf(f)) {
          QTest::mouseClick(t, Qt::LeftButton, {}, at);
          f = QApplication::focusWidget();
        }
        if (f && w->isAncestorOf(f)) {
          if (auto* le = qobject_cast<QLineEdit*>(f)) le->selectAll();
          QTest::keyClicks(f, QString::fromUtf8(kTexts[rng.bounded(int(std::size(kTexts)))]));
          if (f) QTest::keyClick(f, Qt::Key_Return);
        }
      }
      if (const auto id = w->propertyEditor()->element()) kinds_edited << int(id->kind);
      max_undo = std::max(max_undo, w->document()->undoStack()->count());
      if (e % 4 == 0) QTest::qWait(0);  // deferred deletes, queued signals, worker results
    }
    // the document is still a model a file can hold: its spec writes and reads back
    const nlohmann::json j = to_json(w->document()->spec());
    try {
      (void)parse_model_spec(j, "monkey.json");
    } catch (const std::exception& ex) {
      QFAIL(qPrintable(QString("the document's spec no longer reads back: %1").arg(ex.what())));
    }
    // the monkey did reach the editing paths
    qInfo("seed %u (%s): %d events, %d spec changes, undo stack up to %d, %lld widget classes, %lld element kinds selected, "
          "%d linearizations, the Tire tab shown %d times, the Maneuvers tab %d times, %d maneuvers run (%d ended)",
          seed, sedan ? "sedan" : from_empty ? "from File > New" : "cart-pendulum", events, spec_changes, max_undo,
          qlonglong(classes.size()), qlonglong(kinds_edited.size()), linearized, tire_tab, maneuver_tab, maneuver_runs, maneuvers_done);
    if (sedan) QVERIFY(tire_tab > 0 && maneuver_tab > 0);
    QVERIFY(spec_changes > events / 100);
    QVERIFY(kinds_edited.size() >= 4);  // the property editor of most element kinds was open
    QVERIFY(classes.contains("QComboBox"));
    QVERIFY(classes.contains("QLineEdit"));
    // Cancel takes effect at the next step of a run; a run's setup (an operating-point search, a
    // time=T pre-run the monkey may have set to hundreds of seconds) is not interruptible, and under
    // the sanitizers it can take minutes
    w->simulateView()->cancel();
    w->maneuverView()->cancel();
    w->controlView()->cancelEstimate();
    QElapsedTimer waited;
    waited.start();
    QVERIFY(QTest::qWaitFor([&] { return !w->simulateView()->isRunning() && !w->maneuverView()->isRunning() && !w->controlView()->isEstimating(); }, 600000));
    if (waited.elapsed() > 5000) qInfo("seed %u: the last run took %lld ms to stop after Cancel", seed, qlonglong(waited.elapsed()));
    w->document()->undoStack()->setClean();
    w.reset();
    QTest::qWait(0);
  }

 private slots:
  void initTestCase() {
    QCoreApplication::setOrganizationName("codyna-test");
    QCoreApplication::setApplicationName("monkey_test");
  }

  void randomEvents_data() {
    QTest::addColumn<quint32>("seed");
    for (quint32 s = 1; s <= 5; ++s) QTest::newRow(qPrintable(QStringLiteral("seed %1").arg(s))) << s;
    for (quint32 s : kSedanSeeds) QTest::newRow(qPrintable(QStringLiteral("seed %1 sedan").arg(s))) << s;
  }
  void randomEvents() {
    QFETCH(quint32, seed);
    bool ok = false;
    int events = qEnvironmentVariableIntValue("CODYNA_MONKEY_EVENTS", &ok);
    if (!ok || events <= 0) events = 4000;
    // the sanitizer build's 4000 events: the sedan seeds are left to the release run (500 events
    // each). Under ASan a steady search that fails on an edited car runs minutes on the window's
    // thread (12 s in release; Linearize is not on a worker yet) and passed QtTest's 300 s limit.
    if (onSedan(seed) && events >= 4000) QSKIP("the sedan seeds run in the release build (Linearize on the GUI thread is minutes under ASan)");
    runSeed(seed, onSedan(seed) ? events / 2 : events);
  }
};

int main(int argc, char** argv) {
  // a scratch HOME (settings, recent files, dialogs' start folders) before Qt reads it
  QTemporaryDir home;
  qputenv("HOME", home.path().toLocal8Bit());
  qputenv("XDG_CONFIG_HOME", (home.path() + "/.config").toLocal8Bit());
  qputenv("XDG_DATA_HOME", (home.path() + "/.local/share").toLocal8Bit());
  QApplication app(argc, argv);
  MonkeyTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "monkey_test.moc"
