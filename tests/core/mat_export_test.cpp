// io/mat_export: the exported files read back exactly, failures leave nothing
// behind, the reader explains what it cannot read, and peers (GNU Octave with
// the control package, scipy, h5py) see what a MATLAB user would.
#include <gtest/gtest.h>
#include <matio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "analysis/discretize.hpp"
#include "analysis/modal.hpp"
#include "io/mat_export.hpp"
#include "peer_util.hpp"
#include "test_util.hpp"

namespace codyna {

// readable parameter values in test names (found by ADL, so outside the unnamed namespace)
static void PrintTo(MatVersion v, std::ostream* os) { *os << (v == MatVersion::V5 ? "v5" : "v7.3"); }

namespace {

namespace fs = std::filesystem;
using test::bounded;
using test::CommandResult;
using test::MatrixNear;
using test::on_path;
using test::peer_script;
using test::python_with;
using test::run_command;
using test::shell_quoted;
using Strings = std::vector<std::string>;

// ------------------------------------------------------------------ fixtures

// MISSION.md example 2: cart (m2) with a rod (m3, l3) upright on it, force on
// the cart, states [h, h', theta, theta'], outputs h and theta.
LinearSystem cart_pendulum() {
  const double m2 = 20, m3 = 10, l3 = 2, g = 9.81, den = 4 * m2 + m3;
  LinearSystem s;
  s.A.setZero(4, 4);
  s.A(0, 1) = 1;
  s.A(1, 2) = -3 * m3 * g / den;
  s.A(2, 3) = 1;
  s.A(3, 2) = 6 * (m2 + m3) * g / (den * l3);
  s.B.setZero(4, 1);
  s.B(1) = 4 / den;
  s.B(3) = -6 / (l3 * den);
  s.C.setZero(2, 4);
  s.C(0, 0) = 1;
  s.C(1, 2) = 1;
  s.D.setZero(2, 1);
  s.x0 = Eigen::Vector4d(0.5, 0, 0, 0);
  s.u0 = Eigen::VectorXd::Zero(1);
  s.y0 = Eigen::Vector2d(0.5, 0);
  s.xdot0 = Eigen::VectorXd::Zero(4);
  s.state_names = {"h", "h_dot", "theta", "theta_dot"};
  s.state_units = {"m", "m/s", "rad", "rad/s"};
  s.input_names = {"force"};
  s.input_units = {"N"};
  s.output_names = {"h", "theta"};
  s.output_units = {"m", "rad"};
  s.model_name = "cart-pendulum";
  s.model_file = "examples/cart_pendulum.json";
  s.operating_point = "equilibrium";
  s.method = "exact";
  s.codyna_version = "0.1.0";
  return s;
}

// A plant with no inputs and no outputs: B is 4x0, C 0x4, D 0x0.
LinearSystem free_plant() {
  LinearSystem s = cart_pendulum();
  s.B.resize(4, 0);
  s.C.resize(0, 4);
  s.D.resize(0, 0);
  s.u0.resize(0);
  s.y0.resize(0);
  s.input_names.clear();
  s.input_units.clear();
  s.output_names.clear();
  s.output_units.clear();
  return s;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "codyna_mat_XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (fs::path(path_) / name).string(); }

  Strings files() const {  // sorted_names names of everything in the directory
    Strings out;
    for (const auto& e : fs::directory_iterator(path_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::string path_;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

#define EXPECT_THROW_WITH(statement, ...)                                                 \
  do {                                                                                    \
    try {                                                                                 \
      statement;                                                                          \
      ADD_FAILURE() << "no exception from " #statement;                                   \
    } catch (const std::exception& e) {                                               \
      for (const std::string& part : Strings{__VA_ARGS__})                               \
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)                    \
            << "message \"" << e.what() << "\" lacks \"" << part << "\"";                 \
    }                                                                                     \
  } while (0)

// ------------------------------------------------------------------ matlab_identifier

TEST(MatlabIdentifier, MakesValidNamesAndKeepsValidOnes) {
  EXPECT_EQ(matlab_identifier("cart-pendulum 2"), "cart_pendulum_2");
  EXPECT_EQ(matlab_identifier("cart_pendulum"), "cart_pendulum");
  EXPECT_EQ(matlab_identifier("2dof"), "m_2dof");
  EXPECT_EQ(matlab_identifier("_x"), "m__x");
  EXPECT_EQ(matlab_identifier(""), "plant");
  EXPECT_EQ(matlab_identifier("end"), "end_plant");
  EXPECT_EQ(matlab_identifier("function"), "function_plant");
  EXPECT_EQ(matlab_identifier("A"), "A_plant");  // NAME.m defines A: typing A would show the matrix
  EXPECT_EQ(matlab_identifier("ss"), "ss_plant");  // NAME.m calls ss()
  EXPECT_EQ(matlab_identifier(std::string(100, 'x')), std::string(63, 'x'));
  const Strings raw = {"cart-pendulum 2", "2dof", "end", "A", "\xce\xb8 pendulum", std::string(80, '9')};
  for (const std::string& s : raw) {
    const std::string id = matlab_identifier(s);
    EXPECT_EQ(matlab_identifier(id), id) << s;
    EXPECT_LE(id.size(), 63u);
    EXPECT_TRUE(std::isalpha(static_cast<unsigned char>(id[0]))) << id;
  }
}

// ------------------------------------------------------------------ export, read back with matio

class MatExport : public ::testing::TestWithParam<MatVersion> {};

INSTANTIATE_TEST_SUITE_P(Versions, MatExport, ::testing::Values(MatVersion::V5, MatVersion::V73),
                         [](const auto& info) { return info.param == MatVersion::V5 ? "v5" : "v73"; });

TEST_P(MatExport, RoundTripIsExact) {
  TempDir dir;
  const LinearSystem s = cart_pendulum();
  const ExportPaths paths = export_plant(s, dir.path(), "cart_pendulum", GetParam());
  EXPECT_EQ(paths.mat_file, dir / "cart_pendulum.mat");
  EXPECT_EQ(paths.m_file, dir / "cart_pendulum.m");
  EXPECT_EQ(dir.files(), (Strings{"cart_pendulum.m", "cart_pendulum.mat"}));  // no temporary files left

  const MatVariables mat = read_mat_file(paths.mat_file);
  const std::pair<const char*, Eigen::MatrixXd> expected[] = {
      {"A", s.A}, {"B", s.B}, {"C", s.C}, {"D", s.D}, {"x0", s.x0}, {"u0", s.u0}, {"y0", s.y0}, {"xdot0", s.xdot0},
      {"Ts", Eigen::MatrixXd::Zero(1, 1)}};
  for (const auto& [name, value] : expected) {
    ASSERT_TRUE(mat.matrices.count(name)) << name;
    EXPECT_TRUE(MatrixNear(mat.matrices.at(name), value, 0.0)) << name;  // bit for bit
  }
  EXPECT_EQ(mat.strings.at("state_names"), s.state_names);
  EXPECT_EQ(mat.strings.at("input_names"), s.input_names);
  EXPECT_EQ(mat.strings.at("output_names"), s.output_names);
  EXPECT_EQ(mat.strings.at("state_units"), s.state_units);
  EXPECT_EQ(mat.strings.at("input_units"), s.input_units);
  EXPECT_EQ(mat.strings.at("output_units"), s.output_units);
  if (GetParam() == MatVersion::V73) {
    EXPECT_EQ(mat.strings.at("state_names_char"), s.state_names);
    EXPECT_EQ(mat.strings.at("output_units_char"), s.output_units);
  } else {
    EXPECT_FALSE(mat.strings.count("state_names_char"));
  }
  ASSERT_EQ(mat.skipped.size(), 1u);
  EXPECT_EQ(mat.skipped[0].name, "info");
  EXPECT_EQ(mat.skipped[0].reason, "struct");

  // the file's own layout, seen through matio: version, cell shapes, the info struct
  std::unique_ptr<mat_t, int (*)(mat_t*)> f(Mat_Open(paths.mat_file.c_str(), MAT_ACC_RDONLY), Mat_Close);
  ASSERT_TRUE(f);
  EXPECT_EQ(Mat_GetVersion(f.get()), GetParam() == MatVersion::V5 ? MAT_FT_MAT5 : MAT_FT_MAT73);
  std::unique_ptr<matvar_t, void (*)(matvar_t*)> names(Mat_VarRead(f.get(), "state_names"), Mat_VarFree);
  ASSERT_TRUE(names);
  EXPECT_EQ(names->class_type, MAT_C_CELL);
  EXPECT_EQ(names->dims[0], 4u);
  EXPECT_EQ(names->dims[1], 1u);
  EXPECT_EQ(Mat_VarGetCell(names.get(), 2)->class_type, MAT_C_CHAR);
  std::unique_ptr<matvar_t, void (*)(matvar_t*)> info(Mat_VarRead(f.get(), "info"), Mat_VarFree);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->class_type, MAT_C_STRUCT);
  for (const char* field : {"name", "model_name", "model_file", "operating_point", "method", "time", "codyna_version"})
    EXPECT_TRUE(Mat_VarGetStructFieldByName(info.get(), field, 0)) << field;
  const matvar_t* model_name = Mat_VarGetStructFieldByName(info.get(), "model_name", 0);
  ASSERT_EQ(model_name->class_type, MAT_C_CHAR);
  EXPECT_EQ(std::u16string(static_cast<const char16_t*>(model_name->data), model_name->dims[1]), u"cart-pendulum");
}

TEST_P(MatExport, KeepsEmptyMatricesAtTheirTrueSize) {
  TempDir dir;
  const ExportPaths paths = export_plant(free_plant(), dir.path(), "free", GetParam());
  const MatVariables mat = read_mat_file(paths.mat_file);
  const std::pair<const char*, std::array<Eigen::Index, 2>> sizes[] = {
      {"A", {4, 4}}, {"B", {4, 0}}, {"C", {0, 4}}, {"D", {0, 0}}, {"u0", {0, 1}}, {"y0", {0, 1}}};
  for (const auto& [name, size] : sizes) {
    ASSERT_TRUE(mat.matrices.count(name)) << name;
    EXPECT_EQ(mat.matrices.at(name).rows(), size[0]) << name;
    EXPECT_EQ(mat.matrices.at(name).cols(), size[1]) << name;
  }
  EXPECT_EQ(mat.strings.at("state_names").size(), 4u);
  // an empty cell array reads as no strings, or as the one '' of a 0x0 char matrix in v7.3
  EXPECT_TRUE(!mat.strings.count("input_names") || mat.strings.at("input_names").size() <= 1);
  const std::string script = slurp(paths.m_file);
  EXPECT_NE(script.find("plant_inputs = cell(0, 1);"), std::string::npos);
}

TEST_P(MatExport, TextRoundTripsAsUtf8) {
  TempDir dir;
  LinearSystem s = cart_pendulum();
  s.state_names = {"h", "h_dot", "\xce\xb8", "\xce\xb8_dot"};                           // θ
  s.state_units = {"m", "m/s", "\xc2\xb0", "\xf0\x9d\x9c\x83/s"};                       // °, 𝜃 (outside the BMP)
  s.output_units = {"m", ""};
  const MatVariables mat = read_mat_file(export_plant(s, dir.path(), "utf", GetParam()).mat_file);
  EXPECT_EQ(mat.strings.at("state_names"), s.state_names);
  EXPECT_EQ(mat.strings.at("state_units"), s.state_units);
  EXPECT_EQ(mat.strings.at("output_units"), s.output_units);
}

TEST(MatExport, FillsDefaultsForEmptyFields) {
  TempDir dir;
  LinearSystem s;
  s.A = Eigen::Matrix2d{{0, 1}, {-4, -0.4}};
  s.B = Eigen::Vector2d(0, 1);
  s.C = Eigen::RowVector2d(1, 0);
  const MatVariables mat = read_mat_file(export_plant(s, dir.path(), "bare").mat_file);
  EXPECT_TRUE(MatrixNear(mat.matrices.at("D"), Eigen::MatrixXd::Zero(1, 1), 0.0));
  EXPECT_TRUE(MatrixNear(mat.matrices.at("x0"), Eigen::MatrixXd::Zero(2, 1), 0.0));
  EXPECT_EQ(mat.strings.at("state_names"), (Strings{"x1", "x2"}));
  EXPECT_EQ(mat.strings.at("input_names"), (Strings{"u1"}));
  EXPECT_EQ(mat.strings.at("output_names"), (Strings{"y1"}));
  EXPECT_EQ(mat.strings.at("state_units"), (Strings{"", ""}));
}

TEST(MatExport, ScriptDocumentsThePlant) {
  const std::string m = plant_script(cart_pendulum(), "cart_pendulum", MatVersion::V5);
  for (const char* part : {"% Model:            cart-pendulum  (examples/cart_pendulum.json)",
                           "% Operating point:  equilibrium, t = 0 s", "x = x0 + dx,  u = u0 + du,  y = y0 + dy",
                           "%   1  force  [N]", "%   2  theta  [rad]", "fileparts(mfilename('fullpath'))",
                           "load(fullfile(codyna_here, 'cart_pendulum.mat'));", "pkg load control",
                           "  'force'  % [N]", "sys.StateName = state_names;"})
    EXPECT_NE(m.find(part), std::string::npos) << part;
  EXPECT_EQ(m.find("_char"), std::string::npos);  // the v7.3 fallback only in v7.3 scripts
  EXPECT_NE(plant_script(cart_pendulum(), "cp", MatVersion::V73).find("cellstr(char(state_names_char))"),
            std::string::npos);

  LinearSystem odd = cart_pendulum();
  odd.input_names = {"it's\nforce"};  // a quote and a newline must not break the script
  const std::string m2 = plant_script(odd, "odd", MatVersion::V5);
  EXPECT_NE(m2.find("  'it''s force'  % [N]"), std::string::npos);
  EXPECT_NE(m2.find("%   1  it's force  [N]"), std::string::npos);
}

// ------------------------------------------------------------------ failures leave nothing behind

TEST(MatExport, RejectsABadNameAndWritesNothing) {
  TempDir dir;
  EXPECT_THROW_WITH(export_plant(cart_pendulum(), dir.path(), "cart-pendulum"), "cart-pendulum.mat",
                    "not a valid MATLAB identifier", "'cart_pendulum'");
  EXPECT_THROW_WITH(export_plant(cart_pendulum(), dir.path(), "end"), "end_plant");
  EXPECT_TRUE(dir.files().empty());
}

TEST(MatExport, RejectsInconsistentPlantAndWritesNothing) {
  TempDir dir;
  LinearSystem s = cart_pendulum();
  s.B.resize(3, 1);
  EXPECT_THROW_WITH(export_plant(s, dir.path(), "cp"), dir / "cp.mat", "B is 3x1, expected 4x1");
  s = cart_pendulum();
  s.A(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW_WITH(export_plant(s, dir.path(), "cp"), "A has NaN or Inf entries");
  s = cart_pendulum();
  s.state_names.pop_back();
  EXPECT_THROW_WITH(export_plant(s, dir.path(), "cp"), "state_names has 3 entries, expected 4");
  EXPECT_TRUE(dir.files().empty());
}

TEST(MatExport, MissingDirectoryFailsWithTheReason) {
  TempDir dir;
  const std::string missing = dir / "no_such_dir";
  EXPECT_THROW_WITH(export_plant(cart_pendulum(), missing, "cp"), missing + "/cp.mat", "No such file or directory");
  EXPECT_TRUE(dir.files().empty());
}

TEST(MatExport, ReadOnlyDirectoryFailsWithTheReason) {
  TempDir dir;
  const std::string ro = dir / "ro";
  fs::create_directory(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(ro.c_str(), W_OK) == 0) GTEST_SKIP() << "running as root: a read-only directory is still writable";
  EXPECT_THROW_WITH(export_plant(cart_pendulum(), ro, "cp"), ro + "/cp.mat", "Permission denied");
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_TRUE(fs::is_empty(ro));
}

TEST(MatExport, FailureLeavesExistingFilesUntouched) {
  TempDir dir;
  export_plant(cart_pendulum(), dir.path(), "cp");
  const std::string old_mat = slurp(dir / "cp.mat");
  fs::remove(dir / "cp.m");
  fs::create_directory(dir / "cp.m");  // the .m cannot be replaced: the export must not touch cp.mat
  LinearSystem changed = cart_pendulum();
  changed.A(3, 2) = 1.0;
  EXPECT_THROW_WITH(export_plant(changed, dir.path(), "cp"), dir / "cp.m", "a directory");
  EXPECT_EQ(slurp(dir / "cp.mat"), old_mat);
  EXPECT_EQ(dir.files(), (Strings{"cp.m", "cp.mat"}));

  fs::remove(dir / "cp.m");
  export_plant(changed, dir.path(), "cp");  // and a later export replaces both
  EXPECT_EQ(read_mat_file(dir / "cp.mat").matrices.at("A")(3, 2), 1.0);
  EXPECT_EQ(dir.files(), (Strings{"cp.m", "cp.mat"}));
}

// ------------------------------------------------------------------ read_mat_file

using VarPtr = std::unique_ptr<matvar_t, void (*)(matvar_t*)>;

VarPtr make_var(const char* name, matio_classes cls, matio_types type, std::vector<size_t> dims, const void* data,
                int flags = 0) {
  const int rank = static_cast<int>(dims.size());
  return VarPtr(Mat_VarCreate(name, cls, type, rank, dims.data(), const_cast<void*>(data), flags), Mat_VarFree);
}

void write_mat(const std::string& path, const std::vector<VarPtr>& vars) {
  std::unique_ptr<mat_t, int (*)(mat_t*)> f(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5), Mat_Close);
  ASSERT_TRUE(f);
  for (const auto& v : vars) ASSERT_EQ(Mat_VarWrite(f.get(), v.get(), MAT_COMPRESSION_ZLIB), 0);
}

TEST(ReadMatFile, ConvertsNumericAndSkipsTheRest) {
  TempDir dir;
  const double k[] = {1, 2, 3, 4};
  const std::int32_t n[] = {-1, 7};
  const std::uint8_t flags[] = {1, 0, 1};
  const float f[] = {0.5f};
  double re[] = {1, 2}, im[] = {0, 1};
  mat_complex_split_t z{re, im};
  const double cube[] = {1, 2, 3, 4, 5, 6, 7, 8};
  const char16_t text[] = u"force";
  std::vector<VarPtr> vars;
  vars.push_back(make_var("K", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 4}, k));
  vars.push_back(make_var("n", MAT_C_INT32, MAT_T_INT32, {2, 1}, n));
  vars.push_back(make_var("on", MAT_C_UINT8, MAT_T_UINT8, {1, 3}, flags, MAT_F_LOGICAL));
  vars.push_back(make_var("f", MAT_C_SINGLE, MAT_T_SINGLE, {1, 1}, f));
  vars.push_back(make_var("z", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 2}, &z, MAT_F_COMPLEX));
  vars.push_back(make_var("cube", MAT_C_DOUBLE, MAT_T_DOUBLE, {2, 2, 2}, cube));
  vars.push_back(make_var("label", MAT_C_CHAR, MAT_T_UINT16, {1, 5}, text));
  write_mat(dir / "c.mat", vars);

  const MatVariables mat = read_mat_file(dir / "c.mat");
  EXPECT_TRUE(MatrixNear(mat.matrices.at("K"), Eigen::RowVector4d(1, 2, 3, 4), 0.0));
  EXPECT_TRUE(MatrixNear(mat.matrices.at("n"), Eigen::Vector2d(-1, 7), 0.0));
  EXPECT_TRUE(MatrixNear(mat.matrices.at("on"), Eigen::RowVector3d(1, 0, 1), 0.0));
  EXPECT_TRUE(MatrixNear(mat.matrices.at("f"), Eigen::MatrixXd::Constant(1, 1, 0.5), 0.0));
  EXPECT_EQ(mat.strings.at("label"), (Strings{"force"}));
  EXPECT_EQ(mat.matrices.size(), 4u);
  ASSERT_EQ(mat.skipped.size(), 2u);
  EXPECT_EQ(mat.skipped[0].name, "z");
  EXPECT_EQ(mat.skipped[0].reason, "complex");
  EXPECT_EQ(mat.skipped[1].name, "cube");
  EXPECT_EQ(mat.skipped[1].reason, "3-D array");
}

TEST(ReadMatFile, NamesTheVariableWithNaN) {
  TempDir dir;
  const double good[] = {1, 2}, bad[] = {1, std::numeric_limits<double>::quiet_NaN()};
  std::vector<VarPtr> vars;
  vars.push_back(make_var("K", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 2}, good));
  vars.push_back(make_var("Kbad", MAT_C_DOUBLE, MAT_T_DOUBLE, {1, 2}, bad));
  write_mat(dir / "nan.mat", vars);
  EXPECT_THROW_WITH(read_mat_file(dir / "nan.mat"), dir / "nan.mat", "'Kbad'", "NaN or Inf");
}

TEST(ReadMatFile, ExplainsFilesItCannotRead) {
  TempDir dir;
  write_text(dir / "octave.txt",
             "# Created by Octave 7.3.0, Mon Jan 01 00:00:00 2024 UTC <user@host>\n"
             "# name: K\n# type: matrix\n# rows: 1\n# columns: 2\n 1 2\n");
  EXPECT_THROW_WITH(read_mat_file(dir / "octave.txt"), dir / "octave.txt",
                    "Octave text format; save with -v7 or -mat7-binary");
  write_text(dir / "notes.mat", "just some notes, long enough to fill a MAT header of 128 bytes ......"
                                "...................................................................\n");
  EXPECT_THROW_WITH(read_mat_file(dir / "notes.mat"), dir / "notes.mat", "not a MAT file");
  EXPECT_THROW_WITH(read_mat_file(dir / "absent.mat"), dir / "absent.mat", "no such file");
}

// ------------------------------------------------------------------ peers

std::vector<std::complex<double>> sorted_names(std::vector<std::complex<double>> v) {
  std::sort(v.begin(), v.end(),
            [](auto a, auto b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
  return v;
}

// One Octave session for all Octave checks: export cart_pendulum (v5) and
// cart_pendulum73 (v7.3), run tests/peers/octave_plant_check.m on each from
// another folder, keep what it saved.
struct OctaveRun {
  TempDir dir;
  CommandResult result;
  std::optional<MatVariables> v5, v73, K;
};

const OctaveRun& octave_run() {
  static const std::unique_ptr<OctaveRun> run = [] {
    auto r = std::make_unique<OctaveRun>();
    export_plant(cart_pendulum(), r->dir.path(), "cart_pendulum", MatVersion::V5);
    export_plant(cart_pendulum(), r->dir.path(), "cart_pendulum73", MatVersion::V73);
    fs::create_directory(r->dir / "work");
    const auto call = [&](const std::string& name, const std::string& out, const std::string& k) {
      return "octave_plant_check('" + r->dir.path() + "', '" + name + "', '" + (r->dir / out) + "', '" + (r->dir / k) +
             "'); ";
    };
    const std::string eval = "addpath('" + peer_script("") + "'); " + call("cart_pendulum", "peer5.mat", "K.mat") +
                             call("cart_pendulum73", "peer73.mat", "K73.mat");
    r->result = run_command("cd " + shell_quoted(r->dir / "work") + " && " +
                            bounded("octave-cli --no-gui --quiet --eval " + shell_quoted(eval)));
    if (r->result.exit_code == 0) {
      r->v5 = read_mat_file(r->dir / "peer5.mat");
      r->v73 = read_mat_file(r->dir / "peer73.mat");
      r->K = read_mat_file(r->dir / "K.mat");
    }
    return r;
  }();
  return *run;
}

class OctavePeer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!on_path("octave-cli")) GTEST_SKIP() << "octave-cli is not on PATH (CI installs it with octave-control)";
    const OctaveRun& r = octave_run();
    // Octave may print "error: ignoring const execution_exception& while preparing to exit"
    // at exit; that is harmless, so judge by the exit code and the script's own lines.
    ASSERT_EQ(r.result.exit_code, 0) << r.result.output;
    ASSERT_NE(r.result.output.find("CODYNA_OK cart_pendulum\n"), std::string::npos) << r.result.output;
    ASSERT_NE(r.result.output.find("CODYNA_OK cart_pendulum73\n"), std::string::npos) << r.result.output;
  }
  static const MatVariables& v5() { return *octave_run().v5; }
  static const MatVariables& v73() { return *octave_run().v73; }
};

