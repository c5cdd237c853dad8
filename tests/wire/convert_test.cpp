#include "inscribe/wire/convert.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "inscribe/mesh_validation.h"
#include "support/synthetic_meshes.h"

namespace inscribe::wire {
namespace {

using ::testing::HasSubstr;

TEST(MeshConvert, RoundTripKeepsEveryValue) {
  Mesh mesh = testing::UnitCube();
  mesh.vertices(3, 1) = -0.125;  // values that are not small integers
  mesh.vertices(5, 2) = 1e300;
  v1::Mesh wire;
  wire::MeshToProto(mesh, &wire);
  ASSERT_EQ(wire.vertices_size(), 8 * 3);
  ASSERT_EQ(wire.triangles_size(), 12 * 3);
  // Row-major packing: vertex 3's y is the 11th value, triangle 1's corners follow triangle 0's.
  EXPECT_EQ(wire.vertices(3 * 3 + 1), -0.125);
  EXPECT_EQ(wire.triangles(3), mesh.triangles(1, 0));
  EXPECT_EQ(wire::TriangleCount(wire), 12);

  absl::StatusOr<Mesh> back = wire::MeshFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->vertices, mesh.vertices);
  EXPECT_EQ(back->triangles, mesh.triangles);
}

TEST(MeshConvert, EmptyMeshRoundTrips) {
  v1::Mesh wire;
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(wire);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->num_vertices(), 0);
  EXPECT_EQ(mesh->num_triangles(), 0);
}

TEST(MeshConvert, RejectsVerticesNotMultipleOfThree) {
  v1::Mesh wire;
  for (int i = 0; i < 7; ++i) wire.add_vertices(i);
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(wire);
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(mesh.status().message(), HasSubstr("mesh.vertices has length 7"));
  EXPECT_EQ(wire::CheckMeshShape(wire).code(), absl::StatusCode::kInvalidArgument);
}

TEST(MeshConvert, RejectsTrianglesNotMultipleOfThreeNamingTheField) {
  v1::Mesh wire;
  wire::MeshToProto(testing::UnitCube(), &wire);
  wire.add_triangles(0);
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(wire, "request.mesh");
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(mesh.status().message(), HasSubstr("request.mesh.triangles has length 37"));
}

TEST(MeshReportConvert, RoundTripOfAnInvertedOpenMesh) {
  // Validation of a real mesh fills counts, issues of several severities and the box.
  Mesh open = testing::OpenUnitCube();
  const MeshReport report = ValidateMesh(open).report;
  ASSERT_FALSE(report.issues.empty());

  v1::MeshReport wire;
  wire::MeshReportToProto(report, &wire);
  EXPECT_EQ(wire.usable(), report.usable());
  EXPECT_EQ(wire.closed(), report.closed());
  EXPECT_EQ(wire.border_edges(), report.border_edges);
  ASSERT_EQ(wire.bbox_max_size(), 3);
  EXPECT_EQ(wire.bbox_max(2), 1.0);

  absl::StatusOr<MeshReport> back = wire::MeshReportFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->vertices, report.vertices);
  EXPECT_EQ(back->triangles, report.triangles);
  EXPECT_EQ(back->border_edges, report.border_edges);
  EXPECT_EQ(back->components, report.components);
  EXPECT_EQ(back->volume, report.volume);
  EXPECT_EQ(back->bbox.min, report.bbox.min);
  EXPECT_EQ(back->bbox.max, report.bbox.max);
  EXPECT_EQ(back->usable(), report.usable());
  EXPECT_EQ(back->closed(), report.closed());
  ASSERT_EQ(back->issues.size(), report.issues.size());
  for (std::size_t i = 0; i < report.issues.size(); ++i) {
    EXPECT_EQ(back->issues[i].severity, report.issues[i].severity);
    EXPECT_EQ(back->issues[i].code, report.issues[i].code);
    EXPECT_EQ(back->issues[i].message, report.issues[i].message);
    EXPECT_EQ(back->issues[i].count, report.issues[i].count);
  }
}

TEST(MeshReportConvert, FixedSeverityRoundTrips) {
  const MeshReport report = ValidateMesh(testing::Inverted(testing::UnitCube())).report;
  v1::MeshReport wire;
  wire::MeshReportToProto(report, &wire);
  ASSERT_EQ(wire.issues_size(), 1);
  EXPECT_EQ(wire.issues(0).severity(), v1::MeshIssue::FIXED);
  absl::StatusOr<MeshReport> back = wire::MeshReportFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->issues[0].severity, Severity::kFixed);
  EXPECT_TRUE(back->usable());
}

TEST(MeshReportConvert, UnknownSeverityIsAWarning) {
  v1::MeshReport wire;
  wire.add_issues()->set_severity(static_cast<v1::MeshIssue::Severity>(42));
  absl::StatusOr<MeshReport> back = wire::MeshReportFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->issues[0].severity, Severity::kWarning);
}

TEST(MeshReportConvert, RejectsBoxCornerOfWrongLength) {
  v1::MeshReport wire;
  wire.add_bbox_min(0.0);
  EXPECT_EQ(wire::MeshReportFromProto(wire).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(StatusConvert, CodesAndMessagesSurviveBothWays) {
  for (int code = 0; code <= 16; ++code) {
    const absl::Status status(static_cast<absl::StatusCode>(code), code == 0 ? "" : "why");
    const grpc::Status wire = wire::ToGrpcStatus(status);
    EXPECT_EQ(static_cast<int>(wire.error_code()), code);
    EXPECT_EQ(wire::FromGrpcStatus(wire), status);
  }
}

}  // namespace
}  // namespace inscribe::wire
