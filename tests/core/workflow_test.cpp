// The study workflow (study/workflow.hpp): the choices of the "analysis" section
// run through the same functions the CLI and the GUI call.
#include "study/workflow.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <atomic>
#include <filesystem>
#include <tuple>

#include <nlohmann/json.hpp>

#include "analysis/plant_function.hpp"
#include "control/lqr.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/joint.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

ModelSpec example_spec(const std::string& name) { return load_model_spec(example_path(name)); }

// expects a ModelError whose field path is `path`
template <class F>
void expect_model_error_at(F&& f, const std::string& path, const std::string& phrase) {
  try {
    f();
    FAIL() << "no error, expected one at " << path;
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), path) << e.what();
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

// a steady-state search that does not converge is a ConvergenceError (exit code 2 at the command
// line), not bad input; its message names the field, the residual and the unknowns
template <class F>
void expect_not_converged(F&& f, const std::vector<std::string>& phrases) {
  try {
    f();
    FAIL() << "no error, expected a ConvergenceError";
  } catch (const ConvergenceError& e) {
    for (const std::string& p : phrases) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << p << " in " << e.what();
  }
}

}  // namespace

TEST(Workflow, StudyRoundTripsThroughTheModelFile) {
  ModelSpec spec = example_spec("cart_pendulum.json");
  StudySpec& s = spec.analysis;
  s.disabled_effects = {"gravity"};
  s.operating_point = "time=0.25";
  s.set = {{"cart_slider", -0.5}, {"rod_pivot", 0.125}};  // the reader gives them in name order
  s.independent = {"rod_pivot"};
  s.method = "fd-central";
  s.discrete = 0.01;
  s.mat_version = "7.3";
  s.export_name = "cart";
  s.export_dir = "out/plant";
  s.controller = "file";
  s.controller_file = "K.mat";
  s.q_weights = {1, 2, 3, 4};
  s.r_weights = {0.5};
  s.compare_linear = true;
  SignalSpec ramp, table;
  ramp.output = "h";
  ramp.type = "ramp";
  ramp.time = 1.5;
  ramp.slope = 0.25;
  table.output = "theta";
  table.type = "table";
  table.points = {{0, 0}, {1, 0.1}, {2.5, -0.05}};
  SignalSpec from_file;
  from_file.output = "theta";
  from_file.type = "file";
  from_file.file = "theta_ref.csv";
  s.references = {ramp, table};
  s.references.push_back(from_file);
  DisturbanceSpec push;
  push.actuator = "push";
  push.type = "sine";
  push.time = 2;
  push.amplitude = 3;
  push.frequency = 0.5;
  push.phase = 0.25;
  s.disturbances = {push};
  s.anti_windup = "back_calculation";
  s.tracking_time = 0.3;
  s.lqr_controllable_part = true;
  s.closed_loop.enabled = true;
  s.closed_loop.step_time = 7;
  s.closed_loop.step_points = 71;
  s.closed_loop.frequency_min = 0.1;
  s.closed_loop.frequency_max = 50;
  s.closed_loop.frequency_points = 33;
  const auto dir = std::filesystem::temp_directory_path() / "codyna_workflow_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "study.json").string();
  save_model_spec(spec, path);
  const ModelSpec back = load_model_spec(path);
  EXPECT_EQ(back.analysis, s);
  // a default study is not written at all
  save_model_spec(example_spec("pendulum.json"), path);
  EXPECT_EQ(load_model_spec(path).analysis, StudySpec{});
  std::filesystem::remove_all(dir);
}

TEST(Workflow, BadStudyFieldsNameTheirPath) {
  const std::string text = R"({"name": "p", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1, 0, 0, 0]}],
    "joints": [{"name": "j", "type": "revolute", "parent": "ground", "child": "b"}], "analysis": {"method": "spline"}})";
  expect_model_error_at([&] { parse_model_spec_text(text, "m.json"); }, "/analysis/method", "unknown method \"spline\"");
  std::string t2 = text;
  t2.replace(t2.find("\"method\": \"spline\""), 18, "\"operating_point\": \"time=-1\"");
  expect_model_error_at([&] { parse_model_spec_text(t2, "m.json"); }, "/analysis/operating_point", "time=T");
  // the control workflow's fields
  const auto with = [&](const std::string& analysis) {
    std::string t = text;
    t.replace(t.find("{\"method\": \"spline\"}"), 20, analysis);
    return t;
  };
  const std::vector<std::tuple<std::string, std::string, std::string>> bad{
      {R"({"anti_windup": "clamp"})", "/analysis/anti_windup", "unknown anti-windup method \"clamp\""},
      {R"({"tracking_time": -1})", "/analysis/tracking_time", "a time constant > 0 (s)"},
      {R"({"lqr_controllable_part": 1})", "/analysis/lqr_controllable_part", "true or false"},
      {R"({"closed_loop": {"step_points": 1}})", "/analysis/closed_loop/step_points", "an integer from 2 to 1000000"},
      {R"({"closed_loop": {"frequency_min": 10, "frequency_max": 1}})", "/analysis/closed_loop/frequency_max",
       "a frequency above frequency_min 10"},
      {R"({"closed_loop": {"enabled": "yes"}})", "/analysis/closed_loop/enabled", "true or false"},
      {R"({"disturbances": [{"type": "step", "time": 0, "value": 1}]})", "/analysis/disturbances/0", "actuator"},
      {R"({"references": [{"output": "y", "type": "file"}]})", "/analysis/references/0", "file"},
      {R"({"references": [{"output": "y", "type": "file", "file": ""}]})", "/analysis/references/0/file",
       "a file name (CSV or .mat)"},
  };
  for (const auto& [analysis, path, phrase] : bad) {
    const std::string text = with(analysis);  // a structured binding cannot be captured before C++20
    expect_model_error_at([&text] { parse_model_spec_text(text, "m.json"); }, path, phrase);
  }
}

