#include "admission.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace inscribe::server {

Admission::Admission(JobPool* pool, std::int64_t memory_budget_bytes,
                     CallAuthenticator authenticate, CallObserver observer)
    : pool_(pool),
      memory_(memory_budget_bytes),
      authenticate_(std::move(authenticate)),
      observer_(std::move(observer)) {}

absl::Status Admission::Authenticate(const grpc::CallbackServerContext& context) const {
  return authenticate_ ? authenticate_(context) : absl::OkStatus();
}

absl::Status Admission::Enter(const grpc::CallbackServerContext& context) const {
  if (absl::Status authenticated = Authenticate(context); !authenticated.ok()) {
    return authenticated;
  }
  if (draining_.load()) return absl::UnavailableError("server is shutting down; retry");
  return absl::OkStatus();
}

absl::StatusOr<MemoryBudget::Reservation> Admission::Admit(
    const grpc::CallbackServerContext& context, const absl::Status& precheck,
    std::int64_t memory_bytes, const std::string& what, CallRecord& record) {
  if (absl::Status entered = Enter(context); !entered.ok()) return entered;
  if (!precheck.ok()) return precheck;
  return Reserve(memory_bytes, what, &record);
}

absl::StatusOr<MemoryBudget::Reservation> Admission::Reserve(std::int64_t bytes,
                                                             const std::string& what,
                                                             CallRecord* record) {
  absl::StatusOr<MemoryBudget::Reservation> reserved = memory_.Reserve(bytes, what);
  if (reserved.ok() && record != nullptr) {
    record->memory_bytes = std::max(record->memory_bytes, reserved->bytes());
  }
  return reserved;
}

absl::Status Admission::Queue(std::function<void()> job, JobSize size) {
  if (!pool_->TrySubmit(std::move(job), size)) return QueueFullError();
  return absl::OkStatus();
}

absl::Status Admission::QueueFullError() const {
  return absl::ResourceExhaustedError(
      absl::StrCat("server is busy: the job queue is full; this server's limit (--max-queue) is ",
                   pool_->options().max_jobs, " queued or running jobs; retry later"));
}

absl::Status Admission::StillWanted(const grpc::CallbackServerContext& context, bool cancelled) {
  if (cancelled || context.IsCancelled()) {
    return absl::CancelledError("call was cancelled before work started");
  }
  if (std::chrono::system_clock::now() >= context.deadline()) {
    return absl::DeadlineExceededError("deadline passed before work started");
  }
  return absl::OkStatus();
}

void Admission::CallStarted() {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  ++active_calls_;
}

void Admission::CallEnded() {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  if (--active_calls_ == 0) calls_answered_.notify_all();
}

void Admission::Observe(const CallRecord& record) const {
  if (observer_) observer_(record);
}

void Admission::AddStream(DrainableStream* stream) {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  streams_.insert(stream);
}

void Admission::RemoveStream(DrainableStream* stream) {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  streams_.erase(stream);
}

void Admission::StartDraining() {
  draining_.store(true);
  // Each stream is held by a reference while it is told, outside the lock: Drain may finish
  // it, and its OnDone takes the lock to leave the set.
  std::vector<DrainableStream*> streams;
  {
    std::lock_guard<std::mutex> lock(calls_mutex_);
    for (DrainableStream* stream : streams_) {
      stream->Ref();
      streams.push_back(stream);
    }
  }
  for (DrainableStream* stream : streams) {
    stream->Drain();
    stream->Unref();
  }
}

bool Admission::WaitForCalls(std::chrono::system_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(calls_mutex_);
  return calls_answered_.wait_until(lock, deadline, [this] { return active_calls_ == 0; });
}

}  // namespace inscribe::server
