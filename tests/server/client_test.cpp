// Client's retries and deadlines for every unary call, and its checks of malformed answers,
// against a mock Connection; the gRPC Connection against a closed port.
#include "inscribe/client/client.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <deque>
#include <thread>

#include "client_test_support.h"
#include "support/inscribed_process.h"

namespace inscribe::client {
namespace {

using std::chrono::milliseconds;
using ::testing::_;
using ::testing::HasSubstr;
using ::testing::Return;
using ::testing::Truly;

// Answers of one RPC's successive attempts: the scripted errors in order, then `good`. Records
// every attempt's deadline. Copies share the script (gmock copies its actions).
class Script {
 public:
  explicit Script(std::vector<absl::Status> errors = {}) : state_(std::make_shared<State>()) {
    state_->errors.assign(errors.begin(), errors.end());
  }
  template <typename Response>
  absl::StatusOr<Response> Answer(Deadline deadline, Response good) const {
    state_->deadlines.push_back(deadline);
    if (state_->errors.empty()) return good;
    const absl::Status error = state_->errors.front();
    state_->errors.pop_front();
    return error;
  }
  const std::vector<Deadline>& deadlines() const { return state_->deadlines; }

 private:
  struct State {
    std::deque<absl::Status> errors;
    std::vector<Deadline> deadlines;
  };
  std::shared_ptr<State> state_;
};

// Each idempotent unary call: how to expect exactly `calls` attempts of it on the mock, and how
// to make it through Client (with a per-call timeout when given).
struct UnaryRpc {
  const char* name;
  std::function<void(MockConnection&, int calls, Script)> expect;
  std::function<absl::Status(const Client&, std::optional<milliseconds> timeout)> call;
};

std::vector<UnaryRpc> UnaryRpcs() {
  // The per-call options of most calls.
  const auto with = [](std::optional<milliseconds> timeout) {
    CallOptions options;
    options.timeout = timeout;
    return options;
  };
  return {
      {"InspectMesh",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, InspectMesh(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, CubeResponse());
         });
       },
       [](const Client& client, std::optional<milliseconds> timeout) {
         InspectMeshOptions options;
         options.timeout = timeout;
         return client.InspectMesh(testing::UnitCube(), options).status();
       }},
      {"PutMesh",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, PutMesh(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, PutMeshOk());
         });
       },
       [](const Client& client, std::optional<milliseconds> timeout) {
         PutMeshOptions options;
         options.timeout = timeout;
         return client.PutMesh(testing::UnitCube(), options).status();
       }},
      {"Generate",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, Generate(_, _, _))
             .Times(calls)
             .WillRepeatedly([s](auto&, Deadline d, auto&) { return s.Answer(d, GenerateOk()); });
       },
       [](const Client& client, std::optional<milliseconds> timeout) {
         GenerateSettings settings;
         settings.parameters.voxel_size = 0.125;
         GenerateOptions options;
         options.timeout = timeout;
         return client.Generate("sha256:cube", settings, options).status();
       }},
      {"PutSphereSet",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, PutSphereSet(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, PutSphereSetOk());
         });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client
             .PutSphereSet(SphereSet{{Sphere{Vector3::Zero(), 1.0}}, {}}, "", with(timeout))
             .status();
       }},
      {"GetSphereSet",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, GetSphereSet(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, GetSphereSetOk());
         });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client.GetSphereSet("spheres/v1/two", with(timeout)).status();
       }},
      {"GetHierarchy",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, GetHierarchy(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, HierarchyOk(HierarchyVolume::kRss));
         });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client.GetHierarchy("spheres/v1/two", HierarchyVolume::kRss, with(timeout))
             .status();
       }},
      {"UpdateDeformation",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, UpdateDeformation(_, _))
             .Times(calls)
             .WillRepeatedly([s](auto&, Deadline d) { return s.Answer(d, DeformationOk()); });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client
             .UpdateDeformation("", "spheres/v1/two", testing::UnitCube().vertices, {},
                                with(timeout))
             .status();
       }},
      {"Distance",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, Distance(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, DistanceOk(2));
         });
       },
       [](const Client& client, std::optional<milliseconds> timeout) {
         DistanceOptions options;
         options.timeout = timeout;
         return client
             .Distance("spheres/v1/a", "spheres/v1/b", {RigidPose()}, {RigidPose(), RigidPose()},
                       options)
             .status();
       }},
      {"Evaluate",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, Evaluate(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, EvaluateOk());
         });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client.Evaluate("sha256:cube", "spheres/v1/two", {}, with(timeout)).status();
       }},
      {"CacheStats",
       [](MockConnection& c, int calls, Script s) {
         EXPECT_CALL(c, CacheStats(_, _)).Times(calls).WillRepeatedly([s](auto&, Deadline d) {
           return s.Answer(d, v1::CacheStatsResponse());
         });
       },
       [with](const Client& client, std::optional<milliseconds> timeout) {
         return client.CacheStats(with(timeout)).status();
       }},
  };
}

