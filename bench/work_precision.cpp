// Work-precision study on Andrews' squeezing mechanism (docs/BENCHMARKS.md
// section 1, protocol of the Test Set for IVP Solvers): for each integrator and
// rtol = atol = 10^-(2 + k/2), k = 0..kmax, simulate to t = 0.03 s and record the
// significant correct digits SCD = -log10(max_i |y_i - y_ref,i| / |y_ref,i|) of
// the seven angles, and the CPU time (best of `repeats` runs).
//
//   build/bin/codyna_work_precision [--kmax 16] [--repeats 3] [--csv FILE] [--integrators ida,cvode-bdf,...]
//
// Prints a table and writes CSV columns: integrator,k,tol,scd,cpu_s,steps,evaluations,jacobians,projections,completed
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "io/model_file.hpp"
#include "model/compile.hpp"
#include "simulation/simulator.hpp"

namespace {

using namespace codyna;

const std::pair<const char*, double> kReference[] = {
    {"beta", 15.81077119629904},  {"Theta", -15.75637105984298},  {"gamma", 0.04082224013073101},
    {"Phi", -0.5347301163226948}, {"delta", 0.5244099658805304},  {"Omega", 0.5347301163226948},
    {"epsilon", 1.048080741042263}};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> r;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) r.push_back(x);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int kmax = 16, repeats = 3;
  std::string csv, model_path = std::string(CODYNA_SOURCE_DIR) + "/examples/andrews_squeezer.json";
  std::vector<std::string> integrators{"ida", "cvode-bdf", "cvode-adams", "arkode"};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--kmax")) kmax = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--repeats")) repeats = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--csv")) csv = argv[i + 1];
    else if (!std::strcmp(argv[i], "--integrators")) integrators = split(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--model")) model_path = argv[i + 1];
    else {
      std::cerr << "usage: codyna_work_precision [--kmax K] [--repeats N] [--csv FILE] [--integrators a,b] [--model FILE]\n";
      return 1;
    }
  }
  const Model m = compile(load_model_spec(model_path), model_path);
  std::ostringstream out;
  out << "integrator,k,tol,scd,cpu_s,steps,evaluations,jacobians,projections,completed\n";
  std::cout << std::left << std::setw(12) << "integrator" << std::right << std::setw(4) << "k" << std::setw(10) << "tol"
            << std::setw(8) << "SCD" << std::setw(12) << "CPU [s]" << std::setw(10) << "steps" << std::setw(12)
            << "evals" << "\n";
  for (const std::string& method : integrators) {
    for (int k = 0; k <= kmax; ++k) {
      const double tol = std::pow(10.0, -(2.0 + k / 2.0));
      SimulationOptions o;
      o.integrator.method = method;
      o.integrator.rtol = o.integrator.atol = tol;
      o.t_end = 0.03;
      o.output_step = 0.03;
      o.projection_tolerance = 0.1 * tol;  // projections must not spoil the accuracy asked for
      SimulationResult r;
      double best = 1e300;
      for (int rep = 0; rep < repeats; ++rep) {
        const auto t0 = std::chrono::steady_clock::now();
        r = simulate(m, nullptr, nullptr, o);
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      double err = 0;
      for (const auto& [name, ref] : kReference)
        err = std::max(err, std::abs(r.q(r.samples() - 1, m.joints[m.find_joint(name)].idx_q) - ref) / std::abs(ref));
      const double scd = r.completed ? -std::log10(err) : std::nan("");
      std::cout << std::left << std::setw(12) << method << std::right << std::setw(4) << k << std::setw(10)
                << std::setprecision(2) << tol << std::setw(8) << std::fixed << std::setprecision(2) << scd
                << std::setw(12) << std::setprecision(4) << best << std::defaultfloat << std::setw(10)
                << r.stats.steps << std::setw(12) << r.stats.rhs_evals << (r.completed ? "" : "  FAILED: " + r.failure)
                << "\n";
      out << method << "," << k << "," << tol << "," << scd << "," << best << "," << r.stats.steps << ","
          << r.stats.rhs_evals << "," << r.stats.jac_evals << "," << r.stats.projections << "," << r.completed << "\n";
    }
  }
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << out.str();
    if (!f) {
      std::cerr << csv << ": cannot write\n";
      return 2;
    }
    std::cout << "wrote " << csv << "\n";
  }
  return 0;
}
