// Data: the mutable workspace of the algorithms, made from a Model, grouped
// by stage. One Data per thread / integrator; a Data is never shared while
// an algorithm writes it. Templated on the scalar (double, or the autodiff
// scalar used for exact derivatives).
#pragma once

#include <vector>

#include "model/model.hpp"
#include "spatial/spatial.hpp"

namespace codyna {

template <class S>
struct DataT {
  explicit DataT(const Model& model);

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

  // articulated-body workspace (aba)
  std::vector<Mat6T<S>> IA;
  std::vector<Vec6T<S>> pA;
  std::vector<Mat6xT<S>> U;
  std::vector<Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>> Dinv;
  std::vector<Eigen::Matrix<S, Eigen::Dynamic, 1, 0, 6, 1>> u;
  std::vector<Vec6T<S>> c;       // velocity-product accelerations

  // crba workspace
  std::vector<Mat6T<S>> Ic;      // composite inertia

  // loop closures
  VecXT<S> phi;                  // [nc] position residual
  MatXT<S> Jc;                   // [nc x nv] d phi / dq (tangent), so d/dt phi = Jc v
  VecXT<S> gamma;                // [nc] dJc/dt v, so d2/dt2 phi = Jc qdd + gamma
};

extern template struct DataT<double>;
using Data = DataT<double>;

}  // namespace codyna
