// A MuJoCo model (MJCF, as MuJoCo's XML reference defines it) read into the robot model the
// spherizer and the kinematics take (UrdfRobot): one link per body, the world body first, each
// body's solid geoms as its elements, its joints as UrdfJoints. What MJCF has beyond URDF is
// carried by the model's own fields: rotations (UrdfOrigin::rotation), capsules and ellipsoids,
// joint anchors (UrdfJoint::anchor). Several joints in one body, a ball joint (3 turns) and a free
// joint (3 slides, 3 turns) become chains through links of their own, without geometry, named
// BODY/JOINT (unique); their frames are the body's frame moved by the joints before them.
//
// Read: the body tree under every <worldbody> (bodies' pos and orientation), <joint> (hinge,
// slide, ball, free: pos, axis, range, limited, ref) and <freejoint>, <geom> (sphere, capsule,
// cylinder, box, ellipsoid, mesh; size as MuJoCo's half sizes; pos and orientation or fromto;
// mesh, group, contype, conaffinity), <default> classes nested to any depth (geom, joint and mesh
// defaults) with class and childclass, <asset><mesh name file scale> (the name defaults to the
// file's stem), <compiler> (angle, eulerseq, meshdir, assetdir, autolimits, strippath;
// coordinate="local" only) and <include file>, whose files are read only inside the model's
// folder. Everything else (inertials, sites, actuators, sensors, options, ...) is not needed to
// place the geometry and is passed over.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::robot {

// Which geoms are a body's solid. Both lists empty: MuJoCo's own rule, the geoms that take part
// in contacts (contype or conaffinity non-zero; MuJoCo's default is 1 and 1), which is how MuJoCo
// Menagerie's models set up their `collision` class (group 3) and keep their `visual` class
// (contype = conaffinity = 0, group 2) out. Otherwise the geoms whose default class is one of
// `classes` or inherits from one of them, and those whose group is one of `groups`.
struct MjcfGeomSelection {
  std::vector<std::string> classes;
  std::vector<int> groups;
};

struct MjcfReadOptions {
  MjcfGeomSelection solid;
};

enum class MjcfGeomType { kPlane, kHfield, kSphere, kCapsule, kEllipsoid, kCylinder, kBox, kMesh };
const char* MjcfGeomTypeName(MjcfGeomType type);  // "plane", "hfield", "sphere", ...

struct MjcfGeom {
  std::string name;  // "" when unnamed
  MjcfGeomType type = MjcfGeomType::kSphere;
  std::string class_name;  // its default class, "main" when none applies
  int group = 0;
  int contype = 1;
  int conaffinity = 1;
  int body = 0;  // index in MjcfModel::bodies
  // Its shape and its pose in the body's frame (UrdfOrigin::rotation set); meshes with the
  // asset's file as an absolute path and its scale. Planes and height fields: kUnsupported.
  UrdfElement element;
  bool solid = false;  // among its body's link elements (selected, or the visual fallback)
};

enum class MjcfJointType { kHinge, kSlide, kBall, kFree };
const char* MjcfJointTypeName(MjcfJointType type);  // "hinge", "slide", "ball", "free"

struct MjcfJoint {
  std::string name;  // as written, or BODY_jointK for the K-th unnamed joint of a body
  MjcfJointType type = MjcfJointType::kHinge;
  int body = 0;
  // Hinge and slide: MuJoCo's qpos is the joint's value + ref (radians or metres).
  double ref = 0.0;
  // Its coordinates as UrdfRobot::joints indices, in the order they move the body: hinge and
  // slide one; ball three turns about the moving x, y and z axes (qpos quaternion = q_x(a) *
  // q_y(b) * q_z(c)); free three slides along the parent's x, y, z from the body's own pose,
  // then three turns as a ball (qpos position = body pos + body rotation * (tx, ty, tz),
  // quaternion = body quat * q_x q_y q_z).
  std::vector<int> coordinates;
  int line = 0;
};

struct MjcfBody {
  std::string name;         // "world" for the world body; BODYk for the unnamed k-th body
  int parent = -1;          // index in MjcfModel::bodies; -1 for the world
  int link = 0;             // its link in UrdfRobot::links (frame: the body's own)
  std::vector<int> joints;  // MjcfModel::joints, in the order they apply
  int line = 0;
};

struct MjcfModel {
  UrdfRobot robot;                // name: <mujoco model>
  std::vector<MjcfBody> bodies;   // MuJoCo's body order: the world, then depth first
  std::vector<MjcfJoint> joints;  // MuJoCo's joint order (by body, then as written)
  std::vector<MjcfGeom> geoms;    // MuJoCo's geom order (by body, then as written)
  // One line each: bodies whose visual geoms stand in for missing solid ones, geoms that are
  // no solid (planes, height fields), each naming file, line and element.
  std::vector<std::string> warnings;
};

// Reads the MJCF document `bytes`, the file at `model_path` (its folder is where <include> and
// mesh files are looked for; nothing outside it is read). INVALID_ARGUMENT, naming the file,
// line, element and attribute, for: bytes that are not XML, a root other than <mujoco>, a
// malformed number list (pos, quat, size, ...), several orientations on one element, a zero
// quaternion or axis, an unknown geom or joint type, a geom size that is not positive where
// its type needs it, fromto on a sphere or mesh or beside pos, a class or mesh that is not
// defined, a class or name defined twice, a free joint below the top level, a range with
// lower > upper, <include> files that are missing, outside the folder, not <mujoco> documents
// or included twice (cycles too), mesh assets with a path outside the folder or without a
// file (inline vertex meshes, refpos/refquat are not supported), coordinate="global", and
// an unknown angle or eulerseq. Mesh files are not read here (the spherizer reads them and
// skips a body whose mesh is missing). Cost O(size of the documents).
absl::StatusOr<MjcfModel> ParseMjcf(absl::string_view bytes, const std::string& model_path,
                                    const MjcfReadOptions& options = {});

// ParseMjcf on the file at `path`. NOT_FOUND when it does not exist.
absl::StatusOr<MjcfModel> ReadMjcf(const std::string& path, const MjcfReadOptions& options = {});

}  // namespace inscribe::robot
