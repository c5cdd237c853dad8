// inscribed: the inscribe gRPC server. Logs go to stderr as key=value pairs; the one plain line
// "inscribed listening on HOST:PORT" says the server is ready (scripts and tests read it).
// SIGTERM/SIGINT drain and stop it; SIGHUP reloads the token and TLS files.
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "CLI/CLI.hpp"
#include "absl/status/status.h"
#include "inscribe/server/inscribe_server.h"
#include "spdlog/fmt/fmt.h"
#include "spdlog/sinks/stdout_sinks.h"
#include "spdlog/spdlog.h"

namespace {

using inscribe::server::CallRecord;
using inscribe::server::InscribeServer;
using inscribe::server::ServerOptions;

void LogCall(const CallRecord& call) {
  const auto level = call.status.ok() ? spdlog::level::info : spdlog::level::warn;
  spdlog::log(level,
              "event=call method={} peer={} code={} triangles={} memory_mb={:.1f} queued_ms={:.3f}"
              " run_ms={:.3f} frames={} inline_frames={} message=\"{}\"",
              call.method, call.peer, absl::StatusCodeToString(call.status.code()), call.triangles,
              call.memory_bytes / 1048576.0, 1e3 * call.queued_seconds, 1e3 * call.run_seconds,
              call.frames, call.inline_frames, std::string(call.status.message()));
}

// The shared Redis tier going down (lookups then skip it and compute or use the local tiers)
// or coming back; the cache retries on its own.
void LogSharedTier(const inscribe::server::SharedTierEvent& event) {
  if (event.available) {
    spdlog::info("event=redis_up");
  } else {
    spdlog::warn("event=redis_down error=\"{}\" retry_ms={}", std::string(event.error.message()),
                 event.retry_after.count());
  }
}

// The disk cache tier off from the start (bad --cache-dir), stopped by a write failure (full,
// read-only) or writing again. Calls go on either way, served from memory or computed.
void LogDiskTier(const inscribe::server::DiskTierEvent& event) {
  using Kind = inscribe::server::DiskTierEvent::Kind;
  switch (event.kind) {
    case Kind::kOff:
      spdlog::warn(
          "event=disk_cache_off dir=\"{}\" reason=\"{}\" message=\"running with the "
          "memory cache only\"",
          event.dir, std::string(event.error.message()));
      break;
    case Kind::kDegraded:
      spdlog::warn("event=disk_cache_degraded dir=\"{}\" reason=\"{}\" retry_ms={}", event.dir,
                   std::string(event.error.message()), event.retry_after.count());
      break;
    case Kind::kRestored:
      spdlog::info("event=disk_cache_restored dir=\"{}\"", event.dir);
      break;
  }
}

// One line per SIGHUP: for the token file and the TLS files, "reloaded", "off" (not configured)
// or "kept" with the error that made the server keep the ones it had; an error level when
// either was kept.
void LogReload(const inscribe::server::ReloadResult& result) {
  std::string line = "event=reload signal=SIGHUP";
  bool kept = false;
  for (const auto& [name, status] :
       {std::pair{"tokens", &result.tokens}, std::pair{"tls", &result.tls}}) {
    if (!status->has_value()) {
      line += fmt::format(" {}=off", name);
    } else if ((*status)->ok()) {
      line += fmt::format(" {}=reloaded", name);
    } else {
      line +=
          fmt::format(" {}=kept {}_error=\"{}\"", name, name, std::string((*status)->message()));
      kept = true;
    }
  }
  spdlog::log(kept ? spdlog::level::err : spdlog::level::info, "{}", line);
}

// Whether HOST of --listen HOST:PORT is a loopback address, where plaintext cannot be sniffed
// from another machine. 0.0.0.0 and [::] listen on every interface: not loopback.
bool IsLoopbackListen(const std::string& listen) {
  std::string host = listen.substr(0, listen.rfind(':'));
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Block the handled signals before any thread exists so every thread (gRPC's, TBB's)
  // inherits the mask; this thread then takes them synchronously with sigwait, outside signal
  // context, where reloading and stopping may take locks and do I/O.
  sigset_t handled_signals;
  sigemptyset(&handled_signals);
  sigaddset(&handled_signals, SIGINT);
  sigaddset(&handled_signals, SIGTERM);
  sigaddset(&handled_signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &handled_signals, nullptr);
  // A cache file growing past RLIMIT_FSIZE must fail its write with EFBIG (the disk tier then
  // stops writing) rather than kill the server with SIGXFSZ.
  signal(SIGXFSZ, SIG_IGN);

  ServerOptions options;
  double shutdown_grace_seconds = 10.0;
  std::string log_level = "info";
  CLI::App app{"inscribed: serves inscribe.v1.Inscribe over gRPC"};
  app.add_option("--listen", options.listen, "HOST:PORT to bind; port 0 picks a free port")
      ->capture_default_str();
  app.add_option("--jobs", options.jobs, "requests computed at once; 0 = one per hardware thread")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--max-queue", options.max_queue,
                 "requests queued or running at once; more get RESOURCE_EXHAUSTED")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 20))
      ->capture_default_str();
  app.add_option("--max-message-bytes", options.max_message_bytes, "largest request, in bytes")
      ->check(CLI::Range(1, INT_MAX))
      ->capture_default_str();
  app.add_option("--max-triangles", options.limits.max_triangles, "triangles in one mesh")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{INT_MAX}))
      ->capture_default_str();
  app.add_option("--max-voxels", options.limits.max_voxels, "voxels in one generation grid")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 40))
      ->capture_default_str();
  app.add_option("--max-spheres", options.limits.max_spheres, "sphere budget of one Generate call")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 30))
      ->capture_default_str();
  app.add_option("--max-poses", options.limits.max_poses, "pose pairs in one Distance call")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 30))
      ->capture_default_str();
  app.add_option("--max-scene-objects", options.limits.max_scene_objects,
                 "objects in one SceneStream's scene")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 30))
      ->capture_default_str();
  app.add_option("--max-scene-pairs", options.limits.max_scene_pairs,
                 "close pairs in one SceneStream reply (the largest max_pairs)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 30))
      ->capture_default_str();
  app.add_option("--max-scene-ignored", options.limits.max_scene_ignored,
                 "ignored pairs one SceneStream may send")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 30))
      ->capture_default_str();
  app.add_option("--memory-budget", options.limits.memory_budget_bytes,
                 "bytes of working memory the calls in flight may need together, by estimate; "
                 "calls that do not fit get RESOURCE_EXHAUSTED; 0 = unlimited. Not counting "
                 "--cache-memory-bytes, the baseline and messages in flight")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 50))
      ->capture_default_str();
  app.add_option("--cache-dir", options.cache.disk_dir,
                 "directory of the on-disk result cache (created if missing); empty = memory only")
      ->capture_default_str();
  // Validated by ResultCache::Open (a negative bound fails the start, naming the flag).
  app.add_option("--cache-disk-bytes", options.cache.disk_bytes,
                 "bytes of results kept on disk in --cache-dir (least recently used deleted "
                 "first); 0 = unbounded")
      ->capture_default_str();
  app.add_option("--cache-memory-bytes", options.cache.memory_bytes,
                 "bytes of results kept in memory (least recently used dropped first)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 50))
      ->capture_default_str();
  app.add_option("--redis", options.cache.redis_url,
                 "Redis shared by replicas as a third cache tier, "
                 "redis://[:PASSWORD@]HOST[:PORT][/DB]; empty = none")
      ->capture_default_str();
  app.add_option("--redis-timeout-ms", options.cache.redis_timeout_ms,
                 "longest wait for one Redis connect, read or write; Redis slower than this is "
                 "skipped and retried later")
      ->check(CLI::Range(1, 60'000))
      ->capture_default_str();
  app.add_option("--tls-cert", options.tls.cert_file,
                 "PEM certificate chain of the server; with --tls-key serves TLS instead of "
                 "plaintext. The TLS files are read again on SIGHUP")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", options.tls.key_file, "PEM private key of --tls-cert")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-client-ca", options.tls.client_ca_file,
                 "PEM CA certificates: clients must present a certificate signed by one "
                 "(mutual TLS)")
      ->check(CLI::ExistingFile);
  app.add_option("--auth-tokens", options.auth_tokens_file,
                 "file of accepted bearer tokens, one per line; calls without one get "
                 "UNAUTHENTICATED. Read again on SIGHUP")
      ->check(CLI::ExistingFile);
  app.add_option("--metrics-listen", options.metrics_listen,
                 "HOST:PORT of the Prometheus endpoint (/metrics); empty = none")
      ->capture_default_str();
  app.add_option("--shutdown-grace", shutdown_grace_seconds,
                 "seconds calls in progress get to finish after SIGTERM/SIGINT")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  auto logger = spdlog::stderr_logger_mt("inscribed");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e%z level=%l %v");
  logger->set_level(spdlog::level::from_str(log_level));
  logger->flush_on(spdlog::level::info);
  spdlog::set_default_logger(logger);
  options.on_call = LogCall;
  options.cache.on_shared_tier_event = LogSharedTier;
  options.cache.on_disk_tier_event = LogDiskTier;

  absl::StatusOr<std::unique_ptr<InscribeServer>> server = InscribeServer::Start(options);
  if (!server.ok()) {
    spdlog::critical("event=start_failed listen={} error=\"{}\"", options.listen,
                     std::string(server.status().message()));
    return 1;
  }
  spdlog::info(
      "event=serving address={} jobs={} max_queue={} max_message_bytes={} max_triangles={} "
      "max_voxels={} max_spheres={} max_poses={} max_scene_objects={} max_scene_pairs={} "
      "max_scene_ignored={} memory_budget={} cache_dir=\"{}\" "
      "cache_disk_bytes={} cache_memory_bytes={} "
      "redis=\"{}\" tls={} auth={} metrics_port={}",
      (*server)->address(), (*server)->jobs(), options.max_queue, options.max_message_bytes,
      options.limits.max_triangles, options.limits.max_voxels, options.limits.max_spheres,
      options.limits.max_poses, options.limits.max_scene_objects, options.limits.max_scene_pairs,
      options.limits.max_scene_ignored, options.limits.memory_budget_bytes, options.cache.disk_dir,
      options.cache.disk_bytes, options.cache.memory_bytes,
      inscribe::server::RedactRedisUrl(options.cache.redis_url), options.tls.enabled(),
      !options.auth_tokens_file.empty(), (*server)->metrics_port());
  if (!options.auth_tokens_file.empty() && !options.tls.enabled() &&
      !IsLoopbackListen(options.listen)) {
    spdlog::warn(
        "event=plaintext_tokens listen={} message=\"bearer tokens are checked on a plaintext "
        "port that is not loopback: anyone on the path can read and reuse them; add --tls-cert "
        "and --tls-key\"",
        options.listen);
  }
  std::fprintf(stderr, "inscribed listening on %s\n", (*server)->address().c_str());
  std::fflush(stderr);

  int signal_number = 0;
  for (;;) {
    if (sigwait(&handled_signals, &signal_number) != 0) continue;
    if (signal_number != SIGHUP) break;
    LogReload((*server)->Reload());
  }
  spdlog::info("event=draining signal={} grace_s={}",
               signal_number == SIGTERM ? "SIGTERM" : "SIGINT", shutdown_grace_seconds);
  const auto deadline = std::chrono::system_clock::now() +
                        std::chrono::duration_cast<std::chrono::system_clock::duration>(
                            std::chrono::duration<double>(shutdown_grace_seconds));
  (*server)->Shutdown(deadline);
  server->reset();
  spdlog::info("event=stopped");
  return 0;
}
