#include "inscribe/scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

// The sphere around a hierarchy's spheres, in its frame: the root's record (a leaf's own
// sphere for a one-sphere set).
Sphere RootSphere(const SphereHierarchy& h) {
  const SphereHierarchy::Slot& root = h.slot(h.root());
  return Sphere{root.center, root.radius};
}

// The box around a set's spheres, in its frame: min and max corners.
void GrowBox(const std::vector<Sphere>& spheres, Vector3* lo, Vector3* hi) {
  for (const Sphere& s : spheres) {
    *lo = lo->cwiseMin(s.center - Vector3::Constant(s.radius));
    *hi = hi->cwiseMax(s.center + Vector3::Constant(s.radius));
  }
}

// A sphere holding both.
Sphere Enclose(const Sphere& a, const Sphere& b) {
  const double reach = (b.center - a.center).norm() + b.radius;
  return Sphere{a.center, std::max(a.radius, reach)};
}

// Relative slack of the broad phase's test: its sphere distances are computed in double from
// rotated centres, so they err by a few ulps of the coordinates; far above that, far below any
// gap that matters. It also exceeds kCertifiedDistanceMargin, so that a pair the broad phase
// drops has a certified lower bound at or above the threshold.
constexpr double kBroadPhaseSlack = 1e-9;
static_assert(kBroadPhaseSlack > kCertifiedDistanceMargin);

// Pairs per parallel chunk of the narrow phase; fewer run on the calling thread (a frame of a
// few close pairs costs microseconds, less than forking would).
constexpr std::size_t kNarrowChunk = 16;

absl::Status ObjectError(SceneObjectId id, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("object ", id, ": ", status.message()));
}

}  // namespace

absl::Status CheckSceneObject(const SceneObject& object) {
  if (object.spheres == nullptr)
    return absl::InvalidArgumentError("its sphere hierarchy is missing");
  if ((object.internal == nullptr) != (object.cover == nullptr)) {
    return absl::InvalidArgumentError(
        "a certified object needs both its internal spheres and its cover; one is missing");
  }
  if (object.certified()) {
    const CertifiedObject certified{object.internal.get(), object.cover.get(), object.cover_delta};
    if (absl::Status s = CheckCertifiedObject(certified); !s.ok()) return s;
  }
  return NormalizedPose(object.pose).status();
}

absl::Status CheckSceneQuery(const SceneQuery& query) {
  if (std::isnan(query.threshold) || query.threshold == -HUGE_VAL) {
    return absl::InvalidArgumentError(
        absl::StrCat("the threshold must be a number or +infinity, got ", query.threshold));
  }
  if (!std::isfinite(query.abs_err) || query.abs_err < 0.0 || !std::isfinite(query.rel_err) ||
      query.rel_err < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("tolerances must be finite and >= 0, got abs_err ", query.abs_err,
                     " and rel_err ", query.rel_err));
  }
  if (query.max_pairs == 0) return absl::InvalidArgumentError("max_pairs must be at least 1");
  return absl::OkStatus();
}

absl::Status Scene::Add(SceneObject object) {
  if (absl::Status s = CheckSceneObject(object); !s.ok()) return ObjectError(object.id, s);
  if (index_.count(object.id) != 0) {
    return absl::AlreadyExistsError(absl::StrCat("object ", object.id, " is already in the scene"));
  }
  if (objects_.size() >= std::size_t{0xffffffffu}) {
    return absl::ResourceExhaustedError("a scene holds at most 2^32 - 1 objects");
  }
  object.pose = *NormalizedPose(object.pose);
  Entry entry;
  Sphere bound = RootSphere(*object.spheres);
  if (object.certified()) {
    bound = Enclose(Enclose(bound, RootSphere(*object.cover)), RootSphere(*object.internal));
    entry.certified =
        CertifiedObject{object.internal.get(), object.cover.get(), object.cover_delta};
  }
  entry.local_center = bound.center;
  entry.radius = bound.radius;
  Vector3 lo = Vector3::Constant(HUGE_VAL), hi = Vector3::Constant(-HUGE_VAL);
  GrowBox(object.spheres->spheres(), &lo, &hi);
  if (object.certified()) {
    GrowBox(object.cover->spheres(), &lo, &hi);
    GrowBox(object.internal->spheres(), &lo, &hi);
  }
  entry.local_box_center = 0.5 * (lo + hi);
  entry.local_half = 0.5 * (hi - lo);
  entry.object = std::move(object);
  index_.emplace(entry.object.id, objects_.size());
  objects_.push_back(std::move(entry));
  SetPose(objects_.back().object.id, objects_.back().object.pose).IgnoreError();
  order_valid_ = false;
  return absl::OkStatus();
}

