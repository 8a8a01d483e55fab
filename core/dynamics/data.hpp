// Data: the mutable workspace of the algorithms, made from a Model, grouped
// by stage. One Data per thread / integrator; a Data is never shared while
// an algorithm writes it. Templated on the scalar (double, or the autodiff
// scalar used for exact derivatives).
#pragma once

#include <vector>

#include <Eigen/QR>

#include "model/model.hpp"
#include "spatial/spatial.hpp"

namespace codyna {

// Constants the algorithms derive once from the Model (DataT's constructor),
// in double whatever the scalar; not part of any algorithm's output.
struct ModelConstants {
  struct Joint {
    SE3 X_PF, X_MC;                     // X_MC = X_CM^-1
    bool constant_S = false;            // Sb does not depend on q (all but universal and planar)
    Mat6xT<double> Sb{6, 0};            // X_CM S_M when constant_S
    // revolute: liMi = (Rot(axis_P, q) R0, Rot(axis_P, q) p0 + X_PF.p)
    Eigen::Vector3d axis_P = Eigen::Vector3d::UnitZ(), p0 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
    // exact identities the kinematics skip (a product with them is the other factor, bit for bit):
    // R0 = 1 and p0 = 0 (revolute), X_PF's rotation 1, X_MC = 1 (ball and free joints), Sb's
    // linear rows zero (its axes through the body's origin)
    bool r0_identity = true, p0_zero = true, pf_rotation_identity = true, mc_identity = true, sb_angular_only = false;
  };
  std::vector<Joint> joints;                     // [nbodies]
  std::vector<ComInertia> com_inertia;           // [nbodies] body inertia about its com, body axes (= Model::inertia)
  std::vector<RigidInertiaT<double>> body_inertia;  // [nbodies] the same about the body's origin (= Model::inertia):
                                                   // I v in about 24 multiply-adds instead of 36
  std::vector<int> root;                         // [nbodies] the body of its tree attached to ground (0 for ground)
  std::vector<int> dof_body;                     // [nv] body whose joint a velocity index belongs to
  std::vector<int> dof_parent;                   // [nv] next velocity index towards the root (-1: none)
  bool dense_mass_matrix = false;                // every pair of velocity indices is related (a chain): M has no structural zero
  // loop closures (Model::constraints): for constraint k the velocity indices its rows can touch,
  // those of the joints on the paths of its two bodies to the ground, ascending (Jc is zero in
  // every other column), and for each which path holds it (1: body_a's, 2: body_b's, 3: both);
  // a coupler's: its coordinates (side 3)
  std::vector<std::vector<int>> constraint_cols, constraint_side;
  bool body_force_sources = false;               // springs, body forces or body-force actuators write fext
  explicit ModelConstants(const Model& model);
  void assign(const Model& model);  // the same as constructing it again, reusing the arrays
};

template <class S>
struct DataT {
  explicit DataT(const Model& model);
  // the same as DataT(model) for another model (or this one changed), reusing the memory: every
  // member the constructor sets is set again; the workspaces sized at their first use keep their
  // storage and are sized again by the algorithms when the sizes differ
  void reset(const Model& model);

  ModelConstants constants;      // derived from the model once (see above)

  // position stage (forward_kinematics)
  std::vector<SE3T<S>> liMi;     // [nbodies] pose of body i in its parent
  std::vector<SE3T<S>> oMi;      // [nbodies] pose of body i in the world
  std::vector<Mat6xT<S>> Sb;     // [nbodies] joint motion subspace in body coordinates (6 x nv_i)

  // velocity stage
  std::vector<Vec6T<S>> v;       // [nbodies] body spatial velocity, body coordinates
  std::vector<Vec6T<S>> cJ;      // [nbodies] joint bias dS/dt qd, body coordinates

  // acceleration stage
  std::vector<Vec6T<S>> a;       // [nbodies] body spatial acceleration (gravity not included)
  std::vector<Vec6T<S>> f;       // [nbodies] rnea: force transmitted by joint i, body coordinates

