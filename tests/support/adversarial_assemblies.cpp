#include "support/adversarial_assemblies.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "support/synthetic_meshes.h"

namespace inscribe::testing {
namespace {

// Shells appended one by one, each as meant and as given.
class AssemblyBuilder {
 public:
  explicit AssemblyBuilder(std::string name) { assembly_.name = std::move(name); }

  // `meant` oriented as the solid's definition orients it; given inside out when asked.
  void Add(const Mesh& meant, bool give_inverted) {
    assembly_.intended = Concatenate(assembly_.intended, meant);
    assembly_.input = Concatenate(assembly_.input, give_inverted ? Inverted(meant) : meant);
  }
  void Focus(const BoundingBox& box) { assembly_.focus.push_back(box); }
  Assembly& assembly() { return assembly_; }
  Assembly Take() { return std::move(assembly_); }

 private:
  Assembly assembly_;
};

BoundingBox Around(const Vector3& lo, const Vector3& hi, double pad) {
  return BoundingBox{lo - Vector3::Constant(pad), hi + Vector3::Constant(pad)};
}

// Slabs of thickness 2 * half around the six faces of the box [lo, hi].
void FocusFaces(AssemblyBuilder& builder, const Vector3& lo, const Vector3& hi, double half) {
  for (int axis = 0; axis < 3; ++axis) {
    for (const double at : {lo[axis], hi[axis]}) {
      BoundingBox slab{lo, hi};
      slab.min[axis] = at - half;
      slab.max[axis] = at + half;
      builder.Focus(slab);
    }
  }
}

// Splits edge u-v of `mesh` at m (a point of the segment) with a zero-area triangle: the
// triangle holding the directed edge u->v becomes two through m, and (u, v, m) closes the seam.
void SplitWithCollinearTriangle(Mesh& mesh, std::int32_t u, std::int32_t v, const Vector3& m) {
  const auto mi = static_cast<std::int32_t>(mesh.num_vertices());
  mesh.vertices.conservativeResize(mi + 1, 3);
  mesh.vertices.row(mi) = m.transpose();
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles(t, k) != u || mesh.triangles(t, (k + 1) % 3) != v) continue;
      const std::int32_t w = mesh.triangles(t, (k + 2) % 3);
      const Eigen::Index n = mesh.num_triangles();
      mesh.triangles.conservativeResize(n + 2, 3);
      mesh.triangles.row(t) << u, mi, w;
      mesh.triangles.row(n) << mi, v, w;
      mesh.triangles.row(n + 1) << u, v, mi;
      return;
    }
  }
}

}  // namespace

Assembly HollowBoxWithDebris(bool cavity_inward) {
  AssemblyBuilder builder(cavity_inward ? "hollow box with debris, cavity inward"
                                        : "hollow box with debris, cavity outward");
  builder.Add(Box(Vector3::Constant(-1.0), Vector3::Constant(1.0)), false);
  builder.Add(Inverted(Box(Vector3::Constant(-0.6), Vector3::Constant(0.6))), !cavity_inward);
  int piece = 0;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 10; ++j) {
      for (int i = 0; i < 10; ++i, ++piece) {
        const Vector3 c(-1.35 + 0.3 * i, -1.35 + 0.3 * j, 1.3 + 0.3 * k);
        const double h = 0.05;
        const Mesh shell = (i + j + k) % 2 == 0
                               ? Box(c - Vector3::Constant(h), c + Vector3::Constant(h))
                               : Tetrahedron(c + Vector3(-h, -h, -h), c + Vector3(h, -h, -h),
                                             c + Vector3(-h, h, -h), c + Vector3(-h, -h, h));
        builder.Add(shell, piece % 7 == 3);
      }
    }
  }
  builder.Focus(Around(Vector3::Constant(-0.6), Vector3::Constant(0.6), 0.05));
  builder.Focus(BoundingBox{Vector3(-1.45, -1.45, 1.2), Vector3(1.45, 1.45, 2.0)});
  FocusFaces(builder, Vector3::Constant(-0.6), Vector3::Constant(0.6), 1e-3);
  return builder.Take();
}

