#include "service_metrics.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <functional>
#include <iterator>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/container/node_hash_map.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "prometheus/counter.h"
#include "prometheus/family.h"
#include "prometheus/histogram.h"
#include "prometheus/metric_family.h"
#include "prometheus/registry.h"
#include "prometheus/text_serializer.h"

namespace inscribe::server {
namespace {

// Upper bounds in seconds: 100 us (a cache hit, a small distance batch) to 5 minutes (a fine
// generation of a large mesh); roughly 2.5x apart so quantiles interpolate within a factor 2.5.
const prometheus::Histogram::BucketBoundaries& LatencyBuckets() {
  static const prometheus::Histogram::BucketBoundaries buckets = {
      1e-4, 2.5e-4, 5e-4, 1e-3, 2.5e-3, 5e-3, 0.01, 0.025, 0.05, 0.1,
      0.25, 0.5,    1.0,  2.5,  5.0,    10.0, 30.0, 60.0,  120., 300.};
  return buckets;
}

prometheus::ClientMetric Sample(double value, std::vector<prometheus::ClientMetric::Label> labels,
                                prometheus::MetricType type) {
  prometheus::ClientMetric metric;
  metric.label = std::move(labels);
  if (type == prometheus::MetricType::Counter) {
    metric.counter.value = value;
  } else {
    metric.gauge.value = value;
  }
  return metric;
}

// The cache's and the pool's own counters, turned into metric families at each scrape.
class StateCollector {
 public:
  StateCollector(const ResultCache* cache, const JobPool* pool, const InscribeService* service)
      : cache_(cache), pool_(pool), service_(service) {}