TEST_F(OctavePeer, ScriptBuildsTheNamedModelFromV5AndV73) {
  const LinearSystem s = cart_pendulum();
  for (const MatVariables* seen : {&v5(), &v73()}) {
    EXPECT_TRUE(MatrixNear(seen->matrices.at("A_size"), Eigen::RowVector2d(4, 4), 0.0));
    EXPECT_TRUE(MatrixNear(seen->matrices.at("sys_size"), Eigen::RowVector2d(2, 1), 0.0));  // ny x nu
    EXPECT_EQ(seen->strings.at("sys_state_names"), s.state_names);
    EXPECT_EQ(seen->strings.at("sys_input_names"), s.input_names);
    EXPECT_EQ(seen->strings.at("sys_output_names"), s.output_names);
  }
  // the script printed its summary
  EXPECT_NE(octave_run().result.output.find("4 states (h, h_dot, theta, theta_dot)"), std::string::npos);
}

TEST_F(OctavePeer, EigenvaluesMatchModalAnalysis) {
  std::vector<std::complex<double>> octave, codyna;
  const Eigen::MatrixXd& re = v5().matrices.at("eig_re");
  const Eigen::MatrixXd& im = v5().matrices.at("eig_im");
  for (Eigen::Index i = 0; i < re.size(); ++i) octave.emplace_back(re(i), im(i));
  for (const Mode& m : modal_analysis(cart_pendulum()).modes) codyna.push_back(m.eigenvalue);
  ASSERT_EQ(octave.size(), 4u);
  ASSERT_EQ(codyna.size(), 4u);
  octave = sorted_names(octave);
  codyna = sorted_names(codyna);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_LE(std::abs(octave[i] - codyna[i]), 1e-10) << octave[i] << " vs " << codyna[i];
  EXPECT_NEAR(codyna[3].real(), std::sqrt(6 * 30 * 9.81 / (90 * 2)), 1e-12);  // sqrt(6 (m2+m3) g / ((4 m2+m3) l3))
}

