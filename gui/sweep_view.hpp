// SweepView: the "Sweep" page of codyna-gui, a parameter study (issue 22) run as `codyna sweep`
// runs it: core's study_sweep_job on the document's model as it is in the window (saved or not:
// its model file text is handed to the core with SweepRequest::model_text).
//
// The varied fields are a table of (JSON pointer, spec): a row comes from the property editor's
// context menu ("Vary in sweep" on a numeric field gives /bodies/1/mass and a first grid about the
// field's value) or is typed. A spec is a grid a:b:n, a list [v1,v2,...], normal(mu,sigma) or
// uniform(a,b) (then Samples and Seed count). Threads (0: every core), the controller (the nominal
// K kept, or an LQR designed again per variant) and a nonlinear run per variant are the study's
// other choices. Run starts the study on a worker thread (the window stays responsive, a progress
// bar follows it); Cancel sets the core's cancel flag (the variants in flight finish, then the
// study stops and says how far it got). A spec the core refuses is reported with its message,
// which names the field.
//
// The results, as pictures:
//  - Poles: every completed variant's closed-loop poles (open-loop ones when the study has no
//    state feedback) on one map, coloured by the first varied field's value (a colour bar at the
//    side), the nominal poles as black rings: a root locus against the parameter;
//  - Figure of merit: the chosen figure (largest closed-loop real part, largest open-loop real
//    part, and with the nonlinear runs the peak |input| and the final error) against the chosen
//    varied field, variants not stable in red;
//  - Failed: the variants that failed (and runs that did not reach t_end), with the reason;
//  - Summary: the summary `codyna sweep` prints.
// "Save results..." writes HDF5 (.h5), CSV (.csv) or MAT + .m (.mat) through the core's
// study_write_sweep_* functions, never over the model file or a file codyna did not write.
#pragma once

#include <QColor>
#include <QList>
#include <QPointF>
#include <QString>
#include <QWidget>
#include <atomic>
#include <memory>
#include <vector>

#include "gui/job_thread.hpp"
#include "study/sweep.hpp"

QT_BEGIN_NAMESPACE
class QChart;
class QCheckBox;
class QComboBox;
class QLabel;
class QPlainTextEdit;
class QProgressBar;
class QPushButton;
class QScatterSeries;
class QSpinBox;
class QTabWidget;
class QTableWidget;
class QTimer;
QT_END_NAMESPACE

namespace codyna::gui {

class ChartView;
class ColourBar;
class Document;

class SweepView : public QWidget {
  Q_OBJECT
 public:
  explicit SweepView(Document* doc, QWidget* parent = nullptr);
  ~SweepView() override;  // cancels a running study and waits for it

  // A row for `pointer` (a JSON pointer into the model file); an empty spec gives a first grid of
  // 11 values from half to 1.5 times the field's value. A pointer already listed keeps its row.
  void addField(const QString& pointer, const QString& spec = QString());

  // The request the widgets describe (the document's model text included).
  codyna::SweepRequest request() const;
  // Starts the study; false (and the reason in the status and message()) when it cannot start:
  // running already, no field, a spec the core refuses.
  bool run();
  void cancel();
  bool isRunning() const { return worker_.isRunning(); }
  const codyna::SweepJob* result() const { return job_.get(); }
  void clearResult();
  // .h5, .csv or .mat (+ .m), by suffix; false with *error (and message()) when refused
  bool saveResults(const QString& path, QString* error = nullptr);

  // what is drawn, for tests: variant i's poles as plotted (Re, Im), its colour; the figure's points
  QList<QPointF> plottedPoles(int variant) const;
  QColor variantColour(int variant) const;
  QList<QPointF> figurePoints() const;  // every completed variant's (parameter, figure)

