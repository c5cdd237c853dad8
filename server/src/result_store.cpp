#include "result_store.h"

#include <openssl/evp.h>

#include <chrono>
#include <cmath>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "inscribe/medial_spheres.h"
#include "inscribe/mesh_hash.h"
#include "inscribe/server/convert.h"
#include "inscribe/sphere_dilation.h"
#include "inscribe/sphere_quality.h"

namespace inscribe::server {
namespace {

// Bumped whenever generation, dilation or quality would give different results for the same
// input, so that old cache entries (memory or disk) are never served for new code.
constexpr char kSphereAlgorithmVersion[] = "inscribe-spheres-1";
constexpr char kHierarchyVersion[] = "v1";
// Hashed with an uploaded set's numbers: uploaded keys never collide with generated ones.
constexpr char kUploadedSetVersion[] = "inscribe-uploaded-spheres-1";
constexpr char kDeformerVersion[] = "inscribe-deformer-1";
constexpr double kDefaultObjectAngle = 0.6;
constexpr int kDefaultSamples = 32;
constexpr int kMaxSamples = 4096;

std::string Sha256Hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr);
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) absl::StrAppendFormat(&hex, "%02x", digest[i]);
  return hex;
}

// Hex digits of a key that route it (inscribe::client::RouteKey): a mesh and every key derived
// from it share their first 16, so a routing client sends all of them to one replica.
constexpr std::size_t kRouteDigits = 16;

// The first kRouteDigits hex digits of a mesh key ("sha256:<hex>") or of a key derived from
// one ("spheres/v1/<hex>"), or "" for any other key (an uploaded set's is then a full hash).
std::string RoutePrefix(const std::string& key) {
  absl::string_view hex = key;
  if (!absl::ConsumePrefix(&hex, "sha256:") && !absl::ConsumePrefix(&hex, "spheres/v1/")) {
    return "";
  }
  if (hex.size() < kRouteDigits) return "";
  for (char c : hex.substr(0, kRouteDigits)) {
    if (!absl::ascii_isxdigit(c) || absl::ascii_isupper(c)) return "";
  }
  return std::string(hex.substr(0, kRouteDigits));
}

// `prefix` (a RoutePrefix, or "") then the SHA-256 of `canonical`, 64 hex digits in all: the
// prefix takes the place of the digest's last 16 digits. The 192 bits left keep collisions out
// of reach (about 2^96 keys of one mesh before the first).
std::string DerivedKeyHex(const std::string& prefix, const std::string& canonical) {
  const std::string digest = Sha256Hex(canonical);
  if (prefix.empty()) return digest;
  return prefix + digest.substr(0, digest.size() - prefix.size());
}

// Memory a stored mesh holds beyond its bytes: the mesh arrays and the oracle's BVH and
// normals (a measured ~200 bytes per triangle in all).
std::int64_t MeshObjectBytes(const Mesh& mesh) {
  return 200 * static_cast<std::int64_t>(mesh.num_triangles()) +
         24 * static_cast<std::int64_t>(mesh.num_vertices());
}

// Builds the cache value of a validated mesh: bytes = StoredMesh, object = StoredMeshEntry.
absl::StatusOr<CachedValue> MeshValue(const std::string& key, Mesh mesh, MeshReport report,
                                      std::string bytes) {
  if (!report.usable()) {
    for (const MeshIssue& issue : report.issues) {
      if (issue.severity == Severity::kError) {
        return absl::FailedPreconditionError(
            absl::StrCat("mesh cannot be used: ", issue.code, ": ", issue.message));
      }
    }
    return absl::FailedPreconditionError("mesh cannot be used");
  }
  BoundaryOracleOptions oracle_options;
  // The pseudonormal sign is wrong near sheets buried inside a self-intersecting solid.
  if (report.self_intersecting_pairs > 0) oracle_options.inside_test = InsideTest::kRayParity;
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh, oracle_options);
  if (!oracle.ok()) return oracle.status();
  auto entry = std::make_shared<StoredMeshEntry>(
      StoredMeshEntry{key, std::move(mesh), std::move(report), *std::move(oracle)});
  CachedValue value;
  value.object_bytes = MeshObjectBytes(entry->mesh);
  value.object = std::move(entry);
  value.bytes = std::move(bytes);
  return value;
}

