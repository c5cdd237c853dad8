#include "bearer_auth.h"

#include <openssl/crypto.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "grpcpp/server_context.h"

namespace inscribe::server {
namespace {

// A token file is a handful of lines; anything this large is the wrong file.
constexpr std::size_t kMaxTokenFileBytes = std::size_t{1} << 20;

constexpr absl::string_view kScheme = "Bearer";

}  // namespace

absl::StatusOr<BearerAuthenticator> BearerAuthenticator::FromFile(const std::string& path) {
  absl::StatusOr<Digests> digests = ReadFile(path);
  if (!digests.ok()) return digests.status();
  return BearerAuthenticator(path, *std::move(digests));
}

absl::StatusOr<BearerAuthenticator> BearerAuthenticator::FromText(absl::string_view text,
                                                                  absl::string_view source) {
  absl::StatusOr<Digests> digests = Parse(text, source);
  if (!digests.ok()) return digests.status();
  return BearerAuthenticator(std::string(), *std::move(digests));
}

absl::Status BearerAuthenticator::Reload() {
  if (path_.empty()) {
    return absl::FailedPreconditionError("these bearer tokens were not read from a file");
  }
  absl::StatusOr<Digests> digests = ReadFile(path_);
  if (!digests.ok()) return digests.status();
  std::atomic_store(&digests_, std::make_shared<const Digests>(*std::move(digests)));
  return absl::OkStatus();
}

std::shared_ptr<const BearerAuthenticator::Digests> BearerAuthenticator::Accepted() const {
  return std::atomic_load(&digests_);
}

absl::StatusOr<BearerAuthenticator::Digests> BearerAuthenticator::ReadFile(
    const std::string& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::FailedPreconditionError(absl::StrCat("cannot read --auth-tokens file ", path, ": ",
                                                      errno != 0 ? std::strerror(errno) : "?"));
  }
  std::string text;
  char buffer[4096];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxTokenFileBytes) {
      return absl::InvalidArgumentError(
          absl::StrCat("--auth-tokens file ", path, " is over 1 MiB; is it the right file?"));
    }
  }
  if (in.bad()) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot read --auth-tokens file ", path, " (a directory?)"));
  }
  return Parse(text, path);
}

absl::StatusOr<BearerAuthenticator::Digests> BearerAuthenticator::Parse(absl::string_view text,
                                                                        absl::string_view source) {
  Digests digests;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || absl::StartsWith(line, "#")) continue;
    // The messages say where and what is wrong, never the token itself: logs are read by
    // more people than the token file.
    const std::string where = absl::StrCat("--auth-tokens file ", source, " line ", line_number);
    for (char c : line) {
      if (c < 0x21 || c > 0x7e) {
        return absl::InvalidArgumentError(absl::StrCat(
            where, ": a token is printable ASCII without spaces; this one has other characters"));
      }
    }
    if (line.size() < kMinBearerTokenLength || line.size() > kMaxBearerTokenLength) {
      return absl::InvalidArgumentError(absl::StrCat(
          where, ": the token has ", line.size(), " characters; ", kMinBearerTokenLength, " to ",
          kMaxBearerTokenLength, " are accepted (e.g. `openssl rand -hex 32`)"));
    }
    digests.push_back(Sha256(line));
  }
  if (digests.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--auth-tokens file ", source, " holds no token (only blank lines and # comments)"));
  }
  return digests;
}

absl::Status BearerAuthenticator::Check(const grpc::ServerContextBase& context) const {
  // gRPC lower-cases metadata keys on arrival.
  const auto range = context.client_metadata().equal_range("authorization");
  if (range.first == range.second) return CheckHeader(std::nullopt);
  if (std::next(range.first) != range.second) {
    return absl::UnauthenticatedError(
        "missing bearer token: the call has several authorization headers; send one");
  }
  const grpc::string_ref value = range.first->second;
  return CheckHeader(absl::string_view(value.data(), value.size()));
}

absl::Status BearerAuthenticator::CheckHeader(
    std::optional<absl::string_view> authorization) const {
  if (!authorization.has_value()) {
    return absl::UnauthenticatedError(
        "missing bearer token: this server requires \"authorization: Bearer <token>\" "
        "(inscribe --token-file)");
  }
  const absl::string_view value = absl::StripAsciiWhitespace(*authorization);
  // RFC 6750: "Bearer" 1*SP token; the scheme is case-insensitive (RFC 7235).
  if (value.size() <= kScheme.size() ||
      !absl::EqualsIgnoreCase(value.substr(0, kScheme.size()), kScheme) ||
      !absl::ascii_isblank(static_cast<unsigned char>(value[kScheme.size()]))) {
    return absl::UnauthenticatedError(
        "missing bearer token: the authorization header is not \"Bearer <token>\"");
  }
  const Digest presented = Sha256(absl::StripLeadingAsciiWhitespace(value.substr(kScheme.size())));
  // Comparing digests rather than the tokens makes every comparison 32 bytes whatever the
  // lengths; going through all of them makes the time independent of which one matched.
  const std::shared_ptr<const Digests> accepted_now = Accepted();
  int matched = 0;
  for (const Digest& accepted : *accepted_now) {
    matched |=
        static_cast<int>(CRYPTO_memcmp(presented.data(), accepted.data(), presented.size()) == 0);
  }
  if (matched == 0) return absl::UnauthenticatedError("invalid bearer token");
  return absl::OkStatus();
}

}  // namespace inscribe::server
