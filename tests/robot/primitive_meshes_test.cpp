// The curved primitives' triangulations (primitive_meshes.h) against the true shapes, computed
// here from their definitions: an enclosing mesh holds every point of the shape's surface (by
// the mesh's own face planes, worked out in the test) and lies within its stated excess of the
// shape; an inside mesh lies inside the shape and holds the shape shrunk by its excess. Then
// `inscribe urdf`'s covers of cylinders, capsules and ellipsoids hold the true shapes (points
// sampled in them, brute force over the spheres), their cores and internal sets lie inside.
#include "inscribe/robot/primitive_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::robot {
namespace {

// A shape in its own frame: a point of its surface from two uniform numbers in [0, 1) and a
// third picking the part, and the signed amount by which a point lies outside it (exact for
// cylinders and capsules; for ellipsoids the radial test sum (x / a)^2 - 1 scaled, whose sign
// is exact and whose value bounds nothing).
struct Shape {
  std::string name;
  std::function<Vector3(double, double, double)> surface;
  std::function<double(const Vector3&)> outside;  // > 0 outside, <= 0 inside
  Mesh inside, enclosing;
  double inside_excess = 0.0, enclosing_excess = 0.0;
};

Shape Cylinder(double r, double length, int sides) {
  const double h = length / 2;
  Shape shape;
  shape.name = "cylinder " + std::to_string(sides);
  shape.surface = [=](double u, double v, double w) {
    const double angle = 2 * M_PI * u;
    if (w < 0.5) return Vector3(r * std::cos(angle), r * std::sin(angle), -h + length * v);
    const double rho = r * std::sqrt(v);  // a cap, uniform by area
    return Vector3(rho * std::cos(angle), rho * std::sin(angle), w < 0.75 ? -h : h);
  };
  shape.outside = [=](const Vector3& p) {
    return std::max(p.head<2>().norm() - r, std::abs(p.z()) - h);
  };
  shape.inside = CylinderMesh(r, length, sides, PrimitiveFit::kInside);
  shape.enclosing = CylinderMesh(r, length, sides, PrimitiveFit::kEnclosing);
  shape.inside_excess = CylinderExcess(r, PrimitiveFit::kInside, sides);
  shape.enclosing_excess = CylinderExcess(r, PrimitiveFit::kEnclosing, sides);
  return shape;
}

Vector3 UnitDirection(double u, double v) {
  const double z = 2 * v - 1, rho = std::sqrt(std::max(0.0, 1 - z * z)), angle = 2 * M_PI * u;
  return Vector3(rho * std::cos(angle), rho * std::sin(angle), z);
}

Shape Capsule(double r, double length, int sides, int bands) {
  const double h = length / 2;
  Shape shape;
  shape.name = "capsule " + std::to_string(sides) + "x" + std::to_string(bands);
  shape.surface = [=](double u, double v, double w) {
    if (w < 0.5 && length > 0) {
      const double angle = 2 * M_PI * u;
      return Vector3(r * std::cos(angle), r * std::sin(angle), -h + length * v);
    }
    const Vector3 d = UnitDirection(u, v);
    return Vector3(r * d + Vector3(0, 0, d.z() >= 0 ? h : -h));
  };
  shape.outside = [=](const Vector3& p) {
    const Vector3 axis(0, 0, std::clamp(p.z(), -h, h));
    return (p - axis).norm() - r;
  };
  shape.inside = CapsuleMesh(r, length, sides, bands, PrimitiveFit::kInside);
  shape.enclosing = CapsuleMesh(r, length, sides, bands, PrimitiveFit::kEnclosing);
  shape.inside_excess = CapsuleExcess(r, PrimitiveFit::kInside, sides, bands);
  shape.enclosing_excess = CapsuleExcess(r, PrimitiveFit::kEnclosing, sides, bands);
  return shape;
}

Shape Ellipsoid(const Vector3& a, int sides, int bands) {
  Shape shape;
  shape.name = "ellipsoid " + std::to_string(sides) + "x" + std::to_string(bands);
  shape.surface = [=](double u, double v, double) {
    return Vector3(UnitDirection(u, v).cwiseProduct(a));
  };
  shape.outside = [=](const Vector3& p) {
    return a.minCoeff() * (std::sqrt(p.cwiseQuotient(a).squaredNorm()) - 1);
  };
  shape.inside = EllipsoidMesh(a, sides, bands, PrimitiveFit::kInside);
  shape.enclosing = EllipsoidMesh(a, sides, bands, PrimitiveFit::kEnclosing);
  shape.inside_excess = EllipsoidExcess(a, PrimitiveFit::kInside, sides, bands);
  shape.enclosing_excess = EllipsoidExcess(a, PrimitiveFit::kEnclosing, sides, bands);
  return shape;
}

std::vector<Shape> Shapes() {
  return {Cylinder(0.3, 1.2, 3),
          Cylinder(0.04, 0.1, 7),
          Cylinder(0.05, 0.3, kCylinderSides),
          Capsule(0.2, 0.5, 5, 2),
          Capsule(0.03, 0.0, 9, 3),
          Capsule(0.05, 0.2, kCylinderSides, kQuarterBands),
          Ellipsoid(Vector3(0.1, 0.3, 0.05), 6, 3),
          Ellipsoid(Vector3(0.2, 0.1, 0.4), kCylinderSides, kQuarterBands)};
}

// How far `p` lies beyond the convex mesh's face planes (> 0: outside some face); the planes
// from each triangle's corners, the largest over its three corners.
double BeyondFaces(const Mesh& mesh, const Vector3& p) {
  double beyond = -INFINITY;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
    const Vector3 n = (b - a).cross(c - a).normalized();
    beyond = std::max({beyond, n.dot(p - a), n.dot(p - b), n.dot(p - c)});
  }
  return beyond;
}

