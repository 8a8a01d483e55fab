// steady_motion (operating_point.hpp): the search for a steady motion. Unknowns, about the current
// iterate (the chart is re-based at each accepted step):
//   the independent coordinates' deviations, less the directions along which the motion may sit
//     anywhere (in the road plane, the heading, a symmetric body's spin angle, the coordinates
//     that advance and on which nothing depends, and those the user holds);
//   every state velocity; the free actuators' values;
//   the moving frame's numbers per joint on ground (yaw rate, the origin's velocity in the road
//     plane, a symmetric body's spin rate).
// Equations: every state rate in the moving frame is 0 (the positions' rates but those of the
// coordinates that advance, and the velocities' rates); the given speed and turn; the output
// targets. Gauss-Newton with minimum-norm steps and a Jacobian by central differences.
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "analysis/linearize.hpp"
#include "analysis/operating_point.hpp"
#include "analysis/plant_function.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "model/errors.hpp"

namespace codyna {

namespace {

std::string names_joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}

int position_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// The search's unknowns and equations about one iterate.
struct SteadySearch {
  const Model& m;
  const SteadyMotionSpec& spec;
  std::vector<std::string> independent;
  int body = 0;              // the steady body
  int motion_joint = -1;     // its entry in motion.joints
  std::vector<int> free_act; // actuator indices solved for
  std::vector<int> cyclic;   // additive coordinates that advance freely (v indices)
  std::vector<int> held;     // coordinates held by the user (v indices)
  Eigen::Vector3d n_world;

  // the iterate
  Eigen::VectorXd q, v, u_all;
  SteadyMotion motion;
  CoordinatePartition part;
  Eigen::MatrixXd basis;     // nz x nb: the free directions of the positions
  std::vector<int> rows;     // the state rows that are equations
  int nparams = 0;

  SteadySearch(const Model& model, const SteadyMotionSpec& s) : m(model), spec(s), n_world(road_normal(model)) {}

  bool on_ground(const JointMotion& jm) const { return m.joints[static_cast<std::size_t>(jm.body)].parent == 0; }
  bool spins(const JointMotion& jm) const { return jm.spin_axis.squaredNorm() > 0; }
  int params_of(const JointMotion& jm) const {
    const JointType t = m.joints[static_cast<std::size_t>(jm.body)].type;
    int k = spins(jm) ? 1 : 0;
    if (on_ground(jm)) k += t == JointType::Spherical ? 1 : 3;
    return k;
  }
  // the in-plane directions of a joint on ground (F axes)
  void plane(const JointMotion& jm, Eigen::Vector3d& e1, Eigen::Vector3d& e2) const {
    const Eigen::Vector3d n = jm.normal;
    e1 = (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY());
    e1 = (e1 - n.dot(e1) * n).normalized();
    e2 = n.cross(e1);
  }