TEST(Client, EveryUnaryCallRetriesUnavailableThenSucceeds) {
  for (const UnaryRpc& rpc : UnaryRpcs()) {
    SCOPED_TRACE(rpc.name);
    auto connection = std::make_shared<MockConnection>();
    rpc.expect(*connection, 3,
               Script({absl::UnavailableError("connection refused"),
                       absl::UnavailableError("connection reset")}));
    const absl::Status status = rpc.call(Client(connection, FastRetries()), std::nullopt);
    EXPECT_TRUE(status.ok()) << status;
  }
}

TEST(Client, EveryUnaryCallGivesUpAfterTheLastAttempt) {
  for (const UnaryRpc& rpc : UnaryRpcs()) {
    SCOPED_TRACE(rpc.name);
    auto connection = std::make_shared<MockConnection>();
    rpc.expect(*connection, 3,
               Script(std::vector<absl::Status>(4, absl::UnavailableError("down"))));
    const absl::Status status = rpc.call(Client(connection, FastRetries()), std::nullopt);
    EXPECT_EQ(status.code(), absl::StatusCode::kUnavailable);
    EXPECT_THAT(status.message(), HasSubstr("3 attempts"));
  }
}

TEST(Client, EveryUnaryCallReturnsOtherErrorsWithoutRetrying) {
  const std::vector<absl::Status> errors = {
      absl::InvalidArgumentError("mesh.vertices has length 7"),
      absl::NotFoundError("unknown mesh"),
      absl::FailedPreconditionError("set has no contacts"),
      absl::ResourceExhaustedError("limit (--max-poses)"),
      absl::DeadlineExceededError("deadline exceeded"),
      absl::InternalError("bug")};
  for (const UnaryRpc& rpc : UnaryRpcs()) {
    for (const absl::Status& error : errors) {
      SCOPED_TRACE(std::string(rpc.name) + " " + error.ToString());
      auto connection = std::make_shared<MockConnection>();
      rpc.expect(*connection, 1, Script({error}));
      EXPECT_EQ(rpc.call(Client(connection, FastRetries()), std::nullopt), error);
    }
  }
}

TEST(Client, EveryUnaryCallHasOneDeadlineFromItsTimeoutOrTheDefault) {
  ClientOptions options = FastRetries();
  options.default_timeout = std::chrono::seconds(7);
  for (const UnaryRpc& rpc : UnaryRpcs()) {
    for (const std::optional<milliseconds> timeout :
         {std::optional<milliseconds>(), std::optional<milliseconds>(250)}) {
      SCOPED_TRACE(std::string(rpc.name) + (timeout ? " per call" : " default"));
      const milliseconds expected = timeout.value_or(options.default_timeout);
      auto connection = std::make_shared<MockConnection>();
      const Script script({absl::UnavailableError("restarting")});
      rpc.expect(*connection, 2, script);
      const Deadline earliest = std::chrono::system_clock::now() + expected;
      EXPECT_TRUE(rpc.call(Client(connection, options), timeout).ok());
      const Deadline latest = std::chrono::system_clock::now() + expected;
      ASSERT_EQ(script.deadlines().size(), 2u);
      // One deadline for the whole call: the retry does not extend it.
      EXPECT_EQ(script.deadlines()[0], script.deadlines()[1]);
      EXPECT_GE(script.deadlines()[0], earliest);
      EXPECT_LE(script.deadlines()[0], latest);
    }
  }
}

TEST(Client, NoRetryWhenTheBackoffWouldOutliveTheDeadline) {
  ClientOptions options;
  options.default_timeout = milliseconds(50);
  options.retry.initial_backoff = std::chrono::seconds(10);
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(_, _))
      .WillOnce(Return(absl::UnavailableError("connection refused")));
  Client client(connection, options);
  EXPECT_EQ(client.InspectMesh(testing::UnitCube()).status().code(),
            absl::StatusCode::kUnavailable);
}

TEST(Client, InspectMeshSendsTheMeshAndReturnsTheReport) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, InspectMesh(Truly([](const v1::InspectMeshRequest& request) {
                                         return request.mesh().vertices_size() == 24 &&
                                                request.mesh().triangles_size() == 36 &&
                                                request.skip_self_intersections();
                                       }),
                                       _))
      .WillOnce(Return(CubeResponse()));
  InspectMeshOptions call;
  call.skip_self_intersections = true;
  absl::StatusOr<InspectMeshResult> result =
      Client(connection).InspectMesh(testing::UnitCube(), call);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->mesh_sha256, "sha256:cube");
  EXPECT_TRUE(result->report.usable());
  EXPECT_EQ(result->report.triangles, 12);
  EXPECT_DOUBLE_EQ(result->report.volume, 1.0);
}

