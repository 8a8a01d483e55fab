#include "gui/plant_panel.hpp"

#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QMimeData>
#include <QPushButton>
#include <QTreeView>
#include <QVBoxLayout>

namespace codyna::gui {

namespace {
const char* kMime = "application/x-codyna-plant-row";

QString limit_text(const std::optional<double>& x) { return x ? QString::number(*x) : QStringLiteral("-"); }
}  // namespace

PlantListModel::PlantListModel(Document* doc, PlantSide side, QObject* parent)
    : QAbstractTableModel(parent), doc_(doc), side_(side) {
  connect(doc, &Document::specChanged, this, [this] {
    beginResetModel();
    sync();
    endResetModel();
  });
  connect(doc, &Document::replaced, this, [this] {  // another model: its own order
    beginResetModel();
    order_.clear();
    sync();
    endResetModel();
  });
  sync();
}

// The rows stay where they are: ticking or unticking moves nothing (the pointer's next click must land
// on the row it aims at). What is shown is kept in order_; a name that appears (a new actuator, a
// rename) goes to the end, one that goes is dropped, and the ticked rows hold the plant's order among
// themselves (after an undo, a load or a reorder elsewhere, the ticked names are dealt into the
// places ticked rows hold).
void PlantListModel::sync() {
  const QStringList sel = selected();
  QStringList all = sel;
  for (const QString& c : candidates())
    if (!all.contains(c)) all << c;
  // a renamed element keeps its row: names that went are taken, in order, by those that came
  QStringList came;
  for (const QString& n : all)
    if (!order_.contains(n)) came << n;
  QStringList next;
  for (const QString& n : order_) {
    if (all.contains(n)) {
      if (!next.contains(n)) next << n;
    } else if (!came.isEmpty()) {
      next << came.takeFirst();
    }
  }
  for (const QString& n : all)
    if (!next.contains(n)) next << n;
  qsizetype k = 0;
  for (QString& n : next)
    if (sel.contains(n)) n = sel[k++];
  order_ = next;
}

QStringList PlantListModel::candidates() const {
  QStringList l;
  if (side_ == PlantSide::In)
    for (const auto& a : doc_->spec().actuators) l << qs(a.name);
  else
    for (const auto& s : doc_->spec().sensors) l << qs(s.name);
  return l;
}

QStringList PlantListModel::selected() const {
  QStringList l;
  for (const auto& n : side_ == PlantSide::In ? doc_->spec().plant.inputs : doc_->spec().plant.outputs) l << qs(n);
  return l;
}

QStringList PlantListModel::rows() const { return order_; }

int PlantListModel::rowCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : static_cast<int>(rows().size()); }
int PlantListModel::columnCount(const QModelIndex& parent) const { return parent.isValid() ? 0 : (side_ == PlantSide::In ? 6 : 4); }

QVariant PlantListModel::headerData(int section, Qt::Orientation o, int role) const {
  if (role != Qt::DisplayRole) return {};
  if (o == Qt::Vertical) {
    const qsizetype k = selected().indexOf(rows().value(section));
    return k >= 0 ? QVariant(QString::number(k + 1)) : QVariant();
  }
  static const QStringList in{tr("Input"), tr("Type"), tr("Unit"), tr("Nominal u0"), tr("Min"), tr("Max")};
  static const QStringList out{tr("Output"), tr("Type"), tr("Unit"), tr("Measures")};
  const QStringList& h = side_ == PlantSide::In ? in : out;
  return section < h.size() ? h[section] : QVariant();
}

