// The Simbody peer's Simbody side (C++17): a PlainModel (bodies, revolute / prismatic / spherical joints,
// ball / revolute / planar_revolute loop closures, gravity, point-to-point spring-dampers,
// constant joint forces) built as a Simbody MultibodySystem, then integrated and sampled.
//   revolute   MobilizedBody::Pin, whose common z axis is turned onto the joint axis
//              (the same turn on both frames, so q = 0 is codyna's zero position)
//   prismatic  MobilizedBody::Slider (common x axis turned onto the joint axis)
//   spherical  MobilizedBody::Ball (q: quaternion of M in F, as codyna's)
//   ball closure             Constraint::Ball (3 rows)
//   revolute closure         Constraint::Ball + two Constraint::ConstantAngle at pi/2 that keep
//                            axis_b normal to two directions normal to axis_a (5 rows; Simbody
//                            copes with the Bricard mechanism's redundant row itself)
//   planar_revolute closure  Constraint::PointOnLine, the line through point_a along axis_a
//                            (2 rows, the points coincide in the plane)
// Simbody reports at the output times by its default (it may step past one and interpolate
// back); codyna stops its integrators on each.
#include "simbody_plain.hpp"

#include <time.h>

#include <Simbody.h>
#include <algorithm>
#include <map>
#include <memory>
#include <stdexcept>

