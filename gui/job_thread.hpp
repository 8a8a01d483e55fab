// JobThread: a view's Run and Cancel for one study job at a time (a sweep, a maneuver, a frequency
// response), on a thread of its own so that the window never waits for the core.
//
// Threading contract
//   - start(), cancel(), isRunning() and the `done` callback belong to the owner's thread (the GUI
//     thread). `work` runs on the job's thread: it fills what it captured (its result) and never
//     touches a QObject of the GUI.
//   - cancel() sets the flag `work` is given (the core's jobs take it as their cancel); a job that
//     throws StudyCancelled ends with JobOutcome::cancelled.
//   - `done` is posted to the owner (queued), after the job's thread has let go of what it holds;
//     isRunning() is false by then. Destroying the JobThread (with its owner) cancels the job and
//     waits for it; what it posted is dropped with the owner.
#pragma once

#include <QString>
#include <QStringList>
#include <atomic>
#include <functional>

#include "study/jobs.hpp"

class QObject;
class QThread;

namespace codyna::gui {

struct JobOutcome {
  QString error;       // what the job threw (empty: it finished), StudyCancelled's words too
  QStringList notes;   // what it told, in its order ("warning: " before a warning)
  bool cancelled = false;
};

class JobThread {
 public:
  JobThread(QObject* owner, QString name);
  ~JobThread();
  JobThread(const JobThread&) = delete;
  JobThread& operator=(const JobThread&) = delete;

  using Work = std::function<void(const std::atomic<bool>& cancel, const StudyMessages& tell)>;
  // Starts `work` on a new thread (the last one's is joined first); false when one runs.
  bool start(Work work, std::function<void(const JobOutcome&)> done);
  void cancel();  // no-op when idle
  bool isRunning() const { return running_; }

 private:
  QObject* owner_;
  QString name_;
  QThread* thread_ = nullptr;
  std::atomic<bool> cancel_{false};
  bool running_ = false;
};

}  // namespace codyna::gui
