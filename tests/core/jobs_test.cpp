// The jobs (study/jobs.hpp), the door every front end goes through: each job's Report against
// the same numbers computed directly from the steps it is made of (the model, the linearization,
// the modal analysis, the LQR design, the run's samples), its classifications against the one
// stability rule, and its refusals naming the option as the front end writes it.
#include "study/jobs.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "analysis/stability.hpp"
#include "control/lqr.hpp"
#include "io/model_file.hpp"
#include "test_util.hpp"

using namespace codyna;

namespace {

ModelSpec jobs_spec(const std::string& example) { return load_model_spec(test::example_path(example)); }

// the same multiset of complex numbers: each of `a` has a partner in `b` within tol
void jobs_expect_same_poles(Eigen::VectorXcd a, Eigen::VectorXcd b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  std::vector<bool> used(static_cast<std::size_t>(b.size()), false);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    Eigen::Index best = -1;
    for (Eigen::Index j = 0; j < b.size(); ++j)
      if (!used[static_cast<std::size_t>(j)] && (best < 0 || std::abs(a[i] - b[j]) < std::abs(a[i] - b[best]))) best = j;
    ASSERT_GE(best, 0);
    used[static_cast<std::size_t>(best)] = true;
    EXPECT_LE(std::abs(a[i] - b[best]), tol * std::max(1.0, std::abs(b[best]))) << a[i] << " vs " << b[best];
  }
}

}  // namespace

// The linearize job's A, B, C, D, modes and controllability are those of study_model,
// study_linearize and modal_analysis called one after the other; each mode's class is the one rule's
TEST(Jobs, LinearizeReportIsItsSteps) {
  const std::string path = test::example_path("cart_pendulum.json");
  const ModelSpec spec = jobs_spec("cart_pendulum.json");
  LinearizeRequest r;
  r.model = path;
  const LinearizeJob job = study_linearize_job(r, spec);
  const Model m = study_model(spec, path);
  const StudyLinearization direct = study_linearize(m);
  const LinearSystem& s = job.linearization.system;
  EXPECT_EQ(s.A, direct.system.A);
  EXPECT_EQ(s.B, direct.system.B);
  EXPECT_EQ(s.C, direct.system.C);
  EXPECT_EQ(s.D, direct.system.D);
  EXPECT_EQ(s.state_names, direct.system.state_names);
  EXPECT_EQ(job.linearization.op.kind, "equilibrium");
  EXPECT_TRUE(job.written.empty());  // no out: computing only
  const ModalAnalysis modes = modal_analysis(direct.system);
  ASSERT_EQ(job.modes.modes.size(), 4u);
  const double tol = stability_tolerance(s.A);
  EXPECT_DOUBLE_EQ(job.modes.stability_tolerance, tol);
  for (std::size_t k = 0; k < modes.modes.size(); ++k) {
    EXPECT_EQ(job.modes.modes[k].eigenvalue, modes.modes[k].eigenvalue);
    // the upright pendulum on its cart: one unstable pole (+sqrt(...)), a double zero (the cart's
    // position and speed: marginal), one stable
    if (k >= static_cast<std::size_t>(job.modes.zero_count))
      EXPECT_EQ(job.modes.modes[k].stability, classify_pole(modes.modes[k].eigenvalue, false, tol));
    else
      EXPECT_EQ(job.modes.modes[k].stability, Stability::Marginal);
  }
  const PoleCount c = count_stability(job.modes);
  EXPECT_EQ(c.unstable, 1);
  EXPECT_EQ(c.marginal, 2);
  EXPECT_EQ(c.stable, 1);
  EXPECT_TRUE(job.uncontrollable.empty());  // the force moves every mode
  EXPECT_EQ(job.uncontrollable.size(), study_uncontrollable(direct.lin.system).size());
  EXPECT_EQ(job.unobservable.size(), study_unobservable(direct.lin.system).size());
}

