// A kill -9 during editing loses at most the last second: a child codyna-gui
// window (this program with --child) opens a copy of the cart-pendulum, a person
// types a new mass, the autosave writes; the parent kills the child with SIGKILL,
// starts a window of its own and is offered the recovered model with that edit,
// unsaved, one undo step above the file, which was never written.
#include <QDir>
#include <QFile>
#include <QLineEdit>
#include <QMessageBox>
#include <QProcess>
#include <QTemporaryDir>
#include <QTest>
#include <QThread>
#include <QUndoStack>
#include <iostream>
#include <nlohmann/json.hpp>

#include "gui/autosave.hpp"
#include "gui/main_window.hpp"
#include "gui/property_editor.hpp"
#include "io/model_file.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {
const QString kCart = QStringLiteral(CODYNA_EXAMPLES_DIR "/cart_pendulum.json");

void names() {
  QCoreApplication::setOrganizationName("codyna-test");
  QCoreApplication::setApplicationName("recovery_test");
}

// the child: edit, let the autosave write, say so, wait to be killed
int child(const QString& model) {
  MainWindow w;
  w.setQuestionHook([](const QString&, const QString&, int) { return int(QMessageBox::No); });
  w.show();
  if (!w.openFile(model)) return 3;
  w.selectElement(ElementId{ElementKind::Body, 1});
  auto* mass = qobject_cast<QLineEdit*>(w.propertyEditor()->editorFor("mass"));
  if (!mass) return 4;
  mass->setFocus();
  mass->selectAll();
  QTest::keyClicks(mass, "13.5");
  QTest::keyClick(mass, Qt::Key_Return);
  if (w.document()->spec().bodies[1].mass != 13.5) return 5;
  if (!QTest::qWaitFor([&] { return QFile::exists(w.autosave()->file()); }, 10000)) return 6;
  std::cout << "READY " << w.autosave()->file().toStdString() << std::endl;
  for (;;) QTest::qWait(100);  // until SIGKILL
}
}  // namespace

class RecoveryTest : public QObject {
  Q_OBJECT
 private slots:
  void killedWhileEditingIsRecovered() {
    QTemporaryDir tmp;
    const QString model = tmp.filePath("cart.json");
    QVERIFY(QFile::copy(kCart, model));
    QFile::setPermissions(model, QFile::ReadOwner | QFile::WriteOwner);
    const QByteArray before = [&] { QFile f(model); f.open(QIODevice::ReadOnly); return f.readAll(); }();
    // nothing left from an earlier run in this scratch data folder
    QVERIFY(Autosave::orphans().isEmpty());

    QProcess c;
    c.setProcessChannelMode(QProcess::ForwardedErrorChannel);
    c.start(QCoreApplication::applicationFilePath(), {"--child", model});
    QVERIFY(c.waitForStarted());
    QVERIFY2(QTest::qWaitFor([&] { return c.canReadLine() || c.state() == QProcess::NotRunning; }, 60000), "child never ready");
    const QString line = QString::fromUtf8(c.readLine()).trimmed();
    QVERIFY2(line.startsWith("READY "), qPrintable("child said: " + line + " exit " + QString::number(c.exitCode())));
    const QString recovery = line.mid(6);
    QVERIFY(QFile::exists(recovery));
    c.kill();  // SIGKILL: no close event, no clean-up
    QVERIFY(c.waitForFinished(10000));
    QCOMPARE(c.exitStatus(), QProcess::CrashExit);
    QVERIFY(QFile::exists(recovery));

    // the next start
    MainWindow w;
    QStringList asked;
    w.setQuestionHook([&](const QString& title, const QString&, int) {
      asked << title;
      return int(QMessageBox::Yes);
    });
    w.show();
    QVERIFY(w.offerRecovery());
    QCOMPARE(asked, QStringList{"Recover unsaved work"});
    QCOMPARE(w.document()->spec().bodies[1].mass, 13.5);
    QCOMPARE(w.document()->filePath(), QFileInfo(model).absoluteFilePath());
    QVERIFY(w.document()->isModified());
    QVERIFY(!QFile::exists(recovery));  // dealt with; this process autosaves its own now
    QVERIFY(QFile::exists(w.autosave()->file()));
    // the model file was never written
    QFile f(model);
    QVERIFY(f.open(QIODevice::ReadOnly));
    QCOMPARE(f.readAll(), before);
    // the recovered edits are one undo step above the saved file
    w.document()->undoStack()->undo();
    QCOMPARE(w.document()->spec().bodies[1].mass, 10.0);
    QVERIFY(!w.document()->isModified());
    QVERIFY(!QFile::exists(w.autosave()->file()));  // clean again: nothing to recover
    QVERIFY(Autosave::orphans().isEmpty());
  }

  void declinedRecoveryIsForgotten() {
    QTemporaryDir tmp;
    const QString model = tmp.filePath("cart.json");
    QVERIFY(QFile::copy(kCart, model));
    // a recovery file of a process that is gone (pid 1 is never a codyna of this user's data folder;
    // use a pid that cannot exist)
    QDir().mkpath(Autosave::directory());
    const QString stale = Autosave::directory() + "/recovery-999999999.json";
    QFile out(stale);
    QVERIFY(out.open(QIODevice::WriteOnly));
    out.write(QByteArray("{\"codyna_recovery\": 1, \"file\": \"") + model.toUtf8() + "\", \"saved\": \"x\", \"model\": " +
              QByteArray::fromStdString(to_json(load_model_spec(model.toStdString())).dump()) + "}");
    out.close();
    MainWindow w;
    w.setQuestionHook([](const QString&, const QString&, int) { return int(QMessageBox::No); });
    QVERIFY(!w.offerRecovery());
    QVERIFY(!QFile::exists(stale));
    QVERIFY(w.document()->spec().bodies.empty());
  }
};

int main(int argc, char** argv) {
  // a scratch data folder (recovery files) shared by the parent and its child
  static QTemporaryDir* data = nullptr;
  if (qEnvironmentVariableIsEmpty("CODYNA_RECOVERY_TEST_DATA")) {
    data = new QTemporaryDir;
    qputenv("CODYNA_RECOVERY_TEST_DATA", data->path().toLocal8Bit());
  }
  qputenv("XDG_DATA_HOME", qgetenv("CODYNA_RECOVERY_TEST_DATA"));
  QApplication app(argc, argv);
  names();
  if (argc == 3 && QString(argv[1]) == "--child") return child(QString::fromLocal8Bit(argv[2]));
  RecoveryTest t;
  const int rc = QTest::qExec(&t, argc, argv);
  delete data;
  return rc;
}

#include "recovery_test.moc"
