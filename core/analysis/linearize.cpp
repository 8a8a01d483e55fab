#include "analysis/linearize.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <initializer_list>
#include <memory>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "analysis/linearizer.hpp"
#include "dynamics/derivatives.hpp"
#include "dynamics/effects.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "model/errors.hpp"
#include "spatial/autodiff.hpp"

namespace codyna {

const char* to_string(JacobianMethod m) {
  switch (m) {
    case JacobianMethod::Exact: return "exact";
    case JacobianMethod::ForwardDifference: return "fd-forward";
    case JacobianMethod::CentralDifference: return "fd-central";
  }
  return "?";
}

namespace {
Eigen::VectorXd stacked(const PlantFunction& f, const Eigen::VectorXd& xu) {
  const int nx = f.nx();
  Eigen::VectorXd xd, y;
  f.eval<double>(xu.head(nx), xu.tail(xu.size() - nx), xd, y);
  Eigen::VectorXd r(xd.size() + y.size());
  r << xd, y;
  return r;
}
}  // namespace

Eigen::MatrixXd plant_jacobian_autodiff(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
  const int nx = f.nx(), nu = static_cast<int>(u.size()), ny = f.ny(), n = nx + nu;
  Eigen::MatrixXd J(nx + ny, n);
  const ADVec xa = ad_seed(x, n, 0), ua = ad_seed(u, n, nx);
  ADVec xd, y;
  f.eval<ADScalar>(xa, ua, xd, y);
  for (int r = 0; r < nx + ny; ++r) {
    const ADScalar& s = r < nx ? xd[r] : y[r - nx];
    J.row(r) = s.derivatives().size() ? Eigen::RowVectorXd(s.derivatives().transpose()) : Eigen::RowVectorXd::Zero(n);
  }
  return J;
}

Eigen::MatrixXd plant_jacobian(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                               JacobianMethod method) {
  Eigen::MatrixXd J(f.nx() + f.ny(), f.nx() + u.size());
  if (method == JacobianMethod::Exact) {
    if (f.analytic_jacobian(x, u, J)) return J;
    return plant_jacobian_autodiff(f, x, u);
  }
  const bool central = method == JacobianMethod::CentralDifference;
  if (f.fd_jacobian(x, u, central, J)) return J;
  return plant_jacobian_fd_full(f, x, u, central);
}

Eigen::MatrixXd plant_jacobian_fd_full(const PlantFunction& f, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                       bool central) {
  const int nx = f.nx(), nu = static_cast<int>(u.size()), ny = f.ny(), n = nx + nu;
  Eigen::VectorXd xu(n);
  xu << x, u;
  Eigen::MatrixXd J(nx + ny, n);
  const Eigen::VectorXd f0 = central ? Eigen::VectorXd() : stacked(f, xu);
  for (int k = 0; k < n; ++k) {
    const double h = fd_step(central, xu[k]);
    Eigen::VectorXd xp = xu;
    xp[k] += h;
    if (central) {
      Eigen::VectorXd xm = xu;
      xm[k] -= h;
      J.col(k) = (stacked(f, xp) - stacked(f, xm)) / (2 * h);
    } else {
      J.col(k) = (stacked(f, xp) - f0) / h;
    }
  }
  return J;
}

namespace {

// A spring-damper whose two points coincide has no direction there: its damping force
// c (n . v) n and, with a rest length, its elastic force k (0 - L0) n have no limit, and so no
// derivative (exact and finite differences would each report their own number). Refused with
// the element and the way out; a rest length 0 spring without damping is smooth (k dp) and fine.
void refuse_coincident_spring_dampers(const Model& model, const Eigen::VectorXd& q, Data& d) {
  if (model.springs.empty()) return;
  forward_kinematics<double>(model, d, q);
  for (const SpringDamperModel& s : model.springs) {
    const double L = (point_position<double>(d, s.body_b, s.point_b) - point_position<double>(d, s.body_a, s.point_a)).norm();
    if (L > 1e-12 || (s.damping == 0.0 && s.rest_length == 0.0)) continue;
    std::string path = "/effects";
    for (std::size_t k = 0; k < model.spec.effects.size(); ++k)
      if (model.spec.effects[k].name == s.name) path += "/" + std::to_string(k);
    throw ModelError(model.source_file, path,
                     "spring_damper \"" + s.name + "\": its two points coincide at the operating point (length " +
                         std::to_string(L) + " m), where its " +
                         (s.damping != 0.0 ? std::string("damping force c (n . v) n") : std::string("force k (0 - rest_length) n")) +
                         " has no direction and no derivative; offset the points, or use rest_length 0 without damping "
                         "(then the force k (x_b - x_a) is smooth), or linearize elsewhere");
  }
}

void refuse_coincident_spring_dampers(const Model& model, const Eigen::VectorXd& q) {
  if (model.springs.empty()) return;
  Data d(model);
  refuse_coincident_spring_dampers(model, q, d);
}

}  // namespace

namespace {

// the largest |entry|, 0 for an empty matrix (Eigen's maxCoeff of an empty one is undefined: a model
// without degrees of freedom, or with no Plant/Out, has empty blocks)
double max_abs(const Eigen::MatrixXd& M) { return M.size() ? M.cwiseAbs().maxCoeff() : 0.0; }

// The realization of motion inputs. With their rates and accelerations the plant is
//   x' = A x + B0 u + B1 u' + B2 u'',   y = C x + D0 u + D1 u' + D2 u''
// (B1, B2 only in the velocity rows). The change of state  xi = x - B2 u' - F u,  F = A B2 + B1,
// removes the derivatives:  xi' = A xi + (B0 + A F) u,  y = C xi + (D0 + C F) u  + (C B2 + D1) u'
// + D2 u'': a proper model of the same transfer function exactly when C B2 + D1 = 0 and D2 = 0
// (an output that responds to an input's rate or acceleration has an improper transfer function:
// refused, naming it). xi equals x whenever the motion inputs are at their operating values.
void realize_motion_inputs(const Model& model, const PlantFunction& f, const Eigen::MatrixXd& J, LinearSystem& s,
                           Linearization& out) {
  const int nx = f.nx(), nu = f.nu(), ny = f.ny(), nm = f.nm();
  Eigen::MatrixXd B1 = Eigen::MatrixXd::Zero(nx, nu), B2 = B1, D1 = Eigen::MatrixXd::Zero(ny, nu), D2 = D1;
  for (int j = 0; j < nm; ++j) {
    const int c = f.motion_inputs()[static_cast<std::size_t>(j)];
    B1.col(c) = J.block(0, nx + nu + j, nx, 1);
    B2.col(c) = J.block(0, nx + nu + nm + j, nx, 1);
    D1.col(c) = J.block(nx, nx + nu + j, ny, 1);
    D2.col(c) = J.block(nx, nx + nu + nm + j, ny, 1);
  }
  const Eigen::MatrixXd F = s.A * B2 + B1;
  const Eigen::MatrixXd rate_gain = s.C * B2 + D1;
  const double scale = std::max({1.0, max_abs(s.C), max_abs(D1)}) * std::max(1.0, max_abs(B2));
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < nm; ++j) {
      const int c = f.motion_inputs()[static_cast<std::size_t>(j)];
      const std::string& yn = model.sensors[static_cast<std::size_t>(model.plant_outputs[i])].name;
      const std::string& un = model.actuators[static_cast<std::size_t>(model.plant_inputs[c])].name;
      if (std::abs(D2(i, c)) > 1e-12 * scale || std::abs(rate_gain(i, c)) > 1e-12 * scale)
        throw std::invalid_argument("linearize: the output \"" + yn + "\" responds to the " +
                                    (std::abs(D2(i, c)) > 1e-12 * scale ? "acceleration" : "rate") +
                                    " of the motion input \"" + un +
                                    "\": its transfer function from it is improper (no state-space model); choose "
                                    "outputs of positions the motion does not drive (docs/model-format.md, motion)");
    }
  s.B += s.A * F;
  s.D += s.C * F;
  out.motion_shift = F;
  out.motion_rate_shift = B2;
  s.state_shift = F;
  s.state_rate_shift = B2;
}

// The rows a motion input's realization shifts get a trailing '~' (after the names are set)
void name_shifted_states(LinearSystem& s) {
  for (int i = 0; i < s.nx() && i < static_cast<int>(s.state_names.size()); ++i)
    if (s.shifted(i)) s.state_names[static_cast<std::size_t>(i)] += "~";
}

}  // namespace

