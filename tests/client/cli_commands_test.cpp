// The CLI's two rules in one place each: how a command's status becomes stderr and an exit
// status (command_outcome.h), and that embedded mode is the service in-process
// (service_session.h), answering as core does.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "command_outcome.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/solid/solid.h"
#include "service_session.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe::cli {
namespace {

using ::testing::HasSubstr;

TEST(CommandOutcome, ServiceCodesMapToTheDocumentedExitStatuses) {
  const struct {
    absl::StatusCode code;
    int exit_code;
  } cases[] = {
      {absl::StatusCode::kUnavailable, kExitServerUnavailable},
      {absl::StatusCode::kDeadlineExceeded, kExitServerUnavailable},
      {absl::StatusCode::kInvalidArgument, kExitBadInput},
      {absl::StatusCode::kNotFound, kExitBadInput},
      {absl::StatusCode::kOutOfRange, kExitBadInput},
      {absl::StatusCode::kResourceExhausted, kExitBadInput},
      {absl::StatusCode::kFailedPrecondition, kExitUnusableMesh},
      {absl::StatusCode::kUnauthenticated, kExitNotAuthorized},
      {absl::StatusCode::kPermissionDenied, kExitNotAuthorized},
      {absl::StatusCode::kInternal, kExitInternal},
      {absl::StatusCode::kUnimplemented, kExitInternal},
      {absl::StatusCode::kUnknown, kExitInternal},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(ExitCodeOf(absl::Status(c.code, "x")), c.exit_code)
        << absl::StatusCodeToString(c.code);
  }
  EXPECT_EQ(ExitCodeOf(absl::OkStatus()), kExitOk);
}

TEST(CommandOutcome, LocalErrorsCarryTheirOwnExitStatus) {
  EXPECT_EQ(ExitCodeOf(BadInputError("x")), kExitBadInput);
  EXPECT_EQ(ExitCodeOf(UnusableMeshError("x")), kExitUnusableMesh);
  EXPECT_EQ(ExitCodeOf(UsageError("x")), kExitUsage);
  EXPECT_EQ(ExitCodeOf(BugError("x")), kExitInternal);
  EXPECT_EQ(ExitCodeOf(CommandError(absl::StatusCode::kUnavailable, "x", 69)), 69);
  // A service answer read differently keeps its code and message.
  const absl::Status usage = WithExitCode(absl::InvalidArgumentError("bad angle"), kExitUsage);
  EXPECT_EQ(ExitCodeOf(usage), kExitUsage);
  EXPECT_EQ(usage.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(usage.message(), "bad angle");
  // Context goes before the message and keeps the exit status.
  const absl::Status context = WithContext("mesh.off", usage);
  EXPECT_EQ(context.message(), "mesh.off: bad angle");
  EXPECT_EQ(ExitCodeOf(context), kExitUsage);
}

std::string Reported(const CommandOutcome& outcome, int* exit_code) {
  ::testing::internal::CaptureStderr();
  *exit_code = ReportOutcome(outcome);
  return ::testing::internal::GetCapturedStderr();
}

TEST(CommandOutcome, PrintsOneLineNamingTheServerOnlyForItsAnswers) {
  int exit_code = -1;
  EXPECT_EQ(Reported({absl::OkStatus(), "h:1"}, &exit_code), "");
  EXPECT_EQ(exit_code, kExitOk);
  EXPECT_EQ(Reported({absl::UnavailableError("down"), "h:1"}, &exit_code),
            "inscribe: down (server h:1: UNAVAILABLE)\n");
  EXPECT_EQ(exit_code, kExitServerUnavailable);
  // Embedded mode: the same answer, no server to name.
  EXPECT_EQ(Reported({absl::FailedPreconditionError("not closed"), ""}, &exit_code),
            "inscribe: not closed\n");
  EXPECT_EQ(exit_code, kExitUnusableMesh);
  // A failure found here is not the server's, even with --server.
  EXPECT_EQ(Reported({BadInputError("a.off: cannot read"), "h:1"}, &exit_code),
            "inscribe: a.off: cannot read\n");
  EXPECT_EQ(exit_code, kExitBadInput);
  EXPECT_EQ(
      Reported({WithExitCode(absl::InvalidArgumentError("p"), kExitUsage), "h:1"}, &exit_code),
      "inscribe: p (server h:1: INVALID_ARGUMENT)\n");
  EXPECT_EQ(exit_code, kExitUsage);
}

// Embedded mode is the service in this process: what it generates is what core generates,
// sphere for sphere, and its limits are core's, not a shared server's.
TEST(ServiceSession, EmbeddedGeneratesWhatCoreGenerates) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(RemoteOptions{});
  ASSERT_TRUE(session.ok()) << session.status();
  client::GenerateSettings settings;
  settings.parameters.max_spheres = 60;
  absl::StatusOr<client::GenerateResult> served = (*session)->client().Generate(mesh, settings);
  ASSERT_TRUE(served.ok()) << served.status();

  absl::StatusOr<Solid> solid = PrepareSolid(mesh);
  ASSERT_TRUE(solid.ok()) << solid.status();
  absl::StatusOr<GeneratedSphereSet> core = GenerateSphereSet(*solid, settings.parameters);
  ASSERT_TRUE(core.ok()) << core.status();
  EXPECT_EQ(served->mesh_sha256, solid->sha256);
  EXPECT_EQ(served->voxel_size, core->voxel_size);
  EXPECT_EQ(served->epsilon, core->epsilon);
  ASSERT_EQ(served->set.size(), core->set.size());
  for (std::size_t i = 0; i < core->set.size(); ++i) {
    EXPECT_EQ(served->set.spheres[i].center, core->set.spheres[i].center) << i;
    EXPECT_EQ(served->set.spheres[i].radius, core->set.spheres[i].radius) << i;
  }
  ASSERT_TRUE(served->quality && core->quality);
  EXPECT_EQ(served->quality->nerr, core->quality->nerr);
}

TEST(ServiceSession, EmbeddedTakesCoresGridLimitInBothDirections) {
  const Mesh cube = testing::UnitCube();
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(RemoteOptions{});
  ASSERT_TRUE(session.ok()) << session.status();
  client::GenerateSettings settings;
  // 1e9 voxels: over core's default limit, refused by core's rule and message.
  settings.parameters.voxel_size = 1e-3;
  absl::StatusOr<client::GenerateResult> refused = (*session)->client().Generate(cube, settings);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("20000000"));
  EXPECT_THAT(refused.status().message(), ::testing::Not(HasSubstr("--max-voxels")));
  // A limit above a shared server's default is the caller's to raise here.
  settings.parameters.voxel_size = 0.04;  // 15,625 voxels
  settings.parameters.medial.max_voxels = 100;
  EXPECT_EQ((*session)->client().Generate(cube, settings).status().code(),
            absl::StatusCode::kInvalidArgument);
  settings.parameters.medial.max_voxels = 30'000'000;
  EXPECT_TRUE((*session)->client().Generate(cube, settings).ok());
}

