#include "support/synthetic_meshes.h"

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace inscribe::testing {

Mesh Box(const Vector3& lo, const Vector3& hi) {
  Mesh mesh;
  mesh.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.row(i) << ((i & 1) ? hi.x() : lo.x()), ((i & 2) ? hi.y() : lo.y()),
        ((i & 4) ? hi.z() : lo.z());
  }
  mesh.triangles.resize(12, 3);
  mesh.triangles << 0, 2, 1, 1, 2, 3,  // z = lo
      4, 5, 6, 5, 7, 6,                // z = hi
      0, 1, 4, 1, 5, 4,                // y = lo
      2, 6, 3, 3, 6, 7,                // y = hi
      0, 4, 2, 2, 4, 6,                // x = lo
      1, 3, 5, 3, 7, 5;                // x = hi
  return mesh;
}

Mesh OpenUnitCube() {
  Mesh mesh = UnitCube();
  mesh.triangles.conservativeResize(11, 3);
  return mesh;
}

Mesh Icosphere(int levels, const Vector3& centre, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                            {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                            {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vector3& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : f) {
      const int a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), c = mid(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f = std::move(next);
  }
  Mesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) {
    mesh.vertices.row(static_cast<Eigen::Index>(i)) = (centre + radius * v[i]).transpose();
  }
  mesh.triangles.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) {
    mesh.triangles.row(static_cast<Eigen::Index>(i)) << f[i][0], f[i][1], f[i][2];
  }
  return mesh;
}

Mesh Tetrahedron(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d) {
  Mesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << a.transpose(), b.transpose(), c.transpose(), d.transpose();
  mesh.triangles.resize(4, 3);
  mesh.triangles << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2;  // outward when (b-a)x(c-a) . (d-a) > 0
  if ((b - a).cross(c - a).dot(d - a) < 0.0) return Inverted(std::move(mesh));
  return mesh;
}

Mesh Octahedron(const Vector3& centre, double radius) {
  Mesh mesh;
  mesh.vertices.resize(6, 3);
  for (int axis = 0; axis < 3; ++axis) {
    Vector3 u = Vector3::Zero();
    u[axis] = radius;
    mesh.vertices.row(2 * axis) = (centre + u).transpose();
    mesh.vertices.row(2 * axis + 1) = (centre - u).transpose();
  }
  // Vertices: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z; one triangle per octant, counter-clockwise
  // seen from outside.
  mesh.triangles.resize(8, 3);
  mesh.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,  // z > 0
      2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;                // z < 0
  return mesh;
}

Mesh Translated(Mesh mesh, const Vector3& offset) {
  mesh.vertices.rowwise() += offset.transpose();
  return mesh;
}

Mesh Concatenate(const Mesh& a, const Mesh& b) {
  Mesh out;
  out.vertices.resize(a.num_vertices() + b.num_vertices(), 3);
  out.vertices << a.vertices, b.vertices;
  out.triangles.resize(a.num_triangles() + b.num_triangles(), 3);
  out.triangles << a.triangles,
      (b.triangles.array() + static_cast<std::int32_t>(a.num_vertices())).matrix();
  return out;
}

Mesh Inverted(Mesh mesh) {
  mesh.triangles.col(1).swap(mesh.triangles.col(2));
  return mesh;
}

Mesh PerFaceVertices(const Mesh& mesh) {
  Mesh out;
  out.vertices.resize(3 * mesh.num_triangles(), 3);
  out.triangles.resize(mesh.num_triangles(), 3);
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      out.vertices.row(3 * t + k) = mesh.vertices.row(mesh.triangles(t, k));
      out.triangles(t, k) = static_cast<std::int32_t>(3 * t + k);
    }
  }
  return out;
}

}  // namespace inscribe::testing
