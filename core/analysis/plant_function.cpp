#include "analysis/plant_function.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <type_traits>
#include <stdexcept>

#include "dynamics/aba.hpp"
#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "spatial/autodiff.hpp"
#include "spatial/linalg.hpp"

namespace codyna {

namespace {

// the constraint rows on q that are independent at q (redundancy can move between rows); rolling's
// no-slip rows, on the velocities only, are not among them (velocity_rows_at)
std::vector<int> independent_rows(const Model& m, const Eigen::VectorXd& q) {
  if (m.nc == 0) return {};
  const int rank = static_cast<int>(m.active_rows.size()) - m.active_velocity_rows;
  if (rank == 0) return {};
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  for (int r : m.velocity_rows) d.Jc.row(r).setZero();
  return partition_rows(d.Jc, 1e-9, rank).independent;
}

// the non-holonomic rows independent of the holonomic rows `held` at q (as prepare_model chose them
// at q0: in order, each kept when it adds to the rank)
std::vector<int> velocity_rows_at(const Model& m, const Eigen::VectorXd& q, const std::vector<int>& held) {
  if (m.active_velocity_rows == 0) return {};
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  const std::vector<int> out = rows_adding_rank(d.Jc, held, m.velocity_rows, m.active_velocity_rows);
  if (static_cast<int>(out.size()) != m.active_velocity_rows)
    throw std::invalid_argument("the rolling conditions lose rank at this configuration (" +
                                std::to_string(out.size()) + " of " + std::to_string(m.active_velocity_rows) +
                                " independent): no state-space model here");
  return out;
}

Eigen::MatrixXd active_jacobian(const Model& m, const Eigen::VectorXd& q, const std::vector<int>& rows) {
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  Eigen::MatrixXd J(rows.size(), m.nv);
  for (std::size_t k = 0; k < rows.size(); ++k) J.row(k) = d.Jc.row(rows[k]);
  return J;
}

// a dependent coordinate on a ball or free joint (a tangent coordinate)
bool tangent_dependent(const Model& m, const std::vector<int>& dep) {
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (j.type != JointType::Spherical && j.type != JointType::Free) continue;
    for (int i : dep)
      if (i >= j.idx_v && i < j.idx_v + j.nv) return true;
  }
  return false;
}

// d phi(q_ref (+) dq) / d(dq[dep]) on `rows`, by automatic differentiation
Eigen::MatrixXd phi_by_dependent(const Model& m, const Eigen::VectorXd& q_ref, const Eigen::VectorXd& dq,
                                 const std::vector<int>& rows, const std::vector<int>& dep) {
  const int nd = static_cast<int>(dep.size());
  ADVec dqa(m.nv);
  for (int i = 0; i < m.nv; ++i) dqa[i] = ADScalar(dq[i], Eigen::VectorXd::Zero(nd));
  for (int c = 0; c < nd; ++c) dqa[dep[static_cast<std::size_t>(c)]].derivatives()[c] = 1.0;
  DataT<ADScalar> d(m);
  const ADVec q = integrate<ADScalar>(m, q_ref.cast<ADScalar>(), dqa);
  const ADVec& phi = constraint_residual<ADScalar>(m, d, q);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), nd);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const ADScalar& p = phi[rows[k]];
    if (p.derivatives().size() == nd) J.row(static_cast<Eigen::Index>(k)) = p.derivatives().transpose();
  }
  return J;
}

Eigen::MatrixXd columns(const Eigen::MatrixXd& J, const std::vector<int>& cols) {
  Eigen::MatrixXd r(J.rows(), cols.size());
  for (std::size_t k = 0; k < cols.size(); ++k) r.col(k) = J.col(cols[k]);
  return r;
}

template <class S>
MatXT<S> columns_t(const MatXT<S>& J, const std::vector<int>& cols) {
  MatXT<S> r(J.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) r.col(k) = J.col(cols[k]);
  return r;
}

// motion input i's coordinate value, rate and acceleration (Model::motions order): the Plant/In's
// value in u and, when u carries them (nu_p + 2 nm inputs), its rate and acceleration; a motion
// outside Plant/In stays at its nominal value, at rest
template <class S>
void motion_of(const Model& m, const std::vector<int>& motion_inputs, const Eigen::VectorXd& u_all, std::size_t i,
               const VecXT<S>& u, S& value, S& rate, S& acc) {
  const int k = m.motions[i], nu_p = static_cast<int>(m.plant_inputs.size()), nmi = static_cast<int>(motion_inputs.size());
  value = S(u_all[k]);
  rate = S(0.0);
  acc = S(0.0);
  for (int j = 0; j < nmi; ++j) {
    const int pos = motion_inputs[static_cast<std::size_t>(j)];
    if (m.plant_inputs[static_cast<std::size_t>(pos)] != k) continue;
    value = u[pos];
    if (u.size() > nu_p) {
      rate = u[nu_p + j];
      acc = u[nu_p + nmi + j];
    }
  }
}

}  // namespace

std::vector<int> CoordinatePartition::rates() const {
  std::vector<int> r;
  for (int i : independent)
    if (std::find(rate_dependent.begin(), rate_dependent.end(), i) == rate_dependent.end()) r.push_back(i);
  return r;
}

namespace {

CoordinatePartition partition_positions(const Model& m, const Eigen::VectorXd& q,
                                        const std::vector<std::string>& preferred);

// Rolling's no-slip rows fix some of the independent coordinates' rates from the others': with
// the holonomic rows Jh (v_dep = -Jh_d^-1 Jh_i v_ind), the rolling rows on the independent rates are
// E = Jn_i - Jn_d Jh_d^-1 Jh_i, and its pivots (column-pivoted QR) are the rates that follow.
void choose_rate_dependent(const Model& m, const Eigen::VectorXd& q, CoordinatePartition& p) {
  p.rate_dependent.clear();
  if (m.active_velocity_rows == 0) return;
  const std::vector<int> held = independent_rows(m, q), rolling = velocity_rows_at(m, q, held);
  Data d(m);
  constraint_terms<double>(m, d, q, Eigen::VectorXd::Zero(m.nv));
  const auto block = [&](const std::vector<int>& rows, const std::vector<int>& cols) {
    Eigen::MatrixXd B(rows.size(), cols.size());
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t c = 0; c < cols.size(); ++c) B(r, c) = d.Jc(rows[r], cols[c]);
    return B;
  };
  Eigen::MatrixXd E = block(rolling, p.independent);
  if (!p.dependent.empty())
    E -= block(rolling, p.dependent) * block(held, p.dependent).partialPivLu().solve(block(held, p.independent));
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(E);
  const auto& perm = qr.colsPermutation().indices();
  std::vector<int> cols;
  for (Eigen::Index k = 0; k < E.rows(); ++k) cols.push_back(static_cast<int>(perm[k]));
  std::sort(cols.begin(), cols.end());
  Eigen::MatrixXd Ed(E.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) Ed.col(static_cast<Eigen::Index>(c)) = E.col(cols[c]);
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(Ed).singularValues();
  if (sv.size() && sv[sv.size() - 1] < 1e-8 * std::max(1.0, sv[0]))
    throw std::invalid_argument("the rolling conditions fix no rate of the independent coordinates at this "
                                "configuration (their Jacobian is singular there)");
  for (int c : cols) p.rate_dependent.push_back(p.independent[static_cast<std::size_t>(c)]);
}

}  // namespace

