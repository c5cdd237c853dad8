#include "inscribe/server/convert.h"

#include "absl/strings/str_cat.h"

namespace inscribe::server {
namespace {

// Packed arrays hold one (x, y, z) or (i, j, k) triple per row.
constexpr int kPerRow = 3;

// Both enums number the canonical codes 0 (OK) to 16 (UNAUTHENTICATED) identically.
constexpr int kLastCanonicalCode = 16;

absl::Status CheckTriples(int length, absl::string_view field, absl::string_view name,
                          absl::string_view row_meaning) {
  if (length % kPerRow == 0) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(field, ".", name, " has length ", length,
                                                 "; expected a multiple of 3 (", row_meaning, ")"));
}

v1::MeshIssue::Severity SeverityToProto(Severity severity) {
  switch (severity) {
    case Severity::kError:
      return v1::MeshIssue::ERROR;
    case Severity::kWarning:
      return v1::MeshIssue::WARNING;
    case Severity::kFixed:
      return v1::MeshIssue::FIXED;
  }
  return v1::MeshIssue::SEVERITY_UNSPECIFIED;
}

Severity SeverityFromProto(v1::MeshIssue::Severity severity) {
  switch (severity) {
    case v1::MeshIssue::ERROR:
      return Severity::kError;
    case v1::MeshIssue::FIXED:
      return Severity::kFixed;
    default:
      // WARNING, and anything newer than this build: informative, never a verdict.
      return Severity::kWarning;
  }
}

void CornerToProto(const Vector3& corner, google::protobuf::RepeatedField<double>* out) {
  out->Reserve(kPerRow);
  for (int i = 0; i < kPerRow; ++i) out->Add(corner[i]);
}

absl::StatusOr<Vector3> CornerFromProto(const google::protobuf::RepeatedField<double>& values,
                                        absl::string_view name) {
  if (values.empty()) return Vector3(Vector3::Zero());
  if (values.size() != kPerRow) {
    return absl::InvalidArgumentError(
        absl::StrCat("report.", name, " has length ", values.size(), "; expected 3 (x, y, z)"));
  }
  return Vector3(values[0], values[1], values[2]);
}

}  // namespace

absl::Status CheckMeshShape(const v1::Mesh& mesh, absl::string_view field) {
  if (absl::Status s = CheckTriples(mesh.vertices_size(), field, "vertices", "x, y, z per vertex");
      !s.ok()) {
    return s;
  }
  return CheckTriples(mesh.triangles_size(), field, "triangles", "3 vertex indices per triangle");
}

std::int64_t TriangleCount(const v1::Mesh& mesh) { return mesh.triangles_size() / kPerRow; }

absl::StatusOr<Mesh> MeshFromProto(const v1::Mesh& mesh, absl::string_view field) {
  if (absl::Status s = CheckMeshShape(mesh, field); !s.ok()) return s;
  Mesh out;
  // Both sides are row-major triples, so each array is one contiguous copy.
  out.vertices =
      Eigen::Map<const Vertices>(mesh.vertices().data(), mesh.vertices_size() / kPerRow, kPerRow);
  out.triangles = Eigen::Map<const Triangles>(mesh.triangles().data(),
                                              mesh.triangles_size() / kPerRow, kPerRow);
  return out;
}

void MeshToProto(const Mesh& mesh, v1::Mesh* out) {
  const double* v = mesh.vertices.data();
  out->mutable_vertices()->Assign(v, v + mesh.vertices.size());
  const std::int32_t* t = mesh.triangles.data();
  out->mutable_triangles()->Assign(t, t + mesh.triangles.size());
}

void MeshReportToProto(const MeshReport& report, v1::MeshReport* out) {
  out->set_vertices(report.vertices);
  out->set_triangles(report.triangles);
  out->set_closed(report.closed());
  out->set_usable(report.usable());
  out->set_non_finite_vertices(report.non_finite_vertices);
  out->set_out_of_range_indices(report.out_of_range_indices);
  out->set_degenerate_triangles(report.degenerate_triangles);
  out->set_duplicate_triangles(report.duplicate_triangles);
  out->set_unreferenced_vertices(report.unreferenced_vertices);
  out->set_border_edges(report.border_edges);
  out->set_non_manifold_edges(report.non_manifold_edges);
  out->set_non_manifold_vertices(report.non_manifold_vertices);
  out->set_inconsistent_edges(report.inconsistent_edges);
  out->set_components(report.components);
  out->set_flipped_triangles(report.flipped_triangles);
  out->set_self_intersections_checked(report.self_intersections_checked);
  out->set_self_intersecting_pairs(report.self_intersecting_pairs);
  out->set_volume(report.volume);
  out->clear_bbox_min();
  out->clear_bbox_max();
  CornerToProto(report.bbox.min, out->mutable_bbox_min());
  CornerToProto(report.bbox.max, out->mutable_bbox_max());
  out->clear_issues();
  out->mutable_issues()->Reserve(static_cast<int>(report.issues.size()));
  for (const MeshIssue& issue : report.issues) {
    v1::MeshIssue* wire = out->add_issues();
    wire->set_severity(SeverityToProto(issue.severity));
    wire->set_code(issue.code);
    wire->set_message(issue.message);
    wire->set_count(issue.count);
  }
}

absl::StatusOr<MeshReport> MeshReportFromProto(const v1::MeshReport& report) {
  absl::StatusOr<Vector3> lo = CornerFromProto(report.bbox_min(), "bbox_min");
  if (!lo.ok()) return lo.status();
  absl::StatusOr<Vector3> hi = CornerFromProto(report.bbox_max(), "bbox_max");
  if (!hi.ok()) return hi.status();
  MeshReport out;
  out.vertices = report.vertices();
  out.triangles = report.triangles();
  out.non_finite_vertices = report.non_finite_vertices();
  out.out_of_range_indices = report.out_of_range_indices();
  out.degenerate_triangles = report.degenerate_triangles();
  out.duplicate_triangles = report.duplicate_triangles();
  out.unreferenced_vertices = report.unreferenced_vertices();
  out.border_edges = report.border_edges();
  out.non_manifold_edges = report.non_manifold_edges();
  out.non_manifold_vertices = report.non_manifold_vertices();
  out.inconsistent_edges = report.inconsistent_edges();
  out.components = report.components();
  out.flipped_triangles = report.flipped_triangles();
  out.self_intersections_checked = report.self_intersections_checked();
  out.self_intersecting_pairs = report.self_intersecting_pairs();
  out.volume = report.volume();
  out.bbox.min = *lo;
  out.bbox.max = *hi;
  out.issues.reserve(static_cast<std::size_t>(report.issues_size()));
  for (const v1::MeshIssue& wire : report.issues()) {
    out.issues.push_back(
        MeshIssue{SeverityFromProto(wire.severity()), wire.code(), wire.message(), wire.count()});
  }
  return out;
}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  const int code = static_cast<int>(status.code());
  return grpc::Status(code > 0 && code <= kLastCanonicalCode ? static_cast<grpc::StatusCode>(code)
                                                             : grpc::StatusCode::UNKNOWN,
                      std::string(status.message()));
}

absl::Status FromGrpcStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  const int code = static_cast<int>(status.error_code());
  return absl::Status(code > 0 && code <= kLastCanonicalCode ? static_cast<absl::StatusCode>(code)
                                                             : absl::StatusCode::kUnknown,
                      status.error_message());
}

}  // namespace inscribe::server
