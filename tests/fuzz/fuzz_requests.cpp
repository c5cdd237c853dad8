// libFuzzer target: the server's request validation. The first byte picks one of the
// inscribe.v1 request messages (RequestKind); the rest is parsed as that message (bytes that
// do not parse are skipped) and sent to a real InscribeServer on loopback with small limits
// (request_fuzz_server.h), whose stored cube, generated sphere set and plain sphere set the
// seeds name, so mutations reach past the key lookups. A finding: a crash or sanitizer report
// in the server, or an answer that is not OK or a clean error: UNKNOWN, INTERNAL (an escaped
// exception or a bug), DEADLINE_EXCEEDED (a hang or unbounded work), UNAVAILABLE or CANCELLED
// (the server went away), or any error with an empty message. Each aborts naming the call.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <thread>

#include "request_fuzz_server.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  using inscribe::fuzz::RequestKind;
  const auto kind = static_cast<RequestKind>(data[0] % inscribe::fuzz::kRequestKinds);
  const absl::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  inscribe::fuzz::FuzzServer& server = inscribe::fuzz::TheFuzzServer();
  const std::optional<grpc::Status> status = inscribe::fuzz::SendRequest(server, kind, bytes);
  // The reply can arrive before the job that sent it has returned: wait for the pool to be idle
  // so that each input's work (and memory) ends with the input. The leak check that libFuzzer
  // runs after an input would otherwise see a job still in TBB's queue (memory LeakSanitizer
  // does not scan) and report what it holds.
  for (int waited_ms = 0; server.server->jobs_in_flight() > 0; ++waited_ms) {
    if (waited_ms > 30'000) {
      std::fprintf(stderr, "fuzz_requests: %s left a job running for 30 s\n",
                   inscribe::fuzz::RequestKindName(kind));
      std::abort();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!status.has_value() || status->ok()) return 0;
  const grpc::StatusCode code = status->error_code();
  const bool unclean = code == grpc::StatusCode::UNKNOWN || code == grpc::StatusCode::INTERNAL ||
                       code == grpc::StatusCode::DEADLINE_EXCEEDED ||
                       code == grpc::StatusCode::UNAVAILABLE ||
                       code == grpc::StatusCode::CANCELLED || code == grpc::StatusCode::DATA_LOSS;
  if (unclean || status->error_message().empty()) {
    std::fprintf(stderr, "fuzz_requests: %s answered code %d: '%s'\n",
                 inscribe::fuzz::RequestKindName(kind), static_cast<int>(code),
                 status->error_message().c_str());
    std::abort();
  }
  return 0;
}
