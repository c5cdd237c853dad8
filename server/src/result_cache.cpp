#include "inscribe/server/result_cache.h"

#include <fcntl.h>
#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <condition_variable>
#include <filesystem>
#include <list>
#include <mutex>
#include <optional>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace inscribe::server {
namespace fs = std::filesystem;
namespace {

constexpr std::size_t kMaxKeyLength = 200;

// On-disk entry, all integers little-endian:
//   "inscribe-cache 1\n"           17 bytes
//   key length                     uint32
//   key                            key length bytes (checked against the requested key, so a
//                                  SHA-256 collision of two keys or a moved file is a miss)
//   payload length                 uint64 (must equal what is left of the file)
//   SHA-256 of the payload         32 bytes
//   payload                        CachedValue::bytes
constexpr absl::string_view kMagic = "inscribe-cache 1\n";
constexpr std::size_t kDigestSize = 32;
std::size_t HeaderSize(std::size_t key_size) {
  return kMagic.size() + 4 + key_size + 8 + kDigestSize;
}

// Temporary files are "<entry name>.tmp-<pid>-<n>" in the entry's directory, so that rename is
// atomic (same file system) and Open can recognise and remove those a crash left behind.
constexpr absl::string_view kTempMarker = ".tmp-";

using Digest = std::array<unsigned char, kDigestSize>;

Digest Sha256(absl::string_view data) {
  Digest digest{};
  unsigned int length = 0;
  const int ok =
      EVP_Digest(data.data(), data.size(), digest.data(), &length, EVP_sha256(), nullptr);
  assert(ok == 1 && length == digest.size());
  static_cast<void>(ok);
  return digest;
}

absl::string_view AsView(const Digest& digest) {
  return absl::string_view(reinterpret_cast<const char*>(digest.data()), digest.size());
}

void AppendLittleEndian(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>(value >> (8 * i)));
}

std::uint64_t ReadLittleEndian(absl::string_view in, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) {
    value |= std::uint64_t{static_cast<unsigned char>(in[i])} << (8 * i);
  }
  return value;
}

std::string EntryHeader(absl::string_view key, absl::string_view payload) {
  std::string header(kMagic);
  header.reserve(HeaderSize(key.size()));
  AppendLittleEndian(header, key.size(), 4);
  header.append(key.data(), key.size());
  AppendLittleEndian(header, payload.size(), 8);
  const Digest digest = Sha256(payload);
  header.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  return header;
}

bool IsLowerHex(absl::string_view name, std::size_t length) {
  if (name.size() != length) return false;
  for (char c : name) {
    if (!absl::ascii_isdigit(c) && (c < 'a' || c > 'f')) return false;
  }
  return true;
}

std::string ErrnoMessage() { return std::error_code(errno, std::generic_category()).message(); }

// Closes the descriptor on every path out of a read.
struct FileDescriptor {
  explicit FileDescriptor(int descriptor) : fd(descriptor) {}
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int fd;
};

bool WriteAll(int fd, absl::string_view data) {
  while (!data.empty()) {
    const ssize_t written = ::write(fd, data.data(), data.size());
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return false;
    data.remove_prefix(static_cast<std::size_t>(written));
  }
  return true;
}

// False on an error or end of file before `size` bytes.
bool ReadAll(int fd, char* out, std::size_t size) {
  while (size > 0) {
    const ssize_t got = ::read(fd, out, size);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    out += got;
    size -= static_cast<std::size_t>(got);
  }
  return true;
}

std::int64_t Cost(absl::string_view key, const CachedValue& value) {
  return static_cast<std::int64_t>(key.size() + value.bytes.size()) + value.object_bytes;
}

absl::Status NotCached(absl::string_view key) {
  return absl::NotFoundError(absl::StrCat("no cached entry ", key));
}

// One computation (or disk lookup) of a key in progress, and its outcome once done.
struct Flight {
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  // A Get led the flight and found the key in neither tier: waiting Gets report NOT_FOUND and
  // waiting GetOrComputes start over (one of them computes).
  bool absent = false;
  absl::Status status;  // the computation's error
  std::shared_ptr<const CachedValue> value;
};

void Publish(Flight& flight, bool absent, absl::Status status,
             std::shared_ptr<const CachedValue> value) {
  {
    std::lock_guard<std::mutex> lock(flight.mutex);
    if (flight.done) return;
    flight.done = true;
    flight.absent = absent;
    flight.status = std::move(status);
    flight.value = std::move(value);
  }
  flight.finished.notify_all();
}

}  // namespace

