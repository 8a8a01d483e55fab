// _codyna: the C++ half of the Python module `codyna` (docs/python.md).
//
// It binds core's study/ layer and the model/ types it hands back, and nothing below them:
// each Python call is one study call. What this file does is conversion only: Python keywords
// into a LinearizeRequest / SimulateRequest / SweepRequest (OptionStyle::Keyword, so the core's messages name
// the keywords), Eigen matrices into numpy arrays, names into lists, C++ exceptions into
// Python ones. It decides nothing, computes nothing and reads or writes no file itself.
//
// The pure-Python package (python/codyna/__init__.py) gives Study its keyword signatures and
// docstrings and calls the functions below with a dict of the keywords given.
#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <climits>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "model/errors.hpp"
#include "model/model.hpp"
#include "model/model_spec.hpp"
#include "study/files.hpp"
#include "study/jobs.hpp"
#include "study/model_summary.hpp"
#include "study/sweep.hpp"
#include "study/tools.hpp"
#include "study/workflow.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace codyna::python {

namespace {

// ---------------------------------------------------------------------------------------------
// Exceptions

PyObject* g_model_error = nullptr;        // codyna.ModelError(ValueError)
PyObject* g_convergence_error = nullptr;  // codyna.ConvergenceError(RuntimeError)

[[noreturn]] void type_error(const std::string& what) { throw py::type_error(what); }

// ---------------------------------------------------------------------------------------------
// Keywords -> request fields. `Keywords` holds the dict the Python layer passes (only the
// keywords given, None left out); every field taken is removed, and what is left at the end is
// a keyword this function does not know (TypeError naming it, as Python says it).

std::string type_name(const py::handle& o) { return py::str(py::type::handle_of(o).attr("__name__")); }

class Keywords {
 public:
  Keywords(const py::dict& given, std::string function) : function_(std::move(function)) {
    for (const auto& kv : given) {
      if (!py::isinstance<py::str>(kv.first)) type_error(function_ + "() keywords must be strings");
      if (kv.second.is_none()) continue;  // None: not given (the model file's value stays)
      items_.emplace_back(kv.first.cast<std::string>(), py::reinterpret_borrow<py::object>(kv.second));
    }
  }

  // the value of `key` (or of its alias), if given
  std::optional<py::object> take(const std::string& key, const std::string& alias = "") {
    std::optional<py::object> found;
    std::string found_key;
    for (auto it = items_.begin(); it != items_.end();) {
      if (it->first == key || (!alias.empty() && it->first == alias)) {
        if (found) type_error(function_ + "(): " + found_key + " and " + it->first + " are the same keyword: give one");
        found = it->second;
        found_key = it->first;
        it = items_.erase(it);
      } else {
        ++it;
      }
    }
    return found;
  }

