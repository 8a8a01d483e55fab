// Study.sweep and codyna.sweep_merge: the keywords into a SweepRequest, one study_sweep_job (on a
// thread of its own, the calling thread waiting without the GIL for Ctrl+C and the progress
// callback) or study_sweep_merge, and the job bound as codyna.Sweep: per-variant arrays laid out
// as the HDF5 file's datasets, the summary, the files written.
#include "bind_common.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <thread>

namespace codyna::python {

namespace {

struct SweepResult {
  std::shared_ptr<const SweepJob> job;
  // a shard's: the study's variant numbers of job->variants (the shard's only); empty: 0 .. n-1
  std::vector<long long> indices;
  std::string summary;  // study_sweep_summary of the job as the core returned it
};

// What a study call returned, for Python. A shard's job holds every variant of the study, those
// of the other shards never run (status Failed, no reason): the result keeps the shard's own
// only, in the study's order, with their numbers in `indices`, and worst / largest_input made
// positions in them.
std::unique_ptr<SweepResult> sweep_result(SweepJob&& job) {
  auto result = std::make_unique<SweepResult>();
  result->summary = study_sweep_summary(job);
  result->job = std::make_shared<const SweepJob>(study_sweep_own_variants(std::move(job), result->indices));
  return result;
}

SweepRequest sweep_request(const Study& s, Keywords& k) {
  SweepRequest r;
  r.style = OptionStyle::Keyword;
  r.model = s.file;
  r.model_text = s.text;
  r.vary = k.field_specs("vary");
  r.samples = k.whole("samples");
  r.seed = k.whole_u64("seed");
  if (const auto t = k.whole("threads", INT_MIN, INT_MAX)) r.threads = static_cast<int>(*t);
  r.redesign = k.text("redesign").value_or("");
  r.simulate = k.flag("simulate");
  r.out = k.path("out").value_or("");
  r.csv = k.path("csv").value_or("");
  r.mat = k.path("mat").value_or("");
  // the command's --restart, or its opposite resume=False
  const auto truth = [&](const std::optional<py::object>& o, const char* key) -> std::optional<bool> {
    if (!o) return std::nullopt;
    if (py::isinstance<py::str>(*o) || py::isinstance<py::bytes>(*o))
      type_error(std::string("sweep(): ") + key + ": expected True or False, got " + type_name(*o));
    return py::bool_(*o).cast<bool>();
  };
  const std::optional<bool> restart = truth(k.take("restart"), "restart"), resume = truth(k.take("resume"), "resume");
  if (restart && resume && *restart == *resume)
    throw py::value_error(std::string("restart=") + (*restart ? "True" : "False") + " and resume=" + (*resume ? "True" : "False") +
                          " contradict each other: give one");
  r.resume = restart ? !*restart : resume.value_or(true);
  if (const auto shard = k.shard("shard")) {
    // sweep_merge reads the model again from the path the shard names: a JSON text has none
    if (!s.text.empty())
      throw py::value_error("shard: a Study.from_json has no model file for sweep_merge to read again (its shards would "
                            "name " + s.file + "): write the JSON to a file and shard codyna.Study(path)");
    r.shard_index = shard->index;
    r.shard_count = shard->count;
  }
  return r;
}

// The sweep runs on a thread of its own (its pool's workers below it) while the calling thread
// waits without the GIL, waking every 50 ms to let Python run its signal handlers (Ctrl+C) and to
// call the progress callback, so that both work whatever thread finishes a variant and the
// workers never take the GIL. A handler or a callback that raised cancels the study (no new
// variant is taken; with `out`, the journal keeps those done) and its exception is raised.
std::unique_ptr<SweepResult> do_sweep(const Study& s, const py::dict& options) {
  Keywords k(options, "sweep");
  const std::optional<py::object> callback = k.take("progress");
  if (callback && !PyCallable_Check(callback->ptr()))
    type_error("sweep(): progress: expected a callable progress(done, total), got " + type_name(*callback));
  const SweepRequest r = sweep_request(s, k);
  k.finish();

  std::atomic<bool> cancel{false};
  std::atomic<long long> done{-1}, total{0};
  SweepProgress progress;
  progress.cancel = &cancel;
  progress.done = [&](long long d, long long n) {
    // a shard counts its own variants (the core's total is the whole study's)
    total = sweep_shard_size(n, r.shard_index, r.shard_count);
    done = d;
  };
  std::mutex mutex;
  std::condition_variable finished_cv;
  bool finished = false;
  auto job = std::make_shared<SweepJob>();
  std::exception_ptr failure;
  std::optional<py::error_already_set> raised;
  {
    py::gil_scoped_release release;
    std::thread study([&] {
      try {
        *job = study_sweep_job(r, {}, progress);
      } catch (...) {
        failure = std::current_exception();
      }
      const std::lock_guard<std::mutex> lock(mutex);
      finished = true;
      finished_cv.notify_all();
    });
    long long reported = -1;
    for (bool end = false; !end;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        end = finished_cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; });
      }
      if (cancel) continue;
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        raised.emplace();  // fetches (and clears) the handler's exception
        cancel = true;
        continue;
      }
      const long long d = done;
      if (callback && d > reported) {
        reported = d;
        try {
          (*callback)(d, total.load());
        } catch (py::error_already_set& e) {
          raised.emplace(std::move(e));
          cancel = true;
        }
      }
    }
    study.join();
  }
  if (raised) throw *raised;
  if (failure) std::rethrow_exception(failure);
  return sweep_result(std::move(*job));
}

