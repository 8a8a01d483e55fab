#include "gui/study_widgets.hpp"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLineEdit>
#include <QPushButton>
#include <QRegularExpression>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "gui/document.hpp"

namespace codyna::gui {

namespace {

QDoubleSpinBox* numberSpin(QWidget* parent, double lo, double hi) {
  auto* s = new QDoubleSpinBox(parent);
  s->setRange(lo, hi);
  s->setDecimals(6);
  s->setSingleStep(0.1);
  s->setKeyboardTracking(false);
  s->setFrame(false);
  return s;
}

// a combo holding `choices` plus `current` when it is not one of them
void fillCombo(QComboBox* c, const QStringList& choices, const QString& current) {
  const QSignalBlocker b(c);
  c->clear();
  c->addItems(choices);
  if (!current.isEmpty() && !choices.contains(current)) c->addItem(current);
  c->setCurrentIndex(c->findText(current));
}

QHBoxLayout* buttonRow(QWidget* parent, QPushButton** add, QPushButton** remove) {
  *add = new QPushButton(QObject::tr("Add"), parent);
  *remove = new QPushButton(QObject::tr("Remove"), parent);
  (*add)->setToolTip(QObject::tr("Add a row (the first name not used yet)"));
  (*remove)->setToolTip(QObject::tr("Remove the selected row"));
  auto* row = new QHBoxLayout;
  row->addWidget(*add);
  row->addWidget(*remove);
  row->addStretch(1);
  return row;
}

QString pointsText(const std::vector<std::pair<double, double>>& p) {
  QStringList l;
  for (const auto& [t, r] : p) l << QStringLiteral("%1 %2").arg(QString::number(t, 'g', 12), QString::number(r, 'g', 12));
  return l.join(QStringLiteral("; "));
}

// the first of `choices` that no row uses yet ("" when each has its row)
QString firstUnused(const QStringList& choices, int rows, const std::function<QString(int)>& nameAt) {
  for (const QString& c : choices) {
    bool used = false;
    for (int r = 0; r < rows && !used; ++r) used = nameAt(r) == c;
    if (!used) return c;
  }
  return {};
}

// removes the selected row, or the last one when none is selected; false when the table is empty
bool removeSelectedRow(QTableWidget* table) {
  int row = table->currentRow();
  if (row < 0) row = table->rowCount() - 1;
  if (row < 0) return false;
  table->removeRow(row);
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------

NameValueTable::NameValueTable(const QString& nameHeader, const QString& valueHeader, QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  table_ = new QTableWidget(0, 2, this);
  table_->setHorizontalHeaderLabels({nameHeader, valueHeader});
  setToolTip(QStringLiteral("%1: %2").arg(nameHeader, valueHeader));  // a caller's setToolTip says more
  table_->verticalHeader()->setVisible(false);
  table_->horizontalHeader()->setSectionResizeMode(0, QHeaderView::Stretch);
  table_->horizontalHeader()->setSectionResizeMode(1, QHeaderView::Stretch);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setMaximumHeight(110);
  layout->addWidget(table_);
  layout->addLayout(buttonRow(this, &add_, &remove_));
  connect(add_, &QPushButton::clicked, this, [this] {
    const QString name = firstUnused(choices_, table_->rowCount(), [this](int r) { return nameCombo(r)->currentText(); });
    if (name.isEmpty()) return;  // every name has its row
    addRow(name, 0.0);
    emit edited(false);
  });
  connect(remove_, &QPushButton::clicked, this, [this] {
    // the row's editors lose focus as they go and may report a last edit: not while half removed
    syncing_ = true;
    const bool removed = removeSelectedRow(table_);
    syncing_ = false;
    if (removed) emit edited(false);
  });
}

QComboBox* NameValueTable::nameCombo(int row) const { return qobject_cast<QComboBox*>(table_->cellWidget(row, 0)); }
QDoubleSpinBox* NameValueTable::valueSpin(int row) const { return qobject_cast<QDoubleSpinBox*>(table_->cellWidget(row, 1)); }

void NameValueTable::setChoices(const QStringList& names) {
  if (names == choices_) return;
  choices_ = names;
  syncing_ = true;
  for (int r = 0; r < table_->rowCount(); ++r) fillCombo(nameCombo(r), choices_, nameCombo(r)->currentText());
  syncing_ = false;
}

void NameValueTable::addRow(const QString& name, double value) {
  const int row = table_->rowCount();
  table_->insertRow(row);
  auto* combo = new QComboBox(table_);
  combo->setFrame(false);
  fillCombo(combo, choices_, name);
  auto* spin = numberSpin(table_, -1e6, 1e6);
  spin->setValue(value);
  table_->setCellWidget(row, 0, combo);
  table_->setCellWidget(row, 1, spin);
  connect(combo, &QComboBox::currentIndexChanged, this, [this] {
    if (!syncing_) emit edited(false);
  });
  connect(spin, &QDoubleSpinBox::valueChanged, this, [this] {
    if (!syncing_) emit edited(true);
  });
}

void NameValueTable::setPairs(const std::vector<std::pair<std::string, double>>& pairs) {
  if (pairs == this->pairs()) return;  // keeps the focus and selection while the user edits
  syncing_ = true;
  table_->setRowCount(0);
  for (const auto& [n, v] : pairs) addRow(qs(n), v);
  syncing_ = false;
}

std::vector<std::pair<std::string, double>> NameValueTable::pairs() const {
  std::vector<std::pair<std::string, double>> v;
  for (int r = 0; r < table_->rowCount(); ++r)
    if (nameCombo(r) && valueSpin(r)) v.emplace_back(ss(nameCombo(r)->currentText()), valueSpin(r)->value());
  return v;
}

// ---------------------------------------------------------------------------

SignalTable::SignalTable(const QString& targetHeader, QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  table_ = new QTableWidget(0, ColumnCount, this);
  table_->setHorizontalHeaderLabels(
      {targetHeader, tr("Type"), tr("Time [s]"), tr("Value"), tr("Frequency [Hz]"), tr("Phase [rad]"),
       tr("Points \"t r; t r\" or file")});
  setToolTip(tr("One signal per row: its %1, the type (step, ramp, sine, table, file), the time it starts "
                        "and its parameters")
                         .arg(targetHeader));
  table_->horizontalHeaderItem(Value)->setToolTip(
      tr("step: the value after the time (absolute for a reference, added for a disturbance); ramp: the slope per s; "
         "sine: the amplitude"));
  table_->horizontalHeaderItem(Data)->setToolTip(
      tr("table: the points t r separated by ';' (times increasing); file: a CSV (t,value) or .mat (t, value), "
         "relative to the model file"));
  table_->verticalHeader()->setVisible(false);
  // cell widgets do not size their columns: widths that show a combo's word and a number
  const int widths[ColumnCount] = {120, 80, 95, 150, 110, 100, 160};
  for (int c = 0; c < ColumnCount; ++c) table_->setColumnWidth(c, widths[c]);
  table_->horizontalHeader()->setStretchLastSection(true);
  table_->verticalHeader()->setDefaultSectionSize(28);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setMaximumHeight(130);
  layout->addWidget(table_);
  layout->addLayout(buttonRow(this, &add_, &remove_));
  connect(add_, &QPushButton::clicked, this, [this] {
    const QString name =
        firstUnused(choices_, table_->rowCount(), [this](int r) { return targetCombo(r)->currentText(); });
    if (name.isEmpty()) return;  // one signal per target (the core refuses a second)
    SignalSpec s;
    s.output = ss(name);
    addRow(s);
    emit edited(false);
  });
  connect(remove_, &QPushButton::clicked, this, [this] {
    // the row's editors lose focus as they go and may report a last edit: not while half removed
    syncing_ = true;
    const bool removed = removeSelectedRow(table_);
    syncing_ = false;
    if (removed) emit edited(false);
  });
}

QComboBox* SignalTable::targetCombo(int row) const { return qobject_cast<QComboBox*>(table_->cellWidget(row, Target)); }
QComboBox* SignalTable::typeCombo(int row) const { return qobject_cast<QComboBox*>(table_->cellWidget(row, Type)); }
QDoubleSpinBox* SignalTable::spin(int row, Column c) const { return qobject_cast<QDoubleSpinBox*>(table_->cellWidget(row, c)); }
QLineEdit* SignalTable::dataEdit(int row) const { return qobject_cast<QLineEdit*>(table_->cellWidget(row, Data)); }

void SignalTable::setChoices(const QStringList& names) {
  if (names == choices_) return;
  choices_ = names;
  syncing_ = true;
  for (int r = 0; r < table_->rowCount(); ++r) fillCombo(targetCombo(r), choices_, targetCombo(r)->currentText());
  syncing_ = false;
}

void SignalTable::addRow(const SignalSpec& s) {
  const int row = table_->rowCount();
  table_->insertRow(row);
  auto* target = new QComboBox(table_);
  target->setFrame(false);
  fillCombo(target, choices_, qs(s.output));
  auto* type = new QComboBox(table_);
  type->setFrame(false);
  QStringList types;
  for (const auto& t : signal_types()) types << qs(t);
  fillCombo(type, types, qs(s.type));
  const double big = 1e9;
  auto* time = numberSpin(table_, 0.0, big);
  time->setValue(s.time);
  const double value = s.type == "ramp" ? s.slope : s.type == "sine" ? s.amplitude : s.value;
  auto* val = numberSpin(table_, -big, big);
  val->setValue(value);
  auto* freq = numberSpin(table_, 0.0, big);
  freq->setValue(s.frequency);
  auto* phase = numberSpin(table_, -big, big);
  phase->setValue(s.phase);
  auto* data = new QLineEdit(table_);
  data->setFrame(false);
  data->setText(s.type == "file" ? qs(s.file) : pointsText(s.points));
  table_->setCellWidget(row, Target, target);
  table_->setCellWidget(row, Type, type);
  table_->setCellWidget(row, Time, time);
  table_->setCellWidget(row, Value, val);
  table_->setCellWidget(row, Frequency, freq);
  table_->setCellWidget(row, Phase, phase);
  table_->setCellWidget(row, Data, data);
  auto changed = [this] {
    if (!syncing_) emit edited(false);
  };
  auto stepped = [this] {
    if (!syncing_) emit edited(true);
  };
  connect(target, &QComboBox::currentIndexChanged, this, changed);
  connect(type, &QComboBox::currentIndexChanged, this, [this, type, data, changed] {
    for (int r = 0; r < table_->rowCount(); ++r)
      if (typeCombo(r) == type) updateRow(r);
    // a file signal needs its file (the core refuses an empty name): written once it is entered
    if (type->currentText() == QLatin1String("file") && data->text().trimmed().isEmpty()) {
      data->setFocus();
      return;
    }
    changed();
  });
  for (QDoubleSpinBox* sp : {time, val, freq, phase}) connect(sp, &QDoubleSpinBox::valueChanged, this, stepped);
  connect(data, &QLineEdit::editingFinished, this, [data, changed] {
    if (data->isModified()) {
      data->setModified(false);
      changed();
    }
  });
  updateRow(row);
}

void SignalTable::updateRow(int row) {
  const QString t = typeCombo(row)->currentText();
  const bool tabular = t == QLatin1String("table") || t == QLatin1String("file");
  spin(row, Time)->setEnabled(!tabular);
  spin(row, Value)->setEnabled(!tabular);
  spin(row, Value)->setPrefix(t == QLatin1String("ramp") ? tr("slope ") : t == QLatin1String("sine") ? tr("ampl. ") : QString());
  spin(row, Value)->setSuffix(t == QLatin1String("ramp") ? tr(" /s") : QString());
  spin(row, Frequency)->setEnabled(t == QLatin1String("sine"));
  spin(row, Phase)->setEnabled(t == QLatin1String("sine"));
  dataEdit(row)->setEnabled(tabular);
  dataEdit(row)->setPlaceholderText(t == QLatin1String("file") ? tr("ref.csv") : t == QLatin1String("table") ? tr("0 0; 1 0.5") : QString());
}

void SignalTable::setSignals(const std::vector<SignalSpec>& v) {
  std::vector<SignalSpec> now;
  QString ignored;
  if (readSignals(&now, &ignored) && now == v) return;
  syncing_ = true;
  table_->setRowCount(0);
  for (const auto& s : v) addRow(s);
  syncing_ = false;
}

bool SignalTable::readSignals(std::vector<SignalSpec>* out, QString* error) const {
  out->clear();
  for (int r = 0; r < table_->rowCount(); ++r) {
    if (!targetCombo(r) || !typeCombo(r) || !spin(r, Value) || !spin(r, Time) || !spin(r, Frequency) || !spin(r, Phase) ||
        !dataEdit(r))
      continue;  // a row being built or removed
    SignalSpec s;
    s.output = ss(targetCombo(r)->currentText());
    s.type = ss(typeCombo(r)->currentText());
    const double a = spin(r, Value)->value();
    if (s.type == "step" || s.type == "ramp" || s.type == "sine") s.time = spin(r, Time)->value();
    if (s.type == "step") s.value = a;
    if (s.type == "ramp") s.slope = a;
    if (s.type == "sine") {
      s.amplitude = a;
      s.frequency = spin(r, Frequency)->value();
      s.phase = spin(r, Phase)->value();
    }
    const QString data = dataEdit(r)->text().trimmed();
    if (s.type == "file") s.file = ss(data);
    if (s.type == "table") {
      for (const QString& pt : data.split(QLatin1Char(';'), Qt::SkipEmptyParts)) {
        const QStringList xy = pt.split(QRegularExpression(QStringLiteral("[,\\s]+")), Qt::SkipEmptyParts);
        bool ok1 = false, ok2 = false;
        const double t = xy.size() == 2 ? xy[0].toDouble(&ok1) : 0.0, v = xy.size() == 2 ? xy[1].toDouble(&ok2) : 0.0;
        if (!ok1 || !ok2) {
          if (error) *error = tr("row %1: \"%2\" is not a point \"t r\"").arg(r + 1).arg(pt.trimmed());
          return false;
        }
        s.points.emplace_back(t, v);
      }
    }
    out->push_back(std::move(s));
  }
  return true;
}

// ---------------------------------------------------------------------------

void setCheckList(QListWidget* list, const QStringList& names_in, const std::vector<std::string>& checked) {
  const QSignalBlocker b(list);
  QStringList names = names_in;
  for (const auto& c : checked)
    if (!names.contains(qs(c))) names << qs(c);
  bool same = list->count() == names.size();
  for (int i = 0; same && i < names.size(); ++i) same = list->item(i)->text() == names[i];
  if (!same) {
    list->clear();
    for (const QString& n : names) {
      auto* item = new QListWidgetItem(n, list);
      item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable | Qt::ItemIsSelectable);
    }
  }
  for (int i = 0; i < list->count(); ++i) {
    const bool on = std::find(checked.begin(), checked.end(), ss(list->item(i)->text())) != checked.end();
    list->item(i)->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  }
}

std::vector<std::string> checkedNames(const QListWidget* list) {
  std::vector<std::string> v;
  for (int i = 0; i < list->count(); ++i)
    if (list->item(i)->checkState() == Qt::Checked) v.push_back(ss(list->item(i)->text()));
  return v;
}

}  // namespace codyna::gui
