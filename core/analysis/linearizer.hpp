// Linearizer: linearize() many times on one model, reusing what does not change
// from one operating point to the next (issue 22: a study, a trajectory).
//
//   Linearizer lz(model);                 // model must outlive lz, its numbers unchanged
//   lz.bind(other);                       // (or bound again: another model, or this one changed)
//   Linearization a = lz.linearize(op1);  // the same numbers as linearize(model, op1)
//   lz.linearize(op2, options, out);      // into out, reusing its storage
//
// On trees without motion inputs, with the exact method and the automatic
// partition (every coordinate independent), it keeps the analytic derivatives'
// workspace (TreeDerivatives), the partition, the state, input and output
// names and units, and where each x0 entry comes from; a call is then the
// exact Jacobian (x0dot and y0 are its own accelerations and sensor values,
// equal to a forward-dynamics evaluation's to round-off) and copies, with no
// heap allocation when writing into a
// Linearization of the same sizes. Other cases (closed loops, motion inputs,
// finite differences, chosen independent coordinates) take linearize()'s
// general path. linearize(model, op, options) is Linearizer(model).linearize(op,
// options): A, B, C, D, x0, u0, y0, x0dot bit for bit the same either way.
#pragma once

#include <memory>

#include "analysis/linearize.hpp"

namespace codyna {

class Linearizer {
 public:
  explicit Linearizer(const Model& model);
  ~Linearizer();
  Linearizer(const Linearizer&) = delete;
  Linearizer& operator=(const Linearizer&) = delete;

  Linearization linearize(const OperatingPoint& op, const LinearizeOptions& options = {});
  void linearize(const OperatingPoint& op, const LinearizeOptions& options, Linearization& out);

  // linearize another model (or this one after its numbers changed) from now on, keeping the
  // workspaces' storage: everything derived from the model is made again at the next call, as
  // by a new Linearizer(model)
  void bind(const Model& model);

 private:
  friend Linearization linearize(const Model&, const OperatingPoint&, const LinearizeOptions&);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace codyna
