#include "redis_tier.h"

#include <hiredis/hiredis.h>
#include <pthread.h>
#include <signal.h>
#include <sys/time.h>

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "cache_entry_format.h"

namespace inscribe::server {
namespace {

constexpr absl::string_view kScheme = "redis://";
constexpr absl::string_view kKeyPrefix = "inscribe:";
constexpr std::chrono::milliseconds kFirstBackoff{1000};
constexpr std::chrono::milliseconds kLongestBackoff{30'000};
// Idle connections kept for reuse; more are opened while more lookups run at once (each
// blocking call holds one), and closed when returned beyond this many.
constexpr std::size_t kMaxIdleConnections = 4;

struct ReplyDeleter {
  void operator()(redisReply* reply) const { freeReplyObject(reply); }
};
using Reply = std::unique_ptr<redisReply, ReplyDeleter>;

// hiredis writes with write(2), so a write to a connection Redis has closed raises SIGPIPE,
// whose default action ends the process. A library must not change the process's signal
// dispositions, so this blocks SIGPIPE on the calling thread for one command and discards one
// raised meanwhile (the write itself then fails with EPIPE, which hiredis reports). Costs a
// few system calls per command.
class SigpipeBlocked {
 public:
  SigpipeBlocked() {
    sigemptyset(&pipe_);
    sigaddset(&pipe_, SIGPIPE);
    sigset_t pending;
    sigpending(&pending);
    was_pending_ = sigismember(&pending, SIGPIPE) == 1;  // not ours to discard
    pthread_sigmask(SIG_BLOCK, &pipe_, &old_mask_);
  }
  ~SigpipeBlocked() {
    if (!was_pending_) {
      sigset_t pending;
      sigpending(&pending);
      if (sigismember(&pending, SIGPIPE) == 1) {
        const timespec now{0, 0};
        sigtimedwait(&pipe_, nullptr, &now);
      }
    }
    pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
  }
  SigpipeBlocked(const SigpipeBlocked&) = delete;
  SigpipeBlocked& operator=(const SigpipeBlocked&) = delete;

 private:
  sigset_t pipe_;
  sigset_t old_mask_;
  bool was_pending_ = false;
};

std::string RedisKey(absl::string_view key) { return absl::StrCat(kKeyPrefix, key); }

absl::Status BadUrl(absl::string_view url, absl::string_view why) {
  return absl::InvalidArgumentError(
      absl::StrCat("--redis ", RedactRedisUrl(url), ": ", why,
                   "; expected redis://[:PASSWORD@]HOST[:PORT][/DB]"));
}

}  // namespace

std::string RedactRedisUrl(absl::string_view url) {
  const std::size_t scheme_end = url.find("://");
  const std::size_t start = scheme_end == absl::string_view::npos ? 0 : scheme_end + 3;
  const std::size_t at = url.rfind('@');
  if (at == absl::string_view::npos || at < start) return std::string(url);
  const absl::string_view userinfo = url.substr(start, at - start);
  const std::size_t colon = userinfo.find(':');
  // "user@host" (no colon) is a password for Redis' AUTH too: hide it all.
  const absl::string_view user =
      colon == absl::string_view::npos ? absl::string_view() : userinfo.substr(0, colon);
  return absl::StrCat(url.substr(0, start), user, ":***", url.substr(at));
}

absl::StatusOr<RedisAddress> ParseRedisUrl(absl::string_view url) {
  if (url.substr(0, kScheme.size()) != kScheme) {
    return BadUrl(url, "the scheme must be redis:// (TLS rediss:// is not supported)");
  }
  absl::string_view rest = url.substr(kScheme.size());
  RedisAddress address;
  // The last '@' ends the user information, so a password may hold '@', ':' or '/'.
  if (const std::size_t at = rest.rfind('@'); at != absl::string_view::npos) {
    const absl::string_view userinfo = rest.substr(0, at);
    const std::size_t colon = userinfo.find(':');
    if (colon == absl::string_view::npos) {
      return BadUrl(url, "the user information must be :PASSWORD or USER:PASSWORD");
    }
    address.user = std::string(userinfo.substr(0, colon));
    address.password = std::string(userinfo.substr(colon + 1));
    if (address.password.empty()) return BadUrl(url, "the password after ':' is empty");
    rest.remove_prefix(at + 1);
  }
  absl::string_view host_port = rest;
  if (const std::size_t slash = rest.find('/'); slash != absl::string_view::npos) {
    host_port = rest.substr(0, slash);
    const absl::string_view db = rest.substr(slash + 1);
    if (!db.empty() && (!absl::SimpleAtoi(db, &address.db) || address.db < 0)) {
      return BadUrl(url, absl::StrCat("the database '", db, "' is not a number >= 0"));
    }
  }
  absl::string_view port;
  if (!host_port.empty() && host_port.front() == '[') {  // [IPv6]:PORT
    const std::size_t close = host_port.find(']');
    if (close == absl::string_view::npos) return BadUrl(url, "the host has '[' without ']'");
    address.host = std::string(host_port.substr(1, close - 1));
    const absl::string_view after = host_port.substr(close + 1);
    if (!after.empty() && after.front() != ':') {
      return BadUrl(url, "the host's ']' must be followed by :PORT or nothing");
    }
    if (!after.empty()) port = after.substr(1);
  } else if (const std::size_t colon = host_port.rfind(':'); colon != absl::string_view::npos) {
    address.host = std::string(host_port.substr(0, colon));
    port = host_port.substr(colon + 1);
    if (port.empty()) return BadUrl(url, "the port after ':' is empty");
  } else {
    address.host = std::string(host_port);
  }
  if (address.host.empty()) return BadUrl(url, "the host is empty");
  if (!port.empty() &&
      (!absl::SimpleAtoi(port, &address.port) || address.port < 1 || address.port > 65535)) {
    return BadUrl(url, absl::StrCat("the port '", port, "' is not a number in 1-65535"));
  }
  return address;
}

// One hiredis connection; unusable once a call on it failed (hiredis sets err).
class RedisTier::Connection {
 public:
  explicit Connection(redisContext* context) : context_(context) {}
  ~Connection() { redisFree(context_); }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  // Runs one command (hiredis printf-style format; "%b" takes a pointer and a length, binary
  // safe). Null with broken() true when the connection failed.
  template <typename... Args>
  Reply Command(const char* format, Args... args) {
    const SigpipeBlocked blocked;
    return Reply(static_cast<redisReply*>(redisCommand(context_, format, args...)));
  }
  bool broken() const { return context_->err != 0; }
  bool closed_by_server() const { return context_->err == REDIS_ERR_EOF; }
  const char* error() const { return context_->errstr; }

