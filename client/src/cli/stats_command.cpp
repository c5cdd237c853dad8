#include "stats_command.h"

#include <iostream>
#include <memory>

#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/wire/cache_stats.h"
#include "nlohmann/json.hpp"
#include "remote_options.h"
#include "service_session.h"

namespace inscribe::cli {
namespace {

struct StatsCliOptions {
  bool json = false;
  RemoteOptions remote;
};

absl::Status RunStats(const StatsCliOptions& options) {
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  absl::StatusOr<client::ServerCacheStats> stats = (*session)->client().CacheStats();
  if (!stats.ok()) return stats.status();
  if (options.json) {
    nlohmann::json j;
    j["server"] = options.remote.server;
    for (const wire::CacheStatsCounter& counter : wire::kCacheStatsCounters) {
      j[counter.name] = (*stats).*counter.value;
    }
    std::cout << j.dump() << "\n";
    return absl::OkStatus();
  }
  std::cout << absl::StrFormat("%-20s %s\n", "server", options.remote.server);
  for (const wire::CacheStatsCounter& counter : wire::kCacheStatsCounters) {
    std::cout << absl::StrFormat("%-20s %d\n", counter.name, (*stats).*counter.value);
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
  SetExitStatusHelp(cmd, "");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunStats(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
