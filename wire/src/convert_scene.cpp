// The proto <-> core mappings of scenes: objects, moved poses, ignored pairs, queries and
// frames (declared in convert.h).
#include <cstddef>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/wire/convert.h"

namespace inscribe::wire {
namespace {

constexpr int kPerRow = 3;

}  // namespace

void SceneObjectToProto(const SceneObject& object, const std::string& sphere_set,
                        const std::string& cover, v1::SceneObject* out) {
  const SceneObject defaults;
  out->set_id(object.id);
  out->set_sphere_set(sphere_set);
  out->set_cover(cover);
  PoseToProto(object.pose, out->mutable_pose());
  if (object.group != defaults.group) out->set_group(object.group);
  if (object.mask != defaults.mask) out->set_mask(object.mask);
}

absl::StatusOr<SceneObject> SceneObjectFromProto(const v1::SceneObject& object,
                                                 absl::string_view field) {
  SceneObject out;
  out.id = object.id();
  if (object.sphere_set().empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, " (object ", object.id(), "): sphere_set is empty"));
  }
  absl::StatusOr<RigidPose> pose =
      PoseFromProto(object.pose(), absl::StrCat(field, " (object ", object.id(), ").pose"));
  if (!pose.ok()) return pose.status();
  out.pose = *pose;
  if (object.has_group()) out.group = object.group();
  if (object.has_mask()) out.mask = object.mask();
  return out;
}

void ScenePosesToProto(const std::vector<std::pair<SceneObjectId, RigidPose>>& poses,
                       v1::SceneMessage* out) {
  out->clear_pose_ids();
  out->mutable_pose_ids()->Reserve(static_cast<int>(poses.size()));
  std::vector<RigidPose> values;
  values.reserve(poses.size());
  for (const auto& [id, pose] : poses) {
    out->add_pose_ids(id);
    values.push_back(pose);
  }
  PosesToProto(values, out->mutable_poses());
}

absl::StatusOr<std::vector<std::pair<SceneObjectId, RigidPose>>> ScenePosesFromProto(
    const v1::SceneMessage& message) {
  absl::StatusOr<std::vector<RigidPose>> poses = PosesFromProto(message.poses(), "poses");
  if (!poses.ok()) return poses.status();
  if (poses->size() != static_cast<std::size_t>(message.pose_ids_size())) {
    return absl::InvalidArgumentError(absl::StrCat("pose_ids has ", message.pose_ids_size(),
                                                   " ids for ", poses->size(), " poses"));
  }
  std::vector<std::pair<SceneObjectId, RigidPose>> out(poses->size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = {message.pose_ids(static_cast<int>(i)), (*poses)[i]};
  }
  return out;
}

void SceneIgnoredToProto(const std::vector<std::pair<SceneObjectId, SceneObjectId>>& pairs,
                         v1::SceneMessage* out) {
  out->clear_ignore();
  out->mutable_ignore()->Reserve(static_cast<int>(2 * pairs.size()));
  for (const auto& [a, b] : pairs) {
    out->add_ignore(a);
    out->add_ignore(b);
  }
}

absl::StatusOr<std::vector<std::pair<SceneObjectId, SceneObjectId>>> SceneIgnoredFromProto(
    const v1::SceneMessage& message) {
  if (message.ignore_size() % 2 != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ignore has ", message.ignore_size(), " ids; expected 2 per pair (a0, b0, a1, b1, ...)"));
  }
  std::vector<std::pair<SceneObjectId, SceneObjectId>> out(
      static_cast<std::size_t>(message.ignore_size() / 2));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = {message.ignore(static_cast<int>(2 * i)), message.ignore(static_cast<int>(2 * i + 1))};
  }
  return out;
}

void SceneQueryToProto(const SceneQuery& query, v1::SceneQuery* out) {
  out->set_threshold(query.threshold);
  out->set_abs_err(query.abs_err);
  out->set_rel_err(query.rel_err);
  out->set_stop_at_first(query.stop_at_first);
  if (query.max_pairs != SceneQuery{}.max_pairs) {
    out->set_max_pairs(static_cast<std::int64_t>(query.max_pairs));
  }
}

