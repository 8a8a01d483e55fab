// Work-precision study (docs/work-precision.md, docs/performance.md): for each problem,
// each codyna integrator (ida, cvode-bdf, cvode-adams, arkode, alf; alf skips the models it
// refuses, those with rolling constraints; on request alf-fixed: alf at fixed steps of
// 0.1 sqrt(tol), and alf-x-fixed: alf extrapolated (alf_extrapolate) at fixed steps of
// 0.16 tol^(1/4), and alf-x: alf extrapolated with error control (halves and quarters), none
// in the default list) (and each Simbody integrator when the Simbody peer is built) and
// rtol = atol = 10^-(2 + k/2), k = 0..kmax, one run, its error against an exact solution,
// a published reference, an exact invariant or a tight reference run, and its CPU time.
//
//   andrews          Andrews' squeezer (Test Set for IVP Solvers), t = 0.03 s: max over the 7
//                    angles of |y - y_ref| / |y_ref| at t = 0.03 (SCD = -log10 of it)
//   a01              IFToMM A01 pendulum, 10 s: max over the samples (every 0.1 s) of the
//                    distance [m] between the mass and the exact elliptic solution (AGM)
//   a02              IFToMM A02, N = 40 four-bars, 20 s through 20 singular positions: max over
//                    the samples (every 0.05 s) and the 41 cranks of |crank - phi_exact| [rad]
//                    (the exact 1-DOF reduction, tests/models/iftomm_a02.hpp)
//   bricard          IFToMM A04 Bricard (redundant constraints), 10 s: max over the samples
//                    (every 0.05 s) of the distance [m] of point C from a reference run
//   a05              IFToMM A05 stiff flyball governor, 10 s: max over the samples (every
//                    0.05 s) of |slider height - reference run| [m]
//   heavy_top        heavy top at 150 rad/s, 10 s: max over the samples (every 0.01 s) of the
//                    relative change of the energy and of the vertical angular momentum
//   double_pendulum  double pendulum, 1000 s: max over the samples (every 1 s) of
//                    |E - E0| / |E0| (E0: the energy at the start, potential datum y = 0)
// The reference runs (bricard, a05) are codyna at 1e-12 with two integrators; their
// difference is printed as the reference's own uncertainty.
//
//   build/bin/codyna_work_precision [--kmax K] [--repeats N] [--max-cpu S] [--csv FILE]
//       [--table FILE] [--integrators ida,cvode-bdf,...] [--problems andrews,a01,...]
//
// CPU time: thread CPU time of one simulate() call (setting up the solver, integrating,
// recording the samples), the best of up to `repeats` runs (repeats stop once 1 s is spent).
// Each run happens in a child process limited to --max-cpu seconds of CPU (default 30): a
// run over it is killed and reported as stopped, and the integrator's sweep on that problem
// stops there (tighter tolerances cost more).
// CSV columns:
//   problem,code,integrator,k,tol,error,cpu_s,steps,evaluations,jacobians,projections,completed
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "dynamics/kinematics.hpp"
#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "models/iftomm_a02.hpp"
#include "simulation/simulator.hpp"
#ifdef CODYNA_HAVE_SIMBODY
#include "simbody_peer.hpp"
#endif

