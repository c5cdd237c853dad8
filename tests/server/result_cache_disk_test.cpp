// The result cache's disk tier: the documented file layout, entries surviving a restart,
// corrupt files dropped and recomputed, an unusable directory at Open (memory only), write
// failures, and a full disk stopping writes until a retry after the backoff succeeds.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/server/result_cache.h"
#include "result_cache_test_support.h"

namespace inscribe::server {
namespace {

using cache_test::EntryFile;
using cache_test::MustNotCompute;
using cache_test::MustNotDecode;
using cache_test::OpenCache;
using cache_test::Returning;
using cache_test::Sha256;
using cache_test::TempDir;
using cache_test::Value;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

// Every byte value, NULs included, so the disk tier must be binary-safe.
std::string BinaryPayload(std::size_t size) {
  std::string payload(size, '\0');
  for (std::size_t i = 0; i < size; ++i) payload[i] = static_cast<char>((i * 7 + i / 256) % 256);
  return payload;
}

// Keeps the bytes (no object) and counts the decodes.
ResultCache::Decode CountingDecode(int* calls) {
  return [calls](std::string bytes) -> absl::StatusOr<CachedValue> {
    ++*calls;
    CachedValue value;
    value.bytes = std::move(bytes);
    return value;
  };
}

std::string LittleEndian(std::uint64_t value, int bytes) {
  std::string out;
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>(value >> (8 * i)));
  return out;
}

// The documented file: magic line, key length (uint32) and key, payload length (uint64),
// SHA-256 of the payload, payload.
std::string ExpectedFile(absl::string_view key, absl::string_view payload) {
  return absl::StrCat("inscribe-cache 1\n", LittleEndian(key.size(), 4), key,
                      LittleEndian(payload.size(), 8), Sha256(payload), payload);
}

std::int64_t ExpectedSize(absl::string_view key, absl::string_view payload) {
  return static_cast<std::int64_t>(ExpectedFile(key, payload).size());
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteFile(const fs::path& path, absl::string_view content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  ASSERT_TRUE(out.good()) << path;
}

TEST(ResultCacheDisk, EntrySurvivesRestartAndIsDecoded) {
  TempDir dir;
  const std::string key = "hierarchy/v1/abc";
  const std::string payload = BinaryPayload(4096);
  {
    auto cache = OpenCache(1 << 20, dir.cache());
    int calls = 0;
    auto computed = cache->GetOrCompute(key, Returning(payload, &calls), MustNotDecode());
    ASSERT_TRUE(computed.ok()) << computed.status();
    EXPECT_EQ(computed->source, CacheSource::kComputed);
    EXPECT_EQ(ReadFile(EntryFile(dir.cache(), key)), ExpectedFile(key, payload));
    EXPECT_EQ(cache->stats().disk_entries, 1);
    EXPECT_EQ(cache->stats().disk_bytes, ExpectedSize(key, payload));
  }
  auto cache = OpenCache(1 << 20, dir.cache());
  EXPECT_EQ(cache->stats().disk_entries, 1);
  EXPECT_EQ(cache->stats().disk_bytes, ExpectedSize(key, payload));
  int decodes = 0;
  auto from_disk = cache->GetOrCompute(key, MustNotCompute(), CountingDecode(&decodes));
  ASSERT_TRUE(from_disk.ok()) << from_disk.status();
  EXPECT_EQ(from_disk->source, CacheSource::kDisk);
  EXPECT_EQ(from_disk->value->bytes, payload);
  EXPECT_EQ(decodes, 1);
  auto again = cache->GetOrCompute(key, MustNotCompute(), CountingDecode(&decodes));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->source, CacheSource::kMemory);
  EXPECT_EQ(again->value, from_disk->value);
  EXPECT_EQ(decodes, 1);

  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.disk_hits, 1);
  EXPECT_EQ(stats.memory_hits, 1);
  EXPECT_EQ(stats.misses + stats.computations + stats.disk_errors, 0);
  EXPECT_EQ(stats.bytes, static_cast<std::int64_t>(key.size() + payload.size()));

