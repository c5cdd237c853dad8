#include "inscribe/robot/self_collision.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "base/parallel.h"  // core's loops (core/src)
#include "inscribe/distance/certified_distance.h"

namespace inscribe::robot {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Spheres one per row, x, y, z, r as contiguous columns (vectorised arithmetic): in the link
// frame when prepared, in the world per sample.
using SphereColumns = Eigen::Array<double, Eigen::Dynamic, 4>;

SphereColumns Columns(const std::vector<Sphere>& spheres) {
  SphereColumns columns(static_cast<Eigen::Index>(spheres.size()), 4);
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    columns.row(static_cast<Eigen::Index>(i)) << spheres[i].center.x(), spheres[i].center.y(),
        spheres[i].center.z(), spheres[i].radius;
  }
  return columns;
}

struct PreparedLink {
  int link = -1;
  SphereColumns spheres, inner;  // inner: the spheres themselves when not certified
  double delta = 0.0;
  double reach = 0.0;  // largest |centre| + radius, link frame
  // Balls holding every sphere of `spheres` and of `inner` (centre of their centres' box),
  // link frame.
  Vector3 bound_centre = Vector3::Zero(), inner_bound_centre = Vector3::Zero();
  double bound_radius = 0.0, inner_bound_radius = 0.0;
};

struct Prepared {
  std::vector<PreparedLink> links;         // the links with spheres, by link index
  std::vector<std::pair<int, int>> pairs;  // indices into `links`, ascending
  std::vector<char> measured;              // per pair: 0 to leave it out of every sample
  bool certified = true;
};

// A ball holding every sphere (none: radius 0), centred on the box of their centres.
void BoundingBall(const SphereColumns& spheres, Vector3* centre, double* radius) {
  *centre = Vector3::Zero();
  *radius = 0.0;
  if (spheres.rows() == 0) return;
  *centre = 0.5 * (spheres.leftCols<3>().colwise().minCoeff() +
                   spheres.leftCols<3>().colwise().maxCoeff())
                      .transpose()
                      .matrix();
  for (Eigen::Index i = 0; i < spheres.rows(); ++i) {
    const Vector3 c(spheres(i, 0), spheres(i, 1), spheres(i, 2));
    *radius = std::max(*radius, (c - *centre).norm() + spheres(i, 3));
  }
  // Rounding of the norms: the ball must hold every sphere, so grow it a little.
  *radius *= 1.0 + 1e-12;
}

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
      for (Eigen::Index i = 0; i < set->rows(); ++i) {
        const Vector3 c((*set)(i, 0), (*set)(i, 1), (*set)(i, 2));
        p.reach = std::max(p.reach, c.norm() + (*set)(i, 3));
      }
    }
    BoundingBall(p.spheres, &p.bound_centre, &p.bound_radius);
    BoundingBall(p.inner, &p.inner_bound_centre, &p.inner_bound_radius);
    prepared.links.push_back(std::move(p));
  }
  for (int a = 0; a < static_cast<int>(prepared.links.size()); ++a) {
    for (int b = a + 1; b < static_cast<int>(prepared.links.size()); ++b) {
      prepared.pairs.emplace_back(a, b);
      prepared.measured.push_back(1);
    }
  }
  return prepared;
}

using WorldSpheres = SphereColumns;

// Signed distance between two posed sphere unions, min over sphere pairs of
// |c_a - c_b| - r_a - r_b (+inf when one is empty), exact where it matters: the result is the
// exact minimum when that is below `cutoff`, and otherwise some value >= cutoff (never below the
// exact minimum). Once a pair at most `collide_at` apart is found, the cutoff drops to
// `cutoff_once_colliding`. `a_ball` (centre, radius) holds every sphere of `a`: a sphere of b
// whose distance to it exceeds min(best, cutoff) by more than `slack` (far above the rounding
// of the test) is skipped; the others are measured against all of a at once. With infinite
// cutoffs the result is the exact minimum.
double UnionDistance(const WorldSpheres& a, const Eigen::Vector4d& a_ball, const WorldSpheres& b,
                     double slack, double cutoff = kInfinity, double collide_at = -kInfinity,
                     double cutoff_once_colliding = kInfinity) {
  double best = kInfinity;
  if (a.rows() == 0) return best;
  for (Eigen::Index j = 0; j < b.rows(); ++j) {
    const double bx = b(j, 0), by = b(j, 1), bz = b(j, 2), br = b(j, 3);
    const double reach = std::min(best, cutoff) + a_ball(3) + br + slack;
    if (!(reach > 0.0)) continue;  // |d| >= 0 >= reach
    const double ex = a_ball(0) - bx, ey = a_ball(1) - by, ez = a_ball(2) - bz;
    if (ex * ex + ey * ey + ez * ez >= reach * reach) continue;
    const auto d2 = (a.col(0) - bx).square() + (a.col(1) - by).square() + (a.col(2) - bz).square();
    // Square roots only for rows with a sphere that can beat min(best, cutoff) + slack.
    const double beat = std::min(best, cutoff) + br + slack;
    if (!(d2 < (a.col(3) + beat).max(0.0).square()).any()) continue;
    const double row = (d2.sqrt() - a.col(3)).minCoeff() - br;
    if (row < best) {
      best = row;
      if (best <= collide_at) cutoff = std::min(cutoff, cutoff_once_colliding);
    }
  }
  return best;
}