QVariant PlantListModel::data(const QModelIndex& index, int role) const {
  const QStringList r = rows();
  if (!index.isValid() || index.row() >= r.size()) return {};
  const QString name = r[index.row()];
  const bool on = selected().contains(name);
  const ModelSpec& s = doc_->spec();
  if (role == Qt::CheckStateRole && index.column() == 0) return on ? Qt::Checked : Qt::Unchecked;
  if (role == Qt::ForegroundRole && !on) return QColor(Qt::gray);
  if (role != Qt::DisplayRole && role != Qt::ToolTipRole) return {};
  if (side_ == PlantSide::In) {
    const int k = find_element(s, ElementKind::Actuator, ss(name));
    if (k < 0) return index.column() == 0 ? QVariant(name + tr(" (missing)")) : QVariant();
    const ActuatorSpec& a = s.actuators[k];
    switch (index.column()) {
      case 0: return on ? QStringLiteral("u%1  %2").arg(selected().indexOf(name) + 1).arg(name) : name;
      case 1:
        if (a.type == ActuatorType::Mix) {
          QStringList driven;
          for (const auto& d : a.drives) driven << qs(d);
          return QStringLiteral("mix of %1").arg(driven.join(", "));
        }
        return QStringLiteral("%1 on %2").arg(to_string(a.type), qs(a.type == ActuatorType::JointForce || a.type == ActuatorType::Motion ? a.joint
                                                                   : a.type == ActuatorType::LineForce ? a.body_a + " - " + a.body_b
                                                                                                       : a.body));
      case 2:
        return qs(a.unit.empty() ? (a.type == ActuatorType::JointForce ? "N | N m"
                                    : a.type == ActuatorType::Motion   ? "m | rad"
                                    : a.type == ActuatorType::BodyTorque ? "N m"
                                                                         : "N")
                                 : a.unit);
      case 3:
        if (a.type == ActuatorType::Motion) return QStringLiteral("q0 of %1").arg(qs(a.joint));  // its nominal value
        return a.u0;
      case 4: return limit_text(a.min);
      case 5: return limit_text(a.max);
    }
  } else {
    const int k = find_element(s, ElementKind::Sensor, ss(name));
    if (k < 0) return index.column() == 0 ? QVariant(name + tr(" (missing)")) : QVariant();
    const SensorSpec& x = s.sensors[k];
    switch (index.column()) {
      case 0: return on ? QStringLiteral("y%1  %2").arg(selected().indexOf(name) + 1).arg(name) : name;
      case 1: return qs(to_string(x.type));
      case 2: return qs(x.unit);
      case 3: return qs(!x.joint.empty() && (x.type == SensorType::JointPosition || x.type == SensorType::JointVelocity || x.type == SensorType::MotionForce) ? x.joint
                        : x.type == SensorType::Distance || x.type == SensorType::DistanceRate ? x.body_a + " - " + x.body_b
                                                                                           : x.body);
    }
  }
  return {};
}

// the ticked rows, top to bottom, are the plant's list
QStringList PlantListModel::tickedInOrder(const QString& also, const QString& without) const {
  const QStringList sel = selected();
  QStringList out;
  for (const QString& n : order_)
    if ((sel.contains(n) || n == also) && n != without) out << n;
  return out;
}

bool PlantListModel::commit(const QStringList& sel) {
  if (sel == selected()) {  // only the order of unticked rows changed: nothing of the model
    beginResetModel();
    endResetModel();
    return true;
  }
  return side_ == PlantSide::In ? doc_->setPlantInputs(sel) : doc_->setPlantOutputs(sel);
}

bool PlantListModel::setChecked(const QString& name, bool on) {
  if (on == selected().contains(name)) return true;
  return commit(on ? tickedInOrder(name, QString()) : tickedInOrder(QString(), name));
}

bool PlantListModel::setData(const QModelIndex& index, const QVariant& value, int role) {
  if (role != Qt::CheckStateRole || index.column() != 0) return false;
  return setChecked(rows().value(index.row()), value.toInt() == Qt::Checked);
}

Qt::ItemFlags PlantListModel::flags(const QModelIndex& index) const {
  if (!index.isValid()) return Qt::ItemIsDropEnabled;
  Qt::ItemFlags f = Qt::ItemIsEnabled | Qt::ItemIsSelectable;
  if (index.column() == 0) f |= Qt::ItemIsUserCheckable;
  f |= Qt::ItemIsDragEnabled;
  return f;
}

bool PlantListModel::moveRow(int from, int to) {
  if (from < 0 || from >= order_.size()) return false;
  to = std::clamp(to, 0, static_cast<int>(order_.size()) - 1);
  if (from == to) return true;
  order_.move(from, to);
  return commit(tickedInOrder(QString(), QString()));
}

bool PlantListModel::moveSelected(int from, int to) {
  const QStringList sel = selected();
  if (from < 0 || from >= sel.size()) return false;
  to = std::clamp(to, 0, static_cast<int>(sel.size()) - 1);
  if (from == to) return true;
  return moveRow(static_cast<int>(order_.indexOf(sel[from])), static_cast<int>(order_.indexOf(sel[to])));
}