  auto other = OpenCache(1 << 20, dir.cache());  // Get reads the disk tier too
  auto got = other->Get(key, CountingDecode(&decodes));
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kDisk);
  EXPECT_EQ(got->value->bytes, payload);
}

enum class Damage { kFlipPayloadByte, kTruncate, kChangeKey, kBadMagic, kTrailingByte, kEmpty };

std::string Damaged(std::string file, Damage damage, std::size_t key_size) {
  switch (damage) {
    case Damage::kFlipPayloadByte:
      file[file.size() - 100] ^= 0x01;
      break;
    case Damage::kTruncate:
      file.resize(file.size() - 10);
      break;
    case Damage::kChangeKey:  // the key starts after the magic line and its uint32 length
      file[17 + 4 + key_size - 1] = 'Z';
      break;
    case Damage::kBadMagic:
      file[0] = 'X';
      break;
    case Damage::kTrailingByte:
      file.push_back('\0');
      break;
    case Damage::kEmpty:
      file.clear();
      break;
  }
  return file;
}

class ResultCacheCorruptFile : public ::testing::TestWithParam<Damage> {
 protected:
  void SetUp() override {
    auto cache = OpenCache(1 << 20, dir_.cache());
    int calls = 0;
    ASSERT_TRUE(cache->GetOrCompute(key_, Returning(payload_, &calls), MustNotDecode()).ok());
    ASSERT_EQ(ReadFile(file_), ExpectedFile(key_, payload_));
    WriteFile(file_, Damaged(ReadFile(file_), GetParam(), key_.size()));
  }

  TempDir dir_;
  const std::string key_ = "spheres/v1/damaged";
  const std::string payload_ = BinaryPayload(1000);
  const fs::path file_ = EntryFile(dir_.cache(), key_);
};

TEST_P(ResultCacheCorruptFile, IsDroppedCountedAndRecomputed) {
  auto cache = OpenCache(1 << 20, dir_.cache());
  EXPECT_EQ(cache->stats().disk_entries, 1);  // its name still looks like an entry
  int calls = 0;
  int decodes = 0;
  auto lookup = cache->GetOrCompute(key_, Returning(payload_, &calls), CountingDecode(&decodes));
  ASSERT_TRUE(lookup.ok()) << lookup.status();
  EXPECT_EQ(lookup->source, CacheSource::kComputed);
  EXPECT_EQ(lookup->value->bytes, payload_);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(decodes, 0);  // rejected before decoding
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.disk_errors, 1);
  EXPECT_EQ(stats.disk_hits, 0);
  EXPECT_EQ(stats.misses, 1);
  EXPECT_EQ(stats.disk_entries, 1);
  EXPECT_EQ(stats.disk_bytes, ExpectedSize(key_, payload_));
  EXPECT_EQ(ReadFile(file_), ExpectedFile(key_, payload_));  // rewritten whole
}

TEST_P(ResultCacheCorruptFile, IsDroppedAndMissingForGet) {
  auto cache = OpenCache(1 << 20, dir_.cache());
  auto got = cache->Get(key_, MustNotDecode());
  EXPECT_EQ(got.status().code(), absl::StatusCode::kNotFound);
  EXPECT_FALSE(fs::exists(file_));
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.disk_errors, 1);
  EXPECT_EQ(stats.misses, 1);
  EXPECT_EQ(stats.disk_entries, 0);
  EXPECT_EQ(stats.disk_bytes, 0);
}

std::string DamageName(const ::testing::TestParamInfo<Damage>& info) {
  static const char* const kNames[] = {"FlipPayloadByte", "Truncate",     "ChangeKey",
                                       "BadMagic",        "TrailingByte", "Empty"};
  return kNames[static_cast<int>(info.param)];
}

INSTANTIATE_TEST_SUITE_P(Damages, ResultCacheCorruptFile,
                         ::testing::Values(Damage::kFlipPayloadByte, Damage::kTruncate,
                                           Damage::kChangeKey, Damage::kBadMagic,
                                           Damage::kTrailingByte, Damage::kEmpty),
                         DamageName);

