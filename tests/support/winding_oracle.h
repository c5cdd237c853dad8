// The winding number of a closed triangle mesh at a point, and the distance from a point to the
// mesh, by brute force in long double: the truth that inside tests, sphere sets and covers are
// checked against. Shares no code with core (not the BoundaryOracle, not core/src): its own
// solid angles, its own point-triangle distance. A solid's inside is where the winding number
// of its validated mesh (Solid::mesh()) is nonzero.
#pragma once

#include <array>
#include <vector>

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

// Relative distance (times the mesh's largest coordinate magnitude) below which a point counts
// as too close to a triangle for the long-double sum to be trusted: there each solid angle errs
// by up to about 1e-19 times (triangle size / distance), far below 1e-6 above it.
inline constexpr double kWindingNearRelative = 1e-11;
// Largest distance of the solid-angle sum / 4 pi from the nearest integer that is trusted.
inline constexpr double kWindingIntegerSlack = 1e-6;

struct WindingSample {
  // The nearest integer to the sum over triangles of the signed solid angles / 4 pi
  // (Van Oosterom & Strackee), counter-clockwise seen from outside = positive inside.
  int winding = 0;
  // False when the point lies within near_distance() of a triangle or the sum is not within
  // kWindingIntegerSlack of an integer: callers skip such points.
  bool reliable = false;
  // The sum / 4 pi itself.
  double raw = 0.0;

  bool inside() const { return winding != 0; }
};

// Built once per mesh. The mesh must be closed and consistently oriented (every edge in two
// triangles of opposite direction), as a validated mesh or a hand-oriented construction is:
// then each vertex-connected shell is a closed surface whose winding number is exactly 0 on
// the unbounded side of its bounding box, so a shell whose box lies farther than
// near_distance() from the point adds 0 and cannot be the nearest triangle's; those shells are
// skipped (exactly, not approximately). Every other triangle is summed. Immutable; const
// methods may be called concurrently.
class WindingOracle {
 public:
  explicit WindingOracle(const Mesh& mesh);

  WindingSample At(const Vector3& p) const;
  // At() for each row of #P by 3 `points`, parallel (TBB); #P entries.
  std::vector<WindingSample> AtAll(const Vertices& points) const;

  // Distance from p to the nearest triangle (mesh units), every triangle considered (shells
  // whose boxes are farther than the best distance found so far are passed over exactly).
  // Computed in long double, so within a few ulps of the exact value.
  double Distance(const Vector3& p) const;
  std::vector<double> Distances(const Vertices& points) const;  // parallel (TBB)

  double near_distance() const { return near_distance_; }
  int shells() const { return static_cast<int>(shells_.size()); }

 private:
  using Point = std::array<long double, 3>;
  using Corners = std::array<Point, 3>;
  struct Triangle {
    Corners corners;
    long double diameter;  // longest side: every point of it is this close to each corner
  };
  struct Shell {
    Point lo, hi;  // bounding box of its vertices
    std::vector<Triangle> triangles;
  };
  static long double BoxDistanceSquared(const Shell& shell, const Point& p);

  std::vector<Shell> shells_;
  double near_distance_ = 0.0;
};

// The squared distance from p to the triangle (a, b, c), zero-area triangles included (then the
// nearest of its three sides), in long double. Exposed for the tests of the oracle itself.
long double PointTriangleDistanceSquared(const std::array<long double, 3>& p,
                                         const std::array<long double, 3>& a,
                                         const std::array<long double, 3>& b,
                                         const std::array<long double, 3>& c);

}  // namespace inscribe::testing
