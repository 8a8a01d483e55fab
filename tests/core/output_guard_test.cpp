// Outputs never replace a user's files (io/output_guard.hpp), and the writers check it themselves.
#include "io/output_guard.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "io/atomic_file.hpp"
#include "io/results_file.hpp"
#include "test_util.hpp"

using namespace codyna;
namespace fs = std::filesystem;

namespace {

struct Dir {
  fs::path p = fs::temp_directory_path() / ("codyna_guard_" + std::to_string(::getpid()));
  Dir() {
    fs::remove_all(p);
    fs::create_directories(p);
  }
  ~Dir() { fs::remove_all(p); }
  std::string operator/(const std::string& f) const { return (p / f).string(); }
};

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
std::string read(const std::string& path) {
  std::ifstream f(path);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

SimulationResult tiny_result(const std::string& model_file) {
  SimulationResult r;
  r.t = {0.0};
  r.q = r.v = r.u = r.y = r.xc = Eigen::MatrixXd(1, 0);
  r.kinetic_energy = r.potential_energy = r.constraint_violation = r.velocity_violation = {0.0};
  r.model_file = model_file;
  return r;
}

}  // namespace

TEST(OutputGuard, TheInputIsNeverAnOutputThroughLinks) {
  Dir d;
  const std::string model = d / "model.json";
  write(model, "{\"name\": \"m\"}\n");
  EXPECT_NE(message_of([&] { guard_output(model, OutputKind::ResultsHdf5, {model}); }).find("the input file"), std::string::npos);
  fs::create_symlink(model, d / "link.h5");
  EXPECT_NE(message_of([&] { guard_output(d / "link.h5", OutputKind::ResultsHdf5, {model}); }).find("the input file"), std::string::npos);
  fs::create_hard_link(model, d / "hard.csv");
  EXPECT_NE(message_of([&] { guard_output(d / "hard.csv", OutputKind::ResultsCsv, {model}); }).find("the input file"), std::string::npos);
  // the writers refuse too, and the model is untouched
  EXPECT_THROW(write_results_csv(tiny_result(model), d / "hard.csv"), std::invalid_argument);
  EXPECT_THROW(write_results_hdf5(tiny_result(model), d / "link.h5"), std::invalid_argument);
  EXPECT_EQ(read(model), "{\"name\": \"m\"}\n");
}

TEST(OutputGuard, OnlyFilesCodynaWroteAreReplaced) {
  Dir d;
  write(d / "notes.csv", "my notes, not a results table\n");
  EXPECT_NE(message_of([&] { guard_output(d / "notes.csv", OutputKind::ResultsCsv, {}); }).find("not a CSV results file written by codyna"),
            std::string::npos);
  write(d / "plant.m", "% my own script\nx = 1;\n");
  EXPECT_FALSE(message_of([&] { guard_output(d / "plant.m", OutputKind::PlantScript, {}); }).empty());
  write(d / "plant.mat", "MATLAB 5.0 MAT-file, Platform: GLNXA64, Created by: someone else");
  EXPECT_FALSE(message_of([&] { guard_output(d / "plant.mat", OutputKind::PlantMat, {}); }).empty());
  fs::create_directory(d / "dir.h5");
  EXPECT_NE(message_of([&] { guard_output(d / "dir.h5", OutputKind::ResultsHdf5, {}); }).find("a directory"), std::string::npos);
  ASSERT_EQ(::mkfifo((d / "fifo.csv").c_str(), 0600), 0);
  EXPECT_NE(message_of([&] { guard_output(d / "fifo.csv", OutputKind::ResultsCsv, {}); }).find("FIFO"), std::string::npos);
  // what codyna wrote, it may write again; empty files and new names are fine
  write_results_csv(tiny_result(""), d / "r.csv");
  write_results_hdf5(tiny_result(""), d / "r.h5");
  EXPECT_NO_THROW(guard_output(d / "r.csv", OutputKind::ResultsCsv, {}));
  EXPECT_NO_THROW(guard_output(d / "r.h5", OutputKind::ResultsHdf5, {}));
  EXPECT_NO_THROW(write_results_csv(tiny_result(""), d / "r.csv"));
  write(d / "empty.csv", "");
  EXPECT_NO_THROW(guard_output(d / "empty.csv", OutputKind::ResultsCsv, {}));
  EXPECT_NO_THROW(guard_output(d / "new.h5", OutputKind::ResultsHdf5, {}));
  // an HDF5 results file is not a CSV, and a CSV is not an HDF5 file
  EXPECT_FALSE(message_of([&] { guard_output(d / "r.h5", OutputKind::ResultsCsv, {}); }).empty());
  EXPECT_FALSE(message_of([&] { guard_output(d / "r.csv", OutputKind::ResultsHdf5, {}); }).empty());
}

TEST(AtomicFileLeftovers, TemporariesOfDeadWritersAreRemovedOnTheNextWrite) {
  Dir d;
  // a writer killed with -9 leaves ".NAME.tmp-PID-XXXXXX"; a pid that cannot run (above pid_max) stands for it
  write(d / ".out.csv.tmp-999999999-abcdef", "half a file");
  write(d / ".out.csv.tmp-" + std::to_string(::getpid()) + "-keep01", "ours, still being written");
  write(d / ".other.csv.tmp-999999999-abcdef", "another target's");
  write_file_atomically(d / "out.csv", "t,x\n0,1\n");
  EXPECT_FALSE(fs::exists(d / ".out.csv.tmp-999999999-abcdef"));
  EXPECT_TRUE(fs::exists(d / (".out.csv.tmp-" + std::to_string(::getpid()) + "-keep01")));
  EXPECT_TRUE(fs::exists(d / ".other.csv.tmp-999999999-abcdef"));
  EXPECT_EQ(read(d / "out.csv"), "t,x\n0,1\n");
}

TEST(AtomicFileLeftovers, SignalHandlerRemovesTemporariesInProgress) {
  Dir d;
  AtomicFile f(d / "big.h5");
  write(f.temp_path(), "partial");
  ASSERT_TRUE(fs::exists(f.temp_path()));
  remove_temporary_files();  // what the CLI's SIGINT/SIGTERM handler calls
  EXPECT_FALSE(fs::exists(f.temp_path()));
  EXPECT_FALSE(fs::exists(d / "big.h5"));
}

TEST(ResultsPair, AFailedCsvKeepsTheOldHdf5) {
  Dir d;
  SimulationResult r = tiny_result("");
  write_results(r, d / "r.h5", d / "r.csv");
  const std::string old_h5 = read(d / "r.h5");
  r.t = {0.0, 0.5};
  r.q = r.v = r.u = r.y = r.xc = Eigen::MatrixXd(2, 0);
  r.kinetic_energy = r.potential_energy = r.constraint_violation = r.velocity_violation = {0.0, 1.0};
  // the CSV cannot be written (its folder is missing): nothing is replaced
  EXPECT_THROW(write_results(r, d / "r.h5", d / "missing/r.csv"), std::runtime_error);
  EXPECT_EQ(read(d / "r.h5"), old_h5);
  // both can: both are new
  write_results(r, d / "r.h5", d / "r.csv");
  EXPECT_EQ(read_results_hdf5(d / "r.h5").samples(), 2);
  EXPECT_NE(read(d / "r.csv").find("0.5"), std::string::npos);
}
