// The sizes of the meshes stored through this process, so that a Generate's grid and memory can
// be estimated on the gRPC thread from the mesh key alone (the cache itself may have to read
// disk or Redis to answer). Private to the server.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

#include "inscribe/geometry/mesh.h"
#include "inscribe/medial/voxel_grid_cells.h"

namespace inscribe::server {

struct MeshSize {
  std::int64_t vertices = 0;
  std::int64_t triangles = 0;
  Vector3 extent = Vector3::Zero();  // bounding-box extent, mesh units

  // The size of `mesh`. O(#V).
  static MeshSize Of(const Mesh& mesh) {
    return MeshSize{mesh.num_vertices(), mesh.num_triangles(),
                    ComputeBoundingBox(mesh.vertices).extent()};
  }

  // Voxels of the generation grid of side `voxel_size` over the bounding box (core's
  // VoxelGridCells), in double so that a tiny voxel size cannot overflow. O(1).
  double GridVoxels(double voxel_size) const { return VoxelGridCells(extent, voxel_size).prod(); }
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
