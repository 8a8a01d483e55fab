#include "model/compile.hpp"

#include <initializer_list>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "vehicle/magic_formula_relaxation.hpp"
#include "vehicle/road.hpp"
#include "vehicle/tir_file.hpp"


namespace codyna {

namespace {

std::string quote(const std::string& s) { return "\"" + s + "\""; }

std::string compile_number(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < 12; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > 12) s += ", ...";
  return s.empty() ? "(none)" : s;
}

Eigen::Vector3d perpendicular(const Eigen::Vector3d& a) {
  const Eigen::Vector3d t = std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return a.cross(t).normalized();
}

bool is_angular(JointType t, int dof) {
  switch (t) {
    case JointType::Revolute: case JointType::Spherical: case JointType::Universal: return true;
    case JointType::Cylindrical: return dof == 0;
    case JointType::Planar: return dof == 2;
    case JointType::Free: return dof < 3;
    default: return false;
  }
}

bool has_scalar_positions(JointType t) { return t != JointType::Spherical && t != JointType::Free; }

class Compiler {
 public:
  Compiler(const ModelSpec& spec, std::string file) : spec_(spec), file_(std::move(file)) {}

  Model run() {
    m_.name = spec_.name;
    m_.spec = spec_;
    m_.source_file = file_;
    if (spec_.name.empty()) fail("/name", "expected a non-empty model name");
    check_names();
    check_bodies();
    build_tree();
    build_constraints();
    build_effects();
    build_actuators();
    build_sensors();
    build_plant();
    check_solver();
    initial_state();
    return std::move(m_);
  }

  // compile_numbers
  Model renumber(const Model& structure, NumbersChanged what) {
    // the spec's elements, counted against the structure's
    const auto same_count = [](std::size_t in_spec, std::size_t in_structure, const char* what) {
      if (in_spec != in_structure)
        throw std::invalid_argument("compile_numbers: the spec has " + std::to_string(in_spec) + " " + what +
                                    ", the structure " + std::to_string(in_structure));
    };
    same_count(spec_.bodies.size(),
               static_cast<std::size_t>(std::count_if(structure.body_spec_index.begin(), structure.body_spec_index.end(),
                                                      [](int bs) { return bs >= 0; })),
               "bodies");
    m_ = structure;
    m_.spec = spec_;
    if (what.bodies) {
      check_bodies();
      for (int b = 1; b < m_.nbodies; ++b) set_body_numbers(b, spec_.bodies[static_cast<std::size_t>(m_.body_spec_index[b])]);
    }
    if (what.effects || what.actuators || what.sensors)
      for (int b = 0; b < m_.nbodies; ++b) compiled_[m_.body_names[static_cast<std::size_t>(b)]] = b;
    if (what.effects) {
      const Model blank;
      m_.has_gravity = blank.has_gravity;
      m_.gravity = blank.gravity;
      m_.springs.clear();
      m_.joint_springs.clear();
      m_.joint_frictions.clear();
      m_.body_forces.clear();
      m_.bushings.clear();
      m_.tires.clear();
      build_effects();
    }
    // in the structure's order, under the same names: the plant's inputs and outputs, the motions
    // and the sensors of motion forces find the same indices
    if (what.actuators) {
      same_count(spec_.actuators.size(), structure.actuators.size(), "actuators");
      m_.actuators.clear();
      m_.motions.clear();
      build_actuators();
    }
    if (what.sensors) {
      same_count(spec_.sensors.size(), structure.sensors.size(), "sensors");
      m_.sensors.clear();
      build_sensors();
    }
    if (what.initial) {
      same_count(spec_.joints.size(), structure.joints.size() - 1, "joints");
      for (std::size_t k = 0; k < spec_.joints.size(); ++k) check_initial_values(spec_.joints[k], at("joints", k));
      initial_state();  // q0, v0, the motions' nominal values, the couplers' offsets: all made again
    }
    return std::move(m_);
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& what) const { throw ModelError(file_, path, what); }

  static std::string at(const char* list, std::size_t i) { return "/" + std::string(list) + "/" + std::to_string(i); }

  template <class T>
  void unique_names(const std::vector<T>& items, const char* list, const char* what) {
    std::map<std::string, std::size_t> seen;
    for (std::size_t i = 0; i < items.size(); ++i) {
      const std::string& n = items[i].name;
      if (n.empty()) fail(at(list, i) + "/name", std::string("expected a non-empty ") + what + " name");
      auto [it, fresh] = seen.emplace(n, i);
      if (!fresh) fail(at(list, i) + "/name", std::string("duplicate ") + what + " name " + quote(n) + " (also " + at(list, it->second) + ")");
    }
  }

  void check_names() {
    unique_names(spec_.bodies, "bodies", "body");
    unique_names(spec_.joints, "joints", "joint");
    unique_names(spec_.constraints, "constraints", "constraint");
    unique_names(spec_.effects, "effects", "effect");
    unique_names(spec_.actuators, "actuators", "actuator");
    unique_names(spec_.sensors, "sensors", "sensor");
    unique_names(spec_.roads, "roads", "road");
    for (std::size_t i = 0; i < spec_.bodies.size(); ++i)
      if (spec_.bodies[i].name == kGroundName) fail(at("bodies", i) + "/name", "\"ground\" is reserved for the fixed world body");
  }

  void check_bodies() {
    // masses and inertias far below the model's own scale are typing slips (or denormals), not physics
    double heaviest = 0, largest_moment = 0;
    for (const BodySpec& b : spec_.bodies) {
      if (std::isfinite(b.mass)) heaviest = std::max(heaviest, b.mass);
      if (b.inertia.allFinite()) largest_moment = std::max(largest_moment, b.inertia.diagonal().cwiseAbs().maxCoeff());
    }
    for (std::size_t i = 0; i < spec_.bodies.size(); ++i) {
      const BodySpec& b = spec_.bodies[i];
      const std::string p = at("bodies", i);
      if (b.mass > 0 && b.mass < std::max(1e-12 * heaviest, 1e-30))
        fail(p + "/mass", "a mass of " + compile_number(b.mass) + " kg is absurdly small beside the heaviest body (" + compile_number(heaviest) +
                              " kg): give it a real mass, or 0 for a massless link");
      if (b.mass > 0 && b.inertia.allFinite() && b.inertia.diagonal().cwiseAbs().maxCoeff() < std::max(1e-15 * largest_moment, 1e-40))
        fail(p + "/inertia", "principal moments this small (" + compile_number(b.inertia.diagonal().maxCoeff()) +
                                 " kg m^2) beside the model's largest (" + compile_number(largest_moment) + ") are not a rigid body's");
    }
    for (std::size_t i = 0; i < spec_.bodies.size(); ++i) {
      const BodySpec& b = spec_.bodies[i];
      const std::string p = at("bodies", i);
      if (!std::isfinite(b.mass) || b.mass < 0) fail(p + "/mass", "expected a non-negative mass in kg, got " + compile_number(b.mass));
      if (!b.com.allFinite()) fail(p + "/com", "expected finite coordinates");
      const Eigen::Matrix3d& I = b.inertia;
      if (!I.allFinite()) fail(p + "/inertia", "expected finite entries");
      if ((I - I.transpose()).norm() > 1e-9 * std::max(1.0, I.norm())) fail(p + "/inertia", "expected a symmetric inertia matrix");
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I);
      const Eigen::Vector3d ev = es.eigenvalues();  // ascending
      const double scale = std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
      // positive semi-definite is accepted (a slender rod has no moment about its own
      // axis); whether the mass matrix stays positive definite is checked on the
      // assembled tree (check_mass_matrix), which names the coordinate that moves nothing
      if (ev[0] < -1e-12 * scale)
        fail(p + "/inertia", "expected a positive semi-definite inertia matrix, got principal moments " + compile_number(ev[0]) + ", " +
                                 compile_number(ev[1]) + ", " + compile_number(ev[2]));
      if (ev[0] + ev[1] < ev[2] * (1 - 1e-9))
        fail(p + "/inertia", "principal moments " + compile_number(ev[0]) + ", " + compile_number(ev[1]) + ", " + compile_number(ev[2]) +
                                 " violate the triangle inequality (I1 + I2 >= I3): no rigid body has them");
      body_index_spec_[b.name] = static_cast<int>(i);
    }
  }