const char* CacheSourceName(CacheSource source) {
  switch (source) {
    case CacheSource::kMemory:
      return "memory";
    case CacheSource::kDisk:
      return "disk";
    case CacheSource::kComputed:
      return "computed";
    case CacheSource::kJoined:
      return "joined";
  }
  return "unknown";
}

absl::Status CheckCacheKey(absl::string_view key) {
  if (key.empty()) return absl::InvalidArgumentError("cache key is empty");
  if (key.size() > kMaxKeyLength) {
    return absl::InvalidArgumentError(
        absl::StrCat("cache key has ", key.size(), " characters; at most ", kMaxKeyLength));
  }
  for (std::size_t i = 0; i < key.size(); ++i) {
    const char c = key[i];
    if (absl::ascii_isalnum(c) || c == '.' || c == '_' || c == ':' || c == '/' || c == '-') {
      continue;
    }
    return absl::InvalidArgumentError(absl::StrCat(
        "cache key \"", absl::CHexEscape(key), "\" has '", absl::CHexEscape(key.substr(i, 1)),
        "' at offset ", i, "; allowed are A-Z a-z 0-9 . _ : / -"));
  }
  return absl::OkStatus();
}

struct ResultCache::Impl {
  struct Entry {
    std::string key;
    std::shared_ptr<const CachedValue> value;
    std::int64_t cost;
  };

  Impl(std::int64_t memory_budget, std::string disk_dir)
      : budget(memory_budget), dir(std::move(disk_dir)) {}

  ~Impl() { assert(flights.empty() && "ResultCache destroyed during a lookup"); }

  absl::Status OpenDisk();
  absl::StatusOr<CacheLookup> Lookup(absl::string_view key, const Compute* compute,
                                     const Decode& decode);
  absl::StatusOr<CacheLookup> Lead(absl::string_view key, const std::shared_ptr<Flight>& flight,
                                   const Compute* compute, const Decode& decode);
  std::shared_ptr<const CachedValue> FindLocked(absl::string_view key);
  std::shared_ptr<const CachedValue> InsertLocked(
      absl::string_view key, std::shared_ptr<const CachedValue> value,
      std::vector<std::shared_ptr<const CachedValue>>& evicted);
  void EraseFlightLocked(absl::string_view key, const std::shared_ptr<Flight>& flight);
  fs::path EntryPath(absl::string_view key) const;
  std::optional<std::string> ReadDisk(absl::string_view key);
  void DropCorrupt(const fs::path& path);
  void WriteDisk(absl::string_view key, absl::string_view payload);

  const std::int64_t budget;
  const fs::path dir;  // empty: no disk tier

  // Guards the memory tier, the flights and the lookup counters. Held only for map and list
  // updates: never while computing, decoding, doing disk IO or freeing evicted values.
  mutable std::mutex mutex;
  std::list<Entry> lru;  // most recently used first
  absl::flat_hash_map<absl::string_view, std::list<Entry>::iterator> index;  // views Entry::key
  absl::flat_hash_map<std::string, std::shared_ptr<Flight>> flights;
  ResultCacheStats counters;  // all but the disk_* fields

  // Guards the disk_* counters; held across each rename or removal (metadata operations, no
  // payload IO) so that they count what the directory holds exactly, assuming this process is
  // its only writer.
  mutable std::mutex disk_mutex;
  std::int64_t disk_entries = 0;
  std::int64_t disk_bytes = 0;
  std::int64_t disk_errors = 0;
  std::int64_t disk_write_errors = 0;
  std::atomic<std::uint64_t> temp_files{0};  // names temporary files uniquely in this process
};

