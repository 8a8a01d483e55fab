// Qt Test of the result plots, the pole map and the matrix / mode table
// models (runs offscreen). Writes screenshots to CODYNA_SCREENSHOT_DIR.
#include <QChart>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QImage>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QSet>
#include <QSignalSpy>
#include <QSvgRenderer>
#include <QPainter>
#include <QTemporaryDir>
#include <QValueAxis>
#include <QWheelEvent>
#include <QLineEdit>
#include <QSpinBox>
#include <QTimer>
#include <QtTest>
#include <cmath>
#include <numbers>

#include "analysis/discretize.hpp"
#include "analysis/linear_system.hpp"
#include "analysis/modal.hpp"
#include "gui/chart_view.hpp"
#include "gui/matrix_models.hpp"
#include "gui/pole_map.hpp"
#include "gui/result_plots.hpp"
#include "gui/signal_plot.hpp"
#include "simulation/result.hpp"

#ifndef CODYNA_SCREENSHOT_DIR
#define CODYNA_SCREENSHOT_DIR "screenshots"
#endif

using codyna::gui::MatrixTableModel;
using codyna::gui::ModeTableModel;
using codyna::gui::PoleMap;
using codyna::gui::ResultPlots;

namespace {

QString screenshot(const QString& name) {
  QDir().mkpath(QStringLiteral(CODYNA_SCREENSHOT_DIR));
  return QDir(QStringLiteral(CODYNA_SCREENSHOT_DIR)).filePath(name);
}

// pixel statistics of an image: distinct colours and the fraction that is not (near) white
struct PixelStats {
  int distinct = 0;
  double non_white = 0;
};
PixelStats stats(const QImage& image) {
  const QImage img = image.convertToFormat(QImage::Format_RGB32);
  QSet<QRgb> colours;
  qint64 nonWhite = 0;
  for (int y = 0; y < img.height(); ++y) {
    const auto* line = reinterpret_cast<const QRgb*>(img.constScanLine(y));
    for (int x = 0; x < img.width(); ++x) {
      colours.insert(line[x]);
      if (qRed(line[x]) < 240 || qGreen(line[x]) < 240 || qBlue(line[x]) < 240) ++nonWhite;
    }
  }
  return {static_cast<int>(colours.size()), double(nonWhite) / (double(img.width()) * img.height())};
}

// does the image hold pixels close to `c` (a series colour)?
int countNear(const QImage& image, QColor c, int tol = 40) {
  const QImage img = image.convertToFormat(QImage::Format_RGB32);
  int n = 0;
  for (int y = 0; y < img.height(); ++y) {
    const auto* line = reinterpret_cast<const QRgb*>(img.constScanLine(y));
    for (int x = 0; x < img.width(); ++x)
      if (std::abs(qRed(line[x]) - c.red()) + std::abs(qGreen(line[x]) - c.green()) +
              std::abs(qBlue(line[x]) - c.blue()) < tol)
        ++n;
  }
  return n;
}

// A pendulum-on-a-cart-like closed-loop response: damped oscillations, a
// controller torque, and a linear prediction that slowly drifts away.
codyna::SimulationResult makeResult(bool withLinear, int n = 501) {
  codyna::SimulationResult r;
  r.u.resize(n, 3);
  r.y.resize(n, 2);
  if (withLinear) r.y_linear.resize(n, 2);
  for (int i = 0; i < n; ++i) {
    const double t = 10.0 * i / (n - 1);
    r.t.push_back(t);
    const double th = 0.5 * std::exp(-0.45 * t) * std::cos(2.1 * t);
    const double x = 0.8 * (1.0 - std::exp(-0.6 * t) * (std::cos(1.3 * t) + 0.2 * std::sin(1.3 * t)));
    r.y(i, 0) = th;
    r.y(i, 1) = x;
    r.u(i, 0) = -12.0 * th + 0.3 * std::sin(3.0 * t) * std::exp(-t);  // plant input "tau_hinge"
    r.u(i, 1) = 1000.0 + i;                                          // not a plant input
    r.u(i, 2) = 4.0 * std::exp(-0.8 * t) * std::sin(1.7 * t + 0.4);   // plant input "F_cart"
    if (withLinear) {
      r.y_linear(i, 0) = 0.5 * std::exp(-0.42 * t) * std::cos(2.15 * t);
      r.y_linear(i, 1) = 0.8 * (1.0 - std::exp(-0.62 * t) * (std::cos(1.28 * t) + 0.2 * std::sin(1.28 * t)));
    }
  }
  r.input_names = {"tau_hinge", "spare", "F_cart"};
  r.input_units = {"N m", "-", "N"};
  r.output_names = {"theta", "x_cart"};
  r.output_units = {"rad", "m"};
  r.completed = true;
  return r;
}

codyna::LinearSystem oscillator() {
  codyna::LinearSystem sys;
  sys.A.resize(2, 2);
  sys.A << 0, 1, -4, -0.4;
  sys.B.resize(2, 1);
  sys.B << 0, 1;
  sys.C.resize(1, 2);
  sys.C << 1, 0;
  sys.D = Eigen::MatrixXd::Zero(1, 1);
  sys.state_names = {"theta", "theta_dot"};
  sys.state_units = {"rad", "rad/s"};
  sys.input_names = {"tau"};
  sys.input_units = {"N m"};
  sys.output_names = {"theta"};
  sys.output_units = {"rad"};
  return sys;
}

// a 4-state system: the oscillator above, a slow real pole and an unstable real one
codyna::LinearSystem fourStates() {
  codyna::LinearSystem sys;
  sys.A = Eigen::MatrixXd::Zero(4, 4);
  sys.A(0, 1) = 1;
  sys.A(1, 0) = -2.25;
  sys.A(1, 1) = -0.4;
  sys.A(2, 2) = -0.5;
  sys.A(3, 3) = 0.8;
  sys.A(2, 0) = 0.3;
  sys.B = Eigen::MatrixXd::Zero(4, 1);
  sys.C = Eigen::MatrixXd::Zero(1, 4);
  sys.D = Eigen::MatrixXd::Zero(1, 1);
  sys.state_names = {"theta", "theta_dot", "x", "phi"};
  return sys;
}

void clickPole(PoleMap& map, int i) {
  const QPoint pos = map.poleWidgetPosition(i);
  QWidget* target = map.childAt(pos);  // the chart view's viewport, as a real click
  QVERIFY(target);
  QTest::mouseClick(target, Qt::LeftButton, Qt::NoModifier, target->mapFrom(&map, pos));
}

}  // namespace

