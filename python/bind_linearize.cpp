// Study.linearize: the keywords into a LinearizeRequest, one study_linearize_job, and the job
// bound as codyna.Linearization (A, B, C, D with names and offsets, the operating point, modes,
// uncontrollable and unobservable modes; stacked along a trajectory) with its linear closed loop
// as codyna.ClosedLoop; Linearization.export runs the same job again with `out`.
#include "bind_common.hpp"

namespace codyna::python {

namespace {

struct LinearizationResult {
  LinearizeRequest request;  // to export: the same job again with `out`
  std::shared_ptr<const ModelSpec> spec;
  std::shared_ptr<const LinearizeJob> job;

  const LinearSystem& system() const {
    if (job->trajectory) throw py::attribute_error("along a trajectory: the systems are stacked (see times)");
    return job->linearization.system;
  }
};

struct ClosedLoopResult {
  std::shared_ptr<const LinearizeJob> job;
  const StudyClosedLoop& cl() const { return *job->closed_loop; }
  const LinearSystem& system() const { return job->closed_loop->loop.system; }
};

LinearizeRequest linearize_request(const Study& s, const py::dict& options) {
  Keywords k(options, "linearize");
  LinearizeRequest r;
  r.style = OptionStyle::Keyword;
  r.model = s.file;
  take_point(k, r.point);
  take_plant(k, r.plant);
  r.method = k.text("method");
  if (const auto v = k.take("mat_version")) r.mat_version = py::str(*v).cast<std::string>();  // 5, "5", "7.3"
  r.name = k.text("name");
  r.controller = k.path("controller");
  r.discrete = k.number("discrete");
  r.trajectory = k.number("trajectory");
  r.trajectory_step = k.number("trajectory_step");
  r.closed_loop = k.flag("closed_loop");
  r.lqr = k.flag("lqr");
  r.lqr_controllable_part = k.flag("lqr_controllable_part");
  r.q_weights = k.numbers("q_weights");
  r.r_weights = k.numbers("r_weights");
  k.finish();
  return r;
}

LinearizationResult do_linearize(const Study& s, const py::dict& options) {
  LinearizationResult l;
  l.request = linearize_request(s, options);
  l.spec = s.spec;
  {
    py::gil_scoped_release release;
    l.job = std::make_shared<const LinearizeJob>(study_linearize_job(l.request, *l.spec));
  }
  return l;
}

py::tuple export_linearization(const LinearizationResult& l, const py::object& dir_object) {
  LinearizeRequest r = l.request;
  r.out = fspath(dir_object);
  if (r.out.empty()) throw py::value_error("export: a folder is needed (\".\" for this one)");
  LinearizeJob job;
  {
    py::gil_scoped_release release;
    job = study_linearize_job(r, *l.spec);
  }
  std::vector<std::string> written = job.written;
  written.insert(written.end(), job.closed_loop_written.begin(), job.closed_loop_written.end());
  return py::tuple(py::cast(written));
}

// ---------------------------------------------------------------------------------------------
// The job's values for Python

py::array_t<std::complex<double>> eigenvalues_of(const ModalAnalysis& m) {
  py::array_t<std::complex<double>> a(static_cast<py::ssize_t>(m.modes.size()));
  for (std::size_t k = 0; k < m.modes.size(); ++k) a.mutable_at(static_cast<py::ssize_t>(k)) = m.modes[k].eigenvalue;
  return a;
}

py::list modes_of(const ModalAnalysis& m) {
  py::list l;
  for (const Mode& mode : m.modes)
    l.append(py::dict("eigenvalue"_a = mode.eigenvalue, "s"_a = mode.s, "natural_frequency"_a = mode.natural_frequency,
                      "damping_ratio"_a = mode.damping_ratio, "shape"_a = mode.shape));
  return l;
}

py::list hidden_of(const std::vector<HiddenMode>& modes) {
  py::list l;
  for (const HiddenMode& h : modes) l.append(py::dict("eigenvalue"_a = h.eigenvalue, "states"_a = h.states, "margin"_a = h.margin));
  return l;
}

// one matrix of the system (along a trajectory: of every system, stacked (N, rows, cols))
py::object system_matrix(const LinearizationResult& l, Eigen::MatrixXd LinearSystem::*field) {
  if (!l.job->trajectory) return py::cast(l.system().*field);
  const std::vector<LinearSystem>& systems = l.job->systems;
  const Eigen::Index rows = systems.empty() ? 0 : (systems[0].*field).rows(), cols = systems.empty() ? 0 : (systems[0].*field).cols();
  py::array_t<double> a({static_cast<py::ssize_t>(systems.size()), static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  auto r = a.mutable_unchecked<3>();
  for (std::size_t k = 0; k < systems.size(); ++k)
    for (Eigen::Index i = 0; i < rows; ++i)
      for (Eigen::Index j = 0; j < cols; ++j) r(static_cast<py::ssize_t>(k), i, j) = (systems[k].*field)(i, j);
  return a;
}

// one vector of the system (along a trajectory: stacked (N, size))
py::object system_vector(const LinearizationResult& l, Eigen::VectorXd LinearSystem::*field) {
  if (!l.job->trajectory) return py::cast(l.system().*field);
  const std::vector<LinearSystem>& systems = l.job->systems;
  const Eigen::Index n = systems.empty() ? 0 : (systems[0].*field).size();
  py::array_t<double> a({static_cast<py::ssize_t>(systems.size()), static_cast<py::ssize_t>(n)});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t k = 0; k < systems.size(); ++k)
    for (Eigen::Index i = 0; i < n; ++i) r(static_cast<py::ssize_t>(k), i) = (systems[k].*field)[i];
  return a;
}

// names or units (along a trajectory: the first system's, which every one shares)
std::vector<std::string> system_names(const LinearizationResult& l, std::vector<std::string> LinearSystem::*field) {
  if (!l.job->trajectory) return l.system().*field;
  return l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].*field;
}

// ---------------------------------------------------------------------------------------------
// The classes

void bind_closed_loop(py::module_& m) {
  using C = const ClosedLoopResult&;
  py::class_<ClosedLoopResult>(m, "ClosedLoop",
                               "The linear closed loop of the study's plant and controller (linearize(closed_loop=True)).\n"
                               "A, B, C, D are the command line's Acl, Bcl, Ccl, Dcl (NAME_cl.mat).")
      .def_property_readonly("A", [](C c) { return c.system().A; }, "Acl (closed-loop states: the plant's deviations, then the controller's states)")
      .def_property_readonly("B", [](C c) { return c.system().B; }, "Bcl (inputs: references dr = r - y0, then disturbances)")
      .def_property_readonly("C", [](C c) { return c.system().C; }, "Ccl (outputs: the plant's outputs dy, then the efforts du)")
      .def_property_readonly("D", [](C c) { return c.system().D; }, "Dcl")
      .def_property_readonly("x0", [](C c) { return c.system().x0; }, "the closed loop's operating point (states)")
      .def_property_readonly("u0", [](C c) { return c.system().u0; }, "its inputs' nominal values")
      .def_property_readonly("y0", [](C c) { return c.system().y0; }, "its outputs' nominal values")
      .def_property_readonly("Ts", [](C c) { return c.system().Ts; }, "sample time (0: continuous; > 0: a sampled controller around the plant's ZOH model)")
      .def_property_readonly("state_names", [](C c) { return c.system().state_names; }, "names of the closed loop's states")
      .def_property_readonly("input_names", [](C c) { return c.system().input_names; }, "names of its inputs")
      .def_property_readonly("output_names", [](C c) { return c.system().output_names; }, "names of its outputs")
      .def_property_readonly("state_units", [](C c) { return c.system().state_units; }, "units of its states")
      .def_property_readonly("input_units", [](C c) { return c.system().input_units; }, "units of its inputs")
      .def_property_readonly("output_units", [](C c) { return c.system().output_units; }, "units of its outputs")
      .def_property_readonly("controller", [](C c) { return c.cl().loop.controller; }, "the controller's description")
      .def_property_readonly("controller_source", [](C c) { return c.cl().setup.controller_source; }, "where the controller came from: the model file's, lqr, a .mat")
      .def_property_readonly("sizes", [](C c) {
        const ClosedLoopLinear& l = c.cl().loop;
        return py::dict("nx"_a = l.nx, "nxc"_a = l.nxc, "nr"_a = l.nr, "nd"_a = l.nd, "ny"_a = l.ny, "nu"_a = l.nu);
      }, "plant states nx, controller states nxc, reference inputs nr, disturbance inputs nd, outputs ny, efforts nu")
      .def("poles", [](C c) { return eigenvalues_of(c.cl().poles); }, "The closed loop's poles (numpy complex), sorted as the printed table.")
      .def_property_readonly("poles_text", [](C c) { return study_format_modes(c.cl().poles); }, "the poles table the command line prints")
      .def_property_readonly("step", [](C c) {
        const StepResponse& s = c.cl().step;
        return py::dict("t"_a = vector_of(s.t), "y"_a = s.y);
      }, "step responses: t and, per input, an array (len(t), outputs)")
      .def_property_readonly("frequency", [](C c) {
        const FrequencyResponse& f = c.cl().frequency;
        return py::dict("w"_a = vector_of(f.w), "H"_a = f.H, "magnitude"_a = f.magnitude, "phase_deg"_a = f.phase_deg);
      }, "frequency responses: w [rad/s] and, per frequency, H, |H| and the unwrapped phase (outputs x inputs)")
      .def_property_readonly("notes", [](C c) {
        std::vector<std::string> n = c.cl().setup.notes;
        n.insert(n.end(), c.cl().notes.begin(), c.cl().notes.end());
        return n;
      }, "what the closed loop's setup and analysis said (the CLI's notes)");
}

// Linearization's matrices, offsets, names and provenance
void bind_linear_system(py::class_<LinearizationResult>& c) {
  using L = const LinearizationResult&;
  using S = LinearSystem;
  c.def_property_readonly("A", [](L l) { return system_matrix(l, &S::A); }, "A (nx x nx; stacked (N, nx, nx) along a trajectory): the matrices x' = A x + B u, y = C x + D u in deviations (x = x0 + dx, u = u0 + du, y = y0 + dy)")
      .def_property_readonly("B", [](L l) { return system_matrix(l, &S::B); }, "B (nx x nu; stacked along a trajectory)")
      .def_property_readonly("C", [](L l) { return system_matrix(l, &S::C); }, "C (ny x nx; stacked along a trajectory)")
      .def_property_readonly("D", [](L l) { return system_matrix(l, &S::D); }, "D (ny x nu; stacked along a trajectory)")
      .def_property_readonly("x0", [](L l) { return system_vector(l, &S::x0); }, "the operating point's state (nx; stacked (N, nx) along a trajectory)")
      .def_property_readonly("u0", [](L l) { return system_vector(l, &S::u0); }, "the Plant/In values there (nu)")
      .def_property_readonly("y0", [](L l) { return system_vector(l, &S::y0); }, "the Plant/Out values there (ny)")
      .def_property_readonly("xdot0", [](L l) { return system_vector(l, &S::xdot0); }, "the state's derivative there (not 0 away from an equilibrium)")
      .def_property_readonly("Ts", [](L l) { return l.job->trajectory ? 0.0 : l.system().Ts; }, "the sample time (0: continuous)")
      .def_property_readonly("state_names", [](L l) { return system_names(l, &S::state_names); }, "names of the states, in the order of A's rows")
      .def_property_readonly("input_names", [](L l) { return system_names(l, &S::input_names); }, "Plant/In names, B's columns")
      .def_property_readonly("output_names", [](L l) { return system_names(l, &S::output_names); }, "Plant/Out names, C's rows")
      .def_property_readonly("state_units", [](L l) { return system_names(l, &S::state_units); }, "units of the states")
      .def_property_readonly("input_units", [](L l) { return system_names(l, &S::input_units); }, "units of the inputs")
      .def_property_readonly("output_units", [](L l) { return system_names(l, &S::output_units); }, "units of the outputs")
      .def_property_readonly("name", [](L l) { return l.job->name; }, "the export's NAME")
      .def_property_readonly("method", [](L l) { return l.job->method; }, "the Jacobians': exact, fd-forward or fd-central")
      .def_property_readonly("fd_error", [](L l) { return l.job->trajectory ? 0.0 : l.job->linearization.lin.fd_error; },
                             "finite differences: max |J_fd - J_exact| / max |J_exact| (0 for exact)")
      .def_property_readonly("independent", [](L l) {
        std::vector<std::string> names;
        if (!l.job->trajectory)
          for (int i : l.job->linearization.lin.partition.independent) names.push_back(l.job->model.v_names[i]);
        return names;
      }, "the independent coordinates of the state (closed loops: the partition chosen or given)")
      .def_property_readonly("operating_point", [](L l) -> py::object {
        if (l.job->trajectory) return py::none();
        const OperatingPoint& op = l.job->linearization.op;
        return operating_point_of(l.job->model, op, study_coordinates(l.job->model, op.q));
      }, "kind (initial, equilibrium, trim, steady, time=T), t, residual, iterations, coordinates and rates by\n"
         "name, inputs (every actuator) by name, and q, v, u as arrays; None along a trajectory")
      .def_property_readonly("handling", [](L l) -> py::object {
        if (l.job->trajectory || !l.job->linearization.handling) return py::none();
        py::dict d;
        for (const auto& [name, value] : l.job->linearization.lin.system.handling) d[py::str(name)] = value;
        return d;
      }, "at operating point steady with the study's handling section: the handling numbers by name\n"
         "(speed, wheelbase, steering_ratio, yaw_rate_gain, lateral_acceleration_gain, understeer_gradient (rad per m/s^2),\n"
         "understeer_gradient_deg_per_g, characteristic_speed, critical_speed, yaw_natural_frequency,\n"
         "yaw_damping_ratio[, sideslip_gain]; docs/vehicles.md), as NAME.mat's handling; else None")
      .def_property_readonly("notes", [](L l) { return l.job->notes; }, "notes for the user (what codyna linearize prints as notes)")
      .def_property_readonly("warnings", [](L l) { return l.job->warnings; }, "warnings for the user (what codyna linearize prints as warnings)");
}

// Linearization's modes, closed loop, trajectory and export
void bind_linear_analysis(py::class_<LinearizationResult>& c) {
  using L = const LinearizationResult&;
  c.def("eigenvalues", [](L l) -> py::object {
        if (l.job->trajectory) throw py::attribute_error("along a trajectory: see max_real and min_real");
        return eigenvalues_of(l.job->modes);
      }, "The eigenvalues of A (numpy complex; z when discrete), in the order of the modes table\n"
         "(by natural frequency).")
      .def_property_readonly("modes", [](L l) { return modes_of(l.job->modes); },
                             "one dict per mode: eigenvalue, s (continuous equivalent), natural_frequency [rad/s],\n"
                             "damping_ratio, shape (numpy complex, state order)")
      .def_property_readonly("modes_text", [](L l) { return study_format_modes(l.job->modes); }, "the modes table the command line prints")
      .def_property_readonly("uncontrollable", [](L l) { return hidden_of(l.job->uncontrollable); },
                             "modes the inputs cannot move (continuous plant): eigenvalue, states, margin")
      .def_property_readonly("unobservable", [](L l) { return hidden_of(l.job->unobservable); },
                             "modes the outputs cannot see (continuous plant): eigenvalue, states, margin")
      .def_property_readonly("closed_loop", [](L l) -> py::object {
        if (!l.job->closed_loop) return py::none();
        return py::cast(ClosedLoopResult{l.job});
      }, "the linear closed loop (a ClosedLoop) with closed_loop=True, else None")
      .def_property_readonly("trajectory", [](L l) { return l.job->trajectory; }, "True along a trajectory (linearize(trajectory=T))")
      .def_property_readonly("times", [](L l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return vector_of(l.job->times);
      }, "along a trajectory: the times of the systems, else None")
      .def_property_readonly("max_real", [](L l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return py::cast(l.job->max_real);
      }, "along a trajectory: the largest Re(eig A) per time")
      .def_property_readonly("min_real", [](L l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return py::cast(l.job->min_real);
      }, "along a trajectory: the smallest Re(eig A) per time")
      .def_property_readonly("trajectory_controller", [](L l) { return l.job->trajectory_controller; }, "along a trajectory: the controller in the loop (\"open loop\" or its description)")
      .def("export", &export_linearization, "dir"_a,
           "export(dir) -> tuple of paths\n\n"
           "Writes what `codyna linearize MODEL --out dir` with the same options writes: dir/NAME.mat and\n"
           "dir/NAME.m (and, with closed_loop=True, NAME_cl.mat, NAME_cl.m, NAME_cl_step.csv,\n"
           "NAME_cl_freq.csv), refusing to replace the model or a file codyna did not write. The folder\n"
           "is created if missing. Returns the paths written, in order.");
}

}  // namespace

void register_linearize(py::module_& m) {
  m.def("_linearize", &do_linearize, "study"_a, "options"_a,
        "study_linearize_job with the keywords given (a dict); codyna.Study.linearize documents them.");
  bind_closed_loop(m);
  py::class_<LinearizationResult> c(m, "Linearization",
                                    "What Study.linearize returns: the command line's A, B, C, D with their names and\n"
                                    "offsets (x = x0 + dx, u = u0 + du, y = y0 + dy), the operating point, the modes\n"
                                    "and what is uncontrollable or unobservable. Along a trajectory (trajectory=T),\n"
                                    "A, B, C, D, x0, u0, y0, xdot0 are stacked along a first axis, one per time.");
  bind_linear_system(c);
  bind_linear_analysis(c);
}

}  // namespace codyna::python