// `codyna sweep-merge SHARD... --out --csv --mat`: the shards' journals joined into the whole
// study's files (the same core call; the nominal model is compiled again, no variant is run)
std::unique_ptr<SweepResult> do_sweep_merge(const py::object& shards, const py::dict& options) {
  Keywords k(options, "sweep_merge");
  SweepRequest outputs;
  outputs.style = OptionStyle::Keyword;
  outputs.out = k.path("out").value_or("");
  outputs.csv = k.path("csv").value_or("");
  outputs.mat = k.path("mat").value_or("");
  outputs.threads = 1;
  k.finish();
  const auto path_of = [&](const py::handle& o) -> std::string {
    if (py::isinstance<py::str>(o) || (py::hasattr(o, "__fspath__") && !py::isinstance<py::bytes>(o))) return fspath(o);
    type_error("sweep_merge(): shards: expected a list of paths (str or os.PathLike), got " + type_name(o));
  };
  std::vector<std::string> paths;
  if (py::isinstance<py::str>(shards) || py::hasattr(shards, "__fspath__")) {
    paths.push_back(path_of(shards));  // one shard (a study of N = 1)
  } else {
    if (py::isinstance<py::dict>(shards) || py::isinstance<py::bytes>(shards) || !py::isinstance<py::iterable>(shards))
      type_error("sweep_merge(): shards: expected a list of paths (str or os.PathLike), got " + type_name(shards));
    for (const auto& item : shards.cast<py::iterable>()) paths.push_back(path_of(item));
  }
  // the GIL stays held: no variant is run, and the HDF5 library is serial (h5py may be in this process)
  return sweep_result(study_sweep_merge(paths, outputs));
}

// ---------------------------------------------------------------------------------------------
// A sweep's per-variant arrays, laid out as the HDF5 file's datasets (study_write_sweep_hdf5): the
// variants first, NaN where a variant has no such value (it failed, or was not simulated)

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool variant_ok(const SweepVariant& v) { return v.status == SweepStatus::Ok; }

