#include "inscribe/solid/boundary_oracle.h"

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "mesh/mesh_topology.h"
#include "solid/closest_point_triangle.h"
#include "solid/exact_winding.h"
#include "solid/triangle_bvh.h"

namespace inscribe {
namespace {

constexpr double kPi = 3.14159265358979323846;

using internal::RoundDown;
using internal::RoundUp;

// A bound u is honoured when the squared distance found is at most u^2 (1 + kBoundRelative):
// the rounding of u = sqrt(d^2) itself (the flat BVH checks the same inside its query).
constexpr double kBoundRelative = 1e-13;

// Below these the pseudonormal's sign is not trusted (see ClassifyFrom): relative to the
// distance, and to the mesh's largest coordinate.
constexpr double kPseudonormalMargin = 1e-7;
constexpr double kPseudonormalAbsolute = 1e-12;

absl::Status CheckVertices(const Vertices& vertices) {
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    if (!vertices.row(v).allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", v, " has a non-finite coordinate"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

struct BoundaryOracle::Impl {
  Mesh mesh;
  // Unit face normals (zero for zero-area triangles), angle-weighted vertex pseudonormals and,
  // per triangle side 3t + k, the sum of the normals of the triangles sharing that edge.
  std::vector<Vector3> face_normals;
  std::vector<Vector3> vertex_normals;
  std::vector<Vector3> edge_normals;
  // Per triangle side 3t + k: the other triangle across that edge, or -1 (border or
  // non-manifold edge, where the pseudonormal falls back to the face normal).
  std::vector<std::int32_t> across;

  BoundaryOracleOptions options;
  BoundingBox box;  // of the vertices; queries outside it are outside the solid

  // Backend kFlatBvh.
  internal::TriangleBvh bvh;

  // Backend kEmbree (all null otherwise).
  float pad = 0;           // outward padding of every primitive box (see UpdateBoxAndPad)
  double magnitude = 0.0;  // largest |coordinate| of the vertices (UpdateBoxAndPad)
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;
  std::mutex error_mutex;
  std::string error;  // the first Embree error, read after build and refit

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (geometry != nullptr) rtcReleaseGeometry(geometry);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  Vector3 Corner(std::int32_t t, int k) const {
    return mesh.vertices.row(mesh.triangles(t, k)).transpose();
  }

  struct QueryState;
  static bool VisitTriangle(RTCPointQueryFunctionArguments* args);

  void ComputeNormals();
  absl::Status BuildScene();
  absl::Status CommitScene();
  // upper_bound: see BoundaryOracle::ClosestPoint; infinity for none.
  BoundaryPoint Closest(const Vector3& p,
                        double upper_bound = std::numeric_limits<double>::infinity()) const;
  BoundaryPoint EmbreeClosest(const Vector3& p, double upper_bound) const;
  Side ClassifyFrom(const Vector3& p, const BoundaryPoint& closest) const;
  Side ClassifyByWinding(const Vector3& p) const;
  int EmbreeWinding(const Vector3& p, bool* on_surface) const;
  void UpdateBoxAndPad();

  struct WindingContext;
  static void AddCrossing(const RTCIntersectFunctionNArguments* args);
};

// Face normals, corner angles and edge normals per triangle in parallel; the vertex sums in
// one pass over the triangles in order, so every sum adds the same terms in the same order as
// a plain serial loop (Build and Refit agree bit for bit). The corner angles (three atan2 per
// triangle) are most of the cost, which is why they run in parallel: Refit is on the path of
// every deformation update.
void BoundaryOracle::Impl::ComputeNormals() {
  const auto nt = static_cast<std::size_t>(mesh.num_triangles());
  face_normals.assign(nt, Vector3::Zero());
  vertex_normals.assign(static_cast<std::size_t>(mesh.num_vertices()), Vector3::Zero());
  edge_normals.assign(3 * nt, Vector3::Zero());
  std::vector<double> angles(3 * nt, 0.0);
  internal::ParallelForRange(std::size_t{0}, nt, 512, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t != end; ++t) {
      const auto ti = static_cast<std::int32_t>(t);
      const Vector3 corners[3] = {Corner(ti, 0), Corner(ti, 1), Corner(ti, 2)};
      const Vector3 n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
      const double length = n.norm();
      if (!(length > 0.0)) continue;
      face_normals[t] = n / length;
      // |e1 x e2| is `length` at every corner, and the three angles sum to
      // pi: two atan2 calls instead of three.
      double* angle = &angles[3 * t];
      for (int k = 0; k < 2; ++k) {
        const Vector3 e1 = corners[(k + 1) % 3] - corners[k];
        const Vector3 e2 = corners[(k + 2) % 3] - corners[k];
        angle[k] = std::atan2(length, e1.dot(e2));
      }
      angle[2] = std::max(0.0, kPi - angle[0] - angle[1]);
    }
  });
  for (std::size_t t = 0; t < nt; ++t) {
    if (face_normals[t].isZero()) continue;
    for (int k = 0; k < 3; ++k) {
      vertex_normals[static_cast<std::size_t>(mesh.triangles(static_cast<Eigen::Index>(t), k))] +=
          angles[3 * t + static_cast<std::size_t>(k)] * face_normals[t];
    }
  }
  internal::ParallelForRange(std::size_t{0}, 3 * nt, 2048, [&](std::size_t begin, std::size_t end) {
    for (std::size_t side = begin; side != end; ++side) {
      const Vector3& own = face_normals[side / 3];
      edge_normals[side] =
          across[side] >= 0 ? own + face_normals[static_cast<std::size_t>(across[side])] : own;
    }
  });
}

absl::Status BoundaryOracle::Impl::BuildScene() {
  device = rtcNewDevice("verbose=0");
  if (device == nullptr) {
    return absl::InternalError(
        absl::StrCat("Embree: cannot create a device (error ", rtcGetDeviceError(nullptr), ")"));
  }
  rtcSetDeviceErrorFunction(
      device,
      [](void* user, RTCError code, const char* message) {
        auto* self = static_cast<Impl*>(user);
        std::lock_guard<std::mutex> lock(self->error_mutex);
        if (self->error.empty()) {
          self->error = absl::StrCat("Embree error ", static_cast<int>(code), ": ",
                                     message != nullptr ? message : "");
        }
      },
      this);
  scene = rtcNewScene(device);
  // LOW scene quality builds a two-level structure whose per-geometry BVH honours the
  // geometry's REFIT quality: Refit then updates bounds without re-partitioning.
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_DYNAMIC);
  geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(mesh.num_triangles()));
  rtcSetGeometryUserData(geometry, this);
  rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
  // Bounds in single precision, rounded outward so that culling never drops a triangle.
  rtcSetGeometryBoundsFunction(
      geometry,
      [](const RTCBoundsFunctionArguments* args) {
        const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
        const auto t = static_cast<std::int32_t>(args->primID);
        Vector3 lo = self->Corner(t, 0), hi = lo;
        for (int k = 1; k < 3; ++k) {
          lo = lo.cwiseMin(self->Corner(t, k));
          hi = hi.cwiseMax(self->Corner(t, k));
        }
        RTCBounds* b = args->bounds_o;
        b->lower_x = RoundDown(lo.x()) - self->pad;
        b->lower_y = RoundDown(lo.y()) - self->pad;
        b->lower_z = RoundDown(lo.z()) - self->pad;
        b->upper_x = RoundUp(hi.x()) + self->pad;
        b->upper_y = RoundUp(hi.y()) + self->pad;
        b->upper_z = RoundUp(hi.z()) + self->pad;
      },
      nullptr);
  // Rays only add up crossings (kExactWinding); occlusion rays are not used.
  rtcSetGeometryIntersectFunction(geometry, AddCrossing);
  rtcSetGeometryOccludedFunction(geometry, [](const RTCOccludedFunctionNArguments*) {});
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  return CommitScene();
}

