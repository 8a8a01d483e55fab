// SimulationResult: what a simulation produces, sample by sample (one row per
// output time), with names, units, solver statistics and provenance, so that a
// results file (io/results_file.hpp) is self-describing.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace codyna {

struct SolverStats {
  std::string integrator;          // "ida", "cvode-bdf", "cvode-adams", "arkode", "rk4", "alf" (never "auto": the one chosen)
  double rtol = 0, atol = 0, max_step = 0;
  long steps = 0;                  // internal steps
  long rhs_evals = 0;              // right-hand side / residual evaluations
  long jac_evals = 0;              // Jacobian evaluations (0 for explicit methods)
  long error_test_failures = 0;
  long nonlinear_iterations = 0;
  long nonlinear_failures = 0;
  long projections = 0;            // constraint projections (closed loops)
  long restarts = 0;               // re-initializations at controller samples / projections
  double wall_time = 0;            // seconds
  std::string integrator_choice;   // when "auto" was asked: what was chosen and why (simulation/integrator_choice.hpp)
  bool integrator_fell_back = false;  // auto's choice failed and the run went on with kAutoFallbackIntegrator
};

struct SimulationResult {
  std::vector<double> t;                       // [N] output times
  Eigen::MatrixXd q, v;                        // [N x nq], [N x nv]
  Eigen::MatrixXd u;                           // [N x nu] every actuator's value (after saturation)
  Eigen::MatrixXd y;                           // [N x ny] plant outputs (Plant/Out)
  Eigen::MatrixXd xc;                          // [N x nxc] controller states (may have 0 columns)
  Eigen::MatrixXd s;                           // [N x ns] effect states (a tire's transient slip; may have 0 columns)
  std::vector<double> kinetic_energy, potential_energy;  // [N]
  std::vector<double> constraint_violation;    // [N] max |phi(q)| (0 for trees)
  std::vector<double> velocity_violation;      // [N] max |Jc v|
  Eigen::MatrixXd y_linear;                    // [N x ny] linear closed loop from the same start (empty if not run)
  double linear_rtol = 0, linear_atol = 0;     // its integration tolerances (Dormand-Prince 5(4))
  double linear_error_estimate = -1;           // max |y_lin - the same at 100x looser tolerances| (-1: not known)
  std::string linear_failure;                  // why y_linear ends in NaN (an unstable linear loop), or ""
  Eigen::MatrixXd y_reference;                 // [N x ny] r(t) the controller was given (empty: no reference)
  Eigen::MatrixXd u_disturbance;               // [N x nu] d(t) added to each actuator (empty: no disturbance)

  std::vector<std::string> q_names, v_names, input_names, output_names, controller_state_names;
  std::vector<std::string> s_names;            // [ns] Model::s_names (units Model::s_units)
  std::vector<std::string> input_units, output_units;

  SolverStats stats;
  bool completed = false;                      // reached t_end
  bool cancelled = false;                      // stopped by the caller (partial result kept)
  std::string failure;                         // solver failure: time and reason (partial result kept)

  std::string model_name, model_file, controller, codyna_version;
  std::string settings_json;                   // the settings of the run, as JSON text

  int samples() const { return static_cast<int>(t.size()); }
};

}  // namespace codyna
