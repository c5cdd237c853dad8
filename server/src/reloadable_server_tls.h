// The listening port's TLS (inscribed --tls-cert, --tls-key, --tls-client-ca) with files that
// can be read again while serving. Private to the server: InscribeServer::Start makes one and
// listens with its credentials; InscribeServer::Reload (inscribed on SIGHUP) calls Reload.
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/server/inscribe_server.h"

namespace grpc {
class ServerCredentials;
}  // namespace grpc

namespace inscribe::server {

// How often gRPC re-reads the published copies, in seconds: a reload reaches new handshakes
// within this long. Each pass reads three files of a few KiB.
inline constexpr unsigned kTlsRefreshSeconds = 1;

// gRPC 1.51's TLS credentials take their certificates from a provider, and the only provider
// in its public API whose data can change after the server starts is its
// FileWatcherCertificateProvider, which re-reads files every kTlsRefreshSeconds. It watches copies,
// never the operator's files: the copies are written only after the new files have been checked
// (PEM parses, the key matches the certificate), so a half-written or mismatched pair never reaches
// a handshake and the old pair keeps serving. The copies live in a private directory (mode 0700,
// under the temporary directory) removed by the destructor: <dir>/current is a symlink to the
// generation being served, swapped with one rename so that the key and the certificate change
// together. Connections already open keep the certificates they were made with. Thread-safe.
class ReloadableServerTls {
 public:
  // Reads and checks the files of `tls` (which must be enabled) and publishes them. Errors name
  // the flag and the file: FAILED_PRECONDITION when one cannot be read (or the private directory
  // cannot be made), INVALID_ARGUMENT when it holds no PEM certificate or unencrypted private
  // key, or when the key is not the certificate's.
  static absl::StatusOr<std::unique_ptr<ReloadableServerTls>> Start(const ServerTlsOptions& tls);

  // Removes the private directory. The credentials (and the connections made with them) must
  // be gone first: gRPC would find no files on its next pass.
  ~ReloadableServerTls();
  ReloadableServerTls(const ReloadableServerTls&) = delete;
  ReloadableServerTls& operator=(const ReloadableServerTls&) = delete;

  // TLS server credentials reading the published files; a client certificate signed by
  // --tls-client-ca is required when that file was given.
  std::shared_ptr<grpc::ServerCredentials> credentials() const { return credentials_; }

  // Reads the same three paths again with Start's checks and errors. OK: the new files are
  // published and new handshakes use them within kTlsRefreshSeconds. Any error: nothing is
  // published, the files served before stay.
  absl::Status Reload();

 private:
  ReloadableServerTls(ServerTlsOptions tls, std::filesystem::path dir, int lock_fd);

  struct Pem;
  // Start's and Reload's one reading of the files, with every check.
  static absl::StatusOr<Pem> Read(const ServerTlsOptions& tls);
  // Writes `pem` as the next generation and points <dir>/current at it.
  absl::Status Publish(const Pem& pem);

  const ServerTlsOptions tls_;
  const std::filesystem::path dir_;
  const int lock_fd_;  // flock held on <dir>/lock while the directory is in use
  std::shared_ptr<grpc::ServerCredentials> credentials_;

  std::mutex mutex_;    // one Publish at a time
  int generation_ = 0;  // guarded by mutex_; the generation <dir>/current names
  std::filesystem::file_time_type last_written_;  // guarded by mutex_
};

}  // namespace inscribe::server
