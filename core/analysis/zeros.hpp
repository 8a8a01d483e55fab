// Transmission zeros of one input-output channel of a linear system: the finite s (or z, when
// discrete) where H_ij(s) = C_i (sI - A)^-1 B_j + D_ij vanishes, the finite generalized
// eigenvalues of the Rosenbrock pencil
//   [A   B_j ]       [I 0]
//   [C_i D_ij]  - s  [0 0]
// computed by the QZ algorithm (Eigen's GeneralizedEigenSolver). A channel with relative degree
// r has n - r of them; the r infinite ones (beta = 0) are left out. What a pole-zero map draws
// next to the poles (eig A); MATLAB's zero(sys(i, j)) and Octave's zero() give the same.
#pragma once

#include <Eigen/Core>

#include "analysis/linear_system.hpp"

namespace codyna {

// Throws std::invalid_argument for an input or output index out of range. A channel that is
// zero at every s (C_i and D_ij zero, say) has no zeros listed and `identically_zero` set.
struct ChannelZeros {
  Eigen::VectorXcd zeros;  // sorted by real part, then imaginary part
  bool identically_zero = false;
};
ChannelZeros transmission_zeros(const LinearSystem& sys, int input, int output);

}  // namespace codyna