  VecXT<S> tau;                  // [nv] rnea output
  MatXT<S> M;                    // [nv x nv] crba output (symmetric, full); empty until crba runs
  VecXT<S> nle;                  // [nv] nonlinear effects: coriolis, centrifugal, gravity
  VecXT<S> Q;                    // [nv] generalized applied forces (effects + actuators)
  std::vector<Vec6T<S>> fext;    // [nbodies] external body forces, body coordinates (effects workspace)
  VecXT<S> qdd;                  // [nv] forward dynamics output
  VecXT<S> lambda;               // [nc] constraint multipliers (M qdd = Q - nle - J^T lambda); 0 on redundant rows
  // motion inputs (Model::motions): the prescribed accelerations u'' forward_dynamics imposes on their
  // coordinates (the caller sets q, v there), and the generalized force each then applies
  // (M qdd + nle - Q on its coordinate: the reaction a motion actuator must supply)
  VecXT<S> motion_acc, motion_force;  // [motions]
  // effect states (Model::ns: a tire's transient slip): their values, which applied_forces reads
  // (the caller sets them; zeros after construction), and their rates, which it writes
  VecXT<S> s, sdot;              // [ns]

  // articulated-body workspace (aba)
  std::vector<Mat6T<S>> IA;      // [nbodies] articulated inertia, body coordinates
  std::vector<Mat6T<S>> Ia;      // [nbodies] IA less the part the joint takes (U Dinv U^T): what the parent receives
  std::vector<Vec6T<S>> pB;      // [nbodies] bias force of body i alone, v x* I v
  std::vector<Vec6T<S>> pA;      // [nbodies] articulated bias force
  std::vector<Mat6xT<S>> U;
  std::vector<Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>> Dinv;
  std::vector<Eigen::Matrix<S, Eigen::Dynamic, 1, 0, 6, 1>> u;
  std::vector<Vec6T<S>> c;       // velocity-product accelerations

  // crba workspace: world axes, moments about the origin of the body's tree
  // root (ModelConstants::root), so that no transform is needed between bodies
  std::vector<RigidInertiaT<S>> Iw;  // [nbodies] inertia of body i
  std::vector<RigidInertiaT<S>> Ic;  // [nbodies] composite inertia of the subtree of body i
  std::vector<Vec6T<S>> Sw;          // [nv] motion axis of each velocity index
  std::vector<Vec6T<S>> fsum;        // [nbodies] scratch: body forces summed towards the root

  // loop closures
  VecXT<S> phi;                  // [nc] position residual
  MatXT<S> Jc;                   // [nc x nv] d phi / dq (tangent), so d/dt phi = Jc v
  VecXT<S> gamma;                // [nc] dJc/dt v, so d2/dt2 phi = Jc qdd + gamma

  // loop-closure workspace (constraint_terms, forward_dynamics<double>): sized
  // by the first call, so that later calls do not allocate
  VecXT<S> zero_v;               // [nv] zeros, never written
  MatXT<S> Jp, Jwa, Jwb, Jwd;    // [3 x nv] point, angular (a, b) and relative angular Jacobians
  struct LoopSolve {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;  // independent rows of Jc
    std::vector<int> rows;                           // [na] independent rows at this q
    Eigen::MatrixXd J, B, L, X, A, LA;               // [na x nv], [nv x 1+na], [nv x nv], [nv x 1+na], [na x na] x 2
    Eigen::VectorXd rhs, Jvel, lam;                  // [na]
    // motion inputs (prescribed_dynamics in double): the free and the driven coordinates, M on the
    // free ones, the right-hand side Q - nle - M_:d a_d
    std::vector<int> free, driven;
    Eigen::MatrixXd Mff;                             // [nf x nf]
    Eigen::VectorXd f;                               // [nv]
  } loop;                        // used with S = double only

 private:
  void size_for(const Model& model);
};

extern template struct DataT<double>;
using Data = DataT<double>;

}  // namespace codyna
