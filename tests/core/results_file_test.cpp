// io/results_file: HDF5 results read back exactly (full, without controller,
// partial), writes are atomic and failures leave nothing behind, peers (h5py,
// GNU Octave's load) see the documented layout, and CSV has the documented
// header and values that parse back to the same doubles.
#include "io/results_file.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "peer_util.hpp"

namespace codyna {
namespace {

namespace fs = std::filesystem;
using ResultStrings = std::vector<std::string>;
using nlohmann::json;
using test::bounded;
using test::CommandResult;
using test::on_path;
using test::peer_script;
using test::peers_dir;
using test::python_with;
using test::run_command;
using test::shell_quoted;

// ------------------------------------------------------------------ fixtures

class ResultsTempDir {
 public:
  ResultsTempDir() {
    std::string pattern = (fs::temp_directory_path() / "codyna_results_XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~ResultsTempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ResultsTempDir(const ResultsTempDir&) = delete;
  ResultsTempDir& operator=(const ResultsTempDir&) = delete;

  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

  // the names in the directory, sorted (temporary files included)
  ResultStrings entries() const {
    ResultStrings names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

// Two uncoupled damped oscillators (mass 1.5) in closed form,
// x_k(t) = exp(-zeta_k w_k t) cos(wd_k t), sampled every 0.02 s: q = x, v = x',
// the input is the damping force on the first, the outputs are x_0 and x_1',
// the controller state is the integral of x_0, and the "linear" outputs differ
// from the outputs by 1e-6 t^2.
SimulationResult oscillator_result(int samples = 50) {
  const double mass = 1.5, w[] = {2.0, 3.5}, zeta[] = {0.1, 0.05};
  SimulationResult r;
  r.q.resize(samples, 2);
  r.v.resize(samples, 2);
  r.u.resize(samples, 1);
  r.y.resize(samples, 2);
  r.xc.resize(samples, 1);
  r.y_linear.resize(samples, 2);
  r.y_reference.resize(samples, 2);
  r.u_disturbance.resize(samples, 1);
  for (int i = 0; i < samples; ++i) {
    const double t = 0.02 * i;
    double kinetic = 0, potential = 0;
    for (int k = 0; k < 2; ++k) {
      const double a = zeta[k] * w[k], wd = w[k] * std::sqrt(1 - zeta[k] * zeta[k]), decay = std::exp(-a * t);
      r.q(i, k) = decay * std::cos(wd * t);
      r.v(i, k) = -decay * (a * std::cos(wd * t) + wd * std::sin(wd * t));
      kinetic += 0.5 * mass * r.v(i, k) * r.v(i, k);
      potential += 0.5 * mass * w[k] * w[k] * r.q(i, k) * r.q(i, k);
      if (k == 0) r.xc(i, 0) = (decay * (wd * std::sin(wd * t) - a * std::cos(wd * t)) + a) / (a * a + wd * wd);
    }
    r.t.push_back(t);
    r.u(i, 0) = -2 * zeta[0] * w[0] * mass * r.v(i, 0);
    r.y(i, 0) = r.q(i, 0);
    r.y(i, 1) = r.v(i, 1);
    r.y_linear.row(i) = r.y.row(i).array() + 1e-6 * t * t;
    r.y_reference.row(i) << (t < 0.5 ? 0.0 : 0.25), std::sin(t);
    r.u_disturbance(i, 0) = t < 0.3 ? 0.0 : -1.0 / 3.0;
    r.kinetic_energy.push_back(kinetic);
    r.potential_energy.push_back(potential);
    r.constraint_violation.push_back(1e-13 * std::abs(std::sin(7 * t)));
    r.velocity_violation.push_back(1e-12 * t);
  }
  r.q_names = {"slider.x", "rocker.angle"};
  r.v_names = {"slider.x_dot", "rocker.angle_dot"};
  r.input_names = {"damper_force"};
  r.output_names = {"x, measured", "omega"};  // a comma: quoted in CSV
  r.controller_state_names = {"integral_x"};
  r.input_units = {"N"};
  r.output_units = {"m", "rad/s²"};  // UTF-8
  r.stats = {"ida", 1e-8, 1e-10, 0.01, 1234, 2345, 56, 7, 3456, 2, 11, 3, 0.125, ""};
  r.completed = true;
  r.model_name = "two oscillators";
  r.model_file = "/models/two oscillators.json";
  r.controller = "pd";
  r.codyna_version = "0.1.0";
  r.settings_json = R"({"t_end": 0.98, "integrator": "ida", "note": "two\nlines, \"quoted\""})";
  return r;
}

SimulationResult without_controller(SimulationResult r) {
  r.xc.resize(r.samples(), 0);
  r.controller_state_names.clear();
  r.y_linear.resize(0, 0);
  r.y_reference.resize(0, 0);
  r.u_disturbance.resize(0, 0);
  r.input_units.clear();
  r.controller.clear();
  return r;
}

SimulationResult partial(SimulationResult r) {
  r.completed = false;
  r.failure = "IDA failed at t = 0.38: the corrector convergence test failed repeatedly";
  return r;
}

// ------------------------------------------------------------------ comparison

::testing::AssertionResult SameMatrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    return ::testing::AssertionFailure() << a.rows() << " x " << a.cols() << " vs " << b.rows() << " x " << b.cols();
  if ((a.array() != b.array()).any()) return ::testing::AssertionFailure() << "a =\n" << a << "\nb =\n" << b;
  return ::testing::AssertionSuccess();
}

void expect_same_results(const SimulationResult& a, const SimulationResult& b) {
  EXPECT_EQ(a.t, b.t);
  EXPECT_TRUE(SameMatrix(a.q, b.q)) << "q";
  EXPECT_TRUE(SameMatrix(a.v, b.v)) << "v";
  EXPECT_TRUE(SameMatrix(a.u, b.u)) << "u";
  EXPECT_TRUE(SameMatrix(a.y, b.y)) << "y";
  EXPECT_TRUE(SameMatrix(a.xc, b.xc)) << "xc";
  EXPECT_TRUE(SameMatrix(a.y_linear, b.y_linear)) << "y_linear";
  EXPECT_TRUE(SameMatrix(a.y_reference, b.y_reference)) << "y_reference";
  EXPECT_TRUE(SameMatrix(a.u_disturbance, b.u_disturbance)) << "u_disturbance";
  EXPECT_EQ(a.kinetic_energy, b.kinetic_energy);
  EXPECT_EQ(a.potential_energy, b.potential_energy);
  EXPECT_EQ(a.constraint_violation, b.constraint_violation);
  EXPECT_EQ(a.velocity_violation, b.velocity_violation);
  EXPECT_EQ(a.q_names, b.q_names);
  EXPECT_EQ(a.v_names, b.v_names);
  EXPECT_EQ(a.input_names, b.input_names);
  EXPECT_EQ(a.output_names, b.output_names);
  EXPECT_EQ(a.controller_state_names, b.controller_state_names);
  EXPECT_EQ(a.input_units, b.input_units);
  EXPECT_EQ(a.output_units, b.output_units);
  EXPECT_EQ(a.stats.integrator, b.stats.integrator);
  EXPECT_EQ(a.stats.rtol, b.stats.rtol);
  EXPECT_EQ(a.stats.atol, b.stats.atol);
  EXPECT_EQ(a.stats.max_step, b.stats.max_step);
  EXPECT_EQ(a.stats.steps, b.stats.steps);
  EXPECT_EQ(a.stats.rhs_evals, b.stats.rhs_evals);
  EXPECT_EQ(a.stats.jac_evals, b.stats.jac_evals);
  EXPECT_EQ(a.stats.error_test_failures, b.stats.error_test_failures);
  EXPECT_EQ(a.stats.nonlinear_iterations, b.stats.nonlinear_iterations);
  EXPECT_EQ(a.stats.nonlinear_failures, b.stats.nonlinear_failures);
  EXPECT_EQ(a.stats.projections, b.stats.projections);
  EXPECT_EQ(a.stats.restarts, b.stats.restarts);
  EXPECT_EQ(a.stats.wall_time, b.stats.wall_time);
  EXPECT_EQ(a.completed, b.completed);
  EXPECT_EQ(a.cancelled, b.cancelled);
  EXPECT_EQ(a.failure, b.failure);
  EXPECT_EQ(a.model_name, b.model_name);
  EXPECT_EQ(a.model_file, b.model_file);
  EXPECT_EQ(a.controller, b.controller);
  EXPECT_EQ(a.codyna_version, b.codyna_version);
  EXPECT_EQ(a.settings_json, b.settings_json);
}

// `f` throws std::runtime_error whose message holds every one of `parts`
::testing::AssertionResult ThrowsWith(const std::function<void()>& f, const ResultStrings& parts) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    for (const std::string& p : parts)
      if (what.find(p) == std::string::npos)
        return ::testing::AssertionFailure() << "\"" << what << "\" lacks \"" << p << "\"";
    return ::testing::AssertionSuccess() << what;
  }
  return ::testing::AssertionFailure() << "nothing thrown";
}

void expect_round_trip(const SimulationResult& r) {
  ResultsTempDir dir;
  write_results_hdf5(r, dir / "run.h5");
  expect_same_results(read_results_hdf5(dir / "run.h5"), r);
  EXPECT_EQ(dir.entries(), ResultStrings{"run.h5"});  // no temporary file left
}

// ------------------------------------------------------------------ HDF5

TEST(ResultsHdf5, FullResultReadsBackExactly) { expect_round_trip(oscillator_result()); }

TEST(ResultsHdf5, ResultWithoutControllerKeepsItsEmptyColumns) {
  const SimulationResult r = without_controller(oscillator_result());
  ASSERT_EQ(r.xc.rows(), 50);
  ASSERT_EQ(r.xc.cols(), 0);
  expect_round_trip(r);
}

TEST(ResultsHdf5, PartialResultKeepsItsFailureText) {
  expect_round_trip(partial(oscillator_result(20)));
  // failed before the first output: no samples at all
  SimulationResult none = partial(oscillator_result(0));
  none.cancelled = true;
  expect_round_trip(none);
}

TEST(ResultsHdf5, ZeroColumnMatrixOfAnyRowCountIsStoredAsSamplesByZero) {
  SimulationResult r = without_controller(oscillator_result());
  r.xc.resize(0, 0);
  ResultsTempDir dir;
  write_results_hdf5(r, dir / "run.h5");
  const SimulationResult back = read_results_hdf5(dir / "run.h5");
  EXPECT_EQ(back.xc.rows(), 50);
  EXPECT_EQ(back.xc.cols(), 0);
}

TEST(ResultsHdf5, MissingDirectoryLeavesNothingAndNamesThePath) {
  ResultsTempDir dir;
  const std::string path = dir / "missing/run.h5";
  EXPECT_TRUE(ThrowsWith([&] { write_results_hdf5(oscillator_result(), path); }, {path, "No such file or directory"}));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(ResultsHdf5, InconsistentResultIsRejectedAndTheOldFileKept) {
  ResultsTempDir dir;
  const std::string path = dir / "run.h5";
  const SimulationResult good = oscillator_result();
  write_results_hdf5(good, path);
  const auto rejected = [&](const std::function<void(SimulationResult&)>& spoil, const std::string& reason) {
    SimulationResult r = good;
    spoil(r);
    return ThrowsWith([&] { write_results_hdf5(r, path); }, {path, reason});
  };
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.q.conservativeResize(49, 2); }, "/q has 49 rows for 50 samples"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.kinetic_energy.pop_back(); }, "/energy/kinetic has 49 entries"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.v_names.pop_back(); }, "/names/v has 1 entries for the 2 columns"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.output_units.pop_back(); }, "/units/outputs has 1 entries for 2"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.y_linear.conservativeResize(50, 1); }, "/y_linear is 50 x 1"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.y_reference.conservativeResize(49, 2); }, "/y_reference is 49 x 2"));
  EXPECT_TRUE(rejected([](SimulationResult& r) { r.u_disturbance.conservativeResize(50, 2); },
                       "/u_disturbance is 50 x 2, expected 50 x 1 like /u"));
  EXPECT_EQ(dir.entries(), ResultStrings{"run.h5"});
  expect_same_results(read_results_hdf5(path), good);
  // and a good write replaces it
  const SimulationResult other = partial(oscillator_result(10));
  write_results_hdf5(other, path);
  expect_same_results(read_results_hdf5(path), other);
}

