#include "gui/model_tree.hpp"

#include <QFont>

namespace codyna::gui {

namespace {
// internalId: 0 for a branch, 1 + kind for an element of that kind
constexpr quintptr kBranch = 0;
int kind_row(ElementKind k) { return static_cast<int>(k); }
ElementKind kind_at_row(int r) { return kElementKinds[r]; }

QString type_of(const ModelSpec& s, ElementKind k, int i) {
  switch (k) {
    case ElementKind::Body: return QStringLiteral("%1 kg").arg(s.bodies[i].mass);
    case ElementKind::Joint: return qs(to_string(s.joints[i].type));
    case ElementKind::Constraint: return qs(to_string(s.constraints[i].type));
    case ElementKind::Effect: return qs(to_string(s.effects[i].type));
    case ElementKind::Actuator: return qs(to_string(s.actuators[i].type));
    case ElementKind::Sensor: return qs(to_string(s.sensors[i].type));
  }
  return {};
}
}  // namespace

ModelTreeModel::ModelTreeModel(Document* doc, QObject* parent) : QAbstractItemModel(parent), doc_(doc) {
  connect(doc, &Document::specChanged, this, [this] {
    beginResetModel();
    endResetModel();
  });
}

QString ModelTreeModel::kindTitle(ElementKind k) {
  switch (k) {
    case ElementKind::Body: return tr("Bodies");
    case ElementKind::Joint: return tr("Joints");
    case ElementKind::Constraint: return tr("Loop closures");
    case ElementKind::Effect: return tr("Effects");
    case ElementKind::Actuator: return tr("Actuators (candidate inputs)");
    case ElementKind::Sensor: return tr("Sensors (candidate outputs)");
  }
  return {};
}

QModelIndex ModelTreeModel::index(int row, int column, const QModelIndex& parent) const {
  if (!hasIndex(row, column, parent)) return {};
  if (!parent.isValid()) return createIndex(row, column, kBranch);
  if (parent.internalId() != kBranch) return {};
  return createIndex(row, column, quintptr(1 + parent.row()));
}

QModelIndex ModelTreeModel::parent(const QModelIndex& child) const {
  if (!child.isValid() || child.internalId() == kBranch) return {};
  return createIndex(int(child.internalId() - 1), 0, kBranch);
}

int ModelTreeModel::rowCount(const QModelIndex& parent) const {
  if (!parent.isValid()) return static_cast<int>(std::size(kElementKinds));
  if (parent.column() != 0 || parent.internalId() != kBranch) return 0;
  return element_count(doc_->spec(), kind_at_row(parent.row()));
}

int ModelTreeModel::columnCount(const QModelIndex&) const { return 2; }

QVariant ModelTreeModel::headerData(int section, Qt::Orientation o, int role) const {
  if (o != Qt::Horizontal || role != Qt::DisplayRole) return {};
  return section == 0 ? tr("Name") : tr("Type");
}

std::optional<ElementId> ModelTreeModel::elementAt(const QModelIndex& index) const {
  if (!index.isValid() || index.internalId() == kBranch) return std::nullopt;
  const ElementKind k = kind_at_row(int(index.internalId() - 1));
  if (index.row() >= element_count(doc_->spec(), k)) return std::nullopt;
  return ElementId{k, index.row()};
}

std::optional<ElementKind> ModelTreeModel::kindAt(const QModelIndex& index) const {
  if (!index.isValid()) return std::nullopt;
  if (index.internalId() == kBranch) return kind_at_row(index.row());
  return kind_at_row(int(index.internalId() - 1));
}

QModelIndex ModelTreeModel::indexOf(ElementId id, int column) const {
  if (id.index < 0 || id.index >= element_count(doc_->spec(), id.kind)) return {};
  return createIndex(id.index, column, quintptr(1 + kind_row(id.kind)));
}

QModelIndex ModelTreeModel::kindIndex(ElementKind k) const { return createIndex(kind_row(k), 0, kBranch); }

QVariant ModelTreeModel::data(const QModelIndex& index, int role) const {
  if (!index.isValid()) return {};
  if (index.internalId() == kBranch) {
    const ElementKind k = kind_at_row(index.row());
    if (role == Qt::DisplayRole && index.column() == 0) return kindTitle(k);
    if (role == Qt::DisplayRole && index.column() == 1) return QString::number(element_count(doc_->spec(), k));
    if (role == Qt::FontRole) {
      QFont f;
      f.setBold(true);
      return f;
    }
    return {};
  }
  const auto id = elementAt(index);
  if (!id) return {};
  if (role == Qt::DisplayRole || role == Qt::EditRole)
    return index.column() == 0 ? qs(element_name(doc_->spec(), id->kind, id->index)) : type_of(doc_->spec(), id->kind, id->index);
  if (role == Qt::ToolTipRole && index.column() == 0) {
    const auto refs = references_to(doc_->spec(), id->kind, element_name(doc_->spec(), id->kind, id->index));
    QStringList l;
    for (const auto& r : refs) l << qs(r);
    return l.isEmpty() ? QVariant() : QVariant(tr("Referenced by:\n") + l.join('\n'));
  }
  return {};
}

bool ModelTreeModel::setData(const QModelIndex& index, const QVariant& value, int role) {
  const auto id = elementAt(index);
  if (!id || role != Qt::EditRole || index.column() != 0) return false;
  QString error;
  if (!doc_->rename(id->kind, id->index, value.toString().trimmed(), &error)) {
    emit renameFailed(error);
    return false;
  }
  return true;
}

Qt::ItemFlags ModelTreeModel::flags(const QModelIndex& index) const {
  if (!index.isValid()) return Qt::NoItemFlags;
  Qt::ItemFlags f = Qt::ItemIsEnabled | Qt::ItemIsSelectable;
  if (index.internalId() != kBranch && index.column() == 0) f |= Qt::ItemIsEditable;
  return f;
}

}  // namespace codyna::gui