  // the chart, the free directions and the equations' rows at the iterate
  void rebase() {
    std::vector<std::string> held_names;
    for (int i : held) held_names.push_back(m.v_names[static_cast<std::size_t>(i)]);
    part = partition_holding(m, q, held_names, independent);
    const int nz = static_cast<int>(part.independent.size());
    auto z_index = [&](int iv) {
      const auto it = std::find(part.independent.begin(), part.independent.end(), iv);
      return it == part.independent.end() ? -1 : static_cast<int>(it - part.independent.begin());
    };
    // directions the search does not move along (columns, z space)
    std::vector<Eigen::VectorXd> fixed;
    auto add_axis = [&](int iv) {
      const int k = z_index(iv);
      if (k < 0) return;
      Eigen::VectorXd e = Eigen::VectorXd::Zero(nz);
      e[k] = 1;
      fixed.push_back(e);
    };
    auto add_block = [&](int iv, const Eigen::Vector3d& d) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(nz);
      for (int c = 0; c < 3; ++c) {
        const int k = z_index(iv + c);
        if (k >= 0) e[k] = d[c];
      }
      if (e.norm() > 1e-12) fixed.push_back(e);
    };
    for (int i : held) add_axis(i);
    for (int i : cyclic) add_axis(i);
    for (const JointMotion& jm : motion.joints) {
      const JointModel& j = m.joints[static_cast<std::size_t>(jm.body)];
      const int iv = j.idx_v;
      if (j.type == JointType::Planar) {
        if (on_ground(jm))
          for (int c = 0; c < 3; ++c) add_axis(iv + c);
        continue;
      }
      Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
      const int iq = j.type == JointType::Free ? j.idx_q + 3 : j.idx_q;
      R = Eigen::Quaterniond(q[iq], q[iq + 1], q[iq + 2], q[iq + 3]).normalized().toRotationMatrix();
      if (spins(jm)) add_block(iv, jm.spin_axis);
      if (!on_ground(jm)) continue;
      add_block(iv, R.transpose() * jm.normal);
      if (j.type == JointType::Free) {
        Eigen::Vector3d e1, e2;
        plane(jm, e1, e2);
        add_block(iv + 3, R.transpose() * e1);
        add_block(iv + 3, R.transpose() * e2);
      }
    }
    if (fixed.empty()) {
      basis = Eigen::MatrixXd::Identity(nz, nz);
    } else {
      Eigen::MatrixXd F(nz, static_cast<Eigen::Index>(fixed.size()));
      for (std::size_t k = 0; k < fixed.size(); ++k) F.col(static_cast<Eigen::Index>(k)) = fixed[k];
      const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(F);
      const Eigen::MatrixXd Q = qr.householderQ();
      const Eigen::Index r = qr.rank();
      basis = Q.rightCols(nz - r);
    }
    // equations: every state row but the rates of the coordinates that advance freely
    rows.clear();
    const std::vector<int> rates = part.rates();
    for (int k = 0; k < nz; ++k)
      if (!std::count(cyclic.begin(), cyclic.end(), part.independent[static_cast<std::size_t>(k)])) rows.push_back(k);
    for (std::size_t k = 0; k < rates.size(); ++k) rows.push_back(nz + static_cast<int>(k));
    nparams = 0;
    for (const JointMotion& jm : motion.joints) nparams += params_of(jm);
  }

  int unknowns() const {
    return static_cast<int>(basis.cols()) + static_cast<int>(part.rates().size()) + static_cast<int>(free_act.size()) + nparams;
  }

