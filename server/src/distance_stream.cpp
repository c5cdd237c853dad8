// DistanceStream: one request per simulator frame, one response per frame, in order, over one
// long-lived bidirectional call (FrameStreamReactor: one frame in the reactor at a time,
// computed on the gRPC thread that read it or on the pool, as the FrameDispatcher says). The
// hierarchies a stream names are resolved once and held for the stream's life.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "frame_dispatch.h"
#include "frame_stream_reactor.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"
#include "service_parts.h"

namespace inscribe::server {
namespace {

// Distinct (set, volume) pairs one stream may hold: each pins a hierarchy in memory even after
// the cache has evicted it, so a stream cannot pin an unbounded amount.
constexpr std::size_t kMaxStreamSets = 1024;

// FrameStreamReactor runs the stream; a frame here is a batch of distance queries, admitted
// against --max-poses and --memory-budget (its reservation held until its reply is written).
class DistanceStreamReactor final
    : public FrameStreamReactor<v1::DistanceFrame, v1::DistanceFrameResult> {
 public:
  DistanceStreamReactor(const ServiceParts& parts, grpc::CallbackServerContext* context)
      : FrameStreamReactor(parts, context, "DistanceStream") {}

 private:
  absl::Status Admit() override {
    const v1::DistanceFrame& frame = request();
    if (frame.pairs_size() > parts().limits.max_poses) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "frame ", frame.frame(), " has ", frame.pairs_size(),
          " pairs; this server's limit (--max-poses) is ", parts().limits.max_poses, " per frame"));
    }
    // Held from here until the frame's reply has been written (or the stream ends).
    absl::StatusOr<MemoryBudget::Reservation> reserved = parts().admission.Reserve(
        frame.pairs_size() * MemoryCosts::kPerFramePair,
        absl::StrCat("DistanceStream frame ", frame.frame(), " of ", frame.pairs_size(), " pairs"),
        &record());
    if (!reserved.ok()) return reserved.status();
    frame_reservation_ = *std::move(reserved);
    return absl::OkStatus();
  }

  FrameWork Work() override {
    FrameWork work;
    work.items = FrameQueries();
    work.resolved = FindHeld();
    work.serial = request().pairs_size() <= kSerialFramePairs;
    work.memory_bytes = frame_reservation_.bytes();
    return work;
  }

  void FrameEnded() override { frame_reservation_.Release(); }

  // The frame's distances into reply(), on whichever thread the dispatcher chose.
  absl::Status Answer(FramePlace /*place*/) override {
    reply().Clear();
    reply().set_frame(request().frame());
    absl::StatusOr<DistanceRequest> tolerance = wire::ToleranceFromProto(request().tolerance());
    if (!tolerance.ok()) return tolerance.status();
    const HierarchyVolume volume = wire::VolumeFromProto(request().volume());
    if (certified_frame()) return ComputeCertifiedFrame(*tolerance, volume);
    // pairs_ holds what FindHeld found; the rest is looked up here, off the gRPC thread when
    // anything was missing (the dispatcher runs unresolved frames on the pool).
    const std::size_t n = static_cast<std::size_t>(request().pairs_size());
    for (std::size_t i = 0; i < n; ++i) {
      const v1::DistancePair& pair = request().pairs(static_cast<int>(i));
      if (!pair.cover_a().empty() || !pair.cover_b().empty()) {
        if (absl::Status s = CheckCovers(pair.cover_a(), pair.cover_b()); !s.ok()) {
          return InPair(i, s);
        }
        return InPair(
            i,
            absl::InvalidArgumentError(
                "cover_a, cover_b: a frame's pairs are all certified (covers named) or none, and "
                "pairs[0] names none"));
      }
      PosedPair& posed = pairs_[i];
      if (posed.a == nullptr) {
        absl::StatusOr<const SphereHierarchy*> a =
            Hierarchy(pair.sphere_set_a(), volume, "sphere_set_a");
        if (!a.ok()) return InPair(i, a.status());
        posed.a = *a;
      }
      if (posed.b == nullptr) {
        absl::StatusOr<const SphereHierarchy*> b =
            Hierarchy(pair.sphere_set_b(), volume, "sphere_set_b");
        if (!b.ok()) return InPair(i, b.status());
        posed.b = *b;
      }
      if (absl::Status s = ReadPoses(i, pair, &posed.pose_a, &posed.pose_b); !s.ok()) {
        return s;
      }
    }
    absl::StatusOr<std::vector<DistanceResult>> results =
        PairSeparationDistances(pairs_, *tolerance, &cancelled());
    if (absl::Status s = Answered(results.status()); !s.ok()) return s;
    wire::AppendDistanceResults(*results, reply().mutable_results());
    return absl::OkStatus();
  }

  // `s` as an error of pair `i` of this frame. Field names are built only for an error: the
  // frame loops are on every frame's path.
  absl::Status InPair(std::size_t i, const absl::Status& s) const {
    return absl::Status(s.code(),
                        absl::StrCat("frame ", request().frame(), " pairs[", i, "].", s.message()));
  }

  // The two poses of pair `i`, normalised; INVALID_ARGUMENT naming the pair and pose.
  absl::Status ReadPoses(std::size_t i, const v1::DistancePair& pair, RigidPose* a,
                         RigidPose* b) const {
    absl::StatusOr<RigidPose> pose_a = wire::PoseFromProto(pair.pose_a(), "pose_a");
    if (!pose_a.ok()) return InPair(i, pose_a.status());
    absl::StatusOr<RigidPose> pose_b = wire::PoseFromProto(pair.pose_b(), "pose_b");
    if (!pose_b.ok()) return InPair(i, pose_b.status());
    *a = *pose_a;
    *b = *pose_b;
    return absl::OkStatus();
  }

  // The frame's queries ended with `status`: CANCELLED when the client went away meanwhile,
  // else `status` naming the frame.
  absl::Status Answered(const absl::Status& status) const {
    if (cancelled().load()) return absl::CancelledError("client went away mid-frame");
    if (status.ok()) return status;
    return absl::Status(status.code(),
                        absl::StrCat("frame ", request().frame(), " ", status.message()));
  }

  // A frame of certified pairs (every pair names covers): intervals from core's
  // CertifiedDistances over the objects the store certifies (ResultStore::GetCertifiedObject).
  absl::Status ComputeCertifiedFrame(const DistanceRequest& tolerance, HierarchyVolume volume) {
    if (absl::Status s = CheckCertifiedTolerance(tolerance); !s.ok()) return s;
    const std::size_t n = static_cast<std::size_t>(request().pairs_size());
    for (std::size_t i = 0; i < n; ++i) {
      const v1::DistancePair& pair = request().pairs(static_cast<int>(i));
      if (pair.cover_a().empty()) {
        return InPair(i, absl::InvalidArgumentError(
                             "cover_a, cover_b: a frame's pairs are all certified (covers named) "
                             "or none, and pairs[0] names covers"));
      }
      if (absl::Status s = CheckCovers(pair.cover_a(), pair.cover_b()); !s.ok()) {
        return InPair(i, s);
      }
      CertifiedPair& posed = certified_pairs_[i];
      if (posed.a == nullptr) {
        absl::StatusOr<const CertifiedObject*> a =
            Certified(pair.sphere_set_a(), pair.cover_a(), volume, "sphere_set_a");
        if (!a.ok()) return InPair(i, a.status());
        posed.a = *a;
      }
      if (posed.b == nullptr) {
        absl::StatusOr<const CertifiedObject*> b =
            Certified(pair.sphere_set_b(), pair.cover_b(), volume, "sphere_set_b");
        if (!b.ok()) return InPair(i, b.status());
        posed.b = *b;
      }
      if (absl::Status s = ReadPoses(i, pair, &posed.pose_a, &posed.pose_b); !s.ok()) {
        return s;
      }
    }
    absl::StatusOr<std::vector<CertifiedDistanceResult>> results =
        inscribe::CertifiedDistances(certified_pairs_, tolerance.closer_than, &cancelled());
    if (absl::Status s = Answered(results.status()); !s.ok()) return s;
    wire::AppendCertifiedDistanceResults(*results, std::isfinite(tolerance.closer_than),
                                         reply().mutable_results());
    return absl::OkStatus();
  }

  // Whether the frame's pairs name covers (then all must): a certified frame.
  bool certified_frame() const {
    return request().pairs_size() > 0 && !request().pairs(0).cover_a().empty();
  }

  // Distance queries the frame asks (a certified pair is two: internal sets and covers): the
  // unit of the stream's cost model.
  std::int64_t FrameQueries() const {
    return (certified_frame() ? 2 : 1) * static_cast<std::int64_t>(request().pairs_size());
  }

  // The key of a held object in held_ or certified_: "volume/key", or "volume/internal|cover";
  // built in slot_, whose capacity stays, so a lookup allocates nothing.
  const std::string& Slot(HierarchyVolume volume, const std::string& key,
                          const std::string* cover = nullptr) {
    slot_.assign(HierarchyVolumeName(volume));
    slot_ += '/';
    slot_ += key;
    if (cover != nullptr) {
      slot_ += '|';
      slot_ += *cover;
    }
    return slot_;
  }

  // Fills pairs_ (certified_pairs_ for a certified frame) with the objects of the frame that this
  // stream already holds, null for the others; true when it holds them all, so that running
  // the frame looks nothing up in the cache. O(pairs) lookups in the stream's own tables.
  bool FindHeld() {
    const HierarchyVolume volume = wire::VolumeFromProto(request().volume());
    const std::size_t n = static_cast<std::size_t>(request().pairs_size());
    bool all = true;
    if (certified_frame()) {
      certified_pairs_.assign(n, CertifiedPair{});
      for (std::size_t i = 0; i < n; ++i) {
        const v1::DistancePair& pair = request().pairs(static_cast<int>(i));
        certified_pairs_[i].a = HeldCertified(volume, pair.sphere_set_a(), pair.cover_a());
        certified_pairs_[i].b = HeldCertified(volume, pair.sphere_set_b(), pair.cover_b());
        all = all && certified_pairs_[i].a != nullptr && certified_pairs_[i].b != nullptr;
      }
      return all;
    }
    pairs_.assign(n, PosedPair{});
    for (std::size_t i = 0; i < n; ++i) {
      const v1::DistancePair& pair = request().pairs(static_cast<int>(i));
      pairs_[i].a = HeldHierarchy(volume, pair.sphere_set_a());
      pairs_[i].b = HeldHierarchy(volume, pair.sphere_set_b());
      all = all && pairs_[i].a != nullptr && pairs_[i].b != nullptr;
    }
    return all;
  }

  const SphereHierarchy* HeldHierarchy(HierarchyVolume volume, const std::string& key) {
    auto it = held_.find(Slot(volume, key));
    return it != held_.end() ? it->second.get() : nullptr;
  }

  const CertifiedObject* HeldCertified(HierarchyVolume volume, const std::string& internal_key,
                                       const std::string& cover_key) {
    auto it = certified_.find(Slot(volume, internal_key, &cover_key));
    return it != certified_.end() ? &it->second->object : nullptr;
  }

  // The certified object of (internal set, cover) for this stream, from the stream's own table
  // or the store; it counts against kMaxStreamSets like a hierarchy.
  absl::StatusOr<const CertifiedObject*> Certified(const std::string& internal_key,
                                                   const std::string& cover_key,
                                                   HierarchyVolume volume, const char* field) {
    if (const CertifiedObject* held = HeldCertified(volume, internal_key, cover_key)) return held;
    if (absl::Status s = CheckKey(internal_key, field); !s.ok()) return s;
    if (held_.size() + certified_.size() >= kMaxStreamSets) {
      return absl::ResourceExhaustedError(
          absl::StrCat(field, ": a stream may name at most ", kMaxStreamSets,
                       " distinct sphere sets (per hierarchy volume); open another stream"));
    }
    absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> entry =
        parts().store.GetCertifiedObject(internal_key, cover_key, volume);
    if (!entry.ok()) {
      return absl::Status(entry.status().code(),
                          absl::StrCat(field, ": ", entry.status().message()));
    }
    const CertifiedObject* object = &(*entry)->object;
    certified_.emplace(Slot(volume, internal_key, &cover_key), *std::move(entry));
    return object;
  }

  // The hierarchy of `key` for this stream, from the stream's own table or the store.
  absl::StatusOr<const SphereHierarchy*> Hierarchy(const std::string& key, HierarchyVolume volume,
                                                   const char* field) {
    if (const SphereHierarchy* held = HeldHierarchy(volume, key)) return held;
    if (absl::Status s = CheckKey(key, field); !s.ok()) return s;
    if (held_.size() + certified_.size() >= kMaxStreamSets) {
      return absl::ResourceExhaustedError(
          absl::StrCat(field, ": a stream may name at most ", kMaxStreamSets,
                       " distinct sphere sets (per hierarchy volume); open another stream"));
    }
    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> h =
        parts().store.GetHierarchy(key, volume);
    if (!h.ok()) {
      return absl::Status(h.status().code(), absl::StrCat(field, ": ", h.status().message()));
    }
    const SphereHierarchy* raw = h->get();
    held_.emplace(Slot(volume, key), *std::move(h));
    return raw;
  }

  // Touched by one thread at a time: gRPC callbacks and the frame's job never overlap.
  MemoryBudget::Reservation frame_reservation_;  // the current frame's estimate
  // The current frame's queries (FindHeld, then Answer), kept to reuse their capacity.
  std::vector<PosedPair> pairs_;
  std::vector<CertifiedPair> certified_pairs_;
  std::string slot_;  // Slot's buffer
  std::unordered_map<std::string, std::shared_ptr<const SphereHierarchy>> held_;
  // Certified pairs' objects by "volume/internal key|cover key".
  std::unordered_map<std::string, std::shared_ptr<const CertifiedObjectEntry>> certified_;
};

}  // namespace

grpc::ServerBidiReactor<v1::DistanceFrame, v1::DistanceFrameResult>*
InscribeService::DistanceStream(grpc::CallbackServerContext* context) {
  auto* reactor = new DistanceStreamReactor(Parts(), context);
  reactor->Start();
  return reactor;
}

}  // namespace inscribe::server
