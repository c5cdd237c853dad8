// Admission by estimated working memory (--memory-budget): every call reserves an up-front
// estimate of the memory its work will need before it is queued, and gives it back when the
// work is done. Private to the server.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "inscribe/server/job_pool.h"

namespace inscribe::server {

// Per-item working memory of the service's jobs, in bytes: what a job allocates beyond the
// request message gRPC already holds and beyond the result cache (which has its own budget).
// Measured as the growth of peak RSS (VmHWM) of `inscribed --jobs 1` over its idle baseline
// (21 MB) across one call, 2026-11-22, RelWithDebInfo, 2 cores; the constants are those
// figures rounded up by 1.2-1.6x for allocator slack and shapes unlike the ones measured.
struct MemoryCosts {
  // InspectMesh / PutMesh: the core Mesh copy, validation (edge maps, the self-intersection
  // test's boxes), the oracle's BVH and the stored serialised copy. Measured with InspectMesh:
  // bunny00 (75,408 triangles) +48 MB, refined_elephant (88,928) +57 MB: 640 B per triangle.
  static constexpr std::int64_t kPerTriangle = 1024;
  static constexpr std::int64_t kPerVertex = 64;
  // Generate: culled voxels, screening flags, candidates, then the spheres and their quality
  // report (exact union volume). Measured: a unit cube (every voxel inside, the worst case) at
  // voxel 0.01, 10^6 voxels and 29,794 spheres, +135 MB; at 0.02, 125,000 voxels, +20 MB;
  // eight.off at a 10^6-voxel grid (43% inside, 24,961 spheres) +59 MB.
  static constexpr std::int64_t kPerVoxel = 160;
  // Quality report and search fixed costs (100,000 boundary samples, direction tables).
  static constexpr std::int64_t kGenerateFixed = 32 << 20;
  // Distance: both pose arrays, the relative poses, the results and the reply (core form, then
  // protobuf, then serialised). Measured: 10^6 pairs between one-sphere sets, +417 MiB with the
  // request's two copies (53 MiB each, gRPC's): 311 MiB = 326 B per pair.
  static constexpr std::int64_t kPerPosePair = 512;
  // DistanceStream: per pair of a frame, the query (two pointers, two poses), result, status
  // and the reply.
  static constexpr std::int64_t kPerFramePair = 512;
  // SceneStream, held for the stream's life: per object, core's scene entry (the object, its
  // certified view, bounding sphere, index and sweep order; ~300 B) and the stream's id tables;
  // per ignored pair, a hash-set slot; per reply pair (max_pairs), the core pair, its protobuf
  // and serialised forms. Estimated from the types' sizes, not measured.
  static constexpr std::int64_t kPerSceneObject = 512;
  static constexpr std::int64_t kPerIgnoredPair = 64;
  static constexpr std::int64_t kPerScenePair = 512;
  // An inline sphere set (PutSphereSet, Evaluate): the core set, its serialised copy, and the
  // exact union volume's regular triangulation (~1 KB per weighted point in CGAL).
  static constexpr std::int64_t kPerSphere = 2048;
  // Evaluate: one boundary sample (point, normal, distance and its nearest-sphere search).
  static constexpr std::int64_t kPerSample = 64;
  // UpdateDeformation: per vertex of the new frame (the core copy, the oracle refit's boxes,
  // the deformed mesh's hash input).
  static constexpr std::int64_t kPerDeformVertex = 256;
  // Calls whose size is not in the request (GetSphereSet, GetHierarchy, a Generate answered
  // from the cache): the reply's copy of a cached object, at most a few MB in practice.
  static constexpr std::int64_t kSmallCall = 4 << 20;
  // Calls estimated at most this run on the pool's small-job lane (JobPoolOptions::
  // small_job_threads), never behind large calls: a Distance of up to ~8,000 pose pairs, a
  // mesh of up to ~8,000 triangles, a stream frame of up to 16,000 pairs; milliseconds of work.
  static constexpr std::int64_t kSmallJob = 8 << 20;
};

// The pool lane of a job estimated at `memory_bytes`: the small-job lane up to kSmallJob. The
// one rule for unary calls and stream frames.
inline JobSize LaneFor(std::int64_t memory_bytes) {
  return memory_bytes <= MemoryCosts::kSmallJob ? JobSize::kSmall : JobSize::kLarge;
}

// "1.50 GiB", "512.00 MiB", "900 B": for messages.
inline std::string FormatBytes(std::int64_t bytes) {
  if (bytes >= (std::int64_t{1} << 30)) {
    return absl::StrFormat("%.2f GiB", static_cast<double>(bytes) / (1 << 30));
  }
  if (bytes >= (std::int64_t{1} << 20)) {
    return absl::StrFormat("%.2f MiB", static_cast<double>(bytes) / (1 << 20));
  }
  return absl::StrCat(bytes, " B");
}

// Sum of the estimates of calls in flight against a fixed budget. Thread-safe; Reserve is a
// lock and two additions, cheap enough for gRPC threads.
class MemoryBudget {
 public:
  // A held part of the budget; given back on destruction (or Release). Move-only.
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& other) noexcept
        : budget_(std::exchange(other.budget_, nullptr)), bytes_(other.bytes_) {}
    Reservation& operator=(Reservation&& other) noexcept {
      if (this != &other) {
        Release();
        budget_ = std::exchange(other.budget_, nullptr);
        bytes_ = other.bytes_;
      }
      return *this;
    }
    ~Reservation() { Release(); }