CoordinatePartition partition_coordinates(const Model& m, const Eigen::VectorXd& q,
                                          const std::vector<std::string>& preferred) {
  CoordinatePartition p = partition_positions(m, q, preferred);
  choose_rate_dependent(m, q, p);
  return p;
}

namespace {

CoordinatePartition partition_positions(const Model& m, const Eigen::VectorXd& q,
                                        const std::vector<std::string>& preferred) {
  CoordinatePartition p;
  for (int k : m.motions) p.driven.push_back(m.actuators[static_cast<std::size_t>(k)].iv);
  const auto is_driven = [&](int i) { return std::find(p.driven.begin(), p.driven.end(), i) != p.driven.end(); };
  for (const std::string& name : preferred) {
    const auto it = std::find(m.v_names.begin(), m.v_names.end(), name);
    if (it != m.v_names.end() && is_driven(static_cast<int>(it - m.v_names.begin())))
      throw std::invalid_argument("independent coordinates: \"" + name + "\" is driven by a motion input (not a state)");
  }
  const std::vector<int> rows = independent_rows(m, q);
  if (rows.empty()) {
    for (int i = 0; i < m.nv; ++i)
      if (!is_driven(i)) p.independent.push_back(i);
    for (const std::string& name : preferred)
      if (std::find(m.v_names.begin(), m.v_names.end(), name) == m.v_names.end())
        throw std::invalid_argument("independent coordinates: unknown coordinate \"" + name + "\"");
    if (!preferred.empty() && static_cast<int>(preferred.size()) != m.dof())
      throw std::invalid_argument("independent coordinates: a tree model has all " + std::to_string(m.dof()) +
                                  " coordinates independent");
    return p;
  }
  // a motion input's coordinate is neither independent nor dependent: its column takes no part
  // in the choice (a zero column is pivoted last)
  Eigen::MatrixXd J = active_jacobian(m, q, rows);
  for (int i : p.driven) J.col(i).setZero();
  if (preferred.empty()) {
    // the dependent coordinates: the pivots of a column-pivoted QR. The coordinates a joint_force
    // actuator drives (a five-bar's cranks) are kept independent when that choice is well
    // conditioned: their columns are shrunk so that they are pivoted last
    const auto dependent_of = [&](const Eigen::MatrixXd& Jw) {
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Jw);
      const auto& perm = qr.colsPermutation().indices();
      std::set<int> dep;
      for (Eigen::Index k = 0; k < Jw.rows(); ++k) dep.insert(perm[k]);
      return dep;
    };
    const auto conditioning = [&](const std::set<int>& dep) {
      std::vector<int> cols(dep.begin(), dep.end());
      const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(columns(J, cols)).singularValues();
      return s.size() ? s[s.size() - 1] / std::max(1.0, s[0]) : 0.0;  // as the check below measures it
    };
    std::set<int> dep = dependent_of(J);
    Eigen::MatrixXd Jw = J;
    bool actuated = false;
    for (const ActuatorModel& a : m.actuators)
      if (a.type == ActuatorType::JointForce) Jw.col(a.iv) *= 1e-3, actuated = true;
    if (actuated) {
      const std::set<int> pref = dependent_of(Jw);
      // kept when conditioned to 1e-3, or to a tenth of the unbiased choice (never below 1e-6)
      if (pref != dep && conditioning(pref) >= std::max(1e-6, std::min(1e-3, 0.1 * conditioning(dep)))) dep = pref;
    }
    for (int i = 0; i < m.nv; ++i)
      if (!is_driven(i)) (dep.count(i) ? p.dependent : p.independent).push_back(i);
  } else {
    std::set<int> ind;
    for (const std::string& name : preferred) {
      auto it = std::find(m.v_names.begin(), m.v_names.end(), name);
      if (it == m.v_names.end())
        throw std::invalid_argument("independent coordinates: unknown coordinate \"" + name + "\"");
      ind.insert(static_cast<int>(it - m.v_names.begin()));
    }
    if (static_cast<int>(ind.size()) != m.dof())
      throw std::invalid_argument("independent coordinates: the model has " + std::to_string(m.dof()) +
                                  " degrees of freedom, " + std::to_string(ind.size()) + " distinct coordinates given");
    for (int i = 0; i < m.nv; ++i)
      if (!is_driven(i)) (ind.count(i) ? p.independent : p.dependent).push_back(i);
  }
  const Eigen::MatrixXd Jd = columns(J, p.dependent);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jd);
  const Eigen::VectorXd s = svd.singularValues();
  if (s.size() && s[s.size() - 1] < 1e-8 * std::max(1.0, s[0]))
    throw std::invalid_argument("independent coordinates: the dependent coordinates cannot be solved from the "
                                "constraints at this configuration (their Jacobian is singular); choose others");
  return p;
}

}  // namespace

CoordinatePartition partition_holding(const Model& m, const Eigen::VectorXd& q, const std::vector<std::string>& held,
                                      const std::vector<std::string>& preferred) {
  std::vector<int> held_v;
  for (const std::string& name : held) {
    const auto it = std::find(m.v_names.begin(), m.v_names.end(), name);
    if (it == m.v_names.end())
      throw std::invalid_argument("held coordinates: unknown coordinate \"" + name + "\"");
    held_v.push_back(static_cast<int>(it - m.v_names.begin()));
    for (int k : m.motions)
      if (m.actuators[static_cast<std::size_t>(k)].iv == held_v.back())
        throw std::invalid_argument("held coordinates: \"" + name + "\" is driven by the motion input \"" +
                                    m.actuators[static_cast<std::size_t>(k)].name + "\" (set that input instead)");
  }
  if (held_v.empty() || !preferred.empty()) {
    CoordinatePartition p = partition_coordinates(m, q, preferred);
    for (std::size_t k = 0; k < held_v.size(); ++k)
      if (std::find(p.independent.begin(), p.independent.end(), held_v[k]) == p.independent.end())
        throw std::invalid_argument("held coordinates: \"" + held[k] +
                                    "\" is not among the independent coordinates chosen; add it to them");
    return p;
  }
  const std::vector<int> rows = independent_rows(m, q);
  if (rows.empty()) return partition_coordinates(m, q);
  // dependent coordinates among the others: the held columns are left out of the pivoting
  Eigen::MatrixXd J = active_jacobian(m, q, rows);
  for (int i : held_v) J.col(i).setZero();
  for (int k : m.motions) J.col(m.actuators[static_cast<std::size_t>(k)].iv).setZero();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J);
  const auto& perm = qr.colsPermutation().indices();
  std::set<int> dep;
  for (Eigen::Index k = 0; k < J.rows(); ++k) dep.insert(perm[k]);
  for (int i : held_v)
    if (dep.count(i))
      throw std::invalid_argument("held coordinates: the loops leave no freedom to hold \"" +
                                  m.v_names[static_cast<std::size_t>(i)] + "\" with the others held too");
  std::vector<std::string> names;
  for (int i = 0; i < m.nv; ++i) {
    bool driven = false;
    for (int k : m.motions) driven = driven || m.actuators[static_cast<std::size_t>(k)].iv == i;
    if (!dep.count(i) && !driven) names.push_back(m.v_names[static_cast<std::size_t>(i)]);
  }
  try {
    return partition_coordinates(m, q, names);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("held coordinates: the loops cannot close with these coordinates held (the remaining "
                                "coordinates cannot be solved from the constraints here)");
  }
}

