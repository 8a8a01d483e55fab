#include "vehicle/magic_formula.hpp"

namespace codyna {

// the two scalars codyna uses, compiled once (magic_formula.hpp declares them extern)
template TireForces<double> magic_formula<double>(const MagicFormulaParameters&, const TireInput<double>&,
                                                  const MagicFormulaOptions&);
template TireForces<Eigen::AutoDiffScalar<Eigen::VectorXd>> magic_formula<Eigen::AutoDiffScalar<Eigen::VectorXd>>(
    const MagicFormulaParameters&, const TireInput<Eigen::AutoDiffScalar<Eigen::VectorXd>>&, const MagicFormulaOptions&);

}  // namespace codyna
