#include "inscribe/geometry/mesh_hash.h"

#include <cstring>
#include <vector>

#include "inscribe/base/sha256.h"

namespace inscribe {
namespace {

constexpr char kMagic[16] = {'i', 'n', 's', 'c', 'r', 'i', 'b', 'e',
                             '.', 'm', 'e', 's', 'h', '.', 'v', '1'};
constexpr char kSpheresMagic[] = "inscribe.spheres.v1";  // 19 bytes and the NUL, not hashed

// Stream in chunks so hashing a large input does not double its memory.
constexpr std::size_t kChunk = 1 << 16;

void AppendLittleEndian(std::vector<std::uint8_t>& out, std::uint64_t bits, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
}

// The bits of `x`, with -0.0 as +0.0 (both describe the same geometry).
void AppendCanonicalDouble(std::vector<std::uint8_t>& out, double x) {
  if (x == 0.0) x = 0.0;
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  AppendLittleEndian(out, bits, 8);
}

}  // namespace

Sha256Digest MeshSha256(const Mesh& mesh) {
  Sha256Hasher hasher;

  std::vector<std::uint8_t> buffer(std::begin(kMagic), std::end(kMagic));
  AppendLittleEndian(buffer, static_cast<std::uint64_t>(mesh.num_vertices()), 8);
  AppendLittleEndian(buffer, static_cast<std::uint64_t>(mesh.num_triangles()), 8);
  hasher.Update(buffer.data(), buffer.size());

  buffer.clear();
  buffer.reserve(kChunk + 64);
  auto flush = [&](bool force) {
    if (force || buffer.size() >= kChunk) {
      hasher.Update(buffer.data(), buffer.size());
      buffer.clear();
    }
  };
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    for (int k = 0; k < 3; ++k) AppendCanonicalDouble(buffer, mesh.vertices(v, k));
    flush(false);
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      AppendLittleEndian(buffer, static_cast<std::uint32_t>(mesh.triangles(t, k)), 4);
    }
    flush(false);
  }
  flush(true);

  return hasher.Finish();
}

Sha256Digest SpheresSha256(const std::vector<Sphere>& spheres) {
  Sha256Hasher hasher;
  std::vector<std::uint8_t> buffer(kSpheresMagic, kSpheresMagic + sizeof kSpheresMagic - 1);
  AppendLittleEndian(buffer, static_cast<std::uint64_t>(spheres.size()), 8);
  buffer.reserve(kChunk + 64);
  for (const Sphere& s : spheres) {
    for (int k = 0; k < 3; ++k) AppendCanonicalDouble(buffer, s.center[k]);
    AppendCanonicalDouble(buffer, s.radius);
    if (buffer.size() >= kChunk) {
      hasher.Update(buffer.data(), buffer.size());
      buffer.clear();
    }
  }
  hasher.Update(buffer.data(), buffer.size());
  return hasher.Finish();
}

std::string FormatSha256(const Sha256Digest& digest) { return "sha256:" + HexDigits(digest); }

}  // namespace inscribe