// Column by column (no general matrix product: these are a few dozen spheres).
void Transform(const Eigen::Isometry3d& pose, const SphereColumns& local, WorldSpheres* world) {
  world->resize(local.rows(), 4);
  const Eigen::Matrix3d& r = pose.linear();
  const Vector3& t = pose.translation();
  for (int axis = 0; axis < 3; ++axis) {
    world->col(axis) =
        r(axis, 0) * local.col(0) + r(axis, 1) * local.col(1) + r(axis, 2) * local.col(2) + t(axis);
  }
  world->col(3) = local.col(3);
}

// Per thread: poses and posed spheres.
struct Workspace {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<WorldSpheres> spheres, inner;
  std::vector<Eigen::Vector4d> ball, inner_ball;  // world centre and radius
  std::vector<double> scale;
  std::vector<char> inner_posed;  // inner[i] holds this sample's inner spheres
};

// The smallest values a pair has shown so far (on one thread): a sample that cannot go below
// them, and does not collide, changes nothing.
struct PairMinima {
  double lower = kInfinity, upper = kInfinity, sphere_distance = kInfinity;
};

// Every pair's interval at q, handed to visit(pair index, interval). With `minima` (one per
// pair), work that cannot change the pair's statistics is skipped: a pair whose bounding balls
// are apart by more than its margin and its minima is not visited, and when neither lower nor
// the margin is below minima.upper the inner spheres are not measured (upper is then +inf).
// The statistics come out exactly as without `minima`. Fails only for q.
template <typename Visit>
absl::Status VisitIntervals(const Kinematics& kinematics, const Prepared& prepared,
                            absl::Span<const double> q, Workspace* work,
                            const std::vector<PairMinima>* minima, Visit&& visit) {
  if (absl::Status status = kinematics.LinkPoses(q, &work->poses); !status.ok()) return status;
  const std::size_t n = prepared.links.size();
  work->spheres.resize(n);
  work->inner.resize(n);
  work->ball.resize(n);
  work->inner_ball.resize(n);
  work->scale.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const PreparedLink& link = prepared.links[i];
    const Eigen::Isometry3d& pose = work->poses[link.link];
    Transform(pose, link.spheres, &work->spheres[i]);
    work->ball[i] << pose * link.bound_centre, link.bound_radius;
    work->inner_ball[i] << pose * link.inner_bound_centre, link.inner_bound_radius;
    work->scale[i] = pose.translation().norm() + link.reach;
  }
  work->inner_posed.assign(n, 0);
  for (std::size_t k = 0; k < prepared.pairs.size(); ++k) {
    if (!prepared.measured[k]) continue;
    const auto [a, b] = prepared.pairs[k];
    const PreparedLink& la = prepared.links[a];
    const PreparedLink& lb = prepared.links[b];
    const double margin = kCertifiedDistanceMargin * std::max(work->scale[a], work->scale[b]) +
                          kCertifiedDistanceFloor;
    if (minima != nullptr) {
      // A lower bound on the spheres' distance (margin covers its rounding).
      const double apart = (work->ball[a].head<3>() - work->ball[b].head<3>()).norm() -
                           la.bound_radius - lb.bound_radius - margin;
      const PairMinima& m = (*minima)[k];
      if (apart > margin && apart > m.lower && apart > m.upper && apart > m.sphere_distance) {
        continue;
      }
    }
    LinkPairInterval interval;
    interval.link_a = la.link;
    interval.link_b = lb.link;
    if (minima == nullptr) {
      interval.sphere_distance =
          UnionDistance(work->spheres[a], work->ball[a], work->spheres[b], margin);
    } else {
      // Exact only where the statistics can change: below every minimum (lower and upper
      // moved by the margin) and 2 margins (colliding); once colliding, below the smallest
      // sphere distance seen. Beyond that, lower, upper and the distance cannot go below the
      // minima and the sample is not colliding (see PairMinima).
      const PairMinima& m = (*minima)[k];
      const double cutoff =
          std::max({m.sphere_distance, m.lower + margin, m.upper + margin, 2.0 * margin});
      interval.sphere_distance = UnionDistance(work->spheres[a], work->ball[a], work->spheres[b],
                                               margin, cutoff, margin, m.sphere_distance);
    }
    interval.lower = std::max(0.0, interval.sphere_distance - margin);
    // upper >= max(lower, margin): no use measuring when that is not below the minimum.
    if (minima != nullptr && std::max(interval.lower, margin) >= (*minima)[k].upper) {
      interval.upper = kInfinity;
      visit(k, interval);
      continue;
    }
    for (const int i : {a, b}) {
      if (!work->inner_posed[i]) {
        Transform(work->poses[prepared.links[i].link], prepared.links[i].inner, &work->inner[i]);
        work->inner_posed[i] = 1;
      }
    }
    // With minima, exact below minima.upper: above it, upper cannot lower the minimum.
    const double inner = UnionDistance(work->inner[a], work->inner_ball[a], work->inner[b], margin,
                                       minima == nullptr ? kInfinity : (*minima)[k].upper);
    const double through_covers = std::max(0.0, interval.sphere_distance) + la.delta + lb.delta;
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

// Per pair: colliding samples and minima, over the samples one thread saw (or all).
struct PairStatistics {
  std::vector<std::int64_t> colliding;
  std::vector<PairMinima> minima;

  explicit PairStatistics(std::size_t pairs) : colliding(pairs, 0), minima(pairs) {}
  void Add(std::size_t k, const LinkPairInterval& interval) {
    colliding[k] += interval.colliding() ? 1 : 0;
    Lower(k, PairMinima{interval.lower, interval.upper, interval.sphere_distance});
  }
  void Lower(std::size_t k, const PairMinima& other) {
    PairMinima& m = minima[k];
    m.lower = std::min(m.lower, other.lower);
    m.upper = std::min(m.upper, other.upper);
    m.sphere_distance = std::min(m.sphere_distance, other.sphere_distance);
  }
  void Merge(const PairStatistics& other) {
    for (std::size_t k = 0; k < colliding.size(); ++k) {
      colliding[k] += other.colliding[k];
      Lower(k, other.minima[k]);
    }
  }
};

// Samples are drawn on the calling thread in blocks of this many, then checked in parallel.
constexpr std::int64_t kBlock = 16384;

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

std::vector<LinkCollisionGeometry> LinkCollisionGeometries(
    const std::vector<LinkSpherizeResult>& links) {
  std::vector<LinkCollisionGeometry> out(links.size());
  for (std::size_t l = 0; l < links.size(); ++l) {
    const LinkSpherizeResult& link = links[l];
    if (link.status != LinkStatus::kSpherized) continue;
    out[l].spheres = link.spheres;
    if (link.delta) {
      out[l].certified_delta = link.delta;
      out[l].inner = link.cores;
    }
  }
  return out;
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
          kinematics, prepared, q, &work, nullptr,
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
  const std::vector<std::vector<bool>> adjacent = AdjacentLinks(kinematics, links);
  Prepared prepared = Prepare(links);
  const std::size_t pair_count = prepared.pairs.size();
  for (std::size_t k = 0; k < pair_count; ++k) {
    const int a = prepared.links[prepared.pairs[k].first].link;
    const int b = prepared.links[prepared.pairs[k].second].link;
    if (adjacent[a][b] && !options.sample_adjacent) prepared.measured[k] = 0;
  }

  std::vector<bool> at_default(pair_count, false);
  {
    Workspace work;
    const std::vector<double> q = DefaultConfiguration(kinematics);
    if (absl::Status status = VisitIntervals(
            kinematics, prepared, q, &work, nullptr,
            [&](std::size_t k, const LinkPairInterval& i) { at_default[k] = i.colliding(); });
        !status.ok()) {
      return status;
    }
  }

  struct Local {
    Workspace work;
    PairStatistics statistics;
    absl::Status status;
  };
  tbb::enumerable_thread_specific<Local> locals([&] {
    return Local{Workspace{}, PairStatistics(pair_count), absl::OkStatus()};
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
    internal::ParallelForRange(
        std::int64_t{0}, count, 16, [&](std::int64_t begin, std::int64_t end) {
          Local& local = locals.local();
          for (std::int64_t s = begin; s < end; ++s) {
            const absl::Status status = VisitIntervals(
                kinematics, prepared, absl::MakeConstSpan(block.data() + s * variables, variables),
                &local.work, &local.statistics.minima,
                [&](std::size_t k, const LinkPairInterval& interval) {
                  local.statistics.Add(k, interval);
                });
            if (!status.ok() && local.status.ok()) local.status = status;
          }
        });
    if (options.control.on_progress) {
      options.control.on_progress(static_cast<double>(first + count) /
                                  static_cast<double>(options.samples));
    }
  }
  PairStatistics statistics(pair_count);
  for (const Local& local : locals) {
    // Sampled values are finite, so only an overflowing mimic can fail here.
    if (!local.status.ok()) return local.status;
    statistics.Merge(local.statistics);
  }

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
    pair.colliding_samples = statistics.colliding[k];
    pair.colliding_fraction =
        static_cast<double>(pair.colliding_samples) / static_cast<double>(options.samples);
    pair.min_lower = statistics.minima[k].lower;
    pair.min_upper = statistics.minima[k].upper;
    pair.min_sphere_distance = statistics.minima[k].sphere_distance;
    if (!prepared.measured[k]) {
      pair.sampled = false;
      pair.min_lower = pair.min_upper = pair.min_sphere_distance =
          std::numeric_limits<double>::quiet_NaN();
    }
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