PlantFunction::PlantFunction(const Model& model, const Eigen::VectorXd& q_ref, const Eigen::VectorXd& u_all,
                             CoordinatePartition partition)
    : model_(model), q_ref_(q_ref), u_all_(u_all), part_(std::move(partition)), rows_(independent_rows(model, q_ref)) {
  if (rows_.size() != part_.dependent.size())
    throw std::invalid_argument("coordinate partition does not match the constraints at the reference configuration");
  rates_ = part_.rates();
  vrows_ = rows_;
  vdep_ = part_.dependent;
  if (!part_.rate_dependent.empty() || model.active_velocity_rows > 0) {
    const std::vector<int> rolling = velocity_rows_at(model, q_ref, rows_);
    if (rolling.size() != part_.rate_dependent.size())
      throw std::invalid_argument("coordinate partition does not match the rolling conditions at the reference "
                                  "configuration");
    vrows_.insert(vrows_.end(), rolling.begin(), rolling.end());
    vdep_.insert(vdep_.end(), part_.rate_dependent.begin(), part_.rate_dependent.end());
  }
  for (std::size_t k = 0; k < model.plant_inputs.size(); ++k)
    if (model.actuators[static_cast<std::size_t>(model.plant_inputs[k])].type == ActuatorType::Motion)
      motion_inputs_.push_back(static_cast<int>(k));
}

Eigen::VectorXd PlantFunction::solve_dependent(const Eigen::VectorXd& z) const {
  newton_dependent(z);
  Eigen::VectorXd r(part_.dependent.size());
  for (std::size_t k = 0; k < part_.dependent.size(); ++k) r[k] = ws_.dq[part_.dependent[k]];
  return r;
}

void PlantFunction::eval_tree(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot,
                              Eigen::VectorXd& y, Reuse reuse) const {
  const Model& m = model_;
  const int n = nz();
  if (!ws_.data) ws_.data = std::make_unique<Data>(m);
  Data& d = *ws_.data;
  ws_.w = x.tail(n);
  ws_.u_all = u_all_;
  for (int k = 0; k < nu(); ++k) ws_.u_all[m.plant_inputs[k]] = u[k];
  const Eigen::VectorXd* qdd = nullptr;
  if (reuse == Reuse::Positions) {
    // ws_.dq, ws_.q and the position stage in d are those of x already
    velocity_kinematics<double>(m, d, ws_.q, ws_.w);
    const Eigen::VectorXd& Q = applied_forces<double>(m, d, ws_.q, ws_.w, ws_.u_all);
    qdd = &aba_same_positions<double>(m, d, ws_.w, Q);
  } else if (reuse == Reuse::Motion) {
    // and the velocity stage too
    const Eigen::VectorXd& Q = applied_forces<double>(m, d, ws_.q, ws_.w, ws_.u_all);
    qdd = &aba_same_motion<double>(m, d, Q);
  } else {
    ws_.dq = x.head(n);  // a tree: every coordinate is independent, in order
    integrate_into<double>(m, q_ref_, ws_.dq, ws_.q);
    qdd = &forward_dynamics<double>(m, d, ws_.q, ws_.w, ws_.u_all);
  }
  tangent_rate_into<double>(m, ws_.dq, ws_.w, ws_.rate);
  if (xdot.size() != 2 * n) xdot.resize(2 * n);
  xdot.head(n) = ws_.rate;
  xdot.tail(n) = *qdd;
  // forward_dynamics left the kinematics of (q, v) in d
  if (y.size() != ny()) y.resize(ny());
  for (int k = 0; k < ny(); ++k) y[k] = sensor_value<double>(m, d, m.sensors[m.plant_outputs[k]], ws_.q, ws_.w);
}

double fd_step(bool central, double xk) {
  const double eps = std::numeric_limits<double>::epsilon();
  return (central ? std::cbrt(eps) : std::sqrt(eps)) * std::max(1.0, std::abs(xk));
}

bool PlantFunction::fd_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u, bool central,
                                Eigen::MatrixXd& J) const {
  if (motion_ || ns() > 0) return false;
  const Model& m = model_;
  if (m.nc != 0 || !part_.dependent.empty() || !m.motions.empty()) return false;
  const int n = nz(), nx_p = 2 * n, nu_p = nu(), ny_p = ny(), rows = nx_p + ny_p;
  if (J.rows() != rows || J.cols() != nx_p + nu_p) J.resize(rows, nx_p + nu_p);
  Eigen::VectorXd &xs = ws_.fd_x, &us = ws_.fd_u, &xd = ws_.fd_xd, &y = ws_.fd_y;
  Eigen::VectorXd &fp = ws_.fd_p, &fm = ws_.fd_m, &f0 = ws_.fd_0;
  xs = x;
  us = u;
  for (Eigen::VectorXd* r : {&fp, &fm, &f0})
    if (r->size() != rows) r->resize(rows);
  auto eval_into = [&](Eigen::VectorXd& out, Reuse reuse) {
    eval_tree(xs, us, xd, y, reuse);
    out.head(nx_p) = xd;
    out.tail(ny_p) = y;
  };
  // position columns: every stage anew; forward differences keep f(x + h e) in J until f(x) is known
  for (int k = 0; k < n; ++k) {
    const double h = fd_step(central, x[k]);
    xs[k] = x[k] + h;
    eval_into(fp, Reuse::Nothing);
    if (central) {
      xs[k] = x[k] - h;
      eval_into(fm, Reuse::Nothing);
      J.col(k) = (fp - fm) / (2 * h);
    } else {
      J.col(k) = fp;
    }
    xs[k] = x[k];
  }
  // at x: the position and velocity stages that the other columns share
  eval_into(f0, Reuse::Nothing);
  if (!central)
    for (int k = 0; k < n; ++k) J.col(k) = (J.col(k) - f0) / fd_step(false, x[k]);
  // input columns on the motion of x, then velocity columns on its positions
  for (int c = 0; c < n + nu_p; ++c) {
    const bool input = c < nu_p;
    const int k = input ? nx_p + c : n + (c - nu_p);
    const Reuse reuse = input ? Reuse::Motion : Reuse::Positions;
    double& e = input ? us[c] : xs[k];
    const double e0 = e;
    const double h = fd_step(central, e0);
    e = e0 + h;
    eval_into(fp, reuse);
    if (central) {
      e = e0 - h;
      eval_into(fm, reuse);
      J.col(k) = (fp - fm) / (2 * h);
    } else {
      J.col(k) = (fp - f0) / h;
    }
    e = e0;
  }
  return true;
}