  // the trial (q, v, u_all, motion) at xi, and its plant function
  struct Trial {
    Eigen::VectorXd x, u_all, u;
    SteadyMotion motion;
  };
  Trial trial(const Eigen::VectorXd& xi) const {
    Trial t;
    const int nz = static_cast<int>(part.independent.size());
    const std::vector<int> rates = part.rates();
    const int nw = static_cast<int>(rates.size()), nb = static_cast<int>(basis.cols());
    t.x = Eigen::VectorXd::Zero(nz + nw);
    t.x.head(nz) = basis * xi.head(nb);
    for (int k = 0; k < nw; ++k) t.x[nz + k] = v[rates[static_cast<std::size_t>(k)]] + xi[nb + k];
    t.u_all = u_all;
    int c = nb + nw;
    for (int a : free_act) t.u_all[a] += xi[c++];
    t.motion = motion;
    for (JointMotion& jm : t.motion.joints) {
      const JointType type = m.joints[static_cast<std::size_t>(jm.body)].type;
      if (on_ground(jm)) {
        jm.yaw_rate += xi[c++];
        if (type != JointType::Spherical) {
          Eigen::Vector3d e1, e2;
          plane(jm, e1, e2);
          if (type == JointType::Planar) {
            e1 = Eigen::Vector3d::UnitX();
            e2 = Eigen::Vector3d::UnitY();
          }
          jm.velocity += xi[c] * e1 + xi[c + 1] * e2;
          c += 2;
        }
      }
      if (spins(jm)) jm.spin_rate += xi[c++];
    }
    t.u.resize(static_cast<Eigen::Index>(m.plant_inputs.size()));
    for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) t.u[static_cast<Eigen::Index>(k)] = t.u_all[m.plant_inputs[k]];
    return t;
  }

  // the motion's reference rates kept by the frame: the coordinates that advance move at their rate
  void keep_cyclic_rates(SteadyMotion& mo, const Eigen::VectorXd& vv) const {
    mo.rates = Eigen::VectorXd::Zero(m.nv);
    for (int i : cyclic) mo.rates[i] = vv[i];
  }

  // the speed and turn of the steady body at (q, v): forward speed of its centre of mass, the
  // speed in the road plane
  void body_motion(const Eigen::VectorXd& qq, const Eigen::VectorXd& vv, double& forward, double& planar) const {
    Data d(m);
    forward_kinematics<double>(m, d, qq, vv);
    const std::size_t b = static_cast<std::size_t>(body);
    const Eigen::Vector3d vc = point_velocity<double>(d, body, m.com[b]);
    const Eigen::Matrix3d R = d.oMi[b].R;
    const JointMotion& jm = motion.joints[static_cast<std::size_t>(motion_joint)];
    Eigen::Vector3d h;
    if (spins(jm)) {
      const Eigen::Vector3d a = R * (m.joints[b].X_CM.R * jm.spin_axis);
      h = a.cross(n_world);
    } else {
      h = R.col(0) - n_world.dot(R.col(0)) * n_world;
    }
    h = h.norm() > 1e-12 ? Eigen::Vector3d(h.normalized()) : Eigen::Vector3d::Zero();
    forward = h.dot(vc);
    planar = (vc - n_world.dot(vc) * n_world).norm();
  }

  // the residual at xi (and, when asked, the state rates' part alone and the plant's outputs)
  Eigen::VectorXd residual(const Eigen::VectorXd& xi, double* rates_left = nullptr, double* extra_left = nullptr) const {
    Trial t = trial(xi);
    PlantFunction f(m, q, t.u_all, part);
    Eigen::VectorXd qq, vv;
    f.state_to_qv(t.x, qq, vv);
    keep_cyclic_rates(t.motion, vv);
    const SteadyMotion& mo = t.motion;
    f.set_motion(mo);
    Eigen::VectorXd xd, y;
    f.eval<double>(t.x, t.u, xd, y);
    const int nrows = static_cast<int>(rows.size());
    std::vector<double> extra;
    double forward = 0, planar = 0;
    body_motion(qq, vv, forward, planar);
    const JointMotion& jm = mo.joints[static_cast<std::size_t>(motion_joint)];
    if (spec.speed) extra.push_back(forward - *spec.speed);
    if (spec.yaw_rate) extra.push_back(jm.yaw_rate - *spec.yaw_rate);
    else if (spec.radius) extra.push_back(jm.yaw_rate * *spec.radius - planar);
    else if (spec.lateral_acceleration) extra.push_back(jm.yaw_rate * planar - *spec.lateral_acceleration);
    else extra.push_back(jm.yaw_rate);  // straight
    std::vector<std::string> out_names;
    for (int k : m.plant_outputs) out_names.push_back(m.sensors[static_cast<std::size_t>(k)].name);
    for (const auto& [name, value] : spec.outputs) extra.push_back(y[position_of(out_names, name)] - value);
    Eigen::VectorXd r(nrows + static_cast<Eigen::Index>(extra.size()));
    for (int k = 0; k < nrows; ++k) r[k] = xd[rows[static_cast<std::size_t>(k)]];
    for (std::size_t k = 0; k < extra.size(); ++k) r[nrows + static_cast<Eigen::Index>(k)] = extra[k];
    if (rates_left) *rates_left = nrows ? r.head(nrows).lpNorm<Eigen::Infinity>() : 0.0;
    if (extra_left) *extra_left = extra.empty() ? 0.0 : r.tail(static_cast<Eigen::Index>(extra.size())).lpNorm<Eigen::Infinity>();
    return r;
  }

  // moves the iterate to xi
  void accept(const Eigen::VectorXd& xi) {
    Trial t = trial(xi);
    // a motion input's coordinate is where its value puts it (the plant function reads the value;
    // the operating point's q must say the same: the steering wheel turned by the steer found)
    for (int k : m.motions) q[m.actuators[static_cast<std::size_t>(k)].iq] = t.u_all[k];
    PlantFunction f(m, q, t.u_all, part);
    f.state_to_qv(t.x, q, v);
    normalize(m, q);
    u_all = t.u_all;
    motion = t.motion;
    keep_cyclic_rates(motion, v);
    // the frame's origins follow the joints
    for (JointMotion& jm : motion.joints) {
      const JointModel& j = m.joints[static_cast<std::size_t>(jm.body)];
      if (j.type == JointType::Free) jm.origin = q.segment<3>(j.idx_q);
      if (j.type == JointType::Planar) jm.origin = Eigen::Vector3d(q[j.idx_q], q[j.idx_q + 1], 0.0);
    }
  }
};

}  // namespace

namespace {
OperatingPoint steady_motion_search(const Model& model, const OperatingPoint& start, const SteadyMotionSpec& spec,
                                    const std::vector<std::string>& independent);
}  // namespace

