#include "analysis/closed_loop_linear.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "analysis/discretize.hpp"

namespace codyna {

namespace {

void expect_matrix_size(const char* what, const Eigen::MatrixXd& M, Eigen::Index rows, Eigen::Index cols) {
  if (M.rows() == rows && M.cols() == cols) return;
  std::ostringstream os;
  os << "closed loop: the controller's " << what << " is " << M.rows() << " x " << M.cols() << ", expected " << rows
     << " x " << cols << " for this plant";
  throw std::invalid_argument(os.str());
}

}  // namespace

ClosedLoopLinear close_loop(const LinearSystem& plant_in, const LinearLaw& law, const DisturbanceInputs& w_in,
                            const std::vector<std::string>& xc_names, const std::string& description) {
  if (plant_in.Ts > 0) throw std::invalid_argument("closed loop: the plant must be continuous (it is discretized here when the controller is sampled)");
  const int nx = plant_in.nx(), nu = plant_in.nu(), ny = plant_in.ny(), nz = plant_in.npositions();
  const int nd = static_cast<int>(w_in.Bw.cols());
  const int nxc = static_cast<int>(law.Ak.rows());
  expect_matrix_size("Ak", law.Ak, nxc, nxc);
  expect_matrix_size("Bx", law.Bx, nxc, nx);
  expect_matrix_size("By", law.By, nxc, ny);
  expect_matrix_size("Bv", law.Bv, nxc, ny);
  expect_matrix_size("Br", law.Br, nxc, ny);
  expect_matrix_size("Ck", law.Ck, nu, nxc);
  expect_matrix_size("Dx", law.Dx, nu, nx);
  expect_matrix_size("Dy", law.Dy, nu, ny);
  expect_matrix_size("Dv", law.Dv, nu, ny);
  expect_matrix_size("Dr", law.Dr, nu, ny);
  if (w_in.Bw.rows() != nx || w_in.Dw.rows() != ny || w_in.Dw.cols() != nd)
    throw std::invalid_argument("closed loop: the disturbance columns do not fit the plant");

  // the plant over [u, w]: continuous, or its exact ZOH model at the controller's sample time
  LinearSystem p = plant_in;
  p.B.resize(nx, nu + nd);
  p.B << plant_in.B, w_in.Bw;
  p.D.resize(ny, nu + nd);
  p.D << plant_in.D, w_in.Dw;
  if (law.Ts > 0) {
    if ((law.Bv.size() && law.Bv.cwiseAbs().maxCoeff() > 0) || (law.Dv.size() && law.Dv.cwiseAbs().maxCoeff() > 0))
      throw std::invalid_argument("closed loop: a sampled controller with derivative action on the outputs' rates is not supported");
    p = discretize_zoh(p, law.Ts);
  }
  const Eigen::MatrixXd B = p.B.leftCols(nu), Bw = p.B.rightCols(nd);
  const Eigen::MatrixXd D = p.D.leftCols(nu), Dw = p.D.rightCols(nd);
  const Eigen::MatrixXd& A = p.A;
  const Eigen::MatrixXd& C = p.C;

  // ydot = Cv dx: the z-columns of C applied to the velocity states w
  Eigen::MatrixXd Cv = Eigen::MatrixXd::Zero(ny, nx);
  if (nz > 0 && 2 * nz == nx) Cv.rightCols(nz) = plant_in.C.leftCols(nz);
  // rolling: fewer rates than positions, zdot = A_zw w
  else if (nz > 0) Cv.rightCols(nx - nz).noalias() = plant_in.C.leftCols(nz) * plant_in.A.topRightCorner(nz, nx - nz);
  // the controller's direct dependence on dx: Dx + Dv Cv (and Bx + Bv Cv)
  const Eigen::MatrixXd Dx = law.Dx + law.Dv * Cv, Bx = law.Bx + law.Bv * Cv;

  // du = M [(Dx + Dy C) dx + Ck xc + Dr dr + Dy Dw dw],  M = (I - Dy D)^-1
  const Eigen::MatrixXd L = Eigen::MatrixXd::Identity(nu, nu) - law.Dy * D;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(L);
  if (nu > 0 && !lu.isInvertible())
    throw std::invalid_argument("closed loop: the algebraic loop through the plant's D and the controller's feedthrough is singular (I - Dy D)");
  // M X = R; an empty side (no controller states, no disturbances) is not handed to Eigen's
  // triangular solve, which would bind a reference to its null data (UBSan)
  const auto solve = [&](const Eigen::MatrixXd& R) -> Eigen::MatrixXd {
    if (nu == 0 || R.cols() == 0) return Eigen::MatrixXd::Zero(nu, R.cols());
    return lu.solve(R);
  };
  const Eigen::MatrixXd Ux = solve(Dx + law.Dy * C);
  const Eigen::MatrixXd Uc = solve(law.Ck);
  const Eigen::MatrixXd Ur = solve(law.Dr);
  const Eigen::MatrixXd Uw = solve(law.Dy * Dw);
  // dy = Yx dx + Yc xc + Yr dr + Yw dw
  const Eigen::MatrixXd Yx = C + D * Ux, Yc = D * Uc, Yr = D * Ur, Yw = Dw + D * Uw;

  const int n = nx + nxc, m = ny + nd, q = ny + nu;
  ClosedLoopLinear cl;
  cl.nx = nx;
  cl.nxc = nxc;
  cl.nr = ny;
  cl.nd = nd;
  cl.ny = ny;
  cl.nu = nu;
  cl.controller = description;
  LinearSystem& s = cl.system;
  s.A.resize(n, n);
  s.A << A + B * Ux, B * Uc, Bx + law.By * Yx, law.Ak + law.By * Yc;
  s.B.resize(n, m);
  s.B << B * Ur, Bw + B * Uw, law.Br + law.By * Yr, law.By * Yw;
  s.C.resize(q, n);
  s.C << Yx, Yc, Ux, Uc;
  s.D.resize(q, m);
  s.D << Yr, Yw, Ur, Uw;
  s.Ts = law.Ts;

  // names, units and offsets
  s.state_names = plant_in.state_names;
  s.state_units = plant_in.state_units;
  for (int k = 0; k < nxc; ++k) {
    s.state_names.push_back(k < static_cast<int>(xc_names.size()) ? xc_names[k] : "xc" + std::to_string(k + 1));
    if (!s.state_units.empty()) s.state_units.push_back("");
  }
  for (int k = 0; k < ny; ++k) {
    s.input_names.push_back("r_" + plant_in.output_names[k]);
    s.input_units.push_back(k < static_cast<int>(plant_in.output_units.size()) ? plant_in.output_units[k] : "");
  }
  for (int k = 0; k < nd; ++k) {
    s.input_names.push_back("d_" + (k < static_cast<int>(w_in.names.size()) ? w_in.names[k] : "w" + std::to_string(k + 1)));
    s.input_units.push_back(k < static_cast<int>(w_in.units.size()) ? w_in.units[k] : "");
  }
  s.output_names = plant_in.output_names;
  s.output_units = plant_in.output_units;
  s.output_units.resize(ny);
  for (int k = 0; k < nu; ++k) {
    s.output_names.push_back("u_" + plant_in.input_names[k]);
    s.output_units.push_back(k < static_cast<int>(plant_in.input_units.size()) ? plant_in.input_units[k] : "");
  }
  s.x0 = Eigen::VectorXd::Zero(n);
  if (plant_in.x0.size() == nx) s.x0.head(nx) = plant_in.x0;
  s.u0 = Eigen::VectorXd::Zero(m);
  if (plant_in.y0.size() == ny) s.u0.head(ny) = plant_in.y0;
  if (w_in.nominal.size() == nd) s.u0.tail(nd) = w_in.nominal;
  s.y0 = Eigen::VectorXd::Zero(q);
  if (plant_in.y0.size() == ny) s.y0.head(ny) = plant_in.y0;
  if (plant_in.u0.size() == nu) s.y0.tail(nu) = plant_in.u0;
  s.xdot0 = Eigen::VectorXd::Zero(n);
  if (plant_in.xdot0.size() == nx) s.xdot0.head(nx) = plant_in.xdot0;
  s.model_name = plant_in.model_name;
  s.model_file = plant_in.model_file;
  s.operating_point = plant_in.operating_point;
  s.method = plant_in.method;
  s.time = plant_in.time;
  s.codyna_version = plant_in.codyna_version;
  s.study = plant_in.study;
  return cl;
}

StepResponse step_response(const LinearSystem& sys, double t_end, int points) {
  if (!(t_end > 0) || !std::isfinite(t_end) || points < 2)
    throw std::invalid_argument("step response: expected an end time > 0 and at least 2 points");
  const int n = sys.nx(), m = sys.nu(), q = sys.ny();
  StepResponse r;
  Eigen::MatrixXd Ad, Bd;
  double h;
  if (sys.Ts > 0) {
    // a discrete loop is given at its own samples, k Ts up to t_end (`points` is not used)
    h = sys.Ts;
    points = static_cast<int>(std::floor(t_end / h + 1e-9)) + 1;
    if (points > 10000000) throw std::invalid_argument("step response: more than 1e7 samples of the discrete loop");
    Ad = sys.A;
    Bd = sys.B;
  } else {
    h = t_end / (points - 1);
    LinearSystem c;
    c.A = sys.A;
    c.B = sys.B;
    c.C = sys.C;
    c.D = sys.D;
    const LinearSystem d = discretize_zoh(c, h);
    Ad = d.A;
    Bd = d.B;
  }
  for (int k = 0; k < points; ++k) r.t.push_back(k * h);
  for (int j = 0; j < m; ++j) {
    Eigen::MatrixXd Y(points, q);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < points; ++k) {
      Y.row(k) = (sys.C * x + sys.D.col(j)).transpose();
      x = Ad * x + Bd.col(j);
    }
    r.y.push_back(std::move(Y));
  }
  return r;
}

