// The inside test, per query on one thread: the pseudonormal (the clean meshes' path), the exact
// winding number (every other mesh's), the previous implementation's three-ray parity in double
// precision (reimplemented here over the same flat BVH, for the ratio), and CGAL's
// Side_of_triangle_mesh, all in this program on the same queries. Checks first that the two
// inside tests InsideTestFor may pick agree with CGAL's on every query of a mesh without
// self-intersections, and that the exact test agrees with the parity one wherever no sheets
// overlap; exits 1 otherwise.
//
//   INSCRIBE_DATA_DIR=/path/to/meshes bench/inside_test_bench [--queries N] [mesh.off ...]
//
// Meshes default to the CGAL demo meshes of the tests plus two assemblies built here: 400
// overlapping boxes (self-intersecting) and a hollow box with 300 parts outside it.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/solid.h"
#include "solid/triangle_bvh.h"

namespace {

using inscribe::BoundaryOracle;
using inscribe::InsideTest;
using inscribe::Mesh;
using inscribe::Side;
using inscribe::Vector3;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// The previous kRayParity: Moeller-Trumbore crossings along three fixed directions, majority
// vote of their parities; the BVH culls with a padded slab test.
bool MollerTrumbore(const Vector3& o, const Vector3& d, const Vector3& a, const Vector3& b,
                    const Vector3& c) {
  const Vector3 e1 = b - a, e2 = c - a, pvec = d.cross(e2);
  const double det = e1.dot(pvec);
  if (det == 0.0) return false;
  const double inv = 1.0 / det;
  const Vector3 tvec = o - a;
  const double u = tvec.dot(pvec) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Vector3 qvec = tvec.cross(e1);
  const double v = d.dot(qvec) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  return e2.dot(qvec) * inv > 0.0;
}

int ParityCrossings(const inscribe::internal::TriangleBvh& bvh, const Vector3& o,
                    const Vector3& d) {
  const double pad = 1e-10 * std::max(bvh.magnitude(), o.cwiseAbs().maxCoeff());
  const Vector3 inv = d.cwiseInverse();
  inscribe::internal::TriangleBvhRef stack[inscribe::internal::TriangleBvh::kTraversalStackSize];
  int top = 0, crossings = 0;
  stack[top++] = bvh.root();
  while (top > 0) {
    const auto ref = stack[--top];
    if (ref.is_leaf()) {
      const auto& leaf = bvh.leaves()[static_cast<std::size_t>(ref.index)];
      for (std::int32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
        const Vector3* c = &bvh.corners()[3 * static_cast<std::size_t>(s)];
        crossings += MollerTrumbore(o, d, c[0], c[1], c[2]) ? 1 : 0;
      }
      continue;
    }
    const auto& n = bvh.nodes()[static_cast<std::size_t>(ref.index)];
    for (int c = 1; c >= 0; --c) {
      double t_near = 0.0, t_far = std::numeric_limits<double>::infinity();
      bool hit = true;
      for (int k = 0; k < 3 && hit; ++k) {
        const double lo = n.lo[k][c] - pad, hi = n.hi[k][c] + pad;
        double t0 = (lo - o[k]) * inv[k], t1 = (hi - o[k]) * inv[k];
        if (t0 > t1) std::swap(t0, t1);
        t_near = std::max(t_near, t0);
        t_far = std::min(t_far, t1);
        hit = t_near <= t_far * (1.0 + 1e-12);
      }
      if (hit) stack[top++] = n.child[c];
    }
  }
  return crossings;
}

bool ParityInside(const inscribe::internal::TriangleBvh& bvh, const inscribe::BoundingBox& box,
                  const Vector3& p) {
  if ((p.array() < box.min.array()).any() || (p.array() > box.max.array()).any()) return false;
  static const Vector3 kDirections[3] = {Vector3(0.5773503f, 0.4082483f, 0.7071068f),
                                         Vector3(-0.6154797f, 0.7071068f, -0.3481553f),
                                         Vector3(0.2672612f, -0.8017837f, 0.5345225f)};
  int votes = 0;
  for (const Vector3& d : kDirections) votes += ParityCrossings(bvh, p, d) % 2;
  return votes >= 2;
}

Mesh Box(const Vector3& lo, const Vector3& hi) {
  Mesh m;
  m.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    m.vertices.row(i) << ((i & 1) ? hi.x() : lo.x()), ((i & 2) ? hi.y() : lo.y()),
        ((i & 4) ? hi.z() : lo.z());
  }
  m.triangles.resize(12, 3);
  m.triangles << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2,
      4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

void Append(Mesh& to, const Mesh& part) {
  const auto nv = to.vertices.rows(), nt = to.triangles.rows();
  to.vertices.conservativeResize(nv + part.vertices.rows(), 3);
  to.vertices.bottomRows(part.vertices.rows()) = part.vertices;
  to.triangles.conservativeResize(nt + part.triangles.rows(), 3);
  to.triangles.bottomRows(part.triangles.rows()) =
      part.triangles.array() + static_cast<std::int32_t>(nv);
}

Mesh OverlappingBoxes() {
  Mesh m;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 10.0), s(0.3, 1.5);
  for (int i = 0; i < 400; ++i) {
    const Vector3 lo(u(rng), u(rng), u(rng));
    Append(m, Box(lo, lo + Vector3(s(rng), s(rng), s(rng))));
  }
  return m;
}

Mesh HollowBoxWithParts() {
  Mesh m = Box(Vector3::Zero(), Vector3::Constant(10));
  Append(m, Box(Vector3::Constant(1), Vector3::Constant(9)));  // the cavity
  for (int i = 0; i < 300; ++i) {
    const Vector3 lo(12 + (i % 20) * 0.5, (i / 20) * 0.5, 0);
    Append(m, Box(lo, lo + Vector3::Constant(0.3)));
  }
  return m;
}

