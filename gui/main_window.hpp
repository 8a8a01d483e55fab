// MainWindow: codyna-gui's window. Model tree and property editor (left), the
// 3-D view with playback (centre), the Linearize and Simulate views (below it),
// the Control Plant/In and Plant/Out panels (right), messages (bottom).
// Every edit goes through the Document's undo stack; unsaved changes are never
// dropped silently (the guard asks on New, Open and Quit).
#pragma once

#include <QMainWindow>
#include <QTimer>
#include <QUrl>
#include <complex>
#include <functional>
#include <map>
#include <memory>

#include "gui/document.hpp"
#include "gui/model_tree.hpp"

class QAction;
class QTreeView;
class QPlainTextEdit;
class QSlider;
class QPushButton;
class QComboBox;
class QLabel;
class QTabWidget;
class QMenu;
class QDockWidget;
class QToolBar;

namespace codyna {
struct SimulationResult;
}

namespace codyna::gui {

class View3D;
class PropertyEditor;
class PlantPanel;
class LinearizeView;
class SimulateView;
class ControlView;
class SweepView;
class TireView;
class KcView;
class ManeuverView;
class Autosave;
class IssuesPanel;

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  Document* document() { return doc_; }
  View3D* view3d() { return view_; }
  QTreeView* modelTree() { return tree_; }
  ModelTreeModel* treeModel() { return tree_model_; }
  PropertyEditor* propertyEditor() { return props_; }
  PlantPanel* plantInPanel() { return plant_in_; }
  PlantPanel* plantOutPanel() { return plant_out_; }
  LinearizeView* linearizeView() { return lin_view_; }
  SimulateView* simulateView() { return sim_view_; }
  ControlView* controlView() { return control_view_; }
  SweepView* sweepView() { return sweep_view_; }
  TireView* tireView() { return tire_view_; }
  ManeuverView* maneuverView() { return maneuver_view_; }
  KcView* kcView() { return kc_view_; }
  QTabWidget* analysisTabs() { return tabs_; }
  QPlainTextEdit* messages() { return messages_; }
  IssuesPanel* issuesPanel() { return issues_; }
  QSlider* playbackSlider() { return slider_; }

  // File operations (the menu's actions call these; tests too). openFile() checks
  // for unsaved changes first; a file that does not load leaves the document as it was.
  bool openFile(const QString& path);
  bool saveFile();
  bool saveFileAs(const QString& path);
  bool newModel();
  bool exportPlant(const QString& dir);  // NAME.m + NAME.mat through core's study_export
  // File > Import: an MJCF (.xml) or URDF (.urdf) file read by core's study_import (what
  // `codyna import` runs), opened as a new, unsaved document (no file: Save asks for a name, the
  // source is never written); the import report is shown. A refused import (elements that change
  // the dynamics) shows the reason and offers to import again ignoring those kinds (the CLI's
  // --ignore); a file that cannot be read gives its message. True when a model was imported.
  bool importFile(const QString& path);
  QAction* importAction() const { return a_import_; }

  // Asks before unsaved changes are lost: true when it may go on (saved or discarded).
  bool maybeSave();
  // Offers back the unsaved work of a codyna that crashed or was killed (Autosave): true when
  // a model was recovered (the file opened, the recovered edits one unsaved undo step on top).
  bool offerRecovery();
  void saveLayout() const;  // window size, docks, splitters (QSettings; also on close)
  Autosave* autosave() { return autosave_; }

  // Dialogs go through these hooks so that tests answer them without a modal loop.
  // question: returns QMessageBox::StandardButton; file: returns a path ("" = cancelled).
  using QuestionHook = std::function<int(const QString& title, const QString& text, int buttons)>;
  using FileHook = std::function<QString(const QString& title, const QString& dir, const QString& filter, bool save)>;
  void setQuestionHook(QuestionHook h) { ask_ = std::move(h); }
  void setFileHook(FileHook h) { file_ = std::move(h); }

  void selectElement(std::optional<ElementId> id);
  std::optional<ElementId> selectedElement() const;
  bool removeSelected();     // asks first when other elements refer to it
  bool duplicateSelected();
  // adds one element of kind k, set up by `setup` (its index given) in the same undo step, and selects it
  bool addElement(ElementKind k, const std::function<void(ModelSpec&, int)>& setup = {}, const QString& text = QString());

  // playback of the last simulation result in the 3-D view (a Simulate run's, or a maneuver's:
  // then with the lane and the track of the steady body drawn on the ground, the camera following
  // that body)
  void setPlaybackTime(double t);
  // the result playing (null: none)
  const SimulationResult* playbackResult() const { return result_.get(); }
  double playbackTime() const { return play_t_; }
  void setPlaying(bool on);
  bool isPlaying() const;
  // mode shape animation (from the Linearize view); index -1 stops it
  void animateMode(int index, const Eigen::VectorXcd& shape);
  bool isAnimatingMode() const;

  QStringList recentFiles() const;
  static QUrl documentationUrl();  // docs/gui.md (installed, or the source tree's)
  QAction* linearizeAction() const { return a_linearize_; }
  QAction* runAction() const { return a_run_; }
  QAction* cancelAction() const { return a_cancel_; }
  void message(const QString& text, bool error = false);

 protected:
  void closeEvent(QCloseEvent* e) override;

 private:
  void buildMenus();
  QAction* addElementAction(ElementKind k);
  void showTreeMenu(const QPoint& at);
  QString aboutText() const;
  void restoreLayout();
  void updateTitle();
  void addRecent(const QString& path);
  void rebuildRecentMenu();
  void onModelChanged();
  void onResult(std::shared_ptr<const SimulationResult> r);
  void onManeuverFinished();  // its run to the playback, its track and lane to the 3-D view
  void stepAnimation();
  int ask(const QString& title, const QString& text, int buttons);
  // a report in a scrollable dialog (the question hook gets intro + "\n\n" + report)
  int showReport(const QString& title, const QString& intro, const QString& report, int buttons);
  bool importNow(const QString& path, const QStringList& ignore);
  QString chooseFile(const QString& title, const QString& dir, const QString& filter, bool save);

  Document* doc_;
  ModelTreeModel* tree_model_;
  QTreeView* tree_;
  PropertyEditor* props_;
  PlantPanel *plant_in_, *plant_out_;
  QString logged_error_;  // the model error last written to the Messages log
  View3D* view_;
  LinearizeView* lin_view_;
  SimulateView* sim_view_;
  ControlView* control_view_ = nullptr;
  SweepView* sweep_view_ = nullptr;
  TireView* tire_view_ = nullptr;
  ManeuverView* maneuver_view_ = nullptr;
  KcView* kc_view_ = nullptr;
  Autosave* autosave_ = nullptr;
  QTabWidget* tabs_;
  QPlainTextEdit* messages_;
  IssuesPanel* issues_ = nullptr;
  std::map<ElementKind, QAction*> add_actions_;
  QToolBar* add_bar_ = nullptr;
  QDockWidget* issues_dock_ = nullptr;
  QSlider* slider_;
  QPushButton* play_;
  QComboBox* speed_;
  QLabel* time_label_;
  QMenu* recent_menu_ = nullptr;
  QTimer anim_;
  std::shared_ptr<const SimulationResult> result_;
  double play_t_ = 0;
  QAction* a_linearize_ = nullptr;
  QAction* a_import_ = nullptr;
  QAction* a_run_ = nullptr;
  QAction* a_cancel_ = nullptr;
  int mode_ = -1;
  Eigen::VectorXcd mode_shape_;
  double mode_phase_ = 0;
  QuestionHook ask_;
  FileHook file_;
};

}  // namespace codyna::gui
