// The disk tier's bound (--cache-disk-bytes): least recently used eviction after writes and at
// Open, the order rebuilt from the files' modification times, files deleted behind the tier's
// back, pinned entries (being read) skipped, entries larger than the bound not written, and
// the counts against what the directory really holds. DiskTier is private to the server; the
// last tests go through ResultCache.
#include "disk_tier.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "cache_entry_format.h"
#include "result_cache_test_support.h"

namespace inscribe::server {
namespace {

using cache_test::EntryFile;
using cache_test::TempDir;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

constexpr std::size_t kPayloadBytes = 1000;

std::string Payload(absl::string_view key) {
  std::string payload(kPayloadBytes, '\0');
  for (std::size_t i = 0; i < payload.size(); ++i) {
    payload[i] = static_cast<char>(key[i % key.size()] + i);
  }
  return payload;
}

// Keys of one length, so that every entry's file has the same size.
std::string Key(int i) { return absl::StrCat("k/", 100 + i); }

// The size of each entry file of these tests.
std::int64_t EntryBytes() {
  return static_cast<std::int64_t>(EntryHeaderSize(Key(0).size()) + kPayloadBytes);
}

std::unique_ptr<DiskTier> OpenTier(const std::string& dir, std::int64_t max_bytes) {
  absl::StatusOr<std::unique_ptr<DiskTier>> tier = DiskTier::Open(dir, max_bytes);
  if (!tier.ok()) throw std::runtime_error(tier.status().ToString());
  return *std::move(tier);
}

void Write(DiskTier& tier, int i) { tier.Write(Key(i), Payload(Key(i))); }

bool Stored(const std::string& dir, int i) { return fs::exists(EntryFile(dir, Key(i))); }

// Which of keys [0, n) have a file, e.g. "0 1 5".
std::string StoredKeys(const std::string& dir, int n) {
  std::string stored;
  for (int i = 0; i < n; ++i) {
    if (Stored(dir, i)) absl::StrAppend(&stored, stored.empty() ? "" : " ", i);
  }
  return stored;
}

// What the directory holds, walked independently of the tier.
struct Held {
  std::int64_t entries = 0;
  std::int64_t bytes = 0;
};
Held DirectoryHolds(const std::string& dir) {
  Held held;
  for (const fs::directory_entry& file : fs::recursive_directory_iterator(dir)) {
    if (!file.is_regular_file() || absl::StrContains(file.path().string(), ".tmp-")) continue;
    ++held.entries;
    held.bytes += static_cast<std::int64_t>(file.file_size());
  }
  return held;
}

void ExpectCountsMatchDirectory(const DiskTier& tier, const std::string& dir) {
  const DiskTier::Counts counts = tier.counts();
  const Held held = DirectoryHolds(dir);
  EXPECT_EQ(counts.entries, held.entries);
  EXPECT_EQ(counts.bytes, held.bytes);
}

// Sets the modification time of key i's file to `seconds` ago.
void SetAge(const std::string& dir, int i, int seconds) {
  const fs::path path = EntryFile(dir, Key(i));
  fs::last_write_time(path, fs::file_time_type::clock::now() - std::chrono::seconds(seconds));
}

TEST(DiskTierBound, StaysWithinTheBoundOverManyWrites) {
  TempDir dir;
  const std::int64_t bound = 10 * EntryBytes() + EntryBytes() / 2;  // room for 10
  auto tier = OpenTier(dir.cache(), bound);
  for (int i = 0; i < 100; ++i) {
    Write(*tier, i);
    ASSERT_LE(tier->counts().bytes, bound) << "after write " << i;
    ASSERT_LE(DirectoryHolds(dir.cache()).bytes, bound) << "after write " << i;
  }
  const DiskTier::Counts counts = tier->counts();
  EXPECT_EQ(counts.max_bytes, bound);
  EXPECT_EQ(counts.entries, 10);
  EXPECT_EQ(counts.evictions, 90);
  EXPECT_EQ(counts.evicted_bytes, 90 * EntryBytes());
  EXPECT_EQ(counts.write_errors + counts.errors + counts.writes_too_large, 0);
  EXPECT_EQ(StoredKeys(dir.cache(), 100), "90 91 92 93 94 95 96 97 98 99");
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

TEST(DiskTierBound, UnboundedNeverEvicts) {
  TempDir dir;
  auto tier = OpenTier(dir.cache(), 0);
  for (int i = 0; i < 30; ++i) Write(*tier, i);
  EXPECT_EQ(tier->counts().entries, 30);
  EXPECT_EQ(tier->counts().evictions, 0);
  EXPECT_EQ(tier->counts().max_bytes, 0);
}

TEST(DiskTierBound, ReadEntrySurvivesAndTheUnreadOldestGoes) {
  TempDir dir;
  auto tier = OpenTier(dir.cache(), 4 * EntryBytes());  // exactly 4 entries fit
  for (int i = 0; i < 4; ++i) Write(*tier, i);
  ASSERT_EQ(StoredKeys(dir.cache(), 10), "0 1 2 3");
  const std::optional<std::string> read = tier->Read(Key(0));
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(*read, Payload(Key(0)));
  Write(*tier, 4);
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "0 2 3 4");  // 1 is now the least recently used
  Write(*tier, 5);
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "0 3 4 5");
  EXPECT_EQ(tier->counts().evictions, 2);
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

TEST(DiskTierBound, SmallerBoundAtOpenEvictsTheOldest) {
  TempDir dir;
  {
    auto tier = OpenTier(dir.cache(), 0);
    for (int i = 0; i < 10; ++i) Write(*tier, i);
  }
  for (int i = 0; i < 10; ++i) SetAge(dir.cache(), i, 100 - i);  // 0 is the oldest
  auto tier = OpenTier(dir.cache(), 4 * EntryBytes());
  const DiskTier::Counts counts = tier->counts();
  EXPECT_EQ(counts.entries, 4);
  EXPECT_EQ(counts.evictions, 6);
  EXPECT_EQ(counts.evicted_bytes, 6 * EntryBytes());
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "6 7 8 9");
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

TEST(DiskTierBound, OrderIsRebuiltFromModificationTimes) {
  TempDir dir;
  {
    auto tier = OpenTier(dir.cache(), 0);
    for (int i = 0; i < 6; ++i) Write(*tier, i);
  }
  // Oldest to newest: 3 0 5 1 4 2, unlike the order of writing.
  const int by_age[] = {3, 0, 5, 1, 4, 2};
  for (int rank = 0; rank < 6; ++rank) SetAge(dir.cache(), by_age[rank], 60 - 10 * rank);
  auto tier = OpenTier(dir.cache(), 6 * EntryBytes());
  ASSERT_EQ(tier->counts().evictions, 0);
  for (int rank = 0; rank < 6; ++rank) {
    Write(*tier, 10 + rank);  // each new entry pushes out exactly one old one
    EXPECT_FALSE(Stored(dir.cache(), by_age[rank])) << "rank " << rank;
    for (int later = rank + 1; later < 6; ++later) {
      EXPECT_TRUE(Stored(dir.cache(), by_age[later])) << "rank " << rank << ", " << later;
    }
  }
  EXPECT_EQ(tier->counts().evictions, 6);
}

TEST(DiskTierBound, ReadRecordsTheUseInTheFileForTheNextOpen) {
  TempDir dir;
  {
    auto tier = OpenTier(dir.cache(), 0);
    for (int i = 0; i < 4; ++i) Write(*tier, i);
  }
  for (int i = 0; i < 4; ++i) SetAge(dir.cache(), i, 100 - i);  // 0 is the oldest
  {
    auto tier = OpenTier(dir.cache(), 0);
    ASSERT_TRUE(tier->Read(Key(0)).has_value());
  }
  EXPECT_GT(fs::last_write_time(EntryFile(dir.cache(), Key(0))),
            fs::last_write_time(EntryFile(dir.cache(), Key(3))));
  auto tier = OpenTier(dir.cache(), 2 * EntryBytes());
  EXPECT_EQ(StoredKeys(dir.cache(), 4), "0 3");
  EXPECT_EQ(tier->counts().evictions, 2);
}

TEST(DiskTierBound, FilesDeletedBehindItsBackAreForgotten) {
  TempDir dir;
  auto tier = OpenTier(dir.cache(), 4 * EntryBytes());
  for (int i = 0; i < 4; ++i) Write(*tier, i);
  ASSERT_TRUE(fs::remove(EntryFile(dir.cache(), Key(1))));
  EXPECT_EQ(tier->counts().entries, 4);  // not noticed yet

  Write(*tier, 4);  // evicts 0; 1 is next in line but gone
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "2 3 4");
  Write(*tier, 5);  // 1 is forgotten, not evicted: 2 stays
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "2 3 4 5");
  DiskTier::Counts counts = tier->counts();
  EXPECT_EQ(counts.evictions, 1);
  EXPECT_EQ(counts.evicted_bytes, EntryBytes());
  EXPECT_EQ(counts.errors, 0);
  ExpectCountsMatchDirectory(*tier, dir.cache());

