// Client's deadlines and retries against a mock Connection, and the gRPC Connection against
// a closed port.
#include "inscribe/client/client.h"

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "inscribe/mesh_validation.h"
#include "inscribe/server/convert.h"
#include "support/synthetic_meshes.h"

namespace inscribe::client {
namespace {

using ::testing::_;
using ::testing::AllOf;
using ::testing::Ge;
using ::testing::HasSubstr;
using ::testing::Le;
using ::testing::Return;
using ::testing::Truly;

class MockConnection : public Connection {
 public:
  MOCK_METHOD(absl::StatusOr<v1::InspectMeshResponse>, InspectMesh,
              (const v1::InspectMeshRequest& request, Deadline deadline), (override));
};

// What a server answers for the unit cube.
v1::InspectMeshResponse CubeResponse() {
  v1::InspectMeshResponse response;
  response.set_mesh_sha256("sha256:cube");
  server::MeshReportToProto(ValidateMesh(testing::UnitCube()).report, response.mutable_report());
  return response;
}

// Backoff short enough for tests; the attempts are what is being checked.
ClientOptions FastRetries() {
  ClientOptions options;
  options.retry.initial_backoff = std::chrono::milliseconds(1);
  options.retry.max_backoff = std::chrono::milliseconds(4);
  return options;
}

TEST(Client, RetriesUnavailableThenSucceeds) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .WillOnce(Return(absl::UnavailableError("connection refused")))
      .WillOnce(Return(absl::UnavailableError("connection refused")))
      .WillOnce(Return(CubeResponse()));
  Client client(connection, FastRetries());

  absl::StatusOr<InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->mesh_sha256, "sha256:cube");
  EXPECT_TRUE(result->report.usable());
  EXPECT_EQ(result->report.triangles, 12);
  EXPECT_DOUBLE_EQ(result->report.volume, 1.0);
}

TEST(Client, GivesUpAfterThreeAttempts) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .Times(3)
      .WillRepeatedly(Return(absl::UnavailableError("connection refused")));
  Client client(connection, FastRetries());

  absl::StatusOr<InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(result.status().message(), HasSubstr("connection refused"));
  EXPECT_THAT(result.status().message(), HasSubstr("3 attempts"));
}

TEST(Client, DoesNotRetryInvalidArgument) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .WillOnce(Return(absl::InvalidArgumentError("mesh.vertices has length 7")));
  Client client(connection, FastRetries());

  absl::StatusOr<InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  EXPECT_EQ(result.status(), absl::InvalidArgumentError("mesh.vertices has length 7"));
}

TEST(Client, DoesNotRetryResourceExhaustedOrDeadlineExceeded) {
  for (const absl::Status& error : {absl::ResourceExhaustedError("limit (--max-triangles)"),
                                    absl::DeadlineExceededError("deadline exceeded")}) {
    auto connection = std::make_shared<MockConnection>();
    EXPECT_CALL(*connection, InspectMesh(_, _)).WillOnce(Return(error));
    Client client(connection, FastRetries());
    EXPECT_EQ(client.InspectMesh(testing::UnitCube()).status(), error);
  }
}

TEST(Client, DefaultDeadlineIsPassedToEveryAttempt) {
  ClientOptions options = FastRetries();
  options.default_timeout = std::chrono::seconds(7);
  auto connection = std::make_shared<MockConnection>();
  const Deadline earliest = std::chrono::system_clock::now() + options.default_timeout;
  Deadline first_deadline;
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .WillOnce([&](const v1::InspectMeshRequest&, Deadline deadline) {
        first_deadline = deadline;
        return absl::UnavailableError("restarting");
      })
      .WillOnce([&](const v1::InspectMeshRequest&, Deadline deadline) {
        // One deadline for the whole call: retries do not extend it.
        EXPECT_EQ(deadline, first_deadline);
        return CubeResponse();
      });
  Client client(connection, options);
  ASSERT_TRUE(client.InspectMesh(testing::UnitCube()).ok());
  const Deadline latest = std::chrono::system_clock::now() + options.default_timeout;
  EXPECT_GE(first_deadline, earliest);
  EXPECT_LE(first_deadline, latest);
}

TEST(Client, PerCallTimeoutOverridesDefaultAndRequestCarriesTheMesh) {
  auto connection = std::make_shared<MockConnection>();
  const Deadline earliest = std::chrono::system_clock::now() + std::chrono::milliseconds(250);
  EXPECT_CALL(*connection, InspectMesh(Truly([](const v1::InspectMeshRequest& request) {
                                         return request.mesh().vertices_size() == 24 &&
                                                request.mesh().triangles_size() == 36 &&
                                                request.skip_self_intersections();
                                       }),
                                       AllOf(Ge(earliest), Le(earliest + std::chrono::seconds(5)))))
      .WillOnce(Return(CubeResponse()));
  Client client(connection);  // default timeout 30 s: the per-call 250 ms must win

  InspectMeshOptions call;
  call.timeout = std::chrono::milliseconds(250);
  call.skip_self_intersections = true;
  EXPECT_TRUE(client.InspectMesh(testing::UnitCube(), call).ok());
}

TEST(Client, NoRetryWhenTheBackoffWouldOutliveTheDeadline) {
  ClientOptions options;
  options.default_timeout = std::chrono::milliseconds(50);
  options.retry.initial_backoff = std::chrono::seconds(10);
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .WillOnce(Return(absl::UnavailableError("connection refused")));
  Client client(connection, options);
  EXPECT_EQ(client.InspectMesh(testing::UnitCube()).status().code(),
            absl::StatusCode::kUnavailable);
}

TEST(Client, MalformedResponseIsInternal) {
  v1::InspectMeshResponse response = CubeResponse();
  response.mutable_report()->add_bbox_min(0.0);  // 4 values
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _)).WillOnce(Return(response));
  Client client(connection);
  EXPECT_EQ(client.InspectMesh(testing::UnitCube()).status().code(), absl::StatusCode::kInternal);
}

// A loopback port that was free a moment ago: bound by the kernel's choice, then released.
int UnusedLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

TEST(GrpcConnection, UnreachableServerIsUnavailable) {
  // Nothing listens there, so every attempt is refused at once.
  Client client(MakeGrpcConnection("127.0.0.1:" + std::to_string(UnusedLoopbackPort())),
                FastRetries());
  absl::StatusOr<InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kUnavailable) << result.status();
}

}  // namespace
}  // namespace inscribe::client
