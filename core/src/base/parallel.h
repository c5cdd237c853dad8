// Private: core's parallel loops. Every parallel loop in core and robot goes through these, so
// that ThreadSanitizer sees how each loop is ordered with the code around it.
//
// The loops run on TBB. Debian's libtbb is not built for ThreadSanitizer, and a TBB loop hands
// its tasks between threads inside it, unseen: TSan then reports TBB's own task objects, and the
// writes before a loop and after its join, as races. So in TSan builds the same loops run their
// subranges on std::threads that the loop starts and joins, which TSan sees; the subranges stay
// unordered with one another, so races between the bodies of a loop are still reported. The
// chunks of ParallelReduce, and so its result, are the same in both builds.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#if defined(__SANITIZE_THREAD__)
#include <sanitizer/tsan_interface.h>
#define INSCRIBE_TSAN_LOOPS 1
#else
#define INSCRIBE_TSAN_LOOPS 0
#endif

namespace inscribe::internal {

// True in ThreadSanitizer builds. Parallel code that is not ours and runs its own TBB loops
// (CGAL's) runs sequentially there.
inline constexpr bool kThreadSanitizer = INSCRIBE_TSAN_LOOPS != 0;

// Happens-before edges through a library whose threads TSan cannot follow (Embree builds its
// BVH on its own TBB threads, calling our callbacks there): what a thread did before
// TsanRelease(key) happens before what any thread does after a later TsanAcquire(key). Each
// release adds to what the key carries, so one acquire after many releases sees them all.
// Nothing outside TSan builds.
inline void TsanRelease(const void* key) {
#if INSCRIBE_TSAN_LOOPS
  __tsan_release(const_cast<void*>(key));
#else
  static_cast<void>(key);
#endif
}
inline void TsanAcquire(const void* key) {
#if INSCRIBE_TSAN_LOOPS
  __tsan_acquire(const_cast<void*>(key));
#else
  static_cast<void>(key);
#endif
}

// A key for TsanRelease/TsanAcquire per thread id. A finished thread's id is reused (and TBB's
// thread-local containers, keyed by it, hand its slot to the new thread: robot's self-collision
// matrix's) only after that thread has ended, an
// order glibc makes where TSan does not see it; RunOnThreads' helpers release their id's key as
// they end and acquire it as they start, which is that order.
inline const void* ThreadIdKey() {
  static char keys[4096];
  const std::uint64_t h = std::hash<std::thread::id>{}(std::this_thread::get_id());
  return &keys[(h * 0x9E3779B97F4A7C15ull) >> 52];  // the top 12 bits of a Fibonacci hash
}

// [first, last) cut into chunks of `grain` indices (at least 1); the last may be shorter.
template <typename Index>
class Chunks {
 public:
  Chunks(Index first, Index last, std::size_t grain)
      : first_(first), last_(last), step_(static_cast<Index>(std::max<std::size_t>(grain, 1))) {}
  std::size_t size() const {
    return last_ <= first_ ? 0 : static_cast<std::size_t>((last_ - first_ - 1) / step_) + 1;
  }
  Index begin(std::size_t c) const { return first_ + static_cast<Index>(c) * step_; }
  Index end(std::size_t c) const { return last_ - begin(c) > step_ ? begin(c) + step_ : last_; }

 private:
  Index first_, last_, step_;
};

// The TSan builds' loop: the chunks, taken in turn by as many threads as the current task arena
// allows (the caller's included). The first exception a body throws stops the remaining chunks
// and is rethrown here.
template <typename Index, typename Body>
void RunOnThreads(Index first, Index last, std::size_t grain, const Body& body) {
  const Chunks<Index> chunks(first, last, grain);
  const std::size_t count = chunks.size();
  if (count == 0) return;
  const std::size_t threads = std::min(
      count, static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency())));
  // Relaxed: taking a chunk orders nothing, so TSan keeps the bodies unordered.
  std::atomic<std::size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto work = [&] {
    for (;;) {
      const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
      if (c >= count) return;
      try {
        body(chunks.begin(c), chunks.end(c));
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next.store(count, std::memory_order_relaxed);
        return;
      }
    }
  };
  std::vector<std::thread> helpers;
  helpers.reserve(threads - 1);
  for (std::size_t t = 1; t < threads; ++t) {
    helpers.emplace_back([&work] {
      TsanAcquire(ThreadIdKey());
      work();
      TsanRelease(ThreadIdKey());
    });
  }
  work();
  for (std::thread& helper : helpers) helper.join();
  if (error) std::rethrow_exception(error);
}

// Calls body(begin, end) on subranges of [first, last), in parallel; TBB splits the range down
// to subranges of about `grain` indices.
template <typename Index, typename Body>
void ParallelForRange(Index first, Index last, std::size_t grain, const Body& body) {
#if INSCRIBE_TSAN_LOOPS
  RunOnThreads(first, last, grain, body);
#else
  tbb::parallel_for(
      tbb::blocked_range<Index>(first, last, grain),
      [&](const tbb::blocked_range<Index>& range) { body(range.begin(), range.end()); });
#endif
}

// Calls f(i) for every i in [first, last), in parallel.
template <typename Index, typename F>
void ParallelFor(Index first, Index last, const F& f) {
#if INSCRIBE_TSAN_LOOPS
  const std::size_t n = last > first ? static_cast<std::size_t>(last - first) : 0;
  RunOnThreads(first, last, std::max<std::size_t>(n / 64, 1), [&](Index begin, Index end) {
    for (Index i = begin; i < end; ++i) f(i);
  });
#else
  tbb::parallel_for(first, last, f);
#endif
}

// Calls f(i) for every i in [first, last), in parallel, on subranges of about `grain` indices.
template <typename Index, typename F>
void ParallelFor(Index first, Index last, std::size_t grain, const F& f) {
  ParallelForRange(first, last, grain, [&f](Index begin, Index end) {
    for (Index i = begin; i != end; ++i) f(i);
  });
}

// Folds [first, last): body(begin, end, value) folds a subrange into value and returns it, on
// chunks of `grain` indices in parallel, each starting from `identity`; join(a, b) then combines
// the chunks' values in index order, on the calling thread. The chunks and the order of the
// joins do not depend on the schedule, so neither does the result.
template <typename Index, typename Value, typename Body, typename Join>
Value ParallelReduce(Index first, Index last, std::size_t grain, const Value& identity,
                     const Body& body, const Join& join) {
  const Chunks<Index> chunks(first, last, grain);
  std::vector<Value> values(chunks.size(), identity);
  ParallelFor(std::size_t{0}, chunks.size(), [&](std::size_t c) {
    values[c] = body(chunks.begin(c), chunks.end(c), std::move(values[c]));
  });
  Value result = identity;
  for (Value& value : values) result = join(std::move(result), std::move(value));
  return result;
}

}  // namespace inscribe::internal
