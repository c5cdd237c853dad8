// Where the service listens and how a client names it: the one default port, and the rule
// that completes a target without one.
#pragma once

#include <string>

#include "absl/strings/string_view.h"

namespace inscribe::wire {

// inscribed's default port (its --listen is 127.0.0.1:50051 unless told otherwise).
inline constexpr int kDefaultPort = 50051;

// `target` as gRPC should dial it: "HOST" becomes "HOST:50051", a bare IPv6 address ("::1")
// "[::1]:50051", "[::1]" "[::1]:50051", "HOST:" "HOST:50051"; "HOST:PORT", "[V6]:PORT" and any
// gRPC target URI (with "://", or a scheme gRPC names: dns:, unix:, unix-abstract:, ipv4:,
// ipv6:, vsock:) are kept as they are. Surrounding whitespace is dropped.
std::string TargetWithDefaultPort(absl::string_view target);

}  // namespace inscribe::wire
