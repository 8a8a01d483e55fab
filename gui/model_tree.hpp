// ModelTreeModel: the Document's elements as a tree, one branch per kind
// (Bodies, Joints, Loop closures, Effects, Actuators, Sensors). It reads the
// Document every time (no copy of the spec); names are edited in place, which
// renames through the Document (every reference follows, one undo step).
#pragma once

#include <QAbstractItemModel>
#include <optional>

#include "gui/document.hpp"

namespace codyna::gui {

struct ElementId {
  ElementKind kind;
  int index = 0;
  bool operator==(const ElementId&) const = default;
};

class ModelTreeModel : public QAbstractItemModel {
  Q_OBJECT
 public:
  explicit ModelTreeModel(Document* doc, QObject* parent = nullptr);

  QModelIndex index(int row, int column, const QModelIndex& parent = {}) const override;
  QModelIndex parent(const QModelIndex& child) const override;
  int rowCount(const QModelIndex& parent = {}) const override;
  int columnCount(const QModelIndex& parent = {}) const override;
  QVariant data(const QModelIndex& index, int role) const override;
  bool setData(const QModelIndex& index, const QVariant& value, int role) override;
  Qt::ItemFlags flags(const QModelIndex& index) const override;
  QVariant headerData(int section, Qt::Orientation o, int role) const override;

  QModelIndex indexOf(ElementId id, int column = 0) const;
  QModelIndex kindIndex(ElementKind k) const;
  std::optional<ElementId> elementAt(const QModelIndex& index) const;
  std::optional<ElementKind> kindAt(const QModelIndex& index) const;  // an element's kind or a branch's
  static QString kindTitle(ElementKind k);

 signals:
  void renameFailed(const QString& message);

 private:
  Document* doc_;
};

}  // namespace codyna::gui
