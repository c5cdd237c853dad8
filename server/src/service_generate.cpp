// Generate: spheres for a stored mesh (GenerateSphereSet through the store's cache), streamed
// with progress. Its grid and working memory are estimated on the gRPC thread from the mesh's
// size when this process stored it (MeshSizes).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "admission.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "mesh_sizes.h"
#include "result_store.h"
#include "service_checks.h"
#include "service_parts.h"

namespace inscribe::server {
namespace {

// Estimated working memory of a Generate on `mesh_key` with `parameters`, from the mesh's size
// when this process stored it (O(1)); INVALID_ARGUMENT naming --max-voxels (`limits`) when its
// grid would be too fine. `memory_budget`: --memory-budget (0 = unlimited).
absl::StatusOr<std::int64_t> GenerateWorkBytes(const MeshSizes& mesh_sizes,
                                               const std::string& mesh_key,
                                               const SphereSetParameters& parameters,
                                               const ServiceLimits& limits,
                                               std::int64_t memory_budget) {
  const std::optional<MeshSize> size = mesh_sizes.Find(mesh_key);
  // The request's grid limit, already capped by this server's.
  const double max_voxels = static_cast<double>(parameters.medial.max_voxels);
  const bool server_limit_binds = parameters.medial.max_voxels >= limits.max_voxels;
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
          limits.max_voxels));
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
  if (!size && memory_budget > 0) bytes = std::min(bytes, double(memory_budget));
  return static_cast<std::int64_t>(bytes);
}

// Generate: a server-streaming call. The job on the pool reports progress; at most one write is
// in flight, so progress messages that arrive during a write are dropped (the next one carries
// a later fraction). The result is the last message. Cancellation (the caller gave up, or its
// deadline passed) sets the flag generation polls, so the worker stops promptly.
class GenerateReactor final : public grpc::ServerWriteReactor<v1::GenerateResponse> {
 public:
  GenerateReactor(const ServiceParts& parts, grpc::CallbackServerContext* context,
                  const v1::GenerateRequest* request)
      : parts_(parts), context_(context), request_(request) {
    record_.method = "Generate";
    record_.peer = context->peer();
  }

  void Start() {
    parts_.admission.CallStarted();
    std::int64_t bytes = 0;
    const absl::Status precheck = Check(&bytes);
    absl::StatusOr<MemoryBudget::Reservation> reserved =
        parts_.admission.Admit(*context_, precheck, bytes,
                               absl::StrCat("Generate on mesh ", request_->mesh_sha256()), record_);
    if (!reserved.ok()) {
      Complete(reserved.status(), nullptr);
      return;
    }
    reservation_ = *std::move(reserved);
    const ServiceClock::time_point arrived = ServiceClock::now();
    // Always the large lane: the fixed cost alone (MemoryCosts::kGenerateFixed) is over
    // kSmallJob, though a clamped estimate may not be.
    if (absl::Status queued =
            parts_.admission.Queue([this, arrived] { Run(arrived); }, JobSize::kLarge);
        !queued.ok()) {
      Complete(queued, nullptr);
    }
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
    parts_.admission.CallEnded();
    delete this;
  }

 private:
  // The O(1) checks of the request on the gRPC thread: the mesh key, the parameters (their
  // grid capped by --max-voxels) and the estimate of their working memory into *bytes.
  absl::Status Check(std::int64_t* bytes) {
    if (absl::Status s = CheckKey(request_->mesh_sha256(), "mesh_sha256"); !s.ok()) return s;
    absl::StatusOr<SphereSetParameters> parameters =
        wire::SphereSetParametersFromProto(*request_, parts_.limits.max_voxels);
    if (!parameters.ok()) return parameters.status();
    parameters_ = *std::move(parameters);
    absl::StatusOr<MeshRepair> repair = wire::MeshRepairFromProto(
        request_->parameters().repair(), request_->parameters().fill_holes());
    if (!repair.ok()) return repair.status();
    repair_ = *repair;
    absl::StatusOr<std::int64_t> estimate =
        GenerateWorkBytes(parts_.mesh_sizes, request_->mesh_sha256(), parameters_, parts_.limits,
                          parts_.admission.memory_budget_bytes());
    if (!estimate.ok()) return estimate.status();
    *bytes = *estimate;
    return absl::OkStatus();
  }

  void Run(ServiceClock::time_point arrived) {
    record_.queued_seconds = SecondsSince(arrived);
    const auto deadline = context_->deadline();
    if (absl::Status wanted = Admission::StillWanted(*context_, cancel_.load()); !wanted.ok()) {
      Complete(wanted, nullptr);
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
      result = parts_.store.Generate(request_->mesh_sha256(), parameters_, repair_, control);
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
    parts_.admission.Observe(record_);
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

  const ServiceParts parts_;
  grpc::CallbackServerContext* const context_;
  const v1::GenerateRequest* const request_;
  SphereSetParameters parameters_;         // the request's, checked in Start
  MeshRepair repair_ = MeshRepair::kSafe;  // the repair the mesh was stored with, from Start
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

}  // namespace

grpc::ServerWriteReactor<v1::GenerateResponse>* InscribeService::Generate(
    grpc::CallbackServerContext* context, const v1::GenerateRequest* request) {
  auto* reactor = new GenerateReactor(Parts(), context, request);
  reactor->Start();
  return reactor;
}

}  // namespace inscribe::server