absl::StatusOr<CachedValue> DecodeMesh(const std::string& key, std::string bytes) {
  v1::StoredMesh stored;
  if (!stored.ParseFromString(bytes)) return absl::DataLossError("stored mesh does not parse");
  absl::StatusOr<Mesh> mesh = MeshFromProto(stored.mesh());
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<MeshReport> report = MeshReportFromProto(stored.report());
  if (!report.ok()) return report.status();
  return MeshValue(key, *std::move(mesh), *std::move(report), std::move(bytes));
}

absl::StatusOr<CachedValue> DecodeSphereSet(std::string bytes) {
  auto entry = std::make_shared<SphereSetEntry>();
  if (!entry->result.ParseFromString(bytes)) {
    return absl::DataLossError("stored sphere set does not parse");
  }
  absl::StatusOr<SphereSet> set = SphereSetFromProto(entry->result.spheres());
  if (!set.ok()) return set.status();
  entry->set = *std::move(set);
  CachedValue value;
  value.object_bytes = static_cast<std::int64_t>(entry->result.ByteSizeLong()) +
                       static_cast<std::int64_t>(sizeof(Sphere) * entry->set.size());
  value.object = std::move(entry);
  value.bytes = std::move(bytes);
  return value;
}

absl::StatusOr<CachedValue> DecodeHierarchy(std::string bytes) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Deserialize(bytes);
  if (!h.ok()) return h.status();
  CachedValue value;
  // Nodes, slots and the ordered copy: about four times the serialised size.
  value.object_bytes = 4 * static_cast<std::int64_t>(bytes.size());
  value.object = std::make_shared<const SphereHierarchy>(*std::move(h));
  value.bytes = std::move(bytes);
  return value;
}

}  // namespace

absl::StatusOr<v1::GenerateParameters> CanonicalParameters(const v1::GenerateParameters& in) {
  v1::GenerateParameters p = in;
  const bool by_size = p.voxel_size() != 0.0, by_budget = p.max_spheres() != 0;
  if (by_size == by_budget) {
    return absl::InvalidArgumentError(
        "parameters: set exactly one of voxel_size (> 0) and max_spheres (> 0)");
  }
  if (by_size && !(std::isfinite(p.voxel_size()) && p.voxel_size() > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "parameters.voxel_size must be a positive finite number, got ", p.voxel_size()));
  }
  if (by_budget && p.max_spheres() < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("parameters.max_spheres must be > 0, got ", p.max_spheres()));
  }
  if (p.object_angle() == 0.0) p.set_object_angle(kDefaultObjectAngle);
  if (!(p.object_angle() > 0.0 && p.object_angle() < M_PI)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "parameters.object_angle must lie in (0, pi) radians, got ", p.object_angle()));
  }
  if (!(std::isfinite(p.epsilon()) && p.epsilon() >= 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("parameters.epsilon must be finite and >= 0, got ", p.epsilon()));
  }
  if (p.samples() == 0) p.set_samples(kDefaultSamples);
  if (p.samples() < 1 || p.samples() > kMaxSamples) {
    return absl::InvalidArgumentError(
        absl::StrCat("parameters.samples must lie in [1, 4096], got ", p.samples()));
  }
  if (!p.dilate()) {
    p.set_dilation_growth(0.0);
  } else {
    if (p.dilation_growth() == 0.0) p.set_dilation_growth(1.0);
    if (!(p.dilation_growth() > 0.0 && p.dilation_growth() <= 1.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameters.dilation_growth must lie in (0, 1], got ", p.dilation_growth()));
    }
  }
  return p;
}

