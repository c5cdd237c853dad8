#include "inscribe/robot/self_collision.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "inscribe/certified_distance.h"

namespace inscribe::robot {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Spheres as columns (x, y, z, r): in the link frame when prepared, in the world per sample.
using SphereColumns = Eigen::Matrix<double, 4, Eigen::Dynamic>;

SphereColumns Columns(const std::vector<Sphere>& spheres) {
  SphereColumns columns(4, static_cast<Eigen::Index>(spheres.size()));
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    columns.col(static_cast<Eigen::Index>(i)) << spheres[i].center, spheres[i].radius;
  }
  return columns;
}

struct PreparedLink {
  int link = -1;
  SphereColumns spheres, inner;  // inner: the spheres themselves when not certified
  double delta = 0.0;
  double reach = 0.0;  // largest |centre| + radius, link frame
};

struct Prepared {
  std::vector<PreparedLink> links;         // the links with spheres, by link index
  std::vector<std::pair<int, int>> pairs;  // indices into `links`, ascending
  bool certified = true;
};

Prepared Prepare(const std::vector<LinkCollisionGeometry>& geometry) {
  Prepared prepared;
  for (int link = 0; link < static_cast<int>(geometry.size()); ++link) {
    const LinkCollisionGeometry& g = geometry[link];
    if (g.spheres.empty()) continue;
    PreparedLink p;
    p.link = link;
    p.spheres = Columns(g.spheres);
    const bool certified = g.certified_delta.has_value();
    prepared.certified = prepared.certified && certified;
    p.delta = certified ? *g.certified_delta : 0.0;
    // Certified without inner spheres: no inner bound (an empty set is infinitely far).
    p.inner = certified ? Columns(g.inner) : p.spheres;
    for (const SphereColumns* set : {&p.spheres, &p.inner}) {
      for (Eigen::Index i = 0; i < set->cols(); ++i) {
        p.reach = std::max(p.reach, set->col(i).head<3>().norm() + set->col(i)(3));
      }
    }
    prepared.links.push_back(std::move(p));
  }
  for (int a = 0; a < static_cast<int>(prepared.links.size()); ++a) {
    for (int b = a + 1; b < static_cast<int>(prepared.links.size()); ++b) {
      prepared.pairs.emplace_back(a, b);
    }
  }
  return prepared;
}

// Signed distance between two posed sphere unions: exact over all pairs (+inf when one is
// empty).
double UnionDistance(const SphereColumns& a, const SphereColumns& b) {
  double best = kInfinity;
  for (Eigen::Index j = 0; j < b.cols(); ++j) {
    const double bx = b(0, j), by = b(1, j), bz = b(2, j), br = b(3, j);
    for (Eigen::Index i = 0; i < a.cols(); ++i) {
      const double dx = a(0, i) - bx, dy = a(1, i) - by, dz = a(2, i) - bz;
      best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz) - a(3, i) - br);
    }
  }
  return best;
}

void Transform(const Eigen::Isometry3d& pose, const SphereColumns& local, SphereColumns* world) {
  world->resize(4, local.cols());
  world->topRows<3>().noalias() = pose.linear() * local.topRows<3>();
  world->topRows<3>().colwise() += pose.translation();
  world->row(3) = local.row(3);
}

// Per thread: poses and posed spheres.
struct Workspace {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<SphereColumns> spheres, inner;
  std::vector<double> scale;
};

// Every pair's interval at q, handed to visit(pair index, interval). Fails only for q.
template <typename Visit>
absl::Status VisitIntervals(const Kinematics& kinematics, const Prepared& prepared,
                            absl::Span<const double> q, Workspace* work, Visit&& visit) {
  if (absl::Status status = kinematics.LinkPoses(q, &work->poses); !status.ok()) return status;
  const std::size_t n = prepared.links.size();
  work->spheres.resize(n);
  work->inner.resize(n);
  work->scale.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const PreparedLink& link = prepared.links[i];
    const Eigen::Isometry3d& pose = work->poses[link.link];
    Transform(pose, link.spheres, &work->spheres[i]);
    Transform(pose, link.inner, &work->inner[i]);
    work->scale[i] = pose.translation().norm() + link.reach;
  }
  for (std::size_t k = 0; k < prepared.pairs.size(); ++k) {
    const auto [a, b] = prepared.pairs[k];
    const double margin = kCertifiedDistanceMargin * std::max(work->scale[a], work->scale[b]) +
                          kCertifiedDistanceFloor;
    LinkPairInterval interval;
    interval.link_a = prepared.links[a].link;
    interval.link_b = prepared.links[b].link;
    interval.sphere_distance = UnionDistance(work->spheres[a], work->spheres[b]);
    interval.lower = std::max(0.0, interval.sphere_distance - margin);
    const double inner = UnionDistance(work->inner[a], work->inner[b]);
    const double through_covers =
        std::max(0.0, interval.sphere_distance) + prepared.links[a].delta + prepared.links[b].delta;
    interval.upper =
        std::max(interval.lower, std::max(0.0, std::min(inner, through_covers)) + margin);
    visit(k, interval);
  }
  return absl::OkStatus();
}

