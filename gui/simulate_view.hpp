// SimulateView: the "Simulate" page of codyna-gui.
//
// Settings (all in the Document, undoable, refreshed from it):
//   controller  none (open loop) / the model file's controller (its
//               description; a PID's Kp, Ki, Kd editable as Plant/In x Plant/Out
//               tables, written to ModelSpec::controller) / a .mat file (K,
//               Kp/Ki/Kd or Ac..Dc; relative to the model file) / the built-in
//               LQR with the diagonals of Q and R        -> StudySpec::controller...
//   solver      end time, output step, integrator, rtol, atol -> SolverSpec
//   compare with the linear closed loop                  -> StudySpec::compare_linear
//   export the linear closed loop with the plant          -> StudySpec::closed_loop.enabled
//   LQR on the controllable part only                     -> StudySpec::lqr_controllable_part
//   PID anti-windup (none, back_calculation, conditional)
//               and its tracking time                     -> StudySpec::anti_windup, tracking_time
//   references r(t) on Plant/Out, disturbances d(t) on the other actuators
//               (step, ramp, sine, table, file; SignalTable, under the plots)
//                                                         -> StudySpec::references, disturbances
// The last five go through Document::setStudyChecked: what the core's reader or
// study_model refuses is refused here with the core's message.
//
// Run starts a SimWorker (study_simulate_job, as codyna simulate runs it, on a worker
// thread, the code of `codyna simulate`) on the document's current model; the
// progress bar and the live plots (ResultPlots, Plant/In = the model's
// plant_inputs columns of u) follow its batches; at the end the full (or
// partial) result is shown with setResult() and a status line (completed /
// cancelled at t = / failed: reason; steps; wall time). Save results (HDF5
// .h5, CSV .csv, core's writers) and Save plot (PNG / SVG).
#pragma once

#include <QString>
#include <QWidget>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "model/model.hpp"
#include "study/workflow.hpp"
#include "gui/sim_worker.hpp"

QT_BEGIN_NAMESPACE
class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QFormLayout;
class QLineEdit;
class QProgressBar;
class QPushButton;
class QTabWidget;
class QStackedWidget;
class QTableWidget;
QT_END_NAMESPACE

namespace codyna::gui {

class Document;
class ResultPlots;
class SignalPlot;
class NameValueTable;
class SignalTable;

class SimulateView : public QWidget {
  Q_OBJECT
 public:
  explicit SimulateView(Document* doc, QWidget* parent = nullptr);
  ~SimulateView() override;

  // Starts a run of the document's current model (no-op while running; a model
  // that does not compile is reported through message()).
  void run();
  // Asks a running simulation to stop (its partial result arrives with runFinished).
  void cancel();
  bool isRunning() const;

  // The last run's result (partial when cancelled or failed in the solver), or null
  // (no run yet, or the last run's setup failed).
  std::shared_ptr<const codyna::SimulationResult> result() const { return result_; }
  // The model the last run simulated (for playback: result()->q belongs to it).
  std::shared_ptr<const codyna::Model> resultModel() const { return result_model_; }
  ResultPlots* plots() const { return plots_; }
  SignalPlot* signalPlot() const { return signal_plot_; }
  NameValueTable* initialStateTable() const { return initial_; }
  QComboBox* startCombo() const { return start_; }
  // isStale(): the document's model changed since the run (the results stay, marked).
  bool isStale() const;
  // Forgets the result (the document now holds another model); a running simulation is cancelled.
  void clearResult();
  QPushButton* saveResultsButton() const { return save_results_; }
  SimWorker* worker() const { return worker_; }

  // HDF5 (.h5, .hdf5) or CSV (.csv) by suffix, through core's writers.
  bool saveResults(const QString& path, QString* error = nullptr);
  // PNG or SVG by suffix (ResultPlots::saveImage).
  bool savePlot(const QString& path, QString* error = nullptr);

  QString statusText() const;

  // The widgets, for the main window and tests.
  QComboBox* controllerCombo() const { return controller_combo_; }
  QLabel* controllerDescription() const { return controller_desc_; }
  QTableWidget* pidTable() const { return pid_table_; }  // rows Plant/In, columns Kp | Ki | Kd per Plant/Out
  QLineEdit* controllerFileEdit() const { return file_edit_; }
  QLineEdit* qWeightsEdit() const { return q_weights_; }
  QLineEdit* rWeightsEdit() const { return r_weights_; }
  QDoubleSpinBox* endTimeSpin() const { return t_end_; }
  QDoubleSpinBox* outputStepSpin() const { return output_step_; }
  QComboBox* integratorCombo() const { return integrator_; }
  QLineEdit* rtolEdit() const { return rtol_; }
  QLineEdit* atolEdit() const { return atol_; }
  QLineEdit* maxStepEdit() const { return max_step_; }
  QCheckBox* alfFixedCheck() const { return alf_fixed_; }
  QCheckBox* alfExtrapolateCheck() const { return alf_extrapolate_; }
  QLineEdit* alfPenaltyEdit() const { return alf_penalty_; }
  QLineEdit* alfIterationsEdit() const { return alf_iterations_; }
  QCheckBox* compareLinearCheck() const { return compare_linear_; }
  SignalTable* referencesTable() const { return references_; }      // one row per Plant/Out followed
  SignalTable* disturbancesTable() const { return disturbances_; }  // actuators that are not Plant/In
  QComboBox* antiWindupCombo() const { return anti_windup_; }
  QDoubleSpinBox* trackingTimeSpin() const { return tracking_time_; }
  QCheckBox* lqrControllablePartCheck() const { return lqr_controllable_; }
  QCheckBox* closedLoopCheck() const { return closed_loop_; }
  QPushButton* runButton() const { return run_button_; }
  QPushButton* cancelButton() const { return cancel_button_; }
  QProgressBar* progressBar() const { return progress_; }

