// Adversarial requests against real inscribed processes on loopback (issue 8): broken meshes,
// a billion-voxel grid, 10^6 poses in one call, garbage and oversized bytes, bad deformations,
// NaN poses, and a small --memory-budget under concurrent abuse. Each abuse must get a clear
// status naming the problem, and the server must answer a normal call afterwards. Requests go
// through the generated stub or a generic stub (raw bytes), since the client library would
// refuse to send most of them.
#include <gmock/gmock.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "support/inscribed_process.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using Seconds = std::chrono::duration<double>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// One inscribed process and a channel to it that sends and receives messages of any size (so
// that the server's limits, not the client's, are what is tested).
class Server {
 public:
  explicit Server(std::vector<std::string> flags) {
    std::vector<std::string> args = {"--listen", "127.0.0.1:0", "--jobs",
                                     "2",        "--log-level", "warn"};
    args.insert(args.end(), flags.begin(), flags.end());
    process_ = std::make_unique<testing::InscribedProcess>(INSCRIBED, args);
    address_ = process_->WaitUntilListening();
    process_->DrainLogInBackground();
    grpc::ChannelArguments channel_args;
    channel_args.SetMaxReceiveMessageSize(-1);
    channel_args.SetMaxSendMessageSize(-1);
    channel_ =
        grpc::CreateCustomChannel(address_, grpc::InsecureChannelCredentials(), channel_args);
    stub_ = v1::Inscribe::NewStub(channel_);
  }

  bool up() const { return !address_.empty(); }
  std::string log() const { return process_->log(); }
  v1::Inscribe::Stub& stub() { return *stub_; }
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }

  // Peak resident memory of the process so far (VmHWM), bytes; -1 if unreadable.
  std::int64_t PeakRss() const { return testing::ReadProcessMemory(process_->pid()).peak_resident; }

 private:
  std::unique_ptr<testing::InscribedProcess> process_;
  std::string address_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Inscribe::Stub> stub_;
};

// A unary call with a deadline generous for a loaded 2-core machine.
template <typename Request, typename Response>
grpc::Status Call(v1::Inscribe::Stub& stub,
                  grpc::Status (v1::Inscribe::Stub::*method)(grpc::ClientContext*, const Request&,
                                                             Response*),
                  const Request& request, Response* response, double seconds = 60.0) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::milliseconds(static_cast<int>(1e3 * seconds)));
  return (stub.*method)(&context, request, response);
}

// Runs a Generate to its end; the final result in *result when OK.
grpc::Status Generate(v1::Inscribe::Stub& stub, const v1::GenerateRequest& request,
                      v1::GenerateResult* result = nullptr) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  auto reader = stub.Generate(&context, request);
  v1::GenerateResponse message;
  while (reader->Read(&message)) {
    if (message.has_result() && result != nullptr) *result = message.result();
  }
  return reader->Finish();
}

v1::Mesh ToProto(const Mesh& mesh) {
  v1::Mesh out;
  wire::MeshToProto(mesh, &out);
  return out;
}

// PutMesh of a known-good mesh: the server still serves after whatever came before.
void ExpectServes(Server& server) {
  v1::PutMeshRequest request;
  *request.mutable_mesh() = ToProto(testing::UnitCube());
  v1::PutMeshResponse response;
  const grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message() << "\n" << server.log();
  EXPECT_THAT(response.mesh_sha256(), ::testing::StartsWith("sha256:"));
}

std::string PutMesh(Server& server, const Mesh& mesh) {
  v1::PutMeshRequest request;
  *request.mutable_mesh() = ToProto(mesh);
  v1::PutMeshResponse response;
  const grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response.mesh_sha256();
}

