// Spatial algebra after Featherstone, in Pinocchio's body-frame flavour.
// A spatial motion m = [w; v] (angular; linear velocity of the point at the
// frame origin), a spatial force f = [n; f] (moment about the frame origin;
// force). SE3 X_AB is the pose of frame B in frame A: p_A = R p_B + p.
// Everything is templated on the scalar so that automatic differentiation
// runs through the same code.
#pragma once

#include <cmath>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace codyna {

template <class S> using Vec3T = Eigen::Matrix<S, 3, 1>;
template <class S> using Mat3T = Eigen::Matrix<S, 3, 3>;
template <class S> using Vec6T = Eigen::Matrix<S, 6, 1>;
template <class S> using Mat6T = Eigen::Matrix<S, 6, 6>;
template <class S> using Mat6xT = Eigen::Matrix<S, 6, Eigen::Dynamic, 0, 6, 6>;  // at most 6 columns, no heap
template <class S> using VecXT = Eigen::Matrix<S, Eigen::Dynamic, 1>;
template <class S> using MatXT = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;

// sine and cosine of one angle: in double one call to the C library's sincos (the two values are
// those of sin and cos, at about the cost of one); any other scalar (autodiff) takes the two
template <class S>
void sin_cos(const S& a, S& s, S& c) {
  using std::cos;
  using std::sin;
  s = sin(a);
  c = cos(a);
}
inline void sin_cos(double a, double& s, double& c) { ::sincos(a, &s, &c); }

template <class S>
Mat3T<S> skew(const Vec3T<S>& w) {
  Mat3T<S> m;
  m << S(0), -w.z(), w.y(), w.z(), S(0), -w.x(), -w.y(), w.x(), S(0);
  return m;
}

// r = (x0, ..., x5), the six components of a spatial vector computed as scalars and written at once
inline void set6(Vec6T<double>& r, double x0, double x1, double x2, double x3, double x4, double x5) {
  r << x0, x1, x2, x3, x4, x5;
}

template <class S>
struct SE3T {
  Mat3T<S> R = Mat3T<S>::Identity();
  Vec3T<S> p = Vec3T<S>::Zero();

  SE3T() = default;
  SE3T(const Mat3T<S>& R_, const Vec3T<S>& p_) : R(R_), p(p_) {}

  SE3T operator*(const SE3T& o) const { return SE3T(R * o.R, R * o.p + p); }
  SE3T inverse() const { return SE3T(R.transpose(), -(R.transpose() * p)); }
  Vec3T<S> act_point(const Vec3T<S>& x) const { return R * x + p; }

  // The four transforms below: in double, each of the six components as one scalar expression
  // and the result written at once (set6). Written as two 3-vectors, the halves were stored as 2 + 1
  // doubles and read back by the caller as aligned pairs, a load that spans two stores and
  // stalls on every transform (store forwarding). The sums are Eigen's, in Eigen's order, so the
  // results are the same bit for bit (its R x adds a row's three products left to right in the
  // first two rows and the last two first in the third; R^T x left to right).

