#include "io/export_mjcf.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"

#ifdef CODYNA_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace codyna {

namespace {

std::string mjcf_number(double x) {
  if (x == 0) return "0";  // also -0
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  // the shortest text that reads back as the same double
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}
std::string brief(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}
std::string vec(const Eigen::Vector3d& v) { return mjcf_number(v.x()) + " " + mjcf_number(v.y()) + " " + mjcf_number(v.z()); }
std::string quat_text(const Eigen::Quaterniond& q) {
  return mjcf_number(q.w()) + " " + mjcf_number(q.x()) + " " + mjcf_number(q.y()) + " " + mjcf_number(q.z());
}
Eigen::Quaterniond quat_of(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return q;
}
std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&apos;"; break;
      default: o += c;
    }
  }
  return o;
}
// text inside an XML comment: no "--"
std::string comment_text(std::string s) {
  for (std::size_t i; (i = s.find("--")) != std::string::npos;) s.replace(i, 2, "- -");
  return s;
}
std::string q(const std::string& s) { return "\"" + esc(s) + "\""; }

SE3 rot(const Eigen::Vector3d& axis, double angle) {
  return SE3(Eigen::AngleAxisd(angle, axis).toRotationMatrix(), Eigen::Vector3d::Zero());
}
SE3 trans(const Eigen::Vector3d& p) { return SE3(Eigen::Matrix3d::Identity(), p); }

bool is_identity(const SE3& X) { return X.p.isZero(0.0) && X.R.isIdentity(0.0); }

// unique names per MuJoCo object type
struct MjcfNames {
  std::set<std::string> used;
  std::string unique(const std::string& base) {
    std::string n = base;
    for (int k = 1; used.count(n); ++k) n = base + "_" + std::to_string(k);
    used.insert(n);
    return n;
  }
};

enum class Elem { Hinge, Slide, Ball, Free };

// one MuJoCo joint: a codyna joint's coordinates (iq, iv its first ones)
struct MjJoint {
  std::string name;
  Elem kind = Elem::Hinge;
  int body = 0;              // codyna body of the codyna joint
  int k = 0;                 // which element of that joint
  int iq = 0, iv = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // in the element's own frame
  double ref = 0;
  SE3 G;                     // the element's frame in the MuJoCo body's frame (qpos = ref)
  double stiffness = 0, kref = 0, damping = 0;  // summed springs (kref = sum k r)
  double armature = 0;       // rotor inertia on its coordinates
  bool has_spring = false;
};

class Exporter {
 public:
  Exporter(const Model& m, std::string source) : m_(m), source_(std::move(source)) {}

  MjcfExport run() {
    label_ = source_.empty() ? "model " + m_.name : source_;
    children_.assign(m_.nbodies, {});
    for (int b = 1; b < m_.nbodies; ++b) children_[m_.parent[b]].push_back(b);
    referenced_.assign(m_.nbodies, false);
    mark_references();
    check_joints();
    elements();
    effects();
    constraints();
    actuators();
    if (!refused_.empty()) {
      std::string w = label_ + ": cannot export to MJCF without changing the dynamics (no exact MJCF equivalent): ";
      for (std::size_t i = 0; i < refused_.size(); ++i) w += (i ? "; " : "") + refused_[i];
      throw MjcfExportRefused(w, refused_);
    }
    sensors();
    write();
    return std::move(out_);
  }

 private:
  const Model& m_;
  std::string source_, label_;
  MjcfExport out_;
  std::vector<std::string> refused_;
  std::vector<std::vector<int>> children_;
  std::vector<bool> referenced_;
  std::vector<std::string> mj_body_;        // MuJoCo body name of each codyna body (its group's)
  std::vector<std::vector<int>> joint_elems_;  // MuJoCo joints of each codyna body's joint
  std::vector<MjJoint> mj_joints_;
  std::vector<int> iv_joint_;               // MuJoCo joint of each velocity index (-1: a ball's or free joint's)
  MjcfNames body_names_, joint_names_, site_names_, tendon_names_, sensor_names_, eq_names_;
  std::ostringstream sites_xml_;            // per codyna body, filled before write()
  std::map<int, std::string> body_sites_;
  std::ostringstream tendon_xml_, actuator_xml_, equality_xml_, sensor_xml_;
  int nsprings_ = 0, nlines_ = 0, nsites_ = 0, nconnect_ = 0, ncoupler_ = 0, nsensors_ = 0;
  int njoint_springs_ = 0, njoint_dampers_ = 0;

  void refuse(const std::string& what) { refused_.push_back(what); }

  const std::string& body_name(int b) const { return m_.body_names[b]; }

  // a codyna body that MuJoCo cannot hold as a body of its own (moving without mass) and that
  // can be merged into its only child: its joints come first in the child's MuJoCo body
  bool mergeable(int b) const {
    if (b == 0 || referenced_[b] || children_[b].size() != 1) return false;
    const JointModel& j = m_.joints[b];
    if (j.nv == 0 || j.type == JointType::Spherical || j.type == JointType::Free) return false;
    if (m_.mass[b] != 0 || !m_.inertia[b].isZero(0.0)) return false;
    const int si = m_.body_spec_index[b];
    if (si >= 0 && !m_.spec.bodies[si].shapes.empty()) return false;
    return m_.joints[children_[b][0]].type != JointType::Free;
  }

