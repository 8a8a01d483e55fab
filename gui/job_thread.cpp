#include "gui/job_thread.hpp"

#include <QMetaObject>
#include <QObject>
#include <QThread>
#include <exception>

#include "gui/document.hpp"

namespace codyna::gui {

JobThread::JobThread(QObject* owner, QString name) : owner_(owner), name_(std::move(name)) {}

JobThread::~JobThread() {
  if (!thread_) return;
  cancel_.store(true);
  thread_->wait();
  delete thread_;
}

bool JobThread::start(Work work, std::function<void(const JobOutcome&)> done) {
  if (running_) return false;
  if (thread_) {
    thread_->wait();
    delete thread_;
    thread_ = nullptr;
  }
  cancel_.store(false);
  running_ = true;
  thread_ = QThread::create([this, work = std::move(work), done = std::move(done)] {
    JobOutcome out;
    const StudyMessages tell = [&out](const StudyMessage& m) {
      out.notes << (m.kind == StudyMessage::Warning ? QStringLiteral("warning: ") : QString()) + qs(m.text);
    };
    try {
      work(cancel_, tell);
    } catch (const StudyCancelled& e) {
      out.cancelled = true;
      out.error = qs(e.what());
    } catch (const std::exception& e) {
      out.error = qs(e.what());
    } catch (...) {
      out.error = QStringLiteral("the job failed (unknown error)");
    }
    QMetaObject::invokeMethod(
        owner_,
        [this, done, out] {
          running_ = false;
          done(out);
        },
        Qt::QueuedConnection);
  });
  thread_->setObjectName(name_);
  thread_->start();
  return true;
}

void JobThread::cancel() {
  if (running_) cancel_.store(true);
}

}  // namespace codyna::gui
