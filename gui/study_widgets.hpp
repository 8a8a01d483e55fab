// Small editors of the study's lists (StudySpec), shared by the Linearize and
// Simulate views. They hold no state of their own beyond what is shown: the
// views fill them from the Document (set*, no signal) and write the Document
// when edited() fires, reading the edited value back (pairs(), readSignals()).
// edited(true) is a number stepped in a spin box: the views merge those into
// one undo step, as the other spin boxes of the views do.
//
//   NameValueTable  NAME = VALUE rows (coordinates set, output targets): a name
//                   combo offering the model's names, a value spin box
//   SignalTable     reference / disturbance signals: target combo, type
//                   (step, ramp, sine, table, file), time and the parameters of
//                   the type; the cells a type does not use are disabled
//   check lists     a QListWidget of checkable names (free inputs, trim_free)
#pragma once

#include <QListWidget>
#include <QStringList>
#include <QWidget>
#include <string>
#include <utility>
#include <vector>

#include "model/study_spec.hpp"

QT_BEGIN_NAMESPACE
class QComboBox;
class QDoubleSpinBox;
class QLineEdit;
class QPushButton;
class QTableWidget;
QT_END_NAMESPACE

namespace codyna::gui {

class NameValueTable : public QWidget {
  Q_OBJECT
 public:
  NameValueTable(const QString& nameHeader, const QString& valueHeader, QWidget* parent = nullptr);

  // the names offered (names already in a row stay offered even when not listed)
  void setChoices(const QStringList& names);
  void setPairs(const std::vector<std::pair<std::string, double>>& pairs);  // no edited()
  std::vector<std::pair<std::string, double>> pairs() const;

  QTableWidget* table() const { return table_; }
  QPushButton* addButton() const { return add_; }
  QPushButton* removeButton() const { return remove_; }
  QComboBox* nameCombo(int row) const;
  QDoubleSpinBox* valueSpin(int row) const;

 signals:
  void edited(bool number);

 private:
  void addRow(const QString& name, double value);
  QTableWidget* table_ = nullptr;
  QPushButton* add_ = nullptr;
  QPushButton* remove_ = nullptr;
  QStringList choices_;
  bool syncing_ = false;
};

class SignalTable : public QWidget {
  Q_OBJECT
 public:
  enum Column { Target, Type, Time, Value, Frequency, Phase, Data, ColumnCount };
  SignalTable(const QString& targetHeader, QWidget* parent = nullptr);

  void setChoices(const QStringList& names);
  void setSignals(const std::vector<codyna::SignalSpec>& s);  // target in SignalSpec::output; no edited()
  // the rows as signals (the target in `output`); false with *error when a table's points do not parse
  bool readSignals(std::vector<codyna::SignalSpec>* out, QString* error) const;

  QTableWidget* table() const { return table_; }
  QPushButton* addButton() const { return add_; }
  QPushButton* removeButton() const { return remove_; }
  QComboBox* targetCombo(int row) const;
  QComboBox* typeCombo(int row) const;
  QDoubleSpinBox* spin(int row, Column c) const;  // Time, Value, Frequency, Phase
  QLineEdit* dataEdit(int row) const;              // table points "t r; t r" or the file

 signals:
  void edited(bool number);

 private:
  void addRow(const codyna::SignalSpec& s);
  void updateRow(int row);  // enables the cells the type uses, names the value column's meaning
  QTableWidget* table_ = nullptr;
  QPushButton* add_ = nullptr;
  QPushButton* remove_ = nullptr;
  QStringList choices_;
  bool syncing_ = false;
};

// A checkable list of `names`, those in `checked` checked (no itemChanged). Names
// checked but not offered are added, so nothing in the file is hidden.
void setCheckList(QListWidget* list, const QStringList& names, const std::vector<std::string>& checked);
std::vector<std::string> checkedNames(const QListWidget* list);

}  // namespace codyna::gui
