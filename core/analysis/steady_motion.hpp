// Steady motions: a car straight at 30 m/s or in a steady turn, a disc rolling upright, a top
// precessing. In such a motion the coordinates that place the mechanism on the road (x, y,
// heading) and the wheels' spin angles advance at constant rates while everything else is
// steady; it is an equilibrium only in a frame that moves with it (a relative equilibrium).
//
// The moving frame, per joint (SteadyMotion::joints), in the joint's parent frame F:
//   free, planar, spherical joints on ground: the road-plane motion, a rotation at `yaw_rate`
//     about the road normal n (F axes; a planar joint turns about its own z) and, for free and
//     planar joints, the velocity `velocity` of the joint's origin at the reference, in the plane;
//   free and spherical joints whose body is symmetric about a body axis a through its origin (a
//     wheel or a disc: the axle of its tire or rolling_disc, with an inertia symmetric about it):
//     a spin at `spin_rate` about a;
//   the other coordinates: a constant rate each (`rates`; a wheel's spin angle), 0 when they do
//   not advance.
// The state of a linearization about the motion is the deviation from the pose that moves with
// the frame, and the velocities in the frame that spins with the body:
//   q = g(t) . (q_ref (+) z) . h(t),   w = h(t)^-1 v
// (g the road-plane motion, h the spin). At t = 0 this is the fixed chart of plant_function.hpp,
// whose rates differ only by the reference's velocity field:
//   z' = rate(z, v - v_ref(q)),   w' = v' + (spin) x v   (planar: v'_xy - r e_z x v_xy)
// (motion_reference_velocity, motion_acceleration_terms). A is then the same wherever along the
// motion it is taken, and its eigenvalues are the motion's, exactly when the dynamics are
// invariant under the frame's motion (a level road along n, gravity along n, no spring to ground
// in the plane, bodies symmetric about their spin axes) and the state is steady in the frame
// (x' = 0 at the reference): check_relative_equilibrium says whether both hold.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "model/model.hpp"

namespace codyna {

struct JointMotion {
  int body = 0;                                        // the joint's child body (Model::joints index)
  double yaw_rate = 0;                                 // rad/s about `normal` (joints on ground)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   // road normal, F axes (planar: F's z)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // the joint origin's velocity at the reference, F axes
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();    // the joint origin's position at the reference, F axes
  Eigen::Vector3d spin_axis = Eigen::Vector3d::Zero(); // unit body axis of symmetry (0: none)
  double spin_rate = 0;                                // rad/s about spin_axis
};

struct SteadyMotion {
  std::vector<JointMotion> joints;  // free, planar and spherical joints
  Eigen::VectorXd rates;            // [nv] the other coordinates' constant rates (0 for the joints above)
  std::vector<int> cyclic;          // velocity indices of the other coordinates that advance (rates != 0)
  // whether the frame turns (a yaw or spin rate): then A about the motion differs from A in the
  // fixed chart; a motion that only translates has the same A either way
  bool turns() const;
};

// The road normal (world axes): against gravity, +z without gravity.
Eigen::Vector3d road_normal(const Model& model);

// The body axis about which body b is symmetric and may spin (its tire's or rolling_disc's axle,
// through the body's origin, with its centre of mass on it and an inertia symmetric about it),
// or 0.
Eigen::Vector3d spin_symmetry_axis(const Model& model, int body);

// The moving frame that the state (q, v) moves with: per free/planar/spherical joint the yaw and
// spin rates that best give its angular velocity and its origin's velocity, the other
// coordinates' rates as they are. What the frame cannot carry (a tilt rate, a climb) is left in
// the state's rates and shows in check_relative_equilibrium's rate residual.
SteadyMotion motion_of_state(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// The velocity field of the moving frame at q (size nv, the joints' velocity coordinates): what
// the velocities would be if the mechanism moved with the frame, posed at q.
template <class S>
void motion_reference_velocity(const Model& model, const SteadyMotion& motion, const VecXT<S>& q, VecXT<S>& v_ref);

// Adds to qdd (size nv) the rate terms of the spinning or turning velocity axes: (spin) x v for a
// spinning free or spherical joint's velocities, -r e_z x v_xy for a turning planar joint's.
template <class S>
void motion_acceleration_terms(const Model& model, const SteadyMotion& motion, const VecXT<S>& v, VecXT<S>& qdd);

// The pose and velocities a time T further along the motion (the frame moved by T), and the
// motion seen from there (its joints' origins and velocities moved with it): for the check that
// A does not depend on where along the motion it is taken.
void advance_motion(const Model& model, SteadyMotion& motion, double T, Eigen::VectorXd& q, Eigen::VectorXd& v);

// A time over which the motion turns by a fair angle (half a radian at its fastest rate), 1 s
// when it does not turn.
double motion_check_time(const SteadyMotion& motion);

}  // namespace codyna