  // motion given in B coordinates -> A coordinates
  Vec6T<S> act_motion(const Vec6T<S>& m) const {
    Vec6T<S> r;
    if constexpr (std::is_same_v<S, double>) {
      const double w0 = R(0, 0) * m[0] + R(0, 1) * m[1] + R(0, 2) * m[2];
      const double w1 = R(1, 0) * m[0] + R(1, 1) * m[1] + R(1, 2) * m[2];
      const double w2 = R(2, 0) * m[0] + (R(2, 1) * m[1] + R(2, 2) * m[2]);
      set6(r,
           w0,
           w1,
           w2,
           R(0, 0) * m[3] + R(0, 1) * m[4] + R(0, 2) * m[5] + (p[1] * w2 - p[2] * w1),
           R(1, 0) * m[3] + R(1, 1) * m[4] + R(1, 2) * m[5] + (p[2] * w0 - p[0] * w2),
           R(2, 0) * m[3] + (R(2, 1) * m[4] + R(2, 2) * m[5]) + (p[0] * w1 - p[1] * w0));
    } else {
      r.template head<3>() = R * m.template head<3>();
      r.template tail<3>() = R * m.template tail<3>() + p.cross(Vec3T<S>(r.template head<3>()));
    }
    return r;
  }
  // motion given in A coordinates -> B coordinates
  Vec6T<S> inv_act_motion(const Vec6T<S>& m) const {
    Vec6T<S> r;
    if constexpr (std::is_same_v<S, double>) {
      const double u0 = m[3] - (p[1] * m[2] - p[2] * m[1]);
      const double u1 = m[4] - (p[2] * m[0] - p[0] * m[2]);
      const double u2 = m[5] - (p[0] * m[1] - p[1] * m[0]);
      set6(r,
           R(0, 0) * m[0] + R(1, 0) * m[1] + R(2, 0) * m[2],
           R(0, 1) * m[0] + R(1, 1) * m[1] + R(2, 1) * m[2],
           R(0, 2) * m[0] + R(1, 2) * m[1] + R(2, 2) * m[2],
           R(0, 0) * u0 + R(1, 0) * u1 + R(2, 0) * u2,
           R(0, 1) * u0 + R(1, 1) * u1 + R(2, 1) * u2,
           R(0, 2) * u0 + R(1, 2) * u1 + R(2, 2) * u2);
    } else {
      r.template head<3>() = R.transpose() * m.template head<3>();
      r.template tail<3>() = R.transpose() * (m.template tail<3>() - p.cross(Vec3T<S>(m.template head<3>())));
    }
    return r;
  }
  // force given in B coordinates -> A coordinates
  Vec6T<S> act_force(const Vec6T<S>& f) const {
    Vec6T<S> r;
    if constexpr (std::is_same_v<S, double>) {
      const double f0 = R(0, 0) * f[3] + R(0, 1) * f[4] + R(0, 2) * f[5];
      const double f1 = R(1, 0) * f[3] + R(1, 1) * f[4] + R(1, 2) * f[5];
      const double f2 = R(2, 0) * f[3] + (R(2, 1) * f[4] + R(2, 2) * f[5]);
      set6(r,
           R(0, 0) * f[0] + R(0, 1) * f[1] + R(0, 2) * f[2] + (p[1] * f2 - p[2] * f1),
           R(1, 0) * f[0] + R(1, 1) * f[1] + R(1, 2) * f[2] + (p[2] * f0 - p[0] * f2),
           R(2, 0) * f[0] + (R(2, 1) * f[1] + R(2, 2) * f[2]) + (p[0] * f1 - p[1] * f0),
           f0,
           f1,
           f2);
    } else {
      r.template tail<3>() = R * f.template tail<3>();
      r.template head<3>() = R * f.template head<3>() + p.cross(Vec3T<S>(r.template tail<3>()));
    }
    return r;
  }
  // force given in A coordinates -> B coordinates
  Vec6T<S> inv_act_force(const Vec6T<S>& f) const {
    Vec6T<S> r;
    if constexpr (std::is_same_v<S, double>) {
      const double n0 = f[0] - (p[1] * f[5] - p[2] * f[4]);
      const double n1 = f[1] - (p[2] * f[3] - p[0] * f[5]);
      const double n2 = f[2] - (p[0] * f[4] - p[1] * f[3]);
      set6(r,
           R(0, 0) * n0 + R(1, 0) * n1 + R(2, 0) * n2,
           R(0, 1) * n0 + R(1, 1) * n1 + R(2, 1) * n2,
           R(0, 2) * n0 + R(1, 2) * n1 + R(2, 2) * n2,
           R(0, 0) * f[3] + R(1, 0) * f[4] + R(2, 0) * f[5],
           R(0, 1) * f[3] + R(1, 1) * f[4] + R(2, 1) * f[5],
           R(0, 2) * f[3] + R(1, 2) * f[4] + R(2, 2) * f[5]);
    } else {
      r.template tail<3>() = R.transpose() * f.template tail<3>();
      r.template head<3>() = R.transpose() * (f.template head<3>() - p.cross(Vec3T<S>(f.template tail<3>())));
    }
    return r;
  }
  // 6x6 motion transform (B coordinates -> A coordinates), for Jacobian columns and inertias
  Mat6T<S> motion_matrix() const {
    Mat6T<S> X = Mat6T<S>::Zero();
    X.template topLeftCorner<3, 3>() = R;
    X.template bottomRightCorner<3, 3>() = R;
    X.template bottomLeftCorner<3, 3>() = skew<S>(p) * R;
    return X;
  }

