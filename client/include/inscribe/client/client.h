// Typed C++ API of the inscribe service: core types in, core types out.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/client/connection.h"
#include "inscribe/mesh.h"
#include "inscribe/mesh_validation.h"

namespace inscribe::client {

// Retries of idempotent calls. Only UNAVAILABLE (server unreachable, restarting or shedding
// connections) is retried: every other error would come back the same.
struct RetryPolicy {
  // Attempts in total, the first included; 1 disables retries.
  int max_attempts = 3;
  // Wait before the second attempt; each further wait is `multiplier` times longer, capped at
  // max_backoff. Every wait is drawn uniformly from [50%, 100%] of that value (jitter), so that
  // clients that failed together do not retry together.
  std::chrono::milliseconds initial_backoff{100};
  std::chrono::milliseconds max_backoff{2000};
  double multiplier = 2.0;
};

struct ClientOptions {
  // Time allowed for a call when the call does not say, covering all of its attempts and the
  // waits between them.
  std::chrono::milliseconds default_timeout{30'000};
  RetryPolicy retry;
};

struct InspectMeshOptions {
  // Skip the exact self-intersection test (O(#T log #T) on the server).
  bool skip_self_intersections = false;
  // Overrides ClientOptions::default_timeout for this call.
  std::optional<std::chrono::milliseconds> timeout;
};

struct InspectMeshResult {
  // "sha256:<64 hex digits>" of the mesh after the server's orientation fixes (equal to
  // FormatSha256(MeshSha256(ValidateMesh(mesh).mesh))); empty when the mesh has non-finite
  // coordinates or out-of-range indices.
  std::string mesh_sha256;
  // The server's validation report, as ValidateMesh would return it locally.
  MeshReport report;
};

// Calls the service through a Connection, adding a deadline to every call and retrying
// idempotent calls on UNAVAILABLE with exponential backoff. Thread-safe; cheap to copy (shares
// the connection).
class Client {
 public:
  explicit Client(std::shared_ptr<Connection> connection, ClientOptions options = {});

  // Validates `mesh` on the server (no state is kept there: idempotent, so retried). Errors:
  // INVALID_ARGUMENT / RESOURCE_EXHAUSTED from the server (message says which limit),
  // UNAVAILABLE after the last attempt, DEADLINE_EXCEEDED. An unusable mesh is not an error:
  // see result.report.usable().
  absl::StatusOr<InspectMeshResult> InspectMesh(const Mesh& mesh,
                                                const InspectMeshOptions& options = {}) const;

  const ClientOptions& options() const { return options_; }

 private:
  std::shared_ptr<Connection> connection_;
  ClientOptions options_;
};

}  // namespace inscribe::client
