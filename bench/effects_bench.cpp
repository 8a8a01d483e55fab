// What a declared effect costs: forward dynamics of the same 12-link chain
// with nothing but gravity, then with joint springs, point-to-point springs and
// joint friction added. Cost should track what is declared: the gravity-only
// model pays nothing for the force elements it does not have.
//   build/bin/codyna_bench_effects            (ratios: compare the times in one run)
#include <benchmark/benchmark.h>

#include "dynamics/forward_dynamics.hpp"
#include "dynamics/prepare.hpp"

namespace {

using namespace codyna;

ModelSpec chain(int n, int joint_springs, int springs, int frictions) {
  ModelSpec s;
  s.name = "chain";
  for (int i = 0; i < n; ++i) {
    BodySpec b;
    b.name = "link" + std::to_string(i);
    b.mass = 1.0;
    b.com = Eigen::Vector3d(0.25, 0, 0);
    b.inertia = Eigen::Vector3d(0.001, 0.02, 0.02).asDiagonal();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.type = JointType::Revolute;
    j.parent = i == 0 ? std::string(kGroundName) : s.bodies[i - 1].name;
    j.child = b.name;
    j.parent_frame.position = Eigen::Vector3d(i == 0 ? 0.0 : 0.5, 0, 0);
    j.axis = (i % 2) ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    s.joints.push_back(j);
  }
  EffectSpec g;
  g.name = "gravity";
  g.type = EffectType::Gravity;
  s.effects.push_back(g);
  for (int k = 0; k < joint_springs; ++k) {
    EffectSpec e;
    e.name = "js" + std::to_string(k);
    e.type = EffectType::JointSpringDamper;
    e.joint = "j" + std::to_string(k % n);
    e.stiffness = 10;
    e.damping = 0.1;
    s.effects.push_back(e);
  }
  for (int k = 0; k < springs; ++k) {
    EffectSpec e;
    e.name = "sp" + std::to_string(k);
    e.type = EffectType::SpringDamper;
    e.body_a = s.bodies[k % n].name;
    e.body_b = s.bodies[(k + 3) % n].name;
    e.stiffness = 100;
    e.damping = 1;
    e.rest_length = 0.3;
    s.effects.push_back(e);
  }
  for (int k = 0; k < frictions; ++k) {
    EffectSpec e;
    e.name = "fr" + std::to_string(k);
    e.type = EffectType::JointFriction;
    e.joint = "j" + std::to_string(k % n);
    e.damping = 0.05;
    s.effects.push_back(e);
  }
  return s;
}

void run(benchmark::State& state, const ModelSpec& spec) {
  const Model m = compile(spec);
  Data d(m);
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(m.nq, 0.1, 0.9), v = Eigen::VectorXd::LinSpaced(m.nv, -1, 1);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(m.nu());
  for (auto _ : state) benchmark::DoNotOptimize(forward_dynamics<double>(m, d, q, v, u).data());
  state.counters["effects"] = static_cast<double>(spec.effects.size());
}

void GravityOnly(benchmark::State& s) { run(s, chain(12, 0, 0, 0)); }
void PlusJointSprings12(benchmark::State& s) { run(s, chain(12, 12, 0, 0)); }
void PlusPointSprings12(benchmark::State& s) { run(s, chain(12, 0, 12, 0)); }
void PlusEverything36(benchmark::State& s) { run(s, chain(12, 12, 12, 12)); }

BENCHMARK(GravityOnly);
BENCHMARK(PlusJointSprings12);
BENCHMARK(PlusPointSprings12);
BENCHMARK(PlusEverything36);

}  // namespace

BENCHMARK_MAIN();
