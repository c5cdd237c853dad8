#include "inscribe/wire/keys.h"

#include <algorithm>
#include <cstdint>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "inscribe/base/sha256.h"

namespace inscribe::wire {
namespace {

// Bumped whenever generation, dilation or quality would give different results for the same
// input, so that old cache entries (memory, disk or Redis) are never served for new code.
constexpr char kSphereAlgorithmVersion[] = "inscribe-spheres-1";
// Written into the key of covers only, and bumped whenever GenerateCover would give another
// cover for the same input (so that covers are recomputed without touching other sets' keys).
constexpr char kCoverAlgorithmVersion[] = "inscribe-cover-4";
constexpr char kHierarchyVersion[] = "v1";
// Hashed with an uploaded set's numbers: uploaded keys never collide with generated ones.
constexpr char kUploadedSetVersion[] = "inscribe-uploaded-spheres-1";
constexpr char kDeformerVersion[] = "inscribe-deformer-1";
// Bumped whenever CertifyCover would give another verdict or figures for the same input.
constexpr char kCertificateVersion[] = "inscribe-certificate-2";

// `prefix` (a RoutePrefix, or "") then the SHA-256 of `canonical`, 64 hex digits in all: the
// prefix takes the place of the digest's last digits. The 192 bits left keep collisions out
// of reach (about 2^96 keys of one mesh before the first).
std::string DerivedKeyHex(const std::string& prefix, absl::string_view canonical) {
  const std::string digest = Sha256Hex(canonical);
  if (prefix.empty()) return digest;
  return prefix + digest.substr(0, digest.size() - prefix.size());
}

}  // namespace

std::string RoutePrefix(absl::string_view key) {
  absl::string_view hex = key;
  if (!absl::ConsumePrefix(&hex, "sha256:") && !absl::ConsumePrefix(&hex, "spheres/v1/")) {
    return "";
  }
  if (hex.size() < kRouteDigits) return "";
  const absl::string_view digits = hex.substr(0, kRouteDigits);
  const bool lower_hex = std::all_of(digits.begin(), digits.end(), [](char c) {
    return absl::ascii_isdigit(c) || (c >= 'a' && c <= 'f');
  });
  return lower_hex ? std::string(digits) : "";
}

std::string RouteKey(absl::string_view key) {
  std::string prefix = RoutePrefix(key);
  return prefix.empty() ? std::string(key) : prefix;
}

std::vector<int> RendezvousOrder(absl::string_view route_key,
                                 const std::vector<std::string>& names) {
  // Score of each (key, name): the first 8 bytes of SHA-256(key NUL name), big-endian. The NUL
  // keeps ("ab", "c") and ("a", "bc") apart.
  std::vector<std::uint64_t> score(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Sha256Digest digest =
        Sha256(absl::StrCat(route_key, absl::string_view("\0", 1), names[i]));
    for (int b = 0; b < 8; ++b) score[i] = (score[i] << 8) | digest[b];
  }
  std::vector<int> order(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) order[i] = static_cast<int>(i);
  // Ties (2^-64 per pair) broken by name, so the order never depends on the vector's order.
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return score[a] != score[b] ? score[a] > score[b] : names[a] < names[b];
  });
  return order;
}

std::string ContentRouteKey(absl::string_view spheres_bytes) {
  return Sha256Hex(spheres_bytes).substr(0, kRouteDigits);
}

