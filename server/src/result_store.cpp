#include "result_store.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/convert.h"
#include "inscribe/wire/keys.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// The decoded object of a lookup as a T: a value of another kind under the key is an INTERNAL
// error naming it, never a cast to the wrong type.
template <typename T>
absl::StatusOr<std::shared_ptr<const T>> ObjectOf(const CacheLookup& found,
                                                  const std::string& key) {
  std::shared_ptr<const T> object = found.value->Get<T>();
  if (object == nullptr) {
    return absl::InternalError(
        absl::StrCat("cache entry ", key, " holds another kind of value than asked for"));
  }
  return object;
}

// Memory a stored mesh holds beyond its bytes: the mesh arrays and the oracle's BVH and
// normals (a measured ~200 bytes per triangle in all).
std::int64_t MeshObjectBytes(const Mesh& mesh) {
  return 200 * static_cast<std::int64_t>(mesh.num_triangles()) +
         24 * static_cast<std::int64_t>(mesh.num_vertices());
}

// Builds the cache value of a validated mesh: bytes = StoredMesh, object = StoredMeshEntry.
absl::StatusOr<CachedValue> MeshValue(const std::string& key, ValidatedMesh validated,
                                      std::string bytes) {
  absl::StatusOr<Solid> solid = MakeSolid(std::move(validated), key);
  if (!solid.ok()) return solid.status();
  auto entry = std::make_shared<const StoredMeshEntry>(StoredMeshEntry{key, *std::move(solid)});
  CachedValue value;
  value.object_bytes = MeshObjectBytes(entry->mesh());
  value.object = std::move(entry);
  value.bytes = std::move(bytes);
  return value;
}

absl::StatusOr<CachedValue> DecodeMesh(const std::string& key, std::string bytes) {
  v1::StoredMesh stored;
  if (!stored.ParseFromString(bytes)) return absl::DataLossError("stored mesh does not parse");
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(stored.mesh());
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<MeshReport> report = wire::MeshReportFromProto(stored.report());
  if (!report.ok()) return report.status();
  return MeshValue(key, ValidatedMesh{*std::move(mesh), *std::move(report)}, std::move(bytes));
}

// A cover's certificate must name the set's spheres and mesh (CheckCoverCertificateBinding):
// one that does not (an entry written before certificates named them) is a corrupt entry, so
// a generated cover is generated again and an uploaded one must be uploaded again.
absl::StatusOr<CachedValue> DecodeSphereSet(std::string bytes) {
  auto entry = std::make_shared<SphereSetEntry>();
  if (!entry->result.ParseFromString(bytes)) {
    return absl::DataLossError("stored sphere set does not parse");
  }
  absl::StatusOr<SphereSet> set = wire::SphereSetFromProto(entry->result.spheres());
  if (!set.ok()) return set.status();
  entry->set = *std::move(set);
  if (entry->result.has_cover()) {
    absl::StatusOr<CoverCertificate> certificate =
        wire::CoverCertificateFromProto(entry->result.cover().certificate());
    if (!certificate.ok()) return certificate.status();
    if (absl::Status bound = CheckCoverCertificateBinding(*certificate, entry->set.spheres,
                                                          entry->result.mesh_sha256());
        !bound.ok()) {
      return absl::DataLossError(
          absl::StrCat("stored cover ", entry->result.sphere_set_key(), ": ", bound.message()));
    }
  }
  CachedValue value;
  value.object_bytes = static_cast<std::int64_t>(entry->result.ByteSizeLong()) +
                       static_cast<std::int64_t>(sizeof(Sphere) * entry->set.size());
  value.object = std::shared_ptr<const SphereSetEntry>(std::move(entry));
  value.bytes = std::move(bytes);
  return value;
}

