#include "dynamics/joint.hpp"

#include <cmath>

#include "spatial/autodiff.hpp"

namespace codyna {

namespace {

template <class S>
struct Quat {
  S w, x, y, z;
  Vec3T<S> vec() const { return Vec3T<S>(x, y, z); }
};

template <class S>
Quat<S> quat_mul(const Quat<S>& a, const Quat<S>& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// exp of a rotation vector as a unit quaternion; series near zero keeps derivatives finite
template <class S>
Quat<S> quat_exp(const Vec3T<S>& w) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S t2 = w.squaredNorm();
  S c, k;  // cos(t/2), sin(t/2)/t
  if (ad_value(t2) < 1e-12) {
    c = S(1) - t2 / S(8);
    k = S(0.5) - t2 / S(48);
  } else {
    const S t = sqrt(t2);
    S sh;
    sin_cos(S(t / S(2)), sh, c);
    k = sh / t;
  }
  return {c, k * w.x(), k * w.y(), k * w.z()};
}

template <class S>
Quat<S> quat_at(const VecXT<S>& q, int i) { return {q[i], q[i + 1], q[i + 2], q[i + 3]}; }

template <class S>
void quat_put(VecXT<S>& q, int i, const Quat<S>& r) {
  q[i] = r.w; q[i + 1] = r.x; q[i + 2] = r.y; q[i + 3] = r.z;
}

}  // namespace

template <class S>
void joint_transform(const JointModel& j, const VecXT<S>& q, SE3T<S>& X, Mat6xT<S>& Sm) {
  const int i = j.idx_q;
  const Vec3T<S> a = j.axis.cast<S>();
  X = SE3T<S>();
  Sm.setZero(6, j.nv);
  switch (j.type) {
    case JointType::Revolute:
      X.R = axis_angle<S>(j.axis, q[i]);
      Sm.template block<3, 1>(0, 0) = a;
      break;
    case JointType::Prismatic:
      X.p = a * q[i];
      Sm.template block<3, 1>(3, 0) = a;
      break;
    case JointType::Fixed:
      break;
    case JointType::Spherical:
      X.R = quat_to_matrix<S>(q[i], q[i + 1], q[i + 2], q[i + 3]);
      Sm.template block<3, 3>(0, 0).setIdentity();
      break;
    case JointType::Universal: {
      const Mat3T<S> R2 = axis_angle<S>(j.axis2, q[i + 1]);
      X.R = axis_angle<S>(j.axis, q[i]) * R2;
      Sm.template block<3, 1>(0, 0) = R2.transpose() * a;
      Sm.template block<3, 1>(0, 1) = j.axis2.cast<S>();
      break;
    }
    case JointType::Cylindrical:
      X.R = axis_angle<S>(j.axis, q[i]);
      X.p = a * q[i + 1];
      Sm.template block<3, 1>(0, 0) = a;
      Sm.template block<3, 1>(3, 1) = a;
      break;
    case JointType::Planar:
      X.R = axis_angle<S>(Eigen::Vector3d::UnitZ(), q[i + 2]);
      X.p = Vec3T<S>(q[i], q[i + 1], S(0));
      Sm.template block<3, 1>(3, 0) = X.R.transpose().col(0);
      Sm.template block<3, 1>(3, 1) = X.R.transpose().col(1);
      Sm(2, 2) = S(1);
      break;
    case JointType::Free:
      X.p = Vec3T<S>(q[i], q[i + 1], q[i + 2]);
      X.R = quat_to_matrix<S>(q[i + 3], q[i + 4], q[i + 5], q[i + 6]);
      Sm.setIdentity(6, 6);
      break;
  }
}

template <class S>
Vec6T<S> joint_bias(const JointModel& j, const VecXT<S>& q, const VecXT<S>& v) {
  Vec6T<S> c = Vec6T<S>::Zero();
  const int iq = j.idx_q, iv = j.idx_v;
  if (j.type == JointType::Universal) {
    const Mat3T<S> R2 = axis_angle<S>(j.axis2, q[iq + 1]);
    const Vec3T<S> s1 = R2.transpose() * j.axis.cast<S>();
    c.template head<3>() = -(j.axis2.cast<S>().cross(s1)) * (v[iv] * v[iv + 1]);
  } else if (j.type == JointType::Planar) {
    const Mat3T<S> R = axis_angle<S>(Eigen::Vector3d::UnitZ(), q[iq + 2]);
    const Vec3T<S> vm = R.transpose() * Vec3T<S>(v[iv], v[iv + 1], S(0));
    c.template tail<3>() = -(Vec3T<S>(S(0), S(0), v[iv + 2]).cross(vm));
  }
  return c;
}

template <class S>
void integrate_into(const Model& model, const VecXT<S>& q, const VecXT<S>& dv, VecXT<S>& r) {
  r = q;
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    const int iq = j.idx_q, iv = j.idx_v;
    switch (j.type) {
      case JointType::Spherical: {
        quat_put(r, iq, quat_mul(quat_at(q, iq), quat_exp<S>(Vec3T<S>(dv.template segment<3>(iv)))));
        break;
      }
      case JointType::Free: {
        const Mat3T<S> R = quat_to_matrix<S>(q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]);
        r.template segment<3>(iq) += R * Vec3T<S>(dv.template segment<3>(iv + 3));
        quat_put(r, iq + 3, quat_mul(quat_at(q, iq + 3), quat_exp<S>(Vec3T<S>(dv.template segment<3>(iv)))));
        break;
      }
      default:
        for (int k = 0; k < j.nv; ++k) r[iq + k] += dv[iv + k];
    }
  }
}