  // body name -> compiled index (after build_tree); ground -> 0
  int body(const std::string& name, const std::string& path, bool allow_ground = true) const {
    if (name == kGroundName) {
      if (!allow_ground) fail(path, "expected a moving body, got \"ground\"");
      return 0;
    }
    auto it = compiled_.find(name);
    if (it == compiled_.end()) {
      std::vector<std::string> names{kGroundName};
      for (const auto& b : spec_.bodies) names.push_back(b.name);
      fail(path, "unknown body " + quote(name) + " (bodies: " + join_names(names) + ")");
    }
    return it->second;
  }

  // joint name -> compiled body index of the joint
  int joint(const std::string& name, const std::string& path) const {
    const int j = m_.find_joint(name);
    if (j < 0) {
      std::vector<std::string> names;
      for (const auto& s : spec_.joints) names.push_back(s.name);
      fail(path, "unknown joint " + quote(name) + " (joints: " + join_names(names) + ")");
    }
    return j;
  }

  void check_dof(int jb, int dof, const std::string& path) const {
    const JointModel& j = m_.joints[jb];
    if (dof < 0 || dof >= j.nv)
      fail(path, "expected a coordinate index from 0 to " + std::to_string(j.nv - 1) + " of " + to_string(j.type) +
                     " joint " + quote(j.name) + ", got " + std::to_string(dof));
  }

  static Eigen::Vector3d unit(const Eigen::Vector3d& a, const std::string& path, const Compiler& c) {
    if (!a.allFinite() || a.norm() < 1e-12) c.fail(path, "expected a non-zero direction");
    return a.normalized();
  }

  // a joint's q0 and v0 as given (compile_numbers checks them again)
  void check_initial_values(const JointSpec& j, const std::string& p) const {
    if (j.q0.size() != 0 && j.q0.size() != joint_nq(j.type))
      fail(p + "/q0", "expected " + std::to_string(joint_nq(j.type)) + " values for a " + to_string(j.type) + " joint, got " + std::to_string(j.q0.size()));
    if (j.v0.size() != 0 && j.v0.size() != joint_nv(j.type))
      fail(p + "/v0", "expected " + std::to_string(joint_nv(j.type)) + " values for a " + to_string(j.type) + " joint, got " + std::to_string(j.v0.size()));
    if ((j.q0.size() && !j.q0.allFinite()) || (j.v0.size() && !j.v0.allFinite())) fail(p, "expected finite q0 and v0");
  }

  // the numbers of model body b (compile_numbers sets them again)
  void set_body_numbers(int b, const BodySpec& s) {
    const auto i = static_cast<std::size_t>(b);
    m_.mass[i] = s.mass;
    m_.com[i] = s.com;
    m_.inertia[i] = spatial_inertia(s.mass, s.com, s.inertia);
  }

  void build_tree() {
    const auto& joints = spec_.joints;
    std::map<std::string, std::size_t> child_of;  // body -> joint spec index
    for (std::size_t k = 0; k < joints.size(); ++k) {
      const JointSpec& j = joints[k];
      const std::string p = at("joints", k);
      if (j.parent != kGroundName && !body_index_spec_.count(j.parent)) {
        std::vector<std::string> names{kGroundName};
        for (const auto& b : spec_.bodies) names.push_back(b.name);
        fail(p + "/parent", "unknown body " + quote(j.parent) + " (bodies: " + join_names(names) + ")");
      }
      if (j.child == kGroundName) fail(p + "/child", "the ground cannot be a joint's child");
      if (!body_index_spec_.count(j.child)) fail(p + "/child", "unknown body " + quote(j.child));
      if (j.child == j.parent) fail(p + "/child", "a joint cannot connect body " + quote(j.child) + " to itself");
      auto [it, fresh] = child_of.emplace(j.child, k);
      if (!fresh)
        fail(p + "/child", "body " + quote(j.child) + " is already moved by joint " + quote(joints[it->second].name) +
                               "; close kinematic loops with a constraint");
      check_initial_values(j, p);
      if (j.armature.size() != 0) {
        const int nv = joint_nv(j.type);
        if (nv == 0) fail(p + "/armature", "a fixed joint has no coordinate to carry an armature (rotor inertia)");
        if (j.armature.size() != 1 && j.armature.size() != nv)
          fail(p + "/armature", "expected one number (every coordinate) or " + std::to_string(nv) + " numbers (one per coordinate of a " +
                                    to_string(j.type) + " joint), got " + std::to_string(j.armature.size()));
        for (Eigen::Index k = 0; k < j.armature.size(); ++k)
          if (!(std::isfinite(j.armature[k]) && j.armature[k] >= 0))
            fail(p + "/armature" + (j.armature.size() > 1 ? "/" + std::to_string(k) : std::string()),
                 "expected a number >= 0 (rotor inertia: kg m^2 on a rotation, kg on a translation)");
      }
    }
    for (std::size_t i = 0; i < spec_.bodies.size(); ++i)
      if (!child_of.count(spec_.bodies[i].name))
        fail(at("bodies", i), unattached_body_detail(spec_.bodies[i].name));

    // stable topological order: a joint is placed once its parent is placed
    std::vector<std::size_t> order;
    std::set<std::string> placed{kGroundName};
    std::vector<bool> done(joints.size(), false);
    for (bool progress = true; progress;) {
      progress = false;
      for (std::size_t k = 0; k < joints.size(); ++k)
        if (!done[k] && placed.count(joints[k].parent)) {
          done[k] = progress = true;
          placed.insert(joints[k].child);
          order.push_back(k);
        }
    }
    for (std::size_t k = 0; k < joints.size(); ++k)
      if (!done[k]) {
        // every body has one parent joint, so an unplaced joint lies on (or hangs from) a cycle
        std::string chain = joints[k].child;
        std::string b = joints[k].parent;
        std::set<std::string> seen{joints[k].child};
        while (!seen.count(b)) {
          chain = b + " -> " + chain;
          seen.insert(b);
          b = joints[child_of.at(b)].parent;
        }
        chain = b + " -> " + chain;
        fail(at("joints", k), "the joints form a cycle (" + chain + "); a tree must hang from \"ground\": cut one joint of the loop and close it with a constraint");
      }

    m_.nbodies = static_cast<int>(order.size()) + 1;
    m_.body_names = {kGroundName};
    m_.parent = {-1};
    m_.joints.assign(1, JointModel{});
    m_.mass = {0.0};
    m_.com = {Eigen::Vector3d::Zero()};
    m_.inertia = {Mat6T<double>::Zero()};
    m_.body_spec_index = {-1};
    compiled_[kGroundName] = 0;
    int iq = 0, iv = 0;
    std::vector<double> armature;  // [nv] as the joints give it
    for (std::size_t k : order) {
      const JointSpec& js = joints[k];
      const std::string p = at("joints", k);
      const int bs = body_index_spec_.at(js.child);
      const BodySpec& b = spec_.bodies[bs];
      const int index = static_cast<int>(m_.body_names.size());
      compiled_[b.name] = index;
      JointModel j;
      j.name = js.name;
      j.type = js.type;
      j.parent = compiled_.at(js.parent);
      j.nq = joint_nq(js.type);
      j.nv = joint_nv(js.type);
      j.idx_q = iq;
      j.idx_v = iv;
      j.X_PF = SE3(js.parent_frame.rotation, js.parent_frame.position);
      j.X_CM = SE3(js.child_frame.rotation, js.child_frame.position);
      j.axis = unit(js.axis, p + "/axis", *this);
      j.axis2 = unit(js.axis2, p + "/axis2", *this);
      if (js.type == JointType::Universal && j.axis.cross(j.axis2).norm() < 1e-6)
        fail(p + "/axis2", "expected a second axis not parallel to the first");
      j.spec_index = static_cast<int>(k);
      for (const FrameSpec* f : {&js.parent_frame, &js.child_frame}) {
        const Eigen::Matrix3d& R = f->rotation;
        if (!R.allFinite() || !f->position.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-9 || R.determinant() < 0)
          fail(p + (f == &js.parent_frame ? "/parent_frame" : "/child_frame"), "expected a finite position and a proper rotation");
      }
      add_coordinate_names(j);
      for (int c = 0; c < j.nv; ++c)
        armature.push_back(js.armature.size() == 0 ? 0.0 : js.armature[js.armature.size() == 1 ? 0 : c]);
      iq += j.nq;
      iv += j.nv;
      m_.body_names.push_back(b.name);
      m_.parent.push_back(j.parent);
      m_.joints.push_back(j);
      m_.mass.emplace_back();
      m_.com.emplace_back();
      m_.inertia.emplace_back();
      set_body_numbers(index, b);
      m_.body_spec_index.push_back(bs);
    }
    m_.nq = iq;
    m_.nv = iv;
    m_.armature.resize(0);  // empty without any rotor inertia: the algorithms then add nothing
    if (std::any_of(armature.begin(), armature.end(), [](double a) { return a != 0; }))
      m_.armature = Eigen::Map<const Eigen::VectorXd>(armature.data(), iv);
  }

