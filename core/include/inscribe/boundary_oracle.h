// Closest points on, and inside/outside tests against, the boundary of a closed mesh.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/mesh.h"

namespace inscribe {

// The point of the boundary nearest to a query point.
struct BoundaryPoint {
  Vector3 point = Vector3::Zero();        // on the boundary, mesh frame
  std::int32_t triangle = -1;             // 0-based triangle index
  Vector3 barycentric = Vector3::Zero();  // weights of the triangle's corners 0, 1, 2; sum to 1
  double distance = 0.0;                  // |query - point|, mesh units
};

enum class Side { kInside, kOutside, kOnBoundary };

// How Classify decides inside from outside.
enum class InsideTest {
  // Sign against the angle-weighted pseudonormal of the closest feature (Baerentzen & Aanaes
  // 2005). Costs nothing beyond the closest-point query. Exact for a closed, outward-oriented
  // 2-manifold WITHOUT self-intersections; wrong near sheets buried inside the solid.
  kPseudonormal,
  // Parity of crossings along three fixed rays (majority vote), each crossing computed in
  // double precision. Same answer as CGAL's Side_of_triangle_mesh, also for self-intersecting
  // meshes (where overlapped regions count as outside). About three ray casts per query.
  kRayParity,
};

struct BoundaryOracleOptions {
  // Use kRayParity for meshes whose MeshReport has self_intersecting_pairs > 0.
  InsideTest inside_test = InsideTest::kPseudonormal;
};

// Queries against a mesh's boundary. The fast path is an Embree 3 BVH over the triangles (held
// in single precision for culling only, with bounds rounded outward); every closest point and
// distance is computed in double precision on the mesh's own coordinates, so results match a
// brute-force double-precision scan exactly up to ties.
//
// Inside/outside follows options.inside_test (see InsideTest). Use a mesh that passed
// PrepareMesh.
//
// Thread safety: const methods may be called concurrently from any number of threads. Refit
// must not overlap any other call. Moves are cheap; copies are not allowed.
class BoundaryOracle {
 public:
  // Builds the BVH. Errors: empty mesh, out-of-range indices, non-finite coordinates, Embree
  // failures (INTERNAL with Embree's message). Cost O(#T log #T).
  static absl::StatusOr<BoundaryOracle> Build(const Mesh& mesh,
                                              const BoundaryOracleOptions& options = {});

  BoundaryOracle(BoundaryOracle&&) noexcept;
  BoundaryOracle& operator=(BoundaryOracle&&) noexcept;
  ~BoundaryOracle();

  BoundaryPoint ClosestPoint(const Vector3& query) const;
  Side Classify(const Vector3& query) const;
  // Distance to the boundary, negative inside, 0 on it.
  double SignedDistance(const Vector3& query) const;

  // Batch versions over #Q by 3 query points, parallel (TBB). Output has #Q entries.
  std::vector<BoundaryPoint> ClosestPoints(const Vertices& queries) const;
  std::vector<Side> ClassifyAll(const Vertices& queries) const;
  std::vector<double> SignedDistances(const Vertices& queries) const;

  // New vertex positions for the same triangles (#V by 3, #V unchanged): updates the normals
  // and refits the BVH in place (RTC_BUILD_QUALITY_REFIT) instead of rebuilding it.
  // Errors: wrong vertex count, non-finite coordinates. Cost O(#V + #T).
  absl::Status Refit(const Vertices& new_vertices);

  const Mesh& mesh() const;

 private:
  struct Impl;
  explicit BoundaryOracle(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inscribe