  template <class T>
  SE3T<T> cast() const { return SE3T<T>(R.template cast<T>(), p.template cast<T>()); }
};

using SE3 = SE3T<double>;

// m1 x m2 (motion cross motion)
template <class S>
Vec6T<S> cross_motion(const Vec6T<S>& m1, const Vec6T<S>& m2) {
  const Vec3T<S> w = m1.template head<3>(), v = m1.template tail<3>();
  const Vec3T<S> w2 = m2.template head<3>(), v2 = m2.template tail<3>();
  Vec6T<S> r;
  if constexpr (std::is_same_v<S, double>) {  // one write (see SE3T's transforms)
    set6(r,
         w[1] * w2[2] - w[2] * w2[1],
         w[2] * w2[0] - w[0] * w2[2],
         w[0] * w2[1] - w[1] * w2[0],
         (w[1] * v2[2] - w[2] * v2[1]) + (v[1] * w2[2] - v[2] * w2[1]),
         (w[2] * v2[0] - w[0] * v2[2]) + (v[2] * w2[0] - v[0] * w2[2]),
         (w[0] * v2[1] - w[1] * v2[0]) + (v[0] * w2[1] - v[1] * w2[0]));
  } else {
    r.template head<3>() = w.cross(w2);
    r.template tail<3>() = w.cross(v2) + v.cross(w2);
  }
  return r;
}

// m1 x (k s): the cross product with a joint's motion s qd (s a 6-vector at s_data), the same
// numbers as cross_motion(m1, Vec6(s * k)). In double without that 6-vector in memory: written
// there by pairs and read back by the cross product's pairs (1, 2), it stalled on store
// forwarding (a quarter of the ABA's velocity terms on chain 30).
template <class S>
Vec6T<S> cross_motion_scaled(const Vec6T<S>& m1, const S* s_data, const S& k) {
  if constexpr (std::is_same_v<S, double>) {
    const double a0 = s_data[0] * k, a1 = s_data[1] * k, a2 = s_data[2] * k;
    const double b0 = s_data[3] * k, b1 = s_data[4] * k, b2 = s_data[5] * k;
    const double w0 = m1[0], w1 = m1[1], w2 = m1[2], v0 = m1[3], v1 = m1[4], v2 = m1[5];
    Vec6T<double> r;
    set6(r, w1 * a2 - w2 * a1, w2 * a0 - w0 * a2, w0 * a1 - w1 * a0,
         (w1 * b2 - w2 * b1) + (v1 * a2 - v2 * a1), (w2 * b0 - w0 * b2) + (v2 * a0 - v0 * a2),
         (w0 * b1 - w1 * b0) + (v0 * a1 - v1 * a0));
    return r;
  } else {
    return cross_motion<S>(m1, Vec6T<S>(Eigen::Map<const Vec6T<S>>(s_data) * k));
  }
}

// m x* f (motion cross force)
template <class S>
Vec6T<S> cross_force(const Vec6T<S>& m, const Vec6T<S>& f) {
  const Vec3T<S> w = m.template head<3>(), v = m.template tail<3>();
  const Vec3T<S> n = f.template head<3>(), fl = f.template tail<3>();
  Vec6T<S> r;
  if constexpr (std::is_same_v<S, double>) {  // one write (see SE3T's transforms)
    set6(r,
         (w[1] * n[2] - w[2] * n[1]) + (v[1] * fl[2] - v[2] * fl[1]),
         (w[2] * n[0] - w[0] * n[2]) + (v[2] * fl[0] - v[0] * fl[2]),
         (w[0] * n[1] - w[1] * n[0]) + (v[0] * fl[1] - v[1] * fl[0]),
         w[1] * fl[2] - w[2] * fl[1],
         w[2] * fl[0] - w[0] * fl[2],
         w[0] * fl[1] - w[1] * fl[0]);
  } else {
    r.template head<3>() = w.cross(n) + v.cross(fl);
    r.template tail<3>() = w.cross(fl);
  }
  return r;
}

