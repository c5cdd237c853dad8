#include "inscribe/separation_distance.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

// b's frame seen from a's: x_a = rotation * x_b + translation.
struct Relative {
  Eigen::Matrix3d rotation;
  Vector3 translation;
};

Relative RelativePose(const RigidPose& pose_a, const RigidPose& pose_b) {
  const RigidPose t = pose_a.Inverse() * pose_b;
  return Relative{t.rotation.toRotationMatrix(), t.translation};
}

// A leaf sphere as a rectangle swept sphere: a point rectangle at its centre.
Rss PointRss(const Sphere& s) {
  Rss r;
  r.origin = s.center;
  r.radius = s.radius;
  return r;
}

// Reads one hierarchy's node or leaf volumes for the search.
class Side {
 public:
  explicit Side(const SphereHierarchy& h) : h_(h) {}
  bool rss() const { return h_.volume() == HierarchyVolume::kRss; }
  // The leaf's sphere, or the sphere around the node's volume.
  const Sphere& sphere(HierarchyRef ref) const {
    return IsLeaf(ref) ? h_.spheres()[static_cast<std::size_t>(LeafSphere(ref))]
                       : h_.outer_sphere(ref);
  }
  // The volume as an RSS: the node's own, or a point RSS built in *scratch.
  const Rss& AsRss(HierarchyRef ref, Rss* scratch) const {
    if (!IsLeaf(ref) && rss()) return h_.rss(ref);
    *scratch = PointRss(sphere(ref));
    return *scratch;
  }
  // How big the volume is: the side to descend is the bigger one.
  double Size(HierarchyRef ref) const { return sphere(ref).radius; }
  const SphereHierarchy& hierarchy() const { return h_; }

 private:
  const SphereHierarchy& h_;
};

// Node pairs with at most this many sphere pairs below them are compared pair by pair.
constexpr std::int32_t kAllPairs = 32;

class Search {
 public:
  Search(const SphereHierarchy& a, const SphereHierarchy& b, const Relative& relative,
         const DistanceRequest& request)
      : a_(a),
        b_(b),
        rel_(relative),
        request_(request),
        yes_no_(std::isfinite(request.closer_than)) {}

