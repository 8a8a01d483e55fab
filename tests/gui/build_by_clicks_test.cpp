// A double inverted pendulum on a cart built from File > New through the widgets
// alone, as a person does it: elements added from the Edit > Add menu, names,
// numbers and vectors typed into the property editor and confirmed with Enter,
// types and references picked from the drop-downs' lists, the plant ticked in the
// Plant/In and Plant/Out panels, the operating point picked, Linearize clicked.
// No JSON is typed. Its A and B must equal, to 1e-12, those of the same
// mechanism written by hand as a model file (tests/data/gui/double_pendulum_cart.json),
// linearized headless by core's study.
#include <QAbstractItemView>
#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QPushButton>
#include <QTest>
#include <QTreeView>
#include <QUndoStack>
#include <Eigen/Eigenvalues>

#include "drive.hpp"
#include "gui/linearize_view.hpp"
#include "gui/main_window.hpp"
#include "gui/plant_panel.hpp"
#include "gui/property_editor.hpp"
#include "io/model_file.hpp"
#include "study/workflow.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

void toggle(PlantPanel* p, const QString& name) {
  QTreeView* v = p->view();
  v->setFocus();
  v->setCurrentIndex(p->listModel()->index(static_cast<int>(p->listModel()->rows().indexOf(name)), 0));
  QTest::keyClick(v, Qt::Key_Space);
}

}  // namespace

class BuildByClicksTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  PropertyEditor* props() { return w->propertyEditor(); }

  // Edit > Add > Add KIND, from the window's menu
  void add(const QString& kind) {
    QAction* found = drive::addAction(w.get(), kind);
    QVERIFY2(found, qPrintable(kind));
    found->trigger();
    QVERIFY(props()->element());
  }

  // types `text` into the field and presses Enter; the model must take it
  void type(const QString& field, const QString& text) {
    auto* e = qobject_cast<QLineEdit*>(props()->editorFor(field));
    QVERIFY2(e, qPrintable("no line edit for " + field));
    e->setFocus();
    e->selectAll();
    QTest::keyClicks(e, text);
    QTest::keyClick(e, Qt::Key_Return);
    // taken (or already the value): nothing marked, no reason shown
    QVERIFY2(props()->markedField().isEmpty() && props()->errorText().isEmpty(),
             qPrintable(field + " = " + text + " not taken: " + props()->errorText()));
  }

  void choose(const QString& field, const QString& text) {
    const int before = w->document()->undoStack()->count();
    QVERIFY2(drive::pickWithKeys(qobject_cast<QComboBox*>(props()->editorFor(field)), text), qPrintable(field + " <- " + text));
    QCOMPARE(w->document()->undoStack()->count(), before + 1);
  }

  void body(const QString& name, const QString& mass, const QString& com, const QString& inertia) {
    add("body");
    type("name", name);
    type("mass", mass);
    if (!com.isEmpty()) type("com", com);
    type("inertia", inertia);
  }

 private slots:
  void init() {
    w = drive::window("build_by_clicks_test");
    QVERIFY(w);
  }
  void cleanup() { drive::close(w); }

  void doublePendulumOnACartFromNew() {
    QVERIFY(w->newModel());
    body("cart", "2", "", "0.1, 0.1, 0.1");
    add("joint");
    type("name", "slider");
    choose("type", "prismatic");
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("child"))->currentText(), QString("cart"));
    type("axis", "1, 0, 0");

    body("rod1", "1", "0, 0.5, 0", "0.0833, 0.001, 0.0833");
    add("joint");
    type("name", "hinge1");
    choose("parent", "cart");
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("child"))->currentText(), QString("rod1"));
    QVERIFY(props()->editorFor("q0"));  // a new joint has its initial position and rate fields
    QVERIFY(props()->editorFor("v0"));
    type("q0", "0.05");

    body("rod2", "0.5", "0, 0.5, 0", "0.04, 0.001, 0.04");
    add("joint");
    type("name", "hinge2");
    choose("parent", "rod1");
    type("parent_frame/position", "0, 1, 0");
    QCOMPARE(qobject_cast<QLineEdit*>(props()->editorFor("parent_frame/rotation"))->text(), QString("0, 0, 0"));

    add("effect");  // gravity, -y
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("type"))->currentText(), QString("gravity"));
    QCOMPARE(w->document()->spec().effects.at(0).g, Eigen::Vector3d(0, -9.81, 0));

    add("actuator");
    type("name", "force");
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("joint"))->currentText(), QString("slider"));
    type("unit", "N");
    for (const auto& [name, joint] : {std::pair{"x", "slider"}, std::pair{"phi1", "hinge1"}, std::pair{"phi2", "hinge2"}}) {
      add("sensor");
      type("name", name);
      if (QString(joint) != "slider") choose("joint", joint);
    }
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));

    // the plant: force in, x, phi1, phi2 out
    toggle(w->plantInPanel(), "force");
    for (const char* y : {"x", "phi1", "phi2"}) toggle(w->plantOutPanel(), y);
    QCOMPARE(w->document()->spec().plant.inputs, (std::vector<std::string>{"force"}));
    QCOMPARE(w->document()->spec().plant.outputs, (std::vector<std::string>{"x", "phi1", "phi2"}));

    // linearize at the upright equilibrium
    LinearizeView* lv = w->linearizeView();
    w->analysisTabs()->setCurrentWidget(lv);
    QVERIFY(drive::pickWithKeys(lv->operatingPointCombo(), "equilibrium"));
    QCOMPARE(w->document()->spec().analysis.operating_point, std::string("equilibrium"));
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    const LinearSystem& clicked = lv->result()->system;

    // the same mechanism from its file, headless
    const std::string file = CODYNA_TEST_DATA_DIR "/gui/double_pendulum_cart.json";
    const Model m = study_model(load_model_spec(file), file);
    const StudyLinearization ref = study_linearize(m);
    QCOMPARE(clicked.state_names, ref.system.state_names);
    QCOMPARE(clicked.A.rows(), 6);
    QCOMPARE(clicked.B.cols(), 1);
    const double a_err = (clicked.A - ref.system.A).cwiseAbs().maxCoeff();
    const double b_err = (clicked.B - ref.system.B).cwiseAbs().maxCoeff();
    QVERIFY2(a_err <= 1e-12 * std::max(1.0, ref.system.A.cwiseAbs().maxCoeff()), qPrintable(QString("A differs by %1").arg(a_err)));
    QVERIFY2(b_err <= 1e-12 * std::max(1.0, ref.system.B.cwiseAbs().maxCoeff()), qPrintable(QString("B differs by %1").arg(b_err)));
    QVERIFY(((clicked.C - ref.system.C).cwiseAbs().maxCoeff()) <= 1e-12);
    // upright: the equilibrium search went from phi1 = 0.05 to 0
    QVERIFY(std::abs(clicked.x0[1]) < 1e-9);
    // the pendulum is unstable upright: A has a pole in the right half plane (not a trivial model)
    QVERIFY(ref.system.A.eigenvalues().real().maxCoeff() > 1.0);
  }

  // a geared motor from File > New: two discs on revolute joints, a constraint switched to a coupler
  // in its type drop-down, its joints picked, the ratio typed; the linearization reflects the rotor
  // inertia as N^2 Jm (the closed form of tests/core/coupler_test.cpp)
  void gearedMotorFromNew() {
    QVERIFY(w->newModel());
    body("rotor", "1", "", "0.01, 0.01, 0.02");
    add("joint");
    type("name", "motor");
    body("load", "2", "", "0.3, 0.3, 0.5");
    add("joint");
    type("name", "wheel");
    type("parent_frame/position", "1, 0, 0");
    add("constraint");
    choose("type", "coupler");
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("joint_a"))->currentText(), QString("motor"));
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("joint_b"))->currentText(), QString("wheel"));
    QVERIFY(props()->editorFor("joint_c"));
    QVERIFY(props()->editorFor("offset"));
    type("ratio_b", "-7");
    type("name", "gearbox");
    add("actuator");
    type("name", "torque");
    QCOMPARE(qobject_cast<QComboBox*>(props()->editorFor("joint"))->currentText(), QString("motor"));
    add("sensor");
    type("name", "angle");
    choose("joint", "wheel");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    const ConstraintSpec& c = w->document()->spec().constraints.at(0);
    QCOMPARE(c.type, ConstraintType::Coupler);
    QCOMPARE(c.ratio_a, 1.0);
    QCOMPARE(c.ratio_b, -7.0);
    toggle(w->plantInPanel(), "torque");
    toggle(w->plantOutPanel(), "angle");

    LinearizeView* lv = w->linearizeView();
    w->analysisTabs()->setCurrentWidget(lv);
    QVERIFY(drive::pickWithKeys(lv->operatingPointCombo(), "initial"));
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    const LinearSystem& s = lv->result()->system;
    QCOMPARE(s.A.rows(), 2);  // one degree of freedom
    const double N = 7, Jm = 0.02, Jl = 0.5;
    // the automatic choice keeps the actuated motor: (Jm + Jl / N^2) motor'' = torque
    const double expected = s.state_names[0] == "motor" ? N * N / (N * N * Jm + Jl) : N / (Jl + N * N * Jm);
    QVERIFY2(std::abs(s.B(1, 0) - expected) <= 1e-12 * expected,
             qPrintable(QString("B = %1, expected %2 (%3)").arg(s.B(1, 0)).arg(expected).arg(QString::fromStdString(s.state_names[0]))));
  }
};

QTEST_MAIN(BuildByClicksTest)
#include "build_by_clicks_test.moc"
