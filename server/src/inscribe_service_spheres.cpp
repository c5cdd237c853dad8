// The InscribeService RPCs over stored meshes and cached results: PutMesh, Generate,
// GetSphereSet, GetHierarchy, Distance (certified queries: inscribe_service_certified.cpp),
// CacheStats. Each validates on the gRPC thread what is O(1), then hands the rest to the pool
// through ResultStore (the cache).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <new>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "mesh_sizes.h"
#include "oneapi/tbb/task_arena.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// Adds the work counts of `results` (their tests, summed) to a Distance answer.
void AddWork(const std::vector<DistanceResult>& results, v1::DistanceResponse* response) {
  std::int64_t volume_tests = 0, sphere_tests = 0;
  for (const DistanceResult& r : results) {
    volume_tests += r.volume_tests;
    sphere_tests += r.sphere_tests;
  }
  response->set_volume_tests(response->volume_tests() + volume_tests);
  response->set_sphere_tests(response->sphere_tests() + sphere_tests);
}

}  // namespace

grpc::ServerUnaryReactor* InscribeService::PutMesh(grpc::CallbackServerContext* context,
                                                   const v1::PutMeshRequest* request,
                                                   v1::PutMeshResponse* response) {
  return RunUnary(context, "PutMesh", wire::TriangleCount(request->mesh()),
                  CheckMesh(request->mesh()), MeshWorkBytes(request->mesh()),
                  absl::StrCat("PutMesh of ", wire::TriangleCount(request->mesh()), " triangles"),
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<Mesh> mesh = wire::MeshFromProto(request->mesh());
                    if (!mesh.ok()) return mesh.status();
                    bool already = false;
                    ValidateOptions repair;
                    repair.fill_holes = request->fill_holes();
                    repair.weld_tolerance = request->weld_tolerance();
                    absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> stored =
                        store_->PutMesh(*std::move(mesh), repair, &already);
                    if (!stored.ok()) return stored.status();
                    RecordMeshSize(**stored);
                    response->set_mesh_sha256((*stored)->key);
                    wire::MeshReportToProto((*stored)->solid.report, response->mutable_report());
                    response->set_already_stored(already);
                    return absl::OkStatus();
                  });
}

// Generate: a server-streaming call. The job on the pool reports progress; at most one write is
// in flight, so progress messages that arrive during a write are dropped (the next one carries
// a later fraction). The result is the last message. Cancellation (the caller gave up, or its
// deadline passed) sets the flag generation polls, so the worker stops promptly.
class GenerateReactor final : public grpc::ServerWriteReactor<v1::GenerateResponse> {
 public:
  GenerateReactor(InscribeService* service, grpc::CallbackServerContext* context,
                  const v1::GenerateRequest* request)
      : service_(service), context_(context), request_(request) {
    record_.method = "Generate";
    record_.peer = context->peer();
  }

  void Start() {
    service_->CallStarted();
    absl::Status precheck = service_->Authenticate(*context_);
    if (precheck.ok() && service_->draining_.load()) {
      precheck = absl::UnavailableError("server is shutting down; retry");
    }
    if (precheck.ok()) precheck = CheckKey(request_->mesh_sha256(), "mesh_sha256");
    std::int64_t bytes = 0;
    if (precheck.ok()) {
      absl::StatusOr<SphereSetParameters> parameters =
          wire::SphereSetParametersFromProto(*request_, service_->limits_.max_voxels);
      if (!parameters.ok()) {
        precheck = parameters.status();
      } else {
        parameters_ = *std::move(parameters);
        absl::StatusOr<std::int64_t> estimate =
            service_->GenerateWorkBytes(request_->mesh_sha256(), parameters_);
        precheck = estimate.status();
        if (estimate.ok()) bytes = *estimate;
      }
    }
    if (precheck.ok()) {
      absl::StatusOr<MemoryBudget::Reservation> reserved = service_->memory_->Reserve(
          bytes, absl::StrCat("Generate on mesh ", request_->mesh_sha256()));
      if (reserved.ok()) {
        reservation_ = *std::move(reserved);
        record_.memory_bytes = reservation_.bytes();
      } else {
        precheck = reserved.status();
      }
    }
    if (!precheck.ok()) {
      Complete(precheck, nullptr);
      return;
    }
    const ServiceClock::time_point arrived = ServiceClock::now();
    const bool queued = service_->pool_->TrySubmit([this, arrived] { Run(arrived); });
    if (!queued) Complete(service_->QueueFullError(), nullptr);
  }

  void OnCancel() override { cancel_.store(true); }