  std::optional<std::string> text(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    return text_of(*o, key);
  }
  // a path: str or os.PathLike
  std::optional<std::string> path(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    if (py::hasattr(*o, "__fspath__") && !py::isinstance<py::str>(*o))
      return text_of(py::module_::import("os").attr("fspath")(*o), key);
    return text_of(*o, key);
  }
  std::optional<double> number(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    return number_of(*o, key);
  }
  bool flag(const std::string& key) {
    const auto o = take(key);
    if (!o) return false;
    if (py::isinstance<py::str>(*o) || py::isinstance<py::bytes>(*o))
      type_error(function_ + "(): " + key + ": expected True or False, got " + type_name(*o));
    return py::bool_(*o);
  }
  // names: one str, or an iterable of str
  std::optional<std::vector<std::string>> names(const std::string& key, const std::string& alias = "") {
    const auto o = take(key, alias);
    if (!o) return std::nullopt;
    if (py::isinstance<py::str>(*o)) return std::vector<std::string>{o->cast<std::string>()};
    std::vector<std::string> v;
    for (const auto& item : iterable(*o, key, "a str or a list of str")) v.push_back(text_of(item, key));
    return v;
  }
  // numbers: one number, or an iterable (list, numpy array) of numbers
  std::optional<std::vector<double>> numbers(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    if (!py::isinstance<py::str>(*o) && !py::hasattr(*o, "__iter__")) return std::vector<double>{number_of(*o, key)};
    std::vector<double> v;
    for (const auto& item : iterable(*o, key, "a number or a sequence of numbers")) v.push_back(number_of(item, key));
    return v;
  }
  // NAME=VALUE texts: a dict {name: value} (each value written with 17 significant digits, so
  // that the core reads back the same double), or "NAME=VALUE" strings (one, or a list)
  std::vector<std::string> pairs(const std::string& key, const std::string& alias = "") {
    const auto o = take(key, alias);
    if (!o) return {};
    std::vector<std::string> v;
    if (py::isinstance<py::dict>(*o)) {
      for (const auto& kv : o->cast<py::dict>()) {
        char value[64];
        std::snprintf(value, sizeof value, "%.17g", number_of(kv.second, key));
        v.push_back(text_of(kv.first, key) + "=" + value);
      }
      return v;
    }
    if (py::isinstance<py::str>(*o)) return {o->cast<std::string>()};
    for (const auto& item : iterable(*o, key, "a dict {name: value} or \"NAME=VALUE\" strings")) v.push_back(text_of(item, key));
    return v;
  }
  // a whole number (int or a numpy integer; a float or a bool is a TypeError) within [lo, hi]
  std::optional<long long> whole(const std::string& key, long long lo = LLONG_MIN, long long hi = LLONG_MAX) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    const py::int_ i = int_of(*o, key);
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
    if (overflow != 0 || x < lo || x > hi)
      throw py::value_error(key + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                            ", got " + py::repr(i).cast<std::string>());
    return x;
  }
  // an unsigned 64-bit whole number (a seed)
  std::optional<std::uint64_t> whole_u64(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    const py::int_ i = int_of(*o, key);
    const bool negative = PyObject_RichCompareBool(i.ptr(), py::int_(0).ptr(), Py_LT) == 1;
    const unsigned long long x = negative ? 0 : PyLong_AsUnsignedLongLong(i.ptr());
    if (negative || (x == static_cast<unsigned long long>(-1) && PyErr_Occurred())) {
      PyErr_Clear();
      throw py::value_error(key + ": expected a whole number from 0 to " + std::to_string(UINT64_MAX) + ", got " +
                            py::repr(i).cast<std::string>());
    }
    return static_cast<std::uint64_t>(x);
  }
  // FIELD=SPEC texts: "FIELD=SPEC" strings (one, or a list), or a dict {field: spec} whose spec
  // is a SPEC text ("5:15:11", "normal(10,3)"), a sequence of numbers (the list [v1,v2,...],
  // each written with 17 significant digits) or one number (a list of one)
  std::vector<std::string> field_specs(const std::string& key) {
    const auto o = take(key);
    if (!o) return {};
    if (py::isinstance<py::str>(*o)) return {o->cast<std::string>()};
    std::vector<std::string> v;
    if (py::isinstance<py::dict>(*o)) {
      for (const auto& kv : o->cast<py::dict>()) {
        const std::string field = text_of(kv.first, key);
        if (py::isinstance<py::str>(kv.second)) {
          v.push_back(field + "=" + kv.second.cast<std::string>());
          continue;
        }
        std::vector<double> values;
        if (py::hasattr(kv.second, "__iter__")) {
          for (const auto& item : iterable(py::reinterpret_borrow<py::object>(kv.second), key + "[" + field + "]",
                                           "a SPEC str, a sequence of numbers or a number"))
            values.push_back(number_of(item, key + "[" + field + "]"));
        } else {
          values.push_back(number_of(kv.second, key + "[" + field + "]"));
        }
        std::string list = field + "=[";
        for (std::size_t i = 0; i < values.size(); ++i) {
          char value[64];
          std::snprintf(value, sizeof value, "%.17g", values[i]);
          if (i) list += ',';
          list += value;
        }
        v.push_back(list + "]");
      }
      return v;
    }
    for (const auto& item : iterable(*o, key, "a dict {field: spec} or \"FIELD=SPEC\" strings")) v.push_back(text_of(item, key));
    return v;
  }
  // a sweep's shard: (K, N) (a tuple or list of two whole numbers), the command's "K/N" text or
  // "slurm" (a Slurm job array task's), read and checked by the core's study_parse_shard /
  // study_check_shard as codyna sweep --shard is (their std::invalid_argument: a ValueError)
  std::optional<SweepShard> shard(const std::string& key) {
    const auto o = take(key);
    if (!o) return std::nullopt;
    if (py::isinstance<py::str>(*o)) return study_parse_shard(o->cast<std::string>(), OptionStyle::Keyword);
    if (py::isinstance<py::dict>(*o) || py::isinstance<py::bytes>(*o) || !py::isinstance<py::sequence>(*o))
      type_error(function_ + "(): " + key + ": expected a tuple (K, N), a \"K/N\" str or \"slurm\", got " + type_name(*o));
    const std::string given = py::repr(*o).cast<std::string>();
    const py::sequence seq = o->cast<py::sequence>();
    if (seq.size() != 2) return study_check_shard(-1, 0, OptionStyle::Keyword, given);
    const auto whole = [&](const py::handle& x) {
      int overflow = 0;
      const long long v = PyLong_AsLongLongAndOverflow(int_of(x, key).ptr(), &overflow);
      return overflow != 0 ? -1 : v;
    };
    const long long k = whole(seq[0]), n = whole(seq[1]);
    return study_check_shard(k, n, OptionStyle::Keyword, given);
  }
  // signals: a "NAME=VALUE[@TIME]" string or a dict (the model file's object, as JSON text),
  // one or a list of them
  std::optional<std::vector<std::string>> signals(const std::string& key, const std::string& alias = "") {
    const auto o = take(key, alias);
    if (!o) return std::nullopt;
    if (py::isinstance<py::str>(*o) || py::isinstance<py::dict>(*o)) return std::vector<std::string>{signal_of(*o, key)};
    std::vector<std::string> v;
    for (const auto& item : iterable(*o, key, "a str, a dict or a list of them")) v.push_back(signal_of(item, key));
    return v;
  }

  // what is left was not asked for
  void finish() const {
    if (!items_.empty()) type_error(function_ + "() got an unexpected keyword argument '" + items_.front().first + "'");
  }

 private:
  py::iterable iterable(const py::object& o, const std::string& key, const char* expected) const {
    if (py::isinstance<py::dict>(o) || py::isinstance<py::bytes>(o) || !py::isinstance<py::iterable>(o))
      type_error(function_ + "(): " + key + ": expected " + expected + ", got " + type_name(o));
    return o.cast<py::iterable>();
  }
  std::string text_of(const py::handle& o, const std::string& key) const {
    if (!py::isinstance<py::str>(o)) type_error(function_ + "(): " + key + ": expected a str, got " + type_name(o));
    return o.cast<std::string>();
  }
  double number_of(const py::handle& o, const std::string& key) const {
    if (py::isinstance<py::str>(o) || py::isinstance<py::bool_>(o) || py::isinstance<py::bytes>(o) ||
        !py::hasattr(o, "__float__"))
      type_error(function_ + "(): " + key + ": expected a number, got " + type_name(o));
    return py::float_(py::reinterpret_borrow<py::object>(o)).cast<double>();
  }
  py::int_ int_of(const py::handle& o, const std::string& key) const {
    if (py::isinstance<py::bool_>(o) || !py::hasattr(o, "__index__"))
      type_error(function_ + "(): " + key + ": expected a whole number (int), got " + type_name(o));
    PyObject* i = PyNumber_Index(o.ptr());
    if (!i) throw py::error_already_set();
    return py::reinterpret_steal<py::int_>(i);
  }
  std::string signal_of(const py::handle& o, const std::string& key) const {
    if (py::isinstance<py::dict>(o)) return py::str(py::module_::import("json").attr("dumps")(o));
    if (!py::isinstance<py::str>(o))
      type_error(function_ + "(): " + key + ": expected a \"NAME=VALUE[@TIME]\" str or a dict, got " + type_name(o));
    return o.cast<std::string>();
  }