  std::vector<prometheus::MetricFamily> Collect() const {
    using prometheus::MetricType;
    const ResultCacheStats s = cache_->stats();
    std::vector<prometheus::MetricFamily> families;
    const auto add = [&families](std::string name, std::string help, MetricType type,
                                 std::vector<prometheus::ClientMetric> samples) {
      families.push_back({std::move(name), std::move(help), type, std::move(samples)});
    };
    const auto by = [](const char* label, const char* value) {
      return std::vector<prometheus::ClientMetric::Label>{{label, value}};
    };

    add("inscribe_cache_lookups_total",
        "Cache lookups by where the value came from: memory, disk or redis (hits), joined (waited "
        "for an identical computation) or miss (found in no tier)",
        MetricType::Counter,
        {Sample(s.memory_hits, by("result", "memory"), MetricType::Counter),
         Sample(s.disk_hits, by("result", "disk"), MetricType::Counter),
         Sample(s.shared_hits, by("result", "redis"), MetricType::Counter),
         Sample(s.joined, by("result", "joined"), MetricType::Counter),
         Sample(s.misses, by("result", "miss"), MetricType::Counter)});
    add("inscribe_cache_computations_total", "Results computed (failed computations included)",
        MetricType::Counter, {Sample(s.computations, {}, MetricType::Counter)});
    add("inscribe_cache_evictions_total", "Entries dropped from memory for the byte budget",
        MetricType::Counter, {Sample(s.evictions, {}, MetricType::Counter)});
    add("inscribe_cache_entries", "Entries held, by tier", MetricType::Gauge,
        {Sample(s.entries, by("tier", "memory"), MetricType::Gauge),
         Sample(s.disk_entries, by("tier", "disk"), MetricType::Gauge)});
    add("inscribe_cache_bytes", "Bytes held, by tier (memory counts decoded objects too)",
        MetricType::Gauge,
        {Sample(s.bytes, by("tier", "memory"), MetricType::Gauge),
         Sample(s.disk_bytes, by("tier", "disk"), MetricType::Gauge)});
    add("inscribe_cache_errors_total",
        "Cache tier errors: disk corrupt (entries dropped on read), disk write, disk skipped "
        "(writes not tried while disk writes were stopped), redis read "
        "(unreachable, timed out, refused), redis write, redis corrupt, redis skipped (lookups "
        "and writes that bypassed Redis while it was marked down)",
        MetricType::Counter,
        {Sample(s.disk_errors, {{"tier", "disk"}, {"kind", "corrupt"}}, MetricType::Counter),
         Sample(s.disk_write_errors, {{"tier", "disk"}, {"kind", "write"}}, MetricType::Counter),
         Sample(s.disk_writes_skipped, {{"tier", "disk"}, {"kind", "skipped"}},
                MetricType::Counter),
         Sample(s.shared_errors, {{"tier", "redis"}, {"kind", "read"}}, MetricType::Counter),
         Sample(s.shared_write_errors, {{"tier", "redis"}, {"kind", "write"}}, MetricType::Counter),
         Sample(s.shared_corrupt, {{"tier", "redis"}, {"kind", "corrupt"}}, MetricType::Counter),
         Sample(s.shared_skipped, {{"tier", "redis"}, {"kind", "skipped"}}, MetricType::Counter)});
    add("inscribe_redis_available",
        "1 while the shared Redis tier is configured and answering, else 0", MetricType::Gauge,
        {Sample(s.shared_available, {}, MetricType::Gauge)});
    add("inscribe_disk_cache_available",
        "1 while the disk cache tier (--cache-dir) is configured and writing, else 0 (none, "
        "unwritable at start, or writes stopped after a failure)",
        MetricType::Gauge, {Sample(s.disk_available, {}, MetricType::Gauge)});
    add("inscribe_disk_cache_limit_bytes",
        "Bound of the disk cache tier (--cache-disk-bytes); 0 = unbounded or no disk tier",
        MetricType::Gauge, {Sample(s.disk_bytes_limit, {}, MetricType::Gauge)});
    add("inscribe_disk_cache_evictions_total",
        "Entries deleted from the disk cache tier for its bound, least recently used first",
        MetricType::Counter, {Sample(s.disk_evictions, {}, MetricType::Counter)});
    add("inscribe_disk_cache_evicted_bytes_total", "Bytes of those entries", MetricType::Counter,
        {Sample(s.disk_evicted_bytes, {}, MetricType::Counter)});
    add("inscribe_disk_cache_writes_too_large_total",
        "Results not written to disk because their file alone exceeds the bound",
        MetricType::Counter, {Sample(s.disk_writes_too_large, {}, MetricType::Counter)});

    const std::int64_t in_flight = pool_->jobs_in_flight();
    const JobPoolOptions& pool = pool_->options();
    add("inscribe_jobs_in_flight", "Jobs accepted by the pool and not finished (queued + running)",
        MetricType::Gauge, {Sample(in_flight, {}, MetricType::Gauge)});
    add("inscribe_jobs_queued", "Jobs waiting for a pool thread", MetricType::Gauge,
        {Sample(std::max<std::int64_t>(0, in_flight - pool.concurrency), {}, MetricType::Gauge)});
    add("inscribe_jobs_capacity",
        "Jobs the pool accepts at once (--max-queue); more get RESOURCE_EXHAUSTED",
        MetricType::Gauge, {Sample(pool.max_jobs, {}, MetricType::Gauge)});
    add("inscribe_jobs_concurrency", "Jobs run at the same time (--jobs)", MetricType::Gauge,
        {Sample(pool.concurrency, {}, MetricType::Gauge)});
    add("inscribe_scenes_open", "SceneStream calls open, each holding its scene", MetricType::Gauge,
        {Sample(service_->open_scenes(), {}, MetricType::Gauge)});
    return families;
  }

 private:
  const ResultCache* const cache_;
  const JobPool* const pool_;
  const InscribeService* const service_;
};

// The HTTP side: one thread accepting on a listening socket, answering each connection in turn
// (a scrape is one short request; Prometheus scrapes every few seconds). Not prometheus-cpp's
// civetweb Exposer: civetweb runs its handlers on 100 KB thread stacks, and CGAL's
// Triangulation_data_structure_3 puts 64 KB of static thread-local storage (two 32 KB
// instantiations in core) into every thread of this process, which leaves too little stack:
// the first scrape overflowed it. Serialisation stays prometheus-cpp's (TextSerializer).
class MetricsEndpoint {
 public:
  using Body = std::function<std::string()>;

  static absl::StatusOr<std::unique_ptr<MetricsEndpoint>> Listen(const std::string& listen,
                                                                 Body body);
  ~MetricsEndpoint() {
    const char stop = 1;
    while (::write(wake_[1], &stop, 1) < 0 && errno == EINTR) {
    }
    thread_.join();
    ::close(listener_);
    ::close(wake_[0]);
    ::close(wake_[1]);
  }
  MetricsEndpoint(const MetricsEndpoint&) = delete;
  MetricsEndpoint& operator=(const MetricsEndpoint&) = delete;

  int port() const { return port_; }

 private:
  MetricsEndpoint(int listener, const std::array<int, 2>& wake, int port, Body body)
      : listener_(listener), wake_(wake), port_(port), body_(std::move(body)) {
    thread_ = std::thread([this] { Serve(); });
  }

