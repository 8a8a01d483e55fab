// linearize() end to end against the exact Jacobian alone, side by side in one
// run (issue 22), and the throughput of a parameter study on 1 and 2 threads.
//
//   Jacobian/<n>   PlantFunction::analytic_jacobian on a plant made once (its
//                  workspace warm, J preallocated): the exact [A B; C D] alone
//   Linearize/<n>  linearize(model, op): the partition, the plant function, the
//                  exact Jacobian, xdot0 and y0, names, units, x0 (everything a
//                  LinearSystem holds), the operating point given; one call
//                  alone (the thread's kept workspaces bound to the model, a
//                  new Linearization returned)
//   Linearizer/<n> the same numbers through a Linearizer kept from call to call
//                  (analysis/linearizer.hpp), written into the same
//                  Linearization: what a study or a trajectory pays per point
// The models are those of bench/derivatives_bench.cpp: 3-D hinge chains of n
// links (varied axes, full inertias, a motor per joint, gravity; n = 7, 30) and
// the 28-DOF ball-joint tree (n = 0), at their initial point with moving
// velocities; Loop*/<example> the same for closed-loop examples (at rest,
// where the general path runs). The ratios Linearize / Jacobian and
// Linearizer / Jacobian are printed at the end for every model (medians when
// --benchmark_repetitions is given).
//
//   Sweep/threads:<t>/variants:<n>  study_sweep_job over the cart-pendulum's
//                  rod mass on a grid of n variants (each variant read,
//                  compiled, linearized at the model's equilibrium, its poles
//                  and the closed loop with the model's LQR fixed), wall-clock
//                  time; the counter variants_per_s is the throughput. n = 200
//                  on 1 and 2 threads, and n = 1 (the study's fixed, serial
//                  cost): the summary estimates from them the speed-up on 16
//                  threads (Amdahl's law; docs/performance.md).
//
//   build/bin/codyna_bench_linearize --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "analysis/linearize.hpp"
#include "analysis/linearizer.hpp"
#include "analysis/operating_point.hpp"
#include "dynamics/prepare.hpp"
#include "io/model_file.hpp"
#include "dynamics/data.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "simulation/simulator.hpp"
#include "study/sweep.hpp"
#include "study/workflow.hpp"
#include "bench_models.hpp"

namespace {

using namespace codyna;

// the models of bench/derivatives_bench.cpp: n = 0 is the 28-DOF ball-joint tree
using bench::bench_model;

// the model at its initial point with moving velocities and nonzero inputs (so
// that no term of the Jacobian vanishes), and the plant's x, u there exactly as
// linearize() forms them
struct Fixture {
  Model m;
  OperatingPoint op;
  Eigen::VectorXd x, u;
  explicit Fixture(Model model) : m(std::move(model)), op(initial_point(m)) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> r(-1, 1);
    if (m.nc == 0)  // closed loops keep their assembled velocities (Jc v = 0)
      for (Eigen::Index k = 0; k < op.v.size(); ++k) op.v[k] = 0.5 * r(rng);
    for (int k : m.plant_inputs) op.u[k] = r(rng);
  }
  PlantFunction plant() const { return PlantFunction(m, op.q, op.u, partition_coordinates(m, op.q)); }
  void state_of(const PlantFunction& f) {
    x = Eigen::VectorXd::Zero(f.nx());
    for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = op.v[f.partition().independent[k]];
    u.resize(f.nu());
    for (int k = 0; k < f.nu(); ++k) u[k] = op.u[m.plant_inputs[k]];
  }
};

Model chain(int n) { return compile(bench_model(n)); }
Model example(const std::string& name) {
  const std::string path = std::string(CODYNA_SOURCE_DIR) + "/examples/" + name + ".json";
  return compile(load_model_spec(path), path);
}

void jacobian(benchmark::State& state, Fixture& fx) {
  const PlantFunction f = fx.plant();
  fx.state_of(f);
  Eigen::MatrixXd J;
  if (!f.analytic_jacobian(fx.x, fx.u, J)) {
    state.SkipWithError("no analytic Jacobian");
    return;
  }
  for (auto _ : state) {
    f.analytic_jacobian(fx.x, fx.u, J);
    benchmark::DoNotOptimize(J.data());
  }
  state.counters["nv"] = fx.m.nv;
}

void linearized(benchmark::State& state, Fixture& fx) {
  for (auto _ : state) {
    const Linearization l = linearize(fx.m, fx.op);
    benchmark::DoNotOptimize(l.system.A.data());
  }
  state.counters["nv"] = fx.m.nv;
}

void linearized_reusing(benchmark::State& state, Fixture& fx) {
  Linearizer lz(fx.m);
  Linearization l;
  for (auto _ : state) {
    lz.linearize(fx.op, {}, l);
    benchmark::DoNotOptimize(l.system.A.data());
  }
  state.counters["nv"] = fx.m.nv;
}