absl::StatusOr<SceneQuery> SceneQueryFromProto(const v1::SceneQuery& query,
                                               std::int64_t max_pairs_limit,
                                               absl::string_view limit_name) {
  SceneQuery out;
  out.threshold = query.threshold();
  out.abs_err = query.abs_err();
  out.rel_err = query.rel_err();
  out.stop_at_first = query.stop_at_first();
  if (query.has_max_pairs()) {
    if (query.max_pairs() < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("query: max_pairs must be >= 1, got ", query.max_pairs()));
    }
    if (query.max_pairs() > max_pairs_limit) {
      return absl::ResourceExhaustedError(absl::StrCat("query: max_pairs ", query.max_pairs(),
                                                       " is over this server's limit (", limit_name,
                                                       ") of ", max_pairs_limit));
    }
    out.max_pairs = static_cast<std::size_t>(query.max_pairs());
  } else if (static_cast<std::int64_t>(out.max_pairs) > max_pairs_limit) {
    out.max_pairs = static_cast<std::size_t>(max_pairs_limit);
  }
  if (absl::Status s = CheckSceneQuery(out); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("query: ", s.message()));
  }
  return out;
}

void SceneFrameToProto(const SceneFrame& frame, v1::SceneReply* out) {
  v1::ScenePairs* pairs = out->mutable_pairs();
  pairs->Clear();
  const int n = static_cast<int>(frame.pairs.size());
  pairs->mutable_a()->Reserve(n);
  pairs->mutable_b()->Reserve(n);
  pairs->mutable_distances()->Reserve(n);
  pairs->mutable_points_a()->Reserve(kPerRow * n);
  pairs->mutable_points_b()->Reserve(kPerRow * n);
  for (const ScenePair& p : frame.pairs) {
    pairs->add_a(p.a);
    pairs->add_b(p.b);
    pairs->add_distances(p.result.distance);
    pairs->add_spheres_a(p.result.sphere_a);
    pairs->add_spheres_b(p.result.sphere_b);
    for (int k = 0; k < kPerRow; ++k) pairs->add_points_a(p.result.point_a[k]);
    for (int k = 0; k < kPerRow; ++k) pairs->add_points_b(p.result.point_b[k]);
    pairs->add_certified(p.certified);
    pairs->add_lower(p.lower);
    pairs->add_upper(p.upper);
  }
  out->set_candidate_pairs(frame.candidate_pairs);
  out->set_close_pairs(frame.close_pairs);
  out->set_truncated(frame.truncated);
}

absl::StatusOr<SceneFrame> SceneFrameFromProto(const v1::SceneReply& reply) {
  const v1::ScenePairs& p = reply.pairs();
  const int n = p.a_size();
  if (p.b_size() != n || p.distances_size() != n || p.spheres_a_size() != n ||
      p.spheres_b_size() != n || p.points_a_size() != kPerRow * n ||
      p.points_b_size() != kPerRow * n || p.certified_size() != n || p.lower_size() != n ||
      p.upper_size() != n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "scene pairs: arrays disagree in length (", n, " ids a, ", p.b_size(), " ids b, ",
        p.distances_size(), " distances, ", p.points_a_size(), " point coordinates)"));
  }
  SceneFrame frame;
  frame.pairs.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    ScenePair& out = frame.pairs[static_cast<std::size_t>(i)];
    out.a = p.a(i);
    out.b = p.b(i);
    out.result.distance = p.distances(i);
    out.result.sphere_a = p.spheres_a(i);
    out.result.sphere_b = p.spheres_b(i);
    for (int k = 0; k < kPerRow; ++k) {
      out.result.point_a[k] = p.points_a(kPerRow * i + k);
      out.result.point_b[k] = p.points_b(kPerRow * i + k);
    }
    out.certified = p.certified(i);
    out.lower = p.lower(i);
    out.upper = p.upper(i);
  }
  frame.candidate_pairs = reply.candidate_pairs();
  frame.close_pairs = reply.close_pairs();
  frame.truncated = reply.truncated();
  return frame;
}

}  // namespace inscribe::wire
