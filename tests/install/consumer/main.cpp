// Uses the installed inscribe as an outside project would: the core pipeline on a box, and the
// client library against an address where nothing listens. Prints one line; exit 0 when both
// behave.
#include <chrono>
#include <cstdio>

#include "inscribe/client/client.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/solid/solid.h"

int main() {
  inscribe::Mesh box;
  box.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    box.vertices.row(i) << (i & 1) * 2.0, ((i >> 1) & 1) * 1.0, ((i >> 2) & 1) * 0.5;
  }
  box.triangles.resize(12, 3);
  box.triangles << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2,
      2, 4, 6, 1, 3, 5, 3, 7, 5;
  absl::StatusOr<inscribe::Solid> solid = inscribe::PrepareSolid(box);
  if (!solid.ok()) {
    std::printf("PrepareSolid: %s\n", std::string(solid.status().message()).c_str());
    return 1;
  }
  inscribe::SphereSetParameters parameters;
  parameters.max_spheres = 20;
  absl::StatusOr<inscribe::GeneratedSphereSet> set =
      inscribe::GenerateSphereSet(*solid, parameters);
  if (!set.ok() || set->set.size() == 0 || set->set.size() > 20 || !set->quality) {
    std::printf("GenerateSphereSet failed\n");
    return 1;
  }
  inscribe::client::ClientOptions options;
  options.default_timeout = std::chrono::milliseconds(300);
  options.retry.max_attempts = 1;
  const inscribe::client::Client client(inscribe::client::MakeGrpcConnection("127.0.0.1:1"),
                                        options);
  const absl::StatusOr<inscribe::client::ServerCacheStats> stats = client.CacheStats();
  const bool unreachable = stats.status().code() == absl::StatusCode::kUnavailable ||
                           stats.status().code() == absl::StatusCode::kDeadlineExceeded;
  std::printf("consumer: %s, %zu spheres, nerr %.4f; client: %s\n", solid->sha256.c_str(),
              set->set.size(), set->quality->nerr, stats.status().ToString().c_str());
  return unreachable ? 0 : 1;
}
