// Autosave: a crash, a kill -9 or a power cut loses at most the last second of
// editing. One second after the last change of a modified document its model
// (as the model file would hold it) is written atomically to a recovery file of
// this process, QStandardPaths::AppLocalDataLocation/recovery/recovery-PID.json,
// with the path of the file it came from. Saving, discarding on New/Open and a
// clean close remove it. At the next start, recovery files whose process is gone
// are offered back (MainWindow::offerRecovery): the model file is opened and the
// recovered edits are one undo step on top of it, unsaved; the model file
// itself is never written by the recovery.
#pragma once

#include <QObject>
#include <QString>
#include <QStringList>
#include <QTimer>

namespace codyna::gui {

class Document;

class Autosave : public QObject {
  Q_OBJECT
 public:
  explicit Autosave(Document* doc, QObject* parent = nullptr);
  ~Autosave() override;

  static QString directory();         // where recovery files go
  QString file() const;               // this process's recovery file
  void setDelayMs(int ms) { timer_.setInterval(ms); }
  void writeNow();                    // writes (modified) or removes (clean) at once
  void remove();                      // the document was saved or discarded

  struct Recovered {
    QString recovery_file;  // to remove once dealt with
    QString model_file;     // "" for an untitled model
    QString saved_at;       // ISO time of the autosave
    QByteArray model_json;  // the model as the model file would hold it
  };
  // Recovery files left by processes that are gone (crashed or killed), newest first.
  static QList<Recovered> orphans();

 private:
  Document* doc_;
  QTimer timer_;
};

}  // namespace codyna::gui