Assembly OverlapWithTouchingTetrahedron() {
  AssemblyBuilder builder("overlapping boxes with a tetrahedron on a corner");
  const Vector3 b_lo(0.5, 0.3, 0.2), b_hi(1.5, 1.3, 1.2);
  builder.Add(UnitCube(), false);
  builder.Add(Box(b_lo, b_hi), true);
  // The tetrahedron's apex is the unit cube's vertex 0, (0, 0, 0), by index.
  const Mesh tetrahedron = Tetrahedron(Vector3::Zero(), Vector3(-0.5, -0.1, -0.1),
                                       Vector3(-0.1, -0.5, -0.1), Vector3(-0.1, -0.1, -0.5));
  for (Mesh* mesh : {&builder.assembly().input, &builder.assembly().intended}) {
    const auto base = static_cast<std::int32_t>(mesh->num_vertices()) - 1;
    mesh->vertices.conservativeResize(base + 4, 3);
    mesh->vertices.bottomRows(3) = tetrahedron.vertices.bottomRows(3);
    const Eigen::Index n = mesh->num_triangles();
    mesh->triangles.conservativeResize(n + 4, 3);
    for (Eigen::Index t = 0; t < 4; ++t) {
      for (int k = 0; k < 3; ++k) {
        const std::int32_t v = tetrahedron.triangles(t, k);
        mesh->triangles(n + t, k) = v == 0 ? 0 : base + v;
      }
    }
  }
  builder.Focus(BoundingBox{b_lo, Vector3::Ones()});
  builder.Focus(Around(Vector3::Zero(), Vector3::Zero(), 0.05));
  builder.Focus(Around(b_lo, b_lo, 0.05));
  return builder.Take();
}

Assembly TetrahedronPokingOutOfABox() {
  AssemblyBuilder builder("tetrahedron poking out of a box");
  const Vector3 a(0.3, 0.5, 0.5), b(0.5, 0.3, 0.5), c(1.4, 0.6, 0.4), d(1.4, 0.5, 0.8);
  builder.Add(UnitCube(), false);
  builder.Add(Tetrahedron(a, b, c, d), true);
  builder.Focus(BoundingBox{Vector3(0.25, 0.25, 0.35), Vector3(1.45, 0.65, 0.85)});
  return builder.Take();
}

Assembly NestedShells(bool given_inverted) {
  AssemblyBuilder builder(given_inverted ? "nested shells, given inside out"
                                         : "nested shells, given outward");
  const double halves[] = {2.0, 1.5, 1.0, 0.5};
  for (int level = 0; level < 4; ++level) {
    const Mesh outward = Box(Vector3::Constant(-halves[level]), Vector3::Constant(halves[level]));
    const bool cavity = level % 2 == 1;
    // Given outward: a cavity is given the wrong way; given inside out: the others are.
    builder.Add(cavity ? Inverted(outward) : outward, cavity != given_inverted);
    FocusFaces(builder, Vector3::Constant(-halves[level]), Vector3::Constant(halves[level]), 0.05);
  }
  return builder.Take();
}

Assembly OffsetTwinBoxes() {
  AssemblyBuilder builder("twin boxes 1e-9 apart");
  const Vector3 offset = Vector3::Constant(1e-9);
  builder.Add(UnitCube(), false);
  builder.Add(Box(offset, Vector3::Ones() + offset), false);
  FocusFaces(builder, Vector3::Zero(), Vector3::Ones(), 3e-9);
  return builder.Take();
}

Assembly HairlineHollowBox() {
  AssemblyBuilder builder("hollow box with 1e-9 walls");
  const Vector3 lo = Vector3::Constant(1e-9), hi = Vector3::Constant(1.0 - 1e-9);
  builder.Add(UnitCube(), false);
  builder.Add(Inverted(Box(lo, hi)), true);
  FocusFaces(builder, Vector3::Zero(), Vector3::Ones(), 3e-9);
  return builder.Take();
}

