// Parameter studies (docs/parameter-studies.md; threads, Slurm shards and MPI ranks): `codyna sweep MODEL.json --vary
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

#include "io/sweep_data.hpp"
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

// Parses the --vary texts against the model file's JSON (the field must hold a number) and the
// sampling options; std::invalid_argument naming the option for anything wrong.
SweepPlan study_sweep_plan(const SweepRequest& r, const nlohmann::json& model_file);
// true when SPEC (the text after FIELD=) names a distribution, normal(...) or uniform(...), as
// the plan reads it: a study with one needs samples and a seed
bool study_sweep_spec_is_random(const std::string& spec);

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

// Writes the HDF5 results / the CSV (each atomically; see docs/parameter-studies.md): the file
// formats are io/sweep_files.hpp's, these are the front ends' door to them.
void study_write_sweep_hdf5(const SweepJob& job, const std::string& path);
void study_write_sweep_csv(const SweepJob& job, const std::string& path);
// DIR/NAME.mat (MAT v5: the A, B, C, D stacks as nx x nx x n arrays, values, status, reason, poles,
// K, names) and DIR/NAME.m, which loads it and builds `sys` over the completed variants `ok`
// (MATLAB: one ss array; Octave, whose ss has no array dimension: a cell array of ss). NAME must
// be a MATLAB identifier.
void study_write_sweep_mat(const SweepJob& job, const std::string& mat_path);
// A front end's Save: the format from the suffix (.h5 / .hdf5, .csv, .mat), each output checked
// against the study's model file as the writers check it; any other suffix is refused naming them.
void study_save_sweep(const SweepJob& job, const std::string& path);

// The summary `codyna sweep` prints.
std::string study_sweep_summary(const SweepJob& job);

}  // namespace codyna
