// The integrity framing of a stored cache entry, shared by the disk tier (one file per entry)
// and the Redis tier (one value per entry). All integers little-endian:
//   "inscribe-cache 1\n"           17 bytes
//   key length                     uint32
//   key                            key length bytes (checked against the requested key, so a
//                                  SHA-256 collision of two keys, a moved file or a value
//                                  stored under the wrong name is a miss)
//   payload length                 uint64 (must equal what follows the header)
//   SHA-256 of the payload         32 bytes
//   payload                        CachedValue::bytes
// Private to the server library.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/strings/string_view.h"
#include "inscribe/base/sha256.h"

namespace inscribe::server {

// Bytes of the header for a key of `key_size` characters.
std::size_t EntryHeaderSize(std::size_t key_size);

// The header to write before `payload` (hashes the payload).
std::string EntryHeader(absl::string_view key, absl::string_view payload);

// Whether `header` (EntryHeaderSize(key.size()) bytes) is the header of an entry for `key` whose
// payload has `payload_size` bytes. Cheap: no hashing.
bool EntryHeaderMatches(absl::string_view header, absl::string_view key,
                        std::uint64_t payload_size);

// Whether `payload` has the SHA-256 recorded in `header` (one that EntryHeaderMatches).
bool EntryPayloadMatches(absl::string_view header, absl::string_view payload);

// Header + payload as one string (a Redis value).
std::string FramedEntry(absl::string_view key, absl::string_view payload);

// Checks a whole framed entry for `key` and, when it passes, leaves only its payload in
// `entry`. False (entry unspecified) when any check fails.
bool UnframeEntry(absl::string_view key, std::string& entry);

}  // namespace inscribe::server
