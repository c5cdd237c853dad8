// Request checks and small conversions shared by the InscribeService RPC files. Private to the
// server.
#pragma once

#include <chrono>
#include <cmath>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/server/result_cache.h"
#include "inscribe/v1/service.pb.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"

namespace inscribe::server {

using ServiceClock = std::chrono::steady_clock;

inline double SecondsSince(ServiceClock::time_point start) {
  return std::chrono::duration<double>(ServiceClock::now() - start).count();
}

// The one status of a mesh the service cannot use, whichever call brought it (PutMesh, and
// Generate's upload through it; a frame of UpdateDeformation): FAILED_PRECONDITION with
// `problem` as the message, which names what is wrong (the mesh report's first error, or the
// frame's bad vertex).
inline absl::Status UnusableMeshError(absl::string_view problem) {
  return absl::FailedPreconditionError(problem);
}

// A required cache key: INVALID_ARGUMENT naming `field` when empty or malformed. O(length).
inline absl::Status CheckKey(const std::string& key, const char* field) {
  if (key.empty()) return absl::InvalidArgumentError(absl::StrCat(field, " is required"));
  if (absl::Status s = CheckCacheKey(key); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": ", s.message()));
  }
  return absl::OkStatus();
}

// The covers of a certified distance query (Distance, a DistanceStream pair): both or
// neither, each a well-formed key. O(length).
inline absl::Status CheckCovers(const std::string& cover_a, const std::string& cover_b) {
  if (cover_a.empty() != cover_b.empty()) {
    return absl::InvalidArgumentError(
        "cover_a and cover_b: give both (a certified query) or neither");
  }
  if (cover_a.empty()) return absl::OkStatus();
  if (absl::Status s = CheckKey(cover_a, "cover_a"); !s.ok()) return s;
  return CheckKey(cover_b, "cover_b");
}

// A certified query computes every sphere distance exactly: a tolerance would loosen a bound
// it promises. INVALID_ARGUMENT for abs_err or rel_err other than 0.
inline absl::Status CheckCertifiedTolerance(const DistanceRequest& tolerance) {
  if (tolerance.abs_err == 0.0 && tolerance.rel_err == 0.0) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(
      "tolerance: a certified query (covers named) computes exact distances; abs_err and "
      "rel_err must be 0, got ",
      tolerance.abs_err, " and ", tolerance.rel_err));
}

// Estimated working memory of validating and storing `mesh` (InspectMesh, PutMesh), bytes. O(1).
inline std::int64_t MeshWorkBytes(const v1::Mesh& mesh) {
  return wire::TriangleCount(mesh) * MemoryCosts::kPerTriangle +
         mesh.vertices_size() / 3 * MemoryCosts::kPerVertex;
}

}  // namespace inscribe::server