  // A read of a vanished entry is a miss that corrects the counts.
  ASSERT_TRUE(fs::remove(EntryFile(dir.cache(), Key(3))));
  EXPECT_FALSE(tier->Read(Key(3)).has_value());
  counts = tier->counts();
  EXPECT_EQ(counts.entries, 3);
  EXPECT_EQ(counts.errors, 0);
  ExpectCountsMatchDirectory(*tier, dir.cache());
  // Rewritten, it is counted once.
  Write(*tier, 3);
  EXPECT_EQ(tier->counts().entries, 4);
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

// The system call thread `tid` of this process is blocked in, or -1 when it is running.
long CurrentSyscall(pid_t tid) {
  std::ifstream in(absl::StrCat("/proc/self/task/", tid, "/syscall"));
  long number = -1;
  if (!(in >> number)) return -1;  // "running"
  return number;
}

bool WaitUntil(const std::function<bool()>& condition) {
  for (int i = 0; i < 2000; ++i) {  // up to 20 s
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

TEST(DiskTierBound, EntryBeingReadIsNotEvicted) {
  TempDir dir;
  auto tier = OpenTier(dir.cache(), 3 * EntryBytes());
  for (int i = 0; i < 3; ++i) Write(*tier, i);
  // Key 0, the least recently used, becomes a FIFO: reading it blocks in open() until a writer
  // opens the other end, which holds the read in progress for as long as the test needs. A
  // second link outside the cache reaches the FIFO even if the entry's name is deleted.
  const fs::path oldest = EntryFile(dir.cache(), Key(0));
  const fs::path fifo = dir.path() / "fifo";
  const fs::path kept = dir.path() / "fifo-kept";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_hard_link(fifo, kept);
  fs::rename(fifo, oldest);

  std::atomic<pid_t> reader_tid{0};
  std::optional<std::string> read;
  std::thread reader([&] {
    reader_tid = ::gettid();
    read = tier->Read(Key(0));
  });
  // Holding the FIFO open for reading and writing releases the reader, whenever it opens.
  const auto release_and_join = [&] {
    const int fd = ::open(kept.c_str(), O_RDWR | O_CLOEXEC);
    reader.join();
    if (fd >= 0) ::close(fd);
  };
  struct JoinOnExit {
    std::thread& thread;
    const std::function<void()> release_and_join;
    ~JoinOnExit() {
      if (thread.joinable()) release_and_join();
    }
  } join_on_exit{reader, release_and_join};

  ASSERT_TRUE(WaitUntil([&] {
    return reader_tid.load() != 0 && CurrentSyscall(reader_tid.load()) == SYS_openat;
  })) << "the reader never blocked opening the entry";
  Write(*tier, 3);  // over the bound: 0 is pinned, 1 goes
  Write(*tier, 4);  // 2 goes
  EXPECT_TRUE(fs::exists(oldest)) << "evicted while being read";
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "0 3 4");
  EXPECT_EQ(tier->counts().evictions, 2);

  release_and_join();
  EXPECT_FALSE(read.has_value());  // a FIFO fails the entry's checks: dropped as corrupt
  EXPECT_FALSE(fs::exists(oldest));
  const DiskTier::Counts counts = tier->counts();
  EXPECT_EQ(counts.errors, 1);
  EXPECT_EQ(counts.entries, 2);
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

TEST(DiskTierBound, EntryLargerThanTheBoundIsNotWritten) {
  TempDir dir;
  auto tier = OpenTier(dir.cache(), 3 * EntryBytes());
  Write(*tier, 0);
  Write(*tier, 1);
  tier->Write("k/large", std::string(3 * EntryBytes(), 'x'));  // its header makes it too large
  EXPECT_FALSE(fs::exists(EntryFile(dir.cache(), "k/large")));
  const DiskTier::Counts counts = tier->counts();
  EXPECT_EQ(counts.writes_too_large, 1);
  EXPECT_EQ(counts.evictions, 0);
  EXPECT_EQ(counts.write_errors, 0);
  EXPECT_EQ(StoredKeys(dir.cache(), 10), "0 1");
  // One that fits exactly is written, evicting what it must.
  const std::string fits(
      static_cast<std::size_t>(3 * EntryBytes()) - EntryHeaderSize(std::string("k/fits").size()),
      'y');
  tier->Write("k/fits", fits);
  EXPECT_TRUE(fs::exists(EntryFile(dir.cache(), "k/fits")));
  EXPECT_EQ(tier->counts().evictions, 2);
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

// Threads writing and reading overlapping keys: the bound holds and the counts stay exact.
TEST(DiskTierBound, ConcurrentReadsAndWritesKeepTheCountsExact) {
  TempDir dir;
  const std::int64_t bound = 20 * EntryBytes();
  auto tier = OpenTier(dir.cache(), bound);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&tier, t] {
      std::mt19937 random(t);
      for (int n = 0; n < 200; ++n) {
        const int i = static_cast<int>(random() % 60);
        if (random() % 2 == 0) {
          Write(*tier, i);
        } else if (std::optional<std::string> read = tier->Read(Key(i))) {
          EXPECT_EQ(*read, Payload(Key(i)));
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  const DiskTier::Counts counts = tier->counts();
  EXPECT_LE(counts.bytes, bound);
  EXPECT_GT(counts.evictions, 0);
  EXPECT_EQ(counts.errors + counts.write_errors, 0);
  ExpectCountsMatchDirectory(*tier, dir.cache());
}

TEST(ResultCacheDiskBound, StatsReportTheBoundAndItsEvictions) {
  TempDir dir;
  ResultCacheOptions options = cache_test::Options(1 << 20, dir.cache());
  options.disk_bytes = 3 * EntryBytes();
  auto opened = ResultCache::Open(options);
  ASSERT_TRUE(opened.ok()) << opened.status();
  ResultCache& cache = **opened;
  for (int i = 0; i < 5; ++i)
    ASSERT_TRUE(cache.Put(Key(i), cache_test::Value(Payload(Key(i)))).ok());
  ASSERT_TRUE(cache.Put("k/large", cache_test::Value(std::string(4 * EntryBytes(), 'x'))).ok());
  const ResultCacheStats stats = cache.stats();
  EXPECT_EQ(stats.disk_bytes_limit, 3 * EntryBytes());
  EXPECT_EQ(stats.disk_entries, 3);
  EXPECT_EQ(stats.disk_bytes, 3 * EntryBytes());
  EXPECT_EQ(stats.disk_evictions, 2);
  EXPECT_EQ(stats.disk_evicted_bytes, 2 * EntryBytes());
  EXPECT_EQ(stats.disk_writes_too_large, 1);
  EXPECT_EQ(stats.entries, 6);  // all of them still in memory
}

TEST(ResultCacheDiskBound, NegativeBoundIsRejectedNamingTheFlag) {
  TempDir dir;
  ResultCacheOptions options = cache_test::Options(1 << 20, dir.cache());
  options.disk_bytes = -1;
  const absl::Status status = ResultCache::Open(options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("--cache-disk-bytes"));
}

}  // namespace
}  // namespace inscribe::server
