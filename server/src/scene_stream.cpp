// SceneStream: a scene (core's Scene) held for the life of one bidirectional call. The first
// message creates it, each further message changes it (poses, objects, ignored pairs, query)
// and is answered with the frame's close pairs, in order. One message is in the reactor at a
// time (FrameStreamReactor), so the scene is only ever touched by one thread at a time. The
// objects' hierarchies are resolved when they are added; the scene (and with it every
// hierarchy it holds) is freed when the call is done, however it ends.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "frame_dispatch.h"
#include "frame_stream_reactor.h"
#include "inscribe/scene/scene.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"
#include "service_parts.h"

namespace inscribe::server {
namespace {

// FrameStreamReactor runs the stream; a frame here is a message that changes the scene and
// asks its close pairs. Errors of a message name its frame.
class SceneStreamReactor final : public FrameStreamReactor<v1::SceneMessage, v1::SceneReply> {
 public:
  SceneStreamReactor(const ServiceParts& parts, grpc::CallbackServerContext* context)
      : FrameStreamReactor(parts, context, "SceneStream") {
    parts.open_scenes.fetch_add(1);  // until Closed
  }

 private:
  // The O(1) checks of the message on the gRPC thread: first message or not, the limits, its
  // query, and the memory of the scene it would make (reserved here, held for the stream).
  absl::Status Admit() override {
    const ServiceLimits& limits = parts().limits;
    if (!created_ && !request().has_query()) {
      return absl::InvalidArgumentError(
          "query: the first message creates the scene and must carry its query");
    }
    if (created_ && request().volume() != v1::HIERARCHY_VOLUME_UNSPECIFIED) {
      return absl::InvalidArgumentError(
          "volume: only the first message chooses the hierarchy volume");
    }
    if (request().has_query()) {
      absl::StatusOr<SceneQuery> query =
          wire::SceneQueryFromProto(request().query(), limits.max_scene_pairs, "--max-scene-pairs");
      if (!query.ok()) return query.status();
      pending_query_ = *query;
    } else {
      pending_query_ = query_;
    }
    // At most, before the changes are checked: removals of unknown ids fail later anyway.
    const std::int64_t objects = static_cast<std::int64_t>(scene_.size()) + request().add_size();
    if (objects - request().remove_size() > limits.max_scene_objects) {
      return absl::ResourceExhaustedError(
          absl::StrCat("would hold ", objects - request().remove_size(),
                       " objects; this server's limit (--max-scene-objects) is ",
                       limits.max_scene_objects, " per scene"));
    }
    if (request().pose_ids_size() > limits.max_scene_objects) {
      return absl::ResourceExhaustedError(
          absl::StrCat("has ", request().pose_ids_size(),
                       " poses; this server's limit (--max-scene-objects) is ",
                       limits.max_scene_objects, " per scene"));
    }
    const std::int64_t ignored = ignored_sent_ + request().ignore_size() / 2;
    if (ignored > limits.max_scene_ignored) {
      return absl::ResourceExhaustedError(
          absl::StrCat("would bring the scene's ignored pairs to ", ignored,
                       "; this server's limit (--max-scene-ignored) is ", limits.max_scene_ignored,
                       " per stream"));
    }
    const std::int64_t bytes =
        objects * MemoryCosts::kPerSceneObject + ignored * MemoryCosts::kPerIgnoredPair +
        static_cast<std::int64_t>(pending_query_.max_pairs) * MemoryCosts::kPerScenePair;
    if (bytes > scene_reservation_.bytes()) {
      absl::StatusOr<MemoryBudget::Reservation> reserved = parts().admission.Reserve(
          bytes,
          absl::StrCat("SceneStream of ", objects, " objects and max_pairs ",
                       pending_query_.max_pairs),
          &record());
      if (!reserved.ok()) return reserved.status();
      scene_reservation_ = *std::move(reserved);
    }
    ignored_sent_ = ignored;
    return absl::OkStatus();
  }

  // The message's work, in the stream's cost unit (Items): the objects and the last frame's
  // candidate pairs. It is resolved when it adds no objects (whose sets are looked up in the
  // cache), and serial (answered on the calling thread, SceneQuery::parallel false, when
  // inline) when the last frame had few candidates.
  FrameWork Work() override {
    FrameWork work;
    work.items = Items();
    work.resolved = request().add_size() == 0;
    work.serial = last_candidates_ <= kSerialFramePairs;
    // The pool's lane: by the message's working memory (the scene's own is reserved for the
    // stream's life), so small scenes never wait behind large calls.
    work.memory_bytes = work.items * MemoryCosts::kPerScenePair;
    return work;
  }

  std::int64_t Items() const {
    return static_cast<std::int64_t>(scene_.size()) + request().add_size() + last_candidates_;
  }

  absl::Status InFrame(const absl::Status& status) const override {
    return absl::Status(status.code(),
                        absl::StrCat("frame ", request().frame(), " ", status.message()));
  }

  void Timed(double seconds) override { reply().set_seconds(seconds); }

