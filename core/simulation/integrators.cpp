// SUNDIALS adapters (CVODE, ARKODE ERKStep, IDA) and the fixed-step RK4.
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_proj.h>
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <sstream>

#include "dynamics/joint.hpp"
#include "model/model_spec.hpp"
#include "simulation/integrator.hpp"
#include "simulation/reference_integrator.hpp"

namespace codyna {

namespace {

Eigen::Map<Eigen::VectorXd> view(N_Vector v) { return {N_VGetArrayPointer(v), N_VGetLength(v)}; }

// CVODE BDF runs at this fraction of the tolerances asked for (measured, docs/work-precision.md)
constexpr double kBdfToleranceFactor = 0.1;

// owns a SUNContext, the state vector(s) and the solver memory
class SundialsBase : public Integrator {
 protected:
  SundialsBase(ClosedLoopSystem& sys, const IntegratorSettings& s) : sys_(sys), set_(s) {
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("SUNDIALS: cannot create a context");
  }
  ~SundialsBase() override {
    if (LS_) SUNLinSolFree(LS_);
    if (A_) SUNMatDestroy(A_);
    if (NLS_) SUNNonlinSolFree(NLS_);
    if (y_) N_VDestroy(y_);
    if (yp_) N_VDestroy(yp_);
    if (id_) N_VDestroy(id_);
    SUNContext_Free(&ctx_);
  }
  // right-hand side / residual callbacks report exceptions here and return -1 (unrecoverable)
  template <class F>
  int guarded(F&& f) {
    try {
      f();
      return 0;
    } catch (const std::exception& e) {
      error_ = e.what();
      return -1;
    }
  }
  [[noreturn]] void fail(const char* solver, int flag, double t) {
    std::ostringstream os;
    os << solver << " failed (flag " << flag << ")";
    if (!error_.empty()) os << ": " << error_;
    if (!last_message_.empty()) os << ": " << last_message_;
    throw IntegratorFailure(t, os.str());
  }
  // the ODE right-hand side, shared by CVODE and ARKODE
  static int ode_rhs(double t, N_Vector y, N_Vector yd, void* self) {
    auto* me = static_cast<SundialsBase*>(self);
    return me->guarded([&] {
      Eigen::VectorXd out;
      me->sys_.rhs(t, view(y), out);
      view(yd) = out;
    });
  }
  static void check(int flag, const char* solver, const char* what) {
    if (flag < 0) throw std::runtime_error(std::string(solver) + " setup: " + what + " failed");
  }
  static void on_error(int, const char*, const char* function, char* msg, void* self) {
    auto* me = static_cast<SundialsBase*>(self);
    me->last_message_ = std::string(function) + ": " + msg;
  }

  // statistics: the runs before the last re-initialization (whose counters
  // SUNDIALS resets) plus the current run's
  void add_stats(SolverStats& s) const override {
    add_done(s);
    counters(s);
    s.projections += projections_;
  }
  virtual void counters(SolverStats& s) const = 0;  // the current run's (reset by a re-initialization)
  void add_done(SolverStats& s) const {
    s.steps += done_.steps;
    s.rhs_evals += done_.rhs_evals;
    s.jac_evals += done_.jac_evals;
    s.error_test_failures += done_.error_test_failures;
    s.nonlinear_iterations += done_.nonlinear_iterations;
    s.nonlinear_failures += done_.nonlinear_failures;
  }