namespace {

// closed loops, motion inputs, finite differences, chosen independent coordinates: a plant
// function made for this operating point
// the largest distance from an eigenvalue of A to the nearest of B's not taken yet, relative to
// their largest modulus (the same spectrum: 0)
// (eigenvalues within 1e-4 of the largest modulus of 0 count as 0: a motion's cyclic coordinates
// make Jordan blocks at 0, whose computed eigenvalues scatter by eps^(1/k))
double spectrum_distance(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  if (A.rows() == 0 || A.rows() != B.rows()) return A.rows() == B.rows() ? 0.0 : 1.0;
  Eigen::VectorXcd a = A.eigenvalues(), b = B.eigenvalues();
  double scale = 1e-300, worst = 0;
  for (Eigen::Index i = 0; i < a.size(); ++i) scale = std::max({scale, std::abs(a[i]), std::abs(b[i])});
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (std::abs(a[i]) < 1e-4 * scale) a[i] = 0;
    if (std::abs(b[i]) < 1e-4 * scale) b[i] = 0;
  }
  std::vector<bool> taken(static_cast<std::size_t>(b.size()), false);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    Eigen::Index best = -1;
    for (Eigen::Index k = 0; k < b.size(); ++k)
      if (!taken[static_cast<std::size_t>(k)] && (best < 0 || std::abs(a[i] - b[k]) < std::abs(a[i] - b[best]))) best = k;
    taken[static_cast<std::size_t>(best)] = true;
    worst = std::max(worst, std::abs(a[i] - b[best]));
  }
  return worst / scale;
}

