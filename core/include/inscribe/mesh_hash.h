// Content hash of a mesh: the key under which sphere sets are cached.
#pragma once

#include <string>

#include "inscribe/mesh.h"
#include "inscribe/sha256.h"

namespace inscribe {

// SHA-256 over a canonical little-endian encoding of the mesh:
//   "inscribe.mesh.v1" (16 bytes), uint64 #V, uint64 #T,
//   #V x 3 IEEE-754 binary64 coordinates (with -0.0 written as +0.0), #T x 3 int32 indices.
// Equal arrays give equal digests on every platform; any change of a bit in a coordinate or an
// index changes it. Cost O(#V + #T).
Sha256Digest MeshSha256(const Mesh& mesh);

// "sha256:" followed by 64 lowercase hex digits.
std::string FormatSha256(const Sha256Digest& digest);

}  // namespace inscribe
