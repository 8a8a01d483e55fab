#include "study/sweep_variant.hpp"

#include "analysis/response_figures.hpp"
#include "analysis/stability.hpp"


#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/tools.hpp"

namespace codyna::sweep_detail {

void sort_poles(Eigen::VectorXcd& p) {
  std::sort(p.data(), p.data() + p.size(), [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.real() < b.real() || (a.real() == b.real() && a.imag() < b.imag());
  });
}

Eigen::VectorXcd poles_of(const Eigen::MatrixXd& A) {
  Eigen::VectorXcd p = A.size() ? Eigen::VectorXcd(A.eigenvalues()) : Eigen::VectorXcd();
  sort_poles(p);
  return p;
}

double max_real(const Eigen::VectorXcd& p) {
  return p.size() ? p.real().maxCoeff() : -std::numeric_limits<double>::infinity();
}

// asymptotically stable (analysis/stability.hpp): every pole stable, continuous or sampled
bool stable_poles(const Eigen::VectorXcd& p, const Eigen::MatrixXd& A, bool discrete) {
  return classify_poles(p, discrete, stability_tolerance(A)).asymptotically_stable();
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}




// The variant's nonlinear closed-loop run with the sweep's controller.
void simulate_variant(const Context& c, nlohmann::json j, SweepVariant& v) {
  try {
    if (c.replace_controller) {
      nlohmann::json K = nlohmann::json::array();
      for (Eigen::Index a = 0; a < c.K.rows(); ++a) {
        nlohmann::json row = nlohmann::json::array();
        for (Eigen::Index b = 0; b < c.K.cols(); ++b) row.push_back(c.K(a, b));
        K.push_back(row);
      }
      j["controller"] = {{"type", "state_feedback"}, {"K", K}, {"operating_point", c.controller_point}};
      if (j.contains("analysis") && j["analysis"].is_object()) j["analysis"]["controller"] = "model";
    }
    SimulateRequest sr;
    sr.model = c.request->model;
    const SimulateJob sj = study_simulate_job(sr, study_parse_model(j, c.request->model));
    const SimulationResult& r = sj.result;
    v.sim_status = r.completed ? 0 : 1;
    v.sim_reason = r.completed ? std::string() : r.failure;
    v.sim_t_end = r.t.empty() ? 0.0 : r.t.back();
    v.peak_input = sj.max_abs_input;
    v.final_error = 0;
    const Eigen::Index ny = r.y.cols();
    v.overshoot = v.settling_time = Eigen::VectorXd::Constant(ny, std::numeric_limits<double>::quiet_NaN());
    if (!r.t.empty() && ny > 0) {
      const Eigen::Index last = r.y.rows() - 1;
      Eigen::VectorXd target = sj.setup.plant ? sj.setup.plant->lin.system.y0 : Eigen::VectorXd::Zero(ny);
      if (r.y_reference.cols() == ny && r.y_reference.rows() == r.y.rows()) target = r.y_reference.row(last).transpose();
      if (target.size() == ny) {
        v.final_error = (r.y.row(last).transpose() - target).cwiseAbs().maxCoeff();
        if (r.completed) response_figures(r.t, r.y.rowwise() - target.transpose(), v.overshoot, v.settling_time);
      } else {
        v.final_error = std::numeric_limits<double>::quiet_NaN();
      }
    }
    // seconds at a limit per Plant/In: 0 never, NaN for an input without limits
    const Model& m = sj.model;
    v.saturation_time = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(m.plant_inputs.size()),
                                                  std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < m.plant_inputs.size(); ++k) {
      const ActuatorModel& a = m.actuators[static_cast<std::size_t>(m.plant_inputs[k])];
      if (!std::isfinite(a.min) && !std::isfinite(a.max)) continue;
      double at = 0;
      for (const Saturation& sat : sj.saturation)
        if (sat.actuator == a.name) at += sat.at_max + sat.at_min;
      v.saturation_time[static_cast<Eigen::Index>(k)] = at;
    }
  } catch (const std::exception& e) {
    v.sim_status = 2;
    v.sim_reason = e.what();
    v.peak_input.resize(0);
    v.overshoot.resize(0);
    v.settling_time.resize(0);
    v.saturation_time.resize(0);
  }
}

