// libFuzzer target: the inside test of multi-shell assemblies. Bytes become up to six shells
// (boxes, tetrahedra, octahedra; placed freely, nested as scaled copies of an earlier shell,
// overlapping one, or touching one at a vertex, by shared index or by a coincident copy;
// rotated or not; given in either orientation), then up to 48 points (anywhere in the box
// around them, at shell centres, near vertices, near faces). PrepareSolid, then Classify at
// each point against the brute-force winding number of the validated mesh
// (tests/support/winding_oracle.h, which shares no code with core), skipping points it cannot
// decide (too close to a triangle). Also, when every shell's nesting is clear (each shell's
// vertices plainly inside or outside each other shell, all convex), the validated mesh's
// winding must be nonzero where that of the shells as meant is: each shell outward when an
// even number of others enclose it, a cavity when an odd number do. Findings abort: a point
// classified against the winding number, a shell oriented against the nesting rule.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/solid/solid.h"
#include "support/synthetic_meshes.h"
#include "support/winding_oracle.h"

namespace {

using inscribe::Mesh;
using inscribe::Vector3;
using inscribe::testing::WindingOracle;
using inscribe::testing::WindingSample;

constexpr int kMaxShells = 6;
constexpr int kMaxPoints = 48;

// The input as a stream of bytes, 0 once exhausted.
class ByteStream {
 public:
  ByteStream(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t Next() { return position_ < size_ ? data_[position_++] : 0; }
  bool empty() const { return position_ >= size_; }
  // A multiple of 1/8 in [-2, 2]: shells on this grid touch and coincide exactly.
  double GridCoordinate() { return (Next() % 33 - 16) / 8.0; }
  Vector3 GridPoint() {
    const double x = GridCoordinate(), y = GridCoordinate();
    return Vector3(x, y, GridCoordinate());
  }
  // A step in {-1, 0, 1}^3.
  Vector3 UnitStep() {
    const int b = Next();
    return Vector3(b % 3 - 1, b / 3 % 3 - 1, b / 9 % 3 - 1);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

struct Shell {
  Mesh outward;  // oriented outward (or flat), own vertex numbering
  bool given_inverted = false;
  int shared_vertex = -1;       // this shell's vertex that is an earlier shell's vertex, by index
  int shared_with_shell = -1;   //   that earlier shell
  int shared_with_vertex = -1;  //   and its vertex
  const char* how = "free";
};

Vector3 Centroid(const Mesh& mesh) { return mesh.vertices.colwise().mean().transpose(); }

Mesh Rotated(Mesh mesh, const Eigen::Quaterniond& q, const Vector3& about) {
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    mesh.vertices.row(v) = (q * (mesh.vertices.row(v).transpose() - about) + about).transpose();
  }
  return mesh;
}

// A shell of kind 0 (box), 1 (tetrahedron from byte-chosen corner steps), 2 (octahedron),
// centred near `centre` with half-size `half`.
Mesh MakeShell(int kind, const Vector3& centre, double half, ByteStream& bytes) {
  switch (kind) {
    case 0:
      return inscribe::testing::Box(centre - Vector3::Constant(half),
                                    centre + Vector3::Constant(half));
    case 1: {
      // Corners of the cube [-1, 1]^3 (times half, about centre), three of them moved by a step
      // in {-1, 0, 1}^3 from the bytes: coplanar corners (a flat shell of four zero-area
      // triangles) and coincident ones occur.
      const Vector3 a = centre + half * Vector3(-1, -1, -1);
      const Vector3 b = centre + half * (Vector3(1, -1, -1) + bytes.UnitStep());
      const Vector3 c = centre + half * (Vector3(-1, 1, -1) + bytes.UnitStep());
      const Vector3 d = centre + half * (Vector3(-1, -1, 1) + bytes.UnitStep());
      return inscribe::testing::Tetrahedron(a, b, c, d);
    }
    default:
      return inscribe::testing::Octahedron(centre, half);
  }
}

std::vector<Shell> ReadShells(ByteStream& bytes) {
  std::vector<Shell> shells;
  const int count = 1 + bytes.Next() % kMaxShells;
  for (int i = 0; i < count; ++i) {
    const std::uint8_t flags = bytes.Next();
    const int kind = flags % 3;
    const int relation = i == 0 ? 0 : (flags >> 2) & 3;
    const bool rotate = (flags & 0x40) != 0;
    Shell shell;
    shell.given_inverted = (flags & 0x10) != 0;
    const Shell* parent = i == 0 ? nullptr : &shells[bytes.Next() % shells.size()];
    const double half = (1 + bytes.Next() % 12) / 8.0;
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    if (rotate) {
      q = Eigen::Quaterniond(bytes.Next() - 127.5, bytes.Next() - 127.5, bytes.Next() - 127.5,
                             bytes.Next() - 127.5);
      q.normalize();
    }
    if (relation == 1) {
      // Nested: a copy of the parent scaled about its centroid by 1/8 .. 7/8 (strictly inside
      // a convex parent with volume), moved by up to a sixteenth of its size.
      const double f = (1 + bytes.Next() % 7) / 8.0;
      const Vector3 c = Centroid(parent->outward);
      shell.outward = parent->outward;
      shell.outward.vertices.rowwise() -= c.transpose();
      shell.outward.vertices *= f;
      shell.outward.vertices.rowwise() += c.transpose();
      shell.how = "nested";
    } else if (relation == 2) {
      // Touching: this shell's vertex j placed on the parent's vertex k, exactly.
      Mesh local = MakeShell(kind, Vector3::Zero(), half, bytes);
      const int j = bytes.Next() % static_cast<int>(local.num_vertices());
      const int k = bytes.Next() % static_cast<int>(parent->outward.num_vertices());
      const Vector3 own = local.vertices.row(j).transpose();
      const Vector3 target = parent->outward.vertices.row(k).transpose();
      for (Eigen::Index v = 0; v < local.vertices.rows(); ++v) {
        local.vertices.row(v) =
            (q * (local.vertices.row(v).transpose() - own) + target).transpose();
      }
      shell.outward = local;
      if (bytes.Next() % 2 == 0) {
        shell.shared_vertex = j;
        shell.shared_with_shell = static_cast<int>(parent - shells.data());
        shell.shared_with_vertex = k;
        shell.how = "touching (shared vertex)";
      } else {
        shell.how = "touching (coincident vertex)";
      }
    } else {
      const Vector3 centre =
          relation == 3 ? Centroid(parent->outward) + 0.25 * bytes.GridPoint() : bytes.GridPoint();
      shell.outward = Rotated(MakeShell(kind, centre, half, bytes), q, centre);
      shell.how = relation == 3 ? "overlapping" : "free";
    }
    shells.push_back(std::move(shell));
  }
  return shells;
}

// The shells as one mesh, each oriented by `inverted[s]` (relative to outward), the shared
// vertices merged into the earlier shell's.
Mesh Combine(const std::vector<Shell>& shells, const std::vector<bool>& inverted) {
  Mesh out;
  std::vector<std::vector<std::int32_t>> index(shells.size());
  std::vector<Vector3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
  for (std::size_t s = 0; s < shells.size(); ++s) {
    const Shell& shell = shells[s];
    for (Eigen::Index v = 0; v < shell.outward.num_vertices(); ++v) {
      if (v == shell.shared_vertex) {
        index[s].push_back(index[static_cast<std::size_t>(shell.shared_with_shell)]
                                [static_cast<std::size_t>(shell.shared_with_vertex)]);
      } else {
        index[s].push_back(static_cast<std::int32_t>(vertices.size()));
        vertices.push_back(shell.outward.vertices.row(v).transpose());
      }
    }
    for (Eigen::Index t = 0; t < shell.outward.num_triangles(); ++t) {
      std::array<std::int32_t, 3> tri;
      for (int k = 0; k < 3; ++k) tri[k] = index[s][shell.outward.triangles(t, k)];
      if (inverted[s]) std::swap(tri[1], tri[2]);
      triangles.push_back(tri);
    }
  }
  out.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    out.vertices.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  }
  out.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) out.triangles(static_cast<Eigen::Index>(t), k) = triangles[t][k];
  }
  return out;
}