std::string SphereSetKey(const std::string& mesh_key, const v1::GenerateParameters& p,
                         bool with_quality) {
  // Fixed text, every number with 17 significant digits: the same settings always hash alike
  // (protobuf's binary form is not guaranteed canonical).
  const std::string canonical = absl::StrFormat(
      "%s\n%s\nvoxel_size=%.17g\nmax_spheres=%d\nobject_angle=%.17g\nepsilon=%.17g\nsamples=%d\n"
      "subdivide_boundary=%d\ndilate=%d\ndilation_growth=%.17g\nfill_holes=%d\nquality=%d\n",
      kSphereAlgorithmVersion, mesh_key, p.voxel_size(), p.max_spheres(), p.object_angle(),
      p.epsilon(), p.samples(), p.subdivide_boundary(), p.dilate(), p.dilation_growth(),
      p.fill_holes(), with_quality);
  return "spheres/v1/" + DerivedKeyHex(RoutePrefix(mesh_key), canonical);
}

ResultStore::ResultStore(ResultCache* cache, const StoreLimits& limits)
    : cache_(cache), limits_(limits) {}

absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> ResultStore::PutMesh(Mesh mesh,
                                                                            bool fill_holes,
                                                                            bool* already_stored) {
  ValidateOptions options;
  options.fill_holes = fill_holes;
  ValidatedMesh validated = ValidateMesh(std::move(mesh), options);
  if (validated.report.non_finite_vertices > 0 || validated.report.out_of_range_indices > 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("mesh cannot be used: ", validated.report.non_finite_vertices,
                     " vertices with non-finite coordinates, ",
                     validated.report.out_of_range_indices, " out-of-range indices"));
  }
  const std::string key = FormatSha256(MeshSha256(validated.mesh));
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        v1::StoredMesh stored;
        MeshToProto(validated.mesh, stored.mutable_mesh());
        MeshReportToProto(validated.report, stored.mutable_report());
        return MeshValue(key, validated.mesh, validated.report, stored.SerializeAsString());
      },
      [&](std::string bytes) { return DecodeMesh(key, std::move(bytes)); });
  if (!found.ok()) return found.status();
  if (already_stored != nullptr) {
    *already_stored = found->source == CacheSource::kMemory || found->source == CacheSource::kDisk;
  }
  return found->value->As<StoredMeshEntry>();
}

absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> ResultStore::GetMesh(
    const std::string& key) {
  // Every kind of value shares the cache; a key of another kind (found by fuzz_requests: a
  // mesh key sent as a sphere set key) would hand back another type's object, cast blindly.
  if (!absl::StartsWith(key, "sha256:")) {
    return absl::NotFoundError(absl::StrCat(
        "unknown mesh ", key, " (mesh keys are sha256:<hex>); upload it with PutMesh first"));
  }
  absl::StatusOr<CacheLookup> found =
      cache_->Get(key, [&](std::string bytes) { return DecodeMesh(key, std::move(bytes)); });
  if (!found.ok()) {
    if (found.status().code() == absl::StatusCode::kNotFound) {
      return absl::NotFoundError(
          absl::StrCat("unknown mesh ", key, "; upload it with PutMesh first"));
    }
    return found.status();
  }
  return found->value->As<StoredMeshEntry>();
}