template <class S>
void PlantFunction::eval(const VecXT<S>& x, const VecXT<S>& u, VecXT<S>& xdot, VecXT<S>& y) const {
  if constexpr (std::is_same_v<S, double>) {
    if (motion_ || ns() > 0) {
      // about a steady motion, or with effect states: the generic evaluation below, in double
    } else if (model_.motions.empty() && part_.rate_dependent.empty()) {
      if (part_.dependent.empty() && model_.nc == 0) eval_tree(x, u, xdot, y);
      else eval_closed(x, u, xdot, y);
    } else {
      eval_driven(x, u, xdot, y);
    }
    if (!motion_ && ns() == 0) return;
  }
  const Model& m = model_;
  const int n = nz(), nw_ = nw(), nd = static_cast<int>(part_.dependent.size());
  const auto& ind = part_.independent;
  const auto& dep = part_.dependent;
  VecXT<S> dq = VecXT<S>::Zero(m.nv), v = VecXT<S>::Zero(m.nv);
  for (int k = 0; k < n; ++k) dq[ind[k]] = x[k];
  for (int k = 0; k < nw_; ++k) v[rates_[k]] = x[n + k];
  DataT<S> d(m);
  const VecXT<S> zero_v = VecXT<S>::Zero(m.nv);
  // motion inputs: their coordinates at u (a Plant/In's value, or the nominal), u', u''
  if (!m.motions.empty()) {
    const int nu_p = nu(), nmi = nm();
    if (u.size() != nu_p && u.size() != nu_p + 2 * nmi)
      throw std::invalid_argument("plant function: expected " + std::to_string(nu_p) + " or " +
                                  std::to_string(nu_p + 2 * nmi) + " inputs");
    for (std::size_t i = 0; i < m.motions.size(); ++i) {
      const ActuatorModel& a = m.actuators[static_cast<std::size_t>(m.motions[i])];
      S value = S(0.0), rate = S(0.0), acc = S(0.0);
      motion_of<S>(m, motion_inputs_, u_all_, i, u, value, rate, acc);
      dq[a.iv] = value - S(q_ref_[a.iq]);
      v[a.iv] = rate;
      d.motion_acc[static_cast<Eigen::Index>(i)] = acc;
    }
  }
  if (nd > 0) {
    // dependent positions: converged Newton in double, then one Newton step in S,
    // which carries the exact derivative (implicit function theorem) since phi ~ 0
    Eigen::VectorXd zv(n);
    for (int k = 0; k < n; ++k) zv[k] = ad_value(x[k]);
    Eigen::VectorXd dd = solve_dependent(zv);
    if (!m.motions.empty()) {
      // motion inputs on the loops' coordinates: Newton again from there with them at their values
      Eigen::VectorXd dqv = Eigen::VectorXd::Zero(m.nv);
      for (int i = 0; i < m.nv; ++i) dqv[i] = ad_value(dq[i]);
      for (int k = 0; k < nd; ++k) dqv[dep[k]] = dd[k];
      Data dv(m);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv);
      for (int it = 0; it < 50; ++it) {
        constraint_terms<double>(m, dv, integrate<double>(m, q_ref_, dqv), zero);
        Eigen::VectorXd ph(nd);
        Eigen::MatrixXd Jdd(nd, nd);
        for (int k = 0; k < nd; ++k) {
          ph[k] = dv.phi[rows_[k]];
          for (int c = 0; c < nd; ++c) Jdd(k, c) = dv.Jc(rows_[k], dep[c]);
        }
        if (ph.lpNorm<Eigen::Infinity>() < 1e-14) break;
        const Eigen::VectorXd st = Jdd.partialPivLu().solve(ph);
        for (int k = 0; k < nd; ++k) dqv[dep[k]] -= st[k];
      }
      for (int k = 0; k < nd; ++k) dd[k] = dqv[dep[k]];
    }
    for (int k = 0; k < nd; ++k) dq[dep[k]] = S(dd[k]);
    constraint_terms<S>(m, d, integrate<S>(m, q_ref_.cast<S>(), dq), zero_v);
    MatXT<S> Ja(nd, m.nv);
    VecXT<S> phi(nd);
    for (int k = 0; k < nd; ++k) {
      Ja.row(k) = d.Jc.row(rows_[k]);
      phi[k] = d.phi[rows_[k]];
    }
    MatXT<double> Jd_value(nd, nd);
    for (int r = 0; r < nd; ++r)
      for (int c = 0; c < nd; ++c) Jd_value(r, c) = ad_value(Ja(r, dep[c]));
    // The step carries the exact derivative only with d phi / d(dq_dep) itself. Jc is that where
    // the dependent coordinates add (revolute, prismatic) or at dq = 0; a ball's or free joint's
    // tangent coordinates away from the reference turn with their rotation: differentiate there
    if (tangent_dependent(m, dep)) {
      Eigen::VectorXd dqv(m.nv);
      for (int i = 0; i < m.nv; ++i) dqv[i] = ad_value(dq[i]);
      if (dqv.cwiseAbs().maxCoeff() > 0) Jd_value = phi_by_dependent(m, q_ref_, dqv, rows_, dep);
    }
    const VecXT<S> step = lu_solve<S>(Jd_value.cast<S>(), MatXT<S>(phi)).col(0);
    for (int k = 0; k < nd; ++k) dq[dep[k]] -= step[k];
  }
  const int nvd = static_cast<int>(vdep_.size());
  if (nvd > 0) {
    // dependent velocities from Jc v = 0 (the holonomic rows, and rolling's no-slip rows for the
    // rates they fix)
    constraint_terms<S>(m, d, integrate<S>(m, q_ref_.cast<S>(), dq), zero_v);
    MatXT<S> Ja(nvd, m.nv);
    for (int k = 0; k < nvd; ++k) Ja.row(k) = d.Jc.row(vrows_[k]);
    const MatXT<S> Jd = columns_t<S>(Ja, vdep_), Jz = columns_t<S>(Ja, rates_);
    VecXT<S> w(nw_);
    for (int k = 0; k < nw_; ++k) w[k] = x[n + k];
    VecXT<S> Jw = Jz * w;
    // the motion inputs' rates on the loops' driven columns: Jd v_dep = -Jz w - J_driven u'
    for (int k : m.motions) {
      const int i = m.actuators[static_cast<std::size_t>(k)].iv;
      for (int r = 0; r < nvd; ++r) {
        const S p = Ja(r, i) * v[i];
        Jw[r] = Jw[r] + p;
      }
    }
    const VecXT<S> vd = -lu_solve<S>(Jd, MatXT<S>(Jw)).col(0);
    for (int k = 0; k < nvd; ++k) v[vdep_[k]] = vd[k];
  }
  const VecXT<S> q = integrate<S>(m, q_ref_.cast<S>(), dq);
  VecXT<S> u_all = u_all_.cast<S>();
  for (int k = 0; k < nu(); ++k) u_all[m.plant_inputs[k]] = u[k];
  if (ns() > 0) d.s = x.tail(ns());  // the effect states: applied_forces reads them, writes their rates
  VecXT<S> qdd = forward_dynamics<S>(m, d, q, v, u_all);
  VecXT<S> rate;
  if (motion_) {
    // the rates in the frame that moves with the motion (steady_motion.hpp)
    VecXT<S> v_ref;
    motion_reference_velocity<S>(m, *motion_, q, v_ref);
    rate = tangent_rate<S>(m, dq, VecXT<S>(v - v_ref));
    motion_acceleration_terms<S>(m, *motion_, v, qdd);
  } else {
    rate = tangent_rate<S>(m, dq, v);
  }
  xdot.resize(n + nw_ + ns());
  for (int k = 0; k < n; ++k) xdot[k] = rate[ind[k]];
  for (int k = 0; k < nw_; ++k) xdot[n + k] = qdd[rates_[k]];
  for (int k = 0; k < ns(); ++k) xdot[n + nw_ + k] = d.sdot[k];
  forward_kinematics<S>(m, d, q, v);
  y = sensor_outputs<S>(m, d, m.plant_outputs, q, v);
}

PlantFunction::Workspace::Workspace() = default;
PlantFunction::Workspace::Workspace(const Workspace&) {}
PlantFunction::Workspace& PlantFunction::Workspace::operator=(const Workspace&) {
  td.reset();
  data.reset();
  return *this;
}
PlantFunction::Workspace::~Workspace() = default;

