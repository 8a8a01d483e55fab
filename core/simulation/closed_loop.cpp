#include "simulation/closed_loop.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/crba.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/rnea.hpp"
#include "dynamics/sensors.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

namespace {
// Closed loops for the ODE integrators: M qdd + nle = Q - Jc^T lambda, Jc qdd + gamma = -stab
// on all rows, through the Schur complement A = Jc M^-1 Jc^T. Where A is well conditioned
// (no redundant rows, no singular configuration) a pivoted LDLT solves it, as forward_dynamics
// does on its chosen rows. Otherwise (redundant rows, or a configuration near a singular one,
// where A loses rank: the flat position of IFToMM A02) its eigen-decomposition keeps the
// model's rank of largest directions and drops those below kSingularA of the largest: in a
// direction the constraints no longer see the mechanism moves by inertia, instead of by
// multipliers that grow like 1/sigma^2 and carry the round-off and the drift of the loops
// (docs/work-precision.md, "Hard cases").
Eigen::VectorXd loop_accelerations(const Model& model_, Data& data_, const Baumgarte& stab_, const Eigen::VectorXd& q,
                                   const Eigen::VectorXd& v, const Eigen::VectorXd& u) {
  constexpr double kSingularA = 1e-8, kWellConditioned = 1e-6;
  Data& d = data_;
  const int nv = model_.nv, nc = model_.nc;
  forward_kinematics<double>(model_, d, q, v);
  const Eigen::VectorXd Q = applied_forces<double>(model_, d, q, v, u);
  const Eigen::MatrixXd M = crba_after_kinematics<double>(model_, d);
  const Eigen::VectorXd h = nonlinear_effects<double>(model_, d, q, v);
  constraint_terms<double>(model_, d, q, v);
  Eigen::MatrixXd X(nv, 1 + nc);
  X.col(0) = Q - h;
  X.rightCols(nc) = d.Jc.transpose();
  Eigen::LLT<Eigen::MatrixXd> llt(M);
  if (llt.info() != Eigen::Success) throw std::runtime_error("the mass matrix is not positive definite");
  llt.solveInPlace(X);
  const Eigen::MatrixXd A = d.Jc * X.rightCols(nc);
  Eigen::VectorXd b = d.Jc * X.col(0) + d.gamma;
  if (stab_.alpha != 0.0 || stab_.beta != 0.0) b += 2.0 * stab_.alpha * (d.Jc * v) + stab_.beta * stab_.beta * d.phi;
  const int rank = static_cast<int>(model_.active_rows.size());
  Eigen::VectorXd lambda;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  const Eigen::VectorXd D = ldlt.vectorD().cwiseAbs();
  if (rank == nc && ldlt.info() == Eigen::Success && D.minCoeff() > kWellConditioned * D.maxCoeff()) {
    lambda = ldlt.solve(b);
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);  // ascending eigenvalues
    const Eigen::VectorXd& mu = es.eigenvalues();
    const double largest = mu[nc - 1];
    lambda = Eigen::VectorXd::Zero(nc);
    for (int k = nc - 1; k >= nc - rank && k >= 0; --k) {
      if (!(mu[k] > kSingularA * largest)) break;
      lambda += es.eigenvectors().col(k) * (es.eigenvectors().col(k).dot(b) / mu[k]);
    }
  }
  d.lambda = lambda;
  return X.col(0) - X.rightCols(nc) * lambda;
}
}  // namespace

