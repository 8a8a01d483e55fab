#include "simulation/controller.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <cmath>
#include <sstream>
#include <stdexcept>


namespace codyna {

std::vector<std::string> Controller::state_names() const {
  std::vector<std::string> n;
  for (int k = 0; k < nxc(); ++k) n.push_back("xc" + std::to_string(k + 1));
  return n;
}

namespace {

class Pid final : public Controller {
 public:
  explicit Pid(PidGains g) : g_(std::move(g)) {
    if (g_.anti_windup.method == AntiWindup::Method::BackCalculation) {
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(g_.Ki);
      Kaw_ = cod.pseudoInverse() / g_.anti_windup.tracking_time;  // ny x nu
    }
  }
  int nxc() const override { return g_.Ki.size() ? static_cast<int>(g_.r.size()) : 0; }
  bool needs_rates() const override { return g_.Kd.size() > 0; }
  bool reads_output(int k) const override {
    const auto reads = [k](const Eigen::MatrixXd& G) { return G.size() > 0 && k < G.cols() && !G.col(k).isZero(0.0); };
    return reads(g_.Kp) || reads(g_.Ki) || reads(g_.Kd);
  }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    const Eigen::VectorXd& r = in.r.size() ? in.r : g_.r;
    Eigen::VectorXd u = g_.u0 + g_.Kp * (r - in.y);
    if (g_.Ki.size()) u += g_.Ki * xc;
    if (g_.Kd.size()) u -= g_.Kd * in.ydot;
    return u;
  }
  Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    if (!g_.Ki.size()) return Eigen::VectorXd();
    const Eigen::VectorXd& r = in.r.size() ? in.r : g_.r;
    Eigen::VectorXd e = r - in.y;
    if (g_.anti_windup.method == AntiWindup::Method::None || in.u.size() != g_.u0.size()) return e;
    const Eigen::VectorXd excess = output(in, xc) - in.u;  // > 0: the input sits at its max, < 0: at its min
    if (g_.anti_windup.method == AntiWindup::Method::BackCalculation) return e - Kaw_ * excess;
    // conditional integration: an integral that would push a saturated input further is held
    for (Eigen::Index j = 0; j < e.size(); ++j)
      for (Eigen::Index i = 0; i < excess.size(); ++i)
        if (excess[i] != 0 && g_.Ki(i, j) * e[j] * excess[i] > 0) {
          e[j] = 0;
          break;
        }
    return e;
  }
  std::vector<std::string> state_names() const override {
    std::vector<std::string> n;
    for (int k = 0; k < nxc(); ++k) n.push_back("integral_error" + std::to_string(k + 1));
    return n;
  }
  std::string describe() const override {
    std::string d = std::string("P") + (g_.Ki.size() ? "I" : "") + (g_.Kd.size() ? "D" : "") + " on the plant outputs";
    if (g_.anti_windup.method == AntiWindup::Method::BackCalculation) {
      std::ostringstream os;
      os << ", anti-windup by back-calculation (tracking time " << g_.anti_windup.tracking_time << " s)";
      d += os.str();
    } else if (g_.anti_windup.method == AntiWindup::Method::Conditional) {
      d += ", anti-windup by conditional integration";
    }
    return d;
  }
  const PidGains* pid() const override { return &g_; }
  std::optional<LinearLaw> linear_law(int nx, int ny) const override {
    const Eigen::Index nu = g_.u0.size(), n = nxc();
    if (g_.r.size() != ny) return std::nullopt;
    LinearLaw l;
    l.Ak = Eigen::MatrixXd::Zero(n, n);
    l.Bx = Eigen::MatrixXd::Zero(n, nx);
    l.By = -Eigen::MatrixXd::Identity(n, ny);
    l.Bv = Eigen::MatrixXd::Zero(n, ny);
    l.Br = Eigen::MatrixXd::Identity(n, ny);
    l.Ck = g_.Ki.size() ? g_.Ki : Eigen::MatrixXd::Zero(nu, 0);
    l.Dx = Eigen::MatrixXd::Zero(nu, nx);
    l.Dy = -g_.Kp;
    l.Dv = g_.Kd.size() ? Eigen::MatrixXd(-g_.Kd) : Eigen::MatrixXd::Zero(nu, ny);
    l.Dr = g_.Kp;
    return l;
  }

