// Work-precision study (docs/work-precision.md): for each problem, integrator and
// rtol = atol = 10^-(2 + k/2), k = 0..kmax, one run, its error against an exact or
// reference solution and its CPU time (best of `repeats` runs).
//   andrews: Andrews' squeezing mechanism (protocol of the Test Set for IVP Solvers),
//            t = 0.03 s, error = max_i |y_i - y_ref,i| / |y_ref,i| over the seven
//            angles (SCD = -log10 error);
//   a01:     IFToMM A01 pendulum, 10 s, error = max over the output samples (every
//            0.1 s) of the distance [m] between the mass and the exact elliptic-function
//            solution (computed here by the AGM).
//
//   build/bin/codyna_work_precision [--kmax 20] [--repeats 3] [--csv FILE] [--integrators ida,cvode-bdf,...]
//                                   [--problems andrews,a01]
//
// Prints a table and writes CSV columns:
//   problem,integrator,k,tol,error,scd,cpu_s,steps,evaluations,jacobians,projections,completed
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "model/compile.hpp"
#include "simulation/simulator.hpp"

namespace {

using namespace codyna;

const std::pair<const char*, double> kReference[] = {
    {"beta", 15.81077119629904},  {"Theta", -15.75637105984298},  {"gamma", 0.04082224013073101},
    {"Phi", -0.5347301163226948}, {"delta", 0.5244099658805304},  {"Omega", 0.5347301163226948},
    {"epsilon", 1.048080741042263}};

// Jacobi sn(u | m) by the arithmetic-geometric mean (Abramowitz & Stegun 16.4);
// also returns K(m) = pi / (2 a_N).
double jacobi_sn(double u, double m, double* K = nullptr) {
  double a[16], c[16];
  a[0] = 1;
  double b = std::sqrt(1 - m);
  c[0] = std::sqrt(m);
  int n = 0;
  while (std::abs(c[n]) > 1e-16 && n < 15) {
    a[n + 1] = 0.5 * (a[n] + b);
    c[n + 1] = 0.5 * (a[n] - b);
    b = std::sqrt(a[n] * b);
    ++n;
  }
  if (K) *K = M_PI / (2 * a[n]);
  double phi = std::ldexp(1.0, n) * a[n] * u;
  for (int i = n; i > 0; --i) phi = 0.5 * (phi + std::asin(c[i] / a[i] * std::sin(phi)));
  return std::sin(phi);
}

// IFToMM A01: point mass 1 kg, L = 1 m, g = 9.81, released from the horizontal at rest;
// theta from the downward vertical = 2 asin(k sn(K - w0 t, k)), k = sin(pi/4).
void a01_exact(double t, double* x, double* y) {
  const double k = std::sin(M_PI / 4), m = k * k, w0 = std::sqrt(9.81);
  double K;
  jacobi_sn(0, m, &K);
  const double th = 2 * std::asin(k * jacobi_sn(K - w0 * t, m));
  *x = std::sin(th);
  *y = -std::cos(th);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> r;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) r.push_back(x);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int kmax = 20, repeats = 3;  // tolerances 1e-2 .. 1e-12
  std::string csv;
  std::vector<std::string> integrators{"ida", "cvode-bdf", "cvode-adams", "arkode"};
  std::vector<std::string> problems{"andrews", "a01"};
  for (int i = 1; i < argc; i += 2) {
    if (i + 1 == argc) argv[i] = const_cast<char*>("");  // an option without its value: usage
    if (!std::strcmp(argv[i], "--kmax")) kmax = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--repeats")) repeats = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--csv")) csv = argv[i + 1];
    else if (!std::strcmp(argv[i], "--integrators")) integrators = split(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--problems")) problems = split(argv[i + 1]);
    else {
      std::cerr << "usage: codyna_work_precision [--kmax K] [--repeats N] [--csv FILE] [--integrators a,b] "
                   "[--problems andrews,a01]\n";
      return 1;
    }
  }
  {  // the exact solution against the published point (docs of examples/iftomm_a01_pendulum.json)
    double x, y;
    a01_exact(1.0, &x, &y);
    std::cout << "A01 exact at t = 1 s: (" << std::setprecision(13) << x << ", " << y
              << "), published (-0.9862917511319, -0.1650108531255)\n"
              << std::defaultfloat;
  }
  std::ostringstream out;
  out << "problem,integrator,k,tol,error,scd,cpu_s,steps,evaluations,jacobians,projections,completed\n";
  for (const std::string& problem : problems) {
    std::string file;
    double t_end, output_step;
    if (problem == "andrews") file = "andrews_squeezer.json", t_end = 0.03, output_step = 0.03;
    else if (problem == "a01") file = "iftomm_a01_pendulum.json", t_end = 10.0, output_step = 0.1;
    else {
      std::cerr << "unknown problem " << problem << "\n";
      return 1;
    }
    const std::string model_path = std::string(CODYNA_SOURCE_DIR) + "/examples/" + file;
    const Model m = compile(load_model_spec(model_path), model_path);
    std::cout << "\n" << problem << "\n"
              << std::left << std::setw(12) << "integrator" << std::right << std::setw(4) << "k" << std::setw(10)
              << "tol" << std::setw(12) << "error" << std::setw(12) << "CPU [s]" << std::setw(10) << "steps"
              << std::setw(12) << "evals" << "\n";
    for (const std::string& method : integrators) {
      for (int k = 0; k <= kmax; ++k) {
        const double tol = std::pow(10.0, -(2.0 + k / 2.0));
        SimulationOptions o;
        o.integrator.method = method;
        o.integrator.rtol = o.integrator.atol = tol;
        o.t_end = t_end;
        o.output_step = output_step;
        o.projection_tolerance = 0.1 * tol;  // projections must not spoil the accuracy asked for
        SimulationResult r;
        double best = 1e300;
        for (int rep = 0; rep < repeats; ++rep) {
          const auto t0 = std::chrono::steady_clock::now();
          r = simulate(m, nullptr, nullptr, o);
          best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        double err = 0;
        if (problem == "andrews") {
          for (const auto& [name, ref] : kReference)
            err = std::max(err, std::abs(r.q(r.samples() - 1, m.joints[m.find_joint(name)].idx_q) - ref) /
                                    std::abs(ref));
        } else {  // a01: q from the horizontal, mass at (cos q, sin q)
          const int iq = m.joints[m.find_joint("pin")].idx_q;
          for (int s = 0; s < r.samples(); ++s) {
            double x, y;
            a01_exact(r.t[s], &x, &y);
            const double q = r.q(s, iq);
            err = std::max(err, std::hypot(std::cos(q) - x, std::sin(q) - y));
          }
        }
        if (!r.completed) err = std::nan("");
        const double scd = -std::log10(err);
        std::cout << std::left << std::setw(12) << method << std::right << std::setw(4) << k << std::setw(10)
                  << std::setprecision(2) << tol << std::setw(12) << std::setprecision(3) << err << std::setw(12)
                  << std::fixed << std::setprecision(4) << best << std::defaultfloat << std::setw(10)
                  << r.stats.steps << std::setw(12) << r.stats.rhs_evals
                  << (r.completed ? "" : "  FAILED: " + r.failure) << "\n";
        out << problem << "," << method << "," << k << "," << tol << "," << err << "," << scd << "," << best << ","
            << r.stats.steps << "," << r.stats.rhs_evals << "," << r.stats.jac_evals << "," << r.stats.projections
            << "," << r.completed << "\n";
      }
    }
  }
  if (!csv.empty()) {
    try {
      write_file_atomically(csv, out.str());  // the whole file or the old one, never half
    } catch (const std::exception& e) {
      std::cerr << csv << ": cannot write: " << e.what() << "\n";
      return 2;
    }
    std::cout << "wrote " << csv << "\n";
  }
  return 0;
}
