// codyna.lqr and codyna.place: the core's study_lqr and study_place on numpy matrices (their
// std::invalid_argument: a ValueError), without the GIL while they run.
#include "bind_common.hpp"

namespace codyna::python {

namespace {

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

void register_tools(py::module_& m) {
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

}  // namespace codyna::python