  void Serve() {
    for (;;) {
      pollfd fds[2] = {{listener_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
      if (::poll(fds, 2, -1) < 0) {
        if (errno == EINTR) continue;
        return;
      }
      if (fds[1].revents != 0) return;  // stopping
      const int connection = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
      if (connection < 0) continue;  // the client went away, or out of descriptors for now
      Answer(connection);
      ::close(connection);
    }
  }

  // Reads one request (at most 8 KiB, 2 s per read and write, so a stalled client cannot hold
  // the endpoint) and writes one response; the connection is closed after it.
  void Answer(int connection) const {
    const timeval timeout{2, 0};
    ::setsockopt(connection, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ::setsockopt(connection, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    std::string request;
    char buffer[2048];
    while (request.size() < 8192 && request.find("\r\n\r\n") == std::string::npos &&
           request.find("\n\n") == std::string::npos) {
      const ssize_t got = ::read(connection, buffer, sizeof buffer);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) break;
      request.append(buffer, static_cast<std::size_t>(got));
    }
    const std::vector<absl::string_view> words =
        absl::StrSplit(absl::string_view(request).substr(0, request.find_first_of("\r\n")), ' ',
                       absl::SkipEmpty());
    std::string status = "200 OK";
    std::string content;
    if (words.size() != 3 || !absl::StartsWith(words[2], "HTTP/")) {
      status = "400 Bad Request";
      content = "expected: GET /metrics HTTP/1.1\n";
    } else if (words[0] != "GET" && words[0] != "HEAD") {
      status = "405 Method Not Allowed";
      content = "only GET /metrics is served\n";
    } else if (words[1] != "/metrics" && !absl::StartsWith(words[1], "/metrics?")) {
      status = "404 Not Found";
      content = "only /metrics is served\n";
    } else {
      content = body_();
    }
    std::string response = absl::StrCat(
        "HTTP/1.1 ", status, "\r\nContent-Type: text/plain; version=0.0.4; charset=utf-8\r\n",
        "Content-Length: ", content.size(), "\r\nConnection: close\r\n\r\n");
    if (words.empty() || words[0] != "HEAD") response += content;
    absl::string_view rest = response;
    while (!rest.empty()) {
      const ssize_t sent = ::send(connection, rest.data(), rest.size(), MSG_NOSIGNAL);
      if (sent < 0 && errno == EINTR) continue;
      if (sent <= 0) return;
      rest.remove_prefix(static_cast<std::size_t>(sent));
    }
  }

  const int listener_;
  const std::array<int, 2> wake_;  // a pipe: a byte written to [1] stops Serve
  const int port_;
  const Body body_;
  std::thread thread_;
};

absl::StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Listen(const std::string& listen,
                                                                         Body body) {
  const std::size_t colon = listen.rfind(':');
  std::string host = listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);  // [::1]:9464
  }
  const std::string service = listen.substr(colon + 1);
  int port_number = -1;
  if (!absl::SimpleAtoi(service, &port_number) || port_number < 0 || port_number > 65535 ||
      !absl::ascii_isdigit(service.front())) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen ", listen, ": the port must be a number in 0-65535"));
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int error =
          ::getaddrinfo(host.empty() ? nullptr : host.c_str(), service.c_str(), &hints, &found);
      error != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen ", listen, ": ", ::gai_strerror(error)));
  }
  std::string failure = "no address";
  int listener = -1;
  for (addrinfo* a = found; a != nullptr && listener < 0; a = a->ai_next) {
    listener = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (listener < 0) continue;
    const int on = 1;
    ::setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (::bind(listener, a->ai_addr, a->ai_addrlen) != 0 || ::listen(listener, 16) != 0) {
      failure = std::error_code(errno, std::generic_category()).message();
      ::close(listener);
      listener = -1;
    }
  }
  ::freeaddrinfo(found);
  if (listener < 0) {
    return absl::UnavailableError(absl::StrCat("cannot serve metrics on ", listen, ": ", failure));
  }
  sockaddr_storage bound{};
  socklen_t length = sizeof bound;
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&bound), &length);
  const int port =
      ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6*>(&bound)->sin6_port
                                        : reinterpret_cast<const sockaddr_in*>(&bound)->sin_port);
  std::array<int, 2> wake{};
  if (::pipe2(wake.data(), O_CLOEXEC) != 0) {
    ::close(listener);
    return absl::UnavailableError("cannot serve metrics: pipe2 failed");
  }
  return std::unique_ptr<MetricsEndpoint>(
      new MetricsEndpoint(listener, wake, port, std::move(body)));
}

}  // namespace

