#include "broken_meshes.h"

#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "inscribe/mesh/mesh_io.h"
#include "support/assimp_scenes.h"
#include "support/synthetic_meshes.h"

namespace inscribe::testing {
namespace {

Mesh WithoutTriangles(const Mesh& mesh, const std::vector<Eigen::Index>& removed) {
  Mesh out = mesh;
  out.triangles.resize(mesh.num_triangles() - static_cast<Eigen::Index>(removed.size()), 3);
  Eigen::Index row = 0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (std::find(removed.begin(), removed.end(), t) != removed.end()) continue;
    out.triangles.row(row++) = mesh.triangles.row(t);
  }
  return out;
}

Mesh Scaled(Mesh mesh, double factor) {
  mesh.vertices *= factor;
  return mesh;
}

// A unit square in z = 0 (two triangles).
Mesh Square() {
  Mesh sheet;
  sheet.vertices.resize(4, 3);
  sheet.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  sheet.triangles.resize(2, 3);
  sheet.triangles << 0, 1, 2, 0, 2, 3;
  return sheet;
}

BrokenMesh Entry(std::string name, Mesh mesh, MeshRepair needs, std::vector<Mesh> intended = {}) {
  return BrokenMesh{std::move(name), std::move(mesh), needs, std::move(intended)};
}

// A CAD-like COLLADA export of three bodies, one node each, exported by assimp and read back
// by ParseMesh: a unit box; a unit box beside it, turned a quarter about x through its centre
// (its wall x = 1 lies on the first box's, its other vertices off by the float rotation's
// rounding, about 4e-8), and a sphere of radius 0.3 cracked 1e-6 wide, over the seam. The
// file's floats stand in for the doubles.
Mesh ColladaAssembly() {
  const Mesh box = UnitCube();
  const Mesh sphere = CrackedSphere(1e-6, 0.3);
  const Eigen::Affine3d turned(Eigen::Translation3d(1.5, 0.5, 0.5) *
                               Eigen::AngleAxisd(M_PI / 2, Vector3::UnitX()) *
                               Eigen::Translation3d(-0.5, -0.5, -0.5));
  const Eigen::Matrix4d beside = turned.matrix();
  Eigen::Matrix4d above = Eigen::Matrix4d::Identity();
  above.block<3, 1>(0, 3) = Vector3(1.0, 0.5, 1.1);
  const std::unique_ptr<aiScene> scene =
      MakeScene({box, sphere}, {{0, Eigen::Matrix4d::Identity()}, {0, beside}, {1, above}});
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), "collada");
  if (blob == nullptr) return Mesh{};
  absl::StatusOr<Mesh> read =
      ParseMesh(std::string(static_cast<const char*>(blob->data), blob->size), "dae");
  return read.ok() ? *std::move(read) : Mesh{};
}

}  // namespace

Mesh CrackedSphere(double gap, double radius) {
  const Mesh sphere = Icosphere(2, Vector3::Zero(), radius);
  const Vector3 direction = Vector3(1.0, 0.3, 0.2).normalized();
  std::vector<char> upper(static_cast<std::size_t>(sphere.num_triangles()));
  std::vector<char> in_upper(static_cast<std::size_t>(sphere.num_vertices()), 0);
  std::vector<char> in_lower(static_cast<std::size_t>(sphere.num_vertices()), 0);
  for (Eigen::Index t = 0; t < sphere.triangles.rows(); ++t) {
    double z = 0.0;
    for (int k = 0; k < 3; ++k) z += sphere.vertices(sphere.triangles(t, k), 2) / 3.0;
    upper[t] = z > 0.1 * radius;
    for (int k = 0; k < 3; ++k) (upper[t] ? in_upper : in_lower)[sphere.triangles(t, k)] = 1;
  }
  Mesh out;
  std::vector<std::int32_t> copy(static_cast<std::size_t>(sphere.num_vertices()), -1);
  Eigen::Index extra = 0;
  for (std::size_t v = 0; v < copy.size(); ++v) {
    if (in_upper[v] && in_lower[v])
      copy[v] = static_cast<std::int32_t>(sphere.num_vertices() + extra++);
  }
  out.vertices.resize(sphere.num_vertices() + extra, 3);
  out.vertices.topRows(sphere.num_vertices()) = sphere.vertices;
  for (std::size_t v = 0; v < copy.size(); ++v) {
    if (copy[v] < 0) continue;
    out.vertices.row(copy[v]) =
        sphere.vertices.row(static_cast<Eigen::Index>(v)) + gap * direction.transpose();
  }
  out.triangles = sphere.triangles;
  for (Eigen::Index t = 0; t < out.triangles.rows(); ++t) {
    if (!upper[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = out.triangles(t, k);
      if (copy[v] >= 0) out.triangles(t, k) = copy[v];
    }
  }
  return out;
}

Mesh BoxesSharingAWall() {
  const Mesh a = UnitCube();
  // The mirror image of `a` in the plane x = 1, orientation restored, sharing `a`'s vertices
  // on that plane: its face x = 1 is `a`'s, corner for corner, in the opposite order.
  Mesh b = a;
  b.vertices.col(0) = (2.0 - a.vertices.col(0).array()).matrix();
  b = Inverted(std::move(b));
  Mesh both = Concatenate(a, b);
  const Eigen::Index n = a.num_vertices();
  for (Eigen::Index t = a.num_triangles(); t < both.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = both.triangles(t, k);
      if (both.vertices(v, 0) == 1.0) both.triangles(t, k) = v - static_cast<std::int32_t>(n);
    }
  }
  return both;
}