// The control job: the plant, the closed loop with the file's LQR, its count, and the static gain
// K equal the LQR designed directly from the plant with the file's weights
TEST(Jobs, ControlReportHasTheLqrGainAndItsVerdict) {
  const std::string path = test::example_path("cart_pendulum.json");
  ControlRequest r;
  r.model = path;
  const ControlJob job = study_control_job(r, jobs_spec("cart_pendulum.json"));
  const LinearSystem& p = job.plant.system;
  ASSERT_EQ(p.nx(), 4);
  ASSERT_TRUE(job.closed_loop);
  const Eigen::Vector4d q(10, 100, 1, 1);
  const LqrResult design = lqr(p.A, p.B, Eigen::MatrixXd(q.asDiagonal()), Eigen::MatrixXd::Constant(1, 1, 0.01));
  EXPECT_TRUE(test::MatrixNear(job.gain, design.K, 1e-9));
  EXPECT_EQ(job.gain_inputs, std::vector<std::string>{"force"});
  EXPECT_EQ(job.gain_states, p.state_names);
  // the closed loop's poles are eig(A - B K), every one stable
  const Eigen::MatrixXd Acl = p.A - p.B * design.K;
  Eigen::VectorXcd poles(static_cast<Eigen::Index>(job.closed_loop->poles.modes.size()));
  for (std::size_t k = 0; k < job.closed_loop->poles.modes.size(); ++k)
    poles[static_cast<Eigen::Index>(k)] = job.closed_loop->poles.modes[k].eigenvalue;
  jobs_expect_same_poles(poles, Acl.eigenvalues(), 1e-8);
  EXPECT_EQ(job.closed_loop_count.stable, 4);
  EXPECT_TRUE(job.closed_loop_count.asymptotically_stable());
  // the plant's curves on the grids the core chooses from its poles
  EXPECT_EQ(job.plant_frequency.w.size(), 400u);
  EXPECT_EQ(job.plant_step.t.size(), 500u);
  // the channel force -> h has the zeros +-sqrt(3 g / (2 l)) (l = 2 m)
  const Eigen::VectorXcd z = study_control_zeros(job, false, 0, 0);
  ASSERT_EQ(z.size(), 2);
  const double expected = std::sqrt(3 * 9.81 / (2 * 2.0));
  EXPECT_NEAR(std::max(z[0].real(), z[1].real()), expected, 1e-9);
  EXPECT_EQ(study_control_zeros(job, false, 5, 0).size(), 0);  // no such channel: nothing, no throw
}

// A state feedback with the wrong sign: the control job counts the unstable closed-loop poles
// as classify_poles does on eig(A - B K), and the simulate job lists the same poles as unstable
TEST(Jobs, UnstableLoopIsSaidTheSameByEveryJob) {
  const std::string path = test::example_path("cart_pendulum.json");
  ModelSpec spec = jobs_spec("cart_pendulum.json");
  ControlRequest cr;
  cr.model = path;
  const ControlJob good = study_control_job(cr, spec);
  spec.controller.type = ControllerType::StateFeedback;
  spec.controller.K = -good.gain;
  const ControlJob bad = study_control_job(cr, spec);
  ASSERT_TRUE(bad.closed_loop);
  const LinearSystem& p = bad.plant.system;
  const Eigen::MatrixXd Acl = p.A + p.B * good.gain;
  const Eigen::VectorXcd direct = Acl.eigenvalues();
  const PoleCount expected = classify_poles(direct, false, stability_tolerance(Acl));
  EXPECT_GT(expected.unstable, 0);
  EXPECT_EQ(bad.closed_loop_count.unstable, expected.unstable);
  EXPECT_EQ(bad.closed_loop_count.stable, expected.stable);
  EXPECT_EQ(bad.gain, -good.gain);

  SimulateRequest sr;
  sr.model = path;
  sr.t_end = 0.2;
  const SimulateJob run = study_simulate_job(sr, spec);
  EXPECT_TRUE(run.setup.linear_unstable);
  jobs_expect_same_poles(run.unstable_poles, unstable_poles(direct, false, stability_tolerance(Acl)), 1e-8);
  const bool warned = std::any_of(run.warnings.begin(), run.warnings.end(),
                                  [](const std::string& w) { return w.find("unstable") != std::string::npos; });
  EXPECT_TRUE(warned);
}

