#include "gui/autosave.hpp"

#include <QCoreApplication>
#include <QDateTime>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QJsonDocument>
#include <QJsonObject>
#include <QSaveFile>
#include <QStandardPaths>
#include <algorithm>
#include <nlohmann/json.hpp>

#include "gui/document.hpp"
#include "study/files.hpp"

namespace codyna::gui {

Autosave::Autosave(Document* doc, QObject* parent) : QObject(parent), doc_(doc) {
  timer_.setSingleShot(true);
  timer_.setInterval(1000);
  connect(&timer_, &QTimer::timeout, this, &Autosave::writeNow);
  connect(doc_, &Document::specChanged, this, [this] { timer_.start(); });
  connect(doc_, &Document::fileChanged, this, [this] {
    if (!doc_->isModified()) remove();  // saved, or a new or opened document
  });
}

Autosave::~Autosave() = default;

QString Autosave::directory() {
  return QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation) + QStringLiteral("/recovery");
}

QString Autosave::file() const {
  return directory() + QStringLiteral("/recovery-%1.json").arg(QCoreApplication::applicationPid());
}

void Autosave::remove() {
  timer_.stop();
  QFile::remove(file());
}

void Autosave::writeNow() {
  timer_.stop();
  if (!doc_->isModified()) {
    remove();
    return;
  }
  QDir().mkpath(directory());
  // the model as its file would hold it, wrapped with where it came from
  nlohmann::json j;
  j["codyna_recovery"] = 1;
  j["file"] = ss(doc_->filePath());
  j["saved"] = ss(QDateTime::currentDateTimeUtc().toString(Qt::ISODate));
  j["pid"] = QCoreApplication::applicationPid();
  j["model"] = study_model_json(doc_->spec());
  QSaveFile out(file());
  if (!out.open(QIODevice::WriteOnly)) return;  // nowhere to write: editing goes on
  out.write(QByteArray::fromStdString(j.dump(1)));
  out.commit();
}

QList<Autosave::Recovered> Autosave::orphans() {
  QList<Recovered> out;
  const QDir dir(directory());
  for (const QFileInfo& f : dir.entryInfoList({QStringLiteral("recovery-*.json")}, QDir::Files, QDir::Time)) {
    bool ok = false;
    const qint64 pid = f.completeBaseName().section('-', 1).toLongLong(&ok);
    if (!ok || pid == QCoreApplication::applicationPid()) continue;
    if (QFileInfo::exists(QStringLiteral("/proc/%1").arg(pid))) continue;  // that codyna still runs
    QFile in(f.absoluteFilePath());
    if (!in.open(QIODevice::ReadOnly)) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in.readAll().toStdString());
    } catch (const std::exception&) {
      continue;  // not ours or cut short: left alone
    }
    if (!j.is_object() || !j.contains("model") || !j.contains("codyna_recovery")) continue;
    Recovered r;
    r.recovery_file = f.absoluteFilePath();
    r.model_file = j.contains("file") && j["file"].is_string() ? qs(j["file"].get<std::string>()) : QString();
    r.saved_at = j.contains("saved") && j["saved"].is_string() ? qs(j["saved"].get<std::string>()) : QString();
    r.model_json = QByteArray::fromStdString(j["model"].dump());
    out << r;
  }
  return out;
}

}  // namespace codyna::gui
