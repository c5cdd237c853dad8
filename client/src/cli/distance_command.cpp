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
#include "command_outcome.h"
#include "inscribe/separation_distance.h"
#include "inscribe/sphere_io.h"
#include "nlohmann/json.hpp"
#include "pose_file.h"
#include "remote_options.h"
#include "service_session.h"

namespace inscribe::cli {
namespace {

struct DistanceCliOptions {
  std::string a_path, b_path, poses_path;
  SphereFileReadOptions a_read, b_read;  // .sph level, YAML link
  std::string hierarchy = "sphere";
  std::string output_path;
  DistanceRequest request;
  bool json = false;
  RemoteOptions remote;
};

std::string FormatCsv(const std::vector<DistanceResult>& results) {
  std::ostringstream out;
  out << "pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const DistanceResult& r = results[i];
    out << absl::StrFormat("%d,%.17g,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", i, r.distance,
                           r.sphere_a, r.sphere_b, r.point_a.x(), r.point_a.y(), r.point_a.z(),
                           r.point_b.x(), r.point_b.y(), r.point_b.z());
  }
  return out.str();
}

// Poses per Distance call: 100,000 poses are a 5.6 MB request and a 6.5 MB answer, far below
// gRPC's and a server's message limits (--max-message-bytes, --max-poses), and large enough
// that the round trips cost nothing next to the queries.
constexpr std::size_t kPosesPerCall = 100'000;

// What distance reports: the service's answers and figures, summed over the calls.
struct Distances {
  std::vector<DistanceResult> results;  // entry i answers pose i
  double seconds = 0.0;                 // the service's time on the queries
  double build_seconds = 0.0;           // ... and on both hierarchies
  int threads = 0;
  std::int64_t volume_tests = 0, sphere_tests = 0;
};

// Both sets stored in the service (PutSphereSet), then the poses in calls of kPosesPerCall,
// A at the origin.
absl::StatusOr<Distances> ComputeDistances(const client::Client& client,
                                           const DistanceCliOptions& options, const SphereSet& a,
                                           const SphereSet& b,
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
  const std::vector<RigidPose> origin = {RigidPose()};
  Distances d;
  d.results.reserve(poses.size());
  for (std::size_t first = 0; first < poses.size(); first += kPosesPerCall) {
    const std::vector<RigidPose> batch(
        poses.begin() + static_cast<std::ptrdiff_t>(first),
        poses.begin() + static_cast<std::ptrdiff_t>(std::min(poses.size(), first + kPosesPerCall)));
    absl::StatusOr<client::DistanceBatchResult> answer =
        client.Distance(keys[0], keys[1], origin, batch, call);
    if (!answer.ok()) return answer.status();
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
  if (std::isfinite(options.request.closer_than)) {
    j["closer_than"] = options.request.closer_than;
    j["closer"] = closer;
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
  absl::StatusOr<std::vector<RigidPose>> poses = ReadPoseFile(options.poses_path);
  if (!poses.ok()) return BadInputError(poses.status().message());

  absl::StatusOr<std::unique_ptr<ServiceSession>> session = ServiceSession::Open(options.remote);
  if (!session.ok()) return session.status();
  const absl::StatusOr<Distances> d =
      ComputeDistances((*session)->client(), options, a->set, b->set, *poses);
  if (!d.ok()) return d.status();

  if (!options.output_path.empty()) {
    std::ofstream out(options.output_path, std::ios::binary | std::ios::trunc);
    out << FormatCsv(d->results);
    if (!out.flush()) return BadInputError(options.output_path + ": cannot write");
  } else if (!options.json) {
    std::cout << FormatCsv(d->results);
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
      "(negative: the deepest overlap); CSV of one row per pose unless --json");
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
                  "Only ask whether the sets are closer than D; stops at the first pair that is");
  cmd->add_option("-o,--output", options->output_path,
                  "Write the CSV here: pose,distance,sphere_a,sphere_b,ax,ay,az,bx,by,bz");
  cmd->add_flag("--json", options->json,
                "Print one JSON summary (queries, seconds, us_per_query, ...) on stdout");
  AddRemoteOptions(cmd, &options->remote, 60.0);
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunDistance(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