// The simulate job's figures: the largest |u| per Plant/In and the energies are the run's samples';
// with the linear comparison, the gap per output is max |y - y_linear|
TEST(Jobs, SimulateReportIsTheRunsSamples) {
  const std::string path = test::example_path("cart_pendulum.json");
  SimulateRequest r;
  r.model = path;
  r.t_end = 1.0;
  r.compare_linear = true;
  const SimulateJob job = study_simulate_job(r, jobs_spec("cart_pendulum.json"));
  const SimulationResult& res = job.result;
  ASSERT_TRUE(res.completed);
  ASSERT_EQ(job.max_abs_input.size(), 1);
  const int force = job.model.plant_inputs[0];
  EXPECT_EQ(job.max_abs_input[0], res.u.col(force).cwiseAbs().maxCoeff());
  EXPECT_EQ(job.energy_start, res.kinetic_energy.front() + res.potential_energy.front());
  EXPECT_EQ(job.energy_end, res.kinetic_energy.back() + res.potential_energy.back());
  ASSERT_EQ(res.y_linear.rows(), res.y.rows());
  ASSERT_EQ(job.linear_gap.size(), res.y.cols());
  for (Eigen::Index k = 0; k < res.y.cols(); ++k) EXPECT_EQ(job.linear_gap[k], (res.y.col(k) - res.y_linear.col(k)).cwiseAbs().maxCoeff());
  EXPECT_EQ(job.unstable_poles.size(), 0);
  EXPECT_FALSE(job.setup.linear_unstable);
  EXPECT_TRUE(job.saturation.empty());
}

// Refusals name the option as the front end writes it
TEST(Jobs, RefusalsNameTheOptionAsWritten) {
  const std::string path = test::example_path("cart_pendulum.json");
  const ModelSpec spec = jobs_spec("cart_pendulum.json");
  LinearizeRequest r;
  r.model = path;
  r.trajectory = -1;
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "--trajectory");
  r.style = OptionStyle::Keyword;
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "trajectory");
  r.trajectory.reset();
  r.point.initial = {"cart_slider=0.1"};
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "initial", "hold");
  // a study value given in the request is said of the option, not of the model file's field
  r = LinearizeRequest{};
  r.model = path;
  r.point.hold = {"cart=1"};
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "--hold cart: unknown coordinate \"cart\"");
  r.point.hold.clear();
  r.closed_loop = r.lqr = true;
  r.q_weights = std::vector<double>{1, 2};
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "--q-weights: expected 4 weights (one per state), got 2");
  r.q_weights.reset();
  r.r_weights = std::vector<double>{-1};
  r.style = OptionStyle::Keyword;
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "r_weights: weight 1 is -1: expected a number > 0");
  r = LinearizeRequest{};
  r.model = path;
  r.discrete = 1e300;
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "--discrete: a sample time of 1e+300 s is too long");
  r.discrete.reset();
  r.point.targets = {"foo=1"};
  EXPECT_INVALID_ARGUMENT_WITH(study_linearize_job(r, spec), "--target foo: output \"foo\" is not in Plant/Out (h, theta)");
  // the same fields written in the model file are still the file's
  ModelSpec bad = spec;
  bad.analysis.set = {{"cart", 1.0}};
  r = LinearizeRequest{};
  r.model = path;
  try {
    (void)study_linearize_job(r, bad);
    ADD_FAILURE() << "no exception";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/set/cart");
  }
  SimulateRequest sr;
  sr.model = path;
  sr.point.initial = {"cart=0.1"};
  EXPECT_INVALID_ARGUMENT_WITH(study_simulate_job(sr, spec), "--initial cart: unknown coordinate");
}

// An export of a linearization already made (the GUI's Export after Linearize) writes the same
// NAME.mat and NAME.m as the job with `out`, and never over a file codyna did not write
TEST(Jobs, ExportOfALinearizationIsTheJobsAndGuarded) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "codyna_jobs_export";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "job");
  LinearizeRequest r;
  r.model = test::example_path("cart_pendulum.json");
  r.out = (dir / "job").string();
  const LinearizeJob job = study_linearize_job(r, jobs_spec("cart_pendulum.json"));
  ASSERT_EQ(job.written.size(), 2u);
  const ExportPaths p = study_export_linearization(job.model, job.linearization.system, (dir / "again").string());
  const auto bytes = [](const std::string& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  EXPECT_EQ(bytes(p.m_file), bytes(job.written[1]));
  EXPECT_EQ(std::filesystem::file_size(p.mat_file), std::filesystem::file_size(job.written[0]));
  std::filesystem::create_directories(dir / "mine");
  const std::string foreign = (dir / "mine" / std::filesystem::path(p.mat_file).filename()).string();
  std::ofstream(foreign) << "my notes";
  EXPECT_THROW(study_export_linearization(job.model, job.linearization.system, (dir / "mine").string()), std::invalid_argument);
  EXPECT_EQ(bytes(foreign), "my notes");
  std::filesystem::remove_all(dir);
}
