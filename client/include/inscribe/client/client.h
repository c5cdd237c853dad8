// Typed C++ API of the inscribe service: core types in, core types out.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/client/connection.h"
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
#include "inscribe/wire/cache_stats.h"
#include "inscribe/wire/deformation_settings.h"

namespace inscribe::client {

// Retries and failover of idempotent calls: the one place they happen (see connection.h). Only
// UNAVAILABLE (server unreachable, restarting or shedding connections) is retried: every other
// error would come back the same. Each attempt is one RPC; over a routed connection each goes
// to the best replica not known to be down, so failing over to the next replica is the next
// attempt, made at once (no backoff) when the connection says another replica can take it.
struct RetryPolicy {
  // RPCs in total for one call, the first included; 1 disables retries and failover. Give at
  // least the number of replicas to let a call reach every one of them.
  int max_attempts = 3;
  // Wait before the second attempt; each further wait is `multiplier` times longer, capped at
  // max_backoff. Every wait is drawn uniformly from [50%, 100%] of that value (jitter), so that
  // clients that failed together do not retry together.
  std::chrono::milliseconds initial_backoff{100};
  std::chrono::milliseconds max_backoff{2000};
  double multiplier = 2.0;
};

struct ClientOptions {
  // Time allowed for a call when the call does not say, covering all of its attempts and the
  // waits between them.
  std::chrono::milliseconds default_timeout{30'000};
  RetryPolicy retry;
};

struct InspectMeshOptions {
  // Skip the exact self-intersection test (O(#T log #T) on the server).
  bool skip_self_intersections = false;
  // How the server may repair the mesh (core's RepairOptions: level, weld tolerance, wrap
  // parameters); the report and hash are the repaired mesh's.
  RepairOptions repair;
  // Overrides ClientOptions::default_timeout for this call.
  std::optional<std::chrono::milliseconds> timeout;
};

struct InspectMeshResult {
  // "sha256:<64 hex digits>" of the mesh after the server's welding and orientation fixes
  // (equal to FormatSha256(MeshSha256(ValidateMesh(mesh).mesh)) with the same options); empty when
  // the mesh has non-finite coordinates or out-of-range indices.
  std::string mesh_sha256;
  // The server's validation report, as ValidateMesh would return it locally.
  MeshReport report;
};

// Options every call takes: overrides ClientOptions::default_timeout for this call.
struct CallOptions {
  std::optional<std::chrono::milliseconds> timeout;
};

// The repairs PutMesh asks the server for; the stored mesh and its key are the repaired mesh's.
struct PutMeshOptions : CallOptions {
  RepairOptions repair;  // core's RepairOptions (level, weld tolerance, wrap parameters)
};

struct PutMeshResult {
  std::string mesh_sha256;  // "sha256:<64 hex>": the key later calls name the mesh by
  MeshReport report;
  bool already_stored = false;
};

// What to generate (paper Sections III-IV): core's parameters, whose defaults and checks are
// core's (SphereSetParameters), and the mesh repair Generate(mesh, ...) asks PutMesh for.
struct GenerateSettings {
  SphereSetParameters parameters;
  RepairOptions repair;  // PutMeshOptions::repair, for Generate(mesh, ...)
};

struct GenerateOptions : CallOptions {
  // Called on the calling thread with the fraction done, at most every progress_interval.
  std::function<void(double fraction)> on_progress;
  double progress_interval = 0.0;  // seconds; 0 = the server's 0.5 s
};

// The generated set with everything the server computed about it (GeneratedSphereSet: sigma,
// epsilon, runs, statistics, dilation, quality, seconds; `seconds` is the original run's when
// the answer was cached), and where the server found it.
struct GenerateResult : GeneratedSphereSet {
  std::string sphere_set_key;  // "spheres/v1/<64 hex>"
  std::string mesh_sha256;
  std::string cache;  // "memory", "disk", "redis" (the replicas' shared tier), "computed", "joined"
};

struct PutSphereSetResult {
  std::string sphere_set_key;
  bool already_stored = false;
};

struct StoredSphereSet {
  SphereSet spheres;
  std::string mesh_sha256;  // empty when uploaded without a mesh
};

// core's DeformationOptions (xi, strict, direction), bounds and store: wire/'s.
using DeformationSettings = wire::DeformationSettings;

// The moved spheres with the update's figures (DeformedSpheres; the set has contacts, so it can
// serve as a later reference), and what the server adds.
struct DeformationResult : DeformedSpheres {
  std::int64_t reference_spheres = 0;
  std::string deformed_mesh_sha256;
  std::string sphere_set_key;  // when settings.store
  // When settings.bounds (volume_union_shrunk and volume_union_inner are not sent).
  std::optional<DeformationErrorBounds> bounds;
};

struct DistanceOptions : CallOptions {
  HierarchyVolume volume = HierarchyVolume::kSphere;
  DistanceRequest tolerance;  // abs_err, rel_err, closer_than
  // Every sphere pair instead of a hierarchy (BruteForceSeparationDistance on the server).
  bool brute_force = false;
  // A certified query, both or neither: cached covers of the solids whose internal sets are
  // the call's sets A and B (the server's certificate rule: service.proto, Distance). Its
  // sphere distances are exact: abs_err and rel_err must be 0 and brute_force false.
  std::string cover_a, cover_b;
};

struct DistanceBatchResult {
  // Entry i answers pose pair i; witnesses in world frame. With covers: the internal sets'.
  std::vector<DistanceResult> results;
  // With covers only: entry i's certified interval [lower, upper] and closer-than answer
  // (kUndecided without closer_than). Its `internal` is results[i]; `cover` is not sent.
  std::vector<CertifiedDistanceResult> certified;
  double server_seconds = 0.0;     // the server's time on the queries
  double hierarchy_seconds = 0.0;  // ... and on getting both hierarchies (built or cached)
  int threads = 0;                 // threads the queries ran on
  // Bounding-volume and sphere-pair tests over all the queries.
  std::int64_t volume_tests = 0, sphere_tests = 0;
};

// Evaluation options are core's (surface_samples, voxel_size and coverage_tolerance go on the
// wire; the seed and protrusion tolerance are the server's defaults).
using EvaluateSettings = QualityOptions;

// CacheStats as the server reports it: wire's counters (see CacheStatsResponse in
// service.proto).
using ServerCacheStats = wire::CacheStats;

// One object pair of a simulator frame: two cached sets and their world poses.
struct PosePair {
  std::string sphere_set_a;
  std::string sphere_set_b;
  RigidPose pose_a;
  RigidPose pose_b;
  // For DistanceSession::QueryCertified: the covers of the two solids (DistanceOptions'
  // cover_a and cover_b); empty for Query.
  std::string cover_a = {}, cover_b = {};
};

struct DistanceSessionOptions {
  HierarchyVolume volume = HierarchyVolume::kSphere;
  DistanceRequest tolerance;
  // Time allowed for each frame's round trip; a late frame ends the session with
  // DEADLINE_EXCEEDED.
  std::chrono::milliseconds frame_timeout{10'000};
  // Time the whole session may stay open; nullopt = no limit.
  std::optional<std::chrono::milliseconds> session_timeout;
};

// A long-lived DistanceStream call for a simulator loop: one Query per frame, answered in
// order over one HTTP/2 stream (no per-call setup). Not thread-safe; movable, not copyable.
// Any error ends the session: later Query calls return the same error. Destroying an open
// session cancels the call.
class DistanceSession {
 public:
  DistanceSession(std::unique_ptr<DistanceStreamConnection> stream,
                  const DistanceSessionOptions& options);
  DistanceSession(DistanceSession&&) noexcept;
  DistanceSession& operator=(DistanceSession&&) noexcept;
  ~DistanceSession();

