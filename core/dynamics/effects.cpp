#include "dynamics/effects.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/sensors.hpp"
#include "dynamics/tire_effect.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

EffectCounters& effect_counters() {
  static thread_local EffectCounters counters;
  return counters;
}

namespace {
// adds a world force F at point p (body coordinates) and a world torque T to body's fext
template <class S>
void add_world_force(DataT<S>& d, int body, const Eigen::Vector3d& p, const Vec3T<S>& F, const Vec3T<S>& T) {
  if (body == 0) return;  // ground reacts; it does not move
  const Mat3T<S> Rt = d.oMi[body].R.transpose();
  const Vec3T<S> f = Rt * F;
  d.fext[body].template tail<3>() += f;
  d.fext[body].template head<3>() += p.cast<S>().cross(f) + Rt * T;
}
// adds a world force F at the world point x and a world torque T to body's fext
template <class S>
void tire_effect_add_wrench(DataT<S>& d, int body, const Vec3T<S>& x, const Vec3T<S>& F, const Vec3T<S>& T) {
  if (body == 0) return;
  const Mat3T<S> Rt = d.oMi[body].R.transpose();
  const Vec3T<S> f = Rt * F;
  const Vec3T<S> xl = Rt * Vec3T<S>(x - d.oMi[body].p);
  d.fext[body].template tail<3>() += f;
  d.fext[body].template head<3>() += xl.cross(f) + Rt * T;
}

// a body's pose and velocity, every entry with one derivative size (no-op for double)
template <class S>
struct TireEffectBody {
  Mat3T<S> R;
  Vec3T<S> p, w, v;
};
template <class S>
TireEffectBody<S> tire_effect_body(const DataT<S>& d, int body) {
  return {d.oMi[body].R, d.oMi[body].p, angular_velocity<S>(d, body), point_velocity<S>(d, body, Eigen::Vector3d::Zero())};
}
}  // namespace

