// ManeuverView: the standard handling maneuvers (`codyna maneuver`, core's study_maneuver_job) on
// the model being edited: the maneuver chosen from the core's list, its parameters typed (an empty
// field keeps the job's default, shown greyed), Run on a worker thread with a progress bar and
// Cancel, then the job's report (the text codyna maneuver prints) and its curve:
//   step steer, sine with dwell                       the yaw rate over time;
//   double lane change                                the path (its x, y outputs), else the yaw rate;
//   swept sine                                        the yaw-rate gain over frequency, run and linear;
//   constant radius, constant speed                   the road-wheel angle over a_y, turns and linear.
// Every number shown is the job's; the view computes nothing itself.
#pragma once

#include <QMap>
#include <QWidget>
#include <atomic>
#include <memory>

#include "gui/job_thread.hpp"
#include "study/maneuver_job.hpp"

class QComboBox;
class QLabel;
class QCheckBox;
class QLineEdit;
class QPlainTextEdit;
class QProgressBar;
class QPushButton;
class QTimer;

namespace codyna::gui {

class ChartView;
class Document;

class ManeuverView : public QWidget {
  Q_OBJECT
 public:
  explicit ManeuverView(Document* doc, QWidget* parent = nullptr);
  ~ManeuverView() override;

  // Starts the maneuver chosen with the fields typed; false (the reason in statusText()) when a
  // field does not read or a run is going. The job's own refusals come with finished().
  bool run();
  void cancel();
  bool isRunning() const { return job_.isRunning(); }

  QComboBox* typeBox() const { return type_; }
  // the field of a parameter, by its flag's name ("speed", "steer", "radius", ...; null: none)
  QLineEdit* field(const QString& key) const { return fields_.value(key, nullptr); }
  QCheckBox* openLoopBox() const { return open_loop_; }
  QPushButton* runButton() const { return run_; }
  QPushButton* cancelButton() const { return cancel_button_; }
  QPlainTextEdit* reportView() const { return report_view_; }
  ChartView* chartView() const { return chart_; }
  QString statusText() const;
  // the last report (null before the first, or after a refusal or a cancel)
  const ManeuverReport* report() const { return report_.get(); }
  std::shared_ptr<const ManeuverReport> sharedReport() const { return report_; }

 signals:
  void message(const QString& text);
  void finished();

 private:
  void buildUi();
  void typeChosen();
  ManeuverRequest request() const;
  void onFinished(std::shared_ptr<const ManeuverReport> report, const JobOutcome& outcome);
  void showCurve();
  void setStatus(const QString& text, bool error);
  void updateButtons();

  Document* doc_;
  QComboBox* type_ = nullptr;
  QCheckBox* open_loop_ = nullptr;
  QMap<QString, QLineEdit*> fields_;
  QMap<QString, QWidget*> labels_;
  QPushButton *run_ = nullptr, *cancel_button_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QLabel* status_ = nullptr;
  QPlainTextEdit* report_view_ = nullptr;
  ChartView* chart_ = nullptr;
  QTimer* timer_ = nullptr;
  std::atomic<double> t_{0}, t_end_{0};
  bool drop_result_ = false;
  std::shared_ptr<const ManeuverReport> report_;
  JobThread job_{this, QStringLiteral("codyna-maneuver")};  // last: joined before the other members go
};

}  // namespace codyna::gui
