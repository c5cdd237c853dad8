#include "inscribe/wire/convert.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inscribe::wire {
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

v1::MeshRepair MeshRepairToProto(MeshRepair repair) {
  switch (repair) {
    case MeshRepair::kNone:
      return v1::MESH_REPAIR_NONE;
    case MeshRepair::kSafe:
      return v1::MESH_REPAIR_SAFE;
    case MeshRepair::kFill:
      return v1::MESH_REPAIR_FILL;
    case MeshRepair::kWrap:
      return v1::MESH_REPAIR_WRAP;
    case MeshRepair::kAuto:
      return v1::MESH_REPAIR_AUTO;
  }
  return v1::MESH_REPAIR_UNSPECIFIED;
}

absl::StatusOr<MeshRepair> MeshRepairFromProto(v1::MeshRepair repair, bool fill_holes) {
  switch (repair) {
    case v1::MESH_REPAIR_UNSPECIFIED:
      return fill_holes ? MeshRepair::kFill : RepairOptions().level;
    case v1::MESH_REPAIR_NONE:
      return MeshRepair::kNone;
    case v1::MESH_REPAIR_SAFE:
      return MeshRepair::kSafe;
    case v1::MESH_REPAIR_FILL:
      return MeshRepair::kFill;
    case v1::MESH_REPAIR_WRAP:
      return MeshRepair::kWrap;
    case v1::MESH_REPAIR_AUTO:
      return MeshRepair::kAuto;
    default:
      break;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("repair level ", static_cast<int>(repair),
                   " is not defined (MESH_REPAIR_NONE, SAFE, FILL, WRAP or AUTO)"));
}

namespace {

template <typename Request>
void RepairToRequest(const RepairOptions& repair, Request* out) {
  out->set_fill_holes(false);
  out->set_weld_tolerance(repair.weld_tolerance);
  v1::MeshRepairOptions* wire = out->mutable_repair();
  wire->set_level(MeshRepairToProto(repair.level));
  wire->set_wrap_alpha(repair.wrap_alpha);
  wire->set_wrap_offset(repair.wrap_offset);
}

template <typename Request>
absl::StatusOr<RepairOptions> RepairFromRequest(const Request& request) {
  absl::StatusOr<MeshRepair> level =
      MeshRepairFromProto(request.repair().level(), request.fill_holes());
  if (!level.ok()) return level.status();
  RepairOptions out;
  out.level = *level;
  out.weld_tolerance = request.weld_tolerance();
  out.wrap_alpha = request.repair().wrap_alpha();
  out.wrap_offset = request.repair().wrap_offset();
  return out;
}

}  // namespace

void RepairOptionsToProto(const RepairOptions& repair, v1::PutMeshRequest* out) {
  RepairToRequest(repair, out);
}
void RepairOptionsToProto(const RepairOptions& repair, v1::InspectMeshRequest* out) {
  RepairToRequest(repair, out);
}
absl::StatusOr<RepairOptions> RepairOptionsFromProto(const v1::PutMeshRequest& request) {
  return RepairFromRequest(request);
}
absl::StatusOr<RepairOptions> RepairOptionsFromProto(const v1::InspectMeshRequest& request) {
  return RepairFromRequest(request);
}

