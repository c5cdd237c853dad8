// The result cache's shared tier: a Redis server several replicas read and write, through
// hiredis (blocking calls with timeouts on a small pool of connections). Values are framed
// entries (cache_entry_format.h) under "inscribe:<cache key>". Redis that is unreachable, slow
// or answering errors never fails a lookup: the tier reports it as an error, marks itself down
// and is skipped for a backoff (1 s, doubling to 30 s), after which one call probes it again.
// Private to the server library; ResultCache documents the behaviour.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/server/result_cache.h"

struct redisContext;  // hiredis stays in the .cpp

namespace inscribe::server {

// A parsed "redis://[[USER]:PASSWORD@]HOST[:PORT][/DB]".
struct RedisAddress {
  std::string host;  // a name or an address; IPv6 in brackets in the URL, bare here
  int port = 6379;
  std::string user;      // empty: AUTH with the password only (the default user)
  std::string password;  // empty: no AUTH
  int db = 0;            // SELECTed on connect when not 0
};

// INVALID_ARGUMENT naming the part of the URL that is wrong; messages show the URL redacted.
absl::StatusOr<RedisAddress> ParseRedisUrl(absl::string_view url);

// Thread-safe.
class RedisTier {
 public:
  struct Counts {
    std::int64_t misses = 0;  // GETs answered "no such key"
    std::int64_t errors =
        0;  // GETs that failed (the lookup went on as a miss), and the check at Create
    std::int64_t writes = 0;        // SETs done
    std::int64_t write_errors = 0;  // SETs that failed
    std::int64_t skipped = 0;       // GETs and SETs not tried while marked down
    std::int64_t corrupt = 0;       // values that failed their checks, deleted
    bool available = false;         // not marked down
  };

  enum class Outcome { kHit, kMiss, kError, kSkipped, kCorrupt };
  struct ReadResult {
    Outcome outcome = Outcome::kMiss;
    std::string payload;  // kHit: the verified payload
  };

  // Parses `url` (INVALID_ARGUMENT) and connects once: an unreachable Redis is not an error
  // here, the tier starts marked down (reported through `on_event`). `timeout_ms` bounds each
  // connect, read and write; `on_event` may be empty, is called on the calling thread with no
  // lock held, and must be cheap.
  static absl::StatusOr<std::unique_ptr<RedisTier>> Create(
      absl::string_view url, int timeout_ms, std::function<void(const SharedTierEvent&)> on_event);

  ~RedisTier();
  RedisTier(const RedisTier&) = delete;
  RedisTier& operator=(const RedisTier&) = delete;

  // GET and verify: one round trip plus the SHA-256 of the payload. A value failing its checks
  // is deleted (kCorrupt). At most about 4 x timeout_ms when Redis stalls (connect, AUTH,
  // SELECT, GET), no time at all while marked down.
  ReadResult Get(absl::string_view key);

  // Deletes the value of `key` as corrupt (e.g. it did not decode); counted.
  void DropCorrupt(absl::string_view key);

  // SET (overwriting: equal keys mean equal content, and a rewrite repairs a bad value).
  // Failures are counted, never reported.
  void Put(absl::string_view key, absl::string_view payload);

  Counts counts() const;

 private:
  class Connection;
  // Whether to try Redis now; `probe` says this call is the one retrying after a backoff.
  struct Attempt {
    bool allowed = false;
    bool probe = false;
  };

  RedisTier(RedisAddress address, int timeout_ms,
            std::function<void(const SharedTierEvent&)> on_event);
  Attempt Begin();
  void Succeeded(const Attempt& attempt);
  void Failed(const Attempt& attempt, const absl::Status& error);
  absl::StatusOr<std::unique_ptr<Connection>> Acquire();
  void Release(std::unique_ptr<Connection> connection);
  absl::StatusOr<std::unique_ptr<Connection>> Connect() const;
  std::string Where() const;  // "redis HOST:PORT", never the password

  const RedisAddress address_;
  const int timeout_ms_;
  const std::function<void(const SharedTierEvent&)> on_event_;

  // Guards the health state and the idle connections; never held during network IO.
  mutable std::mutex mutex_;
  bool available_ = true;
  bool probing_ = false;  // a probe is in progress while marked down
  std::chrono::milliseconds backoff_{0};
  std::chrono::steady_clock::time_point down_until_;
  std::vector<std::unique_ptr<Connection>> idle_;

  std::atomic<std::int64_t> misses_{0}, errors_{0}, writes_{0}, write_errors_{0}, skipped_{0},
      corrupt_{0};
};

}  // namespace inscribe::server
