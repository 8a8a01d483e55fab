#include "study/sweep.hpp"
#include "study/sweep_variant.hpp"

#include "analysis/stability.hpp"


#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "io/output_guard.hpp"
#include "io/sweep_files.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/tools.hpp"

namespace codyna {
namespace {

using namespace sweep_detail;

struct Names {
  OptionStyle style;
  std::string operator()(const std::string& dashed) const { return option_name(style, dashed); }
};

std::string fmt(double x) {
  std::ostringstream os;
  os << std::setprecision(10) << x;
  return os.str();
}

// the first line of a study's journal: what makes its variants what they are
std::string journal_head(const SweepRequest& r, const std::string& model_bytes, long long count) {
  std::uint64_t h = sweep_hash_text(0xcbf29ce484222325ULL, model_bytes);
  for (const std::string& v : r.vary) h = sweep_hash_text(h, v);
  h = sweep_hash_text(h, r.seed ? std::to_string(*r.seed) : "-");
  h = sweep_hash_text(h, r.samples ? std::to_string(*r.samples) : "-");
  h = sweep_hash_text(h, r.redesign);
  h = sweep_hash_text(h, r.simulate ? "simulate" : "");
  h = sweep_hash_text(h, CODYNA_VERSION);
  char key[17];
  std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(h));
  return std::string("codyna sweep journal 1 ") + key + " " + std::to_string(count) + "\n";
}

// the second line: the request itself, so that sweep-merge needs only the shards
std::string journal_request(const SweepRequest& r) {
  nlohmann::json j = {{"model", r.model}, {"vary", r.vary}, {"redesign", r.redesign}, {"simulate", r.simulate}};
  j["samples"] = r.samples ? nlohmann::json(*r.samples) : nlohmann::json();
  j["seed"] = r.seed ? nlohmann::json(std::to_string(*r.seed)) : nlohmann::json();
  return "request " + j.dump() + "\n";
}

}  // namespace

std::string study_sweep_journal_path(const std::string& out) { return out + ".partial"; }

void study_write_sweep_hdf5(const SweepJob& job, const std::string& path) { write_sweep_hdf5(job, path); }
void study_write_sweep_csv(const SweepJob& job, const std::string& path) { write_sweep_csv(job, path); }
void study_write_sweep_mat(const SweepJob& job, const std::string& mat_path) { write_sweep_mat(job, mat_path); }

void study_save_sweep(const SweepJob& job, const std::string& path) {
  std::string suffix = std::filesystem::path(path).extension().string();
  std::transform(suffix.begin(), suffix.end(), suffix.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (suffix == ".h5" || suffix == ".hdf5") write_sweep_hdf5(job, path);
  else if (suffix == ".csv") write_sweep_csv(job, path);
  else if (suffix == ".mat") write_sweep_mat(job, path);
  else throw std::invalid_argument(path + ": choose .h5 (HDF5), .csv or .mat (MATLAB/Octave)");
}

// ------------------------------------------------------------------ the job

namespace {
// `merging`: study_sweep_merge resumes the whole study from the journal it joined, which is not
// news to its caller: no "resuming" note then
SweepJob sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress, bool merging);
}  // namespace

SweepJob study_sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress) {
  return sweep_job(r, tell, progress, false);
}

long long sweep_shard_size(long long n, long long index, long long count) {
  if (count <= 0) return n;
  return index < n ? (n - index + count - 1) / count : 0;
}

