// The plant as a first-order system in minimal coordinates about a base
// configuration q_ref:
//   x = [z; w; s] z: tangent deviation of the independent coordinates from q_ref
//                w: the independent velocities (as many as z, fewer with rolling's
//                   non-holonomic rows: then some of z's rates follow from w)
//                s: the effect states (Model::ns: a tire's transient slip), absolute values
//   xdot = f(x, u),  y = h(x, u)       u: values of the Plant/In actuators
// For a tree every coordinate is independent. For closed loops the
// independent coordinates come from coordinate partitioning of the constraint
// Jacobian (or the user's choice); the dependent ones follow from phi(q) = 0
// (Newton) and Jc v = 0. Rotations of spherical/free joints are tangent
// vectors (right-trivialized: R = R_ref Exp(z)), never quaternion components.
// eval is templated so that automatic differentiation runs through the same
// code (the independent check of the analytic Jacobian, and the exact Jacobian
// away from the operating point); double and ADScalar are instantiated.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "analysis/steady_motion.hpp"
#include "dynamics/data.hpp"

namespace codyna {

class TreeDerivatives;

struct CoordinatePartition {
  std::vector<int> independent;  // v indices, size DOF
  std::vector<int> dependent;    // v indices, size = independent constraint rows
  std::vector<int> driven;       // v indices of the motion inputs' coordinates (Model::motions order)
  // non-holonomic rows (rolling): the independent coordinates whose rates follow from the others'
  // (a subset of `independent`); the state's velocities are the rates of the rest (rates())
  std::vector<int> rate_dependent;
  // the independent coordinates whose rates are states, in `independent`'s order
  std::vector<int> rates() const;
};

// Chooses independent coordinates at q: the dependent ones are the pivot
// columns of a column-pivoted QR of the active constraint rows (the best
// conditioned choice). `preferred` (coordinate names, Model::v_names) overrides
// it; throws std::invalid_argument if a name is unknown, the count is not the
// DOF, or the remaining coordinates cannot be solved from the constraints.
CoordinatePartition partition_coordinates(const Model& model, const Eigen::VectorXd& q,
                                          const std::vector<std::string>& preferred = {});

// The same, with the coordinates `held` (Model::v_names) kept independent, so
// that a search over the independent coordinates can hold them exactly. With
// `preferred` given, every held coordinate must be among them; otherwise the
// dependent coordinates are chosen among the others (column-pivoted QR).
// Throws std::invalid_argument naming the coordinate when that is impossible.
CoordinatePartition partition_holding(const Model& model, const Eigen::VectorXd& q, const std::vector<std::string>& held,
                                      const std::vector<std::string>& preferred = {});

// the finite-difference step of coordinate value xk: sqrt(eps) max(1, |xk|)
// for forward differences, cbrt(eps) max(1, |xk|) for central ones
double fd_step(bool central, double xk);

class PlantFunction {
 public:
  // u_all: every actuator's value at the reference (plant inputs are replaced by eval's u)
  PlantFunction(const Model& model, const Eigen::VectorXd& q_ref, const Eigen::VectorXd& u_all,
                CoordinatePartition partition);

  int nz() const { return static_cast<int>(part_.independent.size()); }
  // the independent velocities: nz() less the active non-holonomic rows (rolling); nz() otherwise
  int nw() const { return static_cast<int>(rates_.size()); }
  // the effect states (Model::ns: the tires' transient slip), last in x, absolute values
  int ns() const { return model_.ns; }
  int nx() const { return nz() + nw() + ns(); }
  // velocity indices of the state's velocities w (CoordinatePartition::rates())
  const std::vector<int>& rates() const { return rates_; }
  int nu() const { return static_cast<int>(model_.plant_inputs.size()); }
  // the Plant/In inputs that are motion inputs (positions in plant_inputs). eval takes u of size
  // nu(), or nu() + 2 nm(): then u's tail holds their rates u' and then their accelerations u''
  // (otherwise 0); the other motion actuators stay at their nominal value, at rest
  int nm() const { return static_cast<int>(motion_inputs_.size()); }
  const std::vector<int>& motion_inputs() const { return motion_inputs_; }
  int ny() const { return static_cast<int>(model_.plant_outputs.size()); }