Linearization linearize_general(const Model& model, const OperatingPoint& op, const LinearizeOptions& options,
                                bool check_motion = true) {
  refuse_coincident_spring_dampers(model, op.q);
  Linearization out;
  out.partition = partition_coordinates(model, op.q, options.independent);
  PlantFunction f(model, op.q, op.u, out.partition);
  if (op.motion && op.motion->turns()) f.set_motion(*op.motion);
  out.about_motion = f.motion() != nullptr;
  const int nx = f.nx(), nu = f.nu(), ny = f.ny();
  // state at the operating point: zero deviation, independent velocities
  Eigen::VectorXd x = Eigen::VectorXd::Zero(nx);
  for (int k = 0; k < f.nw(); ++k) x[f.nz() + k] = op.v[f.rates()[static_cast<std::size_t>(k)]];
  if (f.ns() > 0) {
    // the effect states: the operating point's, or at rest at (q, v): a tire's deflections carry
    // the steady slips (the states of a steady motion; at any other point, the consistent start)
    if (op.s.size() == f.ns()) {
      x.tail(f.ns()) = op.s;
    } else {
      Data d(model);
      x.tail(f.ns()) = effect_states_steady(model, d, op.q, op.v);
    }
  }
  Eigen::VectorXd u(nu);
  for (int k = 0; k < nu; ++k) u[k] = op.u[model.plant_inputs[k]];

  // motion inputs enter with their rates and accelerations too: the Jacobian is taken over
  // [u; u'; u''] of the motion inputs (zero at the operating point)
  const int nm = f.nm();
  Eigen::VectorXd ue = Eigen::VectorXd::Zero(nu + 2 * nm);
  ue.head(nu) = u;
  const Eigen::MatrixXd J = plant_jacobian(f, x, ue, options.method);
  if (options.method != JacobianMethod::Exact) {
    const Eigen::MatrixXd Je = plant_jacobian(f, x, ue, JacobianMethod::Exact);
    const double scale = std::max(max_abs(Je), 1e-300);
    out.fd_error = max_abs(J - Je) / scale;
  }
  LinearSystem& s = out.system;
  s.A = J.topLeftCorner(nx, nx);
  s.B = J.block(0, nx, nx, nu);
  s.C = J.bottomLeftCorner(ny, nx);
  s.D = J.block(nx, nx, ny, nu);
  if (nm > 0) realize_motion_inputs(model, f, J, s, out);
  Eigen::VectorXd xd, y;
  f.eval<double>(x, u, xd, y);
  s.x0 = f.state_offset(op.v);
  s.x0.tail(f.ns()) = x.tail(f.ns());
  s.positions = f.nz();
  s.u0 = u;
  s.y0 = y;
  s.xdot0 = xd;
  if (out.about_motion) out.motion_residual = xd.size() ? xd.lpNorm<Eigen::Infinity>() : 0.0;
  s.state_names = f.state_names();
  s.state_units = f.state_units();
  name_shifted_states(s);
  for (int k : model.plant_inputs) {
    s.input_names.push_back(model.actuators[k].name);
    s.input_units.push_back(model.actuators[k].unit);
  }
  for (int k : model.plant_outputs) {
    s.output_names.push_back(model.sensors[k].name);
    s.output_units.push_back(model.sensors[k].unit);
  }
  s.model_name = model.name;
  s.model_file = model.source_file;
  s.operating_point = op.kind;
  s.method = to_string(options.method);
  s.time = op.t;
  s.codyna_version = CODYNA_VERSION;
  if (out.about_motion && check_motion) {
    // the same a while further along the motion: A's eigenvalues are the motion's only if they
    // do not change along it
    OperatingPoint later = op;
    advance_motion(model, *later.motion, motion_check_time(*later.motion), later.q, later.v);
    normalize(model, later.q);
    try {
      const Linearization there = linearize_general(model, later, options, false);
      // the states keep their axes along the motion when no body spins and no planar joint (whose
      // velocities are the world's) turns: then A itself is compared, else its eigenvalues
      bool same_axes = there.partition.independent == out.partition.independent &&
                       there.partition.rate_dependent == out.partition.rate_dependent;
      for (const JointMotion& jm : op.motion->joints)
        same_axes = same_axes && jm.spin_rate == 0.0 &&
                    !(model.joints[static_cast<std::size_t>(jm.body)].type == JointType::Planar && jm.yaw_rate != 0.0);
      if (same_axes && there.system.A.rows() == s.A.rows()) {
        const double scale = std::max(max_abs(s.A), 1e-300);
        out.motion_drift = max_abs(there.system.A - s.A) / scale;
      } else {
        out.motion_drift = spectrum_distance(s.A, there.system.A);
      }
    } catch (const std::exception&) {
      out.motion_drift = 1.0;  // nowhere to linearize there: not a motion to speak of
    }
  }
  return out;
}

}  // namespace