namespace {

using SweepNote = std::function<void(const std::string&)>;

// the request's options and its output files, checked before any work (a shard writes its own file
// only; an MPI rank's slice, `memory`, checks the whole study's)
void check_sweep_request(const SweepRequest& r, bool shard, bool memory) {
  const Names opt{r.style};
  if (r.redesign != "" && r.redesign != "lqr")
    throw std::invalid_argument(opt("redesign") + " " + r.redesign + ": expected lqr");
  if (r.threads < 0) throw std::invalid_argument(opt("threads") + ": expected 1 or more (0: every core)");
  if (shard) {
    if (r.shard_index < 0 || r.shard_index >= r.shard_count)
      throw std::invalid_argument(opt("shard") + " " + std::to_string(r.shard_index) + "/" + std::to_string(r.shard_count) +
                                  ": expected K/N with 0 <= K < N");
  }
  if (shard && !memory) {
    if (r.out.empty()) throw std::invalid_argument(opt("shard") + ": give " + opt("out") + " (the shard's file)");
    if (!r.csv.empty() || !r.mat.empty())
      throw std::invalid_argument(opt("shard") + ": a shard writes its variants only (" + opt("out") +
                                  "); codyna sweep-merge writes the results, CSV and MAT files");
    if (study_same_file(r.out, r.model))
      throw std::invalid_argument(r.out + ": this is the input file " + r.model + "; choose another name");
    if (!is_sweep_journal(r.out))
      throw std::invalid_argument(r.out + ": exists and is not a shard of codyna sweep; codyna never replaces a file it "
                                  "did not write: remove it or choose another name");
  }
  // the outputs, before any work
  if (!r.out.empty() && (!shard || memory)) study_guard_output(r.out, OutputKind::ResultsHdf5, {r.model});
  if (!r.csv.empty()) {
    guard_output(r.csv, OutputKind::SweepCsv, {r.model});
    if (!r.out.empty() && (r.csv == r.out || study_same_file(r.csv, r.out)))
      throw std::invalid_argument(opt("csv") + " " + r.csv + ": the same file as " + opt("out"));
  }
  if (!r.mat.empty()) {
    const std::filesystem::path p(r.mat);
    if (p.extension() != ".mat") throw std::invalid_argument(opt("mat") + " " + r.mat + ": expected DIR/NAME.mat");
    if (study_matlab_identifier(p.stem().string()) != p.stem().string())
      throw std::invalid_argument(opt("mat") + " " + r.mat + ": '" + p.stem().string() + "' is not a MATLAB identifier (try " +
                                  study_matlab_identifier(p.stem().string()) + ".mat)");
    if (!p.parent_path().empty()) {
      std::error_code ec;
      std::filesystem::create_directories(p.parent_path(), ec);
      if (ec) throw std::runtime_error(p.parent_path().string() + ": cannot create the folder: " + ec.message());
    }
    study_guard_output(r.mat, OutputKind::PlantMat, {r.model});
    study_guard_output((p.parent_path() / (p.stem().string() + ".m")).string(), OutputKind::PlantScript, {r.model});
  }
}

// the nominal model's linearization and controller (they must work, or there is no study): what
// every variant shares (c) and the job's nominal figures; true when the study's controller is a file
bool sweep_nominal(Context& c, std::optional<Model>& structure, SweepJob& job, const SweepRequest& r,
                   const nlohmann::json& file, const ModelSpec& nominal_spec, const SweepNote& note) {
  const Names opt{r.style};
  c.request = &r;
  c.plan = &job.plan;
  c.file = &file;
  c.nominal = &nominal_spec;
  for (const SweepVary& v : job.plan.vary) c.pointers.emplace_back(v.field);
  plan_edits(c, job.plan.vary);
  c.linearize.style = r.style;
  c.linearize.model = r.model;
  c.linearize.modes = false;  // a variant records its poles and uncontrollable modes only
  const LinearizeJob nominal = study_linearize_job(c.linearize, nominal_spec);
  const Model& m = nominal.model;
  if (const std::optional<NumbersChanged> what = numbers_changed(job.plan.vary); what && !c.whole_file) {
    structure = study_linearize_structure(c.linearize, nominal_spec);
    c.structure = &*structure;
    c.changed = *what;
  }
  const StudySpec& s = m.spec.analysis;
  if (s.discrete != 0)
    throw std::invalid_argument(r.model + ": /analysis/discrete: a sweep linearizes in continuous time only (not built yet: "
                                "discrete studies)");
  const LinearSystem& sys = nominal.linearization.lin.system;
  c.nx = sys.nx();
  c.nu = sys.nu();
  c.ny = sys.ny();
  c.state_names = sys.state_names;
  job.state_names = sys.state_names;
  job.input_names = sys.input_names;
  job.output_names = sys.output_names;
  job.operating_point = nominal.linearization.op.kind;
  job.method = nominal.method;
  job.nominal_open_poles = poles_of(sys.A);
  const bool model_controller = s.controller == "model" && m.spec.controller.type != ControllerType::None;
  const bool is_lqr = s.controller == "lqr" || (model_controller && m.spec.controller.type == ControllerType::Lqr);
  if (model_controller && m.spec.controller.operating_point != s.operating_point)
    throw std::invalid_argument(r.model + ": the model file's controller is designed at its " +
                                m.spec.controller.operating_point + " point, the study linearizes at " + s.operating_point +
                                ": a sweep closes the loop where it linearizes (set /analysis/operating_point to \"" +
                                m.spec.controller.operating_point + "\")");
  if (!r.redesign.empty() && !is_lqr)
    throw std::invalid_argument(opt("redesign") + " lqr: the study's controller is not an LQR (the model file's "
                                "controller of type lqr, or \"controller\": \"lqr\" in its analysis section)");
  if (s.controller != "none" && (model_controller || s.controller != "model")) {
    const StudySimulation setup = study_simulation(m);
    const Eigen::MatrixXd* g = setup.controller ? setup.controller->gain() : nullptr;
    if (g && g->rows() == c.nu && g->cols() == c.nx) {
      c.closed_loop = true;
      c.K = *g;
      c.redesign = r.redesign == "lqr";
      job.closed_loop = true;
      job.K = *g;
      job.redesigned = c.redesign;
      job.controller = setup.controller_source + (c.redesign ? ", designed again for every variant"
                                                             : ", K designed on the nominal model and fixed");
      job.nominal_closed_poles = poles_of(sys.A - sys.B * c.K);
    } else if (setup.controller) {
      note("the study's controller (" + setup.controller_source + ") is not a state feedback: open-loop figures only");
    }
  }
  if (!job.closed_loop && job.controller.empty()) job.controller = "none (open loop)";
  if (r.simulate) {
    c.simulate = true;
    job.simulated = true;
    // K fixed: the file's own LQR (or the study's) would be designed again on each variant; the
    // nominal K is handed to the run as the model file's state feedback instead
    if (c.closed_loop && !c.redesign && (is_lqr || (model_controller && m.spec.controller.type == ControllerType::StateFeedback))) {
      c.replace_controller = true;
      c.controller_point = model_controller ? m.spec.controller.operating_point : s.operating_point;
    }
  }
  return s.controller == "file";
}

// the journal of the study's variants: those an interrupted run of this very study finished (have)
// and the file every finished variant is appended to
struct SweepJournalFile {
  std::vector<char> have;
  std::ofstream out;
  std::string path;
};

void open_sweep_journal(SweepJournalFile& jf, SweepJob& job, const SweepRequest& r, const std::string& model_bytes,
                        bool shard, bool memory, bool merging, const SweepNote& note) {
  const long long n = job.plan.count;
  jf.have.assign(static_cast<std::size_t>(n), 0);
  job.shard_index = shard ? r.shard_index : 0;
  job.shard_count = shard ? r.shard_count : 0;
  jf.path =
      memory ? r.journal_file : r.out.empty() ? std::string() : shard ? r.out : study_sweep_journal_path(r.out);
  if (memory) job.journal = journal_head(r, model_bytes, n) + journal_request(r);
  if (!jf.path.empty()) {
    const std::string head = journal_head(r, model_bytes, n), request_line = journal_request(r);
    std::error_code ec;
    if (r.resume && std::filesystem::exists(jf.path, ec)) {
      std::ifstream in(jf.path, std::ios::binary);
      std::string line;
      if (!std::getline(in, line) || line + "\n" != head)
        throw std::invalid_argument(jf.path + ": the journal of another study (other model file contents or options) "
                                    "is in the way: remove it to start afresh");
      std::string kept = head + request_line;
      while (std::getline(in, line)) {
        if (in.eof()) break;  // a last line without its newline was cut by the interruption
        if (line.rfind("request ", 0) == 0) continue;
        try {
          const nlohmann::json j = nlohmann::json::parse(line);
          const long long i = j.at("i").get<long long>();
          if (i < 0 || i >= n || jf.have[static_cast<std::size_t>(i)] || !job.in_shard(i)) continue;
          SweepVariant v = sweep_journal_variant(j);
          if (v.values != job.plan.values(i)) continue;
          job.variants[static_cast<std::size_t>(i)] = std::move(v);
          jf.have[static_cast<std::size_t>(i)] = 1;
          ++job.resumed;
          kept += line + "\n";
          if (memory) job.journal += line + "\n";
        } catch (const std::exception&) {
          // a damaged line: that variant runs again
        }
      }
      in.close();
      write_file_atomically(jf.path, kept);  // without the damaged lines, then appended to
      if (job.resumed > 0 && !shard && !merging)
        note("resuming: " + std::to_string(job.resumed) + " of " + std::to_string(n) + " variants were done (" +
             jf.path + ")");
      if (job.resumed > 0 && shard) {
        const long long slice = sweep_shard_size(n, r.shard_index, r.shard_count);
        note("resuming: " + std::to_string(job.resumed) + " of the " + std::to_string(slice) + " variants of slice " +
             std::to_string(r.shard_index) + "/" + std::to_string(r.shard_count) + " were done (" + jf.path + ")");
      }
    } else {
      if (!is_sweep_journal(jf.path))
        throw std::invalid_argument(jf.path + ": exists and is not the journal of a codyna sweep; codyna never "
                                    "replaces a file it did not write: remove it or choose another --out");
      write_file_atomically(jf.path, head + request_line);
    }
    jf.out.open(jf.path, std::ios::binary | std::ios::app);
    if (!jf.out) throw std::runtime_error(jf.path + ": cannot append to the journal");
  }
}

// the variants not done yet, on `threads` threads, each appended to the journal as it finishes
void run_sweep_variants(const Context& c, SweepJob& job, SweepJournalFile& jf, unsigned threads, bool memory,
                        const SweepProgress& progress) {
  const SweepRequest& r = *c.request;
  const long long n = job.plan.count;
  std::atomic<long long> next{0}, done{job.resumed};
  std::mutex report;
  std::exception_ptr fatal;
  const auto worker = [&] {
    for (;;) {
      if (progress.cancel && progress.cancel->load()) return;
      const long long i = next.fetch_add(1);
      if (i >= n) return;
      if (jf.have[static_cast<std::size_t>(i)] || !job.in_shard(i)) continue;
      SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      try {
        run_variant(c, i, v);
      } catch (...) {  // not a failure of the variant (out of memory): the study stops
        const std::lock_guard<std::mutex> lock(report);
        if (!fatal) fatal = std::current_exception();
        next.store(n);
        return;
      }
      const std::string line = jf.out.is_open() || memory ? sweep_journal_line(i, v) : std::string();
      const long long d = done.fetch_add(1) + 1;
      const std::lock_guard<std::mutex> lock(report);
      if (jf.out.is_open()) jf.out << line << std::flush;
      if (memory) job.journal += line;
      if (progress.done) progress.done(d, n);
    }
  };
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  if (fatal) std::rethrow_exception(fatal);
  const long long expected = sweep_shard_size(n, r.shard_index, r.shard_count);
  if (done.load() < expected) throw StudyCancelled("the sweep was cancelled after " + std::to_string(done.load()) + " of " +
                                            std::to_string(expected) + " variants");

}

// the summary: the worst case is the completed variant with the largest max real part (first on ties)
void count_sweep_variants(SweepJob& job) {
  double worst = -std::numeric_limits<double>::infinity();
  for (long long i = 0; i < job.plan.count; ++i) {
    if (!job.in_shard(i)) continue;
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    if (v.status != SweepStatus::Ok) {
      ++job.failed;
      continue;
    }
    if (v.stable) ++job.stable;
    if (v.sim_status == 0) ++job.sim_completed;
    if (v.peak_input.size() > 0 &&
        (job.largest_input < 0 ||
         v.peak_input.maxCoeff() > job.variants[static_cast<std::size_t>(job.largest_input)].peak_input.maxCoeff()))
      job.largest_input = i;
    const double x = job.closed_loop ? v.closed_max_real : v.open_max_real;
    if (job.worst < 0 || x > worst) {
      worst = x;
      job.worst = i;
    }
  }

}

// a shard's file, or the study's results, CSV and MAT files (the journal removed once they are written)
void write_sweep_outputs(SweepJob& job, const SweepRequest& r, SweepJournalFile& jf, const std::string& model_bytes,
                         bool shard) {
  if (shard) {  // the shard's journal is its result
    jf.out.close();
    if (!jf.out) throw std::runtime_error(r.out + ": cannot finish the shard's file");
    // written again in the variants' order (it was appended to as they finished): the same bytes
    // whatever the threads and the order they finished in
    std::string text = journal_head(r, model_bytes, job.plan.count) + journal_request(r);
    for (long long i = 0; i < job.plan.count; ++i)
      if (job.in_shard(i)) text += sweep_journal_line(i, job.variants[static_cast<std::size_t>(i)]);
    write_file_atomically(r.out, text);
    job.written.push_back(r.out);
    return;
  }
  if (!r.out.empty()) {
    study_write_sweep_hdf5(job, r.out);
    job.written.push_back(r.out);
  }
  if (!r.csv.empty()) {
    study_write_sweep_csv(job, r.csv);
    job.written.push_back(r.csv);
  }
  if (!r.mat.empty()) {
    study_write_sweep_mat(job, r.mat);
    job.written.push_back(r.mat);
    const std::filesystem::path p(r.mat);
    job.written.push_back((p.parent_path() / (p.stem().string() + ".m")).string());
  }
  if (jf.out.is_open()) {
    jf.out.close();
    std::error_code ec;
    std::filesystem::remove(jf.path, ec);
  }
}

SweepJob sweep_job(const SweepRequest& r, const StudyMessages& tell, const SweepProgress& progress, bool merging) {
  SweepJob job;
  const SweepNote note = [&](const std::string& text) {
    job.notes.push_back(text);
    if (tell) tell({StudyMessage::Note, text});
  };
  const bool shard = r.shard_count > 0;
  const bool memory = shard && r.journal_in_memory;  // an MPI rank's slice: the whole study's outputs checked below
  check_sweep_request(r, shard, memory);
  // errors name the file and the field
  const ModelSpec nominal_spec = r.model_text.empty() ? study_read_model(r.model) : study_parse_model_text(r.model_text, r.model);
  for (const std::string& n : nominal_spec.notes) note(n);
  std::string model_bytes = r.model_text;
  if (model_bytes.empty()) {
    std::ifstream in(r.model, std::ios::binary);
    model_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const nlohmann::json file = nlohmann::json::parse(model_bytes);
  job.plan = study_sweep_plan(r, file);
  job.model_file = r.model;
  job.model_name = nominal_spec.name;

  Context c;
  std::optional<Model> structure;
  const bool controller_file = sweep_nominal(c, structure, job, r, file, nominal_spec, note);

  // the variants
  const long long n = job.plan.count;
  job.variants.resize(static_cast<std::size_t>(n));
  unsigned threads = r.threads > 0 ? static_cast<unsigned>(r.threads) : std::max(1u, std::thread::hardware_concurrency());
  if (controller_file && threads > 1) {
    // the controller file is read again with every variant's model (matio, HDF5 for v7.3: not thread-safe)
    note("the study's controller is a file: variants run on one thread");
    threads = 1;
  }
  threads = static_cast<unsigned>(std::min<long long>(threads, n));
  SweepJournalFile jf;
  open_sweep_journal(jf, job, r, model_bytes, shard, memory, merging, note);
  run_sweep_variants(c, job, jf, threads, memory, progress);
  count_sweep_variants(job);
  if (memory) return job;  // the journal in job.journal is the slice's result
  write_sweep_outputs(job, r, jf, model_bytes, shard);
  return job;
}
}  // namespace

SweepJob study_sweep_merge(const std::vector<std::string>& shards, const SweepRequest& outputs, const StudyMessages& tell) {
  if (shards.empty()) throw std::invalid_argument("sweep-merge: give the shards' files");
  std::vector<std::string> texts;
  for (const std::string& path : shards) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::invalid_argument(path + ": cannot read this shard");
    texts.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return study_sweep_merge_journals(texts, shards, outputs, tell);
}

SweepJob study_sweep_merge_journals(const std::vector<std::string>& journals, const std::vector<std::string>& names,
                                    const SweepRequest& outputs, const StudyMessages& tell) {
  if (journals.empty() || journals.size() != names.size()) throw std::invalid_argument("sweep-merge: give the shards' files");
  if (outputs.out.empty()) throw std::invalid_argument(option_name(outputs.style, "out") + ": the merged results (HDF5)");
  std::string head, request;
  std::map<long long, std::string> lines;
  for (std::size_t s = 0; s < journals.size(); ++s) {
    const std::string& path = names[s];
    std::istringstream in(journals[s]);
    std::string h, q, line;
    if (!std::getline(in, h) || h.rfind("codyna sweep journal ", 0) != 0 || !std::getline(in, q) || q.rfind("request ", 0) != 0)
      throw std::invalid_argument(path + ": not a shard written by codyna sweep --shard");
    if (head.empty()) {
      head = h;
      request = q;
    } else if (h != head) {
      throw std::invalid_argument(path + ": a shard of another study than " + names.front() +
                                  " (other model file contents or options)");
    }
    while (std::getline(in, line)) {
      if (in.eof()) break;
      try {
        lines.emplace(nlohmann::json::parse(line).at("i").get<long long>(), line);
      } catch (const std::exception&) {
      }
    }
  }
  const long long n = std::stoll(head.substr(head.rfind(' ') + 1));
  if (static_cast<long long>(lines.size()) != n) {
    std::string missing;
    long long count = 0;
    for (long long i = 0; i < n; ++i)
      if (!lines.count(i) && count++ < 8) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
    throw std::invalid_argument("sweep-merge: variants " + missing + (count > 8 ? ", ..." : "") + " (" + std::to_string(count) +
                                " of " + std::to_string(n) + ") are in none of the shards given: run (or resume) their shards first");
  }
  const nlohmann::json q = nlohmann::json::parse(request.substr(8));
  SweepRequest r = outputs;
  r.model = q.at("model").get<std::string>();
  r.vary = q.at("vary").get<std::vector<std::string>>();
  r.redesign = q.at("redesign").get<std::string>();
  r.simulate = q.at("simulate").get<bool>();
  r.samples.reset();
  r.seed.reset();
  if (!q.at("samples").is_null()) r.samples = q.at("samples").get<long long>();
  if (!q.at("seed").is_null()) r.seed = std::stoull(q.at("seed").get<std::string>());
  r.resume = true;
  r.shard_index = 0;
  r.shard_count = 0;
  // the joined journal: the whole study resumes from it with nothing left to run
  const std::string journal_path = study_sweep_journal_path(r.out);
  study_guard_output(r.out, OutputKind::ResultsHdf5, {r.model});
  if (!is_sweep_journal(journal_path))
    throw std::invalid_argument(journal_path + ": exists and is not the journal of a codyna sweep: remove it");
  std::string text = head + "\n" + request + "\n";
  for (const auto& [i, line] : lines) text += line + "\n";
  write_file_atomically(journal_path, text);
  try {
    SweepJob job = sweep_job(r, tell, {}, true);
    if (job.resumed != n) throw std::runtime_error("sweep-merge: " + std::to_string(n - job.resumed) + " variants were run again");
    return job;
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(journal_path, ec);
    throw;
  }
}

std::string study_sweep_summary(const SweepJob& job) {
  std::ostringstream os;
  const long long n = static_cast<long long>(job.variants.size());
  const std::size_t fields = job.plan.vary.size();
  if (job.shard_count > 0) {
    const long long mine = sweep_shard_size(n, job.shard_index, job.shard_count);
    os << "shard            " << job.shard_index << "/" << job.shard_count << ": " << mine << " of the " << n
       << " variants (i % " << job.shard_count << " = " << job.shard_index << "), " << job.failed
       << " failed; codyna sweep-merge joins the shards\n";
    return os.str();
  }
  os << "sweep            " << job.model_name << ": " << n << " variants, "
     << (job.plan.random ? "joint random samples (seed " + std::to_string(job.plan.seed) + ")" : std::string("a full grid"))
     << " of " << fields << (fields == 1 ? " field" : " fields") << "\n";
  for (const SweepVary& v : job.plan.vary) os << "  " << v.field << " = " << v.spec << " (nominal " << fmt(v.nominal) << ")\n";
  os << "operating point  " << job.operating_point << ", " << job.method << " Jacobians\n";
  os << "closed loop      " << job.controller << "\n";
  if (job.closed_loop) {
    os << "nominal          max Re(closed-loop pole) = " << fmt(max_real(job.nominal_closed_poles)) << "\n";
  }
  os << "completed        " << (n - job.failed) << " of " << n << " (" << job.failed << " failed)\n";
  const long long completed = n - job.failed;
  os << "stable           " << job.stable << " of " << completed << " completed";
  if (completed > 0) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f", 100.0 * static_cast<double>(job.stable) / static_cast<double>(completed));
    os << " (" << pct << " %)";
  }
  os << (job.closed_loop ? ", closed loop" : ", open loop") << "\n";
  if (job.worst >= 0) {
    const SweepVariant& w = job.variants[static_cast<std::size_t>(job.worst)];
    os << "worst case       variant " << job.worst << ":";
    for (std::size_t k = 0; k < fields; ++k) os << (k ? "," : "") << " " << job.plan.vary[k].field << " = " << fmt(w.values[k]);
    os << ", max Re(" << (job.closed_loop ? "closed" : "open") << "-loop pole) = "
       << fmt(job.closed_loop ? w.closed_max_real : w.open_max_real) << "\n";
  }
  if (job.simulated) {
    os << "simulated        " << job.sim_completed << " of " << completed << " completed variants reached t_end\n";
    if (job.largest_input >= 0) {
      const SweepVariant& w = job.variants[static_cast<std::size_t>(job.largest_input)];
      os << "largest input    variant " << job.largest_input << ": peak |u| = " << fmt(w.peak_input.maxCoeff())
         << ", final error " << fmt(w.final_error) << "\n";
    }
    long long far = -1;
    for (long long i = 0; i < n; ++i) {
      const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      if ((v.sim_status == 0 || v.sim_status == 1) &&
          (far < 0 || v.final_error > job.variants[static_cast<std::size_t>(far)].final_error))
        far = i;
    }
    if (far >= 0)
      os << "largest error    variant " << far << ": final error " << fmt(job.variants[static_cast<std::size_t>(far)].final_error)
         << " (the largest |y - y0| over Plant/Out at t_end)\n";
    // the largest of a figure over the variants' entries, and whose it is
    const auto largest = [&](Eigen::VectorXd SweepVariant::*field, const std::vector<std::string>& names, const char* label,
                             const char* unit) {
      long long at = -1;
      Eigen::Index which = 0;
      double best = 0;
      for (long long i = 0; i < n; ++i) {
        const Eigen::VectorXd& x = job.variants[static_cast<std::size_t>(i)].*field;
        for (Eigen::Index k = 0; k < x.size() && k < static_cast<Eigen::Index>(names.size()); ++k)
          if (std::isfinite(x[k]) && (at < 0 || x[k] > best)) {
            at = i;
            which = k;
            best = x[k];
          }
      }
      if (at >= 0)
        os << label << fmt(best) << unit << " (" << names[static_cast<std::size_t>(which)] << "), variant " << at << "\n";
    };
    largest(&SweepVariant::overshoot, job.output_names, "overshoot        largest ", " %");
    largest(&SweepVariant::settling_time, job.output_names, "settling time    longest ", " s (2 % band)");
    largest(&SweepVariant::saturation_time, job.input_names, "at a limit       longest ", " s");
    long long unsettled = 0;
    for (const SweepVariant& v : job.variants)
      if (v.sim_status == 0 && v.settling_time.size() && !v.settling_time.allFinite()) ++unsettled;
    if (unsettled) os << "not settled      " << unsettled << " runs end outside the 2 % band of an output\n";
    long long shown = 0;
    for (long long i = 0; i < n && shown < 5; ++i) {
      const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
      if (v.sim_status <= 0) continue;
      os << (shown++ ? "                 " : "run failed       ") << "variant " << i << ": " << v.sim_reason << "\n";
    }
  }
  long long listed = 0;
  for (long long i = 0; i < n; ++i) {
    const SweepVariant& v = job.variants[static_cast<std::size_t>(i)];
    if (v.status == SweepStatus::Ok) continue;
    if (listed++ == 10) {
      os << "                 ... and " << (job.failed - 10) << " more (the file's /status/reason)\n";
      break;
    }
    os << (listed == 1 ? "failed           " : "                 ") << "variant " << i << " (" << to_string(v.status)
       << "): " << v.reason << "\n";
  }
  return os.str();
}

}  // namespace codyna