void PlantFunction::take_workspace(PlantFunction& other) {
  if (&other == this || &other.model_ != &model_) return;
  // only what depends on the model alone; the sizes that depend on the partition are made here
  if (other.ws_.data) ws_.data = std::move(other.ws_.data);
  if (other.ws_.td) {
    ws_.td = std::move(other.ws_.td);
    ws_.v.resize(model_.nv);
    ws_.u_all.resize(model_.nu());
  }
}

void PlantFunction::set_motion(const SteadyMotion& motion) { motion_ = std::make_shared<const SteadyMotion>(motion); }

bool PlantFunction::analytic_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::MatrixXd& J) const {
  if (motion_ || ns() > 0) return false;  // effect states: automatic differentiation of eval
  const Model& m = model_;
  if (m.nc != 0 || !m.motions.empty()) return closed_loop_jacobian(x, u, J);
  if (!part_.dependent.empty()) return false;
  const int n = nz(), nu_p = nu(), ny_p = ny();
  for (int k = 0; k < n; ++k)
    if (x[k] != 0.0 || part_.independent[k] != k) return false;
  if (!ws_.td) {
    ws_.td = std::make_unique<TreeDerivatives>(m);
    ws_.v.resize(m.nv);
    ws_.u_all.resize(m.nu());
  }
  TreeDerivatives& td = *ws_.td;
  ws_.v = x.tail(n);
  ws_.u_all = u_all_;
  for (int k = 0; k < nu_p; ++k) ws_.u_all[m.plant_inputs[k]] = u[k];
  td.feedthrough_read = true;  // D from dy_du below (acceleration sensors)
  td.compute(q_ref_, ws_.v, ws_.u_all, m.plant_outputs);
  if (J.rows() != 2 * n + ny_p || J.cols() != 2 * n + nu_p) J.resize(2 * n + ny_p, 2 * n + nu_p);
  // column by column, each in one contiguous pass (Eigen's block assignments walk the short
  // columns of each block with an alignment prologue apiece: 3 of the 21 us on tree28):
  // [0 or the identity; the accelerations' derivatives; the outputs']
  for (int c = 0; c < 2 * n + nu_p; ++c) {
    double* col = J.col(c).data();
    std::fill(col, col + n, 0.0);
    const double *a, *y;
    if (c < n) {
      a = td.dqdd_dq.col(c).data();
      y = ny_p ? td.dy_dq.col(c).data() : nullptr;
    } else if (c < 2 * n) {
      col[c - n] = 1.0;  // d/dt of the position deviation: the velocity
      a = td.dqdd_dv.col(c - n).data();
      y = ny_p ? td.dy_dv.col(c - n).data() : nullptr;
    } else {
      a = td.dqdd_du.col(m.plant_inputs[c - 2 * n]).data();
      y = ny_p ? td.dy_du.col(m.plant_inputs[c - 2 * n]).data() : nullptr;
    }
    std::copy(a, a + n, col + n);
    if (ny_p) std::copy(y, y + ny_p, col + 2 * n);
  }
  // the velocity turned by the tangent map of rotations
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (j.type != JointType::Spherical && j.type != JointType::Free) continue;
    const Eigen::Vector3d w = ws_.v.segment<3>(j.idx_v);
    J.block<3, 3>(j.idx_v, j.idx_v) = -0.5 * skew<double>(w);
    if (j.type == JointType::Free)
      J.block<3, 3>(j.idx_v + 3, j.idx_v) = -skew<double>(Eigen::Vector3d(ws_.v.segment<3>(j.idx_v + 3)));
  }
  return true;
}

void PlantFunction::loop_workspace() const {
  Workspace& W = ws_;
  if (W.data && W.G.rows() == model_.nv) return;
  const int n = nz(), nv = model_.nv, nd = static_cast<int>(part_.dependent.size());
  if (!W.data) W.data = std::make_unique<Data>(model_);
  W.v.resize(nv);
  W.u_all.resize(model_.nu());
  W.dq.setZero(nv);
  W.q.resize(model_.nq);
  W.rate.resize(nv);
  W.zero.setZero(nv);
  W.phi.resize(nd);
  W.step.resize(nd);
  W.vd.resize(nd);
  W.Ja.resize(nd, nv);
  W.Jd.resize(nd, nd);
  // columns: the independent coordinates, then the motion inputs' coordinates (closed_loop_jacobian)
  const int np = n + nm();
  W.Jz.resize(nd, np);
  W.G.resize(nv, np);
  W.H.resize(nv, np);
  W.P.resize(nd, np);
  W.DQ.resize(nv, np);
}

// Jd (the plant's rows, the dependent columns) of the constraint terms in the workspace's Data, factored
void PlantFunction::factor_dependent() const {
  const int nd = static_cast<int>(part_.dependent.size());
  const Data& d = *ws_.data;
  for (int c = 0; c < nd; ++c)
    for (int k = 0; k < nd; ++k) ws_.Jd(k, c) = d.Jc(rows_[k], part_.dependent[c]);
  ws_.lu.compute(ws_.Jd);
}

void PlantFunction::newton_dependent(const Eigen::Ref<const Eigen::VectorXd>& z) const {
  loop_workspace();
  Workspace& W = ws_;
  W.dq.setZero();
  for (int k = 0; k < nz(); ++k) W.dq[part_.independent[k]] = z[k];
  newton_from_workspace();
}

void PlantFunction::newton_from_workspace() const {
  const Model& m = model_;
  const int nd = static_cast<int>(part_.dependent.size());
  Workspace& W = ws_;
  Data& d = *W.data;
  integrate_into<double>(m, q_ref_, W.dq, W.q);
  if (nd == 0) return;
  for (int it = 0;; ++it) {
    constraint_terms<double>(m, d, W.q, W.zero);
    for (int k = 0; k < nd; ++k) W.phi[k] = d.phi[rows_[k]];
    if (W.phi.lpNorm<Eigen::Infinity>() < 1e-14 || it == 50) break;
    factor_dependent();
    W.step.noalias() = W.lu.solve(W.phi);
    for (int k = 0; k < nd; ++k) W.dq[part_.dependent[k]] -= W.step[k];
    integrate_into<double>(m, q_ref_, W.dq, W.q);
  }
}

void PlantFunction::eval_closed(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot,
                                Eigen::VectorXd& y) const {
  const Model& m = model_;
  const int n = nz(), nd = static_cast<int>(part_.dependent.size());
  const auto& ind = part_.independent;
  const auto& dep = part_.dependent;
  Workspace& W = ws_;
  newton_dependent(x.head(n));  // W.dq, W.q, and the constraint terms at W.q in d
  Data& d = *W.data;
  W.v.setZero();
  for (int k = 0; k < n; ++k) W.v[ind[k]] = x[n + k];
  if (nd > 0) {
    // dependent velocities from Jc v = 0 on the plant's rows
    factor_dependent();
    for (int k = 0; k < nd; ++k) {
      double s = 0.0;
      for (int c = 0; c < n; ++c) s += d.Jc(rows_[k], ind[c]) * x[n + c];
      W.phi[k] = -s;
    }
    W.vd.noalias() = W.lu.solve(W.phi);
    for (int k = 0; k < nd; ++k) W.v[dep[k]] = W.vd[k];
  }
  W.u_all = u_all_;
  for (int k = 0; k < nu(); ++k) W.u_all[m.plant_inputs[k]] = u[k];
  const Eigen::VectorXd& qdd = forward_dynamics<double>(m, d, W.q, W.v, W.u_all);
  tangent_rate_into<double>(m, W.dq, W.v, W.rate);
  if (xdot.size() != 2 * n) xdot.resize(2 * n);
  for (int k = 0; k < n; ++k) {
    xdot[k] = W.rate[ind[k]];
    xdot[n + k] = qdd[ind[k]];
  }
  // forward_dynamics left the kinematics of (q, v) in d
  if (y.size() != ny()) y.resize(ny());
  for (int k = 0; k < ny(); ++k) y[k] = sensor_value<double>(m, d, m.sensors[m.plant_outputs[k]], W.q, W.v);
}