TEST(ResultsHdf5, ReadFailuresNameThePathAndTheReason) {
  ResultsTempDir dir;
  EXPECT_TRUE(ThrowsWith([&] { read_results_hdf5(dir / "absent.h5"); }, {dir / "absent.h5", "no such file"}));
  std::ofstream(dir / "notes.h5") << "not HDF5\n";
  EXPECT_TRUE(ThrowsWith([&] { read_results_hdf5(dir / "notes.h5"); }, {dir / "notes.h5", "not an HDF5 file"}));
  // a results file cut short
  write_results_hdf5(oscillator_result(), dir / "cut.h5");
  fs::resize_file(dir / "cut.h5", fs::file_size(dir / "cut.h5") / 2);
  EXPECT_TRUE(ThrowsWith([&] { read_results_hdf5(dir / "cut.h5"); }, {dir / "cut.h5"}));
}

// ------------------------------------------------------------------ peers

// `s` as an Octave string literal
std::string octave_string(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// What a reader of the file written from `r` must find (the format of
// tests/peers/read_results.py): the layout of io/results_file.hpp, stated again here.
json expectations(const SimulationResult& r) {
  const std::size_t n = r.t.size();
  json datasets = json::array();
  const auto series = [&](const char* path, const std::vector<double>& values) {
    datasets.push_back({{"path", path}, {"shape", {n}}, {"data", values}});
  };
  const auto matrix = [&](const char* path, const Eigen::MatrixXd& m) {
    std::vector<double> row_major;
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index j = 0; j < m.cols(); ++j) row_major.push_back(m(i, j));
    datasets.push_back({{"path", path}, {"shape", {n, m.cols()}}, {"data", row_major}});
  };
  series("time", r.t);
  matrix("q", r.q);
  matrix("v", r.v);
  matrix("u", r.u);
  matrix("y", r.y);
  matrix("xc", r.xc);
  if (r.y_linear.cols() > 0) matrix("y_linear", r.y_linear);
  if (r.y_reference.cols() > 0) matrix("y_reference", r.y_reference);
  if (r.u_disturbance.cols() > 0) matrix("u_disturbance", r.u_disturbance);
  series("energy/kinetic", r.kinetic_energy);
  series("energy/potential", r.potential_energy);
  series("constraints/position_violation", r.constraint_violation);
  series("constraints/velocity_violation", r.velocity_violation);
  json strings = json::array();
  for (const auto& [path, list] : {std::pair{"names/q", r.q_names},
                                   {"names/v", r.v_names},
                                   {"names/inputs", r.input_names},
                                   {"names/outputs", r.output_names},
                                   {"names/controller_states", r.controller_state_names},
                                   {"units/inputs", r.input_units},
                                   {"units/outputs", r.output_units}})
    strings.push_back({{"path", path}, {"values", list}});
  const SolverStats& s = r.stats;
  json attributes = {
      {"solver",
       {{"integrator", s.integrator},
        {"rtol", s.rtol},
        {"atol", s.atol},
        {"max_step", s.max_step},
        {"steps", s.steps},
        {"rhs_evals", s.rhs_evals},
        {"jac_evals", s.jac_evals},
        {"error_test_failures", s.error_test_failures},
        {"nonlinear_iterations", s.nonlinear_iterations},
        {"nonlinear_failures", s.nonlinear_failures},
        {"projections", s.projections},
        {"restarts", s.restarts},
        {"wall_time", s.wall_time}}},
      {"status", {{"completed", r.completed ? 1 : 0}, {"cancelled", r.cancelled ? 1 : 0}, {"failure", r.failure}}},
      {"provenance",
       {{"model_name", r.model_name},
        {"model_file", r.model_file},
        {"controller", r.controller},
        {"codyna_version", r.codyna_version},
        {"settings_json", r.settings_json}}},
      {"/", {{"format_version", 1}}}};
  return {{"datasets", datasets}, {"strings", strings}, {"attributes", attributes}};
}

