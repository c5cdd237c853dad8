// A Connection over several replicas: rendezvous hashing on each call's route key, failover on
// UNAVAILABLE (see routing.h).
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/cord.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "inscribe/base/sha256.h"
#include "inscribe/client/routing.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/convert.h"
#include "inscribe/wire/keys.h"

namespace inscribe::client {
namespace {

// The route key of a mesh as sent: the hash the server stores it under unless it fixes the
// orientation, welds vertices or fills holes (PutMesh then puts it twice, see
// RoutedConnection::PutMesh).
// O(#V + #T): a copy and one SHA-256 pass, small beside sending the mesh. A malformed mesh
// routes anywhere: every replica answers INVALID_ARGUMENT.
std::string MeshRouteKey(const v1::Mesh& mesh) {
  absl::StatusOr<Mesh> core = wire::MeshFromProto(mesh);
  if (!core.ok()) return "";
  return wire::RouteKey(FormatSha256(MeshSha256(*core)));
}

// The replicas and what is known of their health; shared by the connection and its streams.
class Replicas {
 public:
  Replicas(std::vector<Endpoint> endpoints, const RoutingOptions& options)
      : endpoints_(std::move(endpoints)), options_(options), down_until_(endpoints_.size()) {
    for (const Endpoint& e : endpoints_) names_.push_back(e.name);
  }

  int size() const { return static_cast<int>(endpoints_.size()); }
  const std::string& name(int i) const { return names_[i]; }
  Connection& connection(int i) const { return *endpoints_[i].connection; }
  RoutingPolicy policy() const { return options_.policy; }

  // The replicas to try for `route_key`, best first: by policy, with those marked down moved
  // last (keeping their order). Round robin rotates over the replicas that are up, so that one
  // being down does not double the load of its successor. One SHA-256 per replica (rendezvous)
  // and a mutex round trip.
  std::vector<int> Order(absl::string_view route_key) {
    if (options_.policy == RoutingPolicy::kRendezvous) {
      std::vector<int> order = RendezvousOrder(route_key, names_);
      LiveFirst(order);
      return order;
    }
    std::vector<int> order = ListedIndices();
    const int live = LiveFirst(order);
    const int span = live > 0 ? live : size();
    std::rotate(order.begin(), order.begin() + static_cast<int>(next_.fetch_add(1) % span),
                order.begin() + span);
    return order;
  }

  // The given endpoint order (CacheStats), marked-down replicas last.
  std::vector<int> ListedOrder() {
    std::vector<int> order = ListedIndices();
    LiveFirst(order);
    return order;
  }

  void MarkDown(int i) {
    std::lock_guard<std::mutex> lock(mutex_);
    down_until_[i] = std::chrono::steady_clock::now() + options_.down_for;
  }

  // An answer (any but UNAVAILABLE) proves the replica up again.
  void MarkUp(int i) {
    std::lock_guard<std::mutex> lock(mutex_);
    down_until_[i] = {};
  }

 private:
  std::vector<int> ListedIndices() const {
    std::vector<int> order(endpoints_.size());
    for (int i = 0; i < size(); ++i) order[i] = i;
    return order;
  }

  // Moves the replicas marked down to the end of `order`, the one marked down longest ago
  // first (so that attempts on a fleet that is all down go round it); returns how many are up.
  int LiveFirst(std::vector<int>& order) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    const auto live_end = std::stable_partition(order.begin(), order.end(),
                                                [&](int i) { return down_until_[i] <= now; });
    std::stable_sort(live_end, order.end(),
                     [&](int a, int b) { return down_until_[a] < down_until_[b]; });
    return static_cast<int>(live_end - order.begin());
  }

