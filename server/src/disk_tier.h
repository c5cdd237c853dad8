// The result cache's on-disk tier: a content-addressed directory of framed entries
// (cache_entry_format.h), dir/<first 2 hex digits>/<64 hex digits of SHA-256(key)>, written
// atomically (temporary file, fsync, rename) and verified on read. A write failing because
// the file system is full, read-only or forbids it stops writes for a backoff (1 s, doubling
// to 60 s), after which one write tries again; reads go on. With a bound in bytes, the least
// recently used entries are deleted to stay within it (see DiskTier). Private to the server
// library; ResultCache documents the behaviour.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/server/result_cache.h"

namespace inscribe::server {

// Thread-safe. Assumes this process is the directory's only writer.
//
// Recency: an in-memory index of the entries (name, bytes), most recently used first, built at
// Open from the files' modification times and kept up to date by Read and Write. A Read that
// succeeds sets its file's modification time to now, so the order survives a restart. The
// index is checked against the files whenever one is touched: an entry whose file has vanished
// is dropped from it, one whose size changed is recounted.
//
// Bound: with max_bytes > 0, the least recently used entries are deleted until the entries fit
// in it: before a write renames its file into place (so that the new file fits too), at Open,
// and when a pin is released. Names being read or written are pinned and never deleted
// meanwhile; eviction passes over them to the next, so the entries exceed the bound only while
// the ones that would go are pinned. An entry larger than the whole bound is not written.
class DiskTier {
 public:
  // What the directory holds now, and the errors since Open.
  struct Counts {
    std::int64_t entries = 0;
    std::int64_t bytes = 0;
    std::int64_t errors = 0;            // files dropped (bad checksum, truncated, wrong key)
    std::int64_t write_errors = 0;      // entries that could not be written
    std::int64_t writes_skipped = 0;    // entries not written while writes were stopped
    bool available = true;              // writes are on (not stopped after a failure)
    std::int64_t max_bytes = 0;         // the bound (Open's max_bytes); 0 = unbounded
    std::int64_t evictions = 0;         // entries deleted for the bound (at Open included)
    std::int64_t evicted_bytes = 0;     // their bytes
    std::int64_t writes_too_large = 0;  // entries not written: larger than the whole bound
  };

  // Creates `dir` if needed, checks that it is writable, removes temporary files a crash left,
  // indexes the entries by modification time and evicts down to `max_bytes` (>= 0; 0 =
  // unbounded; ResultCache::Open validates it): O(#entries) directory reads and
  // O(#entries log #entries) sorting. FAILED_PRECONDITION naming the directory when it cannot
  // be created, written or listed. `on_event` (may be empty) is told when writes stop
  // (kDegraded) and start again (kRestored), on the writing thread with no lock held.
  static absl::StatusOr<std::unique_ptr<DiskTier>> Open(
      const std::string& dir, std::int64_t max_bytes,
      std::function<void(const DiskTierEvent&)> on_event = {});

  // The payload stored under `key`, or nullopt when there is none or the file fails its checks
  // (then it is dropped and counted). Reads the whole file and hashes it; a hit becomes the
  // most recently used entry and its file's modification time is set to now.
  std::optional<std::string> Read(absl::string_view key);

  // Drops the file of `key` as corrupt (e.g. its payload did not decode); counted.
  void DropCorrupt(absl::string_view key);

  // Stores `payload` under `key` unless a file is there already (equal keys mean equal
  // content). Failures are counted, never returned: the cache works without the file. A
  // failure of the file system (ENOSPC, EROFS, EACCES, EPERM, EDQUOT, EFBIG, EIO) stops writes
  // for the backoff; writes meanwhile are skipped (counted) at no IO cost. The new entry is the
  // most recently used; older ones are evicted as the bound requires. An entry larger than the
  // whole bound is not written (counted in writes_too_large).
  void Write(absl::string_view key, absl::string_view payload);

  Counts counts() const;

 private:
  // Whether a write may go ahead; `probe` says it is the one retrying after the backoff.
  struct Attempt {
    bool allowed = false;
    bool probe = false;
  };

  // One entry of the recency index; `name` is its file name (64 hex digits).
  struct Indexed {
    std::string name;
    std::int64_t bytes = 0;
  };
  // Pins `name` (keeps eviction away from it) for its lifetime; pins of one name nest. Its
  // destruction evicts whatever the pin held back.
  class PinnedName {
   public:
    PinnedName(DiskTier& tier, std::string name);
    ~PinnedName();
    PinnedName(const PinnedName&) = delete;
    PinnedName& operator=(const PinnedName&) = delete;

   private:
    DiskTier& tier_;
    const std::string name_;
  };

  DiskTier(std::filesystem::path dir, std::int64_t max_bytes,
           std::function<void(const DiskTierEvent&)> on_event)
      : dir_(std::move(dir)), max_bytes_(max_bytes), on_event_(std::move(on_event)) {}
  absl::Status Scan();
  std::filesystem::path EntryPath(absl::string_view key) const;
  // Removes the file as corrupt (counted) and its entry from the index.
  void DropFile(const std::filesystem::path& path);
  // Checks the index against the file at `path` (named `name`): forgotten when the file is
  // gone, else made the most recently used with the file's size, then evicts as needed.
  // Costs one stat.
  void NoteFileLocked(const std::filesystem::path& path, const std::string& name);
  // Makes `name` the most recently used entry, holding `bytes`: added when missing, recounted
  // when its size changed.
  void TouchLocked(const std::string& name, std::int64_t bytes);
  // Drops `name` from the index, if there (its file is gone or going).
  void ForgetLocked(absl::string_view name);
  // While the entries and `incoming` bytes (a file about to be added) exceed the bound:
  // deletes the least recently used unpinned entry. Files already gone are only forgotten, not
  // counted as evictions.
  void EvictLocked(std::int64_t incoming = 0);
  // Writes a temporary file, fsyncs it and renames it to `path`: 0, or the errno of the step
  // that failed (named with its path in `failed_step`; the temporary file is removed).
  int WriteEntry(const std::filesystem::path& path, absl::string_view key,
                 absl::string_view payload, std::string* failed_step);
  Attempt BeginWrite();
  // Ends a write BeginWrite allowed: `failure` 0 or the errno WriteEntry returned. Counts it,
  // stops or restarts writes and reports that through on_event_ (after unlocking).
  void EndWrite(const Attempt& attempt, int failure, const std::string& failed_step);

  const std::filesystem::path dir_;
  const std::int64_t max_bytes_;  // 0 = unbounded
  const std::function<void(const DiskTierEvent&)> on_event_;
  // Guards counts_, the index, the pins and the write health below; held across each rename
  // or removal (metadata operations, no payload IO) so that they count what the directory
  // holds exactly.
  mutable std::mutex mutex_;
  Counts counts_;               // entries and bytes: the index's totals
  std::list<Indexed> recency_;  // most recently used first
  absl::flat_hash_map<absl::string_view, std::list<Indexed>::iterator> index_;  // views names
  absl::flat_hash_map<std::string, int> pins_;  // names read or written now, and how often
  bool probing_ = false;  // while writes are stopped: the retry is in progress
  std::chrono::milliseconds backoff_{0};
  std::chrono::steady_clock::time_point stopped_until_;
  std::atomic<std::uint64_t> temp_files_{0};  // names temporary files uniquely in this process
};

}  // namespace inscribe::server