  void mark_references() {
    for (const ConstraintModel& c : m_.constraints)
      if (c.type != ConstraintType::Coupler) referenced_[c.body_a] = referenced_[c.body_b] = true;
    for (const SpringDamperModel& s : m_.springs) referenced_[s.body_a] = referenced_[s.body_b] = true;
    for (const BushingModel& s : m_.bushings) referenced_[s.body_a] = referenced_[s.body_b] = true;
    for (const BodyForceModel& s : m_.body_forces) referenced_[s.body] = true;
    for (const ActuatorModel& a : m_.actuators)
      if (a.type != ActuatorType::JointForce) referenced_[a.body] = referenced_[a.body_b] = true;
    referenced_[0] = true;
  }

  void check_joints() {
    for (int b = 1; b < m_.nbodies; ++b) {
      const JointModel& j = m_.joints[b];
      if (j.type != JointType::Free) continue;
      if (m_.parent[b] != 0)
        refuse("free joint " + j.name + ": below body " + body_name(m_.parent[b]) +
               " (MuJoCo's free joints join a body to the world only)");
      else if (!is_identity(j.X_PF) || !is_identity(j.X_CM))
        refuse("free joint " + j.name + ": its frames are not the identity (MuJoCo's free joint is the body's "
               "world pose, codyna's the pose of its child frame in its parent frame)");
    }
  }

  // the MuJoCo joints of every codyna joint, named JOINT or JOINT_k
  void elements() {
    joint_elems_.assign(m_.nbodies, {});
    iv_joint_.assign(m_.nv, -1);
    for (int b = 1; b < m_.nbodies; ++b) joint_names_.used.insert(m_.joints[b].name);
    for (int b = 1; b < m_.nbodies; ++b) {
      const JointModel& j = m_.joints[b];
      std::vector<std::pair<Elem, Eigen::Vector3d>> e;
      const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
      switch (j.type) {
        case JointType::Revolute: e = {{Elem::Hinge, j.axis}}; break;
        case JointType::Prismatic: e = {{Elem::Slide, j.axis}}; break;
        case JointType::Spherical: e = {{Elem::Ball, ez}}; break;
        case JointType::Universal: e = {{Elem::Hinge, j.axis}, {Elem::Hinge, j.axis2}}; break;
        case JointType::Cylindrical: e = {{Elem::Hinge, j.axis}, {Elem::Slide, j.axis}}; break;
        case JointType::Planar: e = {{Elem::Slide, ex}, {Elem::Slide, ey}, {Elem::Hinge, ez}}; break;
        case JointType::Free: e = {{Elem::Free, ez}}; break;
        case JointType::Fixed: break;
      }
      for (std::size_t k = 0; k < e.size(); ++k) {
        MjJoint mj;
        mj.kind = e[k].first;
        mj.axis = e[k].second;
        mj.body = b;
        mj.k = static_cast<int>(k);
        mj.iq = j.idx_q + mj.k;
        mj.iv = j.idx_v + mj.k;
        mj.name = e.size() == 1 ? j.name : joint_names_.unique(j.name + "_" + std::to_string(k));
        if (mj.kind == Elem::Hinge || mj.kind == Elem::Slide) {
          mj.ref = m_.q0[mj.iq];
          iv_joint_[mj.iv] = static_cast<int>(mj_joints_.size());
        }
        joint_elems_[b].push_back(static_cast<int>(mj_joints_.size()));
        mj_joints_.push_back(mj);
      }
    }
  }

  int joint_of_iv(int iv) const { return iv_joint_[iv]; }
  // the codyna body whose joint holds velocity index iv
  int body_of_iv(int iv) const {
    for (int b = 1; b < m_.nbodies; ++b)
      if (iv >= m_.joints[b].idx_v && iv < m_.joints[b].idx_v + m_.joints[b].nv) return b;
    return -1;
  }
  std::string coordinate_name(int iv) const { return iv >= 0 && iv < m_.nv ? m_.v_names[iv] : "?"; }