    std::int64_t bytes() const { return budget_ != nullptr ? bytes_ : 0; }
    // Gives back all but `bytes` (no-op when already at most that): for a call whose real
    // size became known after it was admitted on a worst-case estimate.
    void ShrinkTo(std::int64_t bytes) {
      if (budget_ == nullptr || bytes >= bytes_) return;
      budget_->Give(bytes_ - bytes);
      bytes_ = bytes;
    }
    void Release() {
      if (budget_ != nullptr) budget_->Give(bytes_);
      budget_ = nullptr;
    }

   private:
    friend class MemoryBudget;
    Reservation(MemoryBudget* budget, std::int64_t bytes) : budget_(budget), bytes_(bytes) {}
    MemoryBudget* budget_ = nullptr;
    std::int64_t bytes_ = 0;
  };

  // `budget_bytes` 0 = unlimited (every Reserve succeeds, the sum is still kept).
  explicit MemoryBudget(std::int64_t budget_bytes) : budget_(budget_bytes) {}
  MemoryBudget(const MemoryBudget&) = delete;
  MemoryBudget& operator=(const MemoryBudget&) = delete;

  // Reserves `bytes` for `what` (e.g. "Distance of 1000000 pose pairs"), or RESOURCE_EXHAUSTED:
  // naming --memory-budget when `bytes` alone exceeds the budget (the request must shrink), or
  // saying to retry when the calls in flight leave too little of it (as --max-queue does:
  // refusing costs the caller a round trip, waiting would hold the request's bytes unaccounted
  // and block nothing useful).
  absl::StatusOr<Reservation> Reserve(std::int64_t bytes, const std::string& what) {
    bytes = std::max<std::int64_t>(bytes, 0);
    std::lock_guard<std::mutex> lock(mutex_);
    if (budget_ > 0 && bytes > budget_) {
      return absl::ResourceExhaustedError(
          absl::StrCat(what, " needs an estimated ", FormatBytes(bytes),
                       " of working memory; this server's memory budget (--memory-budget) is ",
                       FormatBytes(budget_), "; send a smaller request"));
    }
    if (budget_ > 0 && in_flight_ + bytes > budget_) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "server is busy: calls in flight hold an estimated ", FormatBytes(in_flight_), " of its ",
          FormatBytes(budget_), " memory budget (--memory-budget) and ", what, " needs ",
          FormatBytes(bytes), "; retry later"));
    }
    in_flight_ += bytes;
    peak_ = std::max(peak_, in_flight_);
    return Reservation(this, bytes);
  }

  std::int64_t budget() const { return budget_; }
  // Snapshots, for tests and metrics.
  std::int64_t in_flight() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return in_flight_;
  }
  std::int64_t peak() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return peak_;
  }

 private:
  void Give(std::int64_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    in_flight_ -= bytes;
  }

  const std::int64_t budget_;
  mutable std::mutex mutex_;
  std::int64_t in_flight_ = 0;  // guarded by mutex_
  std::int64_t peak_ = 0;       // guarded by mutex_
};

}  // namespace inscribe::server
