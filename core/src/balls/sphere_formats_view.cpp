// Write-only sphere files for other programs: OBJ meshes of the spheres (viewers).
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "balls/sphere_formats.h"

namespace inscribe::internal {
namespace {

struct UnitIcosphere {
  std::vector<Vector3> vertices;              // on the unit sphere
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// Icosahedron subdivided `levels` times (each triangle into four, new vertices pushed onto the
// sphere): 10 * 4^levels + 2 vertices, 20 * 4^levels triangles. Cost O(4^levels).
UnitIcosphere MakeUnitIcosphere(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  UnitIcosphere s;
  for (const auto& [x, y, z] : std::vector<std::array<double, 3>>{{-1, t, 0},
                                                                  {1, t, 0},
                                                                  {-1, -t, 0},
                                                                  {1, -t, 0},
                                                                  {0, -1, t},
                                                                  {0, 1, t},
                                                                  {0, -1, -t},
                                                                  {0, 1, -t},
                                                                  {t, 0, -1},
                                                                  {t, 0, 1},
                                                                  {-t, 0, -1},
                                                                  {-t, 0, 1}}) {
    s.vertices.push_back(Vector3(x, y, z).normalized());
  }
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto middle = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto [it, inserted] = midpoint.emplace(key, static_cast<int>(s.vertices.size()));
      if (inserted) s.vertices.push_back((s.vertices[a] + s.vertices[b]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(4 * s.triangles.size());
    for (const auto& [a, b, c] : s.triangles) {
      const int ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({b, bc, ab});
      finer.push_back({c, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    s.triangles = std::move(finer);
  }
  return s;
}

}  // namespace

std::string FormatObjSphereFile(const SphereFile& file, int subdivision) {
  const UnitIcosphere unit = MakeUnitIcosphere(subdivision);
  const std::vector<Sphere>& spheres = file.set.spheres;
  std::string out =
      absl::StrCat("# inscribe spheres: ", spheres.size(), " spheres as icospheres of ",
                   unit.vertices.size(), " vertices and ", unit.triangles.size(), " triangles\n");
  if (!file.mesh_sha256.empty()) absl::StrAppend(&out, "# mesh ", file.mesh_sha256, "\n");
  std::size_t base = 1;  // OBJ indices are 1-based and global
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Sphere& sphere = spheres[i];
    absl::StrAppend(&out, "o sphere_", i, "\n");
    for (const Vector3& u : unit.vertices) {
      const Vector3 p = sphere.center + sphere.radius * u;
      absl::StrAppend(&out, "v ", FormatDouble(p.x()), " ", FormatDouble(p.y()), " ",
                      FormatDouble(p.z()), "\n");
    }
    for (const auto& [a, b, c] : unit.triangles) {
      absl::StrAppend(&out, "f ", base + a, " ", base + b, " ", base + c, "\n");
    }
    base += unit.vertices.size();
  }
  return out;
}

}  // namespace inscribe::internal
