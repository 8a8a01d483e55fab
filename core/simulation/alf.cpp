// alf: the index-3 augmented Lagrangian formulation with mass-orthogonal projections of the
// velocities and accelerations (Bayo and Ledesma 1996; Cuadrado, Cardenal, Bayo 1997, "ALI3-P"),
// integrated by the trapezoidal rule at a fixed step. It never inverts the constraint Jacobian
// alone: the Newton matrix is M + (h^2/4) Jc^T alpha Jc, regular while M is, whatever the rank of
// Jc, so it passes singular positions (a four-bar's flat position, IFToMM A02) and takes redundant
// constraints (Bricard) as they are. Per step, from (q_n, v_n, a_n):
//   q^ = q_n + h v_n + h^2/2 a_n,  v = 2/h q - (2/h q_n + v_n),  a = 4/h^2 q - (4/h^2 q_n + 4/h v_n + a_n)
//   f(q) = h^2/4 (M a + nle - Q + Jc^T (lambda* + alpha phi)),  Newton on f = 0 with the matrix above,
//   lambda* += alpha phi after each iteration (the multipliers, kept from step to step);
// then v and a projected onto the constraints' tangent (mass-orthogonally):
//   (M + h^2/4 Jc^T alpha Jc) v = M v*,   (M + h^2/4 Jc^T alpha Jc) a = M a* - h^2/4 Jc^T alpha gamma.
// Additive coordinates only (no ball or free joint), no effect states and no continuous controller
// states: refused by name otherwise. The step is IntegratorSettings::max_step (default 1 ms);
// the penalty and the iterations are alf_penalty and alf_iterations.
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "dynamics/constraints.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "simulation/closed_loop.hpp"
#include "simulation/integrator.hpp"

namespace codyna {

namespace {

class Alf final : public Integrator {
 public:
  Alf(ClosedLoopSystem& sys, const IntegratorSettings& s)
      : sys_(sys), m_(sys.model()), d_(sys.model()), h_(s.max_step > 0 ? s.max_step : 1e-3), alpha_(s.alf_penalty),
        iterations_(s.alf_iterations), rtol_(s.rtol), atol_(s.atol) {
    if (!(alpha_ > 0) || !std::isfinite(alpha_))
      throw std::invalid_argument("integrator alf: alf_penalty: expected a number > 0, got " + std::to_string(alpha_));
    if (iterations_ < 1) throw std::invalid_argument("integrator alf: alf_iterations: expected at least 1");
    if (m_.nq != m_.nv)
      throw std::invalid_argument("integrator alf: the model has ball or free joints (their quaternions are not additive "
                                  "coordinates): not integrated by alf yet");
    if (m_.ns > 0) throw std::invalid_argument("integrator alf: the model has effect states (a tire's transient slip): not integrated by alf yet");
    if (sys.nxc() > 0) throw std::invalid_argument("integrator alf: the controller has continuous states: not integrated by alf yet");
    if (!m_.motions.empty()) throw std::invalid_argument("integrator alf: the model has motion inputs: not integrated by alf yet");
  }

  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    q_ = y.head(m_.nq);
    v_ = y.segment(m_.nq, m_.nv);
    xc_ = y.tail(y.size() - m_.nq - m_.nv);
    // the accelerations and multipliers of the constrained dynamics there
    const Eigen::VectorXd u = sys_.inputs(t, q_, v_, xc_);
    a_ = forward_dynamics<double>(m_, d_, q_, v_, u);
    lambda_ = m_.nc ? Eigen::VectorXd(d_.lambda) : Eigen::VectorXd();
    if (!a_.allFinite()) throw IntegratorFailure(t, "alf: the accelerations at the start are not finite");
  }

  void advance(double t_out) override {
    const int n = std::max(1, static_cast<int>(std::ceil((t_out - t_) / h_ - 1e-9)));
    const double h = (t_out - t_) / n;
    for (int i = 0; i < n; ++i) step(h);
    t_ = t_out;
  }

  Eigen::VectorXd state() const override {
    Eigen::VectorXd y(m_.nq + m_.nv + xc_.size());
    y << q_, v_, xc_;
    return y;
  }
  bool projects() const override { return true; }
  void add_stats(SolverStats& s) const override {
    s.steps += steps_;
    s.rhs_evals += evaluations_;
    s.jac_evals += factorizations_;
    s.nonlinear_iterations += iterations_done_;
    s.nonlinear_failures += failures_;
  }

