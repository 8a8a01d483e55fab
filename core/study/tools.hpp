// The analyses and designs a front end applies to what a study returned, one call each:
// modes, transmission zeros, controllability, LQR and pole placement, the body poses the 3-D
// view draws, and the nonlinear plant stepped from outside (co-simulation). Thin doors onto
// analysis/, control/, dynamics/ and simulation/, so that a front end (the CLI, codyna-gui,
// the MEX gateway, the Python module) includes study/ and model/ only.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "analysis/linear_system.hpp"
#include "analysis/modal.hpp"
#include "analysis/zeros.hpp"
#include "control/controllability.hpp"
#include "control/lqr.hpp"
#include "model/model.hpp"
#include "simulation/integrator.hpp"
#include "simulation/stepper.hpp"

namespace codyna {

// Eigenvalues, frequencies, damping and mode shapes of A (continuous or discrete), and the
// table `codyna linearize` prints (analysis/modal.hpp).
ModalAnalysis study_modes(const LinearSystem& sys);
std::string study_format_modes(const ModalAnalysis& modes);

// The transmission zeros of the channel input -> output (indices into B's columns, C's rows).
ChannelZeros study_zeros(const LinearSystem& sys, int input, int output);

// The modes the inputs cannot move (A, B) and the outputs cannot see (A, C), named by their
// dominant states; study_describe_modes gives "lambda = 0 (cart, cart_dot); ..." for messages.
std::vector<HiddenMode> study_uncontrollable(const LinearSystem& sys);
std::vector<HiddenMode> study_unobservable(const LinearSystem& sys);
std::string study_describe_modes(const std::vector<HiddenMode>& modes);
// "yes, every mode", or "no: " and the modes: how codyna linearize and the GUI say controllability
// (of the uncontrollable modes) and observability (of the unobservable ones)
std::string study_hidden_modes_text(const std::vector<HiddenMode>& hidden);

// LQR (u = -K x, MATLAB's sign convention) continuous or, with `discrete`, for x[k+1] = A x + B u;
// pole placement (MATLAB's place: u = -K x puts eig(A - B K) at `poles`). Bad sizes, weights or
// an unstabilizable pair throw std::invalid_argument with the reason.
LqrResult study_lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                    const Eigen::MatrixXd& R, bool discrete = false);
Eigen::MatrixXd study_place(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::VectorXcd& poles);

// The world pose of every body (index 0 the ground) at a configuration q, as the 3-D view draws
// it. One object per view: it keeps its workspace between calls.
class StudyPoses {
 public:
  explicit StudyPoses(const Model& model);
  ~StudyPoses();
  StudyPoses(const StudyPoses&) = delete;
  StudyPoses& operator=(const StudyPoses&) = delete;
  const std::vector<SE3>& at(const Eigen::VectorXd& q);

 private:
  struct Workspace;
  const Model& model_;
  std::unique_ptr<Workspace> ws_;
};

// The nonlinear plant stepped from outside (simulation/stepper.hpp), with `settings`;
// study_integrator_settings gives the model file's solver settings to start from. The model must
// outlive the stepper.
IntegratorSettings study_integrator_settings(const Model& model);
std::unique_ptr<Stepper> study_stepper(const Model& model, const IntegratorSettings& settings);

}  // namespace codyna
