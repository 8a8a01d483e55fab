// View3D with OpenGL (run under `xvfb-run -a`, Mesa llvmpipe): every example
// renders a non-blank picture (saved as build/screenshots/view3d_<example>.png),
// the picture follows the configuration, the highlight and the overlay switch,
// and the GL camera agrees with the CPU picking.
#include <QApplication>
#include <QDir>
#include <QFileInfo>
#include <QOpenGLWidget>
#include <QSignalSpy>
#include <QVBoxLayout>
#include <QSet>
#include <QtTest>
#include <cmath>

#include "gui/view3d.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"

using codyna::gui::View3D;

namespace {

constexpr int kW = 800, kH = 600;

std::shared_ptr<const codyna::Model> loadExample(const QString& file) {
  const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath(file).toStdString();
  return std::make_shared<const codyna::Model>(codyna::compile(codyna::load_model_spec(path), path));
}

Eigen::VectorXd perturbed(const codyna::Model& m, double amount) {
  Eigen::VectorXd q = m.q0;
  for (int i = 1; i < m.nbodies; ++i) {
    const auto& j = m.joints[static_cast<size_t>(i)];
    if (j.type == codyna::JointType::Spherical) {
      const Eigen::Quaterniond r(Eigen::AngleAxisd(amount, Eigen::Vector3d::UnitX()));
      const Eigen::Quaterniond q0(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2], q[j.idx_q + 3]);
      const Eigen::Quaterniond qn = q0 * r;
      q.segment<4>(j.idx_q) << qn.w(), qn.x(), qn.y(), qn.z();
    } else if (j.type == codyna::JointType::Free) {
      q[j.idx_q] += amount;  // its position (x); the quaternion follows at idx_q + 3
    } else {
      for (int k = 0; k < j.nq; ++k) q[j.idx_q + k] += amount;
    }
  }
  return q;
}

int colorDistance(QRgb a, QRgb b) {
  return std::abs(qRed(a) - qRed(b)) + std::abs(qGreen(a) - qGreen(b)) + std::abs(qBlue(a) - qBlue(b));
}

// pixels where two same-size images differ by more than `margin` (sum of |dr|, |dg|, |db|)
int differingPixels(const QImage& a, const QImage& b, int margin) {
  int n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) n += colorDistance(a.pixel(x, y), b.pixel(x, y)) > margin;
  return n;
}

// colours (5 bits a channel) that cover at least `min_pixels` pixels among those unlike the background
int distinctColors(const QImage& img, const QImage& bg, int margin, int min_pixels) {
  QHash<int, int> bins;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const QRgb c = img.pixel(x, y);
      if (colorDistance(c, bg.pixel(x, y)) <= margin) continue;
      ++bins[(qRed(c) >> 3) << 10 | (qGreen(c) >> 3) << 5 | (qBlue(c) >> 3)];
    }
  int n = 0;
  for (int count : bins) n += count >= min_pixels;
  return n;
}

QImage grabOf(View3D& view) { return view.grabImage().convertToFormat(QImage::Format_RGB32); }

}  // namespace

class View3DXvfb : public QObject {
  Q_OBJECT

  QImage background_;

 private slots:
  void initTestCase() {
    QVERIFY2(View3D::openGLAvailable(), qPrintable(View3D::openGLUnavailableReason()));
    QVERIFY(QDir().mkpath(CODYNA_SCREENSHOT_DIR));
    // the empty view, grid off: the background gradient alone
    View3D view;
    view.resize(kW, kH);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    QVERIFY(view.hasGL());
    view.setShowGrid(false);
    background_ = grabOf(view);
    QCOMPARE(background_.size(), QSize(kW, kH));
    // a gradient: lighter at the bottom, and nothing else
    QVERIFY(qGray(background_.pixel(kW / 2, kH - 2)) > qGray(background_.pixel(kW / 2, 1)) + 10);
    QCOMPARE(differingPixels(background_, background_.mirrored(true, false), 6), 0);
  }