template <class S>
VecXT<S> integrate(const Model& model, const VecXT<S>& q, const VecXT<S>& dv) {
  VecXT<S> r;
  integrate_into<S>(model, q, dv, r);
  return r;
}

namespace {
Eigen::Vector3d quat_log(const Quat<double>& d0) {
  Quat<double> d = d0;
  if (d.w < 0) d = {-d.w, -d.x, -d.y, -d.z};  // shortest rotation
  const double s = d.vec().norm();
  if (s < 1e-12) return 2.0 * d.vec() / d.w;
  return 2.0 * std::atan2(s, d.w) / s * d.vec();
}
Quat<double> conj(const Quat<double>& a) { return {a.w, -a.x, -a.y, -a.z}; }
}  // namespace

Eigen::Vector3d rotation_log(const Eigen::Vector4d& wxyz) {
  const double n = wxyz.norm();
  if (!(n > 0) || !std::isfinite(n)) return Eigen::Vector3d::Zero();
  return quat_log({wxyz[0] / n, wxyz[1] / n, wxyz[2] / n, wxyz[3] / n});
}

Eigen::Vector4d rotation_exp(const Eigen::Vector3d& r) {
  const Quat<double> h = quat_exp<double>(r);
  return {h.w, h.x, h.y, h.z};
}

Eigen::VectorXd difference(const Model& model, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1) {
  Eigen::VectorXd dv(model.nv);
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    const int iq = j.idx_q, iv = j.idx_v;
    switch (j.type) {
      case JointType::Spherical: {
        const auto a = quat_at<double>(q0, iq), c = quat_at<double>(q1, iq);
        const double na = std::sqrt(a.w * a.w + a.vec().squaredNorm()), nc = std::sqrt(c.w * c.w + c.vec().squaredNorm());
        Quat<double> d = quat_mul(conj(a), c);
        d = {d.w / (na * nc), d.x / (na * nc), d.y / (na * nc), d.z / (na * nc)};
        dv.segment<3>(iv) = quat_log(d);
        break;
      }
      case JointType::Free: {
        const auto a = quat_at<double>(q0, iq + 3), c = quat_at<double>(q1, iq + 3);
        const Eigen::Matrix3d R = quat_to_matrix<double>(a.w, a.x, a.y, a.z);
        dv.segment<3>(iv + 3) = R.transpose() * (q1.segment<3>(iq) - q0.segment<3>(iq));
        const double na = std::sqrt(a.w * a.w + a.vec().squaredNorm()), nc = std::sqrt(c.w * c.w + c.vec().squaredNorm());
        Quat<double> d = quat_mul(conj(a), c);
        d = {d.w / (na * nc), d.x / (na * nc), d.y / (na * nc), d.z / (na * nc)};
        dv.segment<3>(iv) = quat_log(d);
        break;
      }
      default:
        for (int k = 0; k < j.nv; ++k) dv[iv + k] = q1[iq + k] - q0[iq + k];
    }
  }
  return dv;
}