class PlotsTest : public QObject {
  Q_OBJECT
 private slots:
  void niceRanges();
  void liveBuffersAndThrottles();
  void liveThrottlesAStream();
  void liveAxesGrow();
  void resultTakesPlantInputs();
  void resultWithoutLinear();
  void decimationKeepsPeaks();
  void timeCursor();
  void saveImages();
  void poleMapContinuous();
  void poleMapDrawsTheCoresStability();
  void poleMapDiscrete();
  void matrixModel();
  void modeModel();
  void zoomKeepsTicksBounded();
  void chartImageAtChosenSize();
  void referencesAndDisturbancesDrawn();
};

void PlotsTest::niceRanges() {
  const auto r = codyna::gui::niceRange(-0.37, 1.93, 5);
  QCOMPARE(r.step, 0.5);
  QCOMPARE(r.min, -0.5);
  QCOMPARE(r.max, 2.0);
  const auto z = codyna::gui::niceRange(0.0, 0.0, 5);
  QVERIFY(z.min < 0.0 && z.max > 0.0);
  const auto e = codyna::gui::niceRange(0.0, 10.0, 5);
  QCOMPARE(e.min, 0.0);
  QCOMPARE(e.max, 10.0);
  QCOMPARE(e.step, 2.0);
  QCOMPARE(codyna::gui::nameWithUnit("theta", "rad"), QStringLiteral("theta [rad]"));
  QCOMPARE(codyna::gui::nameWithUnit("k", ""), QStringLiteral("k"));
}

// 1000 samples as fast as they come: the series are not updated per sample
void PlotsTest::liveBuffersAndThrottles() {
  ResultPlots plots;
  plots.resize(900, 600);
  plots.show();
  QVERIFY(QTest::qWaitForWindowExposed(&plots));
  QCOMPARE(plots.refreshIntervalMs(), 100);
  plots.setRefreshIntervalMs(50);
  plots.reset({"tau"}, {"N m"}, {"theta", "omega"}, {"rad", "rad/s"}, 5.0);
  QCOMPARE(plots.inputSeriesCount(), 1);
  QCOMPARE(plots.outputSeriesCount(), 2);
  QCOMPARE(plots.linearPoints(0).size(), 0);
  const int before = plots.redrawCount();

  QElapsedTimer clock;
  clock.start();
  std::vector<double> ts;
  std::vector<Eigen::VectorXd> us, ys;
  for (int i = 0; i < 1000; ++i) {
    const double t = 0.005 * i;
    Eigen::VectorXd u(1), y(2);
    u << std::sin(t) * 3.0 + 1e-7 * i;  // (values that a float would not keep)
    y << 0.1 * std::cos(2 * t) + 1.0 / 3.0, -0.2 * std::sin(2 * t);
    plots.appendSample(t, u, y);
    ts.push_back(t);
    us.push_back(u);
    ys.push_back(y);
  }
  QTest::qWait(260);
  const qint64 elapsed = clock.elapsed();
  const int redraws = plots.redrawCount() - before;
  QVERIFY2(redraws >= 1, "the timer never redrew");
  QVERIFY2(redraws <= elapsed / plots.refreshIntervalMs() + 2,
           qPrintable(QStringLiteral("%1 redraws in %2 ms").arg(redraws).arg(elapsed)));

  plots.flush();
  const QList<QPointF> in = plots.inputPoints(0), out0 = plots.outputPoints(0), out1 = plots.outputPoints(1);
  QCOMPARE(in.size(), 1000);
  QCOMPARE(out0.size(), 1000);
  QCOMPARE(out1.size(), 1000);
  for (int i = 0; i < 1000; ++i) {
    QCOMPARE(in[i].x(), ts[i]);  // exact: the doubles as given
    QCOMPARE(in[i].y(), us[i](0));
    QCOMPARE(out0[i].x(), ts[i]);
    QCOMPARE(out0[i].y(), ys[i](0));
    QCOMPARE(out1[i].y(), ys[i](1));
  }
  // a flush with nothing new does not redraw
  const int n = plots.redrawCount();
  plots.flush();
  QCOMPARE(plots.redrawCount(), n);
  QVERIFY(plots.saveImage(screenshot("plots_live.png")));
}

// a stream of samples over ~600 ms (event loop running): redraws at most every interval
void PlotsTest::liveThrottlesAStream() {
  ResultPlots plots;
  plots.resize(800, 500);
  plots.show();
  QVERIFY(QTest::qWaitForWindowExposed(&plots));
  plots.reset({"u"}, {}, {"y"}, {}, 1.0);
  plots.setMaxPlotPoints(1000000);  // this test checks the throttle and exact points, not decimation
  const int before = plots.redrawCount();
  QElapsedTimer clock;
  clock.start();
  int sent = 0;
  while (clock.elapsed() < 600) {
    for (int k = 0; k < 20; ++k, ++sent) {
      Eigen::VectorXd u(1), y(1);
      u << sent;
      y << -sent;
      plots.appendSample(1e-3 * sent, u, y);
    }
    QTest::qWait(2);
  }
  const qint64 elapsed = clock.elapsed();
  const int redraws = plots.redrawCount() - before;
  QVERIFY2(redraws >= 3, qPrintable(QString::number(redraws)));
  QVERIFY2(redraws <= elapsed / 100 + 2, qPrintable(QStringLiteral("%1 redraws in %2 ms").arg(redraws).arg(elapsed)));
  QVERIFY(sent > 10 * redraws);
  plots.flush();
  QCOMPARE(plots.inputPoints(0).size(), sent);
  QCOMPARE(plots.outputPoints(0).last(), QPointF(1e-3 * (sent - 1), -(sent - 1)));
}

