// LinearizeView: the "Linearize" page of codyna-gui.
//
// The widgets at the top are the study's linearization choices (the model
// file's "analysis" section, StudySpec): operating point (initial,
// equilibrium, trim, time=T), Jacobian method, sample time Ts (0 =
// continuous), MAT version, export folder and name, and for closed loops the
// independent coordinates, and the steady-state search of an equilibrium or
// a trim (as Simulink's operspec): the coordinates set and held (a name combo
// of the model's positions and rates, a value), the Plant/In inputs solved
// for, the Plant/Out targets, the coordinates a trim solves instead of
// holding. Every change is written through
// Document::setStudy or, for the steady-state search, setStudyChecked (which
// refuses what the core refuses, with its message; one undo step; spin boxes merge while they are
// stepped), and the widgets follow the Document (undo, redo, load).
//
// "Linearize" runs study_linearize_job() on the document's model, the job
// `codyna linearize` runs, and shows the operating point, A, B, C, D with their
// names, the offsets x0, u0, y0, xdot0, the modes (ModeTableModel) and the
// pole map. A mode selected in the table or on the pole map (kept in sync)
// is announced by modeSelected() for the 3-D view. "Export…" (and exportTo())
// writes NAME.mat + NAME.m through study_export(), the code of
// `codyna linearize --out DIR`, re-linearizing first when the shown result is
// out of date.
#pragma once

#include <Eigen/Core>
#include <QMetaType>
#include <QString>
#include <QWidget>
#include <complex>
#include <functional>
#include <memory>
#include <optional>

#include "study/tools.hpp"
#include "model/model.hpp"
#include "study/workflow.hpp"

QT_BEGIN_NAMESPACE
class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QListWidgetItem;
class QPushButton;
class QTabWidget;
class QPlainTextEdit;
class QTableView;
class QTableWidget;
class QGroupBox;
QT_END_NAMESPACE

namespace codyna::gui {

class Document;
class MatrixTableModel;
class ModeTableModel;
class NameValueTable;
class PoleMap;

class LinearizeView : public QWidget {
  Q_OBJECT
 public:
  explicit LinearizeView(Document* doc, QWidget* parent = nullptr);
  ~LinearizeView() override;

  // Linearizes the document's current model with its study (the button does this).
  // On failure: false, message() emitted, the old result (if any) kept but marked stale.
  bool linearize();
  // Writes NAME.mat + NAME.m into `dir` ("" = the study's export folder, relative
  // to the model file), re-linearizing if the result is stale; emits exported().
  bool exportTo(const QString& dir, QString* error = nullptr);

  // The last linearization, or null. isStale(): the document changed since.
  const codyna::StudyLinearization* result() const { return result_ ? &*result_ : nullptr; }
  const codyna::ModalAnalysis& modes() const { return modal_; }
  bool isStale() const;
  // Forgets the result (the document now holds another model): empty matrices, modes and pole map.
  void clearResult();

  // Selects mode `index` in the table and the pole map and emits modeSelected
  // (-1 clears the selection, without a signal).
  void selectMode(int index);
  int selectedMode() const { return selected_mode_; }

  // The widgets, for the main window and tests.
  QComboBox* operatingPointCombo() const { return op_combo_; }
  QDoubleSpinBox* operatingTimeSpin() const { return op_time_; }
  QDoubleSpinBox* steadySpeedSpin() const { return steady_speed_; }
  QComboBox* steadyTurnCombo() const { return steady_turn_; }
  QDoubleSpinBox* steadyTurnValueSpin() const { return steady_turn_value_; }
  QComboBox* methodCombo() const { return method_combo_; }
  QDoubleSpinBox* sampleTimeSpin() const { return ts_spin_; }
  QComboBox* matVersionCombo() const { return mat_combo_; }
  QLineEdit* exportDirEdit() const { return export_dir_; }
  QLineEdit* exportNameEdit() const { return export_name_; }
  QListWidget* independentList() const { return independent_; }
  // the steady-state search (equilibrium, trim): coordinates held, inputs solved, output targets,
  // coordinates a trim frees
  NameValueTable* setTable() const { return set_table_; }
  QListWidget* freeInputsList() const { return free_inputs_; }
  NameValueTable* targetsTable() const { return targets_; }
  QListWidget* trimFreeList() const { return trim_free_; }
  QPushButton* linearizeButton() const { return linearize_button_; }
  QPushButton* exportButton() const { return export_button_; }
  // A, B, C, D (k = 0..3)
  QTableView* matrixView(int k) const { return matrix_views_[k]; }
  MatrixTableModel* matrixModel(int k) const { return matrix_models_[k]; }
  QTableView* modeView() const { return mode_view_; }
  ModeTableModel* modeModel() const { return mode_model_; }
  PoleMap* poleMap() const { return pole_map_; }
  QLabel* operatingPointLabel() const { return op_label_; }
  QLabel* controllabilityLabel() const { return hidden_label_; }
  // the handling numbers of a steady motion (as codyna linearize prints them), in the results'
  // Handling tab, shown only when the result has them
  QPlainTextEdit* handlingText() const { return handling_; }
  QTabWidget* resultTabs() const { return tabs_; }

