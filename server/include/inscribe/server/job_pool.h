// The bounded pool that runs the service's heavy work off the gRPC threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

namespace inscribe::server {

struct JobPoolOptions {
  // Jobs that run at the same time (threads of the pool's TBB arena). Parallel algorithms a job
  // calls (TBB inside core) share these threads, so this bounds the CPU the service uses.
  int concurrency = 1;
  // Jobs queued or running at once; TrySubmit refuses more. Bounds the memory held by requests
  // waiting for a thread.
  std::int64_t max_jobs = 64;
  // Threads of a separate lane for jobs submitted as JobSize::kSmall, so that a small call
  // never waits behind large ones holding every `concurrency` thread (bench/abuse_bench
  // --quick, 2 cores: a 10-pair Distance's p99 went from 107 ms to 7.7 ms, and its rate from
  // 231 to 2,399 calls/s, while 2 clients sent 200,000-pair calls and other attacks). Small
  // jobs never run on the `concurrency` threads, nor large ones
  // here; the lane's threads are extra (the OS shares the cores among all of them). 0 = one
  // queue for all jobs. Counted in max_jobs like any job.
  int small_job_threads = 1;
};

// Which lane a job runs on (see JobPoolOptions::small_job_threads).
enum class JobSize { kLarge, kSmall };

// A TBB task arena with `concurrency` threads (plus one of small_job_threads for small jobs)
// and an admission count. Thread-safe. The
// destructor waits for every accepted job to finish, so jobs may use anything that outlives
// the pool.
//
// TBB's default limit is one worker thread fewer than the machine has cores; the pool raises
// the process-wide limit (tbb::global_control) for as long as it lives, so that `concurrency`
// threads can run even with a single core. One pool per process is the intended use.
class JobPool {
 public:
  explicit JobPool(const JobPoolOptions& options);
  ~JobPool();
  JobPool(const JobPool&) = delete;
  JobPool& operator=(const JobPool&) = delete;

  // Queues `job` and returns true, or returns false without running it when max_jobs jobs are
  // already queued or running. Never blocks and never runs `job` on the calling thread. A job
  // must not throw: report failures through its own channel (e.g. the RPC's status).
  // kSmall jobs go to the small-job lane when the pool has one.
  bool TrySubmit(std::function<void()> job, JobSize size = JobSize::kLarge);

  // Jobs accepted and not yet finished (queued + running); a snapshot for logs and metrics.
  std::int64_t jobs_in_flight() const;

  const JobPoolOptions& options() const;

  // Blocks until no job is queued or running.
  void WaitIdle();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace inscribe::server
