// Request checks and small conversions shared by the InscribeService RPC files. Private to the
// server.
#pragma once

#include <chrono>
#include <cmath>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "inscribe/separation_distance.h"
#include "inscribe/server/result_cache.h"
#include "inscribe/sphere_hierarchy.h"
#include "inscribe/v1/service.pb.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"

namespace inscribe::server {

using ServiceClock = std::chrono::steady_clock;

inline double SecondsSince(ServiceClock::time_point start) {
  return std::chrono::duration<double>(ServiceClock::now() - start).count();
}

// A required cache key: INVALID_ARGUMENT naming `field` when empty or malformed. O(length).
inline absl::Status CheckKey(const std::string& key, const char* field) {
  if (key.empty()) return absl::InvalidArgumentError(absl::StrCat(field, " is required"));
  if (absl::Status s = CheckCacheKey(key); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": ", s.message()));
  }
  return absl::OkStatus();
}

// Estimated working memory of validating and storing `mesh` (InspectMesh, PutMesh), bytes. O(1).
inline std::int64_t MeshWorkBytes(const v1::Mesh& mesh) {
  return wire::TriangleCount(mesh) * MemoryCosts::kPerTriangle +
         mesh.vertices_size() / 3 * MemoryCosts::kPerVertex;
}

}  // namespace inscribe::server
