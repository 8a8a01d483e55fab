// gui_view_bench: frame times of the 3-D view (View3D) while the configuration
// changes every frame, as in playback. Needs OpenGL: run under
//   xvfb-run -a -s "-screen 0 1600x1000x24" ./gui_view_bench [frames]
// Models: every example, and a 100-body 3-D hinge chain built in code.
// Columns: paint = paintGL on the CPU up to glFinish (View3D::lastFrameMs),
// frame = setConfiguration + synchronous repaint of the widget (wall time),
// setq = setConfiguration alone (forward kinematics and item transforms).
#include <QApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QOpenGLWidget>

#include "gui/main_window.hpp"
#include <QWindow>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "gui/view3d.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"

namespace {

// links of 0.1 m with alternating hinge axes (z, y), boxes and cylinders in turn
codyna::ModelSpec hingeChain(int n) {
  codyna::ModelSpec spec;
  spec.name = "chain" + std::to_string(n);
  const double len = 0.1;
  for (int i = 0; i < n; ++i) {
    codyna::BodySpec b;
    b.name = std::string("link").append(std::to_string(i));
    b.mass = 0.1;
    b.com = {len / 2, 0, 0};
    b.inertia = Eigen::Vector3d(1e-5, 1e-4, 1e-4).asDiagonal();
    codyna::ShapeSpec s;
    s.frame.position = {len / 2, 0, 0};
    if (i % 2 == 0) {
      s.type = codyna::ShapeType::Box;
      s.size = {len, 0.02, 0.02};
    } else {
      s.type = codyna::ShapeType::Cylinder;
      s.radius = 0.012;
      s.length = len;
      s.frame.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    }
    const double hue = double(i) / n;
    s.color = {0.3 + 0.6 * hue, 0.4, 0.9 - 0.6 * hue, 1.0};
    b.shapes.push_back(s);
    spec.bodies.push_back(b);

    codyna::JointSpec j;
    j.name = std::string("hinge").append(std::to_string(i));
    j.type = codyna::JointType::Revolute;
    j.parent = i == 0 ? std::string(codyna::kGroundName) : spec.bodies[size_t(i - 1)].name;
    j.child = b.name;
    j.parent_frame.position = i == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(len, 0, 0);
    j.axis = i % 2 == 0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    spec.joints.push_back(j);
  }
  codyna::EffectSpec g;
  g.name = "gravity";
  g.type = codyna::EffectType::Gravity;
  spec.effects.push_back(g);
  return spec;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const size_t k = std::min(v.size() - 1, size_t(std::lround(p * double(v.size() - 1))));
  return v[k];
}

// a smooth motion: each revolute/prismatic coordinate swings about q0
Eigen::VectorXd motion(const codyna::Model& m, int frame) {
  Eigen::VectorXd q = m.q0;
  for (int i = 1; i < m.nbodies; ++i) {
    const auto& j = m.joints[size_t(i)];
    if (j.type == codyna::JointType::Revolute || j.type == codyna::JointType::Prismatic) {
      q[j.idx_q] += 0.3 * std::sin(0.1 * frame + 0.2 * i);
    } else if (j.type == codyna::JointType::Spherical) {
      const Eigen::Quaterniond r(Eigen::AngleAxisd(0.3 * std::sin(0.1 * frame), Eigen::Vector3d::UnitX()));
      const Eigen::Quaterniond q0(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2], q[j.idx_q + 3]);
      const Eigen::Quaterniond qn = q0 * r;
      q.segment<4>(j.idx_q) << qn.w(), qn.x(), qn.y(), qn.z();
    }
  }
  return q;
}

struct Row {
  std::string name;
  int bodies = 0, items = 0;
  double paint_med = 0, paint_p90 = 0, frame_med = 0, frame_p90 = 0, setq_us = 0;
};