  void add_coordinate_names(const JointModel& j) {
    // see Model::v_names: one scheme for coordinates and rates of every joint type
    std::vector<std::string> qs, vs, rs;
    switch (j.type) {
      case JointType::Revolute: case JointType::Prismatic: qs = vs = {""}; break;
      case JointType::Fixed: break;
      case JointType::Spherical:
        qs = {"qw", "qx", "qy", "qz"};
        vs = {"rx", "ry", "rz"};
        rs = {"wx", "wy", "wz"};
        break;
      case JointType::Universal: qs = vs = {"1", "2"}; break;
      case JointType::Cylindrical: qs = vs = {"angle", "slide"}; break;
      case JointType::Planar: qs = vs = {"x", "y", "angle"}; break;
      case JointType::Free:
        qs = {"x", "y", "z", "qw", "qx", "qy", "qz"};
        vs = {"rx", "ry", "rz", "x", "y", "z"};
        rs = {"wx", "wy", "wz", "vx", "vy", "vz"};
        break;
    }
    const auto named = [&](const std::string& s) { return s.empty() ? j.name : j.name + "." + s; };
    for (const auto& s : qs) m_.q_names.push_back(named(s));
    for (std::size_t k = 0; k < vs.size(); ++k) {
      m_.v_names.push_back(named(vs[k]));
      m_.rate_names.push_back(rs.empty() ? named(vs[k]) + "_dot" : named(rs[k]));
      m_.v_units.push_back(is_angular(j.type, static_cast<int>(k)) ? "rad" : "m");
    }
  }

  void build_constraints() {
    int row = 0;
    for (std::size_t k = 0; k < spec_.constraints.size(); ++k) {
      const ConstraintSpec& cs = spec_.constraints[k];
      const std::string p = at("constraints", k);
      ConstraintModel c;
      c.name = cs.name;
      c.type = cs.type;
      if (cs.type == ConstraintType::Coupler) {
        coupler(cs, p, c);
        c.row = row;
        c.nrows = 1;
        m_.row_names.push_back(c.name);
        row += 1;
        m_.constraints.push_back(c);
        continue;
      }
      c.body_a = body(cs.body_a, p + "/body_a");
      c.body_b = body(cs.body_b, p + "/body_b");
      if (c.body_a == c.body_b) fail(p + "/body_b", "expected two different bodies");
      if (!cs.point_a.allFinite()) fail(p + "/point_a", "expected finite coordinates");
      if (!cs.point_b.allFinite()) fail(p + "/point_b", "expected finite coordinates");
      c.point_a = cs.point_a;
      c.point_b = cs.point_b;
      c.axis_a = unit(cs.axis_a, p + "/axis_a", *this);
      const Eigen::Vector3d axis_b = unit(cs.axis_b, p + "/axis_b", *this);
      c.perp_a1 = perpendicular(c.axis_a);
      c.perp_a2 = c.axis_a.cross(c.perp_a1);
      c.perp_b1 = perpendicular(axis_b);
      c.perp_b2 = axis_b.cross(c.perp_b1);
      c.row = row;
      std::vector<std::string> rows;
      if (c.type == ConstraintType::RollingBall || c.type == ConstraintType::RollingDisc) {
        if (!std::isfinite(cs.radius) || cs.radius <= 0)
          fail(p + "/radius", "expected a positive radius (m), got " + compile_number(cs.radius));
        c.radius = cs.radius;
        c.axis_b = axis_b;  // rolling_disc: the axle
        // height on q; no slip along the plane's two directions, on v only
        rows = {"height", "slip_u", "slip_v"};
        m_.velocity_rows.push_back(row + 1);
        m_.velocity_rows.push_back(row + 2);
      } else if (c.type == ConstraintType::PlanarRevolute) rows = {"u", "v"};
      else rows = {"x", "y", "z"};
      if (c.type == ConstraintType::Revolute) rows.insert(rows.end(), {"axis1", "axis2"});
      c.nrows = static_cast<int>(rows.size());
      for (const auto& r : rows) m_.row_names.push_back(c.name + "." + r);
      row += c.nrows;
      m_.constraints.push_back(c);
    }
    m_.nc = row;
  }

  // a coupler's joints: scalar coordinates (revolute, prismatic), two or three different ones,
  // finite ratios, at least two of them non-zero
  void coupler(const ConstraintSpec& cs, const std::string& p, ConstraintModel& c) {
    const std::string* names[3] = {&cs.joint_a, &cs.joint_b, &cs.joint_c};
    const double ratios[3] = {cs.ratio_a, cs.ratio_b, cs.ratio_c};
    const char* keys[3] = {"joint_a", "joint_b", "joint_c"};
    const char* ratio_keys[3] = {"ratio_a", "ratio_b", "ratio_c"};
    int nonzero = 0;
    for (int k = 0; k < 3; ++k) {
      if (k == 2 && names[k]->empty()) {
        if (ratios[k] != 0) fail(p + "/ratio_c", "a ratio_c needs a joint_c (or leave ratio_c at 0)");
        break;
      }
      const int jb = joint(*names[k], p + "/" + keys[k]);
      const JointModel& j = m_.joints[jb];
      if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
        fail(p + "/" + keys[k], "a coupler relates scalar coordinates; " + quote(j.name) + " is " + to_string(j.type) +
                                    " (expected a revolute or prismatic joint)");
      for (int i = 0; i < c.ncoupled; ++i)
        if (c.iv[i] == j.idx_v) fail(p + "/" + keys[k], quote(j.name) + " is coupled to itself (expected different joints)");
      if (!std::isfinite(ratios[k])) fail(p + "/" + ratio_keys[k], "expected a finite ratio");
      if (ratios[k] != 0) ++nonzero;
      c.iq[c.ncoupled] = j.idx_q;
      c.iv[c.ncoupled] = j.idx_v;
      c.ratio[c.ncoupled] = ratios[k];
      if (k == 0) c.body_a = jb;
      if (k == 1) c.body_b = jb;
      ++c.ncoupled;
    }
    if (nonzero < 2) fail(p + "/ratio_b", "a coupler needs at least two non-zero ratios (it would hold a joint still)");
    if (cs.offset && !std::isfinite(*cs.offset)) fail(p + "/offset", "expected a finite number (or leave it out)");
    c.offset_given = cs.offset.has_value();
    c.offset = cs.offset.value_or(0.0);
  }

  void non_negative(double x, const std::string& path, const char* what) const {
    if (!std::isfinite(x) || x < 0) fail(path, std::string("expected a non-negative ") + what + ", got " + compile_number(x));
  }