// Pairs that MoveIt calls adjacent: joined by a joint, or by a path whose inner links have no
// spheres. adjacent[a][b] over link indices.
std::vector<std::vector<bool>> AdjacentLinks(const Kinematics& kinematics,
                                             const std::vector<LinkCollisionGeometry>& geometry) {
  const int n = kinematics.links();
  std::vector<std::vector<int>> neighbours(n);
  for (int link = 0; link < n; ++link) {
    if (const int parent = kinematics.parent(link); parent >= 0) {
      neighbours[link].push_back(parent);
      neighbours[parent].push_back(link);
    }
  }
  std::vector<std::vector<bool>> adjacent(n, std::vector<bool>(n, false));
  for (int start = 0; start < n; ++start) {
    if (geometry[start].spheres.empty()) continue;
    // Walk from `start` through links without spheres; every link with spheres met is adjacent.
    std::vector<bool> seen(n, false);
    std::vector<int> stack = {start};
    seen[start] = true;
    while (!stack.empty()) {
      const int at = stack.back();
      stack.pop_back();
      for (int next : neighbours[at]) {
        if (seen[next]) continue;
        seen[next] = true;
        if (geometry[next].spheres.empty()) {
          stack.push_back(next);
        } else {
          adjacent[start][next] = adjacent[next][start] = true;
        }
      }
    }
  }
  return adjacent;
}

struct PairStatistics {
  std::int64_t colliding = 0;
  double min_lower = kInfinity, min_upper = kInfinity, min_sphere_distance = kInfinity;

  void Add(const LinkPairInterval& interval) {
    colliding += interval.colliding() ? 1 : 0;
    min_lower = std::min(min_lower, interval.lower);
    min_upper = std::min(min_upper, interval.upper);
    min_sphere_distance = std::min(min_sphere_distance, interval.sphere_distance);
  }
  void Merge(const PairStatistics& other) {
    colliding += other.colliding;
    min_lower = std::min(min_lower, other.min_lower);
    min_upper = std::min(min_upper, other.min_upper);
    min_sphere_distance = std::min(min_sphere_distance, other.min_sphere_distance);
  }
};

// Samples are drawn on the calling thread in blocks of this many, then checked in parallel.
constexpr std::int64_t kBlock = 2048;

}  // namespace

const char* CollisionPairClassName(CollisionPairClass type) {
  switch (type) {
    case CollisionPairClass::kAdjacent:
      return "Adjacent";
    case CollisionPairClass::kDefault:
      return "Default";
    case CollisionPairClass::kAlways:
      return "Always";
    case CollisionPairClass::kNever:
      return "Never";
    case CollisionPairClass::kSometimes:
      return "Sometimes";
  }
  return "Sometimes";
}