TEST(ResultCacheDisk, DecodeFailureCountsAsCorruptAndRecomputes) {
  TempDir dir;
  int calls = 0;
  {
    auto cache = OpenCache(1 << 20, dir.cache());
    ASSERT_TRUE(cache->GetOrCompute("k/a", Returning("old", &calls), MustNotDecode()).ok());
  }
  auto cache = OpenCache(1 << 20, dir.cache());
  int decodes = 0;
  const ResultCache::Decode failing = [&](std::string) -> absl::StatusOr<CachedValue> {
    ++decodes;
    return absl::DataLossError("unknown format version");
  };
  auto lookup = cache->GetOrCompute("k/a", Returning("new", &calls), failing);
  ASSERT_TRUE(lookup.ok()) << lookup.status();
  EXPECT_EQ(lookup->source, CacheSource::kComputed);
  EXPECT_EQ(lookup->value->bytes, "new");
  EXPECT_EQ(decodes, 1);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(cache->stats().disk_errors, 1);
  EXPECT_EQ(cache->stats().disk_entries, 1);
  EXPECT_EQ(ReadFile(EntryFile(dir.cache(), "k/a")), ExpectedFile("k/a", "new"));
}

// Collects the disk tier's events (called on the cache's threads).
struct DiskEvents {
  std::mutex mutex;
  std::vector<DiskTierEvent> events;

  std::function<void(const DiskTierEvent&)> Callback() {
    return [this](const DiskTierEvent& event) {
      std::lock_guard<std::mutex> lock(mutex);
      events.push_back(event);
    };
  }
  std::vector<DiskTierEvent> Take() {
    std::lock_guard<std::mutex> lock(mutex);
    return std::exchange(events, {});
  }
};

// Without its disk tier the cache still computes, keeps results in memory and counts them.
void ExpectMemoryOnly(ResultCache& cache) {
  int calls = 0;
  auto lookup = cache.GetOrCompute("k/a", Returning("value", &calls), MustNotDecode());
  ASSERT_TRUE(lookup.ok()) << lookup.status();
  EXPECT_EQ(lookup->source, CacheSource::kComputed);
  auto again = cache.GetOrCompute("k/a", MustNotCompute(), MustNotDecode());
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->source, CacheSource::kMemory);
  const ResultCacheStats stats = cache.stats();
  EXPECT_EQ(stats.disk_available, 0);
  EXPECT_EQ(stats.disk_entries + stats.disk_write_errors + stats.disk_writes_skipped, 0);
}

TEST(ResultCacheOpen, RejectsNegativeBudget) {
  EXPECT_EQ(ResultCache::Open(cache_test::Options(-1, "")).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ResultCacheOpen, UnusableDirectoryRunsWithoutTheDiskTier) {
  TempDir dir;
  const fs::path file = dir.path() / "file";
  WriteFile(file, "x");
  for (const fs::path& bad : {file / "cache", file}) {
    DiskEvents events;
    ResultCacheOptions options = cache_test::Options(1 << 20, bad.string());
    options.on_disk_tier_event = events.Callback();
    auto cache = ResultCache::Open(options);
    ASSERT_TRUE(cache.ok()) << cache.status();
    const std::vector<DiskTierEvent> seen = events.Take();
    ASSERT_EQ(seen.size(), 1u) << bad;
    EXPECT_EQ(seen[0].kind, DiskTierEvent::Kind::kOff);
    EXPECT_EQ(seen[0].dir, bad.string());
    EXPECT_EQ(seen[0].error.code(), absl::StatusCode::kFailedPrecondition);
    EXPECT_THAT(seen[0].error.message(), HasSubstr(bad.string()));
    ExpectMemoryOnly(**cache);
    EXPECT_TRUE(events.Take().empty());
  }
}

TEST(ResultCacheOpen, ReadOnlyDirectoryRunsWithoutTheDiskTier) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes to read-only directories";
  TempDir dir;
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  DiskEvents events;
  ResultCacheOptions options = cache_test::Options(1 << 20, dir.path().string());
  options.on_disk_tier_event = events.Callback();
  auto cache = ResultCache::Open(options);
  fs::permissions(dir.path(), fs::perms::owner_all);
  ASSERT_TRUE(cache.ok()) << cache.status();
  const std::vector<DiskTierEvent> seen = events.Take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].kind, DiskTierEvent::Kind::kOff);
  EXPECT_THAT(seen[0].error.message(), HasSubstr(dir.path().string()));
  ExpectMemoryOnly(**cache);
}