FrequencyResponse frequency_response(const LinearSystem& sys, const std::vector<double>& w) {
  const int n = sys.nx(), m = sys.nu(), q = sys.ny();
  FrequencyResponse f;
  f.w = w;
  const Eigen::MatrixXcd A = sys.A.cast<std::complex<double>>(), B = sys.B.cast<std::complex<double>>();
  const Eigen::MatrixXcd C = sys.C.cast<std::complex<double>>(), D = sys.D.cast<std::complex<double>>();
  for (std::size_t k = 0; k < w.size(); ++k) {
    const std::complex<double> s =
        sys.Ts > 0 ? std::exp(std::complex<double>(0, w[k] * sys.Ts)) : std::complex<double>(0, w[k]);
    Eigen::MatrixXcd H = D;
    if (n > 0) {
      const Eigen::MatrixXcd M = s * Eigen::MatrixXcd::Identity(n, n) - A;
      H += C * Eigen::PartialPivLU<Eigen::MatrixXcd>(M).solve(B);
    }
    Eigen::MatrixXd mag(q, m), ph(q, m);
    for (int i = 0; i < q; ++i)
      for (int j = 0; j < m; ++j) {
        mag(i, j) = std::abs(H(i, j));
        double p = std::arg(H(i, j)) * 180.0 / std::numbers::pi;
        if (k > 0) {  // unwrap: the multiple of 360 degrees nearest the previous phase
          const double prev = f.phase_deg.back()(i, j);
          p += 360.0 * std::round((prev - p) / 360.0);
        }
        ph(i, j) = p;
      }
    f.H.push_back(std::move(H));
    f.magnitude.push_back(std::move(mag));
    f.phase_deg.push_back(std::move(ph));
  }
  return f;
}

