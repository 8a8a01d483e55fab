#include "study/kc_job.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

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
  double travel = 0, steer = 0, fx = 0, fy = 0, mz = 0;
};

// the rig: the compiled model (no gravity, no tires) and what the job measures on it
struct KcRig {
  Model model;
  int wheel = 0, held = 0, upright = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // wheel body coordinates
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();   // unit, wheel body coordinates
  double radius = 0;
  SE3 X_WH;                                          // the held body's pose
  double outward = 1;                                // +1: the wheel is on the held body's left
  double design_height = 0;                          // the wheel centre's z in the held frame
  int steer_iq = -1;
  std::vector<int> free, locked;                     // tangent indices
  std::vector<int> rows;                             // the holonomic constraint rows kept
  // the kingpin's two balls: (body is the upright) points in upright coordinates
  bool kingpin = false;
  Eigen::Vector3d ball_a = Eigen::Vector3d::Zero(), ball_b = Eigen::Vector3d::Zero();
  Eigen::VectorXd u;                                 // the actuators' nominal values
};

// the wheel's geometry at the positions data holds
struct KcGeometry {
  Eigen::Vector3d centre, axis, contact;  // held frame; axis outward
};

KcGeometry kc_geometry(const KcRig& rig, const Data& d) {
  KcGeometry g;
  const SE3& X = d.oMi[rig.wheel];
  const Eigen::Matrix3d RT = rig.X_WH.R.transpose();
  g.centre = RT * (X.act_point(rig.centre) - rig.X_WH.p);
  g.axis = rig.outward * (RT * (X.R * rig.axis));
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d down_in_plane = ez - ez.dot(g.axis) * g.axis;
  g.contact = g.centre - rig.radius * down_in_plane.normalized();
  return g;
}

KcPoint kc_measure(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const KcPoint& design) {
  forward_kinematics(rig.model, d, q);
  const KcGeometry g = kc_geometry(rig, d);
  KcPoint p;
  p.wheel_centre = g.centre;
  p.contact = g.contact;
  const Eigen::Vector3d& a = g.axis;  // outward
  p.camber = std::asin(std::clamp(-a.z(), -1.0, 1.0)) * kc_deg;
  p.toe = std::atan2(a.x(), rig.outward * a.y()) * kc_deg;
  if (rig.kingpin) {
    const SE3& X = d.oMi[rig.upright];
    const Eigen::Matrix3d RT = rig.X_WH.R.transpose();
    Eigen::Vector3d k = RT * (X.R * (rig.ball_b - rig.ball_a));
    if (k.z() < 0) k = -k;
    p.caster = std::atan2(-k.x(), k.z()) * kc_deg;
    p.kingpin = std::atan2(-rig.outward * k.y(), k.z()) * kc_deg;
  } else {
    p.caster = p.kingpin = std::numeric_limits<double>::quiet_NaN();
  }
  p.track_change = 2 * rig.outward * (g.contact.y() - design.contact.y());
  p.wheelbase_change = g.contact.x() - design.contact.x();
  return p;
}

