// Speed of codyna's dynamics and exact derivatives against Pinocchio's on identical models.
//
//   cmake -DCODYNA_PINOCCHIO_DIR=/path/to/pinocchio/install ...   (an installed Pinocchio 3,
//   found with find_package(pinocchio CONFIG); never a dependency of the build)
//   build/bin/codyna_bench_pinocchio [--models chain_2,tree28] [--table FILE] [Google Benchmark flags]
//
// The models are the speed models (tests/models/speed_models.hpp): 3-D hinge chains of 2, 7, 30
// and 60 links with tilted joint frames, varied axes, off-axis coms and full inertias, a motor per
// joint and gravity; and the 28-DOF tree of ball joints and hinges. Pinocchio's model is built from
// codyna's compiled Model: each hinge becomes Pinocchio's fastest revolute (JointModelRZ) in a joint
// frame turned so that its axis is z, each ball joint a JointModelSpherical (its angular velocity in
// the child frame and its tangent on the right, as codyna's), and each body's inertia is placed in
// that joint frame. So both programs have the same coordinates q, v (only the quaternion's order
// differs: codyna w,x,y,z, Pinocchio x,y,z,w).
//
// Before timing, at a random state (q, v, u) of each model, the two must agree to 1e-10 (relative to
// the largest entry) on the mass matrix, the accelerations, the inverse dynamics and the derivatives
// of the accelerations with respect to q, v and the joint torques; otherwise the program stops
// with exit status 2.
//
// What is timed (Pinocchio's calls with its default LOCAL convention and with WORLD, the faster of
// the two in the table):
//   fd      codyna forward_dynamics<double>(q, v, u) (kinematics, gravity and motors, ABA)
//           vs pinocchio::aba(q, v, tau)
//   rnea    codyna rnea<double>(q, v, a) vs pinocchio::rnea(q, v, a)
//   crba    codyna crba<double>(q) (q to the whole M) vs pinocchio::crba(q) (its upper triangle)
//   deriv   the derivative pass: codyna TreeDerivatives::compute(q, v, u, no sensors) (qdd and its
//           derivatives with respect to q, v and the motor inputs)
//   jac     the whole plant Jacobian as linearize() takes it: PlantFunction::analytic_jacobian
//           (A, B, C, D into a kept matrix)
//           both vs pinocchio::computeABADerivatives(q, v, tau) (ddq_dq, ddq_dv, Minv)
// Repetitions run in random interleaved order; the table has the median CPU times and the ratios
// codyna / Pinocchio (below 1: codyna is faster).
#include <benchmark/benchmark.h>

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>
#include <pinocchio/multibody/joint/joints.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
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
#include "dynamics/data.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/prepare.hpp"
#include "dynamics/rnea.hpp"
#include "models/speed_models.hpp"
#include "peer_report.hpp"

namespace {

using namespace codyna;
namespace pin = pinocchio;

struct PinCase {
  std::string name;
  std::unique_ptr<Model> model;
  std::unique_ptr<Data> data;
  std::unique_ptr<TreeDerivatives> deriv;
  std::unique_ptr<PlantFunction> plant;
  Eigen::VectorXd q, v, u, a, x, tau;
  Eigen::MatrixXd J;
  pin::Model pm;
  std::unique_ptr<pin::Data> pd;
  Eigen::VectorXd pq, pv, pa, ptau;  // the same state in Pinocchio's order
  std::vector<int> vmap;
  std::vector<int> no_outputs;
};

pin::SE3 to_pin(const SE3& X) { return pin::SE3(X.R, X.p); }

// a rotation that takes z to the unit vector a
Eigen::Matrix3d z_to(const Eigen::Vector3d& a) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), a).toRotationMatrix();
}

