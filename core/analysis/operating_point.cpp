#include "analysis/operating_point.hpp"

#include <Eigen/QR>
#include <sstream>
#include <stdexcept>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"

namespace codyna {

OperatingPoint initial_point(const Model& model) {
  OperatingPoint op;
  op.kind = "initial";
  op.q = model.q0;
  op.v = model.v0;
  op.u = model.u_nominal();
  return op;
}

OperatingPoint snapshot_point(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& u) {
  if (q.size() != model.nq || v.size() != model.nv || u.size() != model.nu())
    throw std::invalid_argument("snapshot: state sizes do not match the model");
  OperatingPoint op;
  std::ostringstream label;
  label << "time=" << t;
  op.kind = label.str();
  op.t = t;
  op.q = q;
  op.v = v;
  op.u = u;
  return op;
}

namespace {
// accelerations of the independent coordinates at rest, x = [z; 0]
Eigen::VectorXd rest_accelerations(const PlantFunction& f, const Eigen::VectorXd& z, const Eigen::VectorXd& u) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), xd, y;
  x.head(f.nz()) = z;
  f.eval<double>(x, u, xd, y);
  return xd.tail(f.nz());
}

Eigen::VectorXd plant_u(const Model& m, const Eigen::VectorXd& u_all) {
  Eigen::VectorXd u(m.plant_inputs.size());
  for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) u[k] = u_all[m.plant_inputs[k]];
  return u;
}
}  // namespace

OperatingPoint static_equilibrium(const Model& model, const OperatingPoint& start,
                                  const std::vector<std::string>& independent) {
  OperatingPoint op = start;
  op.kind = "equilibrium";
  op.t = start.t;
  op.v = Eigen::VectorXd::Zero(model.nv);
  const Eigen::VectorXd u = plant_u(model, op.u);
  for (op.iterations = 0; op.iterations < 60; ++op.iterations) {
    const PlantFunction f(model, op.q, op.u, partition_coordinates(model, op.q, independent));
    const int n = f.nz();
    const Eigen::VectorXd r = rest_accelerations(f, Eigen::VectorXd::Zero(n), u);
    op.residual = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
    if (op.residual < 1e-11) break;
    const Eigen::MatrixXd J = plant_jacobian(f, Eigen::VectorXd::Zero(f.nx()), u, JacobianMethod::Exact);
    const Eigen::MatrixXd K = J.block(n, 0, n, n);  // d(qdd)/dz
    const Eigen::VectorXd dz = -Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(K).solve(r);
    double t = 1.0;
    bool moved = false;
    for (int k = 0; k < 30 && !moved; ++k, t *= 0.5) {
      const Eigen::VectorXd rn = rest_accelerations(f, t * dz, u);
      if (rn.norm() < r.norm()) {
        Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), v;
        x.head(n) = t * dz;
        f.state_to_qv(x, op.q, v);
        moved = true;
      }
    }
    if (!moved) break;
  }
  return op;
}

OperatingPoint trim(const Model& model, const OperatingPoint& start, const std::vector<std::string>& independent) {
  if (model.plant_inputs.empty())
    throw std::invalid_argument("trim: the plant has no inputs (add actuators to Plant/In) to hold the configuration");
  OperatingPoint op = start;
  op.kind = "trim";
  op.v = Eigen::VectorXd::Zero(model.nv);
  const PlantFunction f(model, op.q, op.u, partition_coordinates(model, op.q, independent));
  const int n = f.nz();
  Eigen::VectorXd u = plant_u(model, op.u);
  for (op.iterations = 0; op.iterations < 5; ++op.iterations) {
    const Eigen::VectorXd r = rest_accelerations(f, Eigen::VectorXd::Zero(n), u);
    op.residual = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
    if (op.residual < 1e-12) break;
    const Eigen::MatrixXd J = plant_jacobian(f, Eigen::VectorXd::Zero(f.nx()), u, JacobianMethod::Exact);
    const Eigen::MatrixXd Bq = J.block(n, f.nx(), n, f.nu());  // d(qdd)/du
    u -= Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(Bq).solve(r);
  }
  for (std::size_t k = 0; k < model.plant_inputs.size(); ++k) op.u[model.plant_inputs[k]] = u[k];
  const Eigen::VectorXd r = rest_accelerations(f, Eigen::VectorXd::Zero(n), u);
  op.residual = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
  // a holding input beyond its actuator's limits cannot hold the configuration: say which binds
  std::ostringstream bound;
  for (int k : model.plant_inputs) {
    const ActuatorModel& a = model.actuators[k];
    if (op.u[k] > a.max) bound << (bound.tellp() ? "; " : "") << a.name << " = " << op.u[k] << " is above its max " << a.max;
    if (op.u[k] < a.min) bound << (bound.tellp() ? "; " : "") << a.name << " = " << op.u[k] << " is below its min " << a.min;
  }
  if (bound.tellp())
    throw std::invalid_argument("trim: holding this configuration needs inputs beyond their limits: " + bound.str() +
                                " (raise the limits, add inputs, or trim another configuration)");
  return op;
}

}  // namespace codyna
