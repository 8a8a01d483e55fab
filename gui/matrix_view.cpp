#include "gui/matrix_view.hpp"

#include <QApplication>
#include <QClipboard>
#include <QContextMenuEvent>
#include <QHeaderView>
#include <QKeyEvent>
#include <QMenu>
#include <algorithm>

#include "gui/matrix_models.hpp"

namespace codyna::gui {

namespace {
QString full(double x) { return QString::number(x, 'g', 17); }
}  // namespace

MatrixView::MatrixView(const QString& name, QWidget* parent) : QTableView(parent), name_(name) {
  setSelectionMode(QAbstractItemView::ContiguousSelection);
  horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  setToolTip(tr("Ctrl+C copies the selected numbers; right click copies %1 as MATLAB or CSV text").arg(name));
}

void MatrixView::setMatrixModel(MatrixTableModel* m) {
  model_ = m;
  setModel(m);
}

QString MatrixView::text(Format f) const {
  if (!model_) return {};
  const Eigen::MatrixXd& M = model_->matrix();
  if (M.size() == 0) return {};
  const int rows = static_cast<int>(M.rows()), cols = static_cast<int>(M.cols());
  auto rowName = [&](int r) { return model_->headerData(r, Qt::Vertical).toString(); };
  auto colName = [&](int c) { return model_->headerData(c, Qt::Horizontal).toString(); };
  QStringList lines;
  switch (f) {
    case Format::Selection: {
      // the selected block (all of it when nothing is selected)
      int r0 = 0, r1 = rows - 1, c0 = 0, c1 = cols - 1;
      const QModelIndexList sel = selectionModel() ? selectionModel()->selectedIndexes() : QModelIndexList();
      if (!sel.isEmpty()) {
        r0 = rows, r1 = -1, c0 = cols, c1 = -1;
        for (const QModelIndex& i : sel) {
          r0 = std::min(r0, i.row()), r1 = std::max(r1, i.row());
          c0 = std::min(c0, i.column()), c1 = std::max(c1, i.column());
        }
      }
      for (int r = r0; r <= r1; ++r) {
        QStringList cells;
        for (int c = c0; c <= c1; ++c) cells << full(M(r, c));
        lines << cells.join('\t');
      }
      return lines.join('\n') + '\n';
    }
    case Format::Matlab: {
      QStringList rn, cn;
      for (int r = 0; r < rows; ++r) rn << rowName(r);
      for (int c = 0; c < cols; ++c) cn << colName(c);
      lines << QStringLiteral("% %1: rows %2; columns %3").arg(name_, rn.join(QLatin1Char(0x20)), cn.join(QLatin1Char(0x20)));
      QStringList body;
      for (int r = 0; r < rows; ++r) {
        QStringList cells;
        for (int c = 0; c < cols; ++c) cells << full(M(r, c));
        body << QStringLiteral("  ") + cells.join(' ');
      }
      lines << QStringLiteral("%1 = [").arg(name_) + '\n' + body.join(";\n") + "];";
      return lines.join('\n') + '\n';
    }
    case Format::Csv: {
      QStringList head{QString()};
      for (int c = 0; c < cols; ++c) head << colName(c);
      lines << head.join(',');
      for (int r = 0; r < rows; ++r) {
        QStringList cells{rowName(r)};
        for (int c = 0; c < cols; ++c) cells << full(M(r, c));
        lines << cells.join(',');
      }
      return lines.join('\n') + '\n';
    }
  }
  return {};
}

void MatrixView::copy(Format f) const {
  const QString t = text(f);
  if (!t.isEmpty()) QApplication::clipboard()->setText(t);
}

void MatrixView::keyPressEvent(QKeyEvent* e) {
  if (e->matches(QKeySequence::Copy)) {
    copy(Format::Selection);
    e->accept();
    return;
  }
  QTableView::keyPressEvent(e);
}

void MatrixView::contextMenuEvent(QContextMenuEvent* e) {
  QMenu menu(this);
  menu.addAction(tr("Copy the selection"), this, [this] { copy(Format::Selection); });
  menu.addAction(tr("Copy %1 as MATLAB").arg(name_), this, [this] { copy(Format::Matlab); });
  menu.addAction(tr("Copy %1 as CSV").arg(name_), this, [this] { copy(Format::Csv); });
  menu.exec(e->globalPos());
}

}  // namespace codyna::gui