TEST(Workflow, DisabledEffectsAreLeftOutOfTheModel) {
  ModelSpec spec = example_spec("pendulum.json");
  spec.analysis.operating_point = "initial";
  const Model with = study_model(spec);
  EXPECT_TRUE(with.has_gravity);
  spec.analysis.disabled_effects = {"gravity"};
  const Model without = study_model(spec);
  EXPECT_FALSE(without.has_gravity);
  // the paper's pendulum: A(2,1) = (3g/(2l)) sin(theta0) with gravity, 0 without; B unchanged
  const StudyLinearization a = study_linearize(with), b = study_linearize(without);
  const double theta0 = with.q0[0];
  EXPECT_NEAR(a.system.A(1, 0), 3 * 9.81 / (2 * 2.0) * std::sin(theta0), 1e-10);
  EXPECT_EQ(b.system.A(1, 0), 0.0);
  EXPECT_NEAR(b.system.B(1, 0), a.system.B(1, 0), 1e-15);
  spec.analysis.disabled_effects = {"wind"};
  expect_model_error_at([&] { study_model(spec, "p.json"); }, "/analysis/disabled_effects/0", "no effect named \"wind\"");
}

TEST(Workflow, SetCoordinatesAndOperatingPoints) {
  ModelSpec spec = example_spec("pendulum.json");
  spec.analysis.set = {{"pivot", 1.0}};
  spec.analysis.operating_point = "initial";
  const Model m = study_model(spec);
  EXPECT_EQ(m.q0[0], 1.0);
  EXPECT_EQ(study_operating_point(m).q[0], 1.0);
  // a set coordinate is held by the equilibrium search: at 1 rad gravity turns the rod, so there
  // is no equilibrium with pivot held (nothing is free to hold it), and the error says so
  expect_not_converged([&] { study_operating_point(m, "equilibrium"); },
                       {"/analysis/operating_point", "held: pivot", "residual accelerations are 3.97527 (tolerance 1e-08; largest on pivot)",
                        "free inputs (none), free coordinates (none)", "free an input: free_inputs / --free-input torque"});
  // held upright (the com straight above the pivot) it is one, to the bit
  spec.analysis.set = {{"pivot", M_PI / 2}};
  const OperatingPoint eq = study_operating_point(study_model(spec), "equilibrium");
  EXPECT_EQ(eq.q[0], M_PI / 2);
  EXPECT_LT(eq.residual, 1e-12);
  spec.analysis.set = {{"no_such_joint", 1.0}};
  expect_model_error_at([&] { study_model(spec); }, "/analysis/set/no_such_joint", "coordinates: pivot; rates: pivot_dot");
  spec.analysis.set.clear();
  spec.analysis.operating_point = "sideways";
  expect_model_error_at([&] { study_operating_point(study_model(spec)); }, "/analysis/operating_point", "unknown operating point");
}

TEST(Workflow, LinearizeAndExportFollowTheStudy) {
  ModelSpec spec = example_spec("cart_pendulum.json");
  spec.analysis.operating_point = "equilibrium";
  spec.analysis.discrete = 0.05;
  spec.analysis.export_name = "cart_plant";
  const Model m = study_model(spec, example_path("cart_pendulum.json"));
  const StudyLinearization l = study_linearize(m);
  EXPECT_EQ(l.system.Ts, 0.05);
  EXPECT_EQ(l.lin.system.Ts, 0.0);
  // the paper's cart-pendulum about the upright position
  const double m2 = 20, m3 = 10, l3 = 2, g = 9.81;
  const auto& names = l.lin.system.state_names;
  const auto at = [&](const std::string& n) { return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin()); };
  ASSERT_LT(at("rod_pivot_dot"), 4);
  EXPECT_NEAR(l.lin.system.A(at("rod_pivot_dot"), at("rod_pivot")), 6 * (m2 + m3) * g / ((4 * m2 + m3) * l3), 1e-9);
  const auto dir = std::filesystem::temp_directory_path() / "codyna_workflow_export";
  std::filesystem::remove_all(dir);
  const ExportPaths p = study_export(m, l.system, dir.string());
  EXPECT_EQ(p.mat_file, (dir / "cart_plant.mat").string());
  const MatVariables v = read_mat_file(p.mat_file);
  EXPECT_EQ(v.matrices.at("Ts")(0, 0), 0.05);
  EXPECT_TRUE(MatrixNear(v.matrices.at("A"), l.system.A, 0.0));
  std::filesystem::remove_all(dir);
  spec.analysis.export_name = "2bad";
  expect_model_error_at([&] { study_export_name(study_model(spec)); }, "/analysis/export_name", "m_2bad");
}

