// Study.simulate: the keywords into a SimulateRequest, one study_simulate_job (without the GIL;
// Ctrl+C stops it as KeyboardInterrupt), and the job bound as codyna.Simulation (the samples and
// their names, the linear prediction, the reports of `codyna simulate`); Simulation.save writes
// the results through the core's output guard and writers.
#include "bind_common.hpp"

#include <atomic>
#include <climits>
#include <chrono>

namespace codyna::python {

namespace {

struct SimulationRun {
  SimulateRequest request;
  SimulateJob job;
};

// Ctrl+C during a run: the progress callback (called after every recorded sample, without the
// GIL) takes the GIL every 50 ms to let Python run its signal handlers; a handler that raised
// (KeyboardInterrupt) sets the run's cancel flag, and the exception is raised again once the
// run has returned its partial result.
struct Interrupt {
  std::atomic<bool> cancel{false};
  std::optional<py::error_already_set> error;
  std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();

  void check() {
    const auto now = std::chrono::steady_clock::now();
    if (now - last < std::chrono::milliseconds(50) || cancel) return;
    last = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      error.emplace();  // fetches (and clears) the handler's exception
      cancel = true;
    }
  }
  [[noreturn]] void raise() {
    if (error) throw *error;
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
};

SimulateRequest simulate_request(const Study& s, const py::dict& options) {
  Keywords k(options, "simulate");
  SimulateRequest r;
  r.style = OptionStyle::Keyword;
  r.model = s.file;
  take_point(k, r.point);
  take_plant(k, r.plant);
  r.controller = k.path("controller");
  r.lqr = k.flag("lqr");
  r.lqr_controllable_part = k.flag("lqr_controllable_part");
  r.compare_linear = k.flag("compare_linear");
  r.open_loop = k.flag("open_loop");
  r.linear_region = k.number("linear_region");
  r.q_weights = k.numbers("q_weights");
  r.r_weights = k.numbers("r_weights");
  r.integrator = k.text("integrator");
  r.t_end = k.number("t_end");
  r.rtol = k.number("rtol");
  r.atol = k.number("atol");
  r.max_step = k.number("max_step");
  r.output_step = k.number("output_step");
  r.alf_penalty = k.number("alf_penalty");
  if (const auto n = k.whole("alf_iterations", INT_MIN, INT_MAX)) r.alf_iterations = static_cast<int>(*n);
  if (k.flag("alf_fixed_step")) r.alf_fixed_step = true;
  if (k.flag("alf_extrapolate")) r.alf_extrapolate = true;
  r.max_samples = k.number("max_samples");
  r.divergence_bound = k.number("divergence_bound");
  k.finish();
  return r;
}

std::unique_ptr<SimulationRun> do_simulate(const Study& s, const py::dict& options) {
  auto run = std::make_unique<SimulationRun>();
  run->request = simulate_request(s, options);
  Interrupt interrupt;
  SimulationCallbacks cb;
  cb.cancel = &interrupt.cancel;
  cb.progress = [&interrupt](double, double) { interrupt.check(); };
  try {
    py::gil_scoped_release release;
    run->job = study_simulate_job(run->request, *s.spec, cb);
  } catch (const StudyCancelled&) {
    if (interrupt.cancel) interrupt.raise();
    throw;
  }
  if (interrupt.cancel || run->job.result.cancelled) interrupt.raise();
  return run;
}

void save_simulation(const SimulationRun& run, const py::object& path_object, const py::object& csv_object) {
  const std::string path = path_object.is_none() ? std::string() : fspath(path_object);
  const std::string csv = csv_object.is_none() ? std::string() : fspath(csv_object);
  if (path.empty() && csv.empty()) throw py::value_error("save: give an HDF5 path, a csv path or both");
  // the rule every front end keeps: an output never replaces the model, the controller file or a
  // file codyna did not write (checked by the core)
  const std::vector<std::string> inputs{run.request.model, run.request.controller.value_or("")};
  if (!path.empty()) study_guard_output(path, OutputKind::ResultsHdf5, inputs);
  if (!csv.empty()) {
    study_guard_output(csv, OutputKind::ResultsCsv, inputs);
    if (!path.empty() && study_same_file(csv, path)) throw py::value_error("save: csv " + csv + " is the same file as " + path);
  }
  // the GIL stays held: the HDF5 library is serial, and h5py may be in this process
  study_write_results(run.job.result, path, csv);
}

// a matrix of the result that may be empty: None then
py::object or_none(const Eigen::MatrixXd& x) { return x.size() == 0 ? py::object(py::none()) : py::cast(x); }

// ---------------------------------------------------------------------------------------------
// The class

// Simulation's samples and their names
void bind_samples(py::class_<SimulationRun>& c) {
  using S = const SimulationRun&;
  c.def_property_readonly("t", [](S s) { return vector_of(s.job.result.t); }, "output times (N)")
      .def_property_readonly("q", [](S s) { return s.job.result.q; }, "configuration (N x nq), q_names")
      .def_property_readonly("v", [](S s) { return s.job.result.v; }, "velocities (N x nv), v_names")
      .def_property_readonly("x", [](S s) {
        const SimulationResult& r = s.job.result;
        Eigen::MatrixXd x(r.q.rows(), r.q.cols() + r.v.cols());
        x << r.q, r.v;
        return x;
      }, "[q v] (N x (nq + nv)), x_names: the stored state of the run (quaternions for ball and free\n"
         "joints), not the linear model's minimal state")
      .def_property_readonly("u", [](S s) { return s.job.result.u; }, "every actuator's value after saturation (N x nu), input_names")
      .def_property_readonly("y", [](S s) { return s.job.result.y; }, "Plant/Out (N x ny), output_names")
      .def_property_readonly("xc", [](S s) { return s.job.result.xc; }, "controller states (N x nxc), controller_state_names")
      .def_property_readonly("s", [](S s) { return s.job.result.s; },
                             "effect states (N x ns): the tires' contact deflections (transient slip), s_names")
      .def_property_readonly("y_linear", [](S s) { return or_none(s.job.result.y_linear); },
                             "the linear closed loop's outputs from the same start (compare_linear=True), else None")
      .def_property_readonly("y_reference", [](S s) { return or_none(s.job.result.y_reference); },
                             "r(t) the controller was given (N x ny), None without references")
      .def_property_readonly("u_disturbance", [](S s) { return or_none(s.job.result.u_disturbance); },
                             "d(t) added to each actuator (N x nu), None without disturbances")
      .def_property_readonly("kinetic_energy", [](S s) { return vector_of(s.job.result.kinetic_energy); }, "kinetic energy per sample (J)")
      .def_property_readonly("potential_energy", [](S s) { return vector_of(s.job.result.potential_energy); }, "potential energy per sample (J)")
      .def_property_readonly("constraint_violation", [](S s) { return vector_of(s.job.result.constraint_violation); }, "max |phi(q)| per sample (0 for trees)")
      .def_property_readonly("velocity_violation", [](S s) { return vector_of(s.job.result.velocity_violation); }, "max |Jc v| per sample")
      .def_property_readonly("q_names", [](S s) { return s.job.result.q_names; }, "names of q's columns")
      .def_property_readonly("v_names", [](S s) { return s.job.result.v_names; }, "names of v's columns")
      .def_property_readonly("x_names", [](S s) {
        std::vector<std::string> n = s.job.result.q_names;
        n.insert(n.end(), s.job.result.v_names.begin(), s.job.result.v_names.end());
        return n;
      }, "q_names + v_names")
      .def_property_readonly("input_names", [](S s) { return s.job.result.input_names; }, "every actuator's name (u's columns)")
      .def_property_readonly("output_names", [](S s) { return s.job.result.output_names; }, "Plant/Out names (y's columns)")
      .def_property_readonly("input_units", [](S s) { return s.job.result.input_units; }, "units of u's columns")
      .def_property_readonly("output_units", [](S s) { return s.job.result.output_units; }, "units of y's columns")
      .def_property_readonly("controller_state_names", [](S s) { return s.job.result.controller_state_names; }, "names of xc's columns")
      .def_property_readonly("s_names", [](S s) { return s.job.result.s_names; }, "names of s's columns (TIRE.deflection_x, TIRE.deflection_y; m)");
}

// Simulation's controller: where it came from, its design, its linear closed loop
void bind_controller(py::class_<SimulationRun>& c) {
  using S = const SimulationRun&;
  c.def_property_readonly("completed", [](S s) { return s.job.result.completed; }, "reached t_end")
      .def_property_readonly("failure", [](S s) { return s.job.result.failure; },
                             "a failed run: the time and reason (the samples up to it are kept); \"\" otherwise")
      .def_property_readonly("controller", [](S s) { return s.job.result.controller; }, "the controller's description")
      .def_property_readonly("controller_source", [](S s) { return s.job.setup.controller_source; }, "\"the model file's ...\", \"lqr\", a .mat, or \"none\"")
      .def_property_readonly("lqr_gain", [](S s) { return or_none(s.job.setup.lqr_gain); },
                             "the gain K designed with lqr=True (u = u0 - K (x - x0), the export's state order), else None")
      .def_property_readonly("lqr_poles", [](S s) -> py::object {
        if (s.job.setup.lqr_poles.size() == 0) return py::none();
        return py::cast(s.job.setup.lqr_poles);
      }, "eig(A - B K) of that design, else None")
      .def_property_readonly("linear_poles", [](S s) -> py::object {
        if (s.job.setup.linear_poles.size() == 0) return py::none();
        return py::cast(s.job.setup.linear_poles);
      }, "a linear controller: the linear closed loop's poles about the operating point, else None")
      .def_property_readonly("linear_discrete", [](S s) { return s.job.setup.linear_discrete; }, "the linear closed-loop poles are z (a sampled controller)")
      .def_property_readonly("linear_unstable", [](S s) { return s.job.setup.linear_unstable; }, "a linear closed-loop pole is unstable (the run is not refused for it)")
      .def_property_readonly("operating_point", [](S s) -> py::object {
        const LinearPlant* plant = s.job.setup.plant.get();
        if (!plant) return py::none();
        return operating_point_of(s.job.model, plant->op, s.job.op_coordinates);
      }, "the point the controller and the linear comparison are about (as Linearization.operating_point),\n"
         "None when nothing needs a plant")
      .def_property_readonly("initial_coordinates", [](S s) -> py::object {
        if (s.job.initial_coordinates.size() == 0) return py::none();
        return named(s.job.model.v_names, s.job.initial_coordinates);
      }, "the run's start by coordinate, when the study names an initial state, else None");
}

// Simulation's reports: the linear region and gap, saturation, the integrator, the messages
void bind_reports(py::class_<SimulationRun>& c) {
  using S = const SimulationRun&;
  c.def_property_readonly("linear_region", [](S s) -> py::object {
        const LinearRegion& r = s.job.region;
        if (r.measured.empty()) return py::none();
        return py::dict("bound"_a = r.bound, "measured"_a = r.measured, "left_at"_a = r.left_at, "left_on"_a = r.left_on,
                        "largest"_a = r.largest, "largest_on"_a = r.largest_on, "final_distance"_a = r.final_distance,
                        "final_on"_a = r.final_on, "settled"_a = r.settled);
      }, "how far the run went from the operating point (left_at = -1: stayed within), None without a plant")
      .def_property_readonly("linear_gap", [](S s) -> py::object {
        if (s.job.linear_gap.size() == 0) return py::none();
        return py::dict("max_abs"_a = named(s.job.result.output_names, s.job.linear_gap),
                        "percent"_a = named(s.job.result.output_names, s.job.linear_gap_percent),
                        "from_time"_a = named(s.job.result.output_names, s.job.linear_gap_from));
      }, "compare_linear=True: per output, the largest |y - y_linear|, that in % of the output's\n"
         "excursion, and the first time the gap passes 1 % (-1: never); else None")
      .def_property_readonly("linear_failure", [](S s) { return s.job.result.linear_failure; }, "why y_linear ends in NaN (an unstable linear loop), or \"\"")
      .def_property_readonly("linear_error_estimate", [](S s) { return s.job.result.linear_error_estimate; }, "max |y_linear - the same at 100x looser tolerances| (-1: not known)")
      .def_property_readonly("saturation", [](S s) {
        py::list l;
        for (const Saturation& x : s.job.saturation)
          l.append(py::dict("actuator"_a = x.actuator, "at_max"_a = x.at_max, "at_min"_a = x.at_min, "first"_a = x.first));
        return l;
      }, "actuators that sat at a limit: seconds at max and at min, first time")
      .def_property_readonly("stats", [](S s) {
        const SolverStats& x = s.job.result.stats;
        return py::dict("integrator"_a = x.integrator, "rtol"_a = x.rtol, "atol"_a = x.atol, "max_step"_a = x.max_step,
                        "steps"_a = x.steps, "rhs_evals"_a = x.rhs_evals, "jac_evals"_a = x.jac_evals,
                        "error_test_failures"_a = x.error_test_failures, "nonlinear_iterations"_a = x.nonlinear_iterations,
                        "nonlinear_failures"_a = x.nonlinear_failures, "projections"_a = x.projections,
                        "restarts"_a = x.restarts, "wall_time"_a = x.wall_time, "integrator_choice"_a = x.integrator_choice);
      }, "the integrator's statistics (integrator, tolerances, steps, evaluations, wall_time ...)")
      .def_property_readonly("settings_json", [](S s) { return s.job.result.settings_json; }, "the run's settings as JSON text (what the HDF5 file's provenance holds)")
      .def_property_readonly("notes", [](S s) { return s.job.notes; }, "notes for the user (what codyna simulate prints as notes)")
      .def_property_readonly("warnings", [](S s) { return s.job.warnings; }, "warnings for the user (unstable linear loop, leaving the linear region ...)")
      .def("save", &save_simulation, "path"_a, "csv"_a = py::none(),
           "save(path, csv=None)\n\n"
           "Writes the results as `codyna simulate --out path [--csv csv]` does (HDF5, and CSV when csv\n"
           "is given; path may be None for CSV only), each atomically, refusing to replace the model,\n"
           "the controller file or a file codyna did not write.");
}

}  // namespace

void register_simulate(py::module_& m) {
  m.def("_simulate", &do_simulate, "study"_a, "options"_a,
        "study_simulate_job with the keywords given (a dict); codyna.Study.simulate documents them.");
  py::class_<SimulationRun> c(m, "Simulation",
                              "What Study.simulate returns: the run's samples (one row per output time), names,\n"
                              "the linear prediction when compare_linear=True, and the reports of `codyna simulate`.");
  bind_samples(c);
  bind_controller(c);
  bind_reports(c);
}

}  // namespace codyna::python