// the y axis grows with the data (and contains it), never shrinks while live;
// the t axis spans 0..t_end and extends past it when needed
void PlotsTest::liveAxesGrow() {
  ResultPlots plots;
  plots.resize(800, 500);
  plots.reset({"u"}, {"N"}, {"y"}, {"m"}, 2.0);
  auto* ay = qobject_cast<QValueAxis*>(plots.outputChart()->axes(Qt::Vertical).first());
  auto* at = qobject_cast<QValueAxis*>(plots.outputChart()->axes(Qt::Horizontal).first());
  QVERIFY(ay && at);
  QCOMPARE(at->min(), 0.0);
  QCOMPARE(at->max(), 2.0);
  QCOMPARE(at->titleText(), QStringLiteral("t [s]"));
  QCOMPARE(ay->titleText(), QStringLiteral("y [m]"));
  QCOMPARE(plots.outputChart()->series().first()->name(), QStringLiteral("y [m]"));

  Eigen::VectorXd u(1), y(1);
  u << 0.0;
  y << 0.3;
  plots.appendSample(0.0, u, y);
  y << 0.42;
  plots.appendSample(0.1, u, y);
  plots.flush();
  QVERIFY(ay->min() <= 0.3 && ay->max() >= 0.42);
  QVERIFY(ay->max() - ay->min() < 1.0);  // fitted to the data, not the default
  const double lo1 = ay->min(), hi1 = ay->max();
  y << 7.5;
  plots.appendSample(0.2, u, y);
  plots.flush();
  QVERIFY(ay->max() >= 7.5 && ay->max() < 10.01);
  QVERIFY(ay->min() <= lo1);
  y << 0.35;  // smaller again: the axis stays
  plots.appendSample(0.3, u, y);
  plots.flush();
  QVERIFY(ay->max() >= 7.5 && ay->min() <= lo1 && ay->max() >= hi1);
  y << 0.0;
  plots.appendSample(3.1, u, y);  // past t_end
  plots.flush();
  QVERIFY(at->max() >= 3.1);
}

void PlotsTest::resultTakesPlantInputs() {
  const codyna::SimulationResult r = makeResult(true);
  ResultPlots plots;
  plots.resize(900, 640);
  plots.show();
  QVERIFY(QTest::qWaitForWindowExposed(&plots));
  plots.setResult(r, {2, 0});
  QCOMPARE(plots.inputSeriesCount(), 2);
  QCOMPARE(plots.outputSeriesCount(), 2);
  const QList<QPointF> in0 = plots.inputPoints(0), in1 = plots.inputPoints(1);
  QCOMPARE(in0.size(), r.samples());
  QCOMPARE(in1.size(), r.samples());
  for (int i = 0; i < r.samples(); ++i) {
    QCOMPARE(in0[i], QPointF(r.t[i], r.u(i, 2)));  // plant input 0 = actuator 2
    QCOMPARE(in1[i], QPointF(r.t[i], r.u(i, 0)));
  }
  for (int k = 0; k < 2; ++k) {
    const QList<QPointF> out = plots.outputPoints(k), lin = plots.linearPoints(k);
    QCOMPARE(out.size(), r.samples());
    QCOMPARE(lin.size(), r.samples());
    for (int i = 0; i < r.samples(); ++i) {
      QCOMPARE(out[i], QPointF(r.t[i], r.y(i, k)));
      QCOMPARE(lin[i], QPointF(r.t[i], r.y_linear(i, k)));
    }
  }
  // names with units, linear entries, dashed pens in the same colour
  QStringList names;
  for (QAbstractSeries* s : plots.inputChart()->series())
    if (s->isVisible()) names << s->name();
  QVERIFY(names.contains("F_cart [N]"));
  QVERIFY(names.contains("tau_hinge [N m]"));
  QVERIFY(!names.join(' ').contains("spare"));
  QLineSeries* theta = nullptr;
  QLineSeries* thetaLin = nullptr;
  for (QAbstractSeries* s : plots.outputChart()->series()) {
    if (s->name() == "theta [rad]") theta = qobject_cast<QLineSeries*>(s);
    if (s->name() == "theta (linear) [rad]") thetaLin = qobject_cast<QLineSeries*>(s);
  }
  QVERIFY(theta && thetaLin);
  QCOMPARE(thetaLin->pen().color(), theta->pen().color());
  QVERIFY(thetaLin->pen().style() != Qt::SolidLine);
  QCOMPARE(theta->pen().style(), Qt::SolidLine);
  auto* at = qobject_cast<QValueAxis*>(plots.outputChart()->axes(Qt::Horizontal).first());
  QCOMPARE(at->min(), 0.0);
  QCOMPARE(at->max(), 10.0);
  // every plotted value inside the y axis range
  auto* ay = qobject_cast<QValueAxis*>(plots.inputChart()->axes(Qt::Vertical).first());
  for (const QPointF& p : in0 + in1) QVERIFY(p.y() >= ay->min() && p.y() <= ay->max());
  QVERIFY(ay->max() < 2.0 * r.u.col(2).cwiseAbs().maxCoeff());  // not absurdly padded

  QTest::qWait(50);
  QVERIFY(plots.saveImage(screenshot("plots_result.png")));
  // the two time axes line up (different y labels and legends notwithstanding)
  const QRectF a = plots.inputChart()->plotArea(), b = plots.outputChart()->plotArea();
  QVERIFY2(std::abs(a.left() - b.left()) < 1.5 && std::abs(a.right() - b.right()) < 1.5,
           qPrintable(QStringLiteral("%1..%2 vs %3..%4").arg(a.left()).arg(a.right()).arg(b.left()).arg(b.right())));
  plots.setTimeCursor(3.2);
  QVERIFY(plots.saveImage(screenshot("plots_result_cursor.png")));
}