// Embree builds in the caller's task arena, on TBB's threads, whose start and join TSan does not
// see. Under TSan the build runs in an arena of one, on the calling thread alone, so TSan sees
// the build and its bounds callbacks in order with the code around them.
absl::Status BoundaryOracle::Impl::CommitScene() {
  if constexpr (internal::kThreadSanitizer) {
    tbb::task_arena calling_thread_only(1);
    calling_thread_only.execute([this] { rtcCommitScene(scene); });
  } else {
    rtcCommitScene(scene);
  }
  std::lock_guard<std::mutex> lock(error_mutex);
  if (!error.empty()) return absl::InternalError(error);
  return absl::OkStatus();
}

struct BoundaryOracle::Impl::QueryState {
  const Impl* impl;
  Vector3 p;
  double pad;  // |p - float(p)|: how far Embree's single-precision query point is off
  double best_squared = std::numeric_limits<double>::infinity();
  BoundaryPoint best;
};

bool BoundaryOracle::Impl::VisitTriangle(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<QueryState*>(args->userPtr);
  const auto t = static_cast<std::int32_t>(args->primID);
  Vector3 bary;
  const Vector3 q =
      internal::ClosestPointOnTriangle(state->p, state->impl->Corner(t, 0),
                                       state->impl->Corner(t, 1), state->impl->Corner(t, 2), &bary);
  const double d2 = (state->p - q).squaredNorm();
  // Ties go to the lower triangle index so that results do not depend on traversal order.
  if (d2 < state->best_squared || (d2 == state->best_squared && t < state->best.triangle)) {
    state->best_squared = d2;
    state->best.point = q;
    state->best.triangle = t;
    state->best.barycentric = bary;
    const double d = std::sqrt(d2);
    // Conservative single-precision search radius: pad for the float query point and a
    // relative margin for Embree's float box distances.
    const float radius = RoundUp((d + state->pad) * (1.0 + 1e-6) + 1e-30);
    if (radius < args->query->radius) {
      args->query->radius = radius;
      return true;
    }
  }
  return false;
}