TEST_F(OctavePeer, LqrGainComesBackThroughReadMatFile) {
  const LinearSystem s = cart_pendulum();
  const Eigen::MatrixXd& K = octave_run().K->matrices.at("K");
  const Eigen::MatrixXd& S = v5().matrices.at("S");
  ASSERT_EQ(K.rows(), 1);
  ASSERT_EQ(K.cols(), 4);
  // K = R^-1 B' S with S solving A'S + SA - S B R^-1 B' S + Q = 0 (Q = I, R = 1)
  const Eigen::MatrixXd riccati = s.A.transpose() * S + S * s.A - S * s.B * s.B.transpose() * S +
                                  Eigen::MatrixXd::Identity(4, 4);
  EXPECT_LE(riccati.cwiseAbs().maxCoeff(), 1e-9 * S.cwiseAbs().maxCoeff());
  EXPECT_TRUE(MatrixNear(K, s.B.transpose() * S, 1e-10));
  LinearSystem closed = s;
  closed.A = s.A - s.B * K;
  for (const Mode& m : modal_analysis(closed).modes) EXPECT_LT(m.eigenvalue.real(), 0.0) << m.eigenvalue;
}

TEST_F(OctavePeer, C2dMatchesDiscretizeZoh) {
  const LinearSystem d = discretize_zoh(cart_pendulum(), 0.01);
  EXPECT_TRUE(MatrixNear(v5().matrices.at("Ad"), d.A, 1e-12));
  EXPECT_TRUE(MatrixNear(v5().matrices.at("Bd"), d.B, 1e-12));
  EXPECT_TRUE(MatrixNear(v5().matrices.at("Cd"), d.C, 0.0));
  EXPECT_TRUE(MatrixNear(v5().matrices.at("Dd"), d.D, 0.0));
  EXPECT_DOUBLE_EQ(d.Ts, 0.01);
}

