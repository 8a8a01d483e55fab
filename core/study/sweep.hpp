// Parameter studies (issue 22, first slice: one machine): `codyna sweep MODEL.json --vary
// FIELD=SPEC ... --out STUDY.h5`. Every variant is the model file with some numbers replaced
// (FIELD is a JSON pointer into the file, the paths ModelError prints: /bodies/1/mass), read,
// compiled and linearized by the file's "analysis" choices through study_linearize_job; its open-
// loop poles, controllability and, when the study has a linear state feedback (the model's LQR,
// a state_feedback, analysis "controller": "lqr" or a K file), the closed-loop poles
// eig(A - B K) with K designed ONCE on the nominal model and kept (or redesigned per variant with
// redesign = "lqr").
//
// Variant numbering, so that a later split over threads, MPI ranks or Slurm shards gives the same
// file bit for bit: variant i's values depend only on (the --vary specs, the seed, i).
//   grid     every --vary is a grid (a:b:n) or a list ([v1,...]): the full grid, the LAST --vary
//            varying fastest (row-major: i = ((i1 n2 + i2) n3 + i3) ...);
//   random   every --vary is a distribution (normal(mu,sigma), uniform(a,b)): `samples` joint
//            samples, entry k of variant i drawn from a counter-based generator
//            (splitmix64 of (seed, i, k, draw)): no state is carried from one variant to the next.
// A grid mixed with distributions is refused (not defined yet).
//
// A variant that fails (a ModelError, an operating point that does not converge, an LQR that
// cannot be designed, A of another size than the nominal's) is recorded with its status and
// reason; it never stops the study. Results are stored in variant order whatever the order the
// threads finish in. Nothing here prints: progress is a callback.
#pragma once

#include <atomic>
#include <complex>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "study/jobs.hpp"