// Per shell: inside out as meant (enclosed by an odd number of others). Empty when some
// shell's nesting is unclear: a vertex the brute force cannot place in another shell while
// its other vertices do not put it plainly outside.
std::vector<bool> MeantInverted(const std::vector<Shell>& shells) {
  std::vector<WindingOracle> alone;
  for (const Shell& s : shells) alone.emplace_back(s.outward);
  std::vector<bool> inverted(shells.size());
  for (std::size_t c = 0; c < shells.size(); ++c) {
    int depth = 0;
    for (std::size_t o = 0; o < shells.size(); ++o) {
      if (o == c) continue;
      bool all_inside = true, some_outside = false, some_unclear = false;
      for (Eigen::Index v = 0; v < shells[c].outward.num_vertices(); ++v) {
        const WindingSample w = alone[o].At(shells[c].outward.vertices.row(v).transpose());
        if (!w.reliable) {
          some_unclear = true;
          all_inside = false;
        } else if (w.winding == 0) {
          some_outside = true;
          all_inside = false;
        } else if (w.winding != 1) {
          return {};  // a shell that is not a simple closed surface
        }
      }
      if (some_unclear && !some_outside) return {};
      depth += all_inside;
    }
    inverted[c] = depth % 2 == 1;
  }
  return inverted;
}