  void effects() {
    for (const EffectSpec& e : m_.spec.effects) {
      switch (e.type) {
        case EffectType::Gravity:
        case EffectType::SpringDamper:
        case EffectType::JointSpringDamper:
        case EffectType::JointFriction:
        case EffectType::JointDamper: break;
        case EffectType::BodyForce:
          refuse("body_force " + e.name + ": a constant applied force has no MJCF equivalent (MuJoCo's are data, "
                 "xfrc_applied, not model)");
          break;
        case EffectType::Bushing:
          refuse("bushing " + e.name + ": a 6-component spring-damper between two frames has no MJCF equivalent");
          break;
        default: refuse(std::string(to_string(e.type)) + " " + e.name + ": no MJCF equivalent");
      }
    }
    // joint springs and dampers, summed per coordinate: sum -k_i (q - r_i) = -K (q - sum k_i r_i / K)
    std::vector<double> damp(m_.nv, 0.0);
    for (const JointSpringModel& s : m_.joint_springs) {
      damp[s.iv] += s.damping;
      const int jj = joint_of_iv(s.iv);
      if (jj < 0) {
        refuse("joint_spring_damper " + s.name + ": a spring on a coordinate of a ball or free joint");
        continue;
      }
      if (s.stiffness != 0) {
        mj_joints_[jj].stiffness += s.stiffness;
        mj_joints_[jj].kref += s.stiffness * s.rest_position;
        mj_joints_[jj].has_spring = true;
        ++njoint_springs_;
      }
    }
    for (const JointSpringModel& s : m_.joint_frictions) damp[s.iv] += s.damping;
    for (MjJoint& j : mj_joints_) {
      const JointModel& jm = m_.joints[j.body];
      if (j.kind == Elem::Hinge || j.kind == Elem::Slide) {
        j.damping = damp[j.iv];
        if (j.damping != 0) ++njoint_dampers_;
      } else {
        // MuJoCo's ball or free joint has one damping for all its coordinates
        bool same = true;
        for (int k = 1; k < jm.nv; ++k) same = same && damp[jm.idx_v + k] == damp[jm.idx_v];
        if (!same) {
          std::string values;
          for (int k = 0; k < jm.nv; ++k) values += (k ? " " : "") + brief(damp[jm.idx_v + k]);
          refuse("joint " + jm.name + ": dampings that differ between the coordinates of a " +
                 to_string(jm.type) + " joint (" + values + "; MuJoCo's " +
                 (j.kind == Elem::Ball ? "ball" : "free") + " joint has one for all)");
        }
        j.damping = damp[jm.idx_v];
        if (j.damping != 0) ++njoint_dampers_;
      }
    }
    armature();
    for (const MjJoint& j : mj_joints_)
      if (j.has_spring && j.stiffness == 0)
        refuse("joint " + m_.joints[j.body].name + ": springs whose stiffnesses sum to zero (a constant torque " +
               "MuJoCo's joint spring cannot give)");
    // point-to-point springs: spatial tendons
    for (const SpringDamperModel& s : m_.springs) {
      const std::string a = site(s.body_a, s.point_a, s.name + "_a"), b = site(s.body_b, s.point_b, s.name + "_b");
      tendon_xml_ << "    <spatial name=" << q(tendon_names_.unique(s.name)) << " stiffness=\"" << mjcf_number(s.stiffness)
                  << "\" damping=\"" << mjcf_number(s.damping) << "\" springlength=\"" << mjcf_number(s.rest_length)
                  << "\">\n      <site site=" << q(a) << "/>\n      <site site=" << q(b) << "/>\n    </spatial>\n";
      ++nsprings_;
    }
  }

  // rotor inertia (JointSpec::armature, per velocity index in Model::armature) -> MuJoCo's joint
  // armature: exact on a hinge or slide; on a ball or free joint only when the same on all its
  // coordinates (MuJoCo's adds diag(a) in its own rates, T^T a I T = a I in codyna's)
  void armature() {
    const Eigen::VectorXd& arm = m_.armature;
    if (arm.size() != m_.nv) return;
    for (MjJoint& j : mj_joints_) {
      const JointModel& jm = m_.joints[j.body];
      if (j.kind == Elem::Hinge || j.kind == Elem::Slide) {
        j.armature = arm[j.iv];
      } else {
        bool same = true;
        for (int k = 1; k < jm.nv; ++k) same = same && arm[jm.idx_v + k] == arm[jm.idx_v];
        if (!same) {
          std::string values;
          for (int k = 0; k < jm.nv; ++k) values += (k ? " " : "") + brief(arm[jm.idx_v + k]);
          refuse("joint " + jm.name + ": armatures that differ between the coordinates of a " + to_string(jm.type) +
                 " joint (" + values + "; MuJoCo's " + (j.kind == Elem::Ball ? "ball" : "free") + " joint has one for all)");
        }
        j.armature = arm[jm.idx_v];
      }
      if (j.armature != 0) ++narmatures_;
    }
  }
  int narmatures_ = 0;

  // a site at a point of a body (body axes), written in that body's MuJoCo body
  std::string site(int body, const Eigen::Vector3d& p, const std::string& base) {
    const std::string n = site_names_.unique(base);
    body_sites_[body] += "<site name=" + q(n) + " pos=\"" + vec(p) + "\" size=\"0.005\"/>\n";
    ++nsites_;
    return n;
  }

  // is the motion of the bodies from `b` to the ground planar about the world axis n at q0:
  // revolute joints about n, prismatic joints across it, fixed joints
  bool planar_path(int b, const Eigen::Vector3d& n, const DataT<double>& d) const {
    for (; b > 0; b = m_.parent[b]) {
      const JointModel& j = m_.joints[b];
      const Eigen::Vector3d a = d.oMi[m_.parent[b]].R * j.X_PF.R * j.axis;
      switch (j.type) {
        case JointType::Fixed: break;
        case JointType::Revolute:
          if (a.cross(n).norm() > 1e-12) return false;
          break;
        case JointType::Prismatic:
          if (std::abs(a.dot(n)) > 1e-12) return false;
          break;
        default: return false;
      }
    }
    return true;
  }

  const std::string& mj_body_of(int b) const {
    static const std::string world = "world";
    return b == 0 ? world : mj_body_[b];
  }