  void build_effects() {
    bool gravity_seen = false;
    for (std::size_t k = 0; k < spec_.effects.size(); ++k) {
      const EffectSpec& e = spec_.effects[k];
      const std::string p = at("effects", k);
      switch (e.type) {
        case EffectType::Gravity:
          if (gravity_seen) fail(p, "gravity is declared twice");
          if (!e.g.allFinite()) fail(p + "/g", "expected finite components");
          gravity_seen = true;
          m_.has_gravity = true;
          m_.gravity = e.g;
          break;
        case EffectType::SpringDamper: {
          SpringDamperModel s;
          s.name = e.name;
          s.body_a = body(e.body_a, p + "/body_a");
          s.body_b = body(e.body_b, p + "/body_b");
          if (s.body_a == s.body_b) fail(p + "/body_b", "expected two different bodies");
          s.point_a = e.point_a;
          s.point_b = e.point_b;
          non_negative(e.stiffness, p + "/stiffness", "stiffness");
          non_negative(e.damping, p + "/damping", "damping");
          non_negative(e.rest_length, p + "/rest_length", "rest length");
          s.stiffness = e.stiffness;
          s.damping = e.damping;
          s.rest_length = e.rest_length;
          m_.springs.push_back(s);
          break;
        }
        case EffectType::JointSpringDamper:
        case EffectType::JointFriction: {
          const int jb = joint(e.joint, p + "/joint");
          check_dof(jb, e.dof, p + "/dof");
          const JointModel& j = m_.joints[jb];
          JointSpringModel s;
          s.name = e.name;
          s.iv = j.idx_v + e.dof;
          s.iq = j.idx_q + e.dof;
          non_negative(e.damping, p + "/damping", "damping");
          s.damping = e.damping;
          if (e.type == EffectType::JointFriction) {
            m_.joint_frictions.push_back(s);
            break;
          }
          if (!has_scalar_positions(j.type))
            fail(p + "/joint", "a joint_spring_damper needs a joint with scalar coordinates; " + quote(j.name) + " is " + to_string(j.type));
          non_negative(e.stiffness, p + "/stiffness", "stiffness");
          if (!std::isfinite(e.rest_position)) fail(p + "/rest_position", "expected a finite number");
          s.stiffness = e.stiffness;
          s.rest_position = e.rest_position;
          m_.joint_springs.push_back(s);
          break;
        }
        case EffectType::BodyForce: {
          BodyForceModel b;
          b.name = e.name;
          b.body = body(e.body_a, p + "/body", false);
          if (!e.force.allFinite()) fail(p + "/force", "expected finite components");
          if (!e.torque.allFinite()) fail(p + "/torque", "expected finite components");
          b.point = e.point_a;
          b.force = e.force;
          b.torque = e.torque;
          b.in_world = e.in_world;
          m_.body_forces.push_back(b);
          break;
        }
        case EffectType::Bushing: {
          BushingModel b;
          b.name = e.name;
          b.body_a = body(e.body_a, p + "/body_a");
          b.body_b = body(e.body_b, p + "/body_b");
          if (b.body_a == b.body_b) fail(p + "/body_b", "expected two different bodies");
          for (const auto& [f, key] : {std::pair{&e.frame_a, "/frame_a"}, std::pair{&e.frame_b, "/frame_b"}}) {
            const Eigen::Matrix3d& R = f->rotation;
            if (!R.allFinite() || !f->position.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
                R.determinant() < 0)
              fail(p + key, "expected a finite position and a proper rotation");
          }
          b.X_a = SE3(e.frame_a.rotation, e.frame_a.position);
          b.X_b = SE3(e.frame_b.rotation, e.frame_b.position);
          const std::pair<const Eigen::Vector3d*, const char*> values[] = {
              {&e.translational_stiffness, "/translational_stiffness"}, {&e.translational_damping, "/translational_damping"},
              {&e.rotational_stiffness, "/rotational_stiffness"}, {&e.rotational_damping, "/rotational_damping"}};
          for (const auto& [v, key] : values)
            if (!v->allFinite() || v->minCoeff() < 0) fail(p + key, "expected three non-negative numbers (x, y, z of the bushing's axes)");
          b.kt = e.translational_stiffness;
          b.ct = e.translational_damping;
          b.kr = e.rotational_stiffness;
          b.cr = e.rotational_damping;
          m_.bushings.push_back(b);
          break;
        }
        case EffectType::Tire:
          m_.tires.push_back(build_tire(e, p));
          add_tire_states(m_.tires.back());
          break;
        case EffectType::JointDamper: {
          // one damping value on every velocity coordinate of the joint: -damping * v
          // (for a spherical joint an isotropic viscous torque -damping * omega)
          const int jb = joint(e.joint, p + "/joint");
          const JointModel& j = m_.joints[jb];
          if (j.nv == 0) fail(p + "/joint", "joint " + quote(j.name) + " is fixed: it has no coordinate to damp");
          non_negative(e.damping, p + "/damping", "damping");
          for (int k = 0; k < j.nv; ++k) {
            JointSpringModel s;
            s.name = e.name;
            s.iv = j.idx_v + k;
            s.iq = j.idx_q;  // not read: a damper acts on velocities only
            s.damping = e.damping;
            m_.joint_frictions.push_back(s);
          }
          break;
        }
      }
    }
  }