void PlotsTest::resultWithoutLinear() {
  ResultPlots plots;
  plots.setResult(makeResult(true), {0});
  QCOMPARE(plots.linearPoints(0).size(), 501);
  const codyna::SimulationResult r = makeResult(false);
  plots.setResult(r, {0});
  QCOMPARE(plots.inputSeriesCount(), 1);
  QCOMPARE(plots.outputSeriesCount(), 2);
  QCOMPARE(plots.linearPoints(0).size(), 0);
  QCOMPARE(plots.linearPoints(1).size(), 0);
  for (QAbstractSeries* s : plots.outputChart()->series()) QVERIFY(!s->name().contains("linear"));
  QCOMPARE(plots.inputPoints(0)[7], QPointF(r.t[7], r.u(7, 0)));
  // a partial result with NaN rows and an index out of range
  codyna::SimulationResult p = makeResult(false, 11);
  p.y(5, 1) = std::numeric_limits<double>::quiet_NaN();
  plots.setResult(p, {2, 9});
  QCOMPARE(plots.inputSeriesCount(), 1);
  QCOMPARE(plots.outputPoints(1).size(), 10);
  QCOMPARE(plots.outputPoints(0).size(), 11);
}

void PlotsTest::decimationKeepsPeaks() {
  ResultPlots plots;
  plots.setMaxPlotPoints(400);
  plots.reset({"u"}, {}, {"y"}, {}, 10.0);
  for (int i = 0; i < 20000; ++i) {
    Eigen::VectorXd u(1), y(1);
    u << std::sin(0.01 * i);
    y << (i == 12345 ? 50.0 : i == 777 ? -20.0 : 0.0);
    plots.appendSample(5e-4 * i, u, y);
  }
  plots.flush();
  const QList<QPointF> y = plots.outputPoints(0);
  QVERIFY(y.size() <= 400);
  QVERIFY(y.contains(QPointF(5e-4 * 12345, 50.0)));
  QVERIFY(y.contains(QPointF(5e-4 * 777, -20.0)));
  QCOMPARE(y.first().x(), 0.0);
  QCOMPARE(y.last().x(), 5e-4 * 19999);
  for (int i = 1; i < y.size(); ++i) QVERIFY(y[i].x() > y[i - 1].x());
}

void PlotsTest::timeCursor() {
  ResultPlots plots;
  plots.setResult(makeResult(true, 101), {0, 2});
  const auto cursorSeries = [&](QChart* chart) -> QLineSeries* {
    for (QAbstractSeries* s : chart->series())
      if (auto* l = qobject_cast<QLineSeries*>(s); l && l->count() == 2 && l->at(0).x() == l->at(1).x()) return l;
    return nullptr;
  };
  plots.setTimeCursor(4.5);
  QLineSeries* c = cursorSeries(plots.outputChart());
  QVERIFY(c && c->isVisible());
  QCOMPARE(c->at(0).x(), 4.5);
  QCOMPARE(plots.inputSeriesCount(), 2);
  QVERIFY(cursorSeries(plots.inputChart())->isVisible());
  for (QLegendMarker* m : plots.outputChart()->legend()->markers(c)) QVERIFY(!m->isVisible());
  plots.setTimeCursor(std::numeric_limits<double>::quiet_NaN());
  QVERIFY(!c->isVisible());
}

void PlotsTest::saveImages() {
  ResultPlots plots;
  plots.resize(820, 560);
  plots.show();
  QVERIFY(QTest::qWaitForWindowExposed(&plots));
  plots.setResult(makeResult(true), {2, 0});
  QTemporaryDir dir;
  QVERIFY(dir.isValid());
  const QString png = dir.filePath("plots.png"), svg = dir.filePath("plots.svg");
  QString error;
  QVERIFY2(plots.saveImage(png, &error), qPrintable(error));
  QImage image(png);
  QVERIFY(!image.isNull());
  QCOMPARE(image.size(), plots.size() * plots.devicePixelRatio());
  const PixelStats s = stats(image);
  QVERIFY2(s.distinct > 50, qPrintable(QString::number(s.distinct)));
  QVERIFY2(s.non_white > 0.02 && s.non_white < 0.6, qPrintable(QString::number(s.non_white)));
  QVERIFY(countNear(image, QColor(0x1f, 0x77, 0xb4)) > 200);  // the first series' colour is drawn
  QVERIFY(countNear(image, QColor(0xd6, 0x27, 0x28)) > 200);

  QVERIFY2(plots.saveImage(svg, &error), qPrintable(error));
  QFile f(svg);
  QVERIFY(f.open(QIODevice::ReadOnly));
  const QByteArray text = f.readAll();
  QVERIFY(text.contains("<svg"));
  QVERIFY(text.contains("<path") || text.contains("<polyline"));
  QVERIFY(text.contains("Plant/Out"));
  // and it draws the plots: rendered back, it is not blank and has both series colours
  QSvgRenderer renderer(svg);
  QVERIFY(renderer.isValid());
  QImage back(plots.size(), QImage::Format_RGB32);
  back.fill(Qt::white);
  {
    QPainter painter(&back);
    renderer.render(&painter);
  }
  back.save(screenshot("plots_svg_rendered.png"));
  QVERIFY(stats(back).non_white > 0.02);
  QVERIFY(countNear(back, QColor(0x1f, 0x77, 0xb4)) > 200);
  QVERIFY(countNear(back, QColor(0xd6, 0x27, 0x28)) > 200);

  error.clear();
  QVERIFY(!plots.saveImage(dir.filePath("no/such/dir/plots.png"), &error));
  QVERIFY(!error.isEmpty());
  error.clear();
  QVERIFY(!plots.saveImage(dir.filePath("no/such/dir/plots.svg"), &error));
  QVERIFY(!error.isEmpty());
  error.clear();
  QVERIFY(!plots.saveImage(dir.filePath("plots.bmpx"), &error));
  QVERIFY(error.contains("png"));
  QVERIFY(!plots.saveImage(dir.filePath("x.png").prepend("/proc/")));  // no error pointer: no crash
}