  std::string function_;
  std::vector<std::pair<std::string, py::object>> items_;
};

void take_point(Keywords& k, PointRequest& p) {
  p.operating_point = k.text("operating_point");
  p.independent = k.names("independent");
  p.trim_free = k.names("trim_free");
  p.free_inputs = k.names("free_input", "free_inputs");
  p.hold = k.pairs("hold");
  p.initial = k.pairs("initial");
  p.targets = k.pairs("target", "targets");
}

void take_plant(Keywords& k, PlantRequest& p) {
  p.inputs = k.names("inputs");
  p.outputs = k.names("outputs");
  p.disabled_effects = k.names("disable_effect", "disable_effects");
  p.references = k.signals("reference", "references");
  p.disturbances = k.signals("disturbance", "disturbances");
}

// ---------------------------------------------------------------------------------------------
// Results -> Python values

py::array_t<double> vector_of(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::dict named(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  py::dict d;
  for (Eigen::Index k = 0; k < v.size() && static_cast<std::size_t>(k) < names.size(); ++k)
    d[py::str(names[static_cast<std::size_t>(k)])] = v[k];
  return d;
}

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

py::dict operating_point_of(const Model& m, const OperatingPoint& op, const Eigen::VectorXd& coordinates) {
  std::vector<std::string> actuators;
  for (const ActuatorModel& a : m.actuators) actuators.push_back(a.name);
  return py::dict("kind"_a = op.kind, "t"_a = op.t, "residual"_a = op.residual, "iterations"_a = op.iterations,
                  "coordinates"_a = named(m.v_names, coordinates), "rates"_a = named(m.rate_names, op.v),
                  "inputs"_a = named(actuators, op.u), "q"_a = op.q, "v"_a = op.v, "u"_a = op.u);
}

// the stack of one matrix of every system along a trajectory: (N, rows, cols)
template <class Get>
py::array_t<double> stacked(const std::vector<LinearSystem>& systems, Get get) {
  const Eigen::Index rows = systems.empty() ? 0 : get(systems[0]).rows(), cols = systems.empty() ? 0 : get(systems[0]).cols();
  py::array_t<double> a({static_cast<py::ssize_t>(systems.size()), static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  auto r = a.mutable_unchecked<3>();
  for (std::size_t k = 0; k < systems.size(); ++k)
    for (Eigen::Index i = 0; i < rows; ++i)
      for (Eigen::Index j = 0; j < cols; ++j) r(static_cast<py::ssize_t>(k), i, j) = get(systems[k])(i, j);
  return a;
}
template <class Get>
py::array_t<double> stacked_vector(const std::vector<LinearSystem>& systems, Get get) {
  const Eigen::Index n = systems.empty() ? 0 : get(systems[0]).size();
  py::array_t<double> a({static_cast<py::ssize_t>(systems.size()), static_cast<py::ssize_t>(n)});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t k = 0; k < systems.size(); ++k)
    for (Eigen::Index i = 0; i < n; ++i) r(static_cast<py::ssize_t>(k), i) = get(systems[k])[i];
  return a;
}

// ---------------------------------------------------------------------------------------------
// The bound objects

struct Study {
  std::shared_ptr<const ModelSpec> spec;
  std::string file;  // the request's `model`: messages, relative paths, outputs that must not replace it
  std::string text;  // from_json: the text (a sweep's variants are edits of it); "": the file's
};

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

struct SimulationRun {
  SimulateRequest request;
  SimulateJob job;
};

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

// ---------------------------------------------------------------------------------------------
// The calls

Study study_from_file(const py::object& path_object) {
  const std::string path = py::str(py::module_::import("os").attr("fspath")(path_object));
  Study s;
  s.spec = std::make_shared<const ModelSpec>(study_read_model(path));
  s.file = path;
  return s;
}

Study study_from_json(const std::string& text, const py::object& base_dir_object) {
  const std::string base_dir = py::str(py::module_::import("os").attr("fspath")(base_dir_object));
  // the label names the text in messages; its folder is where relative paths of the model lead
  const std::string label = base_dir == "." || base_dir.empty() ? "<json>" : base_dir + "/<json>";
  Study s;
  s.spec = std::make_shared<const ModelSpec>(study_parse_model_text(text, label));
  s.file = label;
  s.text = text;
  return s;
}

py::dict model_info(const Study& s) {
  const ModelSummary m = model_summary(study_compile(*s.spec, s.file));
  py::list bodies, joints, constraints, effects, actuators, sensors;
  for (const ModelSummary::Body& b : m.bodies)
    bodies.append(py::dict("name"_a = b.name, "mass"_a = b.mass, "com"_a = b.com, "joint"_a = b.joint, "parent"_a = b.parent));
  for (const ModelSummary::Joint& j : m.joints)
    joints.append(py::dict("name"_a = j.name, "type"_a = j.type, "parent"_a = j.parent, "child"_a = j.child,
                           "coordinates"_a = j.coordinates, "rates"_a = j.rates, "q_names"_a = j.q_names));
  for (const ModelSummary::Constraint& c : m.constraints)
    constraints.append(py::dict("name"_a = c.name, "type"_a = c.type, "body_a"_a = c.body_a, "body_b"_a = c.body_b,
                                "equations"_a = c.equations));
  for (const ModelSummary::Effect& e : m.effects) effects.append(py::dict("name"_a = e.name, "type"_a = e.type));
  for (const ModelSummary::Actuator& a : m.actuators)
    actuators.append(py::dict("name"_a = a.name, "type"_a = a.type, "unit"_a = a.unit, "gain"_a = a.gain, "u0"_a = a.u0,
                              "min"_a = a.min, "max"_a = a.max));
  for (const ModelSummary::Sensor& y : m.sensors) sensors.append(py::dict("name"_a = y.name, "type"_a = y.type, "unit"_a = y.unit));
  return py::dict("name"_a = m.name, "file"_a = m.file, "dof"_a = m.dof, "rate_dof"_a = m.rate_dof, "nq"_a = m.nq,
                  "nv"_a = m.nv, "bodies"_a = bodies, "joints"_a = joints, "coordinates"_a = m.coordinates, "units"_a = m.units,
                  "rates"_a = m.rates, "q_names"_a = m.q_names, "constraints"_a = constraints,
                  "constraint_equations"_a = m.constraint_equations, "independent_equations"_a = m.independent_equations,
                  "redundant_equations"_a = m.redundant_equations, "assembly_residual"_a = m.assembly_residual,
                  "assembly_moves"_a = m.assembly_moves, "effects"_a = effects, "gravity"_a = m.gravity,
                  "actuators"_a = actuators, "sensors"_a = sensors, "plant_inputs"_a = m.plant_inputs,
                  "plant_outputs"_a = m.plant_outputs, "controller"_a = m.controller,
                  "initial_coordinates"_a = named(m.coordinates, m.initial_coordinates),
                  "initial_rates"_a = named(m.rates, m.initial_rates));
}

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
  r.out = py::str(py::module_::import("os").attr("fspath")(dir_object));
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
  const auto fspath = py::module_::import("os").attr("fspath");
  const std::string path = path_object.is_none() ? std::string() : py::str(fspath(path_object)).cast<std::string>();
  const std::string csv = csv_object.is_none() ? std::string() : py::str(fspath(csv_object)).cast<std::string>();
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
  const auto fspath = py::module_::import("os").attr("fspath");
  const auto path_of = [&](const py::handle& o) -> std::string {
    if (py::isinstance<py::str>(o) || (py::hasattr(o, "__fspath__") && !py::isinstance<py::bytes>(o)))
      return py::str(fspath(o)).cast<std::string>();
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

py::tuple do_lqr(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q, const Eigen::MatrixXd& R,
              bool discrete) {
  LqrResult r;
  {
    py::gil_scoped_release release;
    r = study_lqr(A, B, Q, R, discrete);
  }
  return py::make_tuple(r.K, r.X, r.closed_loop_poles);
}

Eigen::MatrixXd do_place(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::VectorXcd& poles) {
  py::gil_scoped_release release;
  return study_place(A, B, poles);
}

}  // namespace

}  // namespace codyna::python

PYBIND11_MODULE(_codyna, m) {
  using namespace codyna;
  using namespace codyna::python;
  m.doc() = "The C++ half of codyna's Python module: bindings of core/study (import codyna, not this).";
  m.attr("__version__") = CODYNA_VERSION;

  g_model_error = PyErr_NewExceptionWithDoc(
      "codyna.ModelError",
      "A bad model or a bad choice in it: the message is the command line's, naming the file and the\n"
      "field (\"pendulum.json: /bodies/0/mass: ...\"). Attributes: file, path (the field, JSON-pointer\n"
      "like), detail (what was expected).",
      PyExc_ValueError, nullptr);
  g_convergence_error = PyErr_NewExceptionWithDoc(
      "codyna.ConvergenceError",
      "An equilibrium or trim search that did not converge: the message names the residual, the\n"
      "unknowns and what to free. Nothing is linearized, exported or simulated about such a point.",
      PyExc_RuntimeError, nullptr);
  m.add_object("ModelError", py::handle(g_model_error));
  m.add_object("ConvergenceError", py::handle(g_convergence_error));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ModelError& e) {
      py::object type = py::reinterpret_borrow<py::object>(g_model_error);
      py::object exc = type(py::str(e.what()));
      exc.attr("file") = e.file();
      exc.attr("path") = e.path();
      exc.attr("detail") = e.detail();
      PyErr_SetObject(g_model_error, exc.ptr());
    } catch (const ConvergenceError& e) {
      PyErr_SetString(g_convergence_error, e.what());
    } catch (const StudyCancelled& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  py::class_<Study>(m, "_Study", "A model file as read (codyna.Study wraps it).")
      .def(py::init(&study_from_file), "path"_a, "Reads and checks a model file (ModelError names the file and the field).")
      .def_static("from_json", &study_from_json, "text"_a, "base_dir"_a = ".",
                  "A model from a JSON text; relative paths in it are relative to base_dir.")
      .def_readonly("file", &Study::file, "the model file (or the label of a JSON text)")
      .def_property_readonly("notes", [](const Study& s) { return s.spec->notes; }, "the model reader's notes")
      .def("model_info", &model_info, "What `codyna info` shows, as a dict (see codyna.Study.model_info).")
      .def("to_json", [](const Study& s) { return study_model_json(*s.spec).dump(2); },
           "The model as the file format writes it (JSON text).");

  m.def("_linearize", &do_linearize, "study"_a, "options"_a,
        "study_linearize_job with the keywords given (a dict); codyna.Study.linearize documents them.");
  m.def("_simulate", &do_simulate, "study"_a, "options"_a,
        "study_simulate_job with the keywords given (a dict); codyna.Study.simulate documents them.");

  m.def("_sweep", &do_sweep, "study"_a, "options"_a,
        "study_sweep_job with the keywords given (a dict); codyna.Study.sweep documents them.");
  m.def("_sweep_merge", &do_sweep_merge, "shards"_a, "options"_a,
        "study_sweep_merge of the shards' files with out, csv, mat (a dict); codyna.sweep_merge documents them.");

  py::class_<ClosedLoopResult>(m, "ClosedLoop",
                               "The linear closed loop of the study's plant and controller (linearize(closed_loop=True)).\n"
                               "A, B, C, D are the command line's Acl, Bcl, Ccl, Dcl (NAME_cl.mat).")
      .def_property_readonly("A", [](const ClosedLoopResult& c) { return c.system().A; }, "Acl (closed-loop states: the plant's deviations, then the controller's states)")
      .def_property_readonly("B", [](const ClosedLoopResult& c) { return c.system().B; }, "Bcl (inputs: references dr = r - y0, then disturbances)")
      .def_property_readonly("C", [](const ClosedLoopResult& c) { return c.system().C; }, "Ccl (outputs: the plant's outputs dy, then the efforts du)")
      .def_property_readonly("D", [](const ClosedLoopResult& c) { return c.system().D; }, "Dcl")
      .def_property_readonly("x0", [](const ClosedLoopResult& c) { return c.system().x0; }, "the closed loop's operating point (states)")
      .def_property_readonly("u0", [](const ClosedLoopResult& c) { return c.system().u0; }, "its inputs' nominal values")
      .def_property_readonly("y0", [](const ClosedLoopResult& c) { return c.system().y0; }, "its outputs' nominal values")
      .def_property_readonly("Ts", [](const ClosedLoopResult& c) { return c.system().Ts; }, "sample time (0: continuous; > 0: a sampled controller around the plant's ZOH model)")
      .def_property_readonly("state_names", [](const ClosedLoopResult& c) { return c.system().state_names; }, "names of the closed loop's states")
      .def_property_readonly("input_names", [](const ClosedLoopResult& c) { return c.system().input_names; }, "names of its inputs")
      .def_property_readonly("output_names", [](const ClosedLoopResult& c) { return c.system().output_names; }, "names of its outputs")
      .def_property_readonly("state_units", [](const ClosedLoopResult& c) { return c.system().state_units; }, "units of its states")
      .def_property_readonly("input_units", [](const ClosedLoopResult& c) { return c.system().input_units; }, "units of its inputs")
      .def_property_readonly("output_units", [](const ClosedLoopResult& c) { return c.system().output_units; }, "units of its outputs")
      .def_property_readonly("controller", [](const ClosedLoopResult& c) { return c.cl().loop.controller; },
                             "the controller's description")
      .def_property_readonly("controller_source", [](const ClosedLoopResult& c) { return c.cl().setup.controller_source; }, "where the controller came from: the model file's, lqr, a .mat")
      .def_property_readonly("sizes", [](const ClosedLoopResult& c) {
        const ClosedLoopLinear& l = c.cl().loop;
        return py::dict("nx"_a = l.nx, "nxc"_a = l.nxc, "nr"_a = l.nr, "nd"_a = l.nd, "ny"_a = l.ny, "nu"_a = l.nu);
      }, "plant states nx, controller states nxc, reference inputs nr, disturbance inputs nd, outputs ny, efforts nu")
      .def("poles", [](const ClosedLoopResult& c) { return eigenvalues_of(c.cl().poles); },
           "The closed loop's poles (numpy complex), sorted as the printed table.")
      .def_property_readonly("poles_text", [](const ClosedLoopResult& c) { return study_format_modes(c.cl().poles); },
                             "the poles table the command line prints")
      .def_property_readonly("step", [](const ClosedLoopResult& c) {
        const StepResponse& s = c.cl().step;
        return py::dict("t"_a = vector_of(s.t), "y"_a = s.y);
      }, "step responses: t and, per input, an array (len(t), outputs)")
      .def_property_readonly("frequency", [](const ClosedLoopResult& c) {
        const FrequencyResponse& f = c.cl().frequency;
        return py::dict("w"_a = vector_of(f.w), "H"_a = f.H, "magnitude"_a = f.magnitude, "phase_deg"_a = f.phase_deg);
      }, "frequency responses: w [rad/s] and, per frequency, H, |H| and the unwrapped phase (outputs x inputs)")
      .def_property_readonly("notes", [](const ClosedLoopResult& c) {
        std::vector<std::string> n = c.cl().setup.notes;
        n.insert(n.end(), c.cl().notes.begin(), c.cl().notes.end());
        return n;
      }, "what the closed loop's setup and analysis said (the CLI's notes)");

  py::class_<LinearizationResult>(m, "Linearization",
                                  "What Study.linearize returns: the command line's A, B, C, D with their names and\n"
                                  "offsets (x = x0 + dx, u = u0 + du, y = y0 + dy), the operating point, the modes\n"
                                  "and what is uncontrollable or unobservable. Along a trajectory (trajectory=T),\n"
                                  "A, B, C, D, x0, u0, y0, xdot0 are stacked along a first axis, one per time.")
      .def_property_readonly("A", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked(l.job->systems, [](const LinearSystem& s) -> const Eigen::MatrixXd& { return s.A; });
        return py::cast(l.system().A);
      }, "A (nx x nx; stacked (N, nx, nx) along a trajectory): the matrices x' = A x + B u, y = C x + D u in deviations (x = x0 + dx, u = u0 + du, y = y0 + dy)")
      .def_property_readonly("B", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked(l.job->systems, [](const LinearSystem& s) -> const Eigen::MatrixXd& { return s.B; });
        return py::cast(l.system().B);
      }, "B (nx x nu; stacked along a trajectory)")
      .def_property_readonly("C", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked(l.job->systems, [](const LinearSystem& s) -> const Eigen::MatrixXd& { return s.C; });
        return py::cast(l.system().C);
      }, "C (ny x nx; stacked along a trajectory)")
      .def_property_readonly("D", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked(l.job->systems, [](const LinearSystem& s) -> const Eigen::MatrixXd& { return s.D; });
        return py::cast(l.system().D);
      }, "D (ny x nu; stacked along a trajectory)")
      .def_property_readonly("x0", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked_vector(l.job->systems, [](const LinearSystem& s) -> const Eigen::VectorXd& { return s.x0; });
        return py::cast(l.system().x0);
      }, "the operating point's state (nx; stacked (N, nx) along a trajectory)")
      .def_property_readonly("u0", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked_vector(l.job->systems, [](const LinearSystem& s) -> const Eigen::VectorXd& { return s.u0; });
        return py::cast(l.system().u0);
      }, "the Plant/In values there (nu)")
      .def_property_readonly("y0", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return stacked_vector(l.job->systems, [](const LinearSystem& s) -> const Eigen::VectorXd& { return s.y0; });
        return py::cast(l.system().y0);
      }, "the Plant/Out values there (ny)")
      .def_property_readonly("xdot0", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory)
          return stacked_vector(l.job->systems, [](const LinearSystem& s) -> const Eigen::VectorXd& { return s.xdot0; });
        return py::cast(l.system().xdot0);
      }, "the state's derivative there (not 0 away from an equilibrium)")
      .def_property_readonly("Ts", [](const LinearizationResult& l) {
        return l.job->trajectory ? 0.0 : l.system().Ts;
      }, "the sample time (0: continuous)")
      .def_property_readonly("state_names", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].state_names)
                                 : l.system().state_names;
      }, "names of the states, in the order of A's rows")
      .def_property_readonly("input_names", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].input_names)
                                 : l.system().input_names;
      }, "Plant/In names, B's columns")
      .def_property_readonly("output_names", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].output_names)
                                 : l.system().output_names;
      }, "Plant/Out names, C's rows")
      .def_property_readonly("state_units", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].state_units)
                                 : l.system().state_units;
      }, "units of the states")
      .def_property_readonly("input_units", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].input_units)
                                 : l.system().input_units;
      }, "units of the inputs")
      .def_property_readonly("output_units", [](const LinearizationResult& l) {
        return l.job->trajectory ? (l.job->systems.empty() ? std::vector<std::string>() : l.job->systems[0].output_units)
                                 : l.system().output_units;
      }, "units of the outputs")
      .def_property_readonly("name", [](const LinearizationResult& l) { return l.job->name; }, "the export's NAME")
      .def_property_readonly("method", [](const LinearizationResult& l) { return l.job->method; },
                             "the Jacobians': exact, fd-forward or fd-central")
      .def_property_readonly("fd_error", [](const LinearizationResult& l) {
        return l.job->trajectory ? 0.0 : l.job->linearization.lin.fd_error;
      }, "finite differences: max |J_fd - J_exact| / max |J_exact| (0 for exact)")
      .def_property_readonly("independent", [](const LinearizationResult& l) {
        std::vector<std::string> names;
        if (!l.job->trajectory)
          for (int i : l.job->linearization.lin.partition.independent) names.push_back(l.job->model.v_names[i]);
        return names;
      }, "the independent coordinates of the state (closed loops: the partition chosen or given)")
      .def_property_readonly("operating_point", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) return py::none();
        const OperatingPoint& op = l.job->linearization.op;
        return operating_point_of(l.job->model, op, study_coordinates(l.job->model, op.q));
      }, "kind (initial, equilibrium, trim, time=T), t, residual, iterations, coordinates and rates by\n"
         "name, inputs (every actuator) by name, and q, v, u as arrays; None along a trajectory")
      .def_property_readonly("notes", [](const LinearizationResult& l) { return l.job->notes; }, "notes for the user (what codyna linearize prints as notes)")
      .def_property_readonly("warnings", [](const LinearizationResult& l) { return l.job->warnings; }, "warnings for the user (what codyna linearize prints as warnings)")
      .def("eigenvalues", [](const LinearizationResult& l) -> py::object {
        if (l.job->trajectory) throw py::attribute_error("along a trajectory: see max_real and min_real");
        return eigenvalues_of(l.job->modes);
      }, "The eigenvalues of A (numpy complex; z when discrete), in the order of the modes table\n"
         "(by natural frequency).")
      .def_property_readonly("modes", [](const LinearizationResult& l) { return modes_of(l.job->modes); },
                             "one dict per mode: eigenvalue, s (continuous equivalent), natural_frequency [rad/s],\n"
                             "damping_ratio, shape (numpy complex, state order)")
      .def_property_readonly("modes_text", [](const LinearizationResult& l) { return study_format_modes(l.job->modes); },
                             "the modes table the command line prints")
      .def_property_readonly("uncontrollable", [](const LinearizationResult& l) { return hidden_of(l.job->uncontrollable); },
                             "modes the inputs cannot move (continuous plant): eigenvalue, states, margin")
      .def_property_readonly("unobservable", [](const LinearizationResult& l) { return hidden_of(l.job->unobservable); },
                             "modes the outputs cannot see (continuous plant): eigenvalue, states, margin")
      .def_property_readonly("closed_loop", [](const LinearizationResult& l) -> py::object {
        if (!l.job->closed_loop) return py::none();
        return py::cast(ClosedLoopResult{l.job});
      }, "the linear closed loop (a ClosedLoop) with closed_loop=True, else None")
      .def_property_readonly("trajectory", [](const LinearizationResult& l) { return l.job->trajectory; }, "True along a trajectory (linearize(trajectory=T))")
      .def_property_readonly("times", [](const LinearizationResult& l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return vector_of(l.job->times);
      }, "along a trajectory: the times of the systems, else None")
      .def_property_readonly("max_real", [](const LinearizationResult& l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return py::cast(l.job->max_real);
      }, "along a trajectory: the largest Re(eig A) per time")
      .def_property_readonly("min_real", [](const LinearizationResult& l) -> py::object {
        if (!l.job->trajectory) return py::none();
        return py::cast(l.job->min_real);
      }, "along a trajectory: the smallest Re(eig A) per time")
      .def_property_readonly("trajectory_controller", [](const LinearizationResult& l) { return l.job->trajectory_controller; }, "along a trajectory: the controller in the loop (\"open loop\" or its description)")
      .def("export", &export_linearization, "dir"_a,
           "export(dir) -> tuple of paths\n\n"
           "Writes what `codyna linearize MODEL --out dir` with the same options writes: dir/NAME.mat and\n"
           "dir/NAME.m (and, with closed_loop=True, NAME_cl.mat, NAME_cl.m, NAME_cl_step.csv,\n"
           "NAME_cl_freq.csv), refusing to replace the model or a file codyna did not write. The folder\n"
           "is created if missing. Returns the paths written, in order.");

  py::class_<SimulationRun>(m, "Simulation",
                            "What Study.simulate returns: the run's samples (one row per output time), names,\n"
                            "the linear prediction when compare_linear=True, and the reports of `codyna simulate`.")
      .def_property_readonly("t", [](const SimulationRun& s) { return vector_of(s.job.result.t); }, "output times (N)")
      .def_property_readonly("q", [](const SimulationRun& s) { return s.job.result.q; }, "configuration (N x nq), q_names")
      .def_property_readonly("v", [](const SimulationRun& s) { return s.job.result.v; }, "velocities (N x nv), v_names")
      .def_property_readonly("x", [](const SimulationRun& s) {
        const SimulationResult& r = s.job.result;
        Eigen::MatrixXd x(r.q.rows(), r.q.cols() + r.v.cols());
        x << r.q, r.v;
        return x;
      }, "[q v] (N x (nq + nv)), x_names: the stored state of the run (quaternions for ball and free\n"
         "joints), not the linear model's minimal state")
      .def_property_readonly("u", [](const SimulationRun& s) { return s.job.result.u; },
                             "every actuator's value after saturation (N x nu), input_names")
      .def_property_readonly("y", [](const SimulationRun& s) { return s.job.result.y; }, "Plant/Out (N x ny), output_names")
      .def_property_readonly("xc", [](const SimulationRun& s) { return s.job.result.xc; },
                             "controller states (N x nxc), controller_state_names")
      .def_property_readonly("y_linear", [](const SimulationRun& s) -> py::object {
        const SimulationResult& r = s.job.result;
        if (r.y_linear.size() == 0) return py::none();
        return py::cast(r.y_linear);
      }, "the linear closed loop's outputs from the same start (compare_linear=True), else None")
      .def_property_readonly("y_reference", [](const SimulationRun& s) -> py::object {
        if (s.job.result.y_reference.size() == 0) return py::none();
        return py::cast(s.job.result.y_reference);
      }, "r(t) the controller was given (N x ny), None without references")
      .def_property_readonly("u_disturbance", [](const SimulationRun& s) -> py::object {
        if (s.job.result.u_disturbance.size() == 0) return py::none();
        return py::cast(s.job.result.u_disturbance);
      }, "d(t) added to each actuator (N x nu), None without disturbances")
      .def_property_readonly("kinetic_energy", [](const SimulationRun& s) { return vector_of(s.job.result.kinetic_energy); }, "kinetic energy per sample (J)")
      .def_property_readonly("potential_energy", [](const SimulationRun& s) { return vector_of(s.job.result.potential_energy); }, "potential energy per sample (J)")
      .def_property_readonly("constraint_violation", [](const SimulationRun& s) { return vector_of(s.job.result.constraint_violation); }, "max |phi(q)| per sample (0 for trees)")
      .def_property_readonly("velocity_violation", [](const SimulationRun& s) { return vector_of(s.job.result.velocity_violation); }, "max |Jc v| per sample")
      .def_property_readonly("q_names", [](const SimulationRun& s) { return s.job.result.q_names; }, "names of q's columns")
      .def_property_readonly("v_names", [](const SimulationRun& s) { return s.job.result.v_names; }, "names of v's columns")
      .def_property_readonly("x_names", [](const SimulationRun& s) {
        std::vector<std::string> n = s.job.result.q_names;
        n.insert(n.end(), s.job.result.v_names.begin(), s.job.result.v_names.end());
        return n;
      }, "q_names + v_names")
      .def_property_readonly("input_names", [](const SimulationRun& s) { return s.job.result.input_names; }, "every actuator's name (u's columns)")
      .def_property_readonly("output_names", [](const SimulationRun& s) { return s.job.result.output_names; }, "Plant/Out names (y's columns)")
      .def_property_readonly("input_units", [](const SimulationRun& s) { return s.job.result.input_units; }, "units of u's columns")
      .def_property_readonly("output_units", [](const SimulationRun& s) { return s.job.result.output_units; }, "units of y's columns")
      .def_property_readonly("controller_state_names", [](const SimulationRun& s) { return s.job.result.controller_state_names; }, "names of xc's columns")
      .def_property_readonly("completed", [](const SimulationRun& s) { return s.job.result.completed; }, "reached t_end")
      .def_property_readonly("failure", [](const SimulationRun& s) { return s.job.result.failure; },
                             "a failed run: the time and reason (the samples up to it are kept); \"\" otherwise")
      .def_property_readonly("controller", [](const SimulationRun& s) { return s.job.result.controller; },
                             "the controller's description")
      .def_property_readonly("controller_source", [](const SimulationRun& s) { return s.job.setup.controller_source; }, "\"the model file's ...\", \"lqr\", a .mat, or \"none\"")
      .def_property_readonly("lqr_gain", [](const SimulationRun& s) -> py::object {
        if (s.job.setup.lqr_gain.size() == 0) return py::none();
        return py::cast(s.job.setup.lqr_gain);
      }, "the gain K designed with lqr=True (u = u0 - K (x - x0), the export's state order), else None")
      .def_property_readonly("lqr_poles", [](const SimulationRun& s) -> py::object {
        if (s.job.setup.lqr_poles.size() == 0) return py::none();
        return py::cast(s.job.setup.lqr_poles);
      }, "eig(A - B K) of that design, else None")
      .def_property_readonly("linear_poles", [](const SimulationRun& s) -> py::object {
        if (s.job.setup.linear_poles.size() == 0) return py::none();
        return py::cast(s.job.setup.linear_poles);
      }, "a linear controller: the linear closed loop's poles about the operating point, else None")
      .def_property_readonly("linear_discrete", [](const SimulationRun& s) { return s.job.setup.linear_discrete; }, "the linear closed-loop poles are z (a sampled controller)")
      .def_property_readonly("linear_unstable", [](const SimulationRun& s) { return s.job.setup.linear_unstable; }, "a linear closed-loop pole is unstable (the run is not refused for it)")
      .def_property_readonly("operating_point", [](const SimulationRun& s) -> py::object {
        const LinearPlant* plant = s.job.setup.plant.get();
        if (!plant) return py::none();
        return operating_point_of(s.job.model, plant->op, s.job.op_coordinates);
      }, "the point the controller and the linear comparison are about (as Linearization.operating_point),\n"
         "None when nothing needs a plant")
      .def_property_readonly("initial_coordinates", [](const SimulationRun& s) -> py::object {
        if (s.job.initial_coordinates.size() == 0) return py::none();
        return named(s.job.model.v_names, s.job.initial_coordinates);
      }, "the run's start by coordinate, when the study names an initial state, else None")
      .def_property_readonly("linear_region", [](const SimulationRun& s) -> py::object {
        const LinearRegion& r = s.job.region;
        if (r.measured.empty()) return py::none();
        return py::dict("bound"_a = r.bound, "measured"_a = r.measured, "left_at"_a = r.left_at, "left_on"_a = r.left_on,
                        "largest"_a = r.largest, "largest_on"_a = r.largest_on, "final_distance"_a = r.final_distance,
                        "final_on"_a = r.final_on, "settled"_a = r.settled);
      }, "how far the run went from the operating point (left_at = -1: stayed within), None without a plant")
      .def_property_readonly("linear_gap", [](const SimulationRun& s) -> py::object {
        if (s.job.linear_gap.size() == 0) return py::none();
        return py::dict("max_abs"_a = named(s.job.result.output_names, s.job.linear_gap),
                        "percent"_a = named(s.job.result.output_names, s.job.linear_gap_percent),
                        "from_time"_a = named(s.job.result.output_names, s.job.linear_gap_from));
      }, "compare_linear=True: per output, the largest |y - y_linear|, that in % of the output's\n"
         "excursion, and the first time the gap passes 1 % (-1: never); else None")
      .def_property_readonly("linear_failure", [](const SimulationRun& s) { return s.job.result.linear_failure; }, "why y_linear ends in NaN (an unstable linear loop), or \"\"")
      .def_property_readonly("linear_error_estimate", [](const SimulationRun& s) { return s.job.result.linear_error_estimate; }, "max |y_linear - the same at 100x looser tolerances| (-1: not known)")
      .def_property_readonly("saturation", [](const SimulationRun& s) {
        py::list l;
        for (const Saturation& x : s.job.saturation)
          l.append(py::dict("actuator"_a = x.actuator, "at_max"_a = x.at_max, "at_min"_a = x.at_min, "first"_a = x.first));
        return l;
      }, "actuators that sat at a limit: seconds at max and at min, first time")
      .def_property_readonly("stats", [](const SimulationRun& s) {
        const SolverStats& x = s.job.result.stats;
        return py::dict("integrator"_a = x.integrator, "rtol"_a = x.rtol, "atol"_a = x.atol, "max_step"_a = x.max_step,
                        "steps"_a = x.steps, "rhs_evals"_a = x.rhs_evals, "jac_evals"_a = x.jac_evals,
                        "error_test_failures"_a = x.error_test_failures, "nonlinear_iterations"_a = x.nonlinear_iterations,
                        "nonlinear_failures"_a = x.nonlinear_failures, "projections"_a = x.projections,
                        "restarts"_a = x.restarts, "wall_time"_a = x.wall_time, "integrator_choice"_a = x.integrator_choice);
      }, "the integrator's statistics (integrator, tolerances, steps, evaluations, wall_time ...)")
      .def_property_readonly("settings_json", [](const SimulationRun& s) { return s.job.result.settings_json; }, "the run's settings as JSON text (what the HDF5 file's provenance holds)")
      .def_property_readonly("notes", [](const SimulationRun& s) { return s.job.notes; }, "notes for the user (what codyna simulate prints as notes)")
      .def_property_readonly("warnings", [](const SimulationRun& s) { return s.job.warnings; }, "warnings for the user (unstable linear loop, leaving the linear region ...)")
      .def("save", &save_simulation, "path"_a, "csv"_a = py::none(),
           "save(path, csv=None)\n\n"
           "Writes the results as `codyna simulate --out path [--csv csv]` does (HDF5, and CSV when csv\n"
           "is given; path may be None for CSV only), each atomically, refusing to replace the model,\n"
           "the controller file or a file codyna did not write.");

  py::class_<SweepResult>(m, "Sweep",
                          "What Study.sweep returns: the parameter study `codyna sweep` runs (docs/parameter-studies.md).\n"
                          "Per-variant arrays have the variants first, laid out as the HDF5 file's datasets, with NaN\n"
                          "where a variant has no value (it failed, or was not simulated).")
      .def("__len__", [](const SweepResult& s) { return s.job->variants.size(); }, "the number of variants")
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
      .def_property_readonly("output_names", [](const SweepResult& s) { return s.job->output_names; }, "Plant/Out names (C's rows)")
      .def_property_readonly("A", [](const SweepResult& s) {
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
      .def_property_readonly("method", [](const SweepResult& s) { return s.job->method; }, "the Jacobians' method")
      .def_property_readonly("simulated", [](const SweepResult& s) { return s.job->simulated; }, "simulate=True: every variant was also run")
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

  for (const char* name : {"ClosedLoop", "Linearization", "Simulation", "Sweep"}) m.attr(name).attr("__module__") = "codyna";

  m.def("lqr", &do_lqr, "A"_a, "B"_a, "Q"_a, "R"_a, "discrete"_a = false,
        "lqr(A, B, Q, R, discrete=False) -> (K, X, poles)\n\n"
        "The linear-quadratic regulator, MATLAB's sign convention u = -K x: K (m x n), the stabilizing\n"
        "Riccati solution X and the closed-loop poles eig(A - B K) (sorted by real, then imaginary\n"
        "part). discrete=True: for x[k+1] = A x[k] + B u[k] (dlqr). Bad sizes or weights, or a pair\n"
        "that cannot be stabilized, raise ValueError with the reason.");
  m.def("place", &do_place, "A"_a, "B"_a, "poles"_a,
        "place(A, B, poles) -> K\n\n"
        "Pole placement as MATLAB's place: u = -K x puts eig(A - B K) at `poles` (complex ones in\n"
        "conjugate pairs). Raises ValueError when it cannot.");
}
