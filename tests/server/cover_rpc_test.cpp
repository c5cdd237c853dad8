// Covers through the service: Generate with cover, certified Distance and DistanceStream, the
// certificate rule, and the Client's typed view of them, against the real server in-process on
// loopback (disk cache in a temporary directory).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cache_entry_format.h"
#include "inscribe/client/client.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/solid/solid.h"
#include "spheres_rpc_fixture.h"
#include "support/sphere_sets.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

class CoverRpcTest : public SpheresRpcTest {
 protected:
  std::unique_ptr<client::Client> MakeClient() {
    return std::make_unique<client::Client>(client::MakeGrpcConnection(server_->address()));
  }

  static v1::GenerateRequest CoverRequest(const std::string& mesh_key, std::int64_t max_spheres) {
    v1::GenerateRequest request;
    request.set_mesh_sha256(mesh_key);
    request.mutable_parameters()->set_max_spheres(max_spheres);
    request.mutable_parameters()->set_cover(true);
    request.set_skip_quality(true);
    return request;
  }
};

const Mesh& Slab() {
  static const Mesh slab = testing::Box(Vector3::Zero(), Vector3(2.0, 1.0, 0.5));
  return slab;
}

// A generated cover carries its certificate through the cache (memory, then disk after a
// restart), under a key of its own; the certificate is the one core proves for that set.
TEST_F(CoverRpcTest, GenerateMakesACertifiedCoverAndCachesItsCertificate) {
  const std::string mesh = PutMesh(Slab());
  v1::GenerateResult cover, again, restarted, internal;
  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &cover).ok());
  EXPECT_EQ(cover.cache(), "computed");
  EXPECT_EQ(cover.kind(), v1::SPHERE_SET_KIND_COVER);
  ASSERT_TRUE(cover.has_cover());
  const v1::CoverCertificate& certificate = cover.cover().certificate();
  EXPECT_TRUE(certificate.certified());
  EXPECT_GE(certificate.delta(), 0.0);
  EXPECT_EQ(certificate.failed_cells(), 0);
  EXPECT_EQ(cover.spheres().contact_triangles_size(), 0);
  EXPECT_FALSE(cover.has_quality());

  // Core agrees: the set is a cover with this delta.
  absl::StatusOr<SphereSet> spheres = wire::SphereSetFromProto(cover.spheres());
  ASSERT_TRUE(spheres.ok()) << spheres.status();
  absl::StatusOr<Solid> solid = PrepareSolid(Slab());
  ASSERT_TRUE(solid.ok()) << solid.status();
  absl::StatusOr<CoverCertificate> core = CertifyCover(*solid, spheres->spheres);
  ASSERT_TRUE(core.ok()) << core.status();
  EXPECT_TRUE(core->certified);
  EXPECT_EQ(core->delta, certificate.delta());
  // It names what it proved: the stored mesh and these spheres.
  EXPECT_EQ(certificate.mesh_sha256(), mesh);
  EXPECT_EQ(certificate.spheres_sha256(), FormatSha256(SpheresSha256(spheres->spheres)));

  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &again).ok());
  EXPECT_EQ(again.cache(), "memory");
  EXPECT_EQ(again.cover().SerializeAsString(), cover.cover().SerializeAsString());
  Restart();
  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &restarted).ok());
  EXPECT_EQ(restarted.cache(), "disk");
  EXPECT_EQ(restarted.kind(), v1::SPHERE_SET_KIND_COVER);
  EXPECT_EQ(restarted.cover().SerializeAsString(), cover.cover().SerializeAsString());

  v1::GenerateRequest plain = CoverRequest(mesh, 30);
  plain.mutable_parameters()->set_cover(false);
  ASSERT_TRUE(Generate(plain, &internal).ok());
  EXPECT_EQ(internal.kind(), v1::SPHERE_SET_KIND_INTERNAL);
  EXPECT_FALSE(internal.has_cover());
  EXPECT_NE(internal.sphere_set_key(), cover.sphere_set_key());
}