// (n, rows, cols): variant i's matrix when it completed with these sizes
py::array_t<double> variant_stack(const SweepJob& j, Eigen::MatrixXd SweepVariant::*field, Eigen::Index rows, Eigen::Index cols) {
  py::array_t<double> a({static_cast<py::ssize_t>(j.variants.size()), static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  auto out = a.mutable_unchecked<3>();
  for (std::size_t i = 0; i < j.variants.size(); ++i) {
    const SweepVariant& v = j.variants[i];
    const Eigen::MatrixXd& M = v.*field;
    const bool have = variant_ok(v) && M.rows() == rows && M.cols() == cols;
    for (Eigen::Index r = 0; r < rows; ++r)
      for (Eigen::Index c = 0; c < cols; ++c) out(static_cast<py::ssize_t>(i), r, c) = have ? M(r, c) : kNaN;
  }
  return a;
}

// (n, size): variant i's vector when it has this size
py::array_t<double> variant_rows(const SweepJob& j, Eigen::VectorXd SweepVariant::*field, Eigen::Index size) {
  py::array_t<double> a({static_cast<py::ssize_t>(j.variants.size()), static_cast<py::ssize_t>(size)});
  auto out = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < j.variants.size(); ++i) {
    const Eigen::VectorXd& x = j.variants[i].*field;
    for (Eigen::Index k = 0; k < size; ++k) out(static_cast<py::ssize_t>(i), k) = x.size() == size ? x[k] : kNaN;
  }
  return a;
}

// (n, nx) complex: variant i's poles when it completed
py::array_t<std::complex<double>> variant_poles(const SweepJob& j, Eigen::VectorXcd SweepVariant::*field) {
  const Eigen::Index nx = static_cast<Eigen::Index>(j.state_names.size());
  py::array_t<std::complex<double>> a({static_cast<py::ssize_t>(j.variants.size()), static_cast<py::ssize_t>(nx)});
  auto out = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < j.variants.size(); ++i) {
    const SweepVariant& v = j.variants[i];
    const Eigen::VectorXcd& p = v.*field;
    const bool have = variant_ok(v) && p.size() == nx;
    for (Eigen::Index k = 0; k < nx; ++k) out(static_cast<py::ssize_t>(i), k) = have ? p[k] : std::complex<double>(kNaN, kNaN);
  }
  return a;
}

// (n): one number per variant, from `get` (NaN where it has none)
template <class T, class Get>
py::array_t<T> per_variant(const SweepJob& j, Get get) {
  py::array_t<T> a(static_cast<py::ssize_t>(j.variants.size()));
  for (std::size_t i = 0; i < j.variants.size(); ++i) a.mutable_at(static_cast<py::ssize_t>(i)) = get(j.variants[i]);
  return a;
}

py::object index_or_none(long long i) { return i < 0 ? py::object(py::none()) : py::object(py::int_(i)); }

// Sweep's plan: the fields varied, each variant's values, status and reason
void bind_sweep_plan(py::class_<SweepResult>& c) {
  c.def("__len__", [](const SweepResult& s) { return s.job->variants.size(); }, "the number of variants")
      .def_property_readonly("model_file", [](const SweepResult& s) { return s.job->model_file; }, "the model file (or the label of a JSON text)")
      .def_property_readonly("model_name", [](const SweepResult& s) { return s.job->model_name; }, "the model's name")
      .def_property_readonly("design", [](const SweepResult& s) { return std::string(s.job->plan.random ? "random" : "grid"); },
                             "\"grid\" (a full grid, the last field varying fastest) or \"random\" (joint random samples)")
      .def_property_readonly("seed", [](const SweepResult& s) -> py::object {
        if (!s.job->plan.random) return py::none();
        return py::int_(s.job->plan.seed);
      }, "a random study's seed, else None")
      .def_property_readonly("fields", [](const SweepResult& s) {
        std::vector<std::string> f;
        for (const SweepVary& v : s.job->plan.vary) f.push_back(v.field);
        return f;
      }, "the varied fields (JSON pointers into the model file), values' columns")
      .def_property_readonly("specs", [](const SweepResult& s) {
        std::vector<std::string> f;
        for (const SweepVary& v : s.job->plan.vary) f.push_back(v.spec);
        return f;
      }, "the SPECs as given, one per field")
      .def_property_readonly("nominal", [](const SweepResult& s) {
        std::vector<double> f;
        for (const SweepVary& v : s.job->plan.vary) f.push_back(v.nominal);
        return vector_of(f);
      }, "the model file's values of the fields")
      .def_property_readonly("values", [](const SweepResult& s) {
        const SweepJob& j = *s.job;
        const std::size_t m = j.plan.vary.size();
        py::array_t<double> a({static_cast<py::ssize_t>(j.variants.size()), static_cast<py::ssize_t>(m)});
        auto out = a.mutable_unchecked<2>();
        for (std::size_t i = 0; i < j.variants.size(); ++i)
          for (std::size_t k = 0; k < m; ++k)
            out(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) = k < j.variants[i].values.size() ? j.variants[i].values[k] : kNaN;
        return a;
      }, "each variant's values of the fields (n x k)")
      .def_property_readonly("status", [](const SweepResult& s) {
        return per_variant<int>(*s.job, [](const SweepVariant& v) { return static_cast<int>(v.status); });
      }, "status codes (n): 0 ok, 1 model error, 2 not converged, 3 refused, 4 failed, 5 sizes differ")
      .def_property_readonly("status_text", [](const SweepResult& s) {
        std::vector<std::string> t;
        for (const SweepVariant& v : s.job->variants) t.push_back(to_string(v.status));
        return t;
      }, "the status codes' names (\"ok\", \"model error\", ...)")
      .def_property_readonly("reasons", [](const SweepResult& s) {
        std::vector<std::string> t;
        for (const SweepVariant& v : s.job->variants) t.push_back(v.reason);
        return t;
      }, "why each variant failed (\"\" when ok)")
      .def_property_readonly("state_names", [](const SweepResult& s) { return s.job->state_names; }, "names of the states (A's rows)")
      .def_property_readonly("input_names", [](const SweepResult& s) { return s.job->input_names; }, "Plant/In names (B's columns)")
      .def_property_readonly("output_names", [](const SweepResult& s) { return s.job->output_names; }, "Plant/Out names (C's rows)");
}

