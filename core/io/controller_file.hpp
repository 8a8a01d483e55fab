// A controller saved in a .mat file (K; Kp, Ki, Kd, r; Ac, Bc, Cc, Dc, Ts): read here, built by
// simulation/controller.hpp's controller_from_matrices. An unreadable file gives
// std::invalid_argument naming it.
#pragma once

#include <memory>
#include <string>

#include "simulation/controller.hpp"

namespace codyna {

ControllerMatrices read_controller_matrices(const std::string& path);

std::unique_ptr<Controller> load_controller(const std::string& path, int nx, int nu, int ny, const Eigen::VectorXd& y0,
                                            const Eigen::VectorXd& u0);

}  // namespace codyna
