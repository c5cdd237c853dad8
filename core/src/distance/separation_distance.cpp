#include "inscribe/distance/separation_distance.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "distance/sphere_pair_search.h"

namespace inscribe {
namespace {

// b's frame seen from a's: x_a = rotation * x_b + translation.
using Relative = internal::RelativeFrame;

Relative RelativePose(const RigidPose& pose_a, const RigidPose& pose_b) {
  const RigidPose t = pose_a.Inverse() * pose_b;
  return Relative{t.rotation.toRotationMatrix(), t.translation};
}

// A leaf sphere as a rectangle swept sphere: a point rectangle at its centre.
Rss PointRss(const SphereHierarchy::Slot& s) {
  Rss r;
  r.origin = s.center;
  r.radius = s.radius;
  return r;
}

// Node pairs with at most this many sphere pairs below them are compared pair by pair: 64
// beat 16, 32 and 128 in bench/separation_distance_bench (eight and knot1, both hierarchies).
constexpr std::int64_t kAllPairs = 64;

// Branch and bound over the two hierarchies, depth first, nearer child pair first. Each step
// reads one record per side (SphereHierarchy::Slot): the sphere around the node, its children
// and its range of spheres; RSS volumes are read only when the spheres around two nodes do not
// already prune them.
class Search {
 public:
  using Slot = SphereHierarchy::Slot;

  Search(const SphereHierarchy& a, const SphereHierarchy& b, const Relative& relative,
         const DistanceRequest& request)
      : a_(a),
        b_(b),
        rel_(relative),
        request_(request),
        yes_no_(std::isfinite(request.closer_than)),
        rss_a_(a.volume() == HierarchyVolume::kRss),
        rss_b_(b.volume() == HierarchyVolume::kRss),
        threshold_(std::min(request.closer_than, request.max_distance)) {}

  DistanceResult Run() {
    DistanceResult out;
    struct Pair {
      HierarchyRef a, b;
      double bound;
    };
    // One stack per thread, kept between queries: no allocation per query.
    thread_local std::vector<Pair> stack;
    stack.clear();
    const HierarchyRef ra = a_.root(), rb = b_.root();
    const Slot& root_b = b_.slot(rb);
    stack.push_back({ra, rb, Bound(ra, a_.slot(ra), rb, root_b, Move(root_b.center), &out)});
    while (!stack.empty()) {
      const Pair p = stack.back();
      stack.pop_back();
      if (p.bound >= threshold_) continue;
      const Slot& sa = a_.slot(p.a);
      const Slot& sb = b_.slot(p.b);
      if (sa.count == 1 && sb.count == 1) {
        // The bound of two leaves is their exact value.
        Improve(p.bound, a_.leaf_order()[static_cast<std::size_t>(sa.first)],
                b_.leaf_order()[static_cast<std::size_t>(sb.first)]);
        if (yes_no_ && best_ < request_.closer_than) break;
        continue;
      }
      // Few sphere pairs left below: compare them all rather than test more volumes.
      if (std::int64_t{sa.count} * sb.count <= kAllPairs) {
        CompareAll(sa, sb, &out);
        if (yes_no_ && best_ < request_.closer_than) break;
        continue;
      }
      const bool split_a = sa.count > 1 && (sb.count == 1 || sa.radius >= sb.radius);
      Pair first, second;
      if (split_a) {
        const Vector3 cb = Move(sb.center);  // shared by both children's tests
        first = {sa.left, p.b, Bound(sa.left, a_.slot(sa.left), p.b, sb, cb, &out)};
        second = {sa.right, p.b, Bound(sa.right, a_.slot(sa.right), p.b, sb, cb, &out)};
      } else {
        const Slot& l = b_.slot(sb.left);
        const Slot& r = b_.slot(sb.right);
        first = {p.a, sb.left, Bound(p.a, sa, sb.left, l, Move(l.center), &out)};
        second = {p.a, sb.right, Bound(p.a, sa, sb.right, r, Move(r.center), &out)};
      }
      // The nearer pair is searched first (pushed last).
      if (first.bound < second.bound) std::swap(first, second);
      if (first.bound < threshold_) stack.push_back(first);
      if (second.bound < threshold_) stack.push_back(second);
    }
    if (best_a_ >= 0) {
      out.distance = best_;
      out.sphere_a = best_a_;
      out.sphere_b = best_b_;
    }
    out.closer = best_ < request_.closer_than;
    return out;
  }