  // the widgets, for the main window and tests
  QTableWidget* fieldTable() const { return fields_; }
  QPushButton* addRowButton() const { return add_row_; }
  QPushButton* removeRowButton() const { return remove_row_; }
  QSpinBox* samplesSpin() const { return samples_; }
  QSpinBox* seedSpin() const { return seed_; }
  QSpinBox* threadsSpin() const { return threads_; }
  QComboBox* redesignCombo() const { return redesign_; }
  QCheckBox* simulateCheck() const { return simulate_; }
  QPushButton* runButton() const { return run_button_; }
  QPushButton* cancelButton() const { return cancel_button_; }
  QPushButton* saveButton() const { return save_button_; }
  QProgressBar* progressBar() const { return progress_; }
  QLabel* statusLabel() const { return status_; }
  QTabWidget* resultTabs() const { return tabs_; }
  QChart* poleChart() const { return pole_chart_; }
  ChartView* poleChartView() const { return pole_view_; }
  ColourBar* colourBar() const { return colour_bar_; }
  QComboBox* figureCombo() const { return figure_combo_; }
  QComboBox* parameterCombo() const { return parameter_combo_; }
  QChart* figureChart() const { return figure_chart_; }
  QTableWidget* failedTable() const { return failed_; }
  QPlainTextEdit* summaryText() const { return summary_; }

 signals:
  void message(const QString& text);
  void started();
  void finished();  // a study ended: completed (result() set), cancelled or refused

 private:
  QString fieldName(const QString& pointer) const;  // "rod.mass", or why the pointer names nothing
  void refreshFieldName(int row);
  QString shownField(const std::string& pointer) const;  // the name when there is one, else the pointer
  void buildUi();
  void setStatus(const QString& text, bool error);
  void updateButtons();
  void onFinished(std::shared_ptr<const codyna::SweepJob> job, const JobOutcome& out);
  void showResult();
  void drawPoles();
  void drawFigure();
  void fillFailed();
  void saveDialog();
  void tick();  // the progress bar follows the workers' count

  Document* doc_;
  std::shared_ptr<const codyna::SweepJob> job_;
  std::atomic<long long> done_{0}, total_{0};
  bool drop_result_ = false;  // the document was replaced while the study ran
  QTimer* timer_ = nullptr;

  struct Drawn {
    QScatterSeries* series = nullptr;
    int first = 0, count = 0;
    QColor colour;
  };
  std::vector<Drawn> drawn_;  // per variant (count 0: not drawn)

  QTableWidget* fields_ = nullptr;
  QPushButton* add_row_ = nullptr;
  QPushButton* remove_row_ = nullptr;
  QSpinBox* samples_ = nullptr;
  QSpinBox* seed_ = nullptr;
  QSpinBox* threads_ = nullptr;
  QComboBox* redesign_ = nullptr;
  QCheckBox* simulate_ = nullptr;
  QPushButton* run_button_ = nullptr;
  QPushButton* cancel_button_ = nullptr;
  QPushButton* save_button_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QLabel* status_ = nullptr;
  QTabWidget* tabs_ = nullptr;
  QChart* pole_chart_ = nullptr;
  ChartView* pole_view_ = nullptr;
  ColourBar* colour_bar_ = nullptr;
  QComboBox* figure_combo_ = nullptr;
  QComboBox* parameter_combo_ = nullptr;
  QChart* figure_chart_ = nullptr;
  ChartView* figure_view_ = nullptr;
  QTableWidget* failed_ = nullptr;
  QPlainTextEdit* summary_ = nullptr;
  JobThread worker_{this, QStringLiteral("codyna-sweep")};  // last: joined before the other members go
};

// The colour scale of the pole map: low values dark blue, high values yellow (viridis).
class ColourBar : public QWidget {
  Q_OBJECT
 public:
  explicit ColourBar(QWidget* parent = nullptr);
  void setRange(const QString& title, double low, double high);
  void clear();
  static QColor colourAt(double t);  // t in [0, 1]
  QString title() const { return title_; }
  double low() const { return low_; }
  double high() const { return high_; }
  QSize sizeHint() const override { return {110, 200}; }

 protected:
  void paintEvent(QPaintEvent*) override;

 private:
  QString title_;
  double low_ = 0, high_ = 0;
  bool shown_ = false;
};

}  // namespace codyna::gui
