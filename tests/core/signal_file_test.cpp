// Time series from files (io/signal_file.hpp): CSV and .mat read to the same points, the
// table interpolated between them, and bad files refused with the file, the column or
// variable and what was expected; then a reference read from a file is followed by a PI loop.
#include "io/signal_file.hpp"

#include <gtest/gtest.h>
#include <matio.h>
#include <unistd.h>

#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "io/mat_export.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/workflow.hpp"
#include "test_util.hpp"

using namespace codyna;
using namespace codyna::test;

namespace {

std::string temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("codyna_signal_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d.string();
}

std::string write_signal_text(const std::string& name, const std::string& text) {
  const std::string path = temp_dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// named double matrices in a MAT v5 file, written by matio directly
std::string write_signal_mat(const std::string& name, const std::vector<std::pair<std::string, Eigen::MatrixXd>>& vars,
                      mat_ft version = MAT_FT_MAT5) {
  const std::string path = temp_dir() + "/" + name;
  std::filesystem::remove(path);
  std::unique_ptr<mat_t, int (*)(mat_t*)> f(Mat_CreateVer(path.c_str(), nullptr, version), Mat_Close);
  EXPECT_TRUE(f);
  for (const auto& [n, M] : vars) {
    size_t dims[2] = {static_cast<size_t>(M.rows()), static_cast<size_t>(M.cols())};
    std::unique_ptr<matvar_t, void (*)(matvar_t*)> v(
        Mat_VarCreate(n.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(M.data()), 0), Mat_VarFree);
    EXPECT_EQ(Mat_VarWrite(f.get(), v.get(), MAT_COMPRESSION_NONE), 0);
  }
  return path;
}

// the message of read_signal_file's error
std::string signal_error_of(const std::string& path) {
  try {
    read_signal_file(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

const std::vector<std::pair<double, double>> kPoints{{0.0, 0.0}, {1.0, 0.0}, {3.0, 0.2}, {4.0, 0.1}};

}  // namespace

TEST(SignalFile, CsvAndMatGiveTheSamePoints) {
  const std::string csv = write_signal_text("ref.csv", "t,value\r\n0,0\r\n1,0\r\n\r\n3,0.2\r\n4, 0.1\r\n");
  EXPECT_EQ(read_signal_file(csv), kPoints);
  Eigen::MatrixXd t(4, 1), v(1, 4);  // a column and a row: both vectors
  t << 0, 1, 3, 4;
  v << 0, 0, 0.2, 0.1;
  const std::string mat = write_signal_mat("ref.mat", {{"t", t}, {"value", v}});
  EXPECT_EQ(read_signal_file(mat), kPoints);
  const std::string mat73 = write_signal_mat("ref73.mat", {{"t", t}, {"value", v}}, MAT_FT_MAT73);
  EXPECT_EQ(read_signal_file(mat73), kPoints);
}

// piecewise linear through the points, held beyond the ends
TEST(SignalFile, TableIsInterpolatedLinearlyAndHeld) {
  SignalSpec s;
  s.type = "file";
  s.points = kPoints;
  EXPECT_EQ(signal_value(s, -1.0, 7.0), 0.0);
  EXPECT_EQ(signal_value(s, 0.5, 7.0), 0.0);
  EXPECT_NEAR(signal_value(s, 2.0, 7.0), 0.1, 1e-15);
  EXPECT_NEAR(signal_value(s, 2.5, 7.0), 0.15, 1e-15);
  EXPECT_NEAR(signal_value(s, 3.25, 7.0), 0.175, 1e-15);
  EXPECT_EQ(signal_value(s, 4.0, 7.0), 0.1);
  EXPECT_EQ(signal_value(s, 100.0, 7.0), 0.1);
}

TEST(SignalFile, BadFilesNameTheFileColumnAndWhatWasExpected) {
  const auto expect = [](const std::string& path, const std::string& part) {
    const std::string e = signal_error_of(path);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;  // starts with the file
    EXPECT_NE(e.find(part), std::string::npos) << e;
  };
  expect(temp_dir() + "/missing.csv", "no such file");
  expect(write_signal_text("empty.csv", ""), "empty: expected a header line (t,value)");
  expect(write_signal_text("noheader.csv", "0,1\n1,2\n"), "line 1: expected a header of two column names (t,value) before the numbers");
  expect(write_signal_text("onlyheader.csv", "time,force\n"), "no rows after the header (time,force)");
  expect(write_signal_text("word.csv", "time,force\n0,1\n1,abc\n"), "row 2 (line 3), column force: expected a number, got \"abc\"");
  expect(write_signal_text("three.csv", "time,force\n0,1,2\n"), "row 1 (line 2): expected two numbers separated by a comma (time,force)");
  expect(write_signal_text("back.csv", "time,force\n0,1\n2,1\n1,1\n"), "row 3 (line 4), column time: the time 1 is not after the previous one (2)");
  expect(write_signal_text("inf.csv", "time,force\n0,1\n1,inf\n"), "row 2 (line 3), column force: the value is not a finite number");
  Eigen::MatrixXd t(3, 1), v(3, 1), w(2, 1), M(2, 2);
  t << 0, 1, 2;
  v << 1, 2, 3;
  w << 1, 2;
  M << 1, 2, 3, 4;
  expect(write_signal_mat("novalue.mat", {{"t", t}, {"y", v}}), "no variable value: a signal .mat holds the vectors t and value");
  expect(write_signal_mat("short.mat", {{"t", t}, {"value", w}}), "t has 3 entries but value has 2: expected one value per time");
  expect(write_signal_mat("matrix.mat", {{"t", M}, {"value", v}}), "variable t is 2 x 2: expected a vector");
  Eigen::MatrixXd tb = t;
  tb(2) = 0.5;
  expect(write_signal_mat("back.mat", {{"t", tb}, {"value", v}}), "variable t, row 3: the time 0.5 is not after the previous one (1)");
  Eigen::MatrixXd vn = v;
  vn(1) = std::nan("");
  expect(write_signal_mat("nan.mat", {{"t", t}, {"value", vn}}), "variable value, row 2: not a finite number");
  expect(write_signal_text("garbage.mat", "not a mat file"), "");
}

namespace {

// The 2 kg spring-mass (k = 3, c = 0.5) under PID on its position (kp = 19, ki = 12, kd = 11.5:
// poles -1, -2, -3): a linear plant, so the nonlinear run is the linear closed loop
ModelSpec slider_pi(const std::string& reference_file) {
  const std::string text = R"({"name": "slider",
    "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
    "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0]}],
    "effects": [{"name": "spring", "type": "joint_spring_damper", "joint": "x", "stiffness": 3, "damping": 0.5}],
    "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N"}],
    "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
    "plant": {"inputs": ["force"], "outputs": ["pos"]},
    "controller": {"type": "pid", "kp": [[19]], "ki": [[12]], "kd": [[11.5]], "operating_point": "initial"},
    "solver": {"integrator": "cvode-bdf", "rtol": 1e-11, "atol": 1e-13, "t_end": 12, "output_step": 0.05},
    "analysis": {"operating_point": "initial", "references": [{"output": "pos", "type": "file", "file": ")" +
                           reference_file + R"("}]}})";
  return parse_model_spec_text(text, temp_dir() + "/slider.json");
}

}  // namespace

