// Tires in codyna-gui (issue 39), driven as a person does: a wheel on a free joint opened, an effect
// added from Edit > Add, "tire" picked from its type list with the mouse (it compiles at once as a
// linear tire of 0.3 m), its law changed to magic_formula from the list (the compile's error at
// `file`, no crash), the .tir chosen in the file dialog opened by "..." (Qt's own dialog: the path
// typed into its file name field, Open clicked), stored relative to the model file, the side picked
// with the keys; a .tir that does not read chosen the same way: the core's message naming the file
// at the field, the window alive.
// The Tire tab clicked: the plotted Fy over the slip angle of the linear tire is -C alpha (ISO-W),
// and of the Magic Formula tire the values study_tire_job gives for the saved model's tire at the
// same load and slip (1e-12), as are Fx, Mz and the combined-slip curves; a load typed changes the
// curves to the job's at that load; a bad .tir opened in the view shows the reader's message.
// The 3-D scene draws the tire on its shapeless wheel: a cylinder of its radius about its axle.
#include <QAbstractButton>
#include <QApplication>
#include <QChart>
#include <QComboBox>
#include <QContextMenuEvent>
#include <QMenu>
#include <QTreeView>
#include <QDialogButtonBox>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QPushButton>
#include <QTabBar>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <cmath>
#include <numbers>

#include "drive.hpp"
#include "gui/chart_view.hpp"
#include "gui/main_window.hpp"
#include "gui/property_editor.hpp"
#include "gui/scene3d.hpp"
#include "gui/tire_view.hpp"
#include "study/tire_job.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kBookTir = QStringLiteral(CODYNA_TEST_DATA_DIR "/tires/PacejkaBook_Defaults.tir");
constexpr double kDeg = std::numbers::pi / 180.0;

const char* const kWheelModel = R"({
  "codyna_model": 1,
  "name": "wheel_on_road",
  "bodies": [{"name": "wheel", "mass": 10, "com": [0, 0, 0], "inertia": [0.3, 0.5, 0.3]}],
  "joints": [{"name": "float", "type": "free", "parent": "ground", "child": "wheel", "q0": [0, 0, 0.3, 1, 0, 0, 0]}],
  "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]}]
})";

// the series of `view` named `name` (nullptr when none)
QLineSeries* series(ChartView* view, const QString& name) {
  for (QAbstractSeries* s : view->chart()->series())
    if (s->name() == name) return qobject_cast<QLineSeries*>(s);
  return nullptr;
}

bool close_to(double a, double b, double rel) { return std::abs(a - b) <= rel * std::max(1.0, std::abs(b)); }

}  // namespace

class TireViewTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;
  QTemporaryDir dir;
  int tire = -1;  // the tire's index among the effects

  PropertyEditor* props() { return w->propertyEditor(); }
  QComboBox* combo(const QString& field) { return qobject_cast<QComboBox*>(props()->editorFor(field)); }
  const EffectSpec& effect() { return w->document()->spec().effects[static_cast<std::size_t>(tire)]; }

  // the file dialog `name` (window-modal, opened by `open`) answered with `path` typed into its
  // file name field and its Open button clicked, as a person does
  QString answerFileDialog(const QString& name, const std::function<void()>& open, const QString& path) {
    open();
    QFileDialog* d = nullptr;
    (void)QTest::qWaitFor([&] {
      d = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
      return d && d->isVisible();
    }, 3000);
    if (!d || d->objectName() != name) return "no file dialog " + name;
    auto* e = d->findChild<QLineEdit*>("fileNameEdit");
    auto* box = d->findChild<QDialogButtonBox*>("buttonBox");
    if (!e || !box || !box->button(QDialogButtonBox::Open)) return "not Qt's own file dialog";
    // the file picked (its folder opened, the file selected: what a click on it in the list does;
    // typed key by key, the dialog follows each '/' into its folder, and under the offscreen platform
    // the field has no keyboard focus to drop the selection it started with), then Open clicked
    d->selectFile(path);
    QTest::qWait(50);
    if (QWidget* p = QApplication::activePopupWidget()) p->close();
    if (d->selectedFiles() != QStringList{QFileInfo(path).absoluteFilePath()})
      return "the dialog selected " + d->selectedFiles().join(", ") + " (the name field: " + e->text() + ")";
    QTest::mouseClick(box->button(QDialogButtonBox::Open), Qt::LeftButton);
    if (!QTest::qWaitFor([d] { return !d->isVisible(); }, 3000))
      return "the dialog stayed open: " + e->text() + (box->button(QDialogButtonBox::Open)->isEnabled() ? " enabled" : " disabled") +
             " popup " + (QApplication::activePopupWidget() ? "yes" : "no") + " dir " + d->directory().path();
    return {};
  }

  // the "..." beside the file field shown now (not one of a rebuild's retired rows)
  // (a row added to the form is shown from the event loop: waited for, as a person sees it appear)
  QPushButton* browseButton() {
    QPushButton* b = nullptr;
    (void)QTest::qWaitFor([&] {
      QWidget* e = props()->editorFor("file");
      b = e && e->parentWidget() ? e->parentWidget()->findChild<QPushButton*>("browse:file") : nullptr;
      return b && b->isVisible();
    }, 2000);
    return b;
  }

  void showTireTab() {
    QTabBar* bar = w->analysisTabs()->tabBar();
    const int at = w->analysisTabs()->indexOf(w->tireView());
    QVERIFY(at >= 0);
    QTest::mouseClick(bar, Qt::LeftButton, {}, bar->tabRect(at).center());
    QCOMPARE(w->analysisTabs()->currentWidget(), static_cast<QWidget*>(w->tireView()));
  }

 private slots:
  void initTestCase() {
    QVERIFY(dir.isValid());
    QVERIFY(QDir(dir.path()).mkpath("tires"));
    QVERIFY(QFile::copy(kBookTir, dir.filePath("tires/PacejkaBook_Defaults.tir")));
    // a .tir that does not read: an unknown FITTYP
    QFile book(kBookTir);
    QVERIFY(book.open(QIODevice::ReadOnly));
    QByteArray text = book.readAll();
    const qsizetype at = text.indexOf("FITTYP");
    QVERIFY(at >= 0);
    const qsizetype eol = text.indexOf('\n', at);
    text.replace(at, eol - at, "FITTYP                   =    99");
    QFile bad(dir.filePath("tires/bad.tir"));
    QVERIFY(bad.open(QIODevice::WriteOnly));
    bad.write(text);
    bad.close();
    QFile model(dir.filePath("wheel.json"));
    QVERIFY(model.open(QIODevice::WriteOnly));
    model.write(kWheelModel);
    model.close();
    w = drive::window("tire_view_test");
    QVERIFY(w);
    QVERIFY(w->openFile(dir.filePath("wheel.json")));
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
  }

  void cleanupTestCase() { drive::close(w); }

  // Edit > Add > Effect, "tire" picked from the type list with the mouse: a linear tire on the wheel
  // that compiles
  void tireBuiltByClicks() {
    QVERIFY(drive::addElement(w.get(), "effect").isEmpty());
    tire = props()->element()->index;
    QVERIFY(combo("type"));
    QVERIFY(combo("type")->findText("tire") >= 0);
    QVERIFY(drive::pickWithMouse(combo("type"), "tire"));
    QCOMPARE(effect().type, EffectType::Tire);
    QCOMPARE(effect().name, std::string("tire"));  // the default name follows the type
    QCOMPARE(effect().law, std::string("linear"));
    QVERIFY(drive::pickWithMouse(combo("body"), "wheel"));
    QCOMPARE(effect().body_a, std::string("wheel"));
    QVERIFY(effect().unloaded_radius && *effect().unloaded_radius == 0.3);
    QCOMPARE(effect().cornering_stiffness, 80000.0);
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->model()->tires.size(), std::size_t(1));
    // typed fields with units
    QVERIFY(drive::typeTaken(w.get(), "unloaded_radius", "0.31").isEmpty());
    QCOMPARE(*effect().unloaded_radius, 0.31);
    QVERIFY(drive::typeTaken(w.get(), "cornering_stiffness", "90000").isEmpty());
    QCOMPARE(effect().cornering_stiffness, 90000.0);
  }

  // the linear tire's curves: Fy = -C alpha (ISO-W), Mz = 0 (no trail), Fx = C_kappa kappa
  void linearTireCurves() {
    showTireTab();
    TireView* v = w->tireView();
    QCOMPARE(v->sourceBox()->currentText(), QString("tire"));
    QVERIFY2(v->errorText().isEmpty(), qPrintable(v->errorText()));
    QCOMPARE(v->loadsEdit()->text(), QString("2000, 4000, 6000"));
    QLineSeries* fy = series(v->lateralView(), "Fz = 4000 N");
    QVERIFY(fy);
    QCOMPARE(fy->count(), 121);
    for (const QPointF& p : fy->points()) QVERIFY(close_to(p.y(), -90000.0 * p.x() * kDeg, 1e-12));
    QVERIFY(close_to(fy->at(120).x(), 15.0, 1e-14) && fy->at(120).y() < 0);  // positive slip angle, negative Fy
    for (const QPointF& p : series(v->aligningView(), "Fz = 4000 N")->points()) QCOMPARE(p.y(), 0.0);
    for (const QPointF& p : series(v->longitudinalView(), "Fz = 2000 N")->points()) QVERIFY(close_to(p.y(), 100000.0 * p.x() / 100.0, 1e-12));
    // axes with units
    QChart* c = v->lateralView()->chart();
    QCOMPARE(c->axes(Qt::Horizontal).value(0)->titleText(), QString("slip angle alpha [deg]"));
    QCOMPARE(c->axes(Qt::Vertical).value(0)->titleText(), QString("Fy [N]"));
    QCOMPARE(v->aligningView()->chart()->axes(Qt::Vertical).value(0)->titleText(), QString("Mz [N m]"));
    QCOMPARE(v->longitudinalView()->chart()->axes(Qt::Horizontal).value(0)->titleText(), QString("longitudinal slip kappa [%]"));
    // the curves follow an edit of the tire
    QVERIFY(drive::typeTaken(w.get(), "cornering_stiffness", "70000").isEmpty());
    fy = series(v->lateralView(), "Fz = 4000 N");
    QVERIFY(fy && close_to(fy->at(0).y(), 70000.0 * 15.0 * kDeg, 1e-12));
  }

  // the law changed to magic_formula from its list: the compile asks for the file at `file`; the
  // .tir chosen in the dialog, stored relative to the model file; the model compiles
  void magicFormulaFileChosen() {
    QVERIFY(drive::pickWithMouse(combo("law"), "magic_formula"));
    QCOMPARE(effect().law, std::string("magic_formula"));
    QVERIFY(!effect().unloaded_radius);  // the file's
    QVERIFY(!w->document()->errorText().isEmpty());
    QVERIFY2(props()->markedFields().contains("file"), qPrintable(props()->markedFields().join(",")));
    QVERIFY(w->isVisible());
    // the Tire view says why it draws nothing
    QVERIFY2(w->tireView()->errorText().contains("file"), qPrintable(w->tireView()->errorText()));
    QPushButton* browse = browseButton();
    QVERIFY(browse && browse->isVisible());
    const QString why = answerFileDialog("tireFileDialog", [browse] { QTest::mouseClick(browse, Qt::LeftButton); },
                                         dir.filePath("tires/PacejkaBook_Defaults.tir"));
    QVERIFY2(why.isEmpty(), qPrintable(why));
    QCOMPARE(effect().file, std::string("tires/PacejkaBook_Defaults.tir"));
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
    QVERIFY(props()->markedFields().isEmpty());
    // the side picked with the keys, and back to the file's
    QVERIFY(drive::pickWithKeys(combo("side"), "right"));
    QCOMPARE(effect().side, std::string("right"));
    QVERIFY(drive::pickWithMouse(combo("side"), "as the file"));
    QCOMPARE(effect().side, std::string());
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
  }

  // every curve plotted is study_tire_job's value for the saved model's tire (1e-12)
  void magicFormulaCurvesAreTheJobs() {
    QVERIFY(w->saveFile());
    TireView* v = w->tireView();
    QVERIFY2(v->errorText().isEmpty(), qPrintable(v->errorText()));
    QCOMPARE(v->loadsEdit()->text(), QString("2000, 4000, 6000"));  // 0.5, 1, 1.5 FNOMIN
    TireRequest r;
    r.model = ss(dir.filePath("wheel.json"));
    r.tire = "tire";
    r.gamma = {0.0};
    auto job = [&](double fz, double alpha, double kappa) {
      TireRequest q = r;
      q.loads = {fz};
      q.alpha = {alpha};
      q.kappa = {kappa};
      const TireJob j = study_tire_job(q);
      return j.rows.row(0).eval();  // Fx Fy Fz Mx My Mz ...
    };
    for (int load : {2000, 4000, 6000}) {
      const QString name = QStringLiteral("Fz = %1 N").arg(load);
      QLineSeries* fy = series(v->lateralView(), name);
      QLineSeries* mz = series(v->aligningView(), name);
      QLineSeries* fx = series(v->longitudinalView(), name);
      QVERIFY(fy && mz && fx);
      for (int k : {10, 67, 100}) {
        const Eigen::VectorXd a = job(load, fy->at(k).x() * kDeg, 0.0);
        QVERIFY2(close_to(fy->at(k).y(), a(1), 1e-12), qPrintable(QString("%1 %2").arg(fy->at(k).y(), 0, 'g', 17).arg(a(1), 0, 'g', 17)));
        QVERIFY(close_to(mz->at(k).y(), a(5), 1e-12));
        const Eigen::VectorXd b = job(load, 0.0, fx->at(k).x() / 100.0);
        QVERIFY(close_to(fx->at(k).y(), b(0), 1e-12));
      }
    }
    // the book tire's cornering stiffness at FNOMIN, -48000 N/rad (ISO-W), from the plotted slope at 0
    QLineSeries* fy = series(v->lateralView(), "Fz = 4000 N");
    const double slope = (fy->at(61).y() - fy->at(59).y()) / ((fy->at(61).x() - fy->at(59).x()) * kDeg);
    QVERIFY2(std::abs(slope + 48000.0) < 100.0, qPrintable(QString::number(slope)));
    // combined slip at the middle load: Fy against Fx with kappa swept, at each slip angle
    for (int alpha : {1, 2, 4, 8}) {
      QLineSeries* s = series(v->combinedView(), QStringLiteral("alpha = %1 deg").arg(alpha));
      QVERIFY(s);
      QCOMPARE(s->count(), 121);
      const double kappa = -0.3 + 0.6 * 30 / 120.0;
      const Eigen::VectorXd c = job(4000, alpha * kDeg, kappa);
      QVERIFY(close_to(s->at(30).x(), c(0), 1e-12) && close_to(s->at(30).y(), c(1), 1e-12));
    }
    QCOMPARE(v->combinedView()->chart()->axes(Qt::Horizontal).value(0)->titleText(), QString("Fx [N]"));
    // a load typed: the curves change to the job's at that load
    const double before = fy->at(100).y();
    v->loadsEdit()->setFocus();
    v->loadsEdit()->selectAll();
    QTest::keyClicks(v->loadsEdit(), "3000");
    QTest::keyClick(v->loadsEdit(), Qt::Key_Return);
    QCOMPARE(v->lateralView()->chart()->series().size(), qsizetype(1));
    fy = series(v->lateralView(), "Fz = 3000 N");
    QVERIFY(fy);
    QVERIFY(fy->at(100).y() != before);
    QVERIFY(close_to(fy->at(100).y(), job(3000, fy->at(100).x() * kDeg, 0.0)(1), 1e-12));
    QVERIFY(series(v->combinedView(), "alpha = 8 deg"));
    // a load that is not a number: refused naming the field, nothing drawn, the window alive
    v->loadsEdit()->selectAll();
    QTest::keyClicks(v->loadsEdit(), "heavy");
    QTest::keyClick(v->loadsEdit(), Qt::Key_Return);
    QVERIFY2(v->errorText().contains("Loads"), qPrintable(v->errorText()));
    QVERIFY(v->lateralView()->chart()->series().isEmpty());
    v->loadsEdit()->clear();
    QTest::mouseClick(v->findChild<QPushButton*>("tirePlot"), Qt::LeftButton);
    QVERIFY(v->errorText().isEmpty());
    QCOMPARE(v->lateralView()->chart()->series().size(), qsizetype(3));
  }

  // a .tir that does not read: chosen for the tire, the reader's message naming the file at the
  // field; opened in the Tire view, the same message there; nothing crashes
  void badTirFile() {
    QPushButton* browse = browseButton();
    QVERIFY(browse && browse->isVisible());
    QString why = answerFileDialog("tireFileDialog", [browse] { QTest::mouseClick(browse, Qt::LeftButton); },
                                   dir.filePath("tires/bad.tir"));
    QVERIFY2(why.isEmpty(), qPrintable(why));
    QVERIFY2(effect().file == "tires/bad.tir", effect().file.c_str());
    QVERIFY2(w->document()->errorText().contains("bad.tir"), qPrintable(w->document()->errorText()));
    QVERIFY2(props()->errorText().contains("bad.tir") && props()->markedFields().contains("file"), qPrintable(props()->errorText()));
    QVERIFY2(w->tireView()->errorText().contains("bad.tir"), qPrintable(w->tireView()->errorText()));
    QVERIFY(w->tireView()->lateralView()->chart()->series().isEmpty());
    // undone: the good file again, curves back
    w->document()->undoStack()->undo();
    QCOMPARE(effect().file, std::string("tires/PacejkaBook_Defaults.tir"));
    QVERIFY(w->tireView()->errorText().isEmpty());
    QVERIFY(!w->tireView()->lateralView()->chart()->series().isEmpty());

    TireView* v = w->tireView();
    QPushButton* open = v->findChild<QPushButton*>("openTirFile");
    QVERIFY(open);
    why = answerFileDialog("tireViewFileDialog", [open] { QTest::mouseClick(open, Qt::LeftButton); }, dir.filePath("tires/bad.tir"));
    QVERIFY2(why.isEmpty(), qPrintable(why));
    QCOMPARE(v->sourceBox()->currentText(), QString("bad.tir"));
    QVERIFY2(v->errorText().contains("bad.tir") && v->errorText().contains("FITTYP"), qPrintable(v->errorText()));
    QVERIFY(v->lateralView()->chart()->series().isEmpty());
    QVERIFY(w->isVisible());
    // the good file opened in the view: the book tire's curves, as `codyna tire --tir` gives them
    why = answerFileDialog("tireViewFileDialog", [open] { QTest::mouseClick(open, Qt::LeftButton); },
                           dir.filePath("tires/PacejkaBook_Defaults.tir"));
    QVERIFY2(why.isEmpty(), qPrintable(why));
    QVERIFY2(v->errorText().isEmpty(), qPrintable(v->errorText()));
    QCOMPARE(v->loadsEdit()->text(), QString("2000, 4000, 6000"));
    QLineSeries* fx = series(v->longitudinalView(), "Fz = 4000 N");
    QVERIFY(fx);
    TireRequest q;
    q.tir = ss(dir.filePath("tires/PacejkaBook_Defaults.tir"));
    q.loads = {4000};
    q.kappa = {fx->at(70).x() / 100.0};
    q.alpha = {0.0};
    q.gamma = {0.0};
    QVERIFY(close_to(fx->at(70).y(), study_tire_job(q).rows(0, 0), 1e-12));
    // the tire element chosen again from the list
    QVERIFY(drive::pickWithMouse(v->sourceBox(), "tire"));
    QVERIFY(v->errorText().isEmpty());
    QVERIFY(series(v->lateralView(), "Fz = 4000 N"));
  }

  // the tree's selection of a tire shows it in the Tire view
  void treeSelectionShowsTheTire() {
    TireView* v = w->tireView();
    QVERIFY(drive::pickWithMouse(v->sourceBox(), "PacejkaBook_Defaults.tir"));
    QVERIFY(drive::clickElement(w.get(), ElementKind::Effect, 0).isEmpty());  // gravity
    QCOMPARE(v->sourceBox()->currentText(), QString("PacejkaBook_Defaults.tir"));
    QVERIFY(drive::clickElement(w.get(), ElementKind::Effect, tire).isEmpty());
    QCOMPARE(v->sourceBox()->currentText(), QString("tire"));
  }

  // the 3-D scene draws the tire on its shapeless wheel: a cylinder of the unloaded radius about
  // its axle at its centre
  void sceneDrawsTheTire() {
    const auto m = w->document()->model();
    QVERIFY(m);
    Scene scene;
    scene.build(m.get());
    const double r = 0.3135;  // the .tir file's UNLOADED_RADIUS
    int found = 0;
    for (const Item& it : scene.items()) {
      if (it.kind != ItemKind::Shape || it.prim != Prim::Cylinder || it.body != 1) continue;
      const Eigen::Matrix3d A = it.local.linear();
      if (std::abs(A.col(0).norm() - r) < 1e-12 && std::abs(A.col(1).norm() - r) < 1e-12 &&
          std::abs(A.col(2).norm() - 0.35 * r) < 1e-12 && (A.col(2).normalized() - Eigen::Vector3d::UnitY()).norm() < 1e-12)
        ++found;
    }
    QCOMPARE(found, 1);
  }

  // a tire sensor by clicks: "tire" picked from a sensor's type list, its tire and quantity from theirs
  void tireSensorByClicks() {
    QVERIFY(drive::addElement(w.get(), "sensor").isEmpty());
    const int k = props()->element()->index;
    QVERIFY(drive::pickWithMouse(combo("type"), "tire"));
    const SensorSpec& s = w->document()->spec().sensors[static_cast<std::size_t>(k)];
    QCOMPARE(s.type, SensorType::Tire);
    QCOMPARE(s.tire, std::string("tire"));
    QVERIFY(combo("tire") && combo("tire")->findText("tire") >= 0);
    QVERIFY(drive::pickWithMouse(combo("quantity"), "Fy"));
    QCOMPARE(w->document()->spec().sensors[static_cast<std::size_t>(k)].quantity, std::string("Fy"));
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->sensors.back().unit, std::string("N"));
  }

  // the wheel's context menu in the model tree, opened as a right click opens it: "Add tire on
  // wheel" makes a second tire on it, which compiles and is shown in the Tire view's list
  void tireFromTheWheelsContextMenu() {
    QTreeView* t = w->modelTree();
    const QModelIndex at = w->treeModel()->indexOf({ElementKind::Body, 0});
    t->scrollTo(at);
    const QPoint p = t->visualRect(at).center();
    QContextMenuEvent e(QContextMenuEvent::Mouse, p, t->viewport()->mapToGlobal(p));
    QApplication::sendEvent(t->viewport(), &e);
    auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
    QVERIFY(menu);
    QAction* hit = nullptr;
    for (QAction* a : menu->actions())
      if (a->objectName() == "addTireOn") hit = a;
    QVERIFY(hit);
    QCOMPARE(hit->text(), QString("Add tire on wheel"));
    QTest::mouseClick(menu, Qt::LeftButton, {}, menu->actionGeometry(hit).center());
    QVERIFY(QTest::qWaitFor([menu] { return !menu->isVisible(); }, 2000));
    const EffectSpec& added = w->document()->spec().effects.back();
    QCOMPARE(added.type, EffectType::Tire);
    QCOMPARE(added.name, std::string("wheel_tire"));
    QCOMPARE(added.body_a, std::string("wheel"));
    QCOMPARE(added.law, std::string("linear"));
    QVERIFY2(w->document()->errorText().isEmpty(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->tires.size(), std::size_t(2));
    QVERIFY(w->tireView()->sourceBox()->findText("wheel_tire") >= 0);
    QCOMPARE(w->tireView()->sourceBox()->currentText(), QString("wheel_tire"));  // selected: shown
    QVERIFY(series(w->tireView()->lateralView(), "Fz = 4000 N"));
  }
};

QTEST_MAIN(TireViewTest)
#include "tire_view_test.moc"