// The fast path (a tree without motion inputs, exact, automatic partition) computes what the
// general path computes: A, B, C, D with the same operations in the same order, so bit for bit
// (the plant function's analytic_jacobian at x = [0; v]: TreeDerivatives::compute at (q, v, u)),
// x0 as state_offset does; x0dot's accelerations and y0 are those TreeDerivatives computed on
// the way (CRBA and a Cholesky solve; the general path evaluates ABA), equal to round-off, which
// spares a forward-dynamics evaluation per point (a quarter of the Jacobian's cost at 7 DOF).
struct Linearizer::Impl {
  const Model* model;
  bool tree;  // no loop closures, no motion inputs: every coordinate independent, in order
  bool ready = false;
  bool busy = false;  // linearize(model, op)'s kept Impl is being used (see there)
  CoordinatePartition partition;
  std::vector<std::string> state_names, state_units, input_names, input_units, output_names, output_units;
  std::vector<int> offset_q;  // [nv] the q index that x0's position entry k carries; -1: a rotation/translation tangent (0)
  std::unique_ptr<TreeDerivatives> td;
  std::unique_ptr<Data> data;
  Eigen::VectorXd dq, rate;

  // Every field of the model that prepare() and the workspaces it binds (TreeDerivatives, its
  // Data and ModelConstants, the spring check's Data) read; whatever else a call needs is read
  // from the model at the call. What was prepared stays good while these are unchanged.
  struct Inputs {
    std::vector<int> ints;
    std::vector<double> nums;
    std::vector<std::string> names;