absl::StatusOr<std::pair<std::shared_ptr<const SphereSetEntry>, CacheSource>> ResultStore::Generate(
    const v1::GenerateRequest& request, const GenerationControl& control) {
  absl::StatusOr<v1::GenerateParameters> parameters = CanonicalParameters(request.parameters());
  if (!parameters.ok()) return parameters.status();
  if (parameters->max_spheres() > limits_.max_spheres) {
    return absl::ResourceExhaustedError(
        absl::StrCat("parameters.max_spheres is ", parameters->max_spheres(),
                     "; this server's limit (--max-spheres) is ", limits_.max_spheres));
  }
  const std::string key = SphereSetKey(request.mesh_sha256(), *parameters, !request.skip_quality());
  // The mesh is looked up only when the result is not cached.
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh =
            GetMesh(request.mesh_sha256());
        if (!mesh.ok()) return mesh.status();
        const auto start = std::chrono::steady_clock::now();
        MedialSphereOptions options;
        options.object_angle = parameters->object_angle();
        options.epsilon = parameters->epsilon();
        options.samples = parameters->samples();
        options.subdivide_boundary = parameters->subdivide_boundary();
        options.max_voxels = limits_.max_voxels;
        absl::StatusOr<MedialSphereResult> generated;
        if (parameters->max_spheres() > 0) {
          SphereBudgetOptions budget;
          budget.max_spheres = parameters->max_spheres();
          budget.base = options;
          absl::StatusOr<SphereBudgetResult> searched =
              GenerateWithSphereBudget((*mesh)->oracle, budget, control);
          if (!searched.ok()) return searched.status();
          generated = std::move(searched->best);
        } else {
          options.voxel_size = parameters->voxel_size();
          generated = GenerateMedialSpheres((*mesh)->oracle, options, control);
        }
        if (!generated.ok()) return generated.status();
        SphereSet set = std::move(generated->set);
        if (parameters->dilate()) {
          DilationOptions dilation;
          dilation.growth = parameters->dilation_growth();
          absl::StatusOr<DilationResult> dilated = DilateSpheres((*mesh)->oracle, set, dilation);
          if (!dilated.ok()) return dilated.status();
          set = std::move(dilated->set);
        }
        v1::GenerateResult result;
        result.set_sphere_set_key(key);
        result.set_mesh_sha256(request.mesh_sha256());
        result.set_voxel_size(generated->voxel_size);
        SphereSetToProto(set, result.mutable_spheres());
        if (!request.skip_quality()) {
          QualityOptions quality_options;
          quality_options.voxel_size = generated->voxel_size;
          absl::StatusOr<QualityReport> quality =
              EvaluateSpheres((*mesh)->oracle, set.spheres, quality_options);
          if (!quality.ok()) return quality.status();
          QualityReportToProto(*quality, result.mutable_quality());
        }
        result.set_seconds(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        return DecodeSphereSet(result.SerializeAsString());
      },
      DecodeSphereSet);
  if (!found.ok()) return found.status();
  return std::make_pair(found->value->As<SphereSetEntry>(), found->source);
}

absl::StatusOr<std::shared_ptr<const SphereSetEntry>> ResultStore::GetSphereSet(
    const std::string& key) {
  // As in GetMesh: only sphere-set keys may reach the cast below.
  if (!absl::StartsWith(key, "spheres/")) {
    return absl::NotFoundError(absl::StrCat("unknown sphere set ", key,
                                            " (sphere set keys are spheres/v1/<hex>); call "
                                            "Generate or PutSphereSet to make it"));
  }
  absl::StatusOr<CacheLookup> found = cache_->Get(key, DecodeSphereSet);
  if (!found.ok()) {
    if (found.status().code() == absl::StatusCode::kNotFound) {
      return absl::NotFoundError(
          absl::StrCat("unknown sphere set ", key, "; call Generate to make it"));
    }
    return found.status();
  }
  return found->value->As<SphereSetEntry>();
}

absl::StatusOr<std::shared_ptr<const SphereHierarchy>> ResultStore::GetHierarchy(
    const std::string& key, HierarchyVolume volume) {
  // Checked first: a hierarchy key is derived from the sphere set's, so an unknown set must
  // not be reported as an unknown hierarchy.
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set = GetSphereSet(key);
  if (!set.ok()) return set.status();
  const std::string hierarchy_key =
      absl::StrCat("hierarchy/", kHierarchyVersion, "/", HierarchyVolumeName(volume), "/", key);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      hierarchy_key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build((*set)->set.spheres, volume);
        if (!h.ok()) return h.status();
        return DecodeHierarchy(h->Serialize());
      },
      DecodeHierarchy);
  if (!found.ok()) return found.status();
  return found->value->As<SphereHierarchy>();
}