// RLIMIT_FSIZE 0 makes every write of a regular file fail with EFBIG, like a full disk, even
// for root; restored when the test ends. SIGXFSZ is ignored so the write fails instead of
// killing the test.
class FileSizeLimit {
 public:
  FileSizeLimit() {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    previous_handler_ = ::signal(SIGXFSZ, SIG_IGN);
  }
  ~FileSizeLimit() {
    Lift();
    ::signal(SIGXFSZ, previous_handler_);
  }
  void Impose() {
    rlimit zero = saved_;
    zero.rlim_cur = 0;
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &zero), 0);
  }
  void Lift() { ::setrlimit(RLIMIT_FSIZE, &saved_); }

 private:
  rlimit saved_{};
  sighandler_t previous_handler_ = SIG_DFL;
};

TEST(ResultCacheDisk, FullDiskStopsWritesUntilTheBackoffThenRestores) {
  TempDir dir;
  ASSERT_TRUE(OpenCache(1 << 20, dir.cache())->Put("k/before", Value("stored before")).ok());
  DiskEvents events;
  ResultCacheOptions options = cache_test::Options(1 << 20, dir.cache());
  options.on_disk_tier_event = events.Callback();
  auto opened = ResultCache::Open(options);
  ASSERT_TRUE(opened.ok()) << opened.status();
  ResultCache& cache = **opened;
  ASSERT_EQ(cache.stats().disk_available, 1);

  FileSizeLimit limit;
  limit.Impose();
  ASSERT_TRUE(cache.Put("k/full", Value("not stored")).ok());
  ASSERT_TRUE(cache.Put("k/skipped", Value("not tried")).ok());
  limit.Lift();
  std::vector<DiskTierEvent> seen = events.Take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].kind, DiskTierEvent::Kind::kDegraded);
  EXPECT_EQ(seen[0].retry_after, std::chrono::milliseconds(1000));
  EXPECT_THAT(seen[0].error.message(), HasSubstr(dir.cache()));
  ResultCacheStats stats = cache.stats();
  EXPECT_EQ(stats.disk_available, 0);
  EXPECT_EQ(stats.disk_write_errors, 1);
  EXPECT_EQ(stats.disk_writes_skipped, 1);
  EXPECT_EQ(stats.disk_entries, 1);
  EXPECT_EQ(stats.entries, 2);  // both values are still served, from memory
  // No temporary file is left behind by the failed write.
  for (const auto& entry : fs::recursive_directory_iterator(dir.cache())) {
    EXPECT_THAT(entry.path().string(), ::testing::Not(HasSubstr(".tmp-")));
  }
  // Reads go on while writes are stopped.
  int decodes = 0;
  auto before = cache.Get("k/before", CountingDecode(&decodes));
  ASSERT_TRUE(before.ok()) << before.status();
  EXPECT_EQ(before->source, CacheSource::kDisk);
  EXPECT_EQ(before->value->bytes, "stored before");

  // Writable again: within the backoff writes are still skipped, after it one write retries.
  ASSERT_TRUE(cache.Put("k/within", Value("skipped too")).ok());
  EXPECT_EQ(cache.stats().disk_writes_skipped, 2);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  ASSERT_TRUE(cache.Put("k/after", Value("stored after")).ok());
  seen = events.Take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].kind, DiskTierEvent::Kind::kRestored);
  EXPECT_TRUE(seen[0].error.ok());
  stats = cache.stats();
  EXPECT_EQ(stats.disk_available, 1);
  EXPECT_EQ(stats.disk_entries, 2);
  EXPECT_EQ(ReadFile(EntryFile(dir.cache(), "k/after")), ExpectedFile("k/after", "stored after"));
  EXPECT_FALSE(fs::exists(EntryFile(dir.cache(), "k/full")));
}