ClosedLoopSystem::ClosedLoopSystem(const Model& model, const Controller* controller, const PlantFunction* plant,
                                   const Eigen::VectorXd& x_ref, const Eigen::VectorXd& u_nominal, Baumgarte stab)
    : model_(model), controller_(controller), plant_(plant), x_ref_(x_ref), u_nominal_(u_nominal), stab_(stab),
      data_(model) {
  if (controller_ && controller_->sample_time() == 0) continuous_states_ = controller_->nxc();
  // a continuous controller's output has no rate or acceleration to give a motion input; a
  // sampled one's (a driver's steer) is held between its samples: the coordinate steps there and
  // rests between (zero-order hold, as the Stepper's co-simulation holds it)
  for (int k : model.plant_inputs)
    if (controller_ && controller_->sample_time() == 0 && model.actuators[static_cast<std::size_t>(k)].type == ActuatorType::Motion)
      throw std::invalid_argument("simulate: the continuous controller drives the motion input \"" +
                                  model.actuators[static_cast<std::size_t>(k)].name +
                                  "\", whose rate and acceleration it does not give: not simulated (linearize takes "
                                  "it; a sampled controller, sample_time > 0, holds it between samples; or simulate "
                                  "with it outside Plant/In, moved by a disturbance signal)");
  if (controller_ && controller_->needs_state() && !plant_)
    throw std::invalid_argument("state feedback needs the plant's linearization (its state order)");
}

ControllerInput ClosedLoopSystem::measure(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
  ControllerInput in;
  in.t = t;
  if (reference_) in.r = reference_(t);
  const auto& out = model_.plant_outputs;
  if (controller_ && controller_->needs_rates()) {
    // outputs and their rates in one pass: q(s) = q (+) s v, derivative at s = 0
    ADVec dq(model_.nv), va(model_.nv);
    for (int i = 0; i < model_.nv; ++i) {
      dq[i] = ADScalar(0.0, Eigen::VectorXd::Constant(1, v[i]));
      va[i] = ADScalar(v[i], Eigen::VectorXd::Zero(1));
    }
    if (!ad_data_) ad_data_ = std::make_unique<DataT<ADScalar>>(model_);
    DataT<ADScalar>& d = *ad_data_;
    if (model_.ns) {
      // the effect states move too: their rates depend on q, v and s only (not on the inputs)
      forward_kinematics<double>(model_, data_, q, v);
      applied_forces<double>(model_, data_, q, v, u_nominal_);
      for (int i = 0; i < model_.ns; ++i) d.s[i] = ADScalar(data_.s[i], Eigen::VectorXd::Constant(1, data_.sdot[i]));
    }
    const ADVec qa = integrate<ADScalar>(model_, q.cast<ADScalar>(), dq);
    forward_kinematics<ADScalar>(model_, d, qa, va);
    const ADVec y = sensor_outputs<ADScalar>(model_, d, out, qa, va);
    in.y.resize(y.size());
    in.ydot.resize(y.size());
    for (Eigen::Index k = 0; k < y.size(); ++k) {
      in.y[k] = y[k].value();
      in.ydot[k] = y[k].derivatives().size() ? y[k].derivatives()[0] : 0.0;
    }
  } else {
    forward_kinematics<double>(model_, data_, q, v);
    in.y = sensor_outputs<double>(model_, data_, out, q, v);
  }
  if (controller_ && controller_->needs_state()) in.x = plant_->qv_to_state(q, v, data_.s) - x_ref_;
  return in;
}

Eigen::VectorXd ClosedLoopSystem::saturate(Eigen::VectorXd u) const {
  for (int k = 0; k < model_.nu(); ++k) u[k] = std::clamp(u[k], model_.actuators[k].min, model_.actuators[k].max);
  return u;
}

void ClosedLoopSystem::apply_beside(Eigen::VectorXd& u, const Eigen::VectorXd& d) const {
  if (beside_held_.size() != static_cast<Eigen::Index>(beside_actuators_.size())) return;  // not sampled yet
  for (std::size_t i = 0; i < beside_actuators_.size(); ++i) {
    const int a = beside_actuators_[i];
    u[a] = beside_held_[static_cast<Eigen::Index>(i)] + (d.size() ? d[a] : 0.0);
  }
}

Eigen::VectorXd ClosedLoopSystem::inputs(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                         const Eigen::VectorXd& xc) const {
  Eigen::VectorXd u = u_nominal_;
  const Eigen::VectorXd d = disturbance_ ? disturbance_(t) : Eigen::VectorXd();
  if (d.size()) u += d;
  apply_beside(u, d);
  Eigen::VectorXd up;
  if (!controller_ || controller_->sample_time() > 0) {
    // held values: a discrete controller's last output, or inputs set from outside (co-simulation)
    if (!held_) return saturate(u);
    up = *held_;
  } else {
    up = controller_->output(measure(t, q, v), xc);
  }
  // a disturbance on a Plant/In input adds to what the controller asks (an excitation at the
  // plant's input: codyna freqresp; a study's disturbances are on other actuators)
  for (std::size_t k = 0; k < model_.plant_inputs.size(); ++k) {
    const int a = model_.plant_inputs[k];
    u[a] = up[k] + (d.size() ? d[a] : 0.0);
  }
  return saturate(u);
}

