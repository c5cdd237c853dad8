#include "distance_command.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "cover_verdict.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/base/atomic_file.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/generation/sphere_file_record.h"
#include "nlohmann/json.hpp"
#include "output_files.h"
#include "pose_file.h"
#include "remote_options.h"
#include "service_session.h"
#include "solid_loading.h"

namespace inscribe::cli {
namespace {

struct DistanceCliOptions {
  std::string a_path, b_path, poses_path;
  SphereFileReadOptions a_read, b_read;  // .sph level, YAML link
  // A certified query: covers of A's and B's solids, and the meshes that certify a cover whose
  // file records no certificate, or one that does not name its spheres and that mesh.
  std::string cover_paths[2], mesh_paths[2];
  std::string hierarchy = "sphere";
  std::string output_path;
  DistanceRequest request;
  bool json = false;
  RemoteOptions remote;

  bool certified() const { return !cover_paths[0].empty(); }
};

// One solid's cover as read: its spheres, and without the mesh the certificate its file records
// (UsableCoverCertificate; with the mesh it is checked against that mesh when stored).
struct CoverInput {
  SphereFile file;
  std::optional<CoverCertificate> certificate;
};

// CSV of the answers; a certified query adds lower,upper (and closer with --closer-than).
std::string FormatCsv(const std::vector<DistanceResult>& results,
                      const std::vector<CertifiedDistanceResult>& certified, bool answers) {
  std::ostringstream out;
  out << "pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz";
  if (!certified.empty()) out << (answers ? ",lower,upper,closer" : ",lower,upper");
  out << "\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const DistanceResult& r = results[i];
    out << absl::StrFormat("%d,%.17g,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", i, r.distance,
                           r.sphere_a, r.sphere_b, r.point_a.x(), r.point_a.y(), r.point_a.z(),
                           r.point_b.x(), r.point_b.y(), r.point_b.z());
    if (!certified.empty()) {
      out << absl::StrFormat(",%.17g,%.17g", certified[i].lower, certified[i].upper);
      if (answers) out << "," << CloserAnswerName(certified[i].closer);
    }
    out << "\n";
  }
  return out.str();
}

// The cover given for one solid (side 0: A, 1: B), read and checked against its internal set:
// that set must not be recorded as dilated or a cover, the two must name the same mesh when
// both name one, and without the mesh the cover must record a certificate of its spheres (and
// of the mesh the files name), which it certifies.
absl::StatusOr<CoverInput> ReadCover(const DistanceCliOptions& options, int side,
                                     const SphereFile& internal) {
  const char* names[2][3] = {{"A", "--cover-a", "--mesh-a"}, {"B", "--cover-b", "--mesh-b"}};
  const auto [name, cover_flag, mesh_flag] = names[side];
  const std::string& path = options.cover_paths[side];
  const std::string kind = RecordedKind(internal);
  if (!kind.empty() && kind != SphereSetKindName(SphereSetKind::kInternal)) {
    return UsageError(absl::StrFormat(
        "%s holds %s spheres; with %s, %s must be internal spheres (inside the solid: generate "
        "them without --dilate or --cover)",
        side == 0 ? options.a_path : options.b_path, kind, cover_flag, name));
  }
  CoverInput in;
  absl::StatusOr<SphereFile> file = ReadSphereFile(path);
  if (!file.ok()) return BadInputError(file.status().message());
  if (file->set.spheres.empty()) return BadInputError(path + ": no spheres");
  in.file = *std::move(file);
  if (!internal.mesh_sha256.empty() && !in.file.mesh_sha256.empty() &&
      internal.mesh_sha256 != in.file.mesh_sha256) {
    return BadInputError(absl::StrFormat("%s was made for mesh %s, its cover %s for mesh %s",
                                         side == 0 ? options.a_path : options.b_path,
                                         internal.mesh_sha256, path, in.file.mesh_sha256));
  }
  if (!options.mesh_paths[side].empty()) {
    // Only malformed stats are refused here; StoreCover checks the certificate against the mesh.
    if (absl::Status s = RecordedCoverCertificate(in.file).status(); !s.ok()) {
      return BadInputError(absl::StrCat(path, ": ", s.message()));
    }
    return in;
  }
  const std::string& named_mesh =
      in.file.mesh_sha256.empty() ? internal.mesh_sha256 : in.file.mesh_sha256;
  absl::StatusOr<std::optional<CoverCertificate>> usable =
      UsableCoverCertificate(in.file, path, named_mesh);
  if (usable.status().code() == absl::StatusCode::kFailedPrecondition) {
    return BadInputError(
        absl::StrFormat("%s %s (%s MESH)", cover_flag, usable.status().message(), mesh_flag));
  }
  if (!usable.ok()) return BadInputError(usable.status().message());
  if (!usable->has_value()) {
    return UsageError(absl::StrFormat(
        "%s %s records no cover certificate (the files `inscribe generate --cover` writes do); "
        "give %s MESH to certify it",
        cover_flag, path, mesh_flag));
  }
  in.certificate = *std::move(usable);
  return in;
}

// The cover stored in the service with its certificate: the one its file records when it
// names the cover's spheres (and the mesh, when given), else the service's proof against the
// mesh (CertifyCover by key, which the service keeps for Distance). Not a cover: exit 1, with
// the point it misses.
absl::StatusOr<std::string> StoreCover(const client::Client& client,
                                       const DistanceCliOptions& options, int side,
                                       const CoverInput& cover) {
  const std::string& path = options.cover_paths[side];
  std::optional<CoverCertificate> recorded = cover.certificate;
  std::optional<StoredSolid> solid;
  if (!options.mesh_paths[side].empty()) {
    absl::StatusOr<StoredSolid> stored = StoreSolid(client, options.mesh_paths[side]);
    if (!stored.ok()) return stored.status();
    solid = *std::move(stored);
    absl::StatusOr<std::optional<CoverCertificate>> usable =
        UsableCoverCertificate(cover.file, path, solid->sha256);
    if (usable.ok()) {
      recorded = *std::move(usable);
    } else {
      std::cerr << "inscribe: " << usable.status().message() << " (certifying it against "
                << options.mesh_paths[side] << " now)\n";
    }
  }
  if (recorded) {
    absl::StatusOr<client::PutSphereSetResult> stored =
        client.PutCertifiedCover(cover.file.set, *recorded);
    if (!stored.ok()) return stored.status();
    return stored->sphere_set_key;
  }
  absl::StatusOr<client::PutSphereSetResult> stored =
      client.PutSphereSet(cover.file.set, solid->sha256);
  if (!stored.ok()) return stored.status();
  absl::StatusOr<CoverCertificate> certificate =
      client.CertifyCover(solid->sha256, stored->sphere_set_key);
  if (!certificate.ok()) return certificate.status();
  if (!certificate->certified) {
    return CommandError(absl::StatusCode::kFailedPrecondition,
                        absl::StrCat(options.cover_paths[side], " is not a cover of ",
                                     options.mesh_paths[side], ": ", CoverVerdict(*certificate)),
                        kExitUnusableMesh);
  }
  return stored->sphere_set_key;
}

// Poses per Distance call: 100,000 poses are a 5.6 MB request and a 6.5 MB answer, far below
// gRPC's and a server's message limits (--max-message-bytes, --max-poses), and large enough
// that the round trips cost nothing next to the queries.
constexpr std::size_t kPosesPerCall = 100'000;

// What distance reports: the service's answers and figures, summed over the calls.
struct Distances {
  std::vector<DistanceResult> results;             // entry i answers pose i
  std::vector<CertifiedDistanceResult> certified;  // with covers: entry i's interval
  double seconds = 0.0;                            // the service's time on the queries
  double build_seconds = 0.0;                      // ... and on both hierarchies
  int threads = 0;
  std::int64_t volume_tests = 0, sphere_tests = 0;
};

// Both sets (and covers) stored in the service (PutSphereSet), then the poses in calls of
// kPosesPerCall, A at the origin.
absl::StatusOr<Distances> ComputeDistances(const client::Client& client,
                                           const DistanceCliOptions& options, const SphereSet& a,
                                           const SphereSet& b,
                                           const std::vector<CoverInput>& covers,
                                           const std::vector<RigidPose>& poses) {
  std::string keys[2];
  for (int k = 0; k < 2; ++k) {
    absl::StatusOr<client::PutSphereSetResult> stored = client.PutSphereSet(k == 0 ? a : b);
    if (!stored.ok()) return stored.status();
    keys[k] = stored->sphere_set_key;
  }
  client::DistanceOptions call;
  call.volume = options.hierarchy == "sphere" ? HierarchyVolume::kSphere : HierarchyVolume::kRss;
  call.brute_force = options.hierarchy == "none";
  call.tolerance = options.request;
  for (std::size_t k = 0; k < covers.size(); ++k) {
    absl::StatusOr<std::string> key = StoreCover(client, options, static_cast<int>(k), covers[k]);
    if (!key.ok()) return key.status();
    (k == 0 ? call.cover_a : call.cover_b) = *std::move(key);
  }
  const std::vector<RigidPose> origin = {RigidPose()};
  Distances d;
  d.results.reserve(poses.size());
  for (std::size_t first = 0; first < poses.size(); first += kPosesPerCall) {
    const std::vector<RigidPose> batch(
        poses.begin() + static_cast<std::ptrdiff_t>(first),
        poses.begin() + static_cast<std::ptrdiff_t>(std::min(poses.size(), first + kPosesPerCall)));
    absl::StatusOr<client::DistanceBatchResult> answer =
        client.Distance(keys[0], keys[1], origin, batch, call);
    // Poses are checked here before sending: what the service refuses is the options.
    if (answer.status().code() == absl::StatusCode::kInvalidArgument) {
      return WithExitCode(answer.status(), kExitUsage);
    }
    if (!answer.ok()) return answer.status();
    for (CertifiedDistanceResult& r : answer->certified) d.certified.push_back(std::move(r));
    d.seconds += answer->server_seconds;
    d.build_seconds += answer->hierarchy_seconds;
    d.threads = std::max(d.threads, answer->threads);
    d.volume_tests += answer->volume_tests;
    d.sphere_tests += answer->sphere_tests;
    for (DistanceResult& r : answer->results) d.results.push_back(std::move(r));
  }
  return d;
}

void PrintSummary(const DistanceCliOptions& options, const SphereSet& a, const SphereSet& b,
                  const Distances& d) {
  double min_distance = std::numeric_limits<double>::infinity();
  std::int64_t touching = 0, closer = 0;
  for (const DistanceResult& r : d.results) {
    min_distance = std::min(min_distance, r.distance);
    touching += r.distance <= 0.0;
    closer += r.closer;
  }
  const auto n = static_cast<double>(d.results.size());
  nlohmann::json j;
  j["a"] = options.a_path;
  j["b"] = options.b_path;
  j["spheres_a"] = a.size();
  j["spheres_b"] = b.size();
  j["hierarchy"] = options.hierarchy;
  j["queries"] = d.results.size();
  j["seconds"] = d.seconds;
  j["us_per_query"] = 1e6 * d.seconds / n;
  j["threads"] = d.threads;
  j["build_seconds"] = d.build_seconds;
  j["min_distance"] = min_distance;
  j["touching"] = touching;
  const bool closer_than = std::isfinite(options.request.closer_than);
  if (closer_than) j["closer_than"] = options.request.closer_than;
  if (closer_than && !options.certified()) j["closer"] = closer;
  if (options.certified()) {
    // The intervals: their bounds' smallest values, widths, and the closer-than answers.
    double min_lower = std::numeric_limits<double>::infinity(), min_upper = min_lower;
    double width_sum = 0.0, max_width = 0.0;
    std::int64_t answers[3] = {0, 0, 0};  // yes, no, undecided
    for (const CertifiedDistanceResult& r : d.certified) {
      min_lower = std::min(min_lower, r.lower);
      min_upper = std::min(min_upper, r.upper);
      width_sum += r.upper - r.lower;
      max_width = std::max(max_width, r.upper - r.lower);
      ++answers[static_cast<int>(r.closer)];
    }
    j["certified"] = true;
    j["min_lower"] = min_lower;
    j["min_upper"] = min_upper;
    j["mean_width"] = width_sum / n;
    j["max_width"] = max_width;
    if (closer_than) {
      j["closer_yes"] = answers[static_cast<int>(CloserAnswer::kYes)];
      j["closer_no"] = answers[static_cast<int>(CloserAnswer::kNo)];
      j["closer_undecided"] = answers[static_cast<int>(CloserAnswer::kUndecided)];
    }
  }
  j["abs_err"] = options.request.abs_err;
  j["rel_err"] = options.request.rel_err;
  j["mean_volume_tests"] = static_cast<double>(d.volume_tests) / n;
  j["mean_sphere_tests"] = static_cast<double>(d.sphere_tests) / n;
  if (options.remote.enabled()) j["server"] = options.remote.server;
  if (!options.output_path.empty()) j["output"] = options.output_path;
  std::cout << j.dump() << "\n";
}

absl::Status RunDistance(const DistanceCliOptions& options) {
  absl::StatusOr<SphereFile> a = ReadSphereFile(options.a_path, options.a_read);
  if (!a.ok()) return BadInputError(a.status().message());
  absl::StatusOr<SphereFile> b = ReadSphereFile(options.b_path, options.b_read);
  if (!b.ok()) return BadInputError(b.status().message());
  for (const auto* file : {&*a, &*b}) {
    if (file->set.spheres.empty()) {
      return BadInputError((file == &*a ? options.a_path : options.b_path) + ": no spheres");
    }
  }
  std::vector<CoverInput> covers;
  if (options.certified()) {
    if (options.hierarchy == "none") {
      return UsageError(
          "--hierarchy none: a certified query (--cover-a, --cover-b) is exact already");
    }
    for (int side = 0; side < 2; ++side) {
      absl::StatusOr<CoverInput> cover = ReadCover(options, side, side == 0 ? *a : *b);
      if (!cover.ok()) return cover.status();
      covers.push_back(*std::move(cover));
    }
  }
  absl::StatusOr<std::vector<RigidPose>> poses = ReadPoseFile(options.poses_path);
  if (!poses.ok()) return BadInputError(poses.status().message());

  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  const absl::StatusOr<Distances> d =
      ComputeDistances((*session)->client(), options, a->set, b->set, covers, *poses);
  if (!d.ok()) return d.status();

  const std::string csv =
      FormatCsv(d->results, d->certified, std::isfinite(options.request.closer_than));
  if (!options.output_path.empty()) {
    if (absl::Status written = WriteFileAtomically(options.output_path, csv); !written.ok()) {
      return BadInputError(written.message());
    }
    ReportWritten(options.output_path, absl::StrCat(d->results.size(), " poses, CSV"));
  } else if (!options.json) {
    std::cout << csv;
  }
  if (options.json) PrintSummary(options, a->set, b->set, *d);
  return absl::OkStatus();
}

}  // namespace

void AddDistanceCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<DistanceCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "distance",
      "Separation distance between two sphere sets, B placed by each pose relative to A "
      "(negative: the deepest overlap), or with covers an interval holding the exact distance "
      "between the solids; CSV of one row per pose unless --json");
  cmd->add_option("A", options->a_path, "Sphere file (.json, .sph, .csv, .yml)")->required();
  cmd->add_option("B", options->b_path, "Sphere file (.json, .sph, .csv, .yml)")->required();
  cmd->add_option("--link-a", options->a_read.yaml_link,
                  "A is a cuRobo YAML: the link whose spheres to use");
  cmd->add_option("--link-b", options->b_read.yaml_link,
                  "B is a cuRobo YAML: the link whose spheres to use");
  cmd->add_option("--sph-level-a", options->a_read.sph_level,
                  "A is a .sph tree: the level to use (-1 = the leaves)")
      ->capture_default_str();
  cmd->add_option("--sph-level-b", options->b_read.sph_level,
                  "B is a .sph tree: the level to use (-1 = the leaves)")
      ->capture_default_str();
  cmd->add_option("--poses", options->poses_path,
                  "One pose of B relative to A per line: qw qx qy qz tx ty tz (# comments)")
      ->required();
  cmd->add_option("--hierarchy", options->hierarchy,
                  "Bounding volumes: sphere (default: the fastest on the Table II benchmark), "
                  "rss (the paper's), or none (every sphere pair)")
      ->check(CLI::IsMember({"rss", "sphere", "none"}));
  cmd->add_option("--abs-err", options->request.abs_err,
                  "Answers may exceed the true distance by this much (mesh units)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rel-err", options->request.rel_err,
                  "... or by this fraction of the answer, whichever is larger")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--closer-than", options->request.closer_than,
                  "Only ask whether the sets are closer than D; stops at the first pair that is. "
                  "With covers: yes, no or undecided per pose, never a wrong yes or no");
  CLI::Option* cover_a = cmd->add_option(
      "--cover-a", options->cover_paths[0],
      "A certified query: a cover of A's solid (A then holds its internal spheres); each answer "
      "gains an interval lower <= exact distance <= upper. The file must record the certificate "
      "of its spheres (as `generate --cover` writes it), or --mesh-a proves one");
  CLI::Option* cover_b =
      cmd->add_option("--cover-b", options->cover_paths[1], "A cover of B's solid (see --cover-a)");
  cover_a->needs(cover_b);
  cover_b->needs(cover_a);
  cmd->add_option("--mesh-a", options->mesh_paths[0],
                  "The mesh of A, to certify --cover-a when its file records no certificate "
                  "of its spheres and this mesh")
      ->needs(cover_a);
  cmd->add_option("--mesh-b", options->mesh_paths[1],
                  "The mesh of B, to certify --cover-b when its file records no certificate "
                  "of its spheres and this mesh")
      ->needs(cover_b);
  cmd->add_option("-o,--output", options->output_path,
                  "Write the CSV here: pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz (with "
                  "covers also lower,upper, and closer with --closer-than)")
      ->check(WritableFile());
  cmd->add_flag("--json", options->json,
                "Print one JSON summary (queries, seconds, us_per_query, ...) on stdout");
  AddRemoteOptions(cmd, &options->remote, 60.0);
  SetExitStatusHelp(cmd,
                    "a mesh cannot be used, or a --cover-a/--cover-b is not a certified cover");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunDistance(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
