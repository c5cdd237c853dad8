// Prometheus metrics of one inscribed process, served over HTTP at GET /metrics
// (--metrics-listen): per-RPC call counts by status code and latency histograms, recorded as
// calls finish; cache lookups by tier, cache sizes and errors, the job pool's occupancy and the
// open scenes,
// read from the cache and the pool at scrape time (so a scrape costs two snapshots, and the
// request path pays nothing for them). Private to the server.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/server/job_pool.h"
#include "inscribe/server/result_cache.h"

namespace inscribe::server {

class ServiceMetrics {
 public:
  // Serves the metrics on `listen` ("HOST:PORT"; port 0 picks a free one, see port()). `cache`,
  // `pool` and `service` (its open scenes) are read at each scrape and must outlive this object.
  // UNAVAILABLE when the address cannot be bound, INVALID_ARGUMENT when it is not HOST:PORT.
  static absl::StatusOr<std::unique_ptr<ServiceMetrics>> Start(const std::string& listen,
                                                               const ResultCache* cache,
                                                               const JobPool* pool,
                                                               const InscribeService* service);

  // Stops the HTTP endpoint (a scrape in progress is finished first).
  ~ServiceMetrics();
  ServiceMetrics(const ServiceMetrics&) = delete;
  ServiceMetrics& operator=(const ServiceMetrics&) = delete;

  // Counts one finished call: inscribe_rpc_calls_total{method,code} and the latency histograms
  // inscribe_rpc_duration_seconds{method} (queued + run: the server's time on the call) and
  // inscribe_rpc_queue_seconds{method}. Thread-safe; a few hundred nanoseconds.
  void RecordCall(const CallRecord& call);

  // The port the endpoint listens on.
  int port() const;

 private:
  struct Impl;
  explicit ServiceMetrics(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inscribe::server