// The certificate of `spheres` against mesh `mesh_key`; one that does not name them
// (CheckCoverCertificateBinding) is a corrupt entry, proved again.
absl::StatusOr<CachedValue> DecodeCertificate(std::string bytes, const std::vector<Sphere>& spheres,
                                              const std::string& mesh_key) {
  v1::CoverCertificate stored;
  if (!stored.ParseFromString(bytes))
    return absl::DataLossError("stored certificate does not parse");
  absl::StatusOr<CoverCertificate> certificate = wire::CoverCertificateFromProto(stored);
  if (!certificate.ok()) return certificate.status();
  if (absl::Status bound = CheckCoverCertificateBinding(*certificate, spheres, mesh_key);
      !bound.ok()) {
    return absl::DataLossError(absl::StrCat("stored certificate: ", bound.message()));
  }
  CachedValue value;
  value.object_bytes = static_cast<std::int64_t>(sizeof(CoverCertificate));
  value.object = std::shared_ptr<const CoverCertificate>(
      std::make_shared<const CoverCertificate>(*std::move(certificate)));
  value.bytes = std::move(bytes);
  return value;
}

// Why a certificate does not let a set serve as a cover.
std::string NotACover(const std::string& set_key, const std::string& mesh_key,
                      const CoverCertificate& c) {
  if (c.uncovered_point) {
    const Vector3& p = *c.uncovered_point;
    return absl::StrCat("sphere set ", set_key, " is not a cover of mesh ", mesh_key,
                        ": the point (", p.x(), ", ", p.y(), ", ", p.z(), "), ", c.uncovered_depth,
                        " deep in the solid, is ", c.uncovered_gap, " from the nearest sphere");
  }
  return absl::StrCat("sphere set ", set_key, " is not a certified cover of mesh ", mesh_key, ": ",
                      c.failed_cells, " cells of side ", c.resolution,
                      " near the boundary are in no single sphere");
}

absl::StatusOr<CachedValue> DecodeHierarchy(std::string bytes) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Deserialize(bytes);
  if (!h.ok()) return h.status();
  CachedValue value;
  // Nodes, slots and the ordered copy: about four times the serialised size.
  value.object_bytes = 4 * static_cast<std::int64_t>(bytes.size());
  value.object = std::shared_ptr<const SphereHierarchy>(
      std::make_shared<const SphereHierarchy>(*std::move(h)));
  value.bytes = std::move(bytes);
  return value;
}

}  // namespace

ResultStore::ResultStore(ResultCache* cache, const StoreLimits& limits)
    : cache_(cache), limits_(limits) {}

absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> ResultStore::PutMesh(
    Mesh mesh, const ValidateOptions& options, bool* already_stored) {
  ValidatedMesh validated = ValidateMesh(std::move(mesh), options);
  // Refused before hashing (a mesh with NaNs or dangling indices has no usable hash) and before
  // the cache is asked.
  if (!validated.report.usable()) return UnusableMeshError(validated.report.first_error());
  const std::string key = FormatSha256(MeshSha256(validated.mesh));
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        v1::StoredMesh stored;
        wire::MeshToProto(validated.mesh, stored.mutable_mesh());
        wire::MeshReportToProto(validated.report, stored.mutable_report());
        return MeshValue(key, validated, stored.SerializeAsString());
      },
      [&](std::string bytes) { return DecodeMesh(key, std::move(bytes)); });
  if (!found.ok()) return found.status();
  if (already_stored != nullptr) {
    *already_stored = found->source == CacheSource::kMemory || found->source == CacheSource::kDisk;
  }
  return ObjectOf<StoredMeshEntry>(*found, key);
}

absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> ResultStore::GetMesh(
    const std::string& key) {
  // Every kind of value shares the cache; a key of another kind (found by fuzz_requests: a
  // mesh key sent as a sphere set key) would hand back another type's object, cast blindly.
  if (!wire::IsMeshKey(key)) {
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
  return ObjectOf<StoredMeshEntry>(*found, key);
}

absl::StatusOr<std::pair<std::shared_ptr<const SphereSetEntry>, CacheSource>> ResultStore::Generate(
    const std::string& mesh_key, const SphereSetParameters& parameters, MeshRepair repair,
    const GenerationControl& control) {
  if (const std::optional<std::int64_t> budget = EffectiveMaxSpheres(parameters);
      budget && *budget > limits_.max_spheres) {
    return absl::ResourceExhaustedError(absl::StrCat("parameters.max_spheres is ", *budget,
                                                     "; this server's limit (--max-spheres) is ",
                                                     limits_.max_spheres));
  }
  const std::string key = wire::GeneratedSphereSetKey(mesh_key, parameters, repair);
  // The mesh is looked up only when the result is not cached.
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = GetMesh(mesh_key);
        if (!mesh.ok()) return mesh.status();
        absl::StatusOr<GeneratedSphereSet> generated =
            GenerateSphereSet((*mesh)->solid, parameters, control);
        if (!generated.ok()) return generated.status();
        // A budget was checked above; a cover bounded by max_protrusion is checked here.
        if (parameters.max_protrusion &&
            static_cast<std::int64_t>(generated->set.size()) > limits_.max_spheres) {
          return absl::ResourceExhaustedError(
              absl::StrCat("the cover needs ", generated->set.size(),
                           " spheres for "
                           "max_protrusion ",
                           parameters.max_protrusion.value_or(0.0),
                           "; this server's limit (--max-spheres) is ", limits_.max_spheres));
        }
        v1::GenerateResult result;
        result.set_sphere_set_key(key);
        result.set_mesh_sha256(mesh_key);
        wire::GeneratedSphereSetToProto(*generated, &result);
        return DecodeSphereSet(result.SerializeAsString());
      },
      DecodeSphereSet);
  if (!found.ok()) return found.status();
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> entry =
      ObjectOf<SphereSetEntry>(*found, key);
  if (!entry.ok()) return entry.status();
  return std::make_pair(*std::move(entry), found->source);
}

absl::StatusOr<std::shared_ptr<const SphereSetEntry>> ResultStore::GetSphereSet(
    const std::string& key) {
  // As in GetMesh: only sphere-set keys may reach the cast below.
  if (!wire::IsSphereSetKey(key)) {
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
  return ObjectOf<SphereSetEntry>(*found, key);
}

absl::StatusOr<std::shared_ptr<const SphereHierarchy>> ResultStore::GetHierarchy(
    const std::string& key, HierarchyVolume volume) {
  // Checked first: a hierarchy key is derived from the sphere set's, so an unknown set must
  // not be reported as an unknown hierarchy.
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set = GetSphereSet(key);
  if (!set.ok()) return set.status();
  const std::string hierarchy_key = wire::HierarchyKey(key, volume);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      hierarchy_key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build((*set)->set.spheres, volume);
        if (!h.ok()) return h.status();
        return DecodeHierarchy(h->Serialize());
      },
      DecodeHierarchy);
  if (!found.ok()) return found.status();
  return ObjectOf<SphereHierarchy>(*found, hierarchy_key);
}

absl::StatusOr<std::shared_ptr<const SphereSetEntry>> ResultStore::PutSphereSet(
    SphereSet set, const std::string& mesh_key, bool* already_stored,
    const std::string& derived_from, const std::optional<CoverCertificate>& certificate) {
  if (certificate && !certificate->certified) {
    return absl::InvalidArgumentError(
        "certificate: it does not certify the set (certified is false); send a certified one, "
        "or none and let CertifyCover prove it against the set's mesh");
  }
  if (certificate) {
    if (absl::Status bound = CheckCoverCertificateBinding(*certificate, set.spheres, mesh_key);
        !bound.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("certificate: ", bound.message()));
    }
  }
  if (!mesh_key.empty()) {
    absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = GetMesh(mesh_key);
    if (!mesh.ok()) return mesh.status();
    const std::int64_t triangles = (*mesh)->mesh().num_triangles();
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
  wire::SphereSetToProto(set, result.mutable_spheres());
  if (certificate) {
    result.set_kind(v1::SPHERE_SET_KIND_COVER);
    wire::CoverCertificateToProto(*certificate, result.mutable_cover()->mutable_certificate());
  }
  // The packed arrays of one message serialise the same way for the same numbers.
  const std::string key = wire::UploadedSphereSetKey(
      mesh_key, derived_from, result.spheres().SerializeAsString(),
      certificate ? result.cover().certificate().SerializeAsString() : "");
  result.set_sphere_set_key(key);
  result.set_mesh_sha256(mesh_key);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key, [&]() { return DecodeSphereSet(result.SerializeAsString()); }, DecodeSphereSet);
  if (!found.ok()) return found.status();
  if (already_stored != nullptr) {
    *already_stored = found->source == CacheSource::kMemory || found->source == CacheSource::kDisk;
  }
  return ObjectOf<SphereSetEntry>(*found, key);
}