// 6x6 spatial inertia (body frame) of mass m, com c, rotational inertia Ic about the com.
inline Mat6T<double> spatial_inertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& Ic) {
  Mat6T<double> I;
  const Eigen::Matrix3d cx = skew<double>(c);
  I.topLeftCorner<3, 3>() = Ic + m * cx * cx.transpose();
  I.topRightCorner<3, 3>() = m * cx;
  I.bottomLeftCorner<3, 3>() = m * cx.transpose();
  I.bottomRightCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  return I;
}

// --- structured operations on spatial inertias ------------------------------
// A symmetric 6x6 spatial inertia (rigid or articulated) acting on a motion
// [w; v] in the coordinates of some frame: I = [A B; B^T C], n = A w + B v,
// f = B^T w + C v.

// out += X* I X*^T with X = X_AB: the inertia I given in B coordinates,
// expressed in A coordinates and added to out. X* = [R, [p]R; 0, R] is the
// force transform B -> A, so this is Xm^T I Xm with Xm the 6x6 motion transform
// A -> B (what ABA and CRBA add to a parent). Written on the 3x3 blocks: rotate
// A, B, C by R, then shift the moment reference by p:
//   C' = R C R^T,  B' = R B R^T + [p] C',  A' = R A R^T + [p] (R B R^T)^T + B' [p]^T
// I is assumed symmetric (only its A, B and C blocks are read).
template <class S>
void add_transformed_inertia(const SE3T<S>& X, const Mat6T<S>& I, Mat6T<S>& out) {
  const Mat3T<S>& R = X.R;
  const Vec3T<S>& p = X.p;
  const Mat3T<S> Rt = R.transpose();
  const Mat3T<S> A = R * (I.template topLeftCorner<3, 3>() * Rt).eval();
  const Mat3T<S> B = R * (I.template topRightCorner<3, 3>() * Rt).eval();
  const Mat3T<S> C = R * (I.template bottomRightCorner<3, 3>() * Rt).eval();
  Mat3T<S> Bp, Ap;
  for (int k = 0; k < 3; ++k) Bp.col(k) = B.col(k) + p.cross(Vec3T<S>(C.col(k)));  // B + [p] C
  for (int k = 0; k < 3; ++k) Ap.col(k) = A.col(k) + p.cross(Vec3T<S>(B.row(k).transpose()));  // A + [p] B^T
  for (int k = 0; k < 3; ++k) Ap.row(k) += p.cross(Vec3T<S>(Bp.row(k).transpose())).transpose();  // + B' [p]^T
  out.template topLeftCorner<3, 3>() += Ap;
  out.template topRightCorner<3, 3>() += Bp;
  out.template bottomLeftCorner<3, 3>() += Bp.transpose();
  out.template bottomRightCorner<3, 3>() += C;
}

// A rigid-body inertia as ten numbers: mass m, first moment h = m c (c: centre
// of mass) and the rotational inertia I about the frame origin (symmetric),
// all in the coordinates of one frame. As a 6x6 spatial inertia it is
// [I, [h]; [h]^T, m 1] (spatial_inertia below gives the same matrix).
template <class S>
struct RigidInertiaT {
  S m = S(0);
  Vec3T<S> h = Vec3T<S>::Zero();
  Mat3T<S> I = Mat3T<S>::Zero();

  // the force [I w + h x v; m v - h x w] of a motion [w; v]
  Vec6T<S> apply(const Vec6T<S>& mo) const {
    const Vec3T<S> w = mo.template head<3>(), v = mo.template tail<3>();
    Vec6T<S> r;
    r.template head<3>() = I * w + h.cross(v);
    r.template tail<3>() = m * v - h.cross(w);
    return r;
  }
  RigidInertiaT& operator+=(const RigidInertiaT& o) {
    m += o.m;
    h += o.h;
    I += o.I;
    return *this;
  }
  Mat6T<S> matrix() const {
    Mat6T<S> X;
    const Mat3T<S> H = skew<S>(h);
    X.template topLeftCorner<3, 3>() = I;
    X.template topRightCorner<3, 3>() = H;
    X.template bottomLeftCorner<3, 3>() = H.transpose();
    X.template bottomRightCorner<3, 3>() = m * Mat3T<S>::Identity();
    return X;
  }
  // from a 6x6 rigid-body spatial inertia (as spatial_inertia makes it)
  static RigidInertiaT from_matrix(const Mat6T<S>& X) {
    RigidInertiaT r;
    r.m = X(5, 5);
    r.h = Vec3T<S>(X(2, 4), X(0, 5), X(1, 3));
    r.I = X.template topLeftCorner<3, 3>();
    return r;
  }
};