  // a tire effect: the wheel, the road, the law's numbers (a .tir file read relative to the model file)
  TireModel build_tire(const EffectSpec& e, const std::string& p) const {
    TireModel t;
    t.name = e.name;
    t.body = body(e.body_a, p + "/body", false);
    t.road_body = body(e.road.body, p + "/road/body");
    if (t.road_body == t.body) fail(p + "/road/body", "expected a road on another body than the wheel");
    if (!e.center.allFinite()) fail(p + "/center", "expected finite components");
    t.center = e.center;
    const double axis_length = e.spin_axis.norm();
    if (!std::isfinite(axis_length) || !(axis_length > 0))
      fail(p + "/spin_axis", "expected a non-zero spin axis (the wheel's axle, wheel body coordinates)");
    t.axis = e.spin_axis / axis_length;
    const double normal_length = e.road.normal.norm();
    if (!std::isfinite(normal_length) || !(normal_length > 0)) fail(p + "/road/normal", "expected a non-zero road normal");
    if (!e.road.point.allFinite()) fail(p + "/road/point", "expected finite components");
    t.road_point = e.road.point;
    t.road_normal = e.road.normal / normal_length;
    const auto positive = [&](double x, const std::string& key, const char* what) {
      if (!std::isfinite(x) || !(x > 0)) fail(p + key, std::string("expected a positive ") + what + ", got " + compile_number(x));
    };
    const auto given_by_file = [&](const std::optional<double>& field, const std::string& key, const char* tir_key) {
      if (field) fail(p + key, std::string("given by the .tir file (") + tir_key + "); leave the field out");
    };
    if (!std::isfinite(e.low_speed) || !(e.low_speed > 0)) fail(p + "/low_speed", "expected a positive speed (m/s), got " + compile_number(e.low_speed));
    t.low_speed = e.low_speed;
    if (e.law == "magic_formula") {
      t.law = TireLaw::MagicFormula;
      if (e.file.empty()) fail(p + "/file", "expected the .tir file of the magic_formula law");
      std::filesystem::path path(e.file);
      if (path.is_relative() && !file_.empty()) path = std::filesystem::path(file_).parent_path() / path;
      try {
        t.mf = std::make_shared<const MagicFormulaParameters>(read_tir_file(path.string()));
      } catch (const std::exception& x) {
        fail(p + "/file", x.what());
      }
      if (e.side == "left") t.side = 1;
      else if (e.side == "right") t.side = 2;
      else if (!e.side.empty()) fail(p + "/side", "unknown side " + quote(e.side) + " (expected one of: left, right)");
      given_by_file(e.unloaded_radius, "/unloaded_radius", "[DIMENSION] UNLOADED_RADIUS");
      t.unloaded_radius = t.mf->UNLOADED_RADIUS;
      if (!t.mf->was_defaulted("VERTICAL/VERTICAL_STIFFNESS")) {
        given_by_file(e.vertical_stiffness, "/vertical_stiffness", "[VERTICAL] VERTICAL_STIFFNESS");
        t.vertical_stiffness = t.mf->VERTICAL_STIFFNESS;
      } else {
        if (!e.vertical_stiffness) fail(p + "/vertical_stiffness", "expected a vertical stiffness (N/m): the .tir file gives none");
        t.vertical_stiffness = *e.vertical_stiffness;
      }
      if (!t.mf->was_defaulted("VERTICAL/VERTICAL_DAMPING")) {
        given_by_file(e.vertical_damping, "/vertical_damping", "[VERTICAL] VERTICAL_DAMPING");
        t.vertical_damping = t.mf->VERTICAL_DAMPING;
      } else {
        t.vertical_damping = e.vertical_damping.value_or(0.0);
      }
    } else if (e.law == "linear" || e.law == "fiala") {
      t.law = e.law == "linear" ? TireLaw::Linear : TireLaw::Fiala;
      if (!e.unloaded_radius) fail(p, "missing required field \"unloaded_radius\"");
      t.unloaded_radius = *e.unloaded_radius;
      if (!e.vertical_stiffness) fail(p, "missing required field \"vertical_stiffness\"");
      t.vertical_stiffness = *e.vertical_stiffness;
      t.vertical_damping = e.vertical_damping.value_or(0.0);
      non_negative(e.longitudinal_stiffness, p + "/longitudinal_stiffness", "longitudinal slip stiffness");
      non_negative(e.cornering_stiffness, p + "/cornering_stiffness", "cornering stiffness");
      non_negative(e.friction, p + "/friction", "friction coefficient");
      t.C_kappa = e.longitudinal_stiffness;
      t.C_alpha = e.cornering_stiffness;
      t.friction = e.friction;
      if (t.law == TireLaw::Linear) {
        if (!std::isfinite(e.camber_stiffness)) fail(p + "/camber_stiffness", "expected a finite number");
        if (!std::isfinite(e.trail)) fail(p + "/trail", "expected a finite number");
        t.C_gamma = e.camber_stiffness;
        t.trail = e.trail;
      } else {
        positive(e.longitudinal_stiffness, "/longitudinal_stiffness", "longitudinal slip stiffness (N)");
        positive(e.cornering_stiffness, "/cornering_stiffness", "cornering stiffness (N/rad)");
        positive(e.friction, "/friction", "friction coefficient");
        non_negative(e.sliding_friction, p + "/sliding_friction", "sliding friction coefficient");
        non_negative(e.width, p + "/width", "width");
        non_negative(e.rolling_resistance, p + "/rolling_resistance", "rolling resistance");
        t.sliding_friction = e.sliding_friction > 0 ? e.sliding_friction : e.friction;
        t.width = e.width;
        t.rolling_resistance = e.rolling_resistance;
      }
    } else {
      fail(p + "/law", "unknown tire law " + quote(e.law) + " (expected one of: linear, fiala, magic_formula)");
    }
    positive(t.unloaded_radius, "/unloaded_radius", "unloaded radius (m)");
    non_negative(t.vertical_stiffness, p + "/vertical_stiffness", "vertical stiffness");
    non_negative(t.vertical_damping, p + "/vertical_damping", "vertical damping");
    non_negative(e.rolling_radius, p + "/rolling_radius", "rolling radius");
    t.rolling_radius = e.rolling_radius > 0 ? e.rolling_radius : t.unloaded_radius;
    if (!std::isfinite(e.longitudinal_relaxation_length))
      fail(p + "/longitudinal_relaxation_length", "expected a finite length (m)");
    if (!std::isfinite(e.lateral_relaxation_length)) fail(p + "/lateral_relaxation_length", "expected a finite length (m)");
    non_negative(e.longitudinal_relaxation_length, p + "/longitudinal_relaxation_length", "relaxation length");
    non_negative(e.lateral_relaxation_length, p + "/lateral_relaxation_length", "relaxation length");
    t.relaxation_x = e.longitudinal_relaxation_length;
    t.relaxation_y = e.lateral_relaxation_length;
    if (e.relaxation_from_file) {
      const std::string key = p + "/relaxation_from_file";
      if (t.law != TireLaw::MagicFormula) fail(key, "expected a magic_formula tire (the lengths come from its .tir file)");
      if (t.relaxation_x > 0 || t.relaxation_y > 0)
        fail(key, "the relaxation lengths come from the .tir file: leave out longitudinal_relaxation_length and "
                  "lateral_relaxation_length, or this field");
      const bool mf52 = t.mf->version == MagicFormulaVersion::MF52;
      for (const char* k : mf52 ? std::initializer_list<const char*>{"LONGITUDINAL_COEFFICIENTS/PTX1", "LATERAL_COEFFICIENTS/PTY1",
                                                                     "LATERAL_COEFFICIENTS/PTY2"}
                                : std::initializer_list<const char*>{"STRUCTURAL/LONGITUDINAL_STIFFNESS",
                                                                     "STRUCTURAL/LATERAL_STIFFNESS"})
        if (t.mf->was_defaulted(k))
          fail(key, std::string("the .tir file gives no ") + k + ", which the relaxation lengths of its version need");
      t.relaxation_from_file = true;
      // at the nominal load, upright
      const double Fz0 = t.mf->FNOMIN;
      const auto [sx, sy] = magic_formula_relaxation_lengths<double>(*t.mf, Fz0, 0.0, t.mf->LONGVL);
      if (!std::isfinite(sx) || !(sx > 0) || !std::isfinite(sy) || !(sy > 0))
        fail(key, "the .tir file's relaxation lengths at FNOMIN are " + compile_number(sx) + " m and " + compile_number(sy) +
                      " m: expected positive lengths");
      t.relaxation_x = sx;
      t.relaxation_y = sy;
    }
    build_tire_road(e.road, p + "/road", t);
    return t;
  }

  // a road of heights (vehicle/road.hpp, docs/roads.md) and the friction regions: tires whose roads
  // read the same CSV file or generate the same ISO 8608 road, with the same regions, share one
  // surface, read or generated once
  // a tire's road as written, or with the surface and regions of the model's road it names (then p,
  // where its fields' errors are, becomes /roads/K)
  RoadSpec resolve_road(const RoadSpec& given, const std::string& given_path, std::string& p) const {
    p = given_path;
    if (given.surface.empty()) return given;
    if (given.grid || given.profile || given.iso8608 || !given.friction.empty())
      fail(given_path + "/surface", "a named road gives the surface and the friction regions: leave out grid, profile, "
                                    "iso8608 and friction, or the name");
    if (given.point != Eigen::Vector3d::Zero() || given.normal != Eigen::Vector3d::UnitZ())
      fail(given_path + (given.point != Eigen::Vector3d::Zero() ? "/point" : "/normal"),
           "a named road lies in the road body's frame: point and normal belong to the plane road; leave them out");
    std::string names;
    std::size_t k = 0;
    for (; k < spec_.roads.size() && spec_.roads[k].name != given.surface; ++k) names += (names.empty() ? "" : ", ") + spec_.roads[k].name;
    if (k == spec_.roads.size())
      fail(given_path + "/surface", "unknown road " + quote(given.surface) + " (expected one of the model's roads: " +
                                        (names.empty() ? "none defined" : names) + ")");
    const NamedRoadSpec& named = spec_.roads[k];
    RoadSpec r = given;
    r.grid = named.grid;
    r.profile = named.profile;
    r.iso8608 = named.iso8608;
    r.friction = named.friction;
    p = at("roads", k);
    if (!r.grid && !r.profile && !r.iso8608 && r.friction.empty()) fail(p, "expected a road surface (grid, profile, iso8608) or friction regions");
    return r;
  }