// Sweep's linear results: A, B, C, D, poles, controllability, the closed loop
void bind_sweep_linear(py::class_<SweepResult>& c) {
  c.def_property_readonly("A", [](const SweepResult& s) {
        const auto nx = static_cast<Eigen::Index>(s.job->state_names.size());
        return variant_stack(*s.job, &SweepVariant::A, nx, nx);
      }, "each variant's continuous A (n x nx x nx)")
      .def_property_readonly("B", [](const SweepResult& s) {
        return variant_stack(*s.job, &SweepVariant::B, static_cast<Eigen::Index>(s.job->state_names.size()),
                             static_cast<Eigen::Index>(s.job->input_names.size()));
      }, "each variant's B (n x nx x nu)")
      .def_property_readonly("C", [](const SweepResult& s) {
        return variant_stack(*s.job, &SweepVariant::C, static_cast<Eigen::Index>(s.job->output_names.size()),
                             static_cast<Eigen::Index>(s.job->state_names.size()));
      }, "each variant's C (n x ny x nx)")
      .def_property_readonly("D", [](const SweepResult& s) {
        return variant_stack(*s.job, &SweepVariant::D, static_cast<Eigen::Index>(s.job->output_names.size()),
                             static_cast<Eigen::Index>(s.job->input_names.size()));
      }, "each variant's D (n x ny x nu)")
      .def_property_readonly("open_poles", [](const SweepResult& s) { return variant_poles(*s.job, &SweepVariant::open_poles); },
                             "eig(A) of each variant (n x nx complex), sorted by real part, then imaginary part")
      .def_property_readonly("open_max_real", [](const SweepResult& s) {
        return per_variant<double>(*s.job, [](const SweepVariant& v) { return variant_ok(v) ? v.open_max_real : kNaN; });
      }, "the largest real part of eig(A) (n)")
      .def_property_readonly("uncontrollable", [](const SweepResult& s) {
        return per_variant<int>(*s.job, [](const SweepVariant& v) { return variant_ok(v) ? v.uncontrollable : -1; });
      }, "the number of modes the inputs cannot move (n; -1: the variant failed)")
      .def_property_readonly("uncontrollable_text", [](const SweepResult& s) {
        std::vector<std::string> t;
        for (const SweepVariant& v : s.job->variants) t.push_back(v.uncontrollable_text);
        return t;
      }, "those modes described (as codyna linearize prints them), per variant")
      .def_property_readonly("stable", [](const SweepResult& s) {
        return per_variant<bool>(*s.job, [](const SweepVariant& v) { return v.stable; });
      }, "the closed loop is asymptotically stable (without a closed loop: the open loop) (n)")
      .def_property_readonly("closed_loop", [](const SweepResult& s) { return s.job->closed_loop; }, "a state feedback closes the loop")
      .def_property_readonly("controller", [](const SweepResult& s) { return s.job->controller; }, "what the closed loop is")
      .def_property_readonly("redesigned", [](const SweepResult& s) { return s.job->redesigned; }, "K designed again for every variant (redesign=\"lqr\")")
      .def_property_readonly("K", [](const SweepResult& s) -> py::object {
        const SweepJob& j = *s.job;
        if (!j.closed_loop) return py::none();
        if (j.redesigned)
          return variant_stack(j, &SweepVariant::K, static_cast<Eigen::Index>(j.input_names.size()),
                               static_cast<Eigen::Index>(j.state_names.size()));
        return py::cast(j.K);
      }, "the gain: nu x nx (the nominal model's, fixed), n x nu x nx when redesigned; None without a closed loop")
      .def_property_readonly("closed_poles", [](const SweepResult& s) -> py::object {
        if (!s.job->closed_loop) return py::none();
        return variant_poles(*s.job, &SweepVariant::closed_poles);
      }, "eig(A - B K) of each variant (n x nx complex, sorted as open_poles); None without a closed loop")
      .def_property_readonly("closed_max_real", [](const SweepResult& s) -> py::object {
        if (!s.job->closed_loop) return py::none();
        return per_variant<double>(*s.job, [](const SweepVariant& v) { return variant_ok(v) ? v.closed_max_real : kNaN; });
      }, "the largest real part of eig(A - B K) (n); None without a closed loop")
      .def_property_readonly("nominal_open_poles", [](const SweepResult& s) { return s.job->nominal_open_poles; }, "eig(A) of the nominal model")
      .def_property_readonly("nominal_closed_poles", [](const SweepResult& s) -> py::object {
        if (!s.job->closed_loop) return py::none();
        return py::cast(s.job->nominal_closed_poles);
      }, "eig(A - B K) of the nominal model; None without a closed loop")
      .def_property_readonly("operating_point", [](const SweepResult& s) { return s.job->operating_point; }, "the study's operating point (equilibrium, ...)")
      .def_property_readonly("method", [](const SweepResult& s) { return s.job->method; }, "the Jacobians' method");
}

