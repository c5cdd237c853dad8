#include "disk_tier.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <optional>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "cache_entry_format.h"

namespace inscribe::server {
namespace fs = std::filesystem;
namespace {

// Temporary files are "<entry name>.tmp-<pid>-<n>" in the entry's directory, so that rename is
// atomic (same file system) and Open can recognise and remove those a crash left behind.
constexpr absl::string_view kTempMarker = ".tmp-";

// Writes stop for this long after a failure of the file system, doubled per failed retry.
constexpr std::chrono::milliseconds kFirstBackoff{1000};
constexpr std::chrono::milliseconds kLongestBackoff{60'000};

// Errors of the file system as a whole (full, read-only, over quota, forbidden, failing) rather
// than of one entry: every further write would fail alike, so writes stop for a backoff.
bool StopsWrites(int error) {
  switch (error) {
    case ENOSPC:
    case EROFS:
    case EACCES:
    case EPERM:
    case EDQUOT:
    case EFBIG:
    case EIO:
      return true;
    default:
      return false;
  }
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

// 0, or the errno of the write that failed. A short write is followed by one that reports
// why (ENOSPC, EFBIG past RLIMIT_FSIZE with SIGXFSZ ignored, ...).
int WriteAll(int fd, absl::string_view data) {
  while (!data.empty()) {
    const ssize_t written = ::write(fd, data.data(), data.size());
    if (written < 0 && errno == EINTR) continue;
    if (written < 0) return errno;
    if (written == 0) return EIO;  // no progress and no reason: treat the device as failing
    data.remove_prefix(static_cast<std::size_t>(written));
  }
  return 0;
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

}  // namespace

absl::StatusOr<std::unique_ptr<DiskTier>> DiskTier::Open(
    const std::string& dir, std::int64_t max_bytes,
    std::function<void(const DiskTierEvent&)> on_event) {
  assert(max_bytes >= 0);
  std::unique_ptr<DiskTier> tier(new DiskTier(dir, max_bytes, std::move(on_event)));
  if (absl::Status status = tier->Scan(); !status.ok()) return status;
  return tier;
}

DiskTier::PinnedName::PinnedName(DiskTier& tier, std::string name)
    : tier_(tier), name_(std::move(name)) {
  std::lock_guard<std::mutex> lock(tier_.mutex_);
  ++tier_.pins_[name_];
}

DiskTier::PinnedName::~PinnedName() {
  std::lock_guard<std::mutex> lock(tier_.mutex_);
  const auto it = tier_.pins_.find(name_);
  assert(it != tier_.pins_.end());
  if (--it->second == 0) tier_.pins_.erase(it);
  tier_.EvictLocked();  // what this pin held back, if anything
}

absl::Status DiskTier::Scan() {
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_, error)) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create cache directory ", dir_.string(), ": ",
                     error ? error.message() : "exists and is not a directory"));
  }
  // Root ignores permission bits, so try a write rather than ask access(2).
  const fs::path probe = dir_ / absl::StrCat("probe", kTempMarker, ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("cache directory ", dir_.string(), " is not writable: ", ErrnoMessage()));
  }
  ::close(fd);
  fs::remove(probe, error);

  // Index the entries (dir/<2 hex>/<64 hex>) by modification time; remove temporary files
  // left by a crash.
  struct Found {
    timespec modified;
    std::string name;
    std::int64_t bytes;
  };
  std::vector<Found> found;
  const fs::directory_iterator end;
  fs::directory_iterator shards(dir_, error);
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
      struct stat info {};
      if (!IsLowerHex(name, 64) || !absl::StartsWith(name, shard_name) ||
          ::stat(files->path().c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
        continue;
      }
      found.push_back(Found{info.st_mtim, name, static_cast<std::int64_t>(info.st_size)});
    }
  }
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot list cache directory ", dir_.string(), ": ", error.message()));
  }
  // Oldest first, so that each push to the front leaves the newest there. Equal times (coarse
  // clocks) fall back to the name, so that the order does not depend on the listing's.
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return std::tie(a.modified.tv_sec, a.modified.tv_nsec, a.name) <
           std::tie(b.modified.tv_sec, b.modified.tv_nsec, b.name);
  });
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Found& entry : found) TouchLocked(entry.name, entry.bytes);
  EvictLocked();
  return absl::OkStatus();
}