// The peer cases: a results file and its expectations file, for each kind of result.
struct PeerCase {
  std::string name, h5, expected;
  std::size_t datasets, lists;
};

std::vector<PeerCase> write_peer_cases(const ResultsTempDir& dir) {
  const std::pair<std::string, SimulationResult> results[] = {
      {"full", oscillator_result()},
      {"no_controller", without_controller(oscillator_result())},
      {"partial", partial(oscillator_result(20))},
      {"no_samples", partial(oscillator_result(0))}};
  std::vector<PeerCase> cases;
  for (const auto& [name, r] : results) {
    PeerCase c{name, dir / (name + ".h5"), dir / (name + ".json"), 0, 0};
    write_results_hdf5(r, c.h5);
    const json e = expectations(r);
    std::ofstream(c.expected) << e.dump(1);
    c.datasets = e["datasets"].size();
    c.lists = e["strings"].size();
    cases.push_back(c);
  }
  return cases;
}

TEST(ResultsFilePeer, H5pyReadsTheDocumentedLayout) {
  static const std::optional<std::string> python = python_with("numpy, h5py");
  if (!python) GTEST_SKIP() << "no python3 with numpy and h5py (set CODYNA_PYTHON; CI installs them)";
  ResultsTempDir dir;
  for (const PeerCase& c : write_peer_cases(dir)) {
    const CommandResult r =
        run_command(bounded(shell_quoted(*python) + " " + shell_quoted(peer_script("read_results.py")) + " " +
                            shell_quoted(c.h5) + " " + shell_quoted(c.expected)));
    EXPECT_EQ(r.exit_code, 0) << c.name << ":\n" << r.output;
    // the script counts the numeric datasets and string lists it found
    const std::string marker =
        "CODYNA_RESULTS_H5PY_OK " + std::to_string(c.datasets) + " " + std::to_string(c.lists) + "\n";
    EXPECT_NE(r.output.find(marker), std::string::npos) << c.name << ":\n" << r.output;
  }
}

