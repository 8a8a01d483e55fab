#include "common.hpp"

#include <iostream>
#include <stdexcept>

#include "io/model_file.hpp"
#include "dynamics/assembly.hpp"
#include "simulation/reference_integrator.hpp"
#include "simulation/simulator.hpp"

#include <algorithm>
#include <cmath>

namespace codyna::cli {

Model load_model(const std::string& path) {
  const ModelSpec spec = load_model_spec(path);
  return compile(spec, path);
}

// applies --set NAME=VALUE to joint coordinates, then re-assembles loops
Model with_settings(Model m, const std::vector<std::string>& set) {
  if (set.empty()) return m;
  for (const std::string& s : set) {
    const auto eq = s.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--set " + s + ": expected NAME=VALUE");
    const std::string name = s.substr(0, eq);
    double value;
    try {
      value = std::stod(s.substr(eq + 1));
    } catch (const std::exception&) {
      throw std::invalid_argument("--set " + s + ": expected a number after '='");
    }
    const auto it = std::find(m.q_names.begin(), m.q_names.end(), name);
    if (it == m.q_names.end()) {
      std::string all;
      for (const auto& n : m.q_names) all += (all.empty() ? "" : ", ") + n;
      throw std::invalid_argument("--set " + s + ": unknown coordinate \"" + name + "\" (coordinates: " + all + ")");
    }
    m.q0[it - m.q_names.begin()] = value;
  }
  const AssemblyResult r = assemble(m, m.q0, m.v0);
  if (!r.converged) throw std::invalid_argument("--set: the loops cannot be assembled at the given coordinates");
  m.q0 = r.q;
  m.v0 = r.v;
  return m;
}

OperatingPoint operating_point(const Model& m, const std::string& which, const std::vector<std::string>& independent) {
  const OperatingPoint start = initial_point(m);
  if (which == "initial") return start;
  if (which == "equilibrium") {
    const OperatingPoint op = static_equilibrium(m, start, independent);
    if (!(op.residual < 1e-8))
      throw std::invalid_argument("--operating-point equilibrium: no static equilibrium found near the initial state "
                                  "(accelerations " + std::to_string(op.residual) + " left after " +
                                  std::to_string(op.iterations) + " iterations); use --operating-point initial, trim or time=T");
    return op;
  }
  if (which == "trim") return trim(m, start, independent);
  if (which.rfind("time=", 0) == 0) {
    double t;
    try {
      t = std::stod(which.substr(5));
    } catch (const std::exception&) {
      throw std::invalid_argument("--operating-point " + which + ": expected time=T with T a number of seconds");
    }
    if (!(t >= 0)) throw std::invalid_argument("--operating-point: the time must be >= 0");
    // the state the simulation reaches at t with the actuators at their nominal values
    // (the model's solver settings; no controller)
    if (t == 0) return snapshot_point(m, 0.0, m.q0, m.v0, start.u);
    SimulationOptions o;
    o.integrator.method = m.spec.solver.integrator;
    o.integrator.rtol = m.spec.solver.rtol;
    o.integrator.atol = m.spec.solver.atol;
    o.integrator.max_step = m.spec.solver.max_step;
    o.t_end = t;
    o.output_step = t;
    const SimulationResult r = simulate(m, nullptr, nullptr, o);
    if (!r.completed) throw std::runtime_error("--operating-point " + which + ": the simulation failed: " + r.failure);
    const State x{r.q.row(r.samples() - 1).transpose(), r.v.row(r.samples() - 1).transpose()};
    return snapshot_point(m, t, x.q, x.v, start.u);
  }
  throw std::invalid_argument("--operating-point " + which + ": expected initial, equilibrium, trim or time=T");
}

int run_guarded(const std::function<void()>& f) {
  try {
    f();
    return 0;
  } catch (const ModelError& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace codyna::cli
