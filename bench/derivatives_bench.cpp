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

namespace {

using namespace codyna;

Eigen::Matrix3d rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

// n = 0: the 28-DOF ball-joint tree (a root hinge, 9 ball joints in three branches)
ModelSpec bench_model(int n) {
  std::mt19937 rng(7 + n);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  ModelSpec s;
  s.name = n ? "chain" + std::to_string(n) : "ball_tree";
  const int nb = n ? n : 10;
  for (int i = 0; i < nb; ++i) {
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 0.5 + u(rng);
    b.com = Eigen::Vector3d(0.3 * u(rng), 0.1 * u(rng), 0.05 * u(rng));
    const Eigen::Matrix3d R = rotation(rng);
    const double a = 0.02 + 0.02 * u(rng), c = 0.02 + 0.02 * u(rng);
    b.inertia = R * Eigen::Vector3d(a, c, 0.5 * (a + c)).asDiagonal() * R.transpose();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.child = b.name;
    if (n) {
      j.type = JointType::Revolute;
      j.parent = i ? "b" + std::to_string(i - 1) : std::string(kGroundName);
      j.axis = i % 3 == 0 ? Eigen::Vector3d::UnitZ() : (i % 3 == 1 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX());
    } else {
      j.type = i == 0 ? JointType::Revolute : JointType::Spherical;
      j.parent = i == 0 ? std::string(kGroundName) : "b" + std::to_string(i <= 3 ? 0 : i - 3);
    }
    j.parent_frame.position = i ? Eigen::Vector3d(0.4, 0.05 * (i % 2), 0.0) : Eigen::Vector3d::Zero();
    s.joints.push_back(j);
    if (j.type == JointType::Revolute) {
      ActuatorSpec a;
      a.name = "m" + std::to_string(i);
      a.joint = j.name;
      s.actuators.push_back(a);
      s.plant.inputs.push_back(a.name);
    } else {
      for (int k = 0; k < 3; ++k) {
        ActuatorSpec a;
        a.name = "m" + std::to_string(i) + "_" + std::to_string(k);
        a.joint = j.name;
        a.dof = k;
        s.actuators.push_back(a);
        s.plant.inputs.push_back(a.name);
      }
    }
  }
  EffectSpec g;
  g.name = "gravity";
  g.type = EffectType::Gravity;
  s.effects.push_back(g);
  return s;
}

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