  void OnWriteDone(bool /*ok*/) override {
    bool finish = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      writing_ = false;
      finish = done_;
    }
    if (finish) SendFinal();
  }

  void OnDone() override {
    service_->CallEnded();
    delete this;
  }

 private:
  void Run(ServiceClock::time_point arrived) {
    record_.queued_seconds = SecondsSince(arrived);
    const auto deadline = context_->deadline();
    if (context_->IsCancelled() || cancel_.load()) {
      Complete(absl::CancelledError("call was cancelled before work started"), nullptr);
      return;
    }
    if (std::chrono::system_clock::now() >= deadline) {
      Complete(absl::DeadlineExceededError("deadline passed before work started"), nullptr);
      return;
    }
    const double interval =
        request_->progress_interval() > 0.0 ? request_->progress_interval() : 0.5;
    ServiceClock::time_point last_progress = ServiceClock::now();
    GenerationControl control;
    control.cancel = &cancel_;
    control.on_progress = [&](double fraction) {
      // Deadlines are checked here too: gRPC cancels the call at the deadline, but the flag
      // is what stops the worker, and progress comes often.
      if (std::chrono::system_clock::now() >= deadline) cancel_.store(true);
      if (SecondsSince(last_progress) >= interval) {
        last_progress = ServiceClock::now();
        Progress(fraction);
      }
    };
    const ServiceClock::time_point started = ServiceClock::now();
    absl::StatusOr<std::pair<std::shared_ptr<const SphereSetEntry>, CacheSource>> result;
    try {
      result = service_->store_->Generate(request_->mesh_sha256(), parameters_,
                                          request_->parameters().fill_holes(), control);
    } catch (const std::bad_alloc&) {
      result = absl::ResourceExhaustedError("server ran out of memory generating spheres");
    }
    record_.run_seconds = SecondsSince(started);
    if (!result.ok() && result.status().code() == absl::StatusCode::kCancelled &&
        std::chrono::system_clock::now() >= deadline) {
      result = absl::DeadlineExceededError(absl::StrCat(
          "deadline passed while generating; stopped after ", record_.run_seconds, " s"));
    }
    if (!result.ok()) {
      Complete(result.status(), nullptr);
      return;
    }
    auto final_message = std::make_unique<v1::GenerateResponse>();
    v1::GenerateResult* out = final_message->mutable_result();
    *out = result->first->result;
    out->set_cache(CacheSourceName(result->second));
    Complete(absl::OkStatus(), std::move(final_message));
  }

  void Progress(double fraction) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (writing_ || done_) return;
    progress_.mutable_progress()->set_fraction(fraction);
    writing_ = true;
    StartWrite(&progress_);
  }

  // The job's last touch of the reactor: after this, OnDone may delete it at any time.
  void Complete(const absl::Status& status, std::unique_ptr<v1::GenerateResponse> final_message) {
    reservation_.Release();
    record_.status = status;
    service_->Observe(record_);
    bool send_now = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      status_ = status;
      final_ = std::move(final_message);
      done_ = true;
      send_now = !writing_;
    }
    if (send_now) SendFinal();
  }

  void SendFinal() {
    if (status_.ok()) {
      StartWriteAndFinish(final_.get(), grpc::WriteOptions(), grpc::Status::OK);
    } else {
      Finish(wire::ToGrpcStatus(status_));
    }
  }

  InscribeService* const service_;
  grpc::CallbackServerContext* const context_;
  const v1::GenerateRequest* const request_;
  SphereSetParameters parameters_;  // the request's, checked in Start
  std::atomic<bool> cancel_{false};
  MemoryBudget::Reservation reservation_;  // set in Start, released in Complete
  CallRecord record_;
  std::mutex mutex_;
  bool writing_ = false;  // a progress write is in flight
  bool done_ = false;     // the job has completed; status_ and final_ are set
  v1::GenerateResponse progress_;
  absl::Status status_;
  std::unique_ptr<v1::GenerateResponse> final_;
};

void InscribeService::RecordMeshSize(const StoredMeshEntry& entry) {
  MeshSize size;
  size.vertices = entry.mesh().num_vertices();
  size.triangles = entry.mesh().num_triangles();
  size.extent = ComputeBoundingBox(entry.mesh().vertices).extent();
  mesh_sizes_->Record(entry.key, size);
}