// A set of one sphere of radius 1 at the origin, stored without a mesh.
std::string PutOneSphere(Server& server) {
  v1::PutSphereSetRequest request;
  for (double c : {0.0, 0.0, 0.0}) request.mutable_spheres()->add_centers(c);
  request.mutable_spheres()->add_radii(1.0);
  v1::PutSphereSetResponse response;
  const grpc::Status status =
      Call(server.stub(), &v1::Inscribe::Stub::PutSphereSet, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response.sphere_set_key();
}

void AddPose(v1::PoseArray* poses, std::vector<double> pose) {
  for (double v : pose) poses->add_values(v);
}

struct BadMesh {
  const char* name;
  Mesh mesh;
  bool usable;  // the validator only warns: stored, and Generate answers
  // Generate finds spheres.
  bool has_spheres = true;
};

Mesh WithVertex(Mesh mesh, int row, const Vector3& value) {
  mesh.vertices.row(row) = value;
  return mesh;
}

TEST(Adversarial, BrokenMeshesGetAReportOrAClearRefusal) {
  Server server({});
  ASSERT_TRUE(server.up()) << server.log();
  const Mesh cube = testing::UnitCube();
  Mesh collinear;
  collinear.vertices.resize(4, 3);
  collinear.vertices << 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3;
  collinear.triangles.resize(4, 3);
  collinear.triangles << 0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2;
  Mesh zero_area = cube;  // one corner moved onto another: two triangles lose their area
  zero_area.vertices.row(1) = zero_area.vertices.row(0);
  Mesh out_of_range = cube;
  out_of_range.triangles(3, 1) = 1000;
  Mesh negative_index = cube;
  negative_index.triangles(0, 0) = -5;
  Mesh duplicated = testing::Concatenate(cube, cube);  // every vertex and triangle twice

  const std::vector<BadMesh> cases = {
      {"empty", Mesh{}, false},
      {"collinear", collinear, false},
      {"zero-area", zero_area, true},
      // Both copies bound the cube: winding number 2 inside it, so the solid is the cube.
      {"duplicated", duplicated, true},
      {"open", testing::OpenUnitCube(), false},
      {"out-of-range", out_of_range, false},
      {"negative-index", negative_index, false},
      {"nan", WithVertex(cube, 2, Vector3(kNaN, 0, 0)), false},
      {"inf", WithVertex(cube, 5, Vector3(0, kInf, -kInf)), false},
  };
  for (const BadMesh& c : cases) {
    SCOPED_TRACE(c.name);
    v1::InspectMeshRequest inspect;
    *inspect.mutable_mesh() = ToProto(c.mesh);
    v1::InspectMeshResponse report;
    const grpc::Status inspected =
        Call(server.stub(), &v1::Inscribe::Stub::InspectMesh, inspect, &report);
    // InspectMesh reports a broken mesh's problems; it is not an error to ask.
    ASSERT_TRUE(inspected.ok()) << inspected.error_message();
    EXPECT_EQ(report.report().usable(), c.usable);
    EXPECT_GT(report.report().issues_size(), 0);

    v1::PutMeshRequest put;
    *put.mutable_mesh() = ToProto(c.mesh);
    v1::PutMeshResponse stored;
    grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, put, &stored);
    if (!c.usable) {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION)
          << status.error_message();
      // The refusal is the report's first error, word for word.
      std::string first_error;
      for (const v1::MeshIssue& issue : report.report().issues()) {
        if (issue.severity() == v1::MeshIssue::ERROR) {
          first_error = issue.message();
          break;
        }
      }
      EXPECT_FALSE(first_error.empty());
      EXPECT_THAT(status.error_message(), HasSubstr(first_error));
      continue;
    }
    ASSERT_TRUE(status.ok()) << status.error_message();
    v1::GenerateRequest generate;
    generate.set_mesh_sha256(stored.mesh_sha256());
    generate.mutable_parameters()->set_voxel_size(0.1);
    v1::GenerateResult result;
    status = Generate(server.stub(), generate, &result);
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(result.spheres().radii_size() > 0, c.has_spheres) << result.spheres().radii_size();
  }
  // Malformed packed arrays are refused on the gRPC thread, naming the field and its length.
  v1::PutMeshRequest ragged;
  *ragged.mutable_mesh() = ToProto(cube);
  ragged.mutable_mesh()->add_vertices(1.0);
  v1::PutMeshResponse response;
  grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, ragged, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), AllOf(HasSubstr("mesh.vertices"), HasSubstr("25")));

  // Two overlapping closed boxes intersect each other: usable (the exact winding number decides),
  // reported, and spheres can be generated.
  const Mesh overlapping =
      testing::Concatenate(cube, testing::Box(Vector3::Constant(0.5), Vector3::Constant(1.5)));
  v1::PutMeshRequest put;
  *put.mutable_mesh() = ToProto(overlapping);
  status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, put, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(response.report().self_intersecting_pairs(), 0);
  v1::GenerateRequest generate;
  generate.set_mesh_sha256(response.mesh_sha256());
  generate.mutable_parameters()->set_voxel_size(0.1);
  generate.set_skip_quality(true);
  v1::GenerateResult result;
  status = Generate(server.stub(), generate, &result);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(result.spheres().radii_size(), 0);
  ExpectServes(server);
}