// The reference read from a CSV (relative to the model file's folder) is followed: the run equals
// the exact response of the linear closed loop to the piecewise-linear r(t), computed segment by
// segment with the matrix exponential of [[Acl, Bcl, 0], [0, 0, 1], [0, 0, 0]] (r' constant on each)
TEST(SignalFile, ReferenceFromAFileIsFollowed) {
  write_signal_text("ref_follow.csv", "t,pos\n0,0\n1,0\n3,0.2\n4,0.1\n");
  const Model m = study_model(slider_pi("ref_follow.csv"), temp_dir() + "/slider.json");
  const StudyClosedLoop cl = study_closed_loop(m);
  const LinearSystem& s = cl.loop.system;
  ASSERT_EQ(s.nx(), 3);
  ASSERT_EQ(s.nu(), 1);
  ASSERT_EQ(s.input_names[0], "r_pos");
  const SimulationResult r = study_simulate(m, cl.setup);
  ASSERT_TRUE(r.completed) << r.failure;
  // exact linear response
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(5, 5);
  M.topLeftCorner(3, 3) = s.A;
  M.block(0, 3, 3, 1) = s.B.col(0);
  M(3, 4) = 1;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(5);  // [x; r; r']
  double t = 0, worst = 0, worst_r = 0;
  const double knots[] = {1, 3, 4, 1e9};
  const double slopes[] = {0, 0.1, -0.1, 0};
  int seg = 0;
  for (int k = 0; k < r.samples(); ++k) {
    while (t < r.t[k] - 1e-12) {  // advance to the next knot or sample
      const double to = std::min(r.t[k], knots[seg]);
      z = Eigen::MatrixXd(M * (to - t)).exp() * z;
      t = to;
      if (t >= knots[seg] - 1e-12) {
        ++seg;
        z[4] = slopes[seg];
      }
    }
    const double y = (s.C.row(0) * z.head(3))(0) + s.D(0, 0) * z[3];
    worst = std::max(worst, std::abs(r.y(k, 0) - y));
    SignalSpec ref;
    ref.type = "table";
    ref.points = kPoints;
    worst_r = std::max(worst_r, std::abs(z[3] - signal_value(ref, r.t[k], 0)));
  }
  std::printf("PI following a CSV reference: max |y - exact linear| %.3g m (peak 0.2 m)\n", worst);
  EXPECT_LT(worst_r, 1e-14);  // the exact propagation's r is the table's
  EXPECT_LT(worst, 1e-8);
  // the loop follows: at the ramp's end (t = 3 s, r = 0.2) y lags by the ramp's slope times the
  // loop's velocity lag, and 8 s after the last knot it holds the final 0.1 (poles -1, -2, -3)
  EXPECT_NEAR(r.y(60, 0), 0.2, 0.05);
  EXPECT_NEAR(r.y(r.samples() - 1, 0), 0.1, 1e-3);
}

