// Spheres and sphere sets: what generation produces and every later stage (volume, quality,
// deformation, hierarchies, files, the service) consumes.
#pragma once

#include <cstdint>
#include <vector>

#include "inscribe/mesh.h"

namespace inscribe {

// A closed ball: centre in the mesh's frame and units, radius in mesh units (> 0 when valid).
struct Sphere {
  Vector3 center = Vector3::Zero();
  double radius = 0.0;
};

// Where an internal sphere touches the boundary: a point of triangle `triangle` given by
// barycentric weights of its corners 0, 1, 2 (sum 1). Deformation (Section V) moves a sphere
// with its contact.
struct SurfaceContact {
  std::int32_t triangle = -1;
  Vector3 barycentric = Vector3::Zero();
};

// Spheres with optional contacts: `contacts` is empty or has one entry per sphere, in order.
struct SphereSet {
  std::vector<Sphere> spheres;
  std::vector<SurfaceContact> contacts;

  std::size_t size() const { return spheres.size(); }
  bool has_contacts() const { return !contacts.empty(); }
};

}  // namespace inscribe
