#include "gui/tire_view.hpp"

#include <QChart>
#include <QComboBox>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QLocale>
#include <QPushButton>
#include <QShowEvent>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"
#include "gui/result_plots.hpp"
#include "model/errors.hpp"
#include "study/tire_job.hpp"

namespace codyna::gui {

namespace {

constexpr int kTireCurvePoints = 121;      // points per curve (an odd count: alpha = 0 and kappa = 0 are on it)
constexpr double kTireDeg = std::numbers::pi / 180.0;
const char* const kTireElementTag = "element:";
const char* const kTireFileTag = "file:";

QChart* tire_chart(const QString& title) {
  QChart* c = ChartView::compactChart(title);
  auto axis = [](const QString& title) {
    auto* a = new QValueAxis;
    QFont f = a->labelsFont();
    f.setPointSizeF(8);
    a->setLabelsFont(f);
    a->setTitleFont(f);
    a->setTitleText(title);
    a->setLabelFormat("%.4g");
    a->setTickType(QValueAxis::TicksDynamic);
    return a;
  };
  c->addAxis(axis(QString()), Qt::AlignBottom);
  c->addAxis(axis(QString()), Qt::AlignLeft);
  return c;
}

QLineSeries* tire_series(QChart* c, const QString& name) {
  auto* s = new QLineSeries;
  s->setName(name);
  c->addSeries(s);
  s->attachAxis(c->axes(Qt::Horizontal).value(0));
  s->attachAxis(c->axes(Qt::Vertical).value(0));
  return s;
}

std::vector<double> tire_range(double lo, double hi) {
  std::vector<double> v(kTireCurvePoints);
  for (int k = 0; k < kTireCurvePoints; ++k) v[static_cast<std::size_t>(k)] = lo + (hi - lo) * k / (kTireCurvePoints - 1);
  v[kTireCurvePoints / 2] = 0.5 * (lo + hi);  // exactly 0 for a symmetric range
  return v;
}

// one number typed into a field: its value, or an error naming the field
double tire_number(const QLineEdit* e, const QString& what) {
  bool ok = false;
  const double x = QLocale::c().toDouble(e->text().trimmed(), &ok);
  if (!ok || !std::isfinite(x)) throw std::invalid_argument(QStringLiteral("%1: \"%2\" is not a number").arg(what, e->text()).toStdString());
  return x;
}

int tire_column(const TireJob& job, const char* name) {
  const auto it = std::find(job.columns.begin(), job.columns.end(), name);
  if (it == job.columns.end()) throw std::logic_error(std::string("the tire job has no column ") + name);
  return static_cast<int>(it - job.columns.begin());
}

QString tire_load_text(double f) { return QStringLiteral("Fz = %1 N").arg(QString::number(f, 'g', 6)); }

}  // namespace

TireView::TireView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  source_ = new QComboBox(this);
  source_->setObjectName("tireSource");
  source_->setToolTip(tr("The tire: a tire element of the model (its law and numbers as a simulation uses them), or a "
                         ".tir file opened here"));
  source_->setSizeAdjustPolicy(QComboBox::AdjustToContents);
  open_ = new QPushButton(tr("Open .tir..."), this);
  open_->setObjectName("openTirFile");
  open_->setToolTip(tr("Plot a Magic Formula tire property file (.tir: MF 5.2, 6.1, 6.2)"));
  plot_ = new QPushButton(tr("Plot"), this);
  plot_->setObjectName("tirePlot");
  plot_->setToolTip(tr("Evaluate the tire over the slips at the loads given (codyna tire: the same code as the simulation)"));
  auto field = [this](const QString& name, const QString& text, const QString& tip) {
    auto* e = new QLineEdit(text, this);
    e->setObjectName(name);
    e->setToolTip(tip);
    e->setMaximumWidth(150);
    connect(e, &QLineEdit::returnPressed, this, &TireView::refresh);
    return e;
  };
  loads_ = field("tireLoads", QString(), tr("Vertical loads Fz (N): a list 2000, 4000, 6000 or a range A:B:N; empty: 0.5, 1 "
                                            "and 1.5 times the .tir file's FNOMIN"));
  alpha_max_ = field("tireAlphaMax", "15", tr("Slip angles from -A to A degrees"));
  kappa_max_ = field("tireKappaMax", "0.3", tr("Longitudinal slips from -K to K"));
  camber_ = field("tireCamber", "0", tr("Camber angle gamma (deg)"));
  speed_ = field("tireSpeed", "16.7", tr("Forward speed Vx (m/s)"));
  ellipse_alphas_ = field("tireEllipseAlphas", "1, 2, 4, 8",
                          tr("Combined slip: the fixed slip angles (deg), each a curve Fy(Fx) as kappa sweeps, at the middle load"));

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Tire"), this));
  top->addWidget(source_, 1);
  top->addWidget(open_);
  top->addStretch(0);
  auto* grid = new QGridLayout;
  int col = 0;
  for (auto [label, e] : {std::pair{tr("Loads [N]"), loads_}, std::pair{tr("|alpha| max [deg]"), alpha_max_},
                          std::pair{tr("|kappa| max [-]"), kappa_max_}, std::pair{tr("camber [deg]"), camber_},
                          std::pair{tr("Vx [m/s]"), speed_}, std::pair{tr("ellipses at alpha [deg]"), ellipse_alphas_}}) {
    grid->addWidget(new QLabel(label, this), 0, col);
    grid->addWidget(e, 1, col++);
  }
  grid->addWidget(plot_, 1, col);
  grid->setColumnStretch(col + 1, 1);
  tire_ = new QLabel(this);
  tire_->setObjectName("tireEvaluated");
  tire_->setWordWrap(true);
  tire_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_ = new QLabel(this);
  error_->setObjectName("tireError");
  error_->setWordWrap(true);
  error_->setStyleSheet("QLabel { color: #a00000; background: #ffe8e8; padding: 3px; }");
  error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  error_->hide();