TEST_F(CoverRpcTest, ClientGeneratesACoverAndTheServerRefusesBadCombinations) {
  const std::unique_ptr<client::Client> client = MakeClient();
  client::GenerateSettings settings;
  settings.parameters.kind = SphereSetKind::kCover;
  settings.parameters.max_spheres = 30;
  absl::StatusOr<client::GenerateResult> generated = client->Generate(Slab(), settings);
  ASSERT_TRUE(generated.ok()) << generated.status();
  EXPECT_EQ(generated->kind, SphereSetKind::kCover);
  ASSERT_TRUE(generated->cover.has_value());
  EXPECT_TRUE(generated->cover->certificate.certified);
  EXPECT_LE(generated->set.size(), 30u);
  ASSERT_TRUE(generated->quality.has_value());
  EXPECT_EQ(generated->quality->coverage, 1.0);

  // The raw request with the same settings names the same cached set.
  v1::GenerateResult raw;
  v1::GenerateRequest request = CoverRequest(generated->mesh_sha256, 30);
  request.set_skip_quality(false);
  ASSERT_TRUE(Generate(request, &raw).ok());
  EXPECT_EQ(raw.sphere_set_key(), generated->sphere_set_key);
  EXPECT_EQ(raw.cache(), "memory");

  // The client refuses what core refuses, before sending.
  settings.parameters.max_protrusion = 0.1;
  absl::StatusOr<client::GenerateResult> both = client->Generate(Slab(), settings);
  EXPECT_EQ(both.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(both.status().message(), HasSubstr("not both"));
  // The server refuses what the wire can say but core cannot.
  request.mutable_parameters()->set_dilate(true);
  grpc::Status refused = Generate(request, &raw);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("dilate and cover"));
  request.mutable_parameters()->set_dilate(false);
  request.mutable_parameters()->set_cover_resolution(2.0);
  refused = Generate(request, &raw);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("resolution"));
}

// Two solids, each with an internal set and a cover, generated through a Client.
struct CertifiedSolids {
  client::GenerateResult internal[2], cover[2];
};

CertifiedSolids GenerateSolids(const client::Client& client) {
  const Mesh bar = testing::Box(Vector3::Zero(), Vector3(1.0, 0.4, 0.4));
  CertifiedSolids out;
  for (int k = 0; k < 2; ++k) {
    client::GenerateSettings settings;
    settings.parameters.max_spheres = 30;
    settings.parameters.evaluate = false;
    absl::StatusOr<client::GenerateResult> internal =
        client.Generate(k == 0 ? Slab() : bar, settings);
    EXPECT_TRUE(internal.ok()) << internal.status();
    settings.parameters.kind = SphereSetKind::kCover;
    absl::StatusOr<client::GenerateResult> cover = client.Generate(k == 0 ? Slab() : bar, settings);
    EXPECT_TRUE(cover.ok()) << cover.status();
    if (!internal.ok() || !cover.ok()) return out;
    out.internal[k] = *std::move(internal);
    out.cover[k] = *std::move(cover);
  }
  return out;
}

