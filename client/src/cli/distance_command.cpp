#include "distance_command.h"

#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "exit_codes.h"
#include "inscribe/separation_distance.h"
#include "inscribe/sphere_hierarchy.h"
#include "inscribe/sphere_io.h"
#include "nlohmann/json.hpp"
#include "pose_file.h"

namespace inscribe::cli {
namespace {

struct DistanceCliOptions {
  std::string a_path, b_path, poses_path;
  std::string hierarchy = "sphere";
  std::string output_path;
  DistanceRequest request;
  bool json = false;
};

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

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

int RunDistance(const DistanceCliOptions& options) {
  absl::StatusOr<SphereFile> a = ReadSphereFile(options.a_path);
  if (!a.ok()) {
    std::cerr << "inscribe: " << a.status().message() << "\n";
    return kExitBadInput;
  }
  absl::StatusOr<SphereFile> b = ReadSphereFile(options.b_path);
  if (!b.ok()) {
    std::cerr << "inscribe: " << b.status().message() << "\n";
    return kExitBadInput;
  }
  for (const auto* file : {&*a, &*b}) {
    if (file->set.spheres.empty()) {
      std::cerr << "inscribe: " << (file == &*a ? options.a_path : options.b_path)
                << ": no spheres\n";
      return kExitBadInput;
    }
  }
  absl::StatusOr<std::vector<RigidPose>> poses = ReadPoseFile(options.poses_path);
  if (!poses.ok()) {
    std::cerr << "inscribe: " << poses.status().message() << "\n";
    return kExitBadInput;
  }

  std::vector<DistanceResult> results(poses->size());
  double build_seconds = 0.0;
  const auto start = Clock::now();
  if (options.hierarchy == "none") {
    const RigidPose identity;
    for (std::size_t i = 0; i < poses->size(); ++i) {
      absl::StatusOr<DistanceResult> r = BruteForceSeparationDistance(
          a->set.spheres, identity, b->set.spheres, (*poses)[i], options.request);
      if (!r.ok()) {
        std::cerr << "inscribe: pose " << i << ": " << r.status().message() << "\n";
        return kExitBadInput;
      }
      results[i] = *r;
    }
  } else {
    const HierarchyVolume volume =
        options.hierarchy == "sphere" ? HierarchyVolume::kSphere : HierarchyVolume::kRss;
    const auto build_start = Clock::now();
    absl::StatusOr<SphereHierarchy> ha = SphereHierarchy::Build(a->set.spheres, volume);
    absl::StatusOr<SphereHierarchy> hb = SphereHierarchy::Build(b->set.spheres, volume);
    if (!ha.ok() || !hb.ok()) {
      std::cerr << "inscribe: " << (ha.ok() ? hb.status() : ha.status()).message() << "\n";
      return kExitBadInput;
    }
    build_seconds = SecondsSince(build_start);
    const auto query_start = Clock::now();
    absl::StatusOr<std::vector<DistanceResult>> batch =
        SeparationDistances(*ha, *hb, *poses, options.request);
    if (!batch.ok()) {
      std::cerr << "inscribe: " << batch.status().message() << "\n";
      return kExitBadInput;
    }
    results = *std::move(batch);
    (void)query_start;
  }
  const double seconds = SecondsSince(start) - build_seconds;

  if (!options.output_path.empty()) {
    std::ofstream out(options.output_path, std::ios::binary | std::ios::trunc);
    out << FormatCsv(results);
    if (!out.flush()) {
      std::cerr << "inscribe: " << options.output_path << ": cannot write\n";
      return kExitBadInput;
    }
  } else if (!options.json) {
    std::cout << FormatCsv(results);
  }
  if (options.json) {
    double min_distance = std::numeric_limits<double>::infinity();
    std::int64_t touching = 0, closer = 0, volume_tests = 0, sphere_tests = 0;
    for (const DistanceResult& r : results) {
      min_distance = std::min(min_distance, r.distance);
      touching += r.distance <= 0.0;
      closer += r.closer;
      volume_tests += r.volume_tests;
      sphere_tests += r.sphere_tests;
    }
    const auto n = static_cast<double>(results.size());
    nlohmann::json j;
    j["a"] = options.a_path;
    j["b"] = options.b_path;
    j["spheres_a"] = a->set.size();
    j["spheres_b"] = b->set.size();
    j["hierarchy"] = options.hierarchy;
    j["queries"] = results.size();
    j["seconds"] = seconds;
    j["us_per_query"] = 1e6 * seconds / n;
    j["threads"] = options.hierarchy == "none" ? 1 : tbb::info::default_concurrency();
    j["build_seconds"] = build_seconds;
    j["min_distance"] = min_distance;
    j["touching"] = touching;
    if (std::isfinite(options.request.closer_than)) {
      j["closer_than"] = options.request.closer_than;
      j["closer"] = closer;
    }
    j["abs_err"] = options.request.abs_err;
    j["rel_err"] = options.request.rel_err;
    j["mean_volume_tests"] = static_cast<double>(volume_tests) / n;
    j["mean_sphere_tests"] = static_cast<double>(sphere_tests) / n;
    if (!options.output_path.empty()) j["output"] = options.output_path;
    std::cout << j.dump() << "\n";
  }
  return kExitOk;
}

}  // namespace

void AddDistanceCommand(CLI::App& app, int* exit_code) {
  auto options = std::make_shared<DistanceCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "distance",
      "Separation distance between two sphere sets, B placed by each pose relative to A "
      "(negative: the deepest overlap); CSV of one row per pose unless --json");
  cmd->add_option("A", options->a_path, "Sphere file (.json, .sph, .csv)")->required();
  cmd->add_option("B", options->b_path, "Sphere file (.json, .sph, .csv)")->required();
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
  cmd->callback([options, exit_code] { *exit_code = RunDistance(*options); });
}

}  // namespace inscribe::cli