  template <class S>
  void eval(const VecXT<S>& x, const VecXT<S>& u, VecXT<S>& xdot, VecXT<S>& y) const;

  // the full configuration and velocity of state x (double)
  void state_to_qv(const Eigen::VectorXd& x, Eigen::VectorXd& q, Eigen::VectorXd& v) const;
  // x of a full (q, v) near q_ref: z = difference(q_ref, q)[independent], w = v[independent], and
  // the effect states s (without s: those at rest at (q, v), effect_states_steady)
  Eigen::VectorXd qv_to_state(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  Eigen::VectorXd qv_to_state(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& s) const;

  // names and units, in state order; absolute values of the additive coordinates at x = 0
  std::vector<std::string> state_names() const;
  std::vector<std::string> state_units() const;
  Eigen::VectorXd state_offset(const Eigen::VectorXd& v_ref) const;

  // The exact Jacobian [A B; C D] at (x, u) by analytic derivatives of the
  // recursive algorithms (dynamics/derivatives.hpp), into J (resized only when
  // its size differs). Applies at x with zero position deviation (the
  // operating point itself), on trees and closed loops; returns false
  // otherwise (callers then differentiate eval<ADScalar>). No heap allocation
  // after the first call. For closed loops, with G = d(v)/d(w) (the
  // independent velocities' map, from Jc v = 0) and H = d(v)/d(z) (from the
  // derivative of Jc v along the loops), the chain rule through q(z), v(z, w)
  // gives A and C from the constrained accelerations' and sensors' derivatives.
  bool analytic_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::MatrixXd& J) const;

  // The finite-difference Jacobian [A B; C D] at (x, u) on tree models, into J
  // (resized only when its size differs): forward ((f(x + h e) - f(x)) / h,
  // h = fd_step(false, x_k)) or central ((f(x + h e) - f(x - h e)) / 2h,
  // h = fd_step(true, x_k)) differences of eval<double>. The velocity and input
  // columns reuse the position stage of x (kinematics of q and the articulated
  // inertias), the input columns its velocity terms too: one full evaluation
  // per position column (two if central), one more at x, the rest without the
  // position stage; the same numbers as differencing eval column by column.
  // Returns false for closed loops.
  bool fd_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u, bool central, Eigen::MatrixXd& J) const;

  // About a steady motion (analysis/steady_motion.hpp): the state is then the deviation from the
  // pose that moves with `motion`'s frame, and eval gives its rates in that frame. The analytic
  // and the finite-difference fast paths do not apply (analytic_jacobian and fd_jacobian return
  // false): the exact Jacobian is automatic differentiation of eval. (A motion that does not turn,
  // SteadyMotion::turns, changes only the positions' rates by constants, nothing of A.)
  void set_motion(const SteadyMotion& motion);
  const SteadyMotion* motion() const { return motion_.get(); }

  const CoordinatePartition& partition() const { return part_; }
  const Eigen::VectorXd& u_all() const { return u_all_; }

  // Takes the model's evaluation workspaces (its Data and TreeDerivatives, the costly part of a first
  // evaluation) from another plant function of the same Model, which makes them again if it is used
  // after. For a search that makes a plant function per step (static_equilibrium): the numbers are
  // those of a plant function that made its own. Nothing is taken from a plant function of another Model.
  void take_workspace(PlantFunction& other);

 private:
  Eigen::VectorXd solve_dependent(const Eigen::VectorXd& z) const;  // tangent deviation of dependent coords (newton_dependent)

  const Model& model_;
  Eigen::VectorXd q_ref_, u_all_;
  CoordinatePartition part_;
  std::vector<int> rows_;  // constraint rows on q independent at q_ref (the holonomic ones)
  // the velocities' rows (rows_, then the active non-holonomic rows), the state's rates, and the
  // velocities solved from them (dependent, then rate_dependent)
  std::vector<int> vrows_, rates_, vdep_;
  std::vector<int> motion_inputs_;
  std::shared_ptr<const SteadyMotion> motion_;