namespace codyna::peer {

namespace {

using SimTK::Vec3;

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);  // as work_precision.cpp: precise under RLIMIT_CPU
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

Vec3 v3(const double* v) { return Vec3(v[0], v[1], v[2]); }

SimTK::Rotation rot(const double* R) {
  SimTK::Mat33 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R[3 * i + j];
  return SimTK::Rotation(m);  // orthonormalizes a matrix that is already a rotation
}

SimTK::Transform frame(const PFrame& f, const SimTK::Rotation& align = SimTK::Rotation()) {
  return SimTK::Transform(rot(f.R) * align, v3(f.p));
}

// two unit vectors normal to a
std::pair<Vec3, Vec3> normals(const double* a) {
  const SimTK::UnitVec3 n(v3(a));
  const Vec3 t = std::abs(n[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  const SimTK::UnitVec3 u(SimTK::cross(n, t));
  return {Vec3(u), Vec3(SimTK::cross(n, u))};
}

const std::string kGround = "ground";

// A PlainModel in Simbody. Owns the system; mobilized bodies by body and by joint name.
struct Built {
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  std::map<std::string, SimTK::MobilizedBody> body, joint;
  const PlainModel* spec = nullptr;

  explicit Built(const PlainModel& s) {
    spec = &s;
    body[kGround] = matter.Ground();
    std::vector<bool> done(s.joints.size(), false);
    for (size_t made = 0, pass = 0; made < s.joints.size(); ++pass) {
      if (pass > s.joints.size()) throw std::runtime_error("simbody peer: the joints do not form a tree");
      for (size_t i = 0; i < s.joints.size(); ++i) {
        const PJoint& j = s.joints[i];
        if (done[i] || !body.count(j.parent)) continue;
        const PBody& b = *std::find_if(s.bodies.begin(), s.bodies.end(), [&](const PBody& x) { return x.name == j.child; });
        SimTK::Mat33 Ic;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) Ic(r, c) = b.I[3 * r + c];
        const SimTK::Inertia I_origin = SimTK::Inertia(Ic).shiftFromMassCenter(-v3(b.com), b.mass);
        const SimTK::Body::Rigid info(SimTK::MassProperties(b.mass, v3(b.com), I_origin));
        SimTK::MobilizedBody& parent = body[j.parent];
        SimTK::MobilizedBody m;
        switch (j.type) {
          case PJointType::Revolute: {
            const SimTK::Rotation a(SimTK::UnitVec3(v3(j.axis)), SimTK::ZAxis);
            m = SimTK::MobilizedBody::Pin(parent, frame(j.parent_frame, a), info, frame(j.child_frame, a));
            break;
          }
          case PJointType::Prismatic: {
            const SimTK::Rotation a(SimTK::UnitVec3(v3(j.axis)), SimTK::XAxis);
            m = SimTK::MobilizedBody::Slider(parent, frame(j.parent_frame, a), info, frame(j.child_frame, a));
            break;
          }
          case PJointType::Spherical:
            m = SimTK::MobilizedBody::Ball(parent, frame(j.parent_frame), info, frame(j.child_frame));
            break;
        }
        body[j.child] = m;
        joint[j.name] = m;
        done[i] = true;
        ++made;
      }
    }
    for (const PConstraint& c : s.constraints) {
      SimTK::MobilizedBody &A = body.at(c.body_a), &B = body.at(c.body_b);
      switch (c.type) {
        case PConstraintType::Ball:
          SimTK::Constraint::Ball(A, v3(c.point_a), B, v3(c.point_b));
          break;
        case PConstraintType::Revolute: {
          SimTK::Constraint::Ball(A, v3(c.point_a), B, v3(c.point_b));
          const auto [u, w] = normals(c.axis_a);
          SimTK::Constraint::ConstantAngle(A, SimTK::UnitVec3(u), B, SimTK::UnitVec3(v3(c.axis_b)));
          SimTK::Constraint::ConstantAngle(A, SimTK::UnitVec3(w), B, SimTK::UnitVec3(v3(c.axis_b)));
          break;
        }
        case PConstraintType::PlanarRevolute:
          SimTK::Constraint::PointOnLine(A, SimTK::UnitVec3(v3(c.axis_a)), v3(c.point_a), B, v3(c.point_b));
          break;
      }
    }
    for (const PEffect& e : s.effects) {
      switch (e.type) {
        case PEffectType::Gravity:
          SimTK::Force::UniformGravity(forces, matter, v3(e.g));
          break;
        case PEffectType::SpringDamper:
          SimTK::Force::TwoPointLinearSpring(forces, body.at(e.body_a), v3(e.point_a), body.at(e.body_b), v3(e.point_b),
                                             e.stiffness, e.rest_length);
          if (e.damping != 0)
            SimTK::Force::TwoPointLinearDamper(forces, body.at(e.body_a), v3(e.point_a), body.at(e.body_b),
                                               v3(e.point_b), e.damping);
          break;
      }
    }
    for (const PJointForce& f : s.joint_forces)
      SimTK::Force::MobilityConstantForce(forces, joint.at(f.joint), SimTK::MobilizerUIndex(f.dof), f.value);
    system.realizeTopology();
  }

  // the model's initial state (q0, v0 as codyna reads them)
  SimTK::State initial_state() {
    SimTK::State st = system.getDefaultState();
    for (const PJoint& j : spec->joints) {
      const SimTK::MobilizedBody& m = joint.at(j.name);
      if (j.type == PJointType::Spherical) {
        const bool has_q = j.q0.size() == 4;
        if (has_q)
          m.setQToFitRotation(st, SimTK::Rotation(SimTK::Quaternion(j.q0[0], j.q0[1], j.q0[2], j.q0[3])));
        if (j.v0.size() == 3) {
          const SimTK::Rotation R_FM = has_q ? SimTK::Rotation(SimTK::Quaternion(j.q0[0], j.q0[1], j.q0[2], j.q0[3]))
                                                        : SimTK::Rotation();
          m.setUToFitAngularVelocity(st, R_FM * Vec3(j.v0[0], j.v0[1], j.v0[2]));  // codyna: M axes; Simbody: F axes
        }
      } else {
        if (!j.q0.empty()) m.setOneQ(st, 0, j.q0[0]);
        if (!j.v0.empty()) m.setOneU(st, 0, j.v0[0]);
      }
    }
    return st;
  }

  double q(const SimTK::State& st, const std::string& name) const { return joint.at(name).getOneQ(st, 0); }
};

// the quantities of bench/work_precision.cpp, from a Simbody state
std::vector<double> quantities(const std::string& p, Built& b, const SimTK::State& st, int a02_n) {
  if (p == "andrews") {
    std::vector<double> y;
    for (const char* n : {"beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"}) y.push_back(b.q(st, n));
    return y;
  }
  if (p == "a01") {
    b.system.realize(st, SimTK::Stage::Position);
    const Vec3 x = b.body.at("mass").findStationLocationInGround(st, Vec3(1, 0, 0));
    return {x[0], x[1]};
  }
  if (p == "a02") {
    std::vector<double> y;
    for (int i = 0; i <= a02_n; ++i) y.push_back(b.q(st, "pivot" + std::to_string(i)));
    return y;
  }
  if (p == "a05") return {0.5 + b.q(st, "slide")};
  b.system.realize(st, SimTK::Stage::Dynamics);
  const double E = b.system.calcEnergy(st);
  if (p == "bricard") {
    const Vec3 C = b.body.at("rod3").getBodyOriginLocation(st);
    return {E, C[0], C[1], C[2]};
  }
  if (p == "heavy_top") return {E, b.matter.calcSystemMomentumAboutGroundOrigin(st)[0][2]};
  return {E};  // double_pendulum
}

}  // namespace

PeerRun run_plain(const PlainModel& spec, const std::string& problem, const std::string& integrator, double tol,
                  double t_end, double output_step, int repeats, int a02_n) {
  Built b(spec);
  PeerRun best;
  best.cpu_s = 1e300;
  double spent = 0;
  for (int rep = 0; rep < repeats && (rep == 0 || spent < 1.0); ++rep) {
    PeerRun r;
    const double t0 = cpu_now();
    std::unique_ptr<SimTK::Integrator> integ;
    if (integrator == "simbody-rkm") integ = std::make_unique<SimTK::RungeKuttaMersonIntegrator>(b.system);
    else if (integrator == "simbody-rkf") integ = std::make_unique<SimTK::RungeKuttaFeldbergIntegrator>(b.system);
    else if (integrator == "simbody-verlet") integ = std::make_unique<SimTK::VerletIntegrator>(b.system);
    else if (integrator == "simbody-cpodes")
      integ = std::make_unique<SimTK::CPodesIntegrator>(b.system, SimTK::CPodes::BDF, SimTK::CPodes::Newton);
    else throw std::invalid_argument("simbody peer: unknown integrator " + integrator);
    integ->setAccuracy(tol);
    integ->setConstraintTolerance(0.1 * tol);
    integ->setFinalTime(t_end);
    SimTK::TimeStepper ts(b.system, *integ);
    try {
      ts.initialize(b.initial_state());
      const int n = static_cast<int>(std::llround(t_end / output_step));
      for (int i = 0; i <= n; ++i) {
        const double t = i == n ? t_end : i * output_step;
        if (i > 0) {
          const SimTK::Integrator::SuccessfulStepStatus status = ts.stepTo(t);
          if (status == SimTK::Integrator::EndOfSimulation && ts.getTime() < t - 1e-9 * std::max(1.0, t))
            throw std::runtime_error("Simbody ended the simulation early: " +
                                     SimTK::Integrator::getTerminationReasonString(integ->getTerminationReason()));
        }
        r.t.push_back(ts.getTime());
        r.y.push_back(quantities(problem, b, ts.getState(), a02_n));
      }
      r.completed = true;
    } catch (const std::exception& e) {
      r.failure = e.what();
    }
    r.cpu_s = cpu_now() - t0;
    r.steps = integ->getNumStepsTaken();
    r.evaluations = integ->getNumRealizations();
    spent += r.cpu_s;
    const double c = std::min(best.cpu_s, r.cpu_s);
    best = std::move(r);
    best.cpu_s = c;
  }
  return best;
}

}  // namespace codyna::peer