absl::Status ResultCache::Impl::OpenDisk() {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir, error)) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create cache directory ", dir.string(), ": ",
                     error ? error.message() : "exists and is not a directory"));
  }
  // Root ignores permission bits, so try a write rather than ask access(2).
  const fs::path probe = dir / absl::StrCat("probe", kTempMarker, ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("cache directory ", dir.string(), " is not writable: ", ErrnoMessage()));
  }
  ::close(fd);
  fs::remove(probe, error);

  // Count the entries (dir/<2 hex>/<64 hex>); remove temporary files left by a crash.
  const fs::directory_iterator end;
  fs::directory_iterator shards(dir, error);
  for (; !error && shards != end; shards.increment(error)) {
    const fs::path& shard = shards->path();
    const std::string shard_name = shard.filename().string();
    std::error_code ignored;
    if (absl::StrContains(shard_name, kTempMarker)) {  // a probe left by a crash
      fs::remove(shard, ignored);
      continue;
    }
    if (!IsLowerHex(shard_name, 2) || !shards->is_directory(ignored)) continue;
    fs::directory_iterator files(shard, error);
    for (; !error && files != end; files.increment(error)) {
      const std::string name = files->path().filename().string();
      if (absl::StrContains(name, kTempMarker)) {
        fs::remove(files->path(), ignored);
        continue;
      }
      if (!IsLowerHex(name, 64) || !absl::StartsWith(name, shard_name) ||
          !files->is_regular_file(ignored)) {
        continue;
      }
      const std::uintmax_t size = files->file_size(ignored);
      if (ignored) continue;
      ++disk_entries;
      disk_bytes += static_cast<std::int64_t>(size);
    }
  }
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot list cache directory ", dir.string(), ": ", error.message()));
  }
  return absl::OkStatus();
}

std::shared_ptr<const CachedValue> ResultCache::Impl::FindLocked(absl::string_view key) {
  const auto it = index.find(key);
  if (it == index.end()) return nullptr;
  lru.splice(lru.begin(), lru, it->second);
  return it->second->value;
}

std::shared_ptr<const CachedValue> ResultCache::Impl::InsertLocked(
    absl::string_view key, std::shared_ptr<const CachedValue> value,
    std::vector<std::shared_ptr<const CachedValue>>& evicted) {
  if (std::shared_ptr<const CachedValue> existing = FindLocked(key)) return existing;
  assert(value->object_bytes >= 0);
  const std::int64_t cost = Cost(key, *value);
  if (cost > budget) return value;  // larger than the whole tier: returned, not kept
  lru.push_front(Entry{std::string(key), value, cost});
  index.emplace(lru.front().key, lru.begin());
  ++counters.entries;
  counters.bytes += cost;
  // The new entry fits on its own, so it is never the one evicted.
  while (counters.bytes > budget) {
    Entry& oldest = lru.back();
    index.erase(oldest.key);
    counters.bytes -= oldest.cost;
    --counters.entries;
    ++counters.evictions;
    evicted.push_back(std::move(oldest.value));  // freed by the caller, after unlocking
    lru.pop_back();
  }
  return value;
}

void ResultCache::Impl::EraseFlightLocked(absl::string_view key,
                                          const std::shared_ptr<Flight>& flight) {
  const auto it = flights.find(key);
  if (it != flights.end() && it->second == flight) flights.erase(it);
}

fs::path ResultCache::Impl::EntryPath(absl::string_view key) const {
  const std::string hex = absl::BytesToHexString(AsView(Sha256(key)));
  return dir / hex.substr(0, 2) / hex;
}

std::optional<std::string> ResultCache::Impl::ReadDisk(absl::string_view key) {
  const fs::path path = EntryPath(key);
  const FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.fd < 0) {
    if (errno == ENOENT || errno == ENOTDIR) return std::nullopt;
    DropCorrupt(path);  // unreadable: as useless as a corrupt one
    return std::nullopt;
  }
  struct stat info {};
  const std::size_t header_size = HeaderSize(key.size());
  std::string header(header_size, '\0');
  const bool header_ok =
      ::fstat(file.fd, &info) == 0 && static_cast<std::uint64_t>(info.st_size) >= header_size &&
      ReadAll(file.fd, header.data(), header.size()) && absl::StartsWith(header, kMagic) &&
      ReadLittleEndian(absl::string_view(header).substr(kMagic.size()), 4) == key.size() &&
      absl::string_view(header).substr(kMagic.size() + 4, key.size()) == key &&
      ReadLittleEndian(absl::string_view(header).substr(kMagic.size() + 4 + key.size()), 8) ==
          static_cast<std::uint64_t>(info.st_size) - header_size;
  if (!header_ok) {
    DropCorrupt(path);
    return std::nullopt;
  }
  std::string payload(static_cast<std::size_t>(info.st_size) - header_size, '\0');
  if (!ReadAll(file.fd, payload.data(), payload.size()) ||
      AsView(Sha256(payload)) != absl::string_view(header).substr(header_size - kDigestSize)) {
    DropCorrupt(path);
    return std::nullopt;
  }
  return payload;
}