  // workspace of analytic_jacobian, made on first use; a copy starts without one
  // eval<double> on a tree, into the workspace (no heap after the first call)
  // what eval_tree may reuse from its last call: Positions, x has the same
  // position part (kinematics of q and articulated inertias are still in the
  // workspace); Motion, x is the same (velocity terms too): only u changed
  enum class Reuse { Nothing, Positions, Motion };
  void eval_tree(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot, Eigen::VectorXd& y,
                 Reuse reuse = Reuse::Nothing) const;

  bool closed_loop_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::MatrixXd& J) const;
  // eval<double> on a closed loop, into the workspace (no heap after the first call):
  // Newton on the plant's rows for the dependent positions, Jc v = 0 for the velocities
  void eval_closed(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot,
                   Eigen::VectorXd& y) const;
  void loop_workspace() const;  // sizes the closed-loop part of the workspace once
  // Newton on phi(q) = 0 (the plant's rows) for the dependent coordinates at independent
  // deviations z, from the reference: leaves dq, q and the constraint terms at q in the workspace
  void newton_dependent(const Eigen::Ref<const Eigen::VectorXd>& z) const;
  // the same from the deviations already in the workspace's dq (the independent coordinates' and
  // the motion inputs' coordinates set, the dependent ones 0)
  void newton_from_workspace() const;
  // eval<double> with motion inputs or rolling's no-slip rows, into the workspace (no heap after the
  // first call): the motions' coordinates, rates and accelerations, Newton for the dependent
  // positions with the motions' coordinates in place, the velocities from all the velocity rows
  // (holonomic and no-slip) with the motions' rates, the dynamics, the sensors
  void eval_driven(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot,
                   Eigen::VectorXd& y) const;
  void factor_dependent() const;  // Jd from the workspace's constraint terms, into its LU

  struct Workspace {
    std::unique_ptr<TreeDerivatives> td;
    std::unique_ptr<Data> data;
    Eigen::VectorXd v, u_all, dq, q, w, rate;
    Eigen::MatrixXd Ja, Jd, Jz, G, H, P, DQ;  // closed loops: active rows, their columns, v maps, products
    Eigen::VectorXd zero, phi, step, vd;      // closed loops: [nv], [nd] x 3
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;  // of Jd
    Eigen::VectorXd fd_x, fd_u, fd_xd, fd_y, fd_p, fd_m, fd_0;  // fd_jacobian
    // rolling (closed_loop_jacobian): the velocity map Gv = dv/d[w; u'] apart from the positions' G,
    // the velocity rows' dependent columns Jvd (factored in luv), their products
    Eigen::MatrixXd Gv, Jvd, Jzv, Pv, Jav, Ph, Phx, DQv;
    Eigen::PartialPivLU<Eigen::MatrixXd> luv;
    // eval_driven: the velocity rows' dependent columns, right-hand side and solution, and their LU
    Eigen::MatrixXd ev_J;
    Eigen::VectorXd ev_r, ev_s;
    Eigen::PartialPivLU<Eigen::MatrixXd> ev_lu;
    Workspace();
    Workspace(const Workspace&);
    Workspace& operator=(const Workspace&);  // the copy makes its own
    ~Workspace();
  };
  mutable Workspace ws_;
};

// The state names and units of a plant whose independent coordinates are `independent`
// (PlantFunction::state_names and state_units, without making a plant function)
std::vector<std::string> plant_state_names(const Model& model, const std::vector<int>& independent);
std::vector<std::string> plant_state_units(const Model& model, const std::vector<int>& independent);
// with non-holonomic rows: the positions' coordinates `independent`, the velocities' `rates`
std::vector<std::string> plant_state_names(const Model& model, const std::vector<int>& independent,
                                           const std::vector<int>& rates);
std::vector<std::string> plant_state_units(const Model& model, const std::vector<int>& independent,
                                           const std::vector<int>& rates);

}  // namespace codyna
