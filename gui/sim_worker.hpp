// SimWorker: runs one simulate job (study/jobs.hpp: study_simulate_job, the job `codyna simulate`
// and Python run, whose report the window shows) on its own QThread, so the GUI thread never
// waits for the integrator.
//
// Threading contract
//   - start(), cancel(), isRunning() and every signal belong to the thread that
//     owns the SimWorker (the GUI thread). The integrator thread never touches
//     a QObject of the GUI: it only fills a buffer and posts queued calls.
//   - The model is shared (std::shared_ptr<const Model>) and immutable, so the
//     document may change meanwhile: the run keeps the model it started with.
//   - Samples are batched: at most one samples() + progress() emission every
//     batchIntervalMs() (50 ms), never one queued call per integrator sample.
//     The last batch always arrives before finished().
//   - cancel() is cooperative (an atomic flag the simulator hands the integrators: they stop
//     inside their step); the partial result comes with finished() (cancelled = true).
//   - A setup that throws (unknown controller file, no equilibrium for the LQR,
//     wrong weights, ...) or a run that throws is reported by failed(text); then
//     finished() is not emitted. isRunning() is false before either signal.
//   - Destroying a running SimWorker cancels the run and waits for its thread.
#pragma once

#include <QElapsedTimer>
#include <QMetaType>
#include <QObject>
#include <QString>
#include <QStringList>
#include <QThread>

#include "model/model_spec.hpp"
#include <QVector>
#include <atomic>
#include <memory>

#include "model/model.hpp"
#include "study/workflow.hpp"

namespace codyna::gui {

// Output samples of the integrator, in time order (copies, owned by the batch).
using SampleBatch = QVector<codyna::Snapshot>;

class SimWorker : public QObject {
  Q_OBJECT
 public:
  explicit SimWorker(QObject* parent = nullptr);
  ~SimWorker() override;

  // Starts a run of the study of `file_spec` (the model file as the document holds it, its
  // analysis and solver sections) through the job codyna simulate runs (study_simulate_job);
  // `model` is its compiled study model (the document's), `file` the model file's path ("" when
  // unsaved). Returns false (and does nothing) when a run is still going or the model is null.
  bool start(std::shared_ptr<const codyna::Model> model, const codyna::ModelSpec& file_spec, const std::string& file);
  // Asks the running integrator to stop at its next output time; no-op when idle.
  void cancel();
  bool isRunning() const { return running_; }
  bool cancelRequested() const { return cancel_.load(); }

  // The thread of the current (or last) run, null before the first run.
  QThread* workerThread() const { return thread_; }
  // The thread the integrator's progress callback ran on in the last run (for tests).
  QThread* integratorThread() const { return integrator_thread_.load(); }

  // What the last run's setup chose ("lqr", "the model file's pid controller", ...).
  QString controllerSource() const { return controller_source_; }
  // What the last run's job says the user should know, in codyna simulate's words: its notes
  // (an LQR on the controllable part names the modes it leaves as they are) before setupDone(),
  // then its warnings ("warning: ..." : an unstable linear closed loop, a run that left the
  // linear region) and the actuators that sat at a limit, before finished().
  QStringList notes() const { return notes_; }
  // Wall time of the last run, setup included (seconds).
  double wallTime() const { return wall_time_; }
  // How many samples() emissions the last run made (for the benchmark and tests).
  int batchCount() const { return batches_; }

  int batchIntervalMs() const { return batch_ms_.load(); }
  void setBatchIntervalMs(int ms) { batch_ms_.store(ms < 1 ? 1 : ms); }

 signals:
  void started();
  // setup done (controller designed, plant linearized): the integrator starts now
  void setupDone(const QString& controllerSource);
  void progress(double t, double tEnd);
  void samples(const codyna::gui::SampleBatch& batch);
  // completed, cancelled (partial) or failed in the solver (partial, result->failure says why)
  void finished(std::shared_ptr<const codyna::SimulationResult> result);
  // the setup or the run threw: no result
  void failed(const QString& message);

 private:
  void runJob(const codyna::ModelSpec& spec, const std::string& file);  // on the worker thread
  void postBatch(bool force);                              // on the worker thread

  QThread* thread_ = nullptr;
  std::atomic<bool> cancel_{false};
  std::atomic<QThread*> integrator_thread_{nullptr};
  bool running_ = false;
  std::atomic<int> batch_ms_{50};  // read by the worker thread
  int batches_ = 0;
  double wall_time_ = 0;
  QString controller_source_;
  QStringList notes_;

  // worker-thread side of the batching (only the worker thread touches these during a run)
  SampleBatch pending_;
  double last_t_ = 0, t_end_ = 0;
  QElapsedTimer since_post_;
};

}  // namespace codyna::gui

Q_DECLARE_METATYPE(codyna::Snapshot)
Q_DECLARE_METATYPE(std::shared_ptr<const codyna::SimulationResult>)
