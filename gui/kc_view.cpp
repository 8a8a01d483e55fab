#include "gui/kc_view.hpp"

#include <QChart>
#include <QFont>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QVBoxLayout>
#include <QValueAxis>
#include <exception>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"
#include "gui/result_plots.hpp"
#include "study/kc_job.hpp"

namespace codyna::gui {

namespace {

QChart* kc_chart(const QString& title) {
  QChart* c = ChartView::compactChart(title);
  c->addAxis(new QValueAxis, Qt::AlignBottom);
  c->addAxis(new QValueAxis, Qt::AlignLeft);
  return c;
}

void kc_series(QChart* c, const QString& name, const QList<QPointF>& points) {
  auto* s = new QLineSeries;
  s->setName(name);
  s->append(points);
  c->addSeries(s);
  s->attachAxis(c->axes(Qt::Horizontal).value(0));
  s->attachAxis(c->axes(Qt::Vertical).value(0));
}

}  // namespace

KcView::KcView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  auto field = [this](const QString& key, const QString& text, const QString& tip) {
    auto* e = new QLineEdit(text, this);
    e->setObjectName(QStringLiteral("kc_%1").arg(key));
    e->setToolTip(tip);
    e->setMaximumWidth(170);
    connect(e, &QLineEdit::returnPressed, this, [this] { run(); });
    return e;
  };
  wheel_ = field("wheel", QString(), tr("The wheel bodies or their tire elements, comma separated: one (a corner) or two (an "
                                        "axle); empty: the model's only tire"));
  travel_range_ = field("travel", "-0.05:0.05:11", tr("Wheel travel MIN:MAX:N (m, bump positive); empty: none"));
  steer_range_ = field("steer-range", QString(), tr("The steer input MIN:MAX:N (its unit); empty: none"));
  roll_ = field("roll", QString(), tr("Body roll MIN:MAX:N (deg), an axle only; empty: none"));
  fy_ = field("fy", QString(), tr("Lateral load at the contact patch MIN:MAX:N (N); empty: none"));
  fx_ = field("fx", QString(), tr("Longitudinal load at the contact patch MIN:MAX:N (N); empty: none"));
  run_ = new QPushButton(tr("Run"), this);
  run_->setObjectName("kcRun");
  run_->setToolTip(tr("Sweep the suspension held at its body (codyna kc: the same job)"));
  auto* grid = new QGridLayout;
  int col = 0;
  for (auto [label, e] : {std::pair{tr("wheels"), wheel_}, std::pair{tr("travel [m]"), travel_range_},
                          std::pair{tr("steer"), steer_range_}, std::pair{tr("roll [deg]"), roll_},
                          std::pair{tr("Fy [N]"), fy_}, std::pair{tr("Fx [N]"), fx_}}) {
    auto* l = new QLabel(label, this);
    l->setBuddy(e);
    grid->addWidget(l, 0, col);
    grid->addWidget(e, 1, col++);
  }
  grid->addWidget(run_, 1, col);
  grid->setColumnStretch(col + 1, 1);
  error_ = new QLabel(this);
  error_->setObjectName("kcError");
  error_->setWordWrap(true);
  error_->setStyleSheet("QLabel { color: #a00000; background: #ffe8e8; padding: 3px; }");
  error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_->hide();
  travel_ = new ChartView(kc_chart(tr("Camber and toe over wheel travel")), this);
  travel_->setObjectName("kcTravel");
  travel_->setMinimumSize(160, 90);
  steer_ = new ChartView(kc_chart(tr("Toe over the steer")), this);
  steer_->setObjectName("kcSteer");
  steer_->setMinimumSize(160, 90);
  report_view_ = new QPlainTextEdit(this);
  report_view_->setObjectName("kcReport");
  report_view_->setReadOnly(true);
  report_view_->setLineWrapMode(QPlainTextEdit::NoWrap);
  QFont mono(QStringLiteral("monospace"));
  mono.setStyleHint(QFont::Monospace);
  report_view_->setFont(mono);
  auto* charts = new QHBoxLayout;
  charts->addWidget(travel_, 1);
  charts->addWidget(steer_, 1);
  auto* lay = new QVBoxLayout(this);
  lay->addLayout(grid);
  lay->addWidget(error_);
  lay->addLayout(charts, 3);
  lay->addWidget(report_view_, 2);
  connect(run_, &QPushButton::clicked, this, [this] { run(); });
  connect(doc_, &Document::modelChanged, this, [this] {
    // the curves belonged to the model as it was
    report_.reset();
    report_view_->clear();
    travel_->chart()->removeAllSeries();
    steer_->chart()->removeAllSeries();
    error_->hide();
  });
}