 signals:
  // a mode was selected (table or pole map): its index in modes(), its shape (state order) and s
  void modeSelected(int index, const Eigen::VectorXcd& shape, std::complex<double> s);
  void linearized();
  void exported(const QString& matFile, const QString& mFile);
  void message(const QString& text);  // errors and notes for the message dock

 private:
  void buildUi();
  void refreshFromDocument();  // study -> widgets
  void refreshIndependent();   // coordinates of the model (closed loops only)
  void refreshSteadyState();   // the names offered and the study's choices of the steady-state search
  void writeStudy(const std::function<void(codyna::StudySpec&)>& change, const QString& text, int mergeKey = -1);
  void opChanged();
  void steadyChanged();  // the steady motion's speed and turn -> the study
  void independentChanged(QListWidgetItem* item);
  void showResult();
  void updateStaleness();
  void modeRowChanged();
  void poleClicked(int index);
  void announceMode(int index);
  void browseExport();

  Document* doc_;
  std::optional<codyna::StudyLinearization> result_;
  std::shared_ptr<const codyna::Model> result_model_;  // the model result_ was computed on
  std::string result_key_;                             // its spec, but for the export's name and folder
  codyna::ModalAnalysis modal_;
  int selected_mode_ = -1;
  bool syncing_ = false;

  QComboBox* op_combo_ = nullptr;
  QDoubleSpinBox* op_time_ = nullptr;
  // operating point steady: the forward speed (0 = as at the start) and the turn (what, how much)
  QDoubleSpinBox* steady_speed_ = nullptr;
  QComboBox* steady_turn_ = nullptr;
  QDoubleSpinBox* steady_turn_value_ = nullptr;
  QComboBox* method_combo_ = nullptr;
  QDoubleSpinBox* ts_spin_ = nullptr;
  QComboBox* mat_combo_ = nullptr;
  QLineEdit* export_dir_ = nullptr;
  QLineEdit* export_name_ = nullptr;
  QPushButton* export_browse_ = nullptr;
  QGroupBox* independent_box_ = nullptr;
  QListWidget* independent_ = nullptr;
  QGroupBox* steady_box_ = nullptr;
  NameValueTable* set_table_ = nullptr;
  QListWidget* free_inputs_ = nullptr;
  NameValueTable* targets_ = nullptr;
  QListWidget* trim_free_ = nullptr;
  QPushButton* linearize_button_ = nullptr;
  QPushButton* export_button_ = nullptr;
  QLabel* op_label_ = nullptr;
  QLabel* stale_label_ = nullptr;
  QLabel* hidden_label_ = nullptr;  // controllable / observable, as codyna linearize says it
  QTabWidget* tabs_ = nullptr;
  QTableView* matrix_views_[4] = {};
  MatrixTableModel* matrix_models_[4] = {};
  QTableWidget* offsets_ = nullptr;
  QPlainTextEdit* handling_ = nullptr;
  QTableView* mode_view_ = nullptr;
  ModeTableModel* mode_model_ = nullptr;
  PoleMap* pole_map_ = nullptr;
};

}  // namespace codyna::gui

Q_DECLARE_METATYPE(Eigen::VectorXcd)
Q_DECLARE_METATYPE(std::complex<double>)