// Pinocchio's model of a codyna tree of hinges and ball joints; false (with a message) otherwise.
// Pinocchio wants each subtree's coordinates contiguous (depth-first order; its crba reads the tree
// that way), codyna does not: vmap[i] is the Pinocchio index of codyna's velocity coordinate i.
bool build_pinocchio(const Model& m, pin::Model& pm, Eigen::VectorXd& gain, std::vector<int>& vmap, std::string& why) {
  pm = pin::Model();
  std::vector<int> order, stack{0};
  while (!stack.empty()) {
    const int b = stack.back();
    stack.pop_back();
    if (b > 0) order.push_back(b);
    for (int k = m.nbodies - 1; k >= 1; --k)
      if (m.joints[k].parent == b) stack.push_back(k);
  }
  std::vector<pin::JointIndex> jid(m.nbodies, 0);
  std::vector<pin::SE3> body_in_joint(m.nbodies, pin::SE3::Identity());  // body frame in its Pinocchio joint frame
  vmap.assign(m.nv, -1);
  for (int b : order) {
    const JointModel& j = m.joints[b];
    const int p = j.parent;
    Eigen::Matrix3d Ra = Eigen::Matrix3d::Identity();
    pin::JointIndex id = 0;
    const pin::SE3 placement_base = body_in_joint[p] * to_pin(j.X_PF);
    if (j.type == JointType::Revolute) {
      Ra = z_to(j.axis);
      id = pm.addJoint(jid[p], pin::JointModelRZ(), placement_base * pin::SE3(Ra, Eigen::Vector3d::Zero()), j.name);
    } else if (j.type == JointType::Spherical) {
      id = pm.addJoint(jid[p], pin::JointModelSpherical(), placement_base, j.name);
    } else {
      why = "joint " + j.name + ": only hinges and ball joints are mapped";
      return false;
    }
    for (int k = 0; k < j.nv; ++k) vmap[j.idx_v + k] = pm.joints[id].idx_v() + k;
    jid[b] = id;
    // child body frame C: M = J(q) Ra^T and C = M X_CM^-1
    body_in_joint[b] = pin::SE3(Ra.transpose(), Eigen::Vector3d::Zero()) * to_pin(j.X_CM.inverse());
    const double mass = m.mass[b];
    const Eigen::Vector3d c = m.com[b];
    const Eigen::Matrix3d I_o = m.inertia[b].topLeftCorner<3, 3>();
    const Eigen::Matrix3d I_c = I_o - mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    pm.appendBodyToJoint(id, pin::Inertia(mass, c, I_c), body_in_joint[b]);
  }
  gain = Eigen::VectorXd::Zero(m.nv);
  for (const auto& a : m.spec.actuators) {
    for (int b = 1; b < m.nbodies; ++b)
      if (m.joints[b].name == a.joint) gain[m.joints[b].idx_v + a.dof] = a.gain;
  }
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (const auto& e : m.spec.effects)
    if (e.type == EffectType::Gravity) g = e.g;
  pm.gravity = pin::Motion(g, Eigen::Vector3d::Zero());
  return true;
}

// a codyna vector or matrix in Pinocchio's coordinate order
Eigen::VectorXd to_pin_v(const std::vector<int>& vmap, const Eigen::VectorXd& x) {
  Eigen::VectorXd r(x.size());
  for (int i = 0; i < x.size(); ++i) r[vmap[i]] = x[i];
  return r;
}
Eigen::MatrixXd to_pin_m(const std::vector<int>& vmap, const Eigen::MatrixXd& A) {
  Eigen::MatrixXd r(A.rows(), A.cols());
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j) r(vmap[i], vmap[j]) = A(i, j);
  return r;
}

Eigen::VectorXd to_pin_q(const Model& m, const pin::Model& pm, const Eigen::VectorXd& q) {
  Eigen::VectorXd pq(m.nq);
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    const int iq = pm.joints[pm.getJointId(j.name)].idx_q();
    if (j.type == JointType::Spherical) {
      pq.segment<3>(iq) = q.segment<3>(j.idx_q + 1);
      pq[iq + 3] = q[j.idx_q];
    } else {
      pq.segment(iq, j.nq) = q.segment(j.idx_q, j.nq);
    }
  }
  return pq;
}

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