TEST(ResultsFilePeer, OctaveLoadReadsDatasetsAndNameLists) {
  if (!on_path("octave-cli")) GTEST_SKIP() << "octave-cli is not on PATH (CI installs it)";
  ResultsTempDir dir;
  const std::vector<PeerCase> cases = write_peer_cases(dir);
  std::string eval = "addpath(" + octave_string(peers_dir()) + "); ";
  for (const PeerCase& c : cases)
    eval += "read_results(" + octave_string(c.h5) + ", " + octave_string(c.expected) + "); ";
  const CommandResult r = run_command(bounded("octave-cli --no-gui --quiet --eval " + shell_quoted(eval)));
  // Octave may print "error: ignoring const execution_exception& while preparing to exit"
  // at exit; that is harmless, so judge by the exit code and the script's own lines.
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const PeerCase& c : cases) {
    const std::string marker =
        "CODYNA_RESULTS_OCTAVE_OK " + std::to_string(c.datasets) + " " + std::to_string(c.lists) + "\n";
    EXPECT_NE(r.output.find(marker), std::string::npos) << c.name << ":\n" << r.output;
  }
}

// ------------------------------------------------------------------ CSV

ResultStrings read_lines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  EXPECT_TRUE(!s.empty() && s.back() == '\n') << "the file does not end with a line break";
  ResultStrings lines;
  std::istringstream stream(s);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

