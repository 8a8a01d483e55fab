// The Simbody peer of the work-precision study (bench/work_precision.cpp): the same
// reference problems, built in Simbody 3.7 from the same model files, integrated by
// Simbody's own integrators, sampled at the same output times into the same quantities.
// The physics is Simbody's: only the parameters come from codyna's model description.
#pragma once

#include <string>
#include <vector>

namespace codyna::peer {

struct PeerRun {
  bool completed = false;
  std::string failure;                    // why not completed
  double cpu_s = 0;                       // best of the repeats: thread CPU time of one run
                                          // (state set-up, initialization, stepping to t_end)
  long steps = 0, evaluations = 0;        // steps taken, realizations (last run)
  std::vector<double> t;                  // 0, output_step, ..., t_end
  std::vector<std::vector<double>> y;     // the problem's quantities at each t (work_precision.cpp)
};

// "simbody-rkm" (Runge-Kutta-Merson, Simbody's default), "simbody-rkf" (Runge-Kutta-Feldberg),
// "simbody-verlet" (Simbody's error-controlled Verlet); also accepted by run_simbody:
// "simbody-cpodes" (CPodes BDF, Newton), which aborts in Debian's Simbody 3.7
std::vector<std::string> simbody_integrators();
bool simbody_supports(const std::string& problem);
// tol: Simbody's accuracy; the constraint tolerance is tol / 10 (as codyna's projections)
PeerRun run_simbody(const std::string& problem, const std::string& integrator, double tol, double t_end,
                    double output_step, int repeats, int a02_n = 40);

}  // namespace codyna::peer
