#include "study/kc_job.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "dynamics/constraints.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "io/atomic_file.hpp"
#include "io/output_guard.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"

namespace codyna {

namespace {

constexpr double kc_deg = 180.0 / 3.14159265358979323846;

// what a sweep point prescribes
struct KcTarget {
  double travel = 0, roll = 0, steer = 0, fx = 0, fy = 0, mz = 0;  // roll in deg
};

// one wheel on the rig and what the job measures on it
struct KcWheelRig {
  int body = 0, upright = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // wheel body coordinates
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();   // unit, wheel body coordinates
  double radius = 0;
  double outward = 1;                                // +1: the wheel is on the held body's left
  double design_height = 0, design_y = 0;            // the wheel centre's z and y in the held frame
  // the kingpin's two balls, points in upright coordinates
  bool kingpin = false;
  Eigen::Vector3d ball_a = Eigen::Vector3d::Zero(), ball_b = Eigen::Vector3d::Zero();
};

// the rig: the compiled model (no gravity, no tires) and its wheels
struct KcRig {
  explicit KcRig(Model m) : model(std::move(m)) {}
  Model model;
  std::vector<KcWheelRig> wheels;
  int held = 0;
  SE3 X_WH;                                          // the held body's pose
  int steer_iq = -1;
  std::vector<int> free, locked;                     // tangent indices
  std::vector<int> rows;                             // the holonomic constraint rows kept
  Eigen::VectorXd u;                                 // the actuators' nominal values
};

// the wheel's geometry at the positions data holds
struct KcGeometry {
  Eigen::Vector3d centre, axis, contact;  // held frame; axis outward
};

KcGeometry kc_geometry(const KcRig& rig, const KcWheelRig& w, const Data& d) {
  KcGeometry g;
  const SE3& X = d.oMi[w.body];
  const Eigen::Matrix3d RT = rig.X_WH.R.transpose();
  g.centre = RT * (X.act_point(w.centre) - rig.X_WH.p);
  g.axis = w.outward * (RT * (X.R * w.axis));
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d down_in_plane = ez - ez.dot(g.axis) * g.axis;
  g.contact = g.centre - w.radius * down_in_plane.normalized();
  return g;
}

// the wheel's measures at the positions data holds (forward_kinematics done)
KcPoint kc_measure_at(const KcRig& rig, const KcWheelRig& w, const Data& d, const KcPoint& design) {
  const KcGeometry g = kc_geometry(rig, w, d);
  KcPoint p;
  p.wheel_centre = g.centre;
  p.contact = g.contact;
  const Eigen::Vector3d& a = g.axis;  // outward
  p.camber = std::asin(std::clamp(-a.z(), -1.0, 1.0)) * kc_deg;
  p.toe = std::atan2(a.x(), w.outward * a.y()) * kc_deg;
  if (w.kingpin) {
    const SE3& X = d.oMi[w.upright];
    Eigen::Vector3d k = rig.X_WH.R.transpose() * (X.R * (w.ball_b - w.ball_a));
    if (k.z() < 0) k = -k;
    p.caster = std::atan2(-k.x(), k.z()) * kc_deg;
    p.kingpin = std::atan2(-w.outward * k.y(), k.z()) * kc_deg;
    const Eigen::Vector3d a = rig.X_WH.inverse().act_point(X.act_point(w.ball_a));
    const Eigen::Vector3d ground = a + k * ((g.contact.z() - a.z()) / k.z());
    p.scrub_radius = w.outward * (g.contact.y() - ground.y());
    p.caster_trail = ground.x() - g.contact.x();
  } else {
    p.caster = p.kingpin = p.scrub_radius = p.caster_trail = std::numeric_limits<double>::quiet_NaN();
  }
  p.track_change = 2 * w.outward * (g.contact.y() - design.contact.y());
  p.wheelbase_change = g.contact.x() - design.contact.x();
  return p;
}

// each wheel's prescribed travel at a point: the common travel and the body roll's
double kc_wheel_travel(const KcWheelRig& w, const KcTarget& t) {
  return t.travel - w.design_y * std::tan(t.roll / kc_deg);
}

// The equilibrium's residuals at (q, lambda): G (free coordinates) = Q(q) + loads - A^T lambda,
// c = [phi(q) on the kept rows; each wheel centre's height - design - travel]; A (rows x free) when asked.
void kc_residuals(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                  const KcTarget& t, Eigen::VectorXd& G, Eigen::VectorXd* c, Eigen::MatrixXd* A) {
  const Model& m = rig.model;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv);
  forward_kinematics(m, d, q, zero);
  Eigen::VectorXd F = applied_forces(m, d, q, zero, rig.u);
  const int nr = static_cast<int>(rig.rows.size());
  const int nw = static_cast<int>(rig.wheels.size());
  Eigen::MatrixXd Afull(nr + nw, m.nv);
  Eigen::VectorXd cfull(nr + nw);
  const Eigen::RowVector3d ez_W = (rig.X_WH.R * Eigen::Vector3d::UnitZ()).transpose();
  const Eigen::Vector3d force_W = rig.X_WH.R * Eigen::Vector3d(t.fx, t.fy, 0);
  const Eigen::Vector3d torque_W = rig.X_WH.R * Eigen::Vector3d(0, 0, t.mz);
  for (int i = 0; i < nw; ++i) {
    const KcWheelRig& w = rig.wheels[static_cast<std::size_t>(i)];
    // the loads at the contact patch (held axes), on the wheel
    const KcGeometry g = kc_geometry(rig, w, d);
    if (t.fx != 0 || t.fy != 0 || t.mz != 0) {
      const Eigen::Vector3d local = d.oMi[w.body].inverse().act_point(rig.X_WH.act_point(g.contact));
      F += point_jacobian(m, d, w.body, local).transpose() * force_W;
      F += body_jacobian_world(m, d, w.body).topRows<3>().transpose() * torque_W;
    }
    Afull.row(nr + i) = ez_W * point_jacobian(m, d, w.body, w.centre);
    cfull(nr + i) = g.centre.z() - w.design_height - kc_wheel_travel(w, t);
  }
  constraint_terms(m, d, q, zero);
  for (int i = 0; i < nr; ++i) {
    Afull.row(i) = d.Jc.row(rig.rows[static_cast<std::size_t>(i)]);
    cfull(i) = d.phi(rig.rows[static_cast<std::size_t>(i)]);
  }
  const int nf = static_cast<int>(rig.free.size());
  G.resize(nf);
  const Eigen::VectorXd reaction = Afull.transpose() * lambda;
  for (int j = 0; j < nf; ++j) G(j) = F(rig.free[static_cast<std::size_t>(j)]) - reaction(rig.free[static_cast<std::size_t>(j)]);
  if (c) *c = cfull;
  if (A) {
    A->resize(nr + nw, nf);
    for (int j = 0; j < nf; ++j) A->col(j) = Afull.col(rig.free[static_cast<std::size_t>(j)]);
  }
}

Eigen::VectorXd kc_step(const KcRig& rig, const Eigen::VectorXd& q, const Eigen::VectorXd& dq_free) {
  Eigen::VectorXd dv = Eigen::VectorXd::Zero(rig.model.nv);
  for (std::size_t j = 0; j < rig.free.size(); ++j) dv(rig.free[j]) = dq_free(static_cast<Eigen::Index>(j));
  return integrate(rig.model, q, dv);
}

// [H -A^T; A 0] at (q, lambda): H = dG/dq on the free coordinates by central differences
Eigen::MatrixXd kc_tangent(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                           const KcTarget& t, const Eigen::MatrixXd& A) {
  const int nf = static_cast<int>(rig.free.size());
  const int m = static_cast<int>(A.rows());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nf + m, nf + m);
  const double h = 1e-6;
  Eigen::VectorXd Gp, Gm;
  for (int j = 0; j < nf; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(nf);
    e(j) = h;
    kc_residuals(rig, d, kc_step(rig, q, e), lambda, t, Gp, nullptr, nullptr);
    kc_residuals(rig, d, kc_step(rig, q, -e), lambda, t, Gm, nullptr, nullptr);
    K.block(0, j, nf, 1) = (Gp - Gm) / (2 * h);
  }
  K.block(0, nf, nf, m) = -A.transpose();
  K.block(nf, 0, m, nf) = A;
  return K;
}