  ClosedLoopSystem& sys_;
  IntegratorSettings set_;
  SolverStats done_;
  long projections_ = 0;  // done inside the solver (CVODE's projection hook); never reset
  SUNContext ctx_ = nullptr;
  N_Vector y_ = nullptr, yp_ = nullptr, id_ = nullptr;
  SUNMatrix A_ = nullptr;
  SUNLinearSolver LS_ = nullptr;
  SUNNonlinearSolver NLS_ = nullptr;
  void* mem_ = nullptr;
  double t_ = 0;
  std::string error_, last_message_;
};

class Cvode final : public SundialsBase {
 public:
  Cvode(ClosedLoopSystem& sys, const IntegratorSettings& s, bool bdf) : SundialsBase(sys, s), bdf_(bdf) {}
  ~Cvode() override {
    if (mem_) CVodeFree(&mem_);
  }
  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    if (!y_) {
      y_ = N_VNew_Serial(sys_.ode_size(), ctx_);
      view(y_) = y;
      mem_ = CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, ctx_);
      check(CVodeInit(mem_, &SundialsBase::ode_rhs, t, y_), "CVodeInit");
      check(CVodeSetUserData(mem_, static_cast<SundialsBase*>(this)), "CVodeSetUserData");
      // BDF: CVODE's local error test at the tolerances asked for leaves a global error
      // about 5x larger on Andrews' squeezer (SCD 7.4 at 1e-10); a tenth of them gives
      // SCD 8.3 for 15% more steps (docs/work-precision.md). Adams keeps them as asked.
      const double f = bdf_ ? kBdfToleranceFactor : 1.0;
      check(CVodeSStolerances(mem_, f * set_.rtol, f * set_.atol), "CVodeSStolerances");
      check(CVodeSetErrHandlerFn(mem_, &SundialsBase::on_error, static_cast<SundialsBase*>(this)), "CVodeSetErrHandlerFn");
      check(CVodeSetMaxNumSteps(mem_, 1000000), "CVodeSetMaxNumSteps");
      if (set_.max_step > 0) check(CVodeSetMaxStep(mem_, set_.max_step), "CVodeSetMaxStep");
      if (bdf_) {
        A_ = SUNDenseMatrix(sys_.ode_size(), sys_.ode_size(), ctx_);
        LS_ = SUNLinSol_Dense(y_, A_, ctx_);
        check(CVodeSetLinearSolver(mem_, LS_, A_), "CVodeSetLinearSolver");
        // exact Jacobian from the analytic derivatives where the system has one (issue 11)
        // Trees only: on loops the ODE Jacobian is taken on the kept rows while rhs() solves on
        // all rows with a singular-direction cut, and at A02's singular passages (N = 40) the
        // mismatch stalled the Newton iteration (HardSingular.A02FortyFourBars timed out)
        if (set_.exact_jacobian && sys_.model().nc == 0 && sys_.exact_ode_jacobian())
          check(CVodeSetJacFn(mem_, &Cvode::jacobian), "CVodeSetJacFn");
        // loops: CVODE projects after every step itself, so the simulator need not restart it
        if (sys_.model().nc > 0) check(CVodeSetProjFn(mem_, &Cvode::project), "CVodeSetProjFn");
      } else {
        NLS_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
        check(CVodeSetNonlinearSolver(mem_, NLS_), "CVodeSetNonlinearSolver");
      }
    } else {
      view(y_) = y;
      counters(done_);
      check(CVodeReInit(mem_, t, y_), "CVodeReInit");
    }
  }
  void advance(double t_out) override {
    CVodeSetStopTime(mem_, t_out);
    const int flag = CVode(mem_, t_out, y_, &t_, CV_NORMAL);
    if (flag < 0) fail("CVODE", flag, t_);
  }
  Eigen::VectorXd state() const override { return view(y_); }
  bool projects() const override { return bdf_ && sys_.model().nc > 0; }
  void counters(SolverStats& s) const override {
    long v = 0;
    CVodeGetNumSteps(mem_, &v), s.steps += v;
    CVodeGetNumRhsEvals(mem_, &v), s.rhs_evals += v;
    if (bdf_) CVodeGetNumLinRhsEvals(mem_, &v), s.rhs_evals += v;  // difference-quotient Jacobians
    CVodeGetNumErrTestFails(mem_, &v), s.error_test_failures += v;
    CVodeGetNumNonlinSolvIters(mem_, &v), s.nonlinear_iterations += v;
    CVodeGetNumNonlinSolvConvFails(mem_, &v), s.nonlinear_failures += v;
    if (bdf_) CVodeGetNumJacEvals(mem_, &v), s.jac_evals += v;
  }