  const std::vector<Endpoint> endpoints_;
  std::vector<std::string> names_;
  const RoutingOptions options_;
  std::atomic<std::uint64_t> next_{0};  // round-robin position
  std::mutex mutex_;
  std::vector<std::chrono::steady_clock::time_point> down_until_;  // guarded by mutex_
};

// A response and the replica that gave it (-1 when none did).
template <typename Response>
struct Answer {
  absl::StatusOr<Response> response;
  int replica = -1;
};

// One attempt of a unary call (see connection.h): `call` on the first replica of `order`. An
// UNAVAILABLE answer marks that replica down and, when there is another replica, carries
// kRetryElsewherePayload: the Client's next attempt goes to the next replica at once.
template <typename Response>
Answer<Response> CallFirst(Replicas& replicas, const std::vector<int>& order,
                           const std::function<absl::StatusOr<Response>(Connection&)>& call) {
  const int i = order.front();
  Answer<Response> answer{call(replicas.connection(i)), i};
  if (answer.response.status().code() != absl::StatusCode::kUnavailable) {
    replicas.MarkUp(i);
    return answer;
  }
  replicas.MarkDown(i);
  absl::Status down(absl::StatusCode::kUnavailable,
                    absl::StrCat(answer.response.status().message(), " (replica ", replicas.name(i),
                                 ", one of ", replicas.size(), ")"));
  if (replicas.size() > 1) down.SetPayload(kRetryElsewherePayload, absl::Cord());
  return Answer<Response>{std::move(down), -1};
}

// For a DistanceStream, which the Client does not retry: runs `call` on the replicas of
// `order` until one answers with anything but UNAVAILABLE, the
// deadline passes (checked before each further replica; the first is always tried), or every
// replica was tried; then returns the last replica's error, naming the replicas tried.
template <typename Response>
Answer<Response> CallInOrder(Replicas& replicas, const std::vector<int>& order, Deadline deadline,
                             const std::function<absl::StatusOr<Response>(Connection&)>& call) {
  Answer<Response> answer{absl::UnavailableError("no replica to call"), -1};
  std::vector<std::string> tried;
  for (int i : order) {
    if (!tried.empty() && std::chrono::system_clock::now() >= deadline) break;
    answer.response = call(replicas.connection(i));
    if (answer.response.status().code() != absl::StatusCode::kUnavailable) {
      replicas.MarkUp(i);
      answer.replica = i;
      return answer;
    }
    replicas.MarkDown(i);
    tried.push_back(replicas.name(i));
  }
  const absl::Status& last = answer.response.status();
  answer.response = absl::Status(
      last.code(), absl::StrCat(last.message(), " (replicas tried: ", absl::StrJoin(tried, ", "),
                                " of ", replicas.size(), ")"));
  return answer;
}

// A DistanceStream or SceneStream over the replicas: opened with its first message on the
// first replica of the message's route key that answers it (CallInOrder).
template <typename Message, typename Reply>
class RoutedFrameStream final : public FrameStream<Message, Reply> {
 public:
  using Stream = FrameStream<Message, Reply>;
  // One replica's stream.
  using Opener =
      std::function<absl::StatusOr<std::unique_ptr<Stream>>(Connection&, Deadline stream_deadline)>;
  // The route key of the first message.
  using RouteKeyOf = std::function<std::string(const Message&)>;

  // `reopen`: when the stream breaks (UNAVAILABLE) after its first message, reopen it on the
  // next replica and send the message again (a DistanceStream frame is a pure query); else the
  // stream ends with that error (a scene lived on the replica that went away).
  RoutedFrameStream(std::shared_ptr<Replicas> replicas, Deadline stream_deadline, Opener open,
                    RouteKeyOf route_key_of, bool reopen)
      : replicas_(std::move(replicas)),
        stream_deadline_(stream_deadline),
        open_(std::move(open)),
        route_key_of_(std::move(route_key_of)),
        reopen_(reopen) {}

  // The server echoes frame numbers and does not require a new stream to start at 0, so a
  // reopened DistanceStream resends the same frame with its own number.
  absl::StatusOr<Reply> RoundTrip(const Message& frame, Deadline deadline) override {
    if (finished_) return ended_;
    if (current_ != nullptr) {
      absl::StatusOr<Reply> result = current_->RoundTrip(frame, deadline);
      if (result.ok()) return result;
      if (result.status().code() != absl::StatusCode::kUnavailable || !reopen_) {
        if (result.status().code() == absl::StatusCode::kUnavailable) {
          replicas_->MarkDown(current_replica_);
        }
        return End(result.status());
      }
      replicas_->MarkDown(current_replica_);
      current_.reset();
    }
    if (!route_key_.has_value()) route_key_ = route_key_of_(frame);
    std::unique_ptr<Stream> opened;
    const Answer<Reply> answer = CallInOrder<Reply>(
        *replicas_, replicas_->Order(*route_key_), deadline,
        [&](Connection& connection) -> absl::StatusOr<Reply> {
          absl::StatusOr<std::unique_ptr<Stream>> stream = open_(connection, stream_deadline_);
          if (!stream.ok()) return stream.status();
          opened = *std::move(stream);
          return opened->RoundTrip(frame, deadline);
        });
    if (!answer.response.ok()) return End(answer.response.status());
    current_ = std::move(opened);
    current_replica_ = answer.replica;
    return answer.response;
  }

  absl::Status Finish() override {
    if (finished_) return ended_;
    finished_ = true;
    if (current_ == nullptr) return absl::OkStatus();  // no frame was sent: nothing to end
    const absl::Status status = current_->Finish();
    current_.reset();
    if (!status.ok()) ended_ = status;
    return status;
  }

 private:
  absl::Status End(absl::Status status) {
    finished_ = true;
    ended_ = status;
    current_.reset();
    return status;
  }

