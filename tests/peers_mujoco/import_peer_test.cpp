// Imports checked against MuJoCo on models no one here wrote (issue 20).
//
// Each case imports a file with codyna's importer (study_import: MJCF through MuJoCo's own
// compiler, URDF through urdfdom), loads the same file with mj_loadXML, and compares at
// qpos0 and at random states
//   - the joint-space mass matrix: codyna crba vs MuJoCo mj_fullM, in codyna's coordinates
//     (M_codyna = T^T M_mj T, T the map of rates below),
//   - the accelerations with the passive forces both sides model (gravity, joint springs and
//     dampers) and actuator inputs: codyna forward_dynamics vs MuJoCo qacc, in MuJoCo's
//     coordinates (qacc_mj = T qdd + c),
// with MuJoCo's contacts and joint limits disabled (codyna models neither: the import reports
// them) and, where the import was told to ignore it, MuJoCo's armature set to 0 (kept otherwise: codyna
// adds it to the diagonal of M as MuJoCo does).
//
// Coordinates: a hinge/slide qpos is codyna's q; a ball's quaternion and a free joint's pose
// are the same numbers; MuJoCo's free-joint qvel is [linear velocity in WORLD axes, angular
// velocity in body axes], codyna's v = [angular, linear] both in body axes, so
// T = [0 R; I 0] there and c = R (w x v_o) (tests/peers_mujoco/mjcf.hpp explains).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>
#include <string>

#include "core/test_util.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/data.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/prepare.hpp"
#include "peers_mujoco/mjcf.hpp"
#include "study/import.hpp"

namespace codyna::test {
namespace {

const std::string kMj = CODYNA_MUJOCO_MODELS;  // /usr/share/mujoco/model (libmujoco-samples)
const std::string kData = CODYNA_TEST_DATA_DIR "/import/";

using peer::MjDataPtr;
using peer::MjModelPtr;

bool have(const std::string& path) { return std::ifstream(path).good(); }

MjModelPtr load_file(const std::string& path) {
  char err[1000] = "";
  MjModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  if (!m) ADD_FAILURE() << "mj_loadXML " << path << ": " << err;
  return m;
}

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  const double scale = std::max(ref.cwiseAbs().maxCoeff(), 1e-300);
  return (a - ref).cwiseAbs().maxCoeff() / scale;
}

// codyna (q, v) -> MuJoCo (qpos, qvel) with T and c as above; `mj_joint[b]` is the MuJoCo joint
// of codyna body b's joint (-1 for fixed joints)
peer::Mapped map_state(const Model& m, const mjModel* mm, const std::vector<int>& mj_joint, const Eigen::VectorXd& q,
                       const Eigen::VectorXd& v) {
  peer::Mapped r;
  r.qpos = Eigen::VectorXd::Zero(mm->nq);
  r.c = Eigen::VectorXd::Zero(mm->nv);
  r.T = Eigen::MatrixXd::Zero(mm->nv, m.nv);
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    const int id = mj_joint[b];
    if (j.type == JointType::Fixed) continue;
    const int qa = mm->jnt_qposadr[id], da = mm->jnt_dofadr[id];
    switch (j.type) {
      case JointType::Revolute:
      case JointType::Prismatic:
        r.qpos[qa] = q[j.idx_q];
        r.T(da, j.idx_v) = 1;
        break;
      case JointType::Spherical: {
        const Eigen::Quaterniond qc(j.X_CM.R);
        const Eigen::Quaterniond qj(q[j.idx_q], q[j.idx_q + 1], q[j.idx_q + 2], q[j.idx_q + 3]);
        const Eigen::Quaterniond qm = qc * qj * qc.conjugate();
        r.qpos.segment<4>(qa) << qm.w(), qm.x(), qm.y(), qm.z();
        r.T.block<3, 3>(da, j.idx_v) = j.X_CM.R;
        break;
      }
      case JointType::Free: {
        r.qpos.segment<7>(qa) = q.segment<7>(j.idx_q);
        const Eigen::Matrix3d R =
            Eigen::Quaterniond(q[j.idx_q + 3], q[j.idx_q + 4], q[j.idx_q + 5], q[j.idx_q + 6]).normalized().toRotationMatrix();
        r.T.block<3, 3>(da, j.idx_v + 3) = R;
        r.T.block<3, 3>(da + 3, j.idx_v) = Eigen::Matrix3d::Identity();
        r.c.segment<3>(da) = R * v.segment<3>(j.idx_v).cross(v.segment<3>(j.idx_v + 3));
        break;
      }
      default: ADD_FAILURE() << "joint type not expected from an import";
    }
  }
  r.qvel = r.T * v;
  return r;
}

