// KcView: the suspension K&C rig (`codyna kc`, core's study_kc_job) on the model being edited: the
// wheels (one: a corner; two: an axle), the sweeps typed as MIN:MAX:N (travel, steer, roll, the
// contact-patch loads Fy and Fx), Run. It shows the report as the command line prints it and two
// charts: camber and toe over wheel travel, and toe over the steer input. Every number plotted is
// a point of the job's report; the view computes nothing itself. The job is quick (a corner's
// sweeps take milliseconds), so it runs on the window's thread.
#pragma once

#include <QWidget>
#include <memory>

class QLabel;
class QLineEdit;
class QPlainTextEdit;
class QPushButton;

namespace codyna {
struct KcReport;
}

namespace codyna::gui {

class ChartView;
class Document;

class KcView : public QWidget {
  Q_OBJECT
 public:
  explicit KcView(Document* doc, QWidget* parent = nullptr);
  ~KcView() override;

  // runs the rig with the fields typed; false (the reason in errorText()) when a field does not
  // read or the job refuses
  bool run();

  // the fields, by their flag's name: "wheel", "travel", "steer-range", "roll", "fy", "fx"
  QLineEdit* field(const QString& key) const;
  QPushButton* runButton() const { return run_; }
  QPlainTextEdit* reportView() const { return report_view_; }
  ChartView* travelView() const { return travel_; }  // camber, toe [deg] over travel [mm]
  ChartView* steerView() const { return steer_; }    // toe [deg] over the steer input
  QString errorText() const;
  const KcReport* report() const { return report_.get(); }

 signals:
  void message(const QString& text);

 private:
  void showCurves();
  void showError(const QString& text);
  Document* doc_;
  QLineEdit *wheel_ = nullptr, *travel_range_ = nullptr, *steer_range_ = nullptr, *roll_ = nullptr, *fy_ = nullptr,
            *fx_ = nullptr;
  QPushButton* run_ = nullptr;
  QLabel* error_ = nullptr;
  QPlainTextEdit* report_view_ = nullptr;
  ChartView *travel_ = nullptr, *steer_ = nullptr;
  std::unique_ptr<KcReport> report_;
};

}  // namespace codyna::gui
