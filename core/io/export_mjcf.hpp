// MJCF export: a compiled codyna Model written as MJCF that MuJoCo 2.2.2 loads as the same
// mechanism (codyna export-mjcf, docs/import.md "Export to MJCF"), the reverse of
// io/import_mjcf. Only what has an exact MJCF equivalent is written; an element without one
// (a bushing, a line of action in world axes, a mix, a three-joint coupler, ...) refuses the
// export, naming every such element: never a silently different model.
//
// What is written (MuJoCo's names in brackets):
//   bodies          mass, centre of mass, inertia as principal moments and axes (inertial quat +
//                   diaginertia, computed here in double precision: MuJoCo 2.2.2 diagonalizes a
//                   fullinertia with an iterative solver that keeps ~3e-7 of it)
//   joints          revolute -> hinge, prismatic -> slide, spherical -> ball, free -> free (from
//                   ground, identity frames: MuJoCo's free joint is the body's world pose),
//                   universal -> hinge, hinge; cylindrical -> hinge, slide; planar -> slide x,
//                   slide y, hinge z, in one MuJoCo body (named JOINT_0, JOINT_1, ...); a
//                   massless body without shapes whose only child follows it is merged into that
//                   child's MuJoCo body (MuJoCo refuses moving bodies without mass), its joints
//                   first. Each body is placed (pos, quat) where the model's initial state q0
//                   puts it and each hinge and slide has ref = its q0, so that MuJoCo's qpos is
//                   codyna's q (and qpos0 its q0); a ball's quaternion in the MuJoCo body's
//                   axes is q_c q q_c^-1 (q_c the rotation of the joint's child frame M); rotor
//                   inertia -> armature (a ball's or free joint's the same on all its coordinates)
//   effects         gravity (summed) -> option gravity; joint_spring_damper, joint_friction,
//                   joint_damper -> joint stiffness, springref, damping (summed per coordinate;
//                   a ball's or free joint's damping must be the same on all its coordinates);
//                   spring_damper -> a spatial tendon between two sites with stiffness, damping
//                   and springlength
//   constraints     ball -> connect; planar_revolute and revolute -> connect where the
//                   mechanism is planar about the closure's axis (the rows connect adds are then
//                   identically zero); coupler of two joints -> joint equality (polycoef c0 c1)
//   actuators       joint_force -> motor on the joint (gear = gain, ctrlrange = [min, max]); on a
//                   ball: gear = gain times the coordinate's axis in the body's axes; on a free
//                   joint's linear coordinates (body axes): a site transmission at the body's
//                   origin; body_force / body_torque in body axes -> a site transmission;
//                   line_force -> a motor on a spatial tendon between the two points
//   sensors         joint_position, joint_velocity of scalar coordinates -> jointpos, jointvel
//   shapes          geoms (box, cylinder, sphere) with contype = conaffinity = 0 (no contacts)
//   initial state   a keyframe "initial" (qpos, qvel, ctrl) where q0 has a turned ball, v0 is
//                   not zero or an actuator's u0 is not zero
//   solver          option timestep = the solver's output_step
// Equalities are written as stiff as MuJoCo allows (solimp 0.9999): MuJoCo's constraints stay
// soft, codyna's exact.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "model/model.hpp"

namespace codyna {

// The first bytes of every MJCF codyna writes (the output guard tells codyna's own files by them).
inline constexpr const char* kMjcfHeader = "<!-- MJCF written by codyna";

struct MjcfExport {
  std::string xml;                       // the MJCF text
  std::vector<std::string> written;      // what was written, one line per kind
  std::vector<std::string> not_written;  // what MJCF does not hold and that does not change the dynamics
  int nbodies = 0, njoints = 0, nactuators = 0, nequalities = 0;  // MuJoCo's counts
};

// An export refused because elements have no exact MJCF equivalent (bad input, exit 1): the
// message names every one of them ("bushing mount: ...").
class MjcfExportRefused : public std::invalid_argument {
 public:
  MjcfExportRefused(const std::string& what, std::vector<std::string> elements)
      : std::invalid_argument(what), elements_(std::move(elements)) {}
  const std::vector<std::string>& elements() const { return elements_; }

 private:
  std::vector<std::string> elements_;
};

// The MJCF of a compiled model; `source` (the model file) names it in messages and in the
// file's first line. Throws MjcfExportRefused.
MjcfExport export_mjcf(const Model& model, const std::string& source = "");

// Whether this build can load MJCF with MuJoCo to check an export (libmujoco-dev), and
// "MuJoCo 2.2.2" or why not.
bool mjcf_load_check_available();
std::string mjcf_load_check_version();
// Loads `xml` with MuJoCo's compiler (mj_loadXML, from memory): "" when MuJoCo loads it,
// MuJoCo's message otherwise (which names the element). Without MuJoCo: "".
std::string mjcf_load_check(const std::string& xml);

}  // namespace codyna