struct KcSolved {
  Eigen::VectorXd q, lambda;
};

double kc_norm_g(const Eigen::VectorXd& G) { return G.size() ? G.lpNorm<Eigen::Infinity>() : 0.0; }

// Newton from s to the point t; false when it does not converge (left: the residual left)
bool kc_newton(const KcRig& rig, Data& d, KcSolved& s, const KcTarget& t, double& left) {
  if (rig.steer_iq >= 0) s.q(rig.steer_iq) = t.steer;
  const int nf = static_cast<int>(rig.free.size());
  Eigen::VectorXd G, c;
  Eigen::MatrixXd A;
  for (int it = 0; it < 60; ++it) {
    kc_residuals(rig, d, s.q, s.lambda, t, G, &c, &A);
    const double scale = 1.0 + s.lambda.lpNorm<Eigen::Infinity>() + std::abs(t.fx) + std::abs(t.fy) + std::abs(t.mz);
    left = std::max(c.lpNorm<Eigen::Infinity>(), kc_norm_g(G) / scale);
    if (c.lpNorm<Eigen::Infinity>() < 1e-12 && kc_norm_g(G) < 1e-9 * scale) return true;
    const Eigen::MatrixXd K = kc_tangent(rig, d, s.q, s.lambda, t, A);
    Eigen::VectorXd rhs(K.rows());
    rhs << -G, -c;
    const Eigen::VectorXd step = K.completeOrthogonalDecomposition().solve(rhs);
    if (!step.allFinite()) return false;
    // a step longer than 0.05 (m, rad) is cut: Newton's first steps off a far start
    const Eigen::VectorXd dq = step.head(nf);
    const double big = dq.size() ? dq.lpNorm<Eigen::Infinity>() : 0.0;
    const double f = big > 0.05 ? 0.05 / big : 1.0;
    s.q = kc_step(rig, s.q, f * dq);
    s.lambda += f * step.tail(step.size() - nf);
  }
  return false;
}