void ResultCache::Impl::DropCorrupt(const fs::path& path) {
  std::error_code error;
  std::lock_guard<std::mutex> lock(disk_mutex);
  ++disk_errors;
  const std::uintmax_t size = fs::file_size(path, error);
  if (fs::remove(path, error)) {
    --disk_entries;
    disk_bytes -= static_cast<std::int64_t>(size);
  }
}

void ResultCache::Impl::WriteDisk(absl::string_view key, absl::string_view payload) {
  const fs::path path = EntryPath(key);
  std::error_code error;
  if (fs::exists(path, error)) return;  // kept: equal keys mean equal content
  const auto count_error = [this] {
    std::lock_guard<std::mutex> lock(disk_mutex);
    ++disk_write_errors;
  };
  fs::create_directories(path.parent_path(), error);
  if (error) return count_error();

  const fs::path temp = path.parent_path() / absl::StrCat(path.filename().string(), kTempMarker,
                                                          ::getpid(), "-", temp_files++);
  const std::string header = EntryHeader(key, payload);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return count_error();
  // fsync before rename: after a crash the name refers to the whole payload or to nothing.
  bool written = WriteAll(fd, header) && WriteAll(fd, payload) && ::fsync(fd) == 0;
  if (::close(fd) != 0) written = false;
  if (!written) {
    fs::remove(temp, error);
    return count_error();
  }

  std::lock_guard<std::mutex> lock(disk_mutex);
  if (fs::exists(path, error)) {  // written meanwhile (by a Put): keep that one
    fs::remove(temp, error);
    return;
  }
  fs::rename(temp, path, error);
  if (error) {
    fs::remove(temp, error);
    ++disk_write_errors;
    return;
  }
  ++disk_entries;
  disk_bytes += static_cast<std::int64_t>(header.size() + payload.size());
}

absl::StatusOr<CacheLookup> ResultCache::Impl::Lookup(absl::string_view key, const Compute* compute,
                                                      const Decode& decode) {
  if (absl::Status status = CheckCacheKey(key); !status.ok()) return status;
  for (;;) {
    std::shared_ptr<Flight> flight;
    bool leader = false;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (std::shared_ptr<const CachedValue> value = FindLocked(key)) {
        ++counters.memory_hits;
        return CacheLookup{std::move(value), CacheSource::kMemory};
      }
      auto [it, inserted] = flights.try_emplace(key);
      if (inserted) it->second = std::make_shared<Flight>();
      flight = it->second;
      leader = inserted;
    }
    if (leader) {
      try {
        return Lead(key, flight, compute, decode);
      } catch (...) {
        // A throwing compute or decode is the caller's bug; still release the waiters.
        {
          std::lock_guard<std::mutex> lock(mutex);
          EraseFlightLocked(key, flight);
        }
        Publish(*flight, /*absent=*/false,
                absl::InternalError(absl::StrCat("computing ", key, " threw an exception")),
                nullptr);
        throw;
      }
    }

    std::unique_lock<std::mutex> wait(flight->mutex);
    flight->finished.wait(wait, [&] { return flight->done; });
    const bool absent = flight->absent;
    const absl::Status status = flight->status;
    std::shared_ptr<const CachedValue> value = flight->value;
    wait.unlock();
    if (absent && compute != nullptr) continue;  // a Get found nothing: compute it ourselves
    // The leader's caller gave up; that says nothing about this caller, which takes over.
    if (compute != nullptr && (status.code() == absl::StatusCode::kCancelled ||
                               status.code() == absl::StatusCode::kDeadlineExceeded)) {
      continue;
    }

    std::lock_guard<std::mutex> lock(mutex);
    if (absent) {
      ++counters.misses;
      return NotCached(key);
    }
    ++counters.joined;
    if (!status.ok()) {
      if (compute != nullptr) return status;
      return absl::NotFoundError(absl::StrCat(
          "no cached entry ", key, " (its computation failed: ", status.ToString(), ")"));
    }
    return CacheLookup{std::move(value), CacheSource::kJoined};
  }
}

