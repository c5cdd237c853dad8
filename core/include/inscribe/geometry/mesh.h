// A triangle mesh as plain arrays: the currency every other part of inscribe trades in.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace inscribe {

// #V by 3 vertex positions, in the mesh file's own units and frame. Row-major so that a row is
// one contiguous (x, y, z) triple that can be handed to other libraries without copying.
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// #T by 3 vertex indices, 0-based, counter-clockwise seen from outside once validated.
using Triangles = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

using Vector3 = Eigen::Vector3d;

// Largest coordinate magnitude ValidateMesh accepts (mesh units); beyond it the mesh has the
// error "coordinates_too_large". Volumes (cubes of differences) and CGAL's constructions
// (products of differences) stay finite below it.
inline constexpr double kMaxMeshCoordinate = 1e100;

struct Mesh {
  Vertices vertices;
  Triangles triangles;

  std::int64_t num_vertices() const { return vertices.rows(); }
  std::int64_t num_triangles() const { return triangles.rows(); }
};

struct BoundingBox {
  Vector3 min = Vector3::Zero();
  Vector3 max = Vector3::Zero();

  Vector3 extent() const { return max - min; }
  double diagonal() const { return extent().norm(); }
};

// Axis-aligned bounds of all vertices (referenced or not). Zero box for an empty mesh.
BoundingBox ComputeBoundingBox(const Vertices& vertices);

// Signed volume enclosed by the triangles, by the divergence theorem: sum over triangles of
// det(v0, v1, v2) / 6. Positive for a closed mesh oriented outward; cost O(#T).
double SignedVolume(const Mesh& mesh);

}  // namespace inscribe
