#include "reloadable_server_tls.h"

#include <fcntl.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <stdlib.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "grpc/grpc_security_constants.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/security/tls_certificate_provider.h"
#include "grpcpp/security/tls_credentials_options.h"

namespace inscribe::server {
namespace fs = std::filesystem;

// The PEM text of the three files, each checked.
struct ReloadableServerTls::Pem {
  std::string chain;      // --tls-cert: >= 1 certificates
  std::string key;        // --tls-key: the unencrypted private key of chain's first certificate
  std::string client_ca;  // --tls-client-ca: >= 1 certificates; empty when not given
};

namespace {

// The private directories are <temp>/<kDirPrefix>XXXXXX.
constexpr char kDirPrefix[] = "inscribed-tls-";
// The lock file a server holds (flock) for as long as its directory is in use.
constexpr char kLockName[] = "lock";

// Names of the published copies inside a generation's directory.
constexpr char kKeyName[] = "key.pem";
constexpr char kChainName[] = "cert.pem";
constexpr char kClientCaName[] = "client-ca.pem";

// The text of PEM file `path` (given as `flag`), after OpenSSL has parsed what it must hold:
// `certificates` >= 1 certificates, or else one private key. FAILED_PRECONDITION when it cannot
// be read, INVALID_ARGUMENT when it holds something else. A few KiB.
absl::StatusOr<std::string> ReadPemFile(const std::string& path, const char* flag,
                                        bool certificates) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in) {
    return absl::FailedPreconditionError(absl::StrCat("cannot read ", flag, " file ", path, ": ",
                                                      errno != 0 ? std::strerror(errno) : "?"));
  }
  const std::unique_ptr<BIO, decltype(&BIO_free)> bio(
      BIO_new_mem_buf(text.data(), static_cast<int>(text.size())), BIO_free);
  bool parsed = false;
  if (certificates) {
    X509* cert = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr);
    parsed = cert != nullptr;
    X509_free(cert);
  } else {
    // No passphrase callback: an encrypted key fails here rather than prompting a terminal.
    EVP_PKEY* key = PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, const_cast<char*>(""));
    parsed = key != nullptr;
    EVP_PKEY_free(key);
  }
  // OpenSSL's per-thread error queue would otherwise hold these for gRPC's next TLS call.
  ERR_clear_error();
  if (!parsed) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, " file ", path, " holds no ",
                     certificates ? "PEM certificate" : "unencrypted PEM private key"));
  }
  return text;
}

// Whether the private key belongs to the first certificate of the chain; a mismatch would
// otherwise only show up as every client's handshake failing.
bool KeyMatchesCertificate(const std::string& chain, const std::string& key_pem) {
  const std::unique_ptr<BIO, decltype(&BIO_free)> cert_bio(
      BIO_new_mem_buf(chain.data(), static_cast<int>(chain.size())), BIO_free);
  const std::unique_ptr<BIO, decltype(&BIO_free)> key_bio(
      BIO_new_mem_buf(key_pem.data(), static_cast<int>(key_pem.size())), BIO_free);
  const std::unique_ptr<X509, decltype(&X509_free)> cert(
      PEM_read_bio_X509(cert_bio.get(), nullptr, nullptr, nullptr), X509_free);
  const std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)> key(
      PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, const_cast<char*>("")),
      EVP_PKEY_free);
  const bool matches =
      cert != nullptr && key != nullptr && X509_check_private_key(cert.get(), key.get()) == 1;
  ERR_clear_error();
  return matches;
}

// Removes the private directories in `temp` whose server is gone without removing its own
// (killed): their lock can be taken. Another user's cannot be opened, and a live server's lock
// is held, so both stay. flock, unlike a process id, means the same across containers that
// share `temp`.
void RemoveAbandonedDirs(const fs::path& temp) {
  std::error_code error;
  for (fs::directory_iterator it(temp, error), end; !error && it != end; it.increment(error)) {
    const fs::path dir = it->path();
    if (dir.filename().string().rfind(kDirPrefix, 0) != 0) continue;
    const int fd = open((dir / kLockName).c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
    close(fd);
  }
}

// Makes the private directory and takes its lock; the lock's descriptor (held until the
// directory is removed) and the directory.
absl::StatusOr<std::pair<int, fs::path>> MakeLockedDir(const fs::path& temp) {
  std::string dir = (temp / absl::StrCat(kDirPrefix, "XXXXXX")).string();
  if (mkdtemp(dir.data()) == nullptr) {
    return absl::FailedPreconditionError(absl::StrCat(
        "cannot make a private directory for the TLS files: ", dir, ": ", std::strerror(errno)));
  }
  // Locked under another name, then renamed: a lock file that RemoveAbandonedDirs can open is
  // always held already.
  const fs::path staging = fs::path(dir) / "lock.new";
  const int fd = open(staging.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0 || flock(fd, LOCK_EX) != 0 ||
      rename(staging.c_str(), (fs::path(dir) / kLockName).c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) close(fd);
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return absl::FailedPreconditionError(
        absl::StrCat("cannot lock the private directory for the TLS files ", dir, ": ", reason));
  }
  return std::pair<int, fs::path>(fd, dir);
}

fs::path GenerationDir(const fs::path& dir, int generation) {
  return dir / absl::StrCat("g", generation);
}

// Makes directory `generation` holding `files` (name, text), each stamped `mtime`.
absl::Status WriteGeneration(const fs::path& generation,
                             const std::vector<std::pair<const char*, const std::string*>>& files,
                             fs::file_time_type mtime) {
  std::error_code error;
  fs::create_directory(generation, error);
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot make ", generation.string(), ": ", error.message()));
  }
  for (const auto& [name, text] : files) {
    const fs::path path = generation / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << *text;
    out.close();
    if (!out) return absl::FailedPreconditionError(absl::StrCat("cannot write ", path.string()));
    fs::last_write_time(path, mtime, error);
    if (error) {
      return absl::FailedPreconditionError(
          absl::StrCat("cannot set the mtime of ", path.string(), ": ", error.message()));
    }
  }
  return absl::OkStatus();
}