TEST(PrimitiveFits, EnclosingMeshesHoldTheShapeAndStayWithinTheirExcess) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Shape& shape : Shapes()) {
    SCOPED_TRACE(shape.name);
    double worst = -INFINITY;
    for (int i = 0; i < 4000; ++i) {
      const Vector3 p = shape.surface(unit(random), unit(random), unit(random));
      worst = std::max(worst, BeyondFaces(shape.enclosing, p));
    }
    // On a flat cap the point lies on the mesh's face (0); nowhere outside.
    EXPECT_LE(worst, 0.0) << "a surface point lies outside the enclosing mesh by " << worst;
    EXPECT_GT(shape.enclosing_excess, 0.0);
    for (Eigen::Index v = 0; v < shape.enclosing.vertices.rows(); ++v) {
      const Vector3 p = shape.enclosing.vertices.row(v).transpose();
      EXPECT_GE(shape.outside(p), -1e-12) << "vertex " << v << " inside the shape";
      // For the ellipsoid `outside` is no distance: the radial bound below is the claim.
      EXPECT_LE(shape.outside(p), shape.enclosing_excess * (1 + 1e-9)) << "vertex " << v;
    }
  }
}

TEST(PrimitiveFits, InsideMeshesLieInsideTheShapeAndHoldItShrunkByTheirExcess) {
  std::mt19937_64 random(12);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Shape& shape : Shapes()) {
    SCOPED_TRACE(shape.name);
    for (Eigen::Index v = 0; v < shape.inside.vertices.rows(); ++v) {
      EXPECT_LE(shape.outside(shape.inside.vertices.row(v).transpose()), 1e-12) << v;
    }
    // The inside mesh misses some of the surface (which is why covers need the other fit)...
    double worst = -INFINITY;
    for (int i = 0; i < 4000; ++i) {
      worst = std::max(worst,
                       BeyondFaces(shape.inside, shape.surface(unit(random), unit(random), 0.3)));
    }
    EXPECT_GT(worst, 0.0);
    EXPECT_LE(worst, shape.inside_excess * (1 + 1e-9));
  }
}

// A link of one element of `shape` placed at a turned origin.
UrdfElement Placed(UrdfShape kind, const Vector3& size, double radius, double length) {
  UrdfElement element;
  element.line = 3;
  element.geometry.shape = kind;
  element.geometry.size = size;
  element.geometry.radius = radius;
  element.geometry.length = length;
  element.origin.xyz = Vector3(0.2, -0.1, 0.4);
  element.origin.rpy = Vector3(0.3, -1.1, 2.0);
  return element;
}