 private:
  static void check(int flag, const char* what) { SundialsBase::check(flag, "CVODE", what); }
  static int jacobian(double t, N_Vector y, N_Vector, SUNMatrix Jac, void* self, N_Vector, N_Vector, N_Vector) {
    auto* me = static_cast<Cvode*>(static_cast<SundialsBase*>(self));
    return me->guarded([&] {
      if (!me->sys_.ode_jacobian(t, view(y), me->jac_)) throw std::runtime_error("no exact Jacobian");
      const auto n = static_cast<Eigen::Index>(SUNDenseMatrix_Rows(Jac));
      Eigen::Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(Jac), n, n) = me->jac_;
    });
  }
  Eigen::MatrixXd jac_;  // workspace of the exact Jacobian
  // CVProjFn: the correction that brings ycur back onto phi = 0, Jc v = 0, and the error
  // estimate projected onto the constraints' tangent space (CVODE's default expects both)
  static int project(double t, N_Vector ycur, N_Vector corr, double, N_Vector err, void* self) {
    auto* me = static_cast<Cvode*>(static_cast<SundialsBase*>(self));
    return me->guarded([&] {
      Eigen::VectorXd y = view(ycur);
      const Eigen::VectorXd y0 = y;
      if (me->sys_.project(y, 0.0, t)) ++me->projections_;
      view(corr) = y - y0;
      if (err) {
        Eigen::VectorXd e = view(err);
        me->sys_.project_tangent(y, e);
        view(err) = e;
      }
    });
  }
  bool bdf_;
};

class Erk final : public SundialsBase {
 public:
  Erk(ClosedLoopSystem& sys, const IntegratorSettings& s) : SundialsBase(sys, s) {}
  ~Erk() override {
    if (mem_) ERKStepFree(&mem_);
  }
  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    if (!y_) {
      y_ = N_VNew_Serial(sys_.ode_size(), ctx_);
      view(y_) = y;
      mem_ = ERKStepCreate(&SundialsBase::ode_rhs, t, y_, ctx_);
      if (!mem_) throw std::runtime_error("ARKODE setup: ERKStepCreate failed");
      check(ERKStepSetUserData(mem_, static_cast<SundialsBase*>(this)), "ARKODE", "ERKStepSetUserData");
      check(ERKStepSStolerances(mem_, set_.rtol, set_.atol), "ARKODE", "ERKStepSStolerances");
      check(ERKStepSetErrHandlerFn(mem_, &SundialsBase::on_error, static_cast<SundialsBase*>(this)), "ARKODE", "ERKStepSetErrHandlerFn");
      check(ERKStepSetMaxNumSteps(mem_, 10000000), "ARKODE", "ERKStepSetMaxNumSteps");
      if (set_.max_step > 0) check(ERKStepSetMaxStep(mem_, set_.max_step), "ARKODE", "ERKStepSetMaxStep");
      if (projects()) check(ERKStepSetPostprocessStepFn(mem_, &Erk::project), "ARKODE", "ERKStepSetPostprocessStepFn");
    } else {
      view(y_) = y;
      counters(done_);
      ERKStepReInit(mem_, &SundialsBase::ode_rhs, t, y_);
    }
  }
  void advance(double t_out) override {
    ERKStepSetStopTime(mem_, t_out);
    const int flag = ERKStepEvolve(mem_, t_out, y_, &t_, ARK_NORMAL);
    if (flag < 0) fail("ARKODE", flag, t_);
  }
  Eigen::VectorXd state() const override { return view(y_); }
  bool projects() const override { return sys_.model().nc > 0; }
  void counters(SolverStats& s) const override {
    long v = 0;
    ERKStepGetNumSteps(mem_, &v), s.steps += v;
    ERKStepGetNumRhsEvals(mem_, &v), s.rhs_evals += v;
    ERKStepGetNumErrTestFails(mem_, &v), s.error_test_failures += v;
  }

 private:
  // after every accepted step, back onto phi = 0, Jc v = 0 (a one-step method starts the next
  // step from the projected state, so this costs no accuracy)
  static int project(double t, N_Vector y, void* self) {
    auto* me = static_cast<Erk*>(static_cast<SundialsBase*>(self));
    return me->guarded([&] {
      Eigen::VectorXd x = view(y);
      if (me->sys_.project(x, 0.0, t)) ++me->projections_, view(y) = x;
    });
  }
};

