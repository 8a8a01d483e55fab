#include "analysis/steady_motion.hpp"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "spatial/autodiff.hpp"

namespace codyna {

bool SteadyMotion::turns() const {
  for (const JointMotion& j : joints)
    if (j.yaw_rate != 0.0 || j.spin_rate != 0.0) return true;
  return false;
}

Eigen::Vector3d road_normal(const Model& model) {
  if (model.has_gravity && model.gravity.norm() > 0) return -model.gravity.normalized();
  return Eigen::Vector3d::UnitZ();
}

namespace {

// the rotation R of a joint's M frame in its F frame, and the origin p (F axes)
void joint_pose(const JointModel& j, const Eigen::VectorXd& q, Eigen::Matrix3d& R, Eigen::Vector3d& p) {
  const int iq = j.idx_q;
  R.setIdentity();
  p.setZero();
  if (j.type == JointType::Free) {
    p = q.segment<3>(iq);
    R = Eigen::Quaterniond(q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]).normalized().toRotationMatrix();
  } else if (j.type == JointType::Spherical) {
    R = Eigen::Quaterniond(q[iq], q[iq + 1], q[iq + 2], q[iq + 3]).normalized().toRotationMatrix();
  } else if (j.type == JointType::Planar) {
    p = Eigen::Vector3d(q[iq], q[iq + 1], 0.0);
    R = Eigen::AngleAxisd(q[iq + 2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
}

void put_rotation(const JointModel& j, const Eigen::Matrix3d& R, Eigen::VectorXd& q) {
  const Eigen::Quaterniond r(R);
  const int i = j.type == JointType::Free ? j.idx_q + 3 : j.idx_q;
  q[i] = r.w();
  q[i + 1] = r.x();
  q[i + 2] = r.y();
  q[i + 3] = r.z();
}

bool axisymmetric(const Eigen::Matrix3d& I, const Eigen::Vector3d& a) {
  const double scale = std::max(I.norm(), 1e-300);
  const double Ia = a.dot(I * a);
  if ((I * a - Ia * a).norm() > 1e-9 * scale) return false;
  // on the plane normal to a: a multiple of the identity
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - a * a.transpose();
  const Eigen::Matrix3d Ip = P * I * P;
  const double mu = 0.5 * Ip.trace();
  return (Ip - mu * P).norm() <= 1e-9 * scale;
}

}  // namespace

Eigen::Vector3d spin_symmetry_axis(const Model& model, int body) {
  const JointModel& j = model.joints[static_cast<std::size_t>(body)];
  if (j.type != JointType::Free && j.type != JointType::Spherical) return Eigen::Vector3d::Zero();
  // candidate axles (body axes) through a centre (body coordinates)
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> axles;
  for (const TireModel& t : model.tires)
    if (t.body == body) axles.emplace_back(t.axis, t.center);
  for (const ConstraintModel& c : model.constraints)
    if (c.type == ConstraintType::RollingDisc && c.body_b == body) axles.emplace_back(c.axis_b, c.point_b);
  if (axles.empty()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d a = axles.front().first.normalized();
  const Eigen::Vector3d o = j.X_CM.p;  // the joint's M origin, body coordinates: the spin is about it
  const double len = std::max(1.0, o.norm());
  for (const auto& [axis, center] : axles)
    if (axis.normalized().cross(a).norm() > 1e-12 || (center - o).cross(a).norm() > 1e-12 * len) return Eigen::Vector3d::Zero();
  const std::size_t b = static_cast<std::size_t>(body);
  const double m = model.mass[b];
  const Eigen::Vector3d c = model.com[b];
  if (m > 0 && (c - o).cross(a).norm() > 1e-12 * len) return Eigen::Vector3d::Zero();
  // the rotational inertia about the centre of mass (body axes) from the spatial inertia
  const Eigen::Matrix3d cx = skew<double>(c);
  const Eigen::Matrix3d Ic = model.inertia[b].topLeftCorner<3, 3>() - m * cx * cx.transpose();
  if (!axisymmetric(Ic, a)) return Eigen::Vector3d::Zero();
  return j.X_CM.R.transpose() * a;  // M axes
}

SteadyMotion motion_of_state(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  SteadyMotion mo;
  mo.rates = v;
  const Eigen::Vector3d n_world = road_normal(model);
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[static_cast<std::size_t>(b)];
    if (j.type != JointType::Free && j.type != JointType::Spherical && j.type != JointType::Planar) continue;
    JointMotion jm;
    jm.body = b;
    const int iv = j.idx_v;
    const bool on_ground = j.parent == 0;
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    joint_pose(j, q, R, p);
    jm.origin = p;
    if (j.type == JointType::Planar) {
      jm.normal = Eigen::Vector3d::UnitZ();
      jm.velocity = Eigen::Vector3d(v[iv], v[iv + 1], 0.0);
      jm.yaw_rate = v[iv + 2];
    } else {
      // the road normal in F axes (F is fixed in the world for a joint on ground)
      jm.normal = on_ground ? Eigen::Vector3d(j.X_PF.R.transpose() * n_world) : Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d w = v.segment<3>(iv);
      const Eigen::Vector3d m = R.transpose() * jm.normal;  // the normal in M axes
      jm.spin_axis = spin_symmetry_axis(model, b);
      const bool spins = jm.spin_axis.squaredNorm() > 0;
      if (spins && on_ground && std::abs(jm.spin_axis.dot(m)) < 1 - 1e-9) {
        Eigen::Matrix<double, 3, 2> G;
        G << jm.spin_axis, m;
        const Eigen::Vector2d sr = G.colPivHouseholderQr().solve(w);
        jm.spin_rate = sr[0];
        jm.yaw_rate = sr[1];
      } else if (spins) {
        jm.spin_rate = jm.spin_axis.dot(w);
      } else if (on_ground) {
        jm.yaw_rate = m.dot(w);
      }
      if (j.type == JointType::Free) {
        jm.velocity = R * v.segment<3>(iv + 3);
        if (on_ground) jm.velocity -= jm.normal.dot(jm.velocity) * jm.normal;  // the frame moves in the road plane
      }
    }
    for (int k = 0; k < j.nv; ++k) mo.rates[iv + k] = 0.0;
    mo.joints.push_back(jm);
  }
  for (int i = 0; i < model.nv; ++i)
    if (mo.rates[i] != 0.0) mo.cyclic.push_back(i);
  return mo;
}

template <class S>
void motion_reference_velocity(const Model& model, const SteadyMotion& motion, const VecXT<S>& q, VecXT<S>& v_ref) {
  v_ref.resize(model.nv);
  for (int i = 0; i < model.nv; ++i) v_ref[i] = S(motion.rates.size() == model.nv ? motion.rates[i] : 0.0);
  for (const JointMotion& jm : motion.joints) {
    const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
    const int iq = j.idx_q, iv = j.idx_v;
    const double r = jm.yaw_rate, s = jm.spin_rate;
    if (j.type == JointType::Planar) {
      v_ref[iv] = jm.velocity.x() - r * (q[iq + 1] - jm.origin.y());
      v_ref[iv + 1] = jm.velocity.y() + r * (q[iq] - jm.origin.x());
      v_ref[iv + 2] = S(r);
      continue;
    }
    const int iqr = j.type == JointType::Free ? iq + 3 : iq;
    const Mat3T<S> R = quat_to_matrix<S>(q[iqr], q[iqr + 1], q[iqr + 2], q[iqr + 3]);
    const Vec3T<S> n = jm.normal.cast<S>();
    const Vec3T<S> w = (s * jm.spin_axis).cast<S>() + R.transpose() * n * S(r);
    v_ref.template segment<3>(iv) = w;
    if (j.type == JointType::Free) {
      const Vec3T<S> dp = Vec3T<S>(q[iq], q[iq + 1], q[iq + 2]) - jm.origin.cast<S>();
      const Vec3T<S> vel = jm.velocity.cast<S>() + n.cross(dp) * S(r);
      v_ref.template segment<3>(iv + 3) = R.transpose() * vel;
    }
  }
}

template <class S>
void motion_acceleration_terms(const Model& model, const SteadyMotion& motion, const VecXT<S>& v, VecXT<S>& qdd) {
  for (const JointMotion& jm : motion.joints) {
    const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
    const int iv = j.idx_v;
    if (j.type == JointType::Planar) {
      const S vx = v[iv], vy = v[iv + 1];
      qdd[iv] += vy * jm.yaw_rate;
      qdd[iv + 1] -= vx * jm.yaw_rate;
      continue;
    }
    if (jm.spin_rate == 0.0) continue;
    const Vec3T<S> spin = (jm.spin_rate * jm.spin_axis).cast<S>();
    qdd.template segment<3>(iv) += spin.cross(Vec3T<S>(v.template segment<3>(iv)));
    if (j.type == JointType::Free) qdd.template segment<3>(iv + 3) += spin.cross(Vec3T<S>(v.template segment<3>(iv + 3)));
  }
}

void advance_motion(const Model& model, SteadyMotion& motion, double T, Eigen::VectorXd& q, Eigen::VectorXd& v) {
  for (int i = 0; i < model.nv; ++i) {
    if (motion.rates.size() != model.nv || motion.rates[i] == 0.0) continue;
    // a coordinate that advances is additive (the joints with rotations are in `joints`)
    for (int b = 1; b < model.nbodies; ++b) {
      const JointModel& j = model.joints[static_cast<std::size_t>(b)];
      if (i >= j.idx_v && i < j.idx_v + j.nv) q[j.idx_q + (i - j.idx_v)] += motion.rates[i] * T;
    }
  }
  for (JointMotion& jm : motion.joints) {
    const JointModel& j = model.joints[static_cast<std::size_t>(jm.body)];
    const int iq = j.idx_q, iv = j.idx_v;
    const double r = jm.yaw_rate;
    const Eigen::Matrix3d G = Eigen::AngleAxisd(r * T, jm.normal).toRotationMatrix();
    // a point p of the moving frame after T: it turns by G about the centre c = o + (n x V) / r, so
    // p + (G - I)(p - o) - (G - I)/r (n x V); (G - I)/r = (sin(rT)/r) [n]x + ((1 - cos(rT))/r) [n]x^2
    // is taken in that form, which is exact as r goes to 0 (a translation V T), where c is far away
    // and c + G (p - c) would lose every digit (a straight run's yaw rate at round-off)
    const double th = r * T;
    const double a = std::abs(th) < 1e-4 ? T * (1 - th * th / 6) : std::sin(th) / r;
    const double b = std::abs(th) < 1e-4 ? T * th * (0.5 - th * th / 24) : (1 - std::cos(th)) / r;
    auto moved = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
      const Eigen::Vector3d w = jm.normal.cross(jm.velocity);
      const Eigen::Vector3d nw = jm.normal.cross(w);
      return p + (G - Eigen::Matrix3d::Identity()) * (p - jm.origin) - a * nw - b * jm.normal.cross(nw);
    };
    if (j.type == JointType::Planar) {
      const Eigen::Vector3d p = moved(Eigen::Vector3d(q[iq], q[iq + 1], 0.0));
      q[iq] = p.x();
      q[iq + 1] = p.y();
      q[iq + 2] += r * T;
      const Eigen::Vector3d w = G * Eigen::Vector3d(v[iv], v[iv + 1], 0.0);
      v[iv] = w.x();
      v[iv + 1] = w.y();
      jm.origin = moved(jm.origin);
      jm.velocity = G * jm.velocity;
      continue;
    }
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    joint_pose(j, q, R, p);
    const Eigen::Matrix3d H = jm.spin_rate != 0.0 ? Eigen::AngleAxisd(jm.spin_rate * T, jm.spin_axis).toRotationMatrix()
                                                  : Eigen::Matrix3d::Identity();
    put_rotation(j, G * R * H, q);
    if (j.type == JointType::Free) q.segment<3>(iq) = moved(p);
    v.segment<3>(iv) = H.transpose() * v.segment<3>(iv);
    if (j.type == JointType::Free) v.segment<3>(iv + 3) = H.transpose() * v.segment<3>(iv + 3);
    jm.origin = moved(jm.origin);
    jm.velocity = G * jm.velocity;
  }
}

double motion_check_time(const SteadyMotion& motion) {
  double fastest = 0;
  for (const JointMotion& jm : motion.joints) fastest = std::max({fastest, std::abs(jm.yaw_rate), std::abs(jm.spin_rate)});
  // half a radian of the fastest turn or spin, at most a second (a yaw rate at round-off is not a
  // turn whose half radian takes 1e30 s)
  return fastest > 0.5 ? 0.5 / fastest : 1.0;
}

template void motion_reference_velocity<double>(const Model&, const SteadyMotion&, const VecXT<double>&, VecXT<double>&);
template void motion_reference_velocity<ADScalar>(const Model&, const SteadyMotion&, const VecXT<ADScalar>&,
                                                  VecXT<ADScalar>&);
template void motion_acceleration_terms<double>(const Model&, const SteadyMotion&, const VecXT<double>&, VecXT<double>&);
template void motion_acceleration_terms<ADScalar>(const Model&, const SteadyMotion&, const VecXT<ADScalar>&,
                                                  VecXT<ADScalar>&);

}  // namespace codyna
