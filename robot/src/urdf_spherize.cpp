#include "inscribe/robot/urdf_spherize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <exception>
#include <map>
#include <numeric>
#include <optional>
#include <queue>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "inscribe/cover/sphere_cover.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/mesh/mesh_clip.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/solid/solid.h"

namespace inscribe::robot {
namespace {

// An element ready for generation: a validated (clipped) solid, or a sphere kept as it is.
struct PreparedElement {
  int link = 0;                  // index in UrdfRobot::links
  int element = 0;               // index in the link's elements
  std::optional<Solid> solid;    // mesh elements
  std::optional<Sphere> sphere;  // <sphere> elements, in the link frame
  double volume = -1.0;          // of the mesh (m^3); -1 for a sphere
  double excess = 0.0;           // a cover's mesh beyond the true shape (curved primitives)
  std::int64_t budget = 0;       // budget modes
};

// The fit of curved primitives that `options.kind` needs: a cover must hold the true shape, an
// internal or dilated set must stay inside it.
PrimitiveFit FitFor(const UrdfSpherizeOptions& options) {
  return options.kind == SphereSetKind::kCover ? PrimitiveFit::kEnclosing : PrimitiveFit::kInside;
}

// How far a cover of ElementMeshInLinkFrame's mesh may protrude beyond the element's true
// shape beyond its certified delta: the enclosing mesh's own excess (0 for meshes and boxes,
// which are the shape).
double CoverExcess(const UrdfGeometry& geometry) {
  switch (geometry.shape) {
    case UrdfShape::kCylinder:
      return CylinderExcess(geometry.radius, PrimitiveFit::kEnclosing);
    case UrdfShape::kCapsule:
      return CapsuleExcess(geometry.radius, PrimitiveFit::kEnclosing);
    case UrdfShape::kEllipsoid:
      return EllipsoidExcess(geometry.size, PrimitiveFit::kEnclosing);
    default:
      return 0.0;
  }
}

// The element's geometry in its link frame, cut by the link's clip planes (unit normals).
// Nothing (no solid, no sphere) when it lies wholly beyond a plane.
absl::Status PrepareElement(const UrdfElement& element, const UrdfSpherizeOptions& options,
                            const RepairOptions& repair,
                            const std::vector<const ClipPlane*>& planes,
                            PreparedElement* prepared) {
  SolidOptions solid_options;
  solid_options.validate.repair = repair;
  if (element.geometry.shape == UrdfShape::kSphere) {
    const Sphere sphere{element.origin.xyz, element.geometry.radius};
    for (const ClipPlane* plane : planes) {
      if (plane->normal.dot(sphere.center) - sphere.radius >= plane->offset)
        return absl::OkStatus();
    }
    prepared->sphere = sphere;
    return absl::OkStatus();
  }
  absl::StatusOr<Mesh> mesh = ElementMeshInLinkFrame(element, options);
  if (!mesh.ok()) return mesh.status();
  if (!planes.empty()) {
    // Cutting needs a closed, consistently oriented mesh: validate (and repair) first.
    absl::StatusOr<ValidatedMesh> validated = PrepareMesh(*std::move(mesh), solid_options.validate);
    if (!validated.ok()) {
      return absl::FailedPreconditionError(
          absl::StrCat("the mesh is not a usable closed solid: ", validated.status().message()));
    }
    mesh = std::move(validated->mesh);
    for (const ClipPlane* plane : planes) {
      absl::StatusOr<Mesh> clipped = ClipMeshByPlane(*mesh, plane->normal, plane->offset);
      if (!clipped.ok()) return clipped.status();
      if (clipped->num_triangles() == 0) return absl::OkStatus();
      mesh = *std::move(clipped);
    }
  }
  // Once cut, the mesh is closed (the clip keeps it so): no repair beyond the safe one.
  if (!planes.empty()) solid_options.validate.repair.level = MeshRepair::kSafe;
  absl::StatusOr<Solid> solid = PrepareSolid(*std::move(mesh), solid_options);
  if (!solid.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the mesh is not a usable closed solid: ", solid.status().message()));
  }
  prepared->volume = solid->report.volume;
  if (options.kind == SphereSetKind::kCover) prepared->excess = CoverExcess(element.geometry);
  prepared->solid.emplace(*std::move(solid));
  return absl::OkStatus();
}

// What one element's generation gives: its spheres, cores (covers, internal sets) and delta.
struct ElementSpheres {
  std::vector<Sphere> spheres, cores;
  double delta = 0.0;
  int runs = 0;
  std::string short_reason;  // why fewer spheres than the budget, when so (the generator's)
};

absl::StatusOr<ElementSpheres> GenerateElement(const PreparedElement& element,
                                               const UrdfSpherizeOptions& options,
                                               const GenerationControl& control) {
  ElementSpheres out;
  if (element.sphere) {
    out.spheres = out.cores = {*element.sphere};
    return out;
  }
  const Solid& solid = *element.solid;
  if (options.kind == SphereSetKind::kCover) {
    CoverParameters parameters;
    parameters.certify.resolution = options.cover_resolution;
    if (options.max_protrusion) {
      parameters.max_protrusion = *options.max_protrusion - options.padding - element.excess;
    } else {
      parameters.max_spheres = element.budget;
    }
    // Made for its own budget (not the estimate's larger one): candidates and samples sized
    // for what it gets.
    absl::StatusOr<GeneratedCover> cover = GenerateCover(solid, parameters, control);
    if (!cover.ok()) return cover.status();
    absl::StatusOr<std::vector<Sphere>> cores =
        UpperBoundSpheres({}, cover->set.spheres, cover->certificate.protrusions);
    if (!cores.ok()) return cores.status();
    out.spheres = std::move(cover->set.spheres);
    // A core inside the enclosing mesh of a convex primitive, shrunk by the mesh's excess over
    // the shape, is inside the shape (the mesh lies within excess of it).
    for (Sphere core : *cores) {
      core.radius -= element.excess;
      if (core.radius > 0.0) out.cores.push_back(core);
    }
    out.delta = cover->certificate.delta + element.excess;
    out.runs = 1;
    out.short_reason = std::move(cover->unused_reason);
    return out;
  }
  SphereSetParameters parameters;
  parameters.kind = options.kind;
  parameters.medial = options.medial;
  parameters.dilation = options.dilation;
  if (options.voxel_size) {
    parameters.voxel_size = options.voxel_size;
  } else {
    parameters.max_spheres = element.budget;
  }
  parameters.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> result = GenerateSphereSet(solid, parameters, control);
  if (!result.ok()) return result.status();
  out.runs = result->runs;
  if (result->set.spheres.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("no sphere at voxel size ", result->voxel_size,
                     " m: the element is thinner than a voxel; give a smaller --voxel-size"));
  }
  out.spheres = std::move(result->set.spheres);
  if (options.kind == SphereSetKind::kInternal) out.cores = out.spheres;
  if (!options.voxel_size && static_cast<std::int64_t>(out.spheres.size()) < element.budget) {
    out.short_reason = result->selection == SphereSelection::kOptimised
                           ? absl::StrCat("the optimised selection found no more among its ",
                                          result->pool_size, " medial candidates")
                           : std::string("the finest voxel grid within the budget gives no more");
  }
  return out;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Budgets for the elements of the budget modes; an error message for a link whose budget is
// too small (keyed by link), or a status for the robot's.
absl::Status ShareBudgets(const UrdfRobot& robot, const UrdfSpherizeOptions& options,
                          std::deque<PreparedElement>& elements,
                          std::vector<LinkSpherizeResult>& results,
                          std::vector<double>& link_seconds, const GenerationControl& control) {
  // Per link: an override, or the per-link budget; the rest share the robot's.
  std::vector<std::vector<PreparedElement*>> by_link(robot.links.size());
  for (PreparedElement& e : elements) by_link[static_cast<std::size_t>(e.link)].push_back(&e);
  std::vector<PreparedElement*> pooled;
  std::int64_t pool = options.max_spheres.value_or(0);
  for (std::size_t l = 0; l < robot.links.size(); ++l) {
    if (by_link[l].empty() || results[l].status == LinkStatus::kSkipped) continue;
    std::optional<std::int64_t> own = options.max_spheres_per_link;
    if (const auto it = options.link_max_spheres.find(robot.links[l].name);
        it != options.link_max_spheres.end()) {
      own = it->second;
    }
    if (!own) {
      for (PreparedElement* e : by_link[l]) pooled.push_back(e);
      continue;
    }
    std::vector<double> volumes;
    for (const PreparedElement* e : by_link[l]) volumes.push_back(e->volume);
    const std::vector<std::int64_t> budgets = LinkSphereBudgets(*own, volumes);
    if (budgets.empty()) {
      results[l].status = LinkStatus::kSkipped;
      results[l].error = absl::StrCat("a budget of ", *own, " spheres is fewer than the link's ",
                                      by_link[l].size(), " elements (one sphere each at least)");
      continue;
    }
    for (std::size_t k = 0; k < budgets.size(); ++k) by_link[l][k]->budget = budgets[k];
    results[l].budget = *own;
  }
  if (!options.max_spheres) return absl::OkStatus();

  // The robot's budget: spheres take one each; meshes share the rest.
  std::vector<PreparedElement*> meshes;
  for (PreparedElement* e : pooled) {
    if (e->sphere) {
      e->budget = 1;
      --pool;
    } else {
      meshes.push_back(e);
    }
  }
  if (pool < static_cast<std::int64_t>(meshes.size())) {
    return absl::InvalidArgumentError(
        absl::StrCat("a robot budget of ", *options.max_spheres, " spheres is fewer than the ",
                     pooled.size(), " elements it is shared among (one sphere each at least)"));
  }
  std::vector<std::int64_t> budgets;
  if (options.kind == SphereSetKind::kCover) {
    // Each cover's estimated delta for every count it could get, then greedy marginal gain.
    const std::int64_t most = pool - static_cast<std::int64_t>(meshes.size()) + 1;
    std::vector<std::vector<double>> estimates;
    for (PreparedElement* e : meshes) {
      const auto start = std::chrono::steady_clock::now();
      CoverParameters parameters;
      parameters.certify.resolution = options.cover_resolution;
      parameters.max_spheres = most;
      absl::StatusOr<PreparedCover> cover = PreparedCover::Prepare(*e->solid, parameters, control);
      if (!cover.ok()) return cover.status();
      estimates.push_back(cover->EstimatedDeltas(most));
      link_seconds[static_cast<std::size_t>(e->link)] += Seconds(start);
    }
    budgets = RobotSphereBudgets(pool, estimates);
  } else {
    std::vector<double> volumes;
    for (const PreparedElement* e : meshes) volumes.push_back(e->volume);
    budgets = LinkSphereBudgets(pool, volumes);
  }
  for (std::size_t k = 0; k < meshes.size(); ++k) meshes[k]->budget = budgets[k];
  for (PreparedElement* e : pooled) results[static_cast<std::size_t>(e->link)].budget += e->budget;
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckUrdfSpherizeOptions(const UrdfSpherizeOptions& options) {
  const int modes = options.max_spheres.has_value() + options.max_spheres_per_link.has_value() +
                    options.max_protrusion.has_value() + options.voxel_size.has_value();
  if (modes > 1) {
    return absl::InvalidArgumentError(
        "give at most one of max_spheres (robot), max_spheres_per_link, max_protrusion and "
        "voxel_size");
  }
  const bool cover = options.kind == SphereSetKind::kCover;
  if (cover && options.voxel_size) {
    return absl::InvalidArgumentError(
        "covers take no voxel_size: give max_spheres, max_spheres_per_link or max_protrusion");
  }
  if (!cover && options.max_protrusion) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_protrusion is for covers; ", SphereSetKindName(options.kind),
                     " sets take max_spheres, max_spheres_per_link or voxel_size"));
  }
  const auto check_budget = [](const char* name, std::int64_t n) {
    if (n < 1 || n > kMaxRobotSpheres) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, " must lie in 1..", kMaxRobotSpheres, ", got ", n));
    }
    return absl::OkStatus();
  };
  const auto check_length = [](const char* name, std::optional<double> value) {
    if (value && !(std::isfinite(*value) && *value > 0.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, " must be a finite length > 0 (metres), got ", *value));
    }
    return absl::OkStatus();
  };
  if (options.max_spheres) {
    if (absl::Status s = check_budget("max_spheres", *options.max_spheres); !s.ok()) return s;
  }
  if (options.max_spheres_per_link) {
    if (absl::Status s = check_budget("max_spheres_per_link", *options.max_spheres_per_link);
        !s.ok()) {
      return s;
    }
  }
  for (const auto& [link, n] : options.link_max_spheres) {
    if (n == 0) continue;  // the link is left out
    if (absl::Status s = check_budget(absl::StrCat("the budget of link '", link, "'").c_str(), n);
        !s.ok()) {
      return s;
    }
  }
  // A budget of 0 (leave the link out) goes with every mode; other per-link budgets only with
  // the budget modes.
  const bool budgets = std::any_of(options.link_max_spheres.begin(), options.link_max_spheres.end(),
                                   [](const auto& entry) { return entry.second != 0; });
  if (budgets && (options.max_protrusion || options.voxel_size)) {
    return absl::InvalidArgumentError(
        "per-link budgets go with max_spheres or max_spheres_per_link, not with "
        "max_protrusion or voxel_size");
  }
  if (absl::Status s = check_length("max_protrusion", options.max_protrusion); !s.ok()) return s;
  if (absl::Status s = check_length("voxel_size", options.voxel_size); !s.ok()) return s;
  if (!std::isfinite(options.padding) || (cover && options.padding < 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("padding must be finite",
                     cover ? " and >= 0 for covers (a smaller cover would not hold the solid)" : "",
                     ", got ", options.padding));
  }
  if (options.max_protrusion && *options.max_protrusion <= options.padding) {
    return absl::InvalidArgumentError(absl::StrCat("max_protrusion ", *options.max_protrusion,
                                                   " leaves nothing beyond the padding ",
                                                   options.padding));
  }
  if (cover && !(options.cover_resolution > 0.0 && options.cover_resolution <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover_resolution must lie in (0, 1], got ", options.cover_resolution));
  }
  for (const ClipPlane& plane : options.clip_planes) {
    if (!plane.normal.allFinite() || !(plane.normal.norm() > 0.0) || !std::isfinite(plane.offset)) {
      return absl::InvalidArgumentError(
          absl::StrCat("the clip plane of link '", plane.link,
                       "' needs a non-zero finite normal and a finite offset"));
    }
  }
  return absl::OkStatus();
}