namespace codyna {

struct SweepRequest {
  OptionStyle style = OptionStyle::Flag;
  std::string model;                        // the model file
  // the model file's text, used instead of reading `model` when not empty (a front end's unsaved
  // document); `model` still names it in messages and is where relative paths start
  std::string model_text;
  std::vector<std::string> vary;            // FIELD=SPEC, in order
  std::optional<long long> samples;         // random studies: the number of variants
  std::optional<std::uint64_t> seed;        // random studies
  int threads = 0;                          // 0: std::thread::hardware_concurrency()
  std::string redesign;                     // "" (K fixed) or "lqr" (designed again per variant)
  std::string out, csv;                     // HDF5 and CSV results; "" = not written
  std::string mat;                          // DIR/NAME.mat + DIR/NAME.m for MATLAB/Octave; "" = not written
  // also a nonlinear closed-loop run per variant (the file's solver settings and initial state),
  // with the same controller as the linear figures: the nominal K as a state feedback about the
  // variant's own operating point, or the LQR designed again with redesign = "lqr"
  bool simulate = false;
  // Resume: with `out`, every finished variant is appended to the journal OUT.partial (one line
  // each, numbers exact), so that a study interrupted (Ctrl+C, a killed job) and started again
  // with the same model file and options skips the variants done and writes the same file as an
  // uninterrupted run. The journal is removed once the results are written; a journal of another
  // study (other file contents or options) is refused. resume = false starts afresh.
  bool resume = true;
  // A shard (Slurm job arrays): shard_count > 0 runs only the variants i with
  // i % shard_count == shard_index and writes them, as a journal, to `out` (no HDF5 there);
  // study_sweep_merge joins the shards into the file the whole study would have written.
  long long shard_index = 0, shard_count = 0;
  // with a shard: its journal is kept in SweepJob::journal and no file is written (an MPI rank's
  // slice; `out`, `csv` and `mat` are then the whole study's, checked but not written, and
  // study_sweep_merge_journals joins the slices)
  bool journal_in_memory = false;
  // with journal_in_memory: the slice's journal is also appended to this file as variants finish
  // (and resumed from it with `resume`), so that an interrupted MPI study started again skips
  // the variants its ranks had done; the file is left for the caller to remove once the whole
  // study's results are written. Empty: in memory only.
  std::string journal_file;
};

// OUT.partial: where the journal of a study writing `out` is kept
std::string study_sweep_journal_path(const std::string& out);

// One --vary, parsed.
struct SweepVary {
  std::string field;               // a JSON pointer into the model file
  std::string spec;                // as given
  enum Kind { Grid, Normal, Uniform } kind = Grid;
  std::vector<double> values;      // Grid: the values (linspace or the list)
  double a = 0, b = 0;             // Normal: mu, sigma; Uniform: a, b
  double nominal = 0;              // the model file's value
};

// The variants' values, a function of the specs, the seed and the index only.
struct SweepPlan {
  std::vector<SweepVary> vary;
  bool random = false;
  std::uint64_t seed = 0;
  long long count = 0;
  std::vector<double> values(long long i) const;  // one per --vary
};

// Parses the --vary texts against the model file's JSON (the field must hold a number) and the
// sampling options; std::invalid_argument naming the option for anything wrong.
SweepPlan study_sweep_plan(const SweepRequest& r, const nlohmann::json& model_file);

enum class SweepStatus : int {
  Ok = 0,
  ModelError = 1,       // the variant's model is refused (ModelError)
  NotConverged = 2,     // its operating point search did not converge (ConvergenceError)
  Refused = 3,          // a choice cannot be applied to it (std::invalid_argument: an LQR not stabilizable)
  Failed = 4,           // any other failure
  SizeDiffers = 5,      // its A, B, C, D are not the nominal's sizes
};
const char* to_string(SweepStatus s);

struct SweepVariant {
  std::vector<double> values;                 // one per --vary
  SweepStatus status = SweepStatus::Failed;
  std::string reason;                         // "" when Ok
  Eigen::MatrixXd A, B, C, D, K;              // continuous plant; K only when redesigned
  Eigen::VectorXcd open_poles, closed_poles;  // sorted by real part, then imaginary part
  double open_max_real = 0, closed_max_real = 0;
  bool stable = false;                        // closed loop (no closed loop: open loop), asymptotically
  bool open_stable = false;                   // the open loop, asymptotically (analysis/stability.hpp)
  int uncontrollable = 0;                     // modes the Plant/In inputs cannot move
  std::string uncontrollable_text;            // study_describe_modes of them
  // simulate: the run's status (-1 not run, 0 reached t_end, 1 the run failed, 2 it could not be
  // set up), its reason, the time reached, the largest |u| of each Plant/In and the final error
  // (the largest |y - target| over Plant/Out at the last sample: the reference there, or y0)
  int sim_status = -1;
  std::string sim_reason;
  double sim_t_end = 0, final_error = 0;
  Eigen::VectorXd peak_input;
  // simulate, per Plant/Out (docs/parameter-studies.md, "Figures of merit"): e(t) = y(t) - target,
  // E = max |e| over the run; overshoot = 100 max(0, max(-s e)) / E in % (s the sign of e where
  // |e| = E), settling time = when |e| enters the band 0.02 E for good (linear between samples;
  // NaN when the last sample is outside it); per Plant/In: the seconds spent at a limit (min or
  // max, summed over the output intervals, as simulate's saturation report counts them)
  Eigen::VectorXd overshoot, settling_time, saturation_time;
};

struct SweepJob {
  std::string model_name, model_file;
  SweepPlan plan;
  std::vector<std::string> state_names, input_names, output_names;
  std::string operating_point, method;
  bool closed_loop = false;                   // a state feedback closes the loop
  std::string controller;                     // what the closed loop is ("the model file's lqr controller, K fixed")
  bool redesigned = false;
  bool simulated = false;
  Eigen::MatrixXd K;                          // the nominal gain (nu x nx), when closed_loop
  Eigen::VectorXcd nominal_closed_poles, nominal_open_poles;
  std::vector<SweepVariant> variants;
  std::vector<std::string> notes, warnings;
  std::vector<std::string> written;
  long long resumed = 0;                      // variants read back from the journal
  long long shard_index = 0, shard_count = 0;  // a shard's (shard_count 0: the whole study)
  std::string journal;                        // a shard's journal, with journal_in_memory
  bool in_shard(long long i) const { return shard_count == 0 || i % shard_count == shard_index; }
  // summary
  long long failed = 0, stable = 0;
  long long worst = -1;                       // the completed variant with the largest max real part
  long long sim_completed = 0;                // simulate: runs that reached t_end
  long long largest_input = -1;               // simulate: the run with the largest peak |u|
};

struct SweepProgress {
  std::function<void(long long done, long long total)> done;  // called from the workers (serialised)
  const std::atomic<bool>* cancel = nullptr;                  // stops taking new variants
};

// The whole `codyna sweep`: the plan, the nominal model (its linearization and controller, which
// must work), every variant on `threads` workers, and the files (each output checked against the
// model file before any work, written through a temporary file renamed into place).
SweepJob study_sweep_job(const SweepRequest& r, const StudyMessages& tell = {}, const SweepProgress& progress = {});

// A shard K of N (SweepRequest::shard_index, shard_count) as a front end is given it, read once
// here for every front end (core/study/sweep_shard.cpp; issue 22): `codyna sweep --shard` and the
// Python module's Study.sweep(shard=). Messages name the option in `style` (--shard, shard).
struct SweepShard {
  long long index = 0, count = 0;
};
// "K/N" (whole numbers, 0 <= K < N, K counting from 0) or "slurm": a Slurm job array task's,
// K = SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN (0 when unset), N = SLURM_ARRAY_TASK_COUNT.
// Throws std::invalid_argument: not K/N; not in a job array (the variables missing, named); a
// variable that is not a whole number; an array whose ID - MIN is not below COUNT (a step or gaps).
SweepShard study_parse_shard(const std::string& text, OptionStyle style);
// (K, N) checked: 0 <= K < N, else std::invalid_argument naming the option and `given` (as the
// user wrote the value: "2/2", "(2, 2)").
SweepShard study_check_shard(long long index, long long count, OptionStyle style, const std::string& given);
// How many of a study's n variants shard `index` of `count` runs (the i with i % count == index;
// count 0: the whole study, n)
long long sweep_shard_size(long long n, long long index, long long count);
// A shard's job with only its own variants, in the study's order: `indices` gets their numbers
// in the whole study, and worst / largest_input become positions among them. A whole study's
// job is returned as it is (indices empty: 0 .. n-1).
SweepJob study_sweep_own_variants(SweepJob&& job, std::vector<long long>& indices);

// `codyna sweep-merge`: the shards' journals (every variant in one of them, all of the same study:
// the same model file bytes and options) joined and written to outputs.out / csv / mat exactly as
// the whole study run at once writes them (the nominal model is compiled again, no variant is).
SweepJob study_sweep_merge(const std::vector<std::string>& shards, const SweepRequest& outputs,
                           const StudyMessages& tell = {});

// The same from journals in memory (SweepJob::journal of shards run with journal_in_memory: the
// MPI ranks'); names[k] names journals[k] in errors ("rank 1").
SweepJob study_sweep_merge_journals(const std::vector<std::string>& journals, const std::vector<std::string>& names,
                                    const SweepRequest& outputs, const StudyMessages& tell = {});

// Writes the HDF5 results / the CSV (each atomically; see docs/parameter-studies.md).
void study_write_sweep_hdf5(const SweepJob& job, const std::string& path);
void study_write_sweep_csv(const SweepJob& job, const std::string& path);
// DIR/NAME.mat (MAT v5: the A, B, C, D stacks as nx x nx x n arrays, values, status, reason, poles,
// K, names) and DIR/NAME.m, which loads it and builds `sys` over the completed variants `ok`
// (MATLAB: one ss array; Octave, whose ss has no array dimension: a cell array of ss). NAME must
// be a MATLAB identifier.
void study_write_sweep_mat(const SweepJob& job, const std::string& mat_path);

// The summary `codyna sweep` prints.
std::string study_sweep_summary(const SweepJob& job);

}  // namespace codyna