  // Distances for every pair of one frame (entry i answers pairs[i]; witnesses in world
  // frame). Frames are numbered 0, 1, ... and the reply's number is checked.
  absl::StatusOr<std::vector<DistanceResult>> Query(const std::vector<PosePair>& pairs);

  // Certified intervals for every pair of one frame, each naming its covers (as
  // Client::Distance with covers; `cover` of each result is not sent). The session's tolerance
  // must then have abs_err and rel_err 0.
  absl::StatusOr<std::vector<CertifiedDistanceResult>> QueryCertified(
      const std::vector<PosePair>& pairs);

  // Ends the stream cleanly; the server's final status.
  absl::Status Close();

 private:
  // Sends one frame of `pairs` and checks the reply's number; any failure ends the session.
  absl::StatusOr<v1::DistanceFrameResult> RoundTrip(const std::vector<PosePair>& pairs);
  // Ends the session with `failure` (its stream cancelled), which it then returns.
  absl::Status Break(absl::Status failure);

  std::unique_ptr<DistanceStreamConnection> stream_;
  DistanceSessionOptions options_;
  std::int64_t next_frame_ = 0;
  absl::Status broken_;  // the error that ended the session, once one has
};

// One object of a scene session: core's object (id, pose, group, mask; its hierarchies stay
// unset: the server resolves them from the keys) and the cached sets it names.
struct SceneSessionObject {
  SceneObject object;
  std::string sphere_set_key;
  // Optional: a cover of the same solid (sphere_set_key is then its internal set), making the
  // object certified under the server's certificate rule (service.proto, Distance).
  std::string cover_key;
};

struct SceneSessionOptions {
  HierarchyVolume volume = HierarchyVolume::kSphere;
  // The scene's query; max_pairs at most the server's --max-scene-pairs.
  SceneQuery query;
  // Pairs never to report.
  std::vector<std::pair<SceneObjectId, SceneObjectId>> ignored;
  // Time allowed for each message's round trip; a late reply ends the session with
  // DEADLINE_EXCEEDED.
  std::chrono::milliseconds frame_timeout{10'000};
  // Time the whole session may stay open; nullopt = no limit.
  std::optional<std::chrono::milliseconds> session_timeout;
};

// What one scene message may change besides poses; applied in this order (remove, add,
// ignore, poses, query).
struct SceneChanges {
  std::vector<SceneObjectId> remove;
  std::vector<SceneSessionObject> add;
  std::vector<std::pair<SceneObjectId, SceneObjectId>> ignore;
  std::vector<std::pair<SceneObjectId, RigidPose>> poses;
  std::optional<SceneQuery> query;  // nullopt: keep the current one
};

// The close pairs of one scene message (SceneFrame: pairs sorted by (a, b), world
// witnesses), and what the server adds.
struct SceneFrameResult : SceneFrame {
  std::int64_t objects = 0;     // in the scene after the message
  double server_seconds = 0.0;  // the server's time on the message
};

// A scene held by the server for the life of one SceneStream call (Client::OpenSceneSession
// creates it): one Frame per simulator frame with the poses that moved, answered with the
// close pairs. Not thread-safe; movable, not copyable. Any error ends the session (and the
// server's scene): later calls return the same error. Destroying an open session cancels the
// call, which frees the scene on the server.
class SceneSession {
 public:
  SceneSession(std::unique_ptr<SceneStreamConnection> stream, const SceneSessionOptions& options);
  SceneSession(SceneSession&&) noexcept;
  SceneSession& operator=(SceneSession&&) noexcept;
  ~SceneSession();