// The pole map draws each pole as the core classifies it (analysis/stability.hpp): poles at
// Re = -1e-12, 0, +1e-12 and a pair on the imaginary axis marginal, -1e-6 stable, +1e-6 unstable
// (continuous); on, inside and outside the unit circle when sampled
void PlotsTest::poleMapDrawsTheCoresStability() {
  for (const bool sampled : {false, true}) {
    codyna::LinearSystem sys;
    const double th = 0.7;
    // blocks: real poles on the diagonal, a pair as [a b; -b a]
    const std::vector<std::complex<double>> poles =
        sampled ? std::vector<std::complex<double>>{{1 - 1e-12, 0}, {1, 0}, {1 + 1e-12, 0}, {0.5, 0}, {1.5, 0},
                                                    {std::cos(th), std::sin(th)}, {0.5 * std::cos(th), 0.5 * std::sin(th)}}
                : std::vector<std::complex<double>>{{-1e-12, 0}, {0, 0}, {1e-12, 0}, {-1e-6, 0}, {1e-6, 0}, {0, 2}, {-0.2, 3}};
    const int n = static_cast<int>(poles.size()) + 2;
    sys.A = Eigen::MatrixXd::Zero(n, n);
    int k = 0;
    for (const auto& p : poles) {
      if (p.imag() != 0) {
        sys.A.block<2, 2>(k, k) << p.real(), p.imag(), -p.imag(), p.real();
        k += 2;
      } else {
        sys.A(k, k) = p.real();
        ++k;
      }
    }
    sys.Ts = sampled ? 0.01 : 0.0;
    sys.B = Eigen::MatrixXd::Zero(n, 0);
    sys.C = Eigen::MatrixXd::Zero(0, n);
    sys.D = Eigen::MatrixXd::Zero(0, 0);
    const codyna::ModalAnalysis modal = codyna::modal_analysis(sys);
    PoleMap map;
    map.resize(400, 300);
    map.setModes(modal);
    // 3 marginal reals and a marginal pair; stable: -1e-6 (0.5) and the pair -0.2 +- 3i (inside);
    // unstable: +1e-6 (1.5)
    QCOMPARE(map.drawnMarginal(), 5);
    QCOMPARE(map.drawnStable(), sampled ? 3 : 3);
    QCOMPARE(map.drawnUnstable(), 1);
    // the same as the core's own count of the same poles
    const double tol = codyna::stability_tolerance(sys.A);
    int unstable = 0;
    for (const auto& m : modal.modes) unstable += codyna::classify_pole(m.eigenvalue, sampled, tol) == codyna::Stability::Unstable;
    QCOMPARE(map.drawnUnstable(), unstable);
  }
}

void PlotsTest::poleMapContinuous() {
  const codyna::ModalAnalysis modal = codyna::modal_analysis(oscillator());
  QCOMPARE(static_cast<int>(modal.modes.size()), 2);
  PoleMap map;
  map.resize(560, 480);
  map.show();
  QVERIFY(QTest::qWaitForWindowExposed(&map));
  map.setModes(modal);
  QTest::qWait(50);
  QCOMPARE(map.poleCount(), 2);
  QVERIFY(!map.isDiscrete());
  QCOMPARE(map.selectedMode(), -1);
  for (int i = 0; i < 2; ++i) {
    QVERIFY(std::abs(map.polePosition(i).x() - modal.modes[i].eigenvalue.real()) <= 1e-12);
    QVERIFY(std::abs(map.polePosition(i).y() - modal.modes[i].eigenvalue.imag()) <= 1e-12);
    QVERIFY(std::abs(map.polePosition(i).x() + 0.2) < 1e-12);
    QVERIFY(std::abs(std::abs(map.polePosition(i).y()) - std::sqrt(4.0 - 0.04)) < 1e-12);
  }
  // drawn where the widget says: both inside the widget, the upper one (Im > 0) higher
  const QPoint p0 = map.poleWidgetPosition(0), p1 = map.poleWidgetPosition(1);
  QVERIFY(map.rect().contains(p0) && map.rect().contains(p1));
  QVERIFY(std::abs(p0.x() - p1.x()) <= 1);
  QVERIFY((map.polePosition(0).y() > 0) == (p0.y() < p1.y()));
  QVERIFY(std::abs(p0.y() - p1.y()) > 100);

  QSignalSpy spy(&map, &PoleMap::modeSelected);
  clickPole(map, 1);
  QCOMPARE(spy.count(), 1);
  QCOMPARE(spy.at(0).at(0).toInt(), 1);
  QCOMPARE(map.selectedMode(), 1);
  clickPole(map, 0);
  QCOMPARE(spy.count(), 2);
  QCOMPARE(spy.at(1).at(0).toInt(), 0);
  QCOMPARE(map.selectedMode(), 0);
  // a click on the PoleMap widget itself works too; a click on nothing changes nothing
  QTest::mouseClick(&map, Qt::LeftButton, Qt::NoModifier, map.poleWidgetPosition(1));
  QCOMPARE(spy.count(), 3);
  QCOMPARE(spy.at(2).at(0).toInt(), 1);
  QTest::mouseClick(map.childAt(QPoint(p0.x() + 120, (p0.y() + p1.y()) / 2)), Qt::LeftButton, Qt::NoModifier,
                    map.childAt(QPoint(p0.x() + 120, (p0.y() + p1.y()) / 2))
                        ->mapFrom(&map, QPoint(p0.x() + 120, (p0.y() + p1.y()) / 2)));
  QCOMPARE(spy.count(), 3);
  map.selectMode(-1);
  QCOMPARE(map.selectedMode(), -1);
  map.selectMode(7);
  QCOMPARE(map.selectedMode(), -1);
  QCOMPARE(spy.count(), 3);  // selectMode does not emit

  // a larger system with a stable real pole and an unstable one; select one for the picture
  const codyna::ModalAnalysis four = codyna::modal_analysis(fourStates());
  map.setModes(four);
  QCOMPARE(map.poleCount(), 4);
  for (int i = 0; i < 4; ++i)
    QCOMPARE(map.polePosition(i), QPointF(four.modes[i].eigenvalue.real(), four.modes[i].eigenvalue.imag()));
  map.selectMode(2);
  QTest::qWait(50);
  QVERIFY(map.saveImage(screenshot("pole_map_continuous.png")));
  const QImage img(screenshot("pole_map_continuous.png"));
  QCOMPARE(img.size(), map.size() * map.devicePixelRatio());
  QVERIFY(countNear(img, QColor(0xd6, 0x27, 0x28)) > 5);  // the unstable pole
  QVERIFY(countNear(img, QColor(0x1f, 0x77, 0xb4)) > 15);  // stable ones
  QTemporaryDir dir;
  QVERIFY(map.saveImage(dir.filePath("poles.svg")));
  QString error;
  QVERIFY(!map.saveImage(dir.filePath("none/poles.png"), &error));
  QVERIFY(!error.isEmpty());
}

