#include "analysis/linearize.hpp"

#include <cmath>
#include <limits>

#include "dynamics/kinematics.hpp"
#include "model/errors.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

const char* to_string(JacobianMethod m) {
  switch (m) {
    case JacobianMethod::Exact: return "exact";
    case JacobianMethod::ForwardDifference: return "fd-forward";
    case JacobianMethod::CentralDifference: return "fd-central";
  }
  return "?";
}

namespace {
Eigen::VectorXd stacked(const PlantFunction& f, const Eigen::VectorXd& xu) {
  const int nx = f.nx();
  Eigen::VectorXd xd, y;
  f.eval<double>(xu.head(nx), xu.tail(f.nu()), xd, y);
  Eigen::VectorXd r(xd.size() + y.size());
  r << xd, y;
  return r;
}
}  // namespace

Eigen::MatrixXd plant_jacobian_autodiff(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
  const int nx = f.nx(), nu = f.nu(), ny = f.ny(), n = nx + nu;
  Eigen::MatrixXd J(nx + ny, n);
  const ADVec xa = ad_seed(x, n, 0), ua = ad_seed(u, n, nx);
  ADVec xd, y;
  f.eval<ADScalar>(xa, ua, xd, y);
  for (int r = 0; r < nx + ny; ++r) {
    const ADScalar& s = r < nx ? xd[r] : y[r - nx];
    J.row(r) = s.derivatives().size() ? Eigen::RowVectorXd(s.derivatives().transpose()) : Eigen::RowVectorXd::Zero(n);
  }
  return J;
}

Eigen::MatrixXd plant_jacobian(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                               JacobianMethod method) {
  Eigen::MatrixXd J(f.nx() + f.ny(), f.nx() + f.nu());
  if (method == JacobianMethod::Exact) {
    if (f.analytic_jacobian(x, u, J)) return J;
    return plant_jacobian_autodiff(f, x, u);
  }
  const bool central = method == JacobianMethod::CentralDifference;
  if (f.fd_jacobian(x, u, central, J)) return J;
  return plant_jacobian_fd_full(f, x, u, central);
}

Eigen::MatrixXd plant_jacobian_fd_full(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                       bool central) {
  const int nx = f.nx(), nu = f.nu(), ny = f.ny(), n = nx + nu;
  Eigen::VectorXd xu(n);
  xu << x, u;
  Eigen::MatrixXd J(nx + ny, n);
  const Eigen::VectorXd f0 = central ? Eigen::VectorXd() : stacked(f, xu);
  for (int k = 0; k < n; ++k) {
    const double h = fd_step(central, xu[k]);
    Eigen::VectorXd xp = xu;
    xp[k] += h;
    if (central) {
      Eigen::VectorXd xm = xu;
      xm[k] -= h;
      J.col(k) = (stacked(f, xp) - stacked(f, xm)) / (2 * h);
    } else {
      J.col(k) = (stacked(f, xp) - f0) / h;
    }
  }
  return J;
}

namespace {

// A spring-damper whose two points coincide has no direction there: its damping force
// c (n . v) n and, with a rest length, its elastic force k (0 - L0) n have no limit, and so no
// derivative (exact and finite differences would each report their own number). Refused with
// the element and the way out; a rest length 0 spring without damping is smooth (k dp) and fine.
void refuse_coincident_spring_dampers(const Model& model, const Eigen::VectorXd& q) {
  if (model.springs.empty()) return;
  Data d(model);
  forward_kinematics<double>(model, d, q);
  for (const SpringDamperModel& s : model.springs) {
    const double L = (point_position<double>(d, s.body_b, s.point_b) - point_position<double>(d, s.body_a, s.point_a)).norm();
    if (L > 1e-12 || (s.damping == 0.0 && s.rest_length == 0.0)) continue;
    std::string path = "/effects";
    for (std::size_t k = 0; k < model.spec.effects.size(); ++k)
      if (model.spec.effects[k].name == s.name) path += "/" + std::to_string(k);
    throw ModelError(model.source_file, path,
                     "spring_damper \"" + s.name + "\": its two points coincide at the operating point (length " +
                         std::to_string(L) + " m), where its " +
                         (s.damping != 0.0 ? std::string("damping force c (n . v) n") : std::string("force k (0 - rest_length) n")) +
                         " has no direction and no derivative; offset the points, or use rest_length 0 without damping "
                         "(then the force k (x_b - x_a) is smooth), or linearize elsewhere");
  }
}

}  // namespace

Linearization linearize(const Model& model, const OperatingPoint& op, const LinearizeOptions& options) {
  refuse_coincident_spring_dampers(model, op.q);
  Linearization out;
  out.partition = partition_coordinates(model, op.q, options.independent);
  const PlantFunction f(model, op.q, op.u, out.partition);
  const int nx = f.nx(), nu = f.nu(), ny = f.ny();
  // state at the operating point: zero deviation, independent velocities
  Eigen::VectorXd x = Eigen::VectorXd::Zero(nx);
  for (int k = 0; k < f.nz(); ++k) x[f.nz() + k] = op.v[out.partition.independent[k]];
  Eigen::VectorXd u(nu);
  for (int k = 0; k < nu; ++k) u[k] = op.u[model.plant_inputs[k]];

  const Eigen::MatrixXd J = plant_jacobian(f, x, u, options.method);
  if (options.method != JacobianMethod::Exact) {
    const Eigen::MatrixXd Je = plant_jacobian(f, x, u, JacobianMethod::Exact);
    const double scale = std::max(Je.cwiseAbs().maxCoeff(), 1e-300);
    out.fd_error = (J - Je).cwiseAbs().maxCoeff() / scale;
  }
  LinearSystem& s = out.system;
  s.A = J.topLeftCorner(nx, nx);
  s.B = J.topRightCorner(nx, nu);
  s.C = J.bottomLeftCorner(ny, nx);
  s.D = J.bottomRightCorner(ny, nu);
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);
  s.x0 = f.state_offset(op.v);
  s.u0 = u;
  s.y0 = y;
  s.xdot0 = xd;
  s.state_names = f.state_names();
  s.state_units = f.state_units();
  for (int k : model.plant_inputs) {
    s.input_names.push_back(model.actuators[k].name);
    s.input_units.push_back(model.actuators[k].unit);
  }
  for (int k : model.plant_outputs) {
    s.output_names.push_back(model.sensors[k].name);
    s.output_units.push_back(model.sensors[k].unit);
  }
  s.model_name = model.name;
  s.model_file = model.source_file;
  s.operating_point = op.kind;
  s.method = to_string(options.method);
  s.time = op.t;
  s.codyna_version = CODYNA_VERSION;
  return out;
}

}  // namespace codyna