// A mode drawn in 3-D: the operating point moved along the mode on the manifold. The pose
// differs from the operating point by exactly the scaled mode (difference() is integrate()'s
// inverse), quaternions stay unit, plain coordinates add, closed loops stay closed.
TEST(Workflow, ModePoseMovesAlongTheModeOnTheManifold) {
  {
    ModelSpec spec = example_spec("heavy_top.json");
    spec.analysis.operating_point = "initial";  // the spinning top has no equilibrium
    const Model m = study_model(spec);
    const StudyLinearization l = study_linearize(m);
    const auto& names = l.lin.system.state_names;
    ASSERT_EQ(names.size(), 6u);
    EXPECT_EQ(names[0], "support.rx");
    EXPECT_EQ(names[2], "support.rz");
    const Eigen::VectorXd q_op = integrate<double>(m, m.q0, Eigen::Vector3d(0.2, -0.1, 0.4));
    Eigen::VectorXcd shape(6);
    shape << 1.0, std::complex<double>(0, 2.0), 0.5, 7.0, 7.0, 7.0;  // the rates (last 3) play no part
    for (double phase : {0.0, 0.7, 2.0}) {
      const Eigen::VectorXd q = study_mode_pose(m, q_op, names, shape, phase, 0.3);
      Eigen::Vector3d expected;
      for (int k = 0; k < 3; ++k) expected[k] = (0.3 / 2.0 * shape[k] * std::polar(1.0, phase)).real();
      EXPECT_TRUE(MatrixNear(difference(m, q_op, q), expected, 1e-12)) << phase;
      EXPECT_NEAR(q.norm(), 1.0, 1e-14);
    }
  }
  {
    const Model m = study_model(example_spec("cart_pendulum.json"));
    const auto names = study_linearize(m).lin.system.state_names;
    Eigen::VectorXcd shape = Eigen::VectorXcd::Zero(static_cast<int>(names.size()));
    shape[0] = 0.5, shape[1] = -1.0;
    const Eigen::VectorXd q = study_mode_pose(m, m.q0, names, shape, 0.0, 0.3);
    for (int k = 0; k < 2; ++k) {
      const int i = static_cast<int>(std::find(m.v_names.begin(), m.v_names.end(), names[k]) - m.v_names.begin());
      EXPECT_NEAR(q[i] - m.q0[i], 0.3 * shape[k].real(), 1e-15) << names[k];
    }
  }
  {
    const Model m = study_model(example_spec("four_bar.json"));
    const auto names = study_linearize(m).lin.system.state_names;
    Eigen::VectorXcd shape = Eigen::VectorXcd::Zero(static_cast<int>(names.size()));
    shape[0] = 1.0;
    const Eigen::VectorXd q = study_mode_pose(m, m.q0, names, shape, 0.0, 0.2);
    Data d(m);
    EXPECT_GT((q - m.q0).norm(), 0.1);
    EXPECT_LT(constraint_residual<double>(m, d, q).lpNorm<Eigen::Infinity>(), 1e-10);
  }
}

// A front end's Cancel reaches a time=T pre-run (the operating point of a run's plant):
// StudyCancelled, not an error of the model, and nothing half made; without it the same
// study runs to its point.
TEST(Workflow, CancelStopsATimeOperatingPointRun) {
  ModelSpec spec = example_spec("cart_pendulum.json");
  spec.analysis.operating_point = "time=2";
  spec.analysis.controller = "lqr";
  const Model m = study_model(spec);
  std::atomic<bool> cancel{true};
  EXPECT_THROW(study_operating_point(m, "", &cancel), StudyCancelled);
  try {
    (void)study_simulation(m, &cancel);
    FAIL() << "not cancelled";
  } catch (const StudyCancelled& e) {
    EXPECT_NE(std::string(e.what()).find("time=2: cancelled at t = 0"), std::string::npos) << e.what();
  }
  cancel = false;
  const StudySimulation s = study_simulation(m, &cancel);
  ASSERT_TRUE(s.plant);
  EXPECT_EQ(s.plant->op.t, 2.0);
  EXPECT_EQ(s.plant->op.kind, "time=2");
}

