#include "stats_command.h"

#include <cstdint>
#include <iostream>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "command_outcome.h"
#include "nlohmann/json.hpp"
#include "remote_options.h"
#include "service_session.h"

namespace inscribe::cli {
namespace {

struct StatsCliOptions {
  bool json = false;
  RemoteOptions remote;
};

// Every counter of CacheStatsResponse, in its order, with its JSON name and what it counts.
std::vector<std::pair<const char*, std::int64_t>> Counters(const client::ServerCacheStats& s) {
  return {{"entries", s.entries},
          {"bytes", s.bytes},
          {"memory_hits", s.memory_hits},
          {"disk_hits", s.disk_hits},
          {"hits", s.hits},
          {"misses", s.misses},
          {"computations", s.computations},
          {"joined", s.joined},
          {"evictions", s.evictions},
          {"disk_entries", s.disk_entries},
          {"disk_bytes", s.disk_bytes},
          {"disk_errors", s.disk_errors},
          {"shared_hits", s.shared_hits},
          {"shared_misses", s.shared_misses},
          {"shared_errors", s.shared_errors},
          {"shared_writes", s.shared_writes},
          {"shared_write_errors", s.shared_write_errors},
          {"shared_skipped", s.shared_skipped},
          {"shared_corrupt", s.shared_corrupt},
          {"shared_available", s.shared_available},
          {"disk_write_errors", s.disk_write_errors},
          {"disk_writes_skipped", s.disk_writes_skipped},
          {"disk_available", s.disk_available},
          {"disk_bytes_limit", s.disk_bytes_limit},
          {"disk_evictions", s.disk_evictions},
          {"disk_evicted_bytes", s.disk_evicted_bytes},
          {"disk_writes_too_large", s.disk_writes_too_large}};
}

absl::Status RunStats(const StatsCliOptions& options) {
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  absl::StatusOr<client::ServerCacheStats> stats = (*session)->client().CacheStats();
  if (!stats.ok()) return stats.status();
  if (options.json) {
    nlohmann::json j;
    j["server"] = options.remote.server;
    for (const auto& [name, value] : Counters(*stats)) j[name] = value;
    std::cout << j.dump() << "\n";
    return absl::OkStatus();
  }
  std::cout << absl::StrFormat("%-20s %s\n", "server", options.remote.server);
  for (const auto& [name, value] : Counters(*stats)) {
    std::cout << absl::StrFormat("%-20s %d\n", name, value);
  }
  return absl::OkStatus();
}

}  // namespace

void AddStatsCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<StatsCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "stats",
      "The server's result-cache counters: entries and bytes in memory and on disk, hits "
      "(memory, disk), misses, computations, joined (waited for an identical request), "
      "evictions, disk errors, the disk bound and its evictions, and the shared Redis tier's "
      "hits, misses, errors, writes, skips (while it is down), corrupt values and "
      "availability");
  cmd->add_flag("--json", options->json, "Print one JSON object on stdout");
  AddRemoteOptions(cmd, &options->remote, 60.0, /*server_required=*/true);
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunStats(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