  auto view = [this](const QString& title, const QString& name) {
    auto* v = new ChartView(tire_chart(title), this);
    v->setObjectName(name);
    v->setMinimumSize(160, 90);  // the window fits 1024 x 700 (gui.editing_test)
    v->setFrameShape(QFrame::NoFrame);
    return v;
  };
  lateral_ = view(tr("Lateral force Fy (pure slip angle, ISO-W)"), "tireLateral");
  longitudinal_ = view(tr("Longitudinal force Fx (pure slip)"), "tireLongitudinal");
  aligning_ = view(tr("Aligning moment Mz (pure slip angle)"), "tireAligning");
  combined_ = view(tr("Combined slip: Fy against Fx, kappa swept"), "tireCombined");
  auto* charts = new QGridLayout;
  charts->addWidget(lateral_, 0, 0);
  charts->addWidget(longitudinal_, 0, 1);
  charts->addWidget(aligning_, 1, 0);
  charts->addWidget(combined_, 1, 1);

  auto* lay = new QVBoxLayout(this);
  lay->addLayout(top);
  lay->addLayout(grid);
  lay->addWidget(tire_);
  lay->addWidget(error_);
  lay->addLayout(charts, 1);

  connect(open_, &QPushButton::clicked, this, &TireView::chooseTirFile);
  connect(plot_, &QPushButton::clicked, this, &TireView::refresh);
  connect(source_, &QComboBox::activated, this, &TireView::sourceChosen);
  connect(doc_, &Document::specChanged, this, &TireView::fillSources);
  connect(doc_, &Document::modelChanged, this, [this] {
    // a model tire's curves follow its edits (when shown; else when next shown)
    if (source_->currentData().toString().startsWith(kTireElementTag)) {
      stale_ = true;
      if (isVisible()) refresh();
    }
  });
  fillSources();
}

QString TireView::errorText() const { return error_->isVisible() ? error_->text() : QString(); }
QString TireView::tireText() const { return tire_->text(); }

void TireView::showEvent(QShowEvent* e) {
  QWidget::showEvent(e);
  if (stale_) refresh();
}

// the model's tire elements, then the files opened here; the choice kept when it is still there
void TireView::fillSources() {
  const QString was = source_->currentData().toString();
  source_->clear();
  for (const EffectSpec& e : doc_->spec().effects)
    if (e.type == EffectType::Tire) source_->addItem(qs(e.name), QString(kTireElementTag) + qs(e.name));
  for (const QString& f : files_) source_->addItem(QFileInfo(f).fileName(), QString(kTireFileTag) + f);
  const int at = source_->findData(was);
  source_->setCurrentIndex(at >= 0 ? at : 0);
  if (at < 0 && source_->count() > 0) {
    loads_->clear();  // another tire: its own default loads
    stale_ = true;
  }
  if (source_->count() == 0) {
    clearCurves();
    tire_->setText(tr("No tire: add a tire effect to the model (Effect, type tire) or open a .tir file"));
    error_->hide();
  }
}

