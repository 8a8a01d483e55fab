// _codyna._maneuver: study_maneuver_job (study/maneuver_job.hpp) with the keywords given, its
// report as a dict of plain values. Conversion only.
#include "bind_common.hpp"
#include "study/maneuver_job.hpp"

namespace codyna::python {

namespace {

py::dict maneuver_step_of(const StepMetrics& m) {
  return py::dict("initial"_a = m.initial, "steady"_a = m.steady, "gain"_a = m.gain, "response_time"_a = m.response_time,
                  "peak_time"_a = m.peak_time, "peak"_a = m.peak, "overshoot_percent"_a = m.overshoot_percent);
}

py::dict swept_characteristics_of(const SweptSineCharacteristics& c) {
  return py::dict("yaw_gain_low"_a = c.yaw_gain_low, "resonance_hz"_a = c.resonance_hz, "peak_ratio"_a = c.peak_ratio,
                  "yaw_phase_1hz"_a = c.yaw_phase_1hz, "lateral_gain_low"_a = c.lateral_gain_low,
                  "lateral_phase_1hz"_a = c.lateral_phase_1hz);
}

py::array_t<std::complex<double>> complex_array(const std::vector<std::complex<double>>& v) {
  py::array_t<std::complex<double>> a(static_cast<py::ssize_t>(v.size()));
  auto m = a.mutable_unchecked<1>();
  for (std::size_t k = 0; k < v.size(); ++k) m(static_cast<py::ssize_t>(k)) = v[k];
  return a;
}

py::dict do_maneuver(const Study& s, const py::dict& options) {
  Keywords k(options, "maneuver");
  ManeuverRequest r;
  r.style = OptionStyle::Keyword;
  r.model = s.file;
  r.type = k.text("type").value_or("");
  r.out = k.path("out").value_or("");
  r.csv = k.path("csv").value_or("");
  r.speed = k.number("speed");
  r.steer = k.number("steer");
  r.steer_time = k.number("steer_time");
  r.ramp = k.number("ramp");
  r.frequency = k.number("frequency");
  r.dwell = k.number("dwell");
  r.steer_scale = k.number("steer_scale");
  r.frequency_min = k.number("frequency_min");
  r.frequency_max = k.number("frequency_max");
  r.sweep_time = k.number("sweep_time");
  r.t_end = k.number("t_end");
  r.output_step = k.number("output_step");
  r.radius = k.number("radius");
  r.speed_min = k.number("speed_min");
  r.speed_max = k.number("speed_max");
  r.ay_min = k.number("ay_min");
  r.ay_max = k.number("ay_max");
  if (const auto n = k.whole("points", 2, 1000)) r.points = static_cast<int>(*n);
  r.width = k.number("width");
  r.length = k.number("length");
  r.preview = k.number("preview");
  r.lateral_gain = k.number("lateral_gain");
  r.speed_kp = k.number("speed_kp");
  r.speed_ki = k.number("speed_ki");
  r.sample_time = k.number("sample_time");
  r.x = k.text("x");
  r.y = k.text("y");
  r.yaw = k.text("yaw");
  r.speed_output = k.text("speed_output");
  r.drive = k.text("drive");
  r.integrator = k.text("integrator");
  r.free_inputs = k.names("free_inputs", "free_input");
  r.open_loop = k.flag("open_loop");
  r.friction = k.number("friction");
  r.steer_rate = k.number("steer_rate");
  k.finish();
  ManeuverReport rep;
  {
    py::gil_scoped_release release;
    rep = study_maneuver_job(r, *s.spec);
  }
  py::dict d("type"_a = rep.type, "model"_a = rep.model_name, "speed"_a = rep.speed, "valid"_a = rep.valid,
             "invalid_reason"_a = rep.invalid_reason, "notes"_a = rep.notes, "written"_a = rep.written,
             "text"_a = study_maneuver_text(rep));
  if (!rep.controller.empty()) {
    d["controller"] = rep.controller;
    d["reference_gain"] = rep.reference_gain;
    d["reference_limit"] = rep.reference_limit;
    d["controller_inputs"] = rep.controller_inputs;
    d["controller_effort"] = vector_of(rep.controller_effort);
  }
  if (rep.type == "step-steer" || rep.type == "sine-with-dwell" || rep.type == "slowly-increasing-steer" ||
      rep.type == "fishhook") {
    d["max_sideslip"] = rep.max_sideslip;
    d["max_sideslip_time"] = rep.max_sideslip_time;
  }
  if (rep.type == "step-steer") {
    d["yaw_rate"] = maneuver_step_of(rep.yaw_rate);
    if (rep.has_lateral_acceleration) d["lateral_acceleration"] = maneuver_step_of(rep.lateral_acceleration);
  } else if (rep.type == "sine-with-dwell") {
    d["peak_yaw_rate"] = rep.sine.peak_yaw_rate;
    d["yaw_rate_ratio_1_00"] = rep.sine.yrr_1_00;
    d["yaw_rate_ratio_1_75"] = rep.sine.yrr_1_75;
    d["lateral_displacement"] = rep.sine.lateral_displacement;
    d["passes_fmvss126"] = rep.sine.passes_fmvss126;
    d["steer_at_0_3g"] = rep.steer_03g;
    d["displacement_applies"] = rep.displacement_applies;
  } else if (rep.type == "swept-sine") {
    d["frequency_hz"] = vector_of(rep.sw_frequency);
    d["input_share"] = vector_of(rep.sw_input_share);
    d["yaw_rate_response"] = complex_array(rep.sw_yaw);
    d["lateral_acceleration_response"] = complex_array(rep.sw_lateral);
    d["characteristics"] = swept_characteristics_of(rep.sw_metrics);
    if (rep.sw_has_linear) {
      d["yaw_rate_response_linear"] = complex_array(rep.sw_yaw_linear);
      d["lateral_acceleration_response_linear"] = complex_array(rep.sw_lateral_linear);
      d["characteristics_linear"] = swept_characteristics_of(rep.sw_metrics_linear);
      d["largest_gap_yaw_rate"] = py::make_tuple(rep.sw_gap_yaw, rep.sw_gap_yaw_hz);
      d["largest_gap_lateral_acceleration"] = py::make_tuple(rep.sw_gap_lateral, rep.sw_gap_lateral_hz);
    }
  } else if (rep.type == "slowly-increasing-steer") {
    d["steer_at_0_3g"] = rep.sis_steer_03g;
    d["time_at_0_3g"] = rep.sis_time_03g;
    d["speed_at_0_3g"] = rep.sis_speed_03g;
    d["steady_steer_at_0_3g"] = rep.sis_steady_steer_03g;
    d["understeer_gradient"] = rep.sis_gradient;
    d["steady_understeer_gradient"] = rep.sis_steady_gradient;
    if (rep.handling_gradient) d["handling_understeer_gradient"] = *rep.handling_gradient;
    d["max_lateral_acceleration"] = rep.sis_ay_max;
    d["steer_at_max_lateral_acceleration"] = rep.sis_steer_at_ay_max;
  } else if (rep.type == "fishhook") {
    d["max_roll"] = rep.fh_max_roll;
    d["max_roll_time"] = rep.fh_max_roll_time;
    d["max_lateral_acceleration"] = rep.fh_ay_max;
    d["tires"] = rep.fh_tires;
    d["tire_sides"] = rep.fh_sides;
    d["min_tire_load"] = vector_of(rep.fh_min_load);
    d["min_tire_load_time"] = vector_of(rep.fh_min_load_time);
    d["two_wheel_lift_time"] = rep.fh_lift_time;
    d["two_wheel_lift_side"] = rep.fh_lift_side;
  } else if (rep.type == "double-lane-change") {
    d["path_error_max"] = rep.path.max_abs;
    d["path_error_rms"] = rep.path.rms;
    d["cones_hit"] = rep.cones_hit;
    d["cone_clearance"] = vector_of(rep.cone_clearance);  // per section with cones (1, 3, 5-6), m
    // the lane's centre line and its cones, n x 2 (x, y)
    const auto points = [](const std::vector<Eigen::Vector2d>& v) {
      py::array_t<double> a({static_cast<py::ssize_t>(v.size()), static_cast<py::ssize_t>(2)});
      auto m = a.mutable_unchecked<2>();
      for (std::size_t k = 0; k < v.size(); ++k) m(static_cast<py::ssize_t>(k), 0) = v[k].x(), m(static_cast<py::ssize_t>(k), 1) = v[k].y();
      return a;
    };
    d["lane_path"] = points(rep.lane_path);
    d["lane_cones"] = points(rep.lane_cones);
  } else if (rep.type == "constant-radius" || rep.type == "constant-speed") {
    d["radius"] = rep.radius;
    d["speed"] = vector_of(rep.cr_speed);
    d["lateral_acceleration"] = vector_of(rep.cr_lateral_acceleration);
    d["steer"] = vector_of(rep.cr_steer);
    d["road_wheel_angle"] = vector_of(rep.cr_road_wheel);
    d["sideslip"] = vector_of(rep.cr_sideslip);
    d["roll"] = vector_of(rep.cr_roll);
    d["understeer_gradient"] = vector_of(rep.cr_gradient);
    if (!rep.cr_linear_steer.empty()) d["linear_steer"] = vector_of(rep.cr_linear_steer);
    if (rep.linear_gradient) d["linear_understeer_gradient"] = *rep.linear_gradient;
    if (rep.handling_gradient) d["handling_understeer_gradient"] = *rep.handling_gradient;
  }
  if (rep.type != "constant-radius" && rep.type != "constant-speed") {
    d["t"] = vector_of(rep.result.t);
    d["outputs"] = rep.result.y;
    d["output_names"] = rep.result.output_names;
  }
  return d;
}

}  // namespace

void register_maneuver(py::module_& m) {
  m.def("_maneuver", &do_maneuver, "study"_a, "options"_a,
        "study_maneuver_job with the keywords given (a dict); codyna.Study.maneuver documents them.");
}

}  // namespace codyna::python