// Sweep's simulations (simulate=True) and its totals, summary, shard and files
void bind_sweep_runs(py::class_<SweepResult>& c) {
  c.def_property_readonly("simulated", [](const SweepResult& s) { return s.job->simulated; }, "simulate=True: every variant was also run")
      .def_property_readonly("sim_status", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return per_variant<int>(*s.job, [](const SweepVariant& v) { return v.sim_status; });
      }, "simulate: -1 not run (the variant failed), 0 reached t_end, 1 the run failed, 2 it could not be set up")
      .def_property_readonly("sim_reason", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        std::vector<std::string> t;
        for (const SweepVariant& v : s.job->variants) t.push_back(v.sim_reason);
        return py::cast(t);
      }, "simulate: why a run failed (\"\" otherwise)")
      .def_property_readonly("t_reached", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return per_variant<double>(*s.job, [](const SweepVariant& v) { return v.sim_status == 0 || v.sim_status == 1 ? v.sim_t_end : kNaN; });
      }, "simulate: the time each run reached (n)")
      .def_property_readonly("final_error", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return per_variant<double>(*s.job, [](const SweepVariant& v) { return v.sim_status == 0 || v.sim_status == 1 ? v.final_error : kNaN; });
      }, "simulate: the largest |y - target| over Plant/Out at the last sample (n)")
      .def_property_readonly("peak_input", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return variant_rows(*s.job, &SweepVariant::peak_input, static_cast<Eigen::Index>(s.job->input_names.size()));
      }, "simulate: the largest |u| of each Plant/In (n x nu)")
      .def_property_readonly("overshoot", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return variant_rows(*s.job, &SweepVariant::overshoot, static_cast<Eigen::Index>(s.job->output_names.size()));
      }, "simulate: the overshoot of each Plant/Out, % (n x ny)")
      .def_property_readonly("settling_time", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return variant_rows(*s.job, &SweepVariant::settling_time, static_cast<Eigen::Index>(s.job->output_names.size()));
      }, "simulate: the 2 % settling time of each Plant/Out, s (n x ny; NaN: not settled)")
      .def_property_readonly("saturation_time", [](const SweepResult& s) -> py::object {
        if (!s.job->simulated) return py::none();
        return variant_rows(*s.job, &SweepVariant::saturation_time, static_cast<Eigen::Index>(s.job->input_names.size()));
      }, "simulate: the seconds each Plant/In spent at a limit (n x nu; NaN: no limits)")
      .def_property_readonly("failed", [](const SweepResult& s) { return s.job->failed; }, "the number of variants that failed")
      .def_property_readonly("stable_count", [](const SweepResult& s) { return s.job->stable; }, "the number of stable completed variants")
      .def_property_readonly("sim_completed", [](const SweepResult& s) { return s.job->sim_completed; }, "simulate: the runs that reached t_end")
      .def_property_readonly("worst", [](const SweepResult& s) { return index_or_none(s.job->worst); },
                             "the completed variant with the largest max real part (closed loop, else open), None if none completed\n"
                             "(its row in the arrays; indices[worst] is its number in the whole study)")
      .def_property_readonly("largest_input", [](const SweepResult& s) { return index_or_none(s.job->largest_input); },
                             "simulate: the run with the largest peak |u| (its row in the arrays), else None")
      .def_property_readonly("summary", [](const SweepResult& s) { return s.summary; },
                             "the summary codyna sweep prints (a shard's: its one line)")
      .def_property_readonly("shard", [](const SweepResult& s) -> py::object {
        if (s.job->shard_count == 0) return py::none();
        return py::make_tuple(s.job->shard_index, s.job->shard_count);
      }, "a shard's (K, N), else None (the whole study, also when merged)")
      .def_property_readonly("indices", [](const SweepResult& s) {
        const std::size_t n = s.job->variants.size();
        py::array_t<std::int64_t> a(static_cast<py::ssize_t>(n));
        for (std::size_t i = 0; i < n; ++i)
          a.mutable_at(static_cast<py::ssize_t>(i)) = s.indices.empty() ? static_cast<std::int64_t>(i) : s.indices[i];
        return a;
      }, "each variant's number in the whole study (n): a shard K/N holds the variants i % N == K; else 0 .. n-1")
      .def_property_readonly("resumed", [](const SweepResult& s) { return s.job->resumed; }, "variants read back from the journal of an interrupted run")
      .def_property_readonly("written", [](const SweepResult& s) { return py::tuple(py::cast(s.job->written)); }, "the files written (out, csv, mat and its .m)")
      .def_property_readonly("notes", [](const SweepResult& s) { return s.job->notes; }, "notes for the user (what codyna sweep prints as notes)")
      .def_property_readonly("warnings", [](const SweepResult& s) { return s.job->warnings; }, "warnings for the user");
}

}  // namespace

void register_sweep(py::module_& m) {
  m.def("_sweep", &do_sweep, "study"_a, "options"_a,
        "study_sweep_job with the keywords given (a dict); codyna.Study.sweep documents them.");
  m.def("_sweep_merge", &do_sweep_merge, "shards"_a, "options"_a,
        "study_sweep_merge of the shards' files with out, csv, mat (a dict); codyna.sweep_merge documents them.");
  py::class_<SweepResult> c(m, "Sweep",
                            "What Study.sweep returns: the parameter study `codyna sweep` runs (docs/parameter-studies.md).\n"
                            "Per-variant arrays have the variants first, laid out as the HDF5 file's datasets, with NaN\n"
                            "where a variant has no value (it failed, or was not simulated).");
  bind_sweep_plan(c);
  bind_sweep_linear(c);
  bind_sweep_runs(c);
}

}  // namespace codyna::python
