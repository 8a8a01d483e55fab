// What the files of _codyna (the C++ half of the Python module `codyna`, docs/python.md) share:
// the includes, the model file as read (Study), Python keywords into request fields (Keywords,
// take_point, take_plant), the result conversions more than one study uses (vector_of, named,
// operating_point_of, fspath), and the register_* functions module.cpp's PYBIND11_MODULE calls,
// one per file (bind_errors.cpp, bind_model.cpp, bind_linearize.cpp, bind_simulate.cpp,
// bind_sweep.cpp, bind_tools.cpp, where each is defined; the rest is defined in bind_common.cpp).
//
// Conversion only: nothing here decides, computes or reads or writes a file. The module is built
// in unity batches (cmake/unity.cmake): a helper in one file's anonymous namespace must not share
// a name with another file's (build.unity_names); a helper two files need belongs here.
#pragma once

#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <climits>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
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

// The model file as read: what every study call starts from (codyna.Study wraps the bound _Study).
struct Study {
  std::shared_ptr<const ModelSpec> spec;
  std::string file;  // the request's `model`: messages, relative paths, outputs that must not replace it
  std::string text;  // from_json: the text (a sweep's variants are edits of it); "": the file's
};

// ---------------------------------------------------------------------------------------------
// Keywords -> request fields

[[noreturn]] void type_error(const std::string& what);  // a Python TypeError
std::string type_name(const py::handle& o);              // o's Python type, for messages
std::string fspath(const py::handle& o);                 // os.fspath(o) as text

// The dict the Python layer passes (only the keywords given, None left out); every field taken
// is removed, and what is left at the end is a keyword the function does not know (TypeError
// naming it, as Python says it). A value of the wrong type is a TypeError naming the keyword.
class Keywords {
 public:
  Keywords(const py::dict& given, std::string function);

  // the value of `key` (or of its alias), if given
  std::optional<py::object> take(const std::string& key, const std::string& alias = "");
  std::optional<std::string> text(const std::string& key);
  std::optional<std::string> path(const std::string& key);  // str or os.PathLike
  std::optional<double> number(const std::string& key);
  bool flag(const std::string& key);  // True or False; not given: false
  // names: one str, or an iterable of str
  std::optional<std::vector<std::string>> names(const std::string& key, const std::string& alias = "");
  // numbers: one number, or an iterable (list, numpy array) of numbers
  std::optional<std::vector<double>> numbers(const std::string& key);
  // NAME=VALUE texts: a dict {name: value} (each value written with 17 significant digits, so
  // that the core reads back the same double), or "NAME=VALUE" strings (one, or a list)
  std::vector<std::string> pairs(const std::string& key, const std::string& alias = "");
  // a whole number (int or a numpy integer; a float or a bool is a TypeError) within [lo, hi]
  std::optional<long long> whole(const std::string& key, long long lo = LLONG_MIN, long long hi = LLONG_MAX);
  std::optional<std::uint64_t> whole_u64(const std::string& key);  // an unsigned 64-bit whole number (a seed)
  // FIELD=SPEC texts: "FIELD=SPEC" strings (one, or a list), or a dict {field: spec} whose spec
  // is a SPEC text ("5:15:11", "normal(10,3)"), a sequence of numbers (the list [v1,v2,...],
  // each written with 17 significant digits) or one number (a list of one)
  std::vector<std::string> field_specs(const std::string& key);
  // a sweep's shard: (K, N) (a tuple or list of two whole numbers), the command's "K/N" text or
  // "slurm" (a Slurm job array task's), read and checked by the core's study_parse_shard /
  // study_check_shard as codyna sweep --shard is (their std::invalid_argument: a ValueError)
  std::optional<SweepShard> shard(const std::string& key);
  // signals: a "NAME=VALUE[@TIME]" string or a dict (the model file's object, as JSON text),
  // one or a list of them
  std::optional<std::vector<std::string>> signals(const std::string& key, const std::string& alias = "");

  // what is left was not asked for
  void finish() const;

 private:
  py::iterable iterable(const py::object& o, const std::string& key, const char* expected) const;
  std::string text_of(const py::handle& o, const std::string& key) const;
  double number_of(const py::handle& o, const std::string& key) const;
  py::int_ int_of(const py::handle& o, const std::string& key) const;
  std::string signal_of(const py::handle& o, const std::string& key) const;
  std::string numbers_list(const py::handle& o, const std::string& key, const std::string& field) const;

  std::string function_;
  std::vector<std::pair<std::string, py::object>> items_;
};

// The keywords linearize and simulate share: the operating point's and the plant's
void take_point(Keywords& k, PointRequest& p);
void take_plant(Keywords& k, PlantRequest& p);

// ---------------------------------------------------------------------------------------------
// Results -> Python values

py::array_t<double> vector_of(const std::vector<double>& v);
// {name: value} for the first min(len(names), len(v)) entries
py::dict named(const std::vector<std::string>& names, const Eigen::VectorXd& v);
// Linearization.operating_point and Simulation.operating_point: kind, t, residual, iterations,
// coordinates, rates and every actuator's input by name, and q, v, u as arrays
py::dict operating_point_of(const Model& m, const OperatingPoint& op, const Eigen::VectorXd& coordinates);

// ---------------------------------------------------------------------------------------------
// One per file, called by module.cpp in this order

void register_errors(py::module_& m);     // bind_errors.cpp: ModelError, ConvergenceError, the translator
void register_model(py::module_& m);      // bind_model.cpp: _Study (read, from_json, model_info, to_json)
void register_linearize(py::module_& m);  // bind_linearize.cpp: _linearize, ClosedLoop, Linearization
void register_simulate(py::module_& m);   // bind_simulate.cpp: _simulate, Simulation
void register_sweep(py::module_& m);      // bind_sweep.cpp: _sweep, _sweep_merge, Sweep
void register_tools(py::module_& m);      // bind_tools.cpp: lqr, place
void register_maneuver(py::module_& m);   // bind_maneuver.cpp: _maneuver
void register_kc(py::module_& m);         // bind_kc.cpp: _kc
void register_freqresp(py::module_& m);   // bind_freqresp.cpp: _freqresp

}  // namespace codyna::python
