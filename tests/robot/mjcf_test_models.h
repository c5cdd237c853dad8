// MuJoCo models written by the tests from MJCF's public conventions, with the mesh files they
// need, into a folder of the test's own.
#pragma once

#include <cstdint>
#include <string>

namespace inscribe::robot::mjcf_models {

// A fresh, empty folder under the system's temporary one, named after `name` and the process.
std::string FreshFolder(const std::string& name);

// Writes `text` to `path` (creating its folder).
void WriteText(const std::string& path, const std::string& text);

// A Menagerie-style arm in `folder`: arm.xml includes its defaults (nested classes `arm`,
// `visual`, `collision`, `pad`, a mesh class) and its links (inside a body); meshes under
// assets/ (OBJ and binary STL, one scaled through a class); every orientation form on bodies and
// geoms (quat, axisangle, euler in `eulerseq`, xyaxes, zaxis, fromto on capsules, cylinders,
// boxes, ellipsoids); hinge joints with anchors and ref, a hinge and a slide in one body, a ball,
// an unlimited hinge; angles in degrees; a floor plane; a welded body with visual geoms only.
// Returns arm.xml's path.
std::string WriteArm(const std::string& folder, const std::string& eulerseq = "zyx");

// A hand of many small bodies: a palm welded to the world, `fingers` fingers of `phalanges`
// bodies each, hinge joints with anchors, capsules from fromto and orientations drawn from
// `seed`. Angles in radians. Returns the model's path.
std::string WriteHand(const std::string& folder, int fingers, int phalanges, std::uint64_t seed);

// A legged robot: a torso with a free joint, four legs with two hinges in the hip body and a knee,
// ellipsoid and capsule geoms, a ball joint at each foot, a floor. Returns the model's path.
std::string WriteQuadruped(const std::string& folder);

}  // namespace inscribe::robot::mjcf_models
