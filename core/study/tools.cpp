#include "study/tools.hpp"

#include "control/place.hpp"
#include "dynamics/data.hpp"
#include "dynamics/kinematics.hpp"

namespace codyna {

ModalAnalysis study_modes(const LinearSystem& sys) { return modal_analysis(sys); }
std::string study_format_modes(const ModalAnalysis& modes) { return format_modes(modes); }

ChannelZeros study_zeros(const LinearSystem& sys, int input, int output) { return transmission_zeros(sys, input, output); }

std::vector<HiddenMode> study_uncontrollable(const LinearSystem& sys) {
  return uncontrollable_modes(sys.A, sys.B, sys.state_names);
}
std::vector<HiddenMode> study_unobservable(const LinearSystem& sys) {
  return unobservable_modes(sys.A, sys.C, sys.state_names);
}
std::string study_describe_modes(const std::vector<HiddenMode>& modes) { return describe(modes); }

std::string study_hidden_modes_text(const std::vector<HiddenMode>& hidden) {
  return hidden.empty() ? std::string("yes, every mode") : "no: " + describe(hidden);
}

LqrResult study_lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                    const Eigen::MatrixXd& R, bool discrete) {
  return discrete ? dlqr(A, B, Q, R) : lqr(A, B, Q, R);
}
Eigen::MatrixXd study_place(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::VectorXcd& poles) {
  return place(A, B, poles);
}

struct StudyPoses::Workspace {
  explicit Workspace(const Model& m) : data(m) {}
  Data data;
};
StudyPoses::StudyPoses(const Model& model) : model_(model), ws_(std::make_unique<Workspace>(model)) {}
StudyPoses::~StudyPoses() = default;
const std::vector<SE3>& StudyPoses::at(const Eigen::VectorXd& q) {
  forward_kinematics(model_, ws_->data, q);
  return ws_->data.oMi;
}

IntegratorSettings study_integrator_settings(const Model& model) {
  return integrator_settings(model.spec.solver);
}
std::unique_ptr<Stepper> study_stepper(const Model& model, const IntegratorSettings& settings) {
  return std::make_unique<Stepper>(model, settings);
}

}  // namespace codyna