TEST(Workflow, SimulationControllerSources) {
  ModelSpec spec = example_spec("cart_pendulum.json");
  spec.solver.t_end = 0.2;
  spec.analysis.controller = "lqr";
  spec.analysis.q_weights = {10, 100, 1, 1};
  spec.analysis.r_weights = {0.01};
  const Model m = study_model(spec);
  const StudySimulation s = study_simulation(m);
  ASSERT_TRUE(s.plant && s.controller);
  const LinearSystem& sys = s.plant->lin.system;
  Eigen::MatrixXd Q = Eigen::Vector4d(10, 100, 1, 1).asDiagonal(), R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  EXPECT_TRUE(MatrixNear(s.lqr_gain, lqr(sys.A, sys.B, Q, R).K, 1e-12));
  const SimulationResult r = study_simulate(m, s);
  EXPECT_TRUE(r.completed);
  EXPECT_NE(r.settings_json.find("\"controller\": \"lqr\""), std::string::npos);
  // "none": open loop even though the model declares a controller
  spec.analysis.controller = "none";
  const StudySimulation open = study_simulation(study_model(spec));
  EXPECT_FALSE(open.controller);
  EXPECT_FALSE(open.plant);
  // "model": the file's LQR, designed about its equilibrium
  spec.analysis.controller = "model";
  const StudySimulation own = study_simulation(study_model(spec));
  ASSERT_TRUE(own.controller);
  EXPECT_EQ(own.plant->op.kind, "equilibrium");
  spec.analysis.controller = "file";
  expect_model_error_at([&] { study_simulation(study_model(spec)); }, "/analysis/controller_file", "none is named");
  spec.analysis.controller = "lqr";
  spec.analysis.q_weights = {1, 2};
  expect_model_error_at([&] { study_simulation(study_model(spec)); }, "/analysis/q_weights", "expected 4 weights");
}

// Uncontrollable parts are named, not discovered later: a second pendulum that no input
// drives makes an LQR impossible, and the message names its states.
TEST(Workflow, LqrOnAnUnstabilizablePlantNamesTheModes) {
  ModelSpec spec = example_spec("pendulum.json");
  BodySpec rod2 = spec.bodies[0];
  rod2.name = "rod2";
  spec.bodies.push_back(rod2);
  JointSpec pivot2 = spec.joints[0];
  pivot2.name = "pivot2";
  pivot2.child = "rod2";
  pivot2.parent_frame.position += Eigen::Vector3d(0, 0, 1);
  spec.joints.push_back(pivot2);
  spec.analysis.controller = "lqr";
  spec.analysis.operating_point = "initial";
  spec.controller = ControllerSpec{};
  const Model m = study_model(spec);
  try {
    study_simulation(m);
    FAIL() << "an LQR was designed for an unstabilizable plant";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not stabilizable"), std::string::npos) << what;
    EXPECT_NE(what.find("pivot2"), std::string::npos) << what;
    EXPECT_EQ(what.find("(pivot,"), std::string::npos) << what;  // the driven pendulum is not blamed
  }
  // designed on the controllable part anyway: the note says that what is left is unstable
  spec.analysis.lqr_controllable_part = true;
  const StudySimulation s = study_simulation(study_model(spec));
  ASSERT_EQ(s.notes.size(), 1u);
  std::printf("%s\n", s.notes[0].c_str());
  EXPECT_NE(s.notes[0].find("lqr on the controllable part (2 of 4 states)"), std::string::npos) << s.notes[0];
  EXPECT_NE(s.notes[0].find("(pivot2"), std::string::npos) << s.notes[0];
  EXPECT_NE(s.notes[0].find("(one of them is unstable: the loop is not stable)"), std::string::npos) << s.notes[0];
  bool unstable = false;
  for (const HiddenMode& h : s.uncontrollable) unstable = unstable || h.eigenvalue.real() > 0;
  EXPECT_TRUE(unstable);
}

