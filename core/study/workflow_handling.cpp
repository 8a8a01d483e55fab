// The study's handling numbers and its text about a steady motion: the steady body, its heading
// and speed, the handling numbers read from a linearization about the motion (study_handling, used
// by study_linearize) and their text for every front end (study_motion_text, study_handling_text).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "analysis/handling.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"
#include "study/workflow.hpp"
#include "study/workflow_detail.hpp"

namespace codyna {

using namespace workflow_detail;
namespace {

int plant_position(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// the steady body of a steady motion (its first joint on ground that is free or planar, or the named one)
int steady_body(const Model& m, const OperatingPoint& op) {
  if (!op.motion) return -1;
  const std::string& named = m.spec.analysis.steady.body;
  for (const JointMotion& jm : op.motion->joints) {
    const JointModel& j = m.joints[static_cast<std::size_t>(jm.body)];
    if (j.parent != 0 || (j.type != JointType::Free && j.type != JointType::Planar)) continue;
    if (named.empty() || m.body_names[static_cast<std::size_t>(jm.body)] == named) return jm.body;
  }
  return -1;
}

// the steady body's heading (world, in the road plane) and its centre of mass's forward speed
void steady_heading(const Model& m, const OperatingPoint& op, int body, Eigen::Vector3d& h, double& speed) {
  Data d(m);
  forward_kinematics<double>(m, d, op.q, op.v);
  const Eigen::Vector3d n = road_normal(m);
  const Eigen::Matrix3d R = d.oMi[static_cast<std::size_t>(body)].R;
  const Eigen::Vector3d a = spin_symmetry_axis(m, body);
  h = a.squaredNorm() > 0 ? Eigen::Vector3d((R * (m.joints[static_cast<std::size_t>(body)].X_CM.R * a)).cross(n))
                          : Eigen::Vector3d(R.col(0) - n.dot(R.col(0)) * n);
  h.normalize();
  speed = h.dot(point_velocity<double>(d, body, m.com[static_cast<std::size_t>(body)]));
}

// the wheelbase: between the foremost and the rearmost tire along the heading h
double tire_wheelbase(const Model& m, const OperatingPoint& op, const Eigen::Vector3d& h) {
  if (m.tires.empty()) workflow_fail(m, "handling/wheelbase", "the model has no tires to measure the wheelbase between: give it");
  Data d(m);
  forward_kinematics<double>(m, d, op.q, op.v);
  double lo = 0, hi = 0;
  for (std::size_t k = 0; k < m.tires.size(); ++k) {
    const double x = h.dot(point_position<double>(d, m.tires[k].body, m.tires[k].center));
    lo = k ? std::min(lo, x) : x;
    hi = k ? std::max(hi, x) : x;
  }
  return hi - lo;
}

// a planar joint's velocities are the world's: in body axes, dv_b = Rz(-psi0) (dv - J v0 dpsi)
// (J the quarter turn), the heading no longer reaches the velocities and a steady turn is steady;
// T_axes: the change of the state (identity without a planar joint on the way)
void planar_body_axes(const Model& m, const StudyLinearization& sl, LinearSystem* body_axes, Eigen::MatrixXd* T_axes) {
  const LinearSystem& sys = sl.lin.system;
  *body_axes = sys;
  *T_axes = Eigen::MatrixXd::Identity(sys.nx(), sys.nx());
  const CoordinatePartition& part = sl.lin.partition;
  const std::vector<int> rates = part.rates();
  const int nz = static_cast<int>(part.independent.size());
  const auto pos = [&](const std::vector<int>& v, int iv) {
    const auto it = std::find(v.begin(), v.end(), iv);
    return it == v.end() ? -1 : static_cast<int>(it - v.begin());
  };
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(sys.nx(), sys.nx());
  bool any = false;
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[static_cast<std::size_t>(b)];
    if (j.type != JointType::Planar) continue;
    const int ipsi = pos(part.independent, j.idx_v + 2), ivx = pos(rates, j.idx_v), ivy = pos(rates, j.idx_v + 1);
    if (ipsi < 0 || ivx < 0 || ivy < 0) continue;
    const double psi = sl.op.q[j.idx_q + 2];
    const Eigen::Vector2d v0(sl.op.v[j.idx_v], sl.op.v[j.idx_v + 1]);
    Eigen::Matrix2d Rt;
    Rt << std::cos(psi), std::sin(psi), -std::sin(psi), std::cos(psi);  // Rz(-psi)
    const Eigen::Vector2d Jv(-v0.y(), v0.x());
    const int rx = nz + ivx, ry = nz + ivy;
    T(rx, rx) = Rt(0, 0);
    T(rx, ry) = Rt(0, 1);
    T(ry, rx) = Rt(1, 0);
    T(ry, ry) = Rt(1, 1);
    const Eigen::Vector2d c = -Rt * Jv;
    T(rx, ipsi) = c.x();
    T(ry, ipsi) = c.y();
    any = true;
  }
  if (any) {
    *T_axes = T;
    const Eigen::MatrixXd Ti = T.inverse();
    body_axes->A = T * sys.A * Ti;
    body_axes->B = T * sys.B;
    body_axes->C = sys.C * Ti;
  }
}

// the speed held by the steady motion's other free inputs (a drive torque): their B and D columns
// (a linearization with them among the inputs, when they are not Plant/In) and the row of the
// speed's change, v^ . (dv + dw x c) in the steady body's axes (v^ its centre of mass' velocity
// direction, c the centre of mass from the joint's origin)
SpeedHold steady_speed_hold(const Model& m, const StudyLinearization& sl, int steer, int body, const Eigen::MatrixXd& T_axes) {
  const LinearSystem& sys = sl.lin.system;
  SpeedHold hold;
  std::vector<int> holders;
  const int steer_act = m.plant_inputs[static_cast<std::size_t>(steer)];
  for (const std::string& name : m.spec.analysis.free_inputs) {
    const int k = m.find_actuator(name);
    if (k >= 0 && k != steer_act) holders.push_back(k);
  }
  const JointModel& j = m.joints[static_cast<std::size_t>(body)];
  const CoordinatePartition& part = sl.lin.partition;
  const std::vector<int> rates = part.rates();
  const int nz = static_cast<int>(part.independent.size());
  const auto state_of = [&](int iv) {
    const auto it = std::find(rates.begin(), rates.end(), iv);
    return it == rates.end() ? -1 : nz + static_cast<int>(it - rates.begin());
  };
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(sys.nx());
  bool row_ok = !holders.empty();
  if (row_ok && j.type == JointType::Free) {
    const Eigen::Vector3d w = sl.op.v.segment<3>(j.idx_v), vo = sl.op.v.segment<3>(j.idx_v + 3);
    const Eigen::Vector3d c = j.X_CM.R.transpose() * (m.com[static_cast<std::size_t>(body)] - j.X_CM.p);
    const Eigen::Vector3d vc = vo + w.cross(c);
    const Eigen::Vector3d dir = vc / std::max(vc.norm(), 1e-300), cw = c.cross(dir);
    for (int a = 0; a < 3; ++a) {
      const int sv = state_of(j.idx_v + 3 + a), sw = state_of(j.idx_v + a);
      row_ok = row_ok && sv >= 0 && sw >= 0;
      if (sv >= 0) row[sv] = dir[a];
      if (sw >= 0) row[sw] = cw[a];
    }
  } else if (row_ok && j.type == JointType::Planar) {
    // body_axes' rows of the planar velocities are already in the body's axes
    const double psi = sl.op.q[j.idx_q + 2];
    const Eigen::Vector2d vw(sl.op.v[j.idx_v], sl.op.v[j.idx_v + 1]);
    const Eigen::Vector2d vb(std::cos(psi) * vw.x() + std::sin(psi) * vw.y(), -std::sin(psi) * vw.x() + std::cos(psi) * vw.y());
    const Eigen::Vector2d dir = vb / std::max(vb.norm(), 1e-300);
    const int sx = state_of(j.idx_v), sy = state_of(j.idx_v + 1);
    row_ok = sx >= 0 && sy >= 0;
    if (row_ok) row[sx] = dir.x(), row[sy] = dir.y();
  } else {
    row_ok = false;
  }
  if (row_ok) {
    Model with = m;
    for (int k : holders)
      if (std::find(with.plant_inputs.begin(), with.plant_inputs.end(), k) == with.plant_inputs.end()) with.plant_inputs.push_back(k);
    LinearizeOptions o;
    o.method = method_of_model(m);
    o.independent = m.spec.analysis.independent;
    const Linearization lw = linearize(with, sl.op, o);
    if (lw.system.state_names == sys.state_names && lw.system.A.rows() == sys.A.rows()) {
      hold.B.resize(sys.nx(), static_cast<Eigen::Index>(holders.size()));
      hold.D.resize(sys.C.rows(), static_cast<Eigen::Index>(holders.size()));
      for (std::size_t h = 0; h < holders.size(); ++h) {
        const auto at = std::find(with.plant_inputs.begin(), with.plant_inputs.end(), holders[h]) - with.plant_inputs.begin();
        hold.B.col(static_cast<Eigen::Index>(h)) = lw.system.B.col(at);
        hold.D.col(static_cast<Eigen::Index>(h)) = lw.system.D.col(at);
      }
      // in the body's axes, as body_axes (the planar velocities turned by T; B's rows alike)
      hold.B = T_axes * hold.B;
      hold.speed = row;
    }
  }
  return hold;
}

}  // namespace

HandlingNumbers workflow_detail::study_handling(const Model& m, const StudyLinearization& sl) {
  const HandlingSpec& hs = m.spec.analysis.handling;
  const LinearSystem& sys = sl.lin.system;
  const auto index = [&](const std::vector<std::string>& names, const std::string& name, const char* field, const char* what) {
    if (name.empty()) return -1;
    const int k = plant_position(names, name);
    if (k < 0) workflow_fail(m, std::string("handling/") + field, "\"" + name + "\" is not " + what + " (" + listed(names) + ")");
    return k;
  };
  if (hs.steer.empty()) workflow_fail(m, "handling/steer", "name the steer input (a Plant/In) for the handling numbers");
  if (hs.yaw_rate.empty()) workflow_fail(m, "handling/yaw_rate", "name the yaw-rate output (a Plant/Out) for the handling numbers");
  const int steer_actuator = m.find_actuator(hs.steer);
  if (steer_actuator >= 0 && plant_position(sys.input_names, hs.steer) < 0) {
    // the steer is not a Plant/In (a controller acts on brakes or a yaw moment, the steer is the
    // driver's): the numbers are the steer's all the same, from the same point linearized with it
    // as the first input
    Model with = m;
    with.plant_inputs.insert(with.plant_inputs.begin(), steer_actuator);
    StudyLinearization sl_steer = sl;
    LinearizeOptions o;
    o.method = method_of_model(m);
    o.independent = m.spec.analysis.independent;
    sl_steer.lin = linearize(with, sl.op, o);
    return study_handling(with, sl_steer);
  }
  const int steer = index(sys.input_names, hs.steer, "steer", "a Plant/In input or another actuator");
  const int yaw = index(sys.output_names, hs.yaw_rate, "yaw_rate", "a Plant/Out output");
  const int ay = index(sys.output_names, hs.lateral_acceleration, "lateral_acceleration", "a Plant/Out output");
  const int beta = index(sys.output_names, hs.sideslip, "sideslip", "a Plant/Out output");
  const int body = steady_body(m, sl.op);
  if (body < 0) workflow_fail(m, "handling", "the handling numbers need the steady body of operating point steady");
  Eigen::Vector3d h;
  double speed = 0;
  steady_heading(m, sl.op, body, h, speed);
  const double L = hs.wheelbase ? *hs.wheelbase : tire_wheelbase(m, sl.op, h);
  LinearSystem body_axes;
  Eigen::MatrixXd T_axes;
  planar_body_axes(m, sl, &body_axes, &T_axes);
  const SpeedHold hold = steady_speed_hold(m, sl, steer, body, T_axes);
  try {
    HandlingNumbers out = handling_numbers(body_axes, steer, yaw, ay, beta, speed, L, hs.steering_ratio.value_or(1.0),
                                           hold.B.cols() > 0 ? &hold : nullptr);
    for (const JointMotion& jm : sl.op.motion->joints)
      out.in_turn = out.in_turn || (jm.yaw_rate != 0 && jm.velocity.norm() < 1e9 * std::abs(jm.yaw_rate));
    return out;
  } catch (const std::invalid_argument& e) {
    workflow_fail(m, "handling", e.what());
  }
}

std::string study_motion_text(const Model& m, const OperatingPoint& op) {
  if (!op.motion) return "";
  std::ostringstream os;
  os.precision(6);
  const int body = steady_body(m, op);
  if (body >= 0) {
    Eigen::Vector3d h;
    double speed = 0;
    steady_heading(m, op, body, h, speed);
    os << m.body_names[static_cast<std::size_t>(body)] << " at " << speed << " m/s";
  }
  for (const JointMotion& jm : op.motion->joints) {
    const JointModel& j = m.joints[static_cast<std::size_t>(jm.body)];
    std::string parts;
    if (j.parent == 0 && (jm.yaw_rate != 0 || jm.velocity.squaredNorm() > 0)) {
      std::ostringstream p;
      p.precision(6);
      // a path of a radius beyond 1e9 m (a yaw rate at round-off) is straight for every purpose
      if (jm.yaw_rate == 0 || jm.velocity.norm() > 1e9 * std::abs(jm.yaw_rate)) p << "straight";
      else p << "yaw rate " << jm.yaw_rate << " rad/s (path radius " << jm.velocity.norm() / std::abs(jm.yaw_rate) << " m)";
      parts += p.str();
    }
    if (jm.spin_rate != 0) {
      std::ostringstream p;
      p.precision(6);
      p << (parts.empty() ? "" : ", ") << "spin " << jm.spin_rate << " rad/s about its axle";
      parts += p.str();
    }
    if (!parts.empty()) os << (os.tellp() ? "; " : "") << "joint " << j.name << ": " << parts;
  }
  std::vector<std::string> adv;
  for (int i : op.motion->cyclic) {
    std::ostringstream p;
    p.precision(6);
    p << m.v_names[static_cast<std::size_t>(i)] << " at " << op.motion->rates[i] << "/s";
    adv.push_back(p.str());
  }
  if (!adv.empty()) os << (os.tellp() ? "; " : "") << "advancing freely (cyclic): " << joined(adv);
  return os.str();
}

std::string study_handling_text(const HandlingNumbers& h) {
  std::ostringstream os;
  os.precision(6);
  os << "handling numbers at " << h.speed << " m/s, wheelbase " << h.wheelbase << " m";
  if (h.steering_ratio != 1.0) os << ", steering ratio " << h.steering_ratio << " (steer per road-wheel angle)";
  os << "\n"
     << "  yaw-rate gain              " << h.yaw_rate_gain << " 1/s (yaw rate per steer angle, steady state)\n"
     << "  lateral-acceleration gain  " << h.lateral_acceleration_gain << " m/s^2 per rad"
     << (h.lateral_acceleration_output ? "" : " (speed x yaw-rate gain)") << "\n";
  if (h.sideslip_given) os << "  sideslip gain              " << h.sideslip_gain << " per rad\n";
  os << "  understeer gradient        " << h.understeer_gradient << " rad/(m/s^2) = " << h.understeer_gradient_deg_per_g
     << " deg/g" << (h.steering_ratio != 1.0 ? " (road-wheel angle)" : "") << "\n";
  if (h.characteristic_speed > 0) os << "  characteristic speed       " << h.characteristic_speed << " m/s (understeer)\n";
  if (h.critical_speed > 0) os << "  critical speed             " << h.critical_speed << " m/s (oversteer)\n";
  if (h.yaw_natural_frequency > 0)
    os << "  yaw natural frequency      " << h.yaw_natural_frequency << " rad/s, damping ratio " << h.yaw_damping_ratio << "\n";
  if (h.speed_held) os << "  (the speed held by the other free inputs: constant-speed gains)\n";
  else if (h.in_turn)
    os << "  (in a turn: the gains hold the other inputs, not the speed: free a drive to hold it; they are not the constant-speed gains)\n";
  return os.str();
}

}  // namespace codyna
