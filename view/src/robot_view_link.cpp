#include "inscribe/view/robot_view_link.h"

#include <algorithm>
#include <exception>
#include <limits>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/solid/solid.h"

namespace inscribe::view {
namespace {

// How far `sphere` reaches outside the ball `shape`: max(0, |c - c'| + r - r').
double ProtrusionFromBall(const Sphere& sphere, const Sphere& shape) {
  return std::max(0.0, (sphere.center - shape.center).norm() + sphere.radius - shape.radius);
}

void GrowBox(const Vector3& lo, const Vector3& hi, std::optional<BoundingBox>* box) {
  if (!box->has_value()) {
    *box = BoundingBox{lo, hi};
  } else {
    (*box)->min = (*box)->min.cwiseMin(lo);
    (*box)->max = (*box)->max.cwiseMax(hi);
  }
}

}  // namespace

RobotViewLink MakeRobotViewLink(const robot::UrdfLink& link, std::vector<Sphere> spheres,
                                const robot::UrdfSpherizeOptions& geometry) {
  RobotViewLink view;
  view.name = link.name;
  view.spheres = std::move(spheres);
  const std::size_t n = view.spheres.size();
  std::vector<double> least(n, std::numeric_limits<double>::infinity());
  bool measurable = !link.elements.empty();
  std::optional<BoundingBox> box;
  for (const robot::UrdfElement& element : link.elements) {
    const std::string where = robot::DescribeUrdfElement(element, link.from_visual);
    if (element.geometry.shape == robot::UrdfShape::kSphere) {
      const Sphere shape{element.origin.xyz, element.geometry.radius};
      view.shapes.push_back(shape);
      const Vector3 reach = Vector3::Constant(shape.radius);
      GrowBox(shape.center - reach, shape.center + reach, &box);
      for (std::size_t i = 0; i < n; ++i) {
        least[i] = std::min(least[i], ProtrusionFromBall(view.spheres[i], shape));
      }
      continue;
    }
    absl::StatusOr<Mesh> mesh = robot::ElementMeshInLinkFrame(element, geometry);
    if (!mesh.ok()) {
      view.problems.push_back(absl::StrCat(where, ": ", mesh.status().message()));
      measurable = false;
      continue;
    }
    const BoundingBox bounds = ComputeBoundingBox(mesh->vertices);
    GrowBox(bounds.min, bounds.max, &box);
    absl::StatusOr<Solid> solid;
    try {
      solid = PrepareSolid(*mesh);
    } catch (const std::exception& e) {  // CGAL giving up on hostile input
      solid = absl::InternalError(e.what());
    }
    if (!solid.ok()) {
      view.problems.push_back(absl::StrCat(where, ": not a closed solid, so the spheres' ",
                                           "protrusion is unknown: ", solid.status().message()));
      view.meshes.push_back(*std::move(mesh));
      measurable = false;
      continue;
    }
    const std::vector<double> out = SphereProtrusions(solid->oracle, view.spheres);
    for (std::size_t i = 0; i < n; ++i) least[i] = std::min(least[i], out[i]);
    view.meshes.push_back(solid->mesh());
  }
  if (box) view.protrusion_tolerance = 1e-9 * box->diagonal();
  if (n > 0 && link.elements.empty()) {
    view.problems.push_back("no geometry: the spheres' protrusion is unknown");
  }
  if (measurable) view.protrusion = std::move(least);
  return view;
}

}  // namespace inscribe::view
