#include "dynamics/prepare.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynamics/assembly.hpp"
#include "dynamics/constraints.hpp"
#include "dynamics/data.hpp"
#include "dynamics/joint.hpp"
#include "dynamics/kinematics.hpp"
#include "model/compile.hpp"

namespace codyna {

namespace {

std::string quoted_name(const std::string& s) { return "\"" + s + "\""; }

std::string prepare_number(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

class Preparer {
 public:
  explicit Preparer(Model& m) : m_(m) {}

  void run() {
    reference_orientations();
    assemble_loops();
    check_mass_matrix();
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw ModelError(m_.source_file, path, what);
  }

  static std::string at(const char* list, std::size_t i) { return "/" + std::string(list) + "/" + std::to_string(i); }

  // body_angle measures from the orientation at the zero configuration
  void reference_orientations() {
    Data d(m_);
    forward_kinematics<double>(m_, d, neutral(m_));
    for (SensorModel& o : m_.sensors)
      if (o.type == SensorType::BodyAngle) o.R0 = d.oMi[o.body].R;
  }

  // the joints' q0, v0 (as written) moved onto the loop-closure constraints, what that moved,
  // and the rows that depend on the others
  void assemble_loops() {
    if (m_.nc == 0) return;
    // nothing moves (every joint fixed): no coordinate can close a loop, and the Jacobians have no
    // columns (their blocks would address an empty matrix)
    if (m_.nv == 0)
      fail(at("constraints", 0), "a loop closure needs a joint that moves, and every joint here is fixed "
                                 "(to weld two bodies, a fixed joint alone does it)");
    const Eigen::VectorXd q = m_.q0, v = m_.v0;
    check_discs_upright(q, "the joints' q0");
    const AssemblyResult r = assemble(m_, q, v);
    if (r.position_residual > 1e-9) {
      // motions that over-drive a loop cannot close it anywhere: say that first
      if (!m_.motions.empty()) {
        Data d(m_);
        constraint_terms<double>(m_, d, r.q, r.v);
        check_driven_loops(d.Jc, static_cast<int>(partition_rows(d.Jc).independent.size()));
      }
      // the motion inputs' coordinates stay at their q0 (assemble holds them): say so
      std::string held;
      for (int k : m_.motions) {
        const ActuatorModel& a = m_.actuators[static_cast<std::size_t>(k)];
        held += (held.empty() ? "" : ", ") + quoted_name(m_.v_names[a.iv]) + " = " + prepare_number(q[a.iq]) + " (motion input " +
                quoted_name(a.name) + ")";
      }
      fail(at("constraints", constraint_of_row(r.worst_row)),
           "the loop cannot be assembled from the joints' q0: residual " + prepare_number(r.position_residual) + " on " +
               m_.row_names[r.worst_row] + " after " + std::to_string(r.iterations) + " iterations" +
               (held.empty() ? "" : " with " + held + " held where the motion puts it") +
               " (check the constraint points and the joints' q0)");
    }
    check_discs_upright(r.q, "the assembled q0");
    m_.q0 = r.q;
    m_.v0 = r.v;
    m_.assembly_residual = std::max(r.position_residual, r.velocity_residual);
    // say what closing the loops moved (a rough q0 lands elsewhere than the user wrote)
    constexpr double kMoved = 1e-6;
    const Eigen::VectorXd dq = difference(m_, q, r.q);
    for (int b = 1; b < m_.nbodies; ++b) {
      const JointModel& j = m_.joints[b];
      for (int k = 0; k < j.nv; ++k) {
        const int i = j.idx_v + k;
        if (std::abs(dq[i]) > kMoved) {
          const bool scalar = j.nq == j.nv;
          m_.assembly_moves.push_back({m_.v_names[static_cast<std::size_t>(i)], scalar ? q[j.idx_q + k] : std::nan(""),
                                       scalar ? r.q[j.idx_q + k] : std::nan(""), dq[i]});
        }
      }
    }
    for (int i = 0; i < m_.nv; ++i)
      if (std::abs(r.v[i] - v[i]) > kMoved) m_.assembly_moves.push_back({m_.rate_names[static_cast<std::size_t>(i)], v[i], r.v[i], r.v[i] - v[i]});
    Data d(m_);
    constraint_terms<double>(m_, d, m_.q0, m_.v0);
    const RowPartition rows = partition_rows(d.Jc);
    m_.active_rows = rows.independent;
    m_.redundant_rows = rows.redundant;
    if (!m_.velocity_rows.empty()) velocity_row_partition(d.Jc, static_cast<int>(rows.independent.size()));
    check_driven_loops(d.Jc, static_cast<int>(rows.independent.size()));
  }

  // a rolling_disc lying flat on its plane (its axle along the normal) has no contact point: its
  // rows are singular there (constraints.cpp refuses |n - (n.a) a| < 1e-6 when evaluated); say so
  // at q0 with the constraint's path rather than fail inside the assembly
  void check_discs_upright(const Eigen::VectorXd& q, const char* where) const {
    bool any = false;
    for (const ConstraintModel& c : m_.constraints) any = any || c.type == ConstraintType::RollingDisc;
    if (!any) return;
    Data d(m_);
    forward_kinematics<double>(m_, d, q);
    for (std::size_t k = 0; k < m_.constraints.size(); ++k) {
      const ConstraintModel& c = m_.constraints[k];
      if (c.type != ConstraintType::RollingDisc) continue;
      const Eigen::Vector3d n = d.oMi[c.body_a].R * c.axis_a, a = d.oMi[c.body_b].R * c.axis_b;
      const double s = (n - n.dot(a) * a).norm();
      if (!(s >= 1e-3))
        fail(at("constraints", k), std::string("the disc lies flat on the plane at ") + where +
                                       " (its axle axis_b is along the plane's normal axis_a: |n - (n.a) a| = " +
                                       prepare_number(s) + " < 1e-3, where its contact point is undefined; stand it up)");
    }
  }

  // With non-holonomic rows the active rows are the independent holonomic ones (which fix the
  // coordinates), then the velocity rows independent of them: a velocity row never stands in for a
  // position row, so that the positions' partition and the rates' stay apart.
  void velocity_row_partition(const Eigen::MatrixXd& Jc, int rank) {
    Eigen::MatrixXd Jh = Jc;
    for (int r : m_.velocity_rows) Jh.row(r).setZero();
    const RowPartition held = partition_rows(Jh);
    std::vector<int> active;
    for (int r : held.independent)
      if (!m_.is_velocity_row(r)) active.push_back(r);
    const std::vector<int> rolling = rows_adding_rank(Jc, active, m_.velocity_rows);
    const int nvel = static_cast<int>(rolling.size());
    active.insert(active.end(), rolling.begin(), rolling.end());
    std::sort(active.begin(), active.end());
    if (static_cast<int>(active.size()) != rank)
      fail(at("constraints", constraint_of_row(m_.velocity_rows.front())),
           "the rolling conditions and the loops leave " + std::to_string(active.size()) +
               " independent rows where their Jacobian has rank " + std::to_string(rank) + " (expected them to agree)");
    m_.active_rows = active;
    m_.active_velocity_rows = nvel;
    m_.redundant_rows.clear();
    for (int r = 0; r < m_.nc; ++r)
      if (!std::binary_search(active.begin(), active.end(), r)) m_.redundant_rows.push_back(r);
  }

  // index into spec.actuators of the motion input k (an index into Model::actuators)
  std::size_t spec_actuator(int k) const {
    for (std::size_t i = 0; i < m_.spec.actuators.size(); ++i)
      if (m_.spec.actuators[i].name == m_.actuators[static_cast<std::size_t>(k)].name) return i;
    return 0;
  }

  // the constraint a row belongs to
  std::size_t constraint_of_row(int row) const {
    std::size_t c = 0;
    while (c + 1 < m_.constraints.size() && m_.constraints[c + 1].row <= row) ++c;
    return c;
  }

  // Motion inputs on the loops' coordinates (a four-bar's crank): the loops must close on the free
  // coordinates whatever the driven ones do, i.e. the free columns J_f keep the rank of Jc at q0.
  // A combination y of rows with y^T J_f = 0 but y^T J_d != 0 fixes the driven coordinates from the
  // others: the motion over-drives the loop (two motions on a one-DOF loop, a motion on a rigid one).
  void check_driven_loops(const Eigen::MatrixXd& Jc, int rank) {
    if (m_.motions.empty() || rank == 0) return;
    Eigen::MatrixXd Jf = Jc;
    for (int k : m_.motions) Jf.col(m_.actuators[static_cast<std::size_t>(k)].iv).setZero();
    const double largest = Eigen::JacobiSVD<Eigen::MatrixXd>(Jc).singularValues()[0];
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jf.transpose(), Eigen::ComputeFullV);  // Jf^T = U S V^T
    const Eigen::VectorXd& s = svd.singularValues();
    int rank_f = 0;
    while (rank_f < s.size() && s[rank_f] > 1e-9 * largest) ++rank_f;
    if (rank_f >= rank) return;
    // the row combination (a column of V past J_f's rank) that sees the driven coordinates most
    double worst = -1.0;
    int motion = m_.motions.front(), row = 0;
    for (int c = rank_f; c < svd.matrixV().cols(); ++c) {
      const Eigen::VectorXd y = svd.matrixV().col(c);
      for (int k : m_.motions) {
        const double g = std::abs(y.dot(Jc.col(m_.actuators[static_cast<std::size_t>(k)].iv)));
        if (g > worst) {
          worst = g;
          motion = k;
          y.cwiseAbs().maxCoeff(&row);
        }
      }
    }
    const ActuatorModel& a = m_.actuators[static_cast<std::size_t>(motion)];
    const ConstraintModel& cm = m_.constraints[constraint_of_row(row)];
    fail(at("actuators", spec_actuator(motion)) + "/joint",
         "the motion input " + quoted_name(a.name) + " drives " + quoted_name(m_.v_names[a.iv]) + ", which the loop closure " +
             quoted_name(cm.name) + " fixes from the other coordinates at q0" +
             (m_.motions.size() > 1 ? " and the other motion inputs" : "") + ": on the coordinates no motion drives the closure rows have rank " +
             std::to_string(rank_f) + ", not " + std::to_string(rank) + " (the motion over-drives or locks the loop; drive a coordinate the loop leaves free, drive fewer, or "
             "use a joint_force)");
  }

  // The tree's mass matrix is positive definite exactly when every joint's articulated
  // inertia D_i = S_i^T IA_i S_i is: one backward pass, O(n), instead of an O(n^3) eigen
  // decomposition. Scale-aware: D_i is judged against the same joint's composite (rigid
  // subtree) inertia S_i^T Ic_i S_i, so a long chain whose mass matrix spans many decades
  // passes while a coordinate that truly moves nothing fails.
  void check_mass_matrix() {
    if (m_.nv == 0) return;
    Data d(m_);
    forward_kinematics<double>(m_, d, m_.q0);
    std::vector<Mat6T<double>> IA(m_.inertia.begin(), m_.inertia.end()), Ic = IA;
    for (int i = m_.nbodies - 1; i >= 1; --i) {
      const JointModel& j = m_.joints[i];
      const Mat6T<double> Xi = d.liMi[i].inverse().motion_matrix();
      Mat6T<double> Ia = IA[i];
      // a coordinate a motion input drives moves as prescribed: its joint passes the whole
      // articulated inertia on, like a fixed joint (its body may be massless, the road under a tire)
      bool driven = false;
      for (int k : m_.motions) driven = driven || (j.nv == 1 && m_.actuators[k].iv == j.idx_v);
      if (j.nv > 0 && !driven) {
        const Mat6xT<double>& S = d.Sb[i];
        const Eigen::MatrixXd U = IA[i] * S;
        Eigen::MatrixXd D = S.transpose() * U;
        Eigen::MatrixXd Dc = S.transpose() * Ic[i] * S;
        if (m_.armature.size() != 0) {  // rotor inertia (armature) on the joint's coordinates
          D.diagonal() += m_.armature.segment(j.idx_v, j.nv);
          Dc.diagonal() += m_.armature.segment(j.idx_v, j.nv);
        }
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(D);
        const double reference = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Dc).eigenvalues().maxCoeff();
        if (!(es.eigenvalues()[0] > 1e-12 * reference) || !(reference > 0)) {
          Eigen::Index k;
          es.eigenvectors().col(0).cwiseAbs().maxCoeff(&k);
          fail("/bodies", "the mass matrix is singular at the initial state: coordinate " +
                              quoted_name(m_.v_names[j.idx_v + k]) + " moves no mass or inertia (give the bodies it moves mass and inertia)" +
                              semi_definite_note(i));
        }
        Ia -= U * D.inverse() * U.transpose();
      }
      const int p = j.parent;
      IA[p] += Xi.transpose() * Ia * Xi;
      Ic[p] += Xi.transpose() * Ic[i] * Xi;
    }
  }

  // Names a body moved by joint i whose inertia is only positive semi-definite
  // (a slender rod turned about its own axis), the usual cause of a singular
  // mass matrix in a model that passed the per-body checks.
  std::string semi_definite_note(int i) const {
    for (int k = i; k < m_.nbodies; ++k) {
      int a = k;
      while (a > i) a = m_.parent[a];
      if (a != i || m_.body_spec_index[k] < 0) continue;
      const BodySpec& b = m_.spec.bodies[m_.body_spec_index[k]];
      const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia).eigenvalues();
      if (b.mass > 0 && !(ev[0] > 1e-12 * std::max(ev[2], 1e-300)))
        return "; body " + quoted_name(b.name) + " has no inertia about one of its axes (principal moments " + prepare_number(ev[0]) + ", " +
               prepare_number(ev[1]) + ", " + prepare_number(ev[2]) + "): a joint that turns it about that axis alone moves nothing";
    }
    return "";
  }

  Model& m_;
};

}  // namespace

void prepare_model(Model& model) { Preparer(model).run(); }

Model compile(const ModelSpec& spec, const std::string& file) {
  Model m = compile_structure(spec, file);
  prepare_model(m);
  return m;
}

}  // namespace codyna
