// ControlView: the "Control" page of codyna-gui, the linear views a control
// engineer reads before running the nonlinear loop (Simulink Control Design's
// Linear System Analyzer, Adams Controls' plant plots).
//
// "Analyse" runs core's study_control_job (study/jobs.hpp): the open-loop plant, as `codyna
// linearize` makes it, and the plant closed by the study's controller (the model file's PID,
// a K or LTI from a .mat, or the LQR the Simulate view designs), as `codyna linearize
// --closed-loop` makes it, on the document's model. It shows
//  - the controller's gain K when it has no states of its own (state feedback, LQR,
//    P and PD: u = u0 - K dx, read off the closed loop), and the closed-loop
//    poles (a table: eigenvalue, frequency, damping; unstable ones in red);
//  - a Bode plot, magnitude in dB and phase in degrees over a logarithmic
//    frequency axis, of one input-output pair of the open-loop plant or of
//    the closed loop (chosen with three drop-downs), and over the open-loop plant's, the
//    frequency response of the nonlinear plant (Estimate: core's study_freqresp_job, the job
//    `codyna freqresp` runs, at the amplitude and frequencies typed, on a worker thread with
//    progress and Cancel): its gain and phase as points on the linear curves, and the largest
//    gap, where, and the harmonics' share in a line under the plot;
//  - the step response to a unit step on the chosen input of the outputs of
//    the chosen output's group (exact at the samples: core's step_response).
// Nothing is computed here: the curves, poles, zeros, the gain and the stability verdict are
// the job's. An edit marks the results out of date;
// New and Open clear them.
#pragma once

#include <QWidget>
#include <atomic>
#include <memory>
#include <optional>

#include "gui/job_thread.hpp"
#include "study/freqresp_job.hpp"
#include "study/jobs.hpp"

QT_BEGIN_NAMESPACE
class QChart;
class QChartView;
class QComboBox;
class QLabel;
class QLineEdit;
class QLineSeries;
class QProgressBar;
class QPushButton;
class QScatterSeries;
class QTableView;
class QTimer;
QT_END_NAMESPACE

namespace codyna::gui {

class Document;
class MatrixTableModel;
class ModeTableModel;

class PoleMap;

class ControlView : public QWidget {
  Q_OBJECT
 public:
  explicit ControlView(Document* doc, QWidget* parent = nullptr);
  ~ControlView() override;

  // Linearizes and closes the loop on the document's model. False (and message()) when the
  // plant cannot be linearized; a loop that cannot be closed (no controller, a K that does not
  // fit) leaves the plant's views and says why.
  bool analyse();
  void clearResult();
  bool isStale() const;

  // what is shown: 0 = the open-loop plant, 1 = the closed loop
  enum System { Plant = 0, ClosedLoop = 1 };
  bool hasClosedLoop() const { return job_ && job_->closed_loop.has_value(); }
  const codyna::LinearSystem* system(System s) const;
  const codyna::FrequencyResponse* frequency(System s) const;
  const codyna::StepResponse* step(System s) const;
  const codyna::StudyClosedLoop* closedLoop() const { return hasClosedLoop() ? &*job_->closed_loop : nullptr; }

  // the widgets, for tests
  QComboBox* systemCombo() const { return system_combo_; }
  QComboBox* inputCombo() const { return input_combo_; }
  QComboBox* outputCombo() const { return output_combo_; }
  QPushButton* analyseButton() const { return analyse_button_; }
  QList<QPointF> magnitudePoints() const;  // (w rad/s, |H| dB)
  QList<QPointF> phasePoints() const;      // (w rad/s, phase deg)
  // the step curves drawn: the outputs of the chosen output's group (all outputs of the plant;
  // of the closed loop, its measured outputs or its efforts), as (t s, y)
  const std::vector<int>& stepOutputs() const { return step_outputs_; }
  QList<QPointF> stepPoints(int output) const;  // empty when `output` is not drawn
  int stepSeriesCount() const;
  MatrixTableModel* gainModel() const { return gain_model_; }
  ModeTableModel* poleModel() const { return pole_model_; }
  QLabel* statusLabel() const { return status_; }
  // the chosen system's poles and the chosen pair's transmission zeros
  PoleMap* poleZeroMap() const { return pz_map_; }