// MuJoCo joint of each codyna body: by name (a URDF's joints keep theirs in both), else in order
// (an MJCF import makes one codyna joint per MuJoCo joint, in MuJoCo's order, and fixed ones for
// bodies without joints)
std::vector<int> joint_map(const Model& m, const mjModel* mm, bool by_name) {
  std::vector<int> spec_to_mj(m.spec.joints.size(), -1);
  int next = 0;
  for (std::size_t i = 0; i < m.spec.joints.size(); ++i) {
    if (m.spec.joints[i].type == JointType::Fixed) continue;
    spec_to_mj[i] = by_name ? mj_name2id(mm, mjOBJ_JOINT, m.spec.joints[i].name.c_str()) : next++;
    EXPECT_GE(spec_to_mj[i], 0) << "MuJoCo has no joint " << m.spec.joints[i].name;
  }
  std::vector<int> out(m.nbodies, -1);
  for (int b = 1; b < m.nbodies; ++b) out[b] = spec_to_mj[m.joints[b].spec_index];
  return out;
}

struct Agreement {
  double M = 0, qacc = 0, qacc_scale = 0;
};

// Compares at qpos0 (v = 0, u = 0), then at `nstates` random states (the odd ones with random
// inputs within the actuators' ranges).
Agreement compare(const std::string& label, const ModelSpec& spec, mjModel* mm, bool by_name, int nstates,
                  unsigned seed = 7, double tol_M = 1e-12, double tol_acc = 1e-9) {
  Agreement worst;
  const Model m = compile(spec);
  mm->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_LIMIT;
  EXPECT_EQ(mm->nv, m.nv) << label;
  // MuJoCo's URDF reader makes no actuators: codyna's joint forces are then applied as qfrc_applied
  const bool applied = mm->nu == 0 && m.nu() > 0;
  if (!applied) EXPECT_EQ(mm->nu, m.nu()) << label;
  if (mm->nv != m.nv || (!applied && mm->nu != m.nu())) return worst;
  const std::vector<int> mj_joint = joint_map(m, mm, by_name);
  MjDataPtr md(mj_makeData(mm));
  Data d(m);
  std::mt19937 rng(seed);
  for (int s = 0; s <= nstates; ++s) {
    Eigen::VectorXd q = m.q0, v = Eigen::VectorXd::Zero(m.nv), u = Eigen::VectorXd::Zero(m.nu());
    if (s > 0) {
      q = random_q(m, rng);
      v = random_v(m, rng, 1.0);
    }
    if (s % 2 == 1)
      for (int k = 0; k < m.nu(); ++k) {
        const ActuatorSpec& a = spec.actuators[k];
        const double lo = a.min.value_or(-1), hi = a.max.value_or(1);
        u[k] = lo + (hi - lo) * std::uniform_real_distribution<double>(0.05, 0.95)(rng);
      }
    const peer::Mapped mp = map_state(m, mm, mj_joint, q, v);
    mj_resetData(mm, md.get());
    Eigen::Map<Eigen::VectorXd>(md->qpos, mm->nq) = mp.qpos;
    Eigen::Map<Eigen::VectorXd>(md->qvel, mm->nv) = mp.qvel;
    if (applied) {
      Eigen::VectorXd tau = Eigen::VectorXd::Zero(m.nv);  // codyna's generalized forces B u
      for (int k = 0; k < m.nu(); ++k) {
        EXPECT_EQ(m.actuators[k].type, ActuatorType::JointForce);
        tau[m.actuators[k].iv] += m.actuators[k].gain * u[k];
      }
      // the same power in MuJoCo's rates: T^T f = tau
      Eigen::Map<Eigen::VectorXd>(md->qfrc_applied, mm->nv) = mp.T.transpose().fullPivLu().solve(tau);
    } else {
      for (int k = 0; k < m.nu(); ++k) md->ctrl[k] = u[k];
    }
    mj_forward(mm, md.get());
    EXPECT_EQ(md->nefc, 0) << label << ": MuJoCo has constraint rows";

    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Mmj(mm->nv, mm->nv);
    mj_fullM(mm, Mmj.data(), md->qM);
    const Eigen::MatrixXd Mcd = crba<double>(m, d, q);
    const double eM = rel_diff(Mcd, mp.T.transpose() * Mmj * mp.T);
    EXPECT_LE(eM, tol_M) << label << " state " << s;

    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, q, v, u);
    const Eigen::VectorXd acc_cd = mp.T * qdd + mp.c;
    const Eigen::VectorXd acc_mj = Eigen::Map<const Eigen::VectorXd>(md->qacc, mm->nv);
    const double eA = rel_diff(acc_cd, acc_mj);
    EXPECT_LE(eA, tol_acc) << label << " state " << s << "\ncodyna T qdd + c = " << acc_cd.transpose()
                           << "\nMuJoCo qacc      = " << acc_mj.transpose();
    worst.M = std::max(worst.M, eM);
    worst.qacc = std::max(worst.qacc, eA);
    worst.qacc_scale = std::max(worst.qacc_scale, acc_mj.cwiseAbs().maxCoeff());
  }
  std::cout << "[mujoco import] " << label << ": nv " << m.nv << ", nu " << m.nu() << ", qpos0 + " << nstates
            << " random states; max rel diff M " << worst.M << ", qacc " << worst.qacc << " (|qacc| up to "
            << worst.qacc_scale << ")" << std::endl;
  return worst;
}

