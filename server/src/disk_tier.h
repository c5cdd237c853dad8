// The result cache's on-disk tier: a content-addressed directory of framed entries
// (cache_entry_format.h), dir/<first 2 hex digits>/<64 hex digits of SHA-256(key)>, written
// atomically (temporary file, fsync, rename) and verified on read. Private to the server
// library; ResultCache documents the behaviour.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace inscribe::server {

// Thread-safe. Assumes this process is the directory's only writer.
class DiskTier {
 public:
  // What the directory holds now, and the errors since Open.
  struct Counts {
    std::int64_t entries = 0;
    std::int64_t bytes = 0;
    std::int64_t errors = 0;        // files dropped (bad checksum, truncated, wrong key)
    std::int64_t write_errors = 0;  // entries that could not be written
  };

  // Creates `dir` if needed, checks that it is writable, removes temporary files a crash left
  // and counts the entries: O(#entries) directory reads. FAILED_PRECONDITION naming the
  // directory when it cannot be created, written or listed.
  static absl::StatusOr<std::unique_ptr<DiskTier>> Open(const std::string& dir);

  // The payload stored under `key`, or nullopt when there is none or the file fails its checks
  // (then it is dropped and counted). Reads the whole file and hashes it.
  std::optional<std::string> Read(absl::string_view key);

  // Drops the file of `key` as corrupt (e.g. its payload did not decode); counted.
  void DropCorrupt(absl::string_view key);

  // Stores `payload` under `key` unless a file is there already (equal keys mean equal
  // content). Failures are counted, never reported: the cache works without the file.
  void Write(absl::string_view key, absl::string_view payload);

  Counts counts() const;

 private:
  explicit DiskTier(std::filesystem::path dir) : dir_(std::move(dir)) {}
  absl::Status Scan();
  std::filesystem::path EntryPath(absl::string_view key) const;
  void DropFile(const std::filesystem::path& path);

  const std::filesystem::path dir_;
  // Guards counts_; held across each rename or removal (metadata operations, no payload IO)
  // so that they count what the directory holds exactly.
  mutable std::mutex mutex_;
  Counts counts_;
  std::atomic<std::uint64_t> temp_files_{0};  // names temporary files uniquely in this process
};

}  // namespace inscribe::server