// the variant's model file, the varied fields set
nlohmann::json variant_file(const Context& c, const SweepVariant& v) {
  nlohmann::json j = *c.file;
  for (std::size_t k = 0; k < c.pointers.size(); ++k) j[c.pointers[k]] = v.values[k];
  return j;
}

// the variant's spec: what reading variant_file gives, by reading only the edited elements again
ModelSpec variant_spec(const Context& c, const SweepVariant& v) {
  if (c.whole_file) return study_parse_model(variant_file(c, v), c.request->model);
  ModelSpec spec = *c.nominal;
  for (const ElementEdit& e : c.edits) {
    nlohmann::json element = (*c.file)[e.section][e.index];
    for (const auto& [pointer, k] : e.fields) element[pointer] = v.values[k];
    parse_model_element(spec, e.section, e.index, element, c.request->model);
  }
  return spec;
}

// what the varied fields change of the compiled model when they leave its tree, names and indices
// as they are (compile_numbers): a body's mass, com or inertia (or a component of them), any field of
// an effect, a joint's q0 or v0, an actuator's or a sensor's numbers (NumbersChanged); nothing otherwise
std::optional<NumbersChanged> numbers_changed(const std::vector<SweepVary>& vary) {
  NumbersChanged what;
  for (const SweepVary& v : vary) {
    const std::string& f = v.field;
    const std::size_t a = f.find('/', 1), b = a == std::string::npos ? a : f.find('/', a + 1);
    if (b == std::string::npos || b == a + 1 || !std::all_of(f.begin() + static_cast<long>(a) + 1, f.begin() + static_cast<long>(b), ::isdigit))
      return std::nullopt;
    const std::string section = f.substr(1, a - 1);
    const std::size_t e = f.find('/', b + 1);
    const std::string name = f.substr(b + 1, e == std::string::npos ? std::string::npos : e - b - 1);
    if (section == "bodies" && (name == "mass" || name == "com" || name == "inertia"))
      what.bodies = true;
    else if (section == "effects")
      what.effects = true;
    else if (section == "joints" && (name == "q0" || name == "v0"))
      what.initial = true;
    else if (section == "actuators" && (name == "gain" || name == "u0" || name == "min" || name == "max" || name == "point" ||
                                        name == "direction" || name == "point_a" || name == "point_b" || name == "weights"))
      what.actuators = true;
    else if (section == "sensors" && (name == "point" || name == "axis" || name == "point_a" || name == "point_b"))
      what.sensors = true;
    else
      return std::nullopt;
  }
  if (vary.empty()) return std::nullopt;
  return what;
}

// which element each varied field belongs to (Context::edits), or whole_file
void plan_edits(Context& c, const std::vector<SweepVary>& vary) {
  static const char* const sections[] = {"bodies", "joints", "constraints", "effects", "actuators", "sensors"};
  for (std::size_t k = 0; k < vary.size(); ++k) {
    const std::string& f = vary[k].field;  // "/section/index/rest..."
    const std::size_t a = f.find('/', 1), b = a == std::string::npos ? a : f.find('/', a + 1);
    const std::string section = f.substr(1, a == std::string::npos ? std::string::npos : a - 1);
    const std::string index = a == std::string::npos ? "" : f.substr(a + 1, b == std::string::npos ? b : b - a - 1);
    const bool known = std::find_if(std::begin(sections), std::end(sections),
                                    [&](const char* s) { return section == s; }) != std::end(sections);
    const bool digits = !index.empty() && index.size() < 9 && std::all_of(index.begin(), index.end(), ::isdigit) &&
                        (index == "0" || index[0] != '0');
    if (!known || !digits || b == std::string::npos || !c.file->contains(section) || !(*c.file)[section].is_array() ||
        std::stoul(index) >= (*c.file)[section].size() || !(*c.file)[section][std::stoul(index)].is_object()) {
      c.whole_file = true;
      return;
    }
    const std::size_t i = std::stoul(index);
    auto it = std::find_if(c.edits.begin(), c.edits.end(), [&](const ElementEdit& e) { return e.section == section && e.index == i; });
    if (it == c.edits.end()) it = c.edits.insert(c.edits.end(), ElementEdit{section, i, {}});
    it->fields.emplace_back(nlohmann::json::json_pointer(f.substr(b)), k);
  }
}