ImportOptions ignoring(std::initializer_list<const char*> kinds) {
  ImportOptions o;
  for (const char* k : kinds) o.ignore.insert(k);
  return o;
}

bool has_finding(const ImportReport& r, const std::string& kind, const std::string& element) {
  for (const ImportFinding& f : r.findings)
    if (f.kind == kind)
      for (const std::string& e : f.elements)
        if (e.find(element) != std::string::npos) return true;
  return false;
}

// --- MuJoCo's own models ------------------------------------------------------------------

TEST(ImportMjcf, HumanoidWithItsArmatureAgreesWithMuJoCo) {
  // the humanoid's hinges carry rotor inertia (armature 0.01): imported as the joints' armature,
  // compared with MuJoCo's M (mj_fullM, armature on its diagonal) and qacc as MuJoCo has them
  const std::string path = kMj + "/humanoid/humanoid.xml";
  if (!have(path)) GTEST_SKIP() << path << " missing (apt-get install libmujoco-samples)";
  const ImportResult r = study_import(path);
  std::cout << r.report.text();
  EXPECT_TRUE(r.report.refusals().empty());
  EXPECT_TRUE(has_finding(r.report, "contacts", "floor"));
  EXPECT_TRUE(has_finding(r.report, "limits", "abdomen_z [-0.785398, 0.785398]"));
  EXPECT_FALSE(has_finding(r.report, "armature", "right_knee"));
  bool mapped = false;
  for (const std::string& line : r.report.mapped) mapped = mapped || line == "21 joint armatures (rotor inertia) -> joint armature";
  EXPECT_TRUE(mapped) << r.report.text();
  const Model m = compile(r.spec);
  EXPECT_EQ(m.nv, 27);
  EXPECT_EQ(m.dof(), 27);
  EXPECT_EQ(m.nu(), 21);
  ASSERT_EQ(m.armature.size(), 27);
  EXPECT_EQ(m.armature.head(6).cwiseAbs().maxCoeff(), 0.0);  // the free root has none
  EXPECT_EQ(m.armature.tail(21).minCoeff(), 0.01);
  EXPECT_EQ(r.spec.plant.inputs.size(), 21u);
  EXPECT_EQ(r.spec.plant.outputs.size(), 21u + 6u);  // 21 hinges, the root's position and body angles

  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  EXPECT_EQ(Eigen::Map<const Eigen::VectorXd>(mm->dof_armature, mm->nv).maxCoeff(), 0.01);  // kept in MuJoCo
  const Agreement a = compare("humanoid.xml (armature kept)", r.spec, mm.get(), false, 8, 7, 1e-10, 1e-10);
  EXPECT_LE(a.M, 1e-10);
  EXPECT_LE(a.qacc, 1e-10);
}

