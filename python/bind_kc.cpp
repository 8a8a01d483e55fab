// _codyna._kc: study_kc_job (study/kc_job.hpp, the suspension K&C rig) with the keywords given,
// its report as a dict of plain values and numpy columns. Conversion only.
#include <sstream>

#include "bind_common.hpp"
#include "study/kc_job.hpp"

namespace codyna::python {

namespace {

// a sweep: "MIN:MAX:N" or a sequence (min, max, n)
std::optional<KcRange> kc_range_of(Keywords& k, const std::string& key) {
  const std::optional<py::object> o = k.take(key);
  if (!o) return std::nullopt;
  if (py::isinstance<py::str>(*o)) return study_kc_range(o->cast<std::string>(), key);
  if (!py::isinstance<py::sequence>(*o) || py::len(*o) != 3)
    type_error(key + ": expected \"MIN:MAX:N\" or (min, max, n), got " + type_name(*o));
  const py::sequence s = o->cast<py::sequence>();
  std::ostringstream text;
  text.precision(17);
  try {
    text << s[0].cast<double>() << ":" << s[1].cast<double>() << ":" << s[2].cast<long long>();
  } catch (const py::cast_error&) {
    type_error(key + ": expected (min, max, n) with numbers and a whole n");
  }
  return study_kc_range(text.str(), key);
}

py::dict kc_point_of(const KcPoint& p) {
  return py::dict("sweep"_a = p.sweep, "wheel"_a = p.wheel, "travel"_a = p.travel, "roll"_a = p.roll, "steer"_a = p.steer,
                  "fx"_a = p.fx, "fy"_a = p.fy, "mz"_a = p.mz, "wheel_centre"_a = p.wheel_centre, "contact"_a = p.contact,
                  "camber"_a = p.camber, "toe"_a = p.toe, "caster"_a = p.caster, "kingpin"_a = p.kingpin,
                  "track_change"_a = p.track_change, "wheelbase_change"_a = p.wheelbase_change,
                  "scrub_radius"_a = p.scrub_radius, "caster_trail"_a = p.caster_trail);
}

py::dict do_kc(const Study& s, const py::dict& options) {
  Keywords k(options, "kc");
  KcRequest r;
  r.model = s.file;
  r.spec = s.spec.get();
  if (const auto w = k.names("wheels", "wheel")) r.wheels = *w;
  r.held = k.text("held").value_or("");
  r.steer = k.text("steer").value_or("");
  r.radius = k.number("radius");
  r.travel = kc_range_of(k, "travel");
  r.roll = kc_range_of(k, "roll");
  r.steer_range = kc_range_of(k, "steer_range");
  r.fx = kc_range_of(k, "fx");
  r.fy = kc_range_of(k, "fy");
  r.mz = kc_range_of(k, "mz");
  r.csv = k.path("csv").value_or("");
  k.finish();
  KcReport rep;
  {
    py::gil_scoped_release release;
    rep = study_kc_job(r);
  }
  py::list wheels;
  for (const KcWheel& w : rep.wheels) {
    const KcGradients& g = w.gradients;
    wheels.append(py::dict(
        "name"_a = w.name, "radius"_a = w.radius, "design"_a = kc_point_of(w.design),
        "gradients"_a = py::dict("bump_steer"_a = g.bump_steer, "bump_camber"_a = g.bump_camber,
                                 "track_per_travel"_a = g.track_per_travel, "roll_centre_height"_a = g.roll_centre_height,
                                 "roll_steer"_a = g.roll_steer, "roll_camber"_a = g.roll_camber, "fy_steer"_a = g.fy_steer,
                                 "fy_camber"_a = g.fy_camber, "fx_steer"_a = g.fx_steer, "fx_camber"_a = g.fx_camber,
                                 "mz_steer"_a = g.mz_steer, "mz_camber"_a = g.mz_camber)));
  }
  py::list points;
  for (const KcPoint& p : rep.points) points.append(kc_point_of(p));
  return py::dict("model"_a = rep.model, "held"_a = rep.held, "steer"_a = rep.steer, "steer_unit"_a = rep.steer_unit,
                  "wheels"_a = wheels, "points"_a = points, "roll_centre"_a = py::make_tuple(rep.roll_centre_y, rep.roll_centre_z),
                  "notes"_a = rep.notes, "written"_a = rep.written, "text"_a = study_kc_text(rep));
}

}  // namespace

void register_kc(py::module_& m) {
  m.def("_kc", &do_kc, "study"_a, "options"_a, "study_kc_job with the keywords given (a dict); codyna.Study.kc documents them.");
}

}  // namespace codyna::python
