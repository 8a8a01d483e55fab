// The rolling_ball constraint (issue 19: a ball rolling without slip on a plane) edited through
// the real widgets as a person does it, and drawn by the 3-D scene:
//   - examples/ball_plate.json: the constraint shows type rolling_ball, radius 0.015; a radius of
//     0.02 typed and confirmed with Enter recompiles the model with that radius, the ball lifted
//     by assembly to the plate top (z = -0.015) + 0.02 = 0.005 (the pivots at the origin, the plate
//     level), 5 coordinates and 3 rates left; a radius of 0 is the model's error naming
//     /constraints/0/radius, marked at the field, and nothing crashes;
//   - a new model (File > New): a body on a free joint, a constraint added and switched to
//     rolling_ball in its type list gets radius 0.05 and the plane z = 0 of the ground: it compiles
//     with the ball's centre assembled to z = 0.05; switched back to ball, the radius goes;
//   - the 3-D scene of ball_plate: the contact patch (a thin disc normal to the plate) and its dot
//     at the ball's centre less R along the plate's normal: (0.1, 0.05, -0.015) level, and for the
//     plate turned by Rx(a) Ry(b) with the ball on it at R (x, y, 0), the contact R (x, y, -0.015)
//     (closed form), both to 1e-12; no line or pin between point_a and point_b;
//   - rolling_disc (a wheel): picked from the type list of a new constraint it gets radius 0.05 and
//     an axle normal to the plane's normal z (the default z would lay it flat): it compiles with
//     the disc's centre assembled to z = 0.05; the body is drawn as a disc about its axle; the
//     contact of examples/rolling_disc.json leant by phi about x is at c - R d = (0, R sin(phi), 0)
//     (d = (0, -sin(phi), cos(phi)), closed form, 1e-12); back to rolling_ball, axis_b goes.
#include <QComboBox>
#include <QDir>
#include <QLineEdit>
#include <QTest>
#include <QTreeView>
#include <QUndoStack>
#include <array>
#include <cmath>

#include "drive.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/prepare.hpp"
#include "gui/main_window.hpp"
#include "gui/model_tree.hpp"
#include "gui/property_editor.hpp"
#include "gui/scene3d.hpp"
#include "io/model_file.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

std::vector<Item> itemsOf(const Scene& scene, ItemKind kind, const std::string& element) {
  std::vector<Item> out;
  for (const auto& it : scene.items())
    if (it.kind == kind && it.element == element) out.push_back(it);
  return out;
}

QString str(const Eigen::Vector3d& v) {
  return QString("(%1, %2, %3)").arg(v.x(), 0, 'g', 17).arg(v.y(), 0, 'g', 17).arg(v.z(), 0, 'g', 17);
}

