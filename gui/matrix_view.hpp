// MatrixView: a table of one matrix (MatrixTableModel) that copies what a
// control engineer pastes elsewhere: Ctrl+C the selected block as tab-separated
// numbers (a spreadsheet's paste), and from the context menu the whole matrix
// as MATLAB/Octave text (`A = [...];`, with the row and column names as a
// comment) or as CSV with the names. Numbers are written with 17 significant
// digits, so what is pasted reads back exactly.
#pragma once

#include <QTableView>

namespace codyna::gui {

class MatrixTableModel;

class MatrixView : public QTableView {
  Q_OBJECT
 public:
  enum class Format { Selection, Matlab, Csv };

  explicit MatrixView(const QString& name, QWidget* parent = nullptr);
  void setMatrixModel(MatrixTableModel* m);
  MatrixTableModel* matrixModel() const { return model_; }
  QString matrixName() const { return name_; }

  QString text(Format f) const;  // what copy() puts on the clipboard
  void copy(Format f) const;

 protected:
  void keyPressEvent(QKeyEvent* e) override;
  void contextMenuEvent(QContextMenuEvent* e) override;

 private:
  QString name_;
  MatrixTableModel* model_ = nullptr;
};

}  // namespace codyna::gui
