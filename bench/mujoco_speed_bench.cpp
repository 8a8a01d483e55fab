// Speed of codyna's dynamics against MuJoCo 2.2.x on the same mechanisms.
//
//   scripts/bench_mujoco.sh [--table FILE] [Google Benchmark flags]
//   build/bin/codyna_bench_mujoco [--models chain_2,tree28] [--table FILE] [flags]
//
// Models (built in codyna as a ModelSpec -> compile, and in MuJoCo from the
// MJCF that tests/peers_mujoco/mjcf.hpp writes for the compiled model):
//   chain_N  N = 1, 2, 4, 7, 15, 30, 60, 90: a 3-D chain of hinges with varied
//            axes, tilted joint frames, off-axis coms and full (non-diagonal)
//            inertia tensors, one joint motor per joint, gravity on
//   tree28   a 16-body humanoid-like tree: ball joints (pelvis, waist,
//            shoulders, hips) and hinges, 28 DOF, one motor per coordinate
// (no contact, limits, passive forces, armature or damping in MuJoCo).
//
// Before timing, each model is checked: codyna's mass matrix (crba) and
// accelerations (forward_dynamics, random non-zero motor inputs) must agree
// with MuJoCo's (mj_fullM of qM, qacc after mj_forward) to 1e-9 relative, or
// the program stops with exit status 2.
//
// What is timed, per model, at one fixed random state (q, v, u):
//   fd     codyna forward_dynamics<double>(q, v, u) (kinematics, applied
//          forces, ABA), vs mj_forward (every stage MuJoCo runs: kinematics,
//          com, mass matrix and its factorization, velocities, bias forces,
//          actuation, qacc)
//   crba   the mass-matrix part alone: codyna crba_composite (after an
//          untimed forward_kinematics(q) + crba_world_terms, which give it
//          the body inertias and motion axes in world axes), vs mj_crb (after
//          an untimed mj_kinematics + mj_comPos, which among other things give
//          mj_crb the same inputs: cinert and cdof)
//   crba_k from the poses to M: codyna crba_after_kinematics (both stages,
//          after an untimed forward_kinematics(q)), vs mj_comPos + mj_crb
//          (after an untimed mj_kinematics)
//   crba_q the whole way from q to M: codyna crba<double>(q) (its own
//          position kinematics included), vs mj_kinematics + mj_comPos + mj_crb
//   jac    the linearization's Jacobians: codyna exact A, B
//          (plant_jacobian(f, x, u, JacobianMethod::Exact) on a PlantFunction
//          built as linearize() does, automatic differentiation), vs
//          mjd_transitionFD(eps = 1e-6, centered) giving MuJoCo's discrete-time
//          A, B (not the same matrices: it is the peer's cost, that is all)
// Benchmarks are run with repetitions in random interleaved order (defaults:
// --benchmark_repetitions=10 --benchmark_enable_random_interleaving=true
// --benchmark_display_aggregates_only=true); the ratio table uses the median
// CPU time of the repetitions, codyna / MuJoCo (below 1: codyna is faster).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/prepare.hpp"
#include "dynamics/data.hpp"
#include "models/speed_models.hpp"
#include "peers_mujoco/mjcf.hpp"
#include "peer_report.hpp"

