// ResultPlots: the simulation plots of codyna-gui. Two stacked Qt Charts,
// "Plant/In" (the plant inputs u over time) and "Plant/Out" (the plant outputs
// y over time, with the linear prediction y_linear dashed in the same colour),
// as in the figures of the paper (torque and angle against time).
//
// Live mode: reset() starts a run, appendSample() may be called at any rate
// (from slots connected to a worker); samples are buffered and the series are
// updated at most every refreshIntervalMs() by a QTimer (or at once by
// flush()), so plotting never floods the event loop.
//
// Long runs: a series with more than maxPlotPoints() samples is drawn
// decimated (per time bucket the first, minimum, maximum and last sample, so
// peaks stay visible); below that limit the plotted points are the samples.
// Non-finite samples (NaN, Inf) are not plotted.
#pragma once

#include <QElapsedTimer>
#include <QList>
#include <QPointF>
#include <QString>
#include <QStringList>
#include <QWidget>
#include <Eigen/Core>
#include <vector>

#include "study/workflow.hpp"

QT_BEGIN_NAMESPACE
class QTimer;
class QChart;
class QChartView;
class QLineSeries;
class QValueAxis;
QT_END_NAMESPACE

namespace codyna::gui {

// An axis range with a "nice" tick step (1, 2 or 5 times a power of ten)
// covering [lo, hi] with about `ticks` intervals; min and max are multiples of
// step. lo == hi (or non-finite input) gives a small range around the value.
struct NiceRange {
  double min = 0, max = 1, step = 0.2;
};
NiceRange niceRange(double lo, double hi, int ticks = 5);

// Sets a dynamic-tick axis to [min, max] with ticks every `step` (anchored
// at 0) without ever passing through a state with a huge number of ticks
// (a wide range with the old, small interval makes Qt Charts create
// thousands of tick items).
void setAxisRange(QValueAxis* axis, double min, double max, double step);

// The chart's first horizontal and vertical value axes titled and ranged about its line series'
// points (round steps; the labels with the step's decimals).
void fitAxesToLines(QChart* chart, const QString& x_title, const QString& y_title);

// "theta [rad]", or "theta" when the unit is empty.
QString nameWithUnit(const QString& name, const QString& unit);

class ResultPlots : public QWidget {
  Q_OBJECT
 public:
  explicit ResultPlots(QWidget* parent = nullptr);
  ~ResultPlots() override;

  // Starts a live run: series names and units (units may be shorter than the
  // names or empty); the t axis spans 0..tEnd. Clears everything plotted.
  void reset(const QStringList& inputNames, const QStringList& inputUnits, const QStringList& outputNames,
             const QStringList& outputUnits, double tEnd);
  // One sample: u the plant inputs only (inputNames order), y the outputs.
  // Missing entries are ignored, extra ones dropped.
  void appendSample(double t, const Eigen::VectorXd& u, const Eigen::VectorXd& y);
  // Redraws now with what is buffered (no-op when nothing changed).
  void flush();

  // Shows a finished (or partial) result: the plant inputs are the columns
  // plantInputs of r.u (in that order; indices outside r.u are skipped), the
  // outputs r.y; r.y_linear, when it has as many columns as r.y and at least
  // as many rows, is overlaid dashed; r.y_reference (the references r(t) the controller
  // followed) likewise, dotted in grey. The t axis spans the result's times.
  void setResult(const codyna::SimulationResult& r, const std::vector<int>& plantInputs);

  // Vertical marker at time t in both charts (playback); NaN hides it.
  void setTimeCursor(double t);
  double timeCursor() const { return cursor_t_; }

  // Writes the two charts as shown: .png (widget grab) or .svg (vector), by
  // suffix. On failure returns false and says why in *error.
  bool saveImage(const QString& path, QString* error = nullptr);

  // Maximum points per plotted series before decimation (default 4000: two per pixel of a wide
  // chart; min and max of each bucket are kept, so no peak is lost and a redraw stays short).
  int maxPlotPoints() const { return max_points_; }
  void setMaxPlotPoints(int n);

  // for tests
  int refreshIntervalMs() const { return refresh_ms_; }
  void setRefreshIntervalMs(int ms);
  int redrawCount() const { return redraws_; }           // how many times the series were actually updated
  QList<QPointF> inputPoints(int k) const;               // Plant/In series k as plotted
  QList<QPointF> outputPoints(int k) const;              // Plant/Out series k as plotted
  QList<QPointF> linearPoints(int k) const;              // empty when no linear overlay
  QList<QPointF> referencePoints(int k) const;           // r(t) of output k; empty without references
  int inputSeriesCount() const { return static_cast<int>(in_.series.size()); }
  int outputSeriesCount() const { return static_cast<int>(out_.series.size()); }
  QChart* inputChart() const { return in_.chart; }
  QChart* outputChart() const { return out_.chart; }

 private:
  // One chart (Plant/In or Plant/Out) and the data behind its series.
  struct Panel {
    QChart* chart = nullptr;
    QChartView* view = nullptr;
    QValueAxis* axis_t = nullptr;
    QValueAxis* axis_y = nullptr;
    QLineSeries* cursor = nullptr;
    std::vector<QLineSeries*> series, linear, reference;    // linear, reference: empty or one per series
    std::vector<QList<QPointF>> data, linear_data, reference_data;  // all finite samples
    double y_lo = 0, y_hi = 0;                   // data range (y_lo > y_hi: no data)
    double shown_lo = 1, shown_hi = 0;           // current y axis range before niceness
    double extra_left = 0, extra_right = 0;      // margins added to line up the plot areas
  };

  void buildPanel(Panel& p, const QString& title);
  void setupSeries(Panel& p, const QStringList& names, const QStringList& units, bool withLinear,
                   bool withReference = false);
  void clearPanel(Panel& p);
  void updateYRange(Panel& p, bool allowShrink);
  void updateTimeAxis(double tEnd);
  void updateCursor(Panel& p);
  void redraw();
  bool alignPlotAreas();  // true if a margin changed
  void scheduleRedraw();
  QList<QPointF> plotted(const QList<QPointF>& all) const;
  static void extend(Panel& p, double y);

  Panel in_, out_;
  QTimer* timer_ = nullptr;
  QTimer* align_timer_ = nullptr;     // aligns the plot areas once the chart layouts have settled
  QElapsedTimer clock_;               // started at construction
  qint64 last_redraw_ms_ = -1000000;  // clock_ time of the last redraw
  bool dirty_ = false;
  int refresh_ms_ = 100;
  int redraws_ = 0;
  int max_points_ = 4000;
  double t_end_ = 1.0;
  double t_max_seen_ = 0.0;
  double cursor_t_;
  bool aligning_ = false;
};

}  // namespace codyna::gui