absl::StatusOr<std::int64_t> InscribeService::GenerateWorkBytes(
    const std::string& mesh_key, const SphereSetParameters& parameters) const {
  const std::optional<MeshSize> size = mesh_sizes_->Find(mesh_key);
  // The request's grid limit, already capped by this server's.
  const double max_voxels = static_cast<double>(parameters.medial.max_voxels);
  const bool server_limit_binds = parameters.medial.max_voxels >= limits_.max_voxels;
  double voxels = max_voxels;  // unknown mesh (stored by another process): the worst case
  if (size && parameters.voxel_size) {
    voxels = size->GridVoxels(*parameters.voxel_size);
    // Over the caller's own limit: core refuses it at once, naming that limit.
    if (voxels > max_voxels && !server_limit_binds) voxels = max_voxels;
    if (voxels > max_voxels) {
      // Refused here, before the call is queued; core would refuse it too (MakeGrid), but
      // only after a pool thread and a cache lookup.
      return absl::InvalidArgumentError(absl::StrFormat(
          "parameters.voxel_size %g gives a grid of %.3g voxels over the mesh's bounding box "
          "(%g x %g x %g); this server's limit (--max-voxels) is %d voxels; use a larger voxel "
          "size",
          *parameters.voxel_size, voxels, size->extent.x(), size->extent.y(), size->extent.z(),
          limits_.max_voxels));
    }
  } else if (size) {
    // A sphere budget N: the paper's search starts at voxels of side ~diagonal / (2 sqrt N)
    // (sphere counts grow as (diagonal / sigma)^2 / 4) and refines from there, and the
    // optimised selection's pool of ~3N spheres sits about sqrt(3) finer; half that side, 8x
    // the voxels, bounds where either ends on the meshes measured (at most the --max-voxels
    // grid). A cover bounded by max_protrusion instead is estimated as one of the default
    // budget.
    const std::int64_t budget = EffectiveMaxSpheres(parameters).value_or(kDefaultMaxSpheres);
    const double sigma =
        0.5 * size->extent.norm() / std::sqrt(std::max(static_cast<double>(budget), 1.0));
    if (sigma > 0.0) voxels = std::min(max_voxels, size->GridVoxels(0.5 * sigma));
  }
  // Subdivided boundary voxels hold up to 8 candidates each.
  if (parameters.medial.subdivide_boundary) voxels *= 2.0;
  double bytes = voxels * MemoryCosts::kPerVoxel + MemoryCosts::kGenerateFixed;
  // Without the mesh's size the worst case may exceed the budget though the mesh is small: it
  // is then admitted when it can run alone, never refused outright.
  if (!size && memory_->budget() > 0) bytes = std::min(bytes, double(memory_->budget()));
  return static_cast<std::int64_t>(bytes);
}

grpc::ServerWriteReactor<v1::GenerateResponse>* InscribeService::Generate(
    grpc::CallbackServerContext* context, const v1::GenerateRequest* request) {
  auto* reactor = new GenerateReactor(this, context, request);
  reactor->Start();
  return reactor;
}

grpc::ServerUnaryReactor* InscribeService::GetSphereSet(grpc::CallbackServerContext* context,
                                                        const v1::GetSphereSetRequest* request,
                                                        v1::GetSphereSetResponse* response) {
  return RunUnary(context, "GetSphereSet", 0, CheckKey(request->sphere_set_key(), "sphere_set_key"),
                  MemoryCosts::kSmallCall, "GetSphereSet",
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<std::shared_ptr<const SphereSetEntry>> entry =
                        store_->GetSphereSet(request->sphere_set_key());
                    if (!entry.ok()) return entry.status();
                    *response->mutable_spheres() = (*entry)->result.spheres();
                    response->set_mesh_sha256((*entry)->result.mesh_sha256());
                    return absl::OkStatus();
                  });
}

grpc::ServerUnaryReactor* InscribeService::GetHierarchy(grpc::CallbackServerContext* context,
                                                        const v1::GetHierarchyRequest* request,
                                                        v1::GetHierarchyResponse* response) {
  return RunUnary(context, "GetHierarchy", 0, CheckKey(request->sphere_set_key(), "sphere_set_key"),
                  MemoryCosts::kSmallCall, "GetHierarchy",
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> h = store_->GetHierarchy(
                        request->sphere_set_key(), wire::VolumeFromProto(request->volume()));
                    if (!h.ok()) return h.status();
                    response->set_hierarchy((*h)->Serialize());
                    return absl::OkStatus();
                  });
}

