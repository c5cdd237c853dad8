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
#include "inscribe/server/convert.h"
#include "inscribe/server/result_cache.h"
#include "inscribe/sphere_hierarchy.h"
#include "inscribe/v1/service.pb.h"
#include "memory_budget.h"

namespace inscribe::server {

using ServiceClock = std::chrono::steady_clock;

inline double SecondsSince(ServiceClock::time_point start) {
  return std::chrono::duration<double>(ServiceClock::now() - start).count();
}

// HIERARCHY_VOLUME_UNSPECIFIED and SPHERE are the sphere hierarchy.
inline HierarchyVolume VolumeFromProto(v1::HierarchyVolume volume) {
  return volume == v1::RSS ? HierarchyVolume::kRss : HierarchyVolume::kSphere;
}

// A required cache key: INVALID_ARGUMENT naming `field` when empty or malformed. O(length).
inline absl::Status CheckKey(const std::string& key, const char* field) {
  if (key.empty()) return absl::InvalidArgumentError(absl::StrCat(field, " is required"));
  if (absl::Status s = CheckCacheKey(key); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": ", s.message()));
  }
  return absl::OkStatus();
}

// The core form of a wire tolerance; INVALID_ARGUMENT for negative or non-finite errors or a
// NaN closer_than.
inline absl::StatusOr<DistanceRequest> ToleranceFromProto(const v1::DistanceTolerance& t) {
  DistanceRequest request;
  request.abs_err = t.abs_err();
  request.rel_err = t.rel_err();
  if (t.has_closer_than()) request.closer_than = t.closer_than();
  if (!(std::isfinite(request.abs_err) && request.abs_err >= 0.0 &&
        std::isfinite(request.rel_err) && request.rel_err >= 0.0) ||
      std::isnan(request.closer_than)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "tolerance: abs_err and rel_err must be finite and >= 0 and closer_than a number, got ",
        request.abs_err, ", ", request.rel_err, ", ", request.closer_than));
  }
  return request;
}

// Estimated working memory of validating and storing `mesh` (InspectMesh, PutMesh), bytes. O(1).
inline std::int64_t MeshWorkBytes(const v1::Mesh& mesh) {
  return TriangleCount(mesh) * MemoryCosts::kPerTriangle +
         mesh.vertices_size() / 3 * MemoryCosts::kPerVertex;
}

}  // namespace inscribe::server
