// The Maneuvers tab (gui/maneuver_view.hpp), driven as a person does: the tab clicked, the maneuver
// picked from its list with the mouse, numbers typed into the fields, Run clicked. What it shows is
// the job's (study_maneuver_job with the same request): the report's text equal to what codyna
// maneuver prints, the curve's points equal to the report's numbers. A field that does not read and
// a refusal of the job are shown naming the field, and nothing runs; the lane change draws the
// car's path (its x and y outputs); Cancel stops a long run (the
// sedan's swept sine) within a step, the window alive.
#include <QApplication>
#include <QChart>
#include <QCheckBox>
#include <QComboBox>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QTabBar>
#include <QTabWidget>
#include <QTest>
#include <cmath>
#include <numbers>

#include "drive.hpp"
#include "gui/chart_view.hpp"
#include "gui/main_window.hpp"
#include "gui/kc_view.hpp"
#include "gui/maneuver_view.hpp"
#include "gui/view3d.hpp"
#include "study/files.hpp"
#include "study/kc_job.hpp"
#include "study/maneuver_job.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

const QString kCar = QStringLiteral(CODYNA_EXAMPLES_DIR "/single_track_car.json");
const QString kSedan = QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan.json");
const QString kSedanEsc = QStringLiteral(CODYNA_EXAMPLES_DIR "/sedan_esc.json");
const QString kCorner = QStringLiteral(CODYNA_EXAMPLES_DIR "/kc_double_wishbone.json");

QLineSeries* maneuver_series_named(ChartView* view, const QString& name) {
  for (QAbstractSeries* s : view->chart()->series())
    if (s->name() == name) return qobject_cast<QLineSeries*>(s);
  return nullptr;
}

}  // namespace

class ManeuverViewTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;

  ManeuverView* view() { return w->maneuverView(); }

  void openTab() {
    auto* tabs = w->findChild<QTabWidget*>();
    QVERIFY(tabs);
    const int i = tabs->indexOf(view());
    QVERIFY(i >= 0);
    QTest::mouseClick(tabs->tabBar(), Qt::LeftButton, {}, tabs->tabBar()->tabRect(i).center());
    QTRY_COMPARE(tabs->currentWidget(), view());
  }

  void type(const QString& key, const QString& text) {
    QLineEdit* e = view()->field(key);
    QVERIFY2(e && e->isVisible(), qPrintable(key));
    QTest::mouseClick(e, Qt::LeftButton);
    e->selectAll();
    QTest::keyClick(e, Qt::Key_Backspace);
    QTest::keyClicks(e, text);
  }

  void runAndWait(int ms = 60000) {
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QTRY_VERIFY_WITH_TIMEOUT(!view()->isRunning(), ms);
  }

  // the job run directly with the request the fields mean (the command line's)
  ManeuverReport job(const QString& file, ManeuverRequest r) {
    r.model = file.toStdString();
    return study_maneuver_job(r, study_read_model(r.model));
  }

 private slots:
  void init() {
    w = std::make_unique<MainWindow>();
    w->resize(1400, 900);
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  }
  void cleanup() { w.reset(); }

  void stepSteerIsTheJobsReport() {
    QVERIFY(w->openFile(kCar));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "step-steer"));
    QVERIFY(!view()->field("radius")->isVisible());
    type("steer", "0.001");
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "step-steer";
    r.steer = 0.001;
    const ManeuverReport rep = job(kCar, r);
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QLineSeries* s = maneuver_series_named(view()->chartView(), "yaw_rate");
    QVERIFY(s);
    QCOMPARE(s->count(), rep.result.samples());
    for (int i = 0; i < s->count(); i += 97) {
      QCOMPARE(s->at(i).x(), rep.result.t[static_cast<std::size_t>(i)]);
      QCOMPARE(s->at(i).y(), rep.result.y(i, 0));
    }
  }

  void badFieldsAndRefusalsNameTheField() {
    QVERIFY(w->openFile(kCar));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "constant-radius"));
    QVERIFY(view()->field("radius")->isVisible());
    QVERIFY(!view()->field("steer")->isVisible());
    runAndWait();  // no radius: the job's refusal
    QCOMPARE(view()->statusText(), QStringLiteral("radius: the constant-radius maneuver needs a radius (m)"));
    QVERIFY(!view()->report());
    type("radius", "12o");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(!view()->isRunning());
    QCOMPARE(view()->statusText(), QStringLiteral("radius: \"12o\" is not a number"));
    // the fishhook's dwell given both ways, Enter in the roll-rate field: refused by its keyword
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "fishhook"));
    QVERIFY(!view()->field("radius")->isVisible());
    type("dwell", "0.2");
    type("dwell-roll-rate", "1.5");
    QTest::keyClick(view()->field("dwell-roll-rate"), Qt::Key_Return);
    QTRY_VERIFY_WITH_TIMEOUT(!view()->isRunning(), 60000);
    QVERIFY2(view()->statusText().startsWith(QStringLiteral("dwell_roll_rate: give the dwell or the roll rate that ends it, not both")),
             qPrintable(view()->statusText()));
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "constant-radius"));
    // then the turns, the free inputs typed as the command line's --free-input
    type("radius", "500");
    type("speed-min", "2");
    type("speed-max", "30");
    type("points", "4");
    type("free-input", "steer, drive");
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "constant-radius";
    r.radius = 500;
    r.speed_min = 2;
    r.speed_max = 30;
    r.points = 4;
    r.free_inputs = std::vector<std::string>{"steer", "drive"};
    const ManeuverReport rep = job(kCar, r);
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QLineSeries* turns = maneuver_series_named(view()->chartView(), "steady turns");
    QLineSeries* lin = maneuver_series_named(view()->chartView(), "linear model");
    QVERIFY(turns && lin);
    QCOMPARE(turns->count(), 4);
    QCOMPARE(lin->count(), 4);
    for (int k = 0; k < 4; ++k) {
      QCOMPARE(turns->at(k).x(), rep.cr_lateral_acceleration[static_cast<std::size_t>(k)]);
      QCOMPARE(turns->at(k).y(), rep.cr_road_wheel[static_cast<std::size_t>(k)] * 180 / std::numbers::pi);
      // the linear model's steer (a ratio of 1 on this car)
      QVERIFY(std::abs(lin->at(k).y() - rep.cr_linear_steer[static_cast<std::size_t>(k)] * 180 / std::numbers::pi) < 1e-12);
    }
  }

  // the sedan with its yaw-rate controller: a swept sine refuses it (the box unticked), the step
  // steer runs it in the loop (the job's report, the controller named), and with "Open loop" ticked
  // by a click the same step runs without it
  void theModelsControllerRunsUnlessOpenLoopIsTicked() {
    QVERIFY(w->openFile(kSedanEsc));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "swept-sine"));
    QVERIFY(view()->openLoopBox()->isVisible());
    QVERIFY(!view()->openLoopBox()->isChecked());
    runAndWait();
    QVERIFY2(view()->statusText().startsWith(QStringLiteral("open_loop: the model file has a pid controller")),
             qPrintable(view()->statusText()));
    QVERIFY(!view()->report());
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "constant-radius"));
    QVERIFY(!view()->openLoopBox()->isVisible());
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "step-steer"));
    type("steer", "0.01");
    type("t-end", "2");  // long enough for the step's metrics, short under the sanitizers
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "step-steer";
    r.steer = 0.01;
    r.t_end = 2;
    const ManeuverReport rep = job(kSedanEsc, r);
    QVERIFY(!rep.controller.empty());
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QTest::mouseClick(view()->openLoopBox(), Qt::LeftButton);
    QVERIFY(view()->openLoopBox()->isChecked());
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    QVERIFY(view()->report() && view()->report()->controller.empty());
    QVERIFY(!view()->reportView()->toPlainText().contains(QStringLiteral("controller")));
    QVERIFY(view()->reportView()->toPlainText().contains(QStringLiteral("largest sideslip")));
  }

  // The lane change runs the model file's yaw-moment controller beside the driver, and Open loop
  // leaves it out: the report is the job's for the same request either way
  void laneChangeRunsTheFilesControllerBesideTheDriver() {
    const QString file = QStringLiteral(CODYNA_TEST_DATA_DIR "/single_track_car_yaw_moment.json");
    QVERIFY(w->openFile(file));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "double-lane-change"));
    QVERIFY(view()->openLoopBox()->isVisible());
    QVERIFY(!view()->openLoopBox()->isChecked());
    type("speed", "22.2");
    type("preview", "6");
    type("drive", "drive");  // the driver holds the speed too
    type("speed-kp", "2000");
    type("speed-ki", "500");
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "double-lane-change";
    r.speed = 22.2;
    r.preview = 6;
    r.drive = "drive";
    r.speed_kp = 2000;
    r.speed_ki = 500;
    const ManeuverReport rep = job(file, r);
    QVERIFY(rep.controller.find("beside the driver") != std::string::npos);
    QVERIFY(rep.result.controller.find("PI on speed 22.2 m/s, kp 2000, ki 500") != std::string::npos);
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QVERIFY(view()->reportView()->toPlainText().contains(QStringLiteral("largest |u - u0| yaw_moment")));
    QTest::mouseClick(view()->openLoopBox(), Qt::LeftButton);
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    QVERIFY(view()->report() && view()->report()->controller.empty());
    r.open_loop = true;
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(job(file, r))));
  }

  // The K&C tab (gui/kc_view.hpp) on the sedan's corner: ranges typed, Enter in a field runs it;
  // the report is codyna kc's text for the same request, the curves its points; a range that does
  // not read is shown naming it, and the last curves stay until a run succeeds
  void kcTabIsTheJobsReportAndCurves() {
    QVERIFY(w->openFile(kCorner));
    KcView* kc = w->kcView();
    auto* tabs = w->findChild<QTabWidget*>();
    QVERIFY(tabs);
    const int i = tabs->indexOf(kc);
    QVERIFY(i >= 0);
    QTest::mouseClick(tabs->tabBar(), Qt::LeftButton, {}, tabs->tabBar()->tabRect(i).center());
    QTRY_COMPARE(tabs->currentWidget(), kc);
    const auto typeInto = [](QLineEdit* e, const QString& text) {
      QTest::mouseClick(e, Qt::LeftButton);
      e->selectAll();
      QTest::keyClick(e, Qt::Key_Backspace);
      QTest::keyClicks(e, text);
    };
    typeInto(kc->field("travel"), "-0.03:0.03:7");
    typeInto(kc->field("steer-range"), "-0.01:0.01:5");
    QTest::keyClick(kc->field("steer-range"), Qt::Key_Return);
    QVERIFY2(kc->errorText().isEmpty(), qPrintable(kc->errorText()));
    QVERIFY(kc->report());
    KcRequest r;
    r.model = kCorner.toStdString();
    r.travel = study_kc_range("-0.03:0.03:7", "travel");
    r.steer_range = study_kc_range("-0.01:0.01:5", "steer range");
    const ModelSpec spec = study_read_model(r.model);
    r.spec = &spec;
    const KcReport rep = study_kc_job(r);
    QCOMPARE(kc->reportView()->toPlainText(), QString::fromStdString(study_kc_text(rep)));
    QLineSeries* camber = maneuver_series_named(kc->travelView(), "camber");
    QLineSeries* toe = maneuver_series_named(kc->travelView(), "toe");
    QLineSeries* steer_toe = maneuver_series_named(kc->steerView(), "toe");
    QVERIFY(camber && toe && steer_toe);
    QCOMPARE(camber->count(), 7);
    QCOMPARE(steer_toe->count(), 5);
    int t = 0, st = 0;
    for (const KcPoint& p : rep.points) {
      if (p.sweep == "travel") {
        QCOMPARE(camber->at(t).x(), p.travel * 1000);
        QCOMPARE(camber->at(t).y(), p.camber);
        QCOMPARE(toe->at(t++).y(), p.toe);
      } else if (p.sweep == "steer") {
        QCOMPARE(steer_toe->at(st).x(), p.steer);
        QCOMPARE(steer_toe->at(st++).y(), p.toe);
      }
    }
    QCOMPARE(t, 7);
    // a range that does not read: the error names it, the curves stay
    typeInto(kc->field("travel"), "0.03:-0.03:7");
    QTest::mouseClick(kc->runButton(), Qt::LeftButton);
    QVERIFY(kc->errorText().contains(QStringLiteral("travel")));
    QCOMPARE(maneuver_series_named(kc->travelView(), "camber")->count(), 7);
    // a wheel the model does not have
    typeInto(kc->field("travel"), "-0.01:0.01:3");
    typeInto(kc->field("wheel"), "wheel_rr");
    QTest::keyClick(kc->field("wheel"), Qt::Key_Return);
    QVERIFY2(kc->errorText().contains(QStringLiteral("wheel_rr")), qPrintable(kc->errorText()));
  }

  void sweptSineShowsTheGainsBesideTheLinearOnes() {
    QVERIFY(w->openFile(kCar));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "swept-sine"));
    type("steer", "0.001");
    type("points", "6");
    runAndWait();
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "swept-sine";
    r.steer = 0.001;
    r.points = 6;
    const ManeuverReport rep = job(kCar, r);
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QLineSeries* run = maneuver_series_named(view()->chartView(), "run");
    QLineSeries* lin = maneuver_series_named(view()->chartView(), "linear model");
    QVERIFY(run && lin);
    QCOMPARE(run->count(), 6);
    for (int k = 0; k < 6; ++k) {
      QCOMPARE(run->at(k).y(), std::abs(rep.sw_yaw[static_cast<std::size_t>(k)]));
      QVERIFY(std::abs(run->at(k).y() - lin->at(k).y()) < 1e-3 * lin->at(k).y());
    }
  }

  void laneChangeShowsThePath() {
    const QString file = QStringLiteral(CODYNA_TEST_DATA_DIR "/single_track_car_driver.json");
    QVERIFY(w->openFile(file));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "double-lane-change"));
    type("speed", "22.2");
    type("preview", "6");
    QTest::keyClick(view()->field("preview"), Qt::Key_Return);  // Enter in a field runs it
    QVERIFY(view()->isRunning());
    QTRY_VERIFY_WITH_TIMEOUT(!view()->isRunning(), 60000);
    QCOMPARE(view()->statusText(), QStringLiteral("Done"));
    ManeuverRequest r;
    r.type = "double-lane-change";
    r.speed = 22.2;
    r.preview = 6;
    const ManeuverReport rep = job(file, r);
    QCOMPARE(view()->reportView()->toPlainText(), QString::fromStdString(study_maneuver_text(rep)));
    QLineSeries* path = maneuver_series_named(view()->chartView(), "path");
    QVERIFY(path);
    QCOMPARE(path->count(), rep.result.samples());
    const auto& names = rep.result.output_names;
    const int ix = static_cast<int>(std::find(names.begin(), names.end(), "x") - names.begin());
    const int iy = static_cast<int>(std::find(names.begin(), names.end(), "y") - names.begin());
    for (int i = 0; i < path->count(); i += 53) {
      QCOMPARE(path->at(i).x(), rep.result.y(i, ix));
      QCOMPARE(path->at(i).y(), rep.result.y(i, iy));
    }

    // the 3-D view plays the run: the car at its start, the lane, its cones and the chassis' track
    // on the ground, the camera following the car
    const SimulationResult* played = w->playbackResult();
    QVERIFY(played);
    QCOMPARE(played->samples(), rep.result.samples());
    QCOMPARE(w->playbackTime(), rep.result.t.front());
    View3D* v3 = w->findChild<View3D*>();
    QVERIFY(v3);
    QCOMPARE(v3->followBody(), w->document()->model()->find_body("chassis"));
    const auto named = [&](const std::string& name) -> const ScenePath* {
      for (const ScenePath& p : v3->paths())
        if (p.name == name) return &p;
      return nullptr;
    };
    const ScenePath *lane = named("lane"), *cones = named("cones"), *track = named("track");
    QVERIFY(lane && cones && track);
    QCOMPARE(lane->points.size(), rep.lane_path.size());
    // the chassis' centre (its planar joint's origin) through forward kinematics, against the x and
    // y sensors of the same samples
    QCOMPARE(int(track->points.size()), rep.result.samples());
    double err = 0;
    for (int i = 0; i < rep.result.samples(); ++i)
      err = std::max({err, std::abs(track->points[i].x() - rep.result.y(i, ix)), std::abs(track->points[i].y() - rep.result.y(i, iy))});
    QVERIFY2(err < 1e-9, qPrintable(QString("track off the sensors by %1 m").arg(err)));
    // ISO 3888-1: the cones of section 1 (15 m from 50 m on) stand 1.1 w + 0.25 apart about the
    // start's line (w = 1.8 m, the car's width here)
    int first = 0;
    for (const Eigen::Vector3d& c : cones->points)
      if (c.x() > 50 - 1e-9 && c.x() < 65 + 1e-9) {
        ++first;
        QVERIFY2(std::abs(std::abs(c.y()) - (1.1 * 1.8 + 0.25) / 2) < 1e-9, qPrintable(QString::number(c.y())));
      }
    QVERIFY(first >= 4);
    // the grid holds the whole track
    const Scene& scene = v3->scene();
    for (const Eigen::Vector3d& p : track->points)
      QVERIFY(std::abs(p.x() - scene.gridCenter().x()) <= scene.gridHalf() && std::abs(p.y() - scene.gridCenter().y()) <= scene.gridHalf());
    // the camera's target moves with the chassis
    const int a = rep.result.samples() / 3, b = 2 * rep.result.samples() / 3;
    w->setPlaybackTime(rep.result.t[a]);
    const Eigen::Vector3d ta = v3->camera().target;
    w->setPlaybackTime(rep.result.t[b]);
    const Eigen::Vector3d moved = v3->camera().target - ta;
    QVERIFY(std::abs(moved.x() - (rep.result.y(b, ix) - rep.result.y(a, ix))) < 1e-9);
    QVERIFY(std::abs(moved.y() - (rep.result.y(b, iy) - rep.result.y(a, iy))) < 1e-9);
    QVERIFY(moved.norm() > 50);  // it went far
    // Play runs it
    QTest::mouseClick(w->findChild<QPushButton*>("playButton"), Qt::LeftButton);
    QVERIFY(w->isPlaying());
    w->setPlaying(false);
  }

  void cancelStopsALongRun() {
    QVERIFY(w->openFile(kSedan));
    openTab();
    QVERIFY(drive::pickWithMouse(view()->typeBox(), "swept-sine"));
    type("steer", "0.02");
    QTest::mouseClick(view()->runButton(), Qt::LeftButton);
    QVERIFY(view()->isRunning());
    QVERIFY(!view()->runButton()->isEnabled());
    // the run under way: the bar shows its time (after the steady search: seconds under ASan)
    auto* bar = view()->findChild<QProgressBar*>("maneuverProgress");
    QVERIFY(bar);
    QTRY_VERIFY_WITH_TIMEOUT(bar->format().startsWith("t = "), 60000);
    QTest::qWait(300);
    QVERIFY(view()->isRunning());
    QTest::mouseClick(view()->cancelButton(), Qt::LeftButton);
    QTRY_VERIFY_WITH_TIMEOUT(!view()->isRunning(), 10000);
    QCOMPARE(view()->statusText(), QStringLiteral("Cancelled"));
    QVERIFY(!view()->report());
    QVERIFY(view()->runButton()->isEnabled());
    QVERIFY(w->isVisible());
  }
};

QTEST_MAIN(ManeuverViewTest)
#include "maneuver_view_test.moc"