void MeshReportToProto(const MeshReport& report, v1::MeshReport* out) {
  out->set_vertices(report.vertices);
  out->set_triangles(report.triangles);
  out->set_closed(report.closed());
  out->set_usable(report.usable());
  out->set_non_finite_vertices(report.non_finite_vertices);
  out->set_out_of_range_indices(report.out_of_range_indices);
  out->set_welded_vertices(report.welded_vertices);
  out->set_weld_collapsed_triangles(report.weld_collapsed_triangles);
  out->set_weld_moved_within(report.weld_moved_within);
  out->set_flat_shells(report.flat_shells);
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
  out->set_holes_filled(report.holes_filled);
  out->set_hole_triangles_added(report.hole_triangles_added);
  out->set_duplicate_triangles_removed(report.duplicate_triangles_removed);
  out->set_double_walls_removed(report.double_walls_removed);
  out->set_crack_weld_tolerance(report.crack_weld_tolerance);
  out->set_crack_vertices_welded(report.crack_vertices_welded);
  out->set_wrapped(report.wrapped);
  out->set_wrap_alpha(report.wrap_alpha);
  out->set_wrap_offset(report.wrap_offset);
  out->set_wrap_input_triangles(report.wrap_input_triangles);
  out->set_wrap_triangles(report.wrap_triangles);
  out->set_wrap_reach(report.wrap_reach);
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
  out.welded_vertices = report.welded_vertices();
  out.weld_collapsed_triangles = report.weld_collapsed_triangles();
  out.weld_moved_within = report.weld_moved_within();
  out.flat_shells = report.flat_shells();
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
  out.holes_filled = report.holes_filled();
  out.hole_triangles_added = report.hole_triangles_added();
  out.duplicate_triangles_removed = report.duplicate_triangles_removed();
  out.double_walls_removed = report.double_walls_removed();
  out.crack_weld_tolerance = report.crack_weld_tolerance();
  out.crack_vertices_welded = report.crack_vertices_welded();
  out.wrapped = report.wrapped();
  out.wrap_alpha = report.wrap_alpha();
  out.wrap_offset = report.wrap_offset();
  out.wrap_input_triangles = report.wrap_input_triangles();
  out.wrap_triangles = report.wrap_triangles();
  out.wrap_reach = report.wrap_reach();
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

void SphereSetToProto(const SphereSet& set, v1::SphereSet* out) {
  out->Clear();
  out->mutable_centers()->Reserve(static_cast<int>(3 * set.size()));
  out->mutable_radii()->Reserve(static_cast<int>(set.size()));
  for (const Sphere& s : set.spheres) {
    for (int k = 0; k < kPerRow; ++k) out->add_centers(s.center[k]);
    out->add_radii(s.radius);
  }
  for (const SurfaceContact& c : set.contacts) {
    out->add_contact_triangles(c.triangle);
    for (int k = 0; k < kPerRow; ++k) out->add_contact_barycentrics(c.barycentric[k]);
  }
}

absl::StatusOr<SphereSet> SphereSetFromProto(const v1::SphereSet& set, absl::string_view field) {
  const int n = set.radii_size();
  if (set.centers_size() != kPerRow * n) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".centers has length ",
                                                   set.centers_size(), "; expected 3 per radius (",
                                                   n, " radii)"));
  }
  const bool contacts = set.contact_triangles_size() > 0 || set.contact_barycentrics_size() > 0;
  if (contacts && (set.contact_triangles_size() != n || set.contact_barycentrics_size() != 3 * n)) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ": contacts need one triangle and 3 barycentrics per sphere (", n, " spheres), got ",
        set.contact_triangles_size(), " and ", set.contact_barycentrics_size()));
  }
  SphereSet out;
  out.spheres.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Sphere& s = out.spheres[static_cast<std::size_t>(i)];
    s.center = Vector3(set.centers(3 * i), set.centers(3 * i + 1), set.centers(3 * i + 2));
    s.radius = set.radii(i);
    if (!s.center.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ": sphere ", i, " has a non-finite centre"));
    }
    if (!std::isfinite(s.radius) || s.radius <= 0.0) {
      return absl::InvalidArgumentError(absl::StrCat(field, ": sphere ", i, " has radius ",
                                                     s.radius, "; radii must be finite and > 0"));
    }
  }
  if (contacts) {
    out.contacts.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      SurfaceContact& c = out.contacts[static_cast<std::size_t>(i)];
      c.triangle = set.contact_triangles(i);
      c.barycentric = Vector3(set.contact_barycentrics(3 * i), set.contact_barycentrics(3 * i + 1),
                              set.contact_barycentrics(3 * i + 2));
      if (!c.barycentric.allFinite()) {
        return absl::InvalidArgumentError(
            absl::StrCat(field, ": sphere ", i, " has non-finite contact barycentrics"));
      }
    }
  }
  return out;
}

