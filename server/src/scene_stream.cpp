// SceneStream: a scene (core's Scene) held for the life of one bidirectional call. The first
// message creates it, each further message changes it (poses, objects, ignored pairs, query)
// and is answered with the frame's close pairs, in order. As in DistanceStream, one message
// is in the reactor at a time (read, compute on the pool, write, read the next), so the scene
// is only ever touched by one thread at a time, and a slow client slows only itself. The
// objects' hierarchies are resolved when they are added; the scene (and with it every
// hierarchy it holds) is freed when the call is done, however it ends.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "drainable_stream.h"
#include "frame_dispatch.h"
#include "inscribe/scene.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {

// States as DistanceStreamReactor's: kReading (a read is pending), kBusy (a message is being
// applied or its reply written), kFinished (Finish was called). Transitions happen under
// mutex_, and Finish and StartRead are called under it.
class SceneStreamReactor final : public grpc::ServerBidiReactor<v1::SceneMessage, v1::SceneReply>,
                                 public DrainableStream {
 public:
  SceneStreamReactor(InscribeService* service, grpc::CallbackServerContext* context)
      : service_(service) {
    record_.method = "SceneStream";
    record_.peer = context->peer();
  }

  // `admitted`: the service's Authenticate verdict; a refused stream ends before any read.
  void Start(const absl::Status& admitted) {
    service_->CallStarted();
    service_->open_scenes_.fetch_add(1);
    {
      std::lock_guard<std::mutex> lock(service_->calls_mutex_);
      service_->streams_.insert(this);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!admitted.ok()) {
      FinishLocked(admitted);
      return;
    }
    if (service_->draining_.load()) {
      FinishLocked(absl::UnavailableError("server is shutting down; retry"));
      return;
    }
    state_ = State::kReading;
    StartRead(&message_);
  }

  void Drain() override {
    std::lock_guard<std::mutex> lock(mutex_);
    draining_ = true;
    if (state_ == State::kReading) {
      FinishLocked(absl::UnavailableError("server is shutting down; reconnect to another"));
    }
  }

  void OnReadDone(bool ok) override {
    const ServiceClock::time_point arrived = ServiceClock::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (state_ == State::kFinished) return;
      if (!ok) {
        // The client half-closed or the call was cancelled; every message read was answered.
        FinishLocked(absl::OkStatus());
        return;
      }
      if (absl::Status s = Admit(); !s.ok()) {
        FinishLocked(
            absl::Status(s.code(), absl::StrCat("frame ", message_.frame(), " ", s.message())));
        return;
      }
      // kBusy: a drain now waits for this message's reply, and nothing else touches it.
      state_ = State::kBusy;
    }
    Dispatch(arrived);
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state_ == State::kFinished) return;
    if (!ok) {
      FinishLocked(absl::CancelledError("client went away"));
      return;
    }
    if (draining_) {
      FinishLocked(absl::UnavailableError("server is shutting down; reconnect to another"));
      return;
    }
    state_ = State::kReading;
    StartRead(&message_);
  }

  void OnCancel() override { cancelled_.store(true); }

  void OnDone() override {
    {
      std::lock_guard<std::mutex> lock(service_->calls_mutex_);
      service_->streams_.erase(this);
    }
    record_.status = final_status_;
    service_->Observe(record_);
    // The scene and its hierarchies go with the reactor.
    scene_ = Scene();
    scene_reservation_.Release();
    service_->open_scenes_.fetch_sub(1);
    service_->CallEnded();
    Unref();
  }

 private:
  enum class State { kStarting, kReading, kBusy, kFinished };

  void FinishLocked(const absl::Status& status) {
    state_ = State::kFinished;
    final_status_ = status;
    Finish(wire::ToGrpcStatus(status));
  }

  // The O(1) checks of message_ on the gRPC thread: first message or not, the limits, its
  // query, and the memory of the scene it would make (reserved here, held for the stream).
  absl::Status Admit() {
    const ServiceLimits& limits = service_->limits_;
    if (!created_ && !message_.has_query()) {
      return absl::InvalidArgumentError(
          "query: the first message creates the scene and must carry its query");
    }
    if (created_ && message_.volume() != v1::HIERARCHY_VOLUME_UNSPECIFIED) {
      return absl::InvalidArgumentError(
          "volume: only the first message chooses the hierarchy volume");
    }
    if (message_.has_query()) {
      absl::StatusOr<SceneQuery> query =
          wire::SceneQueryFromProto(message_.query(), limits.max_scene_pairs, "--max-scene-pairs");
      if (!query.ok()) return query.status();
      pending_query_ = *query;
    } else {
      pending_query_ = query_;
    }
    // At most, before the changes are checked: removals of unknown ids fail later anyway.
    const std::int64_t objects = static_cast<std::int64_t>(scene_.size()) + message_.add_size();
    if (objects - message_.remove_size() > limits.max_scene_objects) {
      return absl::ResourceExhaustedError(
          absl::StrCat("would hold ", objects - message_.remove_size(),
                       " objects; this server's limit (--max-scene-objects) is ",
                       limits.max_scene_objects, " per scene"));
    }
    if (message_.pose_ids_size() > limits.max_scene_objects) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "has ", message_.pose_ids_size(), " poses; this server's limit (--max-scene-objects) is ",
          limits.max_scene_objects, " per scene"));
    }
    const std::int64_t ignored = ignored_sent_ + message_.ignore_size() / 2;
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
      absl::StatusOr<MemoryBudget::Reservation> reserved = service_->memory_->Reserve(
          bytes, absl::StrCat("SceneStream of ", objects, " objects and max_pairs ",
                              pending_query_.max_pairs));
      if (!reserved.ok()) return reserved.status();
      scene_reservation_ = *std::move(reserved);
      record_.memory_bytes = std::max(record_.memory_bytes, scene_reservation_.bytes());
    }
    ignored_sent_ = ignored;
    return absl::OkStatus();
  }

  // Runs the message inline or on the pool (FrameDispatcher, the rule every stream shares);
  // a full pool ends the stream with RESOURCE_EXHAUSTED naming --max-queue. Its work, in the
  // stream's cost unit (Items): the objects and the last frame's candidate pairs. It is
  // resolved when it adds no objects (whose sets are looked up in the cache), and serial
  // (answered on the calling thread, SceneQuery::parallel false, when inline) when the last
  // frame had few candidates.
  void Dispatch(ServiceClock::time_point arrived) {
    FrameWork work;
    work.items = Items();
    work.resolved = message_.add_size() == 0;
    work.serial = last_candidates_ <= kSerialFramePairs;
    // The pool's lane: by the message's working memory (the scene's own is reserved for the
    // stream's life), so small scenes never wait behind large calls.
    work.memory_bytes = work.items * MemoryCosts::kPerScenePair;
    // After a true return the reply may be written and the next message running: no member may
    // be touched here.
    if (!service_->frames_->Run(
            work, cost_.Estimate(work.items),
            [this, arrived](FramePlace place) { RunMessage(arrived, place); })) {
      std::lock_guard<std::mutex> lock(mutex_);
      FinishLocked(service_->QueueFullError());
    }
  }

  std::int64_t Items() const {
    return static_cast<std::int64_t>(scene_.size()) + message_.add_size() + last_candidates_;
  }

  // Applies message_ to the scene and answers it into reply_ (`place`: where it runs), then
  // writes it (or ends the stream).
  void RunMessage(ServiceClock::time_point arrived, FramePlace place) {
    const ServiceClock::time_point started = ServiceClock::now();
    record_.queued_seconds += std::chrono::duration<double>(started - arrived).count();
    const std::int64_t items = Items();
    absl::Status status;
    try {
      status = ComputeMessage(place);
    } catch (const std::bad_alloc&) {
      status = absl::ResourceExhaustedError("server ran out of memory in SceneStream");
    }
    if (status.ok() && cancelled_.load()) status = absl::CancelledError("client went away");
    const double seconds = SecondsSince(started);
    record_.run_seconds += seconds;
    reply_.set_seconds(seconds);
    if (status.ok()) {
      cost_.Record(items, seconds);
      ++record_.frames;
      if (place == FramePlace::kInline) ++record_.inline_frames;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!status.ok()) {
      FinishLocked(absl::Status(status.code(),
                                absl::StrCat("frame ", message_.frame(), " ", status.message())));
      return;
    }
    StartWrite(&reply_);
  }

  absl::Status ComputeMessage(FramePlace place) {
    reply_.Clear();
    reply_.set_frame(message_.frame());
    if (!created_) {
      volume_ = wire::VolumeFromProto(message_.volume());
      created_ = true;
    }
    for (int i = 0; i < message_.remove_size(); ++i) {
      if (absl::Status s = scene_.Remove(message_.remove(i)); !s.ok()) {
        return Named(absl::StrCat("remove[", i, "]"), s);
      }
    }
    for (int i = 0; i < message_.add_size(); ++i) {
      if (absl::Status s = AddObject(i); !s.ok()) return s;
    }
    absl::StatusOr<std::vector<std::pair<SceneObjectId, SceneObjectId>>> ignored =
        wire::SceneIgnoredFromProto(message_);
    if (!ignored.ok()) return ignored.status();
    for (std::size_t i = 0; i < ignored->size(); ++i) {
      const auto [a, b] = (*ignored)[i];
      if (absl::Status s = scene_.Ignore(a, b); !s.ok()) {
        return Named(absl::StrCat("ignore pair ", i, " (", a, ", ", b, ")"), s);
      }
    }
    absl::StatusOr<std::vector<std::pair<SceneObjectId, RigidPose>>> poses =
        wire::ScenePosesFromProto(message_);
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
    absl::StatusOr<SceneFrame> frame = scene_.ClosePairs(query, &cancelled_);
    if (!frame.ok()) return frame.status();
    last_candidates_ = frame->candidate_pairs;
    wire::SceneFrameToProto(*frame, &reply_);
    reply_.set_objects(static_cast<std::int64_t>(scene_.size()));
    return absl::OkStatus();
  }

  // Adds message_.add(i), its hierarchies resolved from the store (a certified object's
  // internal spheres and cover as Distance's certificate rule gives them).
  absl::Status AddObject(int i) {
    const v1::SceneObject& wire_object = message_.add(i);
    const std::string field = absl::StrCat("add[", i, "]");
    absl::StatusOr<SceneObject> object = wire::SceneObjectFromProto(wire_object, field);
    if (!object.ok()) return object.status();
    const std::string named = absl::StrCat(field, " (object ", wire_object.id(), ")");
    if (absl::Status s = CheckKey(wire_object.sphere_set(), "sphere_set"); !s.ok()) {
      return Named(named, s);
    }
    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> spheres =
        service_->store_->GetHierarchy(wire_object.sphere_set(), volume_);
    if (!spheres.ok()) return Named(absl::StrCat(named, ".sphere_set"), spheres.status());
    object->spheres = *std::move(spheres);
    if (!wire_object.cover().empty()) {
      if (absl::Status s = CheckKey(wire_object.cover(), "cover"); !s.ok()) return Named(named, s);
      absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> certified =
          service_->store_->GetCertifiedObject(wire_object.sphere_set(), wire_object.cover(),
                                               volume_);
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

  InscribeService* const service_;
  std::atomic<bool> cancelled_{false};

  std::mutex mutex_;
  State state_ = State::kStarting;  // guarded by mutex_
  bool draining_ = false;           // guarded by mutex_
  absl::Status final_status_;       // set once, by FinishLocked

  // Touched by one thread at a time: gRPC callbacks and the message's job never overlap.
  v1::SceneMessage message_;
  v1::SceneReply reply_;
  Scene scene_;
  bool created_ = false;  // the first message has been applied
  HierarchyVolume volume_ = HierarchyVolume::kSphere;
  SceneQuery query_;          // the current query
  SceneQuery pending_query_;  // message_'s (its own, or the current one)
  std::int64_t ignored_sent_ = 0;
  std::int64_t last_candidates_ = 0;
  FrameCostModel cost_;                          // seconds per item of this stream's messages
  MemoryBudget::Reservation scene_reservation_;  // the scene's estimate, for its life
  CallRecord record_;
};

grpc::ServerBidiReactor<v1::SceneMessage, v1::SceneReply>* InscribeService::SceneStream(
    grpc::CallbackServerContext* context) {
  auto* reactor = new SceneStreamReactor(this, context);
  reactor->Start(Authenticate(*context));
  return reactor;
}

}  // namespace inscribe::server
