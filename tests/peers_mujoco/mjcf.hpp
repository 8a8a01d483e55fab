// MJCF of a compiled codyna model, for MuJoCo 2.2.x, and the map between the
// two state spaces: shared by the peer test (mujoco_peer_test.cpp) and the
// speed benchmark (bench/mujoco_speed_bench.cpp), so that both run MuJoCo on
// the same mechanism codyna has.
//
// Mapping codyna -> MuJoCo (X_PF = joint frame F on the parent, X_CM = joint
// frame M on the child):
//   body pos/quat  = X_PF * X_CM^-1   (the child body frame in the parent at q = 0)
//   joint pos      = X_CM.p           (anchor in the child body frame)
//   hinge/slide    axis = X_CM.R * axis (MuJoCo axes are in the child body frame)
//   universal      hinge(axis) then hinge(axis2)  (MuJoCo composes a body's
//                  joints in order, each in the frame the previous ones moved)
//   cylindrical    hinge(axis) then slide(axis)
//   planar         slide(F x) then slide(F y) then hinge(F z)
//   spherical      ball; MuJoCo's ball quaternion and angular velocity are in
//                  the child body frame, codyna's in M: q_mj = q_c q q_c^*,
//                  w_mj = R_c w (R_c = X_CM.R, q_c its quaternion)
//   free           (only from ground with F = M = identity, as MuJoCo's free
//                  joints are world poses) qpos identical (x, y, z, w, qx, qy, qz);
//                  MuJoCo qvel = [linear velocity of the origin, WORLD axes;
//                  angular velocity, BODY axes], codyna v = [w, v_o] both in
//                  body axes.
//   fixed          no joint (the body is welded at pos/quat)
//   inertia        <inertial pos=com mass quat diaginertia>: codyna's tensor
//                  (about the com, body axes) in its principal axes; see
//                  InertiaInput for why not fullinertia
//
// So qvel_mj = T(q) v with T identity except: free block [0 R; I 0]
// (R = body rotation in the world), ball block R_c. Kinetic energy gives
//   M_codyna = T^T M_mj T
// and differentiating qvel_mj = T v, with d/dt(R v_o) = R (dv_o/dt + w x v_o):
//   qacc_mj = T qdd + c,   c = R (w x v_o) in the free joint's linear rows.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "model/model.hpp"

namespace codyna::peer {

inline std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}
inline std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }
inline std::string quat(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z());
}
inline bool is_identity(const FrameSpec& f) {
  return f.position.isZero(0.0) && f.rotation.isIdentity(0.0);
}

// How the MJCF gives MuJoCo a body's inertia tensor (about the com, body axes):
//   Principal  quat + diaginertia: principal axes and moments, computed here in
//              double precision (Eigen's SelfAdjointEigenSolver, ~1e-16)
//   Full       fullinertia="Ixx Iyy Izz Ixy Ixz Iyz": MuJoCo 2.2.2 diagonalizes
//              it itself, with an iterative eigensolver that stops early: the
//              tensor it keeps differs from the given one by up to ~3e-7 of its
//              largest entry, which alone puts M and qacc ~1e-8 apart. So the
//              checks use Principal; test FullInertiaInput measures that effect.
enum class InertiaInput { Principal, Full };

