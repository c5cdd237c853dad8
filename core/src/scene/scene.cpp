#include "inscribe/scene/scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/float_rounding.h"
#include "base/parallel.h"
#include "distance/sphere_pair_search.h"
#include "scene/scene_sweep.h"

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

// The sweep keeps its axis while that spreads the centres at least this fraction of the axis
// that spreads them most.
constexpr double kSweepAxisHysteresis = 0.7;

// Pairs per parallel chunk of the narrow phase; fewer run on the calling thread (a frame of a
// few close pairs costs microseconds, less than forking would).
constexpr std::size_t kNarrowChunk = 16;

// The narrow phase runs on TBB's threads (SceneQuery::parallel) when the last frame's took at
// least this long on one thread. Measured with scene_bench on 2 cores: forking made 64- and
// 256-object frames of 25-75 us slower, and frames of 150 us or more faster.
constexpr double kForkNarrowSeconds = 100e-6;

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
  entry.local_extent = std::max(entry.local_center.norm() + entry.radius,
                                entry.local_box_center.norm() + entry.local_half.norm());
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
  absl::erase_if(last_pair_, [id](const auto& entry) {
    return entry.first.first == id || entry.first.second == id;
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
    e.rotation = pose.rotation.toRotationMatrix();
    e.world_center = internal::RotateAndShift(e.rotation, e.local_center, pose.translation);
    e.box_center = internal::RotateAndShift(e.rotation, e.local_box_center, pose.translation);
    e.half = internal::RotateAndShift(e.rotation.cwiseAbs(), e.local_half, Vector3::Zero());
    e.scale = pose.translation.norm() + e.local_extent;
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

void Scene::PrepareSweep(double threshold) {
  const std::size_t n = objects_.size();
  if (n < 2) return;
  // Sweep along the axis where the centres spread most, so that intervals overlap least.
  Vector3 mean = Vector3::Zero(), square = Vector3::Zero();
  double largest_scale = 0.0, largest_coordinate = 0.0, largest_radius = 0.0;
  for (const Entry& e : objects_) {
    mean += e.world_center;
    square += e.world_center.cwiseProduct(e.world_center);
    largest_scale = std::max(largest_scale, e.scale);
    largest_coordinate = std::max(largest_coordinate, e.world_center.cwiseAbs().maxCoeff());
    largest_radius = std::max(largest_radius, e.radius);
  }
  mean /= static_cast<double>(n);
  const Vector3 spread = square / static_cast<double>(n) - mean.cwiseProduct(mean);
  int axis = 0;
  spread.maxCoeff(&axis);
  // Changing the axis costs a full sort; the last frame's axis is kept while it spreads at
  // least kSweepAxisHysteresis of the widest (in a cube of objects the three take turns).
  if (order_valid_ && spread[sweep_axis_] >= kSweepAxisHysteresis * spread[axis]) {
    axis = sweep_axis_;
  }
  lows_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    lows_[i] = objects_[i].box_center[axis] - objects_[i].half[axis];
  }
  const double* lows = lows_.data();
  if (!order_valid_ || axis != sweep_axis_) {
    order_.resize(n);
    for (std::size_t i = 0; i < n; ++i) order_[i] = static_cast<std::uint32_t>(i);
    std::sort(order_.begin(), order_.end(),
              [lows](std::uint32_t x, std::uint32_t y) { return lows[x] < lows[y]; });
    sweep_axis_ = axis;
    order_valid_ = true;
  } else {
    // Objects move little between frames: insertion sort costs one pass plus the swaps.
    for (std::size_t i = 1; i < n; ++i) {
      const std::uint32_t moving = order_[i];
      const double key = lows[moving];
      std::size_t j = i;
      for (; j > 0 && lows[order_[j - 1]] > key; --j) order_[j] = order_[j - 1];
      order_[j] = moving;
    }
  }
  // The boxes in sweep order, high ends grown by `reach`: the threshold plus the largest
  // rounding slack of any pair, rounded outward to floats. Boxes whose gap along some axis is
  // at least `reach` hold spheres no closer than the threshold plus any pair's slack, so the
  // box test drops no pair that could be close; nor does the float sphere test
  // (internal::SweepHalfMargin).
  const double reach = threshold + 2.0 * kBroadPhaseSlack * largest_scale + kCertifiedDistanceFloor;
  const double half_margin = internal::SweepHalfMargin(largest_coordinate, largest_radius, reach);
  const bool sphere_test = half_margin >= 0.0;
  // kSweepLanes empty boxes after the last (low +infinity, high -infinity) end every row.
  const auto pad = [n](std::vector<float>& v, float empty) {
    v.resize(n + internal::kSweepLanes);
    std::fill(v.begin() + static_cast<std::ptrdiff_t>(n), v.end(), empty);
  };
  for (int d = 0; d < 3; ++d) {
    pad(sorted_low_[d], std::numeric_limits<float>::infinity());
    pad(sorted_high_[d], -std::numeric_limits<float>::infinity());
    pad(sorted_center_[d], 0.0f);
  }
  pad(sorted_rho_, 0.0f);
  for (std::size_t k = 0; k < n; ++k) {
    const Entry& e = objects_[order_[k]];
    for (int d = 0; d < 3; ++d) {
      sorted_low_[d][k] = internal::LooseRoundDown(e.box_center[d] - e.half[d]);
      sorted_high_[d][k] = internal::LooseRoundUp(e.box_center[d] + e.half[d] + reach);
      sorted_center_[d][k] = sphere_test ? static_cast<float>(e.world_center[d]) : 0.0f;
    }
    sorted_rho_[k] = sphere_test ? internal::LooseRoundUp(e.radius + 0.5 * reach + half_margin)
                                 : std::numeric_limits<float>::max();
  }
}

void Scene::SweepPairs(double threshold,
                       std::vector<std::pair<std::uint32_t, std::uint32_t>>* out) {
  const std::size_t n = objects_.size();
  internal::SweepView view{};
  for (int d = 0; d < 3; ++d) {
    view.low[d] = sorted_low_[d].data();
    view.high[d] = sorted_high_[d].data();
    view.center[d] = sorted_center_[d].data();
  }
  view.rho = sorted_rho_.data();
  view.axis = sweep_axis_;
  std::vector<std::uint32_t>& kept_rows = frame_scratch_.survivors;
  kept_rows.resize(n);
  std::uint32_t* survivors = kept_rows.data();
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const std::size_t kept = internal::ScanSweepRow(view, k, survivors);
    const Entry& a = objects_[order_[k]];
    for (std::size_t q = 0; q < kept; ++q) {
      const std::uint32_t other = order_[survivors[q]];
      const Entry& b = objects_[other];
      if ((a.object.group & b.object.mask) == 0 || (b.object.group & a.object.mask) == 0) continue;
      // The float box and sphere tests passed; the oriented boxes are tested in double, with
      // the pair's own slack.
      const double slack = kBroadPhaseSlack * (a.scale + b.scale) + kCertifiedDistanceFloor;
      if (internal::OrientedBoxesApart(a.box_center, a.rotation, a.local_half, b.box_center,
                                       b.rotation, b.local_half, threshold + slack)) {
        continue;
      }
      if (!ignored_.empty() && ignored_.count(PairKey(a.object.id, b.object.id)) != 0) continue;
      out->emplace_back(order_[k], other);
    }
  }
}