struct ServiceMetrics::Impl {
  Impl()
      : registry(std::make_shared<prometheus::Registry>()),
        calls(prometheus::BuildCounter()
                  .Name("inscribe_rpc_calls_total")
                  .Help("Finished inscribe.v1 calls by method and gRPC status code")
                  .Register(*registry)),
        durations(prometheus::BuildHistogram()
                      .Name("inscribe_rpc_duration_seconds")
                      .Help("Server time of finished calls (queued + run), by method")
                      .Register(*registry)),
        queue_waits(prometheus::BuildHistogram()
                        .Name("inscribe_rpc_queue_seconds")
                        .Help("Time finished calls waited for a pool thread, by method")
                        .Register(*registry)) {}

  // What a scrape returns: the call metrics, then the cache's and the pool's state.
  std::string Exposition() const {
    std::vector<prometheus::MetricFamily> families = registry->Collect();
    std::vector<prometheus::MetricFamily> current = state->Collect();
    families.insert(families.end(), std::make_move_iterator(current.begin()),
                    std::make_move_iterator(current.end()));
    return prometheus::TextSerializer().Serialize(families);
  }

  std::shared_ptr<prometheus::Registry> registry;
  prometheus::Family<prometheus::Counter>& calls;
  prometheus::Family<prometheus::Histogram>& durations;
  prometheus::Family<prometheus::Histogram>& queue_waits;
  std::unique_ptr<StateCollector> state;

  struct PerMethod {
    prometheus::Histogram* duration = nullptr;
    prometheus::Histogram* queue_wait = nullptr;
    absl::flat_hash_map<absl::StatusCode, prometheus::Counter*> calls;
  };
  std::mutex mutex;  // guards `methods` (the map, not the metrics it points to)
  absl::node_hash_map<std::string, PerMethod> methods;  // node-stable: handed out by address

  std::unique_ptr<MetricsEndpoint> endpoint;  // last: its thread stops before the rest goes
};

absl::StatusOr<std::unique_ptr<ServiceMetrics>> ServiceMetrics::Start(
    const std::string& listen, const ResultCache* cache, const JobPool* pool,
    const InscribeService* service) {
  const std::size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon + 1 == listen.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen must be HOST:PORT, got \"", listen, "\""));
  }
  auto impl = std::make_unique<Impl>();
  impl->state = std::make_unique<StateCollector>(cache, pool, service);
  const Impl* raw = impl.get();
  absl::StatusOr<std::unique_ptr<MetricsEndpoint>> endpoint =
      MetricsEndpoint::Listen(listen, [raw] { return raw->Exposition(); });
  if (!endpoint.ok()) return endpoint.status();
  impl->endpoint = *std::move(endpoint);
  return std::unique_ptr<ServiceMetrics>(new ServiceMetrics(std::move(impl)));
}

ServiceMetrics::ServiceMetrics(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ServiceMetrics::~ServiceMetrics() = default;

void ServiceMetrics::RecordCall(const CallRecord& call) {
  const absl::StatusCode code = call.status.code();
  Impl::PerMethod* method = nullptr;
  prometheus::Counter* calls = nullptr;
  {
    // Family::Add builds a new metric object before looking its labels up, so the handles
    // are cached here: after a method's first call, recording costs two lookups.
    std::lock_guard<std::mutex> lock(impl_->mutex);
    auto [it, inserted] = impl_->methods.try_emplace(call.method);
    if (inserted) {
      it->second.duration = &impl_->durations.Add({{"method", call.method}}, LatencyBuckets());
      it->second.queue_wait = &impl_->queue_waits.Add({{"method", call.method}}, LatencyBuckets());
    }
    method = &it->second;
    prometheus::Counter*& counter = method->calls[code];
    if (counter == nullptr) {
      counter =
          &impl_->calls.Add({{"method", call.method}, {"code", absl::StatusCodeToString(code)}});
    }
    calls = counter;
  }
  // Counters and histograms are thread-safe themselves; handles stay valid for the families'
  // lifetime.
  calls->Increment();
  method->duration->Observe(call.queued_seconds + call.run_seconds);
  method->queue_wait->Observe(call.queued_seconds);
}

int ServiceMetrics::port() const { return impl_->endpoint->port(); }

}  // namespace inscribe::server