// The equilibrium's residuals at (q, lambda): G (free coordinates) = Q(q) + loads - A^T lambda,
// c = [phi(q) on the kept rows; wheel centre height - design - travel]; A (rows x free) when asked.
void kc_residuals(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                  const KcTarget& t, Eigen::VectorXd& G, Eigen::VectorXd* c, Eigen::MatrixXd* A) {
  const Model& m = rig.model;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv);
  forward_kinematics(m, d, q, zero);
  Eigen::VectorXd F = applied_forces(m, d, q, zero, rig.u);
  // the loads at the contact patch (held axes), on the wheel
  const KcGeometry g = kc_geometry(rig, d);
  const Eigen::Vector3d contact_W = rig.X_WH.act_point(g.contact);
  const Eigen::Vector3d local = d.oMi[rig.wheel].inverse().act_point(contact_W);
  const Eigen::Vector3d force_W = rig.X_WH.R * Eigen::Vector3d(t.fx, t.fy, 0);
  const Eigen::Vector3d torque_W = rig.X_WH.R * Eigen::Vector3d(0, 0, t.mz);
  F += point_jacobian(m, d, rig.wheel, local).transpose() * force_W;
  F += body_jacobian_world(m, d, rig.wheel).topRows<3>().transpose() * torque_W;
  // the constraints' rows and the travel row
  constraint_terms(m, d, q, zero);
  const int nr = static_cast<int>(rig.rows.size());
  Eigen::MatrixXd Afull(nr + 1, m.nv);
  Eigen::VectorXd cfull(nr + 1);
  for (int i = 0; i < nr; ++i) {
    Afull.row(i) = d.Jc.row(rig.rows[i]);
    cfull(i) = d.phi(rig.rows[i]);
  }
  const Eigen::RowVector3d ez_W = (rig.X_WH.R * Eigen::Vector3d::UnitZ()).transpose();
  Afull.row(nr) = ez_W * point_jacobian(m, d, rig.wheel, rig.centre);
  cfull(nr) = g.centre.z() - rig.design_height - t.travel;
  const int nf = static_cast<int>(rig.free.size());
  G.resize(nf);
  const Eigen::VectorXd reaction = Afull.transpose() * lambda;
  for (int j = 0; j < nf; ++j) G(j) = F(rig.free[j]) - reaction(rig.free[j]);
  if (c) *c = cfull;
  if (A) {
    A->resize(nr + 1, nf);
    for (int j = 0; j < nf; ++j) A->col(j) = Afull.col(rig.free[j]);
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

// Newton from `start` to the point `t`; false when it does not converge
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
    Eigen::VectorXd dq = step.head(nf);
    const double big = dq.size() ? dq.lpNorm<Eigen::Infinity>() : 0.0;
    const double f = big > 0.05 ? 0.05 / big : 1.0;
    s.q = kc_step(rig, s.q, f * dq);
    s.lambda += f * step.tail(step.size() - nf);
  }
  return false;
}

// The sensitivity of the equilibrium at s to a parameter whose residual derivative is (dG, dc):
// the tangent step dq (all coordinates) with K [dq; dlambda] = -[dG; dc]
Eigen::VectorXd kc_sensitivity(const KcRig& rig, Data& d, const KcSolved& s, const Eigen::VectorXd& dG,
                               const Eigen::VectorXd& dc) {
  Eigen::VectorXd G, c;
  Eigen::MatrixXd A;
  kc_residuals(rig, d, s.q, s.lambda, KcTarget{}, G, &c, &A);
  const Eigen::MatrixXd K = kc_tangent(rig, d, s.q, s.lambda, KcTarget{}, A);
  Eigen::VectorXd rhs(K.rows());
  rhs << -dG, -dc;
  const Eigen::VectorXd step = K.completeOrthogonalDecomposition().solve(rhs);
  Eigen::VectorXd dv = Eigen::VectorXd::Zero(rig.model.nv);
  for (std::size_t j = 0; j < rig.free.size(); ++j) dv(rig.free[j]) = step(static_cast<Eigen::Index>(j));
  return dv;
}

// d(point measures)/d(parameter) along the tangent direction dv, by central differences
KcPoint kc_rate(const KcRig& rig, Data& d, const Eigen::VectorXd& q, const Eigen::VectorXd& dv, const KcPoint& design) {
  KcPoint r;
  const double big = dv.lpNorm<Eigen::Infinity>();
  if (!(big > 0)) return r;
  const double e = 1e-5 / big;
  const KcPoint p = kc_measure(rig, d, integrate(rig.model, q, Eigen::VectorXd(e * dv)), design);
  const KcPoint m = kc_measure(rig, d, integrate(rig.model, q, Eigen::VectorXd(-e * dv)), design);
  r.camber = (p.camber - m.camber) / (2 * e);
  r.toe = (p.toe - m.toe) / (2 * e);
  r.contact = (p.contact - m.contact) / (2 * e);
  r.wheel_centre = (p.wheel_centre - m.wheel_centre) / (2 * e);
  r.track_change = (p.track_change - m.track_change) / (2 * e);
  return r;
}