void expect_python_reads_plant(const std::string& reader, MatVersion v) {
  static const std::optional<std::string> python = python_with("scipy.io, h5py");
  if (!python) GTEST_SKIP() << "no python3 with scipy and h5py (set CODYNA_PYTHON; CI installs them)";
  TempDir dir;
  const LinearSystem s = cart_pendulum();
  const ExportPaths paths = export_plant(s, dir.path(), "cart_pendulum", v);
  const CommandResult r = run_command(bounded(shell_quoted(*python) + " " + shell_quoted(peer_script("read_plant.py")) +
                                              " " + reader + " " + shell_quoted(paths.mat_file)));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto seen = nlohmann::json::parse(r.output);
  const auto matrix = [&](const char* name) {
    const auto& m = seen.at(name);
    Eigen::MatrixXd out(m.at("rows").get<int>(), m.at("cols").get<int>());
    for (Eigen::Index i = 0; i < out.rows(); ++i)
      for (Eigen::Index j = 0; j < out.cols(); ++j) out(i, j) = m.at("data").at(i).at(j).get<double>();
    return out;
  };
  EXPECT_TRUE(MatrixNear(matrix("A"), s.A, 0.0));
  EXPECT_TRUE(MatrixNear(matrix("B"), s.B, 0.0));
  EXPECT_TRUE(MatrixNear(matrix("C"), s.C, 0.0));
  EXPECT_TRUE(MatrixNear(matrix("D"), s.D, 0.0));
  EXPECT_EQ(seen.at("Ts").get<double>(), 0.0);
  EXPECT_EQ(seen.at("state_names").get<Strings>(), s.state_names);
  EXPECT_EQ(seen.at("input_names").get<Strings>(), s.input_names);
  EXPECT_EQ(seen.at("output_names").get<Strings>(), s.output_names);
  EXPECT_EQ(seen.at("state_units").get<Strings>(), s.state_units);
}

TEST(PythonPeer, ScipyLoadmatReadsV5) { expect_python_reads_plant("scipy", MatVersion::V5); }

TEST(PythonPeer, H5pyReadsV73) { expect_python_reads_plant("h5py", MatVersion::V73); }

}  // namespace
}  // namespace codyna