  void build_tire_road(const RoadSpec& given, const std::string& given_path, TireModel& t) const {
    std::string p;
    const RoadSpec r = resolve_road(given, given_path, p);
    const int kinds = int(r.grid.has_value()) + int(r.profile.has_value()) + int(r.iso8608.has_value());
    if (kinds > 1) fail(p, "expected one road surface of grid, profile, iso8608, got " + std::to_string(kinds));
    if (kinds == 0 && r.friction.empty()) return;
    const bool plane_given = r.point != Eigen::Vector3d::Zero() || r.normal != Eigen::Vector3d::UnitZ();
    if (kinds == 1 && plane_given)
      fail(p + (r.point != Eigen::Vector3d::Zero() ? "/point" : "/normal"),
           "a road surface lies in the road body's frame: point and normal belong to the plane road; leave them out");
    if (kinds == 0 && plane_given)
      fail(p + "/friction", "friction regions lie on a road in the road body's x, y: leave out point and normal, or the regions");
    std::vector<RoadFrictionRegion> regions;
    std::ostringstream suffix;
    suffix.precision(17);
    for (std::size_t k = 0; k < r.friction.size(); ++k) {
      const RoadFrictionSpec& f = r.friction[k];
      const std::string q = p + "/friction/" + std::to_string(k);
      RoadFrictionRegion region;
      for (const auto& [v, lo, hi, name] : {std::tuple{&f.x, &region.x_min, &region.x_max, "/x"}, std::tuple{&f.y, &region.y_min, &region.y_max, "/y"}}) {
        if (v->empty()) continue;
        if (v->size() != 2 || !((*v)[0] <= (*v)[1])) fail(q + name, "expected [min, max] with min <= max");
        *lo = (*v)[0];
        *hi = (*v)[1];
      }
      if (!std::isfinite(f.scale) || !(f.scale >= 0)) fail(q + "/scale", "expected a friction scale >= 0, got " + compile_number(f.scale));
      if (t.law == TireLaw::Linear && !(t.friction > 0))
        fail(q, "a linear tire without friction (its \"friction\" 0: no limit) has no friction to scale; give the tire a friction");
      region.scale = f.scale;
      regions.push_back(region);
      suffix << ";f" << region.x_min << "," << region.x_max << "," << region.y_min << "," << region.y_max << "," << region.scale;
    }
    const std::string key = given.surface.empty() ? road_key(r) : "named:" + p;  // empty: made per tire
    std::shared_ptr<const RoadSurface>* slot = key.empty() ? nullptr : &roads_[key + suffix.str()];
    if (slot && *slot) {
      t.road = *slot;
    } else {
      RoadSurface road = kinds == 0 ? road_tracks({0.0, 1.0}, {0.0, 0.0}, {}, 0.0, 0.0)  // the plane z = 0 as heights
                         : r.grid   ? build_road_grid(*r.grid, p + "/grid")
                         : r.profile ? build_road_profile(*r.profile, p + "/profile")
                                     : build_road_iso8608(*r.iso8608, p + "/iso8608");
      road.friction = regions;
      t.road = std::make_shared<const RoadSurface>(std::move(road));
      if (slot) *slot = t.road;
    }
    if (t.law == TireLaw::MagicFormula)
      for (const RoadFrictionRegion& region : t.road->friction) {
        auto scaled = std::make_shared<MagicFormulaParameters>(*t.mf);
        scaled->LMUX *= region.scale;
        scaled->LMUY *= region.scale;
        t.mf_regions.push_back(std::move(scaled));
      }
  }

  // what makes two roads the same surface: the CSV file (and the tracks' y), the ISO 8608 road's
  // fields, the plane; empty for inline heights (made per tire)
  std::string road_key(const RoadSpec& r) const {
    std::ostringstream key;
    key.precision(17);
    if (r.grid) {
      if (r.grid->file.empty() || !r.grid->x.empty() || !r.grid->y.empty() || r.grid->z.size()) return "";
      key << "grid:" << road_file(r.grid->file);
    } else if (r.profile) {
      if (r.profile->file.empty() || !r.profile->s.empty() || !r.profile->left.empty() || !r.profile->right.empty()) return "";
      key << "profile:" << road_file(r.profile->file) << ":" << r.profile->left_y.value_or(0) << ":" << r.profile->right_y.value_or(0)
          << ":" << r.profile->left_y.has_value() << r.profile->right_y.has_value();
    } else if (r.iso8608) {
      const RoadIso8608Spec& i = *r.iso8608;
      key << "iso8608:" << i.road_class << "," << i.length << ",";
      for (double b : i.band) key << b << ",";
      key << i.spacing << "," << i.start << "," << i.seed << "," << i.left_y.value_or(0) << "," << i.right_y.value_or(0) << ","
          << i.left_y.has_value() << i.right_y.has_value();
    } else {
      key << "plane";
    }
    return key.str();
  }

  std::string road_file(const std::string& file) const {
    std::filesystem::path path(file);
    if (path.is_relative() && !file_.empty()) path = std::filesystem::path(file_).parent_path() / path;
    return path.string();
  }

  RoadSurface build_road_grid(const RoadGridSpec& g, const std::string& p) const {
    RoadTable table;
    if (!g.file.empty()) {
      if (!g.x.empty() || !g.y.empty() || g.z.size()) fail(p, "expected the grid from a file or inline (x, y, z), not both");
      try {
        table = read_road_grid_csv(road_file(g.file));
      } catch (const std::exception& x) {
        fail(p + "/file", x.what());
      }
    } else {
      if (g.x.empty() || g.y.empty() || !g.z.size()) fail(p, "expected a \"file\", or the nodes \"x\", \"y\" and the heights \"z\" (one row per y)");
      table.x = g.x;
      table.y = g.y;
      table.z.assign(static_cast<std::size_t>(g.z.rows()), std::vector<double>());
      for (Eigen::Index j = 0; j < g.z.rows(); ++j)
        for (Eigen::Index i = 0; i < g.z.cols(); ++i) table.z[static_cast<std::size_t>(j)].push_back(g.z(j, i));
    }
    try {
      return road_grid(table.x, table.y, table.z);
    } catch (const std::exception& x) {
      fail(p + (g.file.empty() ? "" : "/file"), (g.file.empty() ? std::string() : road_file(g.file) + ": ") + x.what());
    }
  }

  // the tracks' y: both given for two tracks (left above right), none for one
  void road_track_ys(const std::optional<double>& left_y, const std::optional<double>& right_y, bool two, const std::string& p) const {
    if (!two) {
      if (left_y || right_y) fail(p + (left_y ? "/left_y" : "/right_y"), "one track has no y: leave the field out");
      return;
    }
    if (!left_y) fail(p, "missing required field \"left_y\" (the left track's y in the road body's frame)");
    if (!right_y) fail(p, "missing required field \"right_y\" (the right track's y in the road body's frame)");
    if (!(*left_y > *right_y)) fail(p + "/left_y", "expected the left track's y above the right track's, got " + compile_number(*left_y) + " and " + compile_number(*right_y));
  }

  RoadSurface build_road_profile(const RoadProfileSpec& r, const std::string& p) const {
    RoadTable table;
    if (!r.file.empty()) {
      if (!r.s.empty() || !r.left.empty() || !r.right.empty()) fail(p, "expected the profile from a file or inline (s, left, right), not both");
      try {
        table = read_road_profile_csv(road_file(r.file));
      } catch (const std::exception& x) {
        fail(p + "/file", x.what());
      }
    } else {
      if (r.s.empty() || r.left.empty()) fail(p, "expected a \"file\", or \"s\" and \"left\" (and \"right\" for two tracks)");
      table.x = r.s;
      table.z = {r.left};
      if (!r.right.empty()) table.z.push_back(r.right);
    }
    const bool two = table.z.size() == 2;
    road_track_ys(r.left_y, r.right_y, two, p);
    try {
      return road_tracks(table.x, table.z[0], two ? table.z[1] : std::vector<double>(), r.left_y.value_or(0), r.right_y.value_or(0));
    } catch (const std::exception& x) {
      fail(p + (r.file.empty() ? "" : "/file"), (r.file.empty() ? std::string() : road_file(r.file) + ": ") + x.what());
    }
  }

  RoadSurface build_road_iso8608(const RoadIso8608Spec& r, const std::string& p) const {
    Iso8608Spec iso;
    iso.road_class = iso8608_class(r.road_class);
    if (iso.road_class < 0) fail(p + "/class", "unknown ISO 8608 class " + quote(r.road_class) + " (expected one of: A, B, C, D, E, F, G, H)");
    if (r.band.size() != 2 || !(r.band[0] > 0) || !(r.band[1] > r.band[0]))
      fail(p + "/band", "expected [n_min, n_max] with 0 < n_min < n_max (cycle/m)");
    iso.length = r.length;
    iso.n_min = r.band[0];
    iso.n_max = r.band[1];
    iso.spacing = r.spacing;
    iso.seed = static_cast<std::uint64_t>(static_cast<std::int64_t>(r.seed));
    road_track_ys(r.left_y, r.right_y, true, p);
    std::vector<std::vector<double>> tracks;
    try {
      tracks = iso8608_tracks(iso);
    } catch (const std::exception& x) {
      fail(p, x.what());
    }
    const std::size_t n = tracks[0].size();
    std::vector<double> s(n);
    for (std::size_t i = 0; i < n; ++i) s[i] = r.start + r.length * static_cast<double>(i) / static_cast<double>(n - 1);
    return road_tracks(s, tracks[0], tracks[1], *r.left_y, *r.right_y);
  }

