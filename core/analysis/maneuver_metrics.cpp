#include "analysis/maneuver_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace codyna {

namespace {

void check_signal(const std::vector<double>& t, const std::vector<double>& y, std::size_t at_least, const char* what) {
  if (t.size() != y.size())
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(t.size()) + " times but " +
                                std::to_string(y.size()) + " values");
  if (t.size() < at_least)
    throw std::invalid_argument(std::string(what) + ": expected at least " + std::to_string(at_least) +
                                " samples, got " + std::to_string(t.size()));
}

}  // namespace

double sample_at(const std::vector<double>& t, const std::vector<double>& y, double tq) {
  if (t.empty()) throw std::invalid_argument("sample_at: no samples");
  if (tq <= t.front()) return y.front();
  if (tq >= t.back()) return y.back();
  const auto it = std::upper_bound(t.begin(), t.end(), tq);
  const std::size_t k = static_cast<std::size_t>(it - t.begin());
  const double w = (tq - t[k - 1]) / (t[k] - t[k - 1]);
  return y[k - 1] + w * (y[k] - y[k - 1]);
}

SampledPeak sampled_peak(const std::vector<double>& t, const std::vector<double>& y, double sign, double from,
                         double to, bool first_local) {
  SampledPeak p;
  const std::size_t n = t.size();
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k) {
    if (t[k] < from || t[k] > to) continue;
    const double v = sign * y[k];
    if (first_local) {
      if (k > 0 && k + 1 < n && v > 0 && v >= sign * y[k - 1] && v > sign * y[k + 1]) {
        p.index = static_cast<int>(k);
        break;
      }
      continue;
    }
    if (v > best) {
      best = v;
      p.index = static_cast<int>(k);
    }
  }
  if (p.index < 0) {
    p.t = 0;
    p.value = 0;
    return p;
  }
  const std::size_t k = static_cast<std::size_t>(p.index);
  p.t = t[k];
  p.value = y[k];
  if (k > 0 && k + 1 < n) {
    // the parabola through the three samples (uniform spacing assumed: the output grid)
    const double h = 0.5 * (t[k + 1] - t[k - 1]);
    const double a = 0.5 * (y[k + 1] - 2 * y[k] + y[k - 1]), b = 0.5 * (y[k + 1] - y[k - 1]);
    if (a != 0) {
      const double x = std::clamp(-b / (2 * a), -1.0, 1.0);
      p.t = t[k] + x * h;
      p.value = y[k] + b * x + a * x * x;
    }
  }
  return p;
}

StepMetrics step_response_metrics(const std::vector<double>& t, const std::vector<double>& y, double t_ref,
                                  double step, double steady_window) {
  check_signal(t, y, 3, "step response");
  if (!(step != 0)) throw std::invalid_argument("step response: the input step is 0");
  StepMetrics m;
  m.initial = y.front();
  double sum = 0;
  int count = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= t.back() - steady_window) {
      sum += y[k];
      ++count;
    }
  m.steady = sum / count;
  const double change = m.steady - m.initial;
  m.gain = change / step;
  if (change == 0) throw std::invalid_argument("step response: the signal does not change");
  // 90 % of the change: the first crossing after t_ref
  m.response_time = -1;
  for (std::size_t k = 1; k < t.size(); ++k) {
    if (t[k] < t_ref) continue;
    const double f0 = (y[k - 1] - m.initial) / change, f1 = (y[k] - m.initial) / change;
    if (f1 >= 0.9) {
      const double tk = f1 == f0 ? t[k] : t[k - 1] + (0.9 - f0) / (f1 - f0) * (t[k] - t[k - 1]);
      m.response_time = std::max(tk, t_ref) - t_ref;
      break;
    }
  }
  const double sign = change > 0 ? 1.0 : -1.0;
  const SampledPeak p = sampled_peak(t, y, sign, t_ref, t.back());
  m.peak = p.value;
  m.peak_time = p.t - t_ref;
  m.overshoot_percent = std::max(0.0, (p.value - m.steady) / change * 100.0);
  return m;
}

SineWithDwellMetrics sine_with_dwell_metrics(const std::vector<double>& t, const std::vector<double>& yaw_rate,
                                             const std::vector<double>& lateral, double t_start, double t_end,
                                             double peak_sign, double peak_from) {
  check_signal(t, yaw_rate, 3, "sine with dwell: yaw rate");
  check_signal(t, lateral, 3, "sine with dwell: lateral position");
  if (t.back() < t_end + 1.75)
    throw std::invalid_argument("sine with dwell: the run ends at " + std::to_string(t.back()) +
                                " s, before 1.75 s after the steer ends (" + std::to_string(t_end + 1.75) + " s)");
  SineWithDwellMetrics m;
  // the first local peak of at least half the largest excursion in that direction until the steer
  // ends (a ripple is not the peak)
  const double sign = peak_sign > 0 ? 1.0 : -1.0;
  const SampledPeak largest = sampled_peak(t, yaw_rate, sign, peak_from, t_end);
  if (largest.index < 0 || !(sign * largest.value > 0))
    throw std::invalid_argument("sine with dwell: the yaw rate has no first peak");
  SampledPeak p;
  for (double from = peak_from;;) {
    p = sampled_peak(t, yaw_rate, sign, from, t.back(), true);
    if (p.index < 0 || sign * p.value >= 0.5 * sign * largest.value) break;
    from = t[static_cast<std::size_t>(p.index) + 1];
  }
  if (p.index < 0) throw std::invalid_argument("sine with dwell: the yaw rate has no first peak");
  m.peak_yaw_rate = p.value;
  m.peak_time = p.t;
  m.yrr_1_00 = sample_at(t, yaw_rate, t_end + 1.0) / p.value * 100.0;
  m.yrr_1_75 = sample_at(t, yaw_rate, t_end + 1.75) / p.value * 100.0;
  m.lateral_displacement = sample_at(t, lateral, t_start + 1.07);
  m.passes_fmvss126 = m.yrr_1_00 <= 35.0 && m.yrr_1_75 <= 20.0 && std::abs(m.lateral_displacement) >= 1.83;
  return m;
}