TEST(ImportMjcf, HumanoidWithArmatureIgnoredAgreesWithMuJoCoWithoutIt) {
  // --ignore armature leaves the rotor inertia out, said in the report
  const std::string path = kMj + "/humanoid/humanoid.xml";
  if (!have(path)) GTEST_SKIP();
  const ImportResult r = study_import(path, ignoring({"armature"}));
  EXPECT_TRUE(has_finding(r.report, "armature", "right_knee 0.01"));
  EXPECT_EQ(compile(r.spec).armature.size(), 0);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  for (int i = 0; i < mm->nv; ++i) mm->dof_armature[i] = 0;  // what the import was told to leave out
  const Agreement a = compare("humanoid.xml (--ignore armature)", r.spec, mm.get(), false, 6);
  EXPECT_LE(a.M, 1e-12);
  EXPECT_LE(a.qacc, 1e-9);
}

TEST(ImportMjcf, ArmatureOnBallHingeAndSlideAgreesWithMuJoCo) {
  // one armature per joint on a ball, a hinge and a slide below a free body: MuJoCo's diagonal in
  // its dof space is codyna's in its own (a ball's rates differ by a constant rotation)
  const std::string path = kData + "armature_ball_free.xml";
  const ImportResult r = study_import(path);
  EXPECT_TRUE(r.report.refusals().empty()) << r.report.text();
  const Model m = compile(r.spec);
  ASSERT_EQ(m.nv, 11);
  ASSERT_EQ(m.armature.size(), 11);
  Eigen::VectorXd expected(11);
  expected << 0, 0, 0, 0, 0, 0, 0.05, 0.05, 0.05, 0.2, 1.5;
  EXPECT_EQ(m.armature, expected);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  const Agreement a = compare("armature_ball_free.xml", r.spec, mm.get(), false, 8, 11, 1e-10, 1e-10);
  EXPECT_LE(a.M, 1e-10);
  EXPECT_LE(a.qacc, 1e-10);
}

