// Exact first derivatives of tree dynamics, by analytic differentiation of the
// recursive algorithms (no automatic differentiation, no finite differences).
//
// Everything is expressed in world coordinates: body i has the world spatial
// velocity V_i = [w; v_O] and acceleration A_i (gravity entered as A_0 = -g),
// the world inertia I_i, and each joint column the world motion subspace S_c.
// A position derivative is taken along a joint's tangent coordinate, the same
// one the plant state uses (right-trivialized for spherical and free joints):
// perturbing coordinate c moves the subtree below it rigidly by the twist S_c.
//
// Joints are handled as "units" whose columns move together with the child
// body: revolute, prismatic, cylindrical, spherical and free joints are one
// unit; universal and planar joints are chains of one-column units through
// massless intermediate frames (their first columns do not turn with the
// later ones). With u = s x V_par, w1 = s x A_par, w2 = u x V_par for a column s
// of unit k (V_par, A_par: velocity and acceleration of the frame unit k moves
// from), the composite inertia Ic, momentum hc, force F and "Coriolis inertia"
// Bc = sum(V x* I - I V x) of a subtree give, for a unit j at or below k,
//   d tau_j / d q_s  = S_j^T [ Ic (w2 - w1) - (Bc + H(hc)) u ]
//   d tau_j / d qd_s = S_j^T [ (Bc + H(hc)) s + Ic c ],   c = -s x (V_par + V_k)
// and for a unit j above k the same subtree terms of k plus s x* F_k (for q).
// H(h) is the matrix with H(h) u = u x* h. Applied forces from body elements
// (spring-dampers, body forces, body-force actuators) and body sensors are
// differentiated through their world wrench / value as functions of the poses
// and velocities of at most two bodies (fixed-size forward differentiation of
// a few lines, no heap), chained with the analytic Jacobians above.
//
// Closed loops (compute_constrained): the same tree derivatives at the
// constrained accelerations a, plus the loop closures. The reactions -Jc^T lambda
// are body wrenches (a force at each ball point, a couple for each orientation
// row) differentiated like the applied ones. The closure rows
// c = Jc a + gamma = d2 phi/dt2 and phidot = Jc v are functions of the poses,
// velocities and accelerations of two bodies (differentiated by fixed-size
// forward differentiation over those 36 local variables), chained with the
// world-frame derivatives of the bodies' motion: perturbing column s (unit k,
// parent frame motion V_p, A_p) of an ancestor of body i at fixed joint
// velocities and accelerations gives
//   dV_i/dq_s = s x (V_i - V_p)
//   dA_i/dq_s = V_p x (s x (V_i - V_p)) + s x (A_i - A_p - V_p x (V_i - V_p))
//   dA_i/dv_s = s x (V_i - V_k - V_p)          (V_k: velocity after unit k)
// Differentiating M a + Jc^T lambda = Q - nle and Jc_r a + gamma_r = 0 (the
// rows r independent at q) gives the derivatives of a by one solve with the
// same Schur complement as the forward dynamics.
//
// Used by linearize() at the reference configuration (trees and closed loops);
// checked against automatic differentiation of the same dynamics in the tests.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

#include "dynamics/data.hpp"
#include "model/model.hpp"

namespace codyna {

class TreeDerivatives {
 public:
  // model must outlive this object; with loop closures (model.nc > 0) only
  // compute_constrained() and rnea_derivatives() apply
  explicit TreeDerivatives(const Model& model);
  // the same as TreeDerivatives(model) for another model (or this one changed), reusing the
  // memory: everything derived from the model is made again, the storage kept where sizes repeat
  void bind(const Model& model);

  // true when compute() applies: a tree (no loop closures; every effect and sensor type is
  // differentiated); closed loops go through compute_constrained()
  static bool supports(const Model& model);

