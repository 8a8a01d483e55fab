// The Control view (Bode, step, gain K, closed-loop poles), offscreen, checked
// against computations of its own: the Bode points against C (jwI - A)^-1 B + D
// of the matrices `codyna linearize` exports, the step curves against an RK4
// integration of the closed loop's matrices at a step far below the plot's.
#include <QComboBox>
#include <QDir>
#include <QLabel>
#include <QMessageBox>
#include <QProcess>
#include <QLineEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalSpy>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QValueAxis>
#include <QUndoStack>
#include <Eigen/LU>
#include <cmath>
#include <complex>
#include <numbers>

#include "drive.hpp"
#include "gui/chart_view.hpp"
#include "gui/pole_map.hpp"
#include "gui/control_view.hpp"
#include "gui/main_window.hpp"
#include "gui/matrix_models.hpp"
#include "control/lqr.hpp"
#include "io/mat_export.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {
const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");
}  // namespace

class ControlViewTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

 private slots:
  void init() {
    w = drive::window("control_view_test");
    QVERIFY(w);
    QVERIFY(w->openFile(kCart));
  }
  void cleanup() { drive::close(w); }

  // the nonlinear plant's frequency response over the linear Bode plot, as a person asks for it:
  // the amplitude and frequencies typed, Enter; at a small force the points lie on the linear
  // model's curve (the test's own C (jwI - A)^-1 B + D: gain to 1e-4, phase to 0.01 rad, on the
  // curve's branch), at a large one the gap grows and the line under the plot says where; bad
  // fields are named, and Cancel stops a long estimate with nothing drawn
  void nonlinearPlantOverTheLinearBode() {
    ControlView* cv = w->controlView();
    w->analysisTabs()->setCurrentWidget(cv);
    QTRY_VERIFY(cv->amplitudeEdit()->isVisible());
    QSignalSpy done(cv, &ControlView::estimateFinished);
    auto type = [](QLineEdit* e, const QString& text) {
      e->setFocus();
      e->selectAll();
      QTest::keyClick(e, Qt::Key_Delete);
      QTest::keyClicks(e, text);
    };
    type(cv->amplitudeEdit(), "0.01");
    type(cv->frequenciesEdit(), "1:10:5");
    QTest::keyClick(cv->frequenciesEdit(), Qt::Key_Return);  // analyses first: nothing was
    QVERIFY(cv->isEstimating());
    QVERIFY(!cv->estimateButton()->isEnabled());
    QVERIFY(cv->cancelEstimateButton()->isEnabled());
    QVERIFY(done.wait(60000));
    QVERIFY2(cv->freqResp(), qPrintable(cv->freqStatusLabel()->text()));
    QCOMPARE(cv->systemCombo()->currentIndex(), int(ControlView::Plant));
    const LinearSystem& s = *cv->system(ControlView::Plant);
    const FreqRespJob& job = *cv->freqResp();
    QCOMPARE(int(job.points.size()), 5);
    for (const char* out : {"h", "theta"}) {
      cv->inputCombo()->setCurrentText("force");
      cv->outputCombo()->setCurrentText(out);
      const int i = cv->outputCombo()->currentIndex(), j = cv->inputCombo()->currentIndex();
      const QList<QPointF> mag = cv->nonlinearMagnitudePoints(), phase = cv->nonlinearPhasePoints();
      const QList<QPointF> line = cv->phasePoints();
      QCOMPARE(mag.size(), 5);
      QCOMPARE(phase.size(), 5);
      for (int k = 0; k < 5; ++k) {
        const double wk = std::pow(10.0, k / 4.0);
        QVERIFY(std::abs(mag[k].x() - wk) < 1e-12 * wk);
        const Eigen::MatrixXcd Z = std::complex<double>(0, wk) * Eigen::MatrixXcd::Identity(s.nx(), s.nx()) - s.A.cast<std::complex<double>>();
        const std::complex<double> h = (s.C.cast<std::complex<double>>() * Z.partialPivLu().solve(s.B.cast<std::complex<double>>()))(i, j) + s.D(i, j);
        const double gain = std::pow(10.0, mag[k].y() / 20);
        QVERIFY2(std::abs(gain - std::abs(h)) <= 1e-4 * std::abs(h),
                 qPrintable(QString("%1 at %2 rad/s: gain %3, linear %4").arg(out).arg(wk).arg(gain).arg(std::abs(h))));
        const double dphi = std::remainder(phase[k].y() * std::numbers::pi / 180 - std::arg(h), 2 * std::numbers::pi);
        QVERIFY2(std::abs(dphi) <= 0.01, qPrintable(QString("%1 at %2 rad/s: phase off by %3 rad").arg(out).arg(wk).arg(dphi)));
        // on the drawn curve's branch: within a degree of the line between its neighbours
        int n = 1;
        while (n + 1 < line.size() && line[n].x() < wk) ++n;
        const double a = std::log(wk / line[n - 1].x()) / std::log(line[n].x() / line[n - 1].x());
        const double on_line = line[n - 1].y() + a * (line[n].y() - line[n - 1].y());
        QVERIFY2(std::abs(phase[k].y() - on_line) < 1, qPrintable(QString("%1 at %2 rad/s: %3 deg, the curve %4").arg(out).arg(wk).arg(phase[k].y()).arg(on_line)));
      }
      // the closed loop's curves are not the plant's: no points there
      cv->systemCombo()->setCurrentIndex(ControlView::ClosedLoop);
      QCOMPARE(cv->nonlinearMagnitudePoints().size(), 0);
      cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    }
    QVERIFY2(job.largest_gap < 1e-4, qPrintable(QString::number(job.largest_gap)));
    QVERIFY2(cv->freqStatusLabel()->text().contains("largest gap"), qPrintable(cv->freqStatusLabel()->text()));

    // 200 N: the pendulum swings far, the gap grows (to several per cent) and is said with its pair
    type(cv->amplitudeEdit(), "200");
    QTest::mouseClick(cv->estimateButton(), Qt::LeftButton);
    QVERIFY(done.wait(60000));
    QVERIFY(cv->freqResp());
    const FreqRespJob& big = *cv->freqResp();
    QVERIFY2(big.largest_gap > 0.02, qPrintable(QString::number(big.largest_gap)));
    const QString where = QString("%1 %").arg(100 * big.largest_gap, 0, 'g', 3);
    const QString label = cv->freqStatusLabel()->text();
    QVERIFY2(label.contains(where) && label.contains(QString::fromStdString(big.output_names[big.gap_output] + "/" + big.input_names[big.gap_input])),
             qPrintable(label));
    QCOMPARE(big.amplitudes[0], 200.0);

    // bad fields: named, red, nothing started, the last estimate stays
    for (auto [edit, text, name] : {std::tuple{cv->amplitudeEdit(), QString("-1"), QString("amplitude")},
                                    std::tuple{cv->frequenciesEdit(), QString("abc"), QString("frequencies")}}) {
      const QString keep = edit->text();
      type(edit, text);
      QTest::keyClick(edit, Qt::Key_Return);
      QVERIFY(!cv->isEstimating());
      QVERIFY2(cv->freqStatusLabel()->text().contains(name), qPrintable(cv->freqStatusLabel()->text()));
      QVERIFY(cv->freqStatusLabel()->styleSheet().contains("b00000"));
      QVERIFY(cv->freqResp());
      type(edit, keep);
    }

    // Cancel: a long estimate (400 frequencies) stops, nothing drawn
    done.clear();
    type(cv->frequenciesEdit(), "0.5:60:400");
    QTest::mouseClick(cv->estimateButton(), Qt::LeftButton);
    QVERIFY(cv->isEstimating());
    QTest::mouseClick(cv->cancelEstimateButton(), Qt::LeftButton);
    QVERIFY(done.wait(60000));
    QVERIFY(!cv->freqResp());
    QCOMPARE(cv->freqStatusLabel()->text(), QString("Cancelled"));
    QCOMPARE(cv->nonlinearMagnitudePoints().size(), 0);
    QVERIFY(cv->estimateButton()->isEnabled());
  }

  // the charts zoom by a dragged rectangle and back by a double click, read the value under the pointer,
  // and copy their curves as CSV
  void chartsZoomReadAndCopy() {
    ControlView* cv = w->controlView();
    w->analysisTabs()->setCurrentWidget(cv);
    QVERIFY(cv->analyse());
    cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    auto* view = cv->findChild<ChartView*>("bodeMagnitude");
    QVERIFY(view);
    QTRY_VERIFY(view->isVisible() && view->chart()->plotArea().width() > 50);
    const QRectF area = view->chart()->plotArea();
    const QPoint a = view->mapFromScene(view->chart()->mapToScene(area.center() - QPointF(area.width() / 4, area.height() / 4)));
    const QPoint b = view->mapFromScene(view->chart()->mapToScene(area.center() + QPointF(area.width() / 4, area.height() / 4)));
    QVERIFY(!view->isZoomed());
    QTest::mouseMove(view->viewport(), a);
    QVERIFY2(view->readout().startsWith("x = "), qPrintable(view->readout()));
    QTest::mousePress(view->viewport(), Qt::LeftButton, {}, a);
    QTest::mouseMove(view->viewport(), b);
    QTest::mouseRelease(view->viewport(), Qt::LeftButton, {}, b);
    QVERIFY(view->isZoomed());
    QTest::mouseDClick(view->viewport(), Qt::LeftButton, {}, a);
    QVERIFY(!view->isZoomed());
    const QStringList csv = view->dataCsv().trimmed().split('\n');
    const QList<QPointF> mag = cv->magnitudePoints();
    QCOMPARE(csv.size(), int(mag.size()) + 1);
    const QStringList row = csv[5].split(',');
    QCOMPARE(row.size(), 2);
    QCOMPARE(row[0].toDouble(), mag[4].x());
    QCOMPARE(row[1].toDouble(), mag[4].y());
  }

  // the pole-zero map of the chosen pair: the plant's force-to-cart-position zeros are the held-cart
  // pendulum's poles +-sqrt(3 g / (2 l)) (the rod, l = 2 m), drawn as circles beside A's poles;
  // the force-to-angle pair's are at the origin
  void poleZeroMapOfTheChosenPair() {
    ControlView* cv = w->controlView();
    w->analysisTabs()->setCurrentWidget(cv);
    QVERIFY(cv->analyse());
    cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    cv->inputCombo()->setCurrentIndex(cv->inputCombo()->findText("force", Qt::MatchContains));
    cv->outputCombo()->setCurrentIndex(cv->outputCombo()->findText("h", Qt::MatchStartsWith));
    PoleMap* map = cv->poleZeroMap();
    QCOMPARE(map->poleCount(), 4);
    QCOMPARE(map->zeroCount(), 2);
    const double z = std::sqrt(3 * 9.81 / (2 * 2.0));
    QVERIFY(std::abs(map->zeroPosition(0).x() + z) < 1e-9 && std::abs(map->zeroPosition(1).x() - z) < 1e-9);
    QVERIFY(map->legendText().contains("zeros"));
    // force to angle: theta follows the cart's acceleration, a double zero at s = 0 (it cancels the
    // cart's double integrator)
    cv->outputCombo()->setCurrentIndex(cv->outputCombo()->findText("theta", Qt::MatchStartsWith));
    QCOMPARE(map->zeroCount(), 2);
    for (int k = 0; k < 2; ++k) QVERIFY(std::hypot(map->zeroPosition(k).x(), map->zeroPosition(k).y()) < 1e-6);
    QCOMPARE(map->poleCount(), 4);
  }

  // the Bode axes on round steps with few enough ticks that their labels fit (at most 6: more were
  // drawn as "..."), the curve inside the range; a flat phase gets a step on either side
  void bodeAxesHoldFewRoundTicks() {
    ControlView* cv = w->controlView();
    w->analysisTabs()->setCurrentWidget(cv);
    QVERIFY(cv->analyse());
    cv->systemCombo()->setCurrentIndex(ControlView::Plant);
    cv->inputCombo()->setCurrentText("force");
    cv->outputCombo()->setCurrentText("theta");
    for (const char* name : {"bodeMagnitude", "bodePhase"}) {
      auto* view = cv->findChild<ChartView*>(name);
      QVERIFY2(view, name);
      auto* y = qobject_cast<QValueAxis*>(view->chart()->axes(Qt::Vertical).value(0));
      QVERIFY(y);
      const double interval = y->tickInterval(), span = y->max() - y->min();
      QVERIFY2(interval > 0 && span / interval <= 5 + 1e-9, qPrintable(QString("%1: %2 ticks").arg(name).arg(span / interval)));
      QVERIFY2(std::abs(std::remainder(y->min(), interval)) < 1e-9 * interval, name);  // on whole steps
      const QList<QPointF> points = QString(name) == "bodeMagnitude" ? cv->magnitudePoints() : cv->phasePoints();
      QVERIFY(!points.isEmpty());
      for (const QPointF& p : points) QVERIFY(p.y() >= y->min() && p.y() <= y->max());
      if (QString(name) == "bodePhase") {  // force -> theta: 0 degrees at every frequency
        QCOMPARE(y->min(), -y->max());
      }
    }
  }

  void closedLoopStepGainAndPoles() {
    ControlView* cv = w->controlView();
    QVERIFY(cv->analyse());
    QVERIFY(cv->hasClosedLoop());
    QCOMPARE(cv->systemCombo()->currentIndex(), int(ControlView::ClosedLoop));
    const StudyClosedLoop* cl = cv->closedLoop();
    // the example's LQR: K shown with the plant's input and state names, every closed-loop pole stable
    QCOMPARE(cv->gainModel()->rowCount(), 1);
    QCOMPARE(cv->gainModel()->columnCount(), 4);
    // K equals the LQR designed from the plant with the example's weights Q = diag(10, 100, 1, 1), R = 0.01
    const LinearSystem& plant = *cv->system(ControlView::Plant);
    const Eigen::Vector4d q(10, 100, 1, 1);
    const LqrResult design = lqr(plant.A, plant.B, Eigen::MatrixXd(q.asDiagonal()), Eigen::MatrixXd::Constant(1, 1, 0.01));
    const double k_err = (cv->gainModel()->matrix() - design.K).cwiseAbs().maxCoeff();
    QVERIFY2(k_err <= 1e-9 * design.K.cwiseAbs().maxCoeff(), qPrintable(QString("K differs by %1").arg(k_err)));
    QCOMPARE(cv->gainModel()->headerData(0, Qt::Vertical).toString(), QString("force"));
    QCOMPARE(cv->poleModel()->rowCount(), 4);
    for (const Mode& m : cl->poles.modes) QVERIFY(m.s.real() < 0);
    QVERIFY(cv->statusLabel()->text().contains("all stable"));
    // what `codyna linearize --closed-loop` prints for the same model: the same poles, the same gain
    {
      LinearizeRequest r;
      r.model = kCart.toStdString();
      r.closed_loop = true;
      const LinearizeJob cli = study_linearize_job(r, w->document()->spec());
      QVERIFY(cli.closed_loop);
      QCOMPARE(cli.closed_loop->poles.modes.size(), cl->poles.modes.size());
      for (std::size_t k = 0; k < cl->poles.modes.size(); ++k) {
        QCOMPARE(cl->poles.modes[k].eigenvalue, cli.closed_loop->poles.modes[k].eigenvalue);
        QCOMPARE(cl->poles.modes[k].stability, cli.closed_loop->poles.modes[k].stability);
      }
      QCOMPARE(study_format_modes(cl->poles), study_format_modes(cli.closed_loop->poles));
      const ClosedLoopLinear& L = cli.closed_loop->loop;
      QCOMPARE(cv->gainModel()->matrix(), Eigen::MatrixXd(-L.system.C.block(L.ny, 0, L.nu, L.nx)));
    }

    // step on the first reference: every output against RK4 on the loop's matrices
    const LinearSystem& s = *cv->system(ControlView::ClosedLoop);
    cv->inputCombo()->setCurrentIndex(0);
    // the measured outputs (h, theta), then with an effort chosen, the efforts (force)
    const int ny = cl->loop.ny;
    cv->outputCombo()->setCurrentIndex(0);
    QCOMPARE(cv->stepSeriesCount(), ny);
    cv->outputCombo()->setCurrentIndex(ny);
    QCOMPARE(cv->stepSeriesCount(), s.ny() - ny);
    QCOMPARE(cv->stepOutputs().front(), ny);
    // every output's curve, each group in turn, against RK4
    std::vector<QList<QPointF>> curves;
    for (int j = 0; j < s.ny(); ++j) {
      cv->outputCombo()->setCurrentIndex(j);
      curves.push_back(cv->stepPoints(j));
    }
    const QList<QPointF> first = curves[0];
    QVERIFY(first.size() > 50);
    const double t_end = first.back().x();
    const int substeps = 40;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(s.nx());
    const Eigen::VectorXd b = s.B.col(0);
    auto f = [&](const Eigen::VectorXd& z) -> Eigen::VectorXd { return s.A * z + b; };
    double max_err = 0, scale = 1e-12;
    for (int k = 0; k < first.size(); ++k) {
      if (k > 0) {
        const double h = (first[k].x() - first[k - 1].x()) / substeps;
        for (int i = 0; i < substeps; ++i) {
          const Eigen::VectorXd k1 = f(x), k2 = f(x + 0.5 * h * k1), k3 = f(x + 0.5 * h * k2), k4 = f(x + h * k3);
          x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        }
      }
      const Eigen::VectorXd y = s.C * x + s.D.col(0);
      for (int j = 0; j < s.ny(); ++j) {
        const QList<QPointF>& p = curves[j];
        QCOMPARE(p.size(), first.size());
        QCOMPARE(p[k].x(), first[k].x());
        max_err = std::max(max_err, std::abs(p[k].y() - y[j]));
        scale = std::max(scale, std::abs(y[j]));
      }
    }
    QVERIFY2(max_err <= 1e-8 * scale, qPrintable(QString("step: max error %1 (scale %2, t_end %3)").arg(max_err).arg(scale).arg(t_end)));

    // an edit marks it out of date; New clears it
    w->selectElement(ElementId{ElementKind::Body, 1});
    QVERIFY(w->document()->edit("mass", [](ModelSpec& m) { m.bodies[1].mass = 11; }));
    QVERIFY(cv->isStale());
    QVERIFY(cv->findChild<QLabel*>("controlStale")->isVisibleTo(cv));
    QVERIFY(w->newModel());
    QVERIFY(!cv->hasClosedLoop());
    QVERIFY(!cv->system(ControlView::Plant));
    QCOMPARE(cv->magnitudePoints().size(), 0);
    QCOMPARE(cv->stepSeriesCount(), 0);
    QCOMPARE(cv->poleModel()->rowCount(), 0);
  }
};

QTEST_MAIN(ControlViewTest)
#include "control_view_test.moc"