TEST(Adversarial, BillionVoxelGenerateIsRefusedBeforeWork) {
  Server server({});
  ASSERT_TRUE(server.up()) << server.log();
  const std::string mesh = PutMesh(server, testing::UnitCube());
  v1::GenerateRequest request;
  request.set_mesh_sha256(mesh);
  request.mutable_parameters()->set_voxel_size(1e-3);  // 1000^3 = 10^9 voxels
  const auto start = std::chrono::steady_clock::now();
  grpc::Status status = Generate(server.stub(), request);
  const double seconds = Seconds(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), AllOf(HasSubstr("1e+09 voxels"), HasSubstr("--max-voxels")));
  EXPECT_LT(seconds, 10.0);  // "does not hang": the refusal is immediate, 10 s is for load
  v1::CacheStatsResponse stats;
  ASSERT_TRUE(
      Call(server.stub(), &v1::Inscribe::Stub::CacheStats, v1::CacheStatsRequest(), &stats).ok());
  EXPECT_EQ(stats.computations(), 1);  // the PutMesh; the refused Generate never looked

  // A voxel size that is not a number is refused as a parameter.
  request.mutable_parameters()->set_voxel_size(kNaN);
  status = Generate(server.stub(), request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("voxel size"));
  ExpectServes(server);
}

// 10^6 pose pairs in one Distance call between two one-sphere sets: B's poses are
// translations along x, so each distance is |t| - 2 exactly.
v1::DistanceRequest MillionPoses(const std::string& set, int pairs) {
  v1::DistanceRequest request;
  request.set_sphere_set_a(set);
  request.set_sphere_set_b(set);
  AddPose(request.mutable_poses_a(), {1, 0, 0, 0, 0, 0, 0});
  request.mutable_poses_b()->mutable_values()->Reserve(7 * pairs);
  for (int i = 0; i < pairs; ++i)
    AddPose(request.mutable_poses_b(), {1, 0, 0, 0, 3.0 + i % 100, 0, 0});
  return request;
}

TEST(Adversarial, MillionPosesAreAnsweredWhenTheLimitsAllowIt) {
  Server server({"--max-poses", "1000000"});
  ASSERT_TRUE(server.up()) << server.log();
  const std::string set = PutOneSphere(server);
  const v1::DistanceRequest request = MillionPoses(set, 1'000'000);
  const std::int64_t baseline = server.PeakRss();
  v1::DistanceResponse response;
  const grpc::Status status =
      Call(server.stub(), &v1::Inscribe::Stub::Distance, request, &response, 120.0);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.results().distances_size(), 1'000'000);
  // For the record (MemoryCosts::kPerPosePair): growth of peak RSS over the call.
  std::cout << "10^6 pose pairs: peak RSS +" << ((server.PeakRss() - baseline) >> 20)
            << " MiB (request " << (request.ByteSizeLong() >> 20) << " MiB, reply "
            << (response.ByteSizeLong() >> 20) << " MiB)\n";
  for (int i : {0, 1, 99, 12'345, 999'999}) {
    EXPECT_NEAR(response.results().distances(i), 1.0 + i % 100, 1e-9) << i;
  }
}