ResultStrings split(const std::string& line) {
  ResultStrings fields;
  std::istringstream stream(line);
  for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
  return fields;
}

// The values of row i in the documented column order.
std::vector<double> csv_row(const SimulationResult& r, int i) {
  std::vector<double> row{r.t[i]};
  for (const Eigen::MatrixXd* m : {&r.q, &r.v, &r.u, &r.y, &r.xc})
    for (Eigen::Index j = 0; j < m->cols(); ++j) row.push_back((*m)(i, j));
  row.insert(row.end(), {r.kinetic_energy[i], r.potential_energy[i], r.constraint_violation[i]});
  for (Eigen::Index j = 0; j < r.y_linear.cols(); ++j) row.push_back(r.y_linear(i, j));
  for (Eigen::Index j = 0; j < r.y_reference.cols(); ++j) row.push_back(r.y_reference(i, j));
  for (Eigen::Index j = 0; j < r.u_disturbance.cols(); ++j) row.push_back(r.u_disturbance(i, j));
  return row;
}

// Every field is "%.17g" of the expected double and parses back to it exactly.
void expect_csv_rows(const ResultStrings& lines, const SimulationResult& r) {
  ASSERT_EQ(lines.size(), r.t.size() + 1);
  for (int i = 0; i < r.samples(); ++i) {
    const ResultStrings fields = split(lines[i + 1]);
    const std::vector<double> want = csv_row(r, i);
    ASSERT_EQ(fields.size(), want.size()) << "row " << i;
    for (std::size_t c = 0; c < want.size(); ++c) {
      std::array<char, 40> printed;
      std::snprintf(printed.data(), printed.size(), "%.17g", want[c]);
      EXPECT_EQ(fields[c], printed.data()) << "row " << i << " column " << c;
      double parsed = 0;
      const auto [end, ec] = std::from_chars(fields[c].data(), fields[c].data() + fields[c].size(), parsed);
      EXPECT_TRUE(ec == std::errc() && end == fields[c].data() + fields[c].size()) << fields[c];
      EXPECT_EQ(parsed, want[c]) << "row " << i << " column " << c;
    }
  }
}