void QualityReportToProto(const QualityReport& r, v1::QualityReport* out) {
  out->set_spheres(r.spheres);
  out->set_volume_mesh(r.volume_mesh);
  out->set_volume_union(r.volume_union);
  out->set_nerr(r.nerr);
  out->set_nerr_is_exact(r.nerr_is_exact);
  out->set_protrusion_max(r.protrusion_max);
  out->set_protrusion_mean(r.protrusion_mean);
  out->set_protrusion_p95(r.protrusion_p95);
  out->set_protruding_spheres(r.protruding_spheres);
  out->set_bbox_diagonal(r.bbox_diagonal);
  out->set_surface_samples(r.surface_samples);
  out->set_coverage(r.coverage);
  out->set_coverage_tolerance(r.coverage_tolerance);
  out->set_boundary_to_union_mean(r.boundary_to_union_mean);
  out->set_boundary_to_union_hausdorff(r.boundary_to_union_hausdorff);
  out->set_radius_min(r.radius_min);
  out->set_radius_max(r.radius_max);
  out->set_fat(r.fat);
  out->set_voxel_size(r.voxel_size);
  out->set_seconds(r.seconds);
  out->set_protrusion_tolerance(r.protrusion_tolerance);
  out->set_fat_up_to_voxel_size(r.fat_up_to_voxel_size);
  out->set_fraction_radius_over_sqrt3_sigma(r.fraction_radius_over_sqrt3_sigma);
}

QualityReport QualityReportFromProto(const v1::QualityReport& r) {
  QualityReport out;
  out.spheres = r.spheres();
  out.volume_mesh = r.volume_mesh();
  out.volume_union = r.volume_union();
  out.nerr = r.nerr();
  out.nerr_is_exact = r.nerr_is_exact();
  out.protrusion_max = r.protrusion_max();
  out.protrusion_mean = r.protrusion_mean();
  out.protrusion_p95 = r.protrusion_p95();
  out.protruding_spheres = r.protruding_spheres();
  out.protrusion_tolerance = r.protrusion_tolerance();
  out.bbox_diagonal = r.bbox_diagonal();
  out.surface_samples = r.surface_samples();
  out.coverage = r.coverage();
  out.coverage_tolerance = r.coverage_tolerance();
  out.boundary_to_union_mean = r.boundary_to_union_mean();
  out.boundary_to_union_hausdorff = r.boundary_to_union_hausdorff();
  out.radius_min = r.radius_min();
  out.radius_max = r.radius_max();
  out.fat_up_to_voxel_size = r.fat_up_to_voxel_size();
  out.voxel_size = r.voxel_size();
  out.fat = r.fat();
  out.fraction_radius_over_sqrt3_sigma = r.fraction_radius_over_sqrt3_sigma();
  out.seconds = r.seconds();
  return out;
}

void PoseToProto(const RigidPose& pose, v1::Pose* out) {
  out->set_qw(pose.rotation.w());
  out->set_qx(pose.rotation.x());
  out->set_qy(pose.rotation.y());
  out->set_qz(pose.rotation.z());
  out->set_tx(pose.translation.x());
  out->set_ty(pose.translation.y());
  out->set_tz(pose.translation.z());
}

namespace {

absl::StatusOr<RigidPose> MakePose(const double* v, absl::string_view what) {
  RigidPose pose;
  pose.rotation = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
  pose.translation = Vector3(v[4], v[5], v[6]);
  absl::StatusOr<RigidPose> normalized = NormalizedPose(pose);
  if (!normalized.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", normalized.status().message()));
  }
  return normalized;
}

constexpr int kPoseNumbers = 7;  // qw, qx, qy, qz, tx, ty, tz

}  // namespace

absl::StatusOr<RigidPose> PoseFromProto(const v1::Pose& pose, absl::string_view field) {
  const double v[kPoseNumbers] = {pose.qw(), pose.qx(), pose.qy(), pose.qz(),
                                  pose.tx(), pose.ty(), pose.tz()};
  return MakePose(v, field);
}

void PosesToProto(const std::vector<RigidPose>& poses, v1::PoseArray* out) {
  out->Clear();
  out->mutable_values()->Reserve(static_cast<int>(kPoseNumbers * poses.size()));
  for (const RigidPose& p : poses) {
    for (double v : {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z(),
                     p.translation.x(), p.translation.y(), p.translation.z()}) {
      out->add_values(v);
    }
  }
}

absl::StatusOr<std::vector<RigidPose>> PosesFromProto(const v1::PoseArray& poses,
                                                      absl::string_view field) {
  if (poses.values_size() % kPoseNumbers != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, " has length ", poses.values_size(),
                     "; expected a multiple of 7 (qw, qx, qy, qz, tx, ty, tz per pose)"));
  }
  std::vector<RigidPose> out(static_cast<std::size_t>(poses.values_size() / kPoseNumbers));
  for (std::size_t i = 0; i < out.size(); ++i) {
    absl::StatusOr<RigidPose> pose =
        MakePose(poses.values().data() + kPoseNumbers * i, absl::StrCat(field, " pose ", i));
    if (!pose.ok()) return pose.status();
    out[i] = *pose;
  }
  return out;
}

