#include "disk_tier.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <optional>
#include <system_error>
#include <utility>

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
    const std::string& dir, std::function<void(const DiskTierEvent&)> on_event) {
  std::unique_ptr<DiskTier> tier(new DiskTier(dir, std::move(on_event)));
  if (absl::Status status = tier->Scan(); !status.ok()) return status;
  return tier;
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

  // Count the entries (dir/<2 hex>/<64 hex>); remove temporary files left by a crash.
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
      if (!IsLowerHex(name, 64) || !absl::StartsWith(name, shard_name) ||
          !files->is_regular_file(ignored)) {
        continue;
      }
      const std::uintmax_t size = files->file_size(ignored);
      if (ignored) continue;
      ++counts_.entries;
      counts_.bytes += static_cast<std::int64_t>(size);
    }
  }
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot list cache directory ", dir_.string(), ": ", error.message()));
  }
  return absl::OkStatus();
}

fs::path DiskTier::EntryPath(absl::string_view key) const {
  const Sha256Digest digest = Sha256(key);
  const std::string hex = absl::BytesToHexString(
      absl::string_view(reinterpret_cast<const char*>(digest.data()), digest.size()));
  return dir_ / hex.substr(0, 2) / hex;
}

std::optional<std::string> DiskTier::Read(absl::string_view key) {
  const fs::path path = EntryPath(key);
  const FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.fd < 0) {
    if (errno == ENOENT || errno == ENOTDIR) return std::nullopt;
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
  return payload;
}

void DiskTier::DropCorrupt(absl::string_view key) { DropFile(EntryPath(key)); }

void DiskTier::DropFile(const fs::path& path) {
  std::error_code error;
  std::lock_guard<std::mutex> lock(mutex_);
  ++counts_.errors;
  const std::uintmax_t size = fs::file_size(path, error);
  if (fs::remove(path, error)) {
    --counts_.entries;
    counts_.bytes -= static_cast<std::int64_t>(size);
  }
}

void DiskTier::Write(absl::string_view key, absl::string_view payload) {
  const fs::path path = EntryPath(key);
  std::error_code error;
  if (fs::exists(path, error)) return;  // kept: equal keys mean equal content
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

  std::lock_guard<std::mutex> lock(mutex_);
  if (fs::exists(path, error)) {  // written meanwhile (by a Put): keep that one
    fs::remove(temp, error);
    return 0;
  }
  fs::rename(temp, path, error);
  if (error) {
    *failed_step = absl::StrCat("rename ", temp.string());
    failure = error.value();
    fs::remove(temp, error);
    return failure;
  }
  ++counts_.entries;
  counts_.bytes += static_cast<std::int64_t>(header.size() + payload.size());
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
  return counts_;
}

}  // namespace inscribe::server
