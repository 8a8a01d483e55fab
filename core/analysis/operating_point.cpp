#include "analysis/operating_point.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "analysis/linearize.hpp"
#include "analysis/plant_function.hpp"
#include "model/errors.hpp"

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
  return xd.segment(f.nz(), f.nw());
}

Eigen::VectorXd plant_u(const Model& m, const Eigen::VectorXd& u_all) {
  Eigen::VectorXd u(m.plant_inputs.size());
  for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) u[k] = u_all[m.plant_inputs[k]];
  return u;
}
}  // namespace


namespace {
int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

std::string joined_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none)" : s;
}
}  // namespace

std::string steady_state_advice(const std::vector<std::string>& plant_inputs, const std::vector<std::string>& fixed_inputs,
                                const std::vector<std::string>& held, const std::string& kind) {
  std::string a;
  if (plant_inputs.empty())
    a = "the plant has no Plant/In input to free: add an actuator to plant.inputs";
  else if (!fixed_inputs.empty())
    a = "free an input: free_inputs / --free-input " + joined_names(fixed_inputs);
  else
    a = "every Plant/In input is free already; add one that acts on the coordinates left unbalanced";
  if (!held.empty()) {
    a += a.empty() ? "" : "; or ";
    a += kind == "trim" ? "free a held coordinate: trim_free / --trim-free " + joined_names(held)
                        : "hold fewer coordinates (analysis set / --hold; held now: " + joined_names(held) + ")";
  }
  if (a.empty()) a = "ask for another state: a reachable output target, or the operating point initial or time=T";
  return a;
}

void require_steady_state(const Model& model, const OperatingPoint& op, const std::vector<std::string>& independent,
                          double tolerance) {
  if (op.residual < tolerance) return;
  const PlantFunction f(model, op.q, op.u, partition_coordinates(model, op.q, independent));
  const Eigen::VectorXd r = rest_accelerations(f, Eigen::VectorXd::Zero(f.nz()), plant_u(model, op.u));
  std::vector<std::string> in_names, coords;
  for (int k : model.plant_inputs) in_names.push_back(model.actuators[k].name);
  for (int i : f.rates()) coords.push_back(model.v_names[static_cast<std::size_t>(i)]);
  std::ostringstream os;
  os << op.kind << ": not converged: the residual accelerations are " << op.residual << " after " << op.iterations
     << " iterations (tolerance " << tolerance;
  if (r.size()) {
    Eigen::Index i = 0;
    const double worst = r.cwiseAbs().maxCoeff(&i);
    os << "; largest on " << coords[static_cast<std::size_t>(i)] << ": " << worst;
  }
  os << ")";
  if (op.kind == "trim") {
    // every independent coordinate held, every Plant/In input solved
    os << "; unknowns: free inputs " << joined_names(in_names) << ", free coordinates (none); held: " << joined_names(coords) << " ("
       << steady_state_advice(in_names, {}, coords, "trim") << ")";
  } else {
    os << "; unknowns: free inputs (none), free coordinates " << joined_names(coords) << " ("
       << steady_state_advice(in_names, in_names, {}, "equilibrium") << ")";
  }
  throw ConvergenceError(os.str());
}

