// Metrics of the standard handling maneuvers, on sampled signals (t ascending, one value per t):
//
//   step_response_metrics   ISO 7401 step steer: from the instant t_ref (the steer's 50 % point)
//                           the response time (first crossing of 90 % of the change to the steady
//                           value, linearly interpolated between samples), the peak response time
//                           (the largest excursion, refined by the parabola through the peak sample
//                           and its neighbours), the overshoot (peak - steady) / (steady - initial)
//                           in %, and the steady-state gain (steady - initial) / input step. The
//                           steady value is the mean over the last `steady_window` seconds.
//   sine_with_dwell_metrics FMVSS 126 / ISO 19365: the first peak of the yaw rate after the steer
//                           changes sign (at peak_from; in the second half wave's direction,
//                           peak_sign; the first local peak of at least half the largest until the
//                           steer ends, so a ripple is not taken for it), the yaw-rate ratios
//                           r(t_end + 1.0) / r_peak and r(t_end + 1.75) / r_peak in %, and the
//                           lateral displacement at t_start + 1.07 s (from the start's position,
//                           perpendicular to the start's heading).
//   path_error_metrics      a driven path's lateral error: max |e| and RMS over a window.
//   understeer_diagram      constant radius: the understeer gradient d(delta)/d(a_y) - d(L/R)/d(a_y)
//                           (the second term zero on one radius) by central differences over the
//                           points (one-sided at the ends), in rad per m/s^2.
// Cost O(N). Everything throws std::invalid_argument on signals too short for the metric.
#pragma once

#include <complex>
#include <string>
#include <vector>

namespace codyna {

// linear interpolation of y(t) at tq (clamped to the ends)
double sample_at(const std::vector<double>& t, const std::vector<double>& y, double tq);

struct StepMetrics {
  double initial = 0, steady = 0;       // the signal before the step and in the steady state
  double gain = 0;                      // (steady - initial) / step
  double response_time = 0;             // s from t_ref to 90 % of the change (-1: never reached)
  double peak_time = 0;                 // s from t_ref to the largest excursion
  double peak = 0;                      // the value there
  double overshoot_percent = 0;         // (peak - steady) / (steady - initial) * 100 (0 without overshoot)
};
StepMetrics step_response_metrics(const std::vector<double>& t, const std::vector<double>& y, double t_ref,
                                  double step, double steady_window = 0.5);

struct SineWithDwellMetrics {
  double peak_yaw_rate = 0, peak_time = 0;       // the first peak after the steer changes sign (rad/s, s)
  double yrr_1_00 = 0, yrr_1_75 = 0;             // % of the peak
  double lateral_displacement = 0;               // m at t_start + 1.07 s
  bool passes_fmvss126 = false;                  // yrr_1_00 <= 35, yrr_1_75 <= 20, |displacement| >= 1.83
};
SineWithDwellMetrics sine_with_dwell_metrics(const std::vector<double>& t, const std::vector<double>& yaw_rate,
                                             const std::vector<double>& lateral, double t_start, double t_end,
                                             double peak_sign, double peak_from);

struct PathErrorMetrics {
  double max_abs = 0, rms = 0;
  double at = 0;  // time of the largest
};
PathErrorMetrics path_error_metrics(const std::vector<double>& t, const std::vector<double>& e, double from = -1e300,
                                    double to = 1e300);

// K(a_y) at each point of (a_y, delta) sorted by a_y (delta the road-wheel angle, rad)
std::vector<double> understeer_diagram(const std::vector<double>& ay, const std::vector<double>& delta);

// the time and value of the sampled maximum of sign * y on [from, to], refined by a parabola
// through the sample and its neighbours
// ISO 7401's frequency-response characteristic values from a yaw-rate (and lateral-acceleration)
// response to steer on a frequency grid f (Hz, rising): the gain at the grid's lowest frequency
// (standing for the steady state), the resonance (the largest yaw-rate gain inside the grid, found
// by a parabola through the largest sample and its neighbours in log f; 0 when the largest is at an
// end), the peak ratio (largest gain / lowest-frequency gain), and the phases at 1 Hz (deg, by
// linear interpolation of the unwrapped phase; NaN when 1 Hz is outside the grid).
struct SweptSineCharacteristics {
  double yaw_gain_low = 0, resonance_hz = 0, peak_ratio = 0, yaw_phase_1hz = 0;
  double lateral_gain_low = 0, lateral_phase_1hz = 0;  // NaN without a lateral acceleration
};
SweptSineCharacteristics swept_sine_characteristics(const std::vector<double>& f,
                                                    const std::vector<std::complex<double>>& yaw_rate,
                                                    const std::vector<std::complex<double>>& lateral = {});

struct SampledPeak {
  double t = 0, value = 0;
  int index = -1;
};
SampledPeak sampled_peak(const std::vector<double>& t, const std::vector<double>& y, double sign, double from,
                         double to, bool first_local = false);

}  // namespace codyna
