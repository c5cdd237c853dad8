#include "request_fuzz_server.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "google/protobuf/stubs/logging.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/convert.h"

namespace inscribe::fuzz {
namespace {

[[noreturn]] void Die(const std::string& what) {
  std::fprintf(stderr, "request fuzz server: %s\n", what.c_str());
  std::abort();
}

std::unique_ptr<grpc::ClientContext> Context() {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::seconds(kFuzzDeadlineSeconds));
  return context;
}

Mesh UnitCube() {
  Mesh mesh;
  mesh.vertices.resize(8, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  mesh.triangles.resize(12, 3);
  mesh.triangles << 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2, 0, 4, 7,
      0, 7, 3, 1, 2, 6, 1, 6, 5;
  return mesh;
}

// Parses `bytes` into a fresh `Message`; false when they are not one.
template <typename Message>
bool Parse(absl::string_view bytes, Message* message) {
  return message->ParseFromArray(bytes.data(), static_cast<int>(bytes.size()));
}

grpc::Status RunGenerate(v1::Inscribe::Stub& stub, const v1::GenerateRequest& request,
                         v1::GenerateResult* result) {
  auto context = Context();
  std::unique_ptr<grpc::ClientReader<v1::GenerateResponse>> reader =
      stub.Generate(context.get(), request);
  v1::GenerateResponse message;
  bool have_result = false;
  while (reader->Read(&message)) {
    if (message.has_result()) {
      have_result = true;
      if (result != nullptr) *result = message.result();
    }
  }
  grpc::Status status = reader->Finish();
  if (status.ok() && !have_result) {
    return grpc::Status(grpc::StatusCode::INTERNAL, "Generate ended OK without a result");
  }
  return status;
}

grpc::Status RunStream(v1::Inscribe::Stub& stub, const v1::DistanceFrame& frame) {
  auto context = Context();
  std::unique_ptr<grpc::ClientReaderWriter<v1::DistanceFrame, v1::DistanceFrameResult>> stream =
      stub.DistanceStream(context.get());
  v1::DistanceFrame second = frame;
  second.set_frame(frame.frame() + 1);
  // A failed write means the server ended the stream; Finish says why.
  if (stream->Write(frame)) stream->Write(second);
  stream->WritesDone();
  v1::DistanceFrameResult result;
  int answers = 0;
  while (stream->Read(&result)) ++answers;
  grpc::Status status = stream->Finish();
  if (status.ok() && answers != 2) {
    return grpc::Status(
        grpc::StatusCode::INTERNAL,
        "DistanceStream ended OK after " + std::to_string(answers) + " answers to 2 frames");
  }
  return status;
}

template <typename Request, typename Response>
std::optional<grpc::Status> Unary(absl::string_view bytes,
                                  grpc::Status (v1::Inscribe::Stub::*method)(grpc::ClientContext*,
                                                                             const Request&,
                                                                             Response*),
                                  v1::Inscribe::Stub& stub) {
  Request request;
  if (!Parse(bytes, &request)) return std::nullopt;
  Response response;
  return (stub.*method)(Context().get(), request, &response);
}

FuzzServer* Start() {
  // Mutated strings are often not UTF-8; protobuf logs each such parse to stderr otherwise.
  google::protobuf::SetLogHandler(nullptr);
  auto fuzz = std::make_unique<FuzzServer>();
  server::ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.jobs = 2;
  options.max_queue = 16;
  options.max_message_bytes = 4 * 1024 * 1024;
  options.cache.memory_bytes = 32 * 1024 * 1024;
  options.limits.max_triangles = kFuzzMaxTriangles;
  options.limits.max_voxels = kFuzzMaxVoxels;
  options.limits.max_spheres = kFuzzMaxSpheres;
  options.limits.max_poses = kFuzzMaxPoses;
  absl::StatusOr<std::unique_ptr<server::InscribeServer>> started =
      server::InscribeServer::Start(options);
  if (!started.ok()) Die(started.status().ToString());
  fuzz->server = *std::move(started);
  fuzz->stub = v1::Inscribe::NewStub(
      grpc::CreateChannel(fuzz->server->address(), grpc::InsecureChannelCredentials()));

  v1::PutMeshRequest put_mesh;
  wire::MeshToProto(UnitCube(), put_mesh.mutable_mesh());
  v1::PutMeshResponse mesh_reply;
  grpc::Status status = fuzz->stub->PutMesh(Context().get(), put_mesh, &mesh_reply);
  if (!status.ok()) Die("PutMesh of the cube: " + status.error_message());
  fuzz->mesh_key = mesh_reply.mesh_sha256();

  v1::GenerateRequest generate;
  generate.set_mesh_sha256(fuzz->mesh_key);
  generate.mutable_parameters()->set_voxel_size(0.25);
  v1::GenerateResult generated;
  status = RunGenerate(*fuzz->stub, generate, &generated);
  if (!status.ok()) Die("Generate for the cube: " + status.error_message());
  fuzz->sphere_set_key = generated.sphere_set_key();

  v1::PutSphereSetRequest put_set;
  SphereSet two;
  two.spheres = {Sphere{Vector3(0, 0, 0), 1.0}, Sphere{Vector3(3, 0, 0), 0.5}};
  wire::SphereSetToProto(two, put_set.mutable_spheres());
  v1::PutSphereSetResponse set_reply;
  status = fuzz->stub->PutSphereSet(Context().get(), put_set, &set_reply);
  if (!status.ok()) Die("PutSphereSet: " + status.error_message());
  fuzz->plain_set_key = set_reply.sphere_set_key();

  // The ball holds the cube (its corners are sqrt(3)/2 from the centre) and reaches 0.4 out.
  v1::PutSphereSetRequest put_cover;
  SphereSet ball;
  ball.spheres = {Sphere{Vector3::Constant(0.5), 0.9}};
  wire::SphereSetToProto(ball, put_cover.mutable_spheres());
  CoverCertificate certificate;
  certificate.certified = true;
  certificate.delta = 0.4;
  certificate.resolution = 1.0 / 512;
  certificate.protrusions = {0.4};
  certificate.mesh_sha256 = fuzz->mesh_key;
  certificate.spheres_sha256 = FormatSha256(SpheresSha256(ball.spheres));
  wire::CoverCertificateToProto(certificate, put_cover.mutable_certificate());
  status = fuzz->stub->PutSphereSet(Context().get(), put_cover, &set_reply);
  if (!status.ok()) Die("PutSphereSet of a cover: " + status.error_message());
  fuzz->cover_set_key = set_reply.sphere_set_key();
  return fuzz.release();
}

}  // namespace

const char* RequestKindName(RequestKind kind) {
  static const char* const kNames[kRequestKinds] = {
      "InspectMesh",    "PutMesh",      "Generate",          "PutSphereSet",
      "GetSphereSet",   "GetHierarchy", "UpdateDeformation", "Distance",
      "DistanceStream", "Evaluate",     "CacheStats",        "CertifyCover"};
  return kNames[static_cast<int>(kind) % kRequestKinds];
}

FuzzServer& TheFuzzServer() {
  // Never destroyed: the server outlives every input, and the process ends without stopping it.
  static FuzzServer* const server = Start();
  return *server;
}

std::optional<grpc::Status> SendRequest(FuzzServer& server, RequestKind kind,
                                        absl::string_view bytes) {
  using Stub = v1::Inscribe::Stub;
  Stub& stub = *server.stub;
  switch (kind) {
    case RequestKind::kInspectMesh:
      return Unary(bytes, &Stub::InspectMesh, stub);
    case RequestKind::kPutMesh:
      return Unary(bytes, &Stub::PutMesh, stub);
    case RequestKind::kGenerate: {
      v1::GenerateRequest request;
      if (!Parse(bytes, &request)) return std::nullopt;
      return RunGenerate(stub, request, nullptr);
    }
    case RequestKind::kPutSphereSet:
      return Unary(bytes, &Stub::PutSphereSet, stub);
    case RequestKind::kGetSphereSet:
      return Unary(bytes, &Stub::GetSphereSet, stub);
    case RequestKind::kGetHierarchy:
      return Unary(bytes, &Stub::GetHierarchy, stub);
    case RequestKind::kUpdateDeformation:
      return Unary(bytes, &Stub::UpdateDeformation, stub);
    case RequestKind::kDistance:
      return Unary(bytes, &Stub::Distance, stub);
    case RequestKind::kDistanceStream: {
      v1::DistanceFrame frame;
      if (!Parse(bytes, &frame)) return std::nullopt;
      return RunStream(stub, frame);
    }
    case RequestKind::kEvaluate:
      return Unary(bytes, &Stub::Evaluate, stub);
    case RequestKind::kCacheStats:
      return Unary(bytes, &Stub::CacheStats, stub);
    case RequestKind::kCertifyCover:
      return Unary(bytes, &Stub::CertifyCover, stub);
  }
  return std::nullopt;
}

}  // namespace inscribe::fuzz