class Ida final : public SundialsBase {
 public:
  Ida(ClosedLoopSystem& sys, const IntegratorSettings& s) : SundialsBase(sys, s) {}
  ~Ida() override {
    if (mem_) IDAFree(&mem_);
  }
  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    Eigen::VectorXd Y, Yp;
    sys_.consistent(t, y, Y, Yp);
    const int n = sys_.dae_size();
    if (!y_) {
      y_ = N_VNew_Serial(n, ctx_);
      yp_ = N_VNew_Serial(n, ctx_);
      id_ = N_VNew_Serial(n, ctx_);
      view(y_) = Y;
      view(yp_) = Yp;
      Eigen::VectorXd id = Eigen::VectorXd::Ones(n);
      id.tail(sys_.na()).setZero();  // multipliers are algebraic
      view(id_) = id;
      mem_ = IDACreate(ctx_);
      check(IDAInit(mem_, &Ida::res, t, y_, yp_), "IDAInit");
      check(IDASetUserData(mem_, this), "IDASetUserData");
      check(IDASStolerances(mem_, set_.rtol, set_.atol), "IDASStolerances");
      check(IDASetErrHandlerFn(mem_, &SundialsBase::on_error, static_cast<SundialsBase*>(this)), "IDASetErrHandlerFn");
      check(IDASetId(mem_, id_), "IDASetId");
      check(IDASetSuppressAlg(mem_, SUNTRUE), "IDASetSuppressAlg");  // index-1 multipliers: no error test
      check(IDASetMaxNumSteps(mem_, 1000000), "IDASetMaxNumSteps");
      if (set_.max_step > 0) check(IDASetMaxStep(mem_, set_.max_step), "IDASetMaxStep");
      A_ = SUNDenseMatrix(n, n, ctx_);
      LS_ = SUNLinSol_Dense(y_, A_, ctx_);
      check(IDASetLinearSolver(mem_, LS_, A_), "IDASetLinearSolver");
      if (set_.exact_jacobian && sys_.exact_dae_jacobian()) check(IDASetJacFn(mem_, &Ida::jacobian), "IDASetJacFn");
    } else {
      view(y_) = Y;
      view(yp_) = Yp;
      counters(done_);
      check(IDAReInit(mem_, t, y_, yp_), "IDAReInit");
    }
  }
  void advance(double t_out) override {
    IDASetStopTime(mem_, t_out);
    const int flag = IDASolve(mem_, t_out, &t_, y_, yp_, IDA_NORMAL);
    if (flag < 0) fail("IDA", flag, t_);
  }
  Eigen::VectorXd state() const override { return view(y_).head(sys_.ode_size()); }
  void counters(SolverStats& s) const override {
    long v = 0;
    IDAGetNumSteps(mem_, &v), s.steps += v;
    IDAGetNumResEvals(mem_, &v), s.rhs_evals += v;
    IDAGetNumLinResEvals(mem_, &v), s.rhs_evals += v;  // difference-quotient Jacobians
    IDAGetNumErrTestFails(mem_, &v), s.error_test_failures += v;
    IDAGetNumNonlinSolvIters(mem_, &v), s.nonlinear_iterations += v;
    IDAGetNumNonlinSolvConvFails(mem_, &v), s.nonlinear_failures += v;
    IDAGetNumJacEvals(mem_, &v), s.jac_evals += v;
  }

 private:
  static int res(double t, N_Vector Y, N_Vector Yp, N_Vector F, void* self) {
    auto* me = static_cast<Ida*>(self);
    return me->guarded([&] {
      Eigen::VectorXd out;
      me->sys_.residual(t, view(Y), view(Yp), out);
      view(F) = out;
    });
  }
  static void check(int flag, const char* what) { SundialsBase::check(flag, "IDA", what); }
  static int jacobian(double t, double cj, N_Vector Y, N_Vector Yp, N_Vector, SUNMatrix Jac, void* self, N_Vector,
                      N_Vector, N_Vector) {
    auto* me = static_cast<Ida*>(self);
    return me->guarded([&] {
      if (!me->sys_.dae_jacobian(t, view(Y), view(Yp), cj, me->jac_)) throw std::runtime_error("no exact Jacobian");
      const auto n = static_cast<Eigen::Index>(SUNDenseMatrix_Rows(Jac));
      Eigen::Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(Jac), n, n) = me->jac_;
    });
  }
  Eigen::MatrixXd jac_;  // workspace of the exact Jacobian
};

