// PutSphereSet, UpdateDeformation, Evaluate and DistanceStream against the real server
// in-process on loopback; answers checked against the core library called directly (the
// deformer, EvaluateSpheres, brute-force distance) on CGAL's demo meshes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/solid/boundary_oracle.h"
#include "spheres_rpc_fixture.h"
#include "support/sphere_sets.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

class StreamRpcTest : public SpheresRpcTest {
 protected:
  // Generates (cached) spheres for `mesh`; the set's key and its spheres.
  std::pair<std::string, SphereSet> Spheres(const std::string& mesh_key, double voxel_size,
                                            bool dilate = false) {
    v1::GenerateRequest request = SphereRequest(mesh_key, voxel_size);
    request.mutable_parameters()->set_dilate(dilate);
    request.set_skip_quality(true);
    v1::GenerateResult result;
    const grpc::Status s = Generate(request, &result);
    EXPECT_TRUE(s.ok()) << s.error_message();
    absl::StatusOr<SphereSet> set = wire::SphereSetFromProto(result.spheres());
    EXPECT_TRUE(set.ok()) << set.status();
    return {result.sphere_set_key(), set.ok() ? *set : SphereSet{}};
  }

  grpc::Status PutSpheres(const SphereSet& set, const std::string& mesh_key,
                          v1::PutSphereSetResponse* response) {
    v1::PutSphereSetRequest request;
    wire::SphereSetToProto(set, request.mutable_spheres());
    request.set_mesh_sha256(mesh_key);
    return stub_->PutSphereSet(Context().get(), request, response);
  }

  grpc::Status Deform(const std::string& set_key, const Vertices& vertices,
                      v1::UpdateDeformationResponse* response, bool bounds = false) {
    v1::UpdateDeformationRequest request;
    request.set_sphere_set_key(set_key);
    for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
      for (int k = 0; k < 3; ++k) request.add_vertices(vertices(v, k));
    }
    request.set_bounds(bounds);
    return stub_->UpdateDeformation(Context().get(), request, response);
  }
};