namespace {

void AppendDistanceResult(const DistanceResult& r, v1::DistanceResults* out) {
  out->add_distances(r.distance);
  out->add_spheres_a(r.sphere_a);
  out->add_spheres_b(r.sphere_b);
  for (int k = 0; k < kPerRow; ++k) out->add_points_a(r.point_a[k]);
  for (int k = 0; k < kPerRow; ++k) out->add_points_b(r.point_b[k]);
  out->add_closer(r.closer);
}

}  // namespace

void AppendDistanceResults(const std::vector<DistanceResult>& results, v1::DistanceResults* out) {
  for (const DistanceResult& r : results) AppendDistanceResult(r, out);
}

absl::StatusOr<std::vector<DistanceResult>> DistanceResultsFromProto(
    const v1::DistanceResults& in) {
  const int n = in.distances_size();
  if (in.spheres_a_size() != n || in.spheres_b_size() != n || in.points_a_size() != kPerRow * n ||
      in.points_b_size() != kPerRow * n || in.closer_size() != n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "distance results: ", n, " distances but ", in.spheres_a_size(), " spheres_a, ",
        in.spheres_b_size(), " spheres_b, ", in.points_a_size(), " points_a numbers, ",
        in.points_b_size(), " points_b numbers and ", in.closer_size(), " closer flags"));
  }
  std::vector<DistanceResult> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    DistanceResult& r = out[static_cast<std::size_t>(i)];
    r.distance = in.distances(i);
    r.sphere_a = in.spheres_a(i);
    r.sphere_b = in.spheres_b(i);
    r.point_a = Vector3(in.points_a(3 * i), in.points_a(3 * i + 1), in.points_a(3 * i + 2));
    r.point_b = Vector3(in.points_b(3 * i), in.points_b(3 * i + 1), in.points_b(3 * i + 2));
    r.closer = in.closer(i);
  }
  return out;
}

namespace {

v1::CloserAnswer AnswerToProto(CloserAnswer answer) {
  switch (answer) {
    case CloserAnswer::kYes:
      return v1::CLOSER_YES;
    case CloserAnswer::kNo:
      return v1::CLOSER_NO;
    case CloserAnswer::kUndecided:
      break;
  }
  return v1::CLOSER_UNDECIDED;
}

}  // namespace

void AppendCertifiedDistanceResults(const std::vector<CertifiedDistanceResult>& results,
                                    bool answers, v1::DistanceResults* out) {
  for (const CertifiedDistanceResult& r : results) {
    AppendDistanceResult(r.internal, out);
    out->add_lower(r.lower);
    out->add_upper(r.upper);
    if (answers) out->add_answers(AnswerToProto(r.closer));
  }
}

absl::StatusOr<std::vector<CertifiedDistanceResult>> CertifiedDistanceResultsFromProto(
    const v1::DistanceResults& in) {
  absl::StatusOr<std::vector<DistanceResult>> internal = DistanceResultsFromProto(in);
  if (!internal.ok()) return internal.status();
  const int n = in.distances_size();
  if (in.lower_size() != n || in.upper_size() != n ||
      (in.answers_size() != 0 && in.answers_size() != n)) {
    return absl::InvalidArgumentError(
        absl::StrCat("certified distance results: ", n, " distances but ", in.lower_size(),
                     " lower, ", in.upper_size(), " upper and ", in.answers_size(), " answers"));
  }
  std::vector<CertifiedDistanceResult> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    CertifiedDistanceResult& r = out[static_cast<std::size_t>(i)];
    r.lower = in.lower(i);
    r.upper = in.upper(i);
    r.internal = std::move((*internal)[static_cast<std::size_t>(i)]);
    if (in.answers_size() == 0) continue;
    switch (in.answers(i)) {
      case v1::CLOSER_YES:
        r.closer = CloserAnswer::kYes;
        break;
      case v1::CLOSER_NO:
        r.closer = CloserAnswer::kNo;
        break;
      case v1::CLOSER_UNDECIDED:
        r.closer = CloserAnswer::kUndecided;
        break;
      default:
        return absl::InvalidArgumentError(
            absl::StrCat("certified distance results: answer ", i, " is ", in.answers(i)));
    }
  }
  return out;
}

}  // namespace inscribe::wire