OperatingPoint steady_state(const Model& model, const OperatingPoint& start, const SteadyStateSpec& spec,
                            const std::vector<std::string>& independent, const std::string& kind) {
  OperatingPoint op = start;
  op.kind = kind;
  op.v = Eigen::VectorXd::Zero(model.nv);
  // names -> indices
  std::vector<std::string> in_names, out_names;
  for (int k : model.plant_inputs) in_names.push_back(model.actuators[k].name);
  for (int k : model.plant_outputs) out_names.push_back(model.sensors[k].name);
  std::vector<int> free_u;  // positions in Plant/In
  for (const std::string& name : spec.free_inputs) {
    const int k = index_of(in_names, name);
    if (k < 0) throw std::invalid_argument("steady state: free input \"" + name + "\" is not in Plant/In (" + joined_names(in_names) + ")");
    if (std::find(free_u.begin(), free_u.end(), k) == free_u.end()) free_u.push_back(k);
  }
  std::vector<int> target_y;
  Eigen::VectorXd target(static_cast<Eigen::Index>(spec.outputs.size()));
  for (std::size_t i = 0; i < spec.outputs.size(); ++i) {
    const int k = index_of(out_names, spec.outputs[i].first);
    if (k < 0)
      throw std::invalid_argument("steady state: output \"" + spec.outputs[i].first + "\" is not in Plant/Out (" +
                                  joined_names(out_names) + ")");
    if (!std::isfinite(spec.outputs[i].second))
      throw std::invalid_argument("steady state: the value of output \"" + spec.outputs[i].first + "\" is not finite");
    target_y.push_back(k);
    target[static_cast<Eigen::Index>(i)] = spec.outputs[i].second;
  }
  Eigen::VectorXd u = plant_u(model, op.u);
  std::vector<std::string> clamped;  // "name = limit (min|max)"
  const auto residual = [&](const PlantFunction& f, const Eigen::VectorXd& z, const Eigen::VectorXd& uu) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), xd, y;
    x.head(f.nz()) = z;
    f.eval<double>(x, uu, xd, y);
    Eigen::VectorXd r(f.nw() + static_cast<Eigen::Index>(target_y.size()));
    r.head(f.nw()) = xd.segment(f.nz(), f.nw());
    for (std::size_t i = 0; i < target_y.size(); ++i)
      r[f.nw() + static_cast<Eigen::Index>(i)] = y[target_y[i]] - target[static_cast<Eigen::Index>(i)];
    return r;
  };
  double accel_left = 0.0, output_left = 0.0;
  std::vector<std::string> free_coords;  // the unknown coordinates of the last iteration
  std::string worst;                     // the coordinate whose acceleration is furthest from 0
  const int rounds = static_cast<int>(free_u.size()) + 1;  // each clamps at least one input, or ends
  for (int round = 0; round < rounds; ++round) {
    for (op.iterations = 0; op.iterations < 60; ++op.iterations) {
      const CoordinatePartition part = partition_holding(model, op.q, spec.held, independent);
      for (std::size_t k = 0; k < model.plant_inputs.size(); ++k) op.u[model.plant_inputs[k]] = u[static_cast<Eigen::Index>(k)];
      const PlantFunction f(model, op.q, op.u, part);
      const int n = f.nz(), na = f.nw();  // positions, and accelerations (fewer with rolling)
      std::vector<int> free_z;  // unknown positions in z
      for (int k = 0; k < n; ++k)
        if (index_of(spec.held, model.v_names[static_cast<std::size_t>(part.independent[static_cast<std::size_t>(k)])]) < 0)
          free_z.push_back(k);
      const Eigen::VectorXd z0 = Eigen::VectorXd::Zero(n);
      const Eigen::VectorXd r = residual(f, z0, u);
      accel_left = na ? r.head(na).lpNorm<Eigen::Infinity>() : 0.0;
      free_coords.clear();
      for (int k : free_z) free_coords.push_back(model.v_names[static_cast<std::size_t>(part.independent[static_cast<std::size_t>(k)])]);
      if (na) {
        Eigen::Index i = 0;
        r.head(na).cwiseAbs().maxCoeff(&i);
        worst = model.v_names[static_cast<std::size_t>(f.rates()[static_cast<std::size_t>(i)])];
      }
      output_left = target_y.empty() ? 0.0 : r.tail(static_cast<Eigen::Index>(target_y.size())).lpNorm<Eigen::Infinity>();
      if (accel_left < 1e-11 && output_left < 1e-11 * (1.0 + (target.size() ? target.lpNorm<Eigen::Infinity>() : 0.0)))
        break;
      const Eigen::MatrixXd J = plant_jacobian(f, Eigen::VectorXd::Zero(f.nx()), u, JacobianMethod::Exact);
      const Eigen::Index m = r.size(), nf = static_cast<Eigen::Index>(free_z.size() + free_u.size());
      if (nf == 0) break;
      Eigen::MatrixXd G(m, nf);
      for (Eigen::Index i = 0; i < m; ++i) {
        const Eigen::Index row = i < na ? n + i : f.nx() + target_y[static_cast<std::size_t>(i - na)];
        Eigen::Index c = 0;
        for (int k : free_z) G(i, c++) = J(row, k);
        for (int k : free_u) G(i, c++) = J(row, f.nx() + k);
      }
      const Eigen::VectorXd step = -Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(G).solve(r);
      bool moved = false;
      double t = 1.0;
      for (int k = 0; k < 30 && !moved; ++k, t *= 0.5) {
        Eigen::VectorXd dz = Eigen::VectorXd::Zero(n), un = u;
        Eigen::Index c = 0;
        for (int j : free_z) dz[j] = t * step[c++];
        for (int j : free_u) un[j] += t * step[c++];
        if (residual(f, dz, un).norm() < r.norm()) {
          Eigen::VectorXd x = Eigen::VectorXd::Zero(f.nx()), v;
          x.head(n) = dz;
          f.state_to_qv(x, op.q, v);
          u = un;
          moved = true;
        }
      }
      if (!moved) break;
    }
    // a free input beyond its limits: hold it at the limit, solve the rest again
    bool clamped_now = false;
    for (auto it = free_u.begin(); it != free_u.end();) {
      const ActuatorModel& a = model.actuators[model.plant_inputs[static_cast<std::size_t>(*it)]];
      const double value = u[*it];
      if (value > a.max || value < a.min) {
        const bool above = value > a.max;
        u[*it] = above ? a.max : a.min;
        std::ostringstream os;
        os << a.name << " at its " << (above ? "max " : "min ") << u[*it] << " (it would need " << value << ")";
        clamped.push_back(os.str());
        it = free_u.erase(it);
        clamped_now = true;
      } else {
        ++it;
      }
    }
    if (!clamped_now) break;
  }
  for (std::size_t k = 0; k < model.plant_inputs.size(); ++k) op.u[model.plant_inputs[k]] = u[static_cast<Eigen::Index>(k)];
  op.residual = accel_left;
  const double out_tol = 1e-8 * (1.0 + (target.size() ? target.lpNorm<Eigen::Infinity>() : 0.0));
  if (!(accel_left < 1e-8) || !(output_left < out_tol)) {
    std::ostringstream os;
    os << "steady state: not found: the residual accelerations are " << accel_left << " (tolerance 1e-08";
    if (!worst.empty()) os << "; largest on " << worst;
    os << ")";
    if (!target_y.empty()) os << ", outputs off by " << output_left;
    std::vector<std::string> fixed_inputs;  // Plant/In inputs the search did not solve for
    for (const std::string& name : in_names)
      if (std::find(spec.free_inputs.begin(), spec.free_inputs.end(), name) == spec.free_inputs.end()) fixed_inputs.push_back(name);
    os << "; unknowns: free inputs " << joined_names(spec.free_inputs) << ", free coordinates " << joined_names(free_coords)
       << "; held: " << joined_names(spec.held);
    if (!clamped.empty()) {
      os << "; the actuator limits bind: ";
      for (std::size_t k = 0; k < clamped.size(); ++k) os << (k ? "; " : "") << clamped[k];
      os << " (raise the limits, free other inputs, or ask for another state)";
    } else {
      os << " (" << steady_state_advice(in_names, fixed_inputs, spec.held, kind) << ")";
    }
    throw ConvergenceError(os.str());
  }
  return op;
}

