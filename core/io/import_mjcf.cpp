#include "io/import_mjcf.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>

#ifdef CODYNA_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace codyna {

#ifndef CODYNA_HAVE_MUJOCO

bool mjcf_import_available() { return false; }
std::string mjcf_reader_version() { return "none (codyna was built without MuJoCo)"; }
ImportResult import_mjcf(const std::string& path, const ImportOptions&) {
  throw std::runtime_error(path + ": MJCF import needs MuJoCo, and this codyna was built without it "
                           "(install libmujoco-dev, then configure and build codyna again)");
}

#else

bool mjcf_import_available() { return true; }
std::string mjcf_reader_version() { return std::string("MuJoCo ") + mj_versionString(); }

namespace {

std::string mjcf_text(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

Eigen::Matrix3d quat_R(const mjtNum* q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}
Eigen::Vector3d v3(const mjtNum* p) { return Eigen::Vector3d(p[0], p[1], p[2]); }

FrameSpec compose(const FrameSpec& a, const FrameSpec& b) {
  FrameSpec f;
  f.position = a.position + a.rotation * b.position;
  f.rotation = a.rotation * b.rotation;
  return f;
}
FrameSpec translation(const Eigen::Vector3d& p) {
  FrameSpec f;
  f.position = p;
  return f;
}

struct ModelDeleter {
  void operator()(mjModel* p) const { mj_deleteModel(p); }
};

// MuJoCo's warnings while compiling (its default handler prints and writes MUJOCO_LOG.TXT)
std::vector<std::string>* g_warnings = nullptr;
extern "C" void collect_warning(const char* msg) {
  if (g_warnings) g_warnings->push_back(msg);
}

class MjcfImporter {
 public:
  MjcfImporter(const mjModel* m, std::string path, const ImportOptions& o) : m_(m), path_(std::move(path)), opt_(o) {}

  ImportResult run() {
    r_.report.source = path_;
    r_.report.format = "MJCF";
    r_.report.reader = mjcf_reader_version() + "'s compiler, mj_loadXML";
    ModelSpec& s = r_.spec;
    const std::string model_name = m_->names[0] ? std::string(m_->names) : std::filesystem::path(path_).stem().string();
    s.name = model_name;
    names();
    bodies();
    passive();
    gravity_and_options();
    equalities();
    tendons();
    actuators();
    sensors();
    contacts_and_other();
    plant();
    describe();
    refuse_if_needed(r_.report);
    return std::move(r_);
  }

 private:
  const mjModel* m_;
  std::string path_;
  const ImportOptions& opt_;
  ImportResult r_;
  int dis(int flag) const { return m_->opt.disableflags & flag; }

  std::vector<std::string> body_name_, joint_name_;  // codyna names by MuJoCo id
  NameSet bodies_, joints_, effects_, actuators_, sensors_, constraints_;
  std::vector<std::string> limits_;
  int nframes_ = 0, nshapes_ = 0, nwelds_ = 0;
  std::map<std::string, int> joint_types_;
  std::vector<std::string> approx_shapes_, hidden_shapes_, world_geoms_;

  const char* mjname(const int* adr, int id) const {
    const char* n = m_->names + adr[id];
    return n[0] ? n : nullptr;
  }
  void add(const std::string& kind, const std::string& what, std::vector<std::string> e, bool dyn) {
    add_finding(r_.report, opt_, kind, what, std::move(e), dyn);
  }

  void names() {
    bodies_.reserve(kGroundName);
    body_name_.assign(m_->nbody, "");
    body_name_[0] = kGroundName;
    // names given in the file first, so that generated ones never take them
    for (int b = 1; b < m_->nbody; ++b)
      if (const char* n = mjname(m_->name_bodyadr, b)) {
        if (std::string(n) == kGroundName) continue;
        body_name_[b] = bodies_.unique(n);
      }
    for (int b = 1; b < m_->nbody; ++b)
      if (body_name_[b].empty()) {
        const char* n = mjname(m_->name_bodyadr, b);
        body_name_[b] = bodies_.unique(n ? std::string(n) + "_body" : "body" + std::to_string(b));
        if (n) r_.spec.notes.push_back(path_ + ": body \"ground\" renamed " + body_name_[b] + " (\"ground\" is codyna's world)");
      }
    joint_name_.assign(m_->njnt, "");
    for (int j = 0; j < m_->njnt; ++j)
      if (const char* n = mjname(m_->name_jntadr, j)) joint_name_[j] = joints_.unique(n);
    for (int j = 0; j < m_->njnt; ++j)
      if (joint_name_[j].empty()) {
        const int b = m_->jnt_bodyid[j];
        const int k = j - m_->body_jntadr[b];
        joint_name_[j] = joints_.unique(body_name_[b] + "_joint" + (m_->body_jntnum[b] > 1 ? std::to_string(k) : ""));
      }
  }

  static const char* mj_joint_type(int t) {
    switch (t) {
      case mjJNT_FREE: return "free";
      case mjJNT_BALL: return "ball";
      case mjJNT_SLIDE: return "slide";
      default: return "hinge";
    }
  }

  void bodies() {
    ModelSpec& s = r_.spec;
    std::vector<std::string> mocap;
    for (int b = 1; b < m_->nbody; ++b) {
      const std::string& name = body_name_[b];
      const std::string& parent = body_name_[m_->body_parentid[b]];
      FrameSpec Xb;
      Xb.position = v3(m_->body_pos + 3 * b);
      Xb.rotation = quat_R(m_->body_quat + 4 * b);
      BodySpec body;
      body.name = name;
      body.mass = m_->body_mass[b];
      body.com = v3(m_->body_ipos + 3 * b);
      const Eigen::Matrix3d Ri = quat_R(m_->body_iquat + 4 * b);
      Eigen::Matrix3d I = Ri * v3(m_->body_inertia + 3 * b).asDiagonal() * Ri.transpose();
      body.inertia = 0.5 * (I + I.transpose());
      shapes(b, body);
      if (m_->body_mocapid[b] >= 0) mocap.push_back(name);
      const int nj = m_->body_jntnum[b];
      if (nj == 0) {
        JointSpec j;
        j.name = joints_.unique(name + "_weld");
        j.type = JointType::Fixed;
        j.parent = parent;
        j.child = name;
        j.parent_frame = Xb;
        s.joints.push_back(j);
        ++nwelds_;
      }
      std::string prev = parent;
      for (int k = 0; k < nj; ++k) {
        const int jid = m_->body_jntadr[b] + k;
        const int type = m_->jnt_type[jid];
        const int qa = m_->jnt_qposadr[jid];
        const Eigen::Vector3d anchor = v3(m_->jnt_pos + 3 * jid);
        const Eigen::Vector3d axis = v3(m_->jnt_axis + 3 * jid).normalized();
        JointSpec j;
        j.name = joint_name_[jid];
        j.parent = prev;
        if (k + 1 < nj) {
          BodySpec frame;  // a massless frame between two joints of one MuJoCo body
          frame.name = bodies_.unique(j.name + "_frame");
          s.bodies.push_back(frame);
          ++nframes_;
          j.child = frame.name;
        } else {
          j.child = name;
        }
        // the frame the joint turns in: the body's frame at qpos0 (first joint), else the frame
        // the previous joints moved; the joint's anchor in it
        const FrameSpec base = k == 0 ? Xb : FrameSpec{};
        ++joint_types_[mj_joint_type(type)];
        switch (type) {
          case mjJNT_HINGE: {
            j.type = JointType::Revolute;
            j.axis = axis;
            const double ref = m_->qpos0[qa];
            FrameSpec turn;
            turn.rotation = Eigen::AngleAxisd(-ref, axis).toRotationMatrix();
            j.parent_frame = compose(compose(base, translation(anchor)), turn);
            j.child_frame = translation(anchor);
            j.q0 = Eigen::VectorXd::Constant(1, ref);
            break;
          }
          case mjJNT_SLIDE: {
            j.type = JointType::Prismatic;
            j.axis = axis;
            const double ref = m_->qpos0[qa];
            j.parent_frame = compose(base, translation(anchor - ref * axis));
            j.child_frame = translation(anchor);
            j.q0 = Eigen::VectorXd::Constant(1, ref);
            break;
          }
          case mjJNT_BALL:
            j.type = JointType::Spherical;
            j.parent_frame = compose(base, translation(anchor));
            j.child_frame = translation(anchor);
            j.q0 = Eigen::Map<const Eigen::Vector4d>(m_->qpos0 + qa);
            break;
          case mjJNT_FREE:
            if (m_->body_parentid[b] != 0 || nj != 1)
              throw ImportRefused(path_ + ": body " + name + ": a free joint below another body (or beside other "
                                  "joints) is not supported", r_.report);
            j.type = JointType::Free;  // MuJoCo's free qpos is the body's pose in the world
            j.q0 = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(m_->qpos0 + qa);
            break;
        }
        if (m_->jnt_limited[jid] && !dis(mjDSBL_LIMIT) && (type == mjJNT_HINGE || type == mjJNT_SLIDE))
          limits_.push_back(j.name + " [" + mjcf_text(m_->jnt_range[2 * jid]) + ", " + mjcf_text(m_->jnt_range[2 * jid + 1]) + "]");
        else if (m_->jnt_limited[jid] && !dis(mjDSBL_LIMIT))
          limits_.push_back(j.name + " (cone " + mjcf_text(m_->jnt_range[2 * jid + 1]) + ")");
        s.joints.push_back(j);
        prev = j.child;
      }
      s.bodies.push_back(body);
    }
    add("other", "mocap bodies (moved by data in MuJoCo): welded where the file puts them", mocap, false);
    add("limits", "joint limits (MuJoCo's soft limit constraints): not modelled, kept in the description", limits_, false);
  }

  Eigen::Vector4d rgba(int g) const {
    const float* c = m_->geom_matid[g] >= 0 ? m_->mat_rgba + 4 * m_->geom_matid[g] : m_->geom_rgba + 4 * g;
    Eigen::Vector4d v(c[0], c[1], c[2], c[3]);
    return v.cwiseMax(0.0).cwiseMin(1.0);
  }

  std::string geom_label(int g) const {
    if (const char* n = mjname(m_->name_geomadr, g)) return n;
    const int b = m_->geom_bodyid[g];
    return body_name_[b] + " geom " + std::to_string(g - m_->body_geomadr[b]);
  }

  void shapes(int b, BodySpec& body) {
    for (int g = m_->body_geomadr[b]; g >= 0 && g < m_->body_geomadr[b] + m_->body_geomnum[b]; ++g) {
      const mjtNum* sz = m_->geom_size + 3 * g;
      FrameSpec f;
      f.position = v3(m_->geom_pos + 3 * g);
      f.rotation = quat_R(m_->geom_quat + 4 * g);
      ShapeSpec sh;
      sh.frame = f;
      sh.color = rgba(g);
      switch (m_->geom_type[g]) {
        case mjGEOM_SPHERE:
          sh.type = ShapeType::Sphere;
          sh.radius = sz[0];
          body.shapes.push_back(sh);
          break;
        case mjGEOM_CAPSULE: {
          sh.type = ShapeType::Cylinder;
          sh.radius = sz[0];
          sh.length = 2 * sz[1];
          body.shapes.push_back(sh);
          for (double e : {-sz[1], sz[1]}) {  // the capsule's round ends
            ShapeSpec end = sh;
            end.type = ShapeType::Sphere;
            end.frame = compose(f, translation(Eigen::Vector3d(0, 0, e)));
            body.shapes.push_back(end);
          }
          break;
        }
        case mjGEOM_CYLINDER:
          sh.type = ShapeType::Cylinder;
          sh.radius = sz[0];
          sh.length = 2 * sz[1];
          body.shapes.push_back(sh);
          break;
        case mjGEOM_BOX:
          sh.type = ShapeType::Box;
          sh.size = 2 * v3(sz);
          body.shapes.push_back(sh);
          break;
        case mjGEOM_ELLIPSOID:
          sh.type = ShapeType::Box;
          sh.size = 2 * v3(sz);
          body.shapes.push_back(sh);
          approx_shapes_.push_back(geom_label(g) + " (ellipsoid: its bounding box)");
          break;
        case mjGEOM_MESH: {
          const int mesh = m_->geom_dataid[g];
          Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
          for (int v = 0; mesh >= 0 && v < m_->mesh_vertnum[mesh]; ++v) {
            const float* p = m_->mesh_vert + 3 * (m_->mesh_vertadr[mesh] + v);
            const Eigen::Vector3d x(p[0], p[1], p[2]);
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
          }
          if (!(lo.array() <= hi.array()).all()) break;
          sh.type = ShapeType::Box;
          sh.size = (hi - lo).cwiseMax(1e-6);
          sh.frame = compose(f, translation(0.5 * (lo + hi)));
          body.shapes.push_back(sh);
          const char* mn = mesh >= 0 ? mjname(m_->name_meshadr, mesh) : nullptr;
          approx_shapes_.push_back(geom_label(g) + " (mesh" + (mn ? std::string(" ") + mn : "") + ": its bounding box)");
          break;
        }
        default:
          hidden_shapes_.push_back(geom_label(g) + (m_->geom_type[g] == mjGEOM_PLANE ? " (plane)" : " (height field)"));
      }
    }
    nshapes_ += static_cast<int>(body.shapes.size());
  }

  void passive() {
    ModelSpec& s = r_.spec;
    std::vector<std::string> armature, armature_uneven, armature_free, friction, ball_springs, damped;
    int nsprings = 0, ndampers = 0, narmatures = 0;
    const bool keep_armature = !opt_.ignore.count("armature");
    for (int j = 0; j < m_->njnt; ++j) {
      const int type = m_->jnt_type[j];
      const int da = m_->jnt_dofadr[j];
      const int ndof = type == mjJNT_FREE ? 6 : type == mjJNT_BALL ? 3 : 1;
      // armature: MuJoCo adds it to the diagonal of M in its dof space; a hinge's or slide's dof is
      // codyna's coordinate, and a ball's rates differ from codyna's by a constant rotation, under
      // which one value on the three dofs stays the same diagonal. A free joint's linear dofs are
      // world-axes velocities in MuJoCo, body-axes ones in codyna: the same diagonal there differs
      // by the velocity term armature (w x v), so it is refused
      bool uneven = false, any = false;
      for (int k = 0; k < ndof; ++k) {
        any = any || m_->dof_armature[da + k] != 0;
        uneven = uneven || m_->dof_armature[da + k] != m_->dof_armature[da];
      }
      if (any) {
        std::string e = joint_name_[j] + " " + mjcf_text(m_->dof_armature[da]);
        for (int k = 1; uneven && k < ndof; ++k) e += " " + mjcf_text(m_->dof_armature[da + k]);
        if (type == mjJNT_FREE) armature_free.push_back(e);
        else if (uneven) armature_uneven.push_back(e);
        else if (!keep_armature) armature.push_back(e);
        else
          for (JointSpec& js : s.joints)
            if (js.name == joint_name_[j]) {
              js.armature = Eigen::VectorXd::Constant(1, m_->dof_armature[da]);
              ++narmatures;
            }
      }
      for (int k = 0; k < ndof; ++k) {
        if (m_->dof_frictionloss[da + k] != 0 && !dis(mjDSBL_FRICTIONLOSS))
          friction.push_back(joint_name_[j] + (ndof > 1 ? "[" + std::to_string(k) + "]" : "") + " " +
                             mjcf_text(m_->dof_frictionloss[da + k]));
      }
      if (dis(mjDSBL_PASSIVE)) continue;
      const double k = m_->jnt_stiffness[j], c = m_->dof_damping[da];
      if (type == mjJNT_HINGE || type == mjJNT_SLIDE) {
        if (k != 0) {
          EffectSpec e;
          e.name = effects_.unique(joint_name_[j] + "_spring");
          e.type = EffectType::JointSpringDamper;
          e.joint = joint_name_[j];
          e.stiffness = k;
          e.damping = c;
          e.rest_position = m_->qpos_spring[m_->jnt_qposadr[j]];
          s.effects.push_back(e);
          ++nsprings;
        } else if (c != 0) {
          EffectSpec e;
          e.name = effects_.unique(joint_name_[j] + "_damper");
          e.type = EffectType::JointDamper;
          e.joint = joint_name_[j];
          e.damping = c;
          s.effects.push_back(e);
          ++ndampers;
        }
      } else {
        if (k != 0) ball_springs.push_back(joint_name_[j] + " " + mjcf_text(k));
        bool same = true;
        for (int q = 1; q < ndof; ++q) same = same && m_->dof_damping[da + q] == c;
        if (!same) damped.push_back(joint_name_[j]);
        if (c != 0 && same) {
          EffectSpec e;
          e.name = effects_.unique(joint_name_[j] + "_damper");
          e.type = EffectType::JointDamper;
          e.joint = joint_name_[j];
          e.damping = c;
          s.effects.push_back(e);
          ++ndampers;
        }
      }
    }
    if (nsprings) r_.report.mapped.push_back(std::to_string(nsprings) + " joint stiffnesses (with their damping, springref as rest position) -> joint_spring_damper");
    if (ndampers) r_.report.mapped.push_back(std::to_string(ndampers) + " joint dampings -> joint_damper");
    if (narmatures) r_.report.mapped.push_back(std::to_string(narmatures) + " joint armatures (rotor inertia) -> joint armature");
    add("armature", "rotor inertia (armature) left out as --ignore armature asks", armature, true);
    add("armature", "different armatures on the coordinates of one ball joint", armature_uneven, true);
    add("armature",
        "armature on a free joint (MuJoCo's linear dofs are world-axes velocities, codyna's body-axes ones: "
        "the same diagonal differs by armature (w x v))",
        armature_free, true);
    add("frictionloss", "dry friction (frictionloss) is not modelled", friction, true);
    add("springs", "stiffness of a ball or free joint has no codyna equivalent", ball_springs, true);
    add("springs", "different dampings on the coordinates of one joint", damped, true);
    if (!dis(mjDSBL_PASSIVE) && (m_->opt.density != 0 || m_->opt.viscosity != 0))
      add("fluid", "fluid forces are not modelled",
          {"density " + mjcf_text(m_->opt.density), "viscosity " + mjcf_text(m_->opt.viscosity),
           "wind [" + mjcf_text(m_->opt.wind[0]) + " " + mjcf_text(m_->opt.wind[1]) + " " + mjcf_text(m_->opt.wind[2]) + "]"}, true);
  }

  void gravity_and_options() {
    const Eigen::Vector3d g = v3(m_->opt.gravity);
    if (!dis(mjDSBL_GRAVITY) && g.norm() > 0) {
      EffectSpec e;
      e.name = effects_.unique("gravity");
      e.type = EffectType::Gravity;
      e.g = g;
      r_.spec.effects.insert(r_.spec.effects.begin(), e);
      r_.report.mapped.push_back("gravity [" + mjcf_text(g.x()) + " " + mjcf_text(g.y()) + " " + mjcf_text(g.z()) + "] m/s^2 -> gravity effect");
    } else {
      r_.report.mapped.push_back("no gravity (zero or disabled in the file)");
    }
    r_.spec.solver.output_step = m_->opt.timestep;
    r_.report.mapped.push_back("timestep " + mjcf_text(m_->opt.timestep) + " s -> solver output_step (codyna's integrators choose their own steps)");
  }

  void equalities() {
    std::vector<std::string> other, inactive, soft;
    int nconnect = 0, ncoupler = 0;
    for (int e = 0; e < m_->neq; ++e) {
      const char* n = mjname(m_->name_eqadr, e);
      const std::string label = n ? n : "equality" + std::to_string(e);
      if (dis(mjDSBL_EQUALITY) || !m_->eq_active[e]) {
        inactive.push_back(label);
        continue;
      }
      if (m_->eq_type[e] == mjEQ_CONNECT) {
        ConstraintSpec c;
        c.name = constraints_.unique(label);
        c.type = ConstraintType::Ball;
        c.body_a = body_name_[m_->eq_obj1id[e]];
        c.body_b = body_name_[m_->eq_obj2id[e] < 0 ? 0 : m_->eq_obj2id[e]];
        c.point_a = v3(m_->eq_data + mjNEQDATA * e);
        c.point_b = v3(m_->eq_data + mjNEQDATA * e + 3);
        r_.spec.constraints.push_back(c);
        ++nconnect;
        soft.push_back(label + " (solref " + mjcf_text(m_->eq_solref[mjNREF * e]) + " " + mjcf_text(m_->eq_solref[mjNREF * e + 1]) + ")");
      } else if (m_->eq_type[e] == mjEQ_JOINT && linear_joint_equality(e)) {
        // MuJoCo: q1 - qpos0_1 = data0 + data1 (q2 - qpos0_2): a coupler q1 - data1 q2 = offset
        const int j1 = m_->eq_obj1id[e], j2 = m_->eq_obj2id[e];
        const mjtNum* d = m_->eq_data + mjNEQDATA * e;
        ConstraintSpec c;
        c.name = constraints_.unique(label);
        c.type = ConstraintType::Coupler;
        c.joint_a = joint_name_[j1];
        c.joint_b = joint_name_[j2];
        c.ratio_a = 1;
        c.ratio_b = -d[1];
        c.offset = m_->qpos0[m_->jnt_qposadr[j1]] + d[0] - d[1] * m_->qpos0[m_->jnt_qposadr[j2]];
        r_.spec.constraints.push_back(c);
        ++ncoupler;
        soft.push_back(label + " (solref " + mjcf_text(m_->eq_solref[mjNREF * e]) + " " + mjcf_text(m_->eq_solref[mjNREF * e + 1]) + ")");
      } else {
        static const char* types[] = {"connect", "weld", "joint", "tendon", "distance"};
        other.push_back(label + " (" + types[m_->eq_type[e]] + ")");
      }
    }
    if (nconnect) r_.report.mapped.push_back(std::to_string(nconnect) + " connect equalities -> ball loop closures");
    if (ncoupler) r_.report.mapped.push_back(std::to_string(ncoupler) + " joint equalities (linear) -> couplers");
    add("equality", "equality constraints other than connect and linear joint couplings have no codyna equivalent yet "
        "(weld, tendon, a polynomial or a single joint held)", other, true);
    add("other", "inactive equality constraints (not imported)", inactive, false);
    add("soft_constraints", "MuJoCo's equality constraints are soft; codyna closes the loops exactly", soft, false);
  }

  // a joint equality between two scalar joints with a polynomial of degree 1 (a coupler)
  bool linear_joint_equality(int e) const {
    const int j1 = m_->eq_obj1id[e], j2 = m_->eq_obj2id[e];
    const mjtNum* d = m_->eq_data + mjNEQDATA * e;
    auto scalar = [&](int j) { return j >= 0 && (m_->jnt_type[j] == mjJNT_HINGE || m_->jnt_type[j] == mjJNT_SLIDE); };
    return scalar(j1) && scalar(j2) && j1 != j2 && d[1] != 0 && d[2] == 0 && d[3] == 0 && d[4] == 0;
  }

  void tendons() {
    std::vector<std::string> acting, passive;
    for (int t = 0; t < m_->ntendon; ++t) {
      const char* n = mjname(m_->name_tendonadr, t);
      const std::string label = n ? n : "tendon" + std::to_string(t);
      const bool acts = (!dis(mjDSBL_PASSIVE) && (m_->tendon_stiffness[t] != 0 || m_->tendon_damping[t] != 0)) ||
                        (!dis(mjDSBL_FRICTIONLOSS) && m_->tendon_frictionloss[t] != 0) ||
                        (!dis(mjDSBL_LIMIT) && m_->tendon_limited[t]);
      (acts ? acting : passive).push_back(label);
    }
    add("tendons", "tendons with stiffness, damping, friction or limits have no codyna equivalent", acting, true);
    add("tendons", "tendons (only their actuators and sensors would act through them)", passive, false);
  }

  void actuators() {
    ModelSpec& s = r_.spec;
    std::vector<std::string> muscles, tendon_act, other, forcerange;
    int nmotor = 0, nservo = 0;
    for (int a = 0; a < m_->nu; ++a) {
      const char* n = mjname(m_->name_actuatoradr, a);
      const std::string label = n ? n : "actuator" + std::to_string(a);
      const int trn = m_->actuator_trntype[a], dyn = m_->actuator_dyntype[a];
      const int gaint = m_->actuator_gaintype[a], biast = m_->actuator_biastype[a];
      const mjtNum* gear = m_->actuator_gear + 6 * a;
      const mjtNum* gp = m_->actuator_gainprm + mjNGAIN * a;
      const mjtNum* bp = m_->actuator_biasprm + mjNBIAS * a;
      if (dyn == mjDYN_MUSCLE || gaint == mjGAIN_MUSCLE || biast == mjBIAS_MUSCLE) { muscles.push_back(label); continue; }
      if (trn == mjTRN_TENDON) { tendon_act.push_back(label + " (tendon transmission)"); continue; }
      if (trn != mjTRN_JOINT && trn != mjTRN_JOINTINPARENT) {
        static const char* trns[] = {"joint", "joint in parent", "slider-crank", "tendon", "site", "body (adhesion)"};
        other.push_back(label + " (" + (trn >= 0 && trn <= 5 ? trns[trn] : "unknown") + " transmission)");
        continue;
      }
      if (dyn != mjDYN_NONE) { other.push_back(label + " (activation dynamics)"); continue; }
      if (gaint != mjGAIN_FIXED) { other.push_back(label + " (gain that varies with length or velocity)"); continue; }
      if (biast != mjBIAS_NONE && biast != mjBIAS_AFFINE) { other.push_back(label + " (user bias)"); continue; }
      const int jid = m_->actuator_trnid[2 * a];
      const int jt = m_->jnt_type[jid];
      ActuatorSpec act;
      act.name = actuators_.unique(label);
      act.type = ActuatorType::JointForce;
      act.joint = joint_name_[jid];
      const bool bias = biast == mjBIAS_AFFINE && (bp[0] != 0 || bp[1] != 0 || bp[2] != 0);
      if (jt == mjJNT_HINGE || jt == mjJNT_SLIDE) {
        act.gain = gp[0] * gear[0];
        if (bias) {
          // force = gain u + b0 + b1 length + b2 velocity, length = gear q: a servo is a spring-damper on
          // the coordinate beside the input
          const double g = gear[0], k = -bp[1] * g * g, c = -bp[2] * g * g;
          if (k == 0 && bp[0] != 0) { other.push_back(label + " (constant bias force)"); continue; }
          EffectSpec e;
          e.name = effects_.unique(act.name + "_servo");
          e.type = EffectType::JointSpringDamper;
          e.joint = act.joint;
          e.stiffness = k;
          e.damping = c;
          e.rest_position = k != 0 ? g * bp[0] / k : 0.0;
          s.effects.push_back(e);
          ++nservo;
        }
      } else {
        // ball: torque gear[0..2] in the body's axes; free: world force gear[0..2], body torque gear[3..5]
        const Eigen::Vector3d lin = v3(gear), ang = v3(gear + 3);
        const bool free = jt == mjJNT_FREE;
        if (bias || trn == mjTRN_JOINTINPARENT) { other.push_back(label + " (servo or parent-frame gear on a " + mj_joint_type(jt) + " joint)"); continue; }
        const Eigen::Vector3d t = free ? ang : lin;
        const Eigen::Vector3d f = free ? lin : Eigen::Vector3d::Zero();
        int nz = 0, axis = 0;
        for (int i = 0; i < 3; ++i)
          if (t[i] != 0) { ++nz; axis = i; }
        if (free && f.norm() > 0 && t.norm() == 0) {
          act.type = ActuatorType::BodyForce;
          act.body = body_name_[m_->jnt_bodyid[jid]];
          act.joint.clear();
          act.direction = f.normalized();
          act.in_world = true;
          act.gain = gp[0] * f.norm();
        } else if (f.norm() == 0 && nz == 1) {
          act.dof = axis;
          act.gain = gp[0] * t[axis];
        } else if (free && f.norm() == 0 && nz > 1) {
          act.type = ActuatorType::BodyTorque;
          act.body = body_name_[m_->jnt_bodyid[jid]];
          act.joint.clear();
          act.direction = t.normalized();
          act.in_world = false;
          act.gain = gp[0] * t.norm();
        } else {
          other.push_back(label + " (gear on several coordinates of a " + std::string(mj_joint_type(jt)) + " joint)");
          continue;
        }
      }
      std::optional<double> lo, hi;
      if (m_->actuator_ctrllimited[a] && !dis(mjDSBL_CLAMPCTRL)) {
        lo = m_->actuator_ctrlrange[2 * a];
        hi = m_->actuator_ctrlrange[2 * a + 1];
      }
      if (m_->actuator_forcelimited[a]) {
        if (!bias && gp[0] > 0) {  // force = gainprm u clamped: the same as clamping u
          const double flo = m_->actuator_forcerange[2 * a] / gp[0], fhi = m_->actuator_forcerange[2 * a + 1] / gp[0];
          lo = lo ? std::max(*lo, flo) : flo;
          hi = hi ? std::min(*hi, fhi) : fhi;
        } else {
          forcerange.push_back(label + " [" + mjcf_text(m_->actuator_forcerange[2 * a]) + ", " + mjcf_text(m_->actuator_forcerange[2 * a + 1]) + "]");
        }
      }
      act.min = lo;
      act.max = hi;
      s.actuators.push_back(act);
      ++nmotor;
    }
    if (nmotor) r_.report.mapped.push_back(std::to_string(nmotor) + " actuators -> joint_force (gain = gainprm x gear, ctrlrange -> min, max)");
    if (nservo) r_.report.mapped.push_back(std::to_string(nservo) + " servo biases (position/velocity actuators) -> joint_spring_damper beside the input");
    add("muscles", "muscle actuators have no codyna equivalent", muscles, true);
    add("tendons", "actuators that pull on tendons have no codyna equivalent", tendon_act, true);
    add("actuators", "actuators codyna cannot represent", other, true);
    add("forcerange", "force limits of servos are not modelled (they act only when saturated)", forcerange, false);
  }

  void sensors() {
    ModelSpec& s = r_.spec;
    std::vector<std::string> unmapped;
    int nmapped = 0;
    for (int i = 0; i < m_->nsensor; ++i) {
      const char* n = mjname(m_->name_sensoradr, i);
      const std::string label = n ? n : "sensor" + std::to_string(i);
      const int type = m_->sensor_type[i], obj = m_->sensor_objid[i];
      SensorSpec sn;
      if (type == mjSENS_JOINTPOS || type == mjSENS_JOINTVEL) {
        sn.name = sensors_.unique(label);
        sn.type = type == mjSENS_JOINTPOS ? SensorType::JointPosition : SensorType::JointVelocity;
        sn.joint = joint_name_[obj];
        s.sensors.push_back(sn);
        ++nmapped;
        continue;
      }
      if (type == mjSENS_FRAMEPOS && m_->sensor_refid[i] < 0) {
        const int ot = m_->sensor_objtype[i];
        int body = -1;
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        if (ot == mjOBJ_XBODY) body = obj;
        else if (ot == mjOBJ_BODY) { body = obj; p = v3(m_->body_ipos + 3 * obj); }
        else if (ot == mjOBJ_SITE) { body = m_->site_bodyid[obj]; p = v3(m_->site_pos + 3 * obj); }
        else if (ot == mjOBJ_GEOM) { body = m_->geom_bodyid[obj]; p = v3(m_->geom_pos + 3 * obj); }
        if (body > 0) {
          for (int c = 0; c < 3; ++c) {
            sn.name = sensors_.unique(label + "." + "xyz"[c]);
            sn.type = SensorType::PointPosition;
            sn.body = body_name_[body];
            sn.point = p;
            sn.component = c;
            s.sensors.push_back(sn);
          }
          ++nmapped;
          continue;
        }
      }
      static const std::map<int, const char*> kinds = {
          {mjSENS_TOUCH, "touch"}, {mjSENS_ACCELEROMETER, "accelerometer"}, {mjSENS_VELOCIMETER, "velocimeter"},
          {mjSENS_GYRO, "gyro"}, {mjSENS_FORCE, "force"}, {mjSENS_TORQUE, "torque"}, {mjSENS_FRAMEPOS, "framepos"},
          {mjSENS_FRAMEQUAT, "framequat"}, {mjSENS_ACTUATORFRC, "actuatorfrc"}, {mjSENS_TENDONPOS, "tendonpos"},
          {mjSENS_BALLQUAT, "ballquat"}, {mjSENS_SUBTREECOM, "subtreecom"}};
      const auto k = kinds.find(type);
      unmapped.push_back(label + " (" + (k != kinds.end() ? k->second : "type " + std::to_string(type)) + ")");
    }
    if (nmapped) r_.report.mapped.push_back(std::to_string(nmapped) + " sensors (jointpos, jointvel, framepos in world axes) -> joint_position, joint_velocity, point_position x/y/z");
    add("sensors", "sensors with no codyna equivalent (not imported; outputs only, the dynamics is unchanged)", unmapped, false);
  }

  void contacts_and_other() {
    std::vector<std::string> colliding;
    if (!dis(mjDSBL_CONTACT)) {
      for (int g = 0; g < m_->ngeom; ++g)
        if (m_->geom_contype[g] || m_->geom_conaffinity[g]) colliding.push_back(geom_label(g));
      for (int p = 0; p < m_->npair; ++p) colliding.push_back("pair " + std::to_string(p));
    }
    add("contacts", "contacts are not modelled: codyna's dynamics is the contact-free one (what a linearization "
        "uses); collision geoms are display shapes", colliding, false);
    for (int g = m_->body_geomadr[0]; g >= 0 && g < m_->body_geomadr[0] + m_->body_geomnum[0]; ++g)
      world_geoms_.push_back(geom_label(g));
    add("shapes", "geoms of the world body are not shown (codyna's ground has no shapes)", world_geoms_, false);
    add("shapes", "shown as boxes", approx_shapes_, false);
    add("shapes", "not shown", hidden_shapes_, false);
    std::vector<std::string> other;
    if (m_->nsite) other.push_back(std::to_string(m_->nsite) + " sites");
    if (m_->ncam) other.push_back(std::to_string(m_->ncam) + " cameras");
    if (m_->nlight) other.push_back(std::to_string(m_->nlight) + " lights");
    if (m_->nkey) other.push_back(std::to_string(m_->nkey) + " keyframes (q0 is qpos0)");
    if (m_->nskin) other.push_back(std::to_string(m_->nskin) + " skins");
    add("other", "elements without effect on the dynamics, not imported", other, false);
  }

  void plant() {
    ModelSpec& s = r_.spec;
    for (const ActuatorSpec& a : s.actuators) s.plant.inputs.push_back(a.name);
    // every joint coordinate as Plant/Out: the file's jointpos sensor where there is one
    std::map<std::string, std::string> jointpos;
    for (const SensorSpec& sn : s.sensors)
      if (sn.type == SensorType::JointPosition && !jointpos.count(sn.joint)) jointpos[sn.joint] = sn.name;
    int added = 0;
    for (const JointSpec& j : s.joints) {
      if (j.type == JointType::Revolute || j.type == JointType::Prismatic) {
        if (!jointpos.count(j.name)) {
          SensorSpec sn;
          sn.name = sensors_.unique(j.name);
          sn.type = SensorType::JointPosition;
          sn.joint = j.name;
          s.sensors.push_back(sn);
          jointpos[j.name] = sn.name;
          ++added;
        }
        s.plant.outputs.push_back(jointpos[j.name]);
      } else if (j.type == JointType::Free) {
        for (int c = 0; c < 3; ++c) {
          SensorSpec sn;
          sn.name = sensors_.unique(j.name + "." + "xyz"[c]);
          sn.type = SensorType::PointPosition;
          sn.body = j.child;
          sn.component = c;
          s.sensors.push_back(sn);
          s.plant.outputs.push_back(sn.name);
        }
        for (int c = 0; c < 3; ++c) {
          SensorSpec sn;
          sn.name = sensors_.unique(j.name + ".r" + "xyz"[c]);
          sn.type = SensorType::BodyAngle;
          sn.body = j.child;
          sn.axis = Eigen::Vector3d::Unit(c);
          s.sensors.push_back(sn);
          s.plant.outputs.push_back(sn.name);
        }
        added += 6;
      }
    }
    if (added) r_.report.mapped.push_back(std::to_string(added) + " sensors added for the joint coordinates (a free joint: its position and body angles)");
    r_.report.mapped.push_back("plant: every actuator as Plant/In (" + std::to_string(s.plant.inputs.size()) +
                               "), every joint coordinate as Plant/Out (" + std::to_string(s.plant.outputs.size()) + ")");
  }

  void describe() {
    ModelSpec& s = r_.spec;
    std::string types;
    for (const auto& [t, n] : joint_types_) types += (types.empty() ? "" : ", ") + std::to_string(n) + " " + t;
    auto& mp = r_.report.mapped;
    mp.insert(mp.begin(),
              std::to_string(m_->nbody - 1) + " bodies (mass, centre of mass, inertia as MuJoCo compiled them)" +
                  (nframes_ ? " + " + std::to_string(nframes_) + " massless frames (bodies with several joints)" : "") +
                  (nwelds_ ? ", " + std::to_string(nwelds_) + " welded by fixed joints" : ""));
    mp.insert(mp.begin() + 1, std::to_string(m_->njnt) + " joints (" + types + ") -> revolute, prismatic, spherical, free; q0 = qpos0");
    mp.insert(mp.begin() + 2, std::to_string(nshapes_) + " display shapes from geoms (capsule = cylinder + 2 spheres)");
    s.description = "Imported from " + std::filesystem::path(path_).filename().string() + " (MJCF, " + mjcf_reader_version() + ") by codyna import.";
    if (!limits_.empty()) {
      s.description += " Joint limits (not modelled):";
      for (const std::string& l : limits_) s.description += " " + l + ";";
      s.description.back() = '.';
    }
  }
};

}  // namespace

ImportResult import_mjcf(const std::string& path, const ImportOptions& options) {
  check_import_options(options);
  ImportReport empty;
  empty.source = path;
  empty.format = "MJCF";
  empty.reader = mjcf_reader_version();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ImportRefused(path + ": cannot open file: " + (std::filesystem::exists(path, ec) ? "not a regular file" : "No such file or directory"), empty);
  std::vector<std::string> warnings;
  g_warnings = &warnings;
  auto* old = mju_user_warning;
  mju_user_warning = collect_warning;
  char err[1024] = "";
  std::unique_ptr<mjModel, ModelDeleter> m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  mju_user_warning = old;
  g_warnings = nullptr;
  if (!m) throw ImportRefused(path + ": MuJoCo cannot read it: " + std::string(err), empty);
  ImportResult r = MjcfImporter(m.get(), path, options).run();
  if (err[0]) r.spec.notes.push_back(path + ": MuJoCo: " + err);
  for (const std::string& w : warnings) r.spec.notes.push_back(path + ": MuJoCo: " + w);
  return r;
}

#endif

}  // namespace codyna
