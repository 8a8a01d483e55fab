#include "simulation/trajectory_linearization.hpp"

#include <stdexcept>

#include "analysis/linearizer.hpp"
#include "analysis/operating_point.hpp"

namespace codyna {

std::vector<Linearization> linearize_along(const Model& model, const SimulationResult& r, LinearizeOptions options,
                                           int stride) {
  if (stride < 1) throw std::invalid_argument("linearize_along: stride must be >= 1");
  std::vector<Linearization> out;
  Linearizer linearizer(model);  // the workspaces and names, made once for every point
  for (int k = 0; k < r.samples(); k += stride) {
    OperatingPoint op = snapshot_point(model, r.t[k], r.q.row(k).transpose(), r.v.row(k).transpose(),
                                       r.u.row(k).transpose());
    // the run's effect states (a matrix without columns has no rows to take: none then)
    if (model.ns > 0 && r.s.cols() == model.ns && r.s.rows() == r.samples()) op.s = r.s.row(k).transpose();
    try {
      out.push_back(linearizer.linearize(op, options));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("linearization at t = " + std::to_string(r.t[k]) + " s: " + e.what());
    }
    if (options.independent.empty() && !out.back().partition.dependent.empty())
      for (int i : out.back().partition.independent) options.independent.push_back(model.v_names[i]);  // keep this order
  }
  return out;
}

}  // namespace codyna