absl::StatusOr<std::shared_ptr<const SphereSetEntry>> ResultStore::PutSphereSet(
    SphereSet set, const std::string& mesh_key, bool* already_stored,
    const std::string& derived_from) {
  if (!mesh_key.empty()) {
    absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = GetMesh(mesh_key);
    if (!mesh.ok()) return mesh.status();
    const std::int64_t triangles = (*mesh)->mesh.num_triangles();
    for (std::size_t i = 0; i < set.contacts.size(); ++i) {
      const std::int32_t t = set.contacts[i].triangle;
      if (t < 0 || t >= triangles) {
        return absl::InvalidArgumentError(absl::StrCat("spheres: sphere ", i, " touches triangle ",
                                                       t, "; mesh ", mesh_key, " has ", triangles,
                                                       " triangles (0-based)"));
      }
    }
  }
  v1::GenerateResult result;
  SphereSetToProto(set, result.mutable_spheres());
  // The packed arrays of one message serialise the same way for the same numbers. The route
  // prefix is the mesh's, else the set's it was derived from, else none (a full SHA-256).
  const std::string prefix = RoutePrefix(mesh_key.empty() ? derived_from : mesh_key);
  const std::string key =
      "spheres/v1/" + DerivedKeyHex(prefix, absl::StrCat(kUploadedSetVersion, "\n", mesh_key, "\n",
                                                         result.spheres().SerializeAsString()));
  result.set_sphere_set_key(key);
  result.set_mesh_sha256(mesh_key);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key, [&]() { return DecodeSphereSet(result.SerializeAsString()); }, DecodeSphereSet);
  if (!found.ok()) return found.status();
  if (already_stored != nullptr) {
    *already_stored = found->source == CacheSource::kMemory || found->source == CacheSource::kDisk;
  }
  return found->value->As<SphereSetEntry>();
}

absl::StatusOr<std::shared_ptr<const DeformerEntry>> ResultStore::GetDeformer(
    const std::string& mesh_key, const std::string& set_key, const DeformationOptions& options) {
  const std::string canonical = absl::StrFormat(
      "%s\n%s\n%s\nxi=%.17g\nstrict=%d\ndirection=%d\ninside=%d\n", kDeformerVersion, mesh_key,
      set_key, options.xi, options.strict, static_cast<int>(options.direction),
      static_cast<int>(options.oracle.inside_test));
  const std::string key = "deformer/v1/" + DerivedKeyHex(RoutePrefix(mesh_key), canonical);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set = GetSphereSet(set_key);
        if (!set.ok()) return set.status();
        if (!(*set)->set.has_contacts()) {
          return absl::FailedPreconditionError(absl::StrCat(
              "sphere set ", set_key,
              " has no contacts; deformation needs a set generated without dilation, or "
              "uploaded with its contacts"));
        }
        absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = GetMesh(mesh_key);
        if (!mesh.ok()) return mesh.status();
        absl::StatusOr<SphereDeformer> deformer =
            SphereDeformer::Create((*mesh)->mesh, (*set)->set, options);
        if (!deformer.ok()) {
          return absl::FailedPreconditionError(absl::StrCat("sphere set ", set_key,
                                                            " does not fit mesh ", mesh_key, ": ",
                                                            deformer.status().message()));
        }
        auto entry = std::make_shared<const DeformerEntry>(mesh_key, (*mesh)->mesh.triangles,
                                                           *std::move(deformer));
        CachedValue value;
        value.persist = false;
        // The reference mesh, its oracle and the per-sphere frames.
        value.object_bytes =
            MeshObjectBytes((*mesh)->mesh) + 96 * static_cast<std::int64_t>((*set)->set.size());
        value.object = std::move(entry);
        return value;
      },
      [](std::string) -> absl::StatusOr<CachedValue> {
        return absl::DataLossError("deformers are never stored on disk");
      });
  if (!found.ok()) return found.status();
  return found->value->As<DeformerEntry>();
}

}  // namespace inscribe::server