 private:
  redisContext* const context_;
};

RedisTier::RedisTier(RedisAddress address, int timeout_ms,
                     std::function<void(const SharedTierEvent&)> on_event)
    : address_(std::move(address)), timeout_ms_(timeout_ms), on_event_(std::move(on_event)) {}

RedisTier::~RedisTier() = default;

absl::StatusOr<std::unique_ptr<RedisTier>> RedisTier::Create(
    absl::string_view url, int timeout_ms, std::function<void(const SharedTierEvent&)> on_event) {
  if (timeout_ms < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("--redis-timeout-ms must be >= 1, got ", timeout_ms));
  }
  absl::StatusOr<RedisAddress> address = ParseRedisUrl(url);
  if (!address.ok()) return address.status();
  std::unique_ptr<RedisTier> tier(
      new RedisTier(*std::move(address), timeout_ms, std::move(on_event)));
  // Connect and PING now so that the log says at once whether Redis is there and accepts us
  // (a missing password shows only when a command is refused); the connection is kept.
  absl::StatusOr<std::unique_ptr<Connection>> connection = tier->Connect();
  if (connection.ok()) {
    const Reply reply = (*connection)->Command("PING");
    if (reply == nullptr) {
      connection = absl::UnavailableError(absl::StrCat(
          tier->Where(), ": PING: ", (*connection)->error(), " (timeout ", timeout_ms, " ms)"));
    } else if (reply->type == REDIS_REPLY_ERROR) {
      connection = absl::UnavailableError(absl::StrCat(
          tier->Where(), ": PING refused: ", absl::string_view(reply->str, reply->len)));
    }
  }
  if (connection.ok()) {
    tier->Release(*std::move(connection));
    if (tier->on_event_) tier->on_event_(SharedTierEvent{true, absl::OkStatus(), {}});
  } else {
    ++tier->errors_;
    tier->Failed(Attempt{true, false}, connection.status());
  }
  return tier;
}

std::string RedisTier::Where() const {
  return absl::StrCat("redis ", address_.host, ":", address_.port);
}

absl::StatusOr<std::unique_ptr<RedisTier::Connection>> RedisTier::Connect() const {
  timeval timeout{};
  timeout.tv_sec = timeout_ms_ / 1000;
  timeout.tv_usec = (timeout_ms_ % 1000) * 1000;
  redisContext* context = redisConnectWithTimeout(address_.host.c_str(), address_.port, timeout);
  if (context == nullptr) {
    return absl::UnavailableError(absl::StrCat(Where(), ": cannot allocate a connection"));
  }
  auto connection = std::make_unique<Connection>(context);
  if (connection->broken()) {
    return absl::UnavailableError(absl::StrCat(Where(), ": connect: ", connection->error(),
                                               " (timeout ", timeout_ms_, " ms)"));
  }
  // Bounds every later read and write on the socket (each recv/send call, so a large value
  // that keeps flowing is not cut off).
  if (redisSetTimeout(context, timeout) != REDIS_OK) {
    return absl::UnavailableError(
        absl::StrCat(Where(), ": setting timeouts: ", connection->error()));
  }
  const auto check = [&](const Reply& reply, absl::string_view what) -> absl::Status {
    if (reply == nullptr) {
      return absl::UnavailableError(absl::StrCat(Where(), ": ", what, ": ", connection->error(),
                                                 " (timeout ", timeout_ms_, " ms)"));
    }
    if (reply->type == REDIS_REPLY_ERROR) {
      return absl::UnavailableError(absl::StrCat(
          Where(), ": ", what, " refused: ", absl::string_view(reply->str, reply->len)));
    }
    return absl::OkStatus();
  };
  if (!address_.password.empty()) {
    // Redis' own replies to AUTH never echo the password.
    Reply reply =
        address_.user.empty()
            ? connection->Command("AUTH %b", address_.password.data(), address_.password.size())
            : connection->Command("AUTH %b %b", address_.user.data(), address_.user.size(),
                                  address_.password.data(), address_.password.size());
    if (absl::Status status = check(reply, "AUTH"); !status.ok()) return status;
  }
  if (address_.db != 0) {
    Reply reply = connection->Command("SELECT %d", address_.db);
    if (absl::Status status = check(reply, absl::StrCat("SELECT ", address_.db)); !status.ok()) {
      return status;
    }
  }
  return connection;
}

RedisTier::Attempt RedisTier::Begin() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (available_) return Attempt{true, false};
  if (!probing_ && std::chrono::steady_clock::now() >= down_until_) {
    probing_ = true;
    return Attempt{true, true};
  }
  ++skipped_;
  return Attempt{false, false};
}

