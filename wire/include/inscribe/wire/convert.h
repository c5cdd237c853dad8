// Conversion between the wire types of proto/inscribe/v1 and the core types, both ways, and
// between grpc::Status and absl::Status. The only place where the two worlds meet: the server
// and the client library both go through these functions, so a field is mapped exactly once
// (a new field is one proto change plus its lines here).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "grpcpp/support/status.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/scene/scene.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/v1/mesh.pb.h"
#include "inscribe/v1/service.pb.h"
#include "inscribe/v1/spheres.pb.h"
#include "inscribe/wire/cache_stats.h"
#include "inscribe/wire/deformation_settings.h"

namespace inscribe::wire {

// OK when the packed arrays of `mesh` have lengths that are multiples of 3, otherwise
// INVALID_ARGUMENT naming the field (prefixed by `field`, e.g. "mesh.vertices") and its
// length. O(1): cheap enough for a gRPC thread, so malformed requests never reach the pool.
absl::Status CheckMeshShape(const v1::Mesh& mesh, absl::string_view field = "mesh");

// Number of triangles the message describes (length of triangles / 3), O(1); for limit checks
// before any copy is made.
std::int64_t TriangleCount(const v1::Mesh& mesh);

// Copies the packed arrays into a core Mesh (#V x 3 doubles, #T x 3 int32, same units, frame and
// 0-based indices). Fails as CheckMeshShape does; index ranges and coordinates are not
// checked here (that is ValidateMesh's job, which reports them as issues). Cost O(#V + #T).
absl::StatusOr<Mesh> MeshFromProto(const v1::Mesh& mesh, absl::string_view field = "mesh");

// The inverse of MeshFromProto: a Mesh always has whole rows, so this cannot fail.
void MeshToProto(const Mesh& mesh, v1::Mesh* out);

// Every count, measure and issue of `report`; closed and usable are evaluated once here.
void MeshReportToProto(const MeshReport& report, v1::MeshReport* out);

// The inverse of MeshReportToProto. closed() and usable() of the result are recomputed from the
// counts and issues (they agree with the wire's closed/usable for reports made by
// MeshReportToProto). An issue severity this build does not know (a newer server) becomes
// kWarning. INVALID_ARGUMENT when bbox_min or bbox_max has a length other than 0 or 3.
absl::StatusOr<MeshReport> MeshReportFromProto(const v1::MeshReport& report);

// Spheres and contacts as packed arrays (contacts only when the set has them).
void SphereSetToProto(const SphereSet& set, v1::SphereSet* out);

// The inverse, checking shapes and numbers: INVALID_ARGUMENT naming the field (prefixed by
// `field`) for centres not 3 per radius, contacts of the wrong length, a non-finite centre,
// a radius that is not finite and > 0, or barycentrics that are not finite. O(#spheres).
absl::StatusOr<SphereSet> SphereSetFromProto(const v1::SphereSet& set,
                                             absl::string_view field = "spheres");

void QualityReportToProto(const QualityReport& report, v1::QualityReport* out);
// The inverse: every field, unchecked (a report is numbers only).
QualityReport QualityReportFromProto(const v1::QualityReport& report);

// A cover certificate, without its list of failed cells (counted in failed_cells).
void CoverCertificateToProto(const CoverCertificate& certificate, v1::CoverCertificate* out);
// INVALID_ARGUMENT when uncovered_point has other than 0 or 3 numbers.
absl::StatusOr<CoverCertificate> CoverCertificateFromProto(const v1::CoverCertificate& certificate);
// Certification options of a request (resolution unset: core's default); INVALID_ARGUMENT for
// a resolution outside (0, 1].
absl::StatusOr<CoverCertifyOptions> CoverCertifyOptionsFromProto(
    const v1::CertifyCoverRequest& request);

void PoseToProto(const RigidPose& pose, v1::Pose* out);
// The pose with its quaternion normalised (NormalizedPose); INVALID_ARGUMENT naming `field`.
absl::StatusOr<RigidPose> PoseFromProto(const v1::Pose& pose, absl::string_view field = "pose");

void PosesToProto(const std::vector<RigidPose>& poses, v1::PoseArray* out);
// Every pose normalised; INVALID_ARGUMENT naming the field and the pose index for a length
// that is not a multiple of 7 or a bad pose.
absl::StatusOr<std::vector<RigidPose>> PosesFromProto(const v1::PoseArray& poses,
                                                      absl::string_view field = "poses");

// Appends one result per query (witness points in the world frame, as computed).
void AppendDistanceResults(const std::vector<DistanceResult>& results, v1::DistanceResults* out);
// The inverse, all queries of `results`; INVALID_ARGUMENT when the arrays' lengths disagree.
absl::StatusOr<std::vector<DistanceResult>> DistanceResultsFromProto(
    const v1::DistanceResults& results);

// Appends certified answers: each result's internal-set answer as AppendDistanceResults does,
// its lower and upper, and its closer answer when `answers` (closer_than was asked).
void AppendCertifiedDistanceResults(const std::vector<CertifiedDistanceResult>& results,
                                    bool answers, v1::DistanceResults* out);
// The inverse, all queries of `results`: lower, upper, closer (kUndecided when no answers were
// sent) and internal; the covers' answer is not sent (`cover` is left empty). INVALID_ARGUMENT
// when the arrays' lengths disagree (no lower and upper: not a certified answer) or an answer
// is unknown.
absl::StatusOr<std::vector<CertifiedDistanceResult>> CertifiedDistanceResultsFromProto(
    const v1::DistanceResults& results);

// A scene object's id, pose, group and mask, and the keys of its sets (`cover` empty: not
// certified). Group and mask are sent only when not core's defaults.
void SceneObjectToProto(const SceneObject& object, const std::string& sphere_set,
                        const std::string& cover, v1::SceneObject* out);
// The object's id, pose (normalised), group and mask (core's defaults where unset), without
// hierarchies: the receiver resolves the keys. INVALID_ARGUMENT naming `field` and the id for
// a bad pose or an empty sphere_set key.
absl::StatusOr<SceneObject> SceneObjectFromProto(const v1::SceneObject& object,
                                                 absl::string_view field);

// Poses of moved objects: ids into pose_ids, poses into poses (7 numbers each).
void ScenePosesToProto(const std::vector<std::pair<SceneObjectId, RigidPose>>& poses,
                       v1::SceneMessage* out);
// The inverse, poses normalised: INVALID_ARGUMENT naming the index for a bad pose, or when
// pose_ids and poses disagree in length.
absl::StatusOr<std::vector<std::pair<SceneObjectId, RigidPose>>> ScenePosesFromProto(
    const v1::SceneMessage& message);

// Ignored pairs, two ids each, into `ignore`.
void SceneIgnoredToProto(const std::vector<std::pair<SceneObjectId, SceneObjectId>>& pairs,
                         v1::SceneMessage* out);
// INVALID_ARGUMENT for an odd number of ids.
absl::StatusOr<std::vector<std::pair<SceneObjectId, SceneObjectId>>> SceneIgnoredFromProto(
    const v1::SceneMessage& message);

// max_pairs goes only when not core's default.
void SceneQueryToProto(const SceneQuery& query, v1::SceneQuery* out);
// Core's query, core's max_pairs default where unset (capped at `max_pairs_limit`), then
// CheckSceneQuery: INVALID_ARGUMENT "query: <why>". A max_pairs set above `max_pairs_limit`
// is RESOURCE_EXHAUSTED naming `limit_name` (the server's flag).
absl::StatusOr<SceneQuery> SceneQueryFromProto(const v1::SceneQuery& query,
                                               std::int64_t max_pairs_limit,
                                               absl::string_view limit_name);

// A frame's pairs and counts (the reply's frame number, object count and seconds are the
// caller's).
void SceneFrameToProto(const SceneFrame& frame, v1::SceneReply* out);
// The inverse; INVALID_ARGUMENT when the pair arrays' lengths disagree.
absl::StatusOr<SceneFrame> SceneFrameFromProto(const v1::SceneReply& reply);

// HIERARCHY_VOLUME_UNSPECIFIED and SPHERE are the sphere hierarchy.
v1::HierarchyVolume VolumeToProto(HierarchyVolume volume);
HierarchyVolume VolumeFromProto(v1::HierarchyVolume volume);

// closer_than is sent only when asked (core's "unset" is +infinity, the wire's is absence);
// other values, NaN included, go as they are for the receiver to judge.
void ToleranceToProto(const DistanceRequest& tolerance, v1::DistanceTolerance* out);
// INVALID_ARGUMENT for negative or non-finite errors or a NaN closer_than.
absl::StatusOr<DistanceRequest> ToleranceFromProto(const v1::DistanceTolerance& tolerance);

// Mesh repair levels. MESH_REPAIR_UNSPECIFIED is core's default (safe), or fill when the
// request's older `fill_holes` flag is set; INVALID_ARGUMENT for a value the proto does not
// define.
v1::MeshRepair MeshRepairToProto(MeshRepair repair);
absl::StatusOr<MeshRepair> MeshRepairFromProto(v1::MeshRepair repair, bool fill_holes);
// The repair a PutMesh or InspectMesh request asks for (its repair, weld_tolerance and older
// fill_holes fields) and back. Errors as MeshRepairFromProto's (the numbers are judged by
// ValidateMesh, which names the bad one).
void RepairOptionsToProto(const RepairOptions& repair, v1::PutMeshRequest* out);
void RepairOptionsToProto(const RepairOptions& repair, v1::InspectMeshRequest* out);
absl::StatusOr<RepairOptions> RepairOptionsFromProto(const v1::PutMeshRequest& request);
absl::StatusOr<RepairOptions> RepairOptionsFromProto(const v1::InspectMeshRequest& request);

// Generation parameters. A field at core's default is left unset (or 0 where the proto says
// "0 = default"), so the wire never restates a default. `repair` is the mesh repair the
// caller stored the mesh with; parameters.evaluate goes as skip_quality.
void GenerateRequestToProto(const std::string& mesh_sha256, const SphereSetParameters& parameters,
                            MeshRepair repair, v1::GenerateRequest* out);
// The core parameters of a request, core's defaults where the wire leaves a field unset, then
// CheckSphereSetParameters: INVALID_ARGUMENT "parameters: <why>". Exactly one of voxel_size,
// max_spheres (> 0) and max_protrusion must be set on the wire, and at most one of dilate and
// cover. `max_voxels_limit` (> 0) caps the voxel limit and
// stands in for an unset one.
absl::StatusOr<SphereSetParameters> SphereSetParametersFromProto(const v1::GenerateRequest& request,
                                                                 std::int64_t max_voxels_limit);

// Everything of a generated set but its key, mesh and cache source (a cover's certificate
// without its list of failed cells).
void GeneratedSphereSetToProto(const GeneratedSphereSet& generated, v1::GenerateResult* out);
// The inverse; INVALID_ARGUMENT as SphereSetFromProto for bad spheres, as
// CoverCertificateFromProto for a malformed certificate.
absl::StatusOr<GeneratedSphereSet> GeneratedSphereSetFromProto(const v1::GenerateResult& result);

// Evaluation options (Evaluate): the sample count, the voxel size and the coverage tolerance go
// on the wire, each left unset at core's default; the seed and protrusion tolerance are core's.
void QualityOptionsToProto(const QualityOptions& options, v1::EvaluateRequest* out);
// Core's defaults where the wire leaves a field unset (a negative sample count is none), then
// CheckQualityOptions and a finite coverage tolerance: INVALID_ARGUMENT otherwise.
absl::StatusOr<QualityOptions> QualityOptionsFromProto(const v1::EvaluateRequest& request);

// An UpdateDeformation request's settings (deformation_settings.h).
void DeformationSettingsToProto(const DeformationSettings& settings,
                                v1::UpdateDeformationRequest* out);
// CheckDeformationOptions' INVALID_ARGUMENT for settings core refuses.
absl::StatusOr<DeformationSettings> DeformationSettingsFromProto(
    const v1::UpdateDeformationRequest& request);

// A deformation update's spheres and figures, and its error bounds.
void DeformedSpheresToProto(const DeformedSpheres& moved, v1::UpdateDeformationResponse* out);
// INVALID_ARGUMENT for bad spheres or a reference_index of another length than the spheres.
absl::StatusOr<DeformedSpheres> DeformedSpheresFromProto(
    const v1::UpdateDeformationResponse& response);
void DeformationBoundsToProto(const DeformationErrorBounds& bounds,
                              v1::UpdateDeformationResponse* out);
// The bounds the wire carries (volume_union_shrunk and volume_union_inner are not sent;
// nerr_upper_uniform_xi is +infinity and uniform_xi_holds false when absent).
DeformationErrorBounds DeformationBoundsFromProto(const v1::UpdateDeformationResponse& response);

// The result cache's counters (cache_stats.h), every one in kCacheStatsCounters to and from
// the CacheStatsResponse field of its name; a field the sender left unset reads as 0.
void CacheStatsToProto(const CacheStats& stats, v1::CacheStatsResponse* out);
CacheStats CacheStatsFromProto(const v1::CacheStatsResponse& response);

// absl and gRPC share the canonical status codes (same numbers, same meaning), so these map
// code and message unchanged; error details are not carried.
grpc::Status ToGrpcStatus(const absl::Status& status);
absl::Status FromGrpcStatus(const grpc::Status& status);

}  // namespace inscribe::wire