void run_variant(const Context& c, long long i, SweepVariant& v) {
  v.values = c.plan->values(i);
  try {
    const ModelSpec spec = variant_spec(c, v);
    const auto simulate_after = [&] {
      if (c.simulate) simulate_variant(c, variant_file(c, v), v);
    };
    const LinearizeJob lj =
        c.structure ? study_linearize_job(c.linearize, spec, *c.structure, c.changed) : study_linearize_job(c.linearize, spec);
    const LinearSystem& sys = lj.linearization.lin.system;  // continuous
    if (sys.nx() != c.nx || sys.nu() != c.nu || sys.ny() != c.ny) {
      v.status = SweepStatus::SizeDiffers;
      v.reason = "A, B, C, D are " + std::to_string(sys.nx()) + " states, " + std::to_string(sys.nu()) + " inputs, " +
                 std::to_string(sys.ny()) + " outputs where the nominal model's are " + std::to_string(c.nx) + ", " +
                 std::to_string(c.nu) + ", " + std::to_string(c.ny);
      return;
    }
    if (sys.state_names != c.state_names) {
      v.status = SweepStatus::SizeDiffers;
      v.reason = "its states are (" + joined(sys.state_names) + ") where the nominal model's are (" +
                 joined(c.state_names) + ")";
      return;
    }
    v.A = sys.A;
    v.B = sys.B;
    v.C = sys.C;
    v.D = sys.D;
    v.open_poles = poles_of(sys.A);
    v.open_max_real = max_real(v.open_poles);
    v.open_stable = stable_poles(v.open_poles, sys.A, sys.Ts > 0);
    v.uncontrollable = static_cast<int>(lj.uncontrollable.size());
    if (v.uncontrollable) v.uncontrollable_text = study_describe_modes(lj.uncontrollable);
    if (c.closed_loop) {
      Eigen::MatrixXd K = c.K;
      if (c.redesign) {
        const StudySimulation setup = study_simulation(lj.model);
        const Eigen::MatrixXd* g = setup.controller ? setup.controller->gain() : nullptr;
        if (!g) throw std::invalid_argument("the LQR was not designed again for this variant");
        K = *g;
        v.K = K;
      }
      const Eigen::MatrixXd Acl = sys.A - sys.B * K;
      v.closed_poles = poles_of(Acl);
      v.closed_max_real = max_real(v.closed_poles);
      v.stable = stable_poles(v.closed_poles, Acl, sys.Ts > 0);
    } else {
      v.stable = stable_poles(v.open_poles, sys.A, sys.Ts > 0);
    }
    v.status = SweepStatus::Ok;
    simulate_after();
  } catch (const ModelError& e) {
    v.status = SweepStatus::ModelError;
    v.reason = e.what();
  } catch (const ConvergenceError& e) {
    v.status = SweepStatus::NotConverged;
    v.reason = e.what();
  } catch (const std::invalid_argument& e) {
    v.status = SweepStatus::Refused;
    v.reason = e.what();
  } catch (const std::exception& e) {
    v.status = SweepStatus::Failed;
    v.reason = e.what();
  }
  if (v.status != SweepStatus::Ok) {
    v.A.resize(0, 0);
    v.B.resize(0, 0);
    v.C.resize(0, 0);
    v.D.resize(0, 0);
    v.K.resize(0, 0);
    v.open_poles.resize(0);
    v.closed_poles.resize(0);
    v.stable = false;
    v.uncontrollable = 0;
    v.uncontrollable_text.clear();
  }
}

}  // namespace codyna::sweep_detail
