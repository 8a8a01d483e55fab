#include "gui/matrix_models.hpp"

#include <QBrush>
#include <QColor>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace codyna::gui {
namespace {

QString withUnit(const QString& name, const QString& unit) {
  return unit.trimmed().isEmpty() ? name : QStringLiteral("%1 [%2]").arg(name, unit.trimmed());
}

QString at(const QStringList& l, int k) { return k >= 0 && k < l.size() ? l[k] : QString(); }

}  // namespace

// ---------------------------------------------------------------------------
// MatrixTableModel

MatrixTableModel::MatrixTableModel(QObject* parent) : QAbstractTableModel(parent) {}

void MatrixTableModel::setMatrix(const Eigen::MatrixXd& m, const QStringList& rowNames, const QStringList& colNames,
                                 const QStringList& rowUnits, const QStringList& colUnits) {
  beginResetModel();
  m_ = m;
  row_names_ = rowNames;
  col_names_ = colNames;
  row_units_ = rowUnits;
  col_units_ = colUnits;
  row_meanings_.clear();
  col_meanings_.clear();
  endResetModel();
}

void MatrixTableModel::clear() { setMatrix(Eigen::MatrixXd(), {}, {}); }

void MatrixTableModel::setMeanings(const QStringList& rows, const QStringList& cols) {
  row_meanings_ = rows;
  col_meanings_ = cols;
  if (m_.rows() > 0) emit headerDataChanged(Qt::Vertical, 0, static_cast<int>(m_.rows()) - 1);
  if (m_.cols() > 0) emit headerDataChanged(Qt::Horizontal, 0, static_cast<int>(m_.cols()) - 1);
}

int MatrixTableModel::rowCount(const QModelIndex& parent) const {
  return parent.isValid() ? 0 : static_cast<int>(m_.rows());
}

int MatrixTableModel::columnCount(const QModelIndex& parent) const {
  return parent.isValid() ? 0 : static_cast<int>(m_.cols());
}

QString MatrixTableModel::rowName(int r) const {
  const QString n = at(row_names_, r);
  return n.isEmpty() ? QString::number(r + 1) : n;
}

QString MatrixTableModel::colName(int c) const {
  const QString n = at(col_names_, c);
  return n.isEmpty() ? QString::number(c + 1) : n;
}

QVariant MatrixTableModel::data(const QModelIndex& index, int role) const {
  if (!index.isValid() || index.row() >= m_.rows() || index.column() >= m_.cols()) return {};
  const double v = m_(index.row(), index.column());
  switch (role) {
    case Qt::DisplayRole:
      return QString::number(v, 'g', 6);
    case Qt::ToolTipRole:
      return QStringLiteral("(%1, %2) = %3").arg(rowName(index.row()), colName(index.column()), QString::number(v, 'g', 17));
    case Qt::UserRole:
      return v;
    case Qt::TextAlignmentRole:
      return QVariant::fromValue(Qt::Alignment(Qt::AlignRight | Qt::AlignVCenter));
    case Qt::ForegroundRole:
      if (v == 0.0) return QBrush(QColor(0xa0, 0xa0, 0xa0));
      return {};
    default:
      return {};
  }
}

QVariant MatrixTableModel::headerData(int section, Qt::Orientation orientation, int role) const {
  const bool horizontal = orientation == Qt::Horizontal;
  if (section < 0 || section >= (horizontal ? m_.cols() : m_.rows())) return {};
  const QString name = horizontal ? colName(section) : rowName(section);
  const QString unit = horizontal ? at(col_units_, section) : at(row_units_, section);
  switch (role) {
    case Qt::DisplayRole:
      return name;
    case Qt::ToolTipRole: {
      const QString meaning = horizontal ? at(col_meanings_, section) : at(row_meanings_, section);
      return meaning.isEmpty() ? withUnit(name, unit)
                               : withUnit(name, unit) + "\n" +
                                     tr("= %1: shifted, the motion inputs enter without their rates").arg(meaning);
    }
    case Qt::UserRole:
      return unit;
    default:
      return {};
  }
}

