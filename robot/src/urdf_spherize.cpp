#include "inscribe/robot/urdf_spherize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <numeric>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "inscribe/mesh_io.h"
#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/solid.h"
#include "inscribe/sphere_set_generation.h"

namespace inscribe::robot {
namespace {

// An element ready for generation: a validated solid, or a sphere kept as it is.
struct PreparedElement {
  std::optional<Solid> solid;    // mesh elements
  std::optional<Sphere> sphere;  // <sphere> elements, in the link frame
  double volume = -1.0;          // of the mesh (m^3); -1 for a sphere
};

// "line 12 (<collision> 'tool')", to start a skipped link's reason.
std::string DescribeElement(const UrdfElement& element, bool from_visual) {
  std::string text =
      absl::StrCat("line ", element.line, " (<", from_visual ? "visual" : "collision", ">");
  if (!element.name.empty()) absl::StrAppend(&text, " '", element.name, "'");
  return text + ")";
}

absl::StatusOr<PreparedElement> PrepareElement(const UrdfElement& element,
                                               const UrdfSpherizeOptions& options) {
  PreparedElement prepared;
  if (element.geometry.shape == UrdfShape::kSphere) {
    prepared.sphere = Sphere{element.origin.xyz, element.geometry.radius};
    return prepared;
  }
  absl::StatusOr<Mesh> mesh = ElementMeshInLinkFrame(element, options);
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<Solid> solid = PrepareSolid(*std::move(mesh));
  if (!solid.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the mesh is not a usable closed solid: ", solid.status().message()));
  }
  prepared.volume = solid->report.volume;
  prepared.solid.emplace(*std::move(solid));
  return prepared;
}

// The spheres of one validated mesh element: a fixed voxel size, or the finest grid within
// `budget` spheres. Adds the generation runs to *runs.
absl::StatusOr<std::vector<Sphere>> GenerateElement(const Solid& solid,
                                                    const UrdfSpherizeOptions& options,
                                                    std::int64_t budget, int* runs) {
  SphereSetParameters parameters;
  parameters.medial = options.medial;
  if (options.voxel_size > 0.0) {
    parameters.voxel_size = options.voxel_size;
  } else {
    parameters.max_spheres = budget;
  }
  parameters.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> result = GenerateSphereSet(solid, parameters);
  if (!result.ok()) return result.status();
  *runs += result->runs;
  if (result->set.spheres.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("no sphere at voxel size ", result->voxel_size,
                     " m: the element is thinner than a voxel; give a smaller --voxel-size"));
  }
  return std::move(result->set.spheres);
}

// SpherizeLink without the timing and the exception guard.
void SpherizeElements(const UrdfLink& link, const UrdfSpherizeOptions& options,
                      LinkSpherizeResult* result) {
  const auto skip = [&](const UrdfElement& element, absl::string_view why) {
    result->status = LinkStatus::kSkipped;
    result->error = absl::StrCat(DescribeElement(element, link.from_visual), ": ", why);
  };
  std::vector<PreparedElement> prepared;
  std::vector<double> volumes;
  for (const UrdfElement& element : link.elements) {
    absl::StatusOr<PreparedElement> ready = PrepareElement(element, options);
    if (!ready.ok()) return skip(element, ready.status().message());
    volumes.push_back(ready->volume);
    prepared.push_back(*std::move(ready));
  }
  std::vector<std::int64_t> budgets(prepared.size(), 0);
  if (options.voxel_size <= 0.0) {
    budgets = LinkSphereBudgets(options.max_spheres_per_link, volumes);
    if (budgets.empty()) {
      result->status = LinkStatus::kSkipped;
      result->error = absl::StrCat("--max-spheres-per-link ", options.max_spheres_per_link,
                                   " is fewer than the link's ", prepared.size(),
                                   " elements (one sphere each at least)");
      return;
    }
  }
  std::vector<Sphere> spheres;
  for (std::size_t i = 0; i < prepared.size(); ++i) {
    if (prepared[i].sphere) {
      spheres.push_back(*prepared[i].sphere);
      continue;
    }
    absl::StatusOr<std::vector<Sphere>> generated =
        GenerateElement(*prepared[i].solid, options, budgets[i], &result->generation_runs);
    if (!generated.ok()) return skip(link.elements[i], generated.status().message());
    spheres.insert(spheres.end(), generated->begin(), generated->end());
  }
  result->status = LinkStatus::kSpherized;
  result->spheres = std::move(spheres);
}

}  // namespace