  void constraints() {
    if (m_.constraints.empty()) return;
    // MuJoCo's connect takes its anchor on body2 where the anchor on body1 is at qpos0: there,
    // hinges and slides are at q0 (their ref) and balls at the identity
    Eigen::VectorXd qmj0 = m_.q0;
    for (int b = 1; b < m_.nbodies; ++b)
      if (m_.joints[b].type == JointType::Spherical) qmj0.segment<4>(m_.joints[b].idx_q) << 1, 0, 0, 0;
    DataT<double> d(m_), d0(m_);
    forward_kinematics<double>(m_, d, qmj0);
    forward_kinematics<double>(m_, d0, m_.q0);
    pending_eq_.clear();
    for (const ConstraintModel& c : m_.constraints) {
      const std::string kind = to_string(c.type);
      if (c.type == ConstraintType::Coupler) {
        if (c.ncoupled != 2) {
          refuse("coupler " + c.name + ": " + std::to_string(c.ncoupled) + " joints (MuJoCo's joint equality couples two)");
          continue;
        }
        int a = 0, bb = 1;
        if (c.ratio[0] == 0) std::swap(a, bb);
        const int ja = joint_of_iv(c.iv[a]), jb = joint_of_iv(c.iv[bb]);
        if (ja < 0 || jb < 0 || c.ratio[a] == 0) {
          refuse("coupler " + c.name + ": not between two scalar coordinates");
          continue;
        }
        // ratio_a q_a + ratio_b q_b = offset  <=>  q_a - ref_a = c0 + c1 (q_b - ref_b)
        const double c1 = -c.ratio[bb] / c.ratio[a];
        const double c0 = c.offset / c.ratio[a] - mj_joints_[ja].ref + c1 * mj_joints_[jb].ref;
        PendingEq e;
        e.name = c.name;
        e.b1 = ja;
        e.b2 = jb;
        e.c0 = c0;
        e.c1 = c1;
        pending_eq_.push_back(e);
        ++ncoupler_;
        continue;
      }
      if (c.type == ConstraintType::RollingBall || c.type == ConstraintType::RollingDisc) {
        refuse(std::string(to_string(c.type)) + " " + c.name +
               ": MuJoCo models rolling by contact and friction, not as an exact no-slip condition");
        continue;
      }
      if (c.type != ConstraintType::Ball) {
        // planar_revolute, revolute: a connect is the same where the loop is planar about the axis
        const Eigen::Vector3d n = d0.oMi[c.body_a].R * c.axis_a;
        bool planar = planar_path(c.body_a, n, d0) && planar_path(c.body_b, n, d0);
        if (c.type == ConstraintType::Revolute) {
          const ConstraintSpec* cs = spec_constraint(c.name);
          const Eigen::Vector3d nb = d0.oMi[c.body_b].R * (cs ? cs->axis_b.normalized() : c.axis_a);
          planar = planar && nb.cross(n).norm() <= 1e-12;
        }
        if (!planar) {
          refuse(kind + " closure " + c.name + ": the loop is not planar about its axis (MuJoCo 2.2.2 has connect, " +
                 "a ball closure, and weld; no " + (c.type == ConstraintType::Revolute ? "hinge" : "planar") + " closure)");
          continue;
        }
      }
      // where the anchors are at MuJoCo's qpos0
      const Eigen::Vector3d pa = point_position<double>(d, c.body_a, c.point_a), pb = point_position<double>(d, c.body_b, c.point_b);
      Eigen::Vector3d gap = pb - pa;
      if (c.type != ConstraintType::Ball) {
        const Eigen::Vector3d n = d.oMi[c.body_a].R * c.axis_a;
        gap -= n * n.dot(gap);
      }
      const double scale = 1 + pa.norm() + pb.norm();
      if (gap.norm() > 1e-9 * scale) {
        refuse(kind + " closure " + c.name + ": its points are " + brief(gap.norm()) + " m apart where MuJoCo's connect " +
               "takes its anchors (qpos0: hinges and slides at q0, ball joints at the identity; a ball joint of the " +
               "loop is turned in q0)");
        continue;
      }
      PendingEq e;
      e.connect = true;
      e.name = c.name;
      // body1 carries the anchor (ground cannot: swap)
      e.b1 = c.body_a == 0 ? c.body_b : c.body_a;
      e.b2 = c.body_a == 0 ? c.body_a : c.body_b;
      e.anchor = c.body_a == 0 ? c.point_b : c.point_a;
      pending_eq_.push_back(e);
      ++nconnect_;
    }
  }

  const ConstraintSpec* spec_constraint(const std::string& name) const {
    for (const ConstraintSpec& c : m_.spec.constraints)
      if (c.name == name) return &c;
    return nullptr;
  }

  struct PendingEq {
    bool connect = false;
    std::string name;
    int b1 = 0, b2 = 0;  // connect: codyna bodies; joint: MuJoCo joints (ja, jb)
    double c0 = 0, c1 = 0;  // joint: q1 - ref1 = c0 + c1 (q2 - ref2)
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();  // connect: on b1, in its frame
  };
  std::vector<PendingEq> pending_eq_;

  struct PendingActuator {
    std::string line;  // attributes after the name
    std::string name;
    const ActuatorModel* a = nullptr;
  };
  std::vector<PendingActuator> pending_act_;