  // The scene and its hierarchies go with the call.
  void Closed() override {
    scene_ = Scene();
    scene_reservation_.Release();
    parts().open_scenes.fetch_sub(1);
  }

  // Applies the message to the scene and answers it into reply() (`place`: where it runs).
  absl::Status Answer(FramePlace place) override {
    reply().Clear();
    reply().set_frame(request().frame());
    if (!created_) {
      volume_ = wire::VolumeFromProto(request().volume());
      created_ = true;
    }
    for (int i = 0; i < request().remove_size(); ++i) {
      if (absl::Status s = scene_.Remove(request().remove(i)); !s.ok()) {
        return Named(absl::StrCat("remove[", i, "]"), s);
      }
    }
    for (int i = 0; i < request().add_size(); ++i) {
      if (absl::Status s = AddObject(i); !s.ok()) return s;
    }
    absl::StatusOr<std::vector<std::pair<SceneObjectId, SceneObjectId>>> ignored =
        wire::SceneIgnoredFromProto(request());
    if (!ignored.ok()) return ignored.status();
    for (std::size_t i = 0; i < ignored->size(); ++i) {
      const auto [a, b] = (*ignored)[i];
      if (absl::Status s = scene_.Ignore(a, b); !s.ok()) {
        return Named(absl::StrCat("ignore pair ", i, " (", a, ", ", b, ")"), s);
      }
    }
    absl::StatusOr<std::vector<std::pair<SceneObjectId, RigidPose>>> poses =
        wire::ScenePosesFromProto(request());
    if (!poses.ok()) return poses.status();
    for (std::size_t i = 0; i < poses->size(); ++i) {
      if (!scene_.contains((*poses)[i].first)) {
        return absl::NotFoundError(
            absl::StrCat("pose_ids[", i, "]: no object ", (*poses)[i].first, " in the scene"));
      }
    }
    if (absl::Status s = scene_.SetPoses(*poses); !s.ok()) return Named("poses", s);
    query_ = pending_query_;
    SceneQuery query = query_;
    query.parallel = place == FramePlace::kPool;  // TBB loops belong in the pool's arena
    absl::StatusOr<SceneFrame> frame = scene_.ClosePairs(query, &cancelled());
    if (!frame.ok()) return frame.status();
    last_candidates_ = frame->candidate_pairs;
    wire::SceneFrameToProto(*frame, &reply());
    reply().set_objects(static_cast<std::int64_t>(scene_.size()));
    return absl::OkStatus();
  }

  // Adds request().add(i), its hierarchies resolved from the store (a certified object's
  // internal spheres and cover as Distance's certificate rule gives them).
  absl::Status AddObject(int i) {
    const v1::SceneObject& wire_object = request().add(i);
    const std::string field = absl::StrCat("add[", i, "]");
    absl::StatusOr<SceneObject> object = wire::SceneObjectFromProto(wire_object, field);
    if (!object.ok()) return object.status();
    const std::string named = absl::StrCat(field, " (object ", wire_object.id(), ")");
    if (absl::Status s = CheckKey(wire_object.sphere_set(), "sphere_set"); !s.ok()) {
      return Named(named, s);
    }
    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> spheres =
        parts().store.GetHierarchy(wire_object.sphere_set(), volume_);
    if (!spheres.ok()) return Named(absl::StrCat(named, ".sphere_set"), spheres.status());
    object->spheres = *std::move(spheres);
    if (!wire_object.cover().empty()) {
      if (absl::Status s = CheckKey(wire_object.cover(), "cover"); !s.ok()) return Named(named, s);
      absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> certified =
          parts().store.GetCertifiedObject(wire_object.sphere_set(), wire_object.cover(), volume_);
      if (!certified.ok()) return Named(absl::StrCat(named, ".cover"), certified.status());
      object->internal = (*certified)->internal;
      object->cover = (*certified)->cover;
      object->cover_delta = (*certified)->object.cover_delta;
    }
    if (absl::Status s = scene_.Add(*std::move(object)); !s.ok()) return Named(named, s);
    return absl::OkStatus();
  }

  // `s` with `where` in front of its message.
  static absl::Status Named(const std::string& where, const absl::Status& s) {
    return absl::Status(s.code(), absl::StrCat(where, ": ", s.message()));
  }

  // Touched by one thread at a time: gRPC callbacks and the message's job never overlap.
  Scene scene_;
  bool created_ = false;  // the first message has been applied
  HierarchyVolume volume_ = HierarchyVolume::kSphere;
  SceneQuery query_;          // the current query
  SceneQuery pending_query_;  // the message's (its own, or the current one)
  std::int64_t ignored_sent_ = 0;
  std::int64_t last_candidates_ = 0;
  MemoryBudget::Reservation scene_reservation_;  // the scene's estimate, for its life
};

}  // namespace

grpc::ServerBidiReactor<v1::SceneMessage, v1::SceneReply>* InscribeService::SceneStream(
    grpc::CallbackServerContext* context) {
  auto* reactor = new SceneStreamReactor(Parts(), context);
  reactor->Start();
  return reactor;
}

}  // namespace inscribe::server