  // The close pairs after `poses` (new world poses of objects that moved).
  absl::StatusOr<SceneFrameResult> Frame(
      const std::vector<std::pair<SceneObjectId, RigidPose>>& poses);
  // The close pairs after `changes`.
  absl::StatusOr<SceneFrameResult> Update(const SceneChanges& changes);

  // The reply to the message that created the scene (its close pairs at the initial poses).
  const SceneFrameResult& created() const { return created_; }

  // Ends the stream cleanly (the server frees the scene); the server's final status.
  absl::Status Close();

 private:
  friend class Client;
  // Sends the creating message: `objects`, options' ignored pairs and query.
  absl::Status Create(const std::vector<SceneSessionObject>& objects);
  // Sends `message` numbered next_frame_ and checks the reply; any failure ends the session.
  absl::StatusOr<SceneFrameResult> RoundTrip(v1::SceneMessage& message);
  absl::Status Break(absl::Status failure);

  std::unique_ptr<SceneStreamConnection> stream_;
  SceneSessionOptions options_;
  SceneFrameResult created_;
  std::int64_t next_frame_ = 0;
  absl::Status broken_;  // the error that ended the session, once one has
};

// Calls the service through a Connection, adding a deadline to every call and retrying
// idempotent calls on UNAVAILABLE (RetryPolicy: exponential backoff, or at once when the
// connection fails over to another replica). Thread-safe; cheap to copy (shares the
// connection).
class Client {
 public:
  explicit Client(std::shared_ptr<Connection> connection, ClientOptions options = {});

  // Validates `mesh` on the server (no state is kept there: idempotent, so retried). Errors:
  // INVALID_ARGUMENT / RESOURCE_EXHAUSTED from the server (message says which limit),
  // UNAVAILABLE after the last attempt, DEADLINE_EXCEEDED. An unusable mesh is not an error:
  // see result.report.usable().
  absl::StatusOr<InspectMeshResult> InspectMesh(const Mesh& mesh,
                                                const InspectMeshOptions& options = {}) const;

  // Every call below is idempotent, so UNAVAILABLE is retried (see RetryPolicy); server errors
  // come back unchanged (codes and messages as service.proto documents them).

  // Validates and stores `mesh` on the server. FAILED_PRECONDITION for an unusable mesh.
  absl::StatusOr<PutMeshResult> PutMesh(const Mesh& mesh, const PutMeshOptions& options = {}) const;

  // Spheres for a stored mesh (cached on the server by content).
  absl::StatusOr<GenerateResult> Generate(const std::string& mesh_sha256,
                                          const GenerateSettings& settings,
                                          const GenerateOptions& options = {}) const;
  // Uploads `mesh` (PutMesh, with settings.repair) and generates; if the
  // server lost the mesh in between (NOT_FOUND: evicted), uploads it once more.
  absl::StatusOr<GenerateResult> Generate(const Mesh& mesh, const GenerateSettings& settings,
                                          const GenerateOptions& options = {}) const;
  // Spheres for `mesh`, which the caller stored as `mesh_sha256` (PutMesh with
  // settings.repair); if the server lost it since (NOT_FOUND: evicted),
  // uploads it once more and asks again, as the overload above does. One deadline for all.
  absl::StatusOr<GenerateResult> Generate(const std::string& mesh_sha256, const Mesh& mesh,
                                          const GenerateSettings& settings,
                                          const GenerateOptions& options = {}) const;