// MJCF of a compiled codyna tree (the MuJoCo joints of a codyna joint are named
// <joint>, or <joint>_0, <joint>_1, ... for the composed ones). With
// actuators = true, every joint_force actuator becomes a MuJoCo motor on the
// same coordinate (gear = gain; on a ball joint, gear = gain * X_CM.R e_k, the
// coordinate's axis in the child body frame, which is where MuJoCo's ball
// torques act), unlimited, in codyna's actuator order; other actuator types
// are refused. Without it the MJCF has no actuators.
inline std::string to_mjcf(const Model& m, InertiaInput in = InertiaInput::Principal, bool actuators = false) {
  const ModelSpec& spec = m.spec;
  std::ostringstream x;
  const Eigen::Vector3d g = m.has_gravity ? m.gravity : Eigen::Vector3d::Zero();
  x << "<mujoco model=\"" << m.name << "\">\n"
    << "  <compiler angle=\"radian\" inertiafromgeom=\"false\" balanceinertia=\"false\" boundmass=\"0\" boundinertia=\"0\"/>\n"
    << "  <option gravity=\"" << vec(g) << "\" timestep=\"0.001\">\n"
    << "    <flag contact=\"disable\" limit=\"disable\" passive=\"disable\" frictionloss=\"disable\"/>\n"
    << "  </option>\n"
    << "  <default><joint limited=\"false\" damping=\"0\" armature=\"0\" stiffness=\"0\" frictionloss=\"0\"/></default>\n"
    << "  <worldbody>\n";
  std::function<void(int, int)> emit = [&](int b, int depth) {
    const JointModel& j = m.joints[b];
    const BodySpec& bs = spec.bodies.at(m.body_spec_index[b]);
    const JointSpec& js = spec.joints.at(j.spec_index);
    const std::string ind(2 * depth + 4, ' ');
    const SE3 X0 = j.X_PF * j.X_CM.inverse();
    x << ind << "<body name=\"" << m.body_names[b] << "\" pos=\"" << vec(X0.p) << "\" quat=\"" << quat(X0.R) << "\">\n";
    x << ind << "  <inertial pos=\"" << vec(bs.com) << "\" mass=\"" << num(bs.mass) << "\"";
    if (in == InertiaInput::Full) {
      x << " fullinertia=\"" << num(bs.inertia(0, 0)) << " " << num(bs.inertia(1, 1)) << " " << num(bs.inertia(2, 2))
        << " " << num(bs.inertia(0, 1)) << " " << num(bs.inertia(0, 2)) << " " << num(bs.inertia(1, 2)) << "\"/>\n";
    } else {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(bs.inertia);
      Eigen::Matrix3d V = es.eigenvectors();
      if (V.determinant() < 0) V.col(2) = -V.col(2);  // a rotation, not a reflection
      x << " quat=\"" << quat(V) << "\" diaginertia=\"" << vec(es.eigenvalues()) << "\"/>\n";
    }
    const Eigen::Matrix3d& Rc = j.X_CM.R;
    const std::string pos = " pos=\"" + vec(j.X_CM.p) + "\"";
    auto joint = [&](const std::string& name, const char* type, const Eigen::Vector3d* axis) {
      x << ind << "  <joint name=\"" << name << "\" type=\"" << type << "\"" << pos;
      if (axis) x << " axis=\"" << vec(Rc * *axis) << "\"";
      x << "/>\n";
    };
    const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
    switch (j.type) {
      case JointType::Revolute: joint(j.name, "hinge", &j.axis); break;
      case JointType::Prismatic: joint(j.name, "slide", &j.axis); break;
      case JointType::Spherical: joint(j.name, "ball", nullptr); break;
      case JointType::Universal:
        joint(j.name + "_0", "hinge", &j.axis);
        joint(j.name + "_1", "hinge", &j.axis2);
        break;
      case JointType::Cylindrical:
        joint(j.name + "_0", "hinge", &j.axis);
        joint(j.name + "_1", "slide", &j.axis);
        break;
      case JointType::Planar:
        joint(j.name + "_0", "slide", &ex);
        joint(j.name + "_1", "slide", &ey);
        joint(j.name + "_2", "hinge", &ez);
        break;
      case JointType::Free:
        if (m.parent[b] != 0 || !is_identity(js.parent_frame) || !is_identity(js.child_frame))
          throw std::runtime_error("to_mjcf: a free joint must join a body to ground with identity frames");
        x << ind << "  <joint name=\"" << j.name << "\" type=\"free\"/>\n";
        break;
      case JointType::Fixed: break;
    }
    for (int c = b + 1; c < m.nbodies; ++c)
      if (m.parent[c] == b) emit(c, depth + 1);
    x << ind << "</body>\n";
  };
  for (int b = 1; b < m.nbodies; ++b)
    if (m.parent[b] == 0) emit(b, 0);
  x << "  </worldbody>\n";
  if (actuators && m.nu() > 0) {
    x << "  <actuator>\n";
    for (const ActuatorModel& a : m.actuators) {
      if (a.type != ActuatorType::JointForce)
        throw std::runtime_error("to_mjcf: actuator " + a.name + " is not a joint force");
      int b = 1;
      while (b < m.nbodies && !(a.iv >= m.joints[b].idx_v && a.iv < m.joints[b].idx_v + m.joints[b].nv)) ++b;
      if (b == m.nbodies) throw std::runtime_error("to_mjcf: actuator " + a.name + " drives no coordinate");
      const JointModel& j = m.joints[b];
      const int k = a.iv - j.idx_v;
      std::string joint = j.name, gear = num(a.gain);
      switch (j.type) {
        case JointType::Revolute:
        case JointType::Prismatic: break;
        case JointType::Universal:
        case JointType::Cylindrical:
        case JointType::Planar: joint = j.name + "_" + std::to_string(k); break;
        case JointType::Spherical: gear = vec(a.gain * j.X_CM.R.col(k)) + " 0 0 0"; break;
        default: throw std::runtime_error("to_mjcf: actuator " + a.name + " on a joint MuJoCo cannot drive the same way");
      }
      x << "    <motor name=\"" << a.name << "\" joint=\"" << joint << "\" gear=\"" << gear << "\" ctrllimited=\"false\"/>\n";
    }
    x << "  </actuator>\n";
  }
  x << "</mujoco>\n";
  return x.str();
}