namespace {

using namespace codyna;

constexpr int kA02N = 40;

const std::pair<const char*, double> kAndrewsReference[] = {
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

// the calling thread's CPU time (every run is single-threaded). Not the process clock: with
// RLIMIT_CPU set, Linux reads that one at scheduler-tick resolution (4 ms here; measured)
double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// a run's output: the problem's quantities at each output time (the same for every code)
struct Series {
  std::vector<double> t;
  std::vector<std::vector<double>> y;
};

struct Problem {
  std::string name;
  double t_end, output_step;
  int kmax;  // the tightest tolerance of the default sweep
  Model model;
  // codyna's result -> the quantities
  std::function<Series(const Model&, const SimulationResult&)> quantities;
  // the error of a run's quantities (ref: the reference run's, empty where not needed)
  std::function<double(const Series&, const Series& ref)> error;
  bool needs_reference = false;
};

Model load_example(const std::string& file) {
  const std::string path = std::string(CODYNA_SOURCE_DIR) + "/examples/" + file;
  return compile(load_model_spec(path), path);
}

int joint_q(const Model& m, const std::string& name) { return m.joints[m.find_joint(name)].idx_q; }

Series by_joint(const SimulationResult& r, const std::vector<int>& idx) {
  Series s;
  s.t = r.t;
  for (int i = 0; i < r.samples(); ++i) {
    std::vector<double> y;
    for (int j : idx) y.push_back(r.q(i, j));
    s.y.push_back(y);
  }
  return s;
}

double max_over_samples(const Series& s, const std::function<double(int)>& f) {
  double e = 0;
  for (int i = 0; i < static_cast<int>(s.t.size()); ++i) e = std::max(e, f(i));
  return e;
}

// the two series have the same output times (else the comparison is meaningless: NaN)
bool aligned(const Series& a, const Series& b) {
  if (a.t.size() != b.t.size()) return false;
  for (size_t i = 0; i < a.t.size(); ++i)
    if (std::abs(a.t[i] - b.t[i]) > 1e-9 * std::max(1.0, std::abs(b.t[i]))) return false;
  return true;
}

std::vector<Problem> make_problems(const std::vector<std::string>& names) {
  std::vector<Problem> ps;
  for (const std::string& n : names) {
    Problem p;
    p.name = n;
    if (n == "andrews") {
      p.t_end = p.output_step = 0.03, p.kmax = 20;
      p.model = load_example("andrews_squeezer.json");
      p.quantities = [](const Model& m, const SimulationResult& r) {
        std::vector<int> idx;
        for (const auto& [name, ref] : kAndrewsReference) idx.push_back(joint_q(m, name));
        return by_joint(r, idx);
      };
      p.error = [](const Series& s, const Series&) {
        double e = 0;
        for (int i = 0; i < 7; ++i)
          e = std::max(e, std::abs(s.y.back()[i] - kAndrewsReference[i].second) / std::abs(kAndrewsReference[i].second));
        return e;
      };
    } else if (n == "a01") {
      p.t_end = 10, p.output_step = 0.1, p.kmax = 20;
      p.model = load_example("iftomm_a01_pendulum.json");
      p.quantities = [](const Model& m, const SimulationResult& r) {  // q from the horizontal
        Series s = by_joint(r, {joint_q(m, "pin")});
        for (auto& y : s.y) y = {std::cos(y[0]), std::sin(y[0])};
        return s;
      };
      p.error = [](const Series& s, const Series&) {
        return max_over_samples(s, [&](int i) {
          double x, y;
          a01_exact(s.t[i], &x, &y);
          return std::hypot(s.y[i][0] - x, s.y[i][1] - y);
        });
      };
    } else if (n == "a02") {
      p.t_end = 20, p.output_step = 0.05, p.kmax = 16;
      p.model = compile(iftomm::a02_spec(kA02N), "iftomm_a02_40");
      p.quantities = [](const Model& m, const SimulationResult& r) {
        std::vector<int> idx;
        for (int i = 0; i <= kA02N; ++i) idx.push_back(joint_q(m, "pivot" + std::to_string(i)));
        return by_joint(r, idx);
      };
      p.error = [](const Series& s, const Series&) {
        const Eigen::VectorXd phi = iftomm::a02_exact(kA02N, s.t);
        return max_over_samples(s, [&](int i) {
          double e = 0;
          for (double c : s.y[i]) e = std::max(e, std::abs(c - phi[i]));
          return e;
        });
      };
    } else if (n == "bricard") {
      p.t_end = 10, p.output_step = 0.05, p.kmax = 20, p.needs_reference = true;
      p.model = load_example("bricard.json");
      p.quantities = [](const Model& m, const SimulationResult& r) {  // E, C (the origin of rod3)
        Series s;
        s.t = r.t;
        Data d(m);
        const int rod3 = m.find_body("rod3");
        for (int i = 0; i < r.samples(); ++i) {
          const Eigen::VectorXd q = r.q.row(i).transpose();
          forward_kinematics<double>(m, d, q);
          const Eigen::Vector3d C = point_position<double>(d, rod3, Eigen::Vector3d::Zero());
          s.y.push_back({r.kinetic_energy[i] + r.potential_energy[i], C.x(), C.y(), C.z()});
        }
        return s;
      };
      p.error = [](const Series& s, const Series& ref) {
        if (!aligned(s, ref)) return std::nan("");
        return max_over_samples(s, [&](int i) {
          return std::hypot(s.y[i][1] - ref.y[i][1], s.y[i][2] - ref.y[i][2], s.y[i][3] - ref.y[i][3]);
        });
      };
    } else if (n == "a05") {
      p.t_end = 10, p.output_step = 0.05, p.kmax = 18, p.needs_reference = true;
      p.model = load_example("iftomm_a05_flyball.json");
      p.quantities = [](const Model& m, const SimulationResult& r) {
        Series s = by_joint(r, {joint_q(m, "slide")});
        for (auto& y : s.y) y[0] += 0.5;  // the slider's height
        return s;
      };
      p.error = [](const Series& s, const Series& ref) {
        if (!aligned(s, ref)) return std::nan("");
        return max_over_samples(s, [&](int i) { return std::abs(s.y[i][0] - ref.y[i][0]); });
      };
    } else if (n == "heavy_top") {
      p.t_end = 10, p.output_step = 0.01, p.kmax = 20;
      p.model = load_example("heavy_top.json");
      p.quantities = [](const Model& m, const SimulationResult& r) {  // E, Lz about the fixed point
        Series s;
        s.t = r.t;
        Data d(m);
        const int b = m.find_body("top");
        const BodySpec& spec = *std::find_if(m.spec.bodies.begin(), m.spec.bodies.end(),
                                             [](const BodySpec& x) { return x.name == "top"; });
        for (int i = 0; i < r.samples(); ++i) {
          const Eigen::VectorXd q = r.q.row(i).transpose(), v = r.v.row(i).transpose();
          forward_kinematics<double>(m, d, q, v);
          const Eigen::Matrix3d& R = d.oMi[b].R;
          const Eigen::Vector3d L = R * spec.inertia * R.transpose() * angular_velocity<double>(d, b) +
                                    spec.mass * point_position<double>(d, b, spec.com)
                                                    .cross(point_velocity<double>(d, b, spec.com));
          s.y.push_back({r.kinetic_energy[i] + r.potential_energy[i], L.z()});
        }
        return s;
      };
      p.error = [](const Series& s, const Series&) {
        return max_over_samples(s, [&](int i) {
          return std::max(std::abs(s.y[i][0] - s.y[0][0]) / std::abs(s.y[0][0]),
                          std::abs(s.y[i][1] - s.y[0][1]) / std::abs(s.y[0][1]));
        });
      };
    } else if (n == "double_pendulum") {
      p.t_end = 1000, p.output_step = 1, p.kmax = 20;
      p.model = load_example("double_pendulum.json");
      p.quantities = [](const Model&, const SimulationResult& r) {
        Series s;
        s.t = r.t;
        for (int i = 0; i < r.samples(); ++i) s.y.push_back({r.kinetic_energy[i] + r.potential_energy[i]});
        return s;
      };
      p.error = [](const Series& s, const Series&) {
        return max_over_samples(s, [&](int i) { return std::abs(s.y[i][0] - s.y[0][0]) / std::abs(s.y[0][0]); });
      };
    } else {
      throw std::invalid_argument("unknown problem \"" + n +
                                  "\" (expected andrews, a01, a02, bricard, a05, heavy_top, double_pendulum)");
    }
    ps.push_back(std::move(p));
  }
  return ps;
}

struct Run {
  std::string problem, code, integrator;
  int k = 0;
  double tol = 0, error = NAN, cpu = 0;
  long steps = 0, evals = 0, jacs = 0, projections = 0;
  bool completed = false;
  std::string failure;
};

struct CodynaRun {
  SimulationResult result;
  double cpu = 0;
};

CodynaRun run_codyna(const Problem& p, const std::string& method, double tol, int repeats) {
  SimulationOptions o;
  o.integrator.method = method;
  o.integrator.rtol = o.integrator.atol = tol;
  if (method == "alf-fixed") {  // alf at fixed steps h = 0.1 sqrt(tol) (10 ms at 1e-2): its error goes as h^2, like tol
    o.integrator.method = "alf";
    o.integrator.alf_fixed_step = true;
    o.integrator.max_step = 0.1 * std::sqrt(tol);
  } else if (method == "alf-x-fixed") {  // alf with Richardson's extrapolation at fixed steps h = 0.16 tol^(1/4) (50 ms at 1e-2, 5 ms at 1e-6): fourth order
    o.integrator.method = "alf";
    o.integrator.alf_extrapolate = o.integrator.alf_fixed_step = true;
    o.integrator.max_step = 0.16 * std::sqrt(std::sqrt(tol));
  } else if (method == "alf-x") {  // alf extrapolated with error control (two steps of H/2 and four of H/4 a step)
    o.integrator.method = "alf";
    o.integrator.alf_extrapolate = true;
  }
  o.t_end = p.t_end;
  o.output_step = p.output_step;
  o.projection_tolerance = 0.1 * tol;  // projections must not spoil the accuracy asked for
  CodynaRun best;
  best.cpu = 1e300;
  double spent = 0;
  for (int rep = 0; rep < repeats && (rep == 0 || spent < 1.0); ++rep) {
    const double t0 = cpu_now();
    SimulationResult r = simulate(p.model, nullptr, nullptr, o);
    const double dt = cpu_now() - t0;
    spent += dt;
    if (dt < best.cpu) best.cpu = dt;
    best.result = std::move(r);
  }
  return best;
}

// One run in a child process (fork) whose CPU time is limited (RLIMIT_CPU): a run that gets
// stuck inside one output interval (tiny steps at a singular position) is killed, the sweep
// goes on. The child sends back the run's numbers and quantities through a pipe.
struct Outcome {
  bool completed = false;
  std::string failure;
  double cpu = 0;
  long steps = 0, evals = 0, jacs = 0, projections = 0;
  Series s;
};

void put(std::string& b, double x) { b.append(reinterpret_cast<const char*>(&x), sizeof x); }
double get(const std::string& b, size_t& at) {
  double x = NAN;
  if (at + sizeof x <= b.size()) std::memcpy(&x, b.data() + at, sizeof x);
  at += sizeof x;
  return x;
}

Outcome in_child(double max_cpu, const std::function<Outcome()>& work) {
  Outcome o;
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error("pipe failed");
  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {  // the child: run, write, exit without running the parent's destructors
    close(fd[0]);
    const rlim_t limit = static_cast<rlim_t>(std::ceil(max_cpu + 1));  // the child's own CPU time starts at 0
    rlimit rl{limit, limit + 1};
    setrlimit(RLIMIT_CPU, &rl);
    std::string b;
    try {
      const Outcome r = work();
      put(b, r.completed), put(b, r.cpu), put(b, r.steps), put(b, r.evals), put(b, r.jacs), put(b, r.projections);
      put(b, r.s.t.size()), put(b, r.s.y.empty() ? 0 : r.s.y[0].size());
      for (size_t i = 0; i < r.s.t.size(); ++i) {
        put(b, r.s.t[i]);
        for (double y : r.s.y[i]) put(b, y);
      }
      b += r.failure;
    } catch (const std::exception& e) {
      b.clear();
      put(b, -1.0);
      b += e.what();
    }
    for (size_t at = 0; at < b.size();) {
      const ssize_t n = write(fd[1], b.data() + at, b.size() - at);
      if (n <= 0) break;
      at += n;
    }
    close(fd[1]);
    _exit(0);
  }
  close(fd[1]);
  std::string b;
  char buf[65536];
  for (ssize_t n; (n = read(fd[0], buf, sizeof buf)) > 0;) b.append(buf, n);
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || b.size() < sizeof(double)) {
    o.failure = WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL)
                    ? "stopped: over the CPU time limit (--max-cpu)"
                    : "the run's process ended abnormally";
    o.cpu = max_cpu;
    return o;
  }
  size_t at = 0;
  const double first = get(b, at);
  if (first < 0) throw std::runtime_error(b.substr(at));
  o.completed = first > 0;
  o.cpu = get(b, at), o.steps = get(b, at), o.evals = get(b, at), o.jacs = get(b, at), o.projections = get(b, at);
  const size_t n = get(b, at), m = get(b, at);
  for (size_t i = 0; i < n; ++i) {
    o.s.t.push_back(get(b, at));
    std::vector<double> y(m);
    for (double& x : y) x = get(b, at);
    o.s.y.push_back(y);
  }
  if (at < b.size()) o.failure = b.substr(at);
  return o;
}