Assembly TranslatedAssembly(const Assembly& assembly, const Vector3& offset) {
  Assembly out = assembly;
  out.name = assembly.name + ", translated";
  out.input = Translated(out.input, offset);
  out.intended = Translated(out.intended, offset);
  for (BoundingBox& box : out.focus) {
    box.min += offset;
    box.max += offset;
  }
  return out;
}

Assembly ThinPlate() {
  AssemblyBuilder builder("plate 1e-3 thick");
  const Vector3 hi(1.0, 1.0, 1e-3);
  builder.Add(Box(Vector3::Zero(), hi), false);
  builder.Focus(BoundingBox{Vector3(-0.1, -0.1, -1e-3), Vector3(1.1, 1.1, 2e-3)});
  FocusFaces(builder, Vector3::Zero(), hi, 1e-4);
  return builder.Take();
}

Assembly BoxWithCollinearTriangles() {
  Mesh mesh = UnitCube();
  // Box() vertex i is at ((i & 1), (i & 2) / 2, (i & 4) / 4). Face diagonals 1-2 (z = 0),
  // 1-4 (y = 0), 3-6 (y = 1); box edges 4-5 and 2-6. Each split point is exact.
  const std::pair<std::int32_t, std::int32_t> edges[] = {{1, 2}, {4, 1}, {3, 6}, {4, 5}, {2, 6}};
  const double along[] = {0.5, 0.25, 0.75, 0.125, 0.5};
  AssemblyBuilder builder("box with collinear triangles");
  for (int e = 0; e < 5; ++e) {
    const auto [u, v] = edges[e];
    const Vector3 a = mesh.vertices.row(u).transpose(), b = mesh.vertices.row(v).transpose();
    const Vector3 m = a + along[e] * (b - a);
    // The directed edge as some triangle holds it.
    bool forward = false;
    for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
      for (int k = 0; k < 3; ++k) {
        forward = forward || (mesh.triangles(t, k) == u && mesh.triangles(t, (k + 1) % 3) == v);
      }
    }
    if (forward) {
      SplitWithCollinearTriangle(mesh, u, v, m);
    } else {
      SplitWithCollinearTriangle(mesh, v, u, m);
    }
    builder.Focus(Around(a.cwiseMin(b), a.cwiseMax(b), 0.02));
  }
  builder.Add(mesh, false);
  return builder.Take();
}

Assembly SliverTetrahedronBesideABox() {
  AssemblyBuilder builder("sliver tetrahedron beside a box");
  builder.Add(Box(Vector3::Constant(0.5), Vector3::Constant(1.5)), false);
  const Vector3 a(-0.38950373607782318, 0.040145213590864301, 0.18486536021429584);
  const Vector3 b(-0.4668687438319471, 0.18867193007190214, -0.3484773720569575);
  const Vector3 c(-0.34508871926043783, 0.21476908823588653, 0.57860868864675452);
  const Vector3 d(-0.35655374514108473, -0.28300537753519567, 0.3244647640530906);
  builder.Add(Tetrahedron(a, b, c, d), true);
  builder.Focus(BoundingBox{Vector3(-0.6, -0.4, -0.5), Vector3(-0.2, 0.4, 0.7)});
  builder.Focus(BoundingBox{Vector3(-0.6, -0.4, -0.5), Vector3(1.6, 1.6, 1.6)});
  return builder.Take();
}

Assembly OverlappingIcospheres() {
  AssemblyBuilder builder("overlapping icospheres");
  const Vector3 centres[] = {{0.0, 0.0, 0.0}, {0.8, 0.0, 0.0}, {0.4, 0.6, 0.1}, {0.3, 0.2, 0.7}};
  const double radii[] = {1.0, 0.7, 0.5, 0.45};
  for (int i = 0; i < 4; ++i) builder.Add(Icosphere(2, centres[i], radii[i]), i == 1);
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const Vector3 lo = (centres[i] - Vector3::Constant(radii[i]))
                             .cwiseMax(centres[j] - Vector3::Constant(radii[j]));
      const Vector3 hi = (centres[i] + Vector3::Constant(radii[i]))
                             .cwiseMin(centres[j] + Vector3::Constant(radii[j]));
      builder.Focus(BoundingBox{lo, hi});
    }
  }
  return builder.Take();
}