// Returns triangle -1 when no triangle lies within upper_bound.
BoundaryPoint BoundaryOracle::Impl::EmbreeClosest(const Vector3& p, double upper_bound) const {
  QueryState state{this, p, 0.0, std::numeric_limits<double>::infinity(), BoundaryPoint{}};
  RTCPointQuery query;
  query.x = static_cast<float>(p.x());
  query.y = static_cast<float>(p.y());
  query.z = static_cast<float>(p.z());
  query.time = 0.0f;
  state.pad = (p - Vector3(query.x, query.y, query.z)).norm();
  // A negative bound is as broken as any other too-small one; NaN means none.
  const bool bounded = upper_bound < std::numeric_limits<double>::infinity();
  if (bounded) upper_bound = std::max(upper_bound, 0.0);
  // The same conservative radius as VisitTriangle sets once it knows a distance.
  query.radius = bounded ? RoundUp((upper_bound + state.pad) * (1.0 + 1e-6) + 1e-30)
                         : std::numeric_limits<float>::infinity();
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene, &query, &context, VisitTriangle, &state);
  if (bounded && !(state.best_squared <= upper_bound * upper_bound * (1.0 + kBoundRelative))) {
    return BoundaryPoint{};
  }
  state.best.distance = std::sqrt(state.best_squared);
  return state.best;
}

BoundaryPoint BoundaryOracle::Impl::Closest(const Vector3& p, double upper_bound) const {
  const bool flat = options.backend == BoundaryOracleBackend::kFlatBvh;
  BoundaryPoint found = flat ? bvh.ClosestPoint(p, upper_bound) : EmbreeClosest(p, upper_bound);
  if (found.triangle < 0) {  // the caller's bound was too small
    found = flat ? bvh.ClosestPoint(p) : EmbreeClosest(p, std::numeric_limits<double>::infinity());
  }
  return found;
}

// The padding makes single-precision culling conservative for rays as well as for point
// queries: a ray cast from float(p) runs parallel to the exact ray from p, at most |p - float(p)|
// away from it, and queries outside the bbox never cast rays, so |p| is bounded by the mesh.
void BoundaryOracle::Impl::UpdateBoxAndPad() {
  box = ComputeBoundingBox(mesh.vertices);
  magnitude = std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff());
  pad = RoundUp(1e-6 * magnitude + 1e-30);
}

struct BoundaryOracle::Impl::WindingContext {
  RTCIntersectContext base;  // must come first: Embree hands back a pointer to it
  const Impl* impl;
  Vector3 origin;
  int winding;
  bool on_surface;
};

// Called for every triangle whose (padded) box the ray enters. Never shortens the ray, so
// traversal visits them all; adds the flat BVH's exact crossing (internal::XRayCrossing).
void BoundaryOracle::Impl::AddCrossing(const RTCIntersectFunctionNArguments* args) {
  if (args->valid[0] == 0) return;
  auto* ctx = reinterpret_cast<WindingContext*>(args->context);
  const auto t = static_cast<std::int32_t>(args->primID);
  const int crossing = internal::XRayCrossing(ctx->origin, ctx->impl->Corner(t, 0),
                                              ctx->impl->Corner(t, 1), ctx->impl->Corner(t, 2));
  if (crossing == internal::kOnTriangle) {
    ctx->on_surface = true;
  } else {
    ctx->winding += crossing;
  }
}

