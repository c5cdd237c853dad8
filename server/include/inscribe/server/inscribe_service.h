// The inscribe.v1.Inscribe gRPC service (callback API).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/server/job_pool.h"
#include "inscribe/server/result_cache.h"
#include "inscribe/v1/service.grpc.pb.h"

namespace inscribe::server {

class Admission;
class FrameDispatcher;
class MeshSizes;
class ResultStore;
struct ServiceParts;

// Per-request limits. Each is a flag of `inscribed` with the same name; a breach is
// RESOURCE_EXHAUSTED with a message naming the flag.
struct ServiceLimits {
  // --max-triangles: triangles in one mesh. Validation costs O(#T log #T) time and ~100 bytes
  // of memory per triangle on top of the request.
  std::int64_t max_triangles = 5'000'000;
  // Vertices in one UpdateDeformation: 3 x max_triangles (a closed mesh has about half as
  // many vertices as triangles), saturating, so an unlimited max_triangles stays unlimited.
  std::int64_t MaxDeformVertices() const {
    constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
    return max_triangles > kMax / 3 ? kMax : 3 * max_triangles;
  }
  // --max-voxels: voxels in one generation grid (a finer grid is INVALID_ARGUMENT up front).
  std::int64_t max_voxels = 20'000'000;
  // --max-spheres: a Generate sphere budget, and spheres in one inline sphere set.
  std::int64_t max_spheres = 1'000'000;
  // --max-poses: pose pairs in one Distance call, or object pairs in one stream frame.
  std::int64_t max_poses = 1'000'000;
  // --max-scene-objects: objects in one SceneStream's scene at once. The broad phase costs
  // O(n + k) per frame for n objects and k candidate pairs, the scene ~512 bytes per object.
  std::int64_t max_scene_objects = 100'000;
  // --max-scene-pairs: close pairs in one SceneStream reply (the largest SceneQuery.max_pairs;
  // its default is the smaller of this and 100,000).
  std::int64_t max_scene_pairs = 100'000;
  // --max-scene-ignored: ignored pairs one SceneStream may send over its life.
  std::int64_t max_scene_ignored = 1'000'000;
  // --memory-budget: bytes of working memory the calls in flight (queued or running) may need
  // together, by an up-front estimate from each request's sizes (server/src/memory_budget.h
  // lists the per-item costs and how they were measured); 0 = unlimited. A call whose estimate
  // alone exceeds it is RESOURCE_EXHAUSTED naming the flag; one that does not fit next to the
  // calls in flight is RESOURCE_EXHAUSTED saying to retry, as a full --max-queue is. Not
  // counted: the result cache (--cache-memory-bytes), the process's baseline and the request
  // and reply messages gRPC holds (each at most --max-message-bytes). 4 GiB covers the default
  // limits' largest Generate (--max-voxels) and mesh (--max-triangles) one at a time.
  std::int64_t memory_budget_bytes = std::int64_t{4} << 30;
};

// What the service did with one call, for access logs and metrics. Times in seconds.
struct CallRecord {
  const char* method = "";         // RPC name, e.g. "InspectMesh"
  std::string peer;                // grpc peer string, e.g. "ipv4:127.0.0.1:53412"
  absl::Status status;             // what the caller was sent
  std::int64_t triangles = 0;      // size of the request's mesh
  double queued_seconds = 0.0;     // from arrival to the start of the job (0 if never queued)
  double run_seconds = 0.0;        // time the job ran (on the pool, or inline for stream frames)
  std::int64_t memory_bytes = 0;   // working memory reserved by estimate (--memory-budget)
  std::int64_t frames = 0;         // streams: frames answered
  std::int64_t inline_frames = 0;  // of which on the gRPC thread that read them (FrameDispatcher)
};

// Called once per finished call, on a gRPC or pool thread, before the reply is sent; must be
// thread-safe and fast. Libraries do not log: the `inscribed` binary passes a logger here.
using CallObserver = std::function<void(const CallRecord&)>;

// Admits or refuses a call from its metadata before any work is done: OK, or the status the
// caller gets (UNAUTHENTICATED, PERMISSION_DENIED); the observer still sees refused calls.
// Called on the gRPC thread for every inscribe.v1 call (not health or reflection), so it must
// be thread-safe and take microseconds. InscribeServer builds one from --auth-tokens.
using CallAuthenticator = std::function<absl::Status(const grpc::CallbackServerContext& context)>;

// Handlers check what is O(1) to check (array shapes, limits, cancellation) on the gRPC thread
// and hand everything else to `pool`; they never compute on gRPC threads, with one exception:
// stream frames of a few queries whose cost the stream has measured are answered on the gRPC
// thread that read them (server/src/frame_dispatch.h, one rule for every stream). `pool` must
// outlive the service and be drained (JobPool::WaitIdle) before the service is destroyed.
class InscribeService final : public v1::Inscribe::CallbackService {
 public:
  // `cache` holds meshes and results; it must outlive the service.
  // `authenticate` may be empty: every call is admitted.
  InscribeService(JobPool* pool, ResultCache* cache, const ServiceLimits& limits,
                  CallObserver observer = nullptr, CallAuthenticator authenticate = nullptr);
  ~InscribeService() override;

  // Validates the mesh (core ValidateMesh, orientation fixed) and replies with the report and
  // the hash of the fixed mesh. Errors: see service.proto.
  grpc::ServerUnaryReactor* InspectMesh(grpc::CallbackServerContext* context,
                                        const v1::InspectMeshRequest* request,
                                        v1::InspectMeshResponse* response) override;

