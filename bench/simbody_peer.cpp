// The Simbody peer's codyna side: the problems' model descriptions (the example files and
// the A02 builder) as PlainModels for bench/simbody_sim.cpp.
#include <stdexcept>

#include "io/model_file.hpp"
#include "model/model_spec.hpp"
#include "models/iftomm_a02.hpp"
#include "simbody_plain.hpp"

namespace codyna::peer {

namespace {

void copy3(const Eigen::Vector3d& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

PFrame plain(const FrameSpec& f) {
  PFrame p;
  copy3(f.position, p.p);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.R[3 * i + j] = f.rotation(i, j);
  return p;
}

PlainModel plain(const ModelSpec& s) {
  PlainModel m;
  for (const BodySpec& b : s.bodies) {
    PBody p;
    p.name = b.name, p.mass = b.mass;
    copy3(b.com, p.com);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p.I[3 * i + j] = b.inertia(i, j);
    m.bodies.push_back(p);
  }
  for (const JointSpec& j : s.joints) {
    PJoint p;
    p.name = j.name, p.parent = j.parent, p.child = j.child;
    if (j.type == JointType::Revolute) p.type = PJointType::Revolute;
    else if (j.type == JointType::Prismatic) p.type = PJointType::Prismatic;
    else if (j.type == JointType::Spherical) p.type = PJointType::Spherical;
    else throw std::runtime_error("simbody peer: joint " + j.name + ": type not modelled");
    p.parent_frame = plain(j.parent_frame), p.child_frame = plain(j.child_frame);
    copy3(j.axis, p.axis);
    p.q0.assign(j.q0.data(), j.q0.data() + j.q0.size());
    p.v0.assign(j.v0.data(), j.v0.data() + j.v0.size());
    m.joints.push_back(p);
  }
  for (const ConstraintSpec& c : s.constraints) {
    PConstraint p;
    p.type = c.type == ConstraintType::Ball       ? PConstraintType::Ball
             : c.type == ConstraintType::Revolute ? PConstraintType::Revolute
                                                  : PConstraintType::PlanarRevolute;
    p.body_a = c.body_a, p.body_b = c.body_b;
    copy3(c.point_a, p.point_a), copy3(c.point_b, p.point_b), copy3(c.axis_a, p.axis_a), copy3(c.axis_b, p.axis_b);
    m.constraints.push_back(p);
  }
  for (const EffectSpec& e : s.effects) {
    PEffect p;
    if (e.type == EffectType::Gravity) p.type = PEffectType::Gravity;
    else if (e.type == EffectType::SpringDamper) p.type = PEffectType::SpringDamper;
    else throw std::runtime_error("simbody peer: effect " + e.name + ": type not modelled");
    copy3(e.g, p.g);
    p.body_a = e.body_a, p.body_b = e.body_b;
    copy3(e.point_a, p.point_a), copy3(e.point_b, p.point_b);
    p.stiffness = e.stiffness, p.damping = e.damping, p.rest_length = e.rest_length;
    m.effects.push_back(p);
  }
  for (const ActuatorSpec& a : s.actuators) {  // held at their nominal values, as in codyna's open-loop runs
    if (a.u0 == 0) continue;
    if (a.type != ActuatorType::JointForce) throw std::runtime_error("simbody peer: actuator " + a.name + " not modelled");
    m.joint_forces.push_back({a.joint, a.dof, a.gain * a.u0});
  }
  return m;
}

ModelSpec spec_of(const std::string& problem, int a02_n) {
  auto example = [](const char* f) { return load_model_spec(std::string(CODYNA_SOURCE_DIR) + "/examples/" + f); };
  if (problem == "andrews") return example("andrews_squeezer.json");
  if (problem == "a01") return example("iftomm_a01_pendulum.json");
  if (problem == "a02") return iftomm::a02_spec(a02_n);
  if (problem == "bricard") return example("bricard.json");
  if (problem == "a05") return example("iftomm_a05_flyball.json");
  if (problem == "heavy_top") return example("heavy_top.json");
  if (problem == "double_pendulum") return example("double_pendulum.json");
  throw std::invalid_argument("simbody peer: unknown problem " + problem);
}

}  // namespace

// simbody-cpodes (CPodes BDF, Simbody's only implicit integrator) is not in the study: Debian's
// Simbody 3.7 aborts in it on every problem here (assertion `!treatAsConst' in
// nvector_SimTK.h); run it alone with --integrators simbody-cpodes to see.
std::vector<std::string> simbody_integrators() { return {"simbody-rkm", "simbody-rkf", "simbody-verlet"}; }

bool simbody_supports(const std::string& problem) {
  for (const char* p : {"andrews", "a01", "a02", "bricard", "a05", "heavy_top", "double_pendulum"})
    if (problem == p) return true;
  return false;
}

PeerRun run_simbody(const std::string& problem, const std::string& integrator, double tol, double t_end,
                    double output_step, int repeats, int a02_n) {
  return run_plain(plain(spec_of(problem, a02_n)), problem, integrator, tol, t_end, output_step, repeats, a02_n);
}

}  // namespace codyna::peer
