// GUI event-loop stalls during a simulation (a benchmark, not a test: no
// pass/fail on time). Run it offscreen:
//
//   QT_QPA_PLATFORM=offscreen codyna_gui_stall_bench [bricard_t_end]
//
// For each scenario a Document is loaded, a SimulateView runs the simulation on
// its worker thread with live plots, and a 1 ms QTimer on the GUI thread
// records the gaps between its ticks: the longest gap is the longest time the
// GUI could not react (stall). The idle row is the same timer with nothing
// running (this machine's timer resolution and noise). Ticking continues
// 300 ms after the end so that showing the final result (setResult) is counted.
#include <QApplication>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QTimer>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "gui/document.hpp"
#include "gui/result_plots.hpp"
#include "gui/sim_worker.hpp"
#include "gui/simulate_view.hpp"

using namespace codyna;
using namespace codyna::gui;

namespace {

struct Gaps {
  std::vector<double> ms;
  double final_ms = 0;  // the longest gap that ended after `done` became true (showing the result)
  double max() const { return ms.empty() ? 0 : *std::max_element(ms.begin(), ms.end()); }
  double pct(double p) const {
    if (ms.empty()) return 0;
    std::vector<double> s = ms;
    std::sort(s.begin(), s.end());
    return s[std::min(s.size() - 1, static_cast<std::size_t>(p * (s.size() - 1) + 0.5))];
  }
};

// ticks a 1 ms timer while `body` runs and until `done` is true, then `tail_ms` more
Gaps measure(const std::function<void()>& body, const std::function<bool()>& done, int tail_ms) {
  Gaps g;
  QTimer tick;
  tick.setTimerType(Qt::PreciseTimer);
  tick.setInterval(1);
  QElapsedTimer clock;
  qint64 last = -1;
  bool finished = false;
  QObject::connect(&tick, &QTimer::timeout, [&] {
    const qint64 now = clock.nsecsElapsed();
    if (last >= 0) {
      const double gap = (now - last) * 1e-6;
      if (finished || done()) g.final_ms = std::max(g.final_ms, gap);
      else g.ms.push_back(gap);
    }
    last = now;
  });
  QEventLoop loop;
  QTimer poll;
  poll.setInterval(5);
  QElapsedTimer after;
  QObject::connect(&poll, &QTimer::timeout, [&] {
    if (!finished && done()) {
      finished = true;
      after.start();
    }
    if (finished && after.elapsed() >= tail_ms) loop.quit();
  });
  clock.start();
  tick.start();
  poll.start();
  body();
  loop.exec();
  return g;
}

struct Scenario {
  const char* label;
  std::string file;
  double t_end, output_step;
};

}  // namespace

int main(int argc, char** argv) {
  if (!qEnvironmentVariableIsSet("QT_QPA_PLATFORM")) qputenv("QT_QPA_PLATFORM", "offscreen");
  QApplication app(argc, argv);
  const double bricard_t = argc > 1 ? std::atof(argv[1]) : 10.0;

  std::printf("GUI event-loop stalls while a simulation runs (1 ms timer on the GUI thread)\n\n");
  std::printf("%-34s %9s %9s %9s %9s %9s %10s %8s %8s %8s %8s\n", "scenario", "samples", "wall [s]", "max [ms]", "p99 [ms]",
              "p50 [ms]", "final [ms]", "ticks", "redraws", "batches", "status");

  QElapsedTimer idle_clock;
  idle_clock.start();
  const Gaps idle = measure([] {}, [&] { return idle_clock.elapsed() >= 1000; }, 0);
  std::printf("%-34s %9s %9s %9.2f %9.2f %9.2f %10s %8zu %8s %8s %8s\n", "idle event loop (1 s)", "-", "1.00",
              idle.max(), idle.pct(0.99), idle.pct(0.5), "-", idle.ms.size(), "-", "-", "-");

  const std::vector<Scenario> scenarios = {
      {"bricard, model tolerances", CODYNA_EXAMPLES_DIR "/bricard.json", bricard_t, 0.01},
      {"cart_pendulum LQR, 1 ms output", CODYNA_EXAMPLES_DIR "/cart_pendulum.json", 100.0, 0.001},
  };
  for (const Scenario& sc : scenarios) {
    Document doc;
    QString err;
    if (!doc.load(QString::fromStdString(sc.file), &err)) {
      std::fprintf(stderr, "%s: %s\n", sc.file.c_str(), qPrintable(err));
      return 1;
    }
    SolverSpec solver = doc.spec().solver;
    solver.t_end = sc.t_end;
    solver.output_step = sc.output_step;
    doc.setSolver(solver);
    SimulateView view(&doc);
    view.resize(1400, 900);
    view.show();
    QApplication::processEvents();
    bool finished = false;
    QObject::connect(&view, &SimulateView::runFinished, [&] { finished = true; });
    const Gaps g = measure([&] { view.run(); }, [&] { return finished; }, 300);
    const auto r = view.result();
    const QString label = QStringLiteral("%1 (%2 s)").arg(sc.label).arg(sc.t_end);
    std::printf("%-34s %9d %9.2f %9.2f %9.2f %9.2f %10.2f %8zu %8d %8d %8s\n", qPrintable(label), r ? r->samples() : 0,
                view.worker()->wallTime(), g.max(), g.pct(0.99), g.pct(0.5), g.final_ms, g.ms.size(),
                view.plots()->redrawCount(), view.worker()->batchCount(),
                r ? (r->completed ? "ok" : "partial") : "failed");
  }
  std::printf("\nmax, p99, p50: gaps between ticks while the run was live (max = the longest stall of the GUI thread);\n"
              "final: the longest gap after the run ended (showing the whole result); ticks: live ticks seen;\n"
              "redraws: plot series updates; batches: queued sample batches from the worker (at most one per %d ms).\n",
              SimWorker().batchIntervalMs());
  return 0;
}
