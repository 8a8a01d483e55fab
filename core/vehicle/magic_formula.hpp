// The steady-state Magic Formula 5.2 / 6.1 / 6.2 tire force law (Pacejka, Tire and Vehicle Dynamics,
// 3rd ed., ch. 4 with the MF-Tyre corrections that MFeval 4.0 documents), evaluated for one contact
// state on any scalar: double (no heap allocation) or Eigen::AutoDiffScalar (derivatives of the
// forces with respect to the inputs by automatic differentiation).
//
// What it computes, as MFeval 4.0 does in its use mode 111 (limits on, no alpha_star, combined
// slip, no turn slip) or 211 (limits off): pure-slip Fx0, Fy0 with camber, load and pressure
// dependence and the scaling coefficients; combined slip through G_x_alpha and G_y_kappa with the
// kappa-induced side force S_Vy_kappa; Mz from the pneumatic trail and the residual moment with the
// equivalent slips of the paper (A54, A55); Mx (the draft paper's equation 49, QSX1..QSX14), My
// (the paper's A48; MF 5.2: the MF-Tyre manual's), the effective rolling radius Re from MFeval's
// fixed-point iteration on the wheel spin; MFeval's epsilon guards (1e-6) in B_x, B_y and K_ya'.
// MF 5.2 (FITTYP 6 or 5) differs where MFeval makes it differ: S_Hy with PHY3, Mz with
// -t (Fy - S_Vy_kappa), My proportional to Fz without the camber and pressure terms.
//
// Limits (options.limits, MFeval's hundreds digit 1): Fz above FZMAX, alpha, gamma, kappa and the
// pressure outside the file's ranges are clamped; below FZMIN the trail and residual moment use
// FZMIN; below VXLOW the slips and shifts are reduced smoothly toward standstill as MFeval does.
// Without limits the inputs are used as given. Mx and My keep MFeval's low-load reductions either
// way. Turn slip (phit) is not evaluated (MFeval's use mode xx1): phit is ignored.
//
// TYRESIDE: MFeval's steady-state solver reads TYRESIDE but does not use it; with
// options.mount = TireMount::AsFile (the default) the file is evaluated as it stands, which is what
// MFeval's tables hold. Mounting the tire on the other side than the file's TYRESIDE mirrors it
// about the wheel's x-z plane: evaluated at (-alpha, -gamma), with Fy, Mz and Mx negated.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "vehicle/tir_file.hpp"
#include "vehicle/tire_forces.hpp"

namespace codyna {

enum class TireMount { AsFile, Left, Right };

struct MagicFormulaOptions {
  bool limits = true;                   // MFeval's use mode 1xx (true) or 2xx (false)
  TireMount mount = TireMount::AsFile;  // the side the tire is mounted on
};

// One contact state in, the forces and moments out (see tire_forces.hpp for the axes).
template <class S>
TireForces<S> magic_formula(const MagicFormulaParameters& p, const TireInput<S>& in,
                            const MagicFormulaOptions& options = {});

extern template TireForces<double> magic_formula<double>(const MagicFormulaParameters&, const TireInput<double>&,
                                                         const MagicFormulaOptions&);
extern template TireForces<Eigen::AutoDiffScalar<Eigen::VectorXd>> magic_formula<Eigen::AutoDiffScalar<Eigen::VectorXd>>(
    const MagicFormulaParameters&, const TireInput<Eigen::AutoDiffScalar<Eigen::VectorXd>>&, const MagicFormulaOptions&);

}  // namespace codyna

#include "vehicle/magic_formula_impl.hpp"
