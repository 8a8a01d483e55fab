// codyna sweep: flags -> a SweepRequest, one study call (study_sweep_job), the progress line and
// the printed summary. The variants, their numbering and the files live in core/study/sweep.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "study/sweep.hpp"
#include "sweep_mpi.hpp"

namespace codyna::cli {

namespace {

struct SweepArgs {
  std::string model, out, csv, mat, redesign, shard;
  std::vector<std::string> vary;
  long long samples = 0;
  std::uint64_t seed = 0;
  int threads = 0;
  bool quiet = false, simulate = false, restart = false;
  const CLI::App* cmd = nullptr;
};

// returns the exit code under mpirun (built with MPI), -1 when run here as one process
int run_sweep(const SweepArgs& a) {
  const int processes = launched_processes();
  if (processes > 1 && !built_with_mpi())
    throw std::invalid_argument("started as one of " + std::to_string(processes) +
                                " processes by an MPI launcher (OMPI_COMM_WORLD_SIZE or PMI_SIZE), but this codyna was built "
                                "without MPI: each process would run the whole study and write the same files. Run it "
                                "without mpirun, build codyna with OpenMPI (Debian: libopenmpi-dev), or split the study with "
                                "--shard K/N and codyna sweep-merge");
  if (processes > 1 && !a.shard.empty())
    throw std::invalid_argument("--shard " + a.shard + ": under mpirun the ranks share the variants already; give one or the other");
  SweepRequest r;
  r.model = a.model;
  r.vary = a.vary;
  if (given(a.cmd, "--samples")) r.samples = a.samples;
  if (given(a.cmd, "--seed")) r.seed = a.seed;
  r.threads = a.threads;
  r.redesign = a.redesign;
  r.out = a.out;
  r.csv = a.csv;
  r.mat = a.mat;
  r.simulate = a.simulate;
  if (!a.shard.empty()) {
    // K/N, or "slurm": SLURM_ARRAY_TASK_ID (from SLURM_ARRAY_TASK_MIN) of SLURM_ARRAY_TASK_COUNT
    const SweepShard shard = study_parse_shard(a.shard, OptionStyle::Flag);
    r.shard_index = shard.index;
    r.shard_count = shard.count;
  }
  r.resume = !a.restart;
  SweepProgress progress;
  const bool bar = !a.quiet && isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  bool bar_open = false;
  auto last = start - std::chrono::seconds(1);
  if (bar)
    progress.done = [&](long long done, long long total) {
      const auto now = std::chrono::steady_clock::now();
      if (done < total && now - last < std::chrono::milliseconds(100)) return;
      last = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const double eta = done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(total - done) : 0.0;
      std::fprintf(stderr, "\r%lld/%lld variants  %3d%%  %.1f s, ETA %.1f s   ", done, total,
                   static_cast<int>(100 * done / total), elapsed, eta);
      std::fflush(stderr);
      bar_open = true;
    };
  const auto tell = [&](const StudyMessage& m) {
    if (bar_open) std::fprintf(stderr, "\n");
    bar_open = false;
    print_message(m);
  };
  const auto print = [&](const SweepJob& job) {
    if (bar_open) std::fprintf(stderr, "\n");
    bar_open = false;
    std::cout << study_sweep_summary(job);
    for (const std::string& f : job.written) std::cout << "wrote " << f << "\n";
  };
  if (processes > 1) {
    const int code = sweep_over_mpi(r, tell, progress, print);
    if (bar_open) std::fprintf(stderr, "\n");
    return code;
  }
  print(study_sweep_job(r, tell, progress));
  return -1;
}

}  // namespace

void add_sweep(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand("sweep", "Parameter study: linearize (and close the loop of) every variant of a model over a grid or random samples; one machine's threads, MPI ranks (mpirun) or Slurm shards");
  cmd->add_option("model", a->model, "model file (JSON)")->required();
  cmd->add_option("--vary", a->vary,
                  "FIELD=SPEC (repeatable): FIELD a JSON pointer into the model file (/bodies/1/mass), SPEC a:b:n, "
                  "[v1,v2,...], normal(mu,sigma) or uniform(a,b)")
      ->required();
  cmd->add_option("--samples", a->samples, "random studies: the number of variants");
  cmd->add_option("--seed", a->seed, "random studies: the seed (variant i depends only on the specs, the seed and i)");
  cmd->add_option("--threads", a->threads, "worker threads (default: every core)");
  cmd->add_option("--redesign", a->redesign, "lqr: design the study's LQR again for every variant (default: K of the nominal model, fixed)");
  cmd->add_option("--out", a->out, "results (HDF5)")->required();
  cmd->add_option("--csv", a->csv, "the per-variant figures as CSV");
  cmd->add_option("--mat", a->mat, "DIR/NAME.mat + DIR/NAME.m: the stacks for MATLAB/Octave, NAME.m builds the ss array over the variants");
  cmd->add_flag("--simulate", a->simulate, "also run every variant's nonlinear closed loop (the file's solver settings): status, peak |u|, final error, overshoot, settling time, time at an input limit");
  cmd->add_flag("--restart", a->restart, "ignore the journal of an interrupted run (OUT.partial) and run every variant again");
  cmd->add_option("--shard", a->shard, "K/N: run only the variants i with i % N = K and write them to --out (a shard; slurm: from SLURM_ARRAY_TASK_ID/COUNT); codyna sweep-merge joins the shards");
  cmd->add_flag("--quiet", a->quiet, "no progress line");
  a->cmd = cmd;
  cmd->footer(
      "MPI: mpirun -np N codyna sweep ... shares the variants among N ranks (variant i on rank i % N, one thread each "
      "unless --threads); rank 0 writes the one result file, the single-process run's bit for bit "
      "(docs/parameter-studies.md)." +
      std::string(built_with_mpi() ? "" : " This codyna was built without MPI: under mpirun it refuses to run."));
  cmd->callback([a] {
    int mpi = -1;
    const int code = run_guarded([&] { mpi = run_sweep(*a); });
    set_exit_code(code == 0 && mpi >= 0 ? mpi : code);
  });

  auto m = std::make_shared<SweepArgs>();
  auto shards = std::make_shared<std::vector<std::string>>();
  auto* merge = app.add_subcommand("sweep-merge", "Join the shards of a codyna sweep --shard K/N into the results the whole study writes");
  merge->add_option("shards", *shards, "the shards' files")->required();
  merge->add_option("--out", m->out, "results (HDF5)")->required();
  merge->add_option("--csv", m->csv, "the per-variant figures as CSV");
  merge->add_option("--mat", m->mat, "DIR/NAME.mat + DIR/NAME.m for MATLAB/Octave");
  merge->callback([m, shards] {
    set_exit_code(run_guarded([&] {
      if (launched_processes() > 1)
        throw std::invalid_argument("sweep-merge: started as one of " + std::to_string(launched_processes()) +
                                    " processes by an MPI launcher; they would all write the same files: run it once, "
                                    "without mpirun");
      SweepRequest outputs;
      outputs.out = m->out;
      outputs.csv = m->csv;
      outputs.mat = m->mat;
      outputs.threads = 1;
      const SweepJob job = study_sweep_merge(*shards, outputs, print_message);
      std::cout << study_sweep_summary(job);
      for (const std::string& f : job.written) std::cout << "wrote " << f << "\n";
    }));
  });
}

}  // namespace codyna::cli