class Rk4 final : public Integrator {
 public:
  Rk4(ClosedLoopSystem& sys, const IntegratorSettings& s) : sys_(sys), h_(s.max_step > 0 ? s.max_step : 1e-3) {}
  void reset(double t, const Eigen::VectorXd& y) override {
    t_ = t;
    y_ = y;
  }
  void advance(double t_out) override {
    const int n = std::max(1, static_cast<int>(std::ceil((t_out - t_) / h_ - 1e-9)));
    const double h = (t_out - t_) / n;
    Eigen::VectorXd k1, k2, k3, k4;
    for (int i = 0; i < n; ++i) {
      try {
        sys_.rhs(t_, y_, k1);
        sys_.rhs(t_ + h / 2, y_ + h / 2 * k1, k2);
        sys_.rhs(t_ + h / 2, y_ + h / 2 * k2, k3);
        sys_.rhs(t_ + h, y_ + h * k3, k4);
      } catch (const std::exception& e) {
        throw IntegratorFailure(t_, std::string("rk4: ") + e.what());
      }
      y_ += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      if (!y_.allFinite()) throw IntegratorFailure(t_, "rk4: the state is no longer finite (step too large?)");
      Eigen::VectorXd q = y_.head(sys_.nq());
      normalize(sys_.model(), q);
      y_.head(sys_.nq()) = q;
      t_ += h;
      ++steps_;
    }
    t_ = t_out;
  }
  Eigen::VectorXd state() const override { return y_; }
  void add_stats(SolverStats& s) const override {
    s.steps += steps_;
    s.rhs_evals += 4 * steps_;
  }

 private:
  ClosedLoopSystem& sys_;
  double h_, t_ = 0;
  Eigen::VectorXd y_;
  long steps_ = 0;
};

}  // namespace

IntegratorSettings integrator_settings(const SolverSpec& solver) {
  IntegratorSettings s;
  s.method = solver.integrator;
  s.rtol = solver.rtol;
  s.atol = solver.atol;
  s.max_step = solver.max_step;
  if (solver.alf_penalty) s.alf_penalty = *solver.alf_penalty;
  if (solver.alf_iterations) s.alf_iterations = *solver.alf_iterations;
  s.alf_fixed_step = solver.alf_fixed_step;
  s.alf_extrapolate = solver.alf_extrapolate;
  return s;
}

std::unique_ptr<Integrator> make_integrator(ClosedLoopSystem& system, const IntegratorSettings& s) {
  if (!(s.rtol > 0) || !(s.atol > 0)) throw std::invalid_argument("integrator: rtol and atol must be positive");
  if (!(s.max_step >= 0)) throw std::invalid_argument("integrator: max_step must be >= 0");
  if (s.method == "ida") return std::make_unique<Ida>(system, s);
  if (s.method == "cvode-bdf") return std::make_unique<Cvode>(system, s, true);
  if (s.method == "cvode-adams") return std::make_unique<Cvode>(system, s, false);
  if (s.method == "arkode") return std::make_unique<Erk>(system, s);
  if (s.method == "rk4") return std::make_unique<Rk4>(system, s);
  if (s.method == "alf") return make_alf_integrator(system, s);
  if (s.method == "auto")
    throw std::invalid_argument("integrator \"auto\" is chosen from the model's state: resolve it with choose_integrator first");
  throw std::invalid_argument("unknown integrator \"" + s.method + "\" (expected one of: " + integrator_names(", ", false) + ")");
}