absl::StatusOr<SceneFrame> Scene::ClosePairs(const SceneQuery& query,
                                             const std::atomic<bool>* cancel) {
  if (absl::Status s = CheckSceneQuery(query); !s.ok()) return s;
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& candidates = frame_scratch_.candidates;
  candidates.clear();
  PrepareSweep(query.threshold);
  SweepPairs(query.threshold, &candidates);

  SceneFrame frame;
  frame.candidate_pairs = static_cast<std::int64_t>(candidates.size());
  std::vector<ScenePair>& answers = frame_scratch_.answers;
  answers.assign(candidates.size(), ScenePair{});
  std::vector<absl::Status>& errors = frame_scratch_.errors;
  errors.assign(candidates.size(), absl::OkStatus());
  // What a pair is close by and ranked by when max_pairs cuts: its distance, or for a certified
  // pair its covers' distance less the margin (lower before clamping at 0; +infinity when the
  // covers are no closer than threshold + margin).
  std::vector<double>& rank = frame_scratch_.rank;
  rank.assign(candidates.size(), std::numeric_limits<double>::infinity());
  DistanceRequest plain;
  plain.abs_err = query.abs_err;
  plain.rel_err = query.rel_err;
  plain.max_distance = query.threshold;
  if (query.stop_at_first && std::isfinite(query.threshold)) plain.closer_than = query.threshold;
  const bool try_last_pair = std::isfinite(plain.closer_than) && !last_pair_.empty();

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
      if (try_last_pair) {
        const auto hint = last_pair_.find(std::make_pair(out.a, out.b));
        const std::vector<Sphere>& spheres_a = a->object.spheres->spheres();
        const std::vector<Sphere>& spheres_b = b->object.spheres->spheres();
        // An id re-added with another set may name a pair out of range: searched instead.
        if (hint != last_pair_.end() &&
            static_cast<std::size_t>(hint->second.first) < spheres_a.size() &&
            static_cast<std::size_t>(hint->second.second) < spheres_b.size()) {
          DistanceResult r = internal::CheckedSpherePairDistance(
              spheres_a, pose_a, spheres_b, pose_b, hint->second.first, hint->second.second);
          if (r.distance < plain.closer_than) {
            out.result = r;
            out.result.closer = true;
            rank[c] = out.result.distance;
            return;
          }
        }
      }
      // Poses normalised by SetPoses and a request from a checked query: no checks needed.
      out.result = internal::CheckedSeparationDistance(*a->object.spheres, pose_a,
                                                       *b->object.spheres, pose_b, plain);
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
  // Each chunk adds its thread time to `work`: the narrow phase's cost on one thread, however
  // many ran it.
  std::atomic<std::int64_t> work_ns{0};
  const auto run = [&](std::size_t begin, std::size_t end) {
    if (cancelled()) return;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t c = begin; c < end; ++c) answer(c);
    work_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(
                   std::chrono::steady_clock::now() - start)
                   .count();
  };
  // Forking pays when the work is large: the other thread wakes, and reads poses and boxes
  // this thread has just written, from its own cache. The last frame's work decides (the
  // first frame's, the candidates' count).
  const bool fork = query.parallel && candidates.size() > kNarrowChunk &&
                    (last_narrow_seconds_ < 0.0 || last_narrow_seconds_ >= kForkNarrowSeconds);
  if (!fork) {
    for (std::size_t begin = 0; begin < candidates.size(); begin += kNarrowChunk) {
      run(begin, std::min(candidates.size(), begin + kNarrowChunk));
    }
  } else {
    internal::ParallelForRange(std::size_t{0}, candidates.size(), kNarrowChunk, run);
  }
  if (cancelled()) return absl::CancelledError("scene frame cancelled");
  last_narrow_seconds_ = 1e-9 * static_cast<double>(work_ns.load());
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
  last_pair_.clear();
  for (const std::size_t c : close) {
    const ScenePair& pair = answers[c];
    if (!pair.certified && pair.result.sphere_a >= 0) {
      last_pair_.emplace(std::make_pair(pair.a, pair.b),
                         std::make_pair(pair.result.sphere_a, pair.result.sphere_b));
    }
    frame.pairs.push_back(std::move(answers[c]));
  }
  std::sort(frame.pairs.begin(), frame.pairs.end(), [](const ScenePair& x, const ScenePair& y) {
    return std::make_pair(x.a, x.b) < std::make_pair(y.a, y.b);
  });
  return frame;
}

}  // namespace inscribe
