#include "inscribe/server/inscribe_service.h"

#include <chrono>
#include <exception>
#include <functional>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "frame_dispatch.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "mesh_sizes.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// The body of InspectMesh, run on the pool. Only expected failures are returned; the mesh's
// own problems are issues in the report, not errors.
absl::Status RunInspectMesh(const v1::InspectMeshRequest& request,
                            v1::InspectMeshResponse* response) {
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(request.mesh());
  if (!mesh.ok()) return mesh.status();
  ValidateOptions options;
  options.check_self_intersections = !request.skip_self_intersections();
  options.fill_holes = request.fill_holes();
  options.weld_tolerance = request.weld_tolerance();
  const ValidatedMesh validated = ValidateMesh(*std::move(mesh), options);
  const MeshReport& report = validated.report;
  // As the CLI does: a hash over NaNs or dangling indices would key nothing usable.
  if (report.non_finite_vertices == 0 && report.out_of_range_indices == 0) {
    response->set_mesh_sha256(FormatSha256(MeshSha256(validated.mesh)));
  }
  wire::MeshReportToProto(report, response->mutable_report());
  return absl::OkStatus();
}

}  // namespace

InscribeService::InscribeService(JobPool* pool, ResultCache* cache, const ServiceLimits& limits,
                                 CallObserver observer, CallAuthenticator authenticate)
    : pool_(pool),
      frames_(std::make_unique<FrameDispatcher>(pool)),
      store_(
          std::make_unique<ResultStore>(cache, StoreLimits{limits.max_voxels, limits.max_spheres})),
      memory_(std::make_unique<MemoryBudget>(limits.memory_budget_bytes)),
      mesh_sizes_(std::make_unique<MeshSizes>()),
      limits_(limits),
      observer_(std::move(observer)),
      authenticate_(std::move(authenticate)) {}

InscribeService::~InscribeService() = default;

void InscribeService::CallStarted() {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  ++active_calls_;
}

void InscribeService::CallEnded() {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  if (--active_calls_ == 0) calls_answered_.notify_all();
}

void InscribeService::Observe(const CallRecord& record) const {
  if (observer_) observer_(record);
}

absl::Status InscribeService::Authenticate(const grpc::CallbackServerContext& context) const {
  return authenticate_ ? authenticate_(context) : absl::OkStatus();
}

void InscribeService::Finish(grpc::ServerUnaryReactor* reactor, CallRecord& record,
                             const absl::Status& status) {
  record.status = status;
  Observe(record);
  reactor->Finish(wire::ToGrpcStatus(status));
  CallEnded();
}

absl::Status InscribeService::QueueFullError() const {
  return absl::ResourceExhaustedError(
      absl::StrCat("server is busy: the job queue is full; this server's limit (--max-queue) is ",
                   pool_->options().max_jobs, " queued or running jobs; retry later"));
}

bool InscribeService::WaitForCalls(std::chrono::system_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(calls_mutex_);
  return calls_answered_.wait_until(lock, deadline, [this] { return active_calls_ == 0; });
}

grpc::ServerUnaryReactor* InscribeService::RunUnary(grpc::CallbackServerContext* context,
                                                    const char* method, std::int64_t triangles,
                                                    const absl::Status& precheck,
                                                    std::int64_t memory_bytes, std::string what,
                                                    std::function<absl::Status()> body) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  const ServiceClock::time_point arrived = ServiceClock::now();
  CallRecord record;
  record.method = method;
  record.peer = context->peer();
  record.triangles = triangles;
  CallStarted();
  // Refused callers learn nothing else: not whether the server drains, nor what their
  // request's problems are.
  if (absl::Status admitted = Authenticate(*context); !admitted.ok()) {
    Finish(reactor, record, admitted);
    return reactor;
  }
  if (draining_.load()) {
    Finish(reactor, record, absl::UnavailableError("server is shutting down; retry"));
    return reactor;
  }
  // O(1) checks stay on the gRPC thread, so bad or oversized requests never occupy the queue.
  if (!precheck.ok()) {
    Finish(reactor, record, precheck);
    return reactor;
  }
  // Reserved before queueing, so that queued calls count too; held by the job (shared: a
  // std::function must be copyable) and given back when the job ends, whichever way it ends,
  // or at once when the pool refuses it.
  absl::StatusOr<MemoryBudget::Reservation> reserved = memory_->Reserve(memory_bytes, what);
  if (!reserved.ok()) {
    Finish(reactor, record, reserved.status());
    return reactor;
  }
  record.memory_bytes = reserved->bytes();
  auto reservation = std::make_shared<MemoryBudget::Reservation>(*std::move(reserved));
  const JobSize size = memory_bytes <= MemoryCosts::kSmallJob ? JobSize::kSmall : JobSize::kLarge;
  const bool queued = pool_->TrySubmit(
      [this, context, reactor, arrived, record, reservation, body = std::move(body)]() mutable {
        record.queued_seconds = SecondsSince(arrived);
        // The caller may have given up (cancel, disconnect) while the job waited; a passed
        // deadline counts too, even before gRPC has noticed it and cancelled the call.
        if (context->IsCancelled()) {
          Finish(reactor, record, absl::CancelledError("call was cancelled before work started"));
          return;
        }
        if (std::chrono::system_clock::now() >= context->deadline()) {
          Finish(reactor, record,
                 absl::DeadlineExceededError("deadline passed before work started"));
          return;
        }
        const ServiceClock::time_point started = ServiceClock::now();
        absl::Status status;
        // Jobs must not throw (JobPool); running out of memory on a huge request is the one
        // exception worth expecting here, and is the caller's to act on.
        try {
          status = body();
        } catch (const std::bad_alloc&) {
          status = absl::ResourceExhaustedError(
              absl::StrCat("server ran out of memory in ", record.method,
                           "; send a smaller request or retry later"));
        } catch (const std::exception& e) {
          status = absl::InternalError(absl::StrCat(record.method, " failed: ", e.what()));
        }
        record.run_seconds = SecondsSince(started);
        reservation->Release();
        Finish(reactor, record, status);
      },
      size);
  if (!queued) Finish(reactor, record, QueueFullError());
  return reactor;
}

absl::Status InscribeService::CheckMesh(const v1::Mesh& mesh) const {
  if (absl::Status shape = wire::CheckMeshShape(mesh); !shape.ok()) return shape;
  if (wire::TriangleCount(mesh) > limits_.max_triangles) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "mesh has ", wire::TriangleCount(mesh),
        " triangles; this server's limit (--max-triangles) is ", limits_.max_triangles));
  }
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* InscribeService::InspectMesh(grpc::CallbackServerContext* context,
                                                       const v1::InspectMeshRequest* request,
                                                       v1::InspectMeshResponse* response) {
  return RunUnary(
      context, "InspectMesh", wire::TriangleCount(request->mesh()), CheckMesh(request->mesh()),
      MeshWorkBytes(request->mesh()),
      absl::StrCat("InspectMesh of ", wire::TriangleCount(request->mesh()), " triangles"),
      [request, response] { return RunInspectMesh(*request, response); });
}

}  // namespace inscribe::server