// Coordinates the user sets are held exactly while the loops close (the four-bar's crank,
// coupler or rocker angle, and a rate); values that cannot all be held are refused with
// where the loops would put them.
TEST(Workflow, SetCoordinatesAreHeldExactlyOnClosedLoops) {
  for (const std::string name : {"pivot_A", "pivot_B", "pivot_D"}) {
    ModelSpec spec = example_spec("four_bar.json");
    spec.analysis.set = {{name, 1.3}};
    const Model m = study_model(spec);
    const int iq = static_cast<int>(std::find(m.q_names.begin(), m.q_names.end(), name) - m.q_names.begin());
    EXPECT_EQ(m.q0[iq], 1.3) << name;
    Data d(m);
    EXPECT_LT(constraint_residual<double>(m, d, m.q0).lpNorm<Eigen::Infinity>(), 1e-10) << name;
  }
  ModelSpec spec = example_spec("four_bar.json");
  spec.analysis.set = {{"pivot_A_dot", 0.5}};
  const Model m = study_model(spec);
  const int iv = static_cast<int>(std::find(m.v_names.begin(), m.v_names.end(), "pivot_A") - m.v_names.begin());
  EXPECT_EQ(m.v0[iv], 0.5);
  Data d(m);
  constraint_terms<double>(m, d, m.q0, m.v0);
  EXPECT_LT((d.Jc * m.v0).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_GT(m.v0.cwiseAbs().maxCoeff(), 0.5 - 1e-12);  // the others follow
  spec.analysis.set = {{"pivot_A", 1.3}, {"pivot_D", 0.2}};
  expect_model_error_at([&] { study_model(spec); }, "/analysis/set", "closing them freely puts pivot_A at");
  spec.analysis.set = {{"pivot_Q_dot", 1.0}};
  expect_model_error_at([&] { study_model(spec); }, "/analysis/set/pivot_Q_dot", "rates: pivot_A");
}

// A trim against a binding actuator limit fails naming the limit, instead of reporting an
// input the actuator cannot give.
TEST(Workflow, TrimAgainstABindingLimitNamesIt) {
  ModelSpec spec = example_spec("pendulum.json");
  spec.analysis.operating_point = "trim";
  spec.analysis.set = {{"pivot", 0.3}};  // held near horizontal: needs about m g l/2 cos(0.3) = 93.7 N m
  const Model free = study_model(spec);
  const OperatingPoint op = study_operating_point(free);
  const double needed = op.u[free.find_actuator("torque")];
  EXPECT_NEAR(needed, 10 * 9.81 * 1.0 * std::cos(0.3), 1e-9);
  spec.actuators[0].max = 50;
  spec.actuators[0].min = -50;
  const Model limited = study_model(spec);
  try {
    study_operating_point(limited);
    FAIL() << "a trim beyond the limit was accepted";
  } catch (const ConvergenceError& e) {
    EXPECT_NE(std::string(e.what()).find("torque = 93.7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("above its max 50"), std::string::npos) << e.what();
  }
}

// A step reference on the cart position is followed by the nonlinear cart-pendulum, with no
// steady-state error, under LQR with the Nbar feed-forward and under PID (the same gains as
// PD on the outputs); the rod ends upright.
TEST(Workflow, StepReferenceOnTheCartIsFollowedByLqrAndPid) {
  ModelSpec spec = example_spec("cart_pendulum.json");
  spec.solver.t_end = 25;
  spec.analysis.set = {{"rod_pivot", 0.0}};  // start upright at rest: only the step moves it
  spec.solver.rtol = 1e-10;
  spec.solver.atol = 1e-12;
  SignalSpec step;
  step.output = "h";
  step.type = "step";
  step.time = 0.5;
  step.value = 0.5;
  spec.analysis.references = {step};
  spec.analysis.controller = "lqr";
  spec.analysis.q_weights = {10, 100, 1, 1};
  spec.analysis.r_weights = {0.01};
  const Model m = study_model(spec);
  const StudySimulation lqr_setup = study_simulation(m);
  EXPECT_NE(lqr_setup.controller->describe().find("Nbar"), std::string::npos);
  const SimulationResult a = study_simulate(m, lqr_setup);
  ASSERT_TRUE(a.completed) << a.failure;
  const int N = a.samples();
  EXPECT_NEAR(a.y(N - 1, 0), 0.5, 1e-6);  // h
  EXPECT_NEAR(a.y(N - 1, 1), 0.0, 1e-6);  // theta
  EXPECT_NEAR(a.y(40, 0), 0.0, 1e-9);     // nothing moves before the step (t = 0.4 s)
  EXPECT_LT(a.y(100, 0), 0.0);            // the cart first backs off to tip the rod (non-minimum phase)
  EXPECT_GT(a.y(500, 0), 0.25);           // then goes to the reference
  // the result records r(t): the operating point's y0 before the step, the step's value after,
  // y0 for the output without a reference; no disturbance column
  ASSERT_EQ(a.y_reference.rows(), N);
  ASSERT_EQ(a.y_reference.cols(), 2);
  EXPECT_EQ(a.y_reference(40, 0), 0.0);
  EXPECT_EQ(a.y_reference(60, 0), 0.5);
  EXPECT_EQ(a.y_reference(N - 1, 0), 0.5);
  EXPECT_EQ(a.y_reference.col(1).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(a.u_disturbance.size(), 0);
  // PID with the LQR's gains split over the outputs (h, theta) and their rates
  const Eigen::MatrixXd K = lqr_setup.lqr_gain;
  ControllerSpec pid;
  pid.type = ControllerType::Pid;
  pid.kp = Eigen::MatrixXd(1, 2);
  pid.kd = Eigen::MatrixXd(1, 2);
  pid.kp << K(0, 0), K(0, 1);
  pid.kd << K(0, 2), K(0, 3);
  spec.controller = pid;
  spec.analysis.controller = "model";
  const Model mp = study_model(spec);
  const SimulationResult b = study_simulate(mp, study_simulation(mp));
  ASSERT_TRUE(b.completed) << b.failure;
  EXPECT_NEAR(b.y(b.samples() - 1, 0), 0.5, 1e-6);
  EXPECT_NEAR(b.y(b.samples() - 1, 1), 0.0, 1e-6);
  // a reference on an output the plant does not have is named
  spec.analysis.references[0].output = "x";
  expect_model_error_at([&] { study_simulation(study_model(spec)); }, "/analysis/references/0/output", "not a Plant/Out output");
}

TEST(Workflow, SignalShapes) {
  SignalSpec s;
  s.time = 1;
  s.type = "step";
  s.value = 2;
  EXPECT_EQ(signal_value(s, 0.5, 0.3), 0.3);
  EXPECT_EQ(signal_value(s, 1.0, 0.3), 2.0);
  s.type = "ramp";
  s.slope = 0.5;
  EXPECT_DOUBLE_EQ(signal_value(s, 3.0, 0.3), 1.3);
  s.type = "sine";
  s.amplitude = 2;
  s.frequency = 0.25;
  EXPECT_NEAR(signal_value(s, 2.0, 0.3), 2.3, 1e-15);
  s.type = "table";
  s.points = {{0, 0}, {2, 4}, {3, 4}};
  EXPECT_EQ(signal_value(s, 1.0, 9), 2.0);
  EXPECT_EQ(signal_value(s, 5.0, 9), 4.0);
  EXPECT_EQ(signal_value(s, -1.0, 9), 0.0);
}

// An inverted spherical pendulum (tests/data/spherical_pendulum.json) with two horizontal forces at
// its tip: upright, no input turns the rod about the vertical, so the yaw is uncontrollable (a
// double pole at 0). An LQR alone is refused, naming the yaw; with lqr_controllable_part the design
// covers the four tilt states, the yaw's poles stay at 0, and the nonlinear run from a tilt of
// 0.1 rad about x and 0.05 rad about y comes upright.
TEST(Workflow, LqrOnTheControllablePartOfASphericalPendulum) {
  const std::string path = std::string(CODYNA_TEST_DATA_DIR) + "/spherical_pendulum.json";
  ModelSpec spec = load_model_spec(path);
  spec.analysis.controller = "lqr";
  try {
    study_simulation(study_model(spec, path));
    FAIL() << "an LQR was designed for a plant that is not stabilizable";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not stabilizable: the Plant/In inputs cannot move lambda = 0 (ball.wz) ("),
              std::string::npos) << what;
    EXPECT_NE(what.find("(ball.wz)"), std::string::npos) << what;  // the yaw rate, by name
    for (const char* tilt : {"ball.rx", "ball.ry", "ball.wx", "ball.wy"}) EXPECT_EQ(what.find(tilt), std::string::npos) << what;
    EXPECT_NE(what.find("\"lqr_controllable_part\": true"), std::string::npos) << what;
  }
  spec.analysis.lqr_controllable_part = true;
  const Model m = study_model(spec, path);
  const StudySimulation setup = study_simulation(m);
  const LinearSystem& sys = setup.plant->lin.system;
  ASSERT_EQ(sys.nx(), 6);
  ASSERT_FALSE(setup.uncontrollable.empty());
  for (const HiddenMode& h : setup.uncontrollable) {
    // a double eigenvalue at 0 (yaw angle and rate), split to +-1.5e-9 by round-off: said as 0
    EXPECT_EQ(h.eigenvalue, 0.0);
    EXPECT_EQ(h.states, std::vector<std::string>{"ball.wz"});
  }
  ASSERT_EQ(setup.notes.size(), 1u);
  EXPECT_EQ(setup.notes[0], "lqr on the controllable part (4 of 6 states): the Plant/In inputs cannot move lambda = 0 "
                            "(ball.wz); these poles stay where they are");
  std::printf("%s\n", setup.notes[0].c_str());
  // the closed loop: four stable tilt poles, the yaw's two at 0; the design's poles are eig(A - B K)
  const Eigen::VectorXcd p = Eigen::MatrixXd(sys.A - sys.B * setup.lqr_gain).eigenvalues();
  int at_zero = 0;
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    if (std::abs(p[k]) < 1e-7) {
      ++at_zero;
    } else {
      EXPECT_LT(p[k].real(), -0.5) << p[k];
    }
  }
  EXPECT_EQ(at_zero, 2);
  ASSERT_EQ(setup.lqr_poles.size(), 6);
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    double nearest = 1e300;
    for (Eigen::Index j = 0; j < 6; ++j) nearest = std::min(nearest, std::abs(p[k] - setup.lqr_poles[j]));
    EXPECT_LT(nearest, 1e-7);
  }
  // the gain does not act on the yaw states (K Tu = 0 up to round-off)
  for (Eigen::Index j = 0; j < 6; ++j)
    if (sys.state_names[j].find("z") != std::string::npos) {
      EXPECT_LT(setup.lqr_gain.col(j).cwiseAbs().maxCoeff(), 1e-9 * setup.lqr_gain.cwiseAbs().maxCoeff()) << sys.state_names[j];
    }
  const SimulationResult r = study_simulate(m, setup);
  ASSERT_TRUE(r.completed) << r.failure;
  const int N = r.samples();
  std::printf("spherical pendulum: tip (%.3g, %.3g) m at 0 s, (%.3g, %.3g) m at %.1f s, max |u| %.3g N\n", r.y(0, 0), r.y(0, 1),
              r.y(N - 1, 0), r.y(N - 1, 1), r.t.back(), r.u.cwiseAbs().maxCoeff());
  EXPECT_GT(std::hypot(r.y(0, 0), r.y(0, 1)), 0.1);
  for (int k = N - 100; k < N; ++k) EXPECT_LT(std::hypot(r.y(k, 0), r.y(k, 1)), 1e-4) << r.t[k];
}

// The simulation's initial state is kept apart from the operating point (issue 21): the run
// starts where `initial` says, the operating point is searched from the model's own state.
TEST(Workflow, InitialStateApartFromTheOperatingPoint) {
  ModelSpec spec = example_spec("pendulum.json");
  const double q_model = spec.joints[0].q0[0];
  spec.analysis.initial = {{"pivot", 0.6}, {"pivot_dot", -0.25}};
  const Model m = study_model(spec);
  EXPECT_EQ(m.q0[0], q_model);  // the model's state (and so the search's start) is untouched
  const StudyInitialState start = study_initial_state(m);
  EXPECT_TRUE(start.given);
  EXPECT_EQ(start.q[0], 0.6);
  EXPECT_EQ(start.v[0], -0.25);
  const OperatingPoint eq = study_operating_point(m, "equilibrium");
  EXPECT_NEAR(eq.q[0], M_PI / 2, 1e-12);
  EXPECT_EQ(study_operating_point(m, "initial").q[0], q_model);
  const StudySimulation setup = study_simulation(m);
  ASSERT_TRUE(setup.plant);
  EXPECT_NEAR(setup.plant->op.q[0], M_PI / 2, 1e-12);
  ASSERT_EQ(setup.options.q0.size(), 1);
  EXPECT_EQ(setup.options.q0[0], 0.6);
  EXPECT_EQ(setup.options.v0[0], -0.25);
  // without it a run starts at the model's state (the options leave the start to the model)
  spec.analysis.initial.clear();
  EXPECT_EQ(study_simulation(study_model(spec)).options.q0.size(), 0);
  // unknown names are refused at their field, with the names there are
  spec.analysis.initial = {{"pivto", 0.6}};
  expect_model_error_at([&] { study_model(spec); }, "/analysis/initial/pivto", "coordinates: pivot; rates: pivot_dot");
  // the model file carries it and reads it back
  spec.analysis.initial = {{"pivot", 0.6}};
  const ModelSpec back = parse_model_spec(to_json(spec), "p.json");
  EXPECT_EQ(back.analysis.initial, spec.analysis.initial);
}

// On a closed loop the initial coordinates are held while the loops close, exactly as held
// coordinates are; the operating point does not move with them.
TEST(Workflow, InitialStateOnALoopIsAssembledAroundTheNamedCoordinate) {
  ModelSpec spec = example_spec("four_bar.json");
  spec.analysis.set = {{"pivot_A", 1.3}};
  const Model held = study_model(spec);
  spec.analysis.set.clear();
  spec.analysis.initial = {{"pivot_A", 1.3}};
  const Model m = study_model(spec);
  const StudyInitialState start = study_initial_state(m);
  EXPECT_EQ(start.q, held.q0);  // the same assembly, to the bit
  EXPECT_EQ(start.q[m.joints[m.find_joint("pivot_A")].idx_q], 1.3);
  spec.analysis.initial.clear();
  const Model plain = study_model(spec);
  EXPECT_EQ(study_operating_point(m, "equilibrium").q, study_operating_point(plain, "equilibrium").q);
}

// A trim the inputs cannot make (a rod tilted on a cart, only the cart's force) is not a best
// effort any more: a ConvergenceError naming the residual, the unknowns and what to free.
TEST(Workflow, TrimThatDoesNotConvergeIsAnError) {
  ModelSpec spec = load_model_spec(std::string(CODYNA_TEST_DATA_DIR) + "/trim_underactuated.json");
  spec.analysis.operating_point = "trim";
  const Model m = study_model(spec);
  expect_not_converged([&] { study_operating_point(m); },
                       {"/analysis/operating_point: trim: not converged", "largest on slider",
                        "free inputs push, free coordinates (none); held: slider, tilt", "trim_free / --trim-free"});
  expect_not_converged([&] { study_linearize(m); }, {"trim: not converged"});
  // a run with nothing linear needs no operating point; one that compares with the linear loop does
  EXPECT_FALSE(study_simulation(m).plant);
  ModelSpec compared = spec;
  compared.analysis.compare_linear = true;
  const Model mc = study_model(compared);
  expect_not_converged([&] { study_simulation(mc); }, {"trim: not converged"});
  // the tilt freed: the upright trim
  spec.analysis.trim_free = {"tilt"};
  const OperatingPoint op = study_operating_point(study_model(spec));
  EXPECT_LT(op.residual, 1e-10);
  EXPECT_NEAR(op.q[1], 0.0, 1e-10);
}

// One naming scheme (Model::v_names, docs/model-format.md "Coordinate and rate names"): every
// coordinate and rate `info` lists is accepted by --hold (set), --initial and --trim-free, sets
// exactly that value, and the linear model's state names are the same names.
TEST(Workflow, OneNameForEveryCoordinateAndRate) {
  const std::string data = CODYNA_TEST_DATA_DIR;
  for (const std::string& path : {data + "/quadrotor.json", data + "/spherical_pendulum.json", example_path("cart_pendulum.json")}) {
    SCOPED_TRACE(path);
    ModelSpec spec = load_model_spec(path);
    spec.analysis.operating_point = "initial";
    const Model m = study_model(spec, path);
    ASSERT_EQ(m.v_names.size(), static_cast<std::size_t>(m.nv));
    ASSERT_EQ(m.rate_names.size(), static_cast<std::size_t>(m.nv));
    // the linear model (no loops: every coordinate is a state) names its states alike
    std::vector<std::string> names = m.v_names;
    names.insert(names.end(), m.rate_names.begin(), m.rate_names.end());
    EXPECT_EQ(study_linearize(m).lin.system.state_names, names);
    for (int i = 0; i < m.nv; ++i) {
      const std::string& c = m.v_names[static_cast<std::size_t>(i)];
      const std::string& r = m.rate_names[static_cast<std::size_t>(i)];
      for (const bool as_initial : {false, true}) {
        ModelSpec s = spec;
        (as_initial ? s.analysis.initial : s.analysis.set) = {{c, 0.125}, {r, -0.25}};
        const Model held = study_model(s, path);
        const StudyInitialState st = study_initial_state(held);
        const Eigen::VectorXd coords = study_coordinates(held, st.q);
        EXPECT_NEAR(coords[i], 0.125, 1e-14) << c;
        EXPECT_EQ(st.v[i], -0.25) << r;
        // the other coordinates keep their values
        const Eigen::VectorXd before = study_coordinates(m, m.q0);
        for (int k = 0; k < m.nv; ++k)
          if (k != i) EXPECT_NEAR(coords[k], before[k], 1e-14) << c << " moved " << m.v_names[static_cast<std::size_t>(k)];
      }
      // --trim-free knows it (the search itself may or may not converge with it freed)
      ModelSpec s = spec;
      s.analysis.operating_point = "trim";
      s.analysis.trim_free = {c};
      try {
        study_operating_point(study_model(s, path));
      } catch (const ConvergenceError&) {
      } catch (const ModelError& e) {
        EXPECT_EQ(std::string(e.what()).find("unknown coordinate"), std::string::npos) << e.what();
      } catch (const std::invalid_argument&) {
      }
    }
  }
  // a name that is none of them is refused with the lists
  ModelSpec spec = load_model_spec(data + "/quadrotor.json");
  spec.analysis.initial = {{"fly.dx", 1.0}};
  expect_model_error_at([&] { study_model(spec); }, "/analysis/initial/fly.dx",
                        "(coordinates: fly.rx, fly.ry, fly.rz, fly.x, fly.y, fly.z; rates: fly.wx");
}

// Assembly says what it moved, and the automatic independent coordinates of a loop are the ones
// the motors drive (issue 21): the five-bar's couplers typed to 0.1 rad move both cranks by
// about 1.15 degrees, each move is listed with its values; the cranks are independent (the
// unbiased column-pivoted QR, as without actuators, picks an elbow).
TEST(Assembly, ReportsWhatItMovedAndPrefersActuatedCoordinates) {
  const std::string path = std::string(CODYNA_TEST_DATA_DIR) + "/five_bar.json";
  const ModelSpec spec = load_model_spec(path);
  const Model m = compile(spec, path);
  ASSERT_EQ(m.nc, 2);
  std::vector<std::string> moved;
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    const double typed = spec.joints[static_cast<std::size_t>(j.spec_index)].q0[0], now = m.q0[j.idx_q];
    const auto it = std::find_if(m.assembly_moves.begin(), m.assembly_moves.end(),
                                 [&](const Model::AssemblyMove& a) { return a.name == j.name; });
    if (std::abs(now - typed) > 1e-6) {
      ASSERT_NE(it, m.assembly_moves.end()) << j.name << " moved from " << typed << " to " << now << " unreported";
      EXPECT_EQ(it->from, typed);
      EXPECT_EQ(it->to, now);
      EXPECT_EQ(it->by, now - typed);
      moved.push_back(j.name);
    } else {
      EXPECT_EQ(it, m.assembly_moves.end()) << j.name;
    }
  }
  EXPECT_EQ(moved, (std::vector<std::string>{"motor_L", "elbow_L", "motor_R", "elbow_R"}));
  EXPECT_NEAR(m.q0[0] * 180 / M_PI, 121.15, 0.01);  // the crank typed at 120 degrees
  // independent coordinates: the motors' joints
  const CoordinatePartition p = partition_coordinates(m, m.q0);
  std::vector<std::string> independent;
  for (int i : p.independent) independent.push_back(m.v_names[static_cast<std::size_t>(i)]);
  EXPECT_EQ(independent, (std::vector<std::string>{"motor_L", "motor_R"}));
  ModelSpec bare = spec;
  bare.actuators.clear();
  bare.plant = {};
  const Model mb = compile(bare, path);
  const CoordinatePartition pb = partition_coordinates(mb, mb.q0);
  EXPECT_NE(pb.independent, p.independent);  // without the motors the QR picks otherwise
  // a tree reports nothing
  EXPECT_TRUE(compile(load_model_spec(example_path("pendulum.json"))).assembly_moves.empty());
}
