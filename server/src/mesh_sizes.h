// The sizes of the meshes stored through this process, so that a Generate's grid and memory can
// be estimated on the gRPC thread from the mesh key alone (the cache itself may have to read
// disk or Redis to answer). Private to the server.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

#include "inscribe/geometry/mesh.h"

namespace inscribe::server {

struct MeshSize {
  std::int64_t vertices = 0;
  std::int64_t triangles = 0;
  Vector3 extent = Vector3::Zero();  // bounding-box extent, mesh units

  // Voxels of the generation grid of side `voxel_size` over the bounding box, as core's
  // MakeGrid counts them (at least one cell per axis), in double so that a tiny voxel size
  // cannot overflow. O(1).
  double GridVoxels(double voxel_size) const {
    double total = 1.0;
    for (int axis = 0; axis < 3; ++axis)
      total *= std::max(1.0, std::ceil(extent[axis] / voxel_size));
    return total;
  }
};

// Thread-safe; lookups are one hash of the key under a lock. At most kMaxEntries meshes are
// remembered (~150 B each); when full the table starts over, and a forgotten mesh's size is
// learnt again on the pool the next time it is used.
class MeshSizes {
 public:
  static constexpr std::size_t kMaxEntries = 1 << 16;

  void Record(const std::string& key, const MeshSize& size) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sizes_.size() >= kMaxEntries && sizes_.find(key) == sizes_.end()) sizes_.clear();
    sizes_[key] = size;
  }

  std::optional<MeshSize> Find(const std::string& key) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = sizes_.find(key);
    if (it == sizes_.end()) return std::nullopt;
    return it->second;
  }

 private:
  mutable std::mutex mutex_;
  std::unordered_map<std::string, MeshSize> sizes_;  // guarded by mutex_
};

}  // namespace inscribe::server