std::vector<Vector3> ReadPoints(ByteStream& bytes, const std::vector<Shell>& shells,
                                const Mesh& mesh) {
  const inscribe::BoundingBox box = inscribe::ComputeBoundingBox(mesh.vertices);
  const double diagonal = box.diagonal();
  const Vector3 lo = box.min - Vector3::Constant(0.1 * diagonal);
  const Vector3 span = box.extent() + Vector3::Constant(0.2 * diagonal);
  std::vector<Vector3> points;
  for (const Shell& s : shells) points.push_back(Centroid(s.outward));
  while (!bytes.empty() && static_cast<int>(points.size()) < kMaxPoints) {
    const std::uint8_t mode = bytes.Next();
    if (mode % 3 == 0) {
      Vector3 p;
      for (int k = 0; k < 3; ++k) p[k] = lo[k] + span[k] * (bytes.Next() / 255.0);
      points.push_back(p);
    } else if (mode % 3 == 1) {
      // Near a vertex: along a byte-chosen step, 2^-(0..31) of the diagonal away.
      const Eigen::Index v = bytes.Next() % mesh.num_vertices();
      const Vector3 step = bytes.UnitStep();
      const double length = diagonal * std::ldexp(1.0, -(mode / 3 % 32));
      points.push_back(mesh.vertices.row(v).transpose() + length * step);
    } else {
      // Near a face: a point of triangle t moved along its normal by +-2^-(0..40) of the
      // diagonal.
      const Eigen::Index t = bytes.Next() % mesh.num_triangles();
      const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
      const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
      const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
      double s = bytes.Next() / 255.0, r = bytes.Next() / 255.0;
      if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
      const Vector3 n = (b - a).cross(c - a);
      const double n_norm = n.norm();
      const std::uint8_t e = bytes.Next();
      const double length = diagonal * std::ldexp(1.0, -(e % 41)) * (e & 0x80 ? -1.0 : 1.0);
      points.push_back(a + s * (b - a) + r * (c - a) + (n_norm > 0 ? length / n_norm : 0.0) * n);
    }
  }
  return points;
}