  // the transient slip's states of tire t (its contact's deflections), after the others
  void add_tire_states(TireModel& t) {
    if (t.relaxation_x > 0) {
      t.state_x = m_.ns++;
      m_.s_names.push_back(t.name + ".deflection_x");
      m_.s_units.push_back("m");
    }
    if (t.relaxation_y > 0) {
      t.state_y = m_.ns++;
      m_.s_names.push_back(t.name + ".deflection_y");
      m_.s_units.push_back("m");
    }
  }

  void build_actuators() {
    for (std::size_t k = 0; k < spec_.actuators.size(); ++k) {
      const ActuatorSpec& s = spec_.actuators[k];
      const std::string p = at("actuators", k);
      ActuatorModel a;
      a.name = s.name;
      a.type = s.type;
      if (s.type == ActuatorType::JointForce) {
        const int jb = joint(s.joint, p + "/joint");
        check_dof(jb, s.dof, p + "/dof");
        a.iv = m_.joints[jb].idx_v + s.dof;
        a.unit = is_angular(m_.joints[jb].type, s.dof) ? "N m" : "N";
      } else if (s.type == ActuatorType::Motion) {
        const int jb = joint(s.joint, p + "/joint");
        const JointModel& j = m_.joints[jb];
        if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
          fail(p + "/joint", "a motion input drives a scalar coordinate (a revolute or prismatic joint); " +
                                 quote(j.name) + " is " + to_string(j.type));
        check_dof(jb, s.dof, p + "/dof");
        a.iv = j.idx_v;
        a.iq = j.idx_q;
        for (int other : m_.motions)
          if (m_.actuators[other].iv == a.iv)
            fail(p + "/joint", quote(j.name) + " is already driven by the motion input " + quote(m_.actuators[other].name));
        if (s.gain != 1.0) fail(p + "/gain", "a motion input has no gain (the coordinate is u itself)");
        if (s.u0 != 0.0)
          fail(p + "/u0", "a motion input's nominal value is its joint's q0; set /joints q0 of " + quote(j.name) + " instead");
        a.unit = j.type == JointType::Revolute ? "rad" : "m";
        m_.motions.push_back(static_cast<int>(k));
      } else if (s.type == ActuatorType::Mix) {
        a.unit = "";  // its drives are resolved once every actuator is known (below)
      } else if (s.type == ActuatorType::LineForce) {
        a.body = body(s.body_a, p + "/body_a");
        a.body_b = body(s.body_b, p + "/body_b");
        if (a.body == a.body_b) fail(p + "/body_b", "expected two different bodies");
        if (!s.point_a.allFinite()) fail(p + "/point_a", "expected finite coordinates");
        if (!s.point_b.allFinite()) fail(p + "/point_b", "expected finite coordinates");
        a.point = s.point_a;
        a.point_b = s.point_b;
        a.unit = "N";
      } else {
        a.body = body(s.body, p + "/body", false);
        a.point = s.type == ActuatorType::BodyTorque ? Eigen::Vector3d::Zero() : s.point;
        a.direction = unit(s.direction, p + "/direction", *this);
        a.in_world = s.in_world;
        a.unit = s.type == ActuatorType::BodyTorque ? "N m" : "N";
      }
      if (!std::isfinite(s.gain)) fail(p + "/gain", "expected a finite number");
      if (!std::isfinite(s.u0)) fail(p + "/u0", "expected a finite number");
      a.gain = s.gain;
      a.u0 = s.u0;
      if (s.min) a.min = *s.min;
      if (s.max) a.max = *s.max;
      if (a.min > a.max) fail(p + "/min", "expected min <= max");
      if (!s.unit.empty()) a.unit = s.unit;
      m_.actuators.push_back(a);
    }
    // mixes: each drives other actuators (no mix), each at most once, with finite weights
    for (std::size_t k = 0; k < spec_.actuators.size(); ++k) {
      const ActuatorSpec& s = spec_.actuators[k];
      if (s.type != ActuatorType::Mix) continue;
      const std::string p = at("actuators", k);
      if (s.drives.empty()) fail(p + "/drives", "expected the names of the actuators the mix drives");
      if (static_cast<Eigen::Index>(s.drives.size()) != s.weights.size())
        fail(p + "/weights", "expected one weight per driven actuator (" + std::to_string(s.drives.size()) + "), got " +
                                 std::to_string(s.weights.size()));
      std::set<int> seen;
      for (std::size_t i = 0; i < s.drives.size(); ++i) {
        const std::string pi = p + "/drives/" + std::to_string(i);
        const int j = m_.find_actuator(s.drives[i]);
        if (j < 0) {
          std::vector<std::string> all;
          for (const auto& a : m_.actuators) all.push_back(a.name);
          fail(pi, "unknown actuator " + quote(s.drives[i]) + " (actuators: " + join_names(all) + ")");
        }
        if (m_.actuators[j].type == ActuatorType::Mix) fail(pi, quote(s.drives[i]) + " is a mix (a mix drives actuators, not mixes)");
        if (m_.actuators[j].type == ActuatorType::Motion)
          fail(pi, quote(s.drives[i]) + " is a motion input (a mix drives forces and torques)");
        if (!seen.insert(j).second) fail(pi, quote(s.drives[i]) + " is listed twice");
        const double w = s.weights[static_cast<Eigen::Index>(i)];
        if (!std::isfinite(w)) fail(p + "/weights/" + std::to_string(i), "expected a finite weight");
        m_.actuators[j].driven_by.emplace_back(static_cast<int>(k), w);
      }
    }
  }

  void build_sensors() {
    for (std::size_t k = 0; k < spec_.sensors.size(); ++k) {
      const SensorSpec& s = spec_.sensors[k];
      const std::string p = at("sensors", k);
      SensorModel o;
      o.name = s.name;
      o.type = s.type;
      switch (s.type) {
        case SensorType::JointPosition:
        case SensorType::JointVelocity: {
          const int jb = joint(s.joint, p + "/joint");
          check_dof(jb, s.dof, p + "/dof");
          const JointModel& j = m_.joints[jb];
          if (s.type == SensorType::JointPosition && !has_scalar_positions(j.type))
            fail(p + "/joint", "joint_position needs a joint with scalar coordinates; " + quote(j.name) + " is " + to_string(j.type) + " (use body_angle)");
          o.iq = j.idx_q + s.dof;
          o.iv = j.idx_v + s.dof;
          const bool ang = is_angular(j.type, s.dof);
          o.unit = s.type == SensorType::JointPosition ? (ang ? "rad" : "m") : (ang ? "rad/s" : "m/s");
          break;
        }
        case SensorType::MotionForce: {
          // the coordinate must be driven by a motion input (built before the sensors)
          const int jb = joint(s.joint, p + "/joint");
          check_dof(jb, s.dof, p + "/dof");
          const JointModel& j = m_.joints[jb];
          o.iv = j.idx_v + s.dof;
          o.iq = j.idx_q + s.dof;
          bool driven = false;
          std::vector<std::string> driven_joints;
          for (const ActuatorModel& a : m_.actuators)
            if (a.type == ActuatorType::Motion) {
              driven = driven || a.iv == o.iv;
              for (const JointModel& jm : m_.joints)
                if (jm.nv > 0 && a.iv >= jm.idx_v && a.iv < jm.idx_v + jm.nv)
                  driven_joints.push_back(jm.name + " (by " + quote(a.name) + ")");
            }
          if (!driven)
            fail(p + "/joint", "motion_force reads the reaction of a motion input; no motion drives " + quote(j.name) +
                                   (j.nv > 1 ? " dof " + std::to_string(s.dof) : std::string()) + " (" +
                                   (driven_joints.empty() ? std::string("the model has no motion input")
                                                          : "driven: " + join_names(driven_joints)) + ")");
          o.unit = is_angular(j.type, s.dof) ? "N m" : "N";
          break;
        }
        case SensorType::PointPosition:
        case SensorType::PointVelocity:
          o.body = body(s.body, p + "/body");
          o.frame = body(s.frame, p + "/frame");
          if (s.component < 0 || s.component > 2) fail(p + "/component", "expected x, y or z (0, 1 or 2)");
          o.point = s.point;
          o.component = s.component;
          o.unit = s.type == SensorType::PointPosition ? "m" : "m/s";
          break;
        case SensorType::BodyAngle:
          o.body = body(s.body, p + "/body", false);
          o.axis = unit(s.axis, p + "/axis", *this);
          o.perp1 = perpendicular(o.axis);
          o.perp2 = o.axis.cross(o.perp1);
          o.unit = "rad";
          break;
        case SensorType::Distance:
        case SensorType::DistanceRate:
          o.body_a = body(s.body_a, p + "/body_a");
          o.body_b = body(s.body_b, p + "/body_b");
          o.point_a = s.point_a;
          o.point_b = s.point_b;
          o.unit = s.type == SensorType::Distance ? "m" : "m/s";
          break;
        case SensorType::AngularVelocity:
        case SensorType::Acceleration:
          o.body = body(s.body, p + "/body");
          o.frame = body(s.frame, p + "/frame");
          if (s.component < 0 || s.component > 2) fail(p + "/component", "expected x, y or z (0, 1 or 2)");
          o.component = s.component;
          o.point = s.point;
          o.specific_force = s.specific_force;
          o.unit = s.type == SensorType::AngularVelocity ? "rad/s" : "m/s^2";
          break;
        case SensorType::Tire: {
          // the tires are built (build_effects) before the sensors
          int found = -1;
          std::vector<std::string> names;
          for (std::size_t t = 0; t < m_.tires.size(); ++t) {
            names.push_back(m_.tires[t].name);
            if (m_.tires[t].name == s.tire) found = static_cast<int>(t);
          }
          if (found < 0) {
            bool other_effect = false;
            for (const EffectSpec& e : spec_.effects) other_effect = other_effect || e.name == s.tire;
            fail(p + "/tire", (other_effect ? quote(s.tire) + " is an effect but not a tire" : "unknown tire " + quote(s.tire)) +
                                  " (tires: " + (names.empty() ? std::string("none") : join_names(names)) + ")");
          }
          o.tire = found;
          int qi = -1;
          for (int k = 0; k < static_cast<int>(std::size(kTireQuantityNames)); ++k)
            if (s.quantity == kTireQuantityNames[k]) qi = k;
          if (qi < 0) {
            std::string all;
            for (const char* q : kTireQuantityNames) all += (all.empty() ? "" : ", ") + std::string(q);
            fail(p + "/quantity", "unknown tire quantity " + quote(s.quantity) + " (expected one of: " + all + ")");
          }
          o.quantity = static_cast<TireQuantity>(qi);
          switch (o.quantity) {
            case TireQuantity::SlipAngle:
            case TireQuantity::Camber: o.unit = "rad"; break;
            case TireQuantity::LongitudinalSlip: o.unit = ""; break;
            case TireQuantity::Mz: o.unit = "N m"; break;
            default: o.unit = "N"; break;
          }
          break;
        }
      }
      if (!s.unit.empty()) o.unit = s.unit;
      m_.sensors.push_back(o);
    }
  }