  // The RPCs below: see service.proto for what each returns and its errors.
  grpc::ServerUnaryReactor* PutMesh(grpc::CallbackServerContext* context,
                                    const v1::PutMeshRequest* request,
                                    v1::PutMeshResponse* response) override;
  grpc::ServerWriteReactor<v1::GenerateResponse>* Generate(
      grpc::CallbackServerContext* context, const v1::GenerateRequest* request) override;
  grpc::ServerUnaryReactor* PutSphereSet(grpc::CallbackServerContext* context,
                                         const v1::PutSphereSetRequest* request,
                                         v1::PutSphereSetResponse* response) override;
  grpc::ServerUnaryReactor* GetSphereSet(grpc::CallbackServerContext* context,
                                         const v1::GetSphereSetRequest* request,
                                         v1::GetSphereSetResponse* response) override;
  grpc::ServerUnaryReactor* GetHierarchy(grpc::CallbackServerContext* context,
                                         const v1::GetHierarchyRequest* request,
                                         v1::GetHierarchyResponse* response) override;
  grpc::ServerUnaryReactor* Distance(grpc::CallbackServerContext* context,
                                     const v1::DistanceRequest* request,
                                     v1::DistanceResponse* response) override;
  grpc::ServerUnaryReactor* UpdateDeformation(grpc::CallbackServerContext* context,
                                              const v1::UpdateDeformationRequest* request,
                                              v1::UpdateDeformationResponse* response) override;
  grpc::ServerBidiReactor<v1::DistanceFrame, v1::DistanceFrameResult>* DistanceStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerBidiReactor<v1::SceneMessage, v1::SceneReply>* SceneStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* Evaluate(grpc::CallbackServerContext* context,
                                     const v1::EvaluateRequest* request,
                                     v1::EvaluateResponse* response) override;
  grpc::ServerUnaryReactor* CertifyCover(grpc::CallbackServerContext* context,
                                         const v1::CertifyCoverRequest* request,
                                         v1::CertifyCoverResponse* response) override;
  grpc::ServerUnaryReactor* CacheStats(grpc::CallbackServerContext* context,
                                       const v1::CacheStatsRequest* request,
                                       v1::CacheStatsResponse* response) override;

  // Graceful shutdown, first half: from now on new calls get UNAVAILABLE ("server is shutting
  // down"), which clients retry, later or on another replica; calls already accepted go on.
  // Open DistanceStreams and SceneStreams end with UNAVAILABLE after the frame they are on (at
  // once when waiting for one), so that long-lived simulator sessions do not hold the drain up.
  void StartDraining();

  // SceneStream calls open now, each holding its scene (metrics: inscribe_scenes_open).
  std::int64_t open_scenes() const { return open_scenes_.load(); }

  // Blocks until every accepted call has been answered or `deadline` passes; true when all
  // were answered. gRPC's own Shutdown(deadline) also waits for idle client connections to
  // close, which long-lived clients never do: waiting here first lets the server then shut
  // down with an immediate deadline without cutting off any call.
  bool WaitForCalls(std::chrono::system_clock::time_point deadline);

 private:
  // Sends `status` to the caller after telling the observer; the call then no longer counts
  // as active.
  void Finish(grpc::ServerUnaryReactor* reactor, CallRecord& record, const absl::Status& status);

  // The shape of every unary call: counts it as active, admits it (Admission::Admit: the
  // caller, draining, `precheck` (O(1) checks done on the gRPC thread), `memory_bytes` of
  // --memory-budget for `what`, e.g. "Distance of 1000 pose pairs") or finishes it with the
  // refusal, else queues `body` on the pool and, once the caller is still waiting and within its
  // deadline, runs it and replies with its status. `body` may throw std::bad_alloc
  // (RESOURCE_EXHAUSTED) but nothing else escapes. The reservation is given back when `body`
  // returns (or the call is refused or cancelled).
  grpc::ServerUnaryReactor* RunUnary(grpc::CallbackServerContext* context, const char* method,
                                     std::int64_t triangles, const absl::Status& precheck,
                                     std::int64_t memory_bytes, std::string what,
                                     std::function<absl::Status()> body);

  // Distance with brute_force: every sphere pair of the two cached sets per pose pair.
  absl::Status BruteForceDistances(const v1::DistanceRequest& request,
                                   const std::vector<RigidPose>& poses_a,
                                   const std::vector<RigidPose>& poses_b,
                                   const DistanceRequest& tolerance,
                                   v1::DistanceResponse* response);

  // Distance with covers: certified intervals (core's CertifiedDistances) from the objects
  // ResultStore::GetCertifiedObject holds (the certificate rule).
  absl::Status CertifiedDistances(const v1::DistanceRequest& request,
                                  const std::vector<RigidPose>& poses_a,
                                  const std::vector<RigidPose>& poses_b,
                                  const DistanceRequest& tolerance, v1::DistanceResponse* response);

  // Shape and --max-triangles of a request's mesh: INVALID_ARGUMENT or RESOURCE_EXHAUSTED.
  absl::Status CheckMesh(const v1::Mesh& mesh) const;

  // What the reactors of Generate and the streams may use (server/src/service_parts.h).
  ServiceParts Parts();

  std::unique_ptr<Admission> admission_;     // the checks before work; calls in flight; drain
  std::unique_ptr<FrameDispatcher> frames_;  // inline or pool, for every stream's frames
  std::unique_ptr<ResultStore> store_;
  std::unique_ptr<MeshSizes> mesh_sizes_;  // of meshes stored here, for Generate's estimate
  const ServiceLimits limits_;
  // Open SceneStreams (each holds one scene until its call is done).
  std::atomic<std::int64_t> open_scenes_{0};
};

}  // namespace inscribe::server