// The sensitivity of the equilibrium s (at the point t) to a parameter whose residual derivative
// is (dG, dc): the tangent step dq (all coordinates) with K [dq; dlambda] = -[dG; dc]
Eigen::VectorXd kc_sensitivity(const KcRig& rig, Data& d, const KcSolved& s, const KcTarget& t, const Eigen::VectorXd& dG,
                               const Eigen::VectorXd& dc) {
  Eigen::VectorXd G, c;
  Eigen::MatrixXd A;
  kc_residuals(rig, d, s.q, s.lambda, t, G, &c, &A);
  const Eigen::MatrixXd K = kc_tangent(rig, d, s.q, s.lambda, t, A);
  Eigen::VectorXd rhs(K.rows());
  rhs << -dG, -dc;
  const Eigen::VectorXd step = K.completeOrthogonalDecomposition().solve(rhs);
  Eigen::VectorXd dv = Eigen::VectorXd::Zero(rig.model.nv);
  for (std::size_t j = 0; j < rig.free.size(); ++j) dv(rig.free[j]) = step(static_cast<Eigen::Index>(j));
  return dv;
}

// d(each wheel's measures)/d(parameter) along the tangent direction dv, by central differences
std::vector<KcPoint> kc_rate(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& dv,
                             const std::vector<KcPoint>& design) {
  std::vector<KcPoint> r(rig.wheels.size());
  const double big = dv.lpNorm<Eigen::Infinity>();
  if (!(big > 0)) return r;
  const double e = 1e-5 / big;
  std::vector<KcPoint> p(r.size()), m(r.size());
  forward_kinematics(rig.model, d, integrate(rig.model, q, Eigen::VectorXd(e * dv)));
  for (std::size_t i = 0; i < r.size(); ++i) p[i] = kc_measure_at(rig, rig.wheels[i], d, design[i]);
  forward_kinematics(rig.model, d, integrate(rig.model, q, Eigen::VectorXd(-e * dv)));
  for (std::size_t i = 0; i < r.size(); ++i) m[i] = kc_measure_at(rig, rig.wheels[i], d, design[i]);
  for (std::size_t i = 0; i < r.size(); ++i) {
    r[i].camber = (p[i].camber - m[i].camber) / (2 * e);
    r[i].toe = (p[i].toe - m[i].toe) / (2 * e);
    r[i].contact = (p[i].contact - m[i].contact) / (2 * e);
    r[i].wheel_centre = (p[i].wheel_centre - m[i].wheel_centre) / (2 * e);
    r[i].track_change = (p[i].track_change - m[i].track_change) / (2 * e);
  }
  return r;
}

void kc_check_range(const KcRange& r, const std::string& option) {
  std::ostringstream text;
  text << option << " " << r.min << ":" << r.max << ":" << r.points;
  if (!std::isfinite(r.min) || !std::isfinite(r.max)) throw std::invalid_argument(text.str() + ": expected finite numbers MIN:MAX:N");
  if (!(r.min < r.max)) throw std::invalid_argument(text.str() + ": expected MIN < MAX (the range in increasing order)");
  if (r.points < 2 || r.points > 10000) throw std::invalid_argument(text.str() + ": expected a point count N from 2 to 10000");
}

std::vector<double> kc_values(const KcRange& r) {
  std::vector<double> v;
  for (int k = 0; k < r.points; ++k) v.push_back(r.min + (r.max - r.min) * k / (r.points - 1));
  return v;
}

// is body b moved through a joint that a motion input drives or a coupler couples (the steering)?
bool kc_steered(const Model& m, int b, int held, const std::vector<int>& steered_bodies) {
  for (; b > 0 && b != held; b = m.parent[b])
    if (std::find(steered_bodies.begin(), steered_bodies.end(), b) != steered_bodies.end()) return true;
  return false;
}

std::string kc_list(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? std::string("none") : s;
}

// the wheel body a --wheel value names (a body, or a tire element's body); tire: its element
std::string kc_wheel_body(const std::string& name, const ModelSpec& spec, const std::string& file) {
  for (const EffectSpec& e : spec.effects)
    if (e.type == EffectType::Tire && (e.name == name || e.body_a == name)) return e.body_a;
  std::vector<std::string> bodies;
  for (const BodySpec& b : spec.bodies) {
    if (b.name == name) return name;
    bodies.push_back(b.name);
  }
  throw std::invalid_argument("--wheel " + name + ": no body or tire element of that name in " +
                              (file.empty() ? std::string("the model") : file) + " (bodies: " + kc_list(bodies) + ")");
}

