// Several inscribed replicas behind one Connection: each call goes to the replica that owns its
// mesh (rendezvous hashing on the mesh hash), so a mesh's generation, hierarchies and distance
// queries all land where they are cached; when that replica is down, the Client's next attempt
// goes to the next replica in the key's rendezvous order (connection.h: retry and failover
// policy), without the caller seeing an error.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/client/connection.h"

namespace inscribe::client {

// One replica: its name (the target it was made for; it is what rendezvous hashing hashes, so
// every client given the same names routes a key the same way) and its connection.
struct Endpoint {
  std::string name;
  std::shared_ptr<Connection> connection;
};

enum class RoutingPolicy {
  // The replica with the highest hash of (route key, endpoint name) first, then the others in
  // descending hash order: adding or removing a replica moves only the keys it owned.
  kRendezvous,
  // Each call to the next replica in turn, ignoring keys (a baseline for benchmarks: it
  // spreads every mesh over every replica).
  kRoundRobin,
};

struct RoutingOptions {
  RoutingPolicy policy = RoutingPolicy::kRendezvous;
  // A replica that answered UNAVAILABLE is tried last for this long, so calls do not keep
  // paying for a replica that is down; after it, calls try it in its turn again.
  std::chrono::milliseconds down_for{2000};
};

// The replica order for `route_key` under rendezvous hashing: indices into `names`, best first.
std::vector<int> RendezvousOrder(absl::string_view route_key,
                                 const std::vector<std::string>& names);

// A Connection routing each call over `endpoints` (at least one; names distinct). Each unary
// call is one RPC, to the first replica of the key's order that is not marked down (those
// marked down go last, the one marked longest ago first); an UNAVAILABLE answer marks the
// replica down for RoutingOptions::down_for and carries kRetryElsewherePayload, so that the
// Client retries on the next replica at once. A DistanceStream is routed by its
// first frame's first pair (set A), and reopened on the next replica, resending the frame, when
// it breaks. Calls naming two sets (Distance, DistanceStream) need the others on the same
// replica: sets of one mesh are, other meshes' only with a shared cache tier (inscribed
// --redis). PutMesh and PutSphereSet also put on the replica of the key the server answers with
// when it routes elsewhere (a repaired mesh, a set without a mesh). CacheStats answers from the
// first endpoint listed (the next when it is down). INVALID_ARGUMENT for no endpoints, a null
// connection or duplicate names.
absl::StatusOr<std::shared_ptr<Connection>> MakeRoutedConnection(
    std::vector<Endpoint> endpoints, const RoutingOptions& options = {});

}  // namespace inscribe::client