TEST(ImportMjcf, ArmatureOnAFreeJointIsRefusedWithTheReason) {
  // MuJoCo's free linear dofs are world-axes velocities, codyna's body-axes ones: the same diagonal
  // differs there by armature (w x v), so the import refuses it (or leaves it out when ignored)
  const std::string path = kData + "armature_free.xml";
  try {
    (void)study_import(path);
    ADD_FAILURE() << "armature on a free joint should stop the import";
  } catch (const ImportRefused& e) {
    EXPECT_NE(std::string(e.what()).find("armature on a free joint"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("root 0.7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--ignore armature"), std::string::npos) << e.what();
  }
  const ImportResult r = study_import(path, ignoring({"armature"}));
  EXPECT_EQ(compile(r.spec).armature.size(), 0);
  // measured: with MuJoCo's armature kept, M still agrees (the diagonal is rotation-invariant) but
  // the accelerations of a spinning, moving body do not, which is the reason for the refusal
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  ModelSpec with = r.spec;
  with.joints.at(0).armature = Eigen::VectorXd::Constant(1, 0.7);
  testing::internal::CaptureStdout();
  const Agreement a = compare("armature_free.xml (codyna's body-axes armature)", with, mm.get(), false, 0, 13, 1e-10, 1.0);
  const Model m = compile(with);
  Data d(m);
  Eigen::VectorXd v(6);
  v << 0.3, -1.2, 2.0, 0.5, 0.4, -0.7;
  const peer::Mapped mp = map_state(m, mm.get(), joint_map(m, mm.get(), false), m.q0, v);
  MjDataPtr md(mj_makeData(mm.get()));
  Eigen::Map<Eigen::VectorXd>(md->qpos, mm->nq) = mp.qpos;
  Eigen::Map<Eigen::VectorXd>(md->qvel, mm->nv) = mp.qvel;
  mj_forward(mm.get(), md.get());
  const Eigen::VectorXd acc = mp.T * forward_dynamics<double>(m, d, m.q0, v, Eigen::VectorXd()) + mp.c;
  const double gap = (acc - Eigen::Map<const Eigen::VectorXd>(md->qacc, mm->nv)).cwiseAbs().maxCoeff();
  (void)testing::internal::GetCapturedStdout();
  EXPECT_LE(a.M, 1e-10);
  EXPECT_GT(gap, 1e-3) << "a free joint's armature would agree with MuJoCo's: the refusal is not needed";
  std::cout << "[mujoco import] armature_free.xml: M agrees to " << a.M << ", qacc of a spinning body differs by " << gap
            << " (the reason for the refusal)" << std::endl;
}

TEST(ImportMjcf, HumanoidMassMatrixWithoutTheArmatureDiffersByExactlyIt) {
  // what --ignore armature leaves out, measured: MuJoCo's M minus codyna's is diag(armature)
  const std::string path = kMj + "/humanoid/humanoid.xml";
  if (!have(path)) GTEST_SKIP();
  const ImportResult r = study_import(path, ignoring({"armature"}));
  const Model m = compile(r.spec);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  MjDataPtr md(mj_makeData(mm.get()));
  mj_forward(mm.get(), md.get());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Mmj(mm->nv, mm->nv);
  mj_fullM(mm.get(), Mmj.data(), md->qM);
  Data d(m);
  const peer::Mapped mp = map_state(m, mm.get(), joint_map(m, mm.get(), false), m.q0, Eigen::VectorXd::Zero(m.nv));
  const Eigen::MatrixXd diff = mp.T.transpose() * Mmj * mp.T - crba<double>(m, d, m.q0);
  Eigen::VectorXd arm = Eigen::Map<const Eigen::VectorXd>(mm->dof_armature, mm->nv);
  EXPECT_LE((diff - Eigen::MatrixXd((mp.T.transpose() * arm).asDiagonal())).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(arm.maxCoeff(), 0.01, 1e-15);
}

TEST(ImportMjcf, SliderCrankTransmissionsAreRefusedThenItsLinksAgree) {
  // MuJoCo 2.2.2's slider_crank.xml has no loop: its "slider-crank" is an actuator transmission
  // (position servos through slider-crank linkages), which codyna cannot represent
  const std::string path = kMj + "/slider_crank/slider_crank.xml";
  if (!have(path)) GTEST_SKIP();
  try {
    (void)study_import(path);
    ADD_FAILURE() << "slider-crank transmissions should stop the import";
  } catch (const ImportRefused& e) {
    EXPECT_NE(std::string(e.what()).find("forward (slider-crank transmission)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--ignore actuators"), std::string::npos) << e.what();
  }
  const ImportResult r = study_import(path, ignoring({"actuators"}));
  EXPECT_EQ(r.spec.actuators.size(), 0u);
  EXPECT_EQ(r.spec.joints.size(), 3u);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  mm->nu = 0;  // the transmissions the import left out (MuJoCo's actuators then do nothing)
  const Agreement a = compare("slider_crank.xml (--ignore actuators)", r.spec, mm.get(), false, 6);
  EXPECT_LE(a.qacc, 1e-9);
}

TEST(ImportMjcf, TendonArmNamesItsTendonsAndMusclesThenAgrees) {
  const std::string path = kMj + "/tendon_arm/arm26.xml";
  if (!have(path)) GTEST_SKIP();
  try {
    (void)study_import(path);
    ADD_FAILURE() << "muscles should stop the import";
  } catch (const ImportRefused& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("muscles"), std::string::npos) << w;
    EXPECT_NE(w.find("SF, SE, EF, EE, BF, BE"), std::string::npos) << w;
  }
  const ImportResult r = study_import(path, ignoring({"muscles", "tendons"}));
  EXPECT_TRUE(has_finding(r.report, "tendons", "SF"));
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  mm->nu = 0;
  const Agreement a = compare("arm26.xml (--ignore muscles,tendons)", r.spec, mm.get(), false, 6);
  EXPECT_LE(a.qacc, 1e-9);
}

TEST(ImportMjcf, MugFreeJointAndMeshAgree) {
  const std::string path = kMj + "/mug/mug.xml";
  if (!have(path)) GTEST_SKIP();
  const ImportResult r = study_import(path);
  EXPECT_TRUE(has_finding(r.report, "shapes", "mesh mug: its bounding box"));
  EXPECT_EQ(r.spec.joints.at(0).type, JointType::Free);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  const Agreement a = compare("mug.xml (free joint)", r.spec, mm.get(), false, 8);
  EXPECT_LE(a.qacc, 1e-9);
}

TEST(ImportMjcf, ConnectEqualityClosesTheLoop) {
  const ImportResult r = study_import(kData + "four_bar_connect.xml");
  ASSERT_EQ(r.spec.constraints.size(), 1u);
  const ConstraintSpec& c = r.spec.constraints[0];
  EXPECT_EQ(c.type, ConstraintType::Ball);
  EXPECT_EQ(c.body_a, "coupler");
  EXPECT_EQ(c.body_b, "rocker");
  EXPECT_LE((c.point_a - Eigen::Vector3d(0.3, 0.2, 0)).norm(), 1e-15);
  EXPECT_LE((c.point_b - Eigen::Vector3d(0.1, 0.2, 0)).norm(), 1e-12);  // MuJoCo's anchor on body2 at qpos0
  EXPECT_TRUE(has_finding(r.report, "soft_constraints", "close"));
  const Model m = compile(r.spec);
  EXPECT_EQ(m.dof(), 1);
  EXPECT_LE(m.assembly_residual, 1e-12);
}

TEST(ImportMjcf, LinearJointEqualityIsACouplerAndAgreesToMuJoCosSoftness) {
  // MuJoCo's equality constraints are soft: with solimp 0.99999 its constraint keeps ~1e-5 of the
  // unconstrained acceleration along the coupling, which bounds the agreement
  const std::string path = kData + "geared_pair.xml";
  const ImportResult r = study_import(path);
  ASSERT_EQ(r.spec.constraints.size(), 1u);
  const ConstraintSpec& c = r.spec.constraints[0];
  EXPECT_EQ(c.type, ConstraintType::Coupler);
  EXPECT_EQ(c.joint_a, "drive");
  EXPECT_EQ(c.joint_b, "driven");
  EXPECT_EQ(c.ratio_b, 2.0);
  EXPECT_NEAR(*c.offset, 0.2 + 2 * -0.1, 1e-15);  // q1 + 2 q2 = ref1 + 2 ref2
  const Model m = compile(r.spec);
  EXPECT_EQ(m.dof(), 1);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  MjDataPtr md(mj_makeData(mm.get()));
  Data d(m);
  double worst = 0;
  for (double u : {0.0, 0.7}) {
    // at qpos0 (the coupling holds), at rest, with and without the motor
    mj_resetData(mm.get(), md.get());
    md->ctrl[0] = u;
    mj_forward(mm.get(), md.get());
    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, m.q0, Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(1, u));
    const Eigen::VectorXd acc_mj = Eigen::Map<const Eigen::VectorXd>(md->qacc, 2);
    worst = std::max(worst, rel_diff(qdd, acc_mj));
    EXPECT_NEAR(qdd[0] + 2 * qdd[1], 0, 1e-12);  // codyna keeps the coupling exactly
  }
  std::cout << "[mujoco import] geared_pair.xml: coupler vs MuJoCo's soft joint equality: max rel diff qacc " << worst
            << std::endl;
  EXPECT_LE(worst, 1e-3);
}