  const std::shared_ptr<Replicas> replicas_;
  const Deadline stream_deadline_;
  const Opener open_;
  const RouteKeyOf route_key_of_;
  const bool reopen_;
  std::optional<std::string> route_key_;  // set by the first frame
  std::unique_ptr<Stream> current_;
  int current_replica_ = -1;
  bool finished_ = false;
  absl::Status ended_ = absl::FailedPreconditionError("stream already finished");
};

class RoutedConnection final : public Connection {
 public:
  explicit RoutedConnection(std::shared_ptr<Replicas> replicas) : replicas_(std::move(replicas)) {}

  absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                      Deadline deadline) override {
    return Call<v1::InspectMeshResponse>(
        MeshRouteKey(request.mesh()), deadline,
        [&](Connection& c) { return c.InspectMesh(request, deadline); });
  }

  // Routed by the hash of the mesh as sent; when the server stored it under another key
  // (vertices welded, orientation fixed, holes filled), it is put on that key's replica too, so
  // that the calls naming the key find it. The answer is then that replica's.
  absl::StatusOr<v1::PutMeshResponse> PutMesh(const v1::PutMeshRequest& request,
                                              Deadline deadline) override {
    return PutTwiceIfKeyMoved<v1::PutMeshResponse>(
        MeshRouteKey(request.mesh()), deadline,
        [&](Connection& c) { return c.PutMesh(request, deadline); },
        [](const v1::PutMeshResponse& r) { return r.mesh_sha256(); });
  }

  absl::StatusOr<v1::GenerateResult> Generate(
      const v1::GenerateRequest& request, Deadline deadline,
      const std::function<void(double fraction)>& on_progress) override {
    // After a failover the progress starts again from the next replica's.
    return Call<v1::GenerateResult>(
        wire::RouteKey(request.mesh_sha256()), deadline,
        [&](Connection& c) { return c.Generate(request, deadline, on_progress); });
  }

  // Routed by the mesh key, else by a hash of the numbers; a set without a mesh is then put on
  // its key's replica too (as PutMesh does), a second upload for (n-1)/n of such sets.
  absl::StatusOr<v1::PutSphereSetResponse> PutSphereSet(const v1::PutSphereSetRequest& request,
                                                        Deadline deadline) override {
    const std::string route = request.mesh_sha256().empty()
                                  ? wire::ContentRouteKey(request.spheres().SerializeAsString())
                                  : wire::RouteKey(request.mesh_sha256());
    return PutTwiceIfKeyMoved<v1::PutSphereSetResponse>(
        route, deadline, [&](Connection& c) { return c.PutSphereSet(request, deadline); },
        [](const v1::PutSphereSetResponse& r) { return r.sphere_set_key(); });
  }

  absl::StatusOr<v1::GetSphereSetResponse> GetSphereSet(const v1::GetSphereSetRequest& request,
                                                        Deadline deadline) override {
    return Call<v1::GetSphereSetResponse>(
        wire::RouteKey(request.sphere_set_key()), deadline,
        [&](Connection& c) { return c.GetSphereSet(request, deadline); });
  }

  absl::StatusOr<v1::GetHierarchyResponse> GetHierarchy(const v1::GetHierarchyRequest& request,
                                                        Deadline deadline) override {
    return Call<v1::GetHierarchyResponse>(
        wire::RouteKey(request.sphere_set_key()), deadline,
        [&](Connection& c) { return c.GetHierarchy(request, deadline); });
  }

  absl::StatusOr<v1::UpdateDeformationResponse> UpdateDeformation(
      const v1::UpdateDeformationRequest& request, Deadline deadline) override {
    return Call<v1::UpdateDeformationResponse>(
        wire::RouteKey(request.sphere_set_key()), deadline,
        [&](Connection& c) { return c.UpdateDeformation(request, deadline); });
  }

  // Routed by set A: set B must be held by the same replica (a set of the same mesh, or the
  // replicas share a Redis tier).
  absl::StatusOr<v1::DistanceResponse> Distance(const v1::DistanceRequest& request,
                                                Deadline deadline) override {
    return Call<v1::DistanceResponse>(wire::RouteKey(request.sphere_set_a()), deadline,
                                      [&](Connection& c) { return c.Distance(request, deadline); });
  }

  absl::StatusOr<v1::EvaluateResponse> Evaluate(const v1::EvaluateRequest& request,
                                                Deadline deadline) override {
    const std::string& key = request.spheres_case() == v1::EvaluateRequest::kSphereSetKey
                                 ? request.sphere_set_key()
                                 : request.mesh_sha256();
    return Call<v1::EvaluateResponse>(wire::RouteKey(key), deadline,
                                      [&](Connection& c) { return c.Evaluate(request, deadline); });
  }