// ---------------------------------------------------------------------------
// ModeTableModel

ModeTableModel::ModeTableModel(QObject* parent) : QAbstractTableModel(parent) {}

void ModeTableModel::setModes(const codyna::ModalAnalysis& modal) {
  beginResetModel();
  modal_ = modal;
  endResetModel();
}

void ModeTableModel::clear() { setModes(codyna::ModalAnalysis{}); }

int ModeTableModel::rowCount(const QModelIndex& parent) const {
  return parent.isValid() ? 0 : static_cast<int>(modal_.modes.size());
}

int ModeTableModel::columnCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : ColumnCount; }

QString ModeTableModel::complexText(std::complex<double> c, int digits) {
  const QString re = QString::number(c.real(), 'g', digits);
  if (c.imag() == 0.0) return re;
  return QStringLiteral("%1 %2 %3j").arg(re, c.imag() < 0 ? QStringLiteral("-") : QStringLiteral("+"),
                                         QString::number(std::abs(c.imag()), 'g', digits));
}

double ModeTableModel::timeConstantOrPeriod(const codyna::Mode& m, bool* isPeriod) {
  // oscillating: Im s not negligible against |s|
  const bool oscillating = std::abs(m.s.imag()) > 1e-9 * std::max(1.0, std::abs(m.s));
  if (isPeriod) *isPeriod = oscillating;
  if (oscillating) return 2.0 * std::numbers::pi / std::abs(m.s.imag());
  return m.s.real() != 0.0 ? 1.0 / std::abs(m.s.real()) : std::numeric_limits<double>::infinity();
}

std::vector<int> ModeTableModel::dominantStates(const codyna::Mode& m) {
  std::vector<int> idx;
  for (Eigen::Index i = 0; i < m.shape.size(); ++i)
    if (std::abs(m.shape(i)) >= 0.5) idx.push_back(static_cast<int>(i));
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return std::abs(m.shape(a)) > std::abs(m.shape(b)); });
  return idx;
}

QString ModeTableModel::stateName(int i) const {
  if (i >= 0 && i < static_cast<int>(modal_.state_names.size()) && !modal_.state_names[i].empty())
    return QString::fromStdString(modal_.state_names[i]);
  return QStringLiteral("x%1").arg(i + 1);
}