TEST(ImportMjcf, MalformedFileNamesTheFileAndTheElement) {
  try {
    (void)study_import(kData + "bad.xml");
    ADD_FAILURE() << "bad.xml imported";
  } catch (const ImportRefused& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("bad.xml: MuJoCo cannot read it"), std::string::npos) << w;
    EXPECT_NE(w.find("frobnicate"), std::string::npos) << w;
    EXPECT_NE(w.find("line 6"), std::string::npos) << w;
  }
}

// --- URDF ------------------------------------------------------------------------------------

TEST(ImportUrdf, Arm7AgreesWithMuJoCosUrdfReader) {
  const std::string path = kData + "arm7.urdf";
  const ImportResult r = study_import(path);
  std::cout << r.report.text();
  EXPECT_EQ(r.spec.actuators.size(), 7u);
  EXPECT_TRUE(has_finding(r.report, "limits", "j1 [-2.9, 2.9] velocity 2"));
  EXPECT_TRUE(has_finding(r.report, "contacts", "link3"));
  EXPECT_EQ(*r.spec.actuators[0].max, 80.0);
  MjModelPtr mm = load_file(path);  // MuJoCo's own URDF reader, the peer
  ASSERT_TRUE(mm);
  EXPECT_EQ(mm->nv, 7);
  const Agreement a = compare("arm7.urdf (MuJoCo's URDF reader)", r.spec, mm.get(), true, 8);
  EXPECT_LE(a.M, 1e-12);
  EXPECT_LE(a.qacc, 1e-10);
}