 private:
  PidGains g_;
  Eigen::MatrixXd Kaw_;
};

class StateFeedback final : public Controller {
 public:
  StateFeedback(Eigen::MatrixXd K, Eigen::VectorXd u0, Eigen::MatrixXd Nbar, Eigen::VectorXd y0)
      : K_(std::move(K)), u0_(std::move(u0)), Nbar_(std::move(Nbar)), y0_(std::move(y0)) {}
  bool needs_state() const override { return true; }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd&) const override {
    if (Nbar_.size() && in.r.size()) return u0_ - K_ * in.x + Nbar_ * (in.r - y0_);
    return u0_ - K_ * in.x;
  }
  std::string describe() const override {
    return Nbar_.size() ? "state feedback u = u0 - K (x - x0) + Nbar (r - y0)" : "state feedback u = u0 - K (x - x0)";
  }
  const Eigen::MatrixXd* gain() const override { return &K_; }
  std::optional<LinearLaw> linear_law(int nx, int ny) const override {
    if (K_.cols() != nx || (Nbar_.size() && Nbar_.cols() != ny)) return std::nullopt;
    const Eigen::Index nu = K_.rows();
    LinearLaw l;
    l.Ak = Eigen::MatrixXd::Zero(0, 0);
    l.Bx = Eigen::MatrixXd::Zero(0, nx);
    l.By = l.Bv = l.Br = Eigen::MatrixXd::Zero(0, ny);
    l.Ck = Eigen::MatrixXd::Zero(nu, 0);
    l.Dx = -K_;
    l.Dy = l.Dv = Eigen::MatrixXd::Zero(nu, ny);
    l.Dr = Nbar_.size() ? Nbar_ : Eigen::MatrixXd::Zero(nu, ny);
    return l;
  }

 private:
  Eigen::MatrixXd K_;
  Eigen::VectorXd u0_;
  Eigen::MatrixXd Nbar_;
  Eigen::VectorXd y0_;
};

class Lti final : public Controller {
 public:
  Lti(Eigen::MatrixXd Ac, Eigen::MatrixXd Bc, Eigen::MatrixXd Cc, Eigen::MatrixXd Dc, double Ts, Eigen::VectorXd y0,
      Eigen::VectorXd u0)
      : Ac_(std::move(Ac)), Bc_(std::move(Bc)), Cc_(std::move(Cc)), Dc_(std::move(Dc)), Ts_(Ts), y0_(std::move(y0)),
        u0_(std::move(u0)) {}
  int nxc() const override { return static_cast<int>(Ac_.rows()); }
  double sample_time() const override { return Ts_; }
  Eigen::VectorXd output(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    return u0_ + Cc_ * xc + Dc_ * (in.y - (in.r.size() ? in.r : y0_));
  }
  Eigen::VectorXd update(const ControllerInput& in, const Eigen::VectorXd& xc) const override {
    return Ac_ * xc + Bc_ * (in.y - (in.r.size() ? in.r : y0_));
  }
  std::optional<LinearLaw> linear_law(int nx, int ny) const override {
    const Eigen::Index n = nxc();
    if (y0_.size() != ny) return std::nullopt;
    LinearLaw l;
    l.Ak = Ac_;
    l.Bx = Eigen::MatrixXd::Zero(n, nx);
    l.By = Bc_;
    l.Bv = Eigen::MatrixXd::Zero(n, ny);
    l.Br = -Bc_;
    l.Ck = Cc_;
    l.Dx = Eigen::MatrixXd::Zero(u0_.size(), nx);
    l.Dy = Dc_;
    l.Dv = Eigen::MatrixXd::Zero(u0_.size(), ny);
    l.Dr = -Dc_;
    l.Ts = Ts_;
    return l;
  }
  std::string describe() const override {
    std::ostringstream os;
    os << "LTI controller, " << nxc() << " states, " << (Ts_ > 0 ? "discrete Ts = " + std::to_string(Ts_) + " s (ZOH)" : "continuous");
    return os.str();
  }

