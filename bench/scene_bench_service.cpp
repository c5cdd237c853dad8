// scene_bench's rows over the service: an inscribed on loopback in this process, one
// SceneSession (SceneStream) per scene, each reply checked against core's Scene.
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "scene_bench.h"

namespace inscribe::scene_bench {

// The same scene over the service: one SceneSession (SceneStream) to an inscribed on loopback,
// every frame sending every pose; each reply is checked against core's Scene fed the same
// frames (every K-th frame) and must be identical.
Timing RunService(const client::Client& client, const Motion& motion,
                  const std::vector<Model>& models, bool certified, double threshold,
                  bool stop_at_first, const Options& options, int frames, int* failures) {
  std::vector<client::SceneSessionObject> objects;
  for (std::size_t i = 0; i < motion.model.size(); ++i) {
    const Model& m = models[motion.model[i]];
    client::SceneSessionObject o;
    o.object.id = i;
    o.object.pose = motion.pose[0][i];
    o.sphere_set_key = certified ? m.cores_key : m.spheres_key;
    if (certified) o.cover_key = m.cover_key;
    objects.push_back(std::move(o));
  }
  client::SceneSessionOptions session_options;
  session_options.volume = HierarchyVolume::kSphere;
  session_options.query.threshold = threshold;
  session_options.query.stop_at_first = stop_at_first;
  absl::StatusOr<client::SceneSession> session = client.OpenSceneSession(objects, session_options);
  if (!session.ok()) {
    std::fprintf(stderr, "SceneStream: %s\n", std::string(session.status().message()).c_str());
    ++*failures;
    return Timing{};
  }
  Scene local = MakeScene(motion, models, certified);
  std::vector<std::pair<SceneObjectId, RigidPose>> moves(motion.model.size());
  std::vector<double> seconds;
  double candidates = 0.0, close = 0.0;
  for (int f = 0; f < frames; ++f) {
    const auto& poses = motion.pose[static_cast<std::size_t>(f)];
    const Clock::time_point start = Clock::now();
    for (std::size_t i = 0; i < poses.size(); ++i) moves[i] = {i, poses[i]};
    absl::StatusOr<client::SceneFrameResult> reply = session->Frame(moves);
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    if (!reply.ok()) {
      std::fprintf(stderr, "SceneStream frame %d: %s\n", f,
                   std::string(reply.status().message()).c_str());
      ++*failures;
      return Summarise(std::move(seconds), candidates, close);
    }
    candidates += static_cast<double>(reply->candidate_pairs);
    close += static_cast<double>(reply->close_pairs);
    // Every frame, untimed: a stop_at_first answer may depend on the scene's earlier frames.
    absl::StatusOr<SceneFrame> want = local.SetPoses(moves).ok()
                                          ? local.ClosePairs(session_options.query)
                                          : absl::InternalError("poses");
    if (f % options.check_every != 0) continue;
    bool same = want.ok() && want->pairs.size() == reply->pairs.size();
    for (std::size_t k = 0; same && k < want->pairs.size(); ++k) {
      const ScenePair& x = want->pairs[k];
      const ScenePair& y = reply->pairs[k];
      same = x.a == y.a && x.b == y.b && x.result.distance == y.result.distance &&
             x.lower == y.lower && x.upper == y.upper && x.certified == y.certified;
    }
    if (!same) {
      std::fprintf(stderr, "SceneStream frame %d differs from core's Scene: %zu pairs, core %zu", f,
                   reply->pairs.size(), want.ok() ? want->pairs.size() : 0);
      for (std::size_t k = 0; want.ok() && k < std::min(want->pairs.size(), reply->pairs.size());
           ++k) {
        const ScenePair& x = want->pairs[k];
        const ScenePair& y = reply->pairs[k];
        if (x.a != y.a || x.b != y.b || x.result.distance != y.result.distance ||
            x.lower != y.lower || x.upper != y.upper) {
          std::fprintf(stderr,
                       "; first difference (%llu, %llu) %.17g [%.17g, %.17g] against "
                       "(%llu, %llu) %.17g [%.17g, %.17g]",
                       static_cast<unsigned long long>(y.a), static_cast<unsigned long long>(y.b),
                       y.result.distance, y.lower, y.upper, static_cast<unsigned long long>(x.a),
                       static_cast<unsigned long long>(x.b), x.result.distance, x.lower, x.upper);
          break;
        }
      }
      std::fprintf(stderr, "\n");
      ++*failures;
    }
  }
  if (absl::Status closed = session->Close(); !closed.ok()) ++*failures;
  return Summarise(std::move(seconds), candidates, close);
}

}  // namespace inscribe::scene_bench