#define EXPECT_NEAR3(a, b)                                                                          \
  QVERIFY2(((a) - (b)).norm() <= 1e-12, qPrintable(QString(#a " = %1, expected %2").arg(str(a), str(b))))

// the ball's centre as assembled (its free joint's position)
Eigen::Vector3d ballCentre(const Model& m, const std::string& joint) {
  const int j = m.find_joint(joint);
  return m.q0.segment<3>(m.joints[static_cast<std::size_t>(j)].idx_q);
}

}  // namespace

class RollingEditingTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  PropertyEditor* props() { return w->propertyEditor(); }
  QComboBox* combo(const QString& field) { return qobject_cast<QComboBox*>(props()->editorFor(field)); }
  QString text(const QString& field) {
    auto* e = qobject_cast<QLineEdit*>(props()->editorFor(field));
    return e ? e->text() : QString("<no line edit for %1>").arg(field);
  }

  void click(ElementKind kind, int index) {
    const QString why = drive::clickElement(w.get(), kind, index);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }
  void add(const QString& kind) {
    const QString why = drive::addElement(w.get(), kind);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }
  void typeInto(const QString& field, const QString& t) {
    const QString why = drive::typeInto(w.get(), field, t);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }
  void type(const QString& field, const QString& t) {
    const QString why = drive::typeTaken(w.get(), field, t);
    QVERIFY2(why.isEmpty(), qPrintable(why));
  }

  // a radius of 0: refused at the field, as the file reader refuses it (/constraints/K/radius), with
  // the reason; the model keeps its radius and compiles
  void typeZeroRadius(int k) {
    const double before = w->document()->spec().constraints.at(static_cast<std::size_t>(k)).radius;
    typeInto("radius", "0");
    QCOMPARE(w->document()->spec().constraints.at(static_cast<std::size_t>(k)).radius, before);
    QVERIFY(w->document()->model());
    QCOMPARE(props()->markedField(), QString("radius"));
    QVERIFY2(props()->errorText().startsWith("radius:") && props()->errorText().contains("positive radius"),
             qPrintable(props()->errorText()));
    QVERIFY(w->isVisible());
  }

  void choose(const QString& field, const QString& t) {
    QVERIFY2(drive::pickWithMouse(combo(field), t), qPrintable(field + " <- " + t));
    QCOMPARE(combo(field)->currentText(), t);
  }

 private slots:
  void init() {
    w = drive::window("rolling_editing_test");
    QVERIFY(w);
  }
  void cleanup() { drive::close(w); }

  void radiusOfTheBallOnThePlate() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/ball_plate.json")));
    click(ElementKind::Constraint, 0);
    QCOMPARE(combo("type")->currentText(), QString("rolling_ball"));
    // a wheel turned over the unfocused type and body drop-downs (scrolling the panel) changes nothing
    for (const char* f : {"type", "body_a"}) {
      drive::wheelOver(combo(f), -2);
      drive::wheelOver(combo(f), 3);
    }
    QCOMPARE(combo("type")->currentText(), QString("rolling_ball"));
    QCOMPARE(w->document()->spec().constraints.at(0).type, ConstraintType::RollingBall);
    QCOMPARE(w->document()->spec().constraints.at(0).body_a, std::string("plate"));
    QCOMPARE(combo("body_a")->currentText(), QString("plate"));
    QCOMPARE(combo("body_b")->currentText(), QString("ball"));
    QCOMPARE(text("radius"), QString("0.015"));
    QCOMPARE(text("axis_a"), QString("0.0, 0.0, 1.0"));
    QCOMPARE(props()->editorFor("radius")->toolTip(), QString("Radius of the rolling ball (m, > 0)"));
    QVERIFY2(props()->editorFor("axis_a")->toolTip().startsWith("Normal of the plane"),
             qPrintable(props()->editorFor("axis_a")->toolTip()));
    QCOMPARE(PropertyEditor::fieldHelp(ElementKind::Constraint, "axis_a", "", "revolute"),
             QString("Axis on the first body, in its frame"));  // the other types keep theirs
    QCOMPARE(PropertyEditor::fieldHelp(ElementKind::Body, "shapes/0/radius", "m"), QString("Radius [m]"));
    {
      const auto m = w->document()->model();
      QVERIFY2(m, qPrintable(w->document()->errorText()));
      QCOMPARE(m->constraints.at(0).radius, 0.015);
      QCOMPARE(m->dof(), 5);
      EXPECT_NEAR3(ballCentre(*m, "ball"), Eigen::Vector3d(0.1, 0.05, 0));
    }

    type("radius", "0.02");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    {
      const auto m = w->document()->model();
      QCOMPARE(w->document()->spec().constraints.at(0).radius, 0.02);
      QCOMPARE(m->constraints.at(0).radius, 0.02);
      QCOMPARE(m->dof(), 5);
      QCOMPARE(m->rate_dof(), 3);
      QCOMPARE(m->row_names, (std::vector<std::string>{"contact.height", "contact.slip_u", "contact.slip_v"}));
      // the plate's top at z = -0.015 (level): assembly lifts the centre to -0.015 + 0.02
      EXPECT_NEAR3(ballCentre(*m, "ball"), Eigen::Vector3d(0.1, 0.05, 0.005));
    }
    QCOMPARE(text("radius"), QString("0.02"));

    typeZeroRadius(0);
    type("radius", "0.015");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(w->document()->model()->dof(), 5);
    EXPECT_NEAR3(ballCentre(*w->document()->model(), "ball"), Eigen::Vector3d(0.1, 0.05, 0));
    // undo back to 0.02: the whole history is exact (the refused 0 never entered it)
    w->document()->undoStack()->undo();
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->model()->constraints.at(0).radius, 0.02);
  }

  void newRollingConstraintFromItsTypeList() {
    QVERIFY(w->newModel());
    add("body");
    type("name", "ball");
    add("joint");
    type("name", "float");
    choose("type", "free");
    QCOMPARE(combo("child")->currentText(), QString("ball"));
    add("constraint");
    QCOMPARE(combo("type")->currentText(), QString("ball"));
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    choose("type", "rolling_ball");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(combo("body_a")->currentText(), QString("ground"));
    QCOMPARE(combo("body_b")->currentText(), QString("ball"));
    QCOMPARE(text("radius"), QString("0.05"));
    QCOMPARE(text("axis_a"), QString("0.0, 0.0, 1.0"));
    QCOMPARE(text("point_a"), QString("0.0, 0.0, 0.0"));
    QCOMPARE(text("point_b"), QString("0.0, 0.0, 0.0"));
    {
      const auto m = w->document()->model();
      QCOMPARE(m->constraints.at(0).type, ConstraintType::RollingBall);
      QCOMPARE(m->constraints.at(0).radius, 0.05);
      QCOMPARE(m->dof(), 5);
      QCOMPARE(m->rate_dof(), 3);
      EXPECT_NEAR3(ballCentre(*m, "float"), Eigen::Vector3d(0, 0, 0.05));  // on the ground plane z = 0
      // a body without shapes under a rolling ball is drawn as the ball, radius 0.05 at point_b
      Scene scene;
      scene.build(m.get());
      int balls = 0;
      for (const Item& it : scene.items())
        if (it.kind == ItemKind::Shape && it.prim == Prim::Sphere && std::abs(it.local.linear().col(0).norm() - 0.05) < 1e-15 &&
            it.local.translation().norm() < 1e-15)
          ++balls;
      QCOMPARE(balls, 1);
      const auto contact = itemsOf(scene, ItemKind::Contact, m->constraints.at(0).name);
      QCOMPARE(contact.size(), std::size_t(2));
      EXPECT_NEAR3(Eigen::Vector3d(contact[0].world.translation()), Eigen::Vector3d::Zero());
    }
    typeZeroRadius(0);
    type("radius", "0.1");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    EXPECT_NEAR3(ballCentre(*w->document()->model(), "float"), Eigen::Vector3d(0, 0, 0.1));
    // back to a ball constraint: the radius goes with the type, the model compiles
    choose("type", "ball");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QVERIFY(!props()->editorFor("radius"));
    QCOMPARE(w->document()->model()->dof(), 3);
  }

  void newRollingDiscFromItsTypeList() {
    QVERIFY(w->newModel());
    add("body");
    type("name", "wheel");
    add("joint");
    type("name", "float");
    choose("type", "free");
    add("constraint");
    choose("type", "rolling_disc");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QCOMPARE(combo("type")->currentText(), QString("rolling_disc"));
    QCOMPARE(combo("body_b")->currentText(), QString("wheel"));
    QCOMPARE(text("radius"), QString("0.05"));
    QVERIFY2(props()->editorFor("axis_b")->toolTip().startsWith("The disc's axle"),
             qPrintable(props()->editorFor("axis_b")->toolTip()));
    {
      const auto m = w->document()->model();
      QCOMPARE(m->constraints.at(0).type, ConstraintType::RollingDisc);
      QCOMPARE(m->constraints.at(0).axis_b.dot(Eigen::Vector3d::UnitZ()), 0.0);
      QCOMPARE(m->dof(), 5);
      QCOMPARE(m->rate_dof(), 3);
      EXPECT_NEAR3(ballCentre(*m, "float"), Eigen::Vector3d(0, 0, 0.05));  // upright on z = 0
      Scene scene;
      scene.build(m.get());
      int discs = 0;  // the body drawn as the disc: radius 0.05 about the axle, at the centre
      for (const Item& it : scene.items())
        if (it.kind == ItemKind::Shape && it.prim == Prim::Cylinder && it.local.translation().norm() < 1e-15 &&
            (it.local.linear().col(2).normalized() - m->constraints.at(0).axis_b).norm() < 1e-12 &&
            std::abs(it.local.linear().col(0).norm() - 0.05) < 1e-15)
          ++discs;
      QCOMPARE(discs, 1);
      const auto contact = itemsOf(scene, ItemKind::Contact, m->constraints.at(0).name);
      QCOMPARE(contact.size(), std::size_t(2));
      EXPECT_NEAR3(Eigen::Vector3d(contact[0].world.translation()), Eigen::Vector3d::Zero());
    }
    // a wheel turned over the disc's unfocused type and body drop-downs changes nothing
    for (const char* f : {"type", "body_b"}) {
      drive::wheelOver(combo(f), -2);
      drive::wheelOver(combo(f), 3);
    }
    QCOMPARE(combo("type")->currentText(), QString("rolling_disc"));
    QCOMPARE(combo("body_b")->currentText(), QString("wheel"));
    // the axle typed along y and confirmed with Enter: still upright, the same centre height
    type("axis_b", "0, 1, 0");
    {
      const auto m = w->document()->model();
      QVERIFY2(m, qPrintable(w->document()->errorText()));
      QCOMPARE(m->constraints.at(0).axis_b, Eigen::Vector3d::UnitY());
      EXPECT_NEAR3(ballCentre(*m, "float"), Eigen::Vector3d(0, 0, 0.05));
    }
    // an axle of zero: refused at the field with the reason, the model kept as it was
    typeInto("axis_b", "0, 0, 0");
    QCOMPARE(props()->markedField(), QString("axis_b"));
    QVERIFY2(props()->errorText().contains("non-zero"), qPrintable(props()->errorText()));
    QVERIFY(w->document()->model());
    QCOMPARE(w->document()->spec().constraints.at(0).axis_b, Eigen::Vector3d::UnitY());
    type("axis_b", "0, 1, 0");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    choose("type", "rolling_ball");
    QVERIFY2(w->document()->model(), qPrintable(w->document()->errorText()));
    QVERIFY(!props()->editorFor("axis_b"));
  }

  void contactOfALeaningDisc() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("rolling_disc.json").toStdString();
    const auto m = std::make_shared<const Model>(compile(load_model_spec(path), path));
    Scene scene;
    scene.build(m.get());
    const int iw = m->joints[static_cast<std::size_t>(m->find_joint("wheel"))].idx_q;
    for (const double phi : {0.0, 0.4, -0.9}) {
      Eigen::VectorXd q = m->q0;
      const Eigen::Quaterniond r(Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()));
      q.segment<3>(iw) = Eigen::Vector3d(0, 0, 0.2 * std::cos(phi));
      q.segment<4>(iw + 3) << r.w(), r.x(), r.y(), r.z();
      Data d(*m);
      forward_kinematics(*m, d, q);
      scene.update(d.oMi);
      const auto t = itemsOf(scene, ItemKind::Contact, "contact");
      QCOMPARE(t.size(), std::size_t(2));
      EXPECT_NEAR3(Eigen::Vector3d(t[0].world.translation()), Eigen::Vector3d(0, 0.2 * std::sin(phi), 0));
      EXPECT_NEAR3(Eigen::Vector3d(t[1].world.translation()), Eigen::Vector3d(0, 0.2 * std::sin(phi), 0));
    }
  }

  void contactPatchOnThePlate() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("ball_plate.json").toStdString();
    const auto m = std::make_shared<const Model>(compile(load_model_spec(path), path));
    Scene scene;
    scene.build(m.get());
    const auto c = itemsOf(scene, ItemKind::Contact, "contact");
    QCOMPARE(c.size(), std::size_t(2));
    QCOMPARE(c[0].prim, Prim::Cylinder);  // the disc of the plane
    QCOMPARE(c[1].prim, Prim::Sphere);    // the dot
    EXPECT_NEAR3(Eigen::Vector3d(c[0].world.translation()), Eigen::Vector3d(0.1, 0.05, -0.015));
    EXPECT_NEAR3(Eigen::Vector3d(c[1].world.translation()), Eigen::Vector3d(0.1, 0.05, -0.015));
    EXPECT_NEAR3(Eigen::Vector3d(c[0].world.linear().col(2).normalized()), Eigen::Vector3d::UnitZ());
    // a thin disc: wider than the ball, much thinner than wide
    const double wide = c[0].world.linear().col(0).norm(), thick = c[0].world.linear().col(2).norm();
    QVERIFY2(wide > 0.015 && thick < 0.25 * wide, qPrintable(QString("disc %1 wide, %2 thick").arg(wide).arg(thick)));
    // nothing else draws the constraint: no line or pin from point_a to point_b, no ground anchor
    for (const Item& it : scene.items()) {
      QVERIFY(it.kind != ItemKind::Anchor || (it.world.translation() - Eigen::Vector3d(0.1, 0.05, -0.015)).norm() > 0.01);
      if (it.element == "contact") QCOMPARE(it.kind, ItemKind::Contact);
    }

    // the plate turned by Rx(a) Ry(b) about the pivots at the origin, the ball on it at R (x, y, 0)
    const int ix = m->joints[static_cast<std::size_t>(m->find_joint("tilt_x"))].idx_q;
    const int iy = m->joints[static_cast<std::size_t>(m->find_joint("tilt_y"))].idx_q;
    const int ib = m->joints[static_cast<std::size_t>(m->find_joint("ball"))].idx_q;
    const std::array<std::array<double, 4>, 2> poses{{{0.12, -0.2, 0.1, 0.05}, {-0.3, 0.25, -0.2, 0.13}}};
    for (const auto& [a, b, x, y] : poses) {
      const Eigen::Matrix3d R = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY())).toRotationMatrix();
      Eigen::VectorXd q = m->q0;
      q[ix] = a, q[iy] = b;
      q.segment<3>(ib) = R * Eigen::Vector3d(x, y, 0);
      Data d(*m);
      forward_kinematics(*m, d, q);
      scene.update(d.oMi);
      const auto t = itemsOf(scene, ItemKind::Contact, "contact");
      EXPECT_NEAR3(Eigen::Vector3d(t[0].world.translation()), Eigen::Vector3d(R * Eigen::Vector3d(x, y, -0.015)));
      EXPECT_NEAR3(Eigen::Vector3d(t[1].world.translation()), Eigen::Vector3d(R * Eigen::Vector3d(x, y, -0.015)));
      EXPECT_NEAR3(Eigen::Vector3d(t[0].world.linear().col(2).normalized()), Eigen::Vector3d(R.col(2)));
    }
  }
};

QTEST_MAIN(RollingEditingTest)
#include "rolling_editing_test.moc"