Eigen::VectorXd ClosedLoopSystem::motion_rates(double t) const {
  const int nm = static_cast<int>(model_.motions.size());
  Eigen::VectorXd r = Eigen::VectorXd::Zero(nm);
  if (!disturbance_rate_) return r;
  const Eigen::VectorXd all = disturbance_rate_(t);
  for (int i = 0; i < nm; ++i) r[i] = all[model_.motions[static_cast<std::size_t>(i)]];
  return r;
}

void ClosedLoopSystem::apply_motions(double t, Eigen::VectorXd& q, Eigen::VectorXd& v, Eigen::VectorXd* acc) {
  const int nm = static_cast<int>(model_.motions.size());
  if (nm == 0) return;
  // u0 plus the disturbance, or a held Plant/In value (no controller drives a motion input)
  Eigen::VectorXd value = u_nominal_;
  const Eigen::VectorXd d = disturbance_ ? disturbance_(t) : Eigen::VectorXd();
  if (d.size()) value += d;
  apply_beside(value, d);
  if (held_)
    for (std::size_t k = 0; k < model_.plant_inputs.size(); ++k) value[model_.plant_inputs[k]] = (*held_)[k];
  value = saturate(value);
  const Eigen::VectorXd rate = motion_rates(t);
  const Eigen::VectorXd all_acc = disturbance_acceleration_ ? disturbance_acceleration_(t) : Eigen::VectorXd();
  if (data_.motion_acc.size() != nm) data_.motion_acc.setZero(nm);
  for (int i = 0; i < nm; ++i) {
    const int k = model_.motions[static_cast<std::size_t>(i)];
    const ActuatorModel& a = model_.actuators[static_cast<std::size_t>(k)];
    const bool held_at_limit = value[k] <= a.min || value[k] >= a.max;  // saturated: the coordinate stops there
    q[a.iq] = value[k];
    v[a.iv] = held_at_limit ? 0.0 : rate[i];
    data_.motion_acc[i] = held_at_limit || all_acc.size() == 0 ? 0.0 : all_acc[k];
  }
  if (acc) *acc = data_.motion_acc;
}

void ClosedLoopSystem::rhs(double t, const Eigen::VectorXd& y, Eigen::VectorXd& ydot) {
  check_cancel();
  ++evaluations_;
  const int nq = model_.nq, nv = model_.nv, nx = nxc(), ns_ = ns();
  Eigen::VectorXd q = y.head(nq), v = y.segment(nq, nv);
  const Eigen::VectorXd xc = y.tail(nx);
  if (ns_) data_.s = y.segment(nq + nv, ns_);
  apply_motions(t, q, v);
  const Eigen::VectorXd u = inputs(t, q, v, xc);
  ydot.resize(ode_size());
  ydot.head(nq) = qdot<double>(model_, q, v);
  if (model_.nc == 0 || !model_.motions.empty()) ydot.segment(nq, nv) = forward_dynamics<double>(model_, data_, q, v, u, stab_);
  else ydot.segment(nq, nv) = loop_accelerations(model_, data_, stab_, q, v, u);
  if (ns_) ydot.segment(nq + nv, ns_) = data_.sdot;  // applied_forces wrote them at (q, v, s)
  if (nx) ydot.tail(nx) = controller_rates(t, q, v, xc, u);
}



Eigen::VectorXd ClosedLoopSystem::controller_rates(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                   const Eigen::VectorXd& xc, const Eigen::VectorXd& u) const {
  ControllerInput in = measure(t, q, v);
  in.u.resize(static_cast<Eigen::Index>(model_.plant_inputs.size()));
  for (std::size_t k = 0; k < model_.plant_inputs.size(); ++k) in.u[k] = u[model_.plant_inputs[k]];
  return controller_->update(in, xc);
}