std::string GeneratedSphereSetKey(const std::string& mesh_key, const SphereSetParameters& p,
                                  MeshRepair repair) {
  // Fixed text, every number with 17 significant digits: the same settings always hash alike.
  // Options added after version 1 of this text appear only when they differ from their
  // defaults, so that the keys of sets made before they existed stay what they were.
  const MedialSphereOptions medial_defaults;
  const QualityOptions quality_defaults;
  const bool dilated = p.kind == SphereSetKind::kDilated;
  std::string canonical = absl::StrFormat(
      "%s\n%s\nvoxel_size=%.17g\nmax_spheres=%d\nobject_angle=%.17g\nepsilon=%.17g\nsamples=%d\n"
      "subdivide_boundary=%d\ndilate=%d\ndilation_growth=%.17g\nfill_holes=%d\nquality=%d\n",
      kSphereAlgorithmVersion, mesh_key, p.voxel_size.value_or(0.0), p.max_spheres.value_or(0),
      p.medial.object_angle, p.medial.epsilon, p.medial.samples, p.medial.subdivide_boundary,
      dilated, dilated ? p.dilation.growth : 0.0, repair == MeshRepair::kFill, p.evaluate);
  // Before repair levels, a mesh was either taken as it was or had its holes filled; the safe
  // fixes only change meshes that were refused before, so "none" and "safe" keep that key.
  if (repair == MeshRepair::kWrap || repair == MeshRepair::kAuto) {
    absl::StrAppendFormat(&canonical, "repair=%s\n", MeshRepairName(repair));
  }
  if (p.medial.screen_samples != medial_defaults.screen_samples) {
    absl::StrAppendFormat(&canonical, "screen_samples=%d\n", p.medial.screen_samples);
  }
  if (p.medial.corner_screen != medial_defaults.corner_screen) {
    absl::StrAppendFormat(&canonical, "corner_screen=%d\n", p.medial.corner_screen);
  }
  if (p.medial.pair_angle_margin != medial_defaults.pair_angle_margin) {
    absl::StrAppendFormat(&canonical, "pair_angle_margin=%.17g\n", p.medial.pair_angle_margin);
  }
  if (p.evaluate && p.quality.surface_samples != quality_defaults.surface_samples) {
    absl::StrAppendFormat(&canonical, "quality_samples=%d\n", p.quality.surface_samples);
  }
  // Sets made before the choice existed were the paper's.
  if (p.kind != SphereSetKind::kCover && EffectiveMaxSpheres(p) &&
      p.selection != SphereSelection::kPaper) {
    absl::StrAppendFormat(&canonical, "selection=%s\n", SphereSelectionName(p.selection));
  }
  if (p.kind == SphereSetKind::kCover) {
    absl::StrAppendFormat(&canonical, "cover=%s\nmax_protrusion=%.17g\ncover_resolution=%.17g\n",
                          kCoverAlgorithmVersion, p.max_protrusion.value_or(0.0),
                          p.cover_resolution);
  }
  return "spheres/v1/" + DerivedKeyHex(RoutePrefix(mesh_key), canonical);
}

std::string UploadedSphereSetKey(const std::string& mesh_key, const std::string& derived_from,
                                 absl::string_view spheres_bytes,
                                 absl::string_view certificate_bytes) {
  const std::string prefix = RoutePrefix(mesh_key.empty() ? derived_from : mesh_key);
  std::string canonical = absl::StrCat(kUploadedSetVersion, "\n", mesh_key, "\n", spheres_bytes);
  if (!certificate_bytes.empty()) absl::StrAppend(&canonical, "\ncertificate\n", certificate_bytes);
  return "spheres/v1/" + DerivedKeyHex(prefix, canonical);
}

std::string CoverCertificateKey(const std::string& set_key, const std::string& mesh_key,
                                const CoverCertifyOptions& options) {
  const std::string canonical = absl::StrFormat(
      "%s\n%s\n%s\nresolution=%.17g\n", kCertificateVersion, set_key, mesh_key, options.resolution);
  return "certificate/v1/" + DerivedKeyHex(RoutePrefix(set_key), canonical);
}

std::string DeformerKey(const std::string& mesh_key, const std::string& set_key,
                        const DeformationOptions& options) {
  const std::string canonical =
      absl::StrFormat("%s\n%s\n%s\nxi=%.17g\nstrict=%d\ndirection=%d\nbackend=%d\n",
                      kDeformerVersion, mesh_key, set_key, options.xi, options.strict,
                      static_cast<int>(options.direction), static_cast<int>(options.backend));
  return "deformer/v1/" + DerivedKeyHex(RoutePrefix(mesh_key), canonical);
}

std::string HierarchyKey(const std::string& set_key, HierarchyVolume volume) {
  return absl::StrCat("hierarchy/", kHierarchyVersion, "/", HierarchyVolumeName(volume), "/",
                      set_key);
}

std::string UpperBoundHierarchyKey(const std::string& internal_key, const std::string& cover_key,
                                   HierarchyVolume volume) {
  return absl::StrCat("hierarchy/", kHierarchyVersion, "/", HierarchyVolumeName(volume), "/upper/",
                      Sha256Hex(absl::StrCat(internal_key, "\n", cover_key, "\n")));
}

bool IsMeshKey(absl::string_view key) { return absl::StartsWith(key, "sha256:"); }
bool IsSphereSetKey(absl::string_view key) { return absl::StartsWith(key, "spheres/"); }

}  // namespace inscribe::wire