KcRig kc_make_rig(const KcRequest& r, const ModelSpec& spec_in, KcReport& report) {
  const std::string file = r.model;
  std::vector<std::string> wheel_bodies;
  if (r.wheels.empty()) {
    std::vector<std::string> tires;
    for (const EffectSpec& e : spec_in.effects)
      if (e.type == EffectType::Tire) tires.push_back(e.body_a);
    if (tires.size() != 1)
      throw std::invalid_argument("--wheel: name the wheel body or its tire element (the model has " + std::to_string(tires.size()) +
                                  " tire elements)");
    wheel_bodies = tires;
  } else {
    if (r.wheels.size() > 2) throw std::invalid_argument("--wheel: expected one wheel (a corner) or two (an axle), not " + std::to_string(r.wheels.size()));
    for (const std::string& w : r.wheels) wheel_bodies.push_back(kc_wheel_body(w, spec_in, file));
    if (wheel_bodies.size() == 2 && wheel_bodies[0] == wheel_bodies[1])
      throw std::invalid_argument("--wheel " + r.wheels[1] + ": the same wheel twice (an axle has two)");
  }
  // the full model once, for the tires' numbers; then the rig's: no gravity, no tires, no plant
  const Model full = study_model(spec_in, file);
  ModelSpec spec = spec_in;
  spec.effects.erase(std::remove_if(spec.effects.begin(), spec.effects.end(),
                                    [](const EffectSpec& e) { return e.type == EffectType::Tire || e.type == EffectType::Gravity; }),
                     spec.effects.end());
  spec.sensors.clear();
  spec.plant = PlantSpec{};
  spec.controller = ControllerSpec{};
  spec.analysis = StudySpec{};
  KcRig rig(study_model(spec, file));
  const Model& m = rig.model;
  // the held body: the root of the first wheel's tree, or the one named; every wheel hangs on it
  const int first = m.find_body(wheel_bodies[0]);
  int root = first;
  while (m.parent[root] > 0) root = m.parent[root];
  if (r.held.empty()) {
    rig.held = root;
  } else {
    rig.held = m.find_body(r.held);
    if (rig.held <= 0) throw std::invalid_argument("--held " + r.held + ": no body of that name in the model");
  }
  for (const std::string& wb : wheel_bodies) {
    const int w = m.find_body(wb);
    if (w == rig.held) throw std::invalid_argument("--held: the wheel " + wb + " itself cannot be held");
    int b = w;
    while (b > 0 && b != rig.held) b = m.parent[b];
    if (b != rig.held)
      throw std::invalid_argument((r.held.empty() ? std::string("--wheel ") + wb : "--held " + r.held) + ": the wheel " + wb +
                                  " does not hang on " + m.body_names[rig.held] + " (an ancestor in the joint tree)");
  }
  report.held = m.body_names[rig.held];
  // locked: every joint from the held body up to ground, the wheels' spins, the motions
  std::vector<bool> lock(static_cast<std::size_t>(m.nv), false);
  for (int b = rig.held; b > 0; b = m.parent[b])
    for (int k = 0; k < m.joints[b].nv; ++k) lock[static_cast<std::size_t>(m.joints[b].idx_v + k)] = true;
  std::vector<std::string> motion_names;
  for (int a : m.motions) {
    lock[static_cast<std::size_t>(m.actuators[a].iv)] = true;
    motion_names.push_back(m.actuators[a].name);
  }
  // the steer input
  if (!r.steer.empty()) {
    const int a = m.find_actuator(r.steer);
    if (a < 0 || m.actuators[a].type != ActuatorType::Motion)
      throw std::invalid_argument("--steer " + r.steer + ": no motion input of that name (motion inputs: " + kc_list(motion_names) + ")");
    rig.steer_iq = m.actuators[a].iq;
    report.steer = r.steer;
    report.steer_unit = m.actuators[a].unit;
  } else if (m.motions.size() == 1) {
    rig.steer_iq = m.actuators[m.motions[0]].iq;
    report.steer = m.actuators[m.motions[0]].name;
    report.steer_unit = m.actuators[m.motions[0]].unit;
  }
  // the holonomic rows kept
  for (int row : m.active_rows)
    if (!m.is_velocity_row(row)) rig.rows.push_back(row);
  rig.u = m.u_nominal();
  // the bodies the steering moves: through a motion's joint or a coupled joint
  std::vector<int> steered;
  const auto in_joint = [&](int b, int iv) { return m.joints[b].nv > 0 && iv >= m.joints[b].idx_v && iv < m.joints[b].idx_v + m.joints[b].nv; };
  for (int b = 1; b < m.nbodies; ++b) {
    for (int a : m.motions)
      if (in_joint(b, m.actuators[a].iv)) steered.push_back(b);
    for (const ConstraintModel& cm : m.constraints)
      if (cm.type == ConstraintType::Coupler)
        for (int k = 0; k < cm.ncoupled; ++k)
          if (in_joint(b, cm.iv[k])) steered.push_back(b);
  }
  Data d(m);
  forward_kinematics(m, d, m.q0);
  rig.X_WH = d.oMi[rig.held];
  for (const std::string& wb : wheel_bodies) {
    KcWheelRig w;
    w.body = m.find_body(wb);
    KcWheel out;
    out.name = wb;
    // centre, axis and radius: the tire's, else the spin joint's axis through its frame M
    bool have_radius = false;
    for (const TireModel& t : full.tires)
      if (full.body_names[t.body] == wb) {
        w.centre = t.center;
        w.axis = t.axis.normalized();
        w.radius = t.unloaded_radius;
        have_radius = true;
        break;
      }
    const JointModel& spin = m.joints[w.body];
    if (!have_radius) {
      if (spin.type != JointType::Revolute)
        throw std::invalid_argument("--wheel " + wb + ": expected a wheel on a revolute (spin) joint or with a tire element");
      w.centre = spin.X_CM.p;
      w.axis = spin.X_CM.R * spin.axis;
    }
    if (r.radius) {
      if (!(*r.radius > 0) || !std::isfinite(*r.radius)) throw std::invalid_argument("--radius: expected a wheel radius > 0 m");
      w.radius = *r.radius;
    } else if (!have_radius) {
      throw std::invalid_argument("--radius: the wheel " + wb + " has no tire element; give its radius (m)");
    }
    out.radius = w.radius;
    for (int k = 0; k < spin.nv; ++k) lock[static_cast<std::size_t>(spin.idx_v + k)] = true;
    w.upright = m.parent[w.body];
    // the kingpin: the upright's balls to bodies that no steering moves
    std::vector<Eigen::Vector3d> balls;
    const JointModel& uj = m.joints[w.upright];
    if (uj.type == JointType::Spherical && !kc_steered(m, uj.parent, rig.held, steered)) balls.push_back(uj.X_CM.p);
    for (int b = 1; b < m.nbodies; ++b)
      if (m.parent[b] == w.upright && m.joints[b].type == JointType::Spherical) balls.push_back(m.joints[b].X_PF.p);
    for (const ConstraintModel& cm : m.constraints) {
      if (cm.type != ConstraintType::Ball) continue;
      if (cm.body_b == w.upright && !kc_steered(m, cm.body_a, rig.held, steered)) balls.push_back(cm.point_b);
      if (cm.body_a == w.upright && !kc_steered(m, cm.body_b, rig.held, steered)) balls.push_back(cm.point_a);
    }
    if (balls.size() == 2) {
      w.kingpin = true;
      w.ball_a = balls[0];
      w.ball_b = balls[1];
    } else {
      report.notes.push_back("caster and kingpin inclination of " + wb + " not measured: its upright " + m.body_names[w.upright] + " has " +
                             std::to_string(balls.size()) + " ball joints to unsteered bodies (the kingpin needs two)");
    }
    // the design position: the model's assembled initial state
    const KcGeometry g = kc_geometry(rig, w, d);
    if (std::abs(g.centre.y()) < 1e-9)
      throw std::invalid_argument("--wheel " + wb + ": its centre is on the held body's x-z plane (y = 0): no outward side");
    w.outward = g.centre.y() > 0 ? 1 : -1;
    w.design_height = g.centre.z();
    w.design_y = g.centre.y();
    rig.wheels.push_back(w);
    report.wheels.push_back(out);
  }
  if (rig.wheels.size() == 2 && rig.wheels[0].outward == rig.wheels[1].outward)
    throw std::invalid_argument("--wheel " + wheel_bodies[1] + ": an axle's two wheels are on opposite sides of the held body (" +
                                wheel_bodies[0] + " and " + wheel_bodies[1] + " are on the same side)");
  for (int i = 0; i < m.nv; ++i) (lock[static_cast<std::size_t>(i)] ? rig.locked : rig.free).push_back(i);
  if (rig.free.empty()) throw std::invalid_argument("--wheel " + wheel_bodies[0] + ": nothing moves once the held body, the spin and the motion inputs are held");
  return rig;
}