// Certified Distance and DistanceStream give, for every pose, exactly the interval the rule of
// certified_distance.h makes of the brute-force sphere distances (covers: lower; the covers'
// cores, and deltas: upper) and the answer DecideCloser gives; the
// stream answers as the batch.
TEST_F(CoverRpcTest, CertifiedIntervalsHoldTheBruteForceSphereDistances) {
  const std::unique_ptr<client::Client> client = MakeClient();
  const CertifiedSolids solids = GenerateSolids(*client);
  ASSERT_FALSE(solids.cover[1].sphere_set_key.empty());
  std::mt19937_64 rng(11);
  std::vector<RigidPose> poses_b;
  for (int i = 0; i < 200; ++i) poses_b.push_back(testing::RandomPose(rng, 2.5));
  const std::vector<RigidPose> origin = {RigidPose()};
  client::DistanceOptions options;
  options.cover_a = solids.cover[0].sphere_set_key;
  options.cover_b = solids.cover[1].sphere_set_key;
  options.tolerance.closer_than = 0.3;
  absl::StatusOr<client::DistanceBatchResult> batch =
      client->Distance(solids.internal[0].sphere_set_key, solids.internal[1].sphere_set_key, origin,
                       poses_b, options);
  ASSERT_TRUE(batch.ok()) << batch.status();
  ASSERT_EQ(batch->certified.size(), poses_b.size());
  ASSERT_EQ(batch->results.size(), poses_b.size());
  const double deltas =
      solids.cover[0].cover->certificate.delta + solids.cover[1].cover->certificate.delta;
  std::vector<Sphere> upper_spheres[2];
  for (int k = 0; k < 2; ++k) {
    const CoverCertificate& certificate = solids.cover[k].cover->certificate;
    ASSERT_EQ(certificate.protrusions.size(), solids.cover[k].set.size());
    absl::StatusOr<std::vector<Sphere>> spheres = UpperBoundSpheres(
        solids.internal[k].set.spheres, solids.cover[k].set.spheres, certificate.protrusions);
    ASSERT_TRUE(spheres.ok()) << spheres.status();
    ASSERT_GT(spheres->size(), solids.cover[k].set.size() / 2);
    upper_spheres[k] = *std::move(spheres);
  }
  int decided = 0;
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    SCOPED_TRACE(i);
    const CertifiedDistanceResult& r = batch->certified[i];
    absl::StatusOr<DistanceResult> covers = BruteForceSeparationDistance(
        solids.cover[0].set.spheres, origin[0], solids.cover[1].set.spheres, poses_b[i]);
    absl::StatusOr<DistanceResult> internal =
        BruteForceSeparationDistance(upper_spheres[0], origin[0], upper_spheres[1], poses_b[i]);
    ASSERT_TRUE(covers.ok() && internal.ok());
    const double lower = std::max(0.0, covers->distance);
    const double upper = std::max(0.0, std::min(internal->distance, lower + deltas));
    EXPECT_LE(r.lower, lower);
    EXPECT_NEAR(r.lower, lower, 1e-9);
    EXPECT_GE(r.upper, upper);
    EXPECT_NEAR(r.upper, upper, 1e-9);
    EXPECT_LE(r.lower, r.upper);
    EXPECT_NEAR(batch->results[i].distance, internal->distance, 1e-9);
    EXPECT_EQ(r.closer, DecideCloser(r.lower, r.upper, 0.3));
    decided += r.closer != CloserAnswer::kUndecided;
  }
  EXPECT_GT(decided, 100);  // most poses are clearly apart or clearly close

  client::DistanceSessionOptions session_options;
  session_options.tolerance.closer_than = 0.3;
  absl::StatusOr<client::DistanceSession> session = client->OpenDistanceSession(session_options);
  ASSERT_TRUE(session.ok()) << session.status();
  std::vector<client::PosePair> pairs;
  for (std::size_t i = 0; i < 20; ++i) {
    pairs.push_back(client::PosePair{solids.internal[0].sphere_set_key,
                                     solids.internal[1].sphere_set_key, origin[0], poses_b[i],
                                     options.cover_a, options.cover_b});
  }
  absl::StatusOr<std::vector<CertifiedDistanceResult>> frame = session->QueryCertified(pairs);
  ASSERT_TRUE(frame.ok()) << frame.status();
  ASSERT_EQ(frame->size(), pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_EQ((*frame)[i].lower, batch->certified[i].lower) << i;
    EXPECT_EQ((*frame)[i].upper, batch->certified[i].upper) << i;
    EXPECT_EQ((*frame)[i].closer, batch->certified[i].closer) << i;
  }
  // A frame mixing certified and plain pairs ends the stream.
  pairs.back().cover_a.clear();
  pairs.back().cover_b.clear();
  absl::StatusOr<std::vector<CertifiedDistanceResult>> mixed = session->QueryCertified(pairs);
  EXPECT_EQ(mixed.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(mixed.status().message(), HasSubstr("all certified"));
}