void TireView::sourceChosen() {
  loads_->clear();
  refresh();
}

bool TireView::showTire(const QString& name) {
  const int at = source_->findData(QString(kTireElementTag) + name);
  if (at < 0) return false;
  if (at != source_->currentIndex()) {
    source_->setCurrentIndex(at);
    loads_->clear();
    stale_ = true;
    if (isVisible()) refresh();
  }
  return true;
}

void TireView::showTirFile(const QString& path) {
  const QString abs = QFileInfo(path).absoluteFilePath();
  if (!files_.contains(abs)) files_ << abs;
  fillSources();
  source_->setCurrentIndex(source_->findData(QString(kTireFileTag) + abs));
  loads_->clear();
  refresh();
}

void TireView::chooseTirFile() {
  QString start = QDir::currentPath();
  if (!doc_->filePath().isEmpty()) start = QFileInfo(doc_->filePath()).absolutePath();
  const QString now = source_->currentData().toString();
  if (now.startsWith(kTireFileTag)) start = QFileInfo(now.mid(int(qstrlen(kTireFileTag)))).absolutePath();
  auto* d = new QFileDialog(this, tr("Open a tire property file"), start, tr("Tire property files (*.tir);;All files (*)"));
  d->setObjectName("tireViewFileDialog");
  d->setOption(QFileDialog::DontUseNativeDialog);
  d->setFileMode(QFileDialog::ExistingFile);
  d->setAcceptMode(QFileDialog::AcceptOpen);
  d->setAttribute(Qt::WA_DeleteOnClose);
  connect(d, &QFileDialog::fileSelected, this, [this](const QString& f) {
    if (!f.isEmpty()) showTirFile(f);
  });
  d->open();
}

void TireView::clearCurves() {
  for (ChartView* v : {lateral_, longitudinal_, aligning_, combined_}) {
    // the series go; the axes stay attached to the chart
    for (QAbstractSeries* s : v->chart()->series()) {
      v->chart()->removeSeries(s);
      delete s;
    }
  }
}

void TireView::showError(const QString& text) {
  clearCurves();
  const bool again = error_->isVisible() && error_->text() == text;  // said once while it stays
  error_->setText(text);
  error_->show();
  if (!again) emit message(text);
}

