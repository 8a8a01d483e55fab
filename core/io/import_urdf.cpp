#include "io/import_urdf.hpp"

#include <filesystem>
#include <functional>
#include <sstream>
#include <stdexcept>

#ifdef CODYNA_HAVE_URDFDOM
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#endif

namespace codyna {

#ifndef CODYNA_HAVE_URDFDOM

bool urdf_import_available() { return false; }
ImportResult import_urdf(const std::string& path, const ImportOptions&) {
  throw std::runtime_error(path + ": URDF import needs urdfdom, and this codyna was built without it "
                           "(install liburdfdom-dev, then configure and build codyna again)");
}

#else

bool urdf_import_available() { return true; }

namespace {

std::string urdf_text(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

FrameSpec frame(const urdf::Pose& p) {
  FrameSpec f;
  f.position = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  f.rotation = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix();
  return f;
}

// urdfdom's messages (it logs through console_bridge, to stderr by default): kept for the error
class Collect : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) lines.push_back(text);
  }
  std::vector<std::string> lines;
};

class UrdfImporter {
 public:
  UrdfImporter(const urdf::ModelInterface& m, std::string path, const ImportOptions& o) : m_(m), path_(std::move(path)), opt_(o) {}

  ImportResult run() {
    ImportReport& rep = r_.report;
    rep.source = path_;
    rep.format = "URDF";
    rep.reader = "urdfdom";
    ModelSpec& s = r_.spec;
    s.name = m_.getName().empty() ? std::filesystem::path(path_).stem().string() : m_.getName();
    auto root = m_.getRoot();
    if (!root) throw ImportRefused(path_ + ": the URDF has no root link", rep);
    const bool world_root = root->name == "world";
    if (world_root && root->inertial && root->inertial->mass != 0)
      throw ImportRefused(path_ + ": link world: the root link named world is the fixed world and cannot have mass", rep);
    bodies_.reserve(kGroundName);
    if (!world_root) {
      add_link(*root);
      JointSpec j;
      j.name = joints_.unique(root->name + "_fixed");
      j.type = JointType::Fixed;
      j.parent = kGroundName;
      j.child = name_of(root->name);
      s.joints.push_back(j);
      ++nroot_;
    }
    std::function<void(const urdf::Link&)> walk = [&](const urdf::Link& l) {
      for (const auto& cj : l.child_joints) {
        auto child = m_.getLink(cj->child_link_name);
        if (!child) throw ImportRefused(path_ + ": joint " + cj->name + ": no link " + cj->child_link_name, rep);
        add_link(*child);
        add_joint(*cj, world_root && l.name == root->name ? std::string(kGroundName) : name_of(l.name));
        walk(*child);
      }
    };
    walk(*root);
    finish();
    refuse_if_needed(rep);
    return std::move(r_);
  }

 private:
  const urdf::ModelInterface& m_;
  std::string path_;
  const ImportOptions& opt_;
  ImportResult r_;
  NameSet bodies_, joints_, effects_, actuators_, sensors_;
  std::map<std::string, std::string> link_names_;
  std::vector<const urdf::Joint*> mimics_;
  std::vector<std::string> limits_, friction_, mimic_, collisions_, meshes_, massless_;
  std::map<std::string, int> types_;
  int nshapes_ = 0, nroot_ = 0, ndampers_ = 0;

  std::string name_of(const std::string& link) const { return link_names_.at(link); }

  void add_link(const urdf::Link& l) {
    BodySpec b;
    b.name = bodies_.unique(l.name == kGroundName ? l.name + "_link" : l.name);
    link_names_[l.name] = b.name;
    if (l.inertial) {
      const FrameSpec f = frame(l.inertial->origin);
      const auto& in = *l.inertial;
      Eigen::Matrix3d I;
      I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      b.mass = in.mass;
      b.com = f.position;
      const Eigen::Matrix3d Ib = f.rotation * I * f.rotation.transpose();
      b.inertia = 0.5 * (Ib + Ib.transpose());
    } else {
      massless_.push_back(l.name);
    }
    for (const auto& v : l.visual_array) {
      if (!v || !v->geometry) continue;
      ShapeSpec sh;
      sh.frame = frame(v->origin);
      if (v->material) sh.color = Eigen::Vector4d(v->material->color.r, v->material->color.g, v->material->color.b, v->material->color.a);
      switch (v->geometry->type) {
        case urdf::Geometry::SPHERE:
          sh.type = ShapeType::Sphere;
          sh.radius = static_cast<const urdf::Sphere&>(*v->geometry).radius;
          break;
        case urdf::Geometry::BOX: {
          const auto& d = static_cast<const urdf::Box&>(*v->geometry).dim;
          sh.type = ShapeType::Box;
          sh.size = Eigen::Vector3d(d.x, d.y, d.z);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& c = static_cast<const urdf::Cylinder&>(*v->geometry);
          sh.type = ShapeType::Cylinder;
          sh.radius = c.radius;
          sh.length = c.length;
          break;
        }
        default:
          meshes_.push_back(l.name + " (" + static_cast<const urdf::Mesh&>(*v->geometry).filename + ")");
          continue;
      }
      b.shapes.push_back(sh);
      ++nshapes_;
    }
    if (!l.collision_array.empty()) collisions_.push_back(l.name);
    r_.spec.bodies.push_back(b);
  }