PathErrorMetrics path_error_metrics(const std::vector<double>& t, const std::vector<double>& e, double from,
                                    double to) {
  check_signal(t, e, 1, "path error");
  PathErrorMetrics m;
  double sum = 0;
  int count = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < from || t[k] > to) continue;
    sum += e[k] * e[k];
    ++count;
    if (std::abs(e[k]) > m.max_abs) {
      m.max_abs = std::abs(e[k]);
      m.at = t[k];
    }
  }
  if (count == 0) throw std::invalid_argument("path error: no samples in the window");
  m.rms = std::sqrt(sum / count);
  return m;
}

std::vector<double> understeer_diagram(const std::vector<double>& ay, const std::vector<double>& delta) {
  check_signal(ay, delta, 2, "understeer diagram");
  const std::size_t n = ay.size();
  std::vector<double> K(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? n - 1 : k + 1;
    if (!(ay[b] != ay[a])) throw std::invalid_argument("understeer diagram: two points at the same lateral acceleration");
    K[k] = (delta[b] - delta[a]) / (ay[b] - ay[a]);
  }
  return K;
}

namespace {

// the unwrapped phase (deg) of H over the grid, each step taken the short way
std::vector<double> unwrapped_phase_deg(const std::vector<std::complex<double>>& H) {
  std::vector<double> p(H.size());
  constexpr double deg = 180 / 3.14159265358979323846;
  for (std::size_t k = 0; k < H.size(); ++k) {
    p[k] = std::arg(H[k]) * deg;
    if (k > 0) p[k] -= 360 * std::round((p[k] - p[k - 1]) / 360);
  }
  return p;
}

double at_one_hz(const std::vector<double>& f, const std::vector<double>& v) {
  for (std::size_t k = 0; k + 1 < f.size(); ++k)
    if (f[k] <= 1.0 && f[k + 1] >= 1.0) return v[k] + (v[k + 1] - v[k]) * (1.0 - f[k]) / (f[k + 1] - f[k]);
  return std::nan("");
}

}  // namespace

SweptSineCharacteristics swept_sine_characteristics(const std::vector<double>& f,
                                                    const std::vector<std::complex<double>>& yaw_rate,
                                                    const std::vector<std::complex<double>>& lateral) {
  if (f.size() < 3 || yaw_rate.size() != f.size() || (!lateral.empty() && lateral.size() != f.size()))
    throw std::invalid_argument("swept_sine_characteristics: expected at least 3 frequencies and a response at each");
  for (std::size_t k = 0; k + 1 < f.size(); ++k)
    if (!(f[k] > 0 && f[k + 1] > f[k])) throw std::invalid_argument("swept_sine_characteristics: the frequencies must rise from above 0");
  SweptSineCharacteristics c;
  c.yaw_gain_low = std::abs(yaw_rate.front());
  std::size_t top = 0;
  for (std::size_t k = 1; k < f.size(); ++k)
    if (std::abs(yaw_rate[k]) > std::abs(yaw_rate[top])) top = k;
  double peak = std::abs(yaw_rate[top]);
  if (top > 0 && top + 1 < f.size()) {
    // the parabola through the three samples in x = log f
    const double x0 = std::log(f[top - 1]), x1 = std::log(f[top]), x2 = std::log(f[top + 1]);
    const double y0 = std::abs(yaw_rate[top - 1]), y1 = peak, y2 = std::abs(yaw_rate[top + 1]);
    const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), a = (d12 - d01) / (x2 - x0);
    const double b = d01 - a * (x0 + x1);
    const double xm = a < 0 ? -b / (2 * a) : x1;
    c.resonance_hz = std::exp(xm);
    peak = std::max(peak, y0 + (xm - x0) * (d01 + a * (xm - x1)));
  }
  c.peak_ratio = c.yaw_gain_low > 0 ? peak / c.yaw_gain_low : std::nan("");
  c.yaw_phase_1hz = at_one_hz(f, unwrapped_phase_deg(yaw_rate));
  c.lateral_gain_low = lateral.empty() ? std::nan("") : std::abs(lateral.front());
  c.lateral_phase_1hz = lateral.empty() ? std::nan("") : at_one_hz(f, unwrapped_phase_deg(lateral));
  return c;
}

}  // namespace codyna