void RedisTier::Succeeded(const Attempt& attempt) {
  if (!attempt.probe) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    probing_ = false;
    available_ = true;
    backoff_ = std::chrono::milliseconds(0);
  }
  if (on_event_) on_event_(SharedTierEvent{true, absl::OkStatus(), {}});
}

void RedisTier::Failed(const Attempt& attempt, const absl::Status& error) {
  std::vector<std::unique_ptr<Connection>> dropped;  // closed after unlocking
  std::chrono::milliseconds retry_after{0};
  bool went_down = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (available_) {
      went_down = true;
      available_ = false;
      backoff_ = kFirstBackoff;
    } else if (attempt.probe) {
      probing_ = false;
      backoff_ = std::min(2 * backoff_, kLongestBackoff);
    } else {
      return;  // a call begun before the tier went down: the backoff already runs
    }
    down_until_ = std::chrono::steady_clock::now() + backoff_;
    retry_after = backoff_;
    dropped.swap(idle_);  // likely dead too; the probe opens a fresh connection
  }
  if (went_down && on_event_) on_event_(SharedTierEvent{false, error, retry_after});
}

absl::StatusOr<std::unique_ptr<RedisTier::Connection>> RedisTier::Acquire() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!idle_.empty()) {
      std::unique_ptr<Connection> connection = std::move(idle_.back());
      idle_.pop_back();
      return connection;
    }
  }
  return Connect();
}

