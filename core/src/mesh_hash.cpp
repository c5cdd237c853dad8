#include "inscribe/mesh_hash.h"

#include <cstring>
#include <vector>

#include "inscribe/sha256.h"

namespace inscribe {
namespace {

constexpr char kMagic[16] = {'i', 'n', 's', 'c', 'r', 'i', 'b', 'e',
                             '.', 'm', 'e', 's', 'h', '.', 'v', '1'};

void AppendLittleEndian(std::vector<std::uint8_t>& out, std::uint64_t bits, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
}

}  // namespace

Sha256Digest MeshSha256(const Mesh& mesh) {
  Sha256Hasher hasher;

  std::vector<std::uint8_t> buffer(std::begin(kMagic), std::end(kMagic));
  AppendLittleEndian(buffer, static_cast<std::uint64_t>(mesh.num_vertices()), 8);
  AppendLittleEndian(buffer, static_cast<std::uint64_t>(mesh.num_triangles()), 8);
  hasher.Update(buffer.data(), buffer.size());

  // Stream in chunks so hashing a large mesh does not double its memory.
  constexpr std::size_t kChunk = 1 << 16;
  buffer.clear();
  buffer.reserve(kChunk + 64);
  auto flush = [&](bool force) {
    if (force || buffer.size() >= kChunk) {
      hasher.Update(buffer.data(), buffer.size());
      buffer.clear();
    }
  };
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    for (int k = 0; k < 3; ++k) {
      double x = mesh.vertices(v, k);
      if (x == 0.0) x = 0.0;  // canonical zero: -0.0 and +0.0 describe the same mesh
      std::uint64_t bits;
      std::memcpy(&bits, &x, sizeof bits);
      AppendLittleEndian(buffer, bits, 8);
    }
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

std::string FormatSha256(const Sha256Digest& digest) { return "sha256:" + HexDigits(digest); }

}  // namespace inscribe