Mesh TransformMesh(Mesh mesh, const Vector3& scale, const Eigen::Matrix3d& rotation,
                   const Vector3& translation) {
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Vector3 scaled = scale.cwiseProduct(Vector3(mesh.vertices.row(i).transpose()));
    mesh.vertices.row(i) = (rotation * scaled + translation).transpose();
  }
  // An odd number of negative scale factors is a reflection: it turns every triangle inside
  // out, which swapping two corners undoes.
  if (scale.x() * scale.y() * scale.z() < 0.0) mesh.triangles.col(1).swap(mesh.triangles.col(2));
  return mesh;
}

absl::StatusOr<Mesh> ElementMeshInLinkFrame(const UrdfElement& element,
                                            const UrdfSpherizeOptions& options) {
  const UrdfGeometry& geometry = element.geometry;
  Mesh mesh;
  Vector3 scale = Vector3::Ones();
  switch (geometry.shape) {
    case UrdfShape::kMesh: {
      absl::StatusOr<std::string> path =
          ResolveMeshFilename(geometry.filename, options.urdf_dir, options.packages);
      if (!path.ok()) return path.status();
      absl::StatusOr<Mesh> read = ReadMesh(*path);
      if (!read.ok()) return read.status();
      mesh = *std::move(read);
      scale = geometry.scale;
      break;
    }
    case UrdfShape::kBox:
      mesh = BoxMesh(geometry.size);
      break;
    case UrdfShape::kCylinder:
      mesh = CylinderMesh(geometry.radius, geometry.length);
      break;
    case UrdfShape::kSphere:
      return absl::InvalidArgumentError("a <sphere> is kept as it is; it has no mesh");
    case UrdfShape::kUnsupported:
      return absl::InvalidArgumentError(
          geometry.unsupported.empty()
              ? std::string("no geometry (an empty or missing <geometry>)")
              : absl::StrCat("<", geometry.unsupported,
                             "> is not URDF geometry inscribe can spherize (mesh, box, "
                             "cylinder, sphere)"));
  }
  return TransformMesh(std::move(mesh), scale, RotationFromRpy(element.origin.rpy),
                       element.origin.xyz);
}

std::vector<std::int64_t> LinkSphereBudgets(std::int64_t max_spheres,
                                            const std::vector<double>& volumes) {
  const std::int64_t spheres =
      std::count_if(volumes.begin(), volumes.end(), [](double volume) { return volume < 0.0; });
  const std::int64_t meshes = static_cast<std::int64_t>(volumes.size()) - spheres;
  const std::int64_t extra = max_spheres - spheres - meshes;  // beyond one per element
  if (extra < 0) return {};
  std::vector<std::int64_t> budgets(volumes.size(), 1);
  double total = 0.0;
  for (double volume : volumes) total += std::max(volume, 0.0);
  // Each mesh's exact share of the extra spheres (equal shares if the volumes say nothing),
  // rounded down, then the leftovers to the largest remainders (ties: file order).
  std::vector<std::pair<double, std::size_t>> remainders;
  std::int64_t given = 0;
  for (std::size_t i = 0; i < volumes.size(); ++i) {
    if (volumes[i] < 0.0) continue;
    const double share = total > 0.0 && std::isfinite(total)
                             ? static_cast<double>(extra) * (volumes[i] / total)
                             : static_cast<double>(extra) / static_cast<double>(meshes);
    const auto whole = static_cast<std::int64_t>(std::floor(share));
    budgets[i] += whole;
    given += whole;
    remainders.emplace_back(share - static_cast<double>(whole), i);
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; given < extra && k < remainders.size(); ++k, ++given) {
    budgets[remainders[k].second] += 1;
  }
  return budgets;
}

const char* LinkStatusName(LinkStatus status) {
  switch (status) {
    case LinkStatus::kSpherized:
      return "spherized";
    case LinkStatus::kSkipped:
      return "skipped";
    case LinkStatus::kNoGeometry:
      return "no_geometry";
  }
  return "unknown";
}

LinkSpherizeResult SpherizeLink(const UrdfLink& link, const UrdfSpherizeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LinkSpherizeResult result;
  result.link = link.name;
  result.from_visual = link.from_visual;
  result.elements = static_cast<int>(link.elements.size());
  if (!link.elements.empty()) {
    try {
      SpherizeElements(link, options, &result);
    } catch (const std::exception& e) {
      // CGAL or an allocation giving up on hostile input: this link's problem, not the run's.
      result.status = LinkStatus::kSkipped;
      result.spheres.clear();
      result.error = absl::StrCat("internal error while spherizing: ", e.what());
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace inscribe::robot