// CertifyCover through the in-process service gives core's certificate, figure for figure.
TEST(ServiceSession, CertifiesAsCoreDoes) {
  const Mesh cube = testing::UnitCube();
  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(RemoteOptions{});
  ASSERT_TRUE(session.ok()) << session.status();
  absl::StatusOr<client::PutMeshResult> stored = (*session)->client().PutMesh(cube);
  ASSERT_TRUE(stored.ok()) << stored.status();
  absl::StatusOr<Solid> solid = PrepareSolid(cube);
  ASSERT_TRUE(solid.ok()) << solid.status();
  CoverCertifyOptions options;
  options.resolution = 1.0 / 64;
  for (const double radius : {0.8, 0.9}) {  // short of the corners, then past them
    SCOPED_TRACE(radius);
    SphereSet set;
    set.spheres = {Sphere{Vector3::Constant(0.5), radius}};
    absl::StatusOr<CoverCertificate> served =
        (*session)->client().CertifyCover(stored->mesh_sha256, set, options);
    ASSERT_TRUE(served.ok()) << served.status();
    absl::StatusOr<CoverCertificate> core = CertifyCover(*solid, set.spheres, options);
    ASSERT_TRUE(core.ok()) << core.status();
    EXPECT_EQ(served->certified, radius > std::sqrt(0.75));
    EXPECT_EQ(served->certified, core->certified);
    EXPECT_EQ(served->delta, core->delta);
    EXPECT_EQ(served->cells, core->cells);
    EXPECT_EQ(served->failed_cells, core->failed_cells);
    EXPECT_EQ(served->uncovered_point, core->uncovered_point);
    EXPECT_EQ(served->uncovered_depth, core->uncovered_depth);
    EXPECT_TRUE(served->failures.empty());  // counted, not sent
  }
  // A resolution outside (0, 1] is the caller's mistake.
  options.resolution = 0.0;
  EXPECT_EQ(
      (*session)->client().CertifyCover(stored->mesh_sha256, SphereSet{}, options).status().code(),
      absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inscribe::cli