UrdfSpherizeOptions WithDefaultMode(UrdfSpherizeOptions options) {
  if (!options.max_spheres && !options.max_spheres_per_link && !options.max_protrusion &&
      !options.voxel_size) {
    options.max_spheres_per_link = kDefaultMaxSpheresPerLink;
  }
  return options;
}

std::vector<std::int64_t> RobotSphereBudgets(
    std::int64_t max_spheres, const std::vector<std::vector<double>>& estimated_deltas) {
  const std::size_t n = estimated_deltas.size();
  if (max_spheres < static_cast<std::int64_t>(n)) return {};
  std::vector<std::int64_t> budgets(n, 1);
  // (estimate at the current budget, -index): the largest estimate first, then the lower index.
  std::priority_queue<std::pair<double, std::int64_t>> queue;
  const auto push = [&](std::size_t e) {
    const std::vector<double>& curve = estimated_deltas[e];
    if (static_cast<std::size_t>(budgets[e]) < curve.size()) {
      queue.emplace(curve[static_cast<std::size_t>(budgets[e]) - 1], -static_cast<std::int64_t>(e));
    }
  };
  for (std::size_t e = 0; e < n; ++e) push(e);
  for (std::int64_t left = max_spheres - static_cast<std::int64_t>(n); left > 0 && !queue.empty();
       --left) {
    const auto e = static_cast<std::size_t>(-queue.top().second);
    queue.pop();
    ++budgets[e];
    push(e);
  }
  return budgets;
}

