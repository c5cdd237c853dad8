// The service's shape: its parts, the unary call's life (RunUnary), and drain. The RPCs are in
// the service_*.cpp files named after them, the streams in distance_stream.cpp and
// scene_stream.cpp.
#include "inscribe/server/inscribe_service.h"

#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <new>
#include <utility>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "frame_dispatch.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "mesh_sizes.h"
#include "result_store.h"
#include "service_checks.h"
#include "service_parts.h"

namespace inscribe::server {

InscribeService::InscribeService(JobPool* pool, ResultCache* cache, const ServiceLimits& limits,
                                 CallObserver observer, CallAuthenticator authenticate)
    : admission_(std::make_unique<Admission>(pool, limits.memory_budget_bytes,
                                             std::move(authenticate), std::move(observer))),
      frames_(std::make_unique<FrameDispatcher>(pool)),
      store_(
          std::make_unique<ResultStore>(cache, StoreLimits{limits.max_voxels, limits.max_spheres})),
      mesh_sizes_(std::make_unique<MeshSizes>()),
      limits_(limits) {}

InscribeService::~InscribeService() = default;

ServiceParts InscribeService::Parts() {
  return ServiceParts{*admission_, *store_, *frames_, *mesh_sizes_, limits_, open_scenes_};
}

void InscribeService::StartDraining() { admission_->StartDraining(); }

bool InscribeService::WaitForCalls(std::chrono::system_clock::time_point deadline) {
  return admission_->WaitForCalls(deadline);
}

void InscribeService::Finish(grpc::ServerUnaryReactor* reactor, CallRecord& record,
                             const absl::Status& status) {
  record.status = status;
  admission_->Observe(record);
  reactor->Finish(wire::ToGrpcStatus(status));
  admission_->CallEnded();
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
  admission_->CallStarted();
  absl::StatusOr<MemoryBudget::Reservation> reserved =
      admission_->Admit(*context, precheck, memory_bytes, what, record);
  if (!reserved.ok()) {
    Finish(reactor, record, reserved.status());
    return reactor;
  }
  // Reserved before queueing, so that queued calls count too; held by the job (shared: a
  // std::function must be copyable) and given back when the job ends, whichever way it ends,
  // or at once when the pool refuses it.
  auto reservation = std::make_shared<MemoryBudget::Reservation>(*std::move(reserved));
  const absl::Status queued = admission_->Queue(
      [this, context, reactor, arrived, record, reservation, body = std::move(body)]() mutable {
        record.queued_seconds = SecondsSince(arrived);
        // The caller may have given up (cancel, disconnect) while the job waited.
        if (absl::Status wanted = Admission::StillWanted(*context); !wanted.ok()) {
          Finish(reactor, record, wanted);
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
      LaneFor(memory_bytes));
  if (!queued.ok()) Finish(reactor, record, queued);
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

}  // namespace inscribe::server
