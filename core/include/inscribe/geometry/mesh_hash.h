// Content hashes: of a mesh (the key under which sphere sets are cached) and of a list of
// spheres (what a cover certificate names as the spheres it proved).
#pragma once

#include <string>
#include <vector>

#include "inscribe/base/sha256.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

// SHA-256 over a canonical little-endian encoding of the mesh:
//   "inscribe.mesh.v1" (16 bytes), uint64 #V, uint64 #T,
//   #V x 3 IEEE-754 binary64 coordinates (with -0.0 written as +0.0), #T x 3 int32 indices.
// Equal arrays give equal digests on every platform; any change of a bit in a coordinate or an
// index changes it. Cost O(#V + #T).
Sha256Digest MeshSha256(const Mesh& mesh);

// SHA-256 over a canonical little-endian encoding of the spheres, in order:
//   "inscribe.spheres.v1" (19 bytes), uint64 #S,
//   #S x (x, y, z, r) IEEE-754 binary64 (with -0.0 written as +0.0).
// Any change of a bit in a coordinate or a radius, of the order or of the count changes it;
// contacts are not hashed. Cost O(#S).
Sha256Digest SpheresSha256(const std::vector<Sphere>& spheres);

// "sha256:" followed by 64 lowercase hex digits.
std::string FormatSha256(const Sha256Digest& digest);

}  // namespace inscribe
