#include "support/sphere_sets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <mutex>

#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/boundary_oracle.h"
#include "support/test_meshes.h"

namespace inscribe::testing {

std::vector<Sphere> RandomSpheres(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  // A curved sheet z = f(x, y) with some scatter off it.
  const double a = unit(rng), b = unit(rng);
  std::vector<Sphere> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double x = unit(rng), y = unit(rng);
    const double z = 0.5 + 0.2 * std::sin(3.0 * a * x + 2.0 * b * y) + 0.03 * normal(rng);
    out.push_back({Vector3(x, y, z), 0.02 + 0.1 * unit(rng)});
  }
  return out;
}

std::vector<Sphere> RandomBalls(int n, double side, double rmin, double rmax, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coord(0.0, side);
  std::uniform_real_distribution<double> radius(rmin, rmax);
  std::vector<Sphere> balls;
  for (int i = 0; i < n; ++i) {
    const Vector3 c(coord(rng), coord(rng), coord(rng));
    balls.push_back({c, radius(rng)});
  }
  return balls;
}

RigidPose RandomPose(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  Vector3 direction(normal(rng), normal(rng), normal(rng));
  direction.normalize();
  return RigidPose{q, direction * spread * std::cbrt(unit(rng))};
}

const std::vector<Sphere>& RealSphereSet(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::vector<Sphere>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  const Mesh mesh = LoadTestMesh(name);
  std::vector<Sphere> spheres;
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  if (oracle.ok()) {
    MedialSphereOptions options;
    options.voxel_size = ComputeBoundingBox(mesh.vertices).diagonal() / 30.0;
    absl::StatusOr<MedialSphereResult> result = GenerateMedialSpheres(*oracle, options);
    EXPECT_TRUE(result.ok()) << result.status();
    if (result.ok()) spheres = result->set.spheres;
  }
  return cache.emplace(name, std::move(spheres)).first->second;
}

}  // namespace inscribe::testing