absl::Status CheckLinkCollisionGeometry(const Kinematics& kinematics,
                                        const std::vector<LinkCollisionGeometry>& links) {
  if (static_cast<int>(links.size()) != kinematics.links()) {
    return absl::InvalidArgumentError(absl::StrCat(links.size(), " link geometries for a robot of ",
                                                   kinematics.links(), " links"));
  }
  for (int link = 0; link < kinematics.links(); ++link) {
    const LinkCollisionGeometry& g = links[link];
    for (const auto& [set, what] :
         {std::pair{&g.spheres, "spheres"}, std::pair{&g.inner, "inner"}}) {
      for (std::size_t i = 0; i < set->size(); ++i) {
        if (absl::Status status = CheckSphere((*set)[i], i); !status.ok()) {
          return absl::InvalidArgumentError(absl::StrCat("link '", kinematics.link_name(link), "' ",
                                                         what, ": ", status.message()));
        }
      }
    }
    if (g.certified_delta && !(std::isfinite(*g.certified_delta) && *g.certified_delta >= 0.0)) {
      return absl::InvalidArgumentError(absl::StrCat("link '", kinematics.link_name(link),
                                                     "': certified_delta ", *g.certified_delta,
                                                     " is not finite and >= 0"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<LinkPairInterval>> LinkPairIntervals(
    const Kinematics& kinematics, const std::vector<LinkCollisionGeometry>& links,
    absl::Span<const double> q) {
  if (absl::Status status = CheckLinkCollisionGeometry(kinematics, links); !status.ok()) {
    return status;
  }
  const Prepared prepared = Prepare(links);
  std::vector<LinkPairInterval> intervals(prepared.pairs.size());
  Workspace work;
  if (absl::Status status = VisitIntervals(
          kinematics, prepared, q, &work,
          [&](std::size_t k, const LinkPairInterval& interval) { intervals[k] = interval; });
      !status.ok()) {
    return status;
  }
  return intervals;
}

absl::StatusOr<SelfCollisionMatrix> ComputeSelfCollisionMatrix(
    const Kinematics& kinematics, const std::vector<LinkCollisionGeometry>& links,
    const SelfCollisionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status status = CheckLinkCollisionGeometry(kinematics, links); !status.ok()) {
    return status;
  }
  if (options.samples < 1 || options.samples > kMaxSelfCollisionSamples) {
    return absl::InvalidArgumentError(
        absl::StrCat("samples ", options.samples, " is outside 1..", kMaxSelfCollisionSamples));
  }
  if (!(options.always_fraction > 0.0 && options.always_fraction <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("always_fraction ", options.always_fraction, " is outside (0, 1]"));
  }
  const Prepared prepared = Prepare(links);
  const std::size_t pair_count = prepared.pairs.size();

  std::vector<bool> at_default(pair_count, false);
  {
    Workspace work;
    const std::vector<double> q = DefaultConfiguration(kinematics);
    if (absl::Status status = VisitIntervals(
            kinematics, prepared, q, &work,
            [&](std::size_t k, const LinkPairInterval& i) { at_default[k] = i.colliding(); });
        !status.ok()) {
      return status;
    }
  }

  struct Local {
    Workspace work;
    std::vector<PairStatistics> statistics;
    absl::Status status;
  };
  tbb::enumerable_thread_specific<Local> locals([&] {
    Local local;
    local.statistics.resize(pair_count);
    return local;
  });
  ConfigurationSampler sampler(kinematics, options.seed);
  const std::size_t variables = kinematics.variables().size();
  std::vector<double> block;
  for (std::int64_t first = 0; first < options.samples; first += kBlock) {
    if (options.control.cancelled()) {
      return absl::CancelledError("self-collision matrix cancelled");
    }
    const std::int64_t count = std::min(kBlock, options.samples - first);
    block.resize(static_cast<std::size_t>(count) * variables);
    for (std::int64_t s = 0; s < count; ++s) {
      sampler.Next(absl::MakeSpan(block.data() + s * variables, variables));
    }
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, count, 16),
                      [&](const tbb::blocked_range<std::int64_t>& range) {
                        Local& local = locals.local();
                        for (std::int64_t s = range.begin(); s < range.end(); ++s) {
                          const absl::Status status = VisitIntervals(
                              kinematics, prepared,
                              absl::MakeConstSpan(block.data() + s * variables, variables),
                              &local.work, [&](std::size_t k, const LinkPairInterval& interval) {
                                local.statistics[k].Add(interval);
                              });
                          if (!status.ok() && local.status.ok()) local.status = status;
                        }
                      });
    if (options.control.on_progress) {
      options.control.on_progress(static_cast<double>(first + count) /
                                  static_cast<double>(options.samples));
    }
  }
  std::vector<PairStatistics> statistics(pair_count);
  for (const Local& local : locals) {
    // Sampled values are finite, so only an overflowing mimic can fail here.
    if (!local.status.ok()) return local.status;
    for (std::size_t k = 0; k < pair_count; ++k) statistics[k].Merge(local.statistics[k]);
  }

  const std::vector<std::vector<bool>> adjacent = AdjacentLinks(kinematics, links);
  SelfCollisionMatrix matrix;
  for (int link = 0; link < kinematics.links(); ++link) {
    matrix.links.push_back(kinematics.link_name(link));
  }
  matrix.samples = options.samples;
  matrix.seed = options.seed;
  matrix.always_fraction = options.always_fraction;
  matrix.certified = prepared.certified;
  for (std::size_t k = 0; k < pair_count; ++k) {
    LinkPairCollision pair;
    pair.link_a = prepared.links[prepared.pairs[k].first].link;
    pair.link_b = prepared.links[prepared.pairs[k].second].link;
    pair.colliding_at_default = at_default[k];
    pair.colliding_samples = statistics[k].colliding;
    pair.colliding_fraction =
        static_cast<double>(pair.colliding_samples) / static_cast<double>(options.samples);
    pair.min_lower = statistics[k].min_lower;
    pair.min_upper = statistics[k].min_upper;
    pair.min_sphere_distance = statistics[k].min_sphere_distance;
    if (adjacent[pair.link_a][pair.link_b]) {
      pair.type = CollisionPairClass::kAdjacent;
    } else if (pair.colliding_at_default) {
      pair.type = CollisionPairClass::kDefault;
    } else if (pair.colliding_fraction >= options.always_fraction) {
      pair.type = CollisionPairClass::kAlways;
    } else if (pair.colliding_samples == 0) {
      pair.type = CollisionPairClass::kNever;
    } else {
      pair.type = CollisionPairClass::kSometimes;
    }
    matrix.pairs.push_back(pair);
  }
  matrix.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return matrix;
}

}  // namespace inscribe::robot