void ClosedLoopSystem::residual(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& Yp, Eigen::VectorXd& F) {
  check_cancel();
  ++evaluations_;
  const int nq = model_.nq, nv = model_.nv, nx = nxc(), n = na(), ns_ = ns();
  Eigen::VectorXd q = Y.head(nq), v = Y.segment(nq, nv);
  const Eigen::VectorXd xc = Y.segment(nq + nv + ns_, nx);
  if (ns_) data_.s = Y.segment(nq + nv, ns_);
  Eigen::VectorXd vp = Yp.segment(nq, nv);
  // motion inputs: their coordinates, rates and accelerations are the signal's (as in rhs); their
  // balance, which holds their unknown reaction, is replaced below by v_d' = u''
  apply_motions(t, q, v);
  for (std::size_t i = 0; i < model_.motions.size(); ++i)
    vp[model_.actuators[static_cast<std::size_t>(model_.motions[i])].iv] = data_.motion_acc[static_cast<Eigen::Index>(i)];
  const Eigen::VectorXd u = inputs(t, q, v, xc);
  F.resize(dae_size());
  F.head(nq) = Yp.head(nq) - qdot<double>(model_, q, v);
  forward_kinematics<double>(model_, data_, q, v);
  const Eigen::VectorXd Q = applied_forces<double>(model_, data_, q, v, u);
  const Eigen::MatrixXd M = crba<double>(model_, data_, q);
  const Eigen::VectorXd h = nonlinear_effects<double>(model_, data_, q, v);
  Eigen::VectorXd dyn = M * vp + h - Q;
  if (n) {
    constraint_terms<double>(model_, data_, q, v);
    const Eigen::VectorXd lambda = Y.tail(n);
    for (int k = 0; k < n; ++k) {
      const int r = rows_[k];
      dyn += data_.Jc.row(r).transpose() * lambda[k];
      F[ode_size() + k] = data_.Jc.row(r).dot(vp) + data_.gamma[r] + 2.0 * stab_.alpha * data_.Jc.row(r).dot(v) +
                          stab_.beta * stab_.beta * data_.phi[r];
    }
  }
  F.segment(nq, nv) = dyn;
  for (std::size_t i = 0; i < model_.motions.size(); ++i) {
    const int iv = model_.actuators[static_cast<std::size_t>(model_.motions[i])].iv;
    F[nq + iv] = Yp[nq + iv] - vp[iv];
  }
  if (ns_) F.segment(nq + nv, ns_) = Yp.segment(nq + nv, ns_) - data_.sdot;  // applied_forces above
  if (nx) F.segment(nq + nv + ns_, nx) = Yp.segment(nq + nv + ns_, nx) - controller_rates(t, q, v, xc, u);
}

void ClosedLoopSystem::consistent(double t, const Eigen::VectorXd& y_in, Eigen::VectorXd& Y, Eigen::VectorXd& Yp) {
  // the motion inputs' coordinates and rates where their signals are
  Eigen::VectorXd y = y_in;
  if (!model_.motions.empty()) {
    Eigen::VectorXd q = y.head(model_.nq), v = y.segment(model_.nq, model_.nv);
    apply_motions(t, q, v);
    y.head(model_.nq) = q;
    y.segment(model_.nq, model_.nv) = v;
  }
  Eigen::VectorXd yd;
  rhs(t, y, yd);
  Y.resize(dae_size());
  Yp = Eigen::VectorXd::Zero(dae_size());
  Y.head(ode_size()) = y;
  Yp.head(ode_size()) = yd;
  if (na()) {
    if (ns()) data_.s = y.segment(model_.nq + model_.nv, ns());
    constraint_terms<double>(model_, data_, y.head(model_.nq), y.segment(model_.nq, model_.nv));
    rows_ = partition_rows(data_.Jc, 1e-9, na()).independent;
    // multipliers for these rows (forward_dynamics gives them on its independent rows)
    forward_dynamics<double>(model_, data_, y.head(model_.nq), y.segment(model_.nq, model_.nv),
                             inputs(t, y.head(model_.nq), y.segment(model_.nq, model_.nv), y.tail(nxc())), stab_);
  }
  for (int k = 0; k < na(); ++k) Y[ode_size() + k] = data_.lambda[rows_[k]];
}