TEST(SignalFile, BadReferenceFileIsAnErrorAtTheField) {
  write_signal_text("ref_bad.csv", "t,pos\n0,0\n1,x\n");
  const Model m = study_model(slider_pi("ref_bad.csv"), temp_dir() + "/slider.json");
  try {
    study_simulation(m);
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/references/0/file");
    EXPECT_NE(std::string(e.what()).find("ref_bad.csv: row 2 (line 3), column pos: expected a number, got \"x\""), std::string::npos)
        << e.what();
  }
}

// A disturbance read from a file is the same signal as the table it holds: the push on the block
// takes the file's values (interpolated) at every sample, and the run is identical to the run
// with the table written in the model; a bad file is an error at the disturbance's field
TEST(SignalFile, DisturbanceFromAFile) {
  write_signal_text("push.csv", "t,push\n0,0\n2,0\n2.5,1\n4,-0.5\n");
  auto spec_with = [](const std::string& disturbance) {
    ModelSpec spec = slider_pi("ref_follow.csv");
    ActuatorSpec push;
    push.name = "push";
    push.type = ActuatorType::JointForce;
    push.joint = "x";
    push.unit = "N";
    spec.actuators.push_back(push);
    const std::string text = R"({"name": "d", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1]}],
      "joints": [{"name": "j", "type": "prismatic", "parent": "ground", "child": "b"}],
      "actuators": [{"name": "push", "type": "joint_force", "joint": "j"}],
      "analysis": {"disturbances": [)" + disturbance + "]}}";
    spec.analysis.disturbances = parse_model_spec_text(text, "d.json").analysis.disturbances;
    return spec;
  };
  write_signal_text("ref_follow.csv", "t,pos\n0,0\n1,0\n3,0.2\n4,0.1\n");
  const std::string dir = temp_dir() + "/slider.json";
  const Model from_file = study_model(spec_with(R"({"actuator": "push", "type": "file", "file": "push.csv"})"), dir);
  const Model from_table =
      study_model(spec_with(R"({"actuator": "push", "type": "table", "points": [[0, 0], [2, 0], [2.5, 1], [4, -0.5]]})"), dir);
  const SimulationResult a = study_simulate(from_file, study_simulation(from_file));
  const SimulationResult b = study_simulate(from_table, study_simulation(from_table));
  ASSERT_TRUE(a.completed && b.completed);
  const int ipush = 1;
  ASSERT_EQ(a.input_names[ipush], "push");
  for (int k = 0; k < a.samples(); ++k) {
    const double t = a.t[k];
    const double d = t <= 2 ? 0 : t <= 2.5 ? (t - 2) / 0.5 : t <= 4 ? 1 - 1.5 * (t - 2.5) / 1.5 : -0.5;
    EXPECT_NEAR(a.u(k, ipush), d, 1e-14) << t;
  }
  EXPECT_EQ(a.y, b.y);
  EXPECT_GT((a.y - study_simulate(study_model(slider_pi("ref_follow.csv"), dir), study_simulation(study_model(slider_pi("ref_follow.csv"), dir))).y)
                .cwiseAbs()
                .maxCoeff(),
            1e-3);  // the push does move the block
  write_signal_text("push_bad.csv", "t,push\n0,0\n0,1\n");
  try {
    study_simulation(study_model(spec_with(R"({"actuator": "push", "type": "file", "file": "push_bad.csv"})"), dir));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_EQ(e.path(), "/analysis/disturbances/0/file");
    EXPECT_NE(std::string(e.what()).find("push_bad.csv: row 2 (line 3), column t: the time 0 is not after the previous one (0)"),
              std::string::npos)
        << e.what();
  }
}