QVariant ModeTableModel::data(const QModelIndex& index, int role) const {
  if (!index.isValid() || index.row() >= rowCount() || index.column() >= ColumnCount) return {};
  const codyna::Mode& m = modal_.modes[index.row()];
  const bool discrete = modal_.Ts > 0.0;
  const double hz = m.natural_frequency / (2.0 * std::numbers::pi);
  bool period = false;
  const double tau = timeConstantOrPeriod(m, &period);
  const bool unstable = m.stability == codyna::Stability::Unstable;  // the core's rule (analysis/stability.hpp)

  if (role == Qt::DisplayRole) {
    switch (index.column()) {
      case Eigenvalue: return complexText(m.eigenvalue);
      case NaturalFrequency: return QString::number(m.natural_frequency, 'g', 6);
      case FrequencyHz: return QString::number(hz, 'g', 6);
      // a zero eigenvalue (a rigid-body or integrator mode) has no damping ratio: "-", not -1
      case DampingRatio: return m.natural_frequency > 0.0 ? QString::number(m.damping_ratio, 'g', 4) : QStringLiteral("-");
      case TimeConstant:
        if (std::isinf(tau)) return QStringLiteral("\u221e");
        return QStringLiteral("%1 = %2").arg(period ? QStringLiteral("T") : QStringLiteral("\u03c4"),
                                             QString::number(tau, 'g', 4));
      case DominantStates: {
        QStringList parts;
        for (int i : dominantStates(m))
          parts << QStringLiteral("%1 (%2)").arg(stateName(i), QString::number(std::abs(m.shape(i)), 'f', 2));
        return parts.join(QStringLiteral(", "));
      }
    }
  } else if (role == Qt::UserRole) {
    switch (index.column()) {
      case Eigenvalue: return index.row();
      case NaturalFrequency: return m.natural_frequency;
      case FrequencyHz: return hz;
      case DampingRatio: return m.damping_ratio;
      case TimeConstant: return tau;
      case DominantStates: {
        QStringList names;
        for (int i : dominantStates(m)) names << stateName(i);
        return names;
      }
    }
  } else if (role == Qt::ToolTipRole) {
    switch (index.column()) {
      case Eigenvalue:
        if (discrete)
          return QStringLiteral("z = %1\ns = ln(z)/Ts = %2\nTs = %3 s")
              .arg(complexText(m.eigenvalue, 17), complexText(m.s, 17), QString::number(modal_.Ts, 'g', 6));
        return QStringLiteral("\u03bb = %1").arg(complexText(m.eigenvalue, 17));
      case TimeConstant:
        return period ? QStringLiteral("period of the oscillation, 2\u03c0/|Im s|")
                      : QStringLiteral("time constant, 1/|Re s|");
      case DominantStates: {
        QStringList parts;
        for (Eigen::Index i = 0; i < m.shape.size(); ++i)
          parts << QStringLiteral("%1: %2").arg(stateName(static_cast<int>(i)), complexText(m.shape(i), 4));
        return parts.join(QLatin1Char('\n'));
      }
      default: return QString::number(data(index, Qt::UserRole).toDouble(), 'g', 17);
    }
  } else if (role == Qt::TextAlignmentRole) {
    if (index.column() == DominantStates) return QVariant::fromValue(Qt::Alignment(Qt::AlignLeft | Qt::AlignVCenter));
    return QVariant::fromValue(Qt::Alignment(Qt::AlignRight | Qt::AlignVCenter));
  } else if (role == Qt::ForegroundRole) {
    if (unstable) return QBrush(QColor(0xc0, 0x10, 0x10));
  }
  return {};
}

QVariant ModeTableModel::headerData(int section, Qt::Orientation orientation, int role) const {
  if (orientation == Qt::Vertical) {
    if (role == Qt::DisplayRole && section >= 0 && section < rowCount()) return section + 1;
    return {};
  }
  const bool discrete = modal_.Ts > 0.0;
  if (role == Qt::DisplayRole) {
    switch (section) {
      case Eigenvalue: return discrete ? QStringLiteral("Eigenvalue z") : QStringLiteral("Eigenvalue \u03bb");
      case NaturalFrequency: return QStringLiteral("\u03c9n [rad/s]");
      case FrequencyHz: return QStringLiteral("f [Hz]");
      case DampingRatio: return QStringLiteral("Damping \u03b6");
      case TimeConstant: return QStringLiteral("\u03c4 / T [s]");
      case DominantStates: return QStringLiteral("Dominant states");
    }
  } else if (role == Qt::ToolTipRole) {
    switch (section) {
      case Eigenvalue:
        return discrete ? QStringLiteral("Eigenvalue z of the discrete A (Ts = %1 s)").arg(modal_.Ts)
                        : QStringLiteral("Eigenvalue \u03bb of A [1/s]");
      case NaturalFrequency: return QStringLiteral("Natural frequency |s| [rad/s]");
      case FrequencyHz: return QStringLiteral("Natural frequency |s|/2\u03c0 [Hz]");
      case DampingRatio: return QStringLiteral("Damping ratio \u2212Re(s)/|s| (negative: unstable)");
      case TimeConstant: return QStringLiteral("Time constant 1/|Re s| of a real mode, period 2\u03c0/|Im s| of an oscillating one [s]");
      case DominantStates: return QStringLiteral("States with |mode shape entry| \u2265 0.5, largest first");
    }
  }
  return {};
}

}  // namespace codyna::gui
