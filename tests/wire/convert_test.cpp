#include "inscribe/wire/convert.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "inscribe/solid/mesh_validation.h"
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

// The weld's counts travel with the report (info prints them from the service's answer).
TEST(MeshReportConvert, AWeldedReportKeepsItsCounts) {
  const MeshReport report = ValidateMesh(testing::PerFaceVertices(testing::UnitCube())).report;
  ASSERT_EQ(report.welded_vertices, 36 - 8);
  v1::MeshReport wire;
  wire::MeshReportToProto(report, &wire);
  absl::StatusOr<MeshReport> back = wire::MeshReportFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->welded_vertices, report.welded_vertices);
  EXPECT_EQ(back->weld_collapsed_triangles, report.weld_collapsed_triangles);
  EXPECT_TRUE(back->usable());
}

// Found by the CLI's remote --fill-holes: the repair's counts were not on the wire, so a
// repaired mesh's report came back "not closed".
TEST(MeshReportConvert, AHoleFilledReportStaysClosed) {
  ValidateOptions fill;
  fill.repair.level = MeshRepair::kFill;
  const MeshReport report = ValidateMesh(testing::OpenUnitCube(), fill).report;
  ASSERT_GT(report.holes_filled, 0);
  ASSERT_TRUE(report.closed());
  v1::MeshReport wire;
  wire::MeshReportToProto(report, &wire);
  absl::StatusOr<MeshReport> back = wire::MeshReportFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->holes_filled, report.holes_filled);
  EXPECT_EQ(back->hole_triangles_added, report.hole_triangles_added);
  EXPECT_TRUE(back->closed());
  EXPECT_EQ(back->usable(), report.usable());
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

