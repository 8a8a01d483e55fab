// The elements of issue 19 edited through the real widgets, as a person does it:
// the element clicked in the model tree, values typed into the property editor and
// confirmed with Enter, types and joints picked from the drop-downs' open lists,
// the plant ticked in the Plant/In panel, Linearize clicked. Each edit is checked
// against a closed form of the linearization it must give:
//   - line_force (the bus suspension's strut U): its gain and its point on the body
//     move U's column of B to gain * (the line's vertical share) / m, for each mass;
//   - bushing (a block on a free joint, from File > New): the six oscillators
//     sqrt(k/m), sqrt(kr/I);
//   - mix (the quadrotor's rotor1): its weights and drives are B's column of the
//     rotor, thrust along body z at its place plus the yaw share;
//   - motion (the cart pendulum's cart driven, a shaker under an inverted pendulum):
//     its type and joint picked; A, B, D of the realization without derivatives,
//     theta/x = -(3/(2l)) s^2 / (s^2 - 3g/(2l)).
// Bad values typed (a negative stiffness, an unknown joint or body, a second motion input on
// a driven joint, a weight missing) are refused naming the field, and nothing crashes; the ball
// and beam's motion moved onto the coupled coordinate r is accepted (a motion on a loop's
// coordinate: the beam left free).
#include <QAbstractItemView>
#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QPushButton>
#include <QTest>
#include <QTreeView>
#include <QUndoStack>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "drive.hpp"
#include "gui/linearize_view.hpp"
#include "gui/main_window.hpp"
#include "gui/model_tree.hpp"
#include "gui/plant_panel.hpp"
#include "gui/property_editor.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

void toggle(PlantPanel* p, const QString& name) {
  QTreeView* v = p->view();
  v->setFocus();
  v->setCurrentIndex(p->listModel()->index(static_cast<int>(p->listModel()->rows().indexOf(name)), 0));
  QTest::keyClick(v, Qt::Key_Space);
}

int indexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

}  // namespace

class ElementsEditingTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  PropertyEditor* props() { return w->propertyEditor(); }
  QComboBox* combo(const QString& field) { return qobject_cast<QComboBox*>(props()->editorFor(field)); }

  // a click on the element's row of the model tree (its kind's node opened first)
  void click(ElementKind kind, const std::string& name) {
    const ModelSpec& s = w->document()->spec();
    int index = -1;
    auto find = [&](const auto& list) {
      for (std::size_t k = 0; k < list.size(); ++k)
        if (list[k].name == name) index = static_cast<int>(k);
    };
    if (kind == ElementKind::Actuator) find(s.actuators);
    if (kind == ElementKind::Effect) find(s.effects);
    if (kind == ElementKind::Joint) find(s.joints);
    QVERIFY2(index >= 0, name.c_str());
    const QString why = drive::clickElement(w.get(), kind, index);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }

  // Edit > Add > Add KIND, from the window's menu
  void add(const QString& kind) {
    const QString why = drive::addElement(w.get(), kind);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }

  // types `text` into the field and presses Enter
  void typeInto(const QString& field, const QString& text) {
    const QString why = drive::typeInto(w.get(), field, text);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }

  // typed and taken: nothing marked, no reason shown
  void type(const QString& field, const QString& text) {
    const QString why = drive::typeTaken(w.get(), field, text);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }

  // typed and refused: the field (or an entry of it: drives/1) is marked and the reason names
  // it; the window lives on
  void typeBad(const QString& field, const QString& text, const QString& reason) {
    typeInto(field, text);
    const QString marked = props()->markedField();
    QVERIFY2(marked == field || marked.startsWith(field + "/"), qPrintable(marked));
    QVERIFY2(props()->errorText().startsWith(QString(marked).replace('/', '.') + ":") && props()->errorText().contains(reason),
             qPrintable(props()->errorText()));
    QVERIFY(w->isVisible());
  }

  void choose(const QString& field, const QString& text) {
    QVERIFY2(drive::pickWithMouse(combo(field), text), qPrintable(field + " <- " + text));
    QCOMPARE(combo(field)->currentText(), text);
  }

  // Linearize clicked at the operating point picked from its list
  const LinearSystem* linearize(const QString& op) {
    LinearizeView* lv = w->linearizeView();
    w->analysisTabs()->setCurrentWidget(lv);
    if (!drive::pickWithKeys(lv->operatingPointCombo(), op)) return nullptr;
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    return lv->result() ? &lv->result()->system : nullptr;
  }

 private slots:
  void init() {
    w = drive::window("elements_editing_test");
    QVERIFY(w);
  }
  void cleanup() { drive::close(w); }

  // The bus suspension's strut U: gain 2.5 typed, then its point on the body moved 0.3 m
  // sideways. At the static equilibrium (X1 - X2 = -m1 g/k1, the suspension spring carrying the
  // body) the line from the wheel's centre to (0.3, 0, 0) on the body rises dy = 1 - m1 g/k1 over
  // its length sqrt(dy^2 + 0.3^2): U's column of B is gain * dy/len / m1 on X1_dot and
  // -gain * dy/len / m2 on X2_dot (the strut pushes the points apart).
  void lineForceOnTheBus() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/bus_suspension.json")));
    click(ElementKind::Actuator, "U");
    QCOMPARE(combo("body_a")->currentText(), QString("wheel"));
    QCOMPARE(combo("body_b")->currentText(), QString("body"));
    type("gain", "2.5");
    type("point_b", "0.3, 0, 0");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    const double m1 = 2500, m2 = 320, k1 = 80000, g = 9.81, gain = 2.5;
    const LinearSystem* s = linearize("equilibrium");
    QVERIFY(s);
    const int x1 = indexOf(s->state_names, "X1"), x2 = indexOf(s->state_names, "X2");
    // X2_dot~: the wheel's rate shifted by the road's (W is a motion input among Plant/In)
    const int v1 = indexOf(s->state_names, "X1_dot"), v2 = indexOf(s->state_names, "X2_dot~");
    const int u = indexOf(s->input_names, "U");
    QVERIFY(x1 >= 0 && x2 >= 0 && v1 >= 0 && v2 >= 0 && u >= 0);
    QVERIFY(std::abs((s->x0[x1] - s->x0[x2]) - (-m1 * g / k1)) < 1e-12);
    const double dy = 1 - m1 * g / k1, len = std::hypot(dy, 0.3);
    QVERIFY2(std::abs(s->B(v1, u) - gain * dy / len / m1) < 1e-12 * gain / m1,
             qPrintable(QString("B(X1_dot, U) = %1, expected %2").arg(s->B(v1, u), 0, 'g', 17).arg(gain * dy / len / m1, 0, 'g', 17)));
    QVERIFY(std::abs(s->B(v2, u) + gain * dy / len / m2) < 1e-12 * gain / m2);
    QVERIFY(std::abs(s->B(x1, u)) < 1e-15 && std::abs(s->B(x2, u)) < 1e-15);

    // bad values: an unknown body (typed into the drop-down), a gain that is no number
    typeBad("body_a", "nowhere", "nowhere");
    QVERIFY(!w->document()->model());
    choose("body_a", "wheel");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QVERIFY(props()->markedField().isEmpty());
    typeBad("gain", "fast", "not a finite number");
    QCOMPARE(w->document()->spec().actuators.at(0).gain, 2.5);  // the spec kept the last good value
    typeBad("point_b", "0.3, 0", "point_b");
  }

  // A block (m = 2 kg, I = diag(0.1, 0.2, 0.3)) on a free joint, held to the ground at its centre
  // of mass by a bushing built by clicks (an effect switched to "bushing" in its type list):
  // A's eigenvalues are +-i sqrt(k/m) for k = 100, 200, 300 and +-i sqrt(kr/I) for kr = 1, 4, 9.
  void bushingOscillators() {
    QVERIFY(w->newModel());
    add("body");
    type("name", "block");
    type("mass", "2");
    type("inertia", "0.1, 0.2, 0.3");
    add("joint");
    type("name", "float");
    choose("type", "free");
    add("effect");
    choose("type", "bushing");
    QCOMPARE(combo("body_a")->currentText(), QString("ground"));
    QCOMPARE(combo("body_b")->currentText(), QString("block"));
    type("name", "mount");
    type("translational_stiffness", "100, 200, 300");
    type("rotational_stiffness", "1, 4, 9");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    // a negative stiffness is refused at the field, naming it and what it expects; the model keeps its value
    typeBad("translational_stiffness", "100, -200, 300", "non-negative");
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->spec().effects.back().translational_stiffness, Eigen::Vector3d(100, 200, 300));
    type("translational_stiffness", "100, 200, 300");

    const LinearSystem* s = linearize("initial");
    QVERIFY(s);
    QCOMPARE(s->A.rows(), 12);
    Eigen::EigenSolver<Eigen::MatrixXd> es(s->A);
    std::vector<double> got, expected;
    for (int k = 0; k < 12; ++k) {
      QVERIFY(std::abs(es.eigenvalues()[k].real()) < 1e-12);
      if (es.eigenvalues()[k].imag() > 0) got.push_back(es.eigenvalues()[k].imag());
    }
    for (double x : {100.0 / 2, 200.0 / 2, 300.0 / 2, 1 / 0.1, 4 / 0.2, 9 / 0.3}) expected.push_back(std::sqrt(x));
    std::sort(got.begin(), got.end());
    std::sort(expected.begin(), expected.end());
    QCOMPARE(got.size(), expected.size());
    for (std::size_t k = 0; k < got.size(); ++k)
      QVERIFY2(std::abs(got[k] - expected[k]) < 1e-12 * expected[k],
               qPrintable(QString("omega %1 = %2, expected %3").arg(k).arg(got[k], 0, 'g', 17).arg(expected[k], 0, 'g', 17)));
  }

  // The quadrotor's rotor1: its yaw share typed as 0.03 (weights "1, 0.03"). At hover (trim, level)
  // B's rotor1 column is thrust1's along body z at (0.2, 0, 0) plus 0.03 of the yaw torque:
  // vz' = 1/m, wy' = -0.2/Iyy, wz' = 0.03/Izz, nothing else. Then it drives thrust2 at (0, 0.2, 0)
  // instead: wx' = +0.2/Ixx.
  void mixOnTheQuadrotor() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/quadrotor.json")));
    click(ElementKind::Actuator, "rotor1");
    QCOMPARE(qobject_cast<QLineEdit*>(props()->editorFor("drives"))->text(), QString("thrust1, yaw_torque"));
    type("weights", "1, 0.03");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    const double m = 1.2, Ixx = 0.012, Iyy = 0.012, Izz = 0.022;
    auto check = [&](const std::map<std::string, double>& rows) {
      const LinearSystem* s = linearize("trim");
      QVERIFY(s);
      const int u = indexOf(s->input_names, "rotor1");
      QVERIFY(u >= 0);
      for (int r = 0; r < s->nx(); ++r) {
        const auto it = rows.find(s->state_names[static_cast<std::size_t>(r)]);
        const double want = it == rows.end() ? 0.0 : it->second;
        QVERIFY2(std::abs(s->B(r, u) - want) <= 1e-12 * std::max(1.0, std::abs(want)),
                 qPrintable(QString("B(%1, rotor1) = %2, expected %3")
                                .arg(QString::fromStdString(s->state_names[static_cast<std::size_t>(r)]))
                                .arg(s->B(r, u), 0, 'g', 17)
                                .arg(want, 0, 'g', 17)));
      }
    };
    check({{"base.vz", 1 / m}, {"base.wy", -0.2 / Iyy}, {"base.wz", 0.03 / Izz}});
    click(ElementKind::Actuator, "rotor1");
    type("drives", "thrust2, yaw_torque");
    check({{"base.vz", 1 / m}, {"base.wx", 0.2 / Ixx}, {"base.wz", 0.03 / Izz}});

    // bad values: a drive that is no actuator, one weight for two drives
    click(ElementKind::Actuator, "rotor1");
    typeBad("drives", "thrust2, nowhere", "nowhere");
    type("drives", "thrust2, yaw_torque");
    typeBad("weights", "1", "weights");
    type("weights", "1, 0.03");
  }

  // The cart pendulum's cart driven by a motion input (a shaker table under the inverted
  // pendulum): an actuator added, its type picked as "motion", its joint picked in the list
  // (rod_pivot, then cart_slider). About upright (uniform rod, l = 2 m, pivot at its end):
  // theta'' = (3g/(2l)) theta - (3/(2l)) x'', so A = [0 1; 3g/(2l) 0], and the realization
  // without derivatives (docs/model-format.md, motion) has B = [0; -(3/(2l)) 3g/(2l)], D = -3/(2l)
  // for theta, D = 1 for h (the cart follows x).
  void motionOnTheCartPendulum() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json")));
    add("actuator");
    type("name", "shaker");
    choose("type", "motion");
    QVERIFY(!props()->editorFor("gain"));  // a motion input has no gain
    choose("joint", "rod_pivot");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->dof(), 1);
    choose("joint", "cart_slider");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    typeBad("joint", "nowhere", "nowhere");
    choose("joint", "cart_slider");
    QVERIFY(props()->markedField().isEmpty());
    toggle(w->plantInPanel(), "force");
    toggle(w->plantInPanel(), "shaker");
    QCOMPARE(w->document()->spec().plant.inputs, (std::vector<std::string>{"shaker"}));

    const LinearSystem* s = linearize("equilibrium");
    QVERIFY(s);
    QCOMPARE(s->nx(), 2);
    // both states shifted by the shaker's motion (its acceleration swings the rod): named so
    const int th = indexOf(s->state_names, "rod_pivot~"), om = indexOf(s->state_names, "rod_pivot_dot~");
    const int h = indexOf(s->output_names, "h"), y = indexOf(s->output_names, "theta");
    QVERIFY(th >= 0 && om >= 0 && h >= 0 && y >= 0);
    const double g = 9.81, l = 2.0, a = 3 * g / (2 * l), b = -3 / (2 * l);
    auto near = [](double x, double want) { return std::abs(x - want) <= 1e-12 * std::max(1.0, std::abs(want)); };
    QVERIFY2(near(s->A(om, th), a), qPrintable(QString("A = %1, expected %2").arg(s->A(om, th), 0, 'g', 17).arg(a)));
    QVERIFY(near(s->A(th, om), 1) && near(s->A(th, th), 0) && near(s->A(om, om), 0));
    QVERIFY2(near(s->B(om, 0), a * b) && near(s->B(th, 0), 0),
             qPrintable(QString("B = %1, %2").arg(s->B(th, 0), 0, 'g', 17).arg(s->B(om, 0), 0, 'g', 17)));
    QVERIFY2(near(s->D(y, 0), b), qPrintable(QString("D = %1").arg(s->D(y, 0), 0, 'g', 17)));
    QVERIFY(near(s->D(h, 0), 1) && near(s->C(h, th), 0));

    // the ball and beam: its motion input moved to the rolling ball's coordinate r, which the
    // rolling coupler ties to the spin (a motion on a loop's coordinate): the beam turns freely,
    // one degree of freedom; a second motion on r is refused, naming the joint field
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/ball_beam.json")));
    click(ElementKind::Actuator, "alpha");
    QCOMPARE(combo("joint")->currentText(), QString("beam_pivot"));
    choose("joint", "r");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->dof(), 1);
    add("actuator");
    type("name", "alpha2");
    choose("type", "motion");
    QVERIFY(drive::pickWithMouse(combo("joint"), "r"));
    QCOMPARE(props()->markedField(), QString("joint"));
    QVERIFY2(props()->errorText().startsWith("joint:"), qPrintable(props()->errorText()));
    QVERIFY(!w->document()->model());
    choose("joint", "beam_pivot");  // both driven: the spin follows r, nothing left free
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->dof(), 0);
  }
};

QTEST_MAIN(ElementsEditingTest)
#include "elements_editing_test.moc"