void RedisTier::Release(std::unique_ptr<Connection> connection) {
  if (connection->broken()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (idle_.size() < kMaxIdleConnections) idle_.push_back(std::move(connection));
}

RedisTier::ReadResult RedisTier::Get(absl::string_view key) {
  const Attempt attempt = Begin();
  if (!attempt.allowed) return ReadResult{Outcome::kSkipped, {}};
  const std::string redis_key = RedisKey(key);
  Reply reply;
  absl::Status error;
  // A pooled connection the server has closed since (a Redis restart) gets one fresh retry.
  for (int tries = 0; tries < 2; ++tries) {
    absl::StatusOr<std::unique_ptr<Connection>> connection = Acquire();
    if (!connection.ok()) {
      error = connection.status();
      break;
    }
    reply = (*connection)->Command("GET %b", redis_key.data(), redis_key.size());
    if (reply == nullptr) {
      error = absl::UnavailableError(absl::StrCat(Where(), ": GET: ", (*connection)->error(),
                                                  " (timeout ", timeout_ms_, " ms)"));
      if ((*connection)->closed_by_server() && tries == 0) continue;
      break;
    }
    Release(*std::move(connection));
    error = absl::OkStatus();
    break;
  }
  if (error.ok() && reply->type != REDIS_REPLY_STRING && reply->type != REDIS_REPLY_NIL) {
    error = absl::UnavailableError(absl::StrCat(Where(), ": GET: ",
                                                reply->type == REDIS_REPLY_ERROR
                                                    ? absl::string_view(reply->str, reply->len)
                                                    : absl::string_view("unexpected reply type")));
  }
  if (!error.ok()) {
    ++errors_;
    Failed(attempt, error);
    return ReadResult{Outcome::kError, {}};
  }
  Succeeded(attempt);
  if (reply->type == REDIS_REPLY_NIL) {
    ++misses_;
    return ReadResult{Outcome::kMiss, {}};
  }
  ReadResult result{Outcome::kHit, std::string(reply->str, reply->len)};
  reply.reset();  // the value is held twice until here
  if (!UnframeEntry(key, result.payload)) {
    DropCorrupt(key);
    return ReadResult{Outcome::kCorrupt, {}};
  }
  return result;
}

void RedisTier::DropCorrupt(absl::string_view key) {
  ++corrupt_;
  const Attempt attempt = Begin();
  if (!attempt.allowed) return;
  absl::StatusOr<std::unique_ptr<Connection>> connection = Acquire();
  if (!connection.ok()) return Failed(attempt, connection.status());
  const std::string redis_key = RedisKey(key);
  const Reply reply = (*connection)->Command("DEL %b", redis_key.data(), redis_key.size());
  if (reply == nullptr) {
    return Failed(attempt,
                  absl::UnavailableError(absl::StrCat(Where(), ": DEL: ", (*connection)->error())));
  }
  Release(*std::move(connection));
  Succeeded(attempt);
}

void RedisTier::Put(absl::string_view key, absl::string_view payload) {
  const Attempt attempt = Begin();
  if (!attempt.allowed) return;
  const std::string redis_key = RedisKey(key);
  const std::string value = FramedEntry(key, payload);
  absl::StatusOr<std::unique_ptr<Connection>> connection = Acquire();
  absl::Status error;
  if (!connection.ok()) {
    error = connection.status();
  } else {
    const Reply reply =
        (*connection)
            ->Command("SET %b %b", redis_key.data(), redis_key.size(), value.data(), value.size());
    if (reply == nullptr) {
      error = absl::UnavailableError(absl::StrCat(Where(), ": SET: ", (*connection)->error(),
                                                  " (timeout ", timeout_ms_, " ms)"));
    } else {
      Release(*std::move(connection));
      if (reply->type == REDIS_REPLY_ERROR) {  // e.g. OOM: maxmemory without an eviction policy
        error = absl::UnavailableError(
            absl::StrCat(Where(), ": SET: ", absl::string_view(reply->str, reply->len)));
      }
    }
  }
  if (!error.ok()) {
    ++write_errors_;
    return Failed(attempt, error);
  }
  ++writes_;
  Succeeded(attempt);
}

RedisTier::Counts RedisTier::counts() const {
  Counts counts;
  counts.misses = misses_.load();
  counts.errors = errors_.load();
  counts.writes = writes_.load();
  counts.write_errors = write_errors_.load();
  counts.skipped = skipped_.load();
  counts.corrupt = corrupt_.load();
  std::lock_guard<std::mutex> lock(mutex_);
  counts.available = available_;
  return counts;
}

}  // namespace inscribe::server