std::unique_ptr<PinCase> make_case(const ModelSpec& spec, bool& ok) {
  auto c = std::make_unique<PinCase>();
  c->name = spec.name;
  c->model = std::make_unique<Model>(compile(spec));
  const Model& m = *c->model;
  c->data = std::make_unique<Data>(m);
  Eigen::VectorXd gain;
  std::string why;
  if (!build_pinocchio(m, c->pm, gain, c->vmap, why)) {
    std::cerr << spec.name << ": " << why << "\n";
    ok = false;
    return c;
  }
  c->pd = std::make_unique<pin::Data>(c->pm);
  std::mt19937 rng(11 + m.nv);
  std::uniform_real_distribution<double> u1(-1.0, 1.0);
  Eigen::VectorXd dq(m.nv);
  for (int i = 0; i < m.nv; ++i) dq[i] = 1.5 * u1(rng);
  c->q = integrate<double>(m, neutral(m), dq);
  c->v.resize(m.nv);
  c->a.resize(m.nv);
  for (int i = 0; i < m.nv; ++i) c->v[i] = 2.0 * u1(rng), c->a[i] = u1(rng);
  c->u.resize(m.nu());
  for (int i = 0; i < m.nu(); ++i) c->u[i] = u1(rng);
  c->tau = gain.cwiseProduct(c->u);  // one motor per coordinate, in the same order
  c->pq = to_pin_q(m, c->pm, c->q);
  c->pv = to_pin_v(c->vmap, c->v);
  c->pa = to_pin_v(c->vmap, c->a);
  c->ptau = to_pin_v(c->vmap, c->tau);

  const Eigen::MatrixXd M = crba<double>(m, *c->data, c->q);
  pin::crba(c->pm, *c->pd, c->pq);
  const Eigen::MatrixXd Mp = c->pd->M.selfadjointView<Eigen::Upper>();  // Pinocchio fills the upper triangle
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, *c->data, c->q, c->v, c->u);
  pin::aba(c->pm, *c->pd, c->pq, c->pv, c->ptau);
  const Eigen::VectorXd qdd_p = c->pd->ddq;
  const Eigen::VectorXd tau_c = rnea<double>(m, *c->data, c->q, c->v, c->a);
  pin::rnea(c->pm, *c->pd, c->pq, c->pv, c->pa);
  const Eigen::VectorXd tau_p = c->pd->tau;
  c->deriv = std::make_unique<TreeDerivatives>(m);
  c->deriv->compute(c->q, c->v, c->u, c->no_outputs);
  pin::computeABADerivatives(c->pm, *c->pd, c->pq, c->pv, c->ptau);
  const Eigen::MatrixXd Minv = c->pd->Minv.selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd dqdd_du_p = Minv * to_pin_v(c->vmap, gain).asDiagonal();
  const std::vector<int>& P = c->vmap;
  const double eM = rel_diff(to_pin_m(P, M), Mp), eA = rel_diff(to_pin_v(P, qdd), qdd_p);
  const double eT = rel_diff(to_pin_v(P, tau_c), tau_p);
  const double eDq = rel_diff(to_pin_m(P, c->deriv->dqdd_dq), c->pd->ddq_dq);
  const double eDv = rel_diff(to_pin_m(P, c->deriv->dqdd_dv), c->pd->ddq_dv);
  const double eDu = rel_diff(to_pin_m(P, c->deriv->dqdd_du), dqdd_du_p);  // one motor per coordinate, in order
  const double eQ = rel_diff(to_pin_v(P, c->deriv->qdd), qdd_p);
  std::printf("check %-9s nv %3d: max rel diff to Pinocchio: M %.1e, qdd %.1e, rnea %.1e, dqdd/dq %.1e, dqdd/dv %.1e, "
              "dqdd/du %.1e (qdd of the pass %.1e)\n",
              spec.name.c_str(), m.nv, eM, eA, eT, eDq, eDv, eDu, eQ);
  if (!(eM <= 1e-10 && eA <= 1e-10 && eT <= 1e-10 && eDq <= 1e-10 && eDv <= 1e-10 && eDu <= 1e-10 && eQ <= 1e-10)) {
    std::cerr << spec.name << ": codyna and Pinocchio disagree; not timing different mechanisms\n";
    ok = false;
  }
  c->plant = std::make_unique<PlantFunction>(m, c->q, c->u, partition_coordinates(m, c->q));
  c->x = Eigen::VectorXd::Zero(c->plant->nx());
  c->x.tail(m.nv) = c->v;
  if (!c->plant->analytic_jacobian(c->x, c->u, c->J)) {
    std::cerr << spec.name << ": the analytic plant Jacobian does not apply\n";
    ok = false;
  }
  return c;
}

std::vector<std::unique_ptr<PinCase>> g_cases;

// --- benchmarks ---------------------------------------------------------------------
void fd_codyna(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(forward_dynamics<double>(*c->model, *c->data, c->q, c->v, c->u).data());
}
void fd_pin(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(pin::aba(c->pm, *c->pd, c->pq, c->pv, c->ptau).data());
}
void fd_pin_world(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(pin::aba(c->pm, *c->pd, c->pq, c->pv, c->ptau, pin::Convention::WORLD).data());
}
void rnea_codyna(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(rnea<double>(*c->model, *c->data, c->q, c->v, c->a).data());
}
void rnea_pin(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(pin::rnea(c->pm, *c->pd, c->pq, c->pv, c->pa).data());
}
void crba_codyna(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(crba<double>(*c->model, *c->data, c->q).data());
}
void crba_pin(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(pin::crba(c->pm, *c->pd, c->pq).data());
}
void crba_pin_world(benchmark::State& st, PinCase* c) {
  for (auto _ : st) benchmark::DoNotOptimize(pin::crba(c->pm, *c->pd, c->pq, pin::Convention::WORLD).data());
}
void deriv_codyna(benchmark::State& st, PinCase* c) {
  for (auto _ : st) {
    c->deriv->compute(c->q, c->v, c->u, c->no_outputs);
    benchmark::DoNotOptimize(c->deriv->dqdd_dq.data());
  }
}
void jac_codyna(benchmark::State& st, PinCase* c) {
  for (auto _ : st) {
    c->plant->analytic_jacobian(c->x, c->u, c->J);
    benchmark::DoNotOptimize(c->J.data());
  }
}
void deriv_pin(benchmark::State& st, PinCase* c) {
  for (auto _ : st) {
    pin::computeABADerivatives(c->pm, *c->pd, c->pq, c->pv, c->ptau);
    benchmark::DoNotOptimize(c->pd->ddq_dq.data());
  }
}