  void add_joint(const urdf::Joint& uj, const std::string& parent) {
    ModelSpec& s = r_.spec;
    JointSpec j;
    j.name = joints_.unique(uj.name);
    j.parent = parent;
    j.child = name_of(uj.child_link_name);
    j.parent_frame = frame(uj.parent_to_joint_origin_transform);
    Eigen::Vector3d axis(uj.axis.x, uj.axis.y, uj.axis.z);
    bool scalar = false;
    switch (uj.type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
        j.type = JointType::Revolute;
        scalar = true;
        ++types_[uj.type == urdf::Joint::REVOLUTE ? "revolute" : "continuous"];
        break;
      case urdf::Joint::PRISMATIC:
        j.type = JointType::Prismatic;
        scalar = true;
        ++types_["prismatic"];
        break;
      case urdf::Joint::FLOATING:
        j.type = JointType::Free;
        ++types_["floating"];
        break;
      case urdf::Joint::PLANAR: {
        // codyna's planar joint moves in F's x-y plane: turn F (and M) so that z is the URDF normal
        j.type = JointType::Planar;
        const Eigen::Matrix3d Ra = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis.normalized()).toRotationMatrix();
        j.parent_frame.rotation = j.parent_frame.rotation * Ra;
        j.child_frame.rotation = Ra;
        ++types_["planar"];
        break;
      }
      case urdf::Joint::FIXED:
        j.type = JointType::Fixed;
        ++types_["fixed"];
        break;
      default: throw ImportRefused(path_ + ": joint " + uj.name + ": unknown joint type", r_.report);
    }
    if (scalar) {
      if (axis.norm() == 0) throw ImportRefused(path_ + ": joint " + uj.name + ": zero axis", r_.report);
      j.axis = axis.normalized();
    }
    s.joints.push_back(j);
    if (uj.limits && uj.type != urdf::Joint::FIXED) {
      std::string l = uj.name;
      if (uj.type == urdf::Joint::REVOLUTE || uj.type == urdf::Joint::PRISMATIC)
        l += " [" + urdf_text(uj.limits->lower) + ", " + urdf_text(uj.limits->upper) + "]";
      if (uj.limits->velocity > 0) l += " velocity " + urdf_text(uj.limits->velocity);
      limits_.push_back(l);
    }
    if (uj.dynamics && uj.type != urdf::Joint::FIXED) {
      if (uj.dynamics->damping != 0) {
        EffectSpec e;
        e.name = effects_.unique(j.name + "_damper");
        e.type = EffectType::JointDamper;
        e.joint = j.name;
        e.damping = uj.dynamics->damping;
        s.effects.push_back(e);
        ++ndampers_;
      }
      if (uj.dynamics->friction != 0) friction_.push_back(uj.name + " " + urdf_text(uj.dynamics->friction));
    }
    if (uj.mimic) mimics_.push_back(&uj);
    if (scalar) {
      ActuatorSpec a;
      a.name = actuators_.unique(j.name + "_motor");
      a.type = ActuatorType::JointForce;
      a.joint = j.name;
      if (uj.limits && uj.limits->effort > 0) {
        a.min = -uj.limits->effort;
        a.max = uj.limits->effort;
      }
      s.actuators.push_back(a);
      s.plant.inputs.push_back(a.name);
      SensorSpec sn;
      sn.name = sensors_.unique(j.name);
      sn.type = SensorType::JointPosition;
      sn.joint = j.name;
      s.sensors.push_back(sn);
      s.plant.outputs.push_back(sn.name);
    }
  }

  // mimic: q(joint) = multiplier q(mimicked) + offset, a coupler between two scalar joints
  void couplers() {
    ModelSpec& s = r_.spec;
    int n = 0;
    for (const urdf::Joint* uj : mimics_) {
      const auto other = m_.getJoint(uj->mimic->joint_name);
      auto scalar = [](int t) {
        return t == urdf::Joint::REVOLUTE || t == urdf::Joint::CONTINUOUS || t == urdf::Joint::PRISMATIC;
      };
      const std::string text = uj->name + " = " + urdf_text(uj->mimic->multiplier) + " " + uj->mimic->joint_name + " + " + urdf_text(uj->mimic->offset);
      if (!other || !scalar(uj->type) || !scalar(other->type) || uj->mimic->multiplier == 0 || other->name == uj->name) {
        mimic_.push_back(text + (other ? "" : " (no such joint)"));
        continue;
      }
      ConstraintSpec c;
      c.name = uj->name + "_mimic";
      c.type = ConstraintType::Coupler;
      c.joint_a = uj->name;
      c.joint_b = other->name;
      c.ratio_a = 1;
      c.ratio_b = -uj->mimic->multiplier;
      c.offset = uj->mimic->offset;
      s.constraints.push_back(c);
      ++n;
    }
    if (n) r_.report.mapped.push_back(std::to_string(n) + " mimic joints -> couplers (q = multiplier q_mimicked + offset, exact)");
  }

  void finish() {
    couplers();
    ModelSpec& s = r_.spec;
    EffectSpec g;
    g.name = effects_.unique("gravity");
    g.type = EffectType::Gravity;
    g.g = Eigen::Vector3d(0, 0, -9.81);
    s.effects.insert(s.effects.begin(), g);
    std::string types;
    for (const auto& [t, n] : types_) types += (types.empty() ? "" : ", ") + std::to_string(n) + " " + t;
    auto& mp = r_.report.mapped;
    mp.push_back(std::to_string(s.bodies.size()) + " links -> bodies (inertial origin and rotation applied to the tensor)" +
                 (massless_.empty() ? "" : "; " + std::to_string(massless_.size()) + " without <inertial> are massless"));
    mp.push_back(std::to_string(s.joints.size() - nroot_) + " joints (" + types + ") -> revolute, prismatic, free, planar, fixed" +
                 (nroot_ ? "; the root link welded to ground" : "; the root link world is ground"));
    mp.push_back(std::to_string(nshapes_) + " visuals -> display shapes");
    if (ndampers_) mp.push_back(std::to_string(ndampers_) + " joint dampings -> joint_damper");
    mp.push_back("gravity [0 0 -9.81] m/s^2 (URDF has none; z up, as ROS and MuJoCo)");
    mp.push_back(std::to_string(s.actuators.size()) + " joint_force actuators, one per movable joint (effort -> min, max; "
                 "urdfdom does not read <transmission>)");
    mp.push_back("plant: every actuator as Plant/In (" + std::to_string(s.plant.inputs.size()) +
                 "), every joint coordinate as Plant/Out (" + std::to_string(s.plant.outputs.size()) + ")");
    add_finding(r_.report, opt_, "frictionloss", "dry joint friction (dynamics friction) is not modelled", friction_, true);
    add_finding(r_.report, opt_, "mimic", "mimic joints codyna cannot couple (not between two revolute, continuous or prismatic joints)", mimic_, true);
    add_finding(r_.report, opt_, "limits", "joint limits: not modelled, kept in the description", limits_, false);
    add_finding(r_.report, opt_, "contacts", "collision geometry is not modelled (codyna's dynamics has no contact)", collisions_, false);
    add_finding(r_.report, opt_, "shapes", "meshes are not shown (codyna reads no mesh files)", meshes_, false);
    s.description = "Imported from " + std::filesystem::path(path_).filename().string() + " (URDF, urdfdom) by codyna import.";
    if (!limits_.empty()) {
      s.description += " Joint limits (not modelled):";
      for (const std::string& l : limits_) s.description += " " + l + ";";
      s.description.back() = '.';
    }
  }
};

}  // namespace

ImportResult import_urdf(const std::string& path, const ImportOptions& options) {
  check_import_options(options);
  ImportReport empty;
  empty.source = path;
  empty.format = "URDF";
  empty.reader = "urdfdom";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ImportRefused(path + ": cannot open file: " + (std::filesystem::exists(path, ec) ? "not a regular file" : "No such file or directory"), empty);
  Collect collect;
  console_bridge::OutputHandler* old = console_bridge::getOutputHandler();
  console_bridge::useOutputHandler(&collect);
  urdf::ModelInterfaceSharedPtr m;
  try {
    m = urdf::parseURDFFile(path);
  } catch (const std::exception& e) {
    collect.lines.push_back(e.what());
  }
  console_bridge::useOutputHandler(old);
  if (!m) {
    std::string why;
    for (const std::string& l : collect.lines) why += (why.empty() ? "" : "; ") + l;
    throw ImportRefused(path + ": not a valid URDF: " + (why.empty() ? "urdfdom could not parse it" : why), empty);
  }
  ImportResult r = UrdfImporter(*m, path, options).run();
  for (const std::string& l : collect.lines) r.spec.notes.push_back(path + ": urdfdom: " + l);
  return r;
}

#endif

}  // namespace codyna
