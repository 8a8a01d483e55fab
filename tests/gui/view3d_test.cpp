// View3D without OpenGL (QT_QPA_PLATFORM=offscreen): the placeholder, the
// public API on every example, and the CPU side (camera, scene, picking).
#include <QApplication>
#include <QDir>
#include <QLabel>
#include <QSet>
#include <QSignalSpy>
#include <QtTest>
#include <cmath>

#include "gui/scene3d.hpp"
#include "gui/view3d.hpp"
#include "dynamics/kinematics.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"

using codyna::gui::Camera;
using codyna::gui::ItemKind;
using codyna::gui::Prim;
using codyna::gui::Ray;
using codyna::gui::Scene;
using codyna::gui::View3D;

namespace {

std::shared_ptr<const codyna::Model> loadExample(const QString& file) {
  const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath(file).toStdString();
  return std::make_shared<const codyna::Model>(codyna::compile(codyna::load_model_spec(path), path));
}

QStringList exampleFiles() { return QDir(CODYNA_EXAMPLES_DIR).entryList({"*.json"}, QDir::Files, QDir::Name); }

// a configuration away from q0: revolute-like coordinates turned, quaternions tilted
Eigen::VectorXd perturbed(const codyna::Model& m, double amount) {
  Eigen::VectorXd q = m.q0;
  for (int i = 1; i < m.nbodies; ++i) {
    const auto& j = m.joints[i];
    if (j.type == codyna::JointType::Spherical) {
      const Eigen::Quaterniond r(Eigen::AngleAxisd(amount, Eigen::Vector3d::UnitX()));
      const Eigen::Quaterniond q0(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2], q[j.idx_q + 3]);
      const Eigen::Quaterniond qn = q0 * r;
      q.segment<4>(j.idx_q) << qn.w(), qn.x(), qn.y(), qn.z();
    } else if (j.type != codyna::JointType::Free) {
      for (int k = 0; k < j.nq; ++k) q[j.idx_q + k] += amount;
    }
  }
  return q;
}

std::string bodyName(const codyna::Model& m, int i) { return m.body_names[static_cast<size_t>(i)]; }

// the items of one element, in the order the scene made them
std::vector<codyna::gui::Item> itemsOf(const Scene& scene, ItemKind kind, const std::string& element) {
  std::vector<codyna::gui::Item> out;
  for (const auto& it : scene.items())
    if (it.kind == kind && it.element == element) out.push_back(it);
  return out;
}

// a unit cylinder or arrow (z in [-0.5, 0.5]) under T: its two end points, where z = -0.5 and z = +0.5
Eigen::Vector3d tail(const Eigen::Affine3d& T) { return T * Eigen::Vector3d(0, 0, -0.5); }
Eigen::Vector3d tip(const Eigen::Affine3d& T) { return T * Eigen::Vector3d(0, 0, 0.5); }

bool near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol = 1e-12) { return (a - b).norm() <= tol; }

QString str(const Eigen::Vector3d& v) { return QString("(%1, %2, %3)").arg(v.x(), 0, 'g', 17).arg(v.y(), 0, 'g', 17).arg(v.z(), 0, 'g', 17); }

#define EXPECT_NEAR3(a, b) QVERIFY2(near((a), (b)), qPrintable(QString(#a " = %1, expected %2").arg(str(a), str(b))))

void place(Scene& scene, const codyna::Model& m, const Eigen::VectorXd& q) {
  codyna::Data d(m);
  codyna::forward_kinematics(m, d, q);
  scene.update(d.oMi);
}

}  // namespace

class View3DTest : public QObject {
  Q_OBJECT

 private slots:
  void noOpenGLOffscreen() {
    QCOMPARE(QGuiApplication::platformName(), QStringLiteral("offscreen"));
    QVERIFY(!View3D::openGLAvailable());
    QVERIFY(!View3D::openGLAvailable());  // cached, same answer
    QVERIFY(View3D::openGLUnavailableReason().contains("platform offscreen"));
    View3D view;
    QVERIFY(!view.hasGL());
    auto* label = view.findChild<QLabel*>("view3dPlaceholder");
    QVERIFY(label);
    QVERIFY(label->text().startsWith("3-D view unavailable: no OpenGL context"));
    view.resize(400, 300);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    QVERIFY(label->isVisible());
    QCOMPARE(label->geometry(), view.rect());
    const QImage img = view.grabImage();
    QVERIFY(!img.isNull());
    QCOMPARE(img.size(), QSize(400, 300) * view.devicePixelRatio());
  }

