// Parameter studies (core/study/sweep, issue 22): the cart-pendulum's rod mass over 11 values
// with the nominal LQR fixed (every variant's closed-loop poles against eig(A - B K) from that
// variant's own linearization, made here through the linearize job), a Monte Carlo of 200
// samples repeated and on 1 and 2 threads (the same file, byte for byte), variants that fail
// recorded with their reason, and bad --vary options named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "study/files.hpp"
#include "study/jobs.hpp"
#include "study/sweep.hpp"
#include "study/tools.hpp"
#include "io/mat_export.hpp"

namespace codyna {
namespace {

namespace fs = std::filesystem;

const std::string kModel = std::string(CODYNA_EXAMPLES_DIR) + "/cart_pendulum.json";

class SweepTempDir {
 public:
  SweepTempDir() {
    std::string pattern = (fs::temp_directory_path() / "codyna_sweep_XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~SweepTempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (fs::path(path_) / name).string(); }

 private:
  std::string path_;
};

std::string slurp_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json model_json() {
  std::ifstream in(kModel);
  return nlohmann::json::parse(in);
}

// the continuous A, B of the model file with /bodies/1/mass = mass, through the linearize job
LinearSystem linearized_with_rod_mass(double mass) {
  nlohmann::json j = model_json();
  j["bodies"][1]["mass"] = mass;
  LinearizeRequest r;
  r.model = kModel;
  return study_linearize_job(r, study_parse_model(j, kModel)).linearization.lin.system;
}

Eigen::VectorXcd sorted_strings(Eigen::VectorXcd p) {
  std::sort(p.data(), p.data() + p.size(), [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.real() < b.real() || (a.real() == b.real() && a.imag() < b.imag());
  });
  return p;
}

SweepRequest rod_mass_grid() {
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=5:15:11"};
  r.threads = 2;
  return r;
}

TEST(Sweep, FixedLqrClosedLoopPolesAreEigOfEachVariantsOwnLinearization) {
  const SweepJob job = study_sweep_job(rod_mass_grid());
  ASSERT_EQ(job.variants.size(), 11u);
  ASSERT_TRUE(job.closed_loop);
  EXPECT_FALSE(job.redesigned);
  // the nominal LQR designed here from the file's weights (Q = diag(10, 100, 1, 1), R = 0.01)
  const LinearSystem nominal = linearized_with_rod_mass(10.0);
  Eigen::MatrixXd Q = Eigen::Vector4d(10, 100, 1, 1).asDiagonal(), R(1, 1);
  R(0, 0) = 0.01;
  const Eigen::MatrixXd K = study_lqr(nominal.A, nominal.B, Q, R).K;
  ASSERT_EQ(job.K.rows(), 1);
  ASSERT_EQ(job.K.cols(), 4);
  EXPECT_LE((job.K - K).norm(), 1e-10 * K.norm());
  double spread = 0;
  for (int i = 0; i < 11; ++i) {
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    const double mass = 5.0 + i;
    ASSERT_EQ(v.status, SweepStatus::Ok) << v.reason;
    ASSERT_EQ(v.values.size(), 1u);
    EXPECT_NEAR(v.values[0], mass, 1e-14);
    const LinearSystem own = linearized_with_rod_mass(mass);
    EXPECT_LE((v.A - own.A).norm(), 1e-12 * own.A.norm()) << "variant " << i;
    EXPECT_LE((v.B - own.B).norm(), 1e-12 * own.B.norm()) << "variant " << i;
    const Eigen::VectorXcd expected = sorted_strings((own.A - own.B * K).eigenvalues());
    ASSERT_EQ(v.closed_poles.size(), 4);
    EXPECT_LE((v.closed_poles - expected).cwiseAbs().maxCoeff(), 1e-10) << "variant " << i;
    EXPECT_NEAR(v.closed_max_real, expected.real().maxCoeff(), 1e-10);
    EXPECT_TRUE(v.stable);
    const Eigen::VectorXcd open = sorted_strings(own.A.eigenvalues());
    EXPECT_LE((v.open_poles - open).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_GT(v.open_max_real, 0);  // upright: unstable without the controller
    EXPECT_EQ(v.uncontrollable, 0);
    // with K designed again the poles are not those of the fixed K (except at the nominal mass)
    if (i != 5) {
      const Eigen::MatrixXd Ki = study_lqr(own.A, own.B, Q, R).K;
      spread = std::max(spread, (sorted_strings((own.A - own.B * Ki).eigenvalues()) - expected).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_GT(spread, 1e-3);  // so the test above can tell a fixed K from a redesigned one
  EXPECT_EQ(job.failed, 0);
  EXPECT_EQ(job.stable, 11);
  EXPECT_EQ(job.worst, 0);  // the lightest rod is the least damped closed loop
}

// A variant reads again only the elements whose fields vary (parse_model_element into a copy of
// the nominal spec); a field outside the element arrays makes each variant read its whole file.
// Both give every variant's A, B, C, D, poles and figures bit for bit as the variant's own file
// read whole and linearized does.
TEST(Sweep, ElementsReadAgainEqualTheVariantsWholeFile) {
  for (const bool outside : {false, true}) {
    SweepRequest r;
    r.model = kModel;
    r.vary = {"/bodies/1/mass=8:12:3", "/bodies/1/com/1=[0.9,1.1]", "/effects/0/g/1=[-9.7,-9.81]"};
    if (outside) r.vary.push_back("/solver/rtol=[1e-9]");
    r.threads = 1;
    const SweepJob job = study_sweep_job(r);
    ASSERT_EQ(job.variants.size(), 12u);
    for (long long i = 0; i < 12; ++i) {
      const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      ASSERT_EQ(v.status, SweepStatus::Ok) << v.reason;
      nlohmann::json j = model_json();
      j["bodies"][1]["mass"] = v.values[0];
      j["bodies"][1]["com"][1] = v.values[1];
      j["effects"][0]["g"][1] = v.values[2];
      if (outside) j["solver"]["rtol"] = v.values[3];
      LinearizeRequest lr;
      lr.model = kModel;
      const LinearSystem own = study_linearize_job(lr, study_parse_model(j, kModel)).linearization.lin.system;
      for (auto [a, b] : {std::pair{&v.A, &own.A}, {&v.B, &own.B}, {&v.C, &own.C}, {&v.D, &own.D}}) {
        ASSERT_EQ(a->rows(), b->rows());
        ASSERT_EQ(a->cols(), b->cols());
        EXPECT_EQ(std::memcmp(a->data(), b->data(), sizeof(double) * static_cast<std::size_t>(a->size())), 0)
            << "variant " << i << (outside ? " (whole files)" : " (elements)");
      }
    }
  }
}

TEST(Sweep, RedesignedLqrIsDesignedOnEachVariant) {
  SweepRequest r = rod_mass_grid();
  r.vary = {"/bodies/1/mass=[6,14]"};
  r.redesign = "lqr";
  const SweepJob job = study_sweep_job(r);
  ASSERT_TRUE(job.redesigned);
  Eigen::MatrixXd Q = Eigen::Vector4d(10, 100, 1, 1).asDiagonal(), R(1, 1);
  R(0, 0) = 0.01;
  for (int i = 0; i < 2; ++i) {
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    ASSERT_EQ(v.status, SweepStatus::Ok) << v.reason;
    const LinearSystem own = linearized_with_rod_mass(i == 0 ? 6 : 14);
    const Eigen::MatrixXd K = study_lqr(own.A, own.B, Q, R).K;
    EXPECT_LE((v.K - K).norm(), 1e-9 * K.norm());
    EXPECT_LE((v.closed_poles - sorted_strings((own.A - own.B * K).eigenvalues())).cwiseAbs().maxCoeff(), 1e-10);
  }
}

TEST(Sweep, MonteCarloIsTheSameFileTwiceAndOnOneOrTwoThreads) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=normal(10,2)", "/bodies/0/mass=uniform(15,25)"};
  r.samples = 200;
  r.seed = 12345;
  const auto run = [&](int threads, const std::string& name) {
    SweepRequest x = r;
    x.threads = threads;
    x.out = dir.file(name + ".h5");
    x.csv = dir.file(name + ".csv");
    return study_sweep_job(x);
  };
  const SweepJob a = run(1, "a"), b = run(1, "b"), c = run(2, "c");
  ASSERT_EQ(a.variants.size(), 200u);
  EXPECT_EQ(slurp_file(dir.file("a.h5")), slurp_file(dir.file("b.h5")));
  EXPECT_EQ(slurp_file(dir.file("a.h5")), slurp_file(dir.file("c.h5")));
  EXPECT_EQ(slurp_file(dir.file("a.csv")), slurp_file(dir.file("c.csv")));
  EXPECT_GT(slurp_file(dir.file("a.h5")).size(), 200u * 16u * 8u);  // the A stack is there
  double mean = 0, lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < 200; ++i) {
    ASSERT_EQ(a.variants[i].values, c.variants[i].values);
    // variant i is a function of (specs, seed, i) alone
    ASSERT_EQ(a.variants[i].values, a.plan.values(static_cast<long long>(i)));
    EXPECT_EQ(a.variants[i].closed_poles, c.variants[i].closed_poles);
    mean += a.variants[i].values[0] / 200;
    lo = std::min(lo, a.variants[i].values[1]);
    hi = std::max(hi, a.variants[i].values[1]);
  }
  EXPECT_NEAR(mean, 10.0, 0.6);  // 3 standard errors of the mean (2 / sqrt(200) = 0.14) and then some
  EXPECT_GE(lo, 15.0);
  EXPECT_LE(hi, 25.0);
  EXPECT_LT(lo, 15.5);
  EXPECT_GT(hi, 24.5);
  // another seed draws other values
  SweepRequest other = r;
  other.seed = 12346;
  EXPECT_NE(study_sweep_plan(other, model_json()).values(0), a.plan.values(0));
  // a sample never depends on how many there are (a shard of a larger study draws the same)
  SweepRequest more = r;
  more.samples = 1000;
  EXPECT_EQ(study_sweep_plan(more, model_json()).values(199), a.plan.values(199));
}

TEST(Sweep, FailedVariantsAreRecordedWithTheirReasonAndTheOthersComplete) {
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=[10,-1,0,12]"};
  r.threads = 2;
  const SweepJob job = study_sweep_job(r);
  ASSERT_EQ(job.variants.size(), 4u);
  EXPECT_EQ(job.variants[0].status, SweepStatus::Ok);
  EXPECT_EQ(job.variants[1].status, SweepStatus::ModelError);
  EXPECT_NE(job.variants[1].reason.find("/bodies/1/mass"), std::string::npos) << job.variants[1].reason;
  EXPECT_NE(job.variants[1].reason.find("non-negative mass"), std::string::npos) << job.variants[1].reason;
  // a massless rod is a valid model (nothing holds it up): the fixed K does not stabilize it
  EXPECT_EQ(job.variants[2].status, SweepStatus::Ok) << job.variants[2].reason;
  EXPECT_FALSE(job.variants[2].stable);
  EXPECT_EQ(job.variants[2].uncontrollable, 1);
  EXPECT_EQ(job.variants[3].status, SweepStatus::Ok);
  EXPECT_EQ(job.failed, 1);
  EXPECT_EQ(job.stable, 2);
  EXPECT_EQ(job.worst, 2);
  const std::string summary = study_sweep_summary(job);
  EXPECT_NE(summary.find("variant 1 (model error)"), std::string::npos) << summary;
  // redesigned, the massless rod's LQR cannot be made: refused, with the reason
  r.redesign = "lqr";
  const SweepJob again = study_sweep_job(r);
  EXPECT_EQ(again.variants[2].status, SweepStatus::Refused);
  EXPECT_NE(again.variants[2].reason.find("not stabilizable"), std::string::npos) << again.variants[2].reason;
  EXPECT_EQ(again.variants[3].status, SweepStatus::Ok);
}

TEST(Sweep, SimulateRunsEachVariantWithTheNominalGain) {
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=[10,15,-1,20]"};
  r.simulate = true;
  r.threads = 1;
  const SweepJob one = study_sweep_job(r);
  r.threads = 2;
  const SweepJob two = study_sweep_job(r);
  ASSERT_TRUE(one.simulated);
  // the nominal variant's run is `codyna simulate` of the model file (its LQR designed there: the same K)
  SimulateRequest sr;
  sr.model = kModel;
  const SimulateJob nominal = study_simulate_job(sr, study_read_model(kModel));
  ASSERT_TRUE(nominal.result.completed);
  const SweepVariant& v0 = one.variants[0];
  ASSERT_EQ(v0.sim_status, 0) << v0.sim_reason;
  ASSERT_EQ(v0.peak_input.size(), 1);
  EXPECT_NEAR(v0.peak_input[0], nominal.max_abs_input[0], 1e-9 * nominal.max_abs_input[0]);
  const SimulationResult& n = nominal.result;
  const double final_theta = std::abs(n.y(n.y.rows() - 1, 1) - nominal.setup.plant->lin.system.y0[1]);
  const double final_h = std::abs(n.y(n.y.rows() - 1, 0) - nominal.setup.plant->lin.system.y0[0]);
  EXPECT_NEAR(v0.final_error, std::max(final_theta, final_h), 1e-9);
  EXPECT_NEAR(v0.sim_t_end, 5.0, 1e-12);
  // the failed variant is not run; the others are, the same on 1 and 2 threads
  EXPECT_EQ(one.variants[2].sim_status, -1);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(one.variants[i].sim_status, two.variants[i].sim_status);
    EXPECT_EQ(one.variants[i].final_error, two.variants[i].final_error);
    EXPECT_EQ(one.variants[i].peak_input, two.variants[i].peak_input);
  }
  EXPECT_EQ(one.variants[3].sim_status, 0);
  // with the LQR designed again, the 15 kg rod's run is another run (K fixed is what was run above)
  r.redesign = "lqr";
  const SweepJob again = study_sweep_job(r);
  EXPECT_EQ(again.variants[1].sim_status, 0);
  EXPECT_GT(std::abs(again.variants[1].final_error - one.variants[1].final_error), 1e-6);
  EXPECT_NEAR(again.variants[0].final_error, one.variants[0].final_error, 1e-9);  // the nominal: the same K
}

TEST(Sweep, AnInterruptedStudyResumesToTheSameFile) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=normal(10,2)", "/bodies/0/mass=uniform(15,25)"};
  r.samples = 120;
  r.seed = 99;
  r.simulate = true;
  r.threads = 2;
  r.out = dir.file("whole.h5");
  r.csv = dir.file("whole.csv");
  study_sweep_job(r);
  EXPECT_FALSE(fs::exists(study_sweep_journal_path(r.out)));  // removed once the results are written
  // stopped after 50 variants (as a Ctrl+C would: the journal stays, no result file)
  r.out = dir.file("cut.h5");
  r.csv = dir.file("cut.csv");
  std::atomic<bool> stop{false};
  SweepProgress p;
  p.cancel = &stop;
  p.done = [&](long long done, long long) {
    if (done >= 50) stop = true;
  };
  EXPECT_THROW(study_sweep_job(r, {}, p), StudyCancelled);
  EXPECT_FALSE(fs::exists(r.out));
  ASSERT_TRUE(fs::exists(study_sweep_journal_path(r.out)));
  // another study may not take that journal over
  SweepRequest other = r;
  other.seed = 100;
  try {
    study_sweep_job(other);
    ADD_FAILURE() << "another seed resumed the journal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("another study"), std::string::npos) << e.what();
  }
  // the same study started again skips what was done and writes the uninterrupted file
  std::vector<std::string> notes;
  const SweepJob resumed = study_sweep_job(r, [&](const StudyMessage& m) { notes.push_back(m.text); });
  EXPECT_GE(resumed.resumed, 50);
  EXPECT_LT(resumed.resumed, 120);
  EXPECT_EQ(slurp_file(dir.file("cut.h5")), slurp_file(dir.file("whole.h5")));
  EXPECT_EQ(slurp_file(dir.file("cut.csv")), slurp_file(dir.file("whole.csv")));
  EXPECT_FALSE(fs::exists(study_sweep_journal_path(r.out)));
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("resuming: "), std::string::npos) << notes.back();
}

TEST(Sweep, ShardsMergeIntoTheWholeStudysFile) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=normal(10,3)", "/bodies/0/mass=uniform(10,30)"};
  r.samples = 101;
  r.seed = 4;
  r.threads = 2;
  r.out = dir.file("whole.h5");
  r.csv = dir.file("whole.csv");
  study_sweep_job(r);
  std::vector<std::string> shards;
  for (long long k = 0; k < 3; ++k) {
    SweepRequest s = r;
    s.csv = "";
    s.out = dir.file("shard" + std::to_string(k) + ".sweep");
    s.shard_index = k;
    s.shard_count = 3;
    s.threads = 1;
    const SweepJob part = study_sweep_job(s);
    EXPECT_EQ(part.shard_count, 3);
    shards.push_back(s.out);
  }
  EXPECT_FALSE(fs::exists(r.out + "x"));
  SweepRequest outputs;
  outputs.out = dir.file("merged.h5");
  outputs.csv = dir.file("merged.csv");
  // a shard missing: refused, naming the variants
  try {
    study_sweep_merge({shards[0], shards[2]}, outputs);
    ADD_FAILURE() << "merged without shard 1";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("variants 1, 4, 7"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(outputs.out));
  const SweepJob merged = study_sweep_merge({shards[2], shards[0], shards[1]}, outputs);
  EXPECT_EQ(merged.resumed, 101);
  EXPECT_EQ(slurp_file(outputs.out), slurp_file(r.out));
  EXPECT_EQ(slurp_file(outputs.csv), slurp_file(r.csv));
  EXPECT_FALSE(fs::exists(study_sweep_journal_path(outputs.out)));
  // a shard of another study is refused
  SweepRequest other = r;
  other.seed = 5;
  other.csv = "";
  other.out = dir.file("other.sweep");
  other.shard_index = 1;
  other.shard_count = 3;
  study_sweep_job(other);
  outputs.out = dir.file("mixed.h5");
  outputs.csv = "";
  EXPECT_THROW(study_sweep_merge({shards[0], other.out, shards[2]}, outputs), std::invalid_argument);
}

// MPI's path without MPI: three slices with their journals in memory (no file written, the whole
// study's outputs named), joined by study_sweep_merge_journals into the single run's bytes
TEST(Sweep, JournalsInMemoryMergeIntoTheWholeStudysFile) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=5:15:7"};
  r.simulate = true;
  r.threads = 1;
  r.out = dir.file("whole.h5");
  r.csv = dir.file("whole.csv");
  study_sweep_job(r);
  SweepRequest slice = r;
  slice.out = dir.file("merged.h5");
  slice.csv = dir.file("merged.csv");
  slice.journal_in_memory = true;
  slice.shard_count = 3;
  std::vector<std::string> journals;
  for (long long k = 0; k < 3; ++k) {
    slice.shard_index = k;
    const SweepJob part = study_sweep_job(slice);
    EXPECT_TRUE(part.written.empty());
    journals.push_back(part.journal);
  }
  EXPECT_FALSE(fs::exists(slice.out));
  EXPECT_FALSE(fs::exists(study_sweep_journal_path(slice.out)));
  // 7 variants: 3 + 2 + 2 lines after the journal's two
  EXPECT_EQ(std::count(journals[1].begin(), journals[1].end(), '\n'), 4);
  try {
    study_sweep_merge_journals({journals[0], journals[2]}, {"rank 0", "rank 2"}, slice);
    ADD_FAILURE() << "merged without rank 1";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("variants 1, 4"), std::string::npos) << e.what();
  }
  const SweepJob merged = study_sweep_merge_journals({journals[2], journals[0], journals[1]}, {"rank 2", "rank 0", "rank 1"}, slice);
  EXPECT_EQ(merged.resumed, 7);
  EXPECT_EQ(slurp_file(slice.out), slurp_file(r.out));
  EXPECT_EQ(slurp_file(slice.csv), slurp_file(r.csv));
  ASSERT_EQ(merged.variants[3].overshoot.size(), 2);  // the figures went through the journal
  EXPECT_TRUE(std::isfinite(merged.variants[3].overshoot[0]));
  EXPECT_NEAR(merged.variants[3].settling_time[0], 4.713, 1e-3);  // h settles within the file's 5 s
  EXPECT_TRUE(std::isnan(merged.variants[3].settling_time[1]));     // theta does not: NaN, kept bit for bit
  EXPECT_EQ(merged.variants[3].saturation_time.size(), 1);  // the cart's force has no limits: NaN
  EXPECT_TRUE(std::isnan(merged.variants[3].saturation_time[0]));
  // a journal in memory that is not one is named
  EXPECT_THROW(study_sweep_merge_journals({journals[0], "garbage\n"}, {"rank 0", "rank 1"}, slice), std::invalid_argument);
}

// a shard's file is its journal, appended to as variants finish; finished, it is written again in the
// variants' order, so two threads give the bytes one gives (and a Slurm task the bytes of K/N)
TEST(Sweep, AShardsFileIsTheSameBytesWhateverTheThreads) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=5:15:40"};
  r.shard_count = 2;
  r.shard_index = 1;
  r.threads = 1;
  r.out = dir.file("one.sweep");
  study_sweep_job(r);
  for (int run = 0; run < 3; ++run) {
    r.threads = 2;
    r.out = dir.file("two_" + std::to_string(run) + ".sweep");
    study_sweep_job(r);
    EXPECT_EQ(slurp_file(r.out), slurp_file(dir.file("one.sweep"))) << "run " << run;
  }
}