// Points the symlink <dir>/current at <dir>/<generation>. rename() replaces it in one step: a
// path through it resolves to the old generation or to the new one, never to a missing file.
absl::Status PointCurrentAt(const fs::path& dir, const fs::path& generation) {
  const fs::path link = dir / "next";
  std::error_code error;
  fs::remove(link, error);
  fs::create_directory_symlink(generation, link, error);
  if (!error) fs::rename(link, dir / "current", error);
  if (error) {
    return absl::FailedPreconditionError(absl::StrCat("cannot point ", (dir / "current").string(),
                                                      " at ", generation.string(), ": ",
                                                      error.message()));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<ReloadableServerTls::Pem> ReloadableServerTls::Read(const ServerTlsOptions& tls) {
  Pem pem;
  absl::StatusOr<std::string> chain = ReadPemFile(tls.cert_file, "--tls-cert", true);
  if (!chain.ok()) return chain.status();
  absl::StatusOr<std::string> key = ReadPemFile(tls.key_file, "--tls-key", false);
  if (!key.ok()) return key.status();
  if (!KeyMatchesCertificate(*chain, *key)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--tls-key file ", tls.key_file, " is not the key of --tls-cert file ", tls.cert_file));
  }
  pem.chain = *std::move(chain);
  pem.key = *std::move(key);
  if (!tls.client_ca_file.empty()) {
    absl::StatusOr<std::string> roots = ReadPemFile(tls.client_ca_file, "--tls-client-ca", true);
    if (!roots.ok()) return roots.status();
    pem.client_ca = *std::move(roots);
  }
  return pem;
}

absl::StatusOr<std::unique_ptr<ReloadableServerTls>> ReloadableServerTls::Start(
    const ServerTlsOptions& tls) {
  absl::StatusOr<Pem> pem = Read(tls);
  if (!pem.ok()) return pem.status();
  std::error_code error;
  const fs::path temp = fs::temp_directory_path(error);
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("no temporary directory for the TLS files: ", error.message()));
  }
  RemoveAbandonedDirs(temp);
  absl::StatusOr<std::pair<int, fs::path>> locked = MakeLockedDir(temp);
  if (!locked.ok()) return locked.status();
  auto server_tls = std::unique_ptr<ReloadableServerTls>(
      new ReloadableServerTls(tls, locked->second, locked->first));
  {
    std::lock_guard<std::mutex> lock(server_tls->mutex_);
    if (absl::Status published = server_tls->Publish(*pem); !published.ok()) return published;
  }
  // The watcher reads the files once here, before the first handshake can happen.
  namespace gx = grpc::experimental;
  const fs::path current = server_tls->dir_ / "current";
  auto provider = std::make_shared<gx::FileWatcherCertificateProvider>(
      (current / kKeyName).string(), (current / kChainName).string(),
      tls.client_ca_file.empty() ? std::string() : (current / kClientCaName).string(),
      kTlsRefreshSeconds);
  gx::TlsServerCredentialsOptions options(provider);
  options.watch_identity_key_cert_pairs();
  if (tls.client_ca_file.empty()) {
    options.set_cert_request_type(GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
  } else {
    options.watch_root_certs();
    options.set_cert_request_type(GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  }
  server_tls->credentials_ = gx::TlsServerCredentials(options);
  return server_tls;
}

ReloadableServerTls::ReloadableServerTls(ServerTlsOptions tls, fs::path dir, int lock_fd)
    : tls_(std::move(tls)), dir_(std::move(dir)), lock_fd_(lock_fd) {}

ReloadableServerTls::~ReloadableServerTls() {
  // The watcher's last reference (and its thread) goes with the credentials, when the server
  // holds none any more; the files go after.
  credentials_.reset();
  std::error_code ignored;
  fs::remove_all(dir_, ignored);
  close(lock_fd_);
}

absl::Status ReloadableServerTls::Reload() {
  absl::StatusOr<Pem> pem = Read(tls_);
  if (!pem.ok()) return pem.status();
  std::lock_guard<std::mutex> lock(mutex_);
  return Publish(*pem);
}

absl::Status ReloadableServerTls::Publish(const Pem& pem) {
  const int next = generation_ + 1;
  const fs::path next_dir = GenerationDir(dir_, next);
  // gRPC reads the key and the chain again when either's mtime (in whole seconds) changed while
  // it read them; each generation is stamped at least a second after the last one, so a read
  // that straddles the swap always shows up as a change.
  const auto now = fs::file_time_type::clock::now();
  const auto stamp =
      generation_ == 0 ? now : std::max(now, last_written_ + std::chrono::seconds(1));
  std::vector<std::pair<const char*, const std::string*>> files = {{kKeyName, &pem.key},
                                                                   {kChainName, &pem.chain}};
  if (!pem.client_ca.empty()) files.emplace_back(kClientCaName, &pem.client_ca);
  absl::Status published = WriteGeneration(next_dir, files, stamp);
  if (published.ok()) published = PointCurrentAt(dir_, next_dir.filename());
  std::error_code ignored;
  if (!published.ok()) {
    fs::remove_all(next_dir, ignored);
    return published;
  }
  // The generation just replaced may still be read by a pass that resolved the symlink before
  // the swap; the one before it by nobody.
  fs::remove_all(GenerationDir(dir_, next - 2), ignored);
  generation_ = next;
  last_written_ = stamp;
  return absl::OkStatus();
}

}  // namespace inscribe::server