absl::Status Scene::Remove(SceneObjectId id) {
  const auto it = index_.find(id);
  if (it == index_.end())
    return absl::NotFoundError(absl::StrCat("no object ", id, " in the scene"));
  const std::size_t position = it->second;
  index_.erase(it);
  if (position + 1 != objects_.size()) {
    objects_[position] = std::move(objects_.back());
    index_[objects_[position].object.id] = position;
  }
  objects_.pop_back();
  absl::erase_if(ignored_, [id](const std::pair<SceneObjectId, SceneObjectId>& key) {
    return key.first == id || key.second == id;
  });
  order_valid_ = false;
  return absl::OkStatus();
}

absl::Status Scene::SetPoses(const std::vector<std::pair<SceneObjectId, RigidPose>>& poses) {
  std::vector<std::pair<std::size_t, RigidPose>> checked;
  checked.reserve(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto it = index_.find(poses[i].first);
    if (it == index_.end()) {
      return absl::NotFoundError(
          absl::StrCat("poses[", i, "]: no object ", poses[i].first, " in the scene"));
    }
    absl::StatusOr<RigidPose> pose = NormalizedPose(poses[i].second);
    if (!pose.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("poses[", i, "] (object ", poses[i].first, "): ", pose.status().message()));
    }
    checked.emplace_back(it->second, *pose);
  }
  for (const auto& [position, pose] : checked) {
    Entry& e = objects_[position];
    e.object.pose = pose;
    e.world_center = pose * e.local_center;
    const Eigen::Matrix3d rotation = pose.rotation.toRotationMatrix();
    e.box_center = rotation * e.local_box_center + pose.translation;
    e.half = rotation.cwiseAbs() * e.local_half;
    e.scale = pose.translation.norm() + std::max(e.local_center.norm() + e.radius,
                                                 e.local_box_center.norm() + e.local_half.norm());
  }
  return absl::OkStatus();
}

absl::Status Scene::SetPose(SceneObjectId id, const RigidPose& pose) {
  return SetPoses({{id, pose}});
}

absl::Status Scene::Ignore(SceneObjectId a, SceneObjectId b) {
  if (a == b)
    return absl::InvalidArgumentError(absl::StrCat("object ", a, " cannot ignore itself"));
  for (const SceneObjectId id : {a, b}) {
    if (index_.count(id) == 0) {
      return absl::NotFoundError(absl::StrCat("no object ", id, " in the scene"));
    }
  }
  ignored_.insert(PairKey(a, b));
  return absl::OkStatus();
}