[[noreturn]] void Fail(const char* what, const std::vector<Shell>& shells,
                       const std::vector<bool>& meant_inverted, const inscribe::Solid& solid,
                       const Vector3& p, const WindingSample& w, const char* side) {
  std::fprintf(stderr,
               "fuzz_assembly: %s\n  at (%.17g, %.17g, %.17g): winding %d (sum %.12g), %s\n", what,
               p.x(), p.y(), p.z(), w.winding, w.raw, side);
  std::fprintf(stderr,
               "  report: %lld components, %lld self-intersecting pairs (checked %d), %lld "
               "non-manifold vertices, %lld degenerate triangles\n",
               static_cast<long long>(solid.report.components),
               static_cast<long long>(solid.report.self_intersecting_pairs),
               solid.report.self_intersections_checked ? 1 : 0,
               static_cast<long long>(solid.report.non_manifold_vertices),
               static_cast<long long>(solid.report.degenerate_triangles));
  for (std::size_t i = 0; i < shells.size(); ++i) {
    const Shell& s = shells[i];
    const inscribe::BoundingBox box = inscribe::ComputeBoundingBox(s.outward.vertices);
    std::fprintf(stderr, "  shell %zu: %lld vertices in [%g, %g] x [%g, %g] x [%g, %g], %s%s%s\n",
                 i, static_cast<long long>(s.outward.num_vertices()), box.min.x(), box.max.x(),
                 box.min.y(), box.max.y(), box.min.z(), box.max.z(), s.how,
                 s.given_inverted ? ", given inside out" : "",
                 meant_inverted.empty() ? ""
                 : meant_inverted[i]    ? ", a cavity as meant"
                                        : ", outward as meant");
    for (Eigen::Index v = 0; v < s.outward.num_vertices(); ++v) {
      std::fprintf(stderr, "    vertex %lld: (%.17g, %.17g, %.17g)\n", static_cast<long long>(v),
                   s.outward.vertices(v, 0), s.outward.vertices(v, 1), s.outward.vertices(v, 2));
    }
  }
  std::abort();
}

const char* SideName(inscribe::Side side) {
  return side == inscribe::Side::kInside    ? "Classify: inside"
         : side == inscribe::Side::kOutside ? "Classify: outside"
                                            : "Classify: on boundary";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteStream bytes(data, size);
  const std::vector<Shell> shells = ReadShells(bytes);
  std::vector<bool> given(shells.size());
  for (std::size_t s = 0; s < shells.size(); ++s) given[s] = shells[s].given_inverted;
  const Mesh input = Combine(shells, given);
  const std::vector<Vector3> points = ReadPoints(bytes, shells, input);

  absl::StatusOr<inscribe::Solid> solid = inscribe::PrepareSolid(input);
  if (!solid.ok()) return 0;  // e.g. no volume left, shells sharing an edge
  const WindingOracle validated(solid->mesh());
  const std::vector<bool> meant_inverted = MeantInverted(shells);
  std::optional<WindingOracle> meant;
  if (!meant_inverted.empty()) meant.emplace(Combine(shells, meant_inverted));

  for (const Vector3& p : points) {
    const WindingSample w = validated.At(p);
    if (w.reliable) {
      const inscribe::Side side = solid->oracle.Classify(p);
      if (side != (w.inside() ? inscribe::Side::kInside : inscribe::Side::kOutside)) {
        Fail("Classify disagrees with the winding number of the validated mesh", shells,
             meant_inverted, *solid, p, w, SideName(side));
      }
    }
    if (meant) {
      const WindingSample m = meant->At(p);
      if (m.reliable && w.reliable && m.inside() != w.inside()) {
        Fail(
            "validation oriented a shell against the nesting rule (winding of the shells as "
            "meant shown)",
            shells, meant_inverted, *solid, p, m,
            w.inside() ? "validated mesh: inside" : "validated mesh: outside");
      }
    }
  }
  return 0;
}
