// The server the request fuzz target talks to: a real InscribeServer on 127.0.0.1:0, started
// once per process with small limits, so that no input's work can grow past a fraction of a
// second; and one way to send arbitrary bytes as any inscribe.v1 request to it. Shared by the
// fuzz target (fuzz_requests.cpp) and the program that writes its seed corpus.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/strings/string_view.h"
#include "grpcpp/support/status.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/v1/service.grpc.pb.h"

namespace inscribe::fuzz {

// Every request message of inscribe.v1.Inscribe; an input's first byte modulo kRequestKinds
// picks one. The order is part of the seed corpus's format: append, never reorder.
enum class RequestKind : std::uint8_t {
  kInspectMesh,
  kPutMesh,
  kGenerate,
  kPutSphereSet,
  kGetSphereSet,
  kGetHierarchy,
  kUpdateDeformation,
  kDistance,
  kDistanceStream,  // the bytes are one DistanceFrame, sent twice on one stream
  kEvaluate,
  kCacheStats,
  kCertifyCover,
};
inline constexpr int kRequestKinds = 12;

const char* RequestKindName(RequestKind kind);

// Limits the fuzzing server runs with; also what the seeds stay within.
inline constexpr std::int64_t kFuzzMaxTriangles = 2000;
inline constexpr std::int64_t kFuzzMaxVoxels = 20'000;
inline constexpr std::int64_t kFuzzMaxSpheres = 2000;
inline constexpr std::int64_t kFuzzMaxPoses = 1000;
// Each call's deadline; a deadline reached is a finding (a hang, or work the limits failed to
// bound). Every request the limits admit takes well under a second in a normal build, the
// slowest seen being a cover Generate of the cube (0.6 s; 12.6 s under ASan), so the deadline is
// 20 s, stretched like every test time limit under the sanitizers (tests/CMakeLists.txt).
#ifndef INSCRIBE_TEST_TIME_SCALE
#error "INSCRIBE_TEST_TIME_SCALE comes from tests/fuzz/CMakeLists.txt"
#endif
inline constexpr int kFuzzDeadlineSeconds = 20 * INSCRIBE_TEST_TIME_SCALE;

struct FuzzServer {
  std::unique_ptr<server::InscribeServer> server;
  std::unique_ptr<v1::Inscribe::Stub> stub;
  // A unit cube (8 vertices, 12 triangles), stored with PutMesh.
  std::string mesh_key;
  // Spheres generated for the cube (voxel size 0.25, with contacts): usable by every RPC.
  std::string sphere_set_key;
  // Two spheres with no contacts and no mesh, stored with PutSphereSet.
  std::string plain_set_key;
  // One ball around the cube, stored with PutSphereSet and its certificate: a cover for
  // certified Distance and DistanceStream queries.
  std::string cover_set_key;
};

// The process's server, started (and the entries above stored) on first use. Aborts with a
// message on stderr when it cannot start: nothing can be fuzzed then.
FuzzServer& TheFuzzServer();

// Parses `bytes` as `kind`'s request message and sends it to `server` with the deadline above,
// reading every reply. nullopt when the bytes are not such a message; else the call's status,
// with a failure status also when an OK Generate sent no result or a stream sent no answer.
std::optional<grpc::Status> SendRequest(FuzzServer& server, RequestKind kind,
                                        absl::string_view bytes);

}  // namespace inscribe::fuzz
