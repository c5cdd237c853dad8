// The C++ side of bench/python_overhead.py: the same work as the Python bindings' calls, timed
// in C++ so that the script can print both in one run. Prints one JSON object.
//
//   python_peer MESH MAX_SPHERES POSES_FILE GENERATE_RUNS DISTANCE_RUNS
//
// POSES_FILE: N x 7 little-endian doubles [qw, qx, qy, qz, tx, ty, tz] (the script's poses).
// Times: GenerateSphereSet(PrepareSolid(mesh), max_spheres) (what inscribe.generate(solid,
// max_spheres=N) runs), and PairSeparationDistances of the set's sphere hierarchy against
// itself, a at the identity, b at each pose (what inscribe.distance(h, h, poses) runs).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/solid.h"

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

[[noreturn]] void Fail(const std::string& message) {
  std::cerr << "python_peer: " << message << "\n";
  std::exit(1);
}

void PrintList(const char* name, const std::vector<double>& values, bool last) {
  std::printf("\"%s\": [", name);
  for (std::size_t i = 0; i < values.size(); ++i) std::printf("%s%.9f", i ? ", " : "", values[i]);
  std::printf("]%s\n", last ? "" : ",");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) Fail("usage: python_peer MESH MAX_SPHERES POSES_FILE GENERATE_RUNS DISTANCE_RUNS");
  const std::string mesh_path = argv[1];
  const std::int64_t max_spheres = std::atoll(argv[2]);
  const int generate_runs = std::atoi(argv[4]);
  const int distance_runs = std::atoi(argv[5]);

  std::ifstream in(argv[3], std::ios::binary);
  std::vector<double> numbers;
  for (double value; in.read(reinterpret_cast<char*>(&value), sizeof value);) {
    numbers.push_back(value);
  }
  if (numbers.empty() || numbers.size() % 7 != 0) Fail("poses file is not N x 7 doubles");
  std::vector<inscribe::RigidPose> poses;
  for (std::size_t i = 0; i < numbers.size(); i += 7) {
    inscribe::RigidPose pose;
    pose.rotation = Eigen::Quaterniond(numbers[i], numbers[i + 1], numbers[i + 2], numbers[i + 3]);
    pose.translation = inscribe::Vector3(numbers[i + 4], numbers[i + 5], numbers[i + 6]);
    absl::StatusOr<inscribe::RigidPose> normalized = inscribe::NormalizedPose(pose);
    if (!normalized.ok()) Fail(std::string(normalized.status().message()));
    poses.push_back(*normalized);
  }

  absl::StatusOr<inscribe::Mesh> mesh = inscribe::ReadMesh(mesh_path);
  if (!mesh.ok()) Fail(std::string(mesh.status().message()));
  absl::StatusOr<inscribe::Solid> solid = inscribe::PrepareSolid(*std::move(mesh));
  if (!solid.ok()) Fail(std::string(solid.status().message()));

  inscribe::SphereSetParameters parameters;
  parameters.max_spheres = max_spheres;
  std::vector<double> generate_seconds;
  inscribe::SphereSet set;
  for (int run = 0; run < generate_runs; ++run) {
    const Clock::time_point start = Clock::now();
    absl::StatusOr<inscribe::GeneratedSphereSet> generated =
        inscribe::GenerateSphereSet(*solid, parameters);
    generate_seconds.push_back(SecondsSince(start));
    if (!generated.ok()) Fail(std::string(generated.status().message()));
    set = std::move(generated->set);
  }

  absl::StatusOr<inscribe::SphereHierarchy> hierarchy =
      inscribe::SphereHierarchy::Build(set.spheres, inscribe::HierarchyVolume::kSphere);
  if (!hierarchy.ok()) Fail(std::string(hierarchy.status().message()));
  std::vector<inscribe::PosedPair> pairs;
  for (const inscribe::RigidPose& pose : poses) {
    pairs.push_back({&*hierarchy, &*hierarchy, inscribe::RigidPose{}, pose});
  }
  std::vector<double> distance_seconds;
  double checksum = 0.0;
  for (int run = 0; run < distance_runs; ++run) {
    const Clock::time_point start = Clock::now();
    absl::StatusOr<std::vector<inscribe::DistanceResult>> results =
        inscribe::PairSeparationDistances(pairs);
    distance_seconds.push_back(SecondsSince(start));
    if (!results.ok()) Fail(std::string(results.status().message()));
    checksum = 0.0;
    for (const inscribe::DistanceResult& r : *results) checksum += r.distance;
  }

  std::printf("{\"spheres\": %zu, \"poses\": %zu, \"distance_sum\": %.17g,\n", set.size(),
              poses.size(), checksum);
  PrintList("generate_seconds", generate_seconds, false);
  PrintList("distance_seconds", distance_seconds, true);
  std::printf("}\n");
  return 0;
}