void PlantFunction::eval_driven(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& xdot,
                                Eigen::VectorXd& y) const {
  const Model& m = model_;
  const int n = nz(), nw_ = nw(), nu_p = nu(), nmi = nm();
  if (u.size() != nu_p && !(nmi > 0 && u.size() == nu_p + 2 * nmi))
    throw std::invalid_argument("plant function: expected " + std::to_string(nu_p) + " or " +
                                std::to_string(nu_p + 2 * nmi) + " inputs");
  loop_workspace();
  Workspace& W = ws_;
  Data& d = *W.data;
  W.dq.setZero();
  W.v.setZero();
  for (int k = 0; k < n; ++k) W.dq[part_.independent[static_cast<std::size_t>(k)]] = x[k];
  for (int k = 0; k < nw_; ++k) W.v[rates_[static_cast<std::size_t>(k)]] = x[n + k];
  // motion inputs: their coordinates at u (a Plant/In's value, or the nominal), u', u''
  for (std::size_t i = 0; i < m.motions.size(); ++i) {
    const ActuatorModel& a = m.actuators[static_cast<std::size_t>(m.motions[i])];
    double value = 0, rate = 0, acc = 0;
    motion_of<double>(m, motion_inputs_, u_all_, i, u, value, rate, acc);
    W.dq[a.iv] = value - q_ref_[a.iq];
    W.v[a.iv] = rate;
    d.motion_acc[static_cast<Eigen::Index>(i)] = acc;
  }
  // the dependent positions, with the motions' coordinates where they are
  newton_from_workspace();
  const int nvd = static_cast<int>(vdep_.size());
  if (nvd > 0) {
    // the dependent velocities from Jc v = 0 on the velocity rows (the holonomic ones, then rolling's
    // no-slip rows for the rates they fix): Jd v_dep = -(Jc over the rates) w - (Jc over the motions) u'
    constraint_terms<double>(m, d, W.q, W.zero);
    if (W.ev_J.rows() != nvd) {
      W.ev_J.resize(nvd, nvd);
      W.ev_r.resize(nvd);
      W.ev_s.resize(nvd);
    }
    for (int r = 0; r < nvd; ++r) {
      const int row = vrows_[static_cast<std::size_t>(r)];
      for (int c = 0; c < nvd; ++c) W.ev_J(r, c) = d.Jc(row, vdep_[static_cast<std::size_t>(c)]);
      double s = 0.0;
      for (int c = 0; c < nw_; ++c) s += d.Jc(row, rates_[static_cast<std::size_t>(c)]) * x[n + c];
      for (int k : m.motions) {
        const int i = m.actuators[static_cast<std::size_t>(k)].iv;
        s += d.Jc(row, i) * W.v[i];
      }
      W.ev_r[r] = -s;
    }
    W.ev_lu.compute(W.ev_J);
    W.ev_s.noalias() = W.ev_lu.solve(W.ev_r);
    for (int k = 0; k < nvd; ++k) W.v[vdep_[static_cast<std::size_t>(k)]] = W.ev_s[k];
  }
  W.u_all = u_all_;
  for (int k = 0; k < nu_p; ++k) W.u_all[m.plant_inputs[static_cast<std::size_t>(k)]] = u[k];
  const Eigen::VectorXd& qdd = forward_dynamics<double>(m, d, W.q, W.v, W.u_all);
  tangent_rate_into<double>(m, W.dq, W.v, W.rate);
  if (xdot.size() != n + nw_) xdot.resize(n + nw_);
  for (int k = 0; k < n; ++k) xdot[k] = W.rate[part_.independent[static_cast<std::size_t>(k)]];
  for (int k = 0; k < nw_; ++k) xdot[n + k] = qdd[rates_[static_cast<std::size_t>(k)]];
  // the sensors as eval<ADScalar> reads them: the kinematics of (q, v) again
  forward_kinematics<double>(m, d, W.q, W.v);
  if (y.size() != ny()) y.resize(ny());
  for (int k = 0; k < ny(); ++k) y[k] = sensor_value<double>(m, d, m.sensors[m.plant_outputs[k]], W.q, W.v);
}