TEST_F(StreamRpcTest, PutSphereSetKeysByContentAndChecksTheSet) {
  const std::string mesh = PutMesh(testing::UnitCube());
  SphereSet set;
  set.spheres = {{Vector3(0.5, 0.5, 0.5), 0.5}, {Vector3(0.25, 0.25, 0.25), 0.25}};
  v1::PutSphereSetResponse first, again, other_mesh, no_mesh;
  ASSERT_TRUE(PutSpheres(set, mesh, &first).ok());
  EXPECT_THAT(first.sphere_set_key(), ::testing::StartsWith("spheres/v1/"));
  EXPECT_FALSE(first.already_stored());
  ASSERT_TRUE(PutSpheres(set, mesh, &again).ok());
  EXPECT_TRUE(again.already_stored());
  EXPECT_EQ(again.sphere_set_key(), first.sphere_set_key());
  ASSERT_TRUE(PutSpheres(set, "", &no_mesh).ok());
  EXPECT_NE(no_mesh.sphere_set_key(), first.sphere_set_key());
  set.spheres[1].radius = 0.2500001;
  ASSERT_TRUE(PutSpheres(set, mesh, &other_mesh).ok());
  EXPECT_NE(other_mesh.sphere_set_key(), first.sphere_set_key());

  // The stored set reads back as sent, naming its mesh.
  v1::GetSphereSetRequest get;
  get.set_sphere_set_key(first.sphere_set_key());
  v1::GetSphereSetResponse got;
  ASSERT_TRUE(stub_->GetSphereSet(Context().get(), get, &got).ok());
  EXPECT_EQ(got.mesh_sha256(), mesh);
  ASSERT_EQ(got.spheres().radii_size(), 2);
  EXPECT_EQ(got.spheres().radii(1), 0.25);

  v1::PutSphereSetResponse response;
  SphereSet bad = set;
  bad.spheres[1].radius = -1.0;
  grpc::Status s = PutSpheres(bad, mesh, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("sphere 1"));
  s = PutSpheres(set, "sha256:" + std::string(64, 'c'), &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  SphereSet contacts = set;
  contacts.contacts = {{0, Vector3(1, 0, 0)}, {12, Vector3(1, 0, 0)}};  // the cube has 12
  s = PutSpheres(contacts, mesh, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("triangle 12"));
}

TEST_F(StreamRpcTest, PutSphereSetOverTheLimitIsResourceExhausted) {
  configure_ = [](ServerOptions& options) { options.limits.max_spheres = 10; };
  Restart();
  SphereSet set;
  set.spheres.assign(11, Sphere{Vector3::Zero(), 1.0});
  v1::PutSphereSetResponse response;
  const grpc::Status s = PutSpheres(set, "", &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(s.error_message(), HasSubstr("--max-spheres"));
}

// The server's update equals the core deformer's on the same reference, frame after frame,
// and the deformer is kept between calls (a cache hit, no new computation).
TEST_F(StreamRpcTest, UpdateDeformationMatchesTheCoreDeformerAndKeepsIt) {
  INSCRIBE_REQUIRE_MESH("elephant.off");
  const Mesh elephant = testing::LoadTestMesh("elephant.off");
  const std::string mesh = PutMesh(elephant);
  const auto [key, set] = Spheres(mesh, 0.04);
  ASSERT_TRUE(set.has_contacts());
  absl::StatusOr<SphereDeformer> local = SphereDeformer::Create(elephant, set);
  ASSERT_TRUE(local.ok()) << local.status();

  for (int frame = 0; frame < 3; ++frame) {
    SCOPED_TRACE(frame);
    // A bend that grows with the frame: y moves with x squared.
    Vertices moved = elephant.vertices;
    for (Eigen::Index v = 0; v < moved.rows(); ++v) {
      moved(v, 1) += 0.2 * frame * moved(v, 0) * moved(v, 0);
    }
    const std::int64_t computations = Stats().computations();
    v1::UpdateDeformationResponse response;
    const grpc::Status s = Deform(key, moved, &response, /*bounds=*/true);
    ASSERT_TRUE(s.ok()) << s.error_message();
    if (frame > 0) {
      EXPECT_EQ(Stats().computations(), computations);  // deformer reused
    }
    absl::StatusOr<DeformedSpheres> expected = local->Update(moved);
    ASSERT_TRUE(expected.ok()) << expected.status();
    absl::StatusOr<SphereSet> got = wire::SphereSetFromProto(response.spheres());
    ASSERT_TRUE(got.ok());
    ASSERT_EQ(got->size(), expected->set.size());
    for (std::size_t i = 0; i < got->size(); ++i) {
      EXPECT_NEAR((got->spheres[i].center - expected->set.spheres[i].center).norm(), 0.0, 1e-12);
      EXPECT_NEAR(got->spheres[i].radius, expected->set.spheres[i].radius, 1e-12);
    }
    EXPECT_EQ(response.shrunk(), expected->shrunk);
    EXPECT_EQ(response.xi(), expected->xi);
    EXPECT_EQ(response.reference_spheres(), static_cast<std::int64_t>(set.size()));
    absl::StatusOr<DeformationErrorBounds> bounds =
        BoundDeformationError(local->oracle(), expected->set.spheres, expected->xi);
    ASSERT_TRUE(bounds.ok());
    EXPECT_NEAR(response.nerr_lower(), bounds->nerr_lower, 1e-12);
    EXPECT_NEAR(response.nerr_upper(), bounds->nerr_upper, 1e-12);
    EXPECT_LE(response.nerr_lower(), response.nerr_upper());
    EXPECT_EQ(response.deformed_mesh_sha256(),
              FormatSha256(MeshSha256(Mesh{moved, elephant.triangles})));
  }
}

TEST_F(StreamRpcTest, UpdateDeformationByTranslationMovesEverySphereAndStoresOnRequest) {
  const Mesh ball = testing::Icosphere(3);
  const std::string mesh = PutMesh(ball);
  const auto [key, set] = Spheres(mesh, 0.15);
  const Vector3 shift(1.5, -2.0, 0.25);
  Vertices moved = ball.vertices;
  moved.rowwise() += shift.transpose();
  v1::UpdateDeformationRequest request;
  request.set_sphere_set_key(key);
  request.set_mesh_sha256(mesh);
  for (Eigen::Index v = 0; v < moved.rows(); ++v) {
    for (int k = 0; k < 3; ++k) request.add_vertices(moved(v, k));
  }
  request.set_store(true);
  v1::UpdateDeformationResponse response;
  const grpc::Status s = stub_->UpdateDeformation(Context().get(), request, &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  absl::StatusOr<SphereSet> got = wire::SphereSetFromProto(response.spheres());
  ASSERT_TRUE(got.ok());
  ASSERT_EQ(got->size(), set.size());
  for (std::size_t i = 0; i < set.size(); ++i) {
    EXPECT_NEAR((got->spheres[i].center - set.spheres[i].center - shift).norm(), 0.0, 1e-9);
    EXPECT_NEAR(got->spheres[i].radius, set.spheres[i].radius, 1e-9);
  }
  EXPECT_EQ(response.shrunk(), 0);

  // The stored moved set serves Distance: against the original at the identity, the two
  // unions are as far apart as brute force says.
  ASSERT_THAT(response.sphere_set_key(), ::testing::StartsWith("spheres/v1/"));
  v1::DistanceRequest distance;
  distance.set_sphere_set_a(key);
  distance.set_sphere_set_b(response.sphere_set_key());
  wire::PosesToProto({RigidPose{}}, distance.mutable_poses_a());
  wire::PosesToProto({RigidPose{}}, distance.mutable_poses_b());
  v1::DistanceResponse answer;
  ASSERT_TRUE(stub_->Distance(Context().get(), distance, &answer).ok());
  absl::StatusOr<DistanceResult> brute =
      BruteForceSeparationDistance(set.spheres, RigidPose{}, got->spheres, RigidPose{});
  ASSERT_TRUE(brute.ok());
  EXPECT_NEAR(answer.results().distances(0), brute->distance, 1e-9);
}

TEST_F(StreamRpcTest, UpdateDeformationErrorsHaveTheirCodes) {
  const Mesh ball = testing::Icosphere(2);
  const std::string mesh = PutMesh(ball);
  const auto [key, set] = Spheres(mesh, 0.2);
  v1::UpdateDeformationResponse response;

  Vertices short_by_one = ball.vertices.topRows(ball.vertices.rows() - 1);
  grpc::Status s = Deform(key, short_by_one, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("vertices has"));

  Vertices nan = ball.vertices;
  nan(3, 1) = std::nan("");
  s = Deform(key, nan, &response);  // an unusable mesh, as PutMesh's
  EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(s.error_message(), HasSubstr("vertex 3"));

  Vertices mirrored = ball.vertices;  // a mirror image encloses negative volume
  mirrored.col(0) *= -1.0;
  EXPECT_EQ(Deform(key, mirrored, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  EXPECT_EQ(Deform("spheres/v1/" + std::string(64, 'd'), ball.vertices, &response).error_code(),
            grpc::StatusCode::NOT_FOUND);

  const auto dilated = Spheres(mesh, 0.2, /*dilate=*/true);
  s = Deform(dilated.first, ball.vertices, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(s.error_message(), HasSubstr("no contacts"));

  v1::PutSphereSetResponse uploaded;
  ASSERT_TRUE(PutSpheres(set, "", &uploaded).ok());
  s = Deform(uploaded.sphere_set_key(), ball.vertices, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("mesh_sha256 is required"));
}

TEST_F(StreamRpcTest, EvaluateByKeyAndInlineEqualsTheLibrary) {
  INSCRIBE_REQUIRE_MESH("knot1.off");
  const Mesh knot = testing::LoadTestMesh("knot1.off");
  const std::string mesh = PutMesh(knot);
  const auto [key, set] = Spheres(mesh, 0.05);
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(knot);
  ASSERT_TRUE(oracle.ok());
  QualityOptions options;
  options.surface_samples = 20'000;
  options.voxel_size = 0.05;
  absl::StatusOr<QualityReport> expected = EvaluateSpheres(*oracle, set.spheres, options);
  ASSERT_TRUE(expected.ok());

  v1::EvaluateRequest by_key;
  by_key.set_sphere_set_key(key);  // the set names its mesh
  by_key.set_samples(20'000);
  by_key.set_voxel_size(0.05);
  v1::EvaluateRequest inline_set = by_key;
  wire::SphereSetToProto(set, inline_set.mutable_sphere_set());
  inline_set.set_mesh_sha256(mesh);
  for (const v1::EvaluateRequest& request : {by_key, inline_set}) {
    v1::EvaluateResponse response;
    const grpc::Status s = stub_->Evaluate(Context().get(), request, &response);
    ASSERT_TRUE(s.ok()) << s.error_message();
    const v1::QualityReport& q = response.quality();
    EXPECT_EQ(q.spheres(), expected->spheres);
    EXPECT_DOUBLE_EQ(q.volume_union(), expected->volume_union);
    EXPECT_DOUBLE_EQ(q.nerr(), expected->nerr);
    EXPECT_DOUBLE_EQ(q.coverage(), expected->coverage);
    EXPECT_DOUBLE_EQ(q.boundary_to_union_hausdorff(), expected->boundary_to_union_hausdorff);
    EXPECT_EQ(q.surface_samples(), 20'000);
    EXPECT_EQ(q.fat(), expected->fat);
    EXPECT_DOUBLE_EQ(q.fat_up_to_voxel_size(), expected->fat_up_to_voxel_size);
  }

  v1::EvaluateResponse response;
  v1::EvaluateRequest unknown = by_key;
  unknown.set_sphere_set_key("spheres/v1/" + std::string(64, 'e'));
  EXPECT_EQ(stub_->Evaluate(Context().get(), unknown, &response).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::EvaluateRequest greedy = by_key;
  greedy.set_samples(1'000'000'000);
  grpc::Status s = stub_->Evaluate(Context().get(), greedy, &response);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("samples"));
  v1::EvaluateRequest wrong_mesh = by_key;
  wrong_mesh.set_mesh_sha256(PutMesh(testing::UnitCube()));
  EXPECT_EQ(stub_->Evaluate(Context().get(), wrong_mesh, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// Frames answered in order, each pair equal to the brute force over the same spheres.
TEST_F(StreamRpcTest, DistanceStreamAnswersEveryFrameLikeBruteForce) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const std::string eight = PutMesh(testing::LoadTestMesh("eight.off"));
  const std::string ball = PutMesh(testing::Icosphere(2));
  const auto a = Spheres(eight, 0.05, /*dilate=*/true);
  const auto b = Spheres(ball, 0.2, /*dilate=*/true);

  auto context = Context();
  auto stream = stub_->DistanceStream(context.get());
  std::mt19937_64 rng(11);
  for (int frame = 0; frame < 100; ++frame) {
    v1::DistanceFrame request;
    request.set_frame(1000 + frame);
    request.set_volume(frame % 2 == 0 ? v1::RSS : v1::SPHERE);
    std::vector<std::pair<RigidPose, RigidPose>> poses;
    for (int p = 0; p < 3; ++p) {
      v1::DistancePair* pair = request.add_pairs();
      pair->set_sphere_set_a(p == 2 ? b.first : a.first);
      pair->set_sphere_set_b(b.first);
      poses.emplace_back(testing::RandomPose(rng, 2.0), testing::RandomPose(rng, 2.0));
      wire::PoseToProto(poses.back().first, pair->mutable_pose_a());
      wire::PoseToProto(poses.back().second, pair->mutable_pose_b());
    }
    ASSERT_TRUE(stream->Write(request));
    v1::DistanceFrameResult result;
    ASSERT_TRUE(stream->Read(&result));
    EXPECT_EQ(result.frame(), 1000 + frame);
    ASSERT_EQ(result.results().distances_size(), 3);
    for (int p = 0; p < 3; ++p) {
      const SphereSet& first = p == 2 ? b.second : a.second;
      absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(
          first.spheres, poses[p].first, b.second.spheres, poses[p].second);
      ASSERT_TRUE(brute.ok());
      EXPECT_NEAR(result.results().distances(p), brute->distance, 1e-9) << frame << " " << p;
      EXPECT_NEAR(result.results().points_b(3 * p + 2), brute->point_b.z(), 1e-6);
    }
  }
  stream->WritesDone();
  const grpc::Status s = stream->Finish();
  EXPECT_TRUE(s.ok()) << s.error_message();
}

TEST_F(StreamRpcTest, DistanceStreamErrorEndsTheStreamNamingThePair) {
  const std::string ball = PutMesh(testing::Icosphere(2));
  const auto a = Spheres(ball, 0.2, /*dilate=*/true);
  struct Case {
    std::function<void(v1::DistanceFrame&)> spoil;
    grpc::StatusCode code;
    std::string says;
  };
  const std::vector<Case> cases = {
      {[](v1::DistanceFrame& f) {
         f.mutable_pairs(1)->set_sphere_set_b("spheres/v1/" + std::string(64, 'f'));
       },
       grpc::StatusCode::NOT_FOUND, "pairs[1].sphere_set_b"},
      {[](v1::DistanceFrame& f) { f.mutable_pairs(0)->mutable_pose_a()->set_qw(std::nan("")); },
       grpc::StatusCode::INVALID_ARGUMENT, "pairs[0].pose_a"},
      {[](v1::DistanceFrame& f) { f.mutable_tolerance()->set_abs_err(-1.0); },
       grpc::StatusCode::INVALID_ARGUMENT, "abs_err"},
      {[](v1::DistanceFrame& f) {
         for (int i = 0; i < 5001; ++i) *f.add_pairs() = f.pairs(0);
       },
       grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-poses"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.says);
    auto context = Context();
    auto stream = stub_->DistanceStream(context.get());
    v1::DistanceFrame frame;
    for (int p = 0; p < 2; ++p) {
      v1::DistancePair* pair = frame.add_pairs();
      pair->set_sphere_set_a(a.first);
      pair->set_sphere_set_b(a.first);
      wire::PoseToProto(RigidPose{}, pair->mutable_pose_a());
      wire::PoseToProto(RigidPose{Eigen::Quaterniond::Identity(), Vector3(3, 0, 0)},
                        pair->mutable_pose_b());
    }
    v1::DistanceFrameResult result;
    ASSERT_TRUE(stream->Write(frame));  // a good frame first
    ASSERT_TRUE(stream->Read(&result));
    c.spoil(frame);
    stream->Write(frame);
    EXPECT_FALSE(stream->Read(&result));
    const grpc::Status s = stream->Finish();
    EXPECT_EQ(s.error_code(), c.code) << s.error_message();
    EXPECT_THAT(s.error_message(), HasSubstr(c.says));
  }
}

// A client that goes away in the middle of a big frame frees its work: the frame's job stops
// long before it would have finished.
TEST_F(StreamRpcTest, ClientDisconnectMidFrameStopsTheWork) {
  // The reply stays under gRPC's 4 MiB default. Under a sanitizer a tenth is still far over
  // the 0.2 s needed below, and the sanitizers run these queries many times slower.
  const int kPairs = testing::kSanitizedBuild ? 5'000 : 50'000;
  std::mutex mutex;
  std::vector<CallRecord> streams;
  observer_ = [&](const CallRecord& record) {
    if (std::string(record.method) != "DistanceStream") return;
    std::lock_guard<std::mutex> lock(mutex);
    streams.push_back(record);
  };
  configure_ = [](ServerOptions& options) { options.limits.max_poses = 1'000'000; };
  Restart();
  INSCRIBE_REQUIRE_MESH("knot1.off");
  const std::string mesh = PutMesh(testing::LoadTestMesh("knot1.off"));
  const auto a = Spheres(mesh, 0.006, /*dilate=*/true);
  // Two knots interlocked at random: exact distances between nearby unions (about 2,000 spheres
  // at this voxel size) are the slow queries, so that the frame takes well over 0.2 s (0.36 s
  // on 2 shared cores).
  v1::DistanceFrame frame;
  std::mt19937_64 rng(5);
  for (int p = 0; p < kPairs; ++p) {
    v1::DistancePair* pair = frame.add_pairs();
    pair->set_sphere_set_a(a.first);
    pair->set_sphere_set_b(a.first);
    wire::PoseToProto(testing::RandomPose(rng, 0.3), pair->mutable_pose_a());
    wire::PoseToProto(testing::RandomPose(rng, 0.3), pair->mutable_pose_b());
  }
  auto wait_for_streams = [&](std::size_t n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (streams.size() >= n) return streams[n - 1];
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ADD_FAILURE() << "stream " << n << " never ended";
    return CallRecord{};
  };

  // The whole frame, answered: how long its work takes.
  {
    auto context = Context(120.0);
    auto stream = stub_->DistanceStream(context.get());
    ASSERT_TRUE(stream->Write(frame));
    v1::DistanceFrameResult result;
    ASSERT_TRUE(stream->Read(&result)) << stream->Finish().error_message();
    ASSERT_EQ(result.results().distances_size(), kPairs);
    stream->WritesDone();
    ASSERT_TRUE(stream->Finish().ok());
  }
  const double full = wait_for_streams(1).run_seconds;
  ASSERT_GT(full, 0.2) << "the frame is too small to measure cancellation against";

  // The same frame, then the client goes away 50 ms into it.
  auto context = Context(120.0);
  auto stream = stub_->DistanceStream(context.get());
  ASSERT_TRUE(stream->Write(frame));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  context->TryCancel();
  const CallRecord cancelled = wait_for_streams(2);
  EXPECT_EQ(cancelled.status.code(), absl::StatusCode::kCancelled) << cancelled.status;
  EXPECT_LT(cancelled.run_seconds, 0.5 * full) << "full frame: " << full << " s";
}

// Draining the server ends an idle stream at once with UNAVAILABLE instead of waiting for the
// client to hang up.
TEST_F(StreamRpcTest, ShutdownEndsIdleStreamsPromptly) {
  auto context = Context();
  auto stream = stub_->DistanceStream(context.get());
  v1::DistanceFrame empty;
  ASSERT_TRUE(stream->Write(empty));
  v1::DistanceFrameResult result;
  ASSERT_TRUE(stream->Read(&result));  // the stream is open and idle
  const auto start = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(30));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_FALSE(stream->Read(&result));
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::UNAVAILABLE);
}

}  // namespace
}  // namespace inscribe::server