void Scene::Sweep(double threshold, std::vector<std::pair<std::uint32_t, std::uint32_t>>* out) {
  out->clear();
  const std::size_t n = objects_.size();
  if (n < 2) return;
  // Sweep along the axis where the centres spread most, so that intervals overlap least.
  Vector3 mean = Vector3::Zero(), square = Vector3::Zero();
  for (const Entry& e : objects_) {
    mean += e.world_center;
    square += e.world_center.cwiseProduct(e.world_center);
  }
  mean /= static_cast<double>(n);
  Vector3 spread = square / static_cast<double>(n) - mean.cwiseProduct(mean);
  int axis = 0;
  spread.maxCoeff(&axis);
  const auto low = [this, axis](std::uint32_t i) {
    return objects_[i].box_center[axis] - objects_[i].half[axis];
  };
  if (!order_valid_ || axis != sweep_axis_) {
    order_.resize(n);
    for (std::size_t i = 0; i < n; ++i) order_[i] = static_cast<std::uint32_t>(i);
    std::sort(order_.begin(), order_.end(),
              [&](std::uint32_t x, std::uint32_t y) { return low(x) < low(y); });
    sweep_axis_ = axis;
    order_valid_ = true;
  } else {
    // Objects move little between frames: insertion sort costs one pass plus the swaps.
    for (std::size_t i = 1; i < n; ++i) {
      const std::uint32_t moving = order_[i];
      const double key = low(moving);
      std::size_t j = i;
      for (; j > 0 && low(order_[j - 1]) > key; --j) order_[j] = order_[j - 1];
      order_[j] = moving;
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Entry& a = objects_[order_[k]];
    const double high = a.box_center[axis] + a.half[axis];
    for (std::size_t m = k + 1; m < n; ++m) {
      const Entry& b = objects_[order_[m]];
      const double slack = kBroadPhaseSlack * (a.scale + b.scale) + kCertifiedDistanceFloor;
      // Sorted by low end: every later object's gap along the axis is at least this one's.
      if (low(order_[m]) - high >= threshold + slack) break;
      if ((a.object.group & b.object.mask) == 0 || (b.object.group & a.object.mask) == 0) continue;
      // Two lower bounds on the distance between the objects' spheres: the boxes' largest gap
      // along an axis, and the bounding spheres' gap.
      const double box_gap =
          ((a.box_center - b.box_center).cwiseAbs() - a.half - b.half).maxCoeff();
      if (!(box_gap < threshold + slack)) continue;
      const double gap = (a.world_center - b.world_center).norm() - a.radius - b.radius;
      if (!(gap < threshold + slack)) continue;
      if (!ignored_.empty() && ignored_.count(PairKey(a.object.id, b.object.id)) != 0) continue;
      out->emplace_back(order_[k], order_[m]);
    }
  }
}

absl::StatusOr<SceneFrame> Scene::ClosePairs(const SceneQuery& query,
                                             const std::atomic<bool>* cancel) {
  if (absl::Status s = CheckSceneQuery(query); !s.ok()) return s;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates;
  Sweep(query.threshold, &candidates);

  SceneFrame frame;
  frame.candidate_pairs = static_cast<std::int64_t>(candidates.size());
  std::vector<ScenePair> answers(candidates.size());
  std::vector<absl::Status> errors(candidates.size());
  // What a pair is close by and ranked by when max_pairs cuts: its distance, or for a certified
  // pair its covers' distance less the margin (lower before clamping at 0; +infinity when the
  // covers are no closer than threshold + margin).
  std::vector<double> rank(candidates.size(), std::numeric_limits<double>::infinity());
  DistanceRequest plain;
  plain.abs_err = query.abs_err;
  plain.rel_err = query.rel_err;
  plain.max_distance = query.threshold;
  if (query.stop_at_first && std::isfinite(query.threshold)) plain.closer_than = query.threshold;

  // One candidate: the smaller id is a. A plain pair's distance is pruned at the threshold; a
  // certified pair's covers at the threshold plus the margin (lower < threshold needs no
  // more), and its internal sets at the covers' distance plus the deltas (beyond it the covers
  // give upper).
  const auto answer = [&](std::size_t c) {
    const Entry* a = &objects_[candidates[c].first];
    const Entry* b = &objects_[candidates[c].second];
    if (b->object.id < a->object.id) std::swap(a, b);
    ScenePair& out = answers[c];
    out.a = a->object.id;
    out.b = b->object.id;
    const RigidPose& pose_a = a->object.pose;
    const RigidPose& pose_b = b->object.pose;
    if (!(a->object.certified() && b->object.certified())) {
      absl::StatusOr<DistanceResult> r =
          SeparationDistance(*a->object.spheres, pose_a, *b->object.spheres, pose_b, plain);
      if (!r.ok()) {
        errors[c] = r.status();
        return;
      }
      out.result = *std::move(r);
      // A closer_than query that found no pair answers closer_than itself: not close.
      if (out.result.sphere_a >= 0) rank[c] = out.result.distance;
      return;
    }
    absl::StatusOr<double> margin =
        CertifiedDistanceMargin(a->certified, pose_a, b->certified, pose_b);
    if (!margin.ok()) {
      errors[c] = margin.status();
      return;
    }
    DistanceRequest covers;
    covers.max_distance = query.threshold + *margin;
    absl::StatusOr<DistanceResult> outer =
        SeparationDistance(*a->object.cover, pose_a, *b->object.cover, pose_b, covers);
    if (!outer.ok()) {
      errors[c] = outer.status();
      return;
    }
    out.certified = true;
    if (!std::isfinite(outer->distance)) return;  // covers >= threshold + margin: not close
    const double deltas = a->object.cover_delta + b->object.cover_delta;
    DistanceRequest inner;
    inner.max_distance = std::max(0.0, outer->distance) + deltas;
    absl::StatusOr<DistanceResult> internal =
        SeparationDistance(*a->object.internal, pose_a, *b->object.internal, pose_b, inner);
    if (!internal.ok()) {
      errors[c] = internal.status();
      return;
    }
    CertifiedDistanceResult interval =
        CertifiedInterval(*std::move(internal), *std::move(outer), deltas, *margin, HUGE_VAL);
    out.lower = interval.lower;
    out.upper = interval.upper;
    rank[c] = interval.cover.distance - *margin;
    out.result = std::move(interval.cover);
  };
  const auto cancelled = [cancel] { return cancel != nullptr && cancel->load(); };
  const auto run = [&](std::size_t begin, std::size_t end) {
    if (cancelled()) return;
    for (std::size_t c = begin; c < end; ++c) answer(c);
  };
  if (candidates.size() <= kNarrowChunk || !query.parallel) {
    for (std::size_t begin = 0; begin < candidates.size(); begin += kNarrowChunk) {
      run(begin, std::min(candidates.size(), begin + kNarrowChunk));
    }
  } else {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), kNarrowChunk),
                      [&](const tbb::blocked_range<std::size_t>& r) { run(r.begin(), r.end()); });
  }
  if (cancelled()) return absl::CancelledError("scene frame cancelled");
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (!errors[c].ok()) {
      return absl::Status(errors[c].code(), absl::StrCat("pair (", answers[c].a, ", ", answers[c].b,
                                                         "): ", errors[c].message()));
    }
  }

  std::vector<std::size_t> close;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (rank[c] < query.threshold) close.push_back(c);
  }
  frame.close_pairs = static_cast<std::int64_t>(close.size());
  if (close.size() > query.max_pairs) {
    frame.truncated = true;
    const auto nearer = [&](std::size_t x, std::size_t y) {
      return std::make_tuple(rank[x], answers[x].a, answers[x].b) <
             std::make_tuple(rank[y], answers[y].a, answers[y].b);
    };
    std::nth_element(close.begin(), close.begin() + static_cast<std::ptrdiff_t>(query.max_pairs),
                     close.end(), nearer);
    close.resize(query.max_pairs);
  }
  frame.pairs.reserve(close.size());
  for (const std::size_t c : close) frame.pairs.push_back(std::move(answers[c]));
  std::sort(frame.pairs.begin(), frame.pairs.end(), [](const ScenePair& x, const ScenePair& y) {
    return std::make_pair(x.a, x.b) < std::make_pair(y.a, y.b);
  });
  return frame;
}

}  // namespace inscribe
