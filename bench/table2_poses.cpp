#include "table2_poses.h"

#include <random>

namespace inscribe::bench {
namespace {

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  // A normalised 4D Gaussian is uniform on the unit quaternions, hence on SO(3).
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q;
  do {
    q = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
  } while (q.norm() < 1e-6);
  return q.normalized();
}

}  // namespace

std::vector<PosePair> RandomPosePairs(int count, const PoseSetSpec& spec, double diagonal,
                                      std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> fraction(spec.lo, spec.hi);
  std::vector<PosePair> pairs;
  pairs.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    PosePair p;
    p.a.rotation = RandomRotation(rng);
    p.b.rotation = RandomRotation(rng);
    Vector3 direction;
    do {
      direction = Vector3(normal(rng), normal(rng), normal(rng));
    } while (direction.norm() < 1e-6);
    p.b.translation = direction.normalized() * (fraction(rng) * diagonal);
    pairs.push_back(p);
  }
  return pairs;
}

}  // namespace inscribe::bench
