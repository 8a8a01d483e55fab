// _codyna: the C++ half of the Python module `codyna` (docs/python.md).
//
// It binds core's study/ layer and the model/ types it hands back, and nothing below them:
// each Python call is one study call. Its files do conversion only: Python keywords into a
// LinearizeRequest / SimulateRequest / SweepRequest (OptionStyle::Keyword, so the core's messages
// name the keywords), Eigen matrices into numpy arrays, names into lists, C++ exceptions into
// Python ones. They decide nothing, compute nothing and read or write no file themselves.
//
// This file is the module's entry: it calls each file's register_* in turn. What is shared
// (Study, Keywords, the common conversions) is in bind_common.hpp; each study is bound in its
// own file: bind_errors.cpp, bind_model.cpp, bind_linearize.cpp, bind_simulate.cpp,
// bind_sweep.cpp, bind_tools.cpp.
//
// The pure-Python package (python/codyna/__init__.py) gives Study its keyword signatures and
// docstrings and calls the functions registered here with a dict of the keywords given.
#include "bind_common.hpp"
#include "model/model_spec.hpp"

PYBIND11_MODULE(_codyna, m) {
  using namespace codyna::python;
  m.doc() = "The C++ half of codyna's Python module: bindings of core/study (import codyna, not this).";
  m.attr("__version__") = CODYNA_VERSION;
  // the integrators simulate() takes: the core's list (model_spec.hpp), which the CLI's help and the
  // GUI's combo show too
  {
    pybind11::list names;
    for (const char* name : codyna::kIntegratorNames) names.append(name);
    m.attr("integrators") = pybind11::tuple(names);
  }

  register_errors(m);
  register_model(m);
  register_linearize(m);
  register_simulate(m);
  register_sweep(m);
  for (const char* name : {"ClosedLoop", "Linearization", "Simulation", "Sweep"}) m.attr(name).attr("__module__") = "codyna";
  register_tools(m);
  register_maneuver(m);
  register_kc(m);
  register_freqresp(m);
}