  // Closed loops: everything at (q, v, u_all) for joint accelerations a and
  // multipliers lambda [nc] that satisfy M a + nle = Q - Jc^T lambda and
  // Jc a + gamma = 0 on `rows` (independent constraint rows at q, as
  // forward_dynamics chose them; lambda is zero on the others). Motion inputs
  // (any model, loops or not): their coordinates' rows of that balance carry
  // the motions' reactions instead, and their accelerations are held, so each
  // enters the derivative system as one more row e_d da = d(acceleration)
  // (a rheonomic constraint with a constant Jacobian; its multiplier is the
  // reaction), solved on the free coordinates only (a motion's bodies may be
  // massless, M singular). Fills
  // dqdd_dq, dqdd_dv, dqdd_du (the constrained accelerations' derivatives),
  // Jc, dc_dq, dc_dv, dphid_dq, tau/dtau (at a), Q/dQ (including -Jc^T lambda)
  // and the sensors. No heap after the first call with the same sizes.
  void compute_constrained(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                           const Eigen::VectorXd& a, const Eigen::VectorXd& lambda, const std::vector<int>& rows,
                           const std::vector<int>& outputs);
  // The balance's parts alone (for an implicit integrator's Newton matrix, simulation/alf.cpp):
  // tau/dtau at a, Q/dQ (including -Jc^T lambda), M, Jc, dc_dq, dc_dv, as compute_constrained
  // gives them, without solving for the accelerations' derivatives (dqdd_* and the sensors'
  // derivatives are not touched). With motion inputs, a driven coordinate's row is its balance at
  // the a given (which holds the motion's reaction): the caller replaces it by the motion's.
  void compute_balance(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
                       const Eigen::VectorXd& a, const Eigen::VectorXd& lambda);

  // Everything at (q, v, u_all) (u_all: one value per actuator). `outputs` are
  // sensor indices whose values and derivatives are wanted. After the first
  // call with the same sizes, no heap allocation.
  void compute(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all,
               const std::vector<int>& outputs);

  // Only the rigid-body inverse dynamics tau = RNEA(q, v, a) (no applied
  // forces) and its derivatives; forward kinematics included.
  void rnea_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a);

  // results of compute()
  Eigen::VectorXd qdd;                      // [nv]
  Eigen::MatrixXd dqdd_dq, dqdd_dv;         // [nv x nv]
  Eigen::MatrixXd dqdd_du;                  // [nv x nu_all]
  // motion inputs (Model::motions, compute_constrained): derivatives with respect to each motion's
  // prescribed acceleration; its coordinate's value and rate are the columns of dqdd_dq and dqdd_dv
  Eigen::MatrixXd dqdd_dacc;                // [nv x motions]
  Eigen::VectorXd y;                        // [outputs]
  Eigen::MatrixXd dy_dq, dy_dv;             // [outputs x nv] (through the accelerations too)
  // sensors that read the accelerations (acceleration): their derivatives with respect to the
  // joint accelerations a at fixed (q, v), and through a(q, v, u) with respect to every actuator's
  // input (the D matrix's columns: dy_du = dy_da dqdd_du) and each motion's prescribed acceleration;
  // zero rows for the other sensors
  Eigen::MatrixXd dy_da;                    // [outputs x nv]
  Eigen::MatrixXd dy_du;                    // [outputs x nu_all]
  Eigen::MatrixXd dy_dacc;                  // [outputs x motions]
  // A caller that puts dy_du and dy_dacc into D sets this; otherwise compute() and
  // compute_constrained() refuse an acceleration sensor whose D column for a Plant/In force input
  // or a motion input's acceleration is not zero (it would be left out silently)
  bool feedthrough_read = false;
  // parts (also set by compute())
  Eigen::VectorXd tau;                      // RNEA at (q, v, qdd) without applied forces
  Eigen::MatrixXd dtau_dq, dtau_dv;         // [nv x nv]
  Eigen::VectorXd Q;                        // applied generalized forces
  Eigen::MatrixXd dQ_dq, dQ_dv, dQ_du;      // [nv x nv], [nv x nv], [nv x nu_all]
  // mass matrix at q: compute_constrained() fills it; compute() fills it below kDenseInverseBelow
  // coordinates and on the branched trees tree_inverse takes (M^-1 from its factors), and
  // otherwise only through fill_mass_matrix(), after it (M^-1 from the articulated bodies)
  Eigen::MatrixXd M;
  void fill_mass_matrix() { mass_matrix(); }
  // results of compute_constrained(), one row per constraint row [nc x nv]
  Eigen::MatrixXd Jc;                       // d phi / dq (tangent), as constraint_terms gives it
  Eigen::MatrixXd dc_dq, dc_dv;             // derivatives of c = Jc a + gamma at the given a
  Eigen::MatrixXd dphid_dq;                 // derivatives of phidot = Jc v
  Eigen::VectorXd c;                        // c itself (zero on the kept rows, up to round-off)