void PlotsTest::poleMapDiscrete() {
  const codyna::LinearSystem d = codyna::discretize_zoh(oscillator(), 0.25);
  const codyna::ModalAnalysis modal = codyna::modal_analysis(d);
  QVERIFY(modal.Ts > 0);
  PoleMap map;
  map.resize(520, 480);
  map.show();
  QVERIFY(QTest::qWaitForWindowExposed(&map));
  map.setModes(modal);
  QTest::qWait(50);
  QVERIFY(map.isDiscrete());
  QCOMPARE(map.poleCount(), 2);
  for (int i = 0; i < 2; ++i) {
    const std::complex<double> z = modal.modes[i].eigenvalue;
    QVERIFY(std::abs(map.polePosition(i).x() - z.real()) <= 1e-12);
    QVERIFY(std::abs(map.polePosition(i).y() - z.imag()) <= 1e-12);
    // z = exp(lambda Ts): inside the unit circle, not the s-plane value
    const std::complex<double> expected = std::exp(std::complex<double>(-0.2, z.imag() > 0 ? 1.98997487421 : -1.98997487421) * 0.25);
    QVERIFY(std::abs(z - expected) < 1e-9);
    QVERIFY(std::hypot(map.polePosition(i).x(), map.polePosition(i).y()) < 1.0);
  }
  // the unit circle is drawn (a series through (1,0), (0,1), (-1,0)) and round: equal scales
  QLineSeries* circle = nullptr;
  for (QAbstractSeries* s : map.chart()->series())
    if (s->name() == "unit circle") circle = qobject_cast<QLineSeries*>(s);
  QVERIFY(circle && circle->isVisible() && circle->count() > 100);
  const QPointF c0 = map.chart()->mapToPosition(QPointF(1, 0), circle) - map.chart()->mapToPosition(QPointF(0, 0), circle);
  const QPointF c1 = map.chart()->mapToPosition(QPointF(0, 1), circle) - map.chart()->mapToPosition(QPointF(0, 0), circle);
  QVERIFY2(std::abs(c0.x() + c1.y()) < 2.0, qPrintable(QStringLiteral("%1 vs %2").arg(c0.x()).arg(-c1.y())));

  QSignalSpy spy(&map, &PoleMap::modeSelected);
  clickPole(map, 0);
  QCOMPARE(spy.count(), 1);
  QCOMPARE(spy.at(0).at(0).toInt(), 0);
  QVERIFY(map.saveImage(screenshot("pole_map_discrete.png")));

  // back to continuous: no circle
  map.setModes(codyna::modal_analysis(oscillator()));
  QVERIFY(!map.isDiscrete());
  QVERIFY(!circle->isVisible());
}

void PlotsTest::matrixModel() {
  MatrixTableModel model;
  QCOMPARE(model.rowCount(), 0);
  Eigen::MatrixXd B(3, 2);
  B << 1.0 / 3.0, 0, -2.5e-7, 12345678.9, 4, 1e300;
  model.setMatrix(B, {"theta", "theta_dot", "x"}, {"tau", "F"}, {"rad", "rad/s", "m"}, {"N m", "N"});
  QCOMPARE(model.rowCount(), 3);
  QCOMPARE(model.columnCount(), 2);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 2; ++c) QCOMPARE(model.data(model.index(r, c), Qt::UserRole).toDouble(), B(r, c));
  QCOMPARE(model.data(model.index(0, 0)).toString(), QStringLiteral("0.333333"));
  QCOMPARE(model.data(model.index(1, 1)).toString(), QStringLiteral("1.23457e+07"));
  QCOMPARE(model.data(model.index(1, 0)).toString(), QStringLiteral("-2.5e-07"));
  QVERIFY(model.data(model.index(0, 0), Qt::ToolTipRole).toString().contains("0.33333333333333331"));
  QCOMPARE(model.headerData(0, Qt::Vertical).toString(), QStringLiteral("theta"));
  QCOMPARE(model.headerData(2, Qt::Vertical).toString(), QStringLiteral("x"));
  QCOMPARE(model.headerData(1, Qt::Horizontal).toString(), QStringLiteral("F"));
  QCOMPARE(model.headerData(1, Qt::Vertical, Qt::ToolTipRole).toString(), QStringLiteral("theta_dot [rad/s]"));
  QCOMPARE(model.headerData(0, Qt::Horizontal, Qt::ToolTipRole).toString(), QStringLiteral("tau [N m]"));
  QVERIFY(!model.headerData(5, Qt::Horizontal).isValid());
  QVERIFY(!model.data(model.index(3, 0)).isValid());
  // missing names: 1-based indices
  model.setMatrix(Eigen::MatrixXd::Identity(2, 3), {"a"}, {});
  QCOMPARE(model.columnCount(), 3);
  QCOMPARE(model.headerData(1, Qt::Vertical).toString(), QStringLiteral("2"));
  QCOMPARE(model.headerData(2, Qt::Horizontal).toString(), QStringLiteral("3"));
  QCOMPARE(model.headerData(0, Qt::Vertical, Qt::ToolTipRole).toString(), QStringLiteral("a"));
}

