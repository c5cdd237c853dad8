// Spherizing a robot: each link's collision geometry (its visual geometry when it has none)
// brought into the link's frame and approximated by internal medial spheres.
//
// Elements are spherized one by one and their spheres concatenated, rather than their meshes
// merged into one: two overlapping closed meshes merged are one self-intersecting mesh, whose
// overlap the inside test counts as outside (see InsideTest::kRayParity), so the spheres would
// miss exactly where the parts meet. With a sphere budget, the link's N spheres are shared out
// among its elements (see LinkSphereBudgets).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/medial_spheres.h"
#include "inscribe/mesh.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/sphere.h"

namespace inscribe::robot {

// The per-link sphere budget when neither a budget nor a voxel size is given (`inscribe urdf`
// and the Python bindings).
inline constexpr std::int64_t kDefaultMaxSpheresPerLink = 32;

struct UrdfSpherizeOptions {
  // Exactly one of the two is > 0. max_spheres_per_link: at most this many spheres per link
  // (GenerateWithSphereBudget per element); voxel_size: sigma in metres for every element.
  std::int64_t max_spheres_per_link = 0;
  double voxel_size = 0.0;
  // Everything else of the generation (voxel_size is ignored here).
  MedialSphereOptions medial;
  // Where package:// URIs are looked for, and the directory relative paths start from (the
  // URDF file's).
  PackageSearch packages;
  std::string urdf_dir;
};

// An element's geometry as a closed mesh in its LINK's frame: for a <mesh>, the file scaled
// per axis (mirrored, with the triangles turned to keep them outward, when the scale has an odd
// number of negative components) and then moved by the element's origin, p -> R(rpy) (s . p) +
// xyz; for <box> and <cylinder>, BoxMesh and CylinderMesh moved by the origin. Metres.
// A mesh file is read by ReadMesh (.stl, .obj, .ply, .off, and COLLADA .dae and glTF
// .gltf/.glb with every node's transform and COLLADA's <unit> applied and <up_axis> not: the
// file's own axes, as ROS's loaders take them). Not validated (welding is validation's).
// Errors: the file's resolution (ResolveMeshFilename) or reading (ReadMesh) errors;
// INVALID_ARGUMENT for <sphere> and unsupported geometry, which have no mesh.
absl::StatusOr<Mesh> ElementMeshInLinkFrame(const UrdfElement& element,
                                            const UrdfSpherizeOptions& options);

// The vertices of `mesh` (any frame) taken through scale, then rotation, then translation:
// v -> rotation * (scale . v) + translation, with the triangles reversed when scale mirrors.
// The one place the element-to-link transform is applied.
Mesh TransformMesh(Mesh mesh, const Vector3& scale, const Eigen::Matrix3d& rotation,
                   const Vector3& translation);

// Shares a link's budget of N spheres among its elements: each <sphere> element takes 1; the
// rest goes to the mesh elements in proportion to their volumes (largest remainders), at
// least 1 each. `volumes` has one entry per element, < 0 for a <sphere> element. Empty when
// N is too small to give every element a sphere.
std::vector<std::int64_t> LinkSphereBudgets(std::int64_t max_spheres,
                                            const std::vector<double>& volumes);

enum class LinkStatus {
  kSpherized,   // `spheres` replaces the link's collision geometry
  kSkipped,     // an element could not be spherized; `error` says which and why
  kNoGeometry,  // no <collision> and no <visual>: nothing to do
};

const char* LinkStatusName(LinkStatus status);  // "spherized", "skipped", "no_geometry"

struct LinkSpherizeResult {
  std::string link;
  LinkStatus status = LinkStatus::kNoGeometry;
  bool from_visual = false;  // the spheres stand for the link's visual geometry
  int elements = 0;          // collision (or visual) elements of the link
  // kSpherized: the link's spheres in its own frame (metres), element by element in file
  // order, each element's in the generator's order. Never empty for kSpherized.
  std::vector<Sphere> spheres;
  // kSkipped: one line naming the element (by its line in the URDF) and the problem.
  std::string error;
  int generation_runs = 0;  // generation runs over all elements (budget searches make several)
  double seconds = 0.0;     // wall time for the link: reading, validation, generation
};

// Spherizes one link. Never fails as a whole: a problem with any element makes the link
// kSkipped (nothing of it is kept, so no geometry is silently lost) with the reason. An
// element whose mesh is not a usable closed solid (ValidateMesh's first error), has no
// spheres at the given voxel size, or needs a grid over MedialSphereOptions::max_voxels is
// such a problem. Sequential across elements; the generation itself is parallel (TBB).
LinkSpherizeResult SpherizeLink(const UrdfLink& link, const UrdfSpherizeOptions& options);

}  // namespace inscribe::robot
