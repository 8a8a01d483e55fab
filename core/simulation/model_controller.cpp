#include "simulation/model_controller.hpp"

#include <sstream>

#include "analysis/operating_point.hpp"
#include "control/lqr.hpp"
#include "model/errors.hpp"
#include "simulation/driver.hpp"

namespace codyna {

namespace {

void check_gain_size(const Model& m, const char* field, const Eigen::MatrixXd& M, Eigen::Index rows, Eigen::Index cols) {
  if (M.rows() == rows && M.cols() == cols) return;
  std::ostringstream os;
  os << "expected a " << rows << " x " << cols << " matrix for this plant (" << m.plant_inputs.size() << " inputs, "
     << m.plant_outputs.size() << " outputs), got " << M.rows() << " x " << M.cols();
  throw ModelError(m.source_file, std::string("/controller/") + field, os.str());
}

Eigen::MatrixXd weights(const Model& m, const char* field, const std::vector<double>& w, int n) {
  if (w.empty()) return Eigen::MatrixXd::Identity(n, n);
  if (static_cast<int>(w.size()) != n)
    throw ModelError(m.source_file, std::string("/controller/") + field,
                     "expected " + std::to_string(n) + " weights, got " + std::to_string(w.size()));
  return Eigen::Map<const Eigen::VectorXd>(w.data(), n).asDiagonal();
}

}  // namespace

bool has_model_controller(const Model& model) { return model.spec.controller.type != ControllerType::None; }

LinearPlant controller_plant(const Model& model) {
  const ControllerSpec& c = model.spec.controller;
  LinearPlant p;
  const OperatingPoint start = initial_point(model);
  if (c.operating_point == "equilibrium") p.op = static_equilibrium(model, start);
  else if (c.operating_point == "trim") p.op = trim(model, start);
  else p.op = start;
  if (c.operating_point != "initial") require_steady_state(model, p.op);  // no controller about an unconverged point
  p.lin = linearize(model, p.op);
  return p;
}

std::unique_ptr<Controller> make_model_controller(const Model& m, const LinearPlant& plant) {
  const ControllerSpec& c = m.spec.controller;
  const LinearSystem& s = plant.lin.system;
  const Eigen::Index nu = s.nu(), ny = s.ny(), nx = s.nx();
  switch (c.type) {
    case ControllerType::None:
      return nullptr;
    case ControllerType::Pid: {
      check_gain_size(m, "kp", c.kp, nu, ny);
      if (c.ki.size()) check_gain_size(m, "ki", c.ki, nu, ny);
      if (c.kd.size()) check_gain_size(m, "kd", c.kd, nu, ny);
      if (c.setpoint.size() && c.setpoint.size() != ny)
        throw ModelError(m.source_file, "/controller/setpoint", "expected " + std::to_string(ny) + " values (one per Plant/Out)");
      return make_pid(c.kp, c.ki, c.kd, c.setpoint.size() ? c.setpoint : s.y0, s.u0);
    }
    case ControllerType::StateFeedback:
      check_gain_size(m, "K", c.K, nu, nx);
      return make_state_feedback(c.K, s.u0);
    case ControllerType::Lti: {
      const Eigen::Index n = c.Ac.rows();
      check_gain_size(m, "Bc", c.Bc, n, ny);
      check_gain_size(m, "Cc", c.Cc, nu, n);
      check_gain_size(m, "Dc", c.Dc, nu, ny);
      return make_lti(c.Ac, c.Bc, c.Cc, c.Dc, c.Ts, s.y0, s.u0);
    }
    case ControllerType::Driver: {
      const std::string where = (m.source_file.empty() ? std::string() : m.source_file + ": ") + "/controller";
      return make_driver(model_driver_settings(m, s.u0), where);
    }
    case ControllerType::Lqr: {
      const LqrResult d = lqr(s.A, s.B, weights(m, "q_weights", c.q_weights, static_cast<int>(nx)),
                              weights(m, "r_weights", c.r_weights, static_cast<int>(nu)));
      return make_state_feedback(d.K, s.u0);
    }
  }
  return nullptr;
}

}  // namespace codyna
