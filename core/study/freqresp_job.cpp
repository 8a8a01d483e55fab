#include "study/freqresp_job.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/frequency_estimate.hpp"
#include "analysis/stability.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_quiet.hpp"
#include "io/hdf5_write.hpp"
#include "io/output_guard.hpp"
#include "simulation/simulator.hpp"
#include "study/tire_job.hpp"

namespace codyna {

namespace {

std::string freq_text(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

void check_freqresp_request(const FreqRespRequest& r) {
  const auto opt = [&](const char* dashed) { return option_name(r.run.style, dashed); };
  if (r.frequencies.empty()) throw std::invalid_argument(opt("frequencies") + ": give the frequencies to excite, rad/s");
  for (double w : r.frequencies)
    if (!(w > 0) || !std::isfinite(w))
      throw std::invalid_argument(opt("frequencies") + " " + freq_text(w) + ": expected frequencies > 0 rad/s");
  for (double a : r.amplitudes)
    if (!(std::abs(a) > 0) || !std::isfinite(a))
      throw std::invalid_argument(opt("amplitude") + " " + freq_text(a) + ": expected an amplitude other than 0 (input units)");
  if (r.settle_periods < 0) throw std::invalid_argument(opt("settle-periods") + ": expected 0 or more");
  if (r.periods < 1) throw std::invalid_argument(opt("periods") + ": expected 1 or more");
  if (r.harmonics < 1) throw std::invalid_argument(opt("harmonics") + ": expected 1 or more");
  if (r.samples_per_period < 4 * r.harmonics + 4)
    throw std::invalid_argument(opt("samples-per-period") + " " + std::to_string(r.samples_per_period) + ": expected at least " +
                                std::to_string(4 * r.harmonics + 4) + " (twice the highest harmonic fitted, with room)");
  if (r.run.out.size() || r.run.csv.size() || r.run.t_end || r.run.output_step || r.run.compare_linear)
    throw std::invalid_argument("freqresp: the runs' length, output step and files are the job's own");
}

// the loop's slowest decay rate (1/s) among its stable poles; refuses an unstable loop
double slowest_decay(const Eigen::VectorXcd& poles, double tol, const std::string& what) {
  double decay = std::numeric_limits<double>::infinity();
  for (const auto& p : poles) {
    const Stability s = classify_pole(p, false, tol);
    if (s == Stability::Unstable) {
      std::ostringstream os;
      os.precision(6);
      os << what << " is unstable about the operating point (pole " << p.real() << (p.imag() < 0 ? " - " : " + ")
         << std::abs(p.imag()) << "j): a run cannot settle to a steady sine; close the loop (--lqr, --controller or the "
         << "model file's controller)";
      throw std::invalid_argument(os.str());
    }
    if (s == Stability::Stable) decay = std::min(decay, -p.real());
  }
  return decay;
}

// The plant's poles an excitation of its inputs shows in its outputs: a decaying mode whose share
// of the response, |C v| |w^H B| / (|w^H v| |p|) (v, w its right and left eigenvectors, each the
// null vector of A - p I from its SVD, robust where A has repeated eigenvalues elsewhere), is below
// 1e-9 of the largest is left out (a car's speed, which a steer does not move to first order,
// decays in hours: waiting for it would measure nothing).
Eigen::VectorXcd plant_poles_seen(const LinearSystem& sys) {
  const Eigen::VectorXcd p = Eigen::EigenSolver<Eigen::MatrixXd>(sys.A, false).eigenvalues();
  const double tol = stability_tolerance(sys.A);
  const Eigen::Index n = sys.A.rows();
  const Eigen::MatrixXcd Ac = sys.A.cast<std::complex<double>>(), Bc = sys.B.cast<std::complex<double>>(),
                         Cc = sys.C.cast<std::complex<double>>();
  Eigen::VectorXd share = Eigen::VectorXd::Zero(p.size());
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    if (classify_pole(p[k], false, tol) != Stability::Stable) continue;
    const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(Ac - p[k] * Eigen::MatrixXcd::Identity(n, n), Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXcd v = svd.matrixV().col(n - 1), w = svd.matrixU().col(n - 1);
    const double overlap = std::abs(w.dot(v));  // w^H v
    share[k] = overlap > 0 ? (Cc * v).norm() * (w.adjoint() * Bc).norm() / (overlap * std::abs(p[k]))
                           : std::numeric_limits<double>::infinity();
  }
  double top = 0;  // over the modes with a share (a repeated eigenvalue's has none: it is kept)
  for (double x : share) top = std::isfinite(x) ? std::max(top, x) : top;
  std::vector<std::complex<double>> kept;
  for (Eigen::Index k = 0; k < p.size(); ++k)
    if (classify_pole(p[k], false, tol) != Stability::Stable || share[k] >= 1e-9 * top) kept.push_back(p[k]);
  return Eigen::Map<Eigen::VectorXcd>(kept.data(), static_cast<Eigen::Index>(kept.size()));
}

// One run of a frequency: input j excited by its sine from the point; the fundamentals of the
// plant's inputs (column j of U) and outputs (of Y), the outputs' harmonics' share (of pt.distortion)
struct FreqRespRun {
  const FreqRespRequest& r;
  const Model& m;
  const StudySimulation& setup;
  const OperatingPoint& op;
  const SimulationCallbacks& cb;
  FreqRespJob& job;
  const std::function<void(const std::string&)>& warn;
};

void run_excited(const FreqRespRun& c, int j, double w, int n_settle, FreqRespPoint& pt, Eigen::MatrixXcd& U,
                 Eigen::MatrixXcd& Y) {
  const FreqRespRequest& r = c.r;
  const Model& m = c.m;
  const StudySimulation& setup = c.setup;
  const FreqRespJob& job = c.job;
  const auto& warn = c.warn;
  const OperatingPoint& op = c.op;
  const SimulationCallbacks& cb = c.cb;
  const int nu = static_cast<int>(U.rows()), ny = static_cast<int>(Y.rows());
  const double T = 2 * std::numbers::pi / w;
  SimulationOptions o = setup.options;
  const Model held = held_at(m, op, o);  // the point's state, every actuator at its value there
  o.compare_linear = false;
  o.t0 = 0;
  o.t_end = pt.run_time;
  o.output_step = T / r.samples_per_period;
  const int actuator = m.plant_inputs[static_cast<std::size_t>(j)];
  const double a = job.amplitudes[j];
  const int nact = m.nu();
  o.disturbance = [=](double t) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(nact);
    d[actuator] = a * std::sin(w * t);
    return d;
  };
  o.disturbance_rate = nullptr;
  o.disturbance_acceleration = nullptr;
  const SimulationResult res = simulate(held, setup.controller.get(), setup.plant.get(), o, cb);
  const std::string where = "at " + freq_text(w) + " rad/s, exciting " + job.input_names[static_cast<std::size_t>(j)];
  if (res.cancelled) throw StudyCancelled("the frequency response was cancelled " + where);
  if (!res.completed) throw std::runtime_error(where + ": the run failed: " + res.failure);
  const Eigen::Index i0 = static_cast<Eigen::Index>(n_settle) * r.samples_per_period;
  const Eigen::Index n = static_cast<Eigen::Index>(r.periods) * r.samples_per_period;
  if (res.samples() < i0 + n) throw std::runtime_error(where + ": the run recorded fewer samples than its window");
  Eigen::VectorXd t(n);
  Eigen::MatrixXd X(n, nu + ny);
  for (Eigen::Index i = 0; i < n; ++i) {
    t[i] = res.t[static_cast<std::size_t>(i0 + i)];
    for (int k = 0; k < nu; ++k) X(i, k) = res.u(i0 + i, m.plant_inputs[static_cast<std::size_t>(k)]);
    X.row(i).tail(ny) = res.y.row(i0 + i);
  }
  const std::vector<HarmonicFit> fits = fit_harmonics(t, X, w, r.harmonics);
  for (int k = 0; k < nu; ++k) U(k, j) = fits[static_cast<std::size_t>(k)].harmonics[0];
  for (int k = 0; k < ny; ++k) {
    const HarmonicFit& f = fits[static_cast<std::size_t>(nu + k)];
    Y(k, j) = f.harmonics[0];
    pt.distortion(k, j) = f.distortion();
    const double fundamental = std::abs(f.harmonics[0]);
    if (fundamental > 0 && f.residual_rms > 0.05 * fundamental)
      warn(where + ": " + job.output_names[static_cast<std::size_t>(k)] + " is not periodic at this frequency (what " +
           "the fit leaves is " + freq_text(100 * f.residual_rms / fundamental) + " % of the response): not settled, " +
           "or not a response to the excitation");
  }
}

// the gap, relative to the linear response's size for that pair (at least 1e-3 of its largest
// over the frequencies, so that a notch does not make a small difference look large; a pair
// the linear model does not connect at all: the absolute difference), and the largest
void set_gaps(FreqRespJob& job) {
  const auto ny = static_cast<Eigen::Index>(job.output_names.size()), nu = static_cast<Eigen::Index>(job.input_names.size());
  Eigen::MatrixXd scale = Eigen::MatrixXd::Zero(ny, nu);
  for (const FreqRespPoint& p : job.points) scale = scale.cwiseMax(p.G_linear.cwiseAbs());
  for (std::size_t iw = 0; iw < job.points.size(); ++iw) {
    FreqRespPoint& p = job.points[iw];
    p.gap.resize(ny, nu);
    for (int i = 0; i < ny; ++i)
      for (int j = 0; j < nu; ++j) {
        const double s = scale(i, j) > 0 ? std::max(std::abs(p.G_linear(i, j)), 1e-3 * scale(i, j)) : 1.0;
        p.gap(i, j) = std::abs(p.G(i, j) - p.G_linear(i, j)) / s;
        if (job.gap_point < 0 || p.gap(i, j) > job.largest_gap) {
          job.largest_gap = p.gap(i, j);
          job.gap_point = static_cast<int>(iw);
          job.gap_output = i;
          job.gap_input = j;
        }
      }
  }
}

}  // namespace

FreqRespJob study_freqresp_job(const FreqRespRequest& r, const ModelSpec& spec, const SimulationCallbacks& cb,
                               const StudyMessages& tell) {
  check_freqresp_request(r);
  const auto opt = [&](const char* dashed) { return option_name(r.run.style, dashed); };
  if (!r.csv.empty()) guard_output(r.csv, OutputKind::FrequencyResponseCsv, {r.run.model});
  if (!r.out.empty()) guard_output(r.out, OutputKind::ResultsHdf5, {r.run.model});
  FreqRespJob job;
  const auto note = [&](const std::string& s) {
    job.notes.push_back(s);
    if (tell) tell({StudyMessage::Note, s});
  };
  const auto warn = [&](const std::string& s) {
    job.warnings.push_back(s);
    if (tell) tell({StudyMessage::Warning, s});
  };
  SimulateSetup ss = study_simulate_setup(r.run, spec, true, cb.cancel);
  job.model = std::move(ss.model);
  const Model& m = job.model;
  const StudySimulation& setup = ss.setup;
  for (const std::string& n : setup.notes) note(n);
  const LinearSystem& sys = setup.plant ? setup.plant->lin.system : ss.linearization->lin.system;
  const OperatingPoint& op = setup.plant ? setup.plant->op : ss.linearization->op;
  job.operating_point = op.kind;
  job.controller = setup.controller ? setup.controller_source : "none (open loop)";
  const int nu = static_cast<int>(m.plant_inputs.size()), ny = static_cast<int>(sys.ny());
  if (nu == 0) throw std::invalid_argument(opt("inputs") + ": the plant has no Plant/In input to excite");
  if (ny == 0) throw std::invalid_argument(opt("outputs") + ": the plant has no Plant/Out output to measure");
  job.input_names = sys.input_names;
  job.output_names = sys.output_names;
  job.input_units = sys.input_units;
  job.output_units = sys.output_units;
  if (r.amplitudes.size() > 1 && static_cast<int>(r.amplitudes.size()) != nu)
    throw std::invalid_argument(opt("amplitude") + ": expected one amplitude, or one per Plant/In input (" +
                                std::to_string(nu) + "), got " + std::to_string(r.amplitudes.size()));
  job.amplitudes = Eigen::VectorXd::Constant(nu, r.amplitudes.empty() ? 0.01 : r.amplitudes[0]);
  if (r.amplitudes.size() > 1) job.amplitudes = Eigen::Map<const Eigen::VectorXd>(r.amplitudes.data(), nu);
  if (setup.options.disturbance) note("the study's disturbances are left out: the runs excite the Plant/In inputs only");

  // how long the loop takes to settle: its linear poles (the closed loop's with a linear controller)
  const bool closed = setup.controller != nullptr;
  double decay = std::numeric_limits<double>::infinity();
  if (closed && setup.linear_poles.size()) {
    decay = slowest_decay(setup.linear_poles, stability_tolerance(sys.A), "the closed loop");
  } else if (!closed) {
    decay = slowest_decay(plant_poles_seen(sys), stability_tolerance(sys.A), "the plant");
  } else {
    note("the controller has no linear closed loop to read a settling time from: the runs settle for " +
         std::to_string(r.settle_periods) + " periods (" + opt("settle-periods") + ")");
  }

  job.decay_rate = std::isfinite(decay) ? decay : 0.0;
  const std::vector<double> ws = r.frequencies;
  const FrequencyResponse linear = frequency_response(sys, ws);
  const std::function<void(const std::string&)> warn_fn = warn;
  const FreqRespRun run{r, m, setup, op, cb, job, warn_fn};
  for (std::size_t iw = 0; iw < ws.size(); ++iw) {
    const double w = ws[iw], T = 2 * std::numbers::pi / w;
    FreqRespPoint pt;
    pt.w = w;
    const int n_settle = std::max(r.settle_periods, std::isfinite(decay) ? static_cast<int>(std::ceil(8.0 / decay / T)) : 0);
    pt.settle_time = n_settle * T;
    pt.run_time = (n_settle + r.periods) * T;
    Eigen::MatrixXcd U(nu, nu), Y(ny, nu);
    pt.distortion.resize(ny, nu);
    for (int j = 0; j < nu; ++j) run_excited(run, j, w, n_settle, pt, U, Y);
    const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(U);
    if (!(std::abs(lu.determinant()) > 0))
      throw std::runtime_error("at " + freq_text(w) + " rad/s the inputs did not move independently (a saturated input?)");
    pt.G = Y * lu.inverse();
    pt.G_linear = linear.H[iw];
    job.points.push_back(std::move(pt));
  }

  set_gaps(job);
  if (!r.out.empty()) {
    study_write_freqresp_hdf5(job, r.out);
    job.written.push_back(r.out);
  }
  if (!r.csv.empty()) {
    study_write_freqresp_csv(job, r.csv);
    job.written.push_back(r.csv);
  }
  return job;
}

void study_write_freqresp_csv(const FreqRespJob& job, const std::string& path) {
  guard_output(path, OutputKind::FrequencyResponseCsv, {job.model.source_file});
  std::ostringstream os;
  os.precision(17);
  os << "w_rad_s,f_Hz";
  for (const std::string& y : job.output_names)
    for (const std::string& u : job.input_names)
      for (const char* c : {"magnitude", "phase_deg", "magnitude_linear", "phase_deg_linear", "gap", "distortion"})
        os << "," << y << "/" << u << "_" << c;
  os << "\n";
  for (const FreqRespPoint& p : job.points) {
    os << p.w << "," << p.w / (2 * std::numbers::pi);
    for (Eigen::Index i = 0; i < p.G.rows(); ++i)
      for (Eigen::Index j = 0; j < p.G.cols(); ++j)
        os << "," << std::abs(p.G(i, j)) << "," << std::arg(p.G(i, j)) * 180 / std::numbers::pi << ","
           << std::abs(p.G_linear(i, j)) << "," << std::arg(p.G_linear(i, j)) * 180 / std::numbers::pi << "," << p.gap(i, j)
           << "," << p.distortion(i, j);
    os << "\n";
  }
  write_file_atomically(path, os.str());
}

void study_write_freqresp_hdf5(const FreqRespJob& job, const std::string& path) {
  guard_output(path, OutputKind::ResultsHdf5, {job.model.source_file});
  const std::size_t nw = job.points.size(), ny = job.output_names.size(), nu = job.input_names.size();
  // nw x ny x nu in C order
  const auto cube = [&](const auto& value) {
    std::vector<double> v;
    v.reserve(nw * ny * nu);
    for (const FreqRespPoint& p : job.points)
      for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(ny); ++i)
        for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(nu); ++j) v.push_back(value(p, i, j));
    return v;
  };
  std::vector<double> w, settle, run;
  for (const FreqRespPoint& p : job.points) {
    w.push_back(p.w);
    settle.push_back(p.settle_time);
    run.push_back(p.run_time);
  }
  AtomicFile out(path);
  try {
    const QuietHdf5 quiet;
    Hdf5Handle file(H5Fcreate(out.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                    "cannot create " + out.temp_path());
    h5::write_attribute(file, "/", "codyna_version", std::string(CODYNA_VERSION));
    h5::write_attribute(file, "/", "kind", std::string("frequency_response"));
    h5::write_attribute(file, "/", "model", job.model.name);
    h5::write_attribute(file, "/", "operating_point", job.operating_point);
    h5::write_attribute(file, "/", "controller", job.controller);
    h5::write_doubles(file, "w", {nw}, w);
    h5::write_strings(file, "input_names", job.input_names);
    h5::write_strings(file, "output_names", job.output_names);
    h5::write_doubles(file, "amplitudes", {nu}, std::vector<double>(job.amplitudes.data(), job.amplitudes.data() + nu));
    const std::vector<hsize_t> dims{nw, ny, nu};
    h5::write_doubles(file, "G_real", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.G(i, j).real(); }));
    h5::write_doubles(file, "G_imag", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.G(i, j).imag(); }));
    h5::write_doubles(file, "G_linear_real", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.G_linear(i, j).real(); }));
    h5::write_doubles(file, "G_linear_imag", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.G_linear(i, j).imag(); }));
    h5::write_doubles(file, "gap", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.gap(i, j); }));
    h5::write_doubles(file, "distortion", dims, cube([](const FreqRespPoint& p, auto i, auto j) { return p.distortion(i, j); }));
    h5::write_doubles(file, "settle_time", {nw}, settle);
    h5::write_doubles(file, "run_time", {nw}, run);
    file.close("cannot finish " + out.temp_path());
  } catch (const Hdf5Error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  out.commit();
}