OperatingPoint static_equilibrium(const Model& model, const OperatingPoint& start,
                                  const std::vector<std::string>& independent) {
  OperatingPoint op = start;
  op.kind = "equilibrium";
  op.t = start.t;
  op.v = Eigen::VectorXd::Zero(model.nv);
  const Eigen::VectorXd u = plant_u(model, op.u);
  // one plant function per configuration; each takes the Data and derivative workspaces of the one
  // before it (made once per search, not per step: the same numbers)
  auto plant_at = [&](const Eigen::VectorXd& q, PlantFunction* from) {
    auto p = std::make_unique<PlantFunction>(model, q, op.u, partition_coordinates(model, q, independent));
    if (from) p->take_workspace(*from);
    return p;
  };
  std::unique_ptr<PlantFunction> f = plant_at(op.q, nullptr);
  for (op.iterations = 0; op.iterations < 60; ++op.iterations) {
    const int n = f->nz();
    const Eigen::VectorXd r = rest_accelerations(*f, Eigen::VectorXd::Zero(n), u);
    op.residual = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
    if (op.residual < 1e-11) break;
    const Eigen::MatrixXd J = plant_jacobian(*f, Eigen::VectorXd::Zero(f->nx()), u, JacobianMethod::Exact);
    const Eigen::MatrixXd K = J.block(n, 0, f->nw(), n);  // d(qdd)/dz
    const Eigen::VectorXd dz = -Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(K).solve(r);
    double t = 1.0;
    bool moved = false;
    for (int k = 0; k < 30 && !moved; ++k, t *= 0.5) {
      // a trial step may reach a configuration where the loops' constraints are singular (the
      // Bricard linkage's bifurcations), in this chart or in the next iteration's: a step whose
      // evaluation fails there is too long and is halved like one that does not lower the residual
      try {
        const Eigen::VectorXd rn = rest_accelerations(*f, t * dz, u);
        if (!rn.allFinite() || !(rn.norm() < r.norm())) continue;
        Eigen::VectorXd x = Eigen::VectorXd::Zero(f->nx()), v, q;
        x.head(n) = t * dz;
        f->state_to_qv(x, q, v);
        std::unique_ptr<PlantFunction> next = plant_at(q, f.get());
        if (!rest_accelerations(*next, Eigen::VectorXd::Zero(next->nz()), u).allFinite()) {
          f->take_workspace(*next);
          continue;
        }
        op.q = q;
        f = std::move(next);  // the next iteration's plant function (at op.q, its partition there)
        moved = true;
      } catch (const std::exception&) {  // singular constraints (runtime_error) or no chart there (invalid_argument)
        continue;
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
    const Eigen::MatrixXd Bq = J.block(n, f.nx(), f.nw(), f.nu());  // d(qdd)/du
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
    throw ConvergenceError("trim: holding this configuration needs inputs beyond their limits: " + bound.str() +
                                " (raise the limits, add inputs, or trim another configuration)");
  return op;
}

}  // namespace codyna