template <class S>
const VecXT<S>& applied_forces(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v,
                               const VecXT<S>& u) {
  using std::sqrt;
  EffectCounters& count = effect_counters();
  d.Q.setZero(model.nv);
  bool any_body_force = false;
  for (auto& f : d.fext) f.setZero();
  const Vec3T<S> zero3 = Vec3T<S>::Zero();

  for (const SpringDamperModel& s : model.springs) {
    ++count.springs;
    const Vec3T<S> dp = point_position<S>(d, s.body_b, s.point_b) - point_position<S>(d, s.body_a, s.point_a);
    const S L = sqrt(dp.squaredNorm());
    if (!(ad_value(L) > 1e-12)) {
      // coincident points: no direction. With rest length 0 the elastic force k (L - 0) n = k dp
      // is smooth through them and is applied (its derivative is k: exact and differences agree);
      // otherwise, and for the damping term c (n . v) n, there is no force (linearize refuses
      // such a point: spring_damper_singularity)
      if (s.rest_length == 0.0 && s.stiffness != 0.0) {
        add_world_force<S>(d, s.body_a, s.point_a, Vec3T<S>(S(s.stiffness) * dp), zero3);
        add_world_force<S>(d, s.body_b, s.point_b, Vec3T<S>(-S(s.stiffness) * dp), zero3);
        any_body_force = true;
      }
      continue;
    }
    const Vec3T<S> n = dp / L;
    const S Ld = n.dot(point_velocity<S>(d, s.body_b, s.point_b) - point_velocity<S>(d, s.body_a, s.point_a));
    const S tension = S(s.stiffness) * (L - S(s.rest_length)) + S(s.damping) * Ld;
    add_world_force<S>(d, s.body_a, s.point_a, Vec3T<S>(tension * n), zero3);
    add_world_force<S>(d, s.body_b, s.point_b, Vec3T<S>(-tension * n), zero3);
    any_body_force = true;
  }
  for (const JointSpringModel& s : model.joint_springs) {
    ++count.joint_springs;
    d.Q[s.iv] -= S(s.stiffness) * (q[s.iq] - S(s.rest_position)) + S(s.damping) * v[s.iv];
  }
  for (const JointSpringModel& s : model.joint_frictions) {
    ++count.joint_frictions;
    d.Q[s.iv] -= S(s.damping) * v[s.iv];
  }
  for (const BodyForceModel& b : model.body_forces) {
    ++count.body_forces;
    Vec3T<S> F = b.force.cast<S>(), T = b.torque.cast<S>();
    if (!b.in_world) {
      F = d.oMi[b.body].R * F;
      T = d.oMi[b.body].R * T;
    }
    add_world_force<S>(d, b.body, b.point, F, T);
    any_body_force = true;
  }
  for (const BushingModel& b : model.bushings) {
    // frame A on body_a, frame B on body_b; B's displacement, small rotation and velocities in A's axes
    const Mat3T<S> RA = d.oMi[b.body_a].R * b.X_a.R.cast<S>(), RB = d.oMi[b.body_b].R * b.X_b.R.cast<S>();
    const Vec3T<S> xA = point_position<S>(d, b.body_a, b.X_a.p), xB = point_position<S>(d, b.body_b, b.X_b.p);
    const Mat3T<S> Rrel = RA.transpose() * RB;
    const Vec3T<S> wa = angular_velocity<S>(d, b.body_a), wb = angular_velocity<S>(d, b.body_b);
    // the velocity of B's origin less that of the point of body_a it passes
    const Vec3T<S> va = point_velocity<S>(d, b.body_a, b.X_a.p) + wa.cross(Vec3T<S>(xB - xA));
    const Vec3T<S> dist = RA.transpose() * (xB - xA), vel = RA.transpose() * (point_velocity<S>(d, b.body_b, b.X_b.p) - va);
    const Vec3T<S> wrel = RA.transpose() * (wb - wa);
    Vec3T<S> F, T;
    for (int k = 0; k < 3; ++k) {
      const S theta = rotation_about_axis<S>(Rrel, Eigen::Vector3d::Unit(k));
      F[k] = -(S(b.kt[k]) * dist[k] + S(b.ct[k]) * vel[k]);
      T[k] = -(S(b.kr[k]) * theta + S(b.cr[k]) * wrel[k]);
    }
    const Vec3T<S> Fw = RA * F, Tw = RA * T;
    add_world_force<S>(d, b.body_b, b.X_b.p, Fw, Tw);  // on B at its origin, the reaction on A at the same point
    add_world_force<S>(d, b.body_a, b.X_a.p, Vec3T<S>(-Fw), Vec3T<S>(-(Tw + Vec3T<S>(xB - xA).cross(Fw))));
    any_body_force = true;
  }
  if (d.sdot.size() != model.ns) d.sdot.resize(model.ns);
  if (d.s.size() != model.ns) d.s = VecXT<S>::Zero(model.ns);
  for (const TireModel& t : model.tires) {
    ++count.tires;
    TireEffectBody<S> wb = tire_effect_body<S>(d, t.body), rb = tire_effect_body<S>(d, t.road_body);
    const bool lag = t.state_x >= 0 || t.state_y >= 0;
    if constexpr (!std::is_same_v<S, double>) {
      // the ground's constants with the wheel's derivative size (and the effect states likewise)
      Eigen::Index n = 0;
      for (TireEffectBody<S>* b : {&wb, &rb})
        n = std::max({n, ad_size(b->R), ad_size(b->p), ad_size(b->w), ad_size(b->v)});
      if (lag) n = std::max(n, ad_size(d.s));
      for (TireEffectBody<S>* b : {&wb, &rb}) {
        ad_make_coherent(b->R, n);
        ad_make_coherent(b->p, n);
        ad_make_coherent(b->w, n);
        ad_make_coherent(b->v, n);
      }
      if (lag) ad_make_coherent(d.s, n);
    }
    TireContact<S> c;
    const bool touches = tire_contact<S>(t, wb.R, wb.p, wb.w, wb.v, rb.R, rb.p, rb.w, rb.v, c, lag ? &d.s : nullptr);
    if (t.state_x >= 0) d.sdot[t.state_x] = c.rate_x;
    if (t.state_y >= 0) d.sdot[t.state_y] = c.rate_y;
    if (!touches) continue;
    tire_effect_add_wrench<S>(d, t.body, c.point, c.force, c.moment);
    tire_effect_add_wrench<S>(d, t.road_body, c.point, Vec3T<S>(-c.force), Vec3T<S>(-c.moment));
    any_body_force = true;
  }
  for (int k = 0; k < model.nu(); ++k) {
    ++count.actuators;
    const ActuatorModel& a = model.actuators[k];
    if (a.type == ActuatorType::Mix) continue;  // acts through the actuators it drives
    if (a.type == ActuatorType::Motion) continue;  // prescribes its coordinate (forward_dynamics)
    S input = u[k];
    // (each product evaluated into an S before the sum: an unevaluated autodiff product of a
    // constant input, whose derivatives are empty, beside a variable's loses the derivatives)
    for (const auto& [mix, weight] : a.driven_by) {
      const S term = S(weight) * u[mix];
      input = input + term;
    }
    const S value = S(a.gain) * input;
    if (a.type == ActuatorType::JointForce) {
      d.Q[a.iv] += value;
    } else if (a.type == ActuatorType::LineForce) {
      // along the line from a to b, pushing the points apart for value > 0; no direction where they meet
      const Vec3T<S> dp = point_position<S>(d, a.body_b, a.point_b) - point_position<S>(d, a.body, a.point);
      const S L = sqrt(dp.squaredNorm());
      if (!(ad_value(L) > 1e-12)) continue;
      const Vec3T<S> F = dp / L * value;
      add_world_force<S>(d, a.body, a.point, Vec3T<S>(-F), zero3);
      add_world_force<S>(d, a.body_b, a.point_b, F, zero3);
      any_body_force = true;
    } else if (a.type == ActuatorType::BodyTorque) {
      Vec3T<S> T = a.direction.cast<S>() * value;
      if (!a.in_world) T = d.oMi[a.body].R * T;
      add_world_force<S>(d, a.body, Eigen::Vector3d::Zero(), zero3, T);
      any_body_force = true;
    } else {
      Vec3T<S> F = a.direction.cast<S>() * value;
      if (!a.in_world) F = d.oMi[a.body].R * F;
      add_world_force<S>(d, a.body, a.point, F, zero3);
      any_body_force = true;
    }
  }
  if (any_body_force) add_body_forces_to_generalized<S>(model, d, d.Q);
  return d.Q;
}

