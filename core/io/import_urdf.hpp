// URDF import through urdfdom (Debian liburdfdom-dev, the ROS reference parser): links become
// bodies (inertial origin and rotation applied to the tensor), joints keep their frames
// (parent_frame = the joint's origin, the child link's frame is the joint frame), every
// movable 1-DOF joint gets a joint_force actuator (URDF transmissions are not read by
// urdfdom) and a joint_position sensor. What maps and what does not: docs/import.md.
#pragma once

#include <string>

#include "io/import_report.hpp"

namespace codyna {

// true when codyna was built with urdfdom; otherwise import_urdf throws std::runtime_error.
bool urdf_import_available();

// Reads a URDF file. Throws ImportRefused for a malformed file (naming the file and what
// urdfdom said) and for elements that change the dynamics and cannot be represented, unless
// their kinds are in options.ignore.
ImportResult import_urdf(const std::string& path, const ImportOptions& options = {});

}  // namespace codyna
