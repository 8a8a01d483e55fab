// _codyna._freqresp: study_freqresp_job (study/freqresp_job.hpp) with the keywords given, its job
// as a dict of numpy arrays. Conversion only.
#include <pybind11/numpy.h>

#include "bind_common.hpp"
#include "study/freqresp_job.hpp"

namespace codyna::python {

namespace {

// one (frequencies x outputs x inputs) array per quantity
py::array_t<std::complex<double>> freqresp_cube(const FreqRespJob& job, Eigen::MatrixXcd FreqRespPoint::*m) {
  const auto nw = static_cast<py::ssize_t>(job.points.size());
  const auto ny = static_cast<py::ssize_t>(job.output_names.size()), nu = static_cast<py::ssize_t>(job.input_names.size());
  py::array_t<std::complex<double>> a({nw, ny, nu});
  auto v = a.mutable_unchecked<3>();
  for (py::ssize_t w = 0; w < nw; ++w)
    for (py::ssize_t i = 0; i < ny; ++i)
      for (py::ssize_t j = 0; j < nu; ++j) v(w, i, j) = (job.points[static_cast<std::size_t>(w)].*m)(i, j);
  return a;
}

py::array_t<double> freqresp_real_cube(const FreqRespJob& job, Eigen::MatrixXd FreqRespPoint::*m) {
  const auto nw = static_cast<py::ssize_t>(job.points.size());
  const auto ny = static_cast<py::ssize_t>(job.output_names.size()), nu = static_cast<py::ssize_t>(job.input_names.size());
  py::array_t<double> a({nw, ny, nu});
  auto v = a.mutable_unchecked<3>();
  for (py::ssize_t w = 0; w < nw; ++w)
    for (py::ssize_t i = 0; i < ny; ++i)
      for (py::ssize_t j = 0; j < nu; ++j) v(w, i, j) = (job.points[static_cast<std::size_t>(w)].*m)(i, j);
  return a;
}

py::dict do_freqresp(const Study& s, const py::dict& options) {
  Keywords k(options, "freqresp");
  FreqRespRequest r;
  SimulateRequest& run = r.run;
  run.style = OptionStyle::Keyword;
  run.model = s.file;
  take_point(k, run.point);
  take_plant(k, run.plant);
  run.controller = k.path("controller");
  run.lqr = k.flag("lqr");
  run.lqr_controllable_part = k.flag("lqr_controllable_part");
  run.open_loop = k.flag("open_loop");
  run.q_weights = k.numbers("q_weights");
  run.r_weights = k.numbers("r_weights");
  run.integrator = k.text("integrator");
  run.rtol = k.number("rtol");
  run.atol = k.number("atol");
  run.max_step = k.number("max_step");
  if (const auto w = k.numbers("frequencies")) r.frequencies = *w;
  if (const auto a = k.numbers("amplitude")) r.amplitudes = *a;
  if (const auto n = k.whole("settle_periods", 0, 1000000)) r.settle_periods = static_cast<int>(*n);
  if (const auto n = k.whole("periods", 1, 1000000)) r.periods = static_cast<int>(*n);
  if (const auto n = k.whole("samples_per_period", 1, 1000000)) r.samples_per_period = static_cast<int>(*n);
  if (const auto n = k.whole("harmonics", 1, 1000)) r.harmonics = static_cast<int>(*n);
  r.csv = k.path("csv").value_or("");
  r.out = k.path("out").value_or("");
  k.finish();
  FreqRespJob job;
  {
    py::gil_scoped_release release;
    job = study_freqresp_job(r, *s.spec);
  }
  std::vector<double> w;
  for (const FreqRespPoint& p : job.points) w.push_back(p.w);
  return py::dict("w"_a = vector_of(w), "G"_a = freqresp_cube(job, &FreqRespPoint::G),
                  "G_linear"_a = freqresp_cube(job, &FreqRespPoint::G_linear),
                  "gap"_a = freqresp_real_cube(job, &FreqRespPoint::gap),
                  "distortion"_a = freqresp_real_cube(job, &FreqRespPoint::distortion), "input_names"_a = job.input_names,
                  "output_names"_a = job.output_names, "input_units"_a = job.input_units, "output_units"_a = job.output_units,
                  "amplitudes"_a = job.amplitudes, "operating_point"_a = job.operating_point, "controller"_a = job.controller,
                  "largest_gap"_a = job.largest_gap, "notes"_a = job.notes, "warnings"_a = job.warnings,
                  "written"_a = job.written, "text"_a = study_freqresp_text(job));
}

}  // namespace

void register_freqresp(py::module_& m) { m.def("_freqresp", &do_freqresp); }

}  // namespace codyna::python