struct MjDeleter {
  void operator()(mjModel* p) const { mj_deleteModel(p); }
  void operator()(mjData* p) const { mj_deleteData(p); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDeleter>;

// mj_loadXML of an MJCF string, through a virtual file system (no temp files).
// On failure returns null with MuJoCo's message in err; on success err holds
// MuJoCo's warning, if any.
inline MjModelPtr load_mjcf(const std::string& xml, std::string& err) {
  err.clear();
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* fname = "codyna_peer.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), fname, static_cast<int>(xml.size())) != 0) {
    err = "could not make the virtual file";
    return nullptr;
  }
  const int i = mj_findFileVFS(vfs.get(), fname);
  std::memcpy(vfs->filedata[i], xml.data(), xml.size());
  char buf[1000] = "";
  mjModel* m = mj_loadXML(fname, vfs.get(), buf, sizeof buf);
  mj_deleteVFS(vfs.get());
  err = buf;
  return MjModelPtr(m);
}

inline int mj_joint(const mjModel* mm, const std::string& name) {
  const int id = mj_name2id(mm, mjOBJ_JOINT, name.c_str());
  if (id < 0) throw std::runtime_error("MuJoCo model has no joint " + name);
  return id;
}

// codyna (q, v) -> MuJoCo (qpos, qvel), with T (qvel = T v) and c (qacc = T qdd + c)
struct Mapped {
  Eigen::VectorXd qpos, qvel, c;
  Eigen::MatrixXd T;
};

inline Mapped map_state(const Model& m, const mjModel* mm, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Mapped r;
  r.qpos = Eigen::VectorXd::Zero(mm->nq);
  r.qvel = Eigen::VectorXd::Zero(mm->nv);
  r.c = Eigen::VectorXd::Zero(mm->nv);
  r.T = Eigen::MatrixXd::Zero(mm->nv, m.nv);
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    const int iq = j.idx_q, iv = j.idx_v;
    auto scalar = [&](const std::string& name, int k) {
      const int id = mj_joint(mm, name);
      r.qpos[mm->jnt_qposadr[id]] = q[iq + k];
      r.T(mm->jnt_dofadr[id], iv + k) = 1.0;
    };
    switch (j.type) {
      case JointType::Revolute:
      case JointType::Prismatic: scalar(j.name, 0); break;
      case JointType::Universal:
      case JointType::Cylindrical:
      case JointType::Planar:
        for (int k = 0; k < j.nv; ++k) scalar(j.name + "_" + std::to_string(k), k);
        break;
      case JointType::Spherical: {
        const int id = mj_joint(mm, j.name);
        const Eigen::Quaterniond qc(j.X_CM.R);
        const Eigen::Quaterniond qj(q[iq], q[iq + 1], q[iq + 2], q[iq + 3]);
        const Eigen::Quaterniond qm = qc * qj * qc.conjugate();
        const int a = mm->jnt_qposadr[id];
        r.qpos.segment<4>(a) << qm.w(), qm.x(), qm.y(), qm.z();
        r.T.block<3, 3>(mm->jnt_dofadr[id], iv) = j.X_CM.R;
        break;
      }
      case JointType::Free: {
        const int id = mj_joint(mm, j.name);
        const int a = mm->jnt_qposadr[id], d = mm->jnt_dofadr[id];
        r.qpos.segment<7>(a) = q.segment<7>(iq);
        const Eigen::Matrix3d R = Eigen::Quaterniond(q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]).normalized().toRotationMatrix();
        r.T.block<3, 3>(d, iv + 3) = R;                         // world linear velocity = R v_o
        r.T.block<3, 3>(d + 3, iv) = Eigen::Matrix3d::Identity();  // body angular velocity
        const Eigen::Vector3d w = v.segment<3>(iv), vo = v.segment<3>(iv + 3);
        r.c.segment<3>(d) = R * w.cross(vo);
        break;
      }
      case JointType::Fixed: break;
    }
  }
  r.qvel = r.T * v;
  return r;
}

}  // namespace codyna::peer