 private:
  Eigen::MatrixXd Ac_, Bc_, Cc_, Dc_;
  double Ts_;
  Eigen::VectorXd y0_, u0_;
};

void check_size(const std::string& file, const char* name, const Eigen::MatrixXd& M, Eigen::Index rows, Eigen::Index cols) {
  if (M.rows() != rows || M.cols() != cols) {
    std::ostringstream os;
    os << file << ": variable " << name << " is " << M.rows() << " x " << M.cols() << ", expected " << rows << " x "
       << cols;
    throw std::invalid_argument(os.str());
  }
}

}  // namespace

std::unique_ptr<Controller> make_pid(const Eigen::MatrixXd& Kp, const Eigen::MatrixXd& Ki, const Eigen::MatrixXd& Kd,
                                     const Eigen::VectorXd& r, const Eigen::VectorXd& u0, const AntiWindup& aw) {
  const Eigen::Index nu = u0.size(), ny = r.size();
  check_size("PID", "Kp", Kp, nu, ny);
  if (Ki.size()) check_size("PID", "Ki", Ki, nu, ny);
  if (Kd.size()) check_size("PID", "Kd", Kd, nu, ny);
  if (aw.method != AntiWindup::Method::None && !Ki.size())
    throw std::invalid_argument("PID anti-windup: the controller has no integral action (no Ki), nothing can wind up");
  if (aw.method == AntiWindup::Method::BackCalculation && !(aw.tracking_time > 0 && std::isfinite(aw.tracking_time)))
    throw std::invalid_argument("PID anti-windup by back-calculation: the tracking time must be a number of seconds > 0");
  return std::make_unique<Pid>(PidGains{Kp, Ki, Kd, r, u0, aw});
}

std::unique_ptr<Controller> make_state_feedback(const Eigen::MatrixXd& K, const Eigen::VectorXd& u0,
                                                const Eigen::MatrixXd& Nbar, const Eigen::VectorXd& y0) {
  if (K.rows() != u0.size()) throw std::invalid_argument("state feedback: K has " + std::to_string(K.rows()) + " rows, the plant " + std::to_string(u0.size()) + " inputs");
  if (Nbar.size() && (Nbar.rows() != u0.size() || Nbar.cols() != y0.size()))
    throw std::invalid_argument("state feedback: Nbar must be nu x ny");
  return std::make_unique<StateFeedback>(K, u0, Nbar, y0);
}

Eigen::MatrixXd reference_gain(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& C,
                               const Eigen::MatrixXd& K, const std::vector<int>& tracked) {
  const Eigen::MatrixXd Acl = A - B * K;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(Acl);
  if (!lu.isInvertible())
    throw std::invalid_argument("reference feed-forward: A - B K is singular (the closed loop has a pole at 0)");
  Eigen::MatrixXd Ct(static_cast<Eigen::Index>(tracked.size()), C.cols());
  for (std::size_t i = 0; i < tracked.size(); ++i) Ct.row(i) = C.row(tracked[i]);
  const Eigen::MatrixXd G = -Ct * lu.solve(B);  // dc gain from u to the tracked outputs
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
  if (svd.rank() < static_cast<Eigen::Index>(tracked.size()))
    throw std::invalid_argument("reference feed-forward: the inputs cannot hold the tracked outputs at independent values "
                                "(track fewer outputs than there are inputs)");
  const Eigen::MatrixXd pinv = svd.solve(Eigen::MatrixXd::Identity(G.rows(), G.rows()));
  Eigen::MatrixXd Nbar = Eigen::MatrixXd::Zero(B.cols(), C.rows());
  for (std::size_t i = 0; i < tracked.size(); ++i) Nbar.col(tracked[i]) = pinv.col(static_cast<Eigen::Index>(i));
  return Nbar;
}