std::vector<double> study_frequency_grid(const std::string& text, const std::string& option) {
  const std::vector<double> v = study_tire_grid(text, option);
  for (double w : v)
    if (!(w > 0) || !std::isfinite(w)) throw std::invalid_argument(option + " " + text + ": expected frequencies > 0 rad/s");
  if (text.find(':') == std::string::npos || v.size() < 2) return v;
  return log_grid(v.front(), v.back(), static_cast<int>(v.size()));
}

namespace {
// a phase in degrees in (-180, 180], a half turn shown as 180 whatever the sign of a zero
// imaginary part
double shown_phase(std::complex<double> g) {
  const double p = std::arg(g) * 180 / std::numbers::pi;
  return p < -179.9995 ? p + 360 : p;
}
}  // namespace

std::string study_freqresp_text(const FreqRespJob& job) {
  std::ostringstream os;
  os.precision(6);
  os << "operating point  " << job.operating_point << "\n"
     << "controller       " << job.controller << "\n"
     << "amplitudes       ";
  for (std::size_t j = 0; j < job.input_names.size(); ++j)
    os << (j ? ", " : "") << job.input_names[j] << " " << job.amplitudes[static_cast<Eigen::Index>(j)]
       << (job.input_units[j].empty() ? "" : " " + job.input_units[j]);
  os << "\n";
  if (job.decay_rate > 0) os << "settling        " << 8 / job.decay_rate << " s (8 / the slowest decay rate the outputs see, " << job.decay_rate << " 1/s)\n";
  os << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-12s %-28s %12s %10s %12s %10s %9s %9s\n", "w (rad/s)", "output/input", "gain",
                "phase", "gain linear", "phase lin", "gap", "harmonics");
  os << line;
  for (const FreqRespPoint& p : job.points)
    for (Eigen::Index i = 0; i < p.G.rows(); ++i)
      for (Eigen::Index j = 0; j < p.G.cols(); ++j) {
        const std::string pair = job.output_names[static_cast<std::size_t>(i)] + "/" + job.input_names[static_cast<std::size_t>(j)];
        std::snprintf(line, sizeof line, "%-12.6g %-28s %12.6g %10.4g %12.6g %10.4g %8.3g%% %8.3g%%\n", p.w, pair.c_str(),
                      std::abs(p.G(i, j)), shown_phase(p.G(i, j)), std::abs(p.G_linear(i, j)), shown_phase(p.G_linear(i, j)),
                      100 * p.gap(i, j), 100 * p.distortion(i, j));
        os << line;
      }
  if (job.gap_point >= 0) {
    const FreqRespPoint& p = job.points[static_cast<std::size_t>(job.gap_point)];
    os << "\nlargest gap      " << 100 * job.largest_gap << " % of the linear response, "
       << job.output_names[static_cast<std::size_t>(job.gap_output)] << "/"
       << job.input_names[static_cast<std::size_t>(job.gap_input)] << " at " << p.w << " rad/s\n";
  }
  return os.str();
}

}  // namespace codyna
