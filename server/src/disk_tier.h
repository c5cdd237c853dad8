// The result cache's on-disk tier: a content-addressed directory of framed entries
// (cache_entry_format.h), dir/<first 2 hex digits>/<64 hex digits of SHA-256(key)>, written
// atomically (temporary file, fsync, rename) and verified on read. A write failing because
// the file system is full, read-only or forbids it stops writes for a backoff (1 s, doubling
// to 60 s), after which one write tries again; reads go on. Private to the server library;
// ResultCache documents the behaviour.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/server/result_cache.h"

namespace inscribe::server {

// Thread-safe. Assumes this process is the directory's only writer.
class DiskTier {
 public:
  // What the directory holds now, and the errors since Open.
  struct Counts {
    std::int64_t entries = 0;
    std::int64_t bytes = 0;
    std::int64_t errors = 0;          // files dropped (bad checksum, truncated, wrong key)
    std::int64_t write_errors = 0;    // entries that could not be written
    std::int64_t writes_skipped = 0;  // entries not written while writes were stopped
    bool available = true;            // writes are on (not stopped after a failure)
  };

  // Creates `dir` if needed, checks that it is writable, removes temporary files a crash left
  // and counts the entries: O(#entries) directory reads. FAILED_PRECONDITION naming the
  // directory when it cannot be created, written or listed. `on_event` (may be empty) is told
  // when writes stop (kDegraded) and start again (kRestored), on the writing thread with no
  // lock held.
  static absl::StatusOr<std::unique_ptr<DiskTier>> Open(
      const std::string& dir, std::function<void(const DiskTierEvent&)> on_event = {});

  // The payload stored under `key`, or nullopt when there is none or the file fails its checks
  // (then it is dropped and counted). Reads the whole file and hashes it.
  std::optional<std::string> Read(absl::string_view key);

  // Drops the file of `key` as corrupt (e.g. its payload did not decode); counted.
  void DropCorrupt(absl::string_view key);

  // Stores `payload` under `key` unless a file is there already (equal keys mean equal
  // content). Failures are counted, never returned: the cache works without the file. A
  // failure of the file system (ENOSPC, EROFS, EACCES, EPERM, EDQUOT, EFBIG, EIO) stops writes
  // for the backoff; writes meanwhile are skipped (counted) at no IO cost.
  void Write(absl::string_view key, absl::string_view payload);

  Counts counts() const;

 private:
  // Whether a write may go ahead; `probe` says it is the one retrying after the backoff.
  struct Attempt {
    bool allowed = false;
    bool probe = false;
  };

  DiskTier(std::filesystem::path dir, std::function<void(const DiskTierEvent&)> on_event)
      : dir_(std::move(dir)), on_event_(std::move(on_event)) {}
  absl::Status Scan();
  std::filesystem::path EntryPath(absl::string_view key) const;
  void DropFile(const std::filesystem::path& path);
  // Writes a temporary file, fsyncs it and renames it to `path`: 0, or the errno of the step
  // that failed (named with its path in `failed_step`; the temporary file is removed).
  int WriteEntry(const std::filesystem::path& path, absl::string_view key,
                 absl::string_view payload, std::string* failed_step);
  Attempt BeginWrite();
  // Ends a write BeginWrite allowed: `failure` 0 or the errno WriteEntry returned. Counts it,
  // stops or restarts writes and reports that through on_event_ (after unlocking).
  void EndWrite(const Attempt& attempt, int failure, const std::string& failed_step);

  const std::filesystem::path dir_;
  const std::function<void(const DiskTierEvent&)> on_event_;
  // Guards counts_ and the write health below; held across each rename or removal (metadata
  // operations, no payload IO) so that they count what the directory holds exactly.
  mutable std::mutex mutex_;
  Counts counts_;
  bool probing_ = false;  // while writes are stopped: the retry is in progress
  std::chrono::milliseconds backoff_{0};
  std::chrono::steady_clock::time_point stopped_until_;
  std::atomic<std::uint64_t> temp_files_{0};  // names temporary files uniquely in this process
};

}  // namespace inscribe::server
