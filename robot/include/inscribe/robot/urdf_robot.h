// A robot description as `inscribe urdf` needs it: each link's collision geometry (its
// visual geometry when it has no <collision>), with origins and mesh scales, and where the
// mesh files are (package://, file:// and relative paths), and its joints. ParseUrdf reads it
// from URDF (tinyxml2); ParseMjcf (mjcf_robot.h) fills the same model from a MuJoCo model, using
// what URDF lacks: explicit rotations, capsules, ellipsoids and joint anchors. Materials,
// inertials and the rest are not represented: the writer (spherized_urdf.h) edits the original
// document instead.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe::robot {

// <origin xyz="x y z" rpy="roll pitch yaw">: the pose of an element's frame in its link's
// frame. Metres and radians; both default to zero.
struct UrdfOrigin {
  Vector3 xyz = Vector3::Zero();
  Vector3 rpy = Vector3::Zero();
  // When set, the rotation itself (orthonormal, determinant 1), used instead of rpy: how MJCF's
  // orientations (quat, axisangle, euler, xyaxes, zaxis, fromto) are kept without a lossy
  // conversion to angles. ParseUrdf leaves it unset.
  std::optional<Eigen::Matrix3d> rotation;
};

// URDF's rpy convention: fixed axes, roll about X, then pitch about Y, then yaw about Z, so
// R = Rz(yaw) * Ry(pitch) * Rx(roll). A point p of the element's frame is R * p + xyz in the
// link's frame.
Eigen::Matrix3d RotationFromRpy(const Vector3& rpy);

// The origin's rotation: `rotation` when set, else RotationFromRpy(rpy). The one place the two
// are told apart.
Eigen::Matrix3d OriginRotation(const UrdfOrigin& origin);

enum class UrdfShape {
  kMesh,
  kBox,
  kCylinder,
  kSphere,
  kCapsule,      // MJCF only: a cylinder of `radius` and `length` along z capped by hemispheres
  kEllipsoid,    // MJCF only: semi-axes `size` along x, y, z
  kUnsupported,  // a <geometry> child URDF does not define (e.g. <capsule>), or none
};

struct UrdfGeometry {
  UrdfShape shape = UrdfShape::kUnsupported;
  // kMesh: the filename attribute as written, and the per-axis scale (default 1 1 1; no zero
  // component; a negative one mirrors the mesh).
  std::string filename;
  Vector3 scale = Vector3::Ones();
  // kBox: side lengths along the element's x, y, z; metres, > 0.
  Vector3 size = Vector3::Zero();
  // kEllipsoid: the semi-axes (radii) along x, y, z; metres, > 0.
  // kCylinder and kCapsule (axis z, centred on the element's origin; `length` is the cylinder
  // part's whole length, without the caps) and kSphere: metres, > 0.
  double radius = 0.0;
  double length = 0.0;
  // kUnsupported: the element found under <geometry>, e.g. "capsule"; "" when it is empty.
  std::string unsupported;
};

// One <collision> (or <visual>) element.
struct UrdfElement {
  std::string name;  // its name attribute; "" when absent
  UrdfOrigin origin;
  UrdfGeometry geometry;
  int line = 0;  // of the element in the file, 1-based
};

// "line 12 (<collision> 'tool')": how messages name an element (its line in the URDF, its
// kind, and its name when it has one).
std::string DescribeUrdfElement(const UrdfElement& element, bool from_visual);

struct UrdfLink {
  std::string name;
  int line = 0;
  // The <collision> children in file order; when the link has none, its <visual> children
  // (from_visual is then true). Empty for a link without geometry.
  std::vector<UrdfElement> elements;
  bool from_visual = false;
};

enum class UrdfJointType {
  kFixed,
  kRevolute,    // about `axis`, within [lower, upper] radians
  kContinuous,  // about `axis`, unlimited
  kPrismatic,   // along `axis`, within [lower, upper] metres
  kFloating,    // 6 DOF; kinematics keeps it at its origin
  kPlanar,      // 3 DOF in the plane normal to `axis`; kinematics keeps it at its origin
};

// "fixed", "revolute", "continuous", "prismatic", "floating", "planar": URDF's type names.
const char* UrdfJointTypeName(UrdfJointType type);

