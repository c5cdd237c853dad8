#include "inscribe/base/sha256.h"

#include <openssl/evp.h>

#include <cassert>

namespace inscribe {

struct Sha256Hasher::Context {
  EVP_MD_CTX* md = nullptr;
};

Sha256Hasher::Sha256Hasher() : context_(std::make_unique<Context>()) {
  context_->md = EVP_MD_CTX_new();
  assert(context_->md != nullptr);
  EVP_DigestInit_ex(context_->md, EVP_sha256(), nullptr);
}

Sha256Hasher::~Sha256Hasher() { EVP_MD_CTX_free(context_->md); }

void Sha256Hasher::Update(const void* data, std::size_t size) {
  EVP_DigestUpdate(context_->md, data, size);
}

Sha256Digest Sha256Hasher::Finish() {
  Sha256Digest digest{};
  unsigned int length = 0;
  EVP_DigestFinal_ex(context_->md, digest.data(), &length);
  assert(length == digest.size());
  return digest;
}

Sha256Digest Sha256(absl::string_view bytes) {
  Sha256Hasher hasher;
  hasher.Update(bytes);
  return hasher.Finish();
}

std::string HexDigits(const Sha256Digest& digest) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * digest.size());
  for (std::uint8_t byte : digest) {
    out.push_back(kHex[byte >> 4]);
    out.push_back(kHex[byte & 0xf]);
  }
  return out;
}

std::string Sha256Hex(absl::string_view bytes) { return HexDigits(Sha256(bytes)); }

}  // namespace inscribe