 signals:
  void runStarted();
  void runningChanged(bool running);  // Run/Cancel availability (the window's actions follow it)
  // result null: the setup failed (message() says why)
  void runFinished(std::shared_ptr<const codyna::SimulationResult> result);
  void message(const QString& text);

 private:
  void buildUi();
  void refreshFromDocument();
  void refreshController();
  void refreshSignals();  // targets offered and the study's references and disturbances
  void signalsEdited(bool references, bool number);  // number: a spin box stepped (merged undo steps)
  // setStudyChecked: the core's refusal goes to message() and the widgets show the study again
  void writeStudyChecked(const std::function<void(codyna::StudySpec&)>& change, const QString& text, int mergeKey = -1);
  void writeStudy(const std::function<void(codyna::StudySpec&)>& change, const QString& text, int mergeKey = -1);
  void writeSolver(const std::function<void(codyna::SolverSpec&)>& change, const QString& text, int mergeKey = -1);
  void pidEdited(int row, int column);
  void browseControllerFile();
  void weightsEdited(bool q);
  // a number field of the solver section (rtol, atol, the maximum step, alf's penalty and
  // iterations): its kind, whether empty is allowed (write gets nullopt), where it goes
  struct NumberRule {
    enum Kind { Positive, NonNegative, Count };
    QLineEdit* edit;  // (its form row's label names it in a refusal)
    QString expected;
    Kind kind;
    bool empty_allowed;
    std::function<void(codyna::SolverSpec&, std::optional<double>)> write;
    QString undo_text;
  };
  void solverNumberEdited(const NumberRule& r);
  void onSamples(const SampleBatch& batch);
  void onProgress(double t, double tEnd);
  void onFinished(std::shared_ptr<const codyna::SimulationResult> r);
  void onFailed(const QString& why);
  void setRunning(bool running);
  void restorePlotLimit();
  void saveResultsDialog();
  void updateStaleness();
  void refreshInitialChoices();
  void savePlotDialog();

  Document* doc_;
  SimWorker* worker_ = nullptr;
  ResultPlots* plots_ = nullptr;
  SignalPlot* signal_plot_ = nullptr;
  NameValueTable* initial_ = nullptr;
  QComboBox* start_ = nullptr;
  QTabWidget* plot_tabs_ = nullptr;
  std::shared_ptr<const codyna::SimulationResult> result_;
  std::shared_ptr<const codyna::Model> result_model_;  // the model of the run (current or last)
  std::vector<int> plant_inputs_;                      // of result_model_
  bool syncing_ = false;
  bool live_limit_ = false;      // plots at the live point limit (a run is going)
  int final_plot_points_ = 0;    // the plots' own limit, restored at the end of a run
  QString status_;

  QComboBox* controller_combo_ = nullptr;
  QStackedWidget* controller_pages_ = nullptr;
  QLabel* controller_desc_ = nullptr;
  QTableWidget* pid_table_ = nullptr;
  QLineEdit* file_edit_ = nullptr;
  QPushButton* file_browse_ = nullptr;
  QLineEdit* q_weights_ = nullptr;
  QLineEdit* r_weights_ = nullptr;
  QLabel* lqr_hint_ = nullptr;
  QDoubleSpinBox* t_end_ = nullptr;
  QDoubleSpinBox* output_step_ = nullptr;
  QComboBox* integrator_ = nullptr;
  std::vector<NumberRule> solver_numbers_;
  QFormLayout* solver_form_ = nullptr;  // the solver section's form (its rows' labels)
  QLineEdit* rtol_ = nullptr;
  QLineEdit* atol_ = nullptr;
  QLineEdit* max_step_ = nullptr;
  QCheckBox* alf_fixed_ = nullptr;
  QCheckBox* alf_extrapolate_ = nullptr;
  QLineEdit* alf_penalty_ = nullptr;
  QLineEdit* alf_iterations_ = nullptr;
  QCheckBox* compare_linear_ = nullptr;
  QCheckBox* closed_loop_ = nullptr;
  QCheckBox* lqr_controllable_ = nullptr;
  QComboBox* anti_windup_ = nullptr;
  QDoubleSpinBox* tracking_time_ = nullptr;
  SignalTable* references_ = nullptr;
  SignalTable* disturbances_ = nullptr;
  QPushButton* run_button_ = nullptr;
  QPushButton* cancel_button_ = nullptr;
  QPushButton* save_results_ = nullptr;
  QLabel* stale_label_ = nullptr;
  bool discard_run_ = false;  // the running simulation's model was replaced: drop what it delivers
  QPushButton* save_plot_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QLabel* status_label_ = nullptr;
};

}  // namespace codyna::gui
