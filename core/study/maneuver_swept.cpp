// The swept-sine steer (ISO 7401's frequency response): study/maneuver_job.hpp.
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "analysis/closed_loop_linear.hpp"
#include "analysis/frequency_estimate.hpp"
#include "model/errors.hpp"
#include "study/maneuver_detail.hpp"
#include "study/workflow.hpp"

namespace codyna::mnv {

namespace {

// a sine of amplitude A whose frequency rises exponentially from f0 to f1 over T, from t0, its
// amplitude tapered by half cosines over the first and last `a` seconds (the steer starts and
// ends at rest with its rate: a motion input takes it)
SteerProfile swept_profile(double A, double t0, double f0, double f1, double T, double a) {
  const double k = std::log(f1 / f0) / T;
  struct Parts {
    double w, dw, ddw, phi, dphi, ddphi;
  };
  const auto parts = [=](double t) {
    Parts p{0, 0, 0, 0, 0, 0};
    const double tau = t - t0;
    if (tau <= 0 || tau >= T) return p;
    const double c = kPi / a;
    const double s = tau < a ? tau : tau > T - a ? T - tau : -1.0;  // in a taper: the time from its end
    const double sign = tau > T - a ? -1.0 : 1.0;                     // d s / d t
    if (s < 0) {
      p.w = 1;
    } else {
      p.w = 0.5 * (1 - std::cos(c * s));
      p.dw = sign * 0.5 * c * std::sin(c * s);
      p.ddw = 0.5 * c * c * std::cos(c * s);
    }
    p.dphi = 2 * kPi * f0 * std::exp(k * tau);
    p.phi = (p.dphi - 2 * kPi * f0) / k;
    p.ddphi = k * p.dphi;
    return p;
  };
  SteerProfile sp;
  sp.value = [=](double t) {
    const Parts p = parts(t);
    return A * p.w * std::sin(p.phi);
  };
  sp.rate = [=](double t) {
    const Parts p = parts(t);
    return A * (p.dw * std::sin(p.phi) + p.w * std::cos(p.phi) * p.dphi);
  };
  sp.acceleration = [=](double t) {
    const Parts p = parts(t);
    const double sn = std::sin(p.phi), cs = std::cos(p.phi);
    return A * (p.ddw * sn + 2 * p.dw * cs * p.dphi + p.w * (cs * p.ddphi - sn * p.dphi * p.dphi));
  };
  return sp;
}

// the largest |H - H_lin| over the grid, relative to the largest |H_lin|, and where
void largest_gap(const std::vector<double>& f, const std::vector<std::complex<double>>& H,
                 const std::vector<std::complex<double>>& L, double& gap, double& at) {
  double scale = 0;
  for (const auto& l : L) scale = std::max(scale, std::abs(l));
  gap = 0;
  at = f.front();
  for (std::size_t k = 0; k < f.size(); ++k) {
    const double g = scale > 0 ? std::abs(H[k] - L[k]) / scale : 0.0;
    if (g > gap) {
      gap = g;
      at = f[k];
    }
  }
}

std::vector<std::complex<double>> element(const FrequencyResponse& fr, int i, int j) {
  std::vector<std::complex<double>> v;
  for (const Eigen::MatrixXcd& H : fr.H) v.push_back(H(i, j));
  return v;
}

// the linear model's responses on both grids; false (with a note) when the steer is no Plant/In
bool linear_responses(ManeuverReport& rep, const OpenLoop& ol, const std::vector<double>& w_fine,
                      std::vector<std::complex<double>>& yaw_fine, std::vector<std::complex<double>>& lat_fine) {
  int j = -1;
  for (std::size_t k = 0; k < ol.model.plant_inputs.size(); ++k)
    if (ol.model.plant_inputs[k] == ol.steer) j = static_cast<int>(k);
  if (j < 0) {
    rep.notes.push_back("no linear response to compare with: the steer input is not among Plant/In");
    return false;
  }
  const StudyLinearization lin = study_linearize(ol.model);
  std::vector<double> w_table;
  for (double f : rep.sw_frequency) w_table.push_back(2 * kPi * f);
  const FrequencyResponse table = frequency_response(lin.lin.system, w_table), fine = frequency_response(lin.lin.system, w_fine);
  rep.sw_yaw_linear = element(table, ol.yaw_rate, j);
  yaw_fine = element(fine, ol.yaw_rate, j);
  if (ol.lateral_acceleration >= 0) {
    rep.sw_lateral_linear = element(table, ol.lateral_acceleration, j);
    lat_fine = element(fine, ol.lateral_acceleration, j);
  }
  return true;
}

}  // namespace

ManeuverReport swept_sine(const ManeuverRequest& r, const ModelSpec& spec) {
  const Flags flag{r.style};
  ManeuverReport rep;
  rep.type = r.type;
  const double f0 = positive(flag, r.frequency_min, 0.1, "frequency-min");
  const double f1 = positive(flag, r.frequency_max, 2.0, "frequency-max");
  if (!(f1 > f0)) throw std::invalid_argument(flag("frequency-max") + ": expected a frequency above " + flag("frequency-min"));
  const double T = positive(flag, r.sweep_time, 30.0, "sweep-time");
  if (T * f0 < 2)
    throw std::invalid_argument(flag("sweep-time") + ": the sweep must last at least 2 periods of " + flag("frequency-min"));
  const int n = r.points ? *r.points : 12;
  if (n < 3 || n > 1000) throw std::invalid_argument(flag("points") + ": expected 3 to 1000 frequencies");
  const double A = r.steer ? *r.steer : 0.01;
  if (!std::isfinite(A) || A == 0) throw std::invalid_argument(flag("steer") + ": expected a steer amplitude other than 0");
  const double t0 = r.steer_time ? *r.steer_time : 0.5;
  if (!(t0 >= 0) || !std::isfinite(t0)) throw std::invalid_argument(flag("steer-time") + ": expected a time >= 0");
  const double t_end = r.t_end ? *r.t_end : t0 + T + 5.0;
  if (!(t_end >= t0 + T + 1.0))
    throw std::invalid_argument(flag("t-end") + ": the run must last at least 1 s past the sweep's end (the response settles)");

  const OpenLoop ol = open_loop_setup(r, spec);
  rep.model_name = ol.model.name;
  rep.speed = ol.start.v_body.norm();
  rep.steer = A;
  rep.steer_start = t0;
  rep.steer_end = t0 + T;
  // the sweep reaches 1.25 times past both ends of the band, where its half-cosine tapers (a
  // twentieth of its time each) lie, so that the band is excited at the full amplitude
  const double a = 0.05 * T;
  const SteerProfile profile = swept_profile(A, t0, f0 / 1.25, f1 * 1.25, T, a);
  open_loop_run(rep, r, ol, profile, {t0, t0 + a, t0 + T - a, t0 + T}, t_end);
  if (rep.result.samples() < 3) {
    write(rep, r);
    return rep;
  }
  // the deviations from the straight run, and their transforms' ratio
  const std::vector<double>& t = rep.result.t;
  std::vector<double> du(t.size()), dyaw = column(rep.result, ol.yaw_rate), dlat;
  for (std::size_t k = 0; k < t.size(); ++k) du[k] = profile.value(t[k]);
  for (double& y : dyaw) y -= rep.result.y(0, ol.yaw_rate);
  if (ol.lateral_acceleration >= 0) {
    dlat = column(rep.result, ol.lateral_acceleration);
    for (double& y : dlat) y -= rep.result.y(0, ol.lateral_acceleration);
  }
  rep.sw_frequency = log_grid(f0, f1, n);
  const std::vector<double> f_fine = log_grid(f0, f1, 200);
  std::vector<double> w_table, w_fine;
  for (double f : rep.sw_frequency) w_table.push_back(2 * kPi * f);
  for (double f : f_fine) w_fine.push_back(2 * kPi * f);
  const TransformRatio yaw = transform_ratio(t, du, dyaw, w_table), yaw_fine = transform_ratio(t, du, dyaw, w_fine);
  rep.sw_yaw = yaw.H;
  rep.sw_input_share = yaw.input_share;
  std::vector<std::complex<double>> lat_fine;
  if (!dlat.empty()) {
    rep.sw_lateral = transform_ratio(t, du, dlat, w_table).H;
    lat_fine = transform_ratio(t, du, dlat, w_fine).H;
  }
  rep.sw_metrics = swept_sine_characteristics(f_fine, yaw_fine.H, lat_fine);
  std::vector<std::complex<double>> yaw_lin_fine, lat_lin_fine;
  rep.sw_has_linear = linear_responses(rep, ol, w_fine, yaw_lin_fine, lat_lin_fine);
  if (rep.sw_has_linear) {
    rep.sw_metrics_linear = swept_sine_characteristics(f_fine, yaw_lin_fine, lat_lin_fine);
    largest_gap(f_fine, yaw_fine.H, yaw_lin_fine, rep.sw_gap_yaw, rep.sw_gap_yaw_hz);
    if (!lat_fine.empty()) largest_gap(f_fine, lat_fine, lat_lin_fine, rep.sw_gap_lateral, rep.sw_gap_lateral_hz);
  }
  write(rep, r);
  return rep;
}

}  // namespace codyna::mnv