struct OdeIntegrator::Impl {
  Rhs f;
  double rtol, atol;
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  void* mem = nullptr;
  double t = 0;
  long steps_before = 0;  // of the runs before the last re-initialization
  std::string error;

  static int rhs(double t, N_Vector y, N_Vector yd, void* self) {
    auto* me = static_cast<Impl*>(self);
    try {
      Eigen::VectorXd out;
      me->f(t, view(y), out);
      view(yd) = out;
      return 0;
    } catch (const std::exception& e) {
      me->error = e.what();
      return -1;
    }
  }
  long current_steps() const {
    long v = 0;
    if (mem) ERKStepGetNumSteps(mem, &v);
    return v;
  }
};

OdeIntegrator::OdeIntegrator(Rhs f, double rtol, double atol) : impl_(std::make_unique<Impl>()) {
  if (!(rtol > 0) || !(atol > 0)) throw std::invalid_argument("OdeIntegrator: tolerances must be > 0");
  impl_->f = std::move(f);
  impl_->rtol = rtol;
  impl_->atol = atol;
  if (SUNContext_Create(nullptr, &impl_->ctx) != 0) throw std::runtime_error("SUNDIALS: cannot create a context");
}

OdeIntegrator::~OdeIntegrator() {
  if (impl_->mem) ERKStepFree(&impl_->mem);
  if (impl_->y) N_VDestroy(impl_->y);
  SUNContext_Free(&impl_->ctx);
}

void OdeIntegrator::reset(double t, const Eigen::VectorXd& y) {
  Impl& m = *impl_;
  m.t = t;
  const auto check = [](int flag, const char* what) {
    if (flag < 0) throw std::runtime_error(std::string("ARKODE setup: ") + what + " failed");
  };
  if (!m.y || N_VGetLength(m.y) != y.size()) {
    if (m.mem) m.steps_before += m.current_steps(), ERKStepFree(&m.mem);
    if (m.y) N_VDestroy(m.y);
    m.y = N_VNew_Serial(y.size(), m.ctx);
    view(m.y) = y;
    m.mem = ERKStepCreate(&Impl::rhs, t, m.y, m.ctx);
    if (!m.mem) throw std::runtime_error("ARKODE setup: ERKStepCreate failed");
    check(ERKStepSetUserData(m.mem, &m), "ERKStepSetUserData");
    check(ERKStepSetTableNum(m.mem, ARKODE_DORMAND_PRINCE_7_4_5), "ERKStepSetTableNum");
    check(ERKStepSStolerances(m.mem, m.rtol, m.atol), "ERKStepSStolerances");
    check(ERKStepSetMaxNumSteps(m.mem, 10000000), "ERKStepSetMaxNumSteps");
  } else {
    m.steps_before += m.current_steps();
    view(m.y) = y;
    check(ERKStepReInit(m.mem, &Impl::rhs, t, m.y), "ERKStepReInit");
  }
}

void OdeIntegrator::advance(double t_out) {
  Impl& m = *impl_;
  if (!m.mem) throw std::logic_error("OdeIntegrator::advance before reset");
  if (t_out <= m.t) return;
  ERKStepSetStopTime(m.mem, t_out);
  const int flag = ERKStepEvolve(m.mem, t_out, m.y, &m.t, ARK_NORMAL);
  if (flag < 0) {
    std::ostringstream os;
    os << "ARKODE (linear closed loop) failed (flag " << flag << ")";
    if (!m.error.empty()) os << ": " << m.error;
    throw IntegratorFailure(m.t, os.str());
  }
}

Eigen::VectorXd OdeIntegrator::state() const { return view(impl_->y); }

long OdeIntegrator::steps() const { return impl_->steps_before + impl_->current_steps(); }

}  // namespace codyna