void kc_check_range(const KcRange& r, const std::string& option) {
  const std::string text = option + " " + std::to_string(r.min) + ":" + std::to_string(r.max) + ":" + std::to_string(r.points);
  if (!std::isfinite(r.min) || !std::isfinite(r.max)) throw std::invalid_argument(text + ": expected finite numbers MIN:MAX:N");
  if (!(r.min < r.max)) throw std::invalid_argument(text + ": expected MIN < MAX (the range in increasing order)");
  if (r.points < 2 || r.points > 10000) throw std::invalid_argument(text + ": expected a point count N from 2 to 10000");
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

KcRig kc_make_rig(const KcRequest& r, const ModelSpec& spec_in, KcReport& report) {
  const std::string file = r.model;
  // the wheel: a body, or a tire element's body
  std::string wheel_body;
  const EffectSpec* tire = nullptr;
  std::vector<std::string> tires;
  for (const EffectSpec& e : spec_in.effects)
    if (e.type == EffectType::Tire) tires.push_back(e.name);
  if (r.wheel.empty()) {
    if (tires.size() != 1)
      throw std::invalid_argument("--wheel: name the wheel body or its tire element (the model has " + std::to_string(tires.size()) +
                                  " tire elements)");
    for (const EffectSpec& e : spec_in.effects)
      if (e.type == EffectType::Tire) tire = &e;
  } else {
    for (const EffectSpec& e : spec_in.effects)
      if (e.type == EffectType::Tire && (e.name == r.wheel || e.body_a == r.wheel)) {
        tire = &e;
        break;
      }
    if (!tire) {
      bool found = false;
      for (const BodySpec& b : spec_in.bodies) found = found || b.name == r.wheel;
      if (!found) {
        std::string names;
        for (const BodySpec& b : spec_in.bodies) names += (names.empty() ? "" : ", ") + b.name;
        throw std::invalid_argument("--wheel " + r.wheel + ": no body or tire element of that name in " +
                                    (file.empty() ? std::string("the model") : file) + " (bodies: " + names + ")");
      }
      wheel_body = r.wheel;
    }
  }
  if (tire) wheel_body = tire->body_a;
  // the full model once, for the tire's numbers; then the rig's: no gravity, no tires, no plant
  const Model full = study_model(spec_in, file);
  ModelSpec spec = spec_in;
  spec.effects.erase(std::remove_if(spec.effects.begin(), spec.effects.end(),
                                    [](const EffectSpec& e) { return e.type == EffectType::Tire || e.type == EffectType::Gravity; }),
                     spec.effects.end());
  spec.sensors.clear();
  spec.plant = PlantSpec{};
  spec.controller = ControllerSpec{};
  spec.analysis = StudySpec{};
  KcRig rig{study_model(spec, file)};
  const Model& m = rig.model;
  rig.wheel = m.find_body(wheel_body);
  report.wheel = wheel_body;
  // centre, axis and radius: the tire's, else the spin joint's axis through its frame M
  bool have_radius = false;
  for (const TireModel& t : full.tires)
    if (full.body_names[t.body] == wheel_body) {
      rig.centre = t.center;
      rig.axis = t.axis.normalized();
      rig.radius = t.unloaded_radius;
      have_radius = true;
      break;
    }
  const JointModel& spin = m.joints[rig.wheel];
  if (!have_radius) {
    if (spin.type != JointType::Revolute)
      throw std::invalid_argument("--wheel " + wheel_body + ": expected a wheel on a revolute (spin) joint or with a tire element");
    rig.centre = spin.X_CM.p;
    rig.axis = spin.X_CM.R * spin.axis;
  }
  if (r.radius) {
    if (!(*r.radius > 0) || !std::isfinite(*r.radius)) throw std::invalid_argument("--radius: expected a wheel radius > 0 m");
    rig.radius = *r.radius;
  } else if (!have_radius) {
    throw std::invalid_argument("--radius: the wheel " + wheel_body + " has no tire element; give its radius (m)");
  }
  report.radius = rig.radius;
  // the held body
  int root = rig.wheel;
  while (m.parent[root] > 0) root = m.parent[root];
  if (r.held.empty()) {
    rig.held = root;
  } else {
    rig.held = m.find_body(r.held);
    if (rig.held <= 0) throw std::invalid_argument("--held " + r.held + ": no body of that name in the model");
    int b = rig.wheel;
    while (b > 0 && b != rig.held) b = m.parent[b];
    if (b != rig.held) throw std::invalid_argument("--held " + r.held + ": not a body the wheel " + wheel_body + " hangs on (an ancestor in the joint tree)");
  }
  if (rig.held == rig.wheel) throw std::invalid_argument("--held: the wheel itself cannot be held");
  report.held = m.body_names[rig.held];
  rig.upright = m.parent[rig.wheel];
  // locked: every joint from the held body up to ground, the wheel's spin, the motions
  std::vector<bool> lock(m.nv, false);
  for (int b = rig.held; b > 0; b = m.parent[b])
    for (int k = 0; k < m.joints[b].nv; ++k) lock[m.joints[b].idx_v + k] = true;
  for (int k = 0; k < spin.nv; ++k) lock[spin.idx_v + k] = true;
  std::vector<int> motion_joints;
  std::vector<std::string> motion_names;
  for (int a : m.motions) {
    lock[m.actuators[a].iv] = true;
    motion_names.push_back(m.actuators[a].name);
  }
  for (int i = 0; i < m.nv; ++i) (lock[i] ? rig.locked : rig.free).push_back(i);
  // the steer input
  if (!r.steer.empty()) {
    const int a = m.find_actuator(r.steer);
    if (a < 0 || m.actuators[a].type != ActuatorType::Motion)
      throw std::invalid_argument("--steer " + r.steer + ": no motion input of that name (motion inputs: " +
                                  (motion_names.empty() ? std::string("none") : [&] {
                                    std::string s;
                                    for (const auto& n : motion_names) s += (s.empty() ? "" : ", ") + n;
                                    return s;
                                  }()) + ")");
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
  // the kingpin: the upright's balls to bodies that no steering moves
  std::vector<int> steered;
  for (int b = 1; b < m.nbodies; ++b) {
    for (int a : m.motions)
      if (m.joints[b].nv > 0 && m.actuators[a].iv >= m.joints[b].idx_v && m.actuators[a].iv < m.joints[b].idx_v + m.joints[b].nv)
        steered.push_back(b);
    for (const ConstraintModel& cm : m.constraints)
      if (cm.type == ConstraintType::Coupler)
        for (int k = 0; k < cm.ncoupled; ++k)
          if (m.joints[b].nv > 0 && cm.iv[k] >= m.joints[b].idx_v && cm.iv[k] < m.joints[b].idx_v + m.joints[b].nv)
            steered.push_back(b);
  }
  std::vector<Eigen::Vector3d> balls;
  const JointModel& uj = m.joints[rig.upright];
  if (uj.type == JointType::Spherical && !kc_steered(m, uj.parent, rig.held, steered)) balls.push_back(uj.X_CM.p);
  for (int b = 1; b < m.nbodies; ++b)
    if (m.parent[b] == rig.upright && m.joints[b].type == JointType::Spherical) balls.push_back(m.joints[b].X_PF.p);
  for (const ConstraintModel& cm : m.constraints) {
    if (cm.type != ConstraintType::Ball) continue;
    if (cm.body_b == rig.upright && !kc_steered(m, cm.body_a, rig.held, steered)) balls.push_back(cm.point_b);
    if (cm.body_a == rig.upright && !kc_steered(m, cm.body_b, rig.held, steered)) balls.push_back(cm.point_a);
  }
  if (balls.size() == 2) {
    rig.kingpin = true;
    rig.ball_a = balls[0];
    rig.ball_b = balls[1];
  } else {
    report.notes.push_back("caster and kingpin inclination not measured: the upright " + m.body_names[rig.upright] + " has " +
                           std::to_string(balls.size()) + " ball joints to unsteered bodies (the kingpin needs two)");
  }
  // the design position: the model's assembled initial state
  Data d(m);
  forward_kinematics(m, d, m.q0);
  rig.X_WH = d.oMi[rig.held];
  rig.outward = 1;
  const KcGeometry g = kc_geometry(rig, d);
  if (std::abs(g.centre.y()) < 1e-9)
    throw std::invalid_argument("--wheel " + wheel_body + ": its centre is on the held body's x-z plane (y = 0): no outward side");
  rig.outward = g.centre.y() > 0 ? 1 : -1;
  rig.design_height = g.centre.z();
  if (rig.free.empty()) throw std::invalid_argument("--wheel " + wheel_body + ": nothing moves once the held body, the spin and the motion inputs are held");
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
  return {"sweep",     "travel_m",   "steer",     "Fx_N",       "Fy_N",       "Mz_Nm",          "wheel_x_m",
          "wheel_y_m", "wheel_z_m",  "contact_x_m", "contact_y_m", "contact_z_m", "camber_deg",   "toe_deg",
          "caster_deg", "kingpin_deg", "track_change_m", "wheelbase_change_m"};
}

KcReport study_kc_job(const KcRequest& r) {
  if (r.model.empty() && !r.spec) throw std::invalid_argument("MODEL: give a model file");
  // the request first: nothing is read or solved for a request that cannot run
  if (r.travel) kc_check_range(*r.travel, "--travel");
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
  Data d(rig.model);

  // the design point
  KcSolved design{rig.model.q0, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rig.rows.size()) + 1)};
  const double steer0 = rig.steer_iq >= 0 ? rig.model.q0(rig.steer_iq) : 0.0;
  KcTarget t0;
  t0.steer = steer0;
  double left = 0;
  if (!kc_newton(rig, d, design, t0, left))
    throw ConvergenceError("kc: no static equilibrium at the design position (residual " + kc_value_text(left) +
                           "): a coordinate that no spring, bushing or constraint holds? (--wheel " + report.wheel + ")");
  KcPoint zero_ref;
  {
    forward_kinematics(rig.model, d, design.q);
    const KcGeometry g = kc_geometry(rig, d);
    zero_ref.contact = g.contact;
  }
  report.design = kc_measure(rig, d, design.q, zero_ref);
  report.design.sweep = "design";
  report.design.steer = steer0;

  // a sweep: from the design point outwards, each point from its neighbour, a failing step halved
  auto sweep = [&](const std::string& name, const std::string& option, const KcRange& range, double base, auto set) {
    const std::vector<double> values = kc_values(range);
    std::vector<KcPoint> rows(values.size());
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
        KcPoint p = kc_measure(rig, d, s.q, report.design);
        p.sweep = name;
        KcTarget t = t0;
        set(t, goal);
        p.travel = t.travel;
        p.steer = t.steer;
        p.fx = t.fx;
        p.fy = t.fy;
        p.mz = t.mz;
        rows[static_cast<std::size_t>(k)] = p;
      }
    };
    run(static_cast<int>(start), static_cast<int>(values.size()), 1);
    run(static_cast<int>(start), -1, -1);
    report.points.insert(report.points.end(), rows.begin(), rows.end());
  };
  const bool any = r.travel || r.steer_range || r.fx || r.fy || r.mz;
  if (r.travel || !any) sweep("travel", "--travel", r.travel ? *r.travel : KcRange{-0.05, 0.05, 11}, 0.0, [](KcTarget& t, double v) { t.travel = v; });
  if (r.steer_range) sweep("steer", "--steer-range", *r.steer_range, steer0, [](KcTarget& t, double v) { t.steer = v; });
  if (r.fx) sweep("Fx", "--fx", *r.fx, 0.0, [](KcTarget& t, double v) { t.fx = v; });
  if (r.fy) sweep("Fy", "--fy", *r.fy, 0.0, [](KcTarget& t, double v) { t.fy = v; });
  if (r.mz) sweep("Mz", "--mz", *r.mz, 0.0, [](KcTarget& t, double v) { t.mz = v; });

  // gradients at the design point: the equilibrium's linear sensitivity to travel and each load
  {
    const int nf = static_cast<int>(rig.free.size());
    const int nr = static_cast<int>(rig.rows.size()) + 1;
    Eigen::VectorXd G0, Gp, c;
    Eigen::VectorXd dc = Eigen::VectorXd::Zero(nr);
    dc(nr - 1) = -1;  // c = height - design - travel
    KcGradients& gr = report.gradients;
    const KcPoint bump = kc_rate(rig, d, design.q, kc_sensitivity(rig, d, design, Eigen::VectorXd::Zero(nf), dc), report.design);
    gr.bump_steer = bump.toe;
    gr.bump_camber = bump.camber;
    gr.track_per_travel = bump.track_change;
    // the contact's lateral move over its vertical move: the swing arm's line through the centreline
    const Eigen::Vector3d& cp = report.design.contact;
    gr.roll_centre_height = bump.contact.z() != 0 ? cp.y() * bump.contact.y() / bump.contact.z() : std::numeric_limits<double>::quiet_NaN();
    // body roll phi (right hand about x): the wheel moves by -y phi relative to the body
    gr.roll_steer = -cp.y() * bump.toe / kc_deg;
    gr.roll_camber = -cp.y() * bump.camber / kc_deg;
    auto load_rate = [&](KcTarget unit) {
      kc_residuals(rig, d, design.q, design.lambda, KcTarget{t0.travel, t0.steer, 0, 0, 0}, G0, nullptr, nullptr);
      KcTarget t = unit;
      t.steer = t0.steer;
      kc_residuals(rig, d, design.q, design.lambda, t, Gp, nullptr, nullptr);
      // the loads enter linearly at fixed q
      return kc_rate(rig, d, design.q, kc_sensitivity(rig, d, design, Gp - G0, Eigen::VectorXd::Zero(nr)), report.design);
    };
    const KcPoint fy = load_rate(KcTarget{0, 0, 0, 1000, 0});
    gr.fy_steer = fy.toe;
    gr.fy_camber = fy.camber;
    const KcPoint fx = load_rate(KcTarget{0, 0, 1000, 0, 0});
    gr.fx_steer = fx.toe;
    gr.fx_camber = fx.camber;
    const KcPoint mz = load_rate(KcTarget{0, 0, 0, 0, 1000});
    gr.mz_steer = mz.toe;
    gr.mz_camber = mz.camber;
  }

  if (!r.csv.empty()) {
    std::ostringstream os;
    os.precision(17);
    const std::vector<std::string> cols = study_kc_columns();
    for (std::size_t k = 0; k < cols.size(); ++k) os << (k ? "," : "") << cols[k];
    os << "\n";
    for (const KcPoint& p : report.points) {
      os << p.sweep << "," << p.travel << "," << p.steer << "," << p.fx << "," << p.fy << "," << p.mz;
      for (int k = 0; k < 3; ++k) os << "," << p.wheel_centre(k);
      for (int k = 0; k < 3; ++k) os << "," << p.contact(k);
      os << "," << p.camber << "," << p.toe << "," << p.caster << "," << p.kingpin << "," << p.track_change << ","
         << p.wheelbase_change << "\n";
    }
    write_file_atomically(r.csv, os.str());
    report.written = r.csv;
  }
  return report;
}