void PlotsTest::modeModel() {
  const codyna::ModalAnalysis modal = codyna::modal_analysis(fourStates());
  ModeTableModel model;
  model.setModes(modal);
  QCOMPARE(model.rowCount(), 4);
  QCOMPARE(model.columnCount(), 6);
  QCOMPARE(model.headerData(ModeTableModel::NaturalFrequency, Qt::Horizontal).toString(), QStringLiteral("\u03c9n [rad/s]"));
  QVERIFY(model.headerData(ModeTableModel::FrequencyHz, Qt::Horizontal).toString().contains("[Hz]"));
  QVERIFY(model.headerData(ModeTableModel::DominantStates, Qt::Horizontal).toString().contains("states"));
  for (int i = 0; i < 4; ++i) {
    const codyna::Mode& m = modal.modes[i];
    QCOMPARE(model.data(model.index(i, 0), Qt::UserRole).toInt(), i);
    QCOMPARE(model.data(model.index(i, ModeTableModel::NaturalFrequency), Qt::UserRole).toDouble(), m.natural_frequency);
    QCOMPARE(model.data(model.index(i, ModeTableModel::FrequencyHz), Qt::UserRole).toDouble(),
             m.natural_frequency / (2 * std::numbers::pi));
    QCOMPARE(model.data(model.index(i, ModeTableModel::DampingRatio), Qt::UserRole).toDouble(), m.damping_ratio);
    QCOMPARE(model.headerData(i, Qt::Vertical).toInt(), i + 1);
  }
  // the modes, sorted by natural frequency: -0.5, 0.8, -0.2 +/- 1.487j
  QCOMPARE(model.data(model.index(0, 0)).toString(), QStringLiteral("-0.5"));
  QCOMPARE(model.data(model.index(1, 0)).toString(), QStringLiteral("0.8"));
  QCOMPARE(model.data(model.index(2, 0)).toString(), QStringLiteral("-0.2 - 1.48661j"));
  QCOMPARE(model.data(model.index(3, 0)).toString(), QStringLiteral("-0.2 + 1.48661j"));
  QCOMPARE(model.data(model.index(0, ModeTableModel::TimeConstant), Qt::UserRole).toDouble(), 2.0);
  QVERIFY(model.data(model.index(0, ModeTableModel::TimeConstant)).toString().contains("2"));
  QVERIFY(std::abs(model.data(model.index(3, ModeTableModel::TimeConstant), Qt::UserRole).toDouble() -
                   2 * std::numbers::pi / std::sqrt(2.21)) < 1e-9);
  QVERIFY(model.data(model.index(3, ModeTableModel::TimeConstant)).toString().startsWith("T = "));
  QCOMPARE(model.data(model.index(1, ModeTableModel::DampingRatio)).toString(), QStringLiteral("-1"));
  QVERIFY(model.data(model.index(1, 0), Qt::ForegroundRole).isValid());   // unstable: red
  QVERIFY(!model.data(model.index(0, 0), Qt::ForegroundRole).isValid());
  // dominant states: the unstable mode is phi alone; the oscillation theta and theta_dot, largest first
  QCOMPARE(model.data(model.index(1, ModeTableModel::DominantStates), Qt::UserRole).toStringList(), QStringList{"phi"});
  QCOMPARE(model.data(model.index(1, ModeTableModel::DominantStates)).toString(), QStringLiteral("phi (1.00)"));
  const QStringList osc = model.data(model.index(3, ModeTableModel::DominantStates), Qt::UserRole).toStringList();
  QCOMPARE(osc, (QStringList{"theta_dot", "theta"}));  // |theta_dot| = 1.5 |theta|
  QVERIFY(model.data(model.index(3, ModeTableModel::DominantStates)).toString().startsWith("theta_dot (1.00), theta (0.67)"));
  // discrete: z in the eigenvalue column, s in its tooltip
  const codyna::ModalAnalysis dm = codyna::modal_analysis(codyna::discretize_zoh(oscillator(), 0.1));
  model.setModes(dm);
  QCOMPARE(model.rowCount(), 2);
  QCOMPARE(model.headerData(0, Qt::Horizontal).toString(), QStringLiteral("Eigenvalue z"));
  QCOMPARE(model.data(model.index(0, 0)).toString(), ModeTableModel::complexText(dm.modes[0].eigenvalue));
  QVERIFY(model.data(model.index(0, 0), Qt::ToolTipRole).toString().contains("s = ln(z)/Ts = -0.2"));
  model.clear();
  QCOMPARE(model.rowCount(), 0);
}

// The wheel zooms a chart out and in a few hundred notches: the dynamic ticks follow
// the range (at most 50 labels at any time; a fixed interval made 1.25^k labels, and
// the monkey test ran out of memory on it), the zoom stops at 1e12 wide and at nine
// digits, and a reset brings the first range back.
void PlotsTest::zoomKeepsTicksBounded() {
  auto* chart = new QChart;
  chart->setAnimationOptions(QChart::NoAnimation);
  auto* s = new QLineSeries;
  for (int i = 0; i <= 100; ++i) s->append(0.1 * i, std::sin(0.1 * i));
  chart->addSeries(s);
  auto* x = new QValueAxis;
  auto* y = new QValueAxis;
  for (QValueAxis* a : {x, y}) {
    a->setTickType(QValueAxis::TicksDynamic);
    a->setTickAnchor(0.0);
  }
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  s->attachAxis(x);
  s->attachAxis(y);
  codyna::gui::setAxisRange(x, 0, 10, 1);
  codyna::gui::setAxisRange(y, -1, 1, 0.5);
  codyna::gui::ChartView view(chart);
  view.resize(600, 400);
  view.show();
  QVERIFY(QTest::qWaitForWindowExposed(&view));
  const auto ticks = [](QValueAxis* a) { return (a->max() - a->min()) / a->tickInterval(); };
  const auto wheel = [&](int delta) {
    const QPointF at(300, 200);
    QWheelEvent e(at, view.mapToGlobal(at), QPoint(), QPoint(0, delta), Qt::NoButton, Qt::NoModifier,
                  Qt::NoScrollPhase, false);
    QApplication::sendEvent(view.viewport(), &e);
  };
  // a click that is no drag leaves the ticks as the plot set them
  QTest::mouseClick(view.viewport(), Qt::LeftButton, {}, QPoint(300, 200));
  QCOMPARE(x->tickInterval(), 1.0);
  for (int k = 0; k < 300; ++k) {
    wheel(-120);
    for (QValueAxis* a : {x, y}) {
      QVERIFY2(std::isfinite(a->min()) && std::isfinite(a->max()), qPrintable(QString("notch %1").arg(k)));
      QVERIFY2(ticks(a) <= 50 && ticks(a) >= 1, qPrintable(QString("notch %1: %2 ticks").arg(k).arg(ticks(a))));
    }
  }
  QVERIFY(view.isZoomed());
  QVERIFY(x->max() - x->min() > 1e11 && x->max() - x->min() < 1e13);  // stopped at 1e12, not before
  view.resetZoom();
  QVERIFY(std::abs(x->min()) < 1e-12 && std::abs(x->max() - 10) < 1e-12);
  QVERIFY(ticks(x) <= 50 && ticks(x) >= 1);
  for (int k = 0; k < 300; ++k) {
    wheel(120);
    for (QValueAxis* a : {x, y}) QVERIFY(ticks(a) <= 50 && ticks(a) >= 1);
  }
  const double w = x->max() - x->min(), size = std::max(std::abs(x->min()), std::abs(x->max()));
  QVERIFY2(w > 1e-10 * size && w < 1e-8 * size, qPrintable(QString("width %1 at %2").arg(w).arg(size)));
  view.resetZoom();
  QVERIFY(!view.isZoomed());
  QVERIFY(ticks(x) <= 50 && ticks(x) >= 1);
}

