#include "dynamics/constraints.hpp"

#include "dynamics/kinematics.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {

// a body-fixed vector in world axes with its first two time derivatives (qdd = 0)
template <class S>
struct Attached {
  Vec3T<S> x, xd, xdd;
};

template <class S>
Attached<S> attached(const DataT<S>& d, int body, const Eigen::Vector3d& local) {
  const Vec3T<S> x = d.oMi[body].R * local.cast<S>();
  const Vec3T<S> w = angular_velocity<S>(d, body), al = angular_acceleration<S>(d, body);
  const Vec3T<S> xd = w.cross(x);
  return {x, xd, Vec3T<S>(al.cross(x) + w.cross(xd))};
}

template <class S>
void fill_rows(const Model& model, DataT<S>& d, bool with_velocity) {
  for (const ConstraintModel& c : model.constraints) {
    const Vec3T<S> pa = point_position<S>(d, c.body_a, c.point_a), pb = point_position<S>(d, c.body_b, c.point_b);
    const Vec3T<S> dp = pa - pb;
    Vec3T<S> dpd, dpdd;
    MatXT<S> Jp, Jwa, Jwb;
    if (with_velocity) {
      dpd = point_velocity<S>(d, c.body_a, c.point_a) - point_velocity<S>(d, c.body_b, c.point_b);
      dpdd = point_acceleration<S>(d, c.body_a, c.point_a) - point_acceleration<S>(d, c.body_b, c.point_b);
      Jp = point_jacobian<S>(model, d, c.body_a, c.point_a) - point_jacobian<S>(model, d, c.body_b, c.point_b);
      Jwa = body_jacobian_world<S>(model, d, c.body_a).topRows(3);
      Jwb = body_jacobian_world<S>(model, d, c.body_b).topRows(3);
    }
    int r = c.row;
    switch (c.type) {
      case ConstraintType::Ball:
      case ConstraintType::Revolute:
        d.phi.template segment<3>(r) = dp;
        if (with_velocity) {
          d.Jc.middleRows(r, 3) = Jp;
          d.gamma.template segment<3>(r) = dpdd;
        }
        if (c.type == ConstraintType::Ball) break;
        r += 3;
        for (const Eigen::Vector3d* perp : {&c.perp_b1, &c.perp_b2}) {
          // a . b with a on body_a, b on body_b
          const Attached<S> a = attached<S>(d, c.body_a, c.axis_a), b = attached<S>(d, c.body_b, *perp);
          d.phi[r] = a.x.dot(b.x);
          if (with_velocity) {
            d.Jc.row(r) = a.x.cross(b.x).transpose() * (Jwa - Jwb);
            d.gamma[r] = a.xdd.dot(b.x) + S(2) * a.xd.dot(b.xd) + a.x.dot(b.xdd);
          }
          ++r;
        }
        break;
      case ConstraintType::PlanarRevolute:
        for (const Eigen::Vector3d* perp : {&c.perp_a1, &c.perp_a2}) {
          const Attached<S> e = attached<S>(d, c.body_a, *perp);
          d.phi[r] = e.x.dot(dp);
          if (with_velocity) {
            d.Jc.row(r) = e.x.cross(dp).transpose() * Jwa + e.x.transpose() * Jp;
            d.gamma[r] = e.xdd.dot(dp) + S(2) * e.xd.dot(dpd) + e.x.dot(dpdd);
          }
          ++r;
        }
        break;
    }
  }
}

}  // namespace

template <class S>
const VecXT<S>& constraint_residual(const Model& model, DataT<S>& d, const VecXT<S>& q) {
  forward_kinematics<S>(model, d, q);
  fill_rows<S>(model, d, false);
  return d.phi;
}

template <class S>
void constraint_terms(const Model& model, DataT<S>& d, const VecXT<S>& q, const VecXT<S>& v) {
  const VecXT<S> zero = VecXT<S>::Zero(model.nv);
  forward_kinematics<S>(model, d, q, v, zero);
  fill_rows<S>(model, d, true);
}

#define CODYNA_INSTANTIATE(S)                                                                           \
  template const VecXT<S>& constraint_residual<S>(const Model&, DataT<S>&, const VecXT<S>&);            \
  template void constraint_terms<S>(const Model&, DataT<S>&, const VecXT<S>&, const VecXT<S>&);
CODYNA_INSTANTIATE(double)
CODYNA_INSTANTIATE(ADScalar)
#undef CODYNA_INSTANTIATE

}  // namespace codyna
