#include "gui/maneuver_view.hpp"

#include <QChart>
#include <QComboBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QCheckBox>
#include <QLineEdit>
#include <QLineSeries>
#include <QLocale>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QTimer>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "gui/chart_view.hpp"
#include "gui/document.hpp"
#include "gui/result_plots.hpp"
#include "study/workflow.hpp"

namespace codyna::gui {

namespace {

QString mq(const std::string& s) { return QString::fromStdString(s); }

// a parameter: its flag's name, its label, what an empty field means, the maneuvers it is for
struct ManeuverField {
  const char* key;
  const char* label;
  const char* empty;
  QStringList types;
};

const QList<ManeuverField>& maneuver_fields() {
  static const QList<ManeuverField> f = {
      {"speed", "speed (m/s)", "the model's steady speed",
       {"step-steer", "sine-with-dwell", "swept-sine", "double-lane-change", "constant-speed", "slowly-increasing-steer",
        "fishhook"}},
      {"steer", "steer amplitude", "0.01 (sine: 0.05)", {"step-steer", "sine-with-dwell", "swept-sine", "slowly-increasing-steer", "fishhook"}},
      {"steer-scale", "or x steer at 0.3 g", "FMVSS 126: 1.5 .. 6.5 (ramp 2.5, fishhook 6.5)",
       {"sine-with-dwell", "slowly-increasing-steer", "fishhook"}},
      {"steer-rate", "steer rate (per s)", "13.5 deg/s (fishhook 720 deg/s)", {"slowly-increasing-steer", "fishhook"}},
      {"frequency", "frequency (Hz)", "0.7", {"sine-with-dwell"}},
      {"dwell", "dwell (s)", "0.5 (fishhook 0.25)", {"sine-with-dwell", "fishhook"}},
      {"dwell-roll-rate", "or dwell until roll rate (deg/s)", "NHTSA: 1.5", {"fishhook"}},
      {"frequency-min", "lowest frequency (Hz)", "0.1", {"swept-sine"}},
      {"frequency-max", "highest frequency (Hz)", "2", {"swept-sine"}},
      {"sweep-time", "sweep time (s)", "30", {"swept-sine"}},
      {"radius", "radius (m, > 0 left)", "required", {"constant-radius"}},
      {"speed-min", "lowest speed (m/s)", "5", {"constant-radius"}},
      {"speed-max", "highest speed (m/s)", "the speed of 0.6 g", {"constant-radius"}},
      {"ay-min", "lowest a_y (m/s^2)", "0.5", {"constant-speed"}},
      {"ay-max", "highest a_y (m/s^2)", "0.6 g", {"constant-speed"}},
      {"points", "points", "8 (swept sine: 12)", {"constant-radius", "constant-speed", "swept-sine"}},
      {"width", "vehicle width (m)", "1.8", {"double-lane-change"}},
      {"preview", "driver preview (m)", "the model's", {"double-lane-change"}},
      {"drive", "drive input (holds the speed)", "none", {"double-lane-change", "slowly-increasing-steer"}},
      {"speed-kp", "speed PI: kp (per m/s)", "0", {"double-lane-change", "slowly-increasing-steer"}},
      {"speed-ki", "speed PI: ki (per m)", "0", {"double-lane-change", "slowly-increasing-steer"}},
      {"friction", "friction (controller's reference)", "0.85",
       {"step-steer", "sine-with-dwell", "slowly-increasing-steer", "fishhook", "double-lane-change"}},
      {"t-end", "run length (s)", "the maneuver's",
       {"step-steer", "sine-with-dwell", "swept-sine", "double-lane-change", "slowly-increasing-steer", "fishhook"}},
      {"integrator", "integrator", "the model's",
       {"step-steer", "sine-with-dwell", "swept-sine", "double-lane-change", "slowly-increasing-steer", "fishhook"}},
      {"free-input", "free inputs", "the model's (a turn: steer,drive)",
       {"step-steer", "sine-with-dwell", "swept-sine", "constant-radius", "constant-speed", "slowly-increasing-steer", "fishhook"}},
  };
  return f;
}

// a line series on the chart's two axes
QLineSeries* maneuver_series(QChart* c, const QString& name, const QList<QPointF>& points) {
  auto* s = new QLineSeries;
  s->setName(name);
  s->append(points);
  c->addSeries(s);
  s->attachAxis(c->axes(Qt::Horizontal).value(0));
  s->attachAxis(c->axes(Qt::Vertical).value(0));
  return s;
}

}  // namespace

ManeuverView::ManeuverView(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
  buildUi();
  timer_ = new QTimer(this);
  timer_->setInterval(100);
  connect(timer_, &QTimer::timeout, this, [this] {
    const double t = t_.load(), te = t_end_.load();
    if (te > 0) {
      progress_->setRange(0, 1000);
      progress_->setValue(static_cast<int>(std::clamp(t / te, 0.0, 1.0) * 1000));
      progress_->setFormat(tr("t = %1 of %2 s").arg(t, 0, 'f', 2).arg(te, 0, 'f', 2));
    }
  });
  connect(doc_, &Document::replaced, this, [this] {
    if (isRunning()) drop_result_ = true;  // the running job's result belongs to the old model
    report_.reset();
    report_view_->clear();
    chart_->chart()->removeAllSeries();
    setStatus(QString(), false);
  });
  typeChosen();
  updateButtons();
}

ManeuverView::~ManeuverView() = default;

void ManeuverView::buildUi() {
  auto* outer = new QHBoxLayout(this);
  outer->setContentsMargins(4, 4, 4, 4);
  auto* left = new QVBoxLayout;
  auto* form = new QFormLayout;
  type_ = new QComboBox(this);
  type_->setObjectName("maneuverType");
  for (const char* t : kManeuverTypes) type_->addItem(mq(t), mq(t));
  form->addRow(tr("maneuver"), type_);
  for (const ManeuverField& f : maneuver_fields()) {
    auto* e = new QLineEdit(this);
    e->setObjectName(QStringLiteral("maneuver_%1").arg(f.key));
    e->setPlaceholderText(tr(f.empty));
    auto* l = new QLabel(tr(f.label), this);
    l->setBuddy(e);
    form->addRow(l, e);
    fields_.insert(f.key, e);
    labels_.insert(f.key, l);
  }
  open_loop_ = new QCheckBox(tr("Open loop: leave the model file's controller out"), this);
  open_loop_->setObjectName("maneuverOpenLoop");
  open_loop_->setToolTip(tr("Step steer, sine with dwell, slowly increasing steer and fishhook run the model file's controller "
                            "in the loop (on its Plant/In, never the steer), the double lane change beside its driver; a swept "
                            "sine needs it left out"));
  form->addRow(open_loop_);
  left->addLayout(form);
  auto* buttons = new QHBoxLayout;
  run_ = new QPushButton(tr("Run"), this);
  run_->setObjectName("maneuverRun");
  cancel_button_ = new QPushButton(tr("Cancel"), this);
  cancel_button_->setObjectName("maneuverCancel");
  buttons->addWidget(run_);
  buttons->addWidget(cancel_button_);
  left->addLayout(buttons);
  progress_ = new QProgressBar(this);
  progress_->setObjectName("maneuverProgress");
  progress_->setTextVisible(true);
  progress_->setFormat(QString());
  left->addWidget(progress_);
  status_ = new QLabel(this);
  status_->setObjectName("maneuverStatus");
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  left->addWidget(status_);
  left->addStretch(1);
  auto* right = new QVBoxLayout;
  QChart* chart = ChartView::compactChart(QString());
  chart->addAxis(new QValueAxis, Qt::AlignBottom);
  chart->addAxis(new QValueAxis, Qt::AlignLeft);
  chart_ = new ChartView(chart, this);
  chart_->setObjectName("maneuverChart");
  chart_->setMinimumHeight(260);
  report_view_ = new QPlainTextEdit(this);
  report_view_->setObjectName("maneuverReport");
  report_view_->setReadOnly(true);
  report_view_->setLineWrapMode(QPlainTextEdit::NoWrap);
  QFont mono(QStringLiteral("monospace"));
  mono.setStyleHint(QFont::Monospace);
  report_view_->setFont(mono);
  right->addWidget(chart_, 3);
  right->addWidget(report_view_, 2);
  outer->addLayout(left, 0);
  outer->addLayout(right, 1);
  connect(type_, &QComboBox::currentIndexChanged, this, [this] { typeChosen(); });
  connect(run_, &QPushButton::clicked, this, [this] { run(); });
  connect(cancel_button_, &QPushButton::clicked, this, [this] { cancel(); });
  for (QLineEdit* e : fields_) connect(e, &QLineEdit::returnPressed, this, [this] { run(); });
}

void ManeuverView::typeChosen() {
  const QString t = type_->currentData().toString();
  for (const ManeuverField& f : maneuver_fields()) {
    const bool on = f.types.contains(t);
    fields_[f.key]->setVisible(on);
    labels_[f.key]->setVisible(on);
  }
  open_loop_->setVisible(t == "step-steer" || t == "sine-with-dwell" || t == "swept-sine" || t == "slowly-increasing-steer" ||
                         t == "fishhook" || t == "double-lane-change");
}

QString ManeuverView::statusText() const { return status_->text(); }

void ManeuverView::setStatus(const QString& text, bool error) {
  status_->setText(text);
  status_->setStyleSheet(error ? QStringLiteral("color: #b00020;") : QString());
}

void ManeuverView::updateButtons() {
  run_->setEnabled(!isRunning());
  cancel_button_->setEnabled(isRunning());
  type_->setEnabled(!isRunning());
}

// the request of the fields shown; a field that does not read is refused naming its label
ManeuverRequest ManeuverView::request() const {
  ManeuverRequest r;
  r.style = OptionStyle::Keyword;
  r.type = type_->currentData().toString().toStdString();
  r.model = doc_->filePath().isEmpty() ? std::string("untitled.json") : doc_->filePath().toStdString();
  const auto number = [this](const char* key) -> std::optional<double> {
    const QLineEdit* e = fields_.value(key);
    if (!e || e->isHidden() || e->text().trimmed().isEmpty()) return std::nullopt;
    bool ok = false;
    const double x = QLocale::c().toDouble(e->text().trimmed(), &ok);
    if (!ok || !std::isfinite(x))
      throw std::invalid_argument(QStringLiteral("%1: \"%2\" is not a number").arg(QString::fromUtf8(key), e->text()).toStdString());
    return x;
  };
  r.speed = number("speed");
  r.steer = number("steer");
  r.frequency = number("frequency");
  r.dwell = number("dwell");
  r.dwell_roll_rate = number("dwell-roll-rate");
  r.steer_scale = number("steer-scale");
  r.frequency_min = number("frequency-min");
  r.frequency_max = number("frequency-max");
  r.sweep_time = number("sweep-time");
  r.radius = number("radius");
  r.speed_min = number("speed-min");
  r.speed_max = number("speed-max");
  r.ay_min = number("ay-min");
  r.ay_max = number("ay-max");
  r.width = number("width");
  r.preview = number("preview");
  r.friction = number("friction");
  r.speed_kp = number("speed-kp");
  r.speed_ki = number("speed-ki");
  r.steer_rate = number("steer-rate");
  r.t_end = number("t-end");
  r.open_loop = !open_loop_->isHidden() && open_loop_->isChecked();
  if (const auto p = number("points")) {
    if (*p != std::floor(*p) || std::abs(*p) > 1e6) throw std::invalid_argument("points: expected a whole number");
    r.points = static_cast<int>(*p);
  }
  const QLineEdit* free = fields_.value("free-input");
  if (!free->isHidden() && !free->text().trimmed().isEmpty()) {
    std::vector<std::string> names;
    for (const QString& n : free->text().split(',', Qt::SkipEmptyParts)) names.push_back(n.trimmed().toStdString());
    r.free_inputs = names;
  }
  const QLineEdit* drive = fields_.value("drive");
  if (!drive->isHidden() && !drive->text().trimmed().isEmpty()) r.drive = drive->text().trimmed().toStdString();
  const QLineEdit* integ = fields_.value("integrator");
  if (!integ->isHidden() && !integ->text().trimmed().isEmpty()) r.integrator = integ->text().trimmed().toStdString();
  return r;
}

bool ManeuverView::run() {
  if (isRunning()) return false;
  ManeuverRequest r;
  try {
    r = request();
  } catch (const std::exception& e) {
    setStatus(mq(e.what()), true);
    emit message(tr("Maneuver: %1").arg(mq(e.what())));
    return false;
  }
  t_.store(0);
  t_end_.store(0);
  r.progress = [this](double t, double t_end) {
    t_.store(t);
    t_end_.store(t_end);
  };
  report_.reset();
  const ModelSpec spec = doc_->spec();
  auto result = std::make_shared<std::shared_ptr<const ManeuverReport>>();
  job_.start(
      [r, spec, result](const std::atomic<bool>& cancel, const StudyMessages& tell) mutable {
        r.cancel = &cancel;
        *result = std::make_shared<const ManeuverReport>(study_maneuver_job(r, spec, tell));
      },
      [this, result](const JobOutcome& out) { onFinished(*result, out); });
  progress_->setRange(0, 0);  // busy until the run reports its time
  progress_->setFormat(tr("searching the steady motion..."));
  setStatus(tr("Running %1...").arg(mq(r.type)), false);
  updateButtons();
  timer_->start();
  return true;
}

void ManeuverView::cancel() { job_.cancel(); }

void ManeuverView::onFinished(std::shared_ptr<const ManeuverReport> report, const JobOutcome& out) {
  const QString& error = out.error;
  const bool cancelled = out.cancelled;
  timer_->stop();
  progress_->setRange(0, 1);
  progress_->setValue(cancelled || !error.isEmpty() ? 0 : 1);
  progress_->setFormat(QString());
  updateButtons();
  if (drop_result_) {
    drop_result_ = false;
    setStatus(tr("The maneuver of the previous model was stopped"), false);
    emit finished();
    return;
  }
  for (const QString& n : out.notes) emit message(tr("Maneuver: %1").arg(n));
  if (cancelled) {
    setStatus(tr("Cancelled"), false);
  } else if (!report) {
    setStatus(error, true);
    emit message(tr("Maneuver: %1").arg(error));
  } else {
    report_ = std::move(report);
    report_view_->setPlainText(mq(study_maneuver_text(*report_)));
    showCurve();
    if (report_->valid) setStatus(tr("Done"), false);
    else setStatus(tr("The metrics are invalid: %1").arg(mq(report_->invalid_reason)), true);
  }
  emit finished();
}

void ManeuverView::showCurve() {
  QChart* c = chart_->chart();
  c->removeAllSeries();
  const ManeuverReport& r = *report_;
  constexpr double deg = 180 / std::numbers::pi;
  if (r.type == "constant-radius" || r.type == "constant-speed") {
    QList<QPointF> run, lin;
    for (std::size_t k = 0; k < r.cr_lateral_acceleration.size(); ++k) {
      run << QPointF(r.cr_lateral_acceleration[k], r.cr_road_wheel[k] * deg);
      if (k < r.cr_linear_steer.size() && r.cr_steer[k] != 0)
        lin << QPointF(r.cr_lateral_acceleration[k], r.cr_linear_steer[k] / r.cr_steer[k] * r.cr_road_wheel[k] * deg);
    }
    maneuver_series(c, tr("steady turns"), run);
    if (!lin.isEmpty()) maneuver_series(c, tr("linear model"), lin);
    c->setTitle(tr("Understeer diagram"));
    fitAxesToLines(c, tr("lateral acceleration [m/s^2]"), tr("road-wheel angle [deg]"));
  } else if (r.type == "swept-sine") {
    QList<QPointF> run, lin;
    for (std::size_t k = 0; k < r.sw_frequency.size(); ++k) {
      run << QPointF(r.sw_frequency[k], std::abs(r.sw_yaw[k]));
      if (k < r.sw_yaw_linear.size()) lin << QPointF(r.sw_frequency[k], std::abs(r.sw_yaw_linear[k]));
    }
    maneuver_series(c, tr("run"), run);
    if (!lin.isEmpty()) maneuver_series(c, tr("linear model"), lin);
    c->setTitle(tr("Yaw rate per steer"));
    fitAxesToLines(c, tr("frequency [Hz]"), tr("gain [1/s]"));
  } else if (const auto& names = r.result.output_names;
             r.type == "double-lane-change" && std::count(names.begin(), names.end(), "x") == 1 &&
             std::count(names.begin(), names.end(), "y") == 1) {
    // the car's path (the driver's x and y outputs)
    const int ix = static_cast<int>(std::find(names.begin(), names.end(), "x") - names.begin());
    const int iy = static_cast<int>(std::find(names.begin(), names.end(), "y") - names.begin());
    QList<QPointF> pts;
    for (int i = 0; i < r.result.samples(); ++i) pts << QPointF(r.result.y(i, ix), r.result.y(i, iy));
    maneuver_series(c, tr("path"), pts);
    c->setTitle(tr("The car's path"));
    fitAxesToLines(c, tr("x [m]"), tr("y [m]"));
  } else {
    const std::string wanted = doc_->spec().analysis.handling.yaw_rate;
    const auto it = std::find(names.begin(), names.end(), wanted);
    const int k = it != names.end() ? static_cast<int>(it - names.begin()) : (names.empty() ? -1 : 0);
    if (k >= 0 && r.result.samples() > 0) {
      QList<QPointF> pts;
      for (int i = 0; i < r.result.samples(); ++i) pts << QPointF(r.result.t[static_cast<std::size_t>(i)], r.result.y(i, k));
      maneuver_series(c, mq(names[static_cast<std::size_t>(k)]), pts);
    }
    c->setTitle(tr("Response over time"));
    fitAxesToLines(c, tr("t [s]"), k >= 0 ? mq(names[static_cast<std::size_t>(k)]) : QString());
  }
}

}  // namespace codyna::gui