 private:
  // compute_constrained's and compute_balance's common part: everything up to the mass matrix
  void balance(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u_all, const Eigen::VectorXd& a,
               const Eigen::VectorXd& lambda);
  struct Unit {
    int body = 0;  // child body of the joint
    int iv = 0;    // first velocity index
    int n = 0;     // columns
  };
  void world_kinematics(const Eigen::VectorXd& q, const Eigen::VectorXd& v);  // S, I, V
  void accelerations(const Eigen::VectorXd& a);                               // A (after world_kinematics)
  void composites();                                                           // Ic, hc, Bc, P, R
  void forces();                                                               // F, tau
  void mass_matrix();                                                          // M from P and S
  void inverse_mass_matrix();                                                  // Minv_ (articulated bodies)
  void articulated_solve(const Eigen::VectorXd& f, Eigen::VectorXd& x);        // x = M^-1 f, the same bodies
  void articulated_solve_rows();                                               // X_ := M^-1 X_
  void small_inverse();                                                        // Minv_ from M (small nv)
  void tree_inverse();                                                         // Minv_ from M, tree-sparse
  // from this many coordinates on, compute() solves for its derivatives by the articulated bodies
  // (48 nv^2 multiply-adds) rather than products with M^-1 (2 nv^3). Measured on the speed
  // models' chains (bench/pinocchio_bench.cpp, clang -O3): the products are faster up to 20 links
  // (4.0 against 4.9 us at 7, 16.2 against 18.5 at 20), even at 30, the solve 25% faster at 60
  static constexpr int kRowsSolveFrom = 32;
  // below this many coordinates, compute() takes M^-1 from M's root-free Cholesky factors
  // (small_inverse) instead of the articulated bodies
  static constexpr int kDenseInverseBelow = 16;
  Eigen::MatrixXd chol_, chol_inv_;  // [nv x nv] small_inverse's L (1 / D on the diagonal), L^-1 (D on it)
  // tree_inverse (Featherstone's M = L^T D L from the leaves up, which keeps M's branch sparsity):
  // taken from kDenseInverseBelow to kRowsSolveFrom on trees (parents' columns first) whose sum
  // over columns of the squared subtree range is at most half a chain's (n^3 / 3), where its
  // O(that sum) beats the articulated bodies (tree28: 1.30 -> 1.03 of Pinocchio's derivatives);
  // the parent column of each column (-1 at a root) and the end of its subtree's range (the
  // contiguous superset of its columns: W is zero on the others)
  std::vector<int> lambda_, col_sub_end_;
  bool tree_inverse_ = false;
  Eigen::VectorXd scratch_row_;      // [nv]
  void differentiate_rnea();
  void applied_force_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& u);
  void add_body_wrench(int body, const Vec6T<double>& w, const Eigen::Matrix<double, 6, 24>& dw, int body_a,
                       int body_b);
  void sensor_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const std::vector<int>& outputs);
  void constraint_derivatives(const Eigen::VectorXd& lambda, const Eigen::VectorXd& a);
  // one constraint row's local derivatives (36 = [pose, V, A] of body_a then body_b), chained
  void chain_constraint_row(int row, const Eigen::Matrix<double, 36, 1>& gc, const Eigen::Matrix<double, 36, 1>& gp,
                            int body_a, int body_b);

  void size_for(const Model& model);

  const Model* m_;
  Data d_;
  std::vector<Unit> units_;
  std::vector<int> unit_begin_, unit_end_;       // [nbodies] units of a body's joint
  std::vector<std::vector<int>> path_;           // [nbodies] units from the root down to the body
  std::vector<int> col_unit_;                    // [nv] unit of a velocity column

  // world-frame workspace
  std::vector<Mat6xT<double>> S_;                // [nbodies] world motion subspace of the joint
  std::vector<Vec6T<double>> V_, A_;             // [nbodies]
  std::vector<Vec6T<double>> Vpar_, Apar_, Vu_;  // [units] velocity/acceleration the unit moves from; after it
  // [nbodies] world inertia about the world origin, its subtree sum, and the subtree sum of their
  // rates V x* I - I V x (an inertia of zero mass): 10 and 9 numbers rather than 6 x 6 matrices
  std::vector<RigidInertiaT<double>> I_, Ic_, Bc_;
  std::vector<ComInertia> com_;                  // [nbodies] mass, com, rotational inertia (body axes)
  std::vector<Vec6T<double>> hb_, fv_;           // [nbodies] the body's momentum I V and V x* I V
  std::vector<Vec6T<double>> hc_, F_;            // [nbodies] subtree momentum, subtree RNEA force
  std::vector<Vec6T<double>> cu_;                // [units] Vu x (Su v): the unit's velocity-product term
  // [units] the rows [S^T Ic, S^T (Bc + H(hc))] side by side (P, R), padded to 6 rows: one contiguous
  // 12-vector per coordinate, so that each entry of the RNEA derivatives is one 12-term dot product
  using Rows12 = Eigen::Matrix<double, 6, 12, Eigen::RowMajor>;
  std::vector<Rows12> PR_;
  // the bodies of each body's subtree with a joint that moves (itself first, then in increasing
  // order): sub_bodies_[sub_begin_[i] .. sub_begin_[i + 1])
  std::vector<int> sub_begin_, sub_bodies_;
  std::vector<char> below_;                      // [nbodies] scratch of size_for
  Eigen::VectorXd qdd_zero_, scratch_;
  Eigen::MatrixXd rhs_;
  // M^-1 without M: the articulated-body recursion in world axes applied to every unit force at
  // once (one row of M^-1 per coordinate; O(n d) for a tree of depth d)
  using Rows6 = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Minv_;
  std::vector<Mat6T<double>> IA_;                // [nbodies] articulated inertia (world)
  Rows6 scratch_rows_;
  std::vector<Rows6> Fb_, Ab_;                   // [nbodies] articulated forces, accelerations per unit force
  std::vector<Mat6T<double>> Uu_, Dinv_;         // [units] IA S and (S^T IA S + armature)^-1, padded
  std::vector<Vec6T<double>> pa_, av_;           // [nbodies] articulated_solve's forces and accelerations
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> X_;  // [nv x 2 nv]
  std::vector<Rows6> Fr_, Ar_;                   // [nbodies] forces, accelerations of X_'s columns
  std::vector<int> col_begin_, col_end_;
  std::vector<int> children_, sub_nv_;           // [nbodies] number of child bodies; columns of the subtree
  bool depth_first_ = false;                     // every subtree's columns exactly its range         // [nbodies] columns of the subtree (a contiguous superset)
  Eigen::LLT<Eigen::MatrixXd> llt_;
  // closed loops: kept rows of Jc, M^-1 Jr^T, the Schur complement and its right-hand sides
  Eigen::MatrixXd Jr_, Y_, Sc_, T_;
  Eigen::LLT<Eigen::MatrixXd> llt_schur_;
  // motion inputs: the free and the driven coordinates, M on the free ones, the right-hand sides
  // [q, v, u_all, accelerations] on the free rows
  std::vector<int> free_, driven_;
  Eigen::MatrixXd Mff_, Rf_;
  Eigen::LLT<Eigen::MatrixXd> llt_ff_;
  void solve_prescribed(const std::vector<int>& rows);
};

}  // namespace codyna