 private:
  // b's point in a's frame.
  Vector3 Move(const Vector3& p) const { return internal::MoveToA(rel_, p); }

  // A new best pair; pairs bounded at or above the new threshold cannot improve the answer
  // beyond the tolerance, or cannot answer a closer_than query yes.
  void Improve(double d, std::int32_t sphere_a, std::int32_t sphere_b) {
    best_ = d;
    best_a_ = sphere_a;
    best_b_ = sphere_b;
    threshold_ = internal::PruneThreshold(request_, d);
  }

  // Every sphere below a against every sphere below b (at most kAllPairs pairs). A pair is
  // rejected on squared distances first; the square root is taken only for a possible
  // improvement, with the same expression as the brute force.
  void CompareAll(const Slot& sa, const Slot& sb, DistanceResult* out) {
    const Sphere* spheres_a = &a_.ordered_spheres()[static_cast<std::size_t>(sa.first)];
    const Sphere* spheres_b = &b_.ordered_spheres()[static_cast<std::size_t>(sb.first)];
    const std::int32_t na = sa.count, nb = sb.count;
    Vector3 moved[kAllPairs];
    for (std::int32_t j = 0; j < nb; ++j) moved[j] = Move(spheres_b[j].center);
    out->sphere_tests += std::int64_t{na} * nb;
    for (std::int32_t i = 0; i < na; ++i) {
      const Sphere& s = spheres_a[i];
      for (std::int32_t j = 0; j < nb; ++j) {
        const double reach = threshold_ + s.radius + spheres_b[j].radius;
        const double squared = (s.center - moved[j]).squaredNorm();
        // d < threshold needs |c_a - c_b| < reach: impossible when reach <= 0.
        if (!(reach > 0.0) || squared >= reach * reach) continue;
        const double d = internal::SphereGap(s.center, s.radius, moved[j], spheres_b[j].radius);
        if (d < threshold_) {
          Improve(d, a_.leaf_order()[static_cast<std::size_t>(sa.first + i)],
                  b_.leaf_order()[static_cast<std::size_t>(sb.first + j)]);
        }
      }
    }
  }

  // A lower bound on |c_a - c_b| - r_a - r_b over the spheres below a and b, given b's centre
  // already in a's frame; exact for two leaves. The spheres around the two volumes give a cheap
  // bound first; the RSS test (several times dearer) runs only when that bound would not
  // already prune the pair.
  double Bound(HierarchyRef a, const Slot& sa, HierarchyRef b, const Slot& sb,
               const Vector3& moved_b, DistanceResult* out) const {
    const double cheap = internal::SphereGap(sa.center, sa.radius, moved_b, sb.radius);
    const bool node_a = !IsLeaf(a), node_b = !IsLeaf(b);
    if (!node_a && !node_b) {
      ++out->sphere_tests;
      return cheap;
    }
    ++out->volume_tests;
    const bool rss_a = rss_a_ && node_a, rss_b = rss_b_ && node_b;
    if ((!rss_a && !rss_b) || cheap >= threshold_) return cheap;
    ++out->rss_tests;
    const Rss point_a = rss_a ? Rss() : PointRss(sa);
    const Rss point_b = rss_b ? Rss() : PointRss(sb);
    return std::max(cheap, RssDistance(rss_a ? a_.rss(a) : point_a, rel_.rotation, rel_.translation,
                                       rss_b ? b_.rss(b) : point_b));
  }

