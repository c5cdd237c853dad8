#include "cache_entry_format.h"

namespace inscribe::server {
namespace {

constexpr absl::string_view kMagic = "inscribe-cache 1\n";
constexpr std::size_t kDigestSize = std::tuple_size<Sha256Digest>::value;

void AppendLittleEndian(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>(value >> (8 * i)));
}

std::uint64_t ReadLittleEndian(absl::string_view in, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) {
    value |= std::uint64_t{static_cast<unsigned char>(in[i])} << (8 * i);
  }
  return value;
}

}  // namespace

std::size_t EntryHeaderSize(std::size_t key_size) {
  return kMagic.size() + 4 + key_size + 8 + kDigestSize;
}

std::string EntryHeader(absl::string_view key, absl::string_view payload) {
  std::string header(kMagic);
  header.reserve(EntryHeaderSize(key.size()));
  AppendLittleEndian(header, key.size(), 4);
  header.append(key.data(), key.size());
  AppendLittleEndian(header, payload.size(), 8);
  const Sha256Digest digest = Sha256(payload);
  header.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  return header;
}

bool EntryHeaderMatches(absl::string_view header, absl::string_view key,
                        std::uint64_t payload_size) {
  return header.size() == EntryHeaderSize(key.size()) &&
         header.substr(0, kMagic.size()) == kMagic &&
         ReadLittleEndian(header.substr(kMagic.size()), 4) == key.size() &&
         header.substr(kMagic.size() + 4, key.size()) == key &&
         ReadLittleEndian(header.substr(kMagic.size() + 4 + key.size()), 8) == payload_size;
}

bool EntryPayloadMatches(absl::string_view header, absl::string_view payload) {
  const Sha256Digest digest = Sha256(payload);
  return header.substr(header.size() - kDigestSize) ==
         absl::string_view(reinterpret_cast<const char*>(digest.data()), digest.size());
}

std::string FramedEntry(absl::string_view key, absl::string_view payload) {
  std::string entry = EntryHeader(key, payload);
  entry.append(payload.data(), payload.size());
  return entry;
}

bool UnframeEntry(absl::string_view key, std::string& entry) {
  const std::size_t header_size = EntryHeaderSize(key.size());
  if (entry.size() < header_size) return false;
  const absl::string_view view(entry);
  if (!EntryHeaderMatches(view.substr(0, header_size), key, entry.size() - header_size) ||
      !EntryPayloadMatches(view.substr(0, header_size), view.substr(header_size))) {
    return false;
  }
  entry.erase(0, header_size);
  return true;
}

}  // namespace inscribe::server