TEST(Adversarial, MillionPosesAreRefusedByMaxPosesOrTheMemoryBudget) {
  Server by_count({"--max-poses", "100000"});
  Server by_memory({"--memory-budget", "134217728"});  // 128 MiB: 10^6 pairs need ~500 MB
  ASSERT_TRUE(by_count.up() && by_memory.up()) << by_count.log() << by_memory.log();
  for (Server* server : {&by_count, &by_memory}) {
    const std::string set = PutOneSphere(*server);
    v1::DistanceResponse response;
    grpc::Status status = Call(server->stub(), &v1::Inscribe::Stub::Distance,
                               MillionPoses(set, 1'000'000), &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_THAT(status.error_message(),
                HasSubstr(server == &by_count ? "--max-poses" : "--memory-budget"));
    // A thousand pairs fit both.
    status =
        Call(server->stub(), &v1::Inscribe::Stub::Distance, MillionPoses(set, 1000), &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(response.results().distances_size(), 1000);
  }
}

TEST(Adversarial, NonFinitePosesAreRefusedNamingThePose) {
  Server server({});
  ASSERT_TRUE(server.up()) << server.log();
  const std::string set = PutOneSphere(server);
  const std::vector<std::vector<double>> bad = {
      {kNaN, 0, 0, 0, 0, 0, 0}, {1, 0, 0, 0, kInf, 0, 0}, {0, 0, 0, 0, 5, 0, 0}};
  for (const std::vector<double>& pose : bad) {
    v1::DistanceRequest request = MillionPoses(set, 3);
    AddPose(request.mutable_poses_b(), pose);
    v1::DistanceResponse response;
    const grpc::Status status =
        Call(server.stub(), &v1::Inscribe::Stub::Distance, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("poses_b pose 3"));
  }
  // A pose array whose length is not a multiple of 7.
  v1::DistanceRequest ragged = MillionPoses(set, 2);
  ragged.mutable_poses_b()->add_values(1.0);
  v1::DistanceResponse response;
  grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::Distance, ragged, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("multiple of 7"));

  // DistanceStream: a good frame is answered, a frame with a NaN pose ends the stream naming
  // the frame and the pair; a new stream is then served.
  for (const std::vector<double>& pose : bad) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    auto stream = server.stub().DistanceStream(&context);
    v1::DistanceFrame frame;
    frame.set_frame(1);
    v1::DistancePair* pair = frame.add_pairs();
    pair->set_sphere_set_a(set);
    pair->set_sphere_set_b(set);
    pair->mutable_pose_a()->set_qw(1);
    pair->mutable_pose_b()->set_qw(1);
    pair->mutable_pose_b()->set_tx(4);
    ASSERT_TRUE(stream->Write(frame));
    v1::DistanceFrameResult answer;
    ASSERT_TRUE(stream->Read(&answer));
    EXPECT_NEAR(answer.results().distances(0), 2.0, 1e-12);
    frame.set_frame(2);
    v1::Pose* p = frame.mutable_pairs(0)->mutable_pose_a();
    p->set_qw(pose[0]);
    p->set_qx(pose[1]);
    p->set_tx(pose[4]);
    stream->Write(frame);
    stream->WritesDone();
    EXPECT_FALSE(stream->Read(&answer));
    status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("frame 2 pairs[0].pose_a"));
  }
  ExpectServes(server);
}

TEST(Adversarial, DeformationsWithWrongVertexCountsOrNaNsAreRefused) {
  Server server({});
  ASSERT_TRUE(server.up()) << server.log();
  const Mesh cube = testing::UnitCube();
  v1::GenerateRequest generate;
  generate.set_mesh_sha256(PutMesh(server, cube));
  generate.mutable_parameters()->set_voxel_size(0.25);
  generate.set_skip_quality(true);
  v1::GenerateResult set;
  ASSERT_TRUE(Generate(server.stub(), generate, &set).ok());

  auto update = [&](std::vector<double> vertices) {
    v1::UpdateDeformationRequest request;
    request.set_sphere_set_key(set.sphere_set_key());
    for (double v : vertices) request.add_vertices(v);
    v1::UpdateDeformationResponse response;
    return Call(server.stub(), &v1::Inscribe::Stub::UpdateDeformation, request, &response);
  };
  std::vector<double> moved;
  for (int v = 0; v < cube.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) moved.push_back(1.1 * cube.vertices(v, k));
  }
  std::vector<double> short_by_one(moved.begin(), moved.end() - 3);
  grpc::Status status = update(short_by_one);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), AllOf(HasSubstr("21 numbers"), HasSubstr("8 vertices")));
  std::vector<double> with_nan = moved;
  with_nan[3 * 6 + 2] = kNaN;
  status = update(with_nan);  // an unusable mesh, as PutMesh's
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("vertex 6 has a non-finite coordinate"));
  status = update(moved);  // the same call with good positions works
  EXPECT_TRUE(status.ok()) << status.error_message();
}

