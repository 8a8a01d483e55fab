#include "gui/sim_worker.hpp"

#include <exception>
#include <utility>

#include "study/jobs.hpp"
#include "study/workflow.hpp"

namespace codyna::gui {

SimWorker::SimWorker(QObject* parent) : QObject(parent) {
  qRegisterMetaType<codyna::gui::SampleBatch>("codyna::gui::SampleBatch");
  qRegisterMetaType<std::shared_ptr<const codyna::SimulationResult>>("std::shared_ptr<const codyna::SimulationResult>");
}

SimWorker::~SimWorker() {
  if (thread_) {
    cancel_.store(true);
    thread_->wait();  // what it posted to this object is dropped with it
    delete thread_;
  }
}

bool SimWorker::start(std::shared_ptr<const codyna::Model> model, const codyna::ModelSpec& file_spec, const std::string& file) {
  if (running_ || !model) return false;
  if (thread_) {  // the last run's thread has posted finished() and is about to end
    thread_->wait();
    delete thread_;
    thread_ = nullptr;
  }
  cancel_.store(false);
  integrator_thread_.store(nullptr);
  running_ = true;
  batches_ = 0;
  wall_time_ = 0;
  controller_source_.clear();
  notes_.clear();
  pending_.clear();
  last_t_ = 0;
  t_end_ = model->spec.solver.t_end;
  thread_ = QThread::create([this, spec = file_spec, file] { runJob(spec, file); });
  thread_->setObjectName(QStringLiteral("codyna-simulation"));
  emit started();
  thread_->start();
  return true;
}

void SimWorker::cancel() {
  if (running_) cancel_.store(true);
}

// ---- worker thread ----

void SimWorker::postBatch(bool force) {
  if (!force && since_post_.elapsed() < batch_ms_.load()) return;
  SampleBatch batch;
  batch.swap(pending_);
  const double t = last_t_, tEnd = t_end_;
  since_post_.restart();
  QMetaObject::invokeMethod(
      this,
      [this, batch = std::move(batch), t, tEnd] {
        ++batches_;
        if (!batch.isEmpty()) emit samples(batch);
        emit progress(t, tEnd);
      },
      Qt::QueuedConnection);
}

void SimWorker::runJob(const codyna::ModelSpec& spec, const std::string& file) {
  QElapsedTimer wall;
  wall.start();
  auto fail = [this](const QString& message) {
    QMetaObject::invokeMethod(
        this,
        [this, message] {
          running_ = false;
          emit failed(message);
        },
        Qt::QueuedConnection);
  };
  // the job codyna simulate runs: the study's model, controller and plant, the run, and what the
  // command line says of it (notes, warnings, saturation), decided there, shown here
  codyna::SimulateRequest request;
  request.model = file.empty() ? std::string("untitled.json") : file;
  // a run shown live: the study's limit for it (kShownRunMaxSamples)
  request.max_samples = codyna::kShownRunMaxSamples;
  codyna::SimulationCallbacks cb;
  cb.cancel = &cancel_;
  // record() in the simulator calls on_sample, then progress, for every output time
  cb.on_sample = [this](const codyna::Snapshot& s) { pending_.push_back(s); };
  cb.progress = [this](double t, double tEnd) {
    integrator_thread_.store(QThread::currentThread());
    last_t_ = t;
    t_end_ = tEnd;
    postBatch(false);
  };
  struct CancelledInSetup {};
  std::size_t warnings_before_run = 0;
  const auto ready = [&](const codyna::SimulateJob& job) {
    // a Cancel pressed while the setup ran takes effect here, before the run starts (a time=T
    // pre-run stops at its next step; the steady-state searches are short and run to their end)
    if (cancel_.load()) throw CancelledInSetup{};
    const QString source = QString::fromStdString(job.setup.controller_source);
    QStringList notes;
    for (const std::string& n : job.notes) notes << QString::fromStdString(n);
    if (job.setup.start != "model") notes << QStringLiteral("the run starts at the %1 point").arg(QString::fromStdString(job.setup.start));
    for (const std::string& w : job.warnings) notes << QStringLiteral("warning: %1").arg(QString::fromStdString(w));
    warnings_before_run = job.warnings.size();
    QMetaObject::invokeMethod(
        this,
        [this, source, notes] {
          controller_source_ = source;
          notes_ = notes;
          emit setupDone(source);
        },
        Qt::QueuedConnection);
    t_end_ = job.setup.options.t_end;
    last_t_ = job.setup.options.t0;
    since_post_.start();
  };

  codyna::SimulateJob job;
  try {
    job = codyna::study_simulate_job(request, spec, cb, ready);
  } catch (const CancelledInSetup&) {
    return fail(QStringLiteral("cancelled during the setup (operating point, controller design)"));
  } catch (const codyna::StudyCancelled&) {
    return fail(QStringLiteral("cancelled during the setup (the operating point's time=T run)"));
  } catch (const std::exception& e) {
    return fail(QString::fromStdString(e.what()));
  } catch (...) {
    return fail(QStringLiteral("the simulation failed (unknown error)"));
  }
  postBatch(true);  // the rest, before finished()
  const double seconds = wall.nsecsElapsed() * 1e-9;
  auto result = std::make_shared<const codyna::SimulationResult>(std::move(job.result));
  QStringList after;
  for (std::size_t k = warnings_before_run; k < job.warnings.size(); ++k)
    after << QStringLiteral("warning: %1").arg(QString::fromStdString(job.warnings[k]));
  for (const codyna::Saturation& s : job.saturation)
    after << QStringLiteral("saturation: %1").arg(QString::fromStdString(codyna::saturation_text(s)));
  QMetaObject::invokeMethod(
      this,
      [this, result, seconds, after] {
        wall_time_ = seconds;
        running_ = false;
        notes_ << after;
        emit finished(result);
      },
      Qt::QueuedConnection);
}

}  // namespace codyna::gui