  void renders_data() {
    QTest::addColumn<QString>("file");
    for (const QString& f : QDir(CODYNA_EXAMPLES_DIR).entryList({"*.json"}, QDir::Files, QDir::Name))
      QTest::newRow(qPrintable(f)) << f;
  }

  void renders() {
    QFETCH(QString, file);
    auto m = loadExample(file);
    View3D view;
    view.setWindowTitle(file);
    view.resize(kW, kH);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setModel(m);
    QApplication::processEvents();
    const int frames0 = view.framesDrawn();
    const QImage img = grabOf(view);
    QCOMPARE(img.size(), QSize(kW, kH));
    QVERIFY(view.framesDrawn() > frames0);
    QVERIFY(view.lastFrameMs() > 0);
    const QString name = QFileInfo(file).completeBaseName();
    QVERIFY(img.save(QDir(CODYNA_SCREENSHOT_DIR).filePath("view3d_" + name + ".png")));

    // not blank: the mechanism, grid and frames cover a good share, in several colours
    const int total = kW * kH;
    const int covered = differingPixels(img, background_, 40);
    QVERIFY2(covered > total / 50, qPrintable(QString("%1 of %2 pixels drawn").arg(covered).arg(total)));
    const int colors = distinctColors(img, background_, 40, 40);
    QVERIFY2(colors >= 8, qPrintable(QString("%1 colours").arg(colors)));

    // where picking finds a body, GL drew something, and the highlight changes it
    // (frames and tire forces off: a triad or a tire's load arrow may lie over the body's centre)
    view.setShowFrames(false);
    view.setShowTireForces(false);
    const QImage plain = grabOf(view);
    for (int i = 1; i < m->nbodies; ++i) {
      const QString body = QString::fromStdString(m->body_names[static_cast<size_t>(i)]);
      QPointF p;
      QVERIFY(view.bodyScreenPos(body, &p));
      if (view.pickBody(p.toPoint()) != body) continue;  // hidden behind another body
      const QPoint px = p.toPoint();
      QVERIFY2(colorDistance(plain.pixel(px), background_.pixel(px)) > 40, qPrintable(body));
      view.setHighlight(body);
      const QImage hl = grabOf(view);
      QVERIFY2(colorDistance(hl.pixel(px), plain.pixel(px)) > 40, qPrintable(body));
      QVERIFY2(differingPixels(hl, plain, 40) >= 20, qPrintable(body));
      view.setHighlight("");
    }
    view.setShowFrames(true);
    view.setShowTireForces(true);

    // the largest body's highlight is plainly visible and orange-ish
    QString biggest;
    double volume = -1;
    for (const auto& it : view.scene().items()) {
      if (it.kind != codyna::gui::ItemKind::Shape) continue;
      const double v = std::abs(it.world.linear().determinant());
      if (v > volume) volume = v, biggest = QString::fromStdString(m->body_names[static_cast<size_t>(it.body)]);
    }
    view.setHighlight(biggest);
    const QImage hl = grabOf(view);
    view.setHighlight("");
    QVERIFY2(differingPixels(hl, img, 40) > 300, qPrintable(biggest));
    int orange = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const QRgb c = hl.pixel(x, y);
        orange += colorDistance(c, img.pixel(x, y)) > 40 && qRed(c) > qGreen(c) + 40 && qGreen(c) > qBlue(c) + 40;
      }
    QVERIFY2(orange > 150, qPrintable(QString("%1 orange pixels").arg(orange)));
    // the outline: orange pixels where the picture without the selection shows the background
    int rim = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const QRgb c = hl.pixel(x, y);
        rim += colorDistance(img.pixel(x, y), background_.pixel(x, y)) < 10 && qRed(c) > 200 && qGreen(c) > 90 &&
               qGreen(c) < 170 && qBlue(c) < 60;
      }
    QVERIFY2(rim > 40, qPrintable(QString("%1 outline pixels around %2").arg(rim).arg(biggest)));
    // centres of mass on request: one marker per body with mass, drawn
    int masses = 0, markers = 0;
    for (int i = 1; i < m->nbodies; ++i) masses += m->mass[static_cast<size_t>(i)] > 0;
    for (const auto& it : view.scene().items()) markers += it.kind == codyna::gui::ItemKind::Com;
    QCOMPARE(markers, masses);
    view.setShowCom(true);
    const QImage com = grabOf(view);
    view.setShowCom(false);
    if (masses > 0) QVERIFY2(differingPixels(com, img, 40) > 10, qPrintable(name));
    if (name == "four_bar") QVERIFY(com.save(QDir(CODYNA_SCREENSHOT_DIR).filePath("view3d_four_bar_com.png")));
    if (name == "four_bar") QVERIFY(hl.save(QDir(CODYNA_SCREENSHOT_DIR).filePath("view3d_four_bar_highlight.png")));

    // another configuration is another picture; the same one again is the same picture
    view.setConfiguration(perturbed(*m, 0.5));
    const QImage moved = grabOf(view);
    QVERIFY(moved.save(QDir(CODYNA_SCREENSHOT_DIR).filePath("view3d_" + name + "_moved.png")));
    const int changed = differingPixels(moved, img, 40);
    QVERIFY2(changed > total / 400, qPrintable(QString("%1 pixels changed").arg(changed)));
    view.setConfiguration(m->q0);
    QCOMPARE(differingPixels(grabOf(view), img, 3), 0);

    // frames and axes off: fewer pixels drawn
    view.setShowFrames(false);
    const QImage bare = grabOf(view);
    QVERIFY(differingPixels(bare, img, 40) > 100);
    QVERIFY(differingPixels(bare, background_, 40) < covered);
  }

  // the grid is a floor: it shows under the pendulum, and switching it off removes it
  void gridAndInteraction() {
    View3D view;
    view.resize(kW, kH);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setModel(loadExample("pendulum.json"));
    const QImage with_grid = grabOf(view);
    view.setShowGrid(false);
    const QImage without = grabOf(view);
    view.setShowGrid(true);
    QVERIFY(differingPixels(with_grid, without, 20) > 1000);
    // orbit by dragging changes the picture; F brings the fitted view back at the new angle
    QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(300, 300));
    QTest::mouseMove(&view, QPoint(360, 280));
    QTest::mouseMove(&view, QPoint(420, 260));
    QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(420, 260));
    const QImage orbited = grabOf(view);
    QVERIFY(differingPixels(orbited, with_grid, 40) > 2000);
    view.resetView();
    QCOMPARE(differingPixels(grabOf(view), with_grid, 3), 0);
    // clicks on the GL canvas reach the view and pick
    auto* canvas = view.findChild<QOpenGLWidget*>();
    QVERIFY(canvas);
    QSignalSpy spy(&view, &View3D::bodyPicked);
    QPointF p;
    QVERIFY(view.bodyScreenPos("rod", &p));
    QTest::mouseClick(canvas, Qt::LeftButton, {}, p.toPoint());
    QTest::mouseClick(canvas, Qt::LeftButton, {}, QPoint(4, 4));
    QCOMPARE(spy.count(), 2);
    QCOMPARE(spy.at(0).at(0).toString(), QStringLiteral("rod"));
    QCOMPARE(spy.at(1).at(0).toString(), QString());
  }

  // the sedan in its steady 0.4 g left turn with its tires' contact forces (the picture in
  // docs/vehicles.md): blue load arrows and teal in-plane arrows where the tires touch the road,
  // gone with View > Show tire forces off; the legend over the picture
  void sedanTireForces() {
    const std::string path = QDir(CODYNA_EXAMPLES_DIR).filePath("sedan.json").toStdString();
    codyna::ModelSpec spec = codyna::study_read_model(path);
    spec.analysis.steady.lateral_acceleration = 0.4 * 9.80665;
    auto m = std::make_shared<const codyna::Model>(codyna::study_model(spec, path));
    const codyna::OperatingPoint op = codyna::study_operating_point(*m);
    View3D view;
    view.setWindowTitle("sedan");
    view.resize(1000, 640);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
    view.setModel(m);
    view.setState(op.q, op.v);
    view.setShowFrames(false);  // the car and its forces, not its 25 body frames
    // seen from behind (a drag of 209 px turns the default yaw, 0.45 rad, to -pi/2 + 0.35), a little
    // lower than the default: the loads up, the lateral forces to the left, into the turn
    QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(400, 300));
    QTest::mouseMove(&view, QPoint(500, 300));
    QTest::mouseMove(&view, QPoint(609, 288));
    QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(609, 288));
    QVERIFY(std::abs(view.camera().yaw - (-M_PI / 2 + 0.35)) < 0.01);
    view.fitView();
    QApplication::processEvents();
    const QImage with = grabOf(view);
    QVERIFY(with.save(QDir(CODYNA_SCREENSHOT_DIR).filePath("view3d_sedan_tire_forces.png")));
    view.setShowTireForces(false);
    QApplication::processEvents();
    const QImage without = grabOf(view);
    // shaded blue (the loads: blue over green over red) and teal (green and blue over red)
    const auto count = [](const QImage& img, bool blue) {
      int n = 0;
      for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
          const QRgb c = img.pixel(x, y);
          const int r = qRed(c), g = qGreen(c), b = qBlue(c);
          n += blue ? (b > g + 50 && g > r + 25) : (g > r + 60 && b > r + 50 && std::abs(g - b) < 40);
        }
      return n;
    };
    const int blue = count(with, true), teal = count(with, false);
    qInfo("sedan in a 0.4 g turn: %d blue and %d teal pixels with the tire forces, %d and %d without", blue, teal,
          count(without, true), count(without, false));
    QVERIFY2(blue > 2000, qPrintable(QString::number(blue)));
    QVERIFY2(teal > 600, qPrintable(QString::number(teal)));
    QVERIFY(count(without, true) < blue / 50);
    QVERIFY(count(without, false) < teal / 50);
    // the legend is in the picture (bottom left): dark text on its light box
    const QString legend = view.tireForceLegend();
    QVERIFY(legend.isEmpty());  // hidden with the forces
    view.setShowTireForces(true);
    QVERIFY(view.tireForceLegend().contains("1 kN = "));
    int dark = 0;
    for (int y = with.height() - 60; y < with.height(); ++y)
      for (int x = 0; x < 300; ++x) dark += qGray(with.pixel(x, y)) < 90;
    QVERIFY2(dark > 200, qPrintable(QString::number(dark)));
  }

  // docking moves the view to another window and so to another GL context
  void survivesReparenting() {
    QWidget a, b;
    a.resize(kW, kH), b.resize(kW, kH);
    auto* layout_a = new QVBoxLayout(&a);
    auto* layout_b = new QVBoxLayout(&b);
    layout_a->setContentsMargins(0, 0, 0, 0), layout_b->setContentsMargins(0, 0, 0, 0);
    auto* view = new View3D;
    layout_a->addWidget(view);
    a.show();
    QVERIFY(QTest::qWaitForWindowExposed(&a));
    view->setModel(loadExample("four_bar.json"));
    const QImage first = grabOf(*view);
    QVERIFY(differingPixels(first, background_, 40) > kW * kH / 50);
    layout_b->addWidget(view);  // reparents
    b.show();
    QVERIFY(QTest::qWaitForWindowExposed(&b));
    view->show();
    QApplication::processEvents();
    const QImage second = grabOf(*view);
    QCOMPARE(second.size(), first.size());
    // the same picture (edges may be antialiased differently in the new context)
    QVERIFY(differingPixels(second, background_, 40) > kW * kH / 50);
    QVERIFY(differingPixels(second, first, 40) < kW * kH / 20);
  }
};

QTEST_MAIN(View3DXvfb)
#include "view3d_xvfb.moc"