absl::Status InscribeService::BruteForceDistances(const v1::DistanceRequest& request,
                                                  const std::vector<RigidPose>& poses_a,
                                                  const std::vector<RigidPose>& poses_b,
                                                  const DistanceRequest& tolerance,
                                                  v1::DistanceResponse* response) {
  // Every sphere pair of every pose pair: bounded, so that one call cannot occupy a worker for
  // hours (10^10 pairs are about a minute).
  constexpr double kMaxSpherePairs = 1e10;
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> a =
      store_->GetSphereSet(request.sphere_set_a());
  if (!a.ok()) return a.status();
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> b =
      store_->GetSphereSet(request.sphere_set_b());
  if (!b.ok()) return b.status();
  const std::vector<Sphere>& sa = (*a)->set.spheres;
  const std::vector<Sphere>& sb = (*b)->set.spheres;
  const double work = static_cast<double>(sa.size()) * static_cast<double>(sb.size()) *
                      static_cast<double>(poses_b.size());
  if (work > kMaxSpherePairs) {
    return absl::ResourceExhaustedError(
        absl::StrCat("brute_force: ", work, " sphere pairs (", sa.size(), " x ", sb.size(), " x ",
                     poses_b.size(), " poses); at most ", kMaxSpherePairs, " per call"));
  }
  const ServiceClock::time_point start = ServiceClock::now();
  std::vector<DistanceResult> results(poses_b.size());
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    absl::StatusOr<DistanceResult> r = BruteForceSeparationDistance(
        sa, poses_a[poses_a.size() == 1 ? 0 : i], sb, poses_b[i], tolerance);
    if (!r.ok())
      return absl::Status(r.status().code(), absl::StrCat("pose ", i, ": ", r.status().message()));
    results[i] = *r;
  }
  wire::AppendDistanceResults(results, response->mutable_results());
  response->set_seconds(SecondsSince(start));
  response->set_threads(1);
  AddWork(results, response);
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* InscribeService::Distance(grpc::CallbackServerContext* context,
                                                    const v1::DistanceRequest* request,
                                                    v1::DistanceResponse* response) {
  absl::Status precheck = CheckKey(request->sphere_set_a(), "sphere_set_a");
  if (precheck.ok()) precheck = CheckKey(request->sphere_set_b(), "sphere_set_b");
  if (precheck.ok()) precheck = CheckCovers(request->cover_a(), request->cover_b());
  const bool certified = !request->cover_a().empty();
  if (precheck.ok() && certified && request->brute_force()) {
    precheck = absl::InvalidArgumentError(
        "brute_force: a certified query (covers named) is exact already; leave it unset");
  }
  // Shapes and counts are O(1) to check here; the poses' numbers are checked on the pool.
  const int numbers_a = request->poses_a().values_size();
  const int numbers_b = request->poses_b().values_size();
  const std::int64_t pairs = numbers_b / 7;
  if (precheck.ok() && (numbers_a % 7 != 0 || numbers_b % 7 != 0)) {
    precheck = absl::InvalidArgumentError(
        absl::StrCat(numbers_a % 7 != 0 ? "poses_a" : "poses_b", " has length ",
                     numbers_a % 7 != 0 ? numbers_a : numbers_b,
                     "; expected a multiple of 7 (qw, qx, qy, qz, tx, ty, tz per pose)"));
  }
  if (precheck.ok() && pairs > limits_.max_poses) {
    precheck = absl::ResourceExhaustedError(
        absl::StrCat(pairs, " pose pairs; this server's limit (--max-poses) is ", limits_.max_poses,
                     " per call"));
  }
  if (precheck.ok() && numbers_a != 7 && numbers_a != numbers_b) {
    precheck = absl::InvalidArgumentError(
        absl::StrCat("poses_a has ", numbers_a / 7, " poses and poses_b ", pairs,
                     "; poses_a must have one pose or as many as poses_b"));
  }
  return RunUnary(
      context, "Distance", 0, precheck, pairs * MemoryCosts::kPerPosePair + MemoryCosts::kSmallCall,
      absl::StrCat("Distance of ", pairs, " pose pairs"),
      [this, request, response, certified]() -> absl::Status {
        absl::StatusOr<DistanceRequest> tolerance = wire::ToleranceFromProto(request->tolerance());
        if (!tolerance.ok()) return tolerance.status();
        if (certified) {
          if (absl::Status s = CheckCertifiedTolerance(*tolerance); !s.ok()) return s;
        }
        absl::StatusOr<std::vector<RigidPose>> poses_a =
            wire::PosesFromProto(request->poses_a(), "poses_a");
        if (!poses_a.ok()) return poses_a.status();
        absl::StatusOr<std::vector<RigidPose>> poses_b =
            wire::PosesFromProto(request->poses_b(), "poses_b");
        if (!poses_b.ok()) return poses_b.status();
        if (poses_a->size() != 1 && poses_a->size() != poses_b->size()) {
          return absl::InvalidArgumentError(
              absl::StrCat("poses_a has ", poses_a->size(), " poses and poses_b ", poses_b->size(),
                           "; poses_a must have one pose or as many as poses_b"));
        }
        if (request->brute_force()) {
          return BruteForceDistances(*request, *poses_a, *poses_b, *tolerance, response);
        }
        if (certified) {
          return CertifiedDistances(*request, *poses_a, *poses_b, *tolerance, response);
        }
        const HierarchyVolume volume = wire::VolumeFromProto(request->volume());
        const ServiceClock::time_point hierarchies_start = ServiceClock::now();
        absl::StatusOr<std::shared_ptr<const SphereHierarchy>> a =
            store_->GetHierarchy(request->sphere_set_a(), volume);
        if (!a.ok()) return a.status();
        absl::StatusOr<std::shared_ptr<const SphereHierarchy>> b =
            store_->GetHierarchy(request->sphere_set_b(), volume);
        if (!b.ok()) return b.status();
        response->set_hierarchy_seconds(SecondsSince(hierarchies_start));
        const ServiceClock::time_point start = ServiceClock::now();
        // The pairs in blocks: a block's posed pairs (128 bytes each) are all the memory the
        // query adds to the poses and the results.
        constexpr std::size_t kBlock = 16'384;
        std::vector<PosedPair> posed;
        posed.reserve(std::min(kBlock, poses_b->size()));
        for (std::size_t first = 0; first < poses_b->size(); first += kBlock) {
          const std::size_t end = std::min(poses_b->size(), first + kBlock);
          posed.clear();
          for (std::size_t i = first; i < end; ++i) {
            posed.push_back(PosedPair{a->get(), b->get(), (*poses_a)[poses_a->size() == 1 ? 0 : i],
                                      (*poses_b)[i]});
          }
          absl::StatusOr<std::vector<DistanceResult>> results =
              PairSeparationDistances(posed, *tolerance);
          if (!results.ok()) return results.status();  // poses and tolerance checked above
          wire::AppendDistanceResults(*results, response->mutable_results());
          AddWork(*results, response);
        }
        response->set_seconds(SecondsSince(start));
        response->set_threads(tbb::this_task_arena::max_concurrency());
        return absl::OkStatus();
      });
}