  void actuators() {
    for (const ActuatorModel& a : m_.actuators) {
      const std::string t = to_string(a.type);
      if (!a.driven_by.empty()) continue;  // the mix is refused below
      PendingActuator p;
      p.name = a.name;
      p.a = &a;
      const Eigen::Vector3d z = Eigen::Vector3d::Zero();
      switch (a.type) {
        case ActuatorType::JointForce: {
          const int jj = joint_of_iv(a.iv);
          if (jj >= 0) {
            p.line = "joint=" + q(mj_joints_[jj].name) + " gear=\"" + mjcf_number(a.gain) + "\"";
            break;
          }
          const int b = body_of_iv(a.iv);
          const JointModel& j = m_.joints[b];
          const int k = a.iv - j.idx_v;
          if (j.type == JointType::Spherical) {
            // MuJoCo's ball torques act in the body's axes: the coordinate's axis there is R_c e_k
            p.line = "joint=" + q(j.name) + " gear=\"" + vec(a.gain * j.X_CM.R.col(k)) + " 0 0 0\"";
          } else if (k < 3) {  // free: torque about a body axis (MuJoCo's last three coordinates)
            p.line = "joint=" + q(j.name) + " gear=\"0 0 0 " + vec(a.gain * Eigen::Vector3d::Unit(k)) + "\"";
          } else {  // free: force along a body axis at the body's origin (MuJoCo's linear coordinates are in world axes)
            p.line = "site=" + q(site(b, z, a.name + "_site")) + " gear=\"" + vec(a.gain * Eigen::Vector3d::Unit(k - 3)) + " 0 0 0\"";
          }
          break;
        }
        case ActuatorType::BodyForce:
        case ActuatorType::BodyTorque:
          if (a.in_world) {
            refuse(t + " " + a.name + ": in world axes (MuJoCo 2.2.2's site transmission acts in the site's axes, " +
                   "which turn with the body)");
            continue;
          }
          if (a.type == ActuatorType::BodyForce)
            p.line = "site=" + q(site(a.body, a.point, a.name + "_site")) + " gear=\"" + vec(a.gain * a.direction) + " 0 0 0\"";
          else
            p.line = "site=" + q(site(a.body, z, a.name + "_site")) + " gear=\"0 0 0 " + vec(a.gain * a.direction) + "\"";
          break;
        case ActuatorType::LineForce: {
          const std::string sa = site(a.body, a.point, a.name + "_a"), sb = site(a.body_b, a.point_b, a.name + "_b");
          const std::string tn = tendon_names_.unique(a.name + "_line");
          tendon_xml_ << "    <spatial name=" << q(tn) << ">\n      <site site=" << q(sa) << "/>\n      <site site="
                      << q(sb) << "/>\n    </spatial>\n";
          ++nlines_;
          p.line = "tendon=" + q(tn) + " gear=\"" + mjcf_number(a.gain) + "\"";
          break;
        }
        case ActuatorType::Mix:
          refuse("mix " + a.name + ": one input driving several actuators (a MuJoCo actuator has one transmission)");
          continue;
        default:
          refuse(t + " " + a.name + ": no MJCF equivalent");
          continue;
      }
      if (std::isfinite(a.min) || std::isfinite(a.max))
        p.line += " ctrllimited=\"true\" ctrlrange=\"" + mjcf_number(a.min) + " " + mjcf_number(a.max) + "\"";
      else
        p.line += " ctrllimited=\"false\"";
      pending_act_.push_back(p);
    }
  }

  void sensors() {
    std::vector<std::string> other;
    for (const SensorModel& s : m_.sensors) {
      const int jj = (s.type == SensorType::JointPosition || s.type == SensorType::JointVelocity) ? joint_of_iv(s.iv) : -1;
      if (jj < 0) {
        other.push_back(s.name + " (" + to_string(s.type) + ")");
        continue;
      }
      sensor_xml_ << "    <" << (s.type == SensorType::JointPosition ? "jointpos" : "jointvel") << " name="
                  << q(sensor_names_.unique(s.name)) << " joint=" << q(mj_joints_[jj].name) << "/>\n";
      ++nsensors_;
    }
    if (!other.empty()) {
      std::string t = "sensors without an MJCF equivalent written (outputs only): ";
      for (std::size_t i = 0; i < other.size(); ++i) t += (i ? ", " : "") + other[i];
      out_.not_written.push_back(t);
    }
  }

  // --- writing ---

  std::ostringstream x_;