    // calls f.ints(int...), f.nums(const double*, n) and f.name(string) over those fields, in one order
    template <class F>
    static void visit(const Model& m, F& f) {
      f.ints({m.nq, m.nv, m.nbodies, m.nc, m.nu(), m.ny(), static_cast<int>(m.motions.size()),
              static_cast<int>(m.springs.size()), static_cast<int>(m.body_forces.size()),
              static_cast<int>(m.bushings.size()), static_cast<int>(m.tires.size()), static_cast<int>(m.plant_inputs.size()),
              static_cast<int>(m.plant_outputs.size())});
      for (int b = 0; b < m.nbodies; ++b) {
        const auto i = static_cast<std::size_t>(b);
        const JointModel& j = m.joints[i];
        f.ints({static_cast<int>(j.type), j.parent, m.parent[i], j.idx_q, j.idx_v, j.nq, j.nv});
        f.nums(j.X_PF.R.data(), 9);
        f.nums(j.X_PF.p.data(), 3);
        f.nums(j.X_CM.R.data(), 9);
        f.nums(j.X_CM.p.data(), 3);
        f.nums(j.axis.data(), 3);
        f.nums(j.axis2.data(), 3);
        f.nums(&m.mass[i], 1);
        f.nums(m.com[i].data(), 3);
        f.nums(m.inertia[i].data(), 36);
      }
      for (const ActuatorModel& a : m.actuators) f.ints({static_cast<int>(a.type), a.iv, a.iq});
      for (int k : m.motions) f.ints({k});
      for (int k : m.plant_inputs) {
        f.ints({k});
        f.name(m.actuators[static_cast<std::size_t>(k)].name);
        f.name(m.actuators[static_cast<std::size_t>(k)].unit);
      }
      for (int k : m.plant_outputs) {
        f.ints({k});
        f.name(m.sensors[static_cast<std::size_t>(k)].name);
        f.name(m.sensors[static_cast<std::size_t>(k)].unit);
      }
      for (const auto* v : {&m.v_names, &m.rate_names, &m.v_units})
        for (const std::string& n : *v) f.name(n);
    }
    void fill(const Model& m) {
      struct Writer {
        Inputs& in;
        std::size_t n = 0;
        void ints(std::initializer_list<int> k) { in.ints.insert(in.ints.end(), k); }
        void nums(const double* p, int n) { in.nums.insert(in.nums.end(), p, p + n); }
        void name(const std::string& s) { in.names.push_back(s); }
      } w{*this};
      ints.clear();
      nums.clear();
      names.clear();
      visit(m, w);
    }
    // the model's fields equal those filled (bit for bit; a NaN is unequal to itself: false)
    bool match(const Model& m) const {
      struct Reader {
        const Inputs& in;
        std::size_t ni = 0, nd = 0, ns = 0;
        bool same = true;
        void ints(std::initializer_list<int> k) {
          same = same && ni + k.size() <= in.ints.size() && std::equal(k.begin(), k.end(), in.ints.begin() + static_cast<std::ptrdiff_t>(ni));
          ni += k.size();
        }
        void nums(const double* p, int n) {
          same = same && nd + static_cast<std::size_t>(n) <= in.nums.size() &&
                 std::equal(p, p + n, in.nums.begin() + static_cast<std::ptrdiff_t>(nd));
          nd += static_cast<std::size_t>(n);
        }
        void name(const std::string& s) {
          same = same && ns < in.names.size() && in.names[ns] == s;
          ++ns;
        }
      } r{*this};
      visit(m, r);
      return r.same && r.ni == ints.size() && r.nd == nums.size() && r.ns == names.size();
    }
  } prepared_from;  // the model's, as prepare() last read them

  explicit Impl(const Model& m) { bind(m); }

  // another model, or this one perhaps changed: what prepare() derives is made again at the next
  // call, unless it is the model prepared last with every field prepare() reads unchanged (a NaN
  // compares unequal: made again)
  void bind(const Model& m) {
    if (ready && &m == model && prepared_from.match(m)) return;
    model = &m;
    tree = m.nc == 0 && m.motions.empty() && m.ns == 0;  // (effect states: the general path)
    ready = false;
  }