TEST(ResultsCsv, HeaderAndRowsOfAFullResult) {
  ResultsTempDir dir;
  const SimulationResult r = oscillator_result();
  write_results_csv(r, dir / "run.csv");
  const ResultStrings lines = read_lines(dir / "run.csv");
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0],
            "t,slider.x,rocker.angle,slider.x_dot,rocker.angle_dot,damper_force,\"x, measured\",omega,integral_x,"
            "kinetic_energy,potential_energy,constraint_violation,\"x, measured_linear\",omega_linear,"
            "\"x, measured_reference\",omega_reference,damper_force_disturbance");
  expect_csv_rows(lines, r);
  EXPECT_EQ(dir.entries(), ResultStrings{"run.csv"});
}

TEST(ResultsCsv, ResultWithoutControllerOrLinearRun) {
  ResultsTempDir dir;
  SimulationResult r = without_controller(oscillator_result(5));
  r.output_names = {"x", "omega"};
  write_results_csv(r, dir / "run.csv");
  const ResultStrings lines = read_lines(dir / "run.csv");
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0],
            "t,slider.x,rocker.angle,slider.x_dot,rocker.angle_dot,damper_force,x,omega,"
            "kinetic_energy,potential_energy,constraint_violation");
  expect_csv_rows(lines, r);
}

TEST(ResultsCsv, FailuresLeaveNothingAndNameThePath) {
  ResultsTempDir dir;
  const std::string missing = dir / "missing/run.csv";
  EXPECT_TRUE(
      ThrowsWith([&] { write_results_csv(oscillator_result(), missing); }, {missing, "No such file or directory"}));
  SimulationResult bad = oscillator_result();
  bad.q_names.pop_back();
  EXPECT_TRUE(
      ThrowsWith([&] { write_results_csv(bad, dir / "run.csv"); }, {dir / "run.csv", "/names/q has 1 entries"}));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(ResultsCsv, NumbersIgnoreACommaDecimalLocale) {
  const std::string old = std::setlocale(LC_ALL, nullptr);
  const char* comma = nullptr;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8", "de_DE", "fr_FR"})
    if (std::setlocale(LC_ALL, name)) {
      comma = name;
      break;
    }
  if (!comma) GTEST_SKIP() << "no comma-decimal locale installed";
  ResultsTempDir dir;
  const SimulationResult r = oscillator_result(3);
  write_results_csv(r, dir / "run.csv");
  std::setlocale(LC_ALL, old.c_str());
  expect_csv_rows(read_lines(dir / "run.csv"), r);  // compared in the C locale
}

}  // namespace
}  // namespace codyna