std::string study_kc_text(const KcReport& r) {
  std::ostringstream os;
  char line[2048];
  os << "model    " << r.model << "\n"
     << "wheel    " << r.wheel << " (radius " << r.radius << " m), held " << r.held;
  if (!r.steer.empty()) os << ", steer " << r.steer << (r.steer_unit.empty() ? "" : " (" + r.steer_unit + ")");
  os << "\n";
  const KcPoint& d = r.design;
  std::snprintf(line, sizeof line,
                "design   wheel centre [%.4f, %.4f, %.4f] m, contact [%.4f, %.4f, %.4f] m\n"
                "         camber %.4f deg, toe %.4f deg, caster %.4f deg, kingpin %.4f deg\n",
                d.wheel_centre.x(), d.wheel_centre.y(), d.wheel_centre.z(), d.contact.x(), d.contact.y(), d.contact.z(), d.camber,
                d.toe, d.caster, d.kingpin);
  os << line;
  std::string sweep;
  for (const KcPoint& p : r.points) {
    if (p.sweep != sweep) {
      sweep = p.sweep;
      const char* unit = sweep == "travel" ? "m" : sweep == "steer" ? r.steer_unit.c_str() : sweep == "Mz" ? "N m" : "N";
      std::snprintf(line, sizeof line, "\n%s sweep (%s)\n%10s %9s %9s %9s %9s %11s %11s %10s\n", sweep.c_str(), unit, sweep.c_str(), "camber",
                    "toe", "caster", "kingpin", "track_chg", "wheelb_chg", "wheel_z");
      os << line << "           (deg)     (deg)     (deg)     (deg)       (mm)        (mm)        (m)\n";
    }
    const double v = sweep == "travel" ? p.travel : sweep == "steer" ? p.steer : sweep == "Fx" ? p.fx : sweep == "Fy" ? p.fy : p.mz;
    std::snprintf(line, sizeof line, "%10.5g %9.4f %9.4f %9.4f %9.4f %11.4f %11.4f %10.5f\n", v, p.camber, p.toe, p.caster, p.kingpin,
                  p.track_change * 1e3, p.wheelbase_change * 1e3, p.wheel_centre.z());
    os << line;
  }
  const KcGradients& g = r.gradients;
  std::snprintf(line, sizeof line,
                "\ngradients at design\n"
                "  bump steer          %10.4f deg/m    bump camber   %10.4f deg/m\n"
                "  track change        %10.4f m/m\n"
                "  roll centre height  %10.4f m (above the contact patch; a symmetric axle's)\n"
                "  roll steer          %10.4f deg/deg  roll camber   %10.4f deg/deg (body roll, right hand about x)\n"
                "  Fy compliance steer %10.4f deg/kN   camber        %10.4f deg/kN\n"
                "  Fx compliance steer %10.4f deg/kN   camber        %10.4f deg/kN\n"
                "  Mz compliance steer %10.4f deg/kN m camber        %10.4f deg/kN m\n",
                g.bump_steer, g.bump_camber, g.track_per_travel, g.roll_centre_height, g.roll_steer, g.roll_camber, g.fy_steer,
                g.fy_camber, g.fx_steer, g.fx_camber, g.mz_steer, g.mz_camber);
  os << line;
  return os.str();
}

}  // namespace codyna