using bench::PeerCollector;

std::string cell(double a, double b) {
  if (a <= 0 || b <= 0) return "-";
  char buf[96];
  std::snprintf(buf, sizeof buf, "**%.2f** (%s / %s)", a / b, bench::peer_fmt_time(a).c_str(),
                bench::peer_fmt_time(b).c_str());
  return buf;
}

std::string table(const PeerCollector& col) {
  std::ostringstream t;
  t << "Ratios codyna / Pinocchio " << PINOCCHIO_VERSION
    << " (median CPU time of interleaved repetitions; Pinocchio's faster convention; below 1: codyna is faster)\n\n"
    << "| model | nv | fd: forward_dynamics / aba | rnea | crba | deriv: TreeDerivatives::compute / "
       "computeABADerivatives | jac: plant A,B,C,D / computeABADerivatives |\n"
    << "|---|---:|---|---|---|---|---|\n";
  for (const auto& c : g_cases) {
    auto get = [&](const std::string& op, const std::string& who) { return col.get(op + "/" + c->name + "/" + who); };
    auto best = [&](const std::string& op) {
      const double l = get(op, "pinocchio"), w = get(op, "pinocchio_world");
      return w > 0 && (l <= 0 || w < l) ? w : l;
    };
    t << "| " << c->name << " | " << c->model->nv << " | " << cell(get("fd", "codyna"), best("fd")) << " | "
      << cell(get("rnea", "codyna"), best("rnea")) << " | " << cell(get("crba", "codyna"), best("crba")) << " | "
      << cell(get("deriv", "codyna"), best("deriv")) << " | " << cell(get("jac", "codyna"), best("deriv")) << " |\n";
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
    } else if ((a == "--models" && i + 1 < argc) || a.rfind("--models=", 0) == 0) {
      std::stringstream ss(a == "--models" ? std::string(argv[++i]) : a.substr(9));
      for (std::string item; std::getline(ss, item, ',');) only.push_back(item);
    } else if (a == "--help" || a == "-h") {
      std::printf("codyna_bench_pinocchio [--models chain_2,tree28,...] [--table FILE] [Google Benchmark flags]\n");
      benchmark::PrintDefaultHelp();
      return 0;
    } else {
      args.push_back(a);
    }
  }
  std::printf("Pinocchio %s; codyna %s\n", PINOCCHIO_VERSION, CODYNA_VERSION);
  std::vector<ModelSpec> specs;
  for (int n : {2, 7, 30, 60}) specs.push_back(speed_models::chain(n));
  specs.push_back(speed_models::tree28());
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
    PinCase* p = c.get();
    const std::string n = c->name;
    benchmark::RegisterBenchmark(("fd/" + n + "/codyna").c_str(), fd_codyna, p);
    benchmark::RegisterBenchmark(("fd/" + n + "/pinocchio").c_str(), fd_pin, p);
    benchmark::RegisterBenchmark(("fd/" + n + "/pinocchio_world").c_str(), fd_pin_world, p);
    benchmark::RegisterBenchmark(("rnea/" + n + "/codyna").c_str(), rnea_codyna, p);
    benchmark::RegisterBenchmark(("rnea/" + n + "/pinocchio").c_str(), rnea_pin, p);
    benchmark::RegisterBenchmark(("crba/" + n + "/codyna").c_str(), crba_codyna, p);
    benchmark::RegisterBenchmark(("crba/" + n + "/pinocchio").c_str(), crba_pin, p);
    benchmark::RegisterBenchmark(("crba/" + n + "/pinocchio_world").c_str(), crba_pin_world, p);
    benchmark::RegisterBenchmark(("deriv/" + n + "/codyna").c_str(), deriv_codyna, p);
    benchmark::RegisterBenchmark(("jac/" + n + "/codyna").c_str(), jac_codyna, p);
    benchmark::RegisterBenchmark(("deriv/" + n + "/pinocchio").c_str(), deriv_pin, p);
  }
  return bench::run_peer_benchmarks(argv[0], args, table, table_file);
}
