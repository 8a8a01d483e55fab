// Controllers in the loop. A controller maps the plant's measured outputs
// (Plant/Out, and for state feedback the plant state in the export's order)
// to the Plant/In actuator values:
//   PID           u = u0 + Kp (r - y) + Ki xi - Kd dy/dt,   dxi/dt = r - y
//                 (the paper's u = k (y0 - y) with derivative action on the measurement);
//                 with anti-windup (AntiWindup) the integral is corrected while an input saturates
//   state feedback u = u0 - K (x - x0)    x in the state order of the linearization/export
//   LTI           dxc/dt = Ac xc + Bc (y - y0),  u = u0 + Cc xc + Dc (y - y0)
//                 or, with Ts > 0, sampled with zero-order hold:
//                 xc[k+1] = Ac xc[k] + Bc (y[k] - y0),  u[k] = u0 + Cc xc[k] + Dc (y[k] - y0)
// Inputs are then clamped to the actuators' [min, max] (saturation).
// Sizes are checked against the plant when the controller is made.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/plant_function.hpp"
#include "model/model.hpp"

namespace codyna {

// what a controller sees at time t
struct ControllerInput {
  double t = 0;
  Eigen::VectorXd y;     // plant outputs [ny]
  Eigen::VectorXd ydot;  // their rates at constant velocity [ny] (exact for position outputs)
  Eigen::VectorXd x;     // plant state deviation x - x0 in minimal coordinates [nx] (state feedback only)
  Eigen::VectorXd r;     // reference for the outputs at t [ny]; empty: the controller's own (setpoint, or y0)
  Eigen::VectorXd u;     // the Plant/In values applied at t, after saturation [nu]; empty: not known
                         // (anti-windup then does nothing)
};

// PID anti-windup (docs/simulation.md): what the integral does while an input is at its limit
struct AntiWindup {
  enum class Method { None, BackCalculation, Conditional } method = Method::None;
  double tracking_time = 0.0;  // s, back-calculation: dxi/dt = r - y + pinv(Ki) (u_applied - u) / tracking_time
};

// PID gains as made (Controller::pid)
struct PidGains {
  Eigen::MatrixXd Kp, Ki, Kd;
  Eigen::VectorXd r, u0;
  AntiWindup anti_windup;
};

class Controller {
 public:
  virtual ~Controller() = default;
  virtual int nxc() const { return 0; }             // controller states
  virtual double sample_time() const { return 0; }  // > 0: discrete (zero-order hold)
  virtual bool needs_state() const { return false; }
  virtual bool needs_rates() const { return false; }
  // whether the law reads Plant/Out output k at all (a PID whose gains' column k is zero does not:
  // an acceleration output there is only recorded, not an algebraic loop)
  virtual bool reads_output(int k) const { return true; }
  // plant input values (before saturation) for controller state xc
  virtual Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const = 0;
  // continuous: d xc/dt; discrete: xc at the next sample
  virtual Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const {
    return Eigen::VectorXd::Zero(nxc());
  }
  virtual std::vector<std::string> state_names() const;
  virtual std::string describe() const = 0;
  // state feedback: its gain K (nu x nx); nullptr for other controllers
  virtual const Eigen::MatrixXd* gain() const { return nullptr; }
  // PID: its gains; nullptr for other controllers
  virtual const PidGains* pid() const { return nullptr; }
  // the law as linear maps for a plant of nx states and ny outputs (LinearLaw); nullopt when
  // it has none or does not fit those sizes
  virtual std::optional<LinearLaw> linear_law(int nx, int ny) const { return std::nullopt; }
};

// gains are (nu x ny); empty Ki / Kd mean no integral / derivative action; r defaults to y0.
// Anti-windup needs Ki; back-calculation a tracking time > 0 (std::invalid_argument otherwise).
std::unique_ptr<Controller> make_pid(const Eigen::MatrixXd& Kp, const Eigen::MatrixXd& Ki, const Eigen::MatrixXd& Kd,
                                     const Eigen::VectorXd& r, const Eigen::VectorXd& u0, const AntiWindup& aw = {});

// K is (nu x nx), same state order as the export; x0/u0 are the operating point's.
// With a reference r(t) on the outputs, Nbar (nu x ny) feeds it forward:
//   u = u0 - K (x - x0) + Nbar (r - y0)
std::unique_ptr<Controller> make_state_feedback(const Eigen::MatrixXd& K, const Eigen::VectorXd& u0,
                                                const Eigen::MatrixXd& Nbar = {}, const Eigen::VectorXd& y0 = {});

// The feed-forward gain that makes the outputs `tracked` (indices into y) of the linear closed
// loop dx' = (A - B K) dx + B Nbar dr follow a constant reference with no steady-state error:
// Nbar(:, tracked) = pinv(-C_t (A - B K)^-1 B), other columns zero. Throws std::invalid_argument
// when A - B K is singular (the loop is not stable) or the tracked outputs cannot be reached.
Eigen::MatrixXd reference_gain(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                               const Eigen::MatrixXd& K, const std::vector<int>& tracked);

std::unique_ptr<Controller> make_lti(const Eigen::MatrixXd& Ac, const Eigen::MatrixXd& Bc, const Eigen::MatrixXd& Cc,
                                     const Eigen::MatrixXd& Dc, double Ts, const Eigen::VectorXd& y0,
                                     const Eigen::VectorXd& u0);

// The controller a file of plain matrices holds (io/controller_file.hpp reads it from a .mat:
// Octave save -v7, MATLAB save):
//   K                        -> state feedback
//   Kp [, Ki] [, Kd] [, r]   -> PID on the outputs
//   Ac, Bc, Cc, Dc [, Ts]    -> LTI (discrete when Ts > 0)
// u0, y0 come from the operating point; nx, nu, ny are the plant's sizes. `path` names the file
// in messages. Wrong sizes, missing variables or NaN give std::invalid_argument naming the file,
// the variable and the expected size; a controller variable that could not be read as a real 2-D
// matrix (in `skipped`) is named with the reason.
struct ControllerMatrices {
  struct Skipped {
    std::string name, reason;
  };
  std::map<std::string, Eigen::MatrixXd> matrices;
  std::vector<Skipped> skipped;
};
std::unique_ptr<Controller> controller_from_matrices(const ControllerMatrices& vars, const std::string& path, int nx,
                                                     int nu, int ny, const Eigen::VectorXd& y0, const Eigen::VectorXd& u0);

}  // namespace codyna
