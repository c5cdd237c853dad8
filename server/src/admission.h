// The service's door: what every call passes before its work starts, for every RPC (the unary
// calls, Generate, DistanceStream and SceneStream and each of their frames), and who is inside
// (calls in flight, open streams) so that the door can be closed (drain). Private to the server.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <set>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "drainable_stream.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/server/job_pool.h"
#include "memory_budget.h"

namespace inscribe::server {

// A call passes, in this order:
//   1. the authenticator (UNAUTHENTICATED, PERMISSION_DENIED): a refused caller learns nothing
//      else, neither whether the server drains nor what its request's problems are;
//   2. the door being open: UNAVAILABLE ("server is shutting down; retry") while draining;
//   3. its own O(1) checks, made by the handler on the gRPC thread (shapes, limits naming their
//      flag), so that bad or oversized requests never occupy the queue;
//   4. its estimated working memory, reserved from --memory-budget (MemoryBudget::Reserve);
//   5. a place in the job pool: RESOURCE_EXHAUSTED naming --max-queue when it is full;
// and once its job is about to start, whether the caller still wants the answer (StillWanted).
// Every call, refused or answered, is counted from CallStarted to CallEnded and told to the
// observer. Thread-safe; every check is O(1) and fit for a gRPC thread.
class Admission {
 public:
  // `pool` must outlive this. `memory_budget_bytes`: --memory-budget (0 = unlimited).
  // `authenticate` and `observer` may be empty (every caller admitted; nobody told).
  Admission(JobPool* pool, std::int64_t memory_budget_bytes, CallAuthenticator authenticate,
            CallObserver observer);
  Admission(const Admission&) = delete;
  Admission& operator=(const Admission&) = delete;

  // Step 1 alone: for CacheStats, which answers while draining and with the pool full.
  absl::Status Authenticate(const grpc::CallbackServerContext& context) const;
  // Steps 1 and 2: whether a call may start at all. A stream checks this under its own lock,
  // so that a drain starting meanwhile is either seen here or finds the stream reading.
  absl::Status Enter(const grpc::CallbackServerContext& context) const;
  // Steps 1 to 4 for one call: Enter, then `precheck` (step 3, the handler's verdict), then
  // `memory_bytes` reserved for `what` (e.g. "Distance of 1000 pose pairs"). The reservation,
  // or the status to finish the call with.
  absl::StatusOr<MemoryBudget::Reservation> Admit(const grpc::CallbackServerContext& context,
                                                  const absl::Status& precheck,
                                                  std::int64_t memory_bytes,
                                                  const std::string& what, CallRecord& record);
  // Step 4 alone, for a stream's frame or a size learnt on the pool: `bytes` for `what`, noted
  // in record->memory_bytes (the most a call held at once) when given.
  absl::StatusOr<MemoryBudget::Reservation> Reserve(std::int64_t bytes, const std::string& what,
                                                    CallRecord* record = nullptr);
  // Step 5: queues `job` on the lane `size`, or returns QueueFullError, dropping it unrun.
  absl::Status Queue(std::function<void()> job, JobSize size);
  // RESOURCE_EXHAUSTED naming --max-queue: the pool refused a job (also for a stream's frame,
  // which the FrameDispatcher queues).
  absl::Status QueueFullError() const;
  // For a queued job about to start: CANCELLED when the caller gave up (the context says so,
  // or `cancelled`: the reactor's own OnCancel flag), DEADLINE_EXCEEDED when its deadline has
  // passed, even before gRPC has noticed it; else OK.
  static absl::Status StillWanted(const grpc::CallbackServerContext& context,
                                  bool cancelled = false);

  // A call arrived (before any check); it counts as active until CallEnded.
  void CallStarted();
  void CallEnded();
  // Tells the observer about a finished call, refused ones included (access logs, metrics).
  void Observe(const CallRecord& record) const;
  // An open stream, told when draining starts; registered from its start to its OnDone.
  void AddStream(DrainableStream* stream);
  void RemoveStream(DrainableStream* stream);

  // Closes the door (step 2 refuses from now on) and tells every open stream to end.
  void StartDraining();
  // Blocks until no call is active or `deadline` passes; true when none is.
  bool WaitForCalls(std::chrono::system_clock::time_point deadline);

  // --memory-budget in bytes; 0 = unlimited.
  std::int64_t memory_budget_bytes() const { return memory_.budget(); }

 private:
  JobPool* const pool_;
  MemoryBudget memory_;
  const CallAuthenticator authenticate_;
  const CallObserver observer_;

  std::atomic<bool> draining_{false};
  std::mutex calls_mutex_;
  std::condition_variable calls_answered_;
  std::int64_t active_calls_ = 0;       // guarded by calls_mutex_
  std::set<DrainableStream*> streams_;  // guarded by calls_mutex_
};

}  // namespace inscribe::server