void DiskTier::TouchLocked(const std::string& name, std::int64_t bytes) {
  const auto it = index_.find(name);
  if (it == index_.end()) {
    recency_.push_front(Indexed{name, bytes});
    index_.emplace(recency_.front().name, recency_.begin());
    ++counts_.entries;
    counts_.bytes += bytes;
    return;
  }
  counts_.bytes += bytes - it->second->bytes;
  it->second->bytes = bytes;
  recency_.splice(recency_.begin(), recency_, it->second);
}

void DiskTier::ForgetLocked(absl::string_view name) {
  const auto it = index_.find(name);
  if (it == index_.end()) return;
  const std::list<Indexed>::iterator entry = it->second;
  --counts_.entries;
  counts_.bytes -= entry->bytes;
  index_.erase(it);  // before the entry: the key views its name
  recency_.erase(entry);
}

void DiskTier::NoteFileLocked(const fs::path& path, const std::string& name) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
    ForgetLocked(name);
    return;
  }
  TouchLocked(name, static_cast<std::int64_t>(info.st_size));
  EvictLocked();
}

void DiskTier::EvictLocked(std::int64_t incoming) {
  if (max_bytes_ == 0) return;
  // Walks from the least recently used end towards the front; `next` is the entry after the
  // candidate, so erasing the candidate leaves it valid.
  std::list<Indexed>::iterator next = recency_.end();
  while (counts_.bytes + incoming > max_bytes_ && next != recency_.begin()) {
    const std::list<Indexed>::iterator candidate = std::prev(next);
    if (pins_.contains(candidate->name)) {  // being read or written: the next one goes
      next = candidate;
      continue;
    }
    const fs::path path = dir_ / candidate->name.substr(0, 2) / candidate->name;
    std::error_code error;
    const bool removed = fs::remove(path, error);
    if (error) {  // cannot be deleted (e.g. a read-only directory): kept and counted as held
      next = candidate;
      continue;
    }
    if (removed) {  // else it had vanished: forgotten, not an eviction
      ++counts_.evictions;
      counts_.evicted_bytes += candidate->bytes;
    }
    ForgetLocked(candidate->name);
  }
}

fs::path DiskTier::EntryPath(absl::string_view key) const {
  const Sha256Digest digest = Sha256(key);
  const std::string hex = absl::BytesToHexString(
      absl::string_view(reinterpret_cast<const char*>(digest.data()), digest.size()));
  return dir_ / hex.substr(0, 2) / hex;
}

std::optional<std::string> DiskTier::Read(absl::string_view key) {
  const fs::path path = EntryPath(key);
  const std::string name = path.filename().string();
  const PinnedName pin(*this, name);
  const FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.fd < 0) {
    if (errno == ENOENT || errno == ENOTDIR) {
      std::lock_guard<std::mutex> lock(mutex_);
      // Indexed but missing: deleted behind this process's back, unless a write has just
      // renamed it into place (NoteFileLocked looks again under the lock).
      if (index_.contains(name)) NoteFileLocked(path, name);
      return std::nullopt;
    }
    DropFile(path);  // unreadable: as useless as a corrupt one
    return std::nullopt;
  }
  struct stat info {};
  const std::size_t header_size = EntryHeaderSize(key.size());
  std::string header(header_size, '\0');
  const bool header_ok =
      ::fstat(file.fd, &info) == 0 && static_cast<std::uint64_t>(info.st_size) >= header_size &&
      ReadAll(file.fd, header.data(), header.size()) &&
      EntryHeaderMatches(header, key, static_cast<std::uint64_t>(info.st_size) - header_size);
  if (!header_ok) {
    DropFile(path);
    return std::nullopt;
  }
  std::string payload(static_cast<std::size_t>(info.st_size) - header_size, '\0');
  if (!ReadAll(file.fd, payload.data(), payload.size()) || !EntryPayloadMatches(header, payload)) {
    DropFile(path);
    return std::nullopt;
  }
  // The modification time records the use for the order rebuilt at the next Open; should
  // this fail, only that is lost.
  ::futimens(file.fd, nullptr);
  std::lock_guard<std::mutex> lock(mutex_);
  NoteFileLocked(path, name);
  return payload;
}

void DiskTier::DropCorrupt(absl::string_view key) { DropFile(EntryPath(key)); }

