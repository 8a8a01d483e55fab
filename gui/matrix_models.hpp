// Table models for the linear-analysis views of codyna-gui:
//  - MatrixTableModel: one matrix with named rows and columns (A with the
//    state names, B states x inputs, C outputs x states, D, K, ...);
//  - ModeTableModel: the modes of a ModalAnalysis (eigenvalue, frequency,
//    damping, time constant or period, dominant states).
#pragma once

#include <QAbstractTableModel>
#include <QStringList>
#include <Eigen/Core>

#include "study/tools.hpp"

namespace codyna::gui {

// Numbers are shown with 6 significant digits, full precision (17 digits) in
// the tooltip; Qt::UserRole gives the double. Header tooltips give the name
// with its unit ("theta [rad]"). Exact zeros are shown in grey.
class MatrixTableModel : public QAbstractTableModel {
  Q_OBJECT
 public:
  explicit MatrixTableModel(QObject* parent = nullptr);

  // Names (and units) may be shorter than the matrix; missing names are the
  // 1-based index.
  void setMatrix(const Eigen::MatrixXd& m, const QStringList& rowNames, const QStringList& colNames,
                 const QStringList& rowUnits = {}, const QStringList& colUnits = {});
  void clear();
  // what a row's or column's name stands for, when it is not what it says ("X2_dot - 46.9375 W"
  // for a shifted state X2_dot~): added to the header's tooltip ("" for none)
  void setMeanings(const QStringList& rows, const QStringList& cols);
  const Eigen::MatrixXd& matrix() const { return m_; }

  int rowCount(const QModelIndex& parent = QModelIndex()) const override;
  int columnCount(const QModelIndex& parent = QModelIndex()) const override;
  QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
  // DisplayRole: the name; ToolTipRole: "name [unit]"; Qt::UserRole: the unit.
  QVariant headerData(int section, Qt::Orientation orientation, int role = Qt::DisplayRole) const override;

 private:
  QString rowName(int r) const;
  QString colName(int c) const;

  Eigen::MatrixXd m_;
  QStringList row_names_, col_names_, row_units_, col_units_, row_meanings_, col_meanings_;
};

// One row per mode, in the ModalAnalysis order. Qt::UserRole: on column
// Eigenvalue the mode index (int), on the numeric columns the number
// (double; infinity for the time constant of a pole at 0), on DominantStates
// the state names (QStringList). Unstable modes are shown in red.
class ModeTableModel : public QAbstractTableModel {
  Q_OBJECT
 public:
  enum Column { Eigenvalue = 0, NaturalFrequency, FrequencyHz, DampingRatio, TimeConstant, DominantStates, ColumnCount };

  explicit ModeTableModel(QObject* parent = nullptr);

  void setModes(const codyna::ModalAnalysis& modal);
  void clear();
  const codyna::ModalAnalysis& modes() const { return modal_; }

  int rowCount(const QModelIndex& parent = QModelIndex()) const override;
  int columnCount(const QModelIndex& parent = QModelIndex()) const override;
  QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
  QVariant headerData(int section, Qt::Orientation orientation, int role = Qt::DisplayRole) const override;

  // "-0.2 + 1.98997j" (6 significant digits, "j" as in format_modes)
  static QString complexText(std::complex<double> c, int digits = 6);
  // Time constant 1/|Re s| of a real mode, period 2 pi/|Im s| of an oscillating one.
  static double timeConstantOrPeriod(const codyna::Mode& m, bool* isPeriod = nullptr);
  // indices of the states with |shape entry| >= 0.5, largest first
  static std::vector<int> dominantStates(const codyna::Mode& m);

 private:
  QString stateName(int i) const;

  codyna::ModalAnalysis modal_;
};

}  // namespace codyna::gui