double Rate(int n, const std::chrono::steady_clock::time_point& start) {
  return n / std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  int queries = 200'000;
  std::vector<std::string> names;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--queries" && i + 1 < argc) {
      queries = std::atoi(argv[++i]);
    } else {
      names.push_back(arg);
    }
  }
  if (queries <= 0) {
    std::fprintf(stderr, "--queries takes a positive count\n");
    return 64;
  }
  const bool defaults = names.empty();
  if (defaults) {
    names = {"eight.off", "cow.off", "elephant.off", "knot1.off", "fandisk.off", "bunny00.off"};
  }
  const char* env = std::getenv("INSCRIBE_DATA_DIR");
  const std::string dir = env != nullptr ? env : std::string(INSCRIBE_SOURCE_DIR) + "/data";
  std::vector<std::pair<std::string, Mesh>> meshes;
  for (const std::string& name : names) {
    absl::StatusOr<Mesh> mesh =
        inscribe::ReadMesh(name.find('/') == std::string::npos ? dir + "/" + name : name);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), std::string(mesh.status().message()).c_str());
      return 2;
    }
    meshes.emplace_back(name, *std::move(mesh));
  }
  if (defaults) {
    meshes.emplace_back("400 overlapping boxes", OverlappingBoxes());
    meshes.emplace_back("hollow box + 300 parts", HollowBoxWithParts());
  }
  std::printf("single-thread queries/s on %d points per mesh (uniform in the bbox grown 10%%)\n",
              queries);
  std::printf("%-24s %7s %12s %12s %12s %12s %9s %9s %s\n", "mesh", "pairs", "pseudonormal",
              "exact", "old parity", "CGAL side", "ex/par", "ex/pseudo", "solid's test");
  int failures = 0;
  for (const auto& [name, raw] : meshes) {
    absl::StatusOr<inscribe::Solid> solid = inscribe::PrepareSolid(raw);
    if (!solid.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), std::string(solid.status().message()).c_str());
      return 2;
    }
    const Mesh& mesh = solid->mesh();
    absl::StatusOr<BoundaryOracle> pseudo =
        BoundaryOracle::Build(mesh, {InsideTest::kPseudonormal});
    absl::StatusOr<BoundaryOracle> exact = BoundaryOracle::Build(mesh, {InsideTest::kExactWinding});
    const auto bvh = inscribe::internal::TriangleBvh::Build(mesh);
    SurfaceMesh surface;
    std::vector<SurfaceMesh::Vertex_index> vs;
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
      vs.push_back(surface.add_vertex(
          Kernel::Point_3(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2))));
    }
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      surface.add_face(vs[mesh.triangles(t, 0)], vs[mesh.triangles(t, 1)],
                       vs[mesh.triangles(t, 2)]);
    }
    const bool cgal_ok =
        surface.number_of_faces() == static_cast<std::size_t>(mesh.num_triangles());
    const inscribe::BoundingBox box = inscribe::ComputeBoundingBox(mesh.vertices);
    std::mt19937_64 rng(11);
    std::vector<Vector3> points(static_cast<std::size_t>(queries));
    for (Vector3& p : points) {
      for (int k = 0; k < 3; ++k) {
        const double pad = 0.1 * box.extent()[k];
        p[k] = std::uniform_real_distribution<double>(box.min[k] - pad, box.max[k] + pad)(rng);
      }
    }
    std::vector<char> a(points.size()), b(points.size()), c(points.size()), d(points.size(), 0);
    auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < points.size(); ++i)
      a[i] = pseudo->Classify(points[i]) == Side::kInside;
    const double pseudo_rate = Rate(queries, start);
    start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < points.size(); ++i)
      b[i] = exact->Classify(points[i]) == Side::kInside;
    const double exact_rate = Rate(queries, start);
    start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < points.size(); ++i) c[i] = ParityInside(bvh, box, points[i]);
    const double parity_rate = Rate(queries, start);
    double cgal_rate = 0.0;
    if (cgal_ok) {
      CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel> side(surface);
      start = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < points.size(); ++i) {
        d[i] = side(Kernel::Point_3(points[i].x(), points[i].y(), points[i].z())) ==
               CGAL::ON_BOUNDED_SIDE;
      }
      cgal_rate = Rate(queries, start);
    }
    const bool clean =
        solid->report.self_intersections_checked && solid->report.self_intersecting_pairs == 0;
    int disagree = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (clean && (b[i] != c[i] || (cgal_ok && b[i] != d[i]))) ++disagree;
      if (InsideTestFor(solid->report) == InsideTest::kPseudonormal && a[i] != b[i]) ++disagree;
    }
    if (disagree > 0) {
      ++failures;
      std::fprintf(stderr, "%s: %d queries disagree\n", name.c_str(), disagree);
    }
    std::printf(
        "%-24s %7lld %12.0f %12.0f %12.0f %12.0f %8.2fx %8.2fx %s\n", name.c_str(),
        static_cast<long long>(solid->report.self_intersecting_pairs), pseudo_rate, exact_rate,
        parity_rate, cgal_rate, exact_rate / parity_rate, exact_rate / pseudo_rate,
        InsideTestFor(solid->report) == InsideTest::kPseudonormal ? "pseudonormal" : "exact");
  }
  std::printf(
      "pairs: self-intersecting triangle pairs; ex/par, ex/pseudo: rate ratios (above 1: the "
      "exact test faster). CGAL side: Side_of_triangle_mesh (0: the mesh is not one CGAL "
      "surface). The solid's test is what InsideTestFor gives it.\n");
  return failures == 0 ? 0 : 1;
}
