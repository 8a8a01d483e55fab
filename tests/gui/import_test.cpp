// File > Import in codyna-gui (issue 20), driven through the real menu action offscreen: the
// file dialog is answered by the window's file hook and the report dialog by its question hook
// (tests/gui/drive.hpp's pattern), so the test reads what the dialog shows.
//   - a URDF imported: a new, unsaved document without a file (title untitled*), the report shown,
//     the bodies the core's study_import gives, Linearize works on it, Save asks for a name and
//     the URDF is not written;
//   - MuJoCo's slider_crank.xml (libmujoco-samples, when installed): refused for its slider-crank
//     transmissions, the dialog names them and offers --ignore actuators; "No" keeps the open
//     document, "Yes" imports it without them;
//   - malformed files (MJCF, URDF) and a missing one: a message naming the file and the element,
//     the document as it was.
#include <QApplication>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QPlainTextEdit>
#include <QTimer>
#include <QCryptographicHash>
#include <QFile>
#include <QMessageBox>
#include <QPushButton>
#include <QTemporaryDir>
#include <QTest>

#include "gui/linearize_view.hpp"
#include "gui/main_window.hpp"
#include "study/import.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {
const QString kData = QStringLiteral(CODYNA_TEST_DATA_DIR "/import/");
const QString kSliderCrank = QStringLiteral("/usr/share/mujoco/model/slider_crank/slider_crank.xml");

QByteArray sha(const QString& path) {
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly)) return {};
  return QCryptographicHash::hash(f.readAll(), QCryptographicHash::Sha256);
}
}  // namespace

class ImportTest : public QObject {
  Q_OBJECT
 private:
  std::unique_ptr<MainWindow> w;
  QTemporaryDir tmp;
  struct Asked {
    QString title, text;
  };
  QList<Asked> asked;
  int answer = QMessageBox::Ok;
  QString import_path, save_path;
  QStringList file_titles;

  // File > Import..., the dialog answered with `path`
  void importByMenu(const QString& path) {
    import_path = path;
    QVERIFY(w->importAction());
    w->importAction()->trigger();
  }
  QString lastText(const QString& title) const {
    for (auto it = asked.rbegin(); it != asked.rend(); ++it)
      if (it->title == title) return it->text;
    return {};
  }

 private slots:
  void init() {
    QCoreApplication::setOrganizationName("codyna-test");
    QCoreApplication::setApplicationName("import_test");
    asked.clear();
    file_titles.clear();
    answer = QMessageBox::Ok;
    w = std::make_unique<MainWindow>();
    w->setQuestionHook([this](const QString& title, const QString& text, int) {
      asked << Asked{title, text};
      if (title == "Unsaved changes") return int(QMessageBox::Discard);
      return answer;
    });
    w->setFileHook([this](const QString& title, const QString&, const QString&, bool save) {
      file_titles << title;
      return save ? save_path : import_path;
    });
    w->show();
    QVERIFY(QTest::qWaitForWindowExposed(w.get()));
  }
  void cleanup() {
    w->document()->undoStack()->setClean();
    w.reset();
  }

  void urdfOpensAsANewUnsavedModel() {
    const QString urdf = kData + "double_pendulum.urdf";
    const QByteArray before = sha(urdf);
    importByMenu(urdf);
    QCOMPARE(file_titles.value(0), QString("Import model"));
    // the report dialog: what mapped, as `codyna import` prints it
    const QString report = lastText("Import report");
    QVERIFY2(!report.isEmpty(), "no import report shown");
    QVERIFY2(report.contains("double_pendulum.urdf was imported as a new, unsaved model"), qPrintable(report));
    QVERIFY2(report.contains("read " + urdf + " (URDF, by urdfdom)"), qPrintable(report));
    QVERIFY2(report.contains("2 links -> bodies"), qPrintable(report));
    QVERIFY2(report.contains("plant: every actuator as Plant/In (2), every joint coordinate as Plant/Out (2)"), qPrintable(report));
    // the document: the core's import, no file, modified
    const ImportResult ref = study_import(urdf.toStdString());
    Document* d = w->document();
    QCOMPARE(d->spec().bodies.size(), ref.spec.bodies.size());
    QCOMPARE(d->spec().bodies.size(), std::size_t(2));
    QCOMPARE(d->spec().joints.size(), std::size_t(2));
    QVERIFY(d->filePath().isEmpty());
    QVERIFY(d->isModified());
    QVERIFY(w->isWindowModified());
    QVERIFY2(w->windowTitle().startsWith("untitled"), qPrintable(w->windowTitle()));
    QVERIFY(d->model());
    QCOMPARE(d->model()->dof(), 2);
    // Linearize works on it at once: every joint a Plant/Out, every actuator a Plant/In
    LinearizeView* lv = w->linearizeView();
    lv->operatingPointCombo()->setCurrentIndex(lv->operatingPointCombo()->findText("initial", Qt::MatchContains));
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    QCOMPARE(lv->result()->system.A.rows(), 4);
    QCOMPARE(lv->result()->system.nu(), 2);
    QCOMPARE(lv->result()->system.ny(), 2);
    // hanging at rest: the first joint's stiffness row, A(2,0) = -13.3773 (docs/import.md)
    QVERIFY2(std::abs(lv->result()->system.A(2, 0) - -13.3773) < 1e-4, qPrintable(QString::number(lv->result()->system.A(2, 0))));
    // Save asks for a name (never the URDF); the URDF is unchanged
    save_path = tmp.filePath("dp.json");
    QVERIFY(w->saveFile());
    QCOMPARE(file_titles.value(1), QString("Save model as"));
    QCOMPARE(d->filePath(), QFileInfo(save_path).absoluteFilePath());
    QVERIFY(!d->isModified());
    QCOMPARE(sha(urdf), before);
  }

