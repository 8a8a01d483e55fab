// MJCF import: the file is compiled by MuJoCo's own reader (libmujoco, mj_loadXML), and the
// compiled mjModel is mapped onto a ModelSpec, so that codyna reads an MJCF file exactly as
// MuJoCo does (defaults, childclass, compiler options, inertia from geoms, angle units,
// included files). What maps and what does not: docs/import.md.
//
// Coordinates: a hinge or slide joint's codyna coordinate is MuJoCo's qpos (the joint frame
// on the parent is turned or shifted by -ref), a ball's quaternion and a free joint's pose
// are MuJoCo's qpos too; several joints in one body become a chain of massless frames
// named after the joint they follow (JOINT_frame). A free joint's rates differ: codyna's
// are the angular and linear velocity in body axes, MuJoCo's the linear velocity in world
// axes and then the angular velocity in body axes.
#pragma once

#include <string>

#include "io/import_report.hpp"

namespace codyna {

// true when codyna was built with MuJoCo (libmujoco-dev); otherwise import_mjcf throws
// std::runtime_error saying so.
bool mjcf_import_available();

// "MuJoCo 2.2.2" (or why there is none)
std::string mjcf_reader_version();

// Reads an MJCF file. Throws ImportRefused (std::invalid_argument) for a file MuJoCo does not
// read (MuJoCo's message, which names the element and line) and for elements that change the
// dynamics and cannot be represented, unless their kinds are in options.ignore.
ImportResult import_mjcf(const std::string& path, const ImportOptions& options = {});

}  // namespace codyna