namespace {

using namespace codyna;

using speed_models::chain;
using speed_models::tree28;

// --- one model in both engines -------------------------------------------------

struct Case {
  std::string name;
  std::unique_ptr<Model> model;
  std::unique_ptr<Data> data;
  peer::MjModelPtr mm;
  peer::MjDataPtr md;
  Eigen::VectorXd q, v, u;
  std::unique_ptr<PlantFunction> plant;
  Eigen::VectorXd x, u_plant;
  std::vector<mjtNum> A, B;  // mjd_transitionFD outputs
};

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

void set_mj_state(Case& c, const peer::Mapped& mp) {
  mj_resetData(c.mm.get(), c.md.get());
  Eigen::Map<Eigen::VectorXd>(c.md->qpos, c.mm->nq) = mp.qpos;
  Eigen::Map<Eigen::VectorXd>(c.md->qvel, c.mm->nv) = mp.qvel;
  Eigen::Map<Eigen::VectorXd>(c.md->ctrl, c.mm->nu) = c.u;
}

// builds the case and checks that the two engines agree on M and qacc
std::unique_ptr<Case> make_case(const ModelSpec& spec, bool& ok) {
  auto c = std::make_unique<Case>();
  c->name = spec.name;
  c->model = std::make_unique<Model>(compile(spec));
  const Model& m = *c->model;
  c->data = std::make_unique<Data>(m);
  const std::string xml = peer::to_mjcf(m, peer::InertiaInput::Principal, true);
  std::string err;
  c->mm = peer::load_mjcf(xml, err);
  if (!c->mm) {
    std::cerr << spec.name << ": mj_loadXML: " << err << "\n";
    ok = false;
    return c;
  }
  c->md.reset(mj_makeData(c->mm.get()));
  if (c->mm->nv != m.nv || c->mm->nu != m.nu()) {
    std::cerr << spec.name << ": MuJoCo has nv " << c->mm->nv << ", nu " << c->mm->nu << "; codyna " << m.nv << ", "
              << m.nu() << "\n";
    ok = false;
    return c;
  }
  std::mt19937 rng(7 + m.nv);
  std::uniform_real_distribution<double> u1(-1.0, 1.0);
  Eigen::VectorXd dq(m.nv);
  for (int i = 0; i < m.nv; ++i) dq[i] = 1.5 * u1(rng);
  c->q = integrate<double>(m, neutral(m), dq);
  c->v.resize(m.nv);
  for (int i = 0; i < m.nv; ++i) c->v[i] = 2.0 * u1(rng);
  c->u.resize(m.nu());
  for (int i = 0; i < m.nu(); ++i) c->u[i] = u1(rng);

  const peer::Mapped mp = peer::map_state(m, c->mm.get(), c->q, c->v);
  set_mj_state(*c, mp);
  mj_forward(c->mm.get(), c->md.get());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Mmj(m.nv, m.nv);
  mj_fullM(c->mm.get(), Mmj.data(), c->md->qM);
  const Eigen::MatrixXd Mcd = crba<double>(m, *c->data, c->q);
  const double eM = rel_diff(Mcd, mp.T.transpose() * Mmj * mp.T);
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, *c->data, c->q, c->v, c->u);
  const double eA = rel_diff(mp.T * qdd + mp.c, Eigen::Map<const Eigen::VectorXd>(c->md->qacc, m.nv));
  std::printf("check %-9s nv %3d: max rel diff to MuJoCo: M %.1e, qacc %.1e\n", spec.name.c_str(), m.nv, eM, eA);
  if (!(eM <= 1e-9 && eA <= 1e-9)) {
    std::cerr << spec.name << ": codyna and MuJoCo disagree; not timing different mechanisms\n";
    ok = false;
  }
  if (c->md->nefc != 0) {
    std::cerr << spec.name << ": MuJoCo has constraint rows\n";
    ok = false;
  }

  // the plant function as linearize() builds it, about q (x = [0; v])
  c->plant = std::make_unique<PlantFunction>(m, c->q, c->u, partition_coordinates(m, c->q));
  c->x = Eigen::VectorXd::Zero(c->plant->nx());
  c->x.tail(m.nv) = c->v;
  c->u_plant = c->u;
  const int nx = 2 * c->mm->nv + c->mm->na;
  c->A.assign(static_cast<std::size_t>(nx) * nx, 0.0);
  c->B.assign(static_cast<std::size_t>(nx) * c->mm->nu, 0.0);
  set_mj_state(*c, mp);
  mj_forward(c->mm.get(), c->md.get());
  return c;
}

std::vector<std::unique_ptr<Case>> g_cases;

// --- benchmarks -------------------------------------------------------------------

void fd_codyna(benchmark::State& st, Case* c) {
  for (auto _ : st) benchmark::DoNotOptimize(forward_dynamics<double>(*c->model, *c->data, c->q, c->v, c->u).data());
}
void fd_mujoco(benchmark::State& st, Case* c) {
  for (auto _ : st) {
    mj_forward(c->mm.get(), c->md.get());
    benchmark::DoNotOptimize(c->md->qacc);
  }
}
void crba_codyna(benchmark::State& st, Case* c) {
  forward_kinematics<double>(*c->model, *c->data, c->q);
  crba_world_terms<double>(*c->model, *c->data);
  for (auto _ : st) benchmark::DoNotOptimize(crba_composite<double>(*c->model, *c->data).data());
}
void crba_mujoco(benchmark::State& st, Case* c) {
  mj_kinematics(c->mm.get(), c->md.get());
  mj_comPos(c->mm.get(), c->md.get());
  for (auto _ : st) {
    mj_crb(c->mm.get(), c->md.get());
    benchmark::DoNotOptimize(c->md->qM);
  }
}
void crba_k_codyna(benchmark::State& st, Case* c) {
  forward_kinematics<double>(*c->model, *c->data, c->q);
  for (auto _ : st) benchmark::DoNotOptimize(crba_after_kinematics<double>(*c->model, *c->data).data());
}
void crba_k_mujoco(benchmark::State& st, Case* c) {
  mj_kinematics(c->mm.get(), c->md.get());
  for (auto _ : st) {
    mj_comPos(c->mm.get(), c->md.get());
    mj_crb(c->mm.get(), c->md.get());
    benchmark::DoNotOptimize(c->md->qM);
  }
}
void crba_q_codyna(benchmark::State& st, Case* c) {
  for (auto _ : st) benchmark::DoNotOptimize(crba<double>(*c->model, *c->data, c->q).data());
}
void crba_q_mujoco(benchmark::State& st, Case* c) {
  for (auto _ : st) {
    mj_kinematics(c->mm.get(), c->md.get());
    mj_comPos(c->mm.get(), c->md.get());
    mj_crb(c->mm.get(), c->md.get());
    benchmark::DoNotOptimize(c->md->qM);
  }
}
void jac_codyna(benchmark::State& st, Case* c) {
  for (auto _ : st) {
    const Eigen::MatrixXd J = plant_jacobian(*c->plant, c->x, c->u_plant, JacobianMethod::Exact);
    benchmark::DoNotOptimize(J.data());
  }
}
void jac_mujoco(benchmark::State& st, Case* c) {
  for (auto _ : st) {
    mjd_transitionFD(c->mm.get(), c->md.get(), 1e-6, 1, c->A.data(), c->B.data(), nullptr, nullptr);
    benchmark::DoNotOptimize(c->A.data());
  }
}