template <class S>
VecXT<S> qdot(const Model& model, const VecXT<S>& q, const VecXT<S>& v) {
  VecXT<S> r(model.nq);
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    const int iq = j.idx_q, iv = j.idx_v;
    auto quat_rate = [&](int qi, int wi) {
      const Quat<S> w{S(0), v[wi], v[wi + 1], v[wi + 2]};
      const Quat<S> d = quat_mul(quat_at(q, qi), w);
      quat_put(r, qi, Quat<S>{S(0.5) * d.w, S(0.5) * d.x, S(0.5) * d.y, S(0.5) * d.z});
    };
    switch (j.type) {
      case JointType::Spherical:
        quat_rate(iq, iv);
        break;
      case JointType::Free: {
        const Mat3T<S> R = quat_to_matrix<S>(q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]);
        r.template segment<3>(iq) = R * Vec3T<S>(v.template segment<3>(iv + 3));
        quat_rate(iq + 3, iv);
        break;
      }
      default:
        for (int k = 0; k < j.nv; ++k) r[iq + k] = v[iv + k];
    }
  }
  return r;
}

namespace {
// rotation matrix Exp(t) and inverse right Jacobian Jr^-1(t) of a rotation
// vector; series near zero keep values and derivatives exact there
template <class S>
Mat3T<S> so3_exp(const Vec3T<S>& t) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S t2 = t.squaredNorm();
  const Mat3T<S> K = skew<S>(t);
  S a, b;  // sin(x)/x, (1 - cos x)/x^2
  if (ad_value(t2) < 1e-12) {
    a = S(1) - t2 / S(6);
    b = S(0.5) - t2 / S(24);
  } else {
    const S x = sqrt(t2);
    a = sin(x) / x;
    b = (S(1) - cos(x)) / t2;
  }
  return Mat3T<S>::Identity() + a * K + b * (K * K);
}

template <class S>
Mat3T<S> so3_jr_inv(const Vec3T<S>& t) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S t2 = t.squaredNorm();
  const Mat3T<S> K = skew<S>(t);
  S c;  // 1/x^2 - (1 + cos x)/(2 x sin x)
  if (ad_value(t2) < 1e-8) {
    c = S(1.0 / 12.0) + t2 / S(720);
  } else {
    const S x = sqrt(t2);
    c = S(1) / t2 - (S(1) + cos(x)) / (S(2) * x * sin(x));
  }
  return Mat3T<S>::Identity() + S(0.5) * K + c * (K * K);
}
}  // namespace

template <class S>
void tangent_rate_into(const Model& model, const VecXT<S>& dq, const VecXT<S>& v, VecXT<S>& r) {
  r = v;
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    const int iv = j.idx_v;
    if (j.type != JointType::Spherical && j.type != JointType::Free) continue;
    const Vec3T<S> t = dq.template segment<3>(iv);
    r.template segment<3>(iv) = so3_jr_inv<S>(t) * Vec3T<S>(v.template segment<3>(iv));
    if (j.type == JointType::Free) r.template segment<3>(iv + 3) = so3_exp<S>(t) * Vec3T<S>(v.template segment<3>(iv + 3));
  }
}

template <class S>
VecXT<S> tangent_rate(const Model& model, const VecXT<S>& dq, const VecXT<S>& v) {
  VecXT<S> r;
  tangent_rate_into<S>(model, dq, v, r);
  return r;
}

void normalize(const Model& model, Eigen::VectorXd& q) {
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    int qi = -1;
    if (j.type == JointType::Spherical) qi = j.idx_q;
    if (j.type == JointType::Free) qi = j.idx_q + 3;
    if (qi >= 0) q.segment<4>(qi).normalize();
  }
}

#define CODYNA_INSTANTIATE(S)                                                                   \
  template void joint_transform<S>(const JointModel&, const VecXT<S>&, SE3T<S>&, Mat6xT<S>&); \
  template Vec6T<S> joint_bias<S>(const JointModel&, const VecXT<S>&, const VecXT<S>&);       \
  template VecXT<S> integrate<S>(const Model&, const VecXT<S>&, const VecXT<S>&);             \
  template void integrate_into<S>(const Model&, const VecXT<S>&, const VecXT<S>&, VecXT<S>&);  \
  template void tangent_rate_into<S>(const Model&, const VecXT<S>&, const VecXT<S>&, VecXT<S>&); \
  template VecXT<S> qdot<S>(const Model&, const VecXT<S>&, const VecXT<S>&);                  \
  template VecXT<S> tangent_rate<S>(const Model&, const VecXT<S>&, const VecXT<S>&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