bool ClosedLoopSystem::rows_degraded(const Eigen::VectorXd& q) {
  if (rows_.empty()) return false;
  constraint_terms<double>(model_, data_, q, Eigen::VectorXd::Zero(model_.nv));
  Eigen::MatrixXd Ja(rows_.size(), model_.nv);
  for (std::size_t k = 0; k < rows_.size(); ++k) Ja.row(k) = data_.Jc.row(rows_[k]);
  const Eigen::VectorXd s_all = Eigen::JacobiSVD<Eigen::MatrixXd>(data_.Jc).singularValues();
  const Eigen::VectorXd s_rows = Eigen::JacobiSVD<Eigen::MatrixXd>(Ja).singularValues();
  return s_rows[s_rows.size() - 1] < 0.3 * s_all[rows_.size() - 1];
}

std::pair<double, double> ClosedLoopSystem::violation(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  if (model_.nc == 0) return {0.0, 0.0};
  forward_kinematics<double>(model_, data_, q);
  return constraint_violation_after_kinematics(model_, data_, q, v);
}

void ClosedLoopSystem::project_tangent(const Eigen::VectorXd& y, Eigen::VectorXd& e) {
  if (model_.nc == 0) return;
  constraint_terms<double>(model_, data_, y.head(model_.nq), Eigen::VectorXd::Zero(model_.nv));
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(1e-9);
  // a motion input's coordinate and rate have no error (they are set), and its column takes no part
  Eigen::MatrixXd& J = data_.Jc;
  for (int k : model_.motions) {
    const ActuatorModel& a = model_.actuators[static_cast<std::size_t>(k)];
    J.col(a.iv).setZero();
    e[a.iq] = 0.0;
    e[model_.nq + a.iv] = 0.0;
  }
  cod.compute(J);
  auto remove_normal = [&](auto&& block) { block -= cod.solve(J * Eigen::VectorXd(block)); };
  remove_normal(e.segment(model_.nq, model_.nv));
  if (model_.nq == model_.nv) {
    // the positions' normal: the rows on q only (rolling's no-slip rows do not restrict them)
    if (!model_.velocity_rows.empty()) {
      for (int r : model_.velocity_rows) J.row(r).setZero();
      cod.compute(J);
    }
    remove_normal(e.head(model_.nq));
  }
}

bool ClosedLoopSystem::project(Eigen::VectorXd& y, double tol, double t) {
  if (model_.nc == 0) return false;
  Eigen::VectorXd q = y.head(model_.nq), v = y.segment(model_.nq, model_.nv);
  // the driven coordinates where their motions are (assemble holds them and closes the loops on the
  // others); apply_motions' accelerations are set again by the next rhs
  if (!model_.motions.empty() && !std::isnan(t)) apply_motions(t, q, v);
  const auto [p, w] = violation(q, v);
  if (p <= tol && w <= tol * std::max(1.0, v.norm())) return false;
  AssemblyOptions opt;
  opt.tolerance = tol > 0 ? std::min(1e-12, tol * 1e-3) : 1e-12;
  const AssemblyResult r = assemble(model_, q, v, opt);
  y.head(model_.nq) = r.q;
  y.segment(model_.nq, model_.nv) = r.v;
  return true;
}

}  // namespace codyna

