// Distance with covers: certified intervals [lower, upper] that hold the exact distance between
// the two solids (core's CertifiedDistances), from each solid's internal set and a cover the
// store holds a certificate for (ResultStore::GetCertifiedObject).
#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "oneapi/tbb/task_arena.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {

absl::Status InscribeService::CertifiedDistances(const v1::DistanceRequest& request,
                                                 const std::vector<RigidPose>& poses_a,
                                                 const std::vector<RigidPose>& poses_b,
                                                 const DistanceRequest& tolerance,
                                                 v1::DistanceResponse* response) {
  const HierarchyVolume volume = wire::VolumeFromProto(request.volume());
  const ServiceClock::time_point objects_start = ServiceClock::now();
  absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> a =
      store_->GetCertifiedObject(request.sphere_set_a(), request.cover_a(), volume);
  if (!a.ok()) return a.status();
  absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> b =
      store_->GetCertifiedObject(request.sphere_set_b(), request.cover_b(), volume);
  if (!b.ok()) return b.status();
  response->set_hierarchy_seconds(SecondsSince(objects_start));
  const ServiceClock::time_point start = ServiceClock::now();
  const bool answers = std::isfinite(tolerance.closer_than);
  // In blocks, as Distance does: a block's pairs are all the memory the query adds.
  constexpr std::size_t kBlock = 16'384;
  std::vector<CertifiedPair> pairs;
  pairs.reserve(std::min(kBlock, poses_b.size()));
  for (std::size_t first = 0; first < poses_b.size(); first += kBlock) {
    const std::size_t end = std::min(poses_b.size(), first + kBlock);
    pairs.clear();
    for (std::size_t i = first; i < end; ++i) {
      pairs.push_back(CertifiedPair{&(*a)->object, &(*b)->object,
                                    poses_a[poses_a.size() == 1 ? 0 : i], poses_b[i]});
    }
    absl::StatusOr<std::vector<CertifiedDistanceResult>> results =
        inscribe::CertifiedDistances(pairs, tolerance.closer_than);
    if (!results.ok()) return results.status();
    wire::AppendCertifiedDistanceResults(*results, answers, response->mutable_results());
    std::int64_t volume_tests = 0, sphere_tests = 0;
    for (const CertifiedDistanceResult& r : *results) {
      volume_tests += r.internal.volume_tests + r.cover.volume_tests;
      sphere_tests += r.internal.sphere_tests + r.cover.sphere_tests;
    }
    response->set_volume_tests(response->volume_tests() + volume_tests);
    response->set_sphere_tests(response->sphere_tests() + sphere_tests);
  }
  response->set_seconds(SecondsSince(start));
  response->set_threads(tbb::this_task_arena::max_concurrency());
  return absl::OkStatus();
}

}  // namespace inscribe::server
