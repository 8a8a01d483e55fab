#include "study/tire_contacts.hpp"

#include <stdexcept>

#include "dynamics/data.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/tire_effect.hpp"

namespace codyna {

std::vector<TireContactReport> study_tire_contacts(const Model& model, const Eigen::VectorXd& q,
                                                  const Eigen::VectorXd& v, const Eigen::VectorXd& s_in) {
  if (q.size() != model.nq || v.size() != model.nv)
    throw std::invalid_argument("tire contacts: q has " + std::to_string(q.size()) + " values and v " +
                                std::to_string(v.size()) + ", the model needs " + std::to_string(model.nq) + " and " +
                                std::to_string(model.nv));
  if (s_in.size() != 0 && s_in.size() != model.ns)
    throw std::invalid_argument("tire contacts: " + std::to_string(s_in.size()) + " effect states, the model has " +
                                std::to_string(model.ns));
  std::vector<TireContactReport> out;
  out.reserve(model.tires.size());
  if (model.tires.empty()) return out;
  Data d(model);
  // the deflections given, or at rest at (q, v) (effect_states_steady runs the kinematics too)
  const Eigen::VectorXd s = s_in.size() ? s_in : effect_states_steady(model, d, q, v);
  forward_kinematics(model, d, q, v);
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const TireModel& t : model.tires) {
    // the wheel's and the road's poses and velocities as the tire effect takes them (effects.cpp)
    TireContact<double> c;
    c.point.setZero();
    c.ex = Eigen::Vector3d::UnitX(), c.ey = Eigen::Vector3d::UnitY(), c.ez = Eigen::Vector3d::UnitZ();
    const bool touching = tire_contact<double>(t, d.oMi[t.body].R, d.oMi[t.body].p, angular_velocity<double>(d, t.body),
                                               point_velocity<double>(d, t.body, origin), d.oMi[t.road_body].R,
                                               d.oMi[t.road_body].p, angular_velocity<double>(d, t.road_body),
                                               point_velocity<double>(d, t.road_body, origin), c,
                                               t.state_x >= 0 || t.state_y >= 0 ? &s : nullptr);
    TireContactReport r;
    r.name = t.name;
    r.center = c.center;
    r.in_contact = touching;
    if (!touching) {
      r.point = c.center;
      out.push_back(std::move(r));
      continue;
    }
    r.point = c.point;
    r.ex = c.ex, r.ey = c.ey, r.ez = c.ez;
    r.force = c.force;
    r.moment = c.moment;
    r.Fx = c.out.Fx, r.Fy = c.out.Fy, r.Fz = c.input.Fz, r.Mz = c.out.Mz;
    r.kappa = c.input.kappa, r.alpha = c.input.alpha, r.gamma = c.input.gamma;
    r.Vx = c.Vx;
    r.penetration = c.penetration;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace codyna
