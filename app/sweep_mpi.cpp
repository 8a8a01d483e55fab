#include "sweep_mpi.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common.hpp"
#include "model/errors.hpp"

#ifdef CODYNA_WITH_MPI
#include <mpi.h>
#endif

namespace codyna::cli {

int launched_processes() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* v = std::getenv(name);
    if (v && std::atoi(v) > 1) return std::atoi(v);
  }
  return 1;
}

#ifndef CODYNA_WITH_MPI

bool built_with_mpi() { return false; }

int sweep_over_mpi(const SweepRequest&, const StudyMessages&, const SweepProgress&, const std::function<void(const SweepJob&)>&) {
  throw std::logic_error("sweep_over_mpi: codyna was built without MPI");
}

#else

bool built_with_mpi() { return true; }

namespace {

// messages of up to 2^62 bytes, in pieces an int count can hold
constexpr long long kPiece = 1LL << 30;
constexpr int kTagHead = 1, kTagBody = 2;

void send_text(const std::string& text, int code) {
  const long long head[2] = {code, static_cast<long long>(text.size())};
  MPI_Send(head, 2, MPI_LONG_LONG, 0, kTagHead, MPI_COMM_WORLD);
  for (long long at = 0; at < static_cast<long long>(text.size()); at += kPiece)
    MPI_Send(text.data() + at, static_cast<int>(std::min<long long>(kPiece, static_cast<long long>(text.size()) - at)), MPI_CHAR, 0,
             kTagBody, MPI_COMM_WORLD);
}

std::string receive_text(int from, int& code) {
  long long head[2] = {0, 0};
  MPI_Recv(head, 2, MPI_LONG_LONG, from, kTagHead, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  code = static_cast<int>(head[0]);
  std::string text(static_cast<std::size_t>(head[1]), '\0');
  for (long long at = 0; at < head[1]; at += kPiece)
    MPI_Recv(text.data() + at, static_cast<int>(std::min<long long>(kPiece, head[1] - at)), MPI_CHAR, from, kTagBody,
             MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return text;
}

// the exit code of an exception, its message in `what` (run_guarded's codes)
int failure(std::string& what) {
  try {
    throw;
  } catch (const ModelError& e) {
    what = e.what();
    return 1;
  } catch (const std::invalid_argument& e) {
    what = e.what();
    return 1;
  } catch (const std::exception& e) {
    what = e.what();
    return 2;
  }
}

// rank k of N appends its variants to OUT.partial.<k>of<N> (resumed from it when the study is
// started again on N ranks)
std::string rank_journal(const std::string& out, int rank, int size) {
  return study_sweep_journal_path(out) + "." + std::to_string(rank) + "of" + std::to_string(size);
}

// the ranks' journals next to `out` (OUT.partial.<k>of<M>): rank k and M of each
struct RankJournal {
  std::filesystem::path path;
  int rank = 0, size = 0;
};
std::vector<RankJournal> rank_journals(const std::string& out) {
  std::vector<RankJournal> found;
  const std::filesystem::path base(study_sweep_journal_path(out));
  const std::filesystem::path dir = base.parent_path().empty() ? std::filesystem::path(".") : base.parent_path();
  const std::string prefix = base.filename().string() + ".";
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string tail = name.substr(prefix.size());  // <k>of<M>
    const std::size_t of = tail.find("of");
    if (of == std::string::npos || of == 0 || of + 2 >= tail.size() ||
        tail.find_first_not_of("0123456789") != of || tail.find_first_not_of("0123456789", of + 2) != std::string::npos)
      continue;
    found.push_back({e.path(), std::stoi(tail.substr(0, of)), std::stoi(tail.substr(of + 2))});
  }
  return found;
}

}  // namespace

int sweep_over_mpi(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress,
                   const std::function<void(const SweepJob&)>& print) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);  // the workers never call MPI
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);

  // this rank's slice, into a journal in memory
  std::string text;
  int code = 0;
  try {
    SweepRequest mine = r;
    mine.shard_index = rank;
    mine.shard_count = size;
    mine.journal_in_memory = true;
    if (mine.threads == 0) mine.threads = 1;  // one process per core: mpirun binds each rank to one
    if (!r.out.empty()) {
      // an interrupted study on another number of ranks: its journals hold the variants done
      if (r.resume)
        for (const RankJournal& j : rank_journals(r.out))
          if (j.size != size)
            throw std::invalid_argument(j.path.string() + ": the journal of rank " + std::to_string(j.rank) + " of an interrupted run on " +
                                        std::to_string(j.size) + " ranks: start it again with mpirun -np " + std::to_string(j.size) +
                                        " to resume it, or give --restart to run every variant again on " + std::to_string(size));
      mine.journal_file = rank_journal(r.out, rank, size);
    }
    SweepProgress scaled;
    scaled.cancel = progress.cancel;
    if (rank == 0 && progress.done)  // rank 0's share of the slices, scaled to the whole study
      scaled.done = [&](long long done, long long total) { progress.done(std::min(total, done * size), total); };
    const SweepJob job = study_sweep_job(mine, rank == 0 ? tell : StudyMessages{}, scaled);
    text = job.journal;
  } catch (...) {
    code = failure(text);
  }

  int result = 0;
  if (rank != 0) {
    send_text(text, code);
  } else {
    std::vector<std::string> journals(static_cast<std::size_t>(size)), names(journals.size());
    std::vector<int> codes(journals.size());
    journals[0] = std::move(text);
    codes[0] = code;
    for (int k = 0; k < size; ++k) names[static_cast<std::size_t>(k)] = "rank " + std::to_string(k);
    for (int k = 1; k < size; ++k) journals[static_cast<std::size_t>(k)] = receive_text(k, codes[static_cast<std::size_t>(k)]);
    // the failures: said once when every rank failed alike (a bad option), else rank by rank
    std::vector<int> failed;
    for (int k = 0; k < size; ++k)
      if (codes[static_cast<std::size_t>(k)] != 0) failed.push_back(k);
    if (!failed.empty()) {
      const bool alike = static_cast<int>(failed.size()) == size &&
                         std::all_of(journals.begin(), journals.end(), [&](const std::string& j) { return j == journals[0]; });
      for (int k : failed) {
        std::cerr << "codyna: error: " << (alike ? std::string() : "rank " + std::to_string(k) + " of " + std::to_string(size) + ": ")
                  << journals[static_cast<std::size_t>(k)] << "\n";
        result = std::max(result, codes[static_cast<std::size_t>(k)]);
        if (alike) break;
      }
      if (!alike) std::cerr << "codyna: error: " << failed.size() << " of " << size << " ranks failed; no results written\n";
    } else {
      SweepRequest outputs = r;
      outputs.threads = 1;
      result = run_guarded([&] { print(study_sweep_merge_journals(journals, names, outputs, tell)); });
      if (result == 0 && !r.out.empty())  // the results are written: the ranks' journals (any run's) have served
        for (const RankJournal& j : rank_journals(r.out)) {
          std::error_code ec;
          std::filesystem::remove(j.path, ec);
        }
    }
  }
  MPI_Bcast(&result, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Finalize();
  return result;
}

#endif

}  // namespace codyna::cli