void print_run(const Run& r) {
  std::cout << std::left << std::setw(16) << r.integrator << std::right << std::setw(4) << r.k << std::setw(10)
            << std::setprecision(2) << r.tol << std::setw(12) << std::setprecision(3) << r.error << std::setw(12)
            << std::fixed << std::setprecision(4) << r.cpu << std::defaultfloat << std::setw(10) << r.steps
            << std::setw(12) << r.evals << (r.completed ? "" : "  FAILED: " + r.failure) << std::endl;
}

std::string cell_ms(double cpu) {
  if (!(cpu < 1e300)) return "—";
  std::ostringstream os;
  os << std::setprecision(cpu < 0.01 ? 2 : 3) << cpu * 1e3;
  return os.str();
}

}  // namespace

int main(int argc, char** argv) {
  int kmin = 0, kmax = 20, repeats = 3;
  double expect_below = 0;  // > 0: exit 3 unless every integrator's tightest run on every problem is within it
  double max_cpu = 30;
  std::string csv, table_file;
  std::vector<std::string> integrators{"ida", "cvode-bdf", "cvode-adams", "arkode", "alf"};
  std::vector<std::string> problem_names{"andrews", "a01", "a02", "bricard", "a05", "heavy_top", "double_pendulum"};
#ifdef CODYNA_HAVE_SIMBODY
  for (const std::string& s : peer::simbody_integrators()) integrators.push_back(s);
#endif
  for (int i = 1; i < argc; i += 2) {
    if (i + 1 == argc) argv[i] = const_cast<char*>("");  // an option without its value: usage
    if (!std::strcmp(argv[i], "--kmax")) kmax = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--kmin")) kmin = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--expect-error-below")) expect_below = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--repeats")) repeats = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--max-cpu")) max_cpu = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--csv")) csv = argv[i + 1];
    else if (!std::strcmp(argv[i], "--table")) table_file = argv[i + 1];
    else if (!std::strcmp(argv[i], "--integrators")) integrators = split(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--problems")) problem_names = split(argv[i + 1]);
    else {
      std::cerr << "usage: codyna_work_precision [--kmin K] [--kmax K] [--expect-error-below E] [--repeats N] [--max-cpu S] [--csv FILE] [--table FILE]\n"
                   "                             [--integrators a,b] [--problems andrews,a01,a02,bricard,a05,heavy_top,"
                   "double_pendulum]\n";
      return 1;
    }
  }
  std::vector<Problem> problems;
  try {
    problems = make_problems(problem_names);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  {  // the exact solution against the published point (docs of examples/iftomm_a01_pendulum.json)
    double x, y;
    a01_exact(1.0, &x, &y);
    std::cout << "A01 exact at t = 1 s: (" << std::setprecision(13) << x << ", " << y
              << "), published (-0.9862917511319, -0.1650108531255)\n"
              << std::defaultfloat;
  }
  std::vector<Run> runs;
  bool check_failed = false;
  for (const Problem& p : problems) {
    std::cout << "\n" << p.name << " (" << p.t_end << " s, samples every " << p.output_step << " s)" << std::endl;
    Series ref;
    if (p.needs_reference) {  // two codyna integrators at 1e-12; their difference is the reference's uncertainty
      const char* methods[2] = {"cvode-bdf", "arkode"};
      Series s[2];
      for (int i = 0; i < 2; ++i) {
        const CodynaRun c = run_codyna(p, methods[i], 1e-12, 1);
        if (!c.result.completed) {
          std::cerr << p.name << ": the reference run (" << methods[i] << " at 1e-12) failed: " << c.result.failure << "\n";
          return 2;
        }
        s[i] = p.quantities(p.model, c.result);
      }
      ref = s[0];
      std::cout << "reference: cvode-bdf at 1e-12; its error measured against arkode at 1e-12: "
                << p.error(s[1], s[0]) << std::endl;
    }
    std::cout << std::left << std::setw(16) << "integrator" << std::right << std::setw(4) << "k" << std::setw(10)
              << "tol" << std::setw(12) << "error" << std::setw(12) << "CPU [s]" << std::setw(10) << "steps"
              << std::setw(12) << "evals" << std::endl;
    for (const std::string& method : integrators) {
      const bool simbody = method.rfind("simbody-", 0) == 0;
#ifdef CODYNA_HAVE_SIMBODY
      if (simbody && !peer::simbody_supports(p.name)) {
        std::cout << method << ": the Simbody peer does not model " << p.name << std::endl;
        continue;
      }
#endif
      for (int k = kmin; k <= std::min(kmax, p.kmax); ++k) {
        Run r;
        r.problem = p.name, r.code = simbody ? "simbody" : "codyna", r.integrator = method, r.k = k;
        r.tol = std::pow(10.0, -(2.0 + k / 2.0));
#ifndef CODYNA_HAVE_SIMBODY
        if (simbody) {
          std::cerr << method << ": this build has no Simbody peer (libsimbody-dev)\n";
          return 1;
        }
#endif
        Outcome o;
        try {
          o = in_child(max_cpu, [&] {
            Outcome x;
            if (!simbody) {
              const CodynaRun c = run_codyna(p, method, r.tol, repeats);
              x.cpu = c.cpu, x.completed = c.result.completed, x.failure = c.result.failure;
              x.steps = c.result.stats.steps, x.evals = c.result.stats.rhs_evals;
              x.jacs = c.result.stats.jac_evals, x.projections = c.result.stats.projections;
              x.s = p.quantities(p.model, c.result);
            } else {
#ifdef CODYNA_HAVE_SIMBODY
              const peer::PeerRun pr = peer::run_simbody(p.name, method, r.tol, p.t_end, p.output_step, repeats, kA02N);
              x.cpu = pr.cpu_s, x.completed = pr.completed, x.failure = pr.failure;
              x.steps = pr.steps, x.evals = pr.evaluations;
              x.s.t = pr.t, x.s.y = pr.y;
#endif
            }
            return x;
          });
        } catch (const std::exception& e) {
          const std::string why = e.what();
          if (method.rfind("alf", 0) == 0 && why.find("alf_extrapolate:") != std::string::npos) {
            std::cout << method << ": does not take " << p.name << " at k = " << k << " (" << e.what() << ")" << std::endl;
            continue;  // extrapolated at steps too long for the model's fastest mode: the shorter steps may pass
          }
          if (method.rfind("alf", 0) == 0 && why.find("not integrated by alf") != std::string::npos) {
            std::cout << method << ": does not take " << p.name << " (" << e.what() << ")" << std::endl;
            break;  // a model alf refuses (rolling constraints): no column entry
          }
          std::cerr << method << ": " << e.what() << "\n";
          return 1;
        }
        r.cpu = o.cpu, r.completed = o.completed, r.failure = o.failure;
        r.steps = o.steps, r.evals = o.evals, r.jacs = o.jacs, r.projections = o.projections;
        r.error = r.completed ? p.error(o.s, ref) : std::nan("");
        print_run(r);
        runs.push_back(r);
        if (expect_below > 0 && k == std::min(kmax, p.kmax) && !(r.error <= expect_below)) {
          std::cout << "CHECK FAILED: " << p.name << " " << method << " at tol " << r.tol << ": error " << r.error
                    << " is not below " << expect_below << std::endl;
          check_failed = true;
        }
        if (r.cpu > max_cpu || r.failure.rfind("stopped:", 0) == 0) {
          std::cout << method << ": over " << max_cpu << " s CPU, tighter tolerances skipped" << std::endl;
          break;
        }
      }
    }
  }

  // CPU time at equal accuracy: the cheapest run of each integrator whose error is at most the target
  std::ostringstream table;
  std::vector<std::string> cols;
  for (const std::string& i : integrators) cols.push_back(i);
  table << "| problem | error <= |";
  for (const std::string& c : cols) table << " " << c << " |";
  table << " codyna best / Simbody best |\n|---|---|";
  for (size_t i = 0; i <= cols.size(); ++i) table << "---|";
  table << "\n";
  for (const Problem& p : problems) {
    for (double target : {1e-3, 1e-6, 1e-9}) {
      std::map<std::string, double> best;
      double best_codyna = 1e300, best_simbody = 1e300;
      for (const Run& r : runs) {
        if (r.problem != p.name || !(r.error <= target)) continue;
        double& b = best.try_emplace(r.integrator, 1e300).first->second;
        b = std::min(b, r.cpu);
        (r.code == "simbody" ? best_simbody : best_codyna) = std::min(r.code == "simbody" ? best_simbody : best_codyna, r.cpu);
      }
      table << "| " << p.name << " | " << std::setprecision(1) << target << " |";
      for (const std::string& c : cols) table << " " << cell_ms(best.count(c) ? best[c] : 1e300) << " |";
      if (best_codyna < 1e300 && best_simbody < 1e300)
        table << " " << std::setprecision(2) << best_codyna / best_simbody << " |\n";
      else
        table << " — |\n";
    }
  }
  std::cout << "\nCPU time [ms] of the cheapest run whose error is at most the target:\n" << table.str();

  std::ostringstream out;
  out << "problem,code,integrator,k,tol,error,cpu_s,steps,evaluations,jacobians,projections,completed\n";
  for (const Run& r : runs)
    out << r.problem << "," << r.code << "," << r.integrator << "," << r.k << "," << std::setprecision(17) << r.tol << ","
        << r.error << "," << r.cpu << "," << r.steps << "," << r.evals << "," << r.jacs << "," << r.projections << ","
        << r.completed << "\n";
  for (const auto& [file, text] : {std::pair{csv, out.str()}, std::pair{table_file, table.str()}}) {
    if (file.empty()) continue;
    try {
      write_file_atomically(file, text);  // the whole file or the old one, never half
    } catch (const std::exception& e) {
      std::cerr << file << ": cannot write: " << e.what() << "\n";
      return 2;
    }
    std::cout << "wrote " << file << "\n";
  }
  return check_failed ? 3 : 0;
}