struct PlacedShape {
  UrdfElement element;
  Shape shape;  // in the element's frame
};

TEST(PrimitiveFits, RobotCoversHoldTheTrueShapesAndTheirCoresAndInternalSetsLieInside) {
  const std::vector<PlacedShape> placed = {
      {Placed(UrdfShape::kCylinder, Vector3::Zero(), 0.05, 0.3),
       Cylinder(0.05, 0.3, kCylinderSides)},
      {Placed(UrdfShape::kCapsule, Vector3::Zero(), 0.04, 0.2),
       Capsule(0.04, 0.2, kCylinderSides, kQuarterBands)},
      {Placed(UrdfShape::kEllipsoid, Vector3(0.1, 0.05, 0.2), 0, 0),
       Ellipsoid(Vector3(0.1, 0.05, 0.2), kCylinderSides, kQuarterBands)},
  };
  std::mt19937_64 random(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const PlacedShape& p : placed) {
    SCOPED_TRACE(p.shape.name);
    UrdfRobot robot;
    robot.name = "r";
    robot.links.push_back(UrdfLink{});
    robot.links[0].name = "l";
    robot.links[0].elements = {p.element};
    const Eigen::Matrix3d rotation = OriginRotation(p.element.origin);
    const Vector3 translation = p.element.origin.xyz;
    const auto local = [&](const Vector3& link) -> Vector3 {
      return rotation.transpose() * (link - translation);
    };
    for (int budget : {1, 6, 20}) {
      SCOPED_TRACE(budget);
      UrdfSpherizeOptions options;
      options.max_spheres_per_link = budget;
      absl::StatusOr<RobotSpherizeResult> result = SpherizeRobot(robot, options);
      ASSERT_TRUE(result.ok()) << result.status();
      const LinkSpherizeResult& link = result->links[0];
      ASSERT_EQ(link.status, LinkStatus::kSpherized) << link.error;
      ASSERT_TRUE(link.delta.has_value());
      // Points of the true surface (the worst place for a cover) and of the inside, by
      // shrinking surface points toward the centre.
      int uncovered = 0;
      for (int i = 0; i < 6000; ++i) {
        Vector3 q = p.shape.surface(unit(random), unit(random), unit(random));
        if (i % 3 == 0) q *= unit(random);
        const Vector3 world = rotation * q + translation;
        bool held = false;
        for (const Sphere& s : link.spheres) held = held || (world - s.center).norm() <= s.radius;
        uncovered += !held;
      }
      EXPECT_EQ(uncovered, 0);
      // Cores inside the shape: 200 points of each core's sphere.
      for (const Sphere& core : link.cores) {
        for (int i = 0; i < 200; ++i) {
          const Vector3 q = core.center + core.radius * UnitDirection(unit(random), unit(random));
          EXPECT_LE(p.shape.outside(local(q)), 1e-12) << "core at " << core.center.transpose();
        }
      }
      // The delta holds against the true shape (cylinders and capsules, whose `outside` is the
      // distance): every sphere's farthest points in 500 directions.
      if (p.element.geometry.shape != UrdfShape::kEllipsoid) {
        for (const Sphere& s : link.spheres) {
          for (int i = 0; i < 500; ++i) {
            const Vector3 q = s.center + s.radius * UnitDirection(unit(random), unit(random));
            EXPECT_LE(p.shape.outside(local(q)), *link.delta * (1 + 1e-9));
          }
        }
      }
      options.kind = SphereSetKind::kInternal;
      result = SpherizeRobot(robot, options);
      ASSERT_TRUE(result.ok()) << result.status();
      ASSERT_EQ(result->links[0].status, LinkStatus::kSpherized) << result->links[0].error;
      for (const Sphere& s : result->links[0].spheres) {
        for (int i = 0; i < 200; ++i) {
          const Vector3 q = s.center + s.radius * UnitDirection(unit(random), unit(random));
          EXPECT_LE(p.shape.outside(local(q)), 1e-12) << "internal at " << s.center.transpose();
        }
      }
    }
  }
}

}  // namespace
}  // namespace inscribe::robot