  // The frequency response of the nonlinear plant (Estimate). Starts study_freqresp_job on the
  // document's model (analysing first when there is no result or it is out of date) at the
  // amplitude and frequencies typed (empty: the job's 0.01, and 10 frequencies over the middle
  // of the Bode plot's range); false (the reason in freqStatusLabel(), red) when a field does not
  // read, the model does not analyse, or an estimate is running. The job's own refusals and
  // failures come with estimateFinished().
  bool estimate();
  void cancelEstimate();
  bool isEstimating() const { return freq_job_.isRunning(); }
  // the last estimate (null before the first, while one runs, after one that failed or was
  // cancelled, New and Open)
  const codyna::FreqRespJob* freqResp() const { return freq_.get(); }
  QLineEdit* amplitudeEdit() const { return amplitude_edit_; }
  QLineEdit* frequenciesEdit() const { return frequencies_edit_; }
  QPushButton* estimateButton() const { return estimate_button_; }
  QPushButton* cancelEstimateButton() const { return cancel_button_; }
  QProgressBar* estimateProgress() const { return estimate_progress_; }
  QLabel* freqStatusLabel() const { return freq_status_; }
  // the estimate's points drawn for the chosen pair: (w rad/s, |G| dB) and (w rad/s, phase deg,
  // on the linear curve's branch); empty when the closed loop is shown or there is no estimate
  QList<QPointF> nonlinearMagnitudePoints() const;
  QList<QPointF> nonlinearPhasePoints() const;
  // the frequencies Estimate uses when the field is empty (rad/s; empty before Analyse)
  std::vector<double> defaultEstimateFrequencies() const;

 signals:
  void message(const QString& text);
  void estimateFinished();

 private:
  void buildUi();
  void fillPairs();  // input and output names of the chosen system
  void redraw();     // the chosen pair's Bode and step curves, poles and zeros
  void updateStaleness();
  void onEstimated(std::shared_ptr<const codyna::FreqRespJob> job, const JobOutcome& out);
  void setFreqStatus(const QString& text, bool error);
  void updateEstimateButtons();

  Document* doc_;
  std::shared_ptr<const codyna::Model> model_;  // the model the results belong to
  std::optional<codyna::ControlJob> job_;

  QPushButton* analyse_button_ = nullptr;
  QLabel* status_ = nullptr;
  QLabel* stale_ = nullptr;
  QComboBox* system_combo_ = nullptr;
  QComboBox* input_combo_ = nullptr;
  QComboBox* output_combo_ = nullptr;
  QTableView* gain_view_ = nullptr;
  MatrixTableModel* gain_model_ = nullptr;
  QTableView* pole_view_ = nullptr;
  ModeTableModel* pole_model_ = nullptr;
  QChart* mag_chart_ = nullptr;
  QChart* phase_chart_ = nullptr;
  QChart* step_chart_ = nullptr;
  PoleMap* pz_map_ = nullptr;
  QLineSeries* mag_series_ = nullptr;
  QLineSeries* phase_series_ = nullptr;
  std::vector<QLineSeries*> step_series_;
  std::vector<int> step_outputs_;

  // the nonlinear plant's frequency response
  QLineEdit* amplitude_edit_ = nullptr;
  QLineEdit* frequencies_edit_ = nullptr;
  QPushButton* estimate_button_ = nullptr;
  QPushButton* cancel_button_ = nullptr;
  QProgressBar* estimate_progress_ = nullptr;
  QLabel* freq_status_ = nullptr;
  QScatterSeries* mag_points_ = nullptr;
  QScatterSeries* phase_points_ = nullptr;
  std::shared_ptr<const codyna::FreqRespJob> freq_;
  std::shared_ptr<const codyna::Model> freq_model_;  // the model the estimate belongs to
  QTimer* timer_ = nullptr;
  std::atomic<int> runs_started_{0};
  std::atomic<double> run_t_{0}, run_t_end_{0};
  int runs_total_ = 0, freq_nu_ = 0;
  bool drop_estimate_ = false;
  JobThread freq_job_{this, QStringLiteral("codyna-freqresp")};  // last: joined before the other members go
};

}  // namespace codyna::gui
