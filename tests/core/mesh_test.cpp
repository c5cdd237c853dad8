#include "inscribe/geometry/mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

using testing::Box;
using testing::Icosphere;

TEST(SignedVolume, UnitCubeIsOne) { EXPECT_NEAR(SignedVolume(testing::UnitCube()), 1.0, 1e-15); }

TEST(SignedVolume, InvertedIsNegative) {
  EXPECT_NEAR(SignedVolume(testing::Inverted(testing::UnitCube())), -1.0, 1e-15);
}

TEST(SignedVolume, FarFromOriginKeepsPrecision) {
  const Vector3 lo(1e6, -2e6, 3e6);
  const Mesh box = Box(lo, lo + Vector3(0.5, 2.0, 3.0));
  EXPECT_NEAR(SignedVolume(box), 3.0, 1e-9);
}

TEST(SignedVolume, IcosphereConvergesToBall) {
  // An inscribed polyhedron has less volume than the ball, and the gap closes with subdivision.
  const double ball = 4.0 / 3.0 * M_PI * 8.0;
  double previous_gap = ball;
  for (int level = 0; level <= 4; ++level) {
    const double gap = ball - SignedVolume(Icosphere(level, Vector3(1, 2, 3), 2.0));
    EXPECT_GT(gap, 0.0);
    EXPECT_LT(gap, previous_gap);
    previous_gap = gap;
  }
  EXPECT_LT(previous_gap / ball, 0.005);
}

TEST(BoundingBox, OfBox) {
  const BoundingBox box = ComputeBoundingBox(Box(Vector3(-1, 2, -3), Vector3(4, 5, 6)).vertices);
  EXPECT_EQ(box.min, Vector3(-1, 2, -3));
  EXPECT_EQ(box.max, Vector3(4, 5, 6));
  EXPECT_NEAR(box.diagonal(), std::sqrt(25.0 + 9.0 + 81.0), 1e-12);
}

TEST(BoundingBox, EmptyIsZero) {
  const BoundingBox box = ComputeBoundingBox(Vertices(0, 3));
  EXPECT_EQ(box.min, Vector3::Zero());
  EXPECT_EQ(box.diagonal(), 0.0);
}

}  // namespace
}  // namespace inscribe