namespace inscribe::wire {
namespace {

using ::testing::HasSubstr;

bool SameParameters(const SphereSetParameters& a, const SphereSetParameters& b) {
  const MedialSphereOptions &m = a.medial, &n = b.medial;
  return a.voxel_size == b.voxel_size && a.max_spheres == b.max_spheres &&
         m.object_angle == n.object_angle && m.epsilon == n.epsilon && m.samples == n.samples &&
         m.screen_samples == n.screen_samples && m.corner_screen == n.corner_screen &&
         m.pair_angle_margin == n.pair_angle_margin &&
         m.subdivide_boundary == n.subdivide_boundary && m.max_voxels == n.max_voxels &&
         a.kind == b.kind && a.selection == b.selection &&
         (a.kind != SphereSetKind::kDilated || a.dilation.growth == b.dilation.growth) &&
         a.evaluate == b.evaluate &&
         (!a.evaluate || a.quality.surface_samples == b.quality.surface_samples) &&
         a.max_protrusion == b.max_protrusion &&
         (a.kind != SphereSetKind::kCover || a.cover_resolution == b.cover_resolution);
}

TEST(GenerateParameters, EveryOptionSurvivesTheWire) {
  const std::int64_t limit = 20'000'000;
  SphereSetParameters all;
  all.voxel_size = 0.125;
  all.medial.object_angle = 0.5;
  all.medial.epsilon = 1e-3;
  all.medial.samples = 20;
  all.medial.screen_samples = 0;
  all.medial.corner_screen = false;
  all.medial.pair_angle_margin = 0.1;
  all.medial.subdivide_boundary = true;
  all.medial.max_voxels = 12345;
  all.kind = SphereSetKind::kDilated;
  all.dilation.growth = 0.0;
  all.quality.surface_samples = 777;
  SphereSetParameters budget;
  budget.max_spheres = 42;
  budget.evaluate = false;
  SphereSetParameters paper = budget;
  paper.selection = SphereSelection::kPaper;
  SphereSetParameters defaults;  // the default budget goes as max_spheres
  SphereSetParameters cover;
  cover.kind = SphereSetKind::kCover;
  cover.max_protrusion = 0.02;
  cover.cover_resolution = 1.0 / 128;
  SphereSetParameters cover_budget;
  cover_budget.kind = SphereSetKind::kCover;
  cover_budget.max_spheres = 64;
  for (const SphereSetParameters& p : {all, budget, paper, defaults, cover, cover_budget}) {
    v1::GenerateRequest request;
    GenerateRequestToProto("sha256:x", p, MeshRepair::kFill, &request);
    EXPECT_EQ(request.mesh_sha256(), "sha256:x");
    EXPECT_EQ(request.parameters().repair(), v1::MESH_REPAIR_FILL);
    absl::StatusOr<SphereSetParameters> back = SphereSetParametersFromProto(request, limit);
    ASSERT_TRUE(back.ok()) << back.status();
    SphereSetParameters expected = p;
    if (!expected.voxel_size) expected.max_spheres = EffectiveMaxSpheres(p);
    expected.medial.max_voxels = std::min(p.medial.max_voxels, limit);
    EXPECT_TRUE(SameParameters(*back, expected));
  }
  // Defaults are never restated on the wire.
  v1::GenerateRequest plain;
  GenerateRequestToProto("sha256:x", defaults, MeshRepair::kSafe, &plain);
  const v1::GenerateParameters& wire = plain.parameters();
  EXPECT_FALSE(wire.has_screen_samples() || wire.has_corner_screen() ||
               wire.has_pair_angle_margin() || wire.has_dilation_growth() ||
               wire.has_quality_samples() || wire.has_max_protrusion() ||
               wire.has_cover_resolution() || wire.has_selection() || wire.cover());
  EXPECT_EQ(wire.object_angle(), 0.0);
  EXPECT_EQ(wire.samples(), 0);
  // The caller's grid limit always travels: a server with a larger --max-voxels must not
  // lift it (0 would mean "the server's limit").
  EXPECT_EQ(wire.max_voxels(), MedialSphereOptions().max_voxels);
}

TEST(CoverCertificate, RoundTripsWithoutItsCellList) {
  CoverCertificate c;
  c.certified = false;
  c.delta = 0.125;
  c.resolution = 1.0 / 1024;
  c.cells = 1000;
  c.cells_in_sphere = 600;
  c.cells_outside = 300;
  c.failed_cells = 100;
  c.failures.push_back(CoverCell{Vector3(1, 2, 3), 0.5});
  c.uncovered_point = Vector3(0.1, -0.2, 0.3);
  c.uncovered_depth = 0.01;
  c.uncovered_gap = 0.002;
  c.seconds = 1.5;
  c.protrusions = {0.125, -0.5, 1e-300};
  c.mesh_sha256 = "sha256:" + std::string(64, 'a');
  c.spheres_sha256 = "sha256:" + std::string(64, 'b');
  v1::CoverCertificate wire;
  CoverCertificateToProto(c, &wire);
  absl::StatusOr<CoverCertificate> back = CoverCertificateFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->certified, c.certified);
  EXPECT_EQ(back->delta, c.delta);
  EXPECT_EQ(back->resolution, c.resolution);
  EXPECT_EQ(back->cells, c.cells);
  EXPECT_EQ(back->cells_in_sphere, c.cells_in_sphere);
  EXPECT_EQ(back->cells_outside, c.cells_outside);
  EXPECT_EQ(back->failed_cells, c.failed_cells);
  EXPECT_TRUE(back->failures.empty());
  EXPECT_EQ(back->uncovered_point, c.uncovered_point);
  EXPECT_EQ(back->uncovered_depth, c.uncovered_depth);
  EXPECT_EQ(back->uncovered_gap, c.uncovered_gap);
  EXPECT_EQ(back->seconds, c.seconds);
  EXPECT_EQ(back->protrusions, c.protrusions);
  EXPECT_EQ(back->mesh_sha256, c.mesh_sha256);
  EXPECT_EQ(back->spheres_sha256, c.spheres_sha256);
  // A protrusion that is not finite is refused, naming it.
  wire.set_protrusions(1, std::numeric_limits<double>::infinity());
  EXPECT_THAT(std::string(CoverCertificateFromProto(wire).status().message()),
              ::testing::HasSubstr("protrusions[1]"));
  // A certified set has no witness; a malformed one is refused.
  c.uncovered_point.reset();
  wire.Clear();
  CoverCertificateToProto(c, &wire);
  EXPECT_EQ(wire.uncovered_point_size(), 0);
  EXPECT_FALSE(CoverCertificateFromProto(wire)->uncovered_point);
  wire.add_uncovered_point(1.0);
  EXPECT_THAT(CoverCertificateFromProto(wire).status().message(), HasSubstr("uncovered_point"));
  // Options: unset resolution is core's default; outside (0, 1] is refused.
  v1::CertifyCoverRequest request;
  EXPECT_EQ(CoverCertifyOptionsFromProto(request)->resolution, CoverCertifyOptions().resolution);
  request.set_resolution(0.25);
  EXPECT_EQ(CoverCertifyOptionsFromProto(request)->resolution, 0.25);
  request.set_resolution(1.5);
  EXPECT_FALSE(CoverCertifyOptionsFromProto(request).ok());
}

TEST(GenerateParameters, TheServersVoxelLimitCapsTheRequest) {
  v1::GenerateRequest request;
  request.mutable_parameters()->set_voxel_size(0.1);
  request.mutable_parameters()->set_max_voxels(5000);
  EXPECT_EQ(SphereSetParametersFromProto(request, 1000)->medial.max_voxels, 1000);
  EXPECT_EQ(SphereSetParametersFromProto(request, 9000)->medial.max_voxels, 5000);
  request.mutable_parameters()->set_max_voxels(-3);
  EXPECT_EQ(SphereSetParametersFromProto(request, 9000).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(GenerateParameters, BadRequestsNameTheProblem) {
  v1::GenerateRequest neither;
  EXPECT_THAT(SphereSetParametersFromProto(neither, 100).status().message(),
              HasSubstr("exactly one of voxel_size"));
  v1::GenerateRequest both;
  both.mutable_parameters()->set_voxel_size(0.1);
  both.mutable_parameters()->set_max_spheres(10);
  EXPECT_EQ(SphereSetParametersFromProto(both, 100).status().code(),
            absl::StatusCode::kInvalidArgument);
  v1::GenerateRequest angle;
  angle.mutable_parameters()->set_max_spheres(10);
  angle.mutable_parameters()->set_object_angle(-1.0);
  EXPECT_THAT(SphereSetParametersFromProto(angle, 100).status().message(),
              HasSubstr("parameters: object angle"));
  v1::GenerateRequest samples;
  samples.mutable_parameters()->set_max_spheres(10);
  samples.mutable_parameters()->set_quality_samples(-1);
  EXPECT_THAT(SphereSetParametersFromProto(samples, 100).status().message(),
              HasSubstr("surface samples"));
  v1::GenerateRequest selection;
  selection.mutable_parameters()->set_max_spheres(10);
  selection.mutable_parameters()->set_selection("greedy");
  EXPECT_THAT(SphereSetParametersFromProto(selection, 100).status().message(),
              HasSubstr("parameters.selection: unknown sphere selection 'greedy'"));
  v1::GenerateRequest sized;
  sized.mutable_parameters()->set_voxel_size(0.1);
  sized.mutable_parameters()->set_selection("paper");
  EXPECT_THAT(SphereSetParametersFromProto(sized, 100).status().message(),
              HasSubstr("selection spends a sphere budget"));
}

TEST(GenerateParameters, BadCoverRequestsNameTheProblem) {
  const auto refusal = [](const std::function<void(v1::GenerateParameters*)>& set) {
    v1::GenerateRequest request;
    set(request.mutable_parameters());
    absl::StatusOr<SphereSetParameters> p = SphereSetParametersFromProto(request, 100);
    EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(p.status().message());
  };
  EXPECT_THAT(refusal([](v1::GenerateParameters* p) {
                p->set_max_spheres(10), p->set_dilate(true), p->set_cover(true);
              }),
              HasSubstr("dilate and cover"));
  EXPECT_THAT(refusal([](v1::GenerateParameters* p) {
                p->set_cover(true), p->set_max_spheres(10), p->set_max_protrusion(0.1);
              }),
              HasSubstr("exactly one of"));
  EXPECT_THAT(
      refusal([](v1::GenerateParameters* p) { p->set_cover(true), p->set_voxel_size(0.1); }),
      HasSubstr("not a voxel size"));
  EXPECT_THAT(refusal([](v1::GenerateParameters* p) { p->set_max_protrusion(0.1); }),
              HasSubstr("max_protrusion"));
  EXPECT_THAT(
      refusal([](v1::GenerateParameters* p) { p->set_cover(true), p->set_max_protrusion(-1.0); }),
      HasSubstr("max_protrusion"));
  EXPECT_THAT(refusal([](v1::GenerateParameters* p) {
                p->set_cover(true), p->set_max_spheres(10), p->set_cover_resolution(0.0);
              }),
              HasSubstr("resolution"));
}

TEST(GeneratedSphereSet, RoundTripsEveryFigure) {
  GeneratedSphereSet g;
  g.set.spheres = {Sphere{Vector3(1, 2, 3), 0.5}, Sphere{Vector3(-1, 0, 0.25), 0.125}};
  g.set.contacts = {SurfaceContact{3, Vector3(0.2, 0.3, 0.5)}, SurfaceContact{0, Vector3(1, 0, 0)}};
  g.voxel_size = 0.0625;
  g.epsilon = 1e-4;
  g.runs = 6;
  g.stats.grid_voxels = 11, g.stats.visited_voxels = 12, g.stats.boundary_voxels = 13;
  g.stats.screened_voxels = 14, g.stats.crossing_pairs = 15, g.stats.searched_pairs = 16;
  g.stats.candidates = 17, g.stats.closest_point_queries = 18, g.stats.seconds = 0.5;
  DilationResult d;
  d.v_points = 21, d.edge_points = 22, d.degenerate = 23, d.grown = 24;
  d.max_growth = 0.01, d.seconds = 0.25;
  g.dilation = d;
  QualityReport q;
  q.nerr = 0.03, q.spheres = 2, q.coverage = 0.9;
  g.quality = q;
  g.generation_seconds = 1.5;
  g.seconds = 2.5;
  v1::GenerateResult wire;
  GeneratedSphereSetToProto(g, &wire);
  absl::StatusOr<GeneratedSphereSet> back = GeneratedSphereSetFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->set.size(), 2u);
  EXPECT_EQ(back->set.spheres[1].center, g.set.spheres[1].center);
  EXPECT_EQ(back->set.contacts[0].barycentric, g.set.contacts[0].barycentric);
  EXPECT_EQ(back->voxel_size, g.voxel_size);
  EXPECT_EQ(back->epsilon, g.epsilon);
  EXPECT_EQ(back->runs, 6);
  EXPECT_EQ(back->stats.grid_voxels, 11);
  EXPECT_EQ(back->stats.candidates, 17);
  EXPECT_EQ(back->stats.closest_point_queries, 18);
  EXPECT_EQ(back->stats.seconds, 0.5);
  ASSERT_TRUE(back->dilation.has_value());
  EXPECT_EQ(back->dilation->degenerate, 23);
  EXPECT_EQ(back->dilation->max_growth, 0.01);
  ASSERT_TRUE(back->quality.has_value());
  EXPECT_EQ(back->quality->nerr, 0.03);
  EXPECT_EQ(back->generation_seconds, 1.5);
  EXPECT_EQ(back->seconds, 2.5);
  g.dilation.reset();
  g.quality.reset();
  wire.Clear();
  GeneratedSphereSetToProto(g, &wire);
  back = GeneratedSphereSetFromProto(wire);
  ASSERT_TRUE(back.ok());
  EXPECT_FALSE(back->dilation.has_value() || back->quality.has_value());
  wire.mutable_spheres()->set_radii(0, -1.0);
  EXPECT_EQ(GeneratedSphereSetFromProto(wire).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(GeneratedSphereSet, ACoverRoundTripsWithItsKindAndCertificate) {
  GeneratedSphereSet g;
  g.kind = SphereSetKind::kCover;
  g.set.spheres = {Sphere{Vector3(1, 2, 3), 0.5}};
  g.voxel_size = 0.25;
  GeneratedCover cover;
  cover.certificate.certified = true;
  cover.certificate.delta = 0.0625;
  cover.certificate.resolution = 1.0 / 2048;
  cover.certificate.cells = 99;
  cover.grown_spheres = 7;
  cover.candidates = 4321;
  cover.repair_rounds = 2;
  cover.unused_reason = "no construction with more than 3 of the 4 spheres allowed";
  cover.seconds = 0.75;
  g.cover = cover;
  v1::GenerateResult wire;
  GeneratedSphereSetToProto(g, &wire);
  EXPECT_EQ(wire.kind(), v1::SPHERE_SET_KIND_COVER);
  absl::StatusOr<GeneratedSphereSet> back = GeneratedSphereSetFromProto(wire);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->kind, SphereSetKind::kCover);
  ASSERT_TRUE(back->cover.has_value());
  EXPECT_TRUE(back->cover->certificate.certified);
  EXPECT_EQ(back->cover->certificate.delta, 0.0625);
  EXPECT_EQ(back->cover->certificate.resolution, 1.0 / 2048);
  EXPECT_EQ(back->cover->certificate.cells, 99);
  EXPECT_EQ(back->cover->grown_spheres, 7);
  EXPECT_EQ(back->cover->repair_rounds, 2);
  EXPECT_EQ(back->cover->unused_reason,
            "no construction with more than 3 of the 4 spheres allowed");
  EXPECT_EQ(back->cover->seconds, 0.75);
  EXPECT_EQ(back->cover->candidates, 4321);
  EXPECT_FALSE(back->dilation.has_value());

  // A result cached before kinds were recorded: its dilation stats say it is dilated.
  v1::GenerateResult old;
  *old.mutable_spheres() = wire.spheres();
  EXPECT_EQ(GeneratedSphereSetFromProto(old)->kind, SphereSetKind::kInternal);
  old.mutable_dilation()->set_grown(1);
  EXPECT_EQ(GeneratedSphereSetFromProto(old)->kind, SphereSetKind::kDilated);
  wire.mutable_cover()->mutable_certificate()->add_uncovered_point(1.0);
  EXPECT_EQ(GeneratedSphereSetFromProto(wire).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(CertifiedDistanceResults, RoundTripWithAndWithoutAnswers) {
  std::vector<CertifiedDistanceResult> results(3);
  const CloserAnswer answers[] = {CloserAnswer::kYes, CloserAnswer::kNo, CloserAnswer::kUndecided};
  for (int i = 0; i < 3; ++i) {
    CertifiedDistanceResult& r = results[static_cast<std::size_t>(i)];
    r.lower = 0.25 * i;
    r.upper = 0.25 * i + 0.125;
    r.closer = answers[i];
    r.internal.distance = 0.25 * i + 0.0625;
    r.internal.sphere_a = i;
    r.internal.sphere_b = 2 * i;
    r.internal.point_a = Vector3(i, 1, 2);
    r.internal.point_b = Vector3(3, i, 4);
    r.cover.distance = -1.0;  // not sent
  }
  for (const bool with_answers : {true, false}) {
    SCOPED_TRACE(with_answers);
    v1::DistanceResults wire;
    AppendCertifiedDistanceResults(results, with_answers, &wire);
    EXPECT_EQ(wire.answers_size(), with_answers ? 3 : 0);
    absl::StatusOr<std::vector<CertifiedDistanceResult>> back =
        CertifiedDistanceResultsFromProto(wire);
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ((*back)[i].lower, results[i].lower);
      EXPECT_EQ((*back)[i].upper, results[i].upper);
      EXPECT_EQ((*back)[i].closer, with_answers ? results[i].closer : CloserAnswer::kUndecided);
      EXPECT_EQ((*back)[i].internal.distance, results[i].internal.distance);
      EXPECT_EQ((*back)[i].internal.sphere_b, results[i].internal.sphere_b);
      EXPECT_EQ((*back)[i].internal.point_a, results[i].internal.point_a);
      EXPECT_EQ((*back)[i].cover.distance, DistanceResult().distance);
    }
    // The plain reading of the same answers: the internal sets'.
    absl::StatusOr<std::vector<DistanceResult>> plain = DistanceResultsFromProto(wire);
    ASSERT_TRUE(plain.ok());
    EXPECT_EQ((*plain)[2].distance, results[2].internal.distance);
  }
  v1::DistanceResults wire;
  AppendCertifiedDistanceResults(results, true, &wire);
  v1::DistanceResults short_upper = wire;
  short_upper.mutable_upper()->RemoveLast();
  EXPECT_EQ(CertifiedDistanceResultsFromProto(short_upper).status().code(),
            absl::StatusCode::kInvalidArgument);
  v1::DistanceResults unknown = wire;
  unknown.set_answers(1, v1::CLOSER_ANSWER_UNSPECIFIED);
  EXPECT_EQ(CertifiedDistanceResultsFromProto(unknown).status().code(),
            absl::StatusCode::kInvalidArgument);
  v1::DistanceResults plain;
  AppendDistanceResults({results[0].internal}, &plain);
  EXPECT_EQ(CertifiedDistanceResultsFromProto(plain).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(DeformedSpheres, RoundTripWithBounds) {
  DeformedSpheres moved;
  moved.set.spheres = {Sphere{Vector3(0, 0, 1), 0.5}};
  moved.set.contacts = {SurfaceContact{2, Vector3(0.5, 0.5, 0)}};
  moved.reference_index = {7};
  moved.xi = 0.01, moved.max_protrusion = 0.005, moved.shrunk = 1, moved.dropped = 2;
  moved.closest_point_queries = 30, moved.max_shrink_steps = 4, moved.seconds = 0.125;
  DeformationErrorBounds bounds;
  bounds.nerr_lower = 0.1, bounds.nerr_upper = 0.2, bounds.exact = false;
  bounds.volume_mesh = 3, bounds.volume_union = 2, bounds.seconds = 0.5;
  for (const bool uniform : {false, true}) {
    bounds.uniform_xi_holds = uniform;
    bounds.nerr_upper_uniform_xi = uniform ? 0.3 : std::numeric_limits<double>::infinity();
    v1::UpdateDeformationResponse wire;
    DeformedSpheresToProto(moved, &wire);
    DeformationBoundsToProto(bounds, &wire);
    absl::StatusOr<DeformedSpheres> back = DeformedSpheresFromProto(wire);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(back->reference_index, moved.reference_index);
    EXPECT_EQ(back->set.contacts[0].triangle, 2);
    EXPECT_EQ(back->xi, 0.01);
    EXPECT_EQ(back->dropped, 2);
    EXPECT_EQ(back->max_shrink_steps, 4);
    const DeformationErrorBounds b = DeformationBoundsFromProto(wire);
    EXPECT_EQ(b.nerr_upper, 0.2);
    EXPECT_EQ(b.uniform_xi_holds, uniform);
    EXPECT_EQ(b.nerr_upper_uniform_xi, bounds.nerr_upper_uniform_xi);
    wire.add_reference_index(8);
    EXPECT_EQ(DeformedSpheresFromProto(wire).status().code(), absl::StatusCode::kInvalidArgument);
  }
}

TEST(DistanceTolerance, RoundTripsAndRefusesBadNumbers) {
  DistanceRequest t;
  t.abs_err = 0.1, t.rel_err = 0.2;
  v1::DistanceTolerance wire;
  ToleranceToProto(t, &wire);
  EXPECT_FALSE(wire.has_closer_than());
  t.closer_than = -0.5;
  ToleranceToProto(t, &wire);
  absl::StatusOr<DistanceRequest> back = ToleranceFromProto(wire);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->closer_than, -0.5);
  EXPECT_EQ(back->rel_err, 0.2);
  wire.set_abs_err(-1.0);
  EXPECT_EQ(ToleranceFromProto(wire).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(VolumeFromProto(VolumeToProto(HierarchyVolume::kRss)), HierarchyVolume::kRss);
  EXPECT_EQ(VolumeFromProto(v1::HIERARCHY_VOLUME_UNSPECIFIED), HierarchyVolume::kSphere);
}

}  // namespace
}  // namespace inscribe::wire
