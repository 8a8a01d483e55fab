// Peer check of codyna's dynamics against MuJoCo (2.2.x, Debian libmujoco-dev).
//
// Each case builds one mechanism as a codyna ModelSpec, writes the same
// mechanism as MJCF (peer::to_mjcf in mjcf.hpp, from the compiled Model and its spec) and
// loads it with mj_loadXML from a virtual file. At fixed random states it
// compares
//   - body poses (a precondition: the two models must describe the same motion),
//   - the joint-space mass matrix: codyna crba vs MuJoCo mj_fullM(qM),
//   - the accelerations: codyna forward_dynamics (u = 0) vs MuJoCo qacc
//     after mj_forward (no contact, limits, passive forces, actuators,
//     armature or damping; gravity as in codyna).
//
// The mapping of the mechanism and of the state between codyna and MuJoCo,
// and the MJCF writer, are in mjcf.hpp (shared with bench/mujoco_speed_bench).
// Both comparisons are made in MuJoCo's coordinates for qacc and in codyna's
// for M, rigorously (no rows dropped).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/test_util.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/prepare.hpp"
#include "dynamics/data.hpp"
#include "peers_mujoco/mjcf.hpp"

namespace codyna::test {
namespace {

// Tolerances of the peer check (relative to the largest entry of MuJoCo's value).
constexpr double kMassTol = 1e-10;
constexpr double kAccTol = 1e-9;
constexpr double kInputTol = 1e-12;  // preconditions: compiled inertias, body poses

using peer::InertiaInput;
using peer::map_state;
using peer::Mapped;
using peer::MjDataPtr;
using peer::MjModelPtr;
using peer::to_mjcf;

// mj_loadXML of an MJCF string (peer::load_mjcf), a failure reported to the test
MjModelPtr load_mjcf(const std::string& xml) {
  std::string err;
  MjModelPtr m = peer::load_mjcf(xml, err);
  if (!m) ADD_FAILURE() << "mj_loadXML: " << err << "\n" << xml;
  else if (!err.empty()) std::cout << "mj_loadXML warning: " << err << "\n";
  return m;
}

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

struct Agreement {
  double inertia = 0, pose = 0, M = 0, qacc = 0;
};

// max over bodies of |I_mj - I| / |I| for MuJoCo's compiled inertia tensor
// (R(body_iquat) diag(body_inertia) R^T) vs codyna's, plus the com and the mass
double inertia_diff(const Model& m, const mjModel* mm) {
  double e = 0;
  for (int b = 1; b < m.nbodies; ++b) {
    const BodySpec& bs = m.spec.bodies.at(m.body_spec_index[b]);
    const int id = mj_name2id(mm, mjOBJ_BODY, m.body_names[b].c_str());
    const mjtNum* q = mm->body_iquat + 4 * id;
    const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    const Eigen::Matrix3d I = R * Eigen::Map<const Eigen::Vector3d>(mm->body_inertia + 3 * id).asDiagonal() * R.transpose();
    e = std::max({e, (I - bs.inertia).cwiseAbs().maxCoeff() / bs.inertia.cwiseAbs().maxCoeff(),
                  (Eigen::Map<const Eigen::Vector3d>(mm->body_ipos + 3 * id) - bs.com).cwiseAbs().maxCoeff(),
                  std::abs(mm->body_mass[id] - bs.mass) / bs.mass});
  }
  return e;
}

// Compares codyna and MuJoCo on `spec` at `nstates` random fixed states.
// With InertiaInput::Full only MuJoCo's own inertia conversion is checked
// (against 1e-6); the differences in M and qacc are measured and printed.
Agreement compare(const std::string& label, const ModelSpec& spec, unsigned seed, int nstates,
                  InertiaInput in = InertiaInput::Principal) {
  Agreement worst;
  const bool check = in == InertiaInput::Principal;
  const Model m = compile(spec);
  const std::string xml = to_mjcf(m, in);
  MjModelPtr mm = load_mjcf(xml);
  if (!mm) return worst;
  worst.inertia = inertia_diff(m, mm.get());
  EXPECT_LE(worst.inertia, check ? kInputTol : 1e-6) << label << ": MuJoCo compiled other inertias\n" << xml;
  EXPECT_EQ(mm->nv, m.nv) << xml;
  EXPECT_EQ(mm->nbody, m.nbodies) << xml;
  EXPECT_TRUE(mm->opt.disableflags & mjDSBL_CONTACT);
  EXPECT_EQ(mm->nu, 0);
  for (int i = 0; i < mm->nv; ++i) {
    EXPECT_EQ(mm->dof_armature[i], 0.0);
    EXPECT_EQ(mm->dof_damping[i], 0.0);
  }
  if (mm->nv != m.nv || mm->nbody != m.nbodies) return worst;
  MjDataPtr md(mj_makeData(mm.get()));

  std::mt19937 rng(seed);
  Data d(m);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(m.nu());
  for (int s = 0; s < nstates; ++s) {
    const Eigen::VectorXd q = random_q(m, rng);
    const Eigen::VectorXd v = random_v(m, rng, 2.0);
    const Mapped mp = map_state(m, mm.get(), q, v);
    mj_resetData(mm.get(), md.get());
    Eigen::Map<Eigen::VectorXd>(md->qpos, mm->nq) = mp.qpos;
    Eigen::Map<Eigen::VectorXd>(md->qvel, mm->nv) = mp.qvel;
    mju_zero(md->qfrc_applied, mm->nv);
    mju_zero(md->xfrc_applied, 6 * mm->nbody);
    mj_forward(mm.get(), md.get());
    EXPECT_EQ(md->nefc, 0) << "MuJoCo has constraint rows";

    // mass matrix
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Mmj(mm->nv, mm->nv);
    mj_fullM(mm.get(), Mmj.data(), md->qM);
    const Eigen::MatrixXd Mcd = crba<double>(m, d, q);
    const Eigen::MatrixXd Mmj_in_cd = mp.T.transpose() * Mmj * mp.T;

    // poses (crba ran forward_kinematics); MuJoCo body ids follow the MJCF
    // nesting, so match by name
    double pose = 0;
    for (int b = 1; b < m.nbodies; ++b) {
      const int id = mj_name2id(mm.get(), mjOBJ_BODY, m.body_names[b].c_str());
      const Eigen::Vector3d p = Eigen::Map<const Eigen::Vector3d>(md->xpos + 3 * id);
      const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(md->xmat + 9 * id);
      pose = std::max({pose, (d.oMi[b].p - p).cwiseAbs().maxCoeff(), (d.oMi[b].R - R).cwiseAbs().maxCoeff()});
    }
    EXPECT_LE(pose, kInputTol) << label << " state " << s << ": body poses differ\n" << xml;

    const double eM = rel_diff(Mcd, Mmj_in_cd);
    if (check) {
      EXPECT_LE(eM, kMassTol) << label << " state " << s << "\ncodyna M =\n" << Mcd << "\nMuJoCo T^T M T =\n" << Mmj_in_cd;
    }

    // accelerations, in MuJoCo's coordinates
    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, q, v, u);
    const Eigen::VectorXd acc_cd = mp.T * qdd + mp.c;
    const Eigen::VectorXd acc_mj = Eigen::Map<const Eigen::VectorXd>(md->qacc, mm->nv);
    const double eA = rel_diff(acc_cd, acc_mj);
    if (check) {
      EXPECT_LE(eA, kAccTol) << label << " state " << s << "\ncodyna (T qdd + c) = " << acc_cd.transpose()
                             << "\nMuJoCo qacc         = " << acc_mj.transpose();
    }
    worst.pose = std::max(worst.pose, pose);
    worst.M = std::max(worst.M, eM);
    worst.qacc = std::max(worst.qacc, eA);
  }
  std::cout << "[mujoco peer] " << label << ": nv " << m.nv << ", " << nstates << " states; inertia input rel diff "
            << worst.inertia << ", max |pose diff| " << worst.pose << "; max rel diff M " << worst.M;
  if (check) std::cout << " (tol " << kMassTol << ")";
  std::cout << ", qacc " << worst.qacc;
  if (check) std::cout << " (tol " << kAccTol << ")";
  std::cout << std::endl;
  return worst;
}

// --- mechanisms ---------------------------------------------------------------

Eigen::Matrix3d rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// a body with an off-axis com and a full (non-diagonal) inertia tensor about it
BodySpec body(const std::string& name, double mass, const Eigen::Vector3d& com, const Eigen::Vector3d& principal,
              const Eigen::Matrix3d& axes) {
  BodySpec b;
  b.name = name;
  b.mass = mass;
  b.com = com;
  b.inertia = axes * principal.asDiagonal() * axes.transpose();
  return b;
}

JointSpec joint(const std::string& name, JointType type, const std::string& parent, const std::string& child,
                const FrameSpec& pf, const FrameSpec& cf, const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.parent_frame = pf;
  j.child_frame = cf;
  j.axis = axis.normalized();
  return j;
}

FrameSpec frame(const Eigen::Vector3d& p, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  FrameSpec f;
  f.position = p;
  f.rotation = R;
  return f;
}

EffectSpec gravity(const Eigen::Vector3d& g) {
  EffectSpec e;
  e.name = "gravity";
  e.type = EffectType::Gravity;
  e.g = g;
  return e;
}

// (a) a 3-D double pendulum of hinges: tilted joint frames on both sides,
// axes off the frame axes, off-axis coms, full inertia tensors
ModelSpec double_pendulum() {
  ModelSpec s;
  s.name = "double_pendulum_3d";
  s.bodies.push_back(body("link1", 1.3, {0.05, -0.42, 0.07}, {0.060, 0.011, 0.055}, rot(0.7, {1, 2, 3})));
  s.bodies.push_back(body("link2", 0.8, {-0.03, -0.35, 0.04}, {0.031, 0.006, 0.029}, rot(-1.1, {-2, 1, 0.5})));
  s.joints.push_back(joint("shoulder", JointType::Revolute, kGroundName, "link1",
                           frame({0.1, 0.2, -0.05}, rot(0.4, {0.3, -1, 0.2})), frame({0.02, 0.03, -0.01}, rot(-0.3, {1, 0, 1})),
                           {0.2, 0.1, 1.0}));
  s.joints.push_back(joint("elbow", JointType::Revolute, "link1", "link2", frame({0.04, -0.8, 0.06}, rot(0.9, {0, 0, 1})),
                           frame({-0.01, 0.05, 0.02}, rot(0.5, {2, -1, 1})), {1.0, -0.3, 0.4}));
  s.effects.push_back(gravity({0.2, -9.81, 0.4}));
  return s;
}

// (b) a chain of 4 bodies: ball, hinge, slide, ball
ModelSpec ball_hinge_slide_ball() {
  ModelSpec s;
  s.name = "ball_hinge_slide_ball";
  s.bodies.push_back(body("b1", 2.0, {0.1, -0.3, 0.05}, {0.09, 0.03, 0.08}, rot(0.3, {1, 1, 0})));
  s.bodies.push_back(body("b2", 1.2, {-0.05, -0.25, 0.1}, {0.05, 0.02, 0.045}, rot(1.2, {0, 1, 2})));
  s.bodies.push_back(body("b3", 0.9, {0.02, 0.15, -0.2}, {0.03, 0.035, 0.012}, rot(-0.6, {3, -1, 1})));
  s.bodies.push_back(body("b4", 0.6, {0.07, -0.12, 0.03}, {0.012, 0.018, 0.009}, rot(2.1, {-1, 2, -1})));
  s.joints.push_back(joint("ball1", JointType::Spherical, kGroundName, "b1", frame({0.0, 0.5, 0.1}, rot(0.5, {1, 0, 0})),
                           frame({0.03, 0.02, -0.04}, rot(0.8, {1, -2, 0.5}))));
  s.joints.push_back(joint("hinge", JointType::Revolute, "b1", "b2", frame({0.1, -0.6, 0.0}, rot(-0.4, {0, 1, 1})),
                           frame({0.0, 0.05, 0.0}), {0.3, 0.0, 1.0}));
  s.joints.push_back(joint("slide", JointType::Prismatic, "b2", "b3", frame({-0.05, -0.5, 0.05}, rot(0.2, {1, 1, 1})),
                           frame({0.01, -0.02, 0.03}, rot(0.6, {0, 0, 1})), {0.5, -1.0, 0.2}));
  s.joints.push_back(joint("ball2", JointType::Spherical, "b3", "b4", frame({0.0, 0.3, -0.4}, rot(1.0, {0, 1, 0})),
                           frame({-0.02, 0.06, 0.01}, rot(-0.7, {2, 1, -1}))));
  s.effects.push_back(gravity({0.0, -9.81, 0.0}));
  return s;
}

// (c) a free-floating body with a hinged child, under gravity
ModelSpec floating_with_hinge() {
  ModelSpec s;
  s.name = "floating_with_hinge";
  s.bodies.push_back(body("base", 3.0, {0.04, -0.02, 0.06}, {0.12, 0.09, 0.15}, rot(0.4, {1, 2, -1})));
  s.bodies.push_back(body("arm", 0.7, {0.02, -0.3, 0.05}, {0.025, 0.004, 0.023}, rot(-0.9, {0.5, 1, 2})));
  s.joints.push_back(joint("float", JointType::Free, kGroundName, "base", FrameSpec{}, FrameSpec{}));
  s.joints.push_back(joint("hinge", JointType::Revolute, "base", "arm", frame({0.2, -0.1, 0.05}, rot(0.7, {1, 0, 1})),
                           frame({0.01, 0.04, -0.02}, rot(0.3, {0, 1, 0})), {0.1, 0.2, 1.0}));
  s.effects.push_back(gravity({0.3, -9.81, 0.5}));
  return s;
}

// (d) codyna's random branched tree (every joint type), its free root joint
// put at the world origin (MuJoCo's free joints are world poses)
ModelSpec random_tree(unsigned seed) {
  ModelSpec s = random_tree_spec(seed, 10, true);
  for (JointSpec& j : s.joints)
    if (j.type == JointType::Free) {
      j.parent_frame = FrameSpec{};
      j.child_frame = FrameSpec{};
    }
  return s;
}

// --- tests --------------------------------------------------------------------

TEST(MujocoPeer, Version) {
  std::cout << "[mujoco peer] MuJoCo " << mj_versionString() << " (header " << mjVERSION_HEADER << ")" << std::endl;
  EXPECT_EQ(mj_version(), mjVERSION_HEADER);
}

TEST(MujocoPeer, DoublePendulum3D) { compare("(a) 3-D double pendulum", double_pendulum(), 11, 8); }

TEST(MujocoPeer, BallHingeSlideBall) { compare("(b) ball-hinge-slide-ball chain", ball_hinge_slide_ball(), 12, 8); }

TEST(MujocoPeer, FloatingBaseWithHinge) { compare("(c) free body + hinge", floating_with_hinge(), 13, 8); }

// MuJoCo's own diagonalization of fullinertia (not a codyna check): how far
// the tensor it keeps, and so M and qacc, are from the given ones.
TEST(MujocoPeer, FullInertiaInput) {
  compare("(a) with fullinertia, not asserted", double_pendulum(), 11, 8, InertiaInput::Full);
}

TEST(MujocoPeer, RandomTreesAllJointTypes) {
  for (unsigned seed : {1u, 2u, 3u}) compare("(d) random tree " + std::to_string(seed), random_tree(seed), 100 + seed, 4);
}

}  // namespace
}  // namespace codyna::test
