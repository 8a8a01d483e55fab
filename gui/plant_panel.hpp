// The Control Plant/In and Plant/Out panels (the paper's CADyna panels): the
// candidate inputs (actuators) or outputs (sensors) as a checkable list. Rows
// stay where they are when ticked; the ticked ones, top to bottom, are the plant's
// order (u1, u2, ... in the export), changed by drag and drop or Up/Down. Every change is one
// undo step on the Document, which saves the selection in the model file.
#pragma once

#include <QAbstractTableModel>
#include <QWidget>

#include "gui/document.hpp"

class QTreeView;
class QPushButton;
class QLabel;

namespace codyna::gui {

enum class PlantSide { In, Out };

class PlantListModel : public QAbstractTableModel {
  Q_OBJECT
 public:
  PlantListModel(Document* doc, PlantSide side, QObject* parent = nullptr);
  int rowCount(const QModelIndex& parent = {}) const override;
  int columnCount(const QModelIndex& parent = {}) const override;
  QVariant data(const QModelIndex& index, int role) const override;
  bool setData(const QModelIndex& index, const QVariant& value, int role) override;
  Qt::ItemFlags flags(const QModelIndex& index) const override;
  QVariant headerData(int section, Qt::Orientation o, int role) const override;
  Qt::DropActions supportedDropActions() const override;
  QStringList mimeTypes() const override;
  QMimeData* mimeData(const QModelIndexList& indexes) const override;
  bool dropMimeData(const QMimeData* data, Qt::DropAction action, int row, int column, const QModelIndex& parent) override;

  QStringList rows() const;      // names as shown; the ticked ones among them in plant order
  QStringList selected() const;  // the plant list
  // moves the row `from` to row `to` (ticked ones change the plant's order: one undo step)
  bool moveRow(int from, int to);
  // moves the selected entry `from` (plant position) to plant position `to`; one undo step
  bool moveSelected(int from, int to);
  bool setChecked(const QString& name, bool on);

 private:
  QStringList candidates() const;
  void sync();
  QStringList tickedInOrder(const QString& also, const QString& without) const;
  bool commit(const QStringList& selection);
  QStringList order_;
  Document* doc_;
  PlantSide side_;
};

class PlantPanel : public QWidget {
  Q_OBJECT
 public:
  PlantPanel(Document* doc, PlantSide side, QWidget* parent = nullptr);
  PlantListModel* listModel() { return model_; }
  QTreeView* view() { return view_; }
  QPushButton* upButton() { return up_; }
  QPushButton* downButton() { return down_; }

 private:
  void moveCurrent(int delta);
  Document* doc_;
  PlantSide side_;
  PlantListModel* model_;
  QTreeView* view_;
  QPushButton *up_, *down_;
  QLabel* summary_;
};

}  // namespace codyna::gui