KcView::~KcView() = default;

QLineEdit* KcView::field(const QString& key) const {
  if (key == "wheel") return wheel_;
  if (key == "travel") return travel_range_;
  if (key == "steer-range") return steer_range_;
  if (key == "roll") return roll_;
  if (key == "fy") return fy_;
  if (key == "fx") return fx_;
  return nullptr;
}

QString KcView::errorText() const { return error_->isVisible() ? error_->text() : QString(); }

void KcView::showError(const QString& text) {
  error_->setText(text);
  error_->setVisible(!text.isEmpty());
}

bool KcView::run() {
  KcRequest r;
  r.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : doc_->filePath().toStdString();
  r.spec = &doc_->spec();
  try {
    for (const QString& w : wheel_->text().split(',', Qt::SkipEmptyParts))
      if (!w.trimmed().isEmpty()) r.wheels.push_back(w.trimmed().toStdString());
    const auto range = [](const QLineEdit* e, const char* option) -> std::optional<KcRange> {
      const QString t = e->text().trimmed();
      if (t.isEmpty()) return std::nullopt;
      return study_kc_range(t.toStdString(), option);
    };
    r.travel = range(travel_range_, "travel");
    r.steer_range = range(steer_range_, "steer range");
    r.roll = range(roll_, "roll");
    r.fy = range(fy_, "Fy");
    r.fx = range(fx_, "Fx");
    auto rep = std::make_unique<KcReport>(study_kc_job(r));
    report_ = std::move(rep);
  } catch (const std::exception& e) {
    showError(QString::fromStdString(e.what()));
    return false;
  }
  showError(QString());
  report_view_->setPlainText(QString::fromStdString(study_kc_text(*report_)));
  for (const std::string& n : report_->notes) emit message(QString::fromStdString(n));
  showCurves();
  return true;
}

void KcView::showCurves() {
  QChart* tc = travel_->chart();
  QChart* sc = steer_->chart();
  tc->removeAllSeries();
  sc->removeAllSeries();
  const KcReport& r = *report_;
  for (const KcWheel& w : r.wheels) {
    const QString name = QString::fromStdString(w.name);
    const QString suffix = r.wheels.size() > 1 ? QStringLiteral(" (%1)").arg(name) : QString();
    QList<QPointF> camber, toe, steer_toe;
    for (const KcPoint& p : r.points) {
      if (p.wheel != w.name) continue;
      if (p.sweep == "travel") {
        camber << QPointF(p.travel * 1000, p.camber);
        toe << QPointF(p.travel * 1000, p.toe);
      } else if (p.sweep == "steer") {
        steer_toe << QPointF(p.steer, p.toe);
      }
    }
    if (!camber.isEmpty()) {
      kc_series(tc, tr("camber") + suffix, camber);
      kc_series(tc, tr("toe") + suffix, toe);
    }
    if (!steer_toe.isEmpty()) kc_series(sc, tr("toe") + suffix, steer_toe);
  }
  fitAxesToLines(tc, tr("wheel travel [mm]"), tr("angle [deg]"));
  fitAxesToLines(sc, r.steer.empty() ? tr("steer") : QStringLiteral("%1 [%2]").arg(QString::fromStdString(r.steer),
                                                                                     QString::fromStdString(r.steer_unit)),
                 tr("toe [deg]"));
}

}  // namespace codyna::gui
