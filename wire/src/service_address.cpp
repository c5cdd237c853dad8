#include "inscribe/wire/service_address.h"

#include <algorithm>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace inscribe::wire {

std::string TargetWithDefaultPort(absl::string_view target) {
  target = absl::StripAsciiWhitespace(target);
  if (target.empty() || absl::StrContains(target, "://")) return std::string(target);
  for (absl::string_view scheme : {"dns:", "unix:", "unix-abstract:", "ipv4:", "ipv6:", "vsock:"}) {
    if (absl::StartsWithIgnoreCase(target, scheme)) return std::string(target);
  }
  const std::string port = absl::StrCat(kDefaultPort);
  if (target.front() == '[') {  // [V6] or [V6]:PORT
    const std::size_t close = target.find(']');
    if (close == absl::string_view::npos) return std::string(target);  // gRPC names the error
    const absl::string_view rest = target.substr(close + 1);
    if (rest.empty()) return absl::StrCat(target, ":", port);
    if (rest == ":") return absl::StrCat(target, port);
    return std::string(target);
  }
  const auto colons = std::count(target.begin(), target.end(), ':');
  if (colons == 0) return absl::StrCat(target, ":", port);
  if (colons > 1) return absl::StrCat("[", target, "]:", port);  // a bare IPv6 address
  if (target.back() == ':') return absl::StrCat(target, port);
  return std::string(target);
}

}  // namespace inscribe::wire
