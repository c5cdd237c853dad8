// One link as the robot page shows it: its geometry in its own frame (the link's collision
// elements, or its visual ones when it has none: what `inscribe urdf` spherizes), the spheres
// of the sphere file for it, and how far each sphere reaches outside the link's solid.
#pragma once

#include <string>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::view {

struct RobotViewLink {
  std::string name;
  // Mesh, box and cylinder elements as triangle meshes in the link frame (metres), oriented
  // outward when they are closed solids (ElementMeshInLinkFrame, then ValidateMesh).
  std::vector<Mesh> meshes;
  // <sphere> elements, link frame.
  std::vector<Sphere> shapes;
  // One line per element that could not be read or measured against ("line 12 (<collision>):
  // mesh 'x.dae' is Collada ..."), and why protrusion is unknown when it is.
  std::vector<std::string> problems;
  // The sphere file's spheres for this link, link frame, metres.
  std::vector<Sphere> spheres;
  // Per sphere: how far it reaches outside the link's solid, max(0, r + signed distance of
  // its centre) (SphereProtrusions), metres. With several elements, the least over them: at
  // least the distance it reaches outside their union. Empty when it cannot be known (an
  // element that cannot be read or is not a closed solid, or a link without geometry: see
  // problems).
  std::vector<double> protrusion;
  // Spheres reaching further out than this protrude: 1e-9 of the diagonal of the link's
  // geometry's bounding box (core's default for exact-distance rounding).
  double protrusion_tolerance = 0.0;
};

// The link's geometry through `geometry.packages` and `geometry.urdf_dir` (the rest of the
// options is not used) and the protrusion of `spheres`. Never fails: problems are recorded.
// Cost: reading and validating every element's mesh, O(T log T), plus one closest-point query
// per sphere and element.
RobotViewLink MakeRobotViewLink(const robot::UrdfLink& link, std::vector<Sphere> spheres,
                                const robot::UrdfSpherizeOptions& geometry);

}  // namespace inscribe::view