Eigen::VectorXd effect_states_steady(const Model& model, DataT<double>& d, const Eigen::VectorXd& q,
                                     const Eigen::VectorXd& v) {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(model.ns);
  if (model.ns == 0) return s;
  forward_kinematics<double>(model, d, q, v);
  for (const TireModel& t : model.tires) {
    if (t.state_x < 0 && t.state_y < 0) continue;
    const TireEffectBody<double> wb = tire_effect_body<double>(d, t.body), rb = tire_effect_body<double>(d, t.road_body);
    TireContact<double> c;
    if (!tire_contact<double>(t, wb.R, wb.p, wb.w, wb.v, rb.R, rb.p, rb.w, rb.v, c)) continue;  // off the road: 0
    // du/dt = 0: the deflections whose slips are the steady ones
    if (t.state_x >= 0) s[t.state_x] = c.sigma_x * c.input.kappa;
    if (t.state_y >= 0) s[t.state_y] = c.sigma_y * std::tan(c.input.alpha);
  }
  return s;
}

Model without_effect_states(const Model& model) {
  Model m = model;
  for (TireModel& t : m.tires) {
    t.relaxation_x = t.relaxation_y = 0;
    t.state_x = t.state_y = -1;
  }
  m.ns = 0;
  m.s_names.clear();
  m.s_units.clear();
  return m;
}

template const VecXT<double>& applied_forces<double>(const Model&, DataT<double>&, const VecXT<double>&,
                                                     const VecXT<double>&, const VecXT<double>&);
template const VecXT<ADScalar>& applied_forces<ADScalar>(const Model&, DataT<ADScalar>&, const VecXT<ADScalar>&,
                                                         const VecXT<ADScalar>&, const VecXT<ADScalar>&);

}  // namespace codyna
