// Distance: separation distances between two cached sphere sets for a batch of pose pairs
// (paper Section VI), through their hierarchies, by brute force, or certified with covers
// (service_distance_certified.cpp). Counts and shapes are checked on the gRPC thread, the poses'
// numbers on the pool.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "oneapi/tbb/task_arena.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// Adds the work counts of `results` (their tests, summed) to a Distance answer.
void AddWork(const std::vector<DistanceResult>& results, v1::DistanceResponse* response) {
  std::int64_t volume_tests = 0, sphere_tests = 0;
  for (const DistanceResult& r : results) {
    volume_tests += r.volume_tests;
    sphere_tests += r.sphere_tests;
  }
  response->set_volume_tests(response->volume_tests() + volume_tests);
  response->set_sphere_tests(response->sphere_tests() + sphere_tests);
}

}  // namespace

absl::Status InscribeService::BruteForceDistances(const v1::DistanceRequest& request,
                                                  const std::vector<RigidPose>& poses_a,
                                                  const std::vector<RigidPose>& poses_b,
                                                  const DistanceRequest& tolerance,
                                                  v1::DistanceResponse* response) {
  // Every sphere pair of every pose pair: bounded, so that one call cannot occupy a worker for
  // hours (10^10 pairs are about a minute).
  constexpr double kMaxSpherePairs = 1e10;
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> a =
      store_->GetSphereSet(request.sphere_set_a());
  if (!a.ok()) return a.status();
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> b =
      store_->GetSphereSet(request.sphere_set_b());
  if (!b.ok()) return b.status();
  const std::vector<Sphere>& sa = (*a)->set.spheres;
  const std::vector<Sphere>& sb = (*b)->set.spheres;
  const double work = static_cast<double>(sa.size()) * static_cast<double>(sb.size()) *
                      static_cast<double>(poses_b.size());
  if (work > kMaxSpherePairs) {
    return absl::ResourceExhaustedError(
        absl::StrCat("brute_force: ", work, " sphere pairs (", sa.size(), " x ", sb.size(), " x ",
                     poses_b.size(), " poses); at most ", kMaxSpherePairs, " per call"));
  }
  const ServiceClock::time_point start = ServiceClock::now();
  std::vector<DistanceResult> results(poses_b.size());
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    absl::StatusOr<DistanceResult> r = BruteForceSeparationDistance(
        sa, poses_a[poses_a.size() == 1 ? 0 : i], sb, poses_b[i], tolerance);
    if (!r.ok())
      return absl::Status(r.status().code(), absl::StrCat("pose ", i, ": ", r.status().message()));
    results[i] = *r;
  }
  wire::AppendDistanceResults(results, response->mutable_results());
  response->set_seconds(SecondsSince(start));
  response->set_threads(1);
  AddWork(results, response);
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* InscribeService::Distance(grpc::CallbackServerContext* context,
                                                    const v1::DistanceRequest* request,
                                                    v1::DistanceResponse* response) {
  absl::Status precheck = CheckKey(request->sphere_set_a(), "sphere_set_a");
  if (precheck.ok()) precheck = CheckKey(request->sphere_set_b(), "sphere_set_b");
  if (precheck.ok()) precheck = CheckCovers(request->cover_a(), request->cover_b());
  const bool certified = !request->cover_a().empty();
  if (precheck.ok() && certified && request->brute_force()) {
    precheck = absl::InvalidArgumentError(
        "brute_force: a certified query (covers named) is exact already; leave it unset");
  }
  // Shapes and counts are O(1) to check here; the poses' numbers are checked on the pool.
  const int numbers_a = request->poses_a().values_size();
  const int numbers_b = request->poses_b().values_size();
  const std::int64_t pairs = numbers_b / 7;
  if (precheck.ok() && (numbers_a % 7 != 0 || numbers_b % 7 != 0)) {
    precheck = absl::InvalidArgumentError(
        absl::StrCat(numbers_a % 7 != 0 ? "poses_a" : "poses_b", " has length ",
                     numbers_a % 7 != 0 ? numbers_a : numbers_b,
                     "; expected a multiple of 7 (qw, qx, qy, qz, tx, ty, tz per pose)"));
  }
  if (precheck.ok() && pairs > limits_.max_poses) {
    precheck = absl::ResourceExhaustedError(
        absl::StrCat(pairs, " pose pairs; this server's limit (--max-poses) is ", limits_.max_poses,
                     " per call"));
  }
  // The pairing rule, checked here only: poses_a holds one pose (shared by every pair) or one
  // per pose of poses_b, and PosesFromProto below reads exactly these counts.
  if (precheck.ok() && numbers_a != 7 && numbers_a != numbers_b) {
    precheck = absl::InvalidArgumentError(
        absl::StrCat("poses_a has ", numbers_a / 7, " poses and poses_b ", pairs,
                     "; poses_a must have one pose or as many as poses_b"));
  }
  return RunUnary(
      context, "Distance", 0, precheck, pairs * MemoryCosts::kPerPosePair + MemoryCosts::kSmallCall,
      absl::StrCat("Distance of ", pairs, " pose pairs"),
      [this, request, response, certified]() -> absl::Status {
        absl::StatusOr<DistanceRequest> tolerance = wire::ToleranceFromProto(request->tolerance());
        if (!tolerance.ok()) return tolerance.status();
        if (certified) {
          if (absl::Status s = CheckCertifiedTolerance(*tolerance); !s.ok()) return s;
        }
        absl::StatusOr<std::vector<RigidPose>> poses_a =
            wire::PosesFromProto(request->poses_a(), "poses_a");
        if (!poses_a.ok()) return poses_a.status();
        absl::StatusOr<std::vector<RigidPose>> poses_b =
            wire::PosesFromProto(request->poses_b(), "poses_b");
        if (!poses_b.ok()) return poses_b.status();
        if (request->brute_force()) {
          return BruteForceDistances(*request, *poses_a, *poses_b, *tolerance, response);
        }
        if (certified) {
          return CertifiedDistances(*request, *poses_a, *poses_b, *tolerance, response);
        }
        const HierarchyVolume volume = wire::VolumeFromProto(request->volume());
        const ServiceClock::time_point hierarchies_start = ServiceClock::now();
        absl::StatusOr<std::shared_ptr<const SphereHierarchy>> a =
            store_->GetHierarchy(request->sphere_set_a(), volume);
        if (!a.ok()) return a.status();
        absl::StatusOr<std::shared_ptr<const SphereHierarchy>> b =
            store_->GetHierarchy(request->sphere_set_b(), volume);
        if (!b.ok()) return b.status();
        response->set_hierarchy_seconds(SecondsSince(hierarchies_start));
        const ServiceClock::time_point start = ServiceClock::now();
        // The pairs in blocks: a block's posed pairs (128 bytes each) are all the memory the
        // query adds to the poses and the results.
        constexpr std::size_t kBlock = 16'384;
        std::vector<PosedPair> posed;
        posed.reserve(std::min(kBlock, poses_b->size()));
        for (std::size_t first = 0; first < poses_b->size(); first += kBlock) {
          const std::size_t end = std::min(poses_b->size(), first + kBlock);
          posed.clear();
          for (std::size_t i = first; i < end; ++i) {
            posed.push_back(PosedPair{a->get(), b->get(), (*poses_a)[poses_a->size() == 1 ? 0 : i],
                                      (*poses_b)[i]});
          }
          absl::StatusOr<std::vector<DistanceResult>> results =
              PairSeparationDistances(posed, *tolerance);
          if (!results.ok()) return results.status();  // poses and tolerance checked above
          wire::AppendDistanceResults(*results, response->mutable_results());
          AddWork(*results, response);
        }
        response->set_seconds(SecondsSince(start));
        response->set_threads(tbb::this_task_arena::max_concurrency());
        return absl::OkStatus();
      });
}

}  // namespace inscribe::server