// A malformed answer of each kind: INTERNAL naming what is wrong, and not retried.
TEST(Client, MalformedResponsesAreInternal) {
  auto connection = std::make_shared<MockConnection>();
  Client client(connection, FastRetries());
  const auto expect_internal = [](const absl::Status& status, const std::string& names) {
    EXPECT_EQ(status.code(), absl::StatusCode::kInternal) << status;
    EXPECT_THAT(status.message(), HasSubstr(names));
  };

  v1::PutMeshResponse put = PutMeshOk();
  put.mutable_report()->add_bbox_min(0.0);  // 4 values
  EXPECT_CALL(*connection, PutMesh(_, _)).WillOnce(Return(put));
  expect_internal(client.PutMesh(testing::UnitCube()).status(), "bbox");

  v1::GenerateResult generated = GenerateOk();
  generated.mutable_spheres()->add_centers(1.0);  // 7 numbers for 2 radii
  EXPECT_CALL(*connection, Generate(_, _, _)).WillOnce(Return(generated));
  expect_internal(client.Generate("sha256:cube", {}).status(), "spheres.centers");

  v1::GetSphereSetResponse got = GetSphereSetOk();
  got.mutable_spheres()->set_radii(1, -1.0);
  EXPECT_CALL(*connection, GetSphereSet(_, _)).WillOnce(Return(got));
  expect_internal(client.GetSphereSet("spheres/v1/two").status(), "sphere 1 has radius -1");

  v1::GetHierarchyResponse garbage;
  garbage.set_hierarchy("not a hierarchy");
  EXPECT_CALL(*connection, GetHierarchy(_, _))
      .WillOnce(Return(garbage))
      .WillOnce(Return(HierarchyOk(HierarchyVolume::kRss)));
  expect_internal(client.GetHierarchy("spheres/v1/two", HierarchyVolume::kRss).status(),
                  "hierarchy");
  expect_internal(client.GetHierarchy("spheres/v1/two", HierarchyVolume::kSphere).status(),
                  "asked for sphere, got rss");

  v1::UpdateDeformationResponse moved = DeformationOk();
  moved.mutable_reference_index()->RemoveLast();
  EXPECT_CALL(*connection, UpdateDeformation(_, _)).WillOnce(Return(moved));
  expect_internal(
      client.UpdateDeformation("", "spheres/v1/two", testing::UnitCube().vertices).status(),
      "reference_index has 1 entries for 2 spheres");

  v1::DistanceResponse ragged = DistanceOk(2);
  ragged.mutable_results()->mutable_points_b()->RemoveLast();
  EXPECT_CALL(*connection, Distance(_, _)).WillOnce(Return(ragged)).WillOnce(Return(DistanceOk(1)));
  const std::vector<RigidPose> two_poses(2);
  expect_internal(
      client.Distance("spheres/v1/a", "spheres/v1/b", {RigidPose()}, two_poses).status(),
      "points_b");
  expect_internal(
      client.Distance("spheres/v1/a", "spheres/v1/b", {RigidPose()}, two_poses).status(),
      "1 entries for 2 pose pairs");

  EXPECT_CALL(*connection, Evaluate(_, _)).WillOnce(Return(v1::EvaluateResponse()));
  expect_internal(client.Evaluate("sha256:cube", "spheres/v1/two").status(), "no quality");
}

// One Client from many threads, every other attempt refused: each call retries on its own.
TEST(Client, ConcurrentCallsRetryIndependently) {
  auto connection = std::make_shared<MockConnection>();
  std::atomic<int> attempts{0};
  EXPECT_CALL(*connection, Distance(_, _))
      .WillRepeatedly([&](const v1::DistanceRequest& request, Deadline) {
        // The first attempt of every call fails; the retry carries the same request.
        thread_local std::string last_failed;
        ++attempts;
        if (last_failed != request.sphere_set_a()) {
          last_failed = request.sphere_set_a();
          return absl::StatusOr<v1::DistanceResponse>(absl::UnavailableError("busy"));
        }
        last_failed.clear();
        return absl::StatusOr<v1::DistanceResponse>(DistanceOk(1));
      });
  const Client client(connection, FastRetries());
  constexpr int kThreads = 8, kCalls = 25;
  std::atomic<int> succeeded{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kCalls; ++i) {
        const std::string key = "spheres/v1/" + std::to_string(t * kCalls + i);
        if (client.Distance(key, key, {RigidPose()}, {RigidPose()}).ok()) ++succeeded;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(succeeded.load(), kThreads * kCalls);
  EXPECT_EQ(attempts.load(), 2 * kThreads * kCalls);
}

TEST(GrpcConnection, UnreachableServerIsUnavailable) {
  // Nothing listens there, so every attempt is refused at once.
  Client client(MakeGrpcConnection("127.0.0.1:" + std::to_string(testing::UnusedLoopbackPort())),
                FastRetries());
  absl::StatusOr<InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kUnavailable) << result.status();

  // A stream opens without contacting the server; its first frame finds out.
  absl::StatusOr<DistanceSession> session = client.OpenDistanceSession();
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->Query({PosePair{"spheres/v1/a", "spheres/v1/b", {}, {}}}).status().code(),
            absl::StatusCode::kUnavailable);
}

}  // namespace
}  // namespace inscribe::client