int BoundaryOracle::Impl::EmbreeWinding(const Vector3& p, bool* on_surface) const {
  WindingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.impl = this;
  ctx.origin = p;
  ctx.winding = 0;
  ctx.on_surface = false;
  RTCRayHit rayhit;
  rayhit.ray.org_x = static_cast<float>(p.x());
  rayhit.ray.org_y = static_cast<float>(p.y());
  rayhit.ray.org_z = static_cast<float>(p.z());
  rayhit.ray.dir_x = 1.0f;
  rayhit.ray.dir_y = 0.0f;
  rayhit.ray.dir_z = 0.0f;
  // From behind the float origin: float(p_x) may lie past p_x.
  rayhit.ray.tnear = 0.0f;
  rayhit.ray.org_x =
      std::nextafter(rayhit.ray.org_x, -std::numeric_limits<float>::infinity()) - pad;
  rayhit.ray.tfar = std::numeric_limits<float>::infinity();
  rayhit.ray.time = 0.0f;
  rayhit.ray.mask = 0xFFFFFFFFu;
  rayhit.ray.id = 0;
  rayhit.ray.flags = 0;
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &ctx.base, &rayhit);
  *on_surface = ctx.on_surface;
  return ctx.winding;
}

Side BoundaryOracle::Impl::ClassifyByWinding(const Vector3& p) const {
  if ((p.array() < box.min.array()).any() || (p.array() > box.max.array()).any()) {
    return Side::kOutside;
  }
  bool on_surface = false;
  const int winding = options.backend == BoundaryOracleBackend::kFlatBvh
                          ? bvh.XRayWinding(p, &on_surface)
                          : EmbreeWinding(p, &on_surface);
  if (on_surface) return Side::kOnBoundary;
  return winding != 0 ? Side::kInside : Side::kOutside;
}

Side BoundaryOracle::Impl::ClassifyFrom(const Vector3& p, const BoundaryPoint& closest) const {
  if (options.inside_test == InsideTest::kExactWinding) return ClassifyByWinding(p);
  if (closest.distance == 0.0) return Side::kOnBoundary;
  const Vector3& w = closest.barycentric;
  const std::int32_t t = closest.triangle;
  Vector3 normal;
  const int zeros = (w[0] == 0.0) + (w[1] == 0.0) + (w[2] == 0.0);
  if (zeros >= 2) {  // a corner: the one with weight 1
    const int k = w[0] != 0.0 ? 0 : (w[1] != 0.0 ? 1 : 2);
    normal = vertex_normals[static_cast<std::size_t>(mesh.triangles(t, k))];
  } else if (zeros == 1) {  // an edge: the side opposite the zero-weight corner
    const int k = w[0] == 0.0 ? 0 : (w[1] == 0.0 ? 1 : 2);
    normal = edge_normals[static_cast<std::size_t>(t) * 3 + (k + 1) % 3];
  } else {
    normal = face_normals[static_cast<std::size_t>(t)];
  }
  const double s = (p - closest.point).dot(normal);
  // The sign is trusted only well clear of the rounding of the normals (relative 1e-15 of
  // their weights, summed over at most a few dozen faces) and of the closest point (1e-15 of
  // the coordinates): nearly cancelling normals, as at the edges of a flat sliver, or a query
  // almost in the feature's tangent plane, are decided by the exact winding number instead.
  const double margin = kPseudonormalMargin * closest.distance * std::max(normal.norm(), 1.0) +
                        kPseudonormalAbsolute * magnitude * normal.norm();
  if (!(std::abs(s) > margin)) return ClassifyByWinding(p);
  return s < 0.0 ? Side::kInside : Side::kOutside;
}