bool PlantFunction::closed_loop_jacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                         Eigen::MatrixXd& J) const {
  const Model& m = model_;
  const int n = nz(), nu_p = nu(), ny_p = ny(), nd = static_cast<int>(part_.dependent.size());
  // motion inputs (Plant/In): their coordinates' values are inputs like the independent positions,
  // their rates like the velocities; with u = [u; u'; u''] the Jacobian has their rate and
  // acceleration columns too. A motion outside Plant/In stays at its nominal value, at rest.
  const int nmi = nm(), np = n + nmi;
  const bool rates = !m.motions.empty() && u.size() == nu_p + 2 * nmi && nmi > 0;
  if (u.size() != nu_p && !rates) return false;
  for (int k = 0; k < n; ++k)
    if (x[k] != 0.0) return false;
  // a motion's reaction as an output reads the accelerations: automatic differentiation
  for (int k : m.plant_outputs)
    if (m.sensors[static_cast<std::size_t>(k)].type == SensorType::MotionForce) return false;
  // differentiated where the motions' coordinates are the reference configuration's
  for (int k : m.motions) {
    double value = u_all_[k];
    for (int j = 0; j < nmi; ++j)
      if (m.plant_inputs[motion_inputs_[j]] == k) value = u[motion_inputs_[j]];
    if (value != q_ref_[m.actuators[static_cast<std::size_t>(k)].iq]) return false;
  }
  const auto& ind = part_.independent;
  const auto& dep = part_.dependent;
  // the velocity index of column c of [z, motion inputs]
  auto column = [&](int c) {
    return c < n ? ind[c] : m.actuators[static_cast<std::size_t>(m.plant_inputs[motion_inputs_[c - n]])].iv;
  };
  Workspace& W = ws_;
  loop_workspace();
  if (!W.td) W.td = std::make_unique<TreeDerivatives>(m);
  Data& d = *W.data;
  TreeDerivatives& td = *W.td;
  // the velocity map G at q_ref: v = G [w; u'], Jd v_dep = -Jz [w; u']
  W.G.setZero();
  for (int c = 0; c < np; ++c) W.G(column(c), c) = 1.0;
  if (nd > 0) {  // (Eigen's LU must not see an empty matrix)
    constraint_terms<double>(m, d, q_ref_, W.zero);
    for (int k = 0; k < nd; ++k)
      for (int c = 0; c < np; ++c) W.Jz(k, c) = d.Jc(rows_[k], column(c));
    factor_dependent();
    W.P.noalias() = W.lu.solve(W.Jz);
    for (int k = 0; k < nd; ++k) W.G.row(dep[k]) = -W.P.row(k);
  }
  // G maps [z; u] to the coordinates' deviations and [w; u'] to the velocities. With rolling the
  // velocities have their own map Gv on [w; u'] (the rates of rates_ and the motions', the others
  // from all the velocity rows: holonomic and no-slip)
  const bool rolling = !part_.rate_dependent.empty();
  const int nw_ = nw(), npw = nw_ + nmi, nvd = static_cast<int>(vdep_.size());
  auto wcolumn = [&](int c) {
    return c < nw_ ? rates_[static_cast<std::size_t>(c)]
                   : m.actuators[static_cast<std::size_t>(m.plant_inputs[motion_inputs_[c - nw_]])].iv;
  };
  if (rolling) {
    if (W.Gv.rows() != m.nv || W.Gv.cols() != npw) {
      W.Gv.resize(m.nv, npw);
      W.Jvd.resize(nvd, nvd);
      W.Jzv.resize(nvd, npw);
      W.Pv.resize(nvd, npw);
      W.Jav.resize(nvd, m.nv);
      W.Ph.resize(nvd, np);
      W.Phx.resize(nvd, np);
      W.DQv.resize(m.nv, npw);
    }
    constraint_terms<double>(m, d, q_ref_, W.zero);
    W.Gv.setZero();
    for (int c = 0; c < npw; ++c) W.Gv(wcolumn(c), c) = 1.0;
    for (int k = 0; k < nvd; ++k) {
      for (int c = 0; c < nvd; ++c) W.Jvd(k, c) = d.Jc(vrows_[k], vdep_[c]);
      for (int c = 0; c < npw; ++c) W.Jzv(k, c) = d.Jc(vrows_[k], wcolumn(c));
    }
    W.luv.compute(W.Jvd);
    W.Pv.noalias() = W.luv.solve(W.Jzv);
    for (int k = 0; k < nvd; ++k) W.Gv.row(vdep_[k]) = -W.Pv.row(k);
  }
  const Eigen::MatrixXd& Gv = rolling ? W.Gv : W.G;
  W.v.noalias() = Gv.leftCols(nw_) * x.tail(nw_);
  if (rates)
    for (int j = 0; j < nmi; ++j) W.v += Gv.col(nw_ + j) * u[nu_p + j];
  W.u_all = u_all_;
  for (int k = 0; k < nu_p; ++k) W.u_all[m.plant_inputs[k]] = u[k];
  for (std::size_t i = 0; i < m.motions.size(); ++i) {
    double acc = 0.0;
    if (rates)
      for (int j = 0; j < nmi; ++j)
        if (m.plant_inputs[motion_inputs_[j]] == m.motions[i]) acc = u[nu_p + nmi + j];
    d.motion_acc[static_cast<Eigen::Index>(i)] = acc;
  }
  // the constrained accelerations and multipliers, then their derivatives
  forward_dynamics<double>(m, d, q_ref_, W.v, W.u_all);
  td.feedthrough_read = true;  // D from dy_du and dy_dacc below (acceleration sensors)
  td.compute_constrained(q_ref_, W.v, W.u_all, d.qdd, d.lambda, d.loop.rows, m.plant_outputs);
  // H = dv/d[z, u] at fixed [w, u']: Jd dv_dep = -(d(Jc v)/dq) G on the plant's rows (with rolling:
  // on the velocity rows, for the velocities' dependent columns)
  W.H.setZero();
  if (rolling) {
    for (int k = 0; k < nvd; ++k) W.Jav.row(k) = td.dphid_dq.row(vrows_[k]);
    W.Ph.noalias() = W.Jav * W.G;
    W.Phx.noalias() = W.luv.solve(W.Ph);
    for (int k = 0; k < nvd; ++k) W.H.row(vdep_[k]) = -W.Phx.row(k);
  } else if (nd > 0) {
    for (int k = 0; k < nd; ++k) W.Ja.row(k) = td.dphid_dq.row(rows_[k]);
    W.Jz.noalias() = W.Ja * W.G;
    W.P.noalias() = W.lu.solve(W.Jz);
    for (int k = 0; k < nd; ++k) W.H.row(dep[k]) = -W.P.row(k);
  }
  const int nxr = n + nw_;  // the state's size (2 n without rolling)
  const int ncols = nxr + nu_p + (rates ? 2 * nmi : 0);
  if (J.rows() != nxr + ny_p || J.cols() != ncols) J.resize(nxr + ny_p, ncols);
  J.setZero();
  // the column of motion input j's value, rate and acceleration
  auto value_col = [&](int j) { return nxr + motion_inputs_[j]; };
  auto rate_col = [&](int j) { return nxr + nu_p + j; };
  auto acc_col = [&](int j) { return nxr + nu_p + nmi + j; };
  // position rows: d(rate)/d(dq) G + H (d(rate)/dv = I at dq = 0), and d/dw = Gv (I on the
  // independent rows without rolling)
  W.DQ = W.H;
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (j.type != JointType::Spherical && j.type != JointType::Free) continue;
    const Eigen::Matrix3d wx = skew<double>(Eigen::Vector3d(W.v.segment<3>(j.idx_v)));
    W.DQ.middleRows<3>(j.idx_v).noalias() -= 0.5 * wx * W.G.middleRows<3>(j.idx_v);
    if (j.type == JointType::Free)
      W.DQ.middleRows<3>(j.idx_v + 3).noalias() -=
          skew<double>(Eigen::Vector3d(W.v.segment<3>(j.idx_v + 3))) * W.G.middleRows<3>(j.idx_v);
  }
  for (int k = 0; k < n; ++k) {
    J.row(k).head(n) = W.DQ.row(ind[k]).head(n);
    if (rolling) {
      J.row(k).segment(n, nw_) = W.Gv.row(ind[k]).head(nw_);
      if (rates)
        for (int j = 0; j < nmi; ++j) J(k, rate_col(j)) = W.Gv(ind[k], nw_ + j);
    } else {
      J(k, n + k) = 1.0;
    }
    for (int j = 0; j < nmi; ++j) J(k, value_col(j)) = W.DQ(ind[k], n + j);
  }
  // accelerations of the state's rates: dqdd/dz = dqdd_dq G + dqdd_dv H, dqdd/dw = dqdd_dv Gv
  for (int k = 0; k < nu_p; ++k)
    for (int r = 0; r < nw_; ++r) J(n + r, nxr + k) = td.dqdd_du(rates_[r], m.plant_inputs[k]);
  W.DQ.noalias() = td.dqdd_dq * W.G;
  W.DQ.noalias() += td.dqdd_dv * W.H;
  for (int k = 0; k < nw_; ++k) {
    J.row(n + k).head(n) = W.DQ.row(rates_[k]).head(n);
    for (int j = 0; j < nmi; ++j) J(n + k, value_col(j)) = W.DQ(rates_[k], n + j);
  }
  Eigen::MatrixXd& DW = rolling ? W.DQv : W.DQ;
  DW.noalias() = td.dqdd_dv * Gv;
  for (int k = 0; k < nw_; ++k) {
    J.row(n + k).segment(n, nw_) = DW.row(rates_[k]).head(nw_);
    if (rates)
      for (int j = 0; j < nmi; ++j) J(n + k, rate_col(j)) = DW(rates_[k], nw_ + j);
  }
  if (rates)
    for (std::size_t i = 0; i < m.motions.size(); ++i)
      for (int j = 0; j < nmi; ++j)
        if (m.plant_inputs[motion_inputs_[j]] == m.motions[i])
          for (int k = 0; k < nw_; ++k) J(n + k, acc_col(j)) = td.dqdd_dacc(rates_[k], static_cast<Eigen::Index>(i));
  // sensors
  if (ny_p > 0) {
    J.block(nxr, 0, ny_p, n).noalias() = td.dy_dq * W.G.leftCols(n);
    J.block(nxr, 0, ny_p, n).noalias() += td.dy_dv * W.H.leftCols(n);
    J.block(nxr, n, ny_p, nw_).noalias() = td.dy_dv * Gv.leftCols(nw_);
    for (int j = 0; j < nmi; ++j) {
      J.block(nxr, value_col(j), ny_p, 1).noalias() = td.dy_dq * W.G.col(n + j);
      J.block(nxr, value_col(j), ny_p, 1).noalias() += td.dy_dv * W.H.col(n + j);
      if (rates) J.block(nxr, rate_col(j), ny_p, 1).noalias() = td.dy_dv * Gv.col(nw_ + j);
    }
    // the accelerations' direct dependence on the inputs (acceleration sensors; zero otherwise): a
    // force input's column, a motion's acceleration column (its value and rate came through q, v)
    for (int k = 0; k < nu_p; ++k)
      if (m.actuators[static_cast<std::size_t>(m.plant_inputs[k])].type != ActuatorType::Motion)
        J.block(nxr, nxr + k, ny_p, 1) = td.dy_du.col(m.plant_inputs[k]);
    if (rates)
      for (std::size_t i = 0; i < m.motions.size(); ++i)
        for (int j = 0; j < nmi; ++j)
          if (m.plant_inputs[motion_inputs_[j]] == m.motions[i])
            J.block(nxr, acc_col(j), ny_p, 1) = td.dy_dacc.col(static_cast<Eigen::Index>(i));
  }
  return true;
}

