// The rolling_ball constraint as rendered (run under `xvfb-run -a`, Mesa llvmpipe): the ball and
// plate with the overlays off (frames, motion arrows) shows the contact patch, the only green
// thing in the picture, inside the projection of the disc the scene placed at the contact (the
// ball's centre less R along the plate's normal), and it follows the ball when the ball moves and
// the plate tilts. Saves build/screenshots/rolling_ball_plate.png and _moved.png.
#include <QApplication>
#include <QDir>
#include <QtTest>
#include <cmath>
#include <numbers>

#include "dynamics/prepare.hpp"
#include "gui/view3d.hpp"
#include "io/model_file.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

constexpr int kW = 800, kH = 600;

bool green(QRgb c) { return qGreen(c) > qRed(c) + 40 && qGreen(c) > qBlue(c) + 15; }

// the contact disc's rim in pixels, as the camera projects it
struct Box {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  bool contains(int x, int y, double margin) const {
    return x >= x0 - margin && x <= x1 + margin && y >= y0 - margin && y <= y1 + margin;
  }
  bool overlaps(const Box& o) const { return !(o.x0 > x1 || o.x1 < x0 || o.y0 > y1 || o.y1 < y0); }
};

Box rimOf(const View3D& view, const Item& disc) {
  Camera cam = view.camera();
  cam.width = view.width(), cam.height = view.height();
  Box b;
  for (int k = 0; k < 64; ++k) {
    const double t = 2 * std::numbers::pi * k / 64;
    for (const double z : {-0.5, 0.5}) {
      Eigen::Vector2d px;
      if (!cam.project(disc.world * Eigen::Vector3d(std::cos(t), std::sin(t), z), &px)) continue;
      b.x0 = std::min(b.x0, px.x()), b.x1 = std::max(b.x1, px.x());
      b.y0 = std::min(b.y0, px.y()), b.y1 = std::max(b.y1, px.y());
    }
  }
  return b;
}

const Item* discOf(const View3D& view) {
  for (const Item& it : view.scene().items())
    if (it.kind == ItemKind::Contact && it.prim == Prim::Cylinder) return &it;
  return nullptr;
}

}  // namespace

class RollingXvfb : public QObject {
  Q_OBJECT

 private slots:
  void initTestCase() {
    QVERIFY2(View3D::openGLAvailable(), qPrintable(View3D::openGLUnavailableReason()));
    QVERIFY(QDir().mkpath(CODYNA_SCREENSHOT_DIR));
  }

  void contactPatchIsDrawnAtTheContact() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("ball_plate.json").toStdString();
    const auto m = std::make_shared<const Model>(compile(load_model_spec(path), path));
    View3D view;
    view.resize(kW, kH);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setShowFrames(false);
    view.setModel(m);
    QApplication::processEvents();

    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY())).toRotationMatrix();
    Eigen::VectorXd moved = m->q0;
    moved[m->joints[static_cast<size_t>(m->find_joint("tilt_x"))].idx_q] = 0.15;
    moved[m->joints[static_cast<size_t>(m->find_joint("tilt_y"))].idx_q] = -0.1;
    moved.segment<3>(m->joints[static_cast<size_t>(m->find_joint("ball"))].idx_q) = R * Eigen::Vector3d(-0.15, -0.1, 0);

    Box before;
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1) view.setConfiguration(moved);
      const QImage img = view.grabImage().convertToFormat(QImage::Format_RGB32);
      QCOMPARE(img.size(), QSize(kW, kH));
      QVERIFY(img.save(QDir(CODYNA_SCREENSHOT_DIR).filePath(pass ? "rolling_ball_plate_moved.png" : "rolling_ball_plate.png")));
      const Item* disc = discOf(view);
      QVERIFY(disc);
      const Box rim = rimOf(view, *disc);
      QVERIFY(rim.x1 - rim.x0 > 20);  // the disc spans some pixels at this zoom
      int inside = 0, outside = 0;
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
          if (!green(img.pixel(x, y))) continue;
          if (rim.contains(x, y, 2)) ++inside;
          else ++outside;
        }
      const double area = (rim.x1 - rim.x0) * (rim.y1 - rim.y0);
      qInfo("pass %d: disc box %.0f x %.0f px at (%.0f, %.0f), %d green pixels in it, %d outside", pass, rim.x1 - rim.x0,
            rim.y1 - rim.y0, rim.x0, rim.y0, inside, outside);
      // green only at the contact, where it covers a good share of the disc's box (the ball hides its middle)
      QCOMPARE(outside, 0);
      QVERIFY2(inside > 0.25 * area, qPrintable(QString("%1 green pixels in a box of %2").arg(inside).arg(area)));
      if (pass == 0) before = rim;
      else QVERIFY(!rim.overlaps(before));  // it went with the ball
    }
  }
};

QTEST_MAIN(RollingXvfb)
#include "rolling_xvfb.moc"
