#include "study/tire_job.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "dynamics/tire_effect.hpp"
#include "io/atomic_file.hpp"
#include "io/output_guard.hpp"
#include "study/files.hpp"
#include "study/workflow.hpp"
#include "vehicle/tir_file.hpp"

namespace codyna {

namespace {

double tire_grid_number(const std::string& s, const std::string& option) {
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != s.size() || !std::isfinite(x))
    throw std::invalid_argument(option + " " + s + ": expected a number, a list V1,V2,... or a range A:B:N");
  return x;
}

}  // namespace

std::vector<double> study_tire_grid(const std::string& text, const std::string& option) {
  std::vector<double> v;
  if (text.find(':') != std::string::npos) {
    std::vector<std::string> parts;
    std::stringstream ss(text);
    for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
    if (parts.size() != 3) throw std::invalid_argument(option + " " + text + ": expected a range A:B:N");
    const double a = tire_grid_number(parts[0], option), b = tire_grid_number(parts[1], option);
    const double nd = tire_grid_number(parts[2], option);
    if (nd < 1 || nd > 100000 || nd != std::floor(nd))
      throw std::invalid_argument(option + " " + text + ": expected a whole number of points from 1 to 100000 after the second ':'");
    const int n = static_cast<int>(nd);
    for (int k = 0; k < n; ++k) v.push_back(n == 1 ? a : a + (b - a) * k / (n - 1));
    return v;
  }
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, ',');) v.push_back(tire_grid_number(p, option));
  if (v.empty()) throw std::invalid_argument(option + ": expected at least one value");
  return v;
}

TireJob study_tire_job(const TireRequest& r) {
  const bool from_model = !r.model.empty() || r.spec;
  if (r.tir.empty() == !from_model) throw std::invalid_argument("--tir or --model: give one of them (a .tir file, or a model file with --tire NAME)");
  if (from_model && r.tire.empty()) throw std::invalid_argument("--tire: name the model's tire element to evaluate");
  if (!r.tir.empty() && !r.tire.empty()) throw std::invalid_argument("--tire: names a model's tire element, goes with --model (not --tir)");
  if (!(r.speed > 0) || !std::isfinite(r.speed)) throw std::invalid_argument("--speed: expected a forward speed > 0 m/s");
  TireJob job;
  TireModel t;
  std::unique_ptr<Model> model;
  if (!r.tir.empty()) {
    t.law = TireLaw::MagicFormula;
    try {
      t.mf = std::make_shared<const MagicFormulaParameters>(read_tir_file(r.tir));
    } catch (const TirFileError& e) {
      throw std::invalid_argument(e.what());  // a bad tire file is bad input (exit 1)
    }
    if (r.side == "left") t.side = 1;
    else if (r.side == "right") t.side = 2;
    else if (!r.side.empty()) throw std::invalid_argument("--side " + r.side + ": expected left or right (none: as the file)");
    const char* version = t.mf->FITTYP == 61 ? "MF 6.1" : t.mf->FITTYP == 62 ? "MF 6.2" : "MF 5.2";
    job.tire = r.tir + " (" + version + (r.side.empty() ? "" : ", " + r.side) + ")";
    if (!t.mf->defaulted.empty()) job.notes.push_back(std::to_string(t.mf->defaulted.size()) + " keys the file does not give take their defaults");
  } else {
    if (!r.side.empty()) throw std::invalid_argument("--side: goes with --tir (a model's tire element has its own side)");
    model = std::make_unique<Model>(study_model(r.spec ? *r.spec : study_read_model(r.model), r.model));
    const std::string model_name = r.model.empty() ? std::string("the model") : r.model;
    std::vector<std::string> names;
    for (const TireModel& m : model->tires) names.push_back(m.name);
    const auto it = std::find(names.begin(), names.end(), r.tire);
    if (it == names.end()) {
      std::string all;
      for (const std::string& n : names) all += (all.empty() ? "" : ", ") + n;
      throw std::invalid_argument("--tire " + r.tire + ": no such tire in " + model_name + " (tires: " + (all.empty() ? "none" : all) + ")");
    }
    t = model->tires[static_cast<std::size_t>(it - names.begin())];
    const char* law = t.law == TireLaw::Linear ? "linear" : t.law == TireLaw::Fiala ? "fiala" : "magic_formula";
    job.tire = model_name + ": " + r.tire + " (" + law + ")";
  }
  std::vector<double> loads = r.loads;
  if (loads.empty()) {
    if (t.mf) {
      for (double f : {0.5, 1.0, 1.5}) loads.push_back(f * t.mf->FNOMIN);
    } else if (r.typical_loads) {
      loads = {2000.0, 4000.0, 6000.0};
    } else {
      throw std::invalid_argument("--load: give the loads (N) for a " + std::string(t.law == TireLaw::Linear ? "linear" : "fiala") + " tire");
    }
  }
  for (double f : loads)
    if (!(f >= 0)) throw std::invalid_argument("--load: expected loads >= 0 N, got " + std::to_string(f));
  const auto or_zero = [](const std::vector<double>& v) { return v.empty() ? std::vector<double>{0.0} : v; };
  const std::vector<double> kappa = or_zero(r.kappa), alpha = or_zero(r.alpha), gamma = or_zero(r.gamma);
  for (double a : alpha)
    if (std::abs(a) >= 1.5707963267948966) throw std::invalid_argument("--alpha: a slip angle within (-pi/2, pi/2) rad, got " + std::to_string(a));
  const std::size_t n = loads.size() * kappa.size() * alpha.size() * gamma.size();
  if (n > 10000000) throw std::invalid_argument("the grid has " + std::to_string(n) + " points: at most 10000000");
  job.columns = {"Fx", "Fy", "Fz", "Mx", "My", "Mz", "kappa", "alpha", "gamma", "phit", "Vx", "Re", "t", "mux", "muy", "omega", "Mzr", "Kya", "Kxk"};
  job.rows.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(job.columns.size()));
  Eigen::Index row = 0;
  for (double fz : loads)
    for (double g : gamma)
      for (double a : alpha)
        for (double k : kappa) {
          TireInput<double> in;
          in.Fz = fz;
          in.kappa = k;
          in.alpha = a;
          in.gamma = g;
          in.Vx = r.speed;
          const TireForces<double> f = tire_effect_law<double>(t, in);
          job.rows.row(row++) << f.Fx, f.Fy, f.Fz, f.Mx, f.My, f.Mz, k, a, g, 0.0, r.speed, f.Re, f.trail, f.mux, f.muy,
              f.omega, f.Mzr, f.Kya, f.Kxk;
        }
  if (r.out.empty()) return job;
  std::vector<std::string> inputs{r.tir.empty() ? r.model : r.tir};
  guard_output(r.out, OutputKind::TireCsv, inputs);
  std::ostringstream os;
  os.precision(17);
  for (std::size_t c = 0; c < job.columns.size(); ++c) os << (c ? "," : "") << job.columns[c];
  os << "\n";
  for (Eigen::Index i = 0; i < job.rows.rows(); ++i) {
    for (Eigen::Index c = 0; c < job.rows.cols(); ++c) os << (c ? "," : "") << job.rows(i, c);
    os << "\n";
  }
  write_file_atomically(r.out, os.str());
  job.written = r.out;
  return job;
}

}  // namespace codyna
