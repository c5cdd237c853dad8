// What the result cache tests share: a temporary directory per test, the documented path of an
// entry's file, and values, compute and decode functions that count their calls or fail the
// test when called.
#pragma once

#include <gtest/gtest.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "inscribe/server/result_cache.h"

namespace inscribe::server::cache_test {

namespace fs = std::filesystem;

// A fresh directory under the system's temporary directory, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> count{0};
    path_ = fs::temp_directory_path() /
            absl::StrCat("inscribe_result_cache_test_", ::getpid(), "_", count++);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code error;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, error);
    fs::remove_all(path_, error);
  }
  const fs::path& path() const { return path_; }
  // The cache's own directory: a subdirectory, so Open has to create it.
  std::string cache() const { return (path_ / "cache").string(); }

 private:
  fs::path path_;
};

// SHA-256 by OpenSSL, independent of the server's own hashing.
inline std::string Sha256(absl::string_view data) {
  std::array<unsigned char, 32> digest{};
  unsigned int length = 0;
  EXPECT_EQ(EVP_Digest(data.data(), data.size(), digest.data(), &length, EVP_sha256(), nullptr), 1);
  return std::string(digest.begin(), digest.end());
}

// The documented layout: dir/<2 hex>/<64 hex of SHA-256(key)>.
inline fs::path EntryFile(const std::string& dir, absl::string_view key) {
  const std::string hex = absl::BytesToHexString(Sha256(key));
  return fs::path(dir) / hex.substr(0, 2) / hex;
}

inline ResultCacheOptions Options(std::int64_t memory_bytes, std::string dir) {
  ResultCacheOptions options;
  options.memory_bytes = memory_bytes;
  options.disk_dir = std::move(dir);
  return options;
}

// Throws (failing the test with the status) when Open fails, so tests can use the cache
// directly.
inline std::unique_ptr<ResultCache> OpenCache(std::int64_t memory_bytes, std::string dir = "") {
  absl::StatusOr<std::unique_ptr<ResultCache>> cache =
      ResultCache::Open(Options(memory_bytes, std::move(dir)));
  if (!cache.ok()) throw std::runtime_error(cache.status().ToString());
  return *std::move(cache);
}

inline CachedValue Value(std::string bytes, std::int64_t object_bytes = 0) {
  CachedValue value;
  value.bytes = std::move(bytes);
  value.object_bytes = object_bytes;
  return value;
}

inline ResultCache::Compute Returning(std::string bytes, int* calls,
                                      std::int64_t object_bytes = 0) {
  return [bytes = std::move(bytes), calls, object_bytes]() -> absl::StatusOr<CachedValue> {
    ++*calls;
    return Value(bytes, object_bytes);
  };
}

inline ResultCache::Compute MustNotCompute() {
  return []() -> absl::StatusOr<CachedValue> {
    ADD_FAILURE() << "computed a cached entry";
    return absl::InternalError("computed a cached entry");
  };
}

inline ResultCache::Decode MustNotDecode() {
  return [](std::string) -> absl::StatusOr<CachedValue> {
    ADD_FAILURE() << "decoded with no disk entry";
    return absl::InternalError("decoded with no disk entry");
  };
}

}  // namespace inscribe::server::cache_test