  absl::StatusOr<v1::CertifyCoverResponse> CertifyCover(const v1::CertifyCoverRequest& request,
                                                        Deadline deadline) override {
    const std::string& key = request.spheres_case() == v1::CertifyCoverRequest::kSphereSetKey
                                 ? request.sphere_set_key()
                                 : request.mesh_sha256();
    return Call<v1::CertifyCoverResponse>(wire::RouteKey(key), deadline, [&](Connection& c) {
      return c.CertifyCover(request, deadline);
    });
  }

  // One replica's counters: the first endpoint listed, or the next listed when it is down.
  absl::StatusOr<v1::CacheStatsResponse> CacheStats(const v1::CacheStatsRequest& request,
                                                    Deadline deadline) override {
    return CallFirst<v1::CacheStatsResponse>(
               *replicas_, replicas_->ListedOrder(),
               [&](Connection& c) { return c.CacheStats(request, deadline); })
        .response;
  }

  // Opens nothing yet: the first frame says where the stream goes.
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> OpenDistanceStream(
      Deadline deadline) override {
    // Every pair of a frame must be held by one replica: the first pair's set A routes it.
    return std::make_unique<RoutedFrameStream<v1::DistanceFrame, v1::DistanceFrameResult>>(
        replicas_, deadline, [](Connection& c, Deadline d) { return c.OpenDistanceStream(d); },
        [](const v1::DistanceFrame& frame) {
          return frame.pairs_size() > 0 ? wire::RouteKey(frame.pairs(0).sphere_set_a()) : "";
        },
        /*reopen=*/true);
  }

  // Every object's sets must be held by one replica (or reachable through the shared tier):
  // the first object's set routes the scene.
  absl::StatusOr<std::unique_ptr<SceneStreamConnection>> OpenSceneStream(
      Deadline deadline) override {
    return std::make_unique<RoutedFrameStream<v1::SceneMessage, v1::SceneReply>>(
        replicas_, deadline, [](Connection& c, Deadline d) { return c.OpenSceneStream(d); },
        [](const v1::SceneMessage& message) {
          return message.add_size() > 0 ? wire::RouteKey(message.add(0).sphere_set()) : "";
        },
        /*reopen=*/false);
  }

 private:
  template <typename Response>
  absl::StatusOr<Response> Call(absl::string_view route_key, Deadline deadline,
                                const std::function<absl::StatusOr<Response>(Connection&)>& call) {
    static_cast<void>(deadline);  // the call itself carries it
    return CallFirst<Response>(*replicas_, replicas_->Order(route_key), call).response;
  }

  // Puts on the replicas of `route_key`; when the key the answer names (`stored_key`) routes to
  // another replica, puts there too and returns that answer (rendezvous only: round robin
  // ignores keys).
  template <typename Response>
  absl::StatusOr<Response> PutTwiceIfKeyMoved(
      const std::string& route_key, Deadline deadline,
      const std::function<absl::StatusOr<Response>(Connection&)>& put,
      const std::function<std::string(const Response&)>& stored_key) {
    static_cast<void>(deadline);  // `put` carries it
    Answer<Response> first = CallFirst<Response>(*replicas_, replicas_->Order(route_key), put);
    if (!first.response.ok() || replicas_->policy() != RoutingPolicy::kRendezvous) {
      return std::move(first.response);
    }
    const std::string stored_route = wire::RouteKey(stored_key(*first.response));
    if (stored_route == route_key) return std::move(first.response);
    const std::vector<int> order = replicas_->Order(stored_route);
    if (order.front() == first.replica) return std::move(first.response);
    return CallFirst<Response>(*replicas_, order, put).response;
  }

  const std::shared_ptr<Replicas> replicas_;
};

}  // namespace

std::vector<int> RendezvousOrder(absl::string_view route_key,
                                 const std::vector<std::string>& names) {
  return wire::RendezvousOrder(route_key, names);
}

absl::StatusOr<std::shared_ptr<Connection>> MakeRoutedConnection(std::vector<Endpoint> endpoints,
                                                                 const RoutingOptions& options) {
  if (endpoints.empty()) return absl::InvalidArgumentError("routing needs at least one endpoint");
  std::set<std::string> names;
  for (const Endpoint& e : endpoints) {
    if (e.connection == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat("endpoint ", e.name, " has no connection"));
    }
    if (!names.insert(e.name).second) {
      return absl::InvalidArgumentError(absl::StrCat("endpoint ", e.name, " is listed twice"));
    }
  }
  return std::make_shared<RoutedConnection>(
      std::make_shared<Replicas>(std::move(endpoints), options));
}

}  // namespace inscribe::client
