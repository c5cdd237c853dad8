#include "disk_tier.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
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

}  // namespace

absl::StatusOr<std::unique_ptr<DiskTier>> DiskTier::Open(const std::string& dir) {
  std::unique_ptr<DiskTier> tier(new DiskTier(dir));
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
  const auto count_error = [this] {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.write_errors;
  };
  fs::create_directories(path.parent_path(), error);
  if (error) return count_error();

  const fs::path temp = path.parent_path() / absl::StrCat(path.filename().string(), kTempMarker,
                                                          ::getpid(), "-", temp_files_++);
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

  std::lock_guard<std::mutex> lock(mutex_);
  if (fs::exists(path, error)) {  // written meanwhile (by a Put): keep that one
    fs::remove(temp, error);
    return;
  }
  fs::rename(temp, path, error);
  if (error) {
    fs::remove(temp, error);
    ++counts_.write_errors;
    return;
  }
  ++counts_.entries;
  counts_.bytes += static_cast<std::int64_t>(header.size() + payload.size());
}

DiskTier::Counts DiskTier::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

}  // namespace inscribe::server
