// Eigen's dense decompositions, compiled once. Each of them (EigenSolver, a Schur form, an SVD,
// a QR, an LU, a Cholesky) costs 2 to 11 s of compile time in every translation unit that uses
// it; core/spatial/eigen_instances_*.cpp instantiate them once for the matrix types codyna uses,
// and the `extern template` declarations below keep every other translation unit from
// instantiating them again. Every target that links codyna_core sees this header first (it is
// codyna_core's public precompiled header, core/CMakeLists.txt); a translation unit that does
// not see it still builds and runs the same, only more slowly.
// Instantiated for the matrix types themselves: a decomposition built from an expression
// (EigenSolver<MatrixXd>(A - B * K)) instantiates its compute() for that expression again;
// evaluate such arguments into a MatrixXd first (the same arithmetic).
#pragma once

#include <Eigen/Dense>

// the eigenvalue problems: general, complex, Schur forms, symmetric, generalized
#define CODYNA_EIGEN_EIGENVALUES(X)                                                                       \
  X(class Eigen::EigenSolver<Eigen::MatrixXd>)                                                            \
  X(Eigen::EigenSolver<Eigen::MatrixXd>& Eigen::EigenSolver<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(  \
      const Eigen::EigenBase<Eigen::MatrixXd>&, bool))                                                     \
  X(class Eigen::ComplexEigenSolver<Eigen::MatrixXcd>)                                                    \
  X(Eigen::ComplexEigenSolver<Eigen::MatrixXcd>&                                                          \
        Eigen::ComplexEigenSolver<Eigen::MatrixXcd>::compute<Eigen::MatrixXcd>(                           \
            const Eigen::EigenBase<Eigen::MatrixXcd>&, bool))                                              \
  X(class Eigen::ComplexSchur<Eigen::MatrixXd>)                                                           \
  X(Eigen::ComplexSchur<Eigen::MatrixXd>& Eigen::ComplexSchur<Eigen::MatrixXd>::compute<Eigen::MatrixXd>( \
      const Eigen::EigenBase<Eigen::MatrixXd>&, bool))                                                     \
  X(class Eigen::ComplexSchur<Eigen::MatrixXcd>)                                                          \
  X(Eigen::ComplexSchur<Eigen::MatrixXcd>&                                                                \
        Eigen::ComplexSchur<Eigen::MatrixXcd>::compute<Eigen::MatrixXcd>(                                 \
            const Eigen::EigenBase<Eigen::MatrixXcd>&, bool))                                              \
  X(class Eigen::RealSchur<Eigen::MatrixXd>)                                                              \
  X(Eigen::RealSchur<Eigen::MatrixXd>& Eigen::RealSchur<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(      \
      const Eigen::EigenBase<Eigen::MatrixXd>&, bool))                                                     \
  X(class Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>)                                                 \
  X(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>&                                                       \
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(                         \
            const Eigen::EigenBase<Eigen::MatrixXd>&, int))                                                \
  X(class Eigen::GeneralizedEigenSolver<Eigen::MatrixXd>)

// the SVDs and QRs
#define CODYNA_EIGEN_SVD_QR(X)                                        \
  X(class Eigen::JacobiSVD<Eigen::MatrixXd>)                          \
  X(class Eigen::JacobiSVD<Eigen::MatrixXcd>)                         \
  X(class Eigen::HouseholderQR<Eigen::MatrixXd>)                      \
  X(class Eigen::ColPivHouseholderQR<Eigen::MatrixXd>)                \
  X(class Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>)

// the LUs and Choleskys
#define CODYNA_EIGEN_LU_CHOLESKY(X)                                                            \
  X(class Eigen::FullPivLU<Eigen::MatrixXd>)                                                   \
  X(class Eigen::PartialPivLU<Eigen::MatrixXd>)                                                \
  X(class Eigen::PartialPivLU<Eigen::MatrixXcd>)                                               \
  X(class Eigen::LLT<Eigen::MatrixXd>)                                                         \
  X(Eigen::LLT<Eigen::MatrixXd>& Eigen::LLT<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(       \
      const Eigen::EigenBase<Eigen::MatrixXd>&))                                                \
  X(class Eigen::LDLT<Eigen::MatrixXd>)                                                        \
  X(Eigen::LDLT<Eigen::MatrixXd>& Eigen::LDLT<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(     \
      const Eigen::EigenBase<Eigen::MatrixXd>&))

#define CODYNA_EIGEN_EXTERN(...) extern template __VA_ARGS__;
CODYNA_EIGEN_EIGENVALUES(CODYNA_EIGEN_EXTERN)
CODYNA_EIGEN_SVD_QR(CODYNA_EIGEN_EXTERN)
CODYNA_EIGEN_LU_CHOLESKY(CODYNA_EIGEN_EXTERN)
#undef CODYNA_EIGEN_EXTERN