const char* const kOps[] = {"fd", "crba", "crba_k", "crba_q", "jac"};

using bench::PeerCollector;
const auto fmt_time = bench::peer_fmt_time;
const auto fmt_ratio = bench::peer_fmt_ratio;

std::string table(const PeerCollector& col) {
  std::ostringstream t;
  t << "Ratios codyna / MuJoCo " << mj_versionString()
    << " (median CPU time of interleaved repetitions; below 1: codyna is faster)\n\n"
    << "| model | nv | fd: forward_dynamics / mj_forward | crba: mass-matrix part / mj_crb "
       "| crba_k: poses -> M / mj_comPos + mj_crb | crba_q: q -> M | jac: exact A,B / mjd_transitionFD |\n"
    << "|---|---:|---|---|---|---|---|\n";
  for (const auto& c : g_cases) {
    t << "| " << c->name << " | " << c->model->nv;
    for (const char* op : kOps) {
      const double a = col.get(std::string(op) + "/" + c->name + "/codyna");
      const double b = col.get(std::string(op) + "/" + c->name + "/mujoco");
      t << " | **" << fmt_ratio(a, b) << "** (" << fmt_time(a) << " / " << fmt_time(b) << ")";
    }
    t << " |\n";
  }
  return t.str();
}


}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args;
  std::string table_file;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--table" && i + 1 < argc) {
      table_file = argv[++i];
    } else if (a.rfind("--table=", 0) == 0) {
      table_file = a.substr(8);
    } else if ((a == "--models" && i + 1 < argc) || a.rfind("--models=", 0) == 0) {
      std::stringstream ss(a == "--models" ? std::string(argv[++i]) : a.substr(9));
      for (std::string item; std::getline(ss, item, ',');) only.push_back(item);
    } else if (a == "--help" || a == "-h") {
      std::printf("codyna_bench_mujoco [--models chain_2,tree28,...] [--table FILE] [Google Benchmark flags]\n");
      benchmark::PrintDefaultHelp();
      return 0;
    } else {
      args.push_back(a);
    }
  }
  std::printf("MuJoCo %s; codyna %s\n", mj_versionString(), CODYNA_VERSION);
  std::vector<ModelSpec> specs;
  for (int n : {1, 2, 4, 7, 15, 30, 60, 90}) specs.push_back(chain(n));
  specs.push_back(tree28());
  bool ok = true;
  for (const ModelSpec& s : specs) {
    if (!only.empty() && std::find(only.begin(), only.end(), s.name) == only.end()) continue;
    g_cases.push_back(make_case(s, ok));
  }
  if (!ok) return 2;
  if (g_cases.empty()) {
    std::fprintf(stderr, "no model selected\n");
    return 2;
  }
  for (const auto& c : g_cases) {
    Case* p = c.get();
    benchmark::RegisterBenchmark(("fd/" + p->name + "/codyna").c_str(), fd_codyna, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("fd/" + p->name + "/mujoco").c_str(), fd_mujoco, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba/" + p->name + "/codyna").c_str(), crba_codyna, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba/" + p->name + "/mujoco").c_str(), crba_mujoco, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba_k/" + p->name + "/codyna").c_str(), crba_k_codyna, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba_k/" + p->name + "/mujoco").c_str(), crba_k_mujoco, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba_q/" + p->name + "/codyna").c_str(), crba_q_codyna, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("crba_q/" + p->name + "/mujoco").c_str(), crba_q_mujoco, p)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("jac/" + p->name + "/codyna").c_str(), jac_codyna, p)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("jac/" + p->name + "/mujoco").c_str(), jac_mujoco, p)->Unit(benchmark::kMillisecond);
  }

  return bench::run_peer_benchmarks(argv[0], args, table, table_file);
}