// A rigid body's inertia about its centre of mass (body axes): mass m, centre
// of mass c and rotational inertia Ic about c, for the cheapest move to another
// frame (to_frame).
struct ComInertia {
  double m = 0.0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Matrix3d Ic = Eigen::Matrix3d::Zero();

  static ComInertia from_matrix(const Mat6T<double>& X) {
    ComInertia r;
    const RigidInertiaT<double> o = RigidInertiaT<double>::from_matrix(X);
    r.m = o.m;
    r.c = o.m > 0.0 ? Eigen::Vector3d(o.h / o.m) : Eigen::Vector3d::Zero();
    r.Ic = o.I - r.m * (r.c.squaredNorm() * Eigen::Matrix3d::Identity() - r.c * r.c.transpose());
    return r;
  }
  // the body in a frame where its axes are R (body -> frame) and its origin at r:
  //   p = R c + r,  h = m p,  I = R Ic R^T + m (|p|^2 1 - p p^T)
  // (the symmetric R Ic R^T from its upper triangle)
  template <class S>
  void to_frame(const Mat3T<S>& R, const Vec3T<S>& r, RigidInertiaT<S>& out) const {
    const Vec3T<S> p = R * c.template cast<S>() + r;
    const S ms = S(m);
    out.m = ms;
    out.h = ms * p;
    const Mat3T<S> T = R * Ic.template cast<S>();
    const S pp = p.squaredNorm();
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        S v = T.row(i).dot(R.row(j)) - ms * p[i] * p[j];
        if (i == j) v += ms * pp;
        out.I(i, j) = v;
        out.I(j, i) = v;
      }
  }
};

// Rotation by angle about a unit axis given its cosine and sine:
//   c 1 + s [a] + (1 - c) a a^T
template <class S>
Mat3T<S> axis_rotation(const Eigen::Vector3d& a, const S& c, const S& s) {
  const S t = S(1) - c;
  const S x = S(a.x()), y = S(a.y()), z = S(a.z());
  Mat3T<S> R;
  R << c + t * x * x, t * x * y - s * z, t * x * z + s * y,
       t * x * y + s * z, c + t * y * y, t * y * z - s * x,
       t * x * z - s * y, t * y * z + s * x, c + t * z * z;
  return R;
}

// Rotation by angle about a unit axis, for any scalar.
template <class S>
Mat3T<S> axis_angle(const Eigen::Vector3d& axis, const S& angle) {
  S s, c;
  sin_cos(angle, s, c);
  const Mat3T<S> K = skew<S>(axis.template cast<S>());
  return Mat3T<S>::Identity() + s * K + (S(1) - c) * (K * K);
}

// Rotation matrix of a quaternion stored (w, x, y, z); normalized inside.
template <class S>
Mat3T<S> quat_to_matrix(const S& w0, const S& x0, const S& y0, const S& z0) {
  using std::sqrt;
  const S n = sqrt(w0 * w0 + x0 * x0 + y0 * y0 + z0 * z0);
  const S w = w0 / n, x = x0 / n, y = y0 / n, z = z0 / n;
  Mat3T<S> R;
  R << S(1) - S(2) * (y * y + z * z), S(2) * (x * y - z * w), S(2) * (x * z + y * w),
       S(2) * (x * y + z * w), S(1) - S(2) * (x * x + z * z), S(2) * (y * z - x * w),
       S(2) * (x * z - y * w), S(2) * (y * z + x * w), S(1) - S(2) * (x * x + y * y);
  return R;
}

}  // namespace codyna