const int kChains[] = {7, 30, 0};
const char* const kLoops[] = {"four_bar", "bricard"};

int register_all() {
  for (int n : kChains) {
    const std::string tag = std::to_string(n);
    benchmark::RegisterBenchmark(("Jacobian/" + tag).c_str(), [n](benchmark::State& st) {
      Fixture fx(chain(n));
      jacobian(st, fx);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Linearize/" + tag).c_str(), [n](benchmark::State& st) {
      Fixture fx(chain(n));
      linearized(st, fx);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Linearizer/" + tag).c_str(), [n](benchmark::State& st) {
      Fixture fx(chain(n));
      linearized_reusing(st, fx);
    })->Unit(benchmark::kMicrosecond);
  }
  for (const char* name : kLoops) {
    const std::string n = name;
    benchmark::RegisterBenchmark(("LoopJacobian/" + n).c_str(), [n](benchmark::State& st) {
      Fixture fx(example(n));
      jacobian(st, fx);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("LoopLinearize/" + n).c_str(), [n](benchmark::State& st) {
      Fixture fx(example(n));
      linearized(st, fx);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("LoopLinearizer/" + n).c_str(), [n](benchmark::State& st) {
      Fixture fx(example(n));
      linearized_reusing(st, fx);
    })->Unit(benchmark::kMicrosecond);
  }
  return 0;
}
const int registered = register_all();

// The sedan (examples/sedan.json, issue 39) on its steady 0.4 g turn at 25 m/s: the steady search
// from the model's start (SedanSteadyTurn), linearize() about the motion found (SedanLinearize:
// automatic differentiation of the motion-frame plant function, and the check a time further along
// the turn, which linearizes once more), one forward-dynamics evaluation there (SedanDynamics: what
// an integrator step costs per evaluation) and one second simulated from the turn
// (SedanSimulate1s, the model's integrator); the NoTires variants leave the four tire effects out
// (the same state) for the tires' share of the first two.
struct SedanBench {
  Model with, without;
  OperatingPoint op;
  SedanBench() {
    const std::string path = std::string(CODYNA_SOURCE_DIR) + "/examples/sedan.json";
    ModelSpec spec = load_model_spec(path);
    spec.analysis.steady.lateral_acceleration = 0.4 * 9.80665;
    with = study_model(spec, path);
    op = study_operating_point(with);
    spec.analysis.disabled_effects = {"tire_fl", "tire_fr", "tire_rl", "tire_rr"};
    std::vector<SensorSpec> kept;
    for (const SensorSpec& s : spec.sensors)
      if (s.name.rfind("Fz_", 0) != 0 && s.name.rfind("slip_angle_", 0) != 0) kept.push_back(s);
    spec.sensors = kept;
    without = study_model(spec, path);
  }
};
const SedanBench& sedan_bench() {
  static const SedanBench s;
  return s;
}

void SedanSteadyTurn(benchmark::State& state) {
  const SedanBench& b = sedan_bench();
  for (auto _ : state) {
    const OperatingPoint op = study_operating_point(b.with);
    benchmark::DoNotOptimize(op.q.data());
  }
}
BENCHMARK(SedanSteadyTurn)->Unit(benchmark::kMillisecond);

void SedanLinearize(benchmark::State& state) {
  const SedanBench& b = sedan_bench();
  const Model& m = state.range(0) ? b.with : b.without;
  LinearizeOptions o;
  o.independent = m.spec.analysis.independent;
  for (auto _ : state) {
    const Linearization l = linearize(m, b.op, o);
    benchmark::DoNotOptimize(l.system.A.data());
  }
}
BENCHMARK(SedanLinearize)->ArgName("tires")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

void SedanDynamics(benchmark::State& state) {
  const SedanBench& b = sedan_bench();
  const Model& m = state.range(0) ? b.with : b.without;
  Data d(m);
  for (auto _ : state) {
    const Eigen::VectorXd& qdd = forward_dynamics<double>(m, d, b.op.q, b.op.v, b.op.u);
    benchmark::DoNotOptimize(qdd.data());
  }
}
BENCHMARK(SedanDynamics)->ArgName("tires")->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

void SedanSimulate1s(benchmark::State& state) {
  const SedanBench& b = sedan_bench();
  SimulationOptions so;
  const Model run = held_at(b.with, b.op, so);
  so.t_end = 1.0;
  so.output_step = 0.01;
  long steps = 0;
  for (auto _ : state) {
    const SimulationResult r = simulate(run, nullptr, nullptr, so);
    if (!r.completed) state.SkipWithError("the run did not complete");
    steps = r.stats.steps;
    benchmark::DoNotOptimize(r.q.data());
  }
  state.counters["steps"] = static_cast<double>(steps);
}
BENCHMARK(SedanSimulate1s)->Unit(benchmark::kMillisecond);

constexpr int kVariants = 200;

// args: threads, variants (1 variant: the study's fixed cost, serial, plus one variant), whole
// file (1: a field outside the element arrays varied too, /solver/rtol over the file's own value
// only, so the same variants, each read from its whole file: what every variant cost before the
// varied elements alone were read again)
void Sweep(benchmark::State& state) {
  const int variants = static_cast<int>(state.range(1));
  SweepRequest r;
  r.model = std::string(CODYNA_SOURCE_DIR) + "/examples/cart_pendulum.json";
  r.vary = {variants > 1 ? "/bodies/1/mass=5:15:" + std::to_string(variants) : std::string("/bodies/1/mass=[10]")};
  if (state.range(2)) r.vary.push_back("/solver/rtol=[1e-8]");
  r.threads = static_cast<int>(state.range(0));
  r.resume = false;
  long long ok = 0;
  for (auto _ : state) {
    const SweepJob job = study_sweep_job(r);
    ok = static_cast<long long>(job.variants.size()) - job.failed;
    benchmark::DoNotOptimize(job.variants.data());
  }
  if (ok != variants) state.SkipWithError("variants failed");
  state.counters["variants_per_s"] =
      benchmark::Counter(static_cast<double>(variants), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(Sweep)
    ->ArgNames({"threads", "variants", "whole_file"})
    ->Args({1, kVariants, 0})
    ->Args({2, kVariants, 0})
    ->Args({1, 1, 0})
    ->Args({1, kVariants, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// the ratio table: Linearize / Jacobian per model, from the median (or the mean
// of one run) of each; and the sweep's speed-up on 2 threads
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      const std::string name = r.run_name.str();
      const bool aggregate = r.run_type == Run::RT_Aggregate;
      if (aggregate && r.aggregate_name != "median") continue;
      if (aggregate) have_median_.insert(name);
      if (!aggregate && have_median_.count(name)) continue;
      double t = r.GetAdjustedCPUTime();
      if (name.rfind("Sweep", 0) == 0) t = r.GetAdjustedRealTime();
      times_[name] = aggregate || !times_.count(name) ? t : std::min(times_[name], t);
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\n%-12s %12s %14s %8s %15s %8s\n", "model", "Jacobian us", "linearize us", "ratio",
                "Linearizer us", "ratio");
    for (const auto& [name, t] : times_) {
      for (const std::string loop : {"", "Loop"}) {
        const std::string p = loop + "Jacobian/";
        if (name.rfind(p, 0) != 0) continue;
        const std::string model = name.substr(p.size());
        const auto other = [&](const std::string& what) {
          const auto it = times_.find(loop + what + "/" + model);
          return it == times_.end() ? 0.0 : it->second;
        };
        const double once = other("Linearize"), reused = other("Linearizer");
        std::printf("%-12s %12.3f %14.3f %8.3f %15.3f %8.3f\n", (model == "0" ? std::string("tree28") : model).c_str(),
                    t, once, once / t, reused, reused / t);
      }
    }
    const auto sweep = [&](const std::string& args) {
      for (const auto& [name, t] : times_)
        if (name.rfind("Sweep/" + args + "/", 0) == 0) return t;
      return 0.0;
    };
    const std::string all = "variants:" + std::to_string(kVariants);
    const double s1 = sweep("threads:1/" + all + "/whole_file:0"), s2 = sweep("threads:2/" + all + "/whole_file:0"),
                 one = sweep("threads:1/variants:1/whole_file:0"), whole = sweep("threads:1/" + all + "/whole_file:1");
    if (s1 > 0 && whole > 0)
      std::printf("\nsweep of %d variants on 1 thread: the varied element read again %.1f ms, each variant's whole file "
                  "read %.1f ms: %.2f times faster\n",
                  kVariants, s1, whole, whole / s1);
    if (s1 > 0 && s2 > 0)
      std::printf("\nsweep of %d variants: 1 thread %.1f ms (%.0f variants/s), 2 threads %.1f ms (%.0f variants/s), "
                  "speed-up %.2f\n",
                  kVariants, s1, 1e3 * kVariants / s1, s2, 1e3 * kVariants / s2, s1 / s2);
    if (s1 > 0 && one > 0) {
      // Amdahl: a serial part (the nominal model, the plan, the results) and variants that share nothing
      const double variant = (s1 - one) / (kVariants - 1), serial = std::max(0.0, one - variant);
      std::printf("a study of 1 variant %.2f ms: serial part %.2f ms, %.3f ms per variant; expected speed-up of %d "
                  "variants on 16 threads (no other limit): %.1f\n",
                  one, serial, variant, kVariants, s1 / (serial + kVariants * variant / 16));
    }
  }

 private:
  std::map<std::string, double> times_;
  std::set<std::string> have_median_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
