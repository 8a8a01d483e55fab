#include "model/model.hpp"

#include <algorithm>

namespace codyna {

namespace {
template <class T>
int find_named(const std::vector<T>& items, const std::string& name) {
  for (std::size_t i = 0; i < items.size(); ++i)
    if (items[i].name == name) return static_cast<int>(i);
  return -1;
}
}  // namespace

Eigen::VectorXd Model::u_nominal() const {
  Eigen::VectorXd u(nu());
  for (int k = 0; k < nu(); ++k) u[k] = actuators[k].u0;
  return u;
}

bool Model::is_velocity_row(int row) const {
  return std::binary_search(velocity_rows.begin(), velocity_rows.end(), row);
}

int Model::find_body(const std::string& n) const {
  for (int i = 0; i < nbodies; ++i)
    if (body_names[i] == n) return i;
  return -1;
}
int Model::find_actuator(const std::string& n) const { return find_named(actuators, n); }
int Model::find_sensor(const std::string& n) const { return find_named(sensors, n); }
int Model::find_joint(const std::string& n) const {
  for (int i = 1; i < nbodies; ++i)
    if (joints[i].name == n) return i;
  return -1;
}

Eigen::VectorXd neutral(const Model& model) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq);
  for (int b = 1; b < model.nbodies; ++b) {
    const JointModel& j = model.joints[b];
    if (j.type == JointType::Spherical) q[j.idx_q] = 1.0;
    if (j.type == JointType::Free) q[j.idx_q + 3] = 1.0;
  }
  return q;
}

std::string rate_unit(const std::string& unit) {
  if (unit.empty()) return "1/s";
  const auto ends = [&](const std::string& tail) {
    return unit.size() >= tail.size() && unit.compare(unit.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends("/s")) return unit + "^2";
  if (ends("/s^2")) return unit.substr(0, unit.size() - 1) + "3";
  return unit + "/s";
}

}  // namespace codyna