  void everyExampleRunsThroughTheApi() {
    View3D view;
    view.resize(640, 480);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    const QStringList files = exampleFiles();
    QVERIFY(files.size() >= 8);
    for (const QString& f : files) {
      auto m = loadExample(f);
      view.setModel(m);
      QCOMPARE(view.configuration().size(), m->nq);
      QVERIFY(view.scene().items().size() >= static_cast<size_t>(m->nbodies - 1));
      // every moving body has something pickable
      for (int i = 1; i < m->nbodies; ++i) {
        QPointF p;
        QVERIFY2(view.bodyScreenPos(QString::fromStdString(bodyName(*m, i)), &p), qPrintable(f));
      }
      view.setConfiguration(perturbed(*m, 0.3));
      view.setHighlight(QString::fromStdString(bodyName(*m, 1)));
      QCOMPARE(view.highlight(), QString::fromStdString(bodyName(*m, 1)));
      view.setShowFrames(false);
      view.fitView();
      view.setShowFrames(true);
      view.resetView();
      view.setHighlight("");
      QVERIFY(!view.grabImage().isNull());
      // the whole mechanism is in the picture after a fit
      const Eigen::AlignedBox3d box = view.scene().bounds();
      for (int k = 0; k < 8; ++k) {
        Eigen::Vector2d px;
        QVERIFY(view.camera().project(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)), &px));
        QVERIFY2(px.x() >= 0 && px.x() <= 640 && px.y() >= 0 && px.y() <= 480, qPrintable(f));
      }
    }
    view.setModel(nullptr);
    QVERIFY(view.scene().items().empty());
    view.setConfiguration(Eigen::VectorXd::Zero(3));  // ignored, no model
    QCOMPARE(view.configuration().size(), 0);
    QVERIFY(view.pickBody(QPoint(320, 240)).isEmpty());
    QVERIFY(!view.grabImage().isNull());
  }

  void wrongSizeConfigurationIsIgnored() {
    View3D view;
    auto m = loadExample("double_pendulum.json");
    view.setModel(m);
    view.setConfiguration(Eigen::VectorXd::Constant(m->nq + 1, 0.7));
    QCOMPARE(view.configuration(), m->q0);
  }

  void cameraRoundTrip() {
    Camera cam;
    cam.setUp(Eigen::Vector3d(0, 0, 2));
    QVERIFY(cam.up.isApprox(Eigen::Vector3d::UnitZ()));
    QVERIFY(std::abs(cam.front.dot(cam.up)) < 1e-12);
    cam.target = {1, 2, 3};
    cam.distance = 7;
    cam.yaw = 0.3, cam.pitch = 0.4;
    cam.width = 800, cam.height = 600;
    // target on the optical axis at -distance, centre of the viewport
    const Eigen::Vector4d t = cam.viewMatrix() * Eigen::Vector4d(1, 2, 3, 1);
    QVERIFY((t.head<3>() - Eigen::Vector3d(0, 0, -7)).norm() < 1e-12);
    Eigen::Vector2d px;
    QVERIFY(cam.project(cam.target, &px));
    QVERIFY((px - Eigen::Vector2d(400, 300)).norm() < 1e-9);
    // pixel -> ray -> point -> pixel
    for (auto [x, y] : {std::pair{10.0, 20.0}, {799.0, 1.0}, {400.5, 599.0}}) {
      const Ray r = cam.rayAt(x, y);
      QVERIFY(cam.project(r.origin + 5.0 * r.dir, &px));
      QVERIFY((px - Eigen::Vector2d(x, y)).norm() < 1e-8);
    }
    // the projection matrix agrees with project()
    const Eigen::Vector3d w(1.5, 1.0, 2.2);
    const Eigen::Vector4d c = cam.projectionMatrix() * cam.viewMatrix() * w.homogeneous();
    QVERIFY(cam.project(w, &px));
    QVERIFY(std::abs((c.x() / c.w() + 1) / 2 * 800 - px.x()) < 1e-8);
    QVERIFY(std::abs((1 - c.y() / c.w()) / 2 * 600 - px.y()) < 1e-8);
    // points in front of the camera stay behind the near plane
    QVERIFY(cam.nearPlane() > 0 && cam.nearPlane() < cam.farPlane());
    // up on screen is world up when looking level
    cam.pitch = 0;
    QVERIFY(cam.screenUp().isApprox(cam.up, 1e-12));
    // orbit changes angles, pan moves the target in the screen plane, zoom the distance
    const Eigen::Vector3d before = cam.target;
    cam.pan(10, 0);
    QVERIFY(std::abs((cam.target - before).dot(cam.forward())) < 1e-12);
    QVERIFY((cam.target - before).dot(cam.right()) < 0);  // drag right: the scene follows the mouse
    const double d = cam.distance;
    cam.zoom(1);
    QVERIFY(cam.distance < d);
    cam.orbit(0, 1e6);
    QVERIFY(cam.pitch < 1.5708);
  }

  void primitiveIntersections() {
    Ray r;
    r.origin = {0, 0, 10};
    r.dir = {0, 0, -1};
    Eigen::Affine3d T = Eigen::Affine3d::Identity();
    T.translation() = Eigen::Vector3d(0, 0, 1);
    T.linear() = Eigen::Vector3d(2, 2, 4).asDiagonal();
    QCOMPARE(codyna::gui::intersect(Prim::Box, T, r), 7.0);       // top face at z = 3
    QCOMPARE(codyna::gui::intersect(Prim::Cylinder, T, r), 7.0);  // cap at z = 3
    QCOMPARE(codyna::gui::intersect(Prim::Sphere, T, r), 5.0);    // ellipsoid top at z = 5
    r.origin = {10, 0, 1};
    r.dir = {-1, 0, 0};
    QCOMPARE(codyna::gui::intersect(Prim::Box, T, r), 9.0);
    QCOMPARE(codyna::gui::intersect(Prim::Cylinder, T, r), 8.0);  // side at x = 2
    r.origin = {10, 2.5, 1};                                       // passes beside all three
    QVERIFY(codyna::gui::intersect(Prim::Box, T, r) < 0);
    QVERIFY(codyna::gui::intersect(Prim::Cylinder, T, r) < 0);
    QVERIFY(codyna::gui::intersect(Prim::Sphere, T, r) < 0);
    r.origin = {10, 1.9, 1};  // beside the box (|y| <= 1), through the round ones (radius 2)
    QVERIFY(codyna::gui::intersect(Prim::Box, T, r) < 0);
    QVERIFY(std::abs(codyna::gui::intersect(Prim::Cylinder, T, r) - (10 - std::sqrt(4 - 1.9 * 1.9))) < 1e-12);
    QVERIFY(std::abs(codyna::gui::intersect(Prim::Sphere, T, r) - (10 - std::sqrt(4 - 1.9 * 1.9))) < 1e-12);
    r.origin = {-10, 0, 1};                                        // pointing away
    QVERIFY(codyna::gui::intersect(Prim::Box, T, r) < 0);
  }

  void pickingOnThePendulum() {
    View3D view;
    view.resize(800, 600);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    auto m = loadExample("pendulum.json");
    view.setModel(m);
    QPointF p;
    QVERIFY(view.bodyScreenPos("rod", &p));
    QVERIFY(view.rect().contains(p.toPoint()));
    QCOMPARE(view.pickBody(p.toPoint()), QStringLiteral("rod"));
    QCOMPARE(view.pickBody(QPoint(3, 3)), QString());
    QCOMPARE(view.pickBody(QPoint(796, 596)), QString());
    QVERIFY(!view.bodyScreenPos("nonexistent", &p));
    QVERIFY(!view.bodyScreenPos("ground", &p));

    // the rod moves with the configuration: its old place becomes background
    QVERIFY(view.bodyScreenPos("rod", &p));
    const QPoint old = p.toPoint();
    Eigen::VectorXd q = m->q0;
    q[0] -= 2.0;
    view.setConfiguration(q);
    QPointF p2;
    QVERIFY(view.bodyScreenPos("rod", &p2));
    QVERIFY((p2 - p).manhattanLength() > 50);
    QCOMPARE(view.pickBody(p2.toPoint()), QStringLiteral("rod"));
    QCOMPARE(view.pickBody(old), QString());

    // clicks: a body, then the background; a drag orbits and picks nothing
    QSignalSpy spy(&view, &View3D::bodyPicked);
    QTest::mouseClick(&view, Qt::LeftButton, {}, p2.toPoint());
    QCOMPARE(spy.count(), 1);
    QCOMPARE(spy.at(0).at(0).toString(), QStringLiteral("rod"));
    QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(5, 5));
    QCOMPARE(spy.count(), 2);
    QCOMPARE(spy.at(1).at(0).toString(), QString());
    const double yaw = view.camera().yaw;
    QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(100, 100));
    QTest::mouseMove(&view, QPoint(160, 110));
    QTest::mouseMove(&view, QPoint(220, 120));
    QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(220, 120));
    QCOMPARE(spy.count(), 2);
    QVERIFY(std::abs(view.camera().yaw - yaw) > 0.5);

    // F refits after a zoom
    view.fitView();
    const double fitted = view.camera().distance;
    QWheelEvent wheel(QPointF(400, 300), view.mapToGlobal(QPointF(400, 300)), QPoint(), QPoint(0, 240), Qt::NoButton,
                      Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(&view, &wheel);
    QVERIFY(view.camera().distance < 0.8 * fitted);
    QTest::keyClick(&view, Qt::Key_F);
    QVERIFY(std::abs(view.camera().distance - fitted) < 1e-9 * fitted);
  }

  // on every example, the visible point of each body (or, where something is in front of it, a point
  // near a corner of one of its shapes) picks that body, but for an exception
  void pickingEveryBody() {
    View3D view;
    view.resize(800, 600);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    for (const QString& f : exampleFiles()) {
      auto m = loadExample(f);
      view.setModel(m);
      int exact = 0;
      for (int i = 1; i < m->nbodies; ++i) {
        const QString name = QString::fromStdString(bodyName(*m, i));
        QPointF p;
        QVERIFY(view.bodyScreenPos(name, &p));
        const QString got = view.pickBody(p.toPoint());
        Camera cam = view.camera();
        cam.width = view.width(), cam.height = view.height();
        // empty: hidden by a ground anchor (the ball and plate's pivots over the plate's centre), never a miss
        if (got.isEmpty())
          QVERIFY2(view.scene().pick(cam.rayAt(p.toPoint().x() + 0.5, p.toPoint().y() + 0.5)) == 0, qPrintable(f + ": " + name));
        if (got == name) {
          ++exact;
          continue;
        }
        // hidden there: a point inside one of its shapes near a corner that picks it (the ball and
        // plate's gimbal under the plate shows at its ends)
        bool seen = false;
        for (const auto& it : view.scene().items()) {
          if (it.kind != ItemKind::Shape || it.body != i) continue;
          const double s = it.prim == Prim::Box ? 0.45 : 0.6, sz = it.prim == Prim::Box ? 0.45 : it.prim == Prim::Sphere ? 0.6 : 0.45;
          for (int k = 0; k < 8 && !seen; ++k) {
            Eigen::Vector2d px;
            const Eigen::Vector3d c = it.world * Eigen::Vector3d(k & 1 ? s : -s, k & 2 ? s : -s, k & 4 ? sz : -sz);
            seen = cam.project(c, &px) && view.pickBody(QPoint(int(std::floor(px.x())), int(std::floor(px.y())))) == name;
          }
        }
        if (seen) ++exact;
      }
      // occlusion of a whole body is the exception; but a full car seen from its side hides the far
      // side's suspension behind the near side's and its uprights inside the wheels (a person turns
      // the view): for the sedan (and sedan_esc, the same car, and its corner on the K&C rig), half of
      // its bodies picked at their place is the floor
      if (f == "sedan.json" || f == "sedan_esc.json" || f == "kc_double_wishbone.json")
        QVERIFY2(exact * 2 >= m->nbodies - 1, qPrintable(f));
      else QVERIFY2(exact * 4 >= (m->nbodies - 1) * 3, qPrintable(f));
    }
  }

  // the grid lies under the mechanism, also as the pendulums swing
  void gridUnderTheMechanism() {
    for (const char* f : {"pendulum.json", "double_pendulum.json", "iftomm_a01_pendulum.json", "cart_pendulum.json"}) {
      auto m = loadExample(f);
      Scene scene;
      scene.build(m.get());
      QVERIFY(scene.up().isApprox(Eigen::Vector3d::UnitY()));
      const double h = scene.gridCenter().dot(scene.up());
      codyna::Data d(*m);
      for (double a = -3.1; a <= 3.1; a += 0.2) {
        Eigen::VectorXd q = m->q0;
        for (int k = 0; k < m->nq; ++k)
          if (m->joints[static_cast<size_t>(k + 1)].type == codyna::JointType::Revolute) q[k] = a * (k + 1);
        codyna::forward_kinematics(*m, d, q);
        scene.update(d.oMi);
        QVERIFY2(scene.bounds().min().y() > h, f);
      }
      // and not absurdly far below
      QVERIFY(h > scene.bounds().min().y() - 1.5 * scene.length());
    }
    // up follows gravity: the heavy top has g along -z
    auto top = loadExample("heavy_top.json");
    Scene scene;
    scene.build(top.get());
    QVERIFY(scene.up().isApprox(Eigen::Vector3d::UnitZ()));
    QVERIFY(scene.gridCenter().z() < scene.bounds().min().z());
    QVERIFY(scene.gridStep() > 0 && scene.gridHalf() >= 4 * scene.gridStep());
    QCOMPARE(static_cast<int>(scene.gridLines().size()) % 12, 0);
  }

  // bodies without shapes get a ball and links, which pick; overlays follow the joint types
  void defaultLookForShapelessBodies() {
    codyna::ModelSpec spec;
    spec.name = "bare";
    for (int i = 0; i < 3; ++i) {
      codyna::BodySpec b;
      b.name = std::string("b").append(std::to_string(i));
      b.mass = 1;
      b.com = {0.5, 0, 0};
      b.inertia = Eigen::Matrix3d::Identity() * 0.01;
      spec.bodies.push_back(b);
      codyna::JointSpec j;
      j.name = std::string("j").append(std::to_string(i));
      j.type = i == 1 ? codyna::JointType::Prismatic : codyna::JointType::Revolute;
      j.parent = i == 0 ? std::string("ground") : std::string("b").append(std::to_string(i - 1));
      j.child = b.name;
      j.parent_frame.position = i == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(1, 0, 0);
      j.axis = i == 1 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
      spec.joints.push_back(j);
    }
    codyna::BodySpec lone;  // free-floating, nothing to connect
    lone.name = "lone";
    lone.mass = 2;
    lone.inertia = Eigen::Matrix3d::Identity() * 0.02;
    spec.bodies.push_back(lone);
    codyna::JointSpec free;
    free.name = "jf";
    free.type = codyna::JointType::Free;
    free.parent = "ground";
    free.child = "lone";
    free.q0 = (Eigen::VectorXd(7) << 0, -1, 0, 1, 0, 0, 0).finished();
    spec.joints.push_back(free);
    auto m = std::make_shared<const codyna::Model>(codyna::compile(spec));

    Scene scene;
    scene.build(m.get());
    int shapes[5] = {0, 0, 0, 0, 0}, axes = 0, frames = 0, anchors = 0;
    for (const auto& it : scene.items()) {
      if (it.kind == ItemKind::Shape) ++shapes[it.body];
      axes += it.kind == ItemKind::Axis;
      frames += it.kind == ItemKind::Frame;
      anchors += it.kind == ItemKind::Anchor;
    }
    QCOMPARE(shapes[0], 0);
    for (int i = 1; i <= 4; ++i) QVERIFY2(shapes[i] >= 1, qPrintable(QString::number(i)));
    QVERIFY(shapes[1] >= 3);    // ball, link to the next joint, knobs
    QCOMPARE(axes, 3);          // two revolute, one prismatic; none for the free joint
    QCOMPARE(frames, 5);        // the world and four bodies
    QCOMPARE(anchors, 2);       // joints on the ground
    Eigen::Vector3d p;
    QVERIFY(scene.bodyAnchor(m->find_body("lone"), &p));
    QVERIFY((p - Eigen::Vector3d(0, -1, 0)).norm() < 1e-12);
    // the lone ball has the radius of gyration: sqrt(2.5 * 0.02 / 2)
    double r = 0;
    for (const auto& it : scene.items())
      if (it.kind == ItemKind::Shape && it.body == m->find_body("lone")) r = it.world.linear()(0, 0);
    QVERIFY(std::abs(r - std::sqrt(0.025)) < 1e-12);

    View3D view;
    view.resize(600, 400);
    view.setModel(m);
    for (const char* name : {"b0", "b1", "b2", "lone"}) {
      QPointF q;
      QVERIFY(view.bodyScreenPos(name, &q));
      QVERIFY2(!view.pickBody(q.toPoint()).isEmpty(), name);
    }
  }

  // The bus suspension's strut U (a line_force from the wheel's centre to the body's) is a barrel on
  // the wheel and a rod on the body: their outer ends are the attachment points, which the prismatic
  // joints X1, X2 place at (0, 1.5 + X1, 0) and (0, 0.5 + X2, 0) (closed form, not the scene's own
  // kinematics); the two overlap as the strut is pulled or pushed. The road's motion input W draws a
  // cyan arrow along +y from road_height's frame at (0, -0.2, 0), with a disc around it.
  // a body with nothing to connect is the solid ellipsoid of its mass and inertia on the principal
  // axes: the drawn map L = R diag(a) has L L^T = Q diag(a_k^2) Q^T with a_k^2 = 5 (I_1 + I_2 + I_3 -
  // 2 I_k) / (2 m), for the inertia Q diag(I) Q^T (closed form, independent of the eigen-solver's
  // order and signs); a body force is an arrow along its force from its point
  void equivalentEllipsoidAndBodyForce() {
    codyna::ModelSpec spec;
    spec.name = "ellipsoid";
    codyna::BodySpec b;
    b.name = "slab";
    b.mass = 3;
    b.com = {0.1, 0.2, 0.3};
    const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d I(1.0, 2.0, 2.5);
    b.inertia = Q * I.asDiagonal() * Q.transpose();
    spec.bodies.push_back(b);
    codyna::JointSpec j;
    j.name = "hold";
    j.type = codyna::JointType::Fixed;
    j.parent = "ground";
    j.child = "slab";
    j.parent_frame.position = -b.com;
    spec.joints.push_back(j);
    codyna::EffectSpec f;
    f.name = "push";
    f.type = codyna::EffectType::BodyForce;
    f.body_a = "slab";
    f.point_a = {0.5, 0, 0};
    f.force = {0, 0, -20};
    spec.effects.push_back(f);
    auto m = std::make_shared<const codyna::Model>(codyna::compile(spec));
    Scene scene;
    scene.build(m.get());
    Eigen::Vector3d a2;
    for (int k = 0; k < 3; ++k) a2[k] = 2.5 * (I.sum() - 2 * I[k]) / b.mass;
    const Eigen::Matrix3d expected = Q * a2.asDiagonal() * Q.transpose();
    int shapes = 0, forces = 0;
    for (const auto& it : scene.items()) {
      if (it.kind == ItemKind::Shape && it.body == 1 && it.world.translation().norm() < 1e-12) {  // at the com
        ++shapes;
        QCOMPARE(it.prim, Prim::Sphere);
        const Eigen::Matrix3d L = it.world.linear();
        QVERIFY2((L * L.transpose() - expected).norm() < 1e-12 * expected.norm(), qPrintable(QString("%1 vs %2 / %3").arg((L * L.transpose()).norm()).arg(expected.norm()).arg((L * L.transpose() - expected).norm())));
        QVERIFY(L.determinant() > 0);
      }
      if (it.kind == ItemKind::Force) {
        ++forces;
        QCOMPARE(QString::fromStdString(it.element), QString("push"));
        // the arrow's axis (its z) points along the force, its tail at the point
        const Eigen::Vector3d z = it.world.linear().col(2);
        QVERIFY(z.normalized().isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
        const Eigen::Vector3d tail = it.world * Eigen::Vector3d(0, 0, -0.5), point = Eigen::Vector3d(0.5, 0, 0) - b.com;
        QVERIFY2((tail - point).norm() < 1e-12, "tail at the point");
      }
    }
    QCOMPARE(shapes, 1);
    QCOMPARE(forces, 1);
  }

  // a ball joint is marked by a ball at its centre (the heavy top's pivot, on the ground at the
  // joint frame F's origin), drawn with the joint axes
  void ballJointMarker() {
    auto top = loadExample("heavy_top.json");
    Scene scene;
    scene.build(top.get());
    int balls = 0;
    for (const auto& it : scene.items())
      if (it.kind == ItemKind::Axis && it.prim == Prim::Sphere) {
        ++balls;
        QVERIFY((it.world.translation() - top->joints[1].X_PF.p).norm() < 1e-12);
        QVERIFY(it.world.linear()(0, 0) > 0);
      }
    QCOMPARE(balls, 1);
  }

  void lineForceAndMotionOnTheBus() {
    auto m = loadExample("bus_suspension.json");
    Scene scene;
    scene.build(m.get());
    const int x1 = m->joints[static_cast<size_t>(m->find_joint("X1"))].idx_q;
    const int x2 = m->joints[static_cast<size_t>(m->find_joint("X2"))].idx_q;
    const int road = m->joints[static_cast<size_t>(m->find_joint("road_height"))].idx_q;
    for (const auto& [d1, d2] : {std::pair{0.0, 0.0}, {0.31, -0.12}, {-0.27, 0.22}, {0.9, -0.4}}) {
      Eigen::VectorXd q = m->q0;
      q[x1] = d1, q[x2] = d2, q[road] = 0.05;
      place(scene, *m, q);
      const Eigen::Vector3d a(0, 0.5 + d2, 0), b(0, 1.5 + d1, 0);
      const auto strut = itemsOf(scene, ItemKind::LineForce, "U");
      QCOMPARE(strut.size(), size_t(2));
      const auto& barrel = strut[0];
      const auto& rod = strut[1];
      QCOMPARE(barrel.span, codyna::gui::Span::Barrel);
      QCOMPARE(rod.span, codyna::gui::Span::Rod);
      EXPECT_NEAR3(tail(barrel.world), a);
      EXPECT_NEAR3(tip(rod.world), b);
      // along the line from a to b, barrel and rod meeting or overlapping, neither past the other end
      const Eigen::Vector3d u = (b - a).normalized();
      EXPECT_NEAR3(Eigen::Vector3d((tip(barrel.world) - a).normalized()), u);
      EXPECT_NEAR3(Eigen::Vector3d((b - tail(rod.world)).normalized()), u);
      const double lb = (tip(barrel.world) - a).norm(), lr = (b - tail(rod.world)).norm(), len = (b - a).norm();
      QVERIFY(lb + lr >= len - 1e-12 && lb <= len + 1e-12 && lr <= len + 1e-12);
      QVERIFY(barrel.world.linear().col(0).norm() > rod.world.linear().col(0).norm());  // the thicker barrel
      QVERIFY((barrel.color - rod.color).head<3>().norm() > 0.3);                       // two tones

      const auto w = itemsOf(scene, ItemKind::Motion, "W");
      QCOMPARE(w.size(), size_t(2));
      QCOMPARE(w[0].prim, Prim::Arrow);
      EXPECT_NEAR3(tail(w[0].world), Eigen::Vector3d(0, -0.2, 0));
      EXPECT_NEAR3(Eigen::Vector3d((tip(w[0].world) - tail(w[0].world)).normalized()), Eigen::Vector3d(0, 1, 0));
      QCOMPARE(w[1].prim, Prim::Cylinder);
      EXPECT_NEAR3(Eigen::Vector3d(w[1].world.translation()), Eigen::Vector3d(0, -0.2, 0));
    }
    // only the motion input and the line force are marked; the frame of the view holds them
    int marks = 0;
    for (const auto& it : scene.items())
      marks += it.kind == ItemKind::Motion || it.kind == ItemKind::LineForce || it.kind == ItemKind::Coupler ||
               it.kind == ItemKind::Actuator || it.kind == ItemKind::Bushing;
    QCOMPARE(marks, 4);
  }

  // The quadrotor's mixes rotor1..rotor4 show the actuators they drive: thrust1..thrust4 as arrows
  // from the rotor's point (+-0.2, 0, 0), (0, +-0.2, 0) along body z, one colour per rotor, and the
  // yaw torque they share as an arrow along body z through the centre of mass (neutral: four mixes
  // drive it). Placed by the free joint at a turned pose: p + R * point, R * z (closed form).
  void mixedActuatorsOnTheQuadrotor() {
    auto m = loadExample("quadrotor.json");
    Scene scene;
    scene.build(m.get());
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    const Eigen::Quaterniond qr(R);
    const Eigen::Vector3d p(0.3, -0.2, 1.4);
    Eigen::VectorXd q = m->q0;
    q.head<3>() = p;
    q.segment<4>(3) << qr.w(), qr.x(), qr.y(), qr.z();
    QVERIFY(std::abs(m->q0[3] - 1) < 1e-15);  // q0: level, at (0, 0, 1)
    for (int turned = 0; turned < 2; ++turned) {
      const Eigen::VectorXd config = turned ? q : m->q0;
      place(scene, *m, config);
      const Eigen::Matrix3d Rc = turned ? R : Eigen::Matrix3d::Identity();
      const Eigen::Vector3d pc = turned ? p : Eigen::Vector3d(0, 0, 1);
      const Eigen::Vector3d points[4] = {{0.2, 0, 0}, {0, 0.2, 0}, {-0.2, 0, 0}, {0, -0.2, 0}};
      std::vector<Eigen::Vector4f> colors;
      for (int k = 0; k < 4; ++k) {
        const auto arrow = itemsOf(scene, ItemKind::Actuator, "thrust" + std::to_string(k + 1));
        QCOMPARE(arrow.size(), size_t(1));
        QCOMPARE(arrow[0].prim, Prim::Arrow);
        EXPECT_NEAR3(tail(arrow[0].world), Eigen::Vector3d(pc + Rc * points[k]));
        EXPECT_NEAR3(Eigen::Vector3d((tip(arrow[0].world) - tail(arrow[0].world)).normalized()), Eigen::Vector3d(Rc.col(2)));
        for (const auto& c : colors) QVERIFY((c - arrow[0].color).norm() > 0.3);  // one colour per rotor
        colors.push_back(arrow[0].color);
      }
      const auto yaw = itemsOf(scene, ItemKind::Actuator, "yaw_torque");
      QCOMPARE(yaw.size(), size_t(2));  // arrow and disc
      EXPECT_NEAR3(tail(yaw[0].world), pc);
      EXPECT_NEAR3(Eigen::Vector3d((tip(yaw[0].world) - tail(yaw[0].world)).normalized()), Eigen::Vector3d(Rc.col(2)));
      EXPECT_NEAR3(Eigen::Vector3d(yaw[1].world.translation()), pc);
      // the mixes themselves draw nothing: they act through these
      for (int k = 1; k <= 4; ++k) {
        for (const auto& it : scene.items()) QVERIFY(it.element != "rotor" + std::to_string(k));
      }
    }
  }

  // The ball and beam: the motion input alpha marks the beam's pivot (an arrow along z from the origin),
  // and the rolling coupler links the frames of its joints r (on the beam at the pivot) and spin (on
  // the carriage, at r along the turned beam: (r cos alpha, r sin alpha, 0)) with dashes and a dot on
  // each. The geared pendulum's gear links motor's frame (0, 0, -0.05) to theta's (0, 0, 0).
  void couplersAndMotionOnBallBeamAndGear() {
    auto m = loadExample("ball_beam.json");
    Scene scene;
    scene.build(m.get());
    const int ia = m->joints[static_cast<size_t>(m->find_joint("beam_pivot"))].idx_q;
    const int ir = m->joints[static_cast<size_t>(m->find_joint("r"))].idx_q;
    for (const auto& [alpha, r] : {std::pair{0.0, 0.5}, {0.2, 0.37}, {-0.35, 0.81}}) {
      Eigen::VectorXd q = m->q0;
      q[ia] = alpha, q[ir] = r;
      place(scene, *m, q);
      const auto mo = itemsOf(scene, ItemKind::Motion, "alpha");
      QCOMPARE(mo.size(), size_t(2));
      EXPECT_NEAR3(tail(mo[0].world), Eigen::Vector3d::Zero());
      EXPECT_NEAR3(Eigen::Vector3d((tip(mo[0].world) - tail(mo[0].world)).normalized()), Eigen::Vector3d::UnitZ());
      const auto c = itemsOf(scene, ItemKind::Coupler, "rolling");
      const Eigen::Vector3d a = Eigen::Vector3d::Zero(), b(r * std::cos(alpha), r * std::sin(alpha), 0);
      QCOMPARE(c.size(), size_t(2 + 7));  // two dots, seven dashes
      QCOMPARE(c[0].prim, Prim::Sphere);
      EXPECT_NEAR3(Eigen::Vector3d(c[0].world.translation()), a);
      EXPECT_NEAR3(Eigen::Vector3d(c[1].world.translation()), b);
      EXPECT_NEAR3(tail(c[2].world), a);
      EXPECT_NEAR3(tip(c.back().world), b);
      for (size_t k = 2; k < c.size(); ++k) {  // dashes on the line, gaps between them
        const Eigen::Vector3d s = tail(c[k].world), e = tip(c[k].world);
        QVERIFY(std::abs((s - a).cross(b - a).norm()) < 1e-12 && std::abs((e - a).cross(b - a).norm()) < 1e-12);
        if (k > 2) QVERIFY((s - a).norm() > (tip(c[k - 1].world) - a).norm() + 1e-3 * r);
      }
    }

    auto g = loadExample("geared_pendulum.json");
    scene.build(g.get());
    const int it = g->joints[static_cast<size_t>(g->find_joint("theta"))].idx_q;
    const int im = g->joints[static_cast<size_t>(g->find_joint("motor"))].idx_q;
    Eigen::VectorXd q = g->q0;
    q[it] = 0.3, q[im] = 15.0;
    place(scene, *g, q);
    const auto c = itemsOf(scene, ItemKind::Coupler, "gear");
    QCOMPARE(c.size(), size_t(9));
    EXPECT_NEAR3(Eigen::Vector3d(c[0].world.translation()), Eigen::Vector3d(0, 0, -0.05));
    EXPECT_NEAR3(Eigen::Vector3d(c[1].world.translation()), Eigen::Vector3d::Zero());
    EXPECT_NEAR3(tail(c[2].world), Eigen::Vector3d(0, 0, -0.05));
    EXPECT_NEAR3(tip(c.back().world), Eigen::Vector3d::Zero());
    QVERIFY(itemsOf(scene, ItemKind::Motion, "tau_m").empty());  // a joint force is no motion input
  }

  // A bushing between the ground (its frame at (0, 0, 1.2), turned) and the quadrotor's frame (at
  // its origin): a block on each frame, turned with it, and the line between the origins when apart.
  void bushingBlocks() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("quadrotor.json").toStdString();
    codyna::ModelSpec spec = codyna::load_model_spec(path);
    codyna::EffectSpec b;
    b.name = "mount";
    b.type = codyna::EffectType::Bushing;
    b.body_a = "ground";
    b.body_b = "frame";
    b.frame_a.position = {0, 0, 1.2};
    const Eigen::Matrix3d Ra = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
    b.frame_a.rotation = Ra;
    b.translational_stiffness = {100, 100, 100};
    spec.effects.push_back(b);
    auto m = std::make_shared<const codyna::Model>(codyna::compile(spec, path));
    Scene scene;
    scene.build(m.get());
    const Eigen::Matrix3d R = Eigen::AngleAxisd(-0.5, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
    const Eigen::Quaterniond qr(R);
    const Eigen::Vector3d p(0.1, 0.25, 0.9);
    Eigen::VectorXd q = m->q0;
    q.head<3>() = p;
    q.segment<4>(3) << qr.w(), qr.x(), qr.y(), qr.z();
    place(scene, *m, q);
    const auto items = itemsOf(scene, ItemKind::Bushing, "mount");
    QCOMPARE(items.size(), size_t(3));
    QCOMPARE(items[0].prim, Prim::Box);
    EXPECT_NEAR3(Eigen::Vector3d(items[0].world.translation()), Eigen::Vector3d(0, 0, 1.2));
    const Eigen::Matrix3d La = items[0].world.linear(), Lb = items[1].world.linear();
    const double sa = La.col(0).norm(), sb = Lb.col(0).norm();
    QVERIFY(((La / sa) - Ra).cwiseAbs().maxCoeff() < 1e-12);
    EXPECT_NEAR3(Eigen::Vector3d(items[1].world.translation()), p);
    QVERIFY(((Lb / sb) - R).cwiseAbs().maxCoeff() < 1e-12);
    EXPECT_NEAR3(tail(items[2].world), Eigen::Vector3d(0, 0, 1.2));
    EXPECT_NEAR3(tip(items[2].world), p);
  }

  // the sedan in its steady 0.4 g left turn (examples/sedan.json): one load arrow and one in-plane
  // arrow per tire from its contact point. Against the car's balance, from the kinematics alone
  // (the tires and gravity are its only external forces; every centre of mass turns at the yaw
  // rate r on its circle, a_i = r ez x v_i): the arrows, read back as forces through the legend's
  // scale, sum to m a - m g
  void tireForcesOfTheSedanInATurn() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("sedan.json").toStdString();
    codyna::ModelSpec spec = codyna::study_read_model(path);
    spec.analysis.steady.lateral_acceleration = 0.4 * 9.80665;
    auto m = std::make_shared<const codyna::Model>(codyna::study_model(spec, path));
    const codyna::OperatingPoint op = codyna::study_operating_point(*m);
    QVERIFY(op.motion.has_value());
    const double r = op.motion->joints.at(0).yaw_rate;
    QVERIFY(r > 0.1);

    View3D view;
    view.resize(640, 480);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setModel(m);
    view.setState(op.q, op.v);
    QCOMPARE(view.velocities(), op.v);
    const Scene& scene = view.scene();
    const double scale = scene.tireForceScale();
    // a round scale: 1, 2 or 5 times a power of ten metres per kN, a tire's share of the weight
    // between 0.4 and 1 of a quarter of the car's size
    const double per_kN = scale * 1000, decade = std::pow(10.0, std::floor(std::log10(per_kN) + 1e-9));
    const double mantissa = per_kN / decade;
    QVERIFY2(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 || std::abs(mantissa - 5) < 1e-9,
             qPrintable(QString::number(per_kN)));
    double mass = 0;
    for (int i = 1; i < m->nbodies; ++i) mass += m->mass[static_cast<size_t>(i)];
    const double share_len = mass * m->gravity.norm() / 4 * scale;
    QVERIFY2(share_len > 0.4 * 0.25 * scene.length() && share_len <= 0.25 * scene.length() * (1 + 1e-12),
             qPrintable(QString("%1 m for a quarter of %2 m").arg(share_len).arg(scene.length())));
    const QString legend = view.tireForceLegend();
    QVERIFY2(legend.contains(QString("1 kN = %1 m").arg(per_kN, 0, 'g', 3)), qPrintable(legend));
    QVERIFY(view.findChild<QLabel*>("view3dTireLegend")->isVisible());

    int loads = 0, in_plane = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    QSet<QString> tires;
    for (const auto& it : scene.items()) {
      if (it.kind != ItemKind::TireLoad && it.kind != ItemKind::TireInPlane) continue;
      QCOMPARE(it.prim, Prim::Arrow);
      const Eigen::Vector3d a = tail(it.world), b = tip(it.world), F = (b - a) / scale;
      // from the contact point, on the road (z = 0)
      QVERIFY2(std::abs(a.z()) < 1e-12, qPrintable(str(a)));
      sum += F;
      tires.insert(QString::fromStdString(it.element));
      if (it.kind == ItemKind::TireLoad) {
        ++loads;
        // straight up, a tire's share of the weight within a factor 2 (the outer ones carry more)
        QVERIFY2(F.head<2>().norm() < 1e-12 * F.z(), qPrintable(str(F)));
        QVERIFY(F.z() > 0.4 * mass * m->gravity.norm() / 4 && F.z() < 1.8 * mass * m->gravity.norm() / 4);
      } else {
        ++in_plane;
        QVERIFY2(std::abs(F.z()) < 1e-9 * F.norm(), qPrintable(str(F)));  // in the road plane
      }
    }
    QCOMPARE(loads, 4);
    QCOMPARE(in_plane, 4);
    QCOMPARE(tires, (QSet<QString>{"tire_fl", "tire_fr", "tire_rl", "tire_rr"}));
    // the balance
    codyna::Data d(*m);
    codyna::forward_kinematics(*m, d, op.q, op.v);
    Eigen::Vector3d ma = Eigen::Vector3d::Zero(), W = Eigen::Vector3d::Zero();
    for (int i = 1; i < m->nbodies; ++i) {
      const double mi = m->mass[static_cast<size_t>(i)];
      ma += mi * r * Eigen::Vector3d::UnitZ().cross(codyna::point_velocity<double>(d, i, m->com[static_cast<size_t>(i)]));
      W += mi * m->gravity;
    }
    QVERIFY2((sum + W - ma).norm() < 1e-6 * W.norm(), qPrintable(str(sum) + " vs " + str(Eigen::Vector3d(ma - W))));
    // the lateral force pulls to the centre of the turn, 0.4 g of the car's mass
    QVERIFY(std::abs(sum.head<2>().norm() - 0.4 * W.norm()) < 0.02 * W.norm());

    // hidden and shown again; the arrows and the legend with them
    view.setShowTireForces(false);
    QVERIFY(itemsOf(scene, ItemKind::TireLoad, "tire_fl").empty());
    QVERIFY(view.tireContacts().empty());
    QVERIFY(view.tireForceLegend().isEmpty());
    view.setShowTireForces(true);
    QCOMPARE(itemsOf(scene, ItemKind::TireLoad, "tire_fl").size(), size_t(1));
    // the car a metre up: no contact, no arrow, no legend
    Eigen::VectorXd up = op.q;
    up[m->joints[static_cast<size_t>(m->find_body("chassis"))].idx_q + 2] += 1.0;
    view.setConfiguration(up);
    QCOMPARE(view.tireContacts().size(), size_t(4));
    for (const auto& c : view.tireContacts()) QVERIFY(!c.in_contact);
    QVERIFY(itemsOf(scene, ItemKind::TireLoad, "tire_fl").empty());
    QVERIFY(view.tireForceLegend().isEmpty());
    // a state of the wrong size changes nothing
    view.setState(op.q, Eigen::VectorXd::Zero(m->nv + 1));
    QCOMPARE(view.configuration(), up);
    // a model without tires has no arrows and no legend
    view.setModel(loadExample("cart_pendulum.json"));
    QVERIFY(view.tireContacts().empty());
    QCOMPARE(scene.tireForceScale(), 0.0);
    QVERIFY(view.tireForceLegend().isEmpty());
  }

  // an edited model (same file and name) keeps the camera; another model is framed anew
  void cameraKeptOnEdit() {
    View3D view;
    view.resize(640, 480);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setModel(loadExample("four_bar.json"));
    QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(100, 100));
    QTest::mouseMove(&view, QPoint(200, 150));
    QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(200, 150));
    const double yaw = view.camera().yaw;
    QVERIFY(std::abs(yaw - Camera::kDefaultYaw) > 0.3);
    view.setModel(loadExample("four_bar.json"));
    QCOMPARE(view.camera().yaw, yaw);
    view.setModel(loadExample("pendulum.json"));
    QCOMPARE(view.camera().yaw, Camera::kDefaultYaw);
  }
};

QTEST_MAIN(View3DTest)
#include "view3d_test.moc"