OperatingPoint steady_motion(const Model& model, const OperatingPoint& start, const SteadyMotionSpec& spec,
                             const std::vector<std::string>& independent) {
  if (model.ns == 0) return steady_motion_search(model, start, spec, independent);
  // Effect states (a tire's transient slip) rest where their rates vanish, and there the forces are
  // those of the same model without them (the deflections carry the steady slips): the search
  // runs on that model, whose Jacobian sees how the forces follow the slips (with the states held
  // fixed they would not, and Newton could walk to a wheel turned across the road); the states
  // are at rest at the motion found (OperatingPoint::s left empty)
  return steady_motion_search(without_effect_states(model), start, spec, independent);
}

namespace {
OperatingPoint steady_motion_search(const Model& model, const OperatingPoint& start, const SteadyMotionSpec& spec,
                                    const std::vector<std::string>& independent) {
  SteadySearch S(model, spec);
  S.independent = independent;
  S.q = start.q;
  S.v = start.v;
  S.u_all = start.u;
  S.motion = motion_of_state(model, start.q, start.v);
  // the steady body: named, or the first on a free or planar joint to ground
  for (std::size_t k = 0; k < S.motion.joints.size(); ++k) {
    const JointMotion& jm = S.motion.joints[k];
    const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
    const bool candidate = j.parent == 0 && (j.type == JointType::Free || j.type == JointType::Planar);
    const bool named = !spec.body.empty() && model.body_names[static_cast<std::size_t>(jm.body)] == spec.body;
    if ((named && candidate) || (spec.body.empty() && candidate && S.motion_joint < 0)) {
      S.motion_joint = static_cast<int>(k);
      S.body = jm.body;
    }
  }
  if (S.motion_joint < 0) {
    std::vector<std::string> candidates;
    for (const JointMotion& jm : S.motion.joints) {
      const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
      if (j.parent == 0 && (j.type == JointType::Free || j.type == JointType::Planar))
        candidates.push_back(model.body_names[static_cast<std::size_t>(jm.body)]);
    }
    if (!spec.body.empty() && position_of(model.body_names, spec.body) < 0)
      throw std::invalid_argument("steady: unknown body \"" + spec.body + "\" (bodies on a free or planar joint to ground: " +
                                  names_joined(candidates) + ")");
    throw std::invalid_argument("steady: " + (spec.body.empty() ? std::string("the model has no body") : "body \"" + spec.body + "\" is not a body") +
                                " on a free or planar joint to ground, whose speed and turn a steady motion gives (bodies there: " +
                                names_joined(candidates) + ")");
  }
  int turn_given = 0;
  for (const auto& o : {spec.yaw_rate, spec.radius, spec.lateral_acceleration}) turn_given += o.has_value();
  if (turn_given > 1) throw std::invalid_argument("steady: give one of yaw_rate, radius and lateral_acceleration, not " + std::to_string(turn_given));
  if (spec.radius && (!std::isfinite(*spec.radius) || std::abs(*spec.radius) < 1e-9))
    throw std::invalid_argument("steady: radius " + std::to_string(*spec.radius) + ": expected a finite radius, not 0 (> 0 turns left, < 0 right)");
  for (const auto& o : {spec.speed, spec.yaw_rate, spec.lateral_acceleration})
    if (o && !std::isfinite(*o)) throw std::invalid_argument("steady: a speed, yaw rate or lateral acceleration is not finite");
  // free actuators (any actuator; default: Plant/In)
  std::vector<std::string> act_names;
  for (const ActuatorModel& a : model.actuators) act_names.push_back(a.name);
  if (spec.free_inputs.empty()) {
    S.free_act = model.plant_inputs;
  } else {
    for (const std::string& name : spec.free_inputs) {
      const int k = position_of(act_names, name);
      if (k < 0) throw std::invalid_argument("steady: free input \"" + name + "\" is not an actuator (" + names_joined(act_names) + ")");
      if (!std::count(S.free_act.begin(), S.free_act.end(), k)) S.free_act.push_back(k);
    }
  }
  for (const std::string& name : spec.held) {
    const int i = position_of(model.v_names, name);
    if (i < 0) throw std::invalid_argument("steady: held coordinate \"" + name + "\" is unknown (" + names_joined(model.v_names) + ")");
    S.held.push_back(i);
  }
  std::vector<std::string> out_names;
  for (int k : model.plant_outputs) out_names.push_back(model.sensors[static_cast<std::size_t>(k)].name);
  for (const auto& [name, value] : spec.outputs) {
    if (position_of(out_names, name) < 0)
      throw std::invalid_argument("steady: output \"" + name + "\" is not in Plant/Out (" + names_joined(out_names) + ")");
    if (!std::isfinite(value)) throw std::invalid_argument("steady: the value of output \"" + name + "\" is not finite");
  }
  // the coordinates that advance freely: additive ones (not of the frame's joints) on which the
  // velocities' rates do not depend at the start (a wheel's spin angle, a cart's position)
  {
    const CoordinatePartition p0 = partition_coordinates(model, S.q, independent);
    const PlantFunction f(model, S.q, S.u_all, p0);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), u(f.nu());
    for (int k = 0; k < f.nw(); ++k) x[f.nz() + k] = S.v[f.rates()[static_cast<std::size_t>(k)]];
    for (int k = 0; k < f.nu(); ++k) u[k] = S.u_all[model.plant_inputs[static_cast<std::size_t>(k)]];
    const Eigen::MatrixXd J = plant_jacobian(f, x, u, JacobianMethod::Exact);
    const Eigen::MatrixXd K = J.block(f.nz(), 0, f.nw(), f.nz());
    const double scale = K.size() ? std::max(K.cwiseAbs().maxCoeff(), 1e-300) : 1.0;
    for (int k = 0; k < f.nz(); ++k) {
      const int iv = p0.independent[static_cast<std::size_t>(k)];
      bool of_frame = false;
      for (const JointMotion& jm : S.motion.joints) {
        const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
        of_frame |= iv >= j.idx_v && iv < j.idx_v + j.nv;
      }
      if (of_frame || std::count(S.held.begin(), S.held.end(), iv)) continue;
      if (K.rows() == 0 || K.col(k).cwiseAbs().maxCoeff() <= 1e-11 * scale) S.cyclic.push_back(iv);
    }
  }
  S.keep_cyclic_rates(S.motion, S.v);
  OperatingPoint op = start;
  op.kind = "steady";
  double rates_left = 0, extra_left = 0;
  for (op.iterations = 0; op.iterations < 80; ++op.iterations) {
    S.rebase();
    const int n = S.unknowns();
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd r = S.residual(zero, &rates_left, &extra_left);
    if (rates_left < 1e-11 && extra_left < 1e-11) break;
    Eigen::MatrixXd J(r.size(), n);
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6;
      Eigen::VectorXd xp = zero, xm = zero;
      xp[k] = h;
      xm[k] = -h;
      J.col(k) = (S.residual(xp) - S.residual(xm)) / (2 * h);
    }
    const Eigen::VectorXd step = -Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(J).solve(r);
    bool moved = false;
    double t = 1.0;
    for (int k = 0; k < 30 && !moved; ++k, t *= 0.5) {
      try {
        const Eigen::VectorXd rn = S.residual(t * step);
        if (!rn.allFinite() || !(rn.norm() < r.norm())) continue;
        S.accept(t * step);
        moved = true;
      } catch (const std::exception&) {
        continue;  // no chart or no assembly there: a shorter step
      }
    }
    if (!moved) break;
  }
  S.rebase();
  S.residual(Eigen::VectorXd::Zero(S.unknowns()), &rates_left, &extra_left);
  op.q = S.q;
  op.v = S.v;
  op.u = S.u_all;
  op.residual = rates_left;
  op.motion = S.motion;
  double target_scale = 1.0;
  for (const auto& o : {spec.speed, spec.yaw_rate, spec.radius, spec.lateral_acceleration})
    if (o) target_scale = std::max(target_scale, std::abs(*o));
  if (!(rates_left < 1e-8) || !(extra_left < 1e-8 * target_scale)) {
    std::vector<std::string> free_names, fixed_inputs;
    for (int a : S.free_act) free_names.push_back(act_names[static_cast<std::size_t>(a)]);
    for (const std::string& a : act_names)
      if (!std::count(free_names.begin(), free_names.end(), a)) fixed_inputs.push_back(a);
    std::ostringstream os;
    os << "steady: no steady motion found: the rates left in the moving frame are " << rates_left
       << " (tolerance 1e-08), the speed, turn and output targets off by " << extra_left << " after " << op.iterations
       << " iterations; free inputs " << names_joined(free_names)
       << " (free another actuator that can hold the motion, e.g. a drive torque against the tires' drag: "
       << names_joined(fixed_inputs) << "; or ask for a slower or wider turn)";
    throw ConvergenceError(os.str());
  }
  return op;
}
}  // namespace

}  // namespace codyna