void PlantFunction::state_to_qv(const Eigen::VectorXd& x, Eigen::VectorXd& q, Eigen::VectorXd& v) const {
  Eigen::VectorXd xd, y;
  const int n = nz();
  Eigen::VectorXd dq = Eigen::VectorXd::Zero(model_.nv);
  for (int k = 0; k < n; ++k) dq[part_.independent[k]] = x[k];
  if (!part_.dependent.empty()) {
    const Eigen::VectorXd dd = solve_dependent(x.head(n));
    for (std::size_t k = 0; k < part_.dependent.size(); ++k) dq[part_.dependent[k]] = dd[k];
  }
  q = integrate<double>(model_, q_ref_, dq);
  v = Eigen::VectorXd::Zero(model_.nv);
  for (int k = 0; k < nw(); ++k) v[rates_[static_cast<std::size_t>(k)]] = x[n + k];
  if (!vdep_.empty()) {
    const Eigen::MatrixXd J = active_jacobian(model_, q, vrows_);
    const Eigen::VectorXd vd = -columns(J, vdep_).partialPivLu().solve(columns(J, rates_) * x.segment(n, nw()));
    for (std::size_t k = 0; k < vdep_.size(); ++k) v[vdep_[k]] = vd[static_cast<Eigen::Index>(k)];
  }
}

Eigen::VectorXd PlantFunction::qv_to_state(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
  if (ns() == 0) return qv_to_state(q, v, Eigen::VectorXd());
  Data d(model_);
  return qv_to_state(q, v, effect_states_steady(model_, d, q, v));
}

Eigen::VectorXd PlantFunction::qv_to_state(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                           const Eigen::VectorXd& s) const {
  if (s.size() != ns()) throw std::invalid_argument("plant function: expected " + std::to_string(ns()) + " effect states");
  const Eigen::VectorXd dq = difference(model_, q_ref_, q);
  const int n = nz();
  Eigen::VectorXd x(nx());
  for (int k = 0; k < n; ++k) x[k] = dq[part_.independent[k]];
  for (int k = 0; k < nw(); ++k) x[n + k] = v[rates_[static_cast<std::size_t>(k)]];
  x.tail(ns()) = s;
  return x;
}

namespace {
// joint of velocity index i, and the coordinate's place in it
const JointModel& joint_of(const Model& m, int i, int& k) {
  for (int b = 1; b < m.nbodies; ++b) {
    const JointModel& j = m.joints[b];
    if (i >= j.idx_v && i < j.idx_v + j.nv) {
      k = i - j.idx_v;
      return j;
    }
  }
  throw std::logic_error("velocity index out of range");
}
}  // namespace

std::vector<std::string> plant_state_names(const Model& model, const std::vector<int>& independent,
                                           const std::vector<int>& rates) {
  // Model::v_names and rate_names: for a ball or free joint the position states are the
  // rotation vector (and displacement) of the deviation, in the joint's frame at the operating point
  std::vector<std::string> names;
  names.reserve(independent.size() + rates.size());
  for (int i : independent) names.push_back(model.v_names[static_cast<std::size_t>(i)]);
  for (int i : rates) names.push_back(model.rate_names[static_cast<std::size_t>(i)]);
  names.insert(names.end(), model.s_names.begin(), model.s_names.end());  // the effect states, last
  return names;
}

std::vector<std::string> plant_state_units(const Model& model, const std::vector<int>& independent,
                                           const std::vector<int>& rates) {
  std::vector<std::string> units;
  units.reserve(independent.size() + rates.size());
  for (int i : independent) units.push_back(model.v_units[static_cast<std::size_t>(i)]);
  for (int i : rates) units.push_back(rate_unit(model.v_units[static_cast<std::size_t>(i)]));
  units.insert(units.end(), model.s_units.begin(), model.s_units.end());
  return units;
}

std::vector<std::string> plant_state_names(const Model& model, const std::vector<int>& independent) {
  return plant_state_names(model, independent, independent);
}

std::vector<std::string> plant_state_units(const Model& model, const std::vector<int>& independent) {
  return plant_state_units(model, independent, independent);
}

std::vector<std::string> PlantFunction::state_names() const {
  return plant_state_names(model_, part_.independent, rates_);
}

std::vector<std::string> PlantFunction::state_units() const {
  return plant_state_units(model_, part_.independent, rates_);
}

Eigen::VectorXd PlantFunction::state_offset(const Eigen::VectorXd& v_ref) const {
  const int n = nz();
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(nx());
  for (int k = 0; k < n; ++k) {
    const int i = part_.independent[k];
    int c = 0;
    const JointModel& j = joint_of(model_, i, c);
    // additive coordinates carry their absolute value; rotation/translation tangents of
    // spherical and free joints are deviations from the reference pose (offset 0)
    if (j.type != JointType::Spherical && j.type != JointType::Free) x0[k] = q_ref_[j.idx_q + c];
  }
  for (int k = 0; k < nw(); ++k) x0[n + k] = v_ref[rates_[static_cast<std::size_t>(k)]];
  // the effect states are absolute in x: their offset is 0 (x0 holds their values at the reference)
  return x0;
}

template void PlantFunction::eval<double>(const VecXT<double>&, const VecXT<double>&, VecXT<double>&,
                                          VecXT<double>&) const;
template void PlantFunction::eval<ADScalar>(const VecXT<ADScalar>&, const VecXT<ADScalar>&, VecXT<ADScalar>&,
                                            VecXT<ADScalar>&) const;

}  // namespace codyna