 private:
  // M, nle - Q, and (loops) phi, Jc, gamma at (q, v) and time t
  void evaluate(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    ++evaluations_;
    const Eigen::VectorXd u = sys_.inputs(t, q, v, xc_);
    forward_kinematics<double>(m_, d_, q, v);
    const Eigen::VectorXd Q = applied_forces<double>(m_, d_, q, v, u);
    crba<double>(m_, d_, q);
    nonlinear_effects<double>(m_, d_, q, v);
    bias_ = d_.nle - Q;
    if (m_.nc) constraint_terms<double>(m_, d_, q, v);
  }

  void step(double h) {
    const double t1 = t_ + h, c = h * h / 4;
    h_now_ = h;
    const Eigen::VectorXd vhat = (2 / h) * q_ + v_, ahat = (4 / (h * h)) * q_ + (4 / h) * v_ + a_;
    Eigen::VectorXd q = q_ + h * v_ + (h * h / 2) * a_, v, a;
    Eigen::VectorXd lambda = lambda_;
    const double tol = std::max(atol_, rtol_ * (1.0 + q_.cwiseAbs().maxCoeff()));
    bool converged = false;
    double last = 0;
    for (int it = 0; it < iterations_; ++it) {
      v = (2 / h) * q - vhat;
      a = (4 / (h * h)) * q - ahat;
      evaluate(t1, q, v);
      Eigen::VectorXd f = d_.M * a + bias_;
      if (m_.nc) f += d_.Jc.transpose() * (lambda + alpha_ * d_.phi);
      f *= c;
      newton_matrix();
      const Eigen::VectorXd dq = -lu_.solve(f);
      q += dq;
      ++iterations_done_;
      if (m_.nc) {
        constraint_residual<double>(m_, d_, q);
        lambda += alpha_ * d_.phi;
      }
      if (!dq.allFinite()) break;
      last = dq.cwiseAbs().maxCoeff();
      if (std::getenv("ALF_TRACE")) std::fprintf(stderr, "t %g it %d |dq| %g |phi| %g\n", t1, it, last, m_.nc ? d_.phi.cwiseAbs().maxCoeff() : 0.0);
      if (dq.cwiseAbs().maxCoeff() <= tol) {
        converged = true;
        break;
      }
    }
    if (!converged) {
      ++failures_;
      std::ostringstream os;
      os << "alf: Newton did not converge in " << iterations_ << " iterations at step " << h << " s (the last correction "
         << last << "; alf_iterations; a smaller step, max_step, or another alf_penalty)";
      throw IntegratorFailure(t1, os.str());
    }
    // the mass-orthogonal projections of v and a onto the constraints at q
    v = (2 / h) * q - vhat;
    a = (4 / (h * h)) * q - ahat;
    evaluate(t1, q, v);
    if (m_.nc) {
      newton_matrix();
      v = lu_.solve(d_.M * v);
      constraint_terms<double>(m_, d_, q, v);  // gamma at the projected velocities
      a = lu_.solve(d_.M * a - c * alpha_ * (d_.Jc.transpose() * d_.gamma));
    }
    if (!q.allFinite() || !v.allFinite() || !a.allFinite()) throw IntegratorFailure(t1, "alf: the state is no longer finite");
    q_ = q;
    v_ = v;
    a_ = a;
    lambda_ = lambda;
    t_ = t1;
    ++steps_;
  }

  // M + h^2/4 Jc^T alpha Jc at the last evaluation, factored
  void newton_matrix() {
    K_ = d_.M;
    if (m_.nc) K_.noalias() += (h_now_ * h_now_ / 4 * alpha_) * (d_.Jc.transpose() * d_.Jc);
    lu_.compute(K_);
    ++factorizations_;
  }

  ClosedLoopSystem& sys_;
  const Model& m_;
  Data d_;
  double h_, alpha_;
  int iterations_;
  double rtol_, atol_;
  double h_now_ = 0;
  double t_ = 0;
  Eigen::VectorXd q_, v_, a_, xc_, lambda_, bias_;
  Eigen::MatrixXd K_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  long steps_ = 0, evaluations_ = 0, factorizations_ = 0, iterations_done_ = 0, failures_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_alf_integrator(ClosedLoopSystem& system, const IntegratorSettings& settings) {
  return std::make_unique<Alf>(system, settings);
}

}  // namespace codyna
