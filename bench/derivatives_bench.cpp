// Cost of the exact plant Jacobian [A B; C D] three ways on the same models,
// in one run: the analytic derivatives (linearize's exact path on trees), the
// forward-mode autodiff of the plant function (the independent check), and
// finite differences (central and forward, with the position stage reused by
// the velocity and input columns, and with a full evaluation per column as
// before: the same numbers); plus one forward-dynamics evaluation for scale.
// Models: 3-D hinge chains of n links (varied axes, full inertias, a motor per
// joint, gravity) and a 28-DOF tree of ball joints; and the closed-loop
// examples (loop/<example>: analytic, autodiff, central differences with a
// full evaluation per column, one plant evaluation), at their initial state.
// MuJoCo side by side: see bench/mujoco_speed_bench.cpp.
//   build/bin/codyna_bench_derivatives
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "bench_models.hpp"

namespace {

using namespace codyna;

using bench::bench_model;


struct Fixture {
  Model m;
  OperatingPoint op;
  PlantFunction f;
  Eigen::VectorXd x, u;
  explicit Fixture(int n)
      : m(compile(bench_model(n))), op(initial_point(m)), f(m, op.q, op.u, partition_coordinates(m, op.q)) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> r(-1, 1);
    x = Eigen::VectorXd::Zero(f.nx());
    for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = r(rng);
    u = Eigen::VectorXd::Zero(f.nu());
    for (int k = 0; k < f.nu(); ++k) u[k] = r(rng);
  }
};

void ExactAnalytic(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  Eigen::MatrixXd J;
  for (auto _ : state) {
    fx.f.analytic_jacobian(fx.x, fx.u, J);
    benchmark::DoNotOptimize(J.data());
  }
  state.counters["nv"] = fx.m.nv;
}
void ExactAutodiff(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(plant_jacobian_autodiff(fx.f, fx.x, fx.u).data());
  state.counters["nv"] = fx.m.nv;
}
// finite differences as linearize does them (PlantFunction::fd_jacobian: the
// velocity and input columns on the position stage of x) ...
void CentralDifferences(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(plant_jacobian(fx.f, fx.x, fx.u, JacobianMethod::CentralDifference).data());
  state.counters["nv"] = fx.m.nv;
}
void ForwardDifferences(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(plant_jacobian(fx.f, fx.x, fx.u, JacobianMethod::ForwardDifference).data());
  state.counters["nv"] = fx.m.nv;
}
// ... and as before it: a full evaluation per perturbed column (the same numbers)
void CentralDifferencesFull(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(plant_jacobian_fd_full(fx.f, fx.x, fx.u, true).data());
  state.counters["nv"] = fx.m.nv;
}
void ForwardDifferencesFull(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(plant_jacobian_fd_full(fx.f, fx.x, fx.u, false).data());
  state.counters["nv"] = fx.m.nv;
}
void ForwardDynamics(benchmark::State& state) {
  Fixture fx(static_cast<int>(state.range(0)));
  Data d(fx.m);
  const Eigen::VectorXd v = fx.x.tail(fx.f.nz()), uall = fx.m.u_nominal();
  for (auto _ : state) benchmark::DoNotOptimize(forward_dynamics<double>(fx.m, d, fx.op.q, v, uall).data());
  state.counters["nv"] = fx.m.nv;
}

// 0 = the ball-joint tree
#define SIZES ->Arg(1)->Arg(2)->Arg(7)->Arg(30)->Arg(90)->Arg(0)->Unit(benchmark::kMicrosecond)
BENCHMARK(ExactAnalytic) SIZES;
BENCHMARK(ExactAutodiff) SIZES;
BENCHMARK(CentralDifferences) SIZES;
BENCHMARK(CentralDifferencesFull) SIZES;
BENCHMARK(ForwardDifferences) SIZES;
BENCHMARK(ForwardDifferencesFull) SIZES;
BENCHMARK(ForwardDynamics) SIZES;

// closed loops: the examples, at their initial state, with a moving independent velocity
struct LoopFixture {
  Model m;
  OperatingPoint op;
  PlantFunction f;
  Eigen::VectorXd x, u;
  explicit LoopFixture(const std::string& name)
      : m(load(name)), op(initial_point(m)), f(m, op.q, op.u, partition_coordinates(m, op.q)) {
    x = Eigen::VectorXd::Zero(f.nx());
    for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = 0.5;
    u = Eigen::VectorXd::Constant(f.nu(), 0.3);
  }
  static Model load(const std::string& name) {
    const std::string path = std::string(CODYNA_SOURCE_DIR) + "/examples/" + name + ".json";
    return compile(load_model_spec(path), path);
  }
};

const char* const kLoops[] = {"four_bar", "andrews_squeezer", "bricard", "iftomm_a02_four_bars"};

int register_loops() {
  for (const char* name : kLoops) {
    const std::string n = name;
    benchmark::RegisterBenchmark(("LoopExactAnalytic/" + n).c_str(), [n](benchmark::State& st) {
      LoopFixture fx(n);
      Eigen::MatrixXd J;
      for (auto _ : st) {
        fx.f.analytic_jacobian(fx.x, fx.u, J);
        benchmark::DoNotOptimize(J.data());
      }
      st.counters["nv"] = fx.m.nv;
      st.counters["dof"] = fx.f.nz();
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("LoopExactAutodiff/" + n).c_str(), [n](benchmark::State& st) {
      LoopFixture fx(n);
      for (auto _ : st) benchmark::DoNotOptimize(plant_jacobian_autodiff(fx.f, fx.x, fx.u).data());
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("LoopCentralDifferences/" + n).c_str(), [n](benchmark::State& st) {
      LoopFixture fx(n);
      for (auto _ : st)
        benchmark::DoNotOptimize(plant_jacobian(fx.f, fx.x, fx.u, JacobianMethod::CentralDifference).data());
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("LoopPlantEval/" + n).c_str(), [n](benchmark::State& st) {
      LoopFixture fx(n);
      Eigen::VectorXd xd, y;
      for (auto _ : st) {
        fx.f.eval<double>(fx.x, fx.u, xd, y);
        benchmark::DoNotOptimize(xd.data());
      }
    })->Unit(benchmark::kMicrosecond);
  }
  return 0;
}
const int registered = register_loops();

}  // namespace

BENCHMARK_MAIN();