std::unique_ptr<Controller> make_lti(const Eigen::MatrixXd& Ac, const Eigen::MatrixXd& Bc, const Eigen::MatrixXd& Cc,
                                     const Eigen::MatrixXd& Dc, double Ts, const Eigen::VectorXd& y0,
                                     const Eigen::VectorXd& u0) {
  const Eigen::Index n = Ac.rows();
  check_size("LTI", "Ac", Ac, n, n);
  check_size("LTI", "Bc", Bc, n, y0.size());
  check_size("LTI", "Cc", Cc, u0.size(), n);
  check_size("LTI", "Dc", Dc, u0.size(), y0.size());
  if (!(Ts >= 0)) throw std::invalid_argument("LTI: Ts must be >= 0");
  return std::make_unique<Lti>(Ac, Bc, Cc, Dc, Ts, y0, u0);
}

std::unique_ptr<Controller> controller_from_matrices(const ControllerMatrices& vars, const std::string& path, int nx,
                                                     int nu, int ny, const Eigen::VectorXd& y0, const Eigen::VectorXd& u0) {
  const auto& m = vars.matrices;
  // a controller variable that is there but not a real 2-D matrix is named with the reason
  for (const ControllerMatrices::Skipped& v : vars.skipped)
    for (const char* n : {"K", "Kp", "Ki", "Kd", "r", "Ac", "Bc", "Cc", "Dc", "Ts"})
      if (v.name == n)
        throw std::invalid_argument(path + ": the variable " + v.name + " cannot be used (" + v.reason + ")" +
                                    "; a controller needs real, full, 2-D double matrices (save them with save -v7)");
  auto has = [&](const char* n) { return m.count(n) > 0; };
  auto get = [&](const char* n, Eigen::Index rows, Eigen::Index cols) {
    const Eigen::MatrixXd& M = m.at(n);
    check_size(path, n, M, rows, cols);
    return M;
  };
  if (has("Ac") || has("Bc") || has("Cc") || has("Dc")) {
    for (const char* n : {"Ac", "Bc", "Cc", "Dc"})
      if (!has(n)) throw std::invalid_argument(path + ": an LTI controller needs Ac, Bc, Cc and Dc; " + n + " is missing");
    const Eigen::Index n = m.at("Ac").rows();
    double Ts = 0;
    if (has("Ts")) Ts = get("Ts", 1, 1)(0, 0);
    if (Ts < 0) throw std::invalid_argument(path + ": Ts must be >= 0 (0 = continuous)");
    return make_lti(get("Ac", n, n), get("Bc", n, ny), get("Cc", nu, n), get("Dc", nu, ny), Ts, y0, u0);
  }
  if (has("K")) return make_state_feedback(get("K", nu, nx), u0);
  if (has("Kp")) {
    const Eigen::VectorXd r = has("r") ? Eigen::VectorXd(get("r", ny, 1)) : y0;
    return make_pid(get("Kp", nu, ny), has("Ki") ? get("Ki", nu, ny) : Eigen::MatrixXd(),
                    has("Kd") ? get("Kd", nu, ny) : Eigen::MatrixXd(), r, u0);
  }
  std::string found;
  for (const auto& [k, v] : m) found += (found.empty() ? "" : ", ") + k;
  for (const ControllerMatrices::Skipped& v : vars.skipped) found += (found.empty() ? "" : ", ") + v.name + " (" + v.reason + ", not read)";
  throw std::invalid_argument(path + ": no controller found: expected K (state feedback), Kp [Ki Kd] (PID) or Ac Bc Cc Dc "
                              "(LTI); the file holds " + (found.empty() ? std::string("no variable codyna can read (is it truncated or corrupt?)") : found));
}

}  // namespace codyna
