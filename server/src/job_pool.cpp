#include "inscribe/server/job_pool.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <utility>

#include "oneapi/tbb/global_control.h"
#include "oneapi/tbb/task_arena.h"

// ThreadSanitizer cannot see that TBB's (uninstrumented) queue orders a job's submission before
// its start. In TSan builds the submitter enqueues under a mutex that the job takes once before
// it reads anything (a global one: the job's own fields are what must not be read first), which
// orders the two in a way TSan sees (scripts/sanitize thread); elsewhere this is nothing.
#if defined(__SANITIZE_THREAD__)
#define INSCRIBE_TSAN_HANDOFF 1
#else
#define INSCRIBE_TSAN_HANDOFF 0
#endif

namespace inscribe::server {
namespace {
#if INSCRIBE_TSAN_HANDOFF
std::mutex tsan_handoff_mutex;
#endif
}  // namespace

struct JobPool::Impl {
  explicit Impl(const JobPoolOptions& pool_options)
      : options(pool_options),
        scheduler(tbb::attach{}),
        // max_allowed_parallelism counts the calling thread too: workers = value - 1.
        parallelism(
            tbb::global_control::max_allowed_parallelism,
            std::max<std::size_t>(
                tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
                static_cast<std::size_t>(pool_options.concurrency) +
                    static_cast<std::size_t>(std::max(pool_options.small_job_threads, 0)) + 1)),
        // No slot is reserved for an external thread: jobs are enqueued, never waited on inside
        // the arena, so all `concurrency` slots go to workers.
        arena(pool_options.concurrency, /*reserved_for_masters=*/0),
        // Its own arena: TBB gives each arena its own workers, and a job's parallel loops stay
        // in the arena they started in, so large jobs cannot take the lane's threads.
        small_arena(std::max(pool_options.small_job_threads, 1), /*reserved_for_masters=*/0) {}

  void Finish() {
    // Decrement under the lock so that WaitIdle cannot return (and the pool be destroyed)
    // between the decrement and the notification.
    std::lock_guard<std::mutex> lock(idle_mutex);
    if (in_flight.fetch_sub(1, std::memory_order_acq_rel) == 1) idle.notify_all();
  }

  const JobPoolOptions options;
  // Lets the destructor wait for TBB's worker threads to exit (tbb::finalize).
  tbb::task_scheduler_handle scheduler;
  tbb::global_control parallelism;
  tbb::task_arena arena;
  tbb::task_arena small_arena;  // used only when options.small_job_threads > 0
  std::atomic<std::int64_t> in_flight{0};
  std::mutex idle_mutex;
  std::condition_variable idle;
};

JobPool::JobPool(const JobPoolOptions& options) : impl_(std::make_unique<Impl>(options)) {
  assert(options.concurrency >= 1 && options.max_jobs >= 1);
}

JobPool::~JobPool() {
  WaitIdle();
  impl_->arena.terminate();
  impl_->small_arena.terminate();
  // Join TBB's workers when nothing else in the process uses TBB (otherwise this returns false
  // at once and they live on). Workers left running at exit race the process's teardown: they
  // may still be running thread-exit handlers (e.g. OpenSSL freeing its per-thread state, used
  // by the mesh hash) when exit() starts destroying globals.
  tbb::finalize(impl_->scheduler, std::nothrow);
}

bool JobPool::TrySubmit(std::function<void()> job, JobSize size) {
  // Reserve a place first, then give it back if over the limit: the count never exceeds
  // max_jobs by more than the number of racing submitters, and never admits more than max_jobs.
  if (impl_->in_flight.fetch_add(1, std::memory_order_acq_rel) >= impl_->options.max_jobs) {
    impl_->Finish();
    return false;
  }
  Impl* impl = impl_.get();
  tbb::task_arena& lane = size == JobSize::kSmall && impl->options.small_job_threads > 0
                              ? impl->small_arena
                              : impl->arena;
#if INSCRIBE_TSAN_HANDOFF
  std::lock_guard<std::mutex> handoff(tsan_handoff_mutex);
#endif
  // TBB keeps the task (and so this lambda) alive until after it returns: the job is moved out
  // and destroyed before Finish, so that what it holds (the request, its memory reservation) is
  // released by the time the pool counts it done.
  lane.enqueue([impl, owned = std::make_unique<std::function<void()>>(std::move(job))] {
#if INSCRIBE_TSAN_HANDOFF
    { std::lock_guard<std::mutex> handoff(tsan_handoff_mutex); }
#endif
    {
      const std::function<void()> run = std::move(*owned);
      run();
    }
    impl->Finish();
  });
  return true;
}

std::int64_t JobPool::jobs_in_flight() const {
  return impl_->in_flight.load(std::memory_order_acquire);
}

const JobPoolOptions& JobPool::options() const { return impl_->options; }

void JobPool::WaitIdle() {
  std::unique_lock<std::mutex> lock(impl_->idle_mutex);
  impl_->idle.wait(lock, [this] { return impl_->in_flight.load() == 0; });
}

}  // namespace inscribe::server