  // what depends on the model only, made at the first call after bind()
  void prepare(const OperatingPoint& op) {
    const Model& m = *model;
    ready = false;
    partition = partition_coordinates(m, op.q);  // a tree: every coordinate, in order
    state_names = plant_state_names(m, partition.independent);
    state_units = plant_state_units(m, partition.independent);
    for (auto* v : {&input_names, &input_units, &output_names, &output_units}) v->clear();
    for (int k : m.plant_inputs) {
      input_names.push_back(m.actuators[k].name);
      input_units.push_back(m.actuators[k].unit);
    }
    for (int k : m.plant_outputs) {
      output_names.push_back(m.sensors[k].name);
      output_units.push_back(m.sensors[k].unit);
    }
    offset_q.assign(static_cast<std::size_t>(m.nv), -1);
    for (int b = 1; b < m.nbodies; ++b) {
      const JointModel& j = m.joints[b];
      if (j.type == JointType::Spherical || j.type == JointType::Free) continue;
      for (int c = 0; c < j.nv; ++c) offset_q[static_cast<std::size_t>(j.idx_v + c)] = j.idx_q + c;
    }
    if (td)
      td->bind(m);
    else
      td = std::make_unique<TreeDerivatives>(m);
    td->feedthrough_read = true;  // D from dy_du below (acceleration sensors)
    if (m.springs.empty())
      data.reset();
    else if (data)  // for refuse_coincident_spring_dampers
      data->reset(m);
    else
      data = std::make_unique<Data>(m);
    dq.setZero(m.nv);
    rate.resize(m.nv);
    prepared_from.fill(m);
    ready = true;
  }

  void linearize_tree(const OperatingPoint& op, Linearization& out) {
    if (!ready) prepare(op);
    const Model& m = *model;
    if (data) refuse_coincident_spring_dampers(m, op.q, *data);
    const int n = m.nv, nu = static_cast<int>(m.plant_inputs.size()), ny = static_cast<int>(m.plant_outputs.size());
    if (op.q.size() != m.nq || op.v.size() != n || op.u.size() != m.nu())
      throw std::invalid_argument("linearize: the operating point has " + std::to_string(op.q.size()) + " positions, " +
                                  std::to_string(op.v.size()) + " velocities and " + std::to_string(op.u.size()) +
                                  " actuator values where the model has " + std::to_string(m.nq) + ", " +
                                  std::to_string(n) + " and " + std::to_string(m.nu()));
    LinearSystem& s = out.system;
    // the exact Jacobian (PlantFunction::analytic_jacobian)
    TreeDerivatives& d = *td;
    d.compute(op.q, op.v, op.u, m.plant_outputs);
    s.A.resize(2 * n, 2 * n);
    s.A.topLeftCorner(n, n).setZero();
    s.A.topRightCorner(n, n).setIdentity();
    for (int b = 1; b < m.nbodies; ++b) {
      const JointModel& j = m.joints[b];
      if (j.type != JointType::Spherical && j.type != JointType::Free) continue;
      const Eigen::Vector3d w = op.v.segment<3>(j.idx_v);
      s.A.block<3, 3>(j.idx_v, j.idx_v) = -0.5 * skew<double>(w);
      if (j.type == JointType::Free)
        s.A.block<3, 3>(j.idx_v + 3, j.idx_v) = -skew<double>(Eigen::Vector3d(op.v.segment<3>(j.idx_v + 3)));
    }
    s.A.block(n, 0, n, n) = d.dqdd_dq;
    s.A.block(n, n, n, n) = d.dqdd_dv;
    s.B.resize(2 * n, nu);
    s.B.topRows(n).setZero();
    for (int k = 0; k < nu; ++k) s.B.block(n, k, n, 1) = d.dqdd_du.col(m.plant_inputs[k]);
    s.C.resize(ny, 2 * n);
    s.C.leftCols(n) = d.dy_dq;
    s.C.rightCols(n) = d.dy_dv;
    s.D.resize(ny, nu);
    for (int k = 0; k < nu; ++k) s.D.col(k) = d.dy_du.col(m.plant_inputs[k]);  // zero but for acceleration sensors
    // x0dot and y0: the accelerations and sensor values the Jacobian was taken at (its
    // qdd, by CRBA and a Cholesky solve, agrees with ABA's to round-off), and the
    // positions' rate at a zero deviation
    tangent_rate_into<double>(m, dq, op.v, rate);
    s.xdot0.resize(2 * n);
    s.xdot0.head(n) = rate;
    s.xdot0.tail(n) = d.qdd;
    s.y0 = d.y;
    // x0 (PlantFunction::state_offset), u0
    s.x0.setZero(2 * n);
    for (int k = 0; k < n; ++k) {
      if (offset_q[static_cast<std::size_t>(k)] >= 0) s.x0[k] = op.q[offset_q[static_cast<std::size_t>(k)]];
      s.x0[n + k] = op.v[k];
    }
    s.u0.resize(nu);
    for (int k = 0; k < nu; ++k) s.u0[k] = op.u[m.plant_inputs[k]];
    s.Ts = 0.0;
    s.positions = n;
    // (written into the same Linearization point after point, they are already these: compared
    // first, which costs less than copying them again)
    for (auto [to, from] : {std::pair{&s.state_names, &state_names}, {&s.state_units, &state_units},
                            {&s.input_names, &input_names}, {&s.input_units, &input_units},
                            {&s.output_names, &output_names}, {&s.output_units, &output_units}})
      if (*to != *from) *to = *from;
    s.model_name = m.name;
    s.model_file = m.source_file;
    s.operating_point = op.kind;
    s.method = to_string(JacobianMethod::Exact);
    s.time = op.t;
    s.codyna_version = CODYNA_VERSION;
    s.study.clear();
    out.partition = partition;
    out.fd_error = 0.0;
    out.motion_shift.resize(0, 0);
    out.motion_rate_shift.resize(0, 0);
  }
};

