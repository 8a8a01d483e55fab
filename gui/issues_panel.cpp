#include "gui/issues_panel.hpp"

#include <QHeaderView>
#include <QTreeWidget>
#include <QVBoxLayout>

namespace codyna::gui {

IssuesPanel::IssuesPanel(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  list_ = new QTreeWidget(this);
  list_->setObjectName("issuesList");
  list_->setColumnCount(3);
  list_->setHeaderLabels({tr("Element"), tr("Field"), tr("Problem")});
  list_->setRootIsDecorated(false);
  list_->setUniformRowHeights(true);
  list_->setWordWrap(false);
  list_->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
  list_->header()->setSectionResizeMode(1, QHeaderView::ResizeToContents);
  list_->header()->setStretchLastSection(true);
  list_->setToolTip(tr("Every problem of the model, in the file's order: click one to show its element"));
  // the count is the dock's title ("Issues (3)"): no row of its own, the panel as low as the messages
  auto* lay = new QVBoxLayout(this);
  lay->setContentsMargins(0, 0, 0, 0);
  lay->addWidget(list_, 1);
  // after every change's recompile (the issues are new then, and a rename shows in the Element column)
  connect(doc, &Document::modelChanged, this, &IssuesPanel::rebuild);
  auto chosen = [this](QTreeWidgetItem* item) {
    if (!item) return;
    const QString path = item->data(0, Qt::UserRole).toString();
    const auto ref = element_at_path(ss(path));
    if (ref && ref->index < element_count(doc_->spec(), ref->kind)) emit elementChosen(ElementId{ref->kind, ref->index});
    else emit otherChosen(path);
  };
  connect(list_, &QTreeWidget::itemClicked, this, chosen);
  connect(list_, &QTreeWidget::itemActivated, this, chosen);
  rebuild();
}

int IssuesPanel::count() const { return list_->topLevelItemCount(); }

QString IssuesPanel::summary() const { return summary_; }

void IssuesPanel::rebuild() {
  const ModelSpec& spec = doc_->spec();
  list_->clear();
  for (const Document::Issue& issue : doc_->issues()) {
    QString element, field;
    if (const auto ref = element_at_path(ss(issue.path))) {
      const bool there = ref->index < element_count(spec, ref->kind);
      element = there ? QStringLiteral("%1 %2").arg(to_string(ref->kind), qs(element_name(spec, ref->kind, ref->index)))
                      : QStringLiteral("%1 %2").arg(to_string(ref->kind)).arg(ref->index);
      field = qs(ref->field).replace('/', '.');
    } else if (issue.path.startsWith("/plant/inputs")) {
      element = tr("Plant/In");
    } else if (issue.path.startsWith("/plant/outputs")) {
      element = tr("Plant/Out");
    } else {
      element = issue.path.section('/', 1, 1);
      field = issue.path.section('/', 2).replace('/', '.');
    }
    auto* item = new QTreeWidgetItem(list_, {element, field, issue.detail});
    item->setData(0, Qt::UserRole, issue.path);
    item->setToolTip(2, issue.text);
  }
  const int n = count();
  summary_ = n == 0 ? tr("No issues: the model compiles.") : n == 1 ? tr("1 issue: the model does not compile.")
                                                                  : tr("%1 issues: the model does not compile.").arg(n);
  list_->setToolTip(summary_ + "\n" + tr("Every problem of the model, in the file's order: click one to show its element"));
  emit countChanged(n);
}

}  // namespace codyna::gui
