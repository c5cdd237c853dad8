// Bearer-token authentication of inscribe.v1 calls (inscribed --auth-tokens). Private to the
// server: InscribeServer::Start loads the file and hands the service a CallAuthenticator that
// calls Check; InscribeServer::Reload (inscribed on SIGHUP) calls Reload.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/base/sha256.h"

namespace grpc {
class ServerContextBase;
}  // namespace grpc

namespace inscribe::server {

// Tokens shorter than this are refused when the file is loaded: 16 printable characters are at
// least ~90 bits when random (e.g. `openssl rand -hex 16` gives 32), which online guessing
// cannot reach; shorter ones are typos or placeholders.
inline constexpr std::size_t kMinBearerTokenLength = 16;
// Longer ones are refused too: a header line that long is a mistake (gRPC's default limit for
// all metadata of a call is 8 KiB).
inline constexpr std::size_t kMaxBearerTokenLength = 4096;

// The accepted tokens, kept only as SHA-256 digests. The set is replaced whole by Reload, never
// changed in place. Check and Reload are thread-safe; Check costs one SHA-256 of the presented
// token plus one 32-byte comparison per accepted token (microseconds for a handful of tokens),
// on the calling gRPC thread, and never waits for a Reload.
class BearerAuthenticator {
 public:
  // Reads `path`: one token per line; surrounding whitespace (and a CR) is dropped, blank lines
  // and lines starting with '#' are ignored. Each token is printable ASCII without spaces
  // (0x21-0x7E), kMinBearerTokenLength to kMaxBearerTokenLength characters. Errors name the
  // file (and the line), never a token: FAILED_PRECONDITION when the file cannot be read,
  // INVALID_ARGUMENT when it is over 1 MiB, a token is malformed, or it holds no token.
  static absl::StatusOr<BearerAuthenticator> FromFile(const std::string& path);

  // The same rules on the text of a token file; `source` names it in errors.
  static absl::StatusOr<BearerAuthenticator> FromText(absl::string_view text,
                                                      absl::string_view source);

  // Reads the file given to FromFile again, by the same rules and with the same errors. On
  // success its tokens replace the accepted ones for every later Check (calls already admitted
  // go on); on any error the accepted tokens stay as they were. FAILED_PRECONDITION for one
  // made by FromText: there is no file.
  absl::Status Reload();

  // OK when the call's "authorization" metadata is "Bearer <token>" (the scheme in any case,
  // then spaces) with an accepted token; else UNAUTHENTICATED, "missing bearer token" (no
  // header, several, or another scheme) or "invalid bearer token". Messages never include what
  // the caller sent. Every accepted digest is compared (CRYPTO_memcmp, no early exit), so the
  // time taken does not depend on which token, or how much of one, matched.
  absl::Status Check(const grpc::ServerContextBase& context) const;

  // Check on the header's value; nullopt = no header.
  absl::Status CheckHeader(std::optional<absl::string_view> authorization) const;

  // Tokens accepted now.
  std::size_t token_count() const { return Accepted()->size(); }

 private:
  using Digest = Sha256Digest;
  using Digests = std::vector<Digest>;

  // The one reader and the one parser of token files; FromFile, FromText and Reload use them.
  static absl::StatusOr<Digests> ReadFile(const std::string& path);
  static absl::StatusOr<Digests> Parse(absl::string_view text, absl::string_view source);

  BearerAuthenticator(std::string path, Digests digests)
      : path_(std::move(path)), digests_(std::make_shared<const Digests>(std::move(digests))) {}

  // The set accepted now; a Reload after this returns does not change it.
  std::shared_ptr<const Digests> Accepted() const;

  std::string path_;  // FromFile's file; empty for FromText
  // Read with std::atomic_load and replaced with std::atomic_store (C++17's atomic shared_ptr):
  // a Check uses one whole set, old or new.
  std::shared_ptr<const Digests> digests_;
};

}  // namespace inscribe::server
