// The spherized MuJoCo model: the model read by ParseMjcf written back as one MJCF file (its
// includes inlined) in which every spherized body's solid geoms no longer collide and its
// spheres do.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/robot/robot_file.h"
#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::robot {

// `file` (an MJCF RobotFile) with, in every body whose link is kSpherized in `links` (one per
// file.robot() link, SpherizeRobot's order): each solid geom kept where it is with contype and
// conaffinity 0 (it no longer collides, and still gives the body the mass and inertia MuJoCo
// computed from it, so nothing is counted twice), and after the first of them one
// `<geom type="sphere" size="r" pos="x y z" group="3" mass="0">` per sphere (the body's frame,
// shortest round-trip decimals) in the solid geom's default class (Menagerie's `collision`),
// with its contact settings (contype, conaffinity, condim, friction, solref, solimp, solmix,
// priority, margin, gap; its own where written, else its class's; 1 and 1 when visual geoms
// stood in for a missing solid). Visual geoms, explicit <inertial>s and everything else are
// kept as written; <include>s are inlined; `meshdir` and `texturedir` are rewritten
// relative to `output_directory` (absolute, the folder the result is written to) so the files
// are found from there. INVALID_ARGUMENT for a URDF file or a wrong number of links.
absl::StatusOr<std::string> SpherizedMjcf(const RobotFile& file,
                                          const std::vector<LinkSpherizeResult>& links,
                                          const std::string& output_directory);

}  // namespace inscribe::robot