grpc::ServerUnaryReactor* InscribeService::CacheStats(grpc::CallbackServerContext* context,
                                                      const v1::CacheStatsRequest* /*request*/,
                                                      v1::CacheStatsResponse* response) {
  // A snapshot of counters under the cache's lock: cheap enough for the gRPC thread, and it
  // must answer even when the pool is saturated.
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (absl::Status admitted = Authenticate(*context); !admitted.ok()) {
    CallRecord record;
    record.method = "CacheStats";
    record.peer = context->peer();
    CallStarted();
    Finish(reactor, record, admitted);  // observed, so refusals are logged and counted
    return reactor;
  }
  const ResultCacheStats s = store_->cache().stats();
  response->set_entries(s.entries);
  response->set_bytes(s.bytes);
  response->set_memory_hits(s.memory_hits);
  response->set_disk_hits(s.disk_hits);
  response->set_hits(s.memory_hits + s.disk_hits);
  response->set_misses(s.misses);
  response->set_computations(s.computations);
  response->set_joined(s.joined);
  response->set_evictions(s.evictions);
  response->set_disk_entries(s.disk_entries);
  response->set_disk_bytes(s.disk_bytes);
  response->set_disk_errors(s.disk_errors);
  response->set_shared_hits(s.shared_hits);
  response->set_shared_misses(s.shared_misses);
  response->set_shared_errors(s.shared_errors);
  response->set_shared_writes(s.shared_writes);
  response->set_shared_write_errors(s.shared_write_errors);
  response->set_shared_skipped(s.shared_skipped);
  response->set_shared_corrupt(s.shared_corrupt);
  response->set_shared_available(s.shared_available);
  response->set_disk_write_errors(s.disk_write_errors);
  response->set_disk_writes_skipped(s.disk_writes_skipped);
  response->set_disk_available(s.disk_available);
  response->set_disk_bytes_limit(s.disk_bytes_limit);
  response->set_disk_evictions(s.disk_evictions);
  response->set_disk_evicted_bytes(s.disk_evicted_bytes);
  response->set_disk_writes_too_large(s.disk_writes_too_large);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace inscribe::server