Linearizer::Linearizer(const Model& model) : impl_(std::make_unique<Impl>(model)) {}
Linearizer::~Linearizer() = default;

void Linearizer::linearize(const OperatingPoint& op, const LinearizeOptions& options, Linearization& out) {
  if (impl_->tree && options.method == JacobianMethod::Exact && options.independent.empty() &&
      !(op.motion && op.motion->turns()))
    impl_->linearize_tree(op, out);
  else
    out = linearize_general(*impl_->model, op, options);
}

Linearization Linearizer::linearize(const OperatingPoint& op, const LinearizeOptions& options) {
  Linearization out;
  linearize(op, options, out);
  return out;
}

void Linearizer::bind(const Model& model) { impl_->bind(model); }

// One Linearizer's memory kept per thread, bound again to the model at every call: everything
// derived from the model is made again (nothing of another call's model is read; a model freed
// and another made at its address is as safe as a new one), only the storage is reused, which
// spares the workspaces' allocation and first touch (most of a call's cost beyond the Jacobian:
// docs/performance.md). Not kept for models above kKeptDof coordinates (its nv x nv matrices would
// stay allocated for the thread's life), nor while a call on the same thread is using it.
Linearization linearize(const Model& model, const OperatingPoint& op, const LinearizeOptions& options) {
  constexpr int kKeptDof = 200;
  thread_local std::unique_ptr<Linearizer> kept;
  if (model.nv > kKeptDof || (kept && kept->impl_->busy)) return Linearizer(model).linearize(op, options);
  if (kept)
    kept->bind(model);
  else
    kept = std::make_unique<Linearizer>(model);
  struct Busy {
    bool& b;
    explicit Busy(bool& f) : b(f) { b = true; }
    ~Busy() { b = false; }
  } busy(kept->impl_->busy);
  return kept->linearize(op, options);
}

}  // namespace codyna

namespace codyna {

bool LinearSystem::shifted(int i) const {
  auto touches = [i](const Eigen::MatrixXd& M) {
    if (i < 0 || i >= M.rows() || M.cols() == 0) return false;
    const double scale = std::max(1.0, M.cwiseAbs().maxCoeff());
    return M.row(i).cwiseAbs().maxCoeff() > 1e-14 * scale;
  };
  return touches(state_shift) || touches(state_rate_shift);
}

std::string state_meaning(const LinearSystem& s, int i) {
  if (!s.shifted(i) || i >= static_cast<int>(s.state_names.size())) return "";
  std::string name = s.state_names[static_cast<std::size_t>(i)];
  if (!name.empty() && name.back() == '~') name.pop_back();
  std::string out = name;
  auto term = [&](double c, int k, const char* rate) {
    if (c == 0.0 || k >= static_cast<int>(s.input_names.size())) return;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", std::abs(c));
    out += (c > 0 ? " - " : " + ") + std::string(buf) + " " + s.input_names[static_cast<std::size_t>(k)] + rate;
  };
  for (int k = 0; k < s.state_shift.cols(); ++k) term(s.state_shift(i, k), k, "");
  for (int k = 0; k < s.state_rate_shift.cols(); ++k) term(s.state_rate_shift(i, k), k, "'");
  return out;
}

}  // namespace codyna