BoundaryOracle::BoundaryOracle(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BoundaryOracle::BoundaryOracle(BoundaryOracle&&) noexcept = default;
BoundaryOracle& BoundaryOracle::operator=(BoundaryOracle&&) noexcept = default;
BoundaryOracle::~BoundaryOracle() = default;

absl::StatusOr<BoundaryOracle> BoundaryOracle::Build(const Mesh& mesh,
                                                     const BoundaryOracleOptions& options) {
  if (mesh.num_triangles() == 0) {
    return absl::InvalidArgumentError("boundary oracle: mesh has no triangles");
  }
  if (mesh.num_triangles() > std::numeric_limits<std::int32_t>::max() / 3) {
    return absl::InvalidArgumentError("boundary oracle: too many triangles");
  }
  if (absl::Status s = CheckVertices(mesh.vertices); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("boundary oracle: ", s.message()));
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = mesh.triangles(t, k);
      if (v < 0 || v >= mesh.num_vertices()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "boundary oracle: triangle ", t, " refers to vertex ", v, " of ", mesh.num_vertices()));
      }
    }
  }
  auto impl = std::make_unique<Impl>();
  impl->mesh = mesh;
  impl->options = options;
  impl->UpdateBoxAndPad();
  impl->across.assign(static_cast<std::size_t>(mesh.num_triangles()) * 3, -1);
  const std::vector<internal::EdgeUse> uses = internal::SortedEdgeUses(mesh);
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i == 2) {
      impl->across[static_cast<std::size_t>(uses[i].triangle) * 3 + uses[i].side] =
          uses[i + 1].triangle;
      impl->across[static_cast<std::size_t>(uses[i + 1].triangle) * 3 + uses[i + 1].side] =
          uses[i].triangle;
    }
    i = j;
  }
  impl->ComputeNormals();
  if (options.backend == BoundaryOracleBackend::kFlatBvh) {
    impl->bvh = internal::TriangleBvh::Build(impl->mesh);
  } else if (absl::Status s = impl->BuildScene(); !s.ok()) {
    return s;
  }
  return BoundaryOracle(std::move(impl));
}

absl::Status BoundaryOracle::Refit(const Vertices& new_vertices) {
  if (new_vertices.rows() != impl_->mesh.num_vertices()) {
    return absl::InvalidArgumentError(absl::StrCat("refit: expected ", impl_->mesh.num_vertices(),
                                                   " vertices, got ", new_vertices.rows()));
  }
  if (absl::Status s = CheckVertices(new_vertices); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("refit: ", s.message()));
  }
  impl_->mesh.vertices = new_vertices;
  impl_->UpdateBoxAndPad();
  impl_->ComputeNormals();
  if (impl_->options.backend == BoundaryOracleBackend::kFlatBvh) {
    impl_->bvh.Refit(impl_->mesh);
    return absl::OkStatus();
  }
  rtcCommitGeometry(impl_->geometry);
  return impl_->CommitScene();
}

const Mesh& BoundaryOracle::mesh() const { return impl_->mesh; }

const std::vector<Vector3>& BoundaryOracle::face_normals() const { return impl_->face_normals; }

const std::vector<Vector3>& BoundaryOracle::vertex_normals() const { return impl_->vertex_normals; }

BoundaryPoint BoundaryOracle::ClosestPoint(const Vector3& query) const {
  return impl_->Closest(query);
}

BoundaryPoint BoundaryOracle::ClosestPoint(const Vector3& query, double upper_bound) const {
  return impl_->Closest(query, upper_bound);
}

Side BoundaryOracle::Classify(const Vector3& query) const {
  // The exact test needs no closest point: one ray decides, boundary included.
  if (impl_->options.inside_test == InsideTest::kExactWinding) {
    return impl_->ClassifyByWinding(query);
  }
  return impl_->ClassifyFrom(query, impl_->Closest(query));
}

Side BoundaryOracle::Classify(const Vector3& query, const BoundaryPoint& closest) const {
  return impl_->ClassifyFrom(query, closest);
}

double BoundaryOracle::SignedDistance(const Vector3& query) const {
  const BoundaryPoint closest = impl_->Closest(query);
  return impl_->ClassifyFrom(query, closest) == Side::kInside ? -closest.distance
                                                              : closest.distance;
}

std::vector<BoundaryPoint> BoundaryOracle::ClosestPoints(const Vertices& queries) const {
  std::vector<BoundaryPoint> out(static_cast<std::size_t>(queries.rows()));
  internal::ParallelFor(Eigen::Index{0}, queries.rows(), [&](Eigen::Index i) {
    out[static_cast<std::size_t>(i)] = impl_->Closest(queries.row(i).transpose());
  });
  return out;
}

std::vector<Side> BoundaryOracle::ClassifyAll(const Vertices& queries) const {
  std::vector<Side> out(static_cast<std::size_t>(queries.rows()));
  internal::ParallelFor(Eigen::Index{0}, queries.rows(), [&](Eigen::Index i) {
    out[static_cast<std::size_t>(i)] = Classify(queries.row(i).transpose());
  });
  return out;
}

std::vector<double> BoundaryOracle::SignedDistances(const Vertices& queries) const {
  std::vector<double> out(static_cast<std::size_t>(queries.rows()));
  internal::ParallelFor(Eigen::Index{0}, queries.rows(), [&](Eigen::Index i) {
    out[static_cast<std::size_t>(i)] = SignedDistance(queries.row(i).transpose());
  });
  return out;
}

}  // namespace inscribe