std::string kc_value_text(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

KcRange study_kc_range(const std::string& text, const std::string& option) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
  if (parts.size() != 3) throw std::invalid_argument(option + " " + text + ": expected MIN:MAX:N");
  double x[3];
  for (int k = 0; k < 3; ++k) {
    std::size_t used = 0;
    try {
      x[k] = std::stod(parts[k], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != parts[k].size() || !std::isfinite(x[k]))
      throw std::invalid_argument(option + " " + text + ": expected MIN:MAX:N, \"" + parts[k] + "\" is not a number");
  }
  if (x[2] != std::floor(x[2])) throw std::invalid_argument(option + " " + text + ": expected a whole point count N");
  KcRange r{x[0], x[1], static_cast<int>(std::clamp(x[2], -1.0, 1e9))};
  if (!(r.min < r.max)) throw std::invalid_argument(option + " " + text + ": expected MIN < MAX (the range in increasing order)");
  if (r.points < 2 || r.points > 10000) throw std::invalid_argument(option + " " + text + ": expected a point count N from 2 to 10000");
  return r;
}

std::vector<std::string> study_kc_columns() {
  return {"sweep",       "wheel",       "travel_m",    "roll_deg",   "steer",       "Fx_N",           "Fy_N",
          "Mz_Nm",       "wheel_x_m",   "wheel_y_m",   "wheel_z_m",  "contact_x_m", "contact_y_m",    "contact_z_m",
          "camber_deg",  "toe_deg",     "caster_deg",  "kingpin_deg", "track_change_m", "wheelbase_change_m",
          "scrub_radius_m", "caster_trail_m"};
}

KcReport study_kc_job(const KcRequest& r) {
  if (r.model.empty() && !r.spec) throw std::invalid_argument("MODEL: give a model file");
  // the request first: nothing is read or solved for a request that cannot run
  if (r.travel) kc_check_range(*r.travel, "--travel");
  if (r.roll) kc_check_range(*r.roll, "--roll");
  if (r.roll && (r.roll->min <= -45 || r.roll->max >= 45)) throw std::invalid_argument("--roll: expected body roll angles within (-45, 45) deg");
  if (r.steer_range) kc_check_range(*r.steer_range, "--steer-range");
  if (r.fx) kc_check_range(*r.fx, "--fx");
  if (r.fy) kc_check_range(*r.fy, "--fy");
  if (r.mz) kc_check_range(*r.mz, "--mz");
  const ModelSpec spec = r.spec ? *r.spec : study_read_model(r.model);
  if (!r.csv.empty()) guard_output(r.csv, OutputKind::KcCsv, {r.model});
  KcReport report;
  report.model = r.model;
  const KcRig rig = kc_make_rig(r, spec, report);
  if (r.steer_range && rig.steer_iq < 0)
    throw std::invalid_argument("--steer-range: the model has no motion input to steer with (--steer names one)");
  if (r.roll && rig.wheels.size() != 2)
    throw std::invalid_argument("--roll: rolls an axle: give its two wheels (--wheel LEFT --wheel RIGHT)");
  Data d(rig.model);
  const std::size_t nw = rig.wheels.size();

  // the design point
  KcSolved design{rig.model.q0, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rig.rows.size() + nw))};
  const double steer0 = rig.steer_iq >= 0 ? rig.model.q0(rig.steer_iq) : 0.0;
  KcTarget t0;
  t0.steer = steer0;
  double left = 0;
  if (!kc_newton(rig, d, design, t0, left))
    throw ConvergenceError("kc: no static equilibrium at the design position (residual " + kc_value_text(left) +
                           "): a coordinate that no spring, bushing or constraint holds? (--wheel " + report.wheels[0].name + ")");
  std::vector<KcPoint> designs(nw);
  forward_kinematics(rig.model, d, design.q);
  for (std::size_t i = 0; i < nw; ++i) {
    KcPoint zero_ref;
    zero_ref.contact = kc_geometry(rig, rig.wheels[i], d).contact;
    designs[i] = kc_measure_at(rig, rig.wheels[i], d, zero_ref);
    designs[i].sweep = "design";
    designs[i].wheel = report.wheels[i].name;
    designs[i].steer = steer0;
    report.wheels[i].design = designs[i];
  }

  // a sweep: from the design point outwards, each point from its neighbour, a failing step halved
  auto sweep = [&](const std::string& name, const std::string& option, const KcRange& range, double base, auto set) {
    const std::vector<double> values = kc_values(range);
    std::vector<std::vector<KcPoint>> rows(values.size());
    std::size_t start = 0;
    for (std::size_t k = 1; k < values.size(); ++k)
      if (std::abs(values[k] - base) < std::abs(values[start] - base)) start = k;
    auto run = [&](int from, int to, int dir) {
      KcSolved s = design;
      double at = base;
      for (int k = from; k != to; k += dir) {
        const double goal = values[static_cast<std::size_t>(k)];
        int halvings = 0;
        double step = goal - at;
        while (at != goal) {
          const double next = std::abs(goal - at) <= std::abs(step) ? goal : at + step;
          KcSolved trial = s;
          KcTarget t = t0;
          set(t, next);
          if (kc_newton(rig, d, trial, t, left)) {
            s = trial;
            at = next;
          } else {
            if (++halvings > 12)
              throw ConvergenceError(option + " " + kc_value_text(goal) + ": the suspension cannot reach it (no static position past " +
                                     name + " " + kc_value_text(at) + ", residual " + kc_value_text(left) +
                                     "): the linkage locks or comes apart; sweep a smaller range");
            step /= 2;
          }
        }
        KcTarget t = t0;
        set(t, goal);
        forward_kinematics(rig.model, d, s.q);
        std::vector<KcPoint>& row = rows[static_cast<std::size_t>(k)];
        row.clear();
        for (std::size_t i = 0; i < nw; ++i) {
          KcPoint p = kc_measure_at(rig, rig.wheels[i], d, designs[i]);
          p.sweep = name;
          p.wheel = report.wheels[i].name;
          p.travel = t.travel;
          p.roll = t.roll;
          p.steer = t.steer;
          p.fx = t.fx;
          p.fy = t.fy;
          p.mz = t.mz;
          row.push_back(p);
        }
      }
    };
    run(static_cast<int>(start), static_cast<int>(values.size()), 1);
    run(static_cast<int>(start), -1, -1);
    for (const std::vector<KcPoint>& row : rows) report.points.insert(report.points.end(), row.begin(), row.end());
  };
  const bool any = r.travel || r.roll || r.steer_range || r.fx || r.fy || r.mz;
  if (r.travel || !any) sweep("travel", "--travel", r.travel ? *r.travel : KcRange{-0.05, 0.05, 11}, 0.0, [](KcTarget& t, double v) { t.travel = v; });
  if (r.roll) sweep("roll", "--roll", *r.roll, 0.0, [](KcTarget& t, double v) { t.roll = v; });
  if (r.steer_range) sweep("steer", "--steer-range", *r.steer_range, steer0, [](KcTarget& t, double v) { t.steer = v; });
  if (r.fx) sweep("Fx", "--fx", *r.fx, 0.0, [](KcTarget& t, double v) { t.fx = v; });
  if (r.fy) sweep("Fy", "--fy", *r.fy, 0.0, [](KcTarget& t, double v) { t.fy = v; });
  if (r.mz) sweep("Mz", "--mz", *r.mz, 0.0, [](KcTarget& t, double v) { t.mz = v; });

  // gradients at the design point: the equilibrium's linear sensitivity to travel, roll and each load
  {
    const int nf = static_cast<int>(rig.free.size());
    const int nr = static_cast<int>(rig.rows.size() + nw);
    const Eigen::VectorXd no_force = Eigen::VectorXd::Zero(nf), no_row = Eigen::VectorXd::Zero(nr);
    // travel: every wheel up (c = height - design - travel)
    Eigen::VectorXd dc = Eigen::VectorXd::Zero(nr);
    for (std::size_t i = 0; i < nw; ++i) dc(nr - static_cast<int>(nw) + static_cast<int>(i)) = -1;
    const std::vector<KcPoint> bump = kc_rate(rig, d, design.q, kc_sensitivity(rig, d, design, t0, no_force, dc), designs);
    // body roll (per rad): each wheel moves by -y phi relative to the body
    for (std::size_t i = 0; i < nw; ++i) dc(nr - static_cast<int>(nw) + static_cast<int>(i)) = rig.wheels[i].design_y;
    const std::vector<KcPoint> roll = kc_rate(rig, d, design.q, kc_sensitivity(rig, d, design, t0, no_force, dc), designs);
    Eigen::VectorXd G0, Gp;
    auto load_rate = [&](KcTarget unit) {
      kc_residuals(rig, d, design.q, design.lambda, t0, G0, nullptr, nullptr);
      unit.steer = t0.steer;
      kc_residuals(rig, d, design.q, design.lambda, unit, Gp, nullptr, nullptr);
      // the loads enter linearly at fixed q: per kN (kN m)
      return kc_rate(rig, d, design.q, kc_sensitivity(rig, d, design, t0, Gp - G0, no_row), designs);
    };
    KcTarget unit;
    unit.fy = 1000;
    const std::vector<KcPoint> fy = load_rate(unit);
    unit.fy = 0;
    unit.fx = 1000;
    const std::vector<KcPoint> fx = load_rate(unit);
    unit.fx = 0;
    unit.mz = 1000;
    const std::vector<KcPoint> mz = load_rate(unit);
    for (std::size_t i = 0; i < nw; ++i) {
      KcGradients& gr = report.wheels[i].gradients;
      gr.bump_steer = bump[i].toe;
      gr.bump_camber = bump[i].camber;
      gr.track_per_travel = bump[i].track_change;
      // the contact's lateral move over its vertical move: the swing arm's line through the centreline
      const Eigen::Vector3d& cp = designs[i].contact;
      gr.roll_centre_height = bump[i].contact.z() != 0 ? cp.y() * bump[i].contact.y() / bump[i].contact.z()
                                                       : std::numeric_limits<double>::quiet_NaN();
      gr.roll_steer = roll[i].toe / kc_deg;
      gr.roll_camber = roll[i].camber / kc_deg;
      gr.fy_steer = fy[i].toe;
      gr.fy_camber = fy[i].camber;
      gr.fx_steer = fx[i].toe;
      gr.fx_camber = fx[i].camber;
      gr.mz_steer = mz[i].toe;
      gr.mz_camber = mz[i].camber;
    }
    // an axle's roll centre: the two lines through the contacts, normal to their motion under travel
    report.roll_centre_y = report.roll_centre_z = std::numeric_limits<double>::quiet_NaN();
    if (nw == 2) {
      const Eigen::Vector2d c1(designs[0].contact.y(), designs[0].contact.z()), c2(designs[1].contact.y(), designs[1].contact.z());
      const Eigen::Vector2d d1(bump[0].contact.z(), -bump[0].contact.y()), d2(bump[1].contact.z(), -bump[1].contact.y());
      Eigen::Matrix2d M;
      M << d1, -d2;
      if (std::abs(M.determinant()) > 1e-12 * d1.norm() * d2.norm()) {
        const Eigen::Vector2d st = M.partialPivLu().solve(c2 - c1);
        report.roll_centre_y = (c1 + st(0) * d1).x();
        report.roll_centre_z = (c1 + st(0) * d1).y();
      }
    }
  }

  if (!r.csv.empty()) {
    std::ostringstream os;
    os.precision(17);
    const std::vector<std::string> cols = study_kc_columns();
    for (std::size_t k = 0; k < cols.size(); ++k) os << (k ? "," : "") << cols[k];
    os << "\n";
    for (const KcPoint& p : report.points) {
      os << p.sweep << "," << p.wheel << "," << p.travel << "," << p.roll << "," << p.steer << "," << p.fx << "," << p.fy << "," << p.mz;
      for (int k = 0; k < 3; ++k) os << "," << p.wheel_centre(k);
      for (int k = 0; k < 3; ++k) os << "," << p.contact(k);
      os << "," << p.camber << "," << p.toe << "," << p.caster << "," << p.kingpin << "," << p.track_change << ","
         << p.wheelbase_change << "," << p.scrub_radius << "," << p.caster_trail << "\n";
    }
    write_file_atomically(r.csv, os.str());
    report.written = r.csv;
  }
  return report;
}