  const SphereHierarchy& a_;
  const SphereHierarchy& b_;
  Relative rel_;
  const DistanceRequest& request_;
  const bool yes_no_;  // a closer_than query: stop at the first pair below it
  const bool rss_a_, rss_b_;
  double best_ = std::numeric_limits<double>::infinity();
  double threshold_;  // pairs bounded at or above this are pruned
  std::int32_t best_a_ = -1, best_b_ = -1;
};

absl::Status CheckRequest(const DistanceRequest& request) {
  if (!std::isfinite(request.abs_err) || request.abs_err < 0.0 || !std::isfinite(request.rel_err) ||
      request.rel_err < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("tolerances must be finite and >= 0, got abs_err ", request.abs_err,
                     " and rel_err ", request.rel_err));
  }
  if (std::isnan(request.closer_than) || request.closer_than == -HUGE_VAL) {
    return absl::InvalidArgumentError(
        absl::StrCat("closer_than must be a number or +infinity, got ", request.closer_than));
  }
  if (std::isnan(request.max_distance) || request.max_distance == -HUGE_VAL) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_distance must be a number or +infinity, got ", request.max_distance));
  }
  return absl::OkStatus();
}

// Fills the witnesses of out's pair, in the world frame.
void AddWitnesses(const std::vector<Sphere>& a, const std::vector<Sphere>& b,
                  const RigidPose& pose_a, const Relative& relative, DistanceResult* out) {
  if (out->sphere_a < 0) return;
  const Sphere& sa = a[static_cast<std::size_t>(out->sphere_a)];
  const Sphere& sb = b[static_cast<std::size_t>(out->sphere_b)];
  const Vector3 cb = internal::MoveToA(relative, sb.center);
  Vector3 u = cb - sa.center;
  const double length = u.norm();
  u = length > 0.0 ? Vector3(u / length) : Vector3::UnitX();
  out->point_a = pose_a * Vector3(sa.center + sa.radius * u);
  out->point_b = pose_a * Vector3(cb - sb.radius * u);
}

}  // namespace

DistanceResult internal::CheckedSeparationDistance(const SphereHierarchy& a,
                                                   const RigidPose& pose_a,
                                                   const SphereHierarchy& b,
                                                   const RigidPose& pose_b,
                                                   const DistanceRequest& request) {
  const Relative relative = RelativePose(pose_a, pose_b);
  DistanceResult out;
  if (!internal::FloatFilteredSearch(a, b, relative, request, &out)) {
    out = Search(a, b, relative, request).Run();
  }
  if (!out.closer && std::isfinite(request.closer_than)) out.distance = request.closer_than;
  AddWitnesses(a.spheres(), b.spheres(), pose_a, relative, &out);
  return out;
}

absl::StatusOr<DistanceResult> SeparationDistance(const SphereHierarchy& a, const RigidPose& pose_a,
                                                  const SphereHierarchy& b, const RigidPose& pose_b,
                                                  const DistanceRequest& request) {
  if (absl::Status s = CheckRequest(request); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_a); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_b); !s.ok()) return s;
  return internal::CheckedSeparationDistance(a, pose_a, b, pose_b, request);
}

absl::StatusOr<std::vector<DistanceResult>> SeparationDistances(
    const SphereHierarchy& a, const SphereHierarchy& b, const std::vector<RigidPose>& poses_b,
    const DistanceRequest& request) {
  if (absl::Status s = CheckRequest(request); !s.ok()) return s;
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    if (absl::Status s = CheckPose(poses_b[i]); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("pose ", i, ": ", s.message()));
    }
  }
  std::vector<DistanceResult> out(poses_b.size());
  const RigidPose identity;
  internal::ParallelFor(std::size_t{0}, poses_b.size(), [&](std::size_t i) {
    out[i] = internal::CheckedSeparationDistance(a, identity, b, poses_b[i], request);
  });
  return out;
}