TEST(ResultCacheOpen, CountsEntriesAndRemovesTemporaryFiles) {
  TempDir dir;
  int calls = 0;
  {
    auto cache = OpenCache(1 << 20, dir.cache());
    ASSERT_TRUE(cache->GetOrCompute("k/a", Returning("aaaa", &calls), MustNotDecode()).ok());
    ASSERT_TRUE(cache->Put("k/bb", Value("bbbbbbbb")).ok());
  }
  // What a crash mid-write and a stray file leave behind.
  const fs::path temp = EntryFile(dir.cache(), "k/a").string() + ".tmp-12345-0";
  WriteFile(temp, "partial");
  WriteFile(fs::path(dir.cache()) / "README", "not an entry");
  auto cache = OpenCache(1 << 20, dir.cache());
  EXPECT_EQ(cache->stats().disk_entries, 2);
  EXPECT_EQ(cache->stats().disk_bytes,
            ExpectedSize("k/a", "aaaa") + ExpectedSize("k/bb", "bbbbbbbb"));
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_TRUE(fs::exists(fs::path(dir.cache()) / "README"));
}

TEST(ResultCacheDisk, WriteFailureDoesNotFailTheRequest) {
  TempDir dir;
  auto cache = OpenCache(1 << 20, dir.cache());
  // The directory becomes a file: no entry can be created under it, even by root.
  fs::remove_all(dir.cache());
  WriteFile(dir.cache(), "not a directory");
  int calls = 0;
  auto lookup = cache->GetOrCompute("k/a", Returning("value", &calls), MustNotDecode());
  ASSERT_TRUE(lookup.ok()) << lookup.status();
  EXPECT_EQ(lookup->source, CacheSource::kComputed);
  EXPECT_TRUE(cache->Put("k/b", Value("other")).ok());
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.disk_write_errors, 2);
  EXPECT_EQ(stats.disk_errors, 0);  // a missing directory on read is a plain miss
  EXPECT_EQ(stats.disk_entries, 0);
  EXPECT_EQ(stats.entries, 2);
  auto again = cache->GetOrCompute("k/a", MustNotCompute(), MustNotDecode());
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->source, CacheSource::kMemory);
}

TEST(ResultCache, PutKeepsAnExistingEntry) {
  TempDir dir;
  const std::string key = "meshes/v1/m";
  {
    auto cache = OpenCache(1 << 20, dir.cache());
    auto first = cache->Put(key, Value("first"));
    ASSERT_TRUE(first.ok()) << first.status();
    EXPECT_EQ((*first)->bytes, "first");
    auto second = cache->Put(key, Value("second"));
    ASSERT_TRUE(second.ok()) << second.status();
    EXPECT_EQ(*second, *first);
    auto lookup = cache->GetOrCompute(key, MustNotCompute(), MustNotDecode());
    ASSERT_TRUE(lookup.ok());
    EXPECT_EQ(lookup->source, CacheSource::kMemory);
    EXPECT_EQ(lookup->value, *first);
    const ResultCacheStats stats = cache->stats();
    EXPECT_EQ(stats.entries, 1);
    EXPECT_EQ(stats.disk_entries, 1);
    EXPECT_EQ(stats.computations + stats.misses, 0);
  }
  // Only on disk now: Put does not rewrite the file.
  auto cache = OpenCache(1 << 20, dir.cache());
  ASSERT_TRUE(cache->Put(key, Value("third")).ok());
  EXPECT_EQ(ReadFile(EntryFile(dir.cache(), key)), ExpectedFile(key, "first"));
  EXPECT_EQ(cache->stats().disk_entries, 1);
  EXPECT_EQ(cache->stats().disk_write_errors, 0);
}

}  // namespace
}  // namespace inscribe::server