  void sliderCrankRefusedThenImportedIgnoringItsTransmissions() {
    if (!QFile::exists(kSliderCrank)) QSKIP("libmujoco-samples not installed");
    // a document open before: "No" keeps it
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/pendulum.json")));
    answer = QMessageBox::No;
    importByMenu(kSliderCrank);
    const QString refused = lastText("Import refused");
    QVERIFY2(!refused.isEmpty(), "no refusal shown");
    QVERIFY2(refused.contains("slider_crank.xml holds elements that change the dynamics"), qPrintable(refused));
    QVERIFY2(refused.contains("(as codyna import --ignore actuators)?"), qPrintable(refused));
    QVERIFY2(refused.contains("forward (slider-crank transmission)"), qPrintable(refused));
    QVERIFY(w->document()->filePath().endsWith("pendulum.json"));
    QCOMPARE(w->document()->spec().name, std::string("pendulum"));
    // "Yes": imported again with --ignore actuators
    answer = QMessageBox::Yes;
    importByMenu(kSliderCrank);
    const QString report = lastText("Import report");
    QVERIFY2(report.contains("actuators (changes the dynamics; ignored by --ignore actuators)"), qPrintable(report));
    ImportOptions o;
    o.ignore.insert("actuators");
    const ImportResult ref = study_import(kSliderCrank.toStdString(), o);
    Document* d = w->document();
    QVERIFY(d->filePath().isEmpty());
    QVERIFY(d->isModified());
    QCOMPARE(d->spec().bodies.size(), ref.spec.bodies.size());
    QCOMPARE(d->spec().joints.size(), std::size_t(3));
    QVERIFY(d->spec().actuators.empty());
    QVERIFY(d->model());
    QCOMPARE(d->model()->dof(), 3);
    LinearizeView* lv = w->linearizeView();
    lv->operatingPointCombo()->setCurrentIndex(lv->operatingPointCombo()->findText("initial", Qt::MatchContains));
    QTest::mouseClick(lv->linearizeButton(), Qt::LeftButton);
    QVERIFY(lv->result());
    QCOMPARE(lv->result()->system.A.rows(), 6);
    QVERIFY(lv->result()->system.A.allFinite());
  }

  void theReportDialogItself() {
    // without the question hook: the real dialog, read and closed as a person would
    w->setQuestionHook(nullptr);
    QString shown, title;
    bool closed = false;
    QTimer::singleShot(0, this, [&] {
      QDialog* dlg = nullptr;
      (void)QTest::qWaitFor([&] {
        dlg = qobject_cast<QDialog*>(QApplication::activeModalWidget());
        return dlg && dlg->objectName() == "importReportDialog";
      }, 10000);
      if (!dlg) return;
      title = dlg->windowTitle();
      if (auto* t = dlg->findChild<QPlainTextEdit*>("importReport")) shown = t->toPlainText();
      if (auto* box = dlg->findChild<QDialogButtonBox*>()) {
        QTest::mouseClick(box->button(QDialogButtonBox::Ok), Qt::LeftButton);
        closed = true;
      }
    });
    importByMenu(kData + "arm7.urdf");
    QVERIFY(closed);
    QCOMPARE(title, QString("Import report"));
    QVERIFY2(shown.contains("7 joint_force actuators, one per movable joint"), qPrintable(shown));
    QVERIFY2(shown.contains("limits: "), qPrintable(shown));
    QCOMPARE(w->document()->model()->dof(), 7);
  }

  void malformedFilesGiveAMessageAndKeepTheDocument() {
    QVERIFY(w->openFile(QStringLiteral(CODYNA_EXAMPLES_DIR "/pendulum.json")));
    const struct {
      QString file, phrases[2];
    } cases[] = {{kData + "bad.xml", {"bad.xml: MuJoCo cannot read it", "line 6"}},
                 {kData + "bad.urdf", {"bad.urdf: not a valid URDF", "nowhere"}},
                 {tmp.filePath("missing.urdf"), {"missing.urdf: cannot open file", "No such file"}}};
    for (const auto& c : cases) {
      if (c.file.endsWith(".xml") && !study_import_available("MJCF")) continue;
      if (c.file.endsWith(".urdf") && !study_import_available("URDF")) continue;
      asked.clear();
      importByMenu(c.file);
      const QString text = lastText("Cannot import");
      QVERIFY2(!text.isEmpty(), qPrintable(c.file));
      for (const QString& p : c.phrases) QVERIFY2(text.contains(p), qPrintable(text));
      QCOMPARE(w->document()->spec().name, std::string("pendulum"));
      QVERIFY(!w->document()->isModified());
    }
  }
};

QTEST_MAIN(ImportTest)
#include "import_test.moc"