Row measure(const std::string& name, std::shared_ptr<const codyna::Model> m, int frames, bool overlays = true) {
  codyna::gui::View3D view;
  view.resize(800, 600);
  view.show();
  view.setModel(m);
  view.setShowFrames(overlays);
  auto* canvas = view.findChild<QOpenGLWidget*>();
  QElapsedTimer wait;
  wait.start();
  while (!(view.windowHandle() && view.windowHandle()->isExposed()) && wait.elapsed() < 5000)
    QApplication::processEvents(QEventLoop::AllEvents, 20);  // repaint() does nothing before the window is mapped
  for (int k = 0; k < 5; ++k) {  // warm up: first frames compile shaders and upload meshes
    QApplication::processEvents();
    canvas->repaint();
  }
  std::vector<double> paint, frame, setq;
  QElapsedTimer t;
  for (int f = 0; f < frames; ++f) {
    const Eigen::VectorXd q = motion(*m, f);
    t.start();
    view.setConfiguration(q);
    setq.push_back(t.nsecsElapsed() * 1e-3);
    canvas->repaint();
    QApplication::processEvents();
    frame.push_back(t.nsecsElapsed() * 1e-6);
    paint.push_back(view.lastFrameMs());
  }
  Row r;
  r.name = name;
  r.bodies = m->nbodies - 1;
  r.items = int(view.scene().items().size());
  r.paint_med = percentile(paint, 0.5), r.paint_p90 = percentile(paint, 0.9);
  r.frame_med = percentile(frame, 0.5), r.frame_p90 = percentile(frame, 0.9);
  r.setq_us = percentile(setq, 0.5);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  const int frames = argc > 1 ? std::max(5, std::atoi(argv[1])) : 60;
  if (!codyna::gui::View3D::openGLAvailable()) {
    std::fprintf(stderr, "gui_view_bench: %s; run it under xvfb-run\n",
                 qPrintable(codyna::gui::View3D::openGLUnavailableReason()));
    return 2;
  }
  std::vector<Row> rows;
  const QDir dir(CODYNA_EXAMPLES_DIR);
  for (const QString& f : dir.entryList({"*.json"}, QDir::Files, QDir::Name)) {
    const std::string path = dir.filePath(f).toStdString();
    auto m = std::make_shared<const codyna::Model>(codyna::compile(codyna::load_model_spec(path), path));
    rows.push_back(measure(QFileInfo(f).completeBaseName().toStdString(), m, frames));
  }
  auto chain = std::make_shared<const codyna::Model>(codyna::compile(hingeChain(100)));
  rows.push_back(measure("hinge_chain_100", chain, frames));
  rows.push_back(measure("hinge_chain_100 bare", chain, frames, false));  // frames and axes off

  std::printf("3-D view, 800x600, %d frames each, configuration changed every frame\n", frames);
  std::printf("%-22s %6s %6s %10s %10s %10s %10s %8s\n", "model", "bodies", "items", "paint med", "paint p90",
              "frame med", "frame p90", "setq");
  std::printf("%-22s %6s %6s %10s %10s %10s %10s %8s\n", "", "", "", "ms", "ms", "ms", "ms", "us");
  for (const Row& r : rows)
    std::printf("%-22s %6d %6d %10.2f %10.2f %10.2f %10.2f %8.1f\n", r.name.c_str(), r.bodies, r.items, r.paint_med,
                r.paint_p90, r.frame_med, r.frame_p90, r.setq_us);

  // opening time: File > Open in the main window until the 3-D view has drawn the model
  std::printf("\nopening an example in codyna-gui (load, compile, tree, panels, first 3-D frame), median of 5\n");
  std::printf("%-22s %10s\n", "model", "ms");
  for (const QString& f : dir.entryList({"*.json"}, QDir::Files, QDir::Name)) {
    std::vector<double> ms;
    for (int k = 0; k < 5; ++k) {
      codyna::gui::MainWindow w;
      w.resize(1500, 950);
      w.show();
      QElapsedTimer wait;
      wait.start();
      while (!(w.windowHandle() && w.windowHandle()->isExposed()) && wait.elapsed() < 5000)
        QApplication::processEvents(QEventLoop::AllEvents, 20);
      QApplication::processEvents();
      const int before = w.view3d()->framesDrawn();
      QElapsedTimer t;
      t.start();
      if (!w.openFile(dir.filePath(f))) return 1;
      while (w.view3d()->framesDrawn() == before && t.elapsed() < 10000) QApplication::processEvents();
      ms.push_back(t.nsecsElapsed() * 1e-6);
    }
    std::printf("%-22s %10.1f\n", QFileInfo(f).completeBaseName().toStdString().c_str(), percentile(ms, 0.5));
  }
  return 0;
}
