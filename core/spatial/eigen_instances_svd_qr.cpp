// Eigen's decompositions compiled once (spatial/eigen_instances.hpp): this part's list
#include "spatial/eigen_instances.hpp"

#define CODYNA_EIGEN_INSTANTIATE(...) template __VA_ARGS__;
CODYNA_EIGEN_SVD_QR(CODYNA_EIGEN_INSTANTIATE)
