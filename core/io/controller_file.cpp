#include "io/controller_file.hpp"

#include <stdexcept>

#include "io/mat_export.hpp"

namespace codyna {

ControllerMatrices read_controller_matrices(const std::string& path) {
  MatVariables vars;
  try {
    vars = read_mat_file(path);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
  ControllerMatrices c;
  c.matrices = std::move(vars.matrices);
  for (const SkippedVariable& v : vars.skipped) c.skipped.push_back({v.name, v.reason});
  return c;
}

std::unique_ptr<Controller> load_controller(const std::string& path, int nx, int nu, int ny, const Eigen::VectorXd& y0,
                                            const Eigen::VectorXd& u0) {
  return controller_from_matrices(read_controller_matrices(path), path, nx, nu, ny, y0, u0);
}

}  // namespace codyna