// A chart saved at a size that is not the one on screen: the PNG has exactly that many
// pixels, with the curve drawn across it (not the screen's picture scaled), the SVG
// that size; the view on screen keeps its layout; a bad size or suffix writes nothing.
void PlotsTest::chartImageAtChosenSize() {
  auto* chart = new QChart;
  chart->setAnimationOptions(QChart::NoAnimation);
  chart->setTitle("Step on force");
  auto* s = new QLineSeries;
  s->setName("x");
  QPen pen(QColor(255, 0, 0));
  pen.setWidth(3);
  s->setPen(pen);
  for (int i = 0; i <= 100; ++i) s->append(0.1 * i, std::sin(0.3 * i));
  chart->addSeries(s);
  chart->createDefaultAxes();
  codyna::gui::ChartView view(chart);
  view.resize(500, 300);
  view.show();
  QVERIFY(QTest::qWaitForWindowExposed(&view));
  QTest::qWait(20);
  const QRectF area = chart->plotArea();
  QTemporaryDir dir;
  QString why;
  const QString png = dir.filePath("step.png");
  QVERIFY2(view.saveImage(png, QSize(1300, 520), &why), qPrintable(why));
  QImage img(png);
  QCOMPARE(img.size(), QSize(1300, 520));
  // the red curve reaches far to the right and into the lower part of the large picture
  int rightmost = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const QColor c = img.pixelColor(x, y);
      if (c.red() > 200 && c.green() < 80 && c.blue() < 80) rightmost = std::max(rightmost, x);
    }
  QVERIFY2(rightmost > 1100, qPrintable(QString::number(rightmost)));
  QCOMPARE(chart->plotArea(), area);  // the screen's layout is back
  const QString svg = dir.filePath("step.svg");
  QVERIFY2(view.saveImage(svg, QSize(800, 400), &why), qPrintable(why));
  QCOMPARE(QSvgRenderer(svg).viewBoxF(), QRectF(0, 0, 800, 400));
  QVERIFY(!view.saveImage(dir.filePath("bad.png"), QSize(5, 400), &why));
  QVERIFY(why.contains("16 to 10000"));
  QVERIFY(!QFile::exists(dir.filePath("bad.png")));
  QVERIFY(!view.saveImage(dir.filePath("bad.jpg"), QSize(400, 400), &why));
  QVERIFY(why.contains(".png or .svg"));
  // through the dialog, as the context menu opens it
  const QString viaDialog = dir.filePath("dialog.png");
  QTimer::singleShot(0, [&] {
    auto* d = QApplication::activeModalWidget();
    QVERIFY(d);
    d->findChild<QLineEdit*>("imagePath")->setText(viaDialog);
    d->findChild<QSpinBox*>("imageWidth")->setValue(640);
    d->findChild<QSpinBox*>("imageHeight")->setValue(480);
    QTest::keyClick(d->findChild<QLineEdit*>("imagePath"), Qt::Key_Return);
  });
  QCOMPARE(view.saveImageInteractive(), viaDialog);
  QCOMPARE(QImage(viaDialog).size(), QSize(640, 480));
}

// The references r(t) a run recorded are drawn dotted over the outputs (every sample, same
// numbers) with "(reference)" in the legend; the picker offers r, d and the linear outputs
// by name and reads them from the right columns.
void PlotsTest::referencesAndDisturbancesDrawn() {
  codyna::SimulationResult r = makeResult(true, 101);
  const int n = r.samples();
  r.y_reference.resize(n, 2);
  r.u_disturbance = Eigen::MatrixXd::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    r.y_reference(i, 0) = 0.0;
    r.y_reference(i, 1) = r.t[i] < 2.0 ? 0.0 : 0.8;
    if (r.t[i] >= 3.0) r.u_disturbance(i, 1) = -2.5;
  }
  ResultPlots plots;
  plots.setResult(r, {0, 2});
  for (int k = 0; k < 2; ++k) {
    const QList<QPointF> p = plots.referencePoints(k);
    QCOMPARE(p.size(), n);
    for (int i = 0; i < n; i += 9) QCOMPARE(p[i], QPointF(r.t[i], r.y_reference(i, k)));
  }
  int named = 0;
  for (QAbstractSeries* s : plots.outputChart()->series()) named += s->name().contains("(reference)");
  QCOMPARE(named, 2);
  // a result without references: none drawn
  plots.setResult(makeResult(false), {0});
  QCOMPARE(plots.referencePoints(1).size(), 0);

  const QStringList names = codyna::gui::SignalPlot::signalNames(r);
  for (const char* want : {"r: x_cart [m]", "d: spare [-]", "y: theta (linear) [rad]", "y: x_cart [m]", "F_cart [N]"})
    QVERIFY2(names.contains(want), qPrintable(names.join(" | ")));
  const auto check = [&](const QString& name, const Eigen::MatrixXd& m, int col) {
    const std::vector<double> v = codyna::gui::SignalPlot::signal(r, name);
    QCOMPARE(int(v.size()), n);
    for (int i = 0; i < n; ++i) QCOMPARE(v[i], m(i, col));
  };
  check("r: x_cart [m]", r.y_reference, 1);
  check("d: spare [-]", r.u_disturbance, 1);
  check("y: theta (linear) [rad]", r.y_linear, 0);
  check("y: x_cart [m]", r.y, 1);
  check("F_cart [N]", r.u, 2);
  QVERIFY(codyna::gui::SignalPlot::signal(r, "no such signal").empty());
}

QTEST_MAIN(PlotsTest)
#include "plots_test.moc"