std::vector<BrokenMesh> BrokenMeshCorpus() {
  std::vector<BrokenMesh> corpus;
  const Mesh cube = UnitCube();
  const Mesh sphere = Icosphere(2);
  corpus.push_back(Entry("clean-cube", cube, MeshRepair::kNone, {cube}));
  corpus.push_back(Entry("inverted-cube", Inverted(cube), MeshRepair::kNone, {cube}));
  {
    Mesh mixed = sphere;
    for (Eigen::Index t = 0; t < mixed.triangles.rows(); t += 3) {
      std::swap(mixed.triangles(t, 1), mixed.triangles(t, 2));
    }
    corpus.push_back(Entry("mixed-orientation-sphere", mixed, MeshRepair::kNone, {sphere}));
  }
  const Mesh other = Box(Vector3(0.5, 0.25, 0.25), Vector3(1.5, 1.25, 1.25));
  corpus.push_back(
      Entry("overlapping-boxes", Concatenate(cube, other), MeshRepair::kNone, {cube, other}));
  corpus.push_back(
      Entry("per-face-vertices-cube", PerFaceVertices(cube), MeshRepair::kNone, {cube}));
  {
    // An exporter that rounds each face's copy of a vertex differently: every edge a border.
    Mesh jitter = PerFaceVertices(sphere);
    for (Eigen::Index v = 0; v < jitter.vertices.rows(); ++v) {
      jitter.vertices(v, 0) += 1e-7 * std::sin(3.0 * static_cast<double>(v));
      jitter.vertices(v, 1) += 1e-7 * std::cos(5.0 * static_cast<double>(v));
    }
    corpus.push_back(Entry("per-face-vertices-jittered", jitter, MeshRepair::kSafe, {sphere}));
  }
  for (const double fraction : {1e-9, 1e-7, 1e-5, 1e-4}) {
    // Size: the sphere's diameter, 2.
    corpus.push_back(
        Entry("crack-1e" + std::to_string(static_cast<int>(std::round(std::log10(fraction)))),
              CrackedSphere(2.0 * fraction), MeshRepair::kSafe, {sphere}));
  }
  corpus.push_back(Entry("crack-millimetres", CrackedSphere(2000.0 * 1e-5, 1000.0),
                         MeshRepair::kSafe, {Icosphere(2, Vector3::Zero(), 1000.0)}));
  const Mesh long_box = Box(Vector3::Zero(), Vector3(2, 1, 1));
  corpus.push_back(Entry("double-wall", BoxesSharingAWall(), MeshRepair::kSafe, {long_box}));
  {
    Mesh repeated = BoxesSharingAWall();
    repeated.triangles.conservativeResize(repeated.num_triangles() + 1, 3);
    repeated.triangles.row(repeated.num_triangles() - 1) = repeated.triangles.row(3);
    corpus.push_back(Entry("double-wall-and-duplicate", repeated, MeshRepair::kSafe, {long_box}));
  }
  {
    // Three triangles stored twice, same corners, same order.
    Mesh repeated = cube;
    repeated.triangles.conservativeResize(cube.num_triangles() + 3, 3);
    repeated.triangles.bottomRows(3) = cube.triangles.topRows(3);
    corpus.push_back(Entry("duplicate-triangles-cube", repeated, MeshRepair::kSafe, {cube}));
  }
  corpus.push_back(Entry("faces-removed-cube", OpenUnitCube(), MeshRepair::kFill, {cube}));
  corpus.push_back(Entry("faces-removed-sphere", WithoutTriangles(sphere, {5, 77, 200}),
                         MeshRepair::kFill, {sphere}));
  {
    // A cup: the box without its top face (a square hole of 4 border edges).
    const Mesh cup = WithoutTriangles(cube, {});
    std::vector<Eigen::Index> top;
    for (Eigen::Index t = 0; t < cube.triangles.rows(); ++t) {
      bool all_top = true;
      for (int k = 0; k < 3; ++k)
        all_top = all_top && cube.vertices(cube.triangles(t, k), 2) == 1.0;
      if (all_top) top.push_back(t);
    }
    corpus.push_back(Entry("open-cup", WithoutTriangles(cup, top), MeshRepair::kFill, {cube}));
    corpus.push_back(Entry("open-cup-millimetres", Scaled(WithoutTriangles(cup, top), 1000.0),
                           MeshRepair::kFill, {Scaled(cube, 1000.0)}));
  }
  corpus.push_back(Entry("collada-three-nodes", ColladaAssembly(), MeshRepair::kSafe,
                         {long_box, Icosphere(2, Vector3(1.0, 0.5, 1.1), 0.3)}));
  corpus.push_back(Entry("lone-sheet", Square(), MeshRepair::kWrap));
  corpus.push_back(
      Entry("sheet-stored-twice", Concatenate(Square(), Inverted(Square())), MeshRepair::kWrap));
  {
    // A fin: one triangle hanging off an edge of the cube, which three triangles then share.
    Mesh fin = cube;
    const Eigen::Index t0 = 0;
    const std::int32_t a = fin.triangles(t0, 0), b = fin.triangles(t0, 1);
    fin.vertices.conservativeResize(fin.num_vertices() + 1, 3);
    fin.vertices.row(fin.num_vertices() - 1) =
        (fin.vertices.row(a) + fin.vertices.row(b)) / 2 + Eigen::RowVector3d(0.3, 0.2, -0.4);
    fin.triangles.conservativeResize(fin.num_triangles() + 1, 3);
    fin.triangles.row(fin.num_triangles() - 1) << a, b, fin.num_vertices() - 1;
    corpus.push_back(Entry("non-manifold-fin", fin, MeshRepair::kWrap));
  }
  return corpus;
}

std::string BrokenMeshTestName(int index) {
  std::string name = BrokenMeshCorpus()[static_cast<std::size_t>(index)].name;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

}  // namespace inscribe::testing