void DiskTier::DropFile(const fs::path& path) {
  std::error_code error;
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.errors;
  fs::remove(path, error);
  if (!error) ForgetLocked(path.filename().string());  // removed, or gone already
}

void DiskTier::Write(absl::string_view key, absl::string_view payload) {
  const fs::path path = EntryPath(key);
  const std::uint64_t size = EntryHeaderSize(key.size()) + payload.size();
  if (max_bytes_ > 0 && size > static_cast<std::uint64_t>(max_bytes_)) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.writes_too_large;
    return;
  }
  std::error_code error;
  if (fs::exists(path, error)) return;  // kept: equal keys mean equal content
  const PinnedName pin(*this, path.filename().string());
  const Attempt attempt = BeginWrite();
  if (!attempt.allowed) return;
  std::string failed_step;
  const int failure = WriteEntry(path, key, payload, &failed_step);
  EndWrite(attempt, failure, failed_step);
}

int DiskTier::WriteEntry(const fs::path& path, absl::string_view key, absl::string_view payload,
                         std::string* failed_step) {
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  if (error) {
    *failed_step = absl::StrCat("create ", path.parent_path().string());
    return error.value();
  }
  const fs::path temp = path.parent_path() / absl::StrCat(path.filename().string(), kTempMarker,
                                                          ::getpid(), "-", temp_files_++);
  const std::string header = EntryHeader(key, payload);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    *failed_step = absl::StrCat("create ", temp.string());
    return errno;
  }
  // fsync before rename: after a crash the name refers to the whole payload or to nothing.
  int failure = WriteAll(fd, header);
  if (failure == 0) failure = WriteAll(fd, payload);
  if (failure == 0 && ::fsync(fd) != 0) failure = errno;
  if (::close(fd) != 0 && failure == 0) failure = errno;
  if (failure != 0) {
    *failed_step = absl::StrCat("write ", temp.string());
    fs::remove(temp, error);
    return failure;
  }

  const std::string name = path.filename().string();
  std::lock_guard<std::mutex> lock(mutex_);
  if (fs::exists(path, error)) {  // written meanwhile (by a Put): keep that one
    fs::remove(temp, error);
    NoteFileLocked(path, name);
    return 0;
  }
  // Room first, so that the entries exceed the bound at no moment, unless the ones that would
  // go are pinned.
  const auto bytes = static_cast<std::int64_t>(header.size() + payload.size());
  EvictLocked(bytes);
  fs::rename(temp, path, error);
  if (error) {
    *failed_step = absl::StrCat("rename ", temp.string());
    failure = error.value();
    fs::remove(temp, error);
    return failure;
  }
  TouchLocked(name, bytes);
  return 0;
}

DiskTier::Attempt DiskTier::BeginWrite() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (counts_.available) return Attempt{true, false};
  if (!probing_ && std::chrono::steady_clock::now() >= stopped_until_) {
    probing_ = true;
    return Attempt{true, true};
  }
  ++counts_.writes_skipped;
  return Attempt{false, false};
}

void DiskTier::EndWrite(const Attempt& attempt, int failure, const std::string& failed_step) {
  std::optional<DiskTierEvent> event;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failure == 0) {
      if (attempt.probe) {
        probing_ = false;
        counts_.available = true;
        backoff_ = std::chrono::milliseconds(0);
        event = DiskTierEvent{DiskTierEvent::Kind::kRestored, dir_.string(), absl::OkStatus(), {}};
      }
    } else {
      ++counts_.write_errors;
      const bool stops = StopsWrites(failure);
      if (counts_.available && stops) {
        counts_.available = false;
        backoff_ = kFirstBackoff;
        stopped_until_ = std::chrono::steady_clock::now() + backoff_;
        event = DiskTierEvent{DiskTierEvent::Kind::kDegraded, dir_.string(),
                              absl::ErrnoToStatus(failure, failed_step), backoff_};
      } else if (attempt.probe) {
        // Any failure of the retry (even one of this entry alone) keeps writes stopped.
        probing_ = false;
        backoff_ = std::min(2 * backoff_, kLongestBackoff);
        stopped_until_ = std::chrono::steady_clock::now() + backoff_;
      }
    }
  }
  if (event.has_value() && on_event_) on_event_(*event);
}

DiskTier::Counts DiskTier::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Counts counts = counts_;
  counts.max_bytes = max_bytes_;
  return counts;
}

}  // namespace inscribe::server