absl::StatusOr<RobotSpherizeResult> SpherizeRobot(const UrdfRobot& robot,
                                                  const UrdfSpherizeOptions& given,
                                                  const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckUrdfSpherizeOptions(given); !s.ok()) return s;
  const UrdfSpherizeOptions options = WithDefaultMode(given);
  std::map<std::string, int> link_index;
  for (std::size_t l = 0; l < robot.links.size(); ++l) {
    link_index.emplace(robot.links[l].name, static_cast<int>(l));
  }
  std::vector<std::vector<const ClipPlane*>> planes(robot.links.size());
  std::vector<ClipPlane> unit_planes = options.clip_planes;
  for (ClipPlane& plane : unit_planes) {
    const auto it = link_index.find(plane.link);
    if (it == link_index.end()) {
      return absl::InvalidArgumentError(absl::StrCat("a clip plane names link '", plane.link,
                                                     "', which the robot does not have"));
    }
    const double norm = plane.normal.norm();
    plane.normal /= norm;
    plane.offset /= norm;
    planes[static_cast<std::size_t>(it->second)].push_back(&plane);
  }
  for (const auto& [link, n] : options.link_max_spheres) {
    if (link_index.count(link) == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("a per-link budget names link '", link, "', which the robot does not have"));
    }
  }
  for (const auto& [link, repair] : options.link_repair) {
    if (link_index.count(link) == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("a per-link repair names link '", link, "', which the robot does not have"));
    }
  }

  RobotSpherizeResult out;
  out.links.resize(robot.links.size());
  std::vector<double> link_seconds(robot.links.size(), 0.0);
  std::deque<PreparedElement> elements;  // stable addresses: budgets point at them
  for (std::size_t l = 0; l < robot.links.size(); ++l) {
    const UrdfLink& link = robot.links[l];
    LinkSpherizeResult& result = out.links[l];
    result.link = link.name;
    result.kind = options.kind;
    result.from_visual = link.from_visual;
    result.elements = static_cast<int>(link.elements.size());
    const auto link_start = std::chrono::steady_clock::now();
    const std::size_t first = elements.size();
    if (const auto budget = options.link_max_spheres.find(link.name);
        budget != options.link_max_spheres.end() && budget->second == 0) {
      result.status = LinkStatus::kSkipped;
      result.error = "left out: its budget is 0 (--link-max-spheres)";
      continue;
    }
    for (std::size_t k = 0; k < link.elements.size(); ++k) {
      if (control.cancelled()) return absl::CancelledError("robot spherization cancelled");
      PreparedElement prepared;
      prepared.link = static_cast<int>(l);
      prepared.element = static_cast<int>(k);
      absl::Status status;
      try {
        const auto own = options.link_repair.find(link.name);
        status = PrepareElement(link.elements[k], options,
                                own == options.link_repair.end() ? options.repair : own->second,
                                planes[l], &prepared);
      } catch (const std::exception& e) {
        // CGAL or an allocation giving up on hostile input: this link's problem, not the run's.
        status = absl::InternalError(absl::StrCat("internal error while preparing: ", e.what()));
      }
      if (!status.ok()) {
        result.status = LinkStatus::kSkipped;
        result.error = absl::StrCat(DescribeUrdfElement(link.elements[k], link.from_visual), ": ",
                                    status.message());
        elements.resize(first);
        break;
      }
      if (prepared.solid) {
        for (const MeshIssue& issue : prepared.solid->report.notices()) {
          result.warnings.push_back(
              absl::StrCat(DescribeUrdfElement(link.elements[k], link.from_visual), ": ",
                           SeverityName(issue.severity), ": ", issue.message));
        }
      }
      if (prepared.solid || prepared.sphere) elements.push_back(std::move(prepared));
    }
    if (result.status != LinkStatus::kSkipped && elements.size() > first) {
      result.status = LinkStatus::kSpherized;
    }
    if (result.status == LinkStatus::kNoGeometry && !link.elements.empty()) {
      result.error = "all of its geometry lies beyond its clip planes";
    }
    link_seconds[l] += Seconds(link_start);
  }

  if (options.max_spheres || options.max_spheres_per_link) {
    if (absl::Status s = ShareBudgets(robot, options, elements, out.links, link_seconds, control);
        !s.ok()) {
      return s;
    }
  }

  for (const PreparedElement& element : elements) {
    LinkSpherizeResult& result = out.links[static_cast<std::size_t>(element.link)];
    if (result.status != LinkStatus::kSpherized) continue;
    if (control.cancelled()) return absl::CancelledError("robot spherization cancelled");
    const auto element_start = std::chrono::steady_clock::now();
    absl::StatusOr<ElementSpheres> generated;
    try {
      generated = GenerateElement(element, options, control);
    } catch (const std::exception& e) {
      generated = absl::InternalError(absl::StrCat("internal error while spherizing: ", e.what()));
    }
    link_seconds[static_cast<std::size_t>(element.link)] += Seconds(element_start);
    if (!generated.ok()) {
      if (generated.status().code() == absl::StatusCode::kCancelled) return generated.status();
      const UrdfLink& link = robot.links[static_cast<std::size_t>(element.link)];
      result.status = LinkStatus::kSkipped;
      result.error =
          absl::StrCat(DescribeUrdfElement(link.elements[static_cast<std::size_t>(element.element)],
                                           link.from_visual),
                       ": ", generated.status().message());
      result.spheres.clear();
      result.cores.clear();
      result.delta.reset();
      continue;
    }
    result.generation_runs += generated->runs;
    if (element.budget > 0 && !generated->short_reason.empty() &&
        static_cast<std::int64_t>(generated->spheres.size()) < element.budget) {
      const UrdfLink& link = robot.links[static_cast<std::size_t>(element.link)];
      result.warnings.push_back(
          absl::StrCat(DescribeUrdfElement(link.elements[static_cast<std::size_t>(element.element)],
                                           link.from_visual),
                       ": ", generated->spheres.size(), " of its budget of ", element.budget,
                       " spheres: ", generated->short_reason));
    }
    for (Sphere sphere : generated->spheres) {
      sphere.radius += options.padding;
      result.spheres.push_back(sphere);
    }
    result.cores.insert(result.cores.end(), generated->cores.begin(), generated->cores.end());
    if (options.kind == SphereSetKind::kCover) {
      result.delta = std::max(result.delta.value_or(0.0), generated->delta + options.padding);
    }
  }
  for (std::size_t l = 0; l < out.links.size(); ++l) {
    LinkSpherizeResult& result = out.links[l];
    result.seconds = link_seconds[l];
    if (result.status != LinkStatus::kSpherized) continue;
    const auto thin = std::find_if(result.spheres.begin(), result.spheres.end(),
                                   [](const Sphere& s) { return !(s.radius > 0.0); });
    if (thin != result.spheres.end()) {
      result.status = LinkStatus::kSkipped;
      result.error = absl::StrCat("padding ", options.padding,
                                  " leaves a sphere with radius <= 0 (its radius was ",
                                  thin->radius - options.padding, ")");
      result.spheres.clear();
      result.cores.clear();
    }
  }
  out.seconds = Seconds(start);
  return out;
}

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
      mesh = CylinderMesh(geometry.radius, geometry.length, kCylinderSides, FitFor(options));
      break;
    case UrdfShape::kCapsule:
      mesh = CapsuleMesh(geometry.radius, geometry.length, kCylinderSides, kQuarterBands,
                         FitFor(options));
      break;
    case UrdfShape::kEllipsoid:
      mesh = EllipsoidMesh(geometry.size, kCylinderSides, kQuarterBands, FitFor(options));
      break;
    case UrdfShape::kSphere:
      return absl::InvalidArgumentError("a <sphere> is kept as it is; it has no mesh");
    case UrdfShape::kUnsupported:
      return absl::InvalidArgumentError(
          geometry.unsupported.empty()
              ? std::string("no geometry (an empty or missing <geometry>)")
              : absl::StrCat("<", geometry.unsupported,
                             "> is not URDF geometry inscribe can spherize (mesh, box, "
                             "cylinder, sphere, capsule)"));
  }
  return TransformMesh(std::move(mesh), scale, OriginRotation(element.origin), element.origin.xyz);
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

}  // namespace inscribe::robot