  void write_body(int start, int depth) {
    std::vector<int> chain{start};
    while (mergeable(chain.back())) chain.push_back(children_[chain.back()][0]);
    const int last = chain.back();
    const std::string name = body_names_.unique(body_name(last));
    if (name != body_name(last))
      out_.not_written.push_back("body " + body_name(last) + " is named " + name + " (MuJoCo's world body is world)");
    for (int b : chain) mj_body_[b] = name;
    for (std::size_t i = 0; i + 1 < chain.size(); ++i) merged_.push_back(body_name(chain[i]));
    // the chain of transforms and joints (docs: X = A0 E1(q1) A1 E2(q2) ... An; a hinge's or slide's
    // E(q) = E(ref) E(q - ref) with E(ref) taken into the transform before it)
    SE3 acc;
    std::vector<int> js;
    for (int b : chain) {
      const JointModel& j = m_.joints[b];
      if (j.type == JointType::Free) {
        // MuJoCo's free joint: the body's world pose is qpos (frames are the identity), placed at q0
        const Eigen::VectorXd& q0 = m_.q0;
        acc = SE3(Eigen::Quaterniond(q0[j.idx_q + 3], q0[j.idx_q + 4], q0[j.idx_q + 5], q0[j.idx_q + 6]).normalized().toRotationMatrix(),
                  q0.segment<3>(j.idx_q));
        js.push_back(joint_elems_[b][0]);
        continue;
      }
      acc = acc * j.X_PF;
      for (int e : joint_elems_[b]) {
        MjJoint& mj = mj_joints_[e];
        if (mj.kind == Elem::Hinge) acc = acc * rot(mj.axis, mj.ref);
        if (mj.kind == Elem::Slide) acc = acc * trans(mj.axis * mj.ref);
        mj.G = acc;  // for now the prefix; made relative to the body below
        js.push_back(e);
      }
      acc = acc * j.X_CM.inverse();
    }
    const SE3 X0 = acc, X0i = X0.inverse();
    const std::string ind(2 * depth + 4, ' ');
    x_ << ind << "<body name=" << q(name) << " pos=\"" << vec(X0.p) << "\" quat=\"" << quat_text(quat_of(X0.R)) << "\">\n";
    ++out_.nbodies;
    // inertia: principal moments and axes (double precision here; see the header)
    const double mass = m_.mass[last];
    const int si = m_.body_spec_index[last];
    const BodySpec* bs = si >= 0 ? &m_.spec.bodies[si] : nullptr;
    const Eigen::Vector3d com = m_.com[last];
    const Eigen::Matrix3d Ic = bs ? bs->inertia : Eigen::Matrix3d::Zero();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (Ic + Ic.transpose()));
    Eigen::Matrix3d V = es.eigenvectors();
    Eigen::Vector3d I = es.eigenvalues();
    if (V.determinant() < 0) V.col(2) = -V.col(2);
    const double Imax = I.cwiseAbs().maxCoeff();
    for (int k = 0; k < 3; ++k)
      if (I[k] < 0 && I[k] >= -1e-15 * Imax) I[k] = 0;  // round-off of a zero moment
    // MuJoCo requires A + B >= C exactly; a thin rod's (0, I, I) may miss it by round-off
    if (I[0] + I[1] < I[2] && I[2] - (I[0] + I[1]) <= 1e-12 * Imax) I[2] = I[0] + I[1];
    x_ << ind << "  <inertial pos=\"" << vec(com) << "\" mass=\"" << mjcf_number(mass) << "\" quat=\""
       << quat_text(quat_of(V)) << "\" diaginertia=\"" << vec(I) << "\"/>\n";
    for (int e : js) {
      MjJoint& mj = mj_joints_[e];
      ++out_.njoints;
      if (mj.kind == Elem::Free) {
        x_ << ind << "  <joint name=" << q(mj.name) << " type=\"free\"";
        if (mj.damping != 0) x_ << " damping=\"" << mjcf_number(mj.damping) << "\"";
        if (mj.armature != 0) x_ << " armature=\"" << mjcf_number(mj.armature) << "\"";
        x_ << "/>\n";
        mj.G = SE3();
        continue;
      }
      mj.G = X0i * mj.G;
      x_ << ind << "  <joint name=" << q(mj.name) << " type=\""
         << (mj.kind == Elem::Hinge ? "hinge" : mj.kind == Elem::Slide ? "slide" : "ball") << "\" pos=\"" << vec(mj.G.p) << "\"";
      if (mj.kind != Elem::Ball) {
        x_ << " axis=\"" << vec(mj.G.R * mj.axis) << "\"";
        if (mj.ref != 0) x_ << " ref=\"" << mjcf_number(mj.ref) << "\"";
      }
      if (mj.has_spring)
        x_ << " stiffness=\"" << mjcf_number(mj.stiffness) << "\" springref=\"" << mjcf_number(mj.kref / mj.stiffness) << "\"";
      if (mj.damping != 0) x_ << " damping=\"" << mjcf_number(mj.damping) << "\"";
      if (mj.armature != 0) x_ << " armature=\"" << mjcf_number(mj.armature) << "\"";
      x_ << "/>\n";
    }
    if (bs) {
      for (const ShapeSpec& s : bs->shapes) {
        x_ << ind << "  <geom type=\"";
        switch (s.type) {
          case ShapeType::Box: x_ << "box\" size=\"" << vec(0.5 * s.size) << "\""; break;
          case ShapeType::Cylinder: x_ << "cylinder\" size=\"" << mjcf_number(s.radius) << " " << mjcf_number(0.5 * s.length) << "\""; break;
          case ShapeType::Sphere: x_ << "sphere\" size=\"" << mjcf_number(s.radius) << "\""; break;
        }
        x_ << " pos=\"" << vec(s.frame.position) << "\" quat=\"" << quat_text(quat_of(s.frame.rotation)) << "\" rgba=\""
           << mjcf_number(s.color[0]) << " " << mjcf_number(s.color[1]) << " " << mjcf_number(s.color[2]) << " " << mjcf_number(s.color[3])
           << "\" contype=\"0\" conaffinity=\"0\"/>\n";
        ++nshapes_;
      }
    }
    write_sites(last, ind + "  ");
    for (int c : children_[last]) write_body(c, depth + 1);
    x_ << ind << "</body>\n";
  }
  std::vector<std::string> merged_;
  int nshapes_ = 0;

  void write_sites(int body, const std::string& ind) {
    const auto it = body_sites_.find(body);
    if (it == body_sites_.end()) return;
    std::istringstream in(it->second);
    for (std::string line; std::getline(in, line);) x_ << ind << line << "\n";
  }

  bool keyframe_needed() const {
    for (int b = 1; b < m_.nbodies; ++b)
      if (m_.joints[b].type == JointType::Spherical) {
        const Eigen::Vector4d qb = m_.q0.segment<4>(m_.joints[b].idx_q);
        if (qb != Eigen::Vector4d(1, 0, 0, 0)) return true;
      }
    if (!m_.v0.isZero(0.0)) return true;
    for (const ActuatorModel& a : m_.actuators)
      if (a.u0 != 0) return true;
    return false;
  }

  void write_keyframe() {
    // MuJoCo's qpos and qvel in the order of its joints (the order written)
    std::vector<int> order;
    std::function<void(int)> walk = [&](int start) {
      std::vector<int> chain{start};
      while (mergeable(chain.back())) chain.push_back(children_[chain.back()][0]);
      for (int b : chain)
        for (int e : joint_elems_[b]) order.push_back(e);
      for (int c : children_[chain.back()]) walk(c);
    };
    for (int c : children_[0]) walk(c);
    std::vector<double> qpos, qvel;
    const Eigen::VectorXd &q0 = m_.q0, &v0 = m_.v0;
    for (int e : order) {
      const MjJoint& mj = mj_joints_[e];
      const JointModel& j = m_.joints[mj.body];
      switch (mj.kind) {
        case Elem::Hinge:
        case Elem::Slide:
          qpos.push_back(q0[mj.iq]);
          qvel.push_back(v0[mj.iv]);
          break;
        case Elem::Ball: {
          const Eigen::Quaterniond qc = quat_of(mj.G.R);
          const Eigen::Quaterniond qj(q0[j.idx_q], q0[j.idx_q + 1], q0[j.idx_q + 2], q0[j.idx_q + 3]);
          const Eigen::Quaterniond qm = qc * qj * qc.conjugate();
          for (double c : {qm.w(), qm.x(), qm.y(), qm.z()}) qpos.push_back(c);
          const Eigen::Vector3d w = mj.G.R * v0.segment<3>(j.idx_v);
          for (int k = 0; k < 3; ++k) qvel.push_back(w[k]);
          break;
        }
        case Elem::Free: {
          for (int k = 0; k < 7; ++k) qpos.push_back(q0[j.idx_q + k]);
          const Eigen::Matrix3d R =
              Eigen::Quaterniond(q0[j.idx_q + 3], q0[j.idx_q + 4], q0[j.idx_q + 5], q0[j.idx_q + 6]).normalized().toRotationMatrix();
          const Eigen::Vector3d lin = R * v0.segment<3>(j.idx_v + 3), w = v0.segment<3>(j.idx_v);
          for (int k = 0; k < 3; ++k) qvel.push_back(lin[k]);
          for (int k = 0; k < 3; ++k) qvel.push_back(w[k]);
          break;
        }
      }
    }
    auto list = [](const std::vector<double>& v) {
      std::string s;
      for (std::size_t i = 0; i < v.size(); ++i) s += (i ? " " : "") + mjcf_number(v[i]);
      return s;
    };
    std::vector<double> ctrl;
    for (const PendingActuator& p : pending_act_) ctrl.push_back(p.a->u0);
    x_ << "  <keyframe>\n    <key name=\"initial\"";
    if (!qpos.empty()) x_ << " qpos=\"" << list(qpos) << "\"";
    if (!qvel.empty()) x_ << " qvel=\"" << list(qvel) << "\"";
    if (!ctrl.empty()) x_ << " ctrl=\"" << list(ctrl) << "\"";
    x_ << "/>\n  </keyframe>\n";
  }

  void write() {
    mj_body_.assign(m_.nbodies, "");
    body_names_.used.insert("world");
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int ngravity = 0;
    for (const EffectSpec& e : m_.spec.effects)
      if (e.type == EffectType::Gravity) {
        g += e.g;
        ++ngravity;
      }
    x_ << kMjcfHeader << " " << CODYNA_VERSION << " (codyna export-mjcf) from " << comment_text(label_)
       << ": the same mechanism for MuJoCo 2.2 (docs/import.md) -->\n";
    x_ << "<mujoco model=" << q(m_.name) << ">\n";
    x_ << "  <compiler angle=\"radian\" inertiafromgeom=\"false\" balanceinertia=\"false\" boundmass=\"0\" "
          "boundinertia=\"0\" settotalmass=\"-1\"/>\n";
    const double dt = m_.spec.solver.output_step > 0 ? m_.spec.solver.output_step : 0.002;
    x_ << "  <option gravity=\"" << vec(g) << "\" timestep=\"" << mjcf_number(dt) << "\"/>\n";
    x_ << "  <default>\n    <joint limited=\"false\" armature=\"0\" damping=\"0\" stiffness=\"0\" frictionloss=\"0\"/>\n"
          "    <geom contype=\"0\" conaffinity=\"0\"/>\n"
          "    <equality solimp=\"0.9999 0.9999 0.001 0.5 2\"/>\n  </default>\n";
    x_ << "  <worldbody>\n";
    write_sites(0, "    ");
    for (int c : children_[0]) write_body(c, 0);
    x_ << "  </worldbody>\n";
    if (!tendon_xml_.str().empty()) x_ << "  <tendon>\n" << tendon_xml_.str() << "  </tendon>\n";
    if (!pending_eq_.empty()) {
      x_ << "  <equality>\n";
      for (const PendingEq& e : pending_eq_) {
        const std::string n = eq_names_.unique(e.name);
        if (e.connect) {
          x_ << "    <connect name=" << q(n) << " body1=" << q(mj_body_of(e.b1));
          if (e.b2 != 0) x_ << " body2=" << q(mj_body_of(e.b2));
          x_ << " anchor=\"" << vec(e.anchor) << "\"/>\n";
        } else {
          x_ << "    <joint name=" << q(n) << " joint1=" << q(mj_joints_[e.b1].name) << " joint2=" << q(mj_joints_[e.b2].name)
             << " polycoef=\"" << mjcf_number(e.c0) << " " << mjcf_number(e.c1) << " 0 0 0\"/>\n";
        }
        ++out_.nequalities;
      }
      x_ << "  </equality>\n";
    }
    if (!pending_act_.empty()) {
      x_ << "  <actuator>\n";
      for (const PendingActuator& p : pending_act_) {
        x_ << "    <motor name=" << q(p.name) << " " << p.line << "/>\n";
        ++out_.nactuators;
      }
      x_ << "  </actuator>\n";
    }
    if (!sensor_xml_.str().empty()) x_ << "  <sensor>\n" << sensor_xml_.str() << "  </sensor>\n";
    const bool key = keyframe_needed();
    if (key) write_keyframe();
    x_ << "</mujoco>\n";
    out_.xml = x_.str();

    auto& w = out_.written;
    w.push_back(std::to_string(out_.nbodies) + " bodies (mass, centre of mass, inertia as principal moments and axes)" +
                (merged_.empty() ? "" : "; " + std::to_string(merged_.size()) + " massless frames merged into the body they carry"));
    std::map<std::string, int> types;
    for (const MjJoint& j : mj_joints_) types[j.kind == Elem::Hinge ? "hinge" : j.kind == Elem::Slide ? "slide" : j.kind == Elem::Ball ? "ball" : "free"]++;
    std::string jt;
    for (const auto& [t, n] : types) jt += (jt.empty() ? "" : ", ") + std::to_string(n) + " " + t;
    w.push_back(std::to_string(out_.njoints) + " joints" + (jt.empty() ? "" : " (" + jt + ")") +
                ", hinges and slides with ref = q0 (MuJoCo's qpos is codyna's q)");
    if (nshapes_) w.push_back(std::to_string(nshapes_) + " display shapes -> geoms without contacts (contype = conaffinity = 0)");
    w.push_back(ngravity ? "gravity [" + brief(g.x()) + " " + brief(g.y()) + " " + brief(g.z()) + "] m/s^2" : "no gravity");
    if (njoint_springs_) w.push_back(std::to_string(njoint_springs_) + " joint springs -> joint stiffness, springref");
    if (narmatures_) w.push_back(std::to_string(narmatures_) + " joint armatures (rotor inertia) -> joint armature");
    if (njoint_dampers_) w.push_back(std::to_string(njoint_dampers_) + " joint dampings -> joint damping");
    if (nsprings_) w.push_back(std::to_string(nsprings_) + " spring_damper -> spatial tendons (stiffness, damping, springlength)");
    if (nconnect_) w.push_back(std::to_string(nconnect_) + " loop closures -> connect equalities (solimp 0.9999: MuJoCo's stay soft)");
    if (ncoupler_) w.push_back(std::to_string(ncoupler_) + " couplers -> joint equalities (polycoef)");
    if (out_.nactuators) w.push_back(std::to_string(out_.nactuators) + " actuators -> motors (gear = gain, ctrlrange = [min, max])" +
                                     (nlines_ ? ", " + std::to_string(nlines_) + " on spatial tendons" : ""));
    if (nsensors_) w.push_back(std::to_string(nsensors_) + " joint sensors -> jointpos, jointvel");
    if (key) w.push_back("the initial state (q0, v0, u0) -> keyframe initial");
    w.push_back("timestep " + brief(dt) + " s (the solver's output_step)");
    auto& nw = out_.not_written;
    if (!m_.plant_inputs.empty() || !m_.plant_outputs.empty() || m_.spec.controller.type != ControllerType::None)
      nw.push_back("the plant selection (Plant/In, Plant/Out), the controller and the analysis settings: codyna's own");
    if (!m_.spec.description.empty()) nw.push_back("the description");
  }
};

}  // namespace

