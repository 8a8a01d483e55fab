#include "simulation/integrator_choice.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace codyna {

IntegratorChoice choose_integrator(ClosedLoopSystem& sys, double t, const Eigen::VectorXd& y, double span, double rtol) {
  IntegratorChoice c;
  const bool loops = sys.model().nc > 0;
  const int n = sys.ode_size();
  const double slowest = 1.0 / std::max(span, 1e-12);
  c.slow_rate = slowest;
  std::string failed;  // the right-hand side threw at a perturbed state
  if (n <= kMaxAnalysed) {
    // J = d ydot / d y by central differences (2 n evaluations)
    Eigen::MatrixXd J(n, n);
    Eigen::VectorXd yp = y, ym = y, fp, fm;
    try {
      for (int j = 0; j < n; ++j) {
        const double h = 1e-6 * std::max(1.0, std::abs(y[j]));
        yp[j] = y[j] + h;
        ym[j] = y[j] - h;
        sys.rhs(t, yp, fp);
        sys.rhs(t, ym, fm);
        J.col(j) = (fp - fm) / (2 * h);
        yp[j] = ym[j] = y[j];
      }
    } catch (const std::exception& e) {  // no analysis, not a failed run: the integrator will say
      failed = e.what();
      J.setConstant(NAN);
    }
    if (J.allFinite()) {
      const Eigen::VectorXcd lambda = Eigen::EigenSolver<Eigen::MatrixXd>(J, false).eigenvalues();
      c.analysed = lambda.allFinite();
      if (c.analysed) {
        for (int i = 0; i < lambda.size(); ++i) c.fastest_decay = std::max(c.fastest_decay, -lambda[i].real());
        // the other modes: those decaying less than a hundredth as fast as the fastest
        for (int i = 0; i < lambda.size(); ++i)
          if (-lambda[i].real() < 0.01 * c.fastest_decay) c.slow_rate = std::max(c.slow_rate, std::abs(lambda[i]));
        c.stiff = c.fastest_decay >= 100 * c.slow_rate;
      }
    }
  }
  std::ostringstream why;
  why << std::setprecision(3);
  if (!c.analysed)
    why << (n > kMaxAnalysed    ? "not analysed (" + std::to_string(n) + " states)"
            : !failed.empty() ? "not analysed (" + failed + ")"
                              : std::string("not analysed (the Jacobian is not finite)"))
        << ", taken as not stiff";
  else if (c.stiff)
    why << "stiff: a mode decays at " << c.fastest_decay << " 1/s, " << c.fastest_decay / c.slow_rate
        << " times faster than the motion (" << c.slow_rate << " 1/s)";
  else
    why << "not stiff: the fastest decay " << c.fastest_decay << " 1/s against the motion's " << c.slow_rate << " 1/s";
  // alf refuses rolling constraints (conditions on the velocities alone)
  const bool alf = c.stiff && rtol >= kAlfLooseRtol && sys.model().velocity_rows.empty();
  c.method = alf ? "alf" : c.stiff ? "cvode-bdf" : loops ? "arkode" : "cvode-adams";
  c.alf_extrapolate = alf;
  if (alf)
    why << "; at rtol " << rtol << " >= " << kAlfLooseRtol;
  else
    why << (c.stiff ? "" : loops ? "; closed loops" : "; a tree");
  c.reason = "auto: " + c.method + (alf ? " (extrapolated)" : "") + ", " + why.str();
  return c;
}

void apply_choice(const IntegratorChoice& c, IntegratorSettings& s) {
  s.method = c.method;
  if (c.method == "alf") {
    s.alf_extrapolate = c.alf_extrapolate;
    s.alf_fixed_step = false;  // auto's alf is under error control
  }
}

std::string auto_fallback_note(const std::string& failed, double t_failed, const std::string& why, double t_from) {
  std::ostringstream os;
  os << "; " << failed << " failed at t = " << t_failed << " s (" << why << "): " << kAutoFallbackIntegrator
     << " from t = " << t_from << " s on";
  return os.str();
}

}  // namespace codyna