Qt::DropActions PlantListModel::supportedDropActions() const { return Qt::MoveAction; }
QStringList PlantListModel::mimeTypes() const { return {kMime}; }

QMimeData* PlantListModel::mimeData(const QModelIndexList& indexes) const {
  if (indexes.isEmpty()) return nullptr;
  auto* m = new QMimeData;
  m->setData(kMime, QByteArray::number(indexes.first().row()));
  return m;
}

bool PlantListModel::dropMimeData(const QMimeData* data, Qt::DropAction, int row, int, const QModelIndex& parent) {
  if (!data || !data->hasFormat(kMime)) return false;
  const int from = data->data(kMime).toInt();
  int to = row >= 0 ? row : parent.isValid() ? parent.row() : static_cast<int>(order_.size());
  if (to > from) --to;  // the row is removed before it is inserted
  moveRow(from, to);
  return false;  // the move is done: the view must not remove anything
}

PlantPanel::PlantPanel(Document* doc, PlantSide side, QWidget* parent) : QWidget(parent), doc_(doc), side_(side) {
  model_ = new PlantListModel(doc, side, this);
  view_ = new QTreeView(this);
  view_->setObjectName(side == PlantSide::In ? "plantInView" : "plantOutView");
  view_->setModel(model_);
  view_->setToolTip(side == PlantSide::In
                        ? tr("Candidate plant inputs (actuators): ticked ones are the columns of B and D, in this order")
                        : tr("Candidate plant outputs (sensors): ticked ones are the rows of C and D, in this order"));
  view_->setRootIsDecorated(false);
  view_->setDragDropMode(QAbstractItemView::InternalMove);
  view_->setDragEnabled(true);
  view_->setAcceptDrops(true);
  view_->setDropIndicatorShown(true);
  view_->setSelectionMode(QAbstractItemView::SingleSelection);
  view_->header()->setSectionResizeMode(QHeaderView::ResizeToContents);
  up_ = new QPushButton(tr("Up"), this);
  down_ = new QPushButton(tr("Down"), this);
  up_->setToolTip(tr("Move the selected signal one place earlier in the plant's order"));
  down_->setToolTip(tr("Move the selected signal one place later in the plant's order"));
  up_->setObjectName("up");
  down_->setObjectName("down");
  summary_ = new QLabel(this);
  summary_->setWordWrap(true);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(up_);
  buttons->addWidget(down_);
  buttons->addStretch(1);
  auto* lay = new QVBoxLayout(this);
  lay->setContentsMargins(4, 4, 4, 4);
  auto* hint = new QLabel(side == PlantSide::In ? tr("Tick the actuators that are the plant's inputs u; drag or Up/Down to order them.")
                                                : tr("Tick the sensors that are the plant's outputs y; drag or Up/Down to order them."),
                          this);
  hint->setWordWrap(true);
  lay->addWidget(hint);
  lay->addWidget(view_, 1);
  lay->addLayout(buttons);
  lay->addWidget(summary_);
  connect(up_, &QPushButton::clicked, this, [this] { moveCurrent(-1); });
  connect(down_, &QPushButton::clicked, this, [this] { moveCurrent(+1); });
  auto refresh = [this] {
    const QStringList sel = model_->selected();
    summary_->setText((side_ == PlantSide::In ? tr("u = [%1]") : tr("y = [%1]")).arg(sel.join(", ")));
  };
  connect(doc, &Document::specChanged, this, refresh);
  refresh();
}

// Up/Down: one row; a ticked row passes the unticked ones up to the next ticked row, so that each
// press changes its place in the plant's order
void PlantPanel::moveCurrent(int delta) {
  const QModelIndex cur = view_->currentIndex();
  if (!cur.isValid()) return;
  const QStringList rows = model_->rows();
  const QStringList sel = model_->selected();
  const int from = cur.row();
  const QString name = rows.value(from);
  int to = from + delta;
  if (sel.contains(name)) {
    for (int r = from + delta; r >= 0 && r < rows.size(); r += delta)
      if (sel.contains(rows[r])) {
        to = r;
        break;
      }
  }
  model_->moveRow(from, to);
  view_->setCurrentIndex(model_->index(static_cast<int>(model_->rows().indexOf(name)), 0));
}

}  // namespace codyna::gui