MjcfExport export_mjcf(const Model& model, const std::string& source) { return Exporter(model, source).run(); }

#ifdef CODYNA_HAVE_MUJOCO

bool mjcf_load_check_available() { return true; }
std::string mjcf_load_check_version() { return std::string("MuJoCo ") + mj_versionString(); }

namespace {
std::vector<std::string>* g_check_warnings = nullptr;
extern "C" void collect_check_warning(const char* msg) {
  if (g_check_warnings) g_check_warnings->push_back(msg);
}
struct VfsDeleter {
  void operator()(mjVFS* v) const {
    mj_deleteVFS(v);
    delete v;
  }
};
}  // namespace

std::string mjcf_load_check(const std::string& xml) {
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const char* fname = "codyna_export.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), fname, static_cast<int>(xml.size())) != 0) return "MuJoCo's virtual file system is full";
  const int i = mj_findFileVFS(vfs.get(), fname);
  std::memcpy(vfs->filedata[i], xml.data(), xml.size());
  std::vector<std::string> warnings;
  g_check_warnings = &warnings;
  auto* old = mju_user_warning;
  mju_user_warning = collect_check_warning;
  char err[1024] = "";
  mjModel* m = mj_loadXML(fname, vfs.get(), err, sizeof err);
  mju_user_warning = old;
  g_check_warnings = nullptr;
  if (!m) return err[0] ? std::string(err) : std::string("MuJoCo did not load it");
  mj_deleteModel(m);
  return "";
}

#else

bool mjcf_load_check_available() { return false; }
std::string mjcf_load_check_version() { return "none (codyna was built without MuJoCo)"; }
std::string mjcf_load_check(const std::string&) { return ""; }

#endif

}  // namespace codyna