namespace {

// a value printed with 4 decimals: a round-off residue shows as 0, not -0.0000
double kc_shown(double v) { return std::abs(v) < 5e-5 ? 0.0 : v; }

}  // namespace

std::string study_kc_text(const KcReport& r) {
  std::ostringstream os;
  char line[2048];
  os << "model    " << r.model << "\n";
  for (const KcWheel& w : r.wheels) os << "wheel    " << w.name << " (radius " << w.radius << " m)\n";
  os << "held     " << r.held;
  if (!r.steer.empty()) os << ", steer " << r.steer << (r.steer_unit.empty() ? "" : " (" + r.steer_unit + ")");
  os << "\n";
  const bool axle = r.wheels.size() > 1;
  for (const KcWheel& w : r.wheels) {
    const KcPoint& d = w.design;
    std::snprintf(line, sizeof line,
                  "design%s%s wheel centre [%.4f, %.4f, %.4f] m, contact [%.4f, %.4f, %.4f] m\n"
                  "         camber %.4f deg, toe %.4f deg, caster %.4f deg, kingpin %.4f deg\n"
                  "         scrub radius %.4f m, caster trail %.4f m\n",
                  axle ? " " : "", axle ? w.name.c_str() : "  ", kc_shown(d.wheel_centre.x()), kc_shown(d.wheel_centre.y()),
                  kc_shown(d.wheel_centre.z()), kc_shown(d.contact.x()), kc_shown(d.contact.y()), kc_shown(d.contact.z()), kc_shown(d.camber),
                  kc_shown(d.toe), kc_shown(d.caster), kc_shown(d.kingpin), kc_shown(d.scrub_radius), kc_shown(d.caster_trail));
    os << line;
  }
  std::string sweep;
  for (const KcPoint& p : r.points) {
    if (p.sweep != sweep) {
      sweep = p.sweep;
      const char* unit = sweep == "travel" ? "m" : sweep == "roll" ? "deg" : sweep == "steer" ? r.steer_unit.c_str() : sweep == "Mz" ? "N m" : "N";
      std::snprintf(line, sizeof line, "\n%s sweep (%s)\n%s%10s %9s %9s %9s %9s %11s %11s %10s\n", sweep.c_str(), unit, axle ? "wheel      " : "",
                    sweep.c_str(), "camber", "toe", "caster", "kingpin", "track_chg", "wheelb_chg", "wheel_z");
      os << line << (axle ? "           " : "") << "           (deg)     (deg)     (deg)     (deg)       (mm)        (mm)        (m)\n";
    }
    const double v = sweep == "travel" ? p.travel : sweep == "roll" ? p.roll : sweep == "steer" ? p.steer : sweep == "Fx" ? p.fx : sweep == "Fy" ? p.fy : p.mz;
    if (axle) {
      std::snprintf(line, sizeof line, "%-10s ", p.wheel.c_str());
      os << line;
    }
    std::snprintf(line, sizeof line, "%10.5g %9.4f %9.4f %9.4f %9.4f %11.4f %11.4f %10.5f\n", v, kc_shown(p.camber), kc_shown(p.toe),
                  kc_shown(p.caster), kc_shown(p.kingpin), kc_shown(p.track_change * 1e3), kc_shown(p.wheelbase_change * 1e3), p.wheel_centre.z());
    os << line;
  }
  for (const KcWheel& w : r.wheels) {
    const KcGradients& g = w.gradients;
    std::snprintf(line, sizeof line,
                  "\ngradients at design%s%s\n"
                  "  bump steer          %10.4f deg/m    bump camber   %10.4f deg/m\n"
                  "  track change        %10.4f m/m\n"
                  "  roll centre height  %10.4f m (above the contact patch; this wheel's line, a symmetric axle's)\n"
                  "  roll steer          %10.4f deg/deg  roll camber   %10.4f deg/deg (body roll, right hand about x)\n"
                  "  Fy compliance steer %10.4f deg/kN   camber        %10.4f deg/kN\n"
                  "  Fx compliance steer %10.4f deg/kN   camber        %10.4f deg/kN\n"
                  "  Mz compliance steer %10.4f deg/kN m camber        %10.4f deg/kN m\n",
                  axle ? ", " : "", axle ? w.name.c_str() : "", kc_shown(g.bump_steer), kc_shown(g.bump_camber), kc_shown(g.track_per_travel),
                  kc_shown(g.roll_centre_height), kc_shown(g.roll_steer), kc_shown(g.roll_camber), kc_shown(g.fy_steer), kc_shown(g.fy_camber),
                  kc_shown(g.fx_steer), kc_shown(g.fx_camber), kc_shown(g.mz_steer), kc_shown(g.mz_camber));
    os << line;
  }
  if (axle) {
    std::snprintf(line, sizeof line, "\naxle roll centre    y %.4f m, z %.4f m (held frame; %.4f m above the contacts' mean)\n",
                  kc_shown(r.roll_centre_y), kc_shown(r.roll_centre_z),
                  kc_shown(r.roll_centre_z - 0.5 * (r.wheels[0].design.contact.z() + r.wheels[1].design.contact.z())));
    os << line;
  }
  return os.str();
}

}  // namespace codyna