// The certificate rule: a set serves as a cover only with a certificate the server holds.
TEST_F(CoverRpcTest, ASetIsACoverOnlyWithACertificateTheServerHolds) {
  const std::unique_ptr<client::Client> client = MakeClient();
  const CertifiedSolids solids = GenerateSolids(*client);
  ASSERT_FALSE(solids.cover[1].sphere_set_key.empty());
  const std::string& a = solids.internal[0].sphere_set_key;
  const std::string& b = solids.internal[1].sphere_set_key;
  const std::vector<RigidPose> origin = {RigidPose()};
  RigidPose apart;
  apart.translation = Vector3(4, 0, 0);
  const auto certified = [&](const std::string& internal_a, const std::string& cover_a,
                             const std::string& cover_b) {
    client::DistanceOptions options;
    options.cover_a = cover_a;
    options.cover_b = cover_b;
    return client->Distance(internal_a, b, origin, {apart}, options);
  };
  ASSERT_TRUE(certified(a, solids.cover[0].sphere_set_key, solids.cover[1].sphere_set_key).ok());

  // Generate's internal set names its mesh, so the server certifies it on first use: it is
  // not a cover, and the refusal names its key and a point it misses.
  absl::StatusOr<client::DistanceBatchResult> refused =
      certified(a, a, solids.cover[1].sphere_set_key);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.status().message(), HasSubstr("sphere set " + a + " is not a cover"));
  EXPECT_THAT(refused.status().message(), HasSubstr("the point ("));

  // The cover's spheres uploaded without a mesh or a certificate: nothing to prove them by.
  absl::StatusOr<client::PutSphereSetResult> loose = client->PutSphereSet(solids.cover[0].set);
  ASSERT_TRUE(loose.ok()) << loose.status();
  refused = certified(a, loose->sphere_set_key, solids.cover[1].sphere_set_key);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.status().message(),
              HasSubstr("sphere set " + loose->sphere_set_key + " has no cover certificate"));

  // With its mesh, the server proves it on first use and keeps the proof: CertifyCover by key
  // afterwards computes nothing.
  absl::StatusOr<client::PutSphereSetResult> with_mesh =
      client->PutSphereSet(solids.cover[0].set, solids.cover[0].mesh_sha256);
  ASSERT_TRUE(with_mesh.ok()) << with_mesh.status();
  EXPECT_TRUE(certified(a, with_mesh->sphere_set_key, solids.cover[1].sphere_set_key).ok());
  const std::int64_t computations = Stats().computations();
  absl::StatusOr<CoverCertificate> proof =
      client->CertifyCover(solids.cover[0].mesh_sha256, with_mesh->sphere_set_key);
  ASSERT_TRUE(proof.ok()) << proof.status();
  EXPECT_TRUE(proof->certified);
  EXPECT_EQ(proof->delta, solids.cover[0].cover->certificate.delta);
  EXPECT_EQ(Stats().computations(), computations);

  // With a certificate: taken on the uploader's word, and keyed with it; one that does not
  // certify is refused.
  absl::StatusOr<client::PutSphereSetResult> vouched =
      client->PutCertifiedCover(solids.cover[0].set, solids.cover[0].cover->certificate);
  ASSERT_TRUE(vouched.ok()) << vouched.status();
  EXPECT_NE(vouched->sphere_set_key, loose->sphere_set_key);
  EXPECT_TRUE(certified(a, vouched->sphere_set_key, solids.cover[1].sphere_set_key).ok());
  CoverCertificate failed = solids.cover[0].cover->certificate;
  failed.certified = false;
  absl::StatusOr<client::PutSphereSetResult> bad =
      client->PutCertifiedCover(solids.cover[0].set, failed);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("certificate"));
  // Protrusions that are not one per sphere are refused (they would make wrong cores).
  CoverCertificate short_protrusions = solids.cover[0].cover->certificate;
  short_protrusions.protrusions.pop_back();
  bad = client->PutCertifiedCover(solids.cover[0].set, short_protrusions);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("protrusions for"));
  // A certificate of other spheres, of another mesh, or naming none is refused too.
  SphereSet scaled = solids.cover[0].set;
  for (Sphere& s : scaled.spheres) s.radius *= 0.97;
  bad = client->PutCertifiedCover(scaled, solids.cover[0].cover->certificate);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("edited after they were certified"));

  // A cover (or dilated set) as the internal set; covers of another mesh.
  refused = certified(solids.cover[0].sphere_set_key, solids.cover[0].sphere_set_key,
                      solids.cover[1].sphere_set_key);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.status().message(), HasSubstr("is a cover"));
  refused = certified(a, solids.cover[1].sphere_set_key, solids.cover[1].sphere_set_key);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("but its cover"));

  // One cover without the other, tolerances, brute force.
  EXPECT_EQ(certified(a, solids.cover[0].sphere_set_key, "").status().code(),
            absl::StatusCode::kInvalidArgument);
  client::DistanceOptions loose_tolerance;
  loose_tolerance.cover_a = solids.cover[0].sphere_set_key;
  loose_tolerance.cover_b = solids.cover[1].sphere_set_key;
  loose_tolerance.tolerance.abs_err = 0.01;
  refused = client->Distance(a, b, origin, {apart}, loose_tolerance);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("abs_err"));
  loose_tolerance.tolerance.abs_err = 0.0;
  loose_tolerance.brute_force = true;
  EXPECT_EQ(client->Distance(a, b, origin, {apart}, loose_tolerance).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// PutSphereSet with a certificate that does not name the set it comes with: INVALID_ARGUMENT
// naming the mismatch, whatever else the request holds.
TEST_F(CoverRpcTest, PutSphereSetRefusesACertificateOfAnythingElse) {
  const std::string slab = PutMesh(Slab());
  const std::string bar = PutMesh(testing::Box(Vector3::Zero(), Vector3(1.0, 0.4, 0.4)));
  v1::GenerateResult cover;
  ASSERT_TRUE(Generate(CoverRequest(slab, 20), &cover).ok());
  const auto put = [&](const v1::SphereSet& spheres, const v1::CoverCertificate& certificate,
                       const std::string& mesh) {
    v1::PutSphereSetRequest request;
    *request.mutable_spheres() = spheres;
    *request.mutable_certificate() = certificate;
    request.set_mesh_sha256(mesh);
    v1::PutSphereSetResponse response;
    return stub_->PutSphereSet(Context().get(), request, &response);
  };
  const v1::CoverCertificate& certificate = cover.cover().certificate();
  ASSERT_TRUE(put(cover.spheres(), certificate, "").ok());
  ASSERT_TRUE(put(cover.spheres(), certificate, slab).ok());

  struct Case {
    const char* what;
    v1::SphereSet spheres;
    v1::CoverCertificate certificate;
    std::string mesh;
    const char* message;
  };
  std::vector<Case> cases;
  for (const double scale : {1.03, 0.97}) {
    Case grown{"radii scaled", cover.spheres(), certificate, "", "edited after"};
    for (double& r : *grown.spheres.mutable_radii()) r *= scale;
    cases.push_back(grown);
  }
  Case nudged{"a centre nudged", cover.spheres(), certificate, slab, "other spheres"};
  nudged.spheres.set_centers(1, nudged.spheres.centers(1) + 1e-9);
  cases.push_back(nudged);
  Case dropped{"a sphere dropped", cover.spheres(), certificate, "", "other spheres"};
  dropped.spheres.mutable_radii()->RemoveLast();
  for (int k = 0; k < 3; ++k) dropped.spheres.mutable_centers()->RemoveLast();
  cases.push_back(dropped);
  cases.push_back({"another mesh", cover.spheres(), certificate, bar, "proved against mesh"});
  Case unnamed{"no spheres named", cover.spheres(), certificate, "", "names no spheres"};
  unnamed.certificate.clear_spheres_sha256();
  cases.push_back(unnamed);
  Case meshless{"no mesh named", cover.spheres(), certificate, "", "names no mesh"};
  meshless.certificate.clear_mesh_sha256();
  cases.push_back(meshless);
  Case edited{"its hash edited", cover.spheres(), certificate, "", "other spheres"};
  edited.certificate.set_spheres_sha256("sha256:" + std::string(64, '0'));
  cases.push_back(edited);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const grpc::Status status = put(c.spheres, c.certificate, c.mesh);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("certificate: "));
    EXPECT_THAT(status.error_message(), HasSubstr(c.message));
  }
}

