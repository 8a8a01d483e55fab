// codyna-gui: the desktop pre/post-processor. `codyna-gui [MODEL.json]`.
#include <QApplication>
#include <QCommandLineParser>
#include <QSurfaceFormat>
#include <QIcon>

#include "gui/main_window.hpp"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  QApplication::setOrganizationName("codyna");
  QApplication::setApplicationName("codyna-gui");
  QApplication::setApplicationVersion(CODYNA_VERSION);
  QCommandLineParser parser;
  parser.setApplicationDescription("codyna: multibody dynamics pre/post-processor with a control module");
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument("model", "model file (JSON) to open");
  parser.process(app);
  codyna::gui::MainWindow w;
  app.setWindowIcon(QIcon(":/codyna/codyna.svg"));
  w.show();
  // unsaved work of a codyna that was killed comes first; else the model asked for
  if (!w.offerRecovery() && !parser.positionalArguments().isEmpty()) w.openFile(parser.positionalArguments().first());
  return app.exec();
}