namespace codyna {

namespace {
// quaternion products as matrices: a (x) b = Lq(a) b = Rq(b) a, components [w, x, y, z]
Eigen::Matrix4d Lq(const Eigen::Vector4d& a) {
  Eigen::Matrix4d L;
  L << a[0], -a[1], -a[2], -a[3], a[1], a[0], -a[3], a[2], a[2], a[3], a[0], -a[1], a[3], -a[2], a[1], a[0];
  return L;
}
Eigen::Matrix4d Rq(const Eigen::Vector4d& b) {
  Eigen::Matrix4d R;
  R << b[0], -b[1], -b[2], -b[3], b[1], b[0], b[3], -b[2], b[2], -b[3], b[0], b[1], b[3], b[2], -b[1], b[0];
  return R;
}
Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d H;
  H << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
  return H;
}
// d(rotation tangent)/dp for the (not necessarily unit) quaternion p of a joint: the rotation is
// that of p/|p| and a tangent step d moves it to p/|p| (x) exp(d), so d = 2 vec(conj(p^) (x) dp)/|p|
Eigen::Matrix<double, 3, 4> rotation_tangent(const Eigen::Vector4d& p) {
  const double n = p.norm();
  const Eigen::Vector4d u = p / n;
  const Eigen::Vector3d e = u.tail<3>();
  Eigen::Matrix<double, 3, 4> G;
  G.col(0) = -e;
  G.rightCols<3>() = u[0] * Eigen::Matrix3d::Identity() - hat(e);
  return (2.0 / n) * G;
}
}  // namespace

bool ClosedLoopSystem::exact_dae_jacobian() const {
  // (rolling's no-slip rows have no analytic derivatives yet: SUNDIALS' difference quotients)
  // (nor the effect states: the tires' transient slip)
  return nxc() == 0 && (!controller_ || controller_->sample_time() > 0) && model_.motions.empty() &&
         model_.velocity_rows.empty() && model_.ns == 0;
}

bool ClosedLoopSystem::exact_ode_jacobian() const {
  return exact_dae_jacobian() && (model_.nc == 0 || (stab_.alpha == 0.0 && stab_.beta == 0.0));
}

void ClosedLoopSystem::kinematic_jacobians(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  const int nq = model_.nq, nv = model_.nv;
  if (tangent_map_.rows() != nv || tangent_map_.cols() != nq) tangent_map_.resize(nv, nq);
  if (qdot_dq_.rows() != nq || qdot_dq_.cols() != nq) qdot_dq_.resize(nq, nq);
  if (qdot_dv_.rows() != nq || qdot_dv_.cols() != nv) qdot_dv_.resize(nq, nv);
  tangent_map_.setZero();
  qdot_dq_.setZero();
  qdot_dv_.setZero();
  // quaternion at qi, angular velocity (body axes) at wi: qdot = p (x) (0, w) / 2
  auto quaternion = [&](int qi, int wi) {
    const Eigen::Vector4d p = q.segment<4>(qi);
    const Eigen::Vector4d w(0.0, v[wi], v[wi + 1], v[wi + 2]);
    qdot_dq_.block<4, 4>(qi, qi) = 0.5 * Rq(w);
    qdot_dv_.block<4, 3>(qi, wi) = 0.5 * Lq(p).rightCols<3>();
    tangent_map_.block<3, 4>(wi, qi) = rotation_tangent(p);
  };
  for (int b = 1; b < model_.nbodies; ++b) {
    const JointModel& j = model_.joints[b];
    const int iq = j.idx_q, iv = j.idx_v;
    switch (j.type) {
      case JointType::Spherical:
        quaternion(iq, iv);
        break;
      case JointType::Free: {
        quaternion(iq + 3, iv);
        // position rate R(p) v_lin; a rotation step d turns it by R (d x v_lin)
        const Eigen::Vector4d p = q.segment<4>(iq + 3);
        const Eigen::Matrix3d R = quat_to_matrix<double>(p[0], p[1], p[2], p[3]);
        const Eigen::Vector3d vl = v.segment<3>(iv + 3);
        qdot_dv_.block<3, 3>(iq, iv + 3) = R;
        qdot_dq_.block<3, 4>(iq, iq + 3) = -R * hat(vl) * rotation_tangent(p);
        tangent_map_.block<3, 3>(iv + 3, iq) = R.transpose();  // q_pos = p0 + R dv_lin
        break;
      }
      default:
        for (int k = 0; k < j.nv; ++k) {
          tangent_map_(iv + k, iq + k) = 1.0;
          qdot_dv_(iq + k, iv + k) = 1.0;
        }
    }
  }
}