// A cached cover whose certificate names nothing (as written before certificates named their
// spheres and mesh) is not served: the cover is generated again, certificate and all.
TEST_F(CoverRpcTest, ACachedCoverWithAnUnboundCertificateIsGeneratedAgain) {
  const std::string mesh = PutMesh(Slab());
  v1::GenerateResult cover;
  ASSERT_TRUE(Generate(CoverRequest(mesh, 20), &cover).ok());
  const std::string& key = cover.sphere_set_key();
  server_.reset();
  const std::string hex = Sha256Hex(key);
  const std::filesystem::path path = cache_dir_ / hex.substr(0, 2) / hex;
  std::string entry;
  {
    std::ifstream in(path, std::ios::binary);
    ASSERT_TRUE(in) << path;
    entry.assign(std::istreambuf_iterator<char>(in), {});
  }
  v1::GenerateResult stale;
  ASSERT_TRUE(stale.ParseFromString(entry.substr(EntryHeaderSize(key.size()))));
  stale.mutable_cover()->mutable_certificate()->clear_mesh_sha256();
  stale.mutable_cover()->mutable_certificate()->clear_spheres_sha256();
  const std::string payload = stale.SerializeAsString();
  std::ofstream(path, std::ios::binary | std::ios::trunc) << EntryHeader(key, payload) << payload;
  Restart();

  v1::GetSphereSetRequest get;
  get.set_sphere_set_key(key);
  v1::GetSphereSetResponse got;
  EXPECT_EQ(stub_->GetSphereSet(Context().get(), get, &got).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::GenerateResult again;
  ASSERT_TRUE(Generate(CoverRequest(mesh, 20), &again).ok());
  EXPECT_EQ(again.cache(), "computed");
  EXPECT_EQ(again.sphere_set_key(), key);
  EXPECT_EQ(again.cover().certificate().mesh_sha256(), mesh);
  EXPECT_EQ(again.cover().certificate().spheres_sha256(),
            cover.cover().certificate().spheres_sha256());
}

}  // namespace
}  // namespace inscribe::server