  void build_plant() {
    auto resolve = [&](const std::vector<std::string>& names, const char* list, bool inputs) {
      std::vector<int> idx;
      std::set<std::string> seen;
      for (std::size_t k = 0; k < names.size(); ++k) {
        const std::string p = "/plant/" + std::string(list) + "/" + std::to_string(k);
        const int i = inputs ? m_.find_actuator(names[k]) : m_.find_sensor(names[k]);
        if (i < 0) {
          std::vector<std::string> all;
          if (inputs) for (const auto& a : m_.actuators) all.push_back(a.name);
          else for (const auto& s : m_.sensors) all.push_back(s.name);
          fail(p, std::string("unknown ") + (inputs ? "actuator " : "sensor ") + quote(names[k]) + " (" +
                      (inputs ? "actuators: " : "sensors: ") + join_names(all) + ")");
        }
        if (!seen.insert(names[k]).second) fail(p, quote(names[k]) + " is listed twice");
        idx.push_back(i);
      }
      return idx;
    };
    m_.plant_inputs = resolve(spec_.plant.inputs, "inputs", true);
    m_.plant_outputs = resolve(spec_.plant.outputs, "outputs", false);
  }

  void check_solver() { check_solver_spec(spec_.solver, file_); }

  void initial_state() {
    Eigen::VectorXd q = neutral(m_), v = Eigen::VectorXd::Zero(m_.nv);
    for (int i = 1; i < m_.nbodies; ++i) {
      const JointModel& j = m_.joints[i];
      const JointSpec& js = spec_.joints[j.spec_index];
      if (js.q0.size()) q.segment(j.idx_q, j.nq) = js.q0;
      if (js.v0.size()) v.segment(j.idx_v, j.nv) = js.v0;
    }
    for (int i = 1; i < m_.nbodies; ++i) {
      const JointModel& j = m_.joints[i];
      const int qi = j.type == JointType::Spherical ? j.idx_q : j.type == JointType::Free ? j.idx_q + 3 : -1;
      if (qi >= 0 && q.segment<4>(qi).norm() < 1e-12) fail(at("joints", j.spec_index) + "/q0", "expected a non-zero quaternion");
    }
    m_.q0 = q;
    m_.v0 = v;
    // a motion input's nominal value is its coordinate's q0; the coordinate is at rest there
    for (int k : m_.motions) {
      ActuatorModel& a = m_.actuators[static_cast<std::size_t>(k)];
      a.u0 = q[a.iq];
      if (v[a.iv] != 0.0) {
        for (int i = 1; i < m_.nbodies; ++i)
          if (m_.joints[i].idx_v == a.iv)
            fail(at("joints", m_.joints[i].spec_index) + "/v0",
                 "the coordinate is driven by the motion input " + quote(a.name) +
                     ", which starts at rest (its rate u' is 0 at the nominal); expected 0");
      }
    }
    // a coupler without an offset holds the joints as their q0 write them
    for (ConstraintModel& c : m_.constraints) {
      if (c.type != ConstraintType::Coupler || c.offset_given) continue;
      c.offset = 0;
      for (int k = 0; k < c.ncoupled; ++k) c.offset += c.ratio[k] * q[c.iq[k]];
    }
  }

  const ModelSpec& spec_;
  std::string file_;
  Model m_;
  mutable std::map<std::string, std::shared_ptr<const RoadSurface>> roads_;  // build_tire_road: the roads made
  std::map<std::string, int> body_index_spec_;
  std::map<std::string, int> compiled_;
};

}  // namespace

std::string unattached_body_detail(const std::string& body) {
  return "body \"" + body + "\" is not the child of any joint (attach it, e.g. with a \"fixed\" joint)";
}

void check_solver_spec(const SolverSpec& s, const std::string& file) {
  const auto fail = [&](const std::string& path, const std::string& what) { throw ModelError(file, path, what); };
  if (!is_integrator_name(s.integrator))
    fail("/solver/integrator", "unknown integrator " + quote(s.integrator) + " (expected one of: " + integrator_names() + ")");
  auto positive = [&](double x, const char* f) {
    if (!std::isfinite(x) || x <= 0) fail(std::string("/solver/") + f, "expected a positive number, got " + compile_number(x));
  };
  positive(s.rtol, "rtol");
  positive(s.atol, "atol");
  positive(s.t_end, "t_end");
  positive(s.output_step, "output_step");
  if (!std::isfinite(s.max_step) || s.max_step < 0) fail("/solver/max_step", "expected a non-negative number (0 = no limit)");
  if (s.alf_penalty && !(*s.alf_penalty > 0 && std::isfinite(*s.alf_penalty)))
    fail("/solver/alf_penalty", "expected a penalty > 0 (alf's default 1e11), got " + compile_number(*s.alf_penalty));
  if (s.alf_iterations && *s.alf_iterations < 1)
    fail("/solver/alf_iterations",
         "expected a number of Newton iterations >= 1 (alf's default 100), got " + std::to_string(*s.alf_iterations));
  if (s.integrator == "alf" && s.max_step > s.t_end)
    fail("/solver/max_step", "alf: a step of " + compile_number(s.max_step) + " s is longer than the run (t_end " +
                                 compile_number(s.t_end) + " s)");
}
Model compile_structure(const ModelSpec& spec, const std::string& file) { return Compiler(spec, file).run(); }

Model compile_numbers(const Model& structure, const ModelSpec& spec, NumbersChanged what, const std::string& file) {
  return Compiler(spec, file).renumber(structure, what);
}

}  // namespace codyna
