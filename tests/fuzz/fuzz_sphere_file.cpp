// libFuzzer target: the sphere-file readers. The first byte picks the format (value % 4: json,
// sph, csv, cuRobo yaml) and, for .sph, the level read (bits 2-3: deepest, 0, 1, 2); the rest goes
// through ParseSphereFile. A file that parses must keep sphere_io.h's promises (finite spheres with
// radius > 0, contacts empty or one per sphere) and survive FormatSphereFile then
// ParseSphereFile bit for bit: same spheres, and for JSON the same contacts, hash, params and
// stats. Any break aborts with the reason.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"

namespace {

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "fuzz_sphere_file: %s\n", what);
  std::abort();
}

// Bit-exact, so -0 differs from +0 and every NaN payload counts.
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool SameBits(const inscribe::Vector3& a, const inscribe::Vector3& b) {
  return SameBits(a.x(), b.x()) && SameBits(a.y(), b.y()) && SameBits(a.z(), b.z());
}

bool SameValue(const inscribe::ScalarValue& a, const inscribe::ScalarValue& b) {
  if (a.index() != b.index()) return false;
  if (const double* x = std::get_if<double>(&a)) return SameBits(*x, std::get<double>(b));
  return a == b;
}

bool SameValues(const inscribe::NamedValues& a, const inscribe::NamedValues& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].first != b[i].first || !SameValue(a[i].second, b[i].second)) return false;
  }
  return true;
}

void CheckPromises(const inscribe::SphereFile& file) {
  for (const inscribe::Sphere& sphere : file.set.spheres) {
    if (!sphere.center.allFinite() || !std::isfinite(sphere.radius) || !(sphere.radius > 0.0)) {
      Fail("a parsed sphere is not finite with a positive radius");
    }
  }
  if (!file.set.contacts.empty() && file.set.contacts.size() != file.set.spheres.size()) {
    Fail("parsed contacts are neither empty nor one per sphere");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const inscribe::SphereFileFormat kFormats[] = {
      inscribe::SphereFileFormat::kJson, inscribe::SphereFileFormat::kSph,
      inscribe::SphereFileFormat::kCsv, inscribe::SphereFileFormat::kYaml};
  const inscribe::SphereFileFormat format = kFormats[data[0] % 4];
  inscribe::SphereFileReadOptions read;
  read.sph_level = static_cast<int>((data[0] >> 2) & 3) - 1;
  const absl::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);

  absl::StatusOr<inscribe::SphereFile> parsed = inscribe::ParseSphereFile(bytes, format, read);
  if (!parsed.ok()) {
    if (parsed.status().message().empty()) Fail("a refused file has an empty error message");
    return 0;
  }
  CheckPromises(*parsed);

  absl::StatusOr<std::string> written = inscribe::FormatSphereFile(*parsed, format);
  if (!written.ok()) {
    std::fprintf(stderr, "fuzz_sphere_file: %s\n", std::string(written.status().message()).c_str());
    Fail("a file that parsed cannot be written back");
  }
  // What we wrote is read back at its deepest level (the .sph writer puts the spheres there).
  absl::StatusOr<inscribe::SphereFile> again = inscribe::ParseSphereFile(*written, format);
  if (!again.ok()) {
    std::fprintf(stderr, "fuzz_sphere_file: %s\n", std::string(again.status().message()).c_str());
    Fail("a written file does not parse");
  }
  CheckPromises(*again);
  const inscribe::SphereSet& a = parsed->set;
  const inscribe::SphereSet& b = again->set;
  if (a.spheres.size() != b.spheres.size()) Fail("the round trip changed the sphere count");
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    if (!SameBits(a.spheres[i].center, b.spheres[i].center) ||
        !SameBits(a.spheres[i].radius, b.spheres[i].radius)) {
      Fail("the round trip changed a sphere");
    }
  }
  if (format == inscribe::SphereFileFormat::kJson) {
    if (a.contacts.size() != b.contacts.size()) Fail("the round trip changed the contacts");
    for (std::size_t i = 0; i < a.contacts.size(); ++i) {
      if (a.contacts[i].triangle != b.contacts[i].triangle ||
          !SameBits(a.contacts[i].barycentric, b.contacts[i].barycentric)) {
        Fail("the round trip changed a contact");
      }
    }
    if (parsed->mesh_sha256 != again->mesh_sha256) Fail("the round trip changed mesh_sha256");
    if (!SameValues(parsed->params, again->params)) Fail("the round trip changed the params");
    if (!SameValues(parsed->stats, again->stats)) Fail("the round trip changed the stats");
  }
  return 0;
}
