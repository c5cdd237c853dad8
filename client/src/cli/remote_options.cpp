#include "remote_options.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/strings/ascii.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "inscribe/client/connection.h"

namespace inscribe::cli {

void AddRemoteOptions(CLI::App* cmd, RemoteOptions* options, double default_timeout_seconds,
                      bool server_required) {
  options->timeout_seconds = default_timeout_seconds;
  CLI::Option* server = cmd->add_option(
      "--server", options->server,
      "Run on the inscribed server at HOST:PORT (HOST alone: port 50051) instead of in this "
      "process (the output is the "
      "same); several replicas separated by commas: each mesh's calls go to one of them, "
      "failing over to the next when it is down");
  if (server_required) server->required();
  cmd->add_option("--timeout", options->timeout_seconds,
                  "With --server: seconds a call may take, retries included (exit 69 when "
                  "exceeded or the server cannot be reached)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--tls", options->tls,
                "With --server: TLS, verifying the server against the system's CA certificates");
  cmd->add_option("--tls-ca", options->tls_files.ca_file,
                  "With --server: TLS, verifying the server against these PEM CA certificates")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-cert", options->tls_files.cert_file,
                  "With --server: TLS client certificate (PEM) for servers that verify clients")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-key", options->tls_files.key_file, "Private key (PEM) of --tls-cert")
      ->check(CLI::ExistingFile);
  cmd->add_option("--token-file", options->token_file,
                  "With --server: file whose first line is the bearer token to send")
      ->check(CLI::ExistingFile);
}

std::vector<std::string> RemoteOptions::servers() const {
  std::vector<std::string> out;
  for (absl::string_view part : absl::StrSplit(server, ',', absl::SkipWhitespace())) {
    out.emplace_back(absl::StripAsciiWhitespace(part));
  }
  return out;
}

absl::StatusOr<client::ConnectionOptions> ConnectionOptionsFor(const RemoteOptions& options) {
  client::ConnectionOptions connection_options;
  if (options.tls_enabled()) {
    absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
        client::MakeTlsCredentials(options.tls_files);
    if (!credentials.ok()) return credentials.status();
    connection_options.credentials = *std::move(credentials);
  }
  if (!options.token_file.empty()) {
    absl::StatusOr<std::string> token = client::ReadBearerToken(options.token_file);
    if (!token.ok()) return token.status();
    connection_options.bearer_token = *std::move(token);
  }
  return connection_options;
}

}  // namespace inscribe::cli
