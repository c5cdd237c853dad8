// SHA-256 (OpenSSL), the one digest every content key, checksum and token comparison uses.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/strings/string_view.h"

namespace inscribe {

using Sha256Digest = std::array<std::uint8_t, 32>;

// Incremental SHA-256: Update any number of times, then Finish once. Not copyable.
class Sha256Hasher {
 public:
  Sha256Hasher();
  ~Sha256Hasher();
  Sha256Hasher(const Sha256Hasher&) = delete;
  Sha256Hasher& operator=(const Sha256Hasher&) = delete;

  void Update(const void* data, std::size_t size);
  void Update(absl::string_view bytes) { Update(bytes.data(), bytes.size()); }
  Sha256Digest Finish();

 private:
  struct Context;
  std::unique_ptr<Context> context_;
};

// The digest of `bytes`. O(size).
Sha256Digest Sha256(absl::string_view bytes);

// 64 lowercase hex digits of `digest`.
std::string HexDigits(const Sha256Digest& digest);

// HexDigits(Sha256(bytes)).
std::string Sha256Hex(absl::string_view bytes);

}  // namespace inscribe