  absl::StatusOr<PutSphereSetResult> PutSphereSet(const SphereSet& spheres,
                                                  const std::string& mesh_sha256 = "",
                                                  const CallOptions& options = {}) const;
  // Uploads a cover with the certificate it was made with (e.g. read back from a file
  // `inscribe generate --cover` wrote), which Distance then takes on the caller's word: the
  // set is keyed with it. INVALID_ARGUMENT when it does not certify (certified false).
  absl::StatusOr<PutSphereSetResult> PutCertifiedCover(const SphereSet& spheres,
                                                       const CoverCertificate& certificate,
                                                       const CallOptions& options = {}) const;
  absl::StatusOr<StoredSphereSet> GetSphereSet(const std::string& sphere_set_key,
                                               const CallOptions& options = {}) const;
  // The server's hierarchy, deserialised (SphereHierarchy::Deserialize checks it).
  absl::StatusOr<SphereHierarchy> GetHierarchy(const std::string& sphere_set_key,
                                               HierarchyVolume volume,
                                               const CallOptions& options = {}) const;

  // Moves the cached set `sphere_set_key` onto `deformed_vertices` (#V x 3, the stored mesh's
  // vertex order). `mesh_sha256` empty = the mesh the set names.
  absl::StatusOr<DeformationResult> UpdateDeformation(const std::string& mesh_sha256,
                                                      const std::string& sphere_set_key,
                                                      const Vertices& deformed_vertices,
                                                      const DeformationSettings& settings = {},
                                                      const CallOptions& options = {}) const;

  // One batch: poses_a holds one pose (for all queries) or one per entry of poses_b. With
  // options.cover_a and cover_b a certified query (DistanceBatchResult::certified).
  absl::StatusOr<DistanceBatchResult> Distance(const std::string& sphere_set_a,
                                               const std::string& sphere_set_b,
                                               const std::vector<RigidPose>& poses_a,
                                               const std::vector<RigidPose>& poses_b,
                                               const DistanceOptions& options = {}) const;

  // Quality of a cached set, or of `spheres` sent inline, against a stored mesh.
  absl::StatusOr<QualityReport> Evaluate(const std::string& mesh_sha256,
                                         const std::string& sphere_set_key,
                                         const EvaluateSettings& settings = {},
                                         const CallOptions& options = {}) const;
  absl::StatusOr<QualityReport> Evaluate(const std::string& mesh_sha256, const SphereSet& spheres,
                                         const EvaluateSettings& settings = {},
                                         const CallOptions& options = {}) const;

  // Whether a cached set, or `spheres` sent inline, provably contains the whole solid of a
  // stored mesh (cover_certificate.h); the certificate's resolution is settings.resolution
  // (the failed cells are not sent, only counted).
  absl::StatusOr<CoverCertificate> CertifyCover(const std::string& mesh_sha256,
                                                const std::string& sphere_set_key,
                                                const CoverCertifyOptions& settings = {},
                                                const CallOptions& options = {}) const;
  absl::StatusOr<CoverCertificate> CertifyCover(const std::string& mesh_sha256,
                                                const SphereSet& spheres,
                                                const CoverCertifyOptions& settings = {},
                                                const CallOptions& options = {}) const;

  absl::StatusOr<ServerCacheStats> CacheStats(const CallOptions& options = {}) const;

  // Opens a DistanceStream session (not retried: a stream is not idempotent as a whole).
  absl::StatusOr<DistanceSession> OpenDistanceSession(
      const DistanceSessionOptions& options = {}) const;

  // Opens a SceneStream and creates its scene of `objects` (not retried). Over several
  // replicas the scene goes to the replica of the first object's set (the first one up in
  // its order); every other set it names must be held there too (uploaded there, or shared
  // through --redis). Errors: the server's, naming the object (NOT_FOUND for an unknown key,
  // ALREADY_EXISTS for a repeated id, RESOURCE_EXHAUSTED over its --max-scene-* limits).
  absl::StatusOr<SceneSession> OpenSceneSession(const std::vector<SceneSessionObject>& objects,
                                                const SceneSessionOptions& options = {}) const;

  const ClientOptions& options() const { return options_; }

 private:
  std::shared_ptr<Connection> connection_;
  ClientOptions options_;
};

}  // namespace inscribe::client
