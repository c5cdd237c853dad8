// Spherizing a robot: each link's collision geometry (its visual geometry when it has none)
// brought into the link's frame and approximated by spheres: certified covers by default
// (they hold the link's solid, reaching at most a certified delta past it), internal medial
// spheres or dilated ones on request.
//
// Elements are spherized one by one and their spheres concatenated, rather than their meshes
// merged into one: each element's spheres then follow its own shape, and a budget is spent
// where each element needs it. A budget is shared out among elements (a whole robot's
// among all its links' elements: RobotSphereBudgets; a link's among its own: LinkSphereBudgets).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_dilation.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::robot {

// The per-link sphere budget when no mode is given (`inscribe urdf` and the Python bindings).
inline constexpr std::int64_t kDefaultMaxSpheresPerLink = 32;
// Largest budget a robot or a link may ask for.
inline constexpr std::int64_t kMaxRobotSpheres = 1'000'000;

// A plane in a link's frame: what lies on its far side ({x : normal . x > offset}) is cut off
// the link's meshes before they are spherized (e.g. the table a base is mounted on), so the
// spheres (and a cover's certificate) are about the part kept. <sphere> elements are kept
// whole unless wholly beyond the plane.
struct ClipPlane {
  std::string link;
  Vector3 normal = Vector3::UnitZ();  // non-zero; normalised by the spherizer
  double offset = 0.0;                // metres along the unit normal
};

struct UrdfSpherizeOptions {
  SphereSetKind kind = SphereSetKind::kCover;
  // At most one mode. max_spheres: for the whole robot, shared among links (RobotSphereBudgets);
  // max_spheres_per_link: each link at most N; max_protrusion (covers): every link's delta at
  // most D metres (padding included) with the fewest spheres; voxel_size (internal, dilated):
  // sigma in metres for every element. None: max_spheres_per_link = kDefaultMaxSpheresPerLink.
  std::optional<std::int64_t> max_spheres;
  std::optional<std::int64_t> max_spheres_per_link;
  std::optional<double> max_protrusion;
  std::optional<double> voxel_size;
  // In the budget modes: these links (by name) get exactly their own budget, outside the
  // robot's shared one; 0 leaves the link out (a static base), said in its result.
  std::map<std::string, std::int64_t> link_max_spheres;
  // How each element's mesh may be repaired (core's RepairOptions, default safe), and per link
  // (by name) instead.
  RepairOptions repair;
  std::map<std::string, RepairOptions> link_repair;
  // Added to every radius (metres), as planners' collision buffers: a cover stays a cover
  // with delta + padding. Covers: >= 0; internal and dilated sets: any value leaving every
  // radius positive.
  double padding = 0.0;
  std::vector<ClipPlane> clip_planes;
  // The generation's other settings (voxel_size in `medial` is ignored).
  MedialSphereOptions medial;
  DilationOptions dilation;
  double cover_resolution = CoverCertifyOptions{}.resolution;
  // Where package:// URIs are looked for, and the directory relative paths start from (the
  // URDF file's).
  PackageSearch packages;
  std::string urdf_dir;
};

// OK, or INVALID_ARGUMENT naming the first problem: two modes, a mode the kind does not take
// (voxel_size for covers, max_protrusion for the others), a budget outside 1..kMaxRobotSpheres,
// a length that is not finite and positive, negative padding on covers, a clip plane with a
// zero or non-finite normal or offset. Links named by overrides and clip planes are checked
// against the robot by SpherizeRobot. O(#overrides + #planes).
absl::Status CheckUrdfSpherizeOptions(const UrdfSpherizeOptions& options);

// `options` with the default mode filled in when none is given (max_spheres_per_link =
// kDefaultMaxSpheresPerLink): what SpherizeRobot runs and reports. O(1).
UrdfSpherizeOptions WithDefaultMode(UrdfSpherizeOptions options);

// An element's geometry as a closed mesh in its LINK's frame: for a <mesh>, the file scaled
// per axis (mirrored, with the triangles turned to keep them outward, when the scale has an odd
// number of negative components) and then moved by the element's origin, p -> R (s . p) + xyz
// (R = OriginRotation); for boxes, cylinders, capsules and ellipsoids, BoxMesh, CylinderMesh,
// CapsuleMesh and EllipsoidMesh moved by the origin, the curved ones enclosing the true shape
// for covers (options.kind; a link's delta then adds the mesh's excess over the shape) and
// inside it otherwise (PrimitiveFit). Metres.
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
  kNoGeometry,  // no <collision> and no <visual> (or all of it clipped away): nothing to do
};

const char* LinkStatusName(LinkStatus status);  // "spherized", "skipped", "no_geometry"

struct LinkSpherizeResult {
  std::string link;
  LinkStatus status = LinkStatus::kNoGeometry;
  SphereSetKind kind = SphereSetKind::kCover;
  bool from_visual = false;  // the spheres stand for the link's visual geometry
  int elements = 0;          // collision (or visual) elements of the link
  // kSpherized: the link's spheres in its own frame (metres), padding included, element by
  // element in file order, each element's in the generator's order. Never empty.
  std::vector<Sphere> spheres;
  // kSpherized covers: the spheres hold the link's (clipped) solid and reach at most `delta`
  // past it (padding included; certified); `cores` are balls inside the solid (the covers'
  // cores, core's UpperBoundSpheres), for certified distance intervals. Internal sets: no
  // delta, and `cores` are the spheres before padding (inside the solid). Dilated: neither.
  std::optional<double> delta;
  std::vector<Sphere> cores;
  std::int64_t budget = 0;  // spheres the link was given (budget modes; 0 otherwise)
  // kSkipped: one line naming the element (by its line in the URDF) and the problem.
  std::string error;
  // Every validation warning and fix of the link's meshes (MeshReport::notices), one line each
  // naming the element, as `error` does.
  std::vector<std::string> warnings;
  int generation_runs = 0;  // generation runs over all elements (budget searches make several)
  double seconds = 0.0;     // wall time for the link: reading, validation, generation
};

struct RobotSpherizeResult {
  std::vector<LinkSpherizeResult> links;  // one per UrdfRobot::links entry, same order
  double seconds = 0.0;
};

// Spherizes every link. Fails as a whole only for bad options (CheckUrdfSpherizeOptions, an
// override or clip plane naming no link: INVALID_ARGUMENT), a robot budget smaller than its
// elements (INVALID_ARGUMENT) and cancellation (CANCELLED). Otherwise a problem with any
// element makes its link kSkipped (nothing of it is kept, so no geometry is silently lost)
// with the reason: a mesh that is not a usable closed solid (ValidateMesh's first error), no
// spheres at the given voxel size, a grid over MedialSphereOptions::max_voxels, no certified
// cover within max_protrusion. Deterministic; the generation is parallel (TBB).
absl::StatusOr<RobotSpherizeResult> SpherizeRobot(const UrdfRobot& robot,
                                                  const UrdfSpherizeOptions& options,
                                                  const GenerationControl& control = {});

// Shares a robot's budget of N spheres among mesh elements by greedy marginal gain: every
// element starts with one sphere, and each further sphere goes to the element whose estimated
// delta is then the largest (ties: the lower index), so the largest estimated error falls
// fastest. estimated_deltas[e][k-1]: element e's estimate with k spheres (non-increasing; see
// PreparedCover::EstimatedDeltas; an element's budget stops growing at its list's length).
// Empty when N is fewer than the elements. O(N log #elements).
std::vector<std::int64_t> RobotSphereBudgets(
    std::int64_t max_spheres, const std::vector<std::vector<double>>& estimated_deltas);

}  // namespace inscribe::robot