namespace {

// Triangle t's entry: the area of triangles 0..t (for drawing triangles by area).
std::vector<double> CumulativeAreas(const Mesh& mesh) {
  std::vector<double> cumulative(static_cast<std::size_t>(mesh.num_triangles()));
  double total = 0.0;
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[static_cast<std::size_t>(t)] = total;
  }
  return cumulative;
}

}  // namespace

Vertices AssemblyPoints(const Assembly& assembly, int uniform, int focused, int near_wall,
                        std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const BoundingBox box = ComputeBoundingBox(assembly.intended.vertices);
  const double diagonal = box.diagonal();
  const Vector3 pad = Vector3::Constant(0.1 * diagonal);
  auto in_box = [&](const Vector3& lo, const Vector3& hi) {
    Vector3 p;
    for (int k = 0; k < 3; ++k) p[k] = lo[k] + unit(rng) * (hi[k] - lo[k]);
    return p;
  };
  Vertices points(uniform + focused + near_wall, 3);
  Eigen::Index row = 0;
  for (int i = 0; i < uniform; ++i) points.row(row++) = in_box(box.min - pad, box.max + pad);
  for (int i = 0; i < focused; ++i) {
    const BoundingBox& f = assembly.focus[static_cast<std::size_t>(i) % assembly.focus.size()];
    points.row(row++) = in_box(f.min, f.max);
  }
  // Triangles by area (zero-area ones never chosen).
  const Mesh& mesh = assembly.intended;
  const std::vector<double> cumulative = CumulativeAreas(mesh);
  const double total = cumulative.empty() ? 0.0 : cumulative.back();
  for (int i = 0; i < near_wall; ++i) {
    const auto t = static_cast<Eigen::Index>(
        std::upper_bound(cumulative.begin(), cumulative.end(), unit(rng) * total) -
        cumulative.begin());
    const Eigen::Index tri = std::min<Eigen::Index>(t, mesh.num_triangles() - 1);
    const Vector3 a = mesh.vertices.row(mesh.triangles(tri, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(tri, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(tri, 2)).transpose();
    double s = unit(rng), r = unit(rng);
    if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
    const Vector3 n = (b - a).cross(c - a).normalized();
    const double step = diagonal * std::pow(10.0, -1.0 - 8.0 * unit(rng));
    const double side = unit(rng) < 0.5 ? -1.0 : 1.0;
    points.row(row++) = (a + s * (b - a) + r * (c - a) + side * step * n).transpose();
  }
  return points;
}

Vertices PointsInBalls(const std::vector<Vector3>& centres, const std::vector<double>& radii,
                       int per_ball, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Vertices points(static_cast<Eigen::Index>(centres.size()) * per_ball, 3);
  Eigen::Index row = 0;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    points.row(row++) = centres[i].transpose();
    for (int j = 1; j < per_ball; ++j) {
      const Vector3 u = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
      // Half of them within a hundredth of the radius of the sphere itself.
      const double depth = j % 2 == 0 ? std::cbrt(unit(rng)) : 1.0 - 0.01 * unit(rng);
      points.row(row++) = (centres[i] + radii[i] * depth * u).transpose();
    }
  }
  return points;
}

Vertices BoundaryPoints(const Mesh& mesh, int samples, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::vector<double> cumulative = CumulativeAreas(mesh);
  const double total = cumulative.empty() ? 0.0 : cumulative.back();
  Vertices points(samples + mesh.num_vertices(), 3);
  for (int i = 0; i < samples; ++i) {
    const auto t = std::min<Eigen::Index>(
        std::upper_bound(cumulative.begin(), cumulative.end(), unit(rng) * total) -
            cumulative.begin(),
        mesh.num_triangles() - 1);
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
    double s = unit(rng), r = unit(rng);
    if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
    points.row(i) = (a + s * (b - a) + r * (c - a)).transpose();
  }
  points.bottomRows(mesh.num_vertices()) = mesh.vertices;
  return points;
}

}  // namespace inscribe::testing
