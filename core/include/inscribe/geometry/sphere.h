// Spheres and sphere sets: what generation produces and every later stage (volume, quality,
// deformation, hierarchies, files, the service) consumes.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "inscribe/geometry/mesh.h"

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

// The one validity rule for a sphere every stage accepts: a finite centre and a finite radius
// > 0. OK, or INVALID_ARGUMENT naming the sphere and the first bad number ("sphere 3: center y
// nan is not finite", "sphere 3: radius -1 is not positive"). O(1).
absl::Status CheckSphere(const Sphere& sphere, std::size_t index);

// CheckSphere for every sphere, in order; the first failure. O(n).
absl::Status CheckSpheres(const std::vector<Sphere>& spheres);

}  // namespace inscribe
