// The module's exceptions: codyna.ModelError (a ValueError with file, path and detail) and
// codyna.ConvergenceError (a RuntimeError), and the translator that raises them, or
// KeyboardInterrupt, for the core's ModelError, ConvergenceError and StudyCancelled (the core's
// std::invalid_argument is pybind11's ValueError).
#include "bind_common.hpp"

namespace codyna::python {

namespace {

PyObject* g_model_error = nullptr;        // codyna.ModelError(ValueError)
PyObject* g_convergence_error = nullptr;  // codyna.ConvergenceError(RuntimeError)

void translate(std::exception_ptr p) {
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
}

}  // namespace

void register_errors(py::module_& m) {
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
  py::register_exception_translator(&translate);
}

}  // namespace codyna::python