// <mimic joint="J" multiplier="m" offset="o">: this joint's value is m * value(J) + o.
struct UrdfMimic {
  std::string joint;
  double multiplier = 1.0;
  double offset = 0.0;
};

// One <joint>. The child link's frame is the parent link's frame moved by `origin` and then by
// the joint's motion: a rotation by the joint value about `axis` (revolute, continuous) or a
// translation by the value along `axis` (prismatic), `axis` given in the joint frame.
struct UrdfJoint {
  std::string name;
  UrdfJointType type = UrdfJointType::kFixed;
  std::string parent, child;  // link names
  UrdfOrigin origin;
  Vector3 axis = Vector3::UnitX();  // unit length (normalised when parsed); URDF's default
  // A point of the child's frame the axis passes through: the child's frame is
  // parent * origin * T(anchor) * motion * T(-anchor). MJCF's joint `pos`; zero for URDF
  // (whose axes pass through the joint frame's origin). Metres.
  Vector3 anchor = Vector3::Zero();
  // <limit lower upper>: radians or metres; both 0 when absent (URDF's defaults). Not used for
  // continuous joints. lower <= upper.
  double lower = 0.0;
  double upper = 0.0;
  std::optional<UrdfMimic> mimic;
  int line = 0;
};

struct UrdfRobot {
  std::string name;               // <robot name>, may be empty
  std::vector<UrdfLink> links;    // in file order
  std::vector<UrdfJoint> joints;  // in file order
};

// Parses a URDF document: its links and joints. INVALID_ARGUMENT, naming the line and, where
// there is one, the link or joint and the attribute, for: bytes that are not XML (text or a
// second element beside the root included, which tinyxml2 alone accepts), a root that is not
// <robot>, unexpanded xacro (elements in the xacro namespace, ${...} or $(...) values:
// the message says to run `xacro robot.urdf.xacro > robot.urdf`), a link without a name or with a
// name used before, a missing or malformed number (xyz, rpy, scale: 3 finite numbers; size: 3
// positive; radius, length: one positive; limit lower/upper, mimic multiplier/offset: one finite),
// a zero scale component, a <mesh> without filename; a joint without a name, without a type or with
// a type URDF does not define, without <parent link> or <child link>, with a zero <axis> (revolute,
// continuous, prismatic, planar; the axis is normalised), with lower > upper (revolute, prismatic),
// or with a <mimic> without joint. Geometry URDF does not define is not an error here
// (kUnsupported). Unlike ROS's urdfdom, a revolute or prismatic joint without <limit> is accepted
// (lower = upper = 0: it stays at 0), as some exported files need. What needs the whole tree (joint
// names used twice, links that do not exist, cycles, mimics) is checked by Kinematics::Create.
// <calibration>, <dynamics>, <safety_controller>, effort and velocity are ignored. Cost O(size of
// the document).
absl::StatusOr<UrdfRobot> ParseUrdf(absl::string_view bytes);

// Where package://PKG/... URIs are looked for, in this order: for each directory D of
// package_paths (--package-path) and then of ros_package_path (ROS_PACKAGE_PATH), D/PKG and,
// when D's own name is PKG, D itself; then for each prefix P of ament_prefix_path
// (AMENT_PREFIX_PATH, ROS 2 installs), P/share/PKG. The first existing package directory is
// the package (as ROS does: a package is found once, its files are not searched elsewhere).
struct PackageSearch {
  std::vector<std::string> package_paths;
  std::vector<std::string> ros_package_path;
  std::vector<std::string> ament_prefix_path;
};

// `package_paths` plus ROS_PACKAGE_PATH and AMENT_PREFIX_PATH from the environment, split at
// ':' (empty entries ignored).
PackageSearch PackageSearchFromEnvironment(std::vector<std::string> package_paths);

// The file a <mesh filename> names: package://PKG/REL through `search`; file://PATH (an
// absolute path, or relative to urdf_dir) and plain paths (relative ones to urdf_dir, the
// directory of the URDF file). The file must exist. NOT_FOUND for a package that is not found
// (listing where it was looked for) or a missing file (naming the path tried);
// INVALID_ARGUMENT for another URI scheme (e.g. model://) or an empty path. Cost: a few stat
// calls per search directory.
absl::StatusOr<std::string> ResolveMeshFilename(const std::string& filename,
                                                const std::string& urdf_dir,
                                                const PackageSearch& search);

}  // namespace inscribe::robot
