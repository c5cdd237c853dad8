// CacheStats: the result cache's counters, answered on the gRPC thread.
#include "admission.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "result_store.h"

namespace inscribe::server {

grpc::ServerUnaryReactor* InscribeService::CacheStats(grpc::CallbackServerContext* context,
                                                      const v1::CacheStatsRequest* /*request*/,
                                                      v1::CacheStatsResponse* response) {
  // A snapshot of counters under the cache's lock: cheap enough for the gRPC thread, and it
  // must answer even when the pool is saturated.
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (absl::Status admitted = admission_->Authenticate(*context); !admitted.ok()) {
    CallRecord record;
    record.method = "CacheStats";
    record.peer = context->peer();
    admission_->CallStarted();
    Finish(reactor, record, admitted);  // observed, so refusals are logged and counted
    return reactor;
  }
  wire::CacheStatsToProto(store_->cache().stats(), response);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace inscribe::server
