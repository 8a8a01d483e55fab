// TireView: the tire test rig (`codyna tire`, core's study_tire_job) as curves. For a tire element
// of the model being edited (its law and numbers as the simulation uses them) or a .tir file opened
// here, at the loads typed and one camber and forward speed:
//   - Fy over the slip angle alpha (kappa = 0), one curve per load,
//   - Fx over the longitudinal slip kappa in percent (alpha = 0), one curve per load,
//   - Mz over the slip angle (kappa = 0), one curve per load,
//   - combined slip: Fy against Fx at the middle load, one curve per fixed slip angle, kappa swept.
// ISO-W axes and signs (docs/tires.md): a positive slip angle gives a negative Fy. Every number
// plotted is a value of the job's rows; the view computes nothing itself.
#pragma once

#include <QStringList>
#include <QWidget>

class QComboBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QChart;

namespace codyna::gui {

class ChartView;
class Document;

class TireView : public QWidget {
  Q_OBJECT
 public:
  explicit TireView(Document* doc, QWidget* parent = nullptr);

  // shows the model's tire element `name` (false when the model has none of that name)
  bool showTire(const QString& name);
  // adds the .tir file to the choices and shows it (what the Open .tir... dialog does)
  void showTirFile(const QString& path);
  // computes the curves again for the choices shown; false (and the reason in errorText()) when the
  // core refuses them
  bool refresh();
  // Open .tir...: a file dialog (objectName "tireViewFileDialog", Qt's own, window-modal)
  void chooseTirFile();

  QComboBox* sourceBox() const { return source_; }
  QLineEdit* loadsEdit() const { return loads_; }
  QLineEdit* alphaMaxEdit() const { return alpha_max_; }
  QLineEdit* kappaMaxEdit() const { return kappa_max_; }
  QLineEdit* camberEdit() const { return camber_; }
  QLineEdit* speedEdit() const { return speed_; }
  QLineEdit* ellipseAlphasEdit() const { return ellipse_alphas_; }
  ChartView* lateralView() const { return lateral_; }          // Fy [N] over alpha [deg]
  ChartView* longitudinalView() const { return longitudinal_; }  // Fx [N] over kappa [%]
  ChartView* aligningView() const { return aligning_; }        // Mz [N m] over alpha [deg]
  ChartView* combinedView() const { return combined_; }        // Fy [N] over Fx [N]
  QString errorText() const;
  QString tireText() const;  // what the job says it evaluated, and its notes

 signals:
  void message(const QString& text);

 protected:
  void showEvent(QShowEvent* e) override;

 private:
  void fillSources();
  void sourceChosen();
  void clearCurves();
  void showError(const QString& text);
  Document* doc_;
  QComboBox* source_ = nullptr;
  QPushButton* open_ = nullptr;
  QPushButton* plot_ = nullptr;
  QLineEdit *loads_ = nullptr, *alpha_max_ = nullptr, *kappa_max_ = nullptr, *camber_ = nullptr, *speed_ = nullptr,
            *ellipse_alphas_ = nullptr;
  QLabel* tire_ = nullptr;
  QLabel* error_ = nullptr;
  ChartView *lateral_ = nullptr, *longitudinal_ = nullptr, *aligning_ = nullptr, *combined_ = nullptr;
  QStringList files_;  // the .tir files opened here (absolute paths)
  bool stale_ = true;  // the model changed while the view was hidden
};

}  // namespace codyna::gui