  DistanceResult Run() {
    DistanceResult out;
    struct Pair {
      HierarchyRef a, b;
      double bound;
    };
    // One stack per thread, kept between queries: no allocation per query.
    thread_local std::vector<Pair> stack;
    stack.clear();
    const HierarchyRef ra = a_.hierarchy().root(), rb = b_.hierarchy().root();
    stack.push_back({ra, rb, Bound(ra, rb, Threshold(), &out)});
    while (!stack.empty()) {
      const Pair p = stack.back();
      stack.pop_back();
      const double threshold = Threshold();
      if (p.bound >= threshold) continue;
      if (IsLeaf(p.a) && IsLeaf(p.b)) {
        // The bound of two leaves is their exact value.
        best_ = p.bound;
        best_a_ = LeafSphere(p.a);
        best_b_ = LeafSphere(p.b);
        if (yes_no_ && best_ < request_.closer_than) break;
        continue;
      }
      // Few sphere pairs left below: compare them all rather than test more volumes.
      const std::int32_t na = a_.hierarchy().count(p.a), nb = b_.hierarchy().count(p.b);
      if (na * nb <= kAllPairs) {
        CompareAll(p.a, p.b, &out);
        if (yes_no_ && best_ < request_.closer_than) break;
        continue;
      }
      const bool split_a = !IsLeaf(p.a) && (IsLeaf(p.b) || a_.Size(p.a) >= b_.Size(p.b));
      Pair first, second;
      if (split_a) {
        const HierarchyRef l = a_.hierarchy().left(p.a), r = a_.hierarchy().right(p.a);
        first = {l, p.b, Bound(l, p.b, threshold, &out)};
        second = {r, p.b, Bound(r, p.b, threshold, &out)};
      } else {
        const HierarchyRef l = b_.hierarchy().left(p.b), r = b_.hierarchy().right(p.b);
        first = {p.a, l, Bound(p.a, l, threshold, &out)};
        second = {p.a, r, Bound(p.a, r, threshold, &out)};
      }
      // The nearer pair is searched first (pushed last). The threshold has not moved since
      // the pop: only leaf pairs move it.
      if (first.bound < second.bound) std::swap(first, second);
      if (first.bound < threshold) stack.push_back(first);
      if (second.bound < threshold) stack.push_back(second);
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
  // Every sphere of a against every sphere of b, keeping pairs below the threshold.
  void CompareAll(HierarchyRef a, HierarchyRef b, DistanceResult* out) {
    const SphereHierarchy& ha = a_.hierarchy();
    const SphereHierarchy& hb = b_.hierarchy();
    const std::int32_t* ia = &ha.leaf_order()[static_cast<std::size_t>(ha.first(a))];
    const std::int32_t* ib = &hb.leaf_order()[static_cast<std::size_t>(hb.first(b))];
    const std::int32_t na = ha.count(a), nb = hb.count(b);
    Vector3 moved[kAllPairs];
    for (std::int32_t j = 0; j < nb; ++j) {
      moved[j] =
          rel_.rotation * hb.spheres()[static_cast<std::size_t>(ib[j])].center + rel_.translation;
    }
    out->sphere_tests += na * nb;
    double threshold = Threshold();
    for (std::int32_t i = 0; i < na; ++i) {
      const Sphere& sa = ha.spheres()[static_cast<std::size_t>(ia[i])];
      for (std::int32_t j = 0; j < nb; ++j) {
        const double d = (sa.center - moved[j]).norm() - sa.radius -
                         hb.spheres()[static_cast<std::size_t>(ib[j])].radius;
        if (d < threshold) {
          best_ = d;
          best_a_ = ia[i];
          best_b_ = ib[j];
          threshold = Threshold();
        }
      }
    }
  }

  // Node pairs bounded at or above this cannot improve the answer beyond the tolerance, or
  // cannot answer a closer_than query yes.
  double Threshold() const {
    if (!std::isfinite(best_)) return request_.closer_than;
    const double tolerance = std::max(request_.abs_err, request_.rel_err * std::abs(best_));
    return std::min(best_ - tolerance, request_.closer_than);
  }

  // A lower bound on |c_a - c_b| - r_a - r_b over the spheres below a and b; exact for two
  // leaves. The spheres around the two volumes give a cheap bound first; the RSS test (several
  // times dearer) runs only when that bound would not already prune the pair.
  double Bound(HierarchyRef a, HierarchyRef b, double threshold, DistanceResult* out) const {
    const Sphere& sa = a_.sphere(a);
    const Sphere& sb = b_.sphere(b);
    const double cheap =
        (sa.center - (rel_.rotation * sb.center + rel_.translation)).norm() - sa.radius - sb.radius;
    if (IsLeaf(a) && IsLeaf(b)) {
      ++out->sphere_tests;
      return cheap;
    }
    ++out->volume_tests;
    if ((!a_.rss() || IsLeaf(a)) && (!b_.rss() || IsLeaf(b))) return cheap;
    if (cheap >= threshold) return cheap;
    ++out->rss_tests;
    Rss scratch_a, scratch_b;
    return std::max(cheap, RssDistance(a_.AsRss(a, &scratch_a), rel_.rotation, rel_.translation,
                                       b_.AsRss(b, &scratch_b)));
  }

  Side a_, b_;
  Relative rel_;
  const DistanceRequest& request_;
  const bool yes_no_;  // a closer_than query: stop at the first pair below it
  double best_ = std::numeric_limits<double>::infinity();
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
  return absl::OkStatus();
}

// Fills the witnesses of out's pair, in the world frame.
void AddWitnesses(const std::vector<Sphere>& a, const std::vector<Sphere>& b,
                  const RigidPose& pose_a, const Relative& relative, DistanceResult* out) {
  if (out->sphere_a < 0) return;
  const Sphere& sa = a[static_cast<std::size_t>(out->sphere_a)];
  const Sphere& sb = b[static_cast<std::size_t>(out->sphere_b)];
  const Vector3 cb = relative.rotation * sb.center + relative.translation;
  Vector3 u = cb - sa.center;
  const double length = u.norm();
  u = length > 0.0 ? Vector3(u / length) : Vector3::UnitX();
  out->point_a = pose_a * Vector3(sa.center + sa.radius * u);
  out->point_b = pose_a * Vector3(cb - sb.radius * u);
}

DistanceResult Query(const SphereHierarchy& a, const RigidPose& pose_a, const SphereHierarchy& b,
                     const RigidPose& pose_b, const DistanceRequest& request) {
  const Relative relative = RelativePose(pose_a, pose_b);
  DistanceResult out = Search(a, b, relative, request).Run();
  if (!out.closer && std::isfinite(request.closer_than)) out.distance = request.closer_than;
  AddWitnesses(a.spheres(), b.spheres(), pose_a, relative, &out);
  return out;
}

}  // namespace

absl::StatusOr<DistanceResult> SeparationDistance(const SphereHierarchy& a, const RigidPose& pose_a,
                                                  const SphereHierarchy& b, const RigidPose& pose_b,
                                                  const DistanceRequest& request) {
  if (absl::Status s = CheckRequest(request); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_a); !s.ok()) return s;
  if (absl::Status s = CheckPose(pose_b); !s.ok()) return s;
  return Query(a, pose_a, b, pose_b, request);
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
  tbb::parallel_for(std::size_t{0}, poses_b.size(),
                    [&](std::size_t i) { out[i] = Query(a, identity, b, poses_b[i], request); });
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
    moved[j] = relative.rotation * b[j].center + relative.translation;
  }
  DistanceResult out;
  const bool yes_no = std::isfinite(request.closer_than);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < a.size() && !(yes_no && best < request.closer_than); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      ++out.sphere_tests;
      const double d = (a[i].center - moved[j]).norm() - a[i].radius - b[j].radius;
      if (d < best) {
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