// Protobuf's base-128 varint.
std::string Varint(std::uint64_t value) {
  std::string out;
  for (; value >= 0x80; value >>= 7) out += static_cast<char>(0x80 | (value & 0x7f));
  return out + static_cast<char>(value);
}

// Sends `bytes` as the request of `method` through a generic stub; the call's status.
grpc::Status SendRaw(const std::shared_ptr<grpc::Channel>& channel, const std::string& method,
                     const std::string& bytes) {
  grpc::GenericStub stub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, method, grpc::StubOptions(), &request, &response,
                 [&done](grpc::Status status) { done.set_value(std::move(status)); });
  return done.get_future().get();
}

TEST(Adversarial, GarbageAndOversizedBytesGetAStatusFromEveryMethod) {
  Server server({"--max-message-bytes", "1048576"});
  ASSERT_TRUE(server.up()) << server.log();
  // 100,000 levels of field 1, length-delimited, each wrapping the rest (~400 KB): level k's
  // payload is level k-1 whole, so its length is 1 + |varint(length k-1)| + length k-1.
  std::vector<std::uint64_t> payload(100'001, 0);
  for (std::size_t k = 1; k < payload.size(); ++k) {
    payload[k] = 1 + Varint(payload[k - 1]).size() + payload[k - 1];
  }
  std::string nested;
  for (std::size_t k = payload.size() - 1; k >= 1; --k) nested += "\x0a" + Varint(payload[k - 1]);
  std::string groups;  // start-group tags (field 1, wire type 3) never closed
  for (int i = 0; i < 50'000; ++i) groups += '\x0b';
  const std::string truncated_varint("\x08\xff\xff\xff\xff\xff", 6);
  const std::string bad_length("\x0a\xff\xff\xff\xff\x0f", 6);  // a 4 GB field in 6 bytes
  const std::string oversized(2 << 20, '\0');                   // 2 MiB of zeros
  const std::vector<std::string> methods = {"InspectMesh",  "PutMesh",           "Generate",
                                            "PutSphereSet", "GetSphereSet",      "GetHierarchy",
                                            "Distance",     "UpdateDeformation", "DistanceStream",
                                            "Evaluate",     "CacheStats",        "CertifyCover"};
  for (const std::string& name : methods) {
    const std::string method = "/inscribe.v1.Inscribe/" + name;
    for (const std::string* garbage :
         std::vector<const std::string*>{&nested, &groups, &truncated_varint, &bad_length}) {
      const grpc::Status status = SendRaw(server.channel(), method, *garbage);
      if (name == "DistanceStream") {
        // A frame that does not parse ends the read loop as the client's half-close does
        // (gRPC reports both as a failed read): the stream ends OK, no frame answered. The
        // client library reports "DistanceStream ended without answering frame N".
        EXPECT_TRUE(status.ok()) << status.error_message();
      } else if (name == "CacheStats" && garbage == &nested) {
        EXPECT_TRUE(status.ok()) << "an unknown length-delimited field is skipped";
      } else {
        // gRPC 1.51's callback API answers a request it cannot parse with UNIMPLEMENTED and
        // no message (its handlers' UnimplementedUnaryReactor), before the service sees it.
        EXPECT_EQ(status.error_code(), grpc::StatusCode::UNIMPLEMENTED)
            << name << ": " << status.error_message();
      }
    }
    const grpc::Status status = SendRaw(server.channel(), method, oversized);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << name;
  }
  // A well-formed mesh over --max-message-bytes: refused by gRPC before the handler.
  v1::PutMeshRequest big;
  *big.mutable_mesh() = ToProto(testing::Icosphere(6));  // 81,920 triangles, ~2 MB
  v1::PutMeshResponse response;
  const grpc::Status status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, big, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("larger than max"));
  ExpectServes(server);
}

// Several threads send the largest requests a small-budget server allows, for a few seconds.
// The server must refuse what does not fit (counted) and its peak RSS stay under budget +
// cache + the messages gRPC may hold + the baseline measured before the abuse.
TEST(Adversarial, MemoryStaysUnderTheBudgetUnderConcurrentAbuse) {
  constexpr std::int64_t kBudget = 256 << 20, kCache = 64 << 20, kMessage = 16 << 20;
  constexpr int kThreads = 4;
  Server server({"--memory-budget", std::to_string(kBudget), "--cache-memory-bytes",
                 std::to_string(kCache), "--max-message-bytes", std::to_string(kMessage),
                 "--max-queue", "64"});
  ASSERT_TRUE(server.up()) << server.log();
  const std::string set = PutOneSphere(server);
  ExpectServes(server);
  const std::int64_t baseline = server.PeakRss();
  ASSERT_GT(baseline, 0);

  // Large requests under 16 MiB: 280,000 pose pairs (15.7 MB, ~140 MB of estimated work: one
  // fits, two do not), and an 81,920-triangle mesh (~2 MB, ~85 MB of estimated work).
  const v1::DistanceRequest poses = MillionPoses(set, 280'000);
  v1::PutMeshRequest mesh;
  *mesh.mutable_mesh() = ToProto(testing::Icosphere(6, Vector3::Zero(), 1.0));
  std::atomic<int> answered{0}, refused_by_budget{0}, other{0};
  std::vector<std::string> unexpected;
  std::mutex unexpected_mutex;
  const auto stop = std::chrono::steady_clock::now() + std::chrono::seconds(8);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      grpc::Status status;
      for (int i = 0; std::chrono::steady_clock::now() < stop; ++i) {
        if ((t + i) % 3 != 2) {
          v1::DistanceResponse response;
          status = Call(server.stub(), &v1::Inscribe::Stub::Distance, poses, &response);
          if (status.ok() && response.results().distances_size() != 280'000) ++other;
        } else {
          v1::PutMeshResponse response;
          status = Call(server.stub(), &v1::Inscribe::Stub::PutMesh, mesh, &response);
        }
        if (status.ok()) {
          ++answered;
        } else if (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                   status.error_message().find("--memory-budget") != std::string::npos) {
          ++refused_by_budget;
        } else {
          ++other;
          std::lock_guard<std::mutex> lock(unexpected_mutex);
          unexpected.push_back(status.error_message());
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  const std::int64_t peak = server.PeakRss();
  // Each call in flight may hold its request twice (gRPC's bytes and the parsed message) and
  // its serialised reply, which gRPC still sends after the job has given its reservation back
  // (a 280,000-pair reply is ~15 MB; without it peak RSS passed the bound by 15 MiB once).
  const std::int64_t bound = baseline + kBudget + kCache + 3 * kThreads * kMessage;
  std::cout << "abuse: answered " << answered << ", refused by --memory-budget "
            << refused_by_budget << ", other " << other << "; peak RSS " << (peak >> 20)
            << " MiB (baseline " << (baseline >> 20) << " MiB, bound " << (bound >> 20)
            << " MiB)\n";
  EXPECT_GT(answered.load(), 0);
  EXPECT_GT(refused_by_budget.load(), 0);
  EXPECT_EQ(other.load(), 0) << ::testing::PrintToString(unexpected);
  if (testing::kSanitizedBuild) {
    std::cout << "abuse: the RSS bound is not checked under a sanitizer (its shadow memory)\n";
  } else {
    EXPECT_LT(peak, bound);
  }
  ExpectServes(server);
}

}  // namespace
}  // namespace inscribe::server