bool TireView::refresh() {
  stale_ = false;
  const QString src = source_->currentData().toString();
  if (src.isEmpty()) {
    clearCurves();
    return false;
  }
  TireRequest base;
  if (src.startsWith(kTireElementTag)) {
    base.spec = &doc_->spec();
    base.model = ss(doc_->filePath());
    base.tire = ss(src.mid(int(qstrlen(kTireElementTag))));
  } else {
    base.tir = ss(src.mid(int(qstrlen(kTireFileTag))));
  }
  std::vector<double> alphas, kappas, ellipse;
  try {
    if (!loads_->text().trimmed().isEmpty()) base.loads = study_tire_grid(ss(loads_->text().trimmed()), tr("Loads").toStdString());
    const double amax = std::abs(tire_number(alpha_max_, tr("|alpha| max"))) * kTireDeg;
    const double kmax = std::abs(tire_number(kappa_max_, tr("|kappa| max")));
    if (!(amax > 0) || !(amax < 0.5 * std::numbers::pi)) throw std::invalid_argument("|alpha| max: expected an angle from 0 to 90 degrees");
    if (!(kmax > 0)) throw std::invalid_argument("|kappa| max: expected a slip > 0");
    base.gamma = {tire_number(camber_, tr("camber")) * kTireDeg};
    base.speed = tire_number(speed_, tr("Vx"));
    for (double a : study_tire_grid(ss(ellipse_alphas_->text().trimmed()), tr("ellipses at alpha").toStdString()))
      ellipse.push_back(a * kTireDeg);
    alphas = tire_range(-amax, amax);
    kappas = tire_range(-kmax, kmax);
  } catch (const std::exception& e) {
    showError(qs(e.what()));
    return false;
  }
  TireJob lat, lon, comb;
  try {
    if (base.loads.empty() && base.tir.empty()) {
      // the loads the job takes: a Magic Formula tire its file's FNOMIN (0.5, 1, 1.5 times), a
      // linear or Fiala tire (no nominal load) the job's typical loads
      TireRequest probe = base;
      probe.typical_loads = true;
      const TireJob j = study_tire_job(probe);
      const int fz = tire_column(j, "Fz");
      for (Eigen::Index i = 0; i < j.rows.rows(); ++i) base.loads.push_back(j.rows(i, fz));
    }
    TireRequest r = base;
    r.alpha = alphas;
    r.kappa = {0.0};
    lat = study_tire_job(r);
    if (base.loads.empty()) {  // a .tir's default loads, as the job chose them
      const int fz = tire_column(lat, "Fz");
      for (Eigen::Index i = 0; i < lat.rows.rows(); i += kTireCurvePoints) base.loads.push_back(lat.rows(i, fz));
    }
    r = base;
    r.alpha = {0.0};
    r.kappa = kappas;
    lon = study_tire_job(r);
    r = base;
    r.loads = {base.loads[base.loads.size() / 2]};
    r.alpha = ellipse;
    r.kappa = kappas;
    comb = study_tire_job(r);
  } catch (const std::exception& e) {
    // a bad .tir (the reader names the file, section and key), a model that does not compile
    showError(qs(e.what()));
    return false;
  }
  error_->hide();
  if (loads_->text().trimmed().isEmpty()) {
    QStringList l;
    for (double f : base.loads) l << QString::number(f, 'g', 10);
    loads_->setText(l.join(", "));
  }
  QString said = qs(lat.tire);
  for (const std::string& n : lat.notes) said += "; " + qs(n);
  tire_->setText(said);

  clearCurves();
  const int cFx = tire_column(lat, "Fx"), cFy = tire_column(lat, "Fy"), cMz = tire_column(lat, "Mz"),
            ca = tire_column(lat, "alpha"), ck = tire_column(lat, "kappa");
  const int n = kTireCurvePoints;
  // rows: load, camber (one), slip angle, slip: one block of n rows per load (per slip angle in comb)
  for (std::size_t l = 0; l < base.loads.size(); ++l) {
    const QString name = tire_load_text(base.loads[l]);
    QLineSeries* fy = tire_series(lateral_->chart(), name);
    QLineSeries* mz = tire_series(aligning_->chart(), name);
    QLineSeries* fx = tire_series(longitudinal_->chart(), name);
    QList<QPointF> pfy, pmz, pfx;
    for (int k = 0; k < n; ++k) {
      const Eigen::Index i = static_cast<Eigen::Index>(l) * n + k;
      pfy << QPointF(lat.rows(i, ca) / kTireDeg, lat.rows(i, cFy));
      pmz << QPointF(lat.rows(i, ca) / kTireDeg, lat.rows(i, cMz));
      pfx << QPointF(100.0 * lon.rows(i, ck), lon.rows(i, cFx));  // in percent: round ticks, 0 exactly
    }
    fy->replace(pfy);
    mz->replace(pmz);
    fx->replace(pfx);
  }
  for (std::size_t a = 0; a < ellipse.size(); ++a) {
    QLineSeries* s = tire_series(combined_->chart(), QStringLiteral("alpha = %1 deg").arg(QString::number(ellipse[a] / kTireDeg, 'g', 6)));
    QList<QPointF> p;
    for (int k = 0; k < n; ++k) {
      const Eigen::Index i = static_cast<Eigen::Index>(a) * n + k;
      p << QPointF(comb.rows(i, cFx), comb.rows(i, cFy));
    }
    s->replace(p);
  }
  combined_->chart()->setTitle(tr("Combined slip at %1, kappa swept").arg(tire_load_text(base.loads[base.loads.size() / 2])));
  fitAxesToLines(lateral_->chart(), tr("slip angle alpha [deg]"), tr("Fy [N]"));
  fitAxesToLines(longitudinal_->chart(), tr("longitudinal slip kappa [%]"), tr("Fx [N]"));
  fitAxesToLines(aligning_->chart(), tr("slip angle alpha [deg]"), tr("Mz [N m]"));
  fitAxesToLines(combined_->chart(), tr("Fx [N]"), tr("Fy [N]"));
  return true;
}

}  // namespace codyna::gui
