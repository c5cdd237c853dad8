#include "support/medial_checks.h"

#include <gtest/gtest.h>

#include "support/brute_force_closest_point.h"

namespace inscribe::testing {

void ExpectInternalAndTangent(const BoundaryOracle& oracle, const SphereSet& set) {
  const Mesh& mesh = oracle.mesh();
  const double diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  ASSERT_EQ(set.contacts.size(), set.spheres.size());
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Sphere& s = set.spheres[i];
    const SurfaceContact& c = set.contacts[i];
    ASSERT_GT(s.radius, 0.0) << "sphere " << i;
    EXPECT_EQ(oracle.Classify(s.center), Side::kInside) << "sphere " << i;
    const double exact = BruteForceDistance(mesh, s.center);
    // Protrusion r - d(c), checked against the slow scan and against the oracle.
    EXPECT_LE(s.radius - exact, 1e-9 * diagonal) << "sphere " << i << " sticks out";
    EXPECT_LE(s.radius + oracle.SignedDistance(s.center), 1e-9 * diagonal) << "sphere " << i;
    EXPECT_NEAR(s.radius, exact, 1e-12 * diagonal) << "sphere " << i << " is not tangent";
    ASSERT_GE(c.triangle, 0);
    ASSERT_LT(c.triangle, mesh.num_triangles());
    EXPECT_NEAR(c.barycentric.sum(), 1.0, 1e-12);
    EXPECT_GE(c.barycentric.minCoeff(), -1e-12);
    const Vector3 contact = c.barycentric[0] * mesh.vertices.row(mesh.triangles(c.triangle, 0)) +
                            c.barycentric[1] * mesh.vertices.row(mesh.triangles(c.triangle, 1)) +
                            c.barycentric[2] * mesh.vertices.row(mesh.triangles(c.triangle, 2));
    EXPECT_NEAR((contact.transpose() - s.center.transpose()).norm(), s.radius, 1e-9 * diagonal)
        << "sphere " << i << ": contact not at distance r";
  }
}

}  // namespace inscribe::testing