// the journal's lines are written without a JSON library; each must be the line nlohmann::json dumps
// for the object it holds (sorted_strings keys, no spaces, strings escaped), and read back bit for bit
TEST(Sweep, JournalLinesAreWhatAJsonLibraryWrites) {
  SweepTempDir dir;
  SweepRequest r;
  r.model = kModel;
  r.vary = {"/bodies/1/mass=[-1, 0, 12]"};  // -1: a failed variant with its reason; 0: an uncontrollable mode
  r.simulate = true;
  r.threads = 1;
  r.out = dir.file("study.h5");
  const SweepJob whole = study_sweep_job(r);
  SweepRequest slice = r;
  slice.out = dir.file("merged.h5");
  slice.journal_in_memory = true;
  slice.shard_count = 1;
  slice.shard_index = 0;
  const SweepJob part = study_sweep_job(slice);
  std::istringstream lines(part.journal);
  std::string line;
  int variants = 0;
  for (int k = 0; std::getline(lines, line); ++k) {
    if (k < 2) continue;  // the journal's head and request
    const nlohmann::json j = nlohmann::json::parse(line);
    EXPECT_EQ(j.dump(), line);
    ++variants;
  }
  EXPECT_EQ(variants, 3);
  ASSERT_EQ(whole.variants.size(), 3u);
  EXPECT_EQ(whole.variants[0].status, SweepStatus::ModelError);
  EXPECT_NE(part.journal.find(nlohmann::json(whole.variants[0].reason).dump()), std::string::npos);
  EXPECT_EQ(whole.variants[1].uncontrollable, 1);
  const SweepJob merged = study_sweep_merge_journals({part.journal}, {"rank 0"}, slice);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(merged.variants[k].reason, whole.variants[k].reason);
    EXPECT_EQ(merged.variants[k].uncontrollable_text, whole.variants[k].uncontrollable_text);
    EXPECT_EQ(merged.variants[k].A, whole.variants[k].A);
    EXPECT_EQ(merged.variants[k].closed_poles, whole.variants[k].closed_poles);
    EXPECT_EQ(merged.variants[k].overshoot.size(), whole.variants[k].overshoot.size());
  }
}