bool ClosedLoopSystem::ode_jacobian(double t, const Eigen::VectorXd& y, Eigen::MatrixXd& J) {
  if (!exact_ode_jacobian()) return false;
  const int nq = model_.nq, nv = model_.nv, n = ode_size();
  const Eigen::VectorXd q = y.head(nq), v = y.segment(nq, nv);
  const Eigen::VectorXd u = inputs(t, q, v, y.tail(nxc()));
  if (!deriv_) deriv_ = std::make_unique<TreeDerivatives>(model_);
  if (model_.nc == 0) {
    deriv_->compute(q, v, u, {});
  } else {
    forward_dynamics<double>(model_, data_, q, v, u, stab_);
    deriv_->compute_constrained(q, v, u, data_.qdd, data_.lambda, data_.loop.rows, {});
  }
  kinematic_jacobians(q, v);
  if (J.rows() != n || J.cols() != n) J.resize(n, n);
  J.setZero();
  J.topLeftCorner(nq, nq) = qdot_dq_;
  J.block(0, nq, nq, nv) = qdot_dv_;
  J.block(nq, 0, nv, nq).noalias() = deriv_->dqdd_dq * tangent_map_;
  J.block(nq, nq, nv, nv) = deriv_->dqdd_dv;
  return true;
}

bool ClosedLoopSystem::dae_jacobian(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& Yp, double cj,
                                    Eigen::MatrixXd& J) {
  if (!exact_dae_jacobian()) return false;
  const int nq = model_.nq, nv = model_.nv, nc = model_.nc, n = dae_size(), m = ode_size(), na_ = na();
  if (static_cast<int>(rows_.size()) != na_) return false;  // consistent() not called yet
  const Eigen::VectorXd q = Y.head(nq), v = Y.segment(nq, nv), vp = Yp.segment(nq, nv);
  const Eigen::VectorXd u = inputs(t, q, v, Y.segment(nq + nv, nxc()));
  if (!deriv_) deriv_ = std::make_unique<TreeDerivatives>(model_);
  if (lambda_full_.size() != nc) lambda_full_.resize(nc);
  lambda_full_.setZero();
  for (int k = 0; k < na_; ++k) lambda_full_[rows_[k]] = Y[m + k];
  // tau(q, v, v') and Q - Jc^T lambda with their derivatives (the accelerations' derivatives,
  // which this also solves for, are not used)
  deriv_->compute_constrained(q, v, u, vp, lambda_full_, rows_, {});
  const TreeDerivatives& D = *deriv_;
  kinematic_jacobians(q, v);
  if (J.rows() != n || J.cols() != n) J.resize(n, n);
  J.setZero();
  // q' - qdot(q, v)
  J.topLeftCorner(nq, nq) = cj * Eigen::MatrixXd::Identity(nq, nq) - qdot_dq_;
  J.block(0, nq, nq, nv) = -qdot_dv_;
  // M v' + nle - Q + Jc^T lambda = tau - (Q - Jc^T lambda)
  J.block(nq, 0, nv, nq).noalias() = (D.dtau_dq - D.dQ_dq) * tangent_map_;
  J.block(nq, nq, nv, nv) = D.dtau_dv - D.dQ_dv + cj * D.M;
  for (int k = 0; k < na_; ++k) {
    const int r = rows_[k];
    J.block(nq, m + k, nv, 1) = D.Jc.row(r).transpose();
    // Ja v' + gamma + 2 alpha Ja v + beta^2 phi
    Eigen::RowVectorXd dq = D.dc_dq.row(r);
    Eigen::RowVectorXd dv = D.dc_dv.row(r) + cj * D.Jc.row(r);
    if (stab_.alpha != 0.0) dq += 2.0 * stab_.alpha * D.dphid_dq.row(r), dv += 2.0 * stab_.alpha * D.Jc.row(r);
    if (stab_.beta != 0.0) dq += stab_.beta * stab_.beta * D.Jc.row(r);
    J.block(m + k, 0, 1, nq).noalias() = dq * tangent_map_;
    J.block(m + k, nq, 1, nv) = dv;
  }
  return true;
}

}  // namespace codyna