absl::StatusOr<std::shared_ptr<const CoverCertificate>> ResultStore::CertifySphereSet(
    const std::string& set_key, const std::string& mesh_key, const CoverCertifyOptions& options,
    const GenerationControl& control) {
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set = GetSphereSet(set_key);
  if (!set.ok()) return set.status();
  const std::string key = wire::CoverCertificateKey(set_key, mesh_key, options);
  absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
      key,
      [&]() -> absl::StatusOr<CachedValue> {
        absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = GetMesh(mesh_key);
        if (!mesh.ok()) return mesh.status();
        CoverCertifyOptions unkept = options;
        unkept.max_failures_kept = 0;  // the failed cells are neither stored nor sent
        absl::StatusOr<CoverCertificate> certificate =
            CertifyCover((*mesh)->solid, (*set)->set.spheres, unkept, control);
        if (!certificate.ok()) return certificate.status();
        v1::CoverCertificate stored;
        wire::CoverCertificateToProto(*certificate, &stored);
        return DecodeCertificate(stored.SerializeAsString(), (*set)->set.spheres, mesh_key);
      },
      [&](std::string bytes) {
        return DecodeCertificate(std::move(bytes), (*set)->set.spheres, mesh_key);
      });
  if (!found.ok()) return found.status();
  return ObjectOf<CoverCertificate>(*found, key);
}

absl::StatusOr<CoverCertificate> ResultStore::CoverCertificateOf(const std::string& set_key) {
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set = GetSphereSet(set_key);
  if (!set.ok()) return set.status();
  const v1::GenerateResult& result = (*set)->result;
  CoverCertificate certificate;
  if (result.has_cover()) {
    absl::StatusOr<CoverCertificate> held =
        wire::CoverCertificateFromProto(result.cover().certificate());
    if (!held.ok()) return held.status();
    certificate = *std::move(held);
  } else if (!result.mesh_sha256().empty()) {
    absl::StatusOr<std::shared_ptr<const CoverCertificate>> proved =
        CertifySphereSet(set_key, result.mesh_sha256(), CoverCertifyOptions());
    if (!proved.ok()) return proved.status();
    certificate = **proved;
  } else {
    return absl::FailedPreconditionError(absl::StrCat(
        "sphere set ", set_key,
        " has no cover certificate and names no mesh to prove one against: generate it as a "
        "cover, or upload it with its mesh or with its certificate"));
  }
  if (!certificate.certified) {
    return absl::FailedPreconditionError(NotACover(set_key, result.mesh_sha256(), certificate));
  }
  return certificate;
}

absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> ResultStore::GetCertifiedObject(
    const std::string& internal_key, const std::string& cover_key, HierarchyVolume volume) {
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> internal = GetSphereSet(internal_key);
  if (!internal.ok()) return internal.status();
  const v1::SphereSetKind kind = (*internal)->result.kind();
  if (kind == v1::SPHERE_SET_KIND_COVER || kind == v1::SPHERE_SET_KIND_DILATED ||
      (*internal)->result.has_dilation()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "sphere set ", internal_key, " is ",
        kind == v1::SPHERE_SET_KIND_COVER ? "a cover" : "dilated",
        ": the upper bound of a certified distance needs spheres inside the solid (generate "
        "them without dilate or cover)"));
  }
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> cover = GetSphereSet(cover_key);
  if (!cover.ok()) return cover.status();
  const std::string& internal_mesh = (*internal)->result.mesh_sha256();
  const std::string& cover_mesh = (*cover)->result.mesh_sha256();
  if (!internal_mesh.empty() && !cover_mesh.empty() && internal_mesh != cover_mesh) {
    return absl::InvalidArgumentError(absl::StrCat("sphere set ", internal_key, " is of mesh ",
                                                   internal_mesh, " but its cover ", cover_key,
                                                   " of mesh ", cover_mesh));
  }
  absl::StatusOr<CoverCertificate> certificate = CoverCertificateOf(cover_key);
  if (!certificate.ok()) return certificate.status();
  if (!internal_mesh.empty() && certificate->mesh_sha256 != internal_mesh) {
    return absl::InvalidArgumentError(
        absl::StrCat("sphere set ", internal_key, " is of mesh ", internal_mesh, " but its cover ",
                     cover_key, " was certified for mesh ", certificate->mesh_sha256));
  }
  // The internal set with the cover's cores (UpperBoundSpheres), when the certificate gives
  // them; else the internal set's own hierarchy.
  absl::StatusOr<std::shared_ptr<const SphereHierarchy>> internal_h;
  if (certificate->protrusions.empty()) {
    internal_h = GetHierarchy(internal_key, volume);
  } else {
    const std::string upper_key = wire::UpperBoundHierarchyKey(internal_key, cover_key, volume);
    absl::StatusOr<CacheLookup> found = cache_->GetOrCompute(
        upper_key,
        [&]() -> absl::StatusOr<CachedValue> {
          absl::StatusOr<std::vector<Sphere>> spheres = UpperBoundSpheres(
              (*internal)->set.spheres, (*cover)->set.spheres, certificate->protrusions);
          if (!spheres.ok()) {
            return absl::FailedPreconditionError(
                absl::StrCat("cover ", cover_key, ": ", spheres.status().message()));
          }
          absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(*spheres, volume);
          if (!h.ok()) return h.status();
          return DecodeHierarchy(h->Serialize());
        },
        DecodeHierarchy);
    if (!found.ok()) return found.status();
    internal_h = ObjectOf<SphereHierarchy>(*found, upper_key);
  }
  if (!internal_h.ok()) return internal_h.status();
  absl::StatusOr<std::shared_ptr<const SphereHierarchy>> cover_h = GetHierarchy(cover_key, volume);
  if (!cover_h.ok()) return cover_h.status();
  return std::make_shared<const CertifiedObjectEntry>(*std::move(internal_h), *std::move(cover_h),
                                                      certificate->delta);
}

absl::StatusOr<std::shared_ptr<const DeformerEntry>> ResultStore::GetDeformer(
    const std::string& mesh_key, const std::string& set_key, const DeformationOptions& options) {
  const std::string key = wire::DeformerKey(mesh_key, set_key, options);
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
            SphereDeformer::Create((*mesh)->mesh(), (*set)->set, options);
        if (!deformer.ok()) {
          return absl::FailedPreconditionError(absl::StrCat("sphere set ", set_key,
                                                            " does not fit mesh ", mesh_key, ": ",
                                                            deformer.status().message()));
        }
        auto entry = std::make_shared<const DeformerEntry>(mesh_key, (*mesh)->mesh().triangles,
                                                           *std::move(deformer));
        CachedValue value;
        value.persist = false;
        // The reference mesh, its oracle and the per-sphere frames.
        value.object_bytes =
            MeshObjectBytes((*mesh)->mesh()) + 96 * static_cast<std::int64_t>((*set)->set.size());
        value.object = std::shared_ptr<const DeformerEntry>(std::move(entry));
        return value;
      },
      [](std::string) -> absl::StatusOr<CachedValue> {
        return absl::DataLossError("deformers are never stored on disk");
      });
  if (!found.ok()) return found.status();
  return ObjectOf<DeformerEntry>(*found, key);
}

}  // namespace inscribe::server