absl::StatusOr<CacheLookup> ResultCache::Impl::Lead(absl::string_view key,
                                                    const std::shared_ptr<Flight>& flight,
                                                    const Compute* compute, const Decode& decode) {
  std::shared_ptr<const CachedValue> value;
  if (!dir.empty()) {
    if (std::optional<std::string> payload = ReadDisk(key)) {
      absl::StatusOr<CachedValue> decoded = decode(*std::move(payload));
      if (decoded.ok()) {
        value = std::make_shared<const CachedValue>(*std::move(decoded));
      } else {
        DropCorrupt(EntryPath(key));
      }
    }
  }

  std::vector<std::shared_ptr<const CachedValue>> evicted;
  if (value != nullptr) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++counters.disk_hits;
      value = InsertLocked(key, std::move(value), evicted);
      EraseFlightLocked(key, flight);
    }
    Publish(*flight, /*absent=*/false, absl::OkStatus(), value);
    return CacheLookup{std::move(value), CacheSource::kDisk};
  }

  {
    std::lock_guard<std::mutex> lock(mutex);
    ++counters.misses;
    if (compute == nullptr) {
      EraseFlightLocked(key, flight);
    } else {
      ++counters.computations;
    }
  }
  if (compute == nullptr) {
    Publish(*flight, /*absent=*/true, absl::OkStatus(), nullptr);
    return NotCached(key);
  }

  absl::StatusOr<CachedValue> computed = (*compute)();
  if (!computed.ok()) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      EraseFlightLocked(key, flight);
    }
    Publish(*flight, /*absent=*/false, computed.status(), nullptr);
    return computed.status();
  }
  value = std::make_shared<const CachedValue>(*std::move(computed));
  {
    std::lock_guard<std::mutex> lock(mutex);
    value = InsertLocked(key, std::move(value), evicted);
  }
  // Waiters go on while the file is written. The flight stays registered until the file
  // exists, so a value too large for memory is joined rather than computed again meanwhile.
  Publish(*flight, /*absent=*/false, absl::OkStatus(), value);
  if (!dir.empty() && value->persist) WriteDisk(key, value->bytes);
  {
    std::lock_guard<std::mutex> lock(mutex);
    EraseFlightLocked(key, flight);
  }
  return CacheLookup{std::move(value), CacheSource::kComputed};
}

ResultCache::ResultCache(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ResultCache::~ResultCache() = default;

absl::StatusOr<std::unique_ptr<ResultCache>> ResultCache::Open(const ResultCacheOptions& options) {
  if (options.memory_bytes < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--cache-memory-bytes must be >= 0, got ", options.memory_bytes));
  }
  auto impl = std::make_unique<Impl>(options.memory_bytes, options.disk_dir);
  if (!options.disk_dir.empty()) {
    if (absl::Status status = impl->OpenDisk(); !status.ok()) return status;
  }
  return std::unique_ptr<ResultCache>(new ResultCache(std::move(impl)));
}

absl::StatusOr<CacheLookup> ResultCache::GetOrCompute(absl::string_view key, const Compute& compute,
                                                      const Decode& decode) {
  return impl_->Lookup(key, &compute, decode);
}

absl::StatusOr<CacheLookup> ResultCache::Get(absl::string_view key, const Decode& decode) {
  return impl_->Lookup(key, nullptr, decode);
}

absl::StatusOr<std::shared_ptr<const CachedValue>> ResultCache::Put(absl::string_view key,
                                                                    CachedValue value) {
  if (absl::Status status = CheckCacheKey(key); !status.ok()) return status;
  auto fresh = std::make_shared<const CachedValue>(std::move(value));
  std::shared_ptr<const CachedValue> kept;
  std::vector<std::shared_ptr<const CachedValue>> evicted;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    kept = impl_->FindLocked(key);
    if (kept != nullptr) return kept;
    kept = impl_->InsertLocked(key, std::move(fresh), evicted);
  }
  if (!impl_->dir.empty() && kept->persist) impl_->WriteDisk(key, kept->bytes);
  return kept;
}

ResultCacheStats ResultCache::stats() const {
  ResultCacheStats stats;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    stats = impl_->counters;
  }
  std::lock_guard<std::mutex> lock(impl_->disk_mutex);
  stats.disk_entries = impl_->disk_entries;
  stats.disk_bytes = impl_->disk_bytes;
  stats.disk_errors = impl_->disk_errors;
  stats.disk_write_errors = impl_->disk_write_errors;
  return stats;
}

}  // namespace inscribe::server