std::vector<double> log_grid(double w_min, double w_max, int n) {
  if (!(w_min > 0) || !(w_max > w_min) || !std::isfinite(w_max) || n < 2)
    throw std::invalid_argument("frequency grid: expected 0 < w_min < w_max and at least 2 points");
  std::vector<double> w(n);
  const double a = std::log10(w_min), b = std::log10(w_max);
  for (int k = 0; k < n; ++k) w[k] = std::pow(10.0, a + (b - a) * k / (n - 1));
  w.front() = w_min;
  w.back() = w_max;
  return w;
}

double default_step_time(const ModalAnalysis& poles) {
  double slowest = std::numeric_limits<double>::infinity();
  for (const Mode& md : poles.modes) {
    const double sigma = -md.s.real();
    if (sigma > 1e-9) slowest = std::min(slowest, sigma);
  }
  if (!std::isfinite(slowest)) return 10.0;
  return std::clamp(8.0 / slowest, 1.0, 1000.0);
}

std::pair<double, double> default_frequency_range(const ModalAnalysis& poles, double Ts) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const Mode& md : poles.modes) {
    const double wn = md.natural_frequency;
    if (wn > 1e-9) {
      lo = std::min(lo, wn);
      hi = std::max(hi, wn);
    }
  }
  double a = -2, b = 2;
  if (hi > 0) {
    a = std::floor(std::log10(lo)) - 1;
    b = std::ceil(std::log10(hi)) + 1;
  }
  double w_min = std::pow(10.0, a), w_max = std::pow(10.0, b);
  if (Ts > 0) {
    w_max = std::min(w_max, std::numbers::pi / Ts);
    if (!(w_min < w_max)) w_min = w_max / 1000;
  }
  return {w_min, w_max};
}

}  // namespace codyna