TEST(ImportUrdf, DoublePendulumAgainstTheClosedForm) {
  const ImportResult r = study_import(kData + "double_pendulum.urdf");
  const Model m = compile(r.spec);
  ASSERT_EQ(m.nv, 2);
  const double m1 = 2, l1 = 1, c1 = 0.5, I1 = 2 * 1.0 / 12, m2 = 1, c2 = 0.4, I2 = 1 * 0.64 / 12, g = 9.81;
  Data d(m);
  std::mt19937 rng(3);
  double eM = 0, eA = 0;
  for (int s = 0; s < 10; ++s) {
    const Eigen::VectorXd q = Eigen::Vector2d(std::uniform_real_distribution<double>(-3, 3)(rng),
                                              std::uniform_real_distribution<double>(-3, 3)(rng));
    const double q1 = q[0], q2 = q[1];
    Eigen::Matrix2d M;
    M(0, 0) = I1 + m1 * c1 * c1 + I2 + m2 * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * std::cos(q2));
    M(0, 1) = M(1, 0) = I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(q2));
    M(1, 1) = I2 + m2 * c2 * c2;
    // potential V = -g (m1 c1 cos q1 + m2 (l1 cos q1 + c2 cos(q1 + q2))), both angles from the downward vertical
    const Eigen::Vector2d G(g * (m1 * c1 * std::sin(q1) + m2 * (l1 * std::sin(q1) + c2 * std::sin(q1 + q2))),
                            g * m2 * c2 * std::sin(q1 + q2));
    const Eigen::Vector2d qdd_ref = M.ldlt().solve(-G);
    eM = std::max(eM, rel_diff(crba<double>(m, d, q), M));
    const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, q, Eigen::VectorXd::Zero(2), Eigen::VectorXd::Zero(2));
    eA = std::max(eA, rel_diff(qdd, qdd_ref));
  }
  std::cout << "[closed form] double_pendulum.urdf: max rel diff M " << eM << ", qdd at rest " << eA << std::endl;
  EXPECT_LE(eM, 1e-14);
  EXPECT_LE(eA, 1e-13);
}

TEST(ImportUrdf, DoublePendulumAgreesWithMuJoCo) {
  const std::string path = kData + "double_pendulum.urdf";
  const ImportResult r = study_import(path);
  MjModelPtr mm = load_file(path);
  ASSERT_TRUE(mm);
  const Agreement a = compare("double_pendulum.urdf (MuJoCo's URDF reader)", r.spec, mm.get(), true, 8);
  EXPECT_LE(a.qacc, 1e-10);
}

TEST(ImportUrdf, MimicJointIsACoupler) {
  const ImportResult r = study_import(kData + "gripper_mimic.urdf");
  ASSERT_EQ(r.spec.constraints.size(), 1u);
  const ConstraintSpec& c = r.spec.constraints[0];
  EXPECT_EQ(c.type, ConstraintType::Coupler);
  EXPECT_EQ(c.joint_a, "right_slide");
  EXPECT_EQ(c.joint_b, "left_slide");
  EXPECT_EQ(c.ratio_b, 1.0);  // q_right = -q_left + 0.01
  EXPECT_EQ(*c.offset, 0.01);
  const Model m = compile(r.spec);
  EXPECT_EQ(m.dof(), 1);
  // a force on the left finger alone moves both fingers, mirrored: (m_l + m_r) a = F
  Data d(m);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(m.nu());
  u[0] = 1.0;
  const Eigen::VectorXd qdd = forward_dynamics<double>(m, d, m.q0, Eigen::VectorXd::Zero(m.nv), u);
  EXPECT_NEAR(qdd[0], 1.0 / 0.1, 1e-12);
  EXPECT_NEAR(qdd[1], -1.0 / 0.1, 1e-12);
}

TEST(ImportUrdf, MalformedFileNamesTheFileAndTheElement) {
  try {
    (void)study_import(kData + "bad.urdf");
    ADD_FAILURE() << "bad.urdf imported";
  } catch (const ImportRefused& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("bad.urdf: not a valid URDF"), std::string::npos) << w;
    EXPECT_NE(w.find("nowhere"), std::string::npos) << w;
  }
}

TEST(Import, UnknownIgnoreKindIsRefusedNamingTheKinds) {
  try {
    (void)study_import(kData + "arm7.urdf", ignoring({"contact"}));
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--ignore contact: unknown kind (kinds: contacts, limits"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace codyna::test