void expect_sweep_refused(const std::vector<std::string>& vary, const std::vector<std::string>& words,
                    std::optional<long long> samples = {}, std::optional<std::uint64_t> seed = {}) {
  SweepRequest r;
  r.model = kModel;
  r.vary = vary;
  r.samples = samples;
  r.seed = seed;
  try {
    study_sweep_job(r);
    ADD_FAILURE() << "accepted " << vary[0];
  } catch (const std::invalid_argument& e) {
    for (const std::string& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

TEST(Sweep, BadVaryIsNamed) {
  expect_sweep_refused({"/bodies/7/mass=1:2:3"}, {"--vary", "/bodies/7/mass", "has 2 entries"});
  expect_sweep_refused({"/bodies/1/weight=1:2:3"}, {"--vary", "no field /bodies/1/weight", "mass"});
  expect_sweep_refused({"/bodies/1/name=1:2:3"}, {"--vary", "not a number"});
  expect_sweep_refused({"/bodies/1/com=1:2:3"}, {"--vary", "not a number", "/bodies/1/com/0"});
  expect_sweep_refused({"bodies/1/mass=1:2:3"}, {"--vary", "JSON pointer"});
  expect_sweep_refused({"/bodies/1/mass"}, {"--vary", "FIELD=SPEC"});
  expect_sweep_refused({"/bodies/1/mass=5:15"}, {"--vary", "a:b:n"});
  expect_sweep_refused({"/bodies/1/mass=5:15:2.5"}, {"--vary", "whole number"});
  expect_sweep_refused({"/bodies/1/mass=[1,\"a\"]"}, {"--vary", "not a number"});
  expect_sweep_refused({"/bodies/1/mass=gauss(1,2)"}, {"--vary", "normal(mu,sigma)"});
  expect_sweep_refused({"/bodies/1/mass=normal(1,-2)"}, {"--vary", "sigma >= 0"});
  expect_sweep_refused({"/bodies/1/mass=uniform(3,2)"}, {"--vary", "a < b"});
  expect_sweep_refused({"/bodies/1/mass=1:2:3", "/bodies/0/mass=normal(20,1)"}, {"--vary", "cannot be mixed"});
  expect_sweep_refused({"/bodies/1/mass=normal(10,1)"}, {"--samples"}, {}, 1);
  expect_sweep_refused({"/bodies/1/mass=normal(10,1)"}, {"--seed"}, 10, {});
  expect_sweep_refused({"/bodies/1/mass=1:2:3"}, {"--samples"}, 10, {});
  expect_sweep_refused({"/bodies/1/mass=1:2:3", "/bodies/1/mass=[4]"}, {"--vary", "twice"});
}

TEST(Sweep, TheOutputNeverReplacesTheModel) {
  SweepRequest r = rod_mass_grid();
  r.out = kModel;
  EXPECT_THROW(study_sweep_job(r), std::invalid_argument);
  r.out = "";
  r.csv = kModel;
  EXPECT_THROW(study_sweep_job(r), std::invalid_argument);
}

// A state named with a non-ASCII character keeps its name in the sweep's MAT file, as in the plant
// export: both are written as UTF-16 by io/mat_export's one conversion (the sweep's writer once
// turned each such byte into '?')
TEST(Sweep, NonAsciiStateNamesSurviveTheMatExport) {
  SweepTempDir dir;
  std::string text = slurp_file(kModel);
  for (std::size_t at = 0; (at = text.find("rod_pivot", at)) != std::string::npos; at += 14) text.replace(at, 9, "rod_\u03b8iv");
  const std::string model = dir.file("theta.json");
  std::ofstream(model) << text;
  SweepRequest r;
  r.model = model;
  r.vary = {"/bodies/1/mass=5:6:2"};
  r.threads = 1;
  r.mat = dir.file("theta_sweep.mat");
  const SweepJob job = study_sweep_job(r);
  ASSERT_EQ(job.failed, 0);
  const std::string theta = "rod_\u03b8iv";  // the JSON escape read as UTF-8
  const std::string name = std::string("rod_") + "\xce\xb8" + "iv";
  ASSERT_NE(std::find(job.state_names.begin(), job.state_names.end(), name), job.state_names.end()) << theta;
  const MatVariables sweep = read_mat_file(r.mat);
  EXPECT_EQ(sweep.strings.at("state_names"), job.state_names);
  LinearizeRequest lr;
  lr.model = model;
  lr.out = dir.file("plant");
  const LinearizeJob plant = study_linearize_job(lr, study_read_model(model));
  const MatVariables exported = read_mat_file(plant.written[0]);
  EXPECT_EQ(exported.strings.at("state_names"), sweep.strings.at("state_names"));
}

}  // namespace
}  // namespace codyna