absl::StatusOr<std::vector<DistanceResult>> PairSeparationDistances(
    const std::vector<PosedPair>& pairs, const DistanceRequest& request,
    const std::atomic<bool>* cancel) {
  if (absl::Status s = CheckRequest(request); !s.ok()) return s;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    absl::Status s = pairs[i].a == nullptr || pairs[i].b == nullptr
                         ? absl::InvalidArgumentError("a hierarchy is missing")
                         : CheckPose(pairs[i].pose_a);
    if (s.ok()) s = CheckPose(pairs[i].pose_b);
    if (!s.ok()) {
      return absl::Status(s.code(), absl::StrCat("pairs[", i, "]: ", s.message()));
    }
  }
  // About a millisecond of work per chunk; a frame of a few pairs (the usual simulator frame)
  // costs microseconds, less than forking would.
  constexpr std::size_t kChunk = 64;
  const auto cancelled = [cancel] { return cancel != nullptr && cancel->load(); };
  std::vector<DistanceResult> out(pairs.size());
  const auto run = [&](std::size_t begin, std::size_t end) {
    if (cancelled()) return;
    for (std::size_t i = begin; i < end; ++i) {
      const PosedPair& p = pairs[i];
      out[i] = internal::CheckedSeparationDistance(*p.a, p.pose_a, *p.b, p.pose_b, request);
    }
  };
  if (pairs.size() <= kChunk) {
    run(0, pairs.size());
  } else {
    internal::ParallelForRange(std::size_t{0}, pairs.size(), kChunk, run);
  }
  if (cancelled()) return absl::CancelledError("distance batch cancelled");
  return out;
}

absl::StatusOr<DistanceResult> SpherePairDistance(const std::vector<Sphere>& a,
                                                  const RigidPose& pose_a,
                                                  const std::vector<Sphere>& b,
                                                  const RigidPose& pose_b, std::int32_t i,
                                                  std::int32_t j) {
  if (i < 0 || static_cast<std::size_t>(i) >= a.size() || j < 0 ||
      static_cast<std::size_t>(j) >= b.size()) {
    return absl::InvalidArgumentError(absl::StrCat("sphere pair (", i, ", ", j,
                                                   ") is outside sets of ", a.size(), " and ",
                                                   b.size(), " spheres"));
  }
  if (absl::Status s = CheckPose(pose_a); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_b); !s.ok()) return s;
  return internal::CheckedSpherePairDistance(a, pose_a, b, pose_b, i, j);
}

DistanceResult internal::CheckedSpherePairDistance(const std::vector<Sphere>& a,
                                                   const RigidPose& pose_a,
                                                   const std::vector<Sphere>& b,
                                                   const RigidPose& pose_b, std::int32_t i,
                                                   std::int32_t j) {
  const Relative relative = RelativePose(pose_a, pose_b);
  const Sphere& s = a[static_cast<std::size_t>(i)];
  const Sphere& t = b[static_cast<std::size_t>(j)];
  DistanceResult out;
  out.distance =
      internal::SphereGap(s.center, s.radius, internal::MoveToA(relative, t.center), t.radius);
  out.sphere_a = i;
  out.sphere_b = j;
  out.sphere_tests = 1;
  AddWitnesses(a, b, pose_a, relative, &out);
  return out;
}

absl::StatusOr<DistanceResult> BruteForceSeparationDistance(const std::vector<Sphere>& a,
                                                            const RigidPose& pose_a,
                                                            const std::vector<Sphere>& b,
                                                            const RigidPose& pose_b,
                                                            const DistanceRequest& request) {
  if (absl::Status s = CheckRequest(request); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_a); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_b); !s.ok()) return s;
  const Relative relative = RelativePose(pose_a, pose_b);
  std::vector<Vector3> moved(b.size());
  for (std::size_t j = 0; j < b.size(); ++j) {
    moved[j] = internal::MoveToA(relative, b[j].center);
  }
  DistanceResult out;
  const bool yes_no = std::isfinite(request.closer_than);
  double best = std::numeric_limits<double>::infinity();
  // Pairs at or above max_distance are not answers.
  const double wanted = request.max_distance;
  for (std::size_t i = 0; i < a.size() && !(yes_no && best < request.closer_than); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      ++out.sphere_tests;
      const double d = internal::SphereGap(a[i].center, a[i].radius, moved[j], b[j].radius);
      if (d < best && d < wanted) {
        best = d;
        out.sphere_a = static_cast<std::int32_t>(i);
        out.sphere_b = static_cast<std::int32_t>(j);
        if (yes_no && best < request.closer_than) break;
      }
    }
  }
  out.closer = best < request.closer_than;
  if (std::isfinite(request.closer_than) && !out.closer) {
    out.distance = request.closer_than;
    out.sphere_a = out.sphere_b = -1;
  } else {
    out.distance = best;
  }
  AddWitnesses(a, b, pose_a, relative, &out);
  return out;
}

}  // namespace inscribe
