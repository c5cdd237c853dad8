// CGAL is confined to this file and the other core/src/*.cpp that need it.
#include "inscribe/mesh/mesh_io.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OBJ.h>
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <sstream>
#include <streambuf>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "inscribe/base/atomic_file.h"
#include "mesh/assimp_import.h"
#include "mesh/mesh_file_diagnosis.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Polygon = std::vector<std::size_t>;

std::string Lowercase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// A read-only stream buffer over bytes held elsewhere, with the seeking CGAL's readers use (the
// STL reader looks ahead to tell ASCII from binary); std::istringstream would copy the bytes.
class BytesBuffer : public std::streambuf {
 public:
  explicit BytesBuffer(const std::string& bytes) {
    char* const begin = const_cast<char*>(bytes.data());  // read only: no put area
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                   std::ios_base::openmode which) override {
    if ((which & std::ios_base::in) == 0) return pos_type(off_type(-1));
    const off_type base = dir == std::ios_base::beg   ? 0
                          : dir == std::ios_base::cur ? gptr() - eback()
                                                      : egptr() - eback();
    const off_type target = base + off;
    if (target < 0 || target > egptr() - eback()) return pos_type(off_type(-1));
    setg(eback(), eback() + target, egptr());
    return pos_type(target);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

bool ReadSoup(std::istream& in, const std::string& format, std::vector<Point>& points,
              std::vector<Polygon>& polygons) {
  // Some of CGAL's readers print to std::cerr unless told not to; library code never prints.
  const auto quiet = CGAL::parameters::verbose(false);
  if (format == "off") return CGAL::IO::read_OFF(in, points, polygons, quiet);
  if (format == "obj") return CGAL::IO::read_OBJ(in, points, polygons, quiet);
  if (format == "ply") return CGAL::IO::read_PLY(in, points, polygons, quiet);
  if (format == "stl") {
    std::vector<std::array<std::size_t, 3>> facets;
    if (!CGAL::IO::read_STL(in, points, facets, quiet)) return false;
    polygons.reserve(facets.size());
    for (const auto& f : facets) polygons.push_back({f[0], f[1], f[2]});
    return true;
  }
  return false;
}

bool IsFinite(const Point& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

// Splits a polygon of n > 3 corners into n - 2 triangles. CGAL's hole filling handles
// non-convex and non-planar polygons; a fan is the fallback when it finds no triangulation or
// the corners cannot be used (bad index or coordinate: validation reports those later).
void Triangulate(const Polygon& polygon, const std::vector<Point>& points,
                 std::vector<std::array<std::int64_t, 3>>& out) {
  bool usable = true;
  // Beyond kMaxMeshCoordinate CGAL's projections overflow (GMP aborts on the infinity);
  // validation refuses such meshes anyway.
  for (std::size_t v : polygon) {
    usable = usable && v < points.size() && IsFinite(points[v]) &&
             std::abs(points[v].x()) <= kMaxMeshCoordinate &&
             std::abs(points[v].y()) <= kMaxMeshCoordinate &&
             std::abs(points[v].z()) <= kMaxMeshCoordinate;
  }
  if (usable) {
    std::vector<Point> ring;
    ring.reserve(polygon.size());
    for (std::size_t v : polygon) ring.push_back(points[v]);
    std::vector<CGAL::Triple<int, int, int>> patch;
    try {
      CGAL::Polygon_mesh_processing::triangulate_hole_polyline(ring, std::back_inserter(patch));
    } catch (const std::exception&) {
      patch.clear();
    }
    if (patch.size() == polygon.size() - 2) {
      for (const auto& t : patch) {
        out.push_back({static_cast<std::int64_t>(polygon[t.first]),
                       static_cast<std::int64_t>(polygon[t.second]),
                       static_cast<std::int64_t>(polygon[t.third])});
      }
      return;
    }
  }
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    out.push_back({static_cast<std::int64_t>(polygon[0]), static_cast<std::int64_t>(polygon[i]),
                   static_cast<std::int64_t>(polygon[i + 1])});
  }
}

absl::StatusOr<Mesh> SoupToMesh(const std::vector<Point>& points,
                                const std::vector<Polygon>& polygons, const std::string& bytes,
                                const std::string& format, const std::string& what,
                                ReadMeshInfo* info) {
  constexpr std::int64_t kMaxIndex = std::numeric_limits<std::int32_t>::max();
  if (static_cast<std::int64_t>(points.size()) > kMaxIndex) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": ", points.size(), " vertices is more than inscribe supports (", kMaxIndex, ")"));
  }
  std::vector<std::array<std::int64_t, 3>> triangles;
  triangles.reserve(polygons.size());
  std::int64_t triangulated = 0;
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const Polygon& polygon = polygons[f];
    if (polygon.size() < 3) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": face ", f, " has ", polygon.size(),
                                                     " corners; a face needs at least 3"));
    }
    for (std::size_t corner : polygon) {
      if (corner >= points.size()) {
        std::string why = internal::DiagnoseMeshText(bytes, format);
        if (why.empty()) {
          why = absl::StrCat("face ", f, " refers to vertex ", corner, ", but the file has ",
                             points.size(), " vertices (0-based)");
        }
        return absl::InvalidArgumentError(absl::StrCat(what, ": ", why));
      }
    }
    if (polygon.size() == 3) {
      triangles.push_back({static_cast<std::int64_t>(polygon[0]),
                           static_cast<std::int64_t>(polygon[1]),
                           static_cast<std::int64_t>(polygon[2])});
    } else {
      ++triangulated;
      Triangulate(polygon, points, triangles);
    }
  }
  if (static_cast<std::int64_t>(triangles.size()) > kMaxIndex) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": ", triangles.size(), " triangles is more than inscribe supports"));
  }
  Mesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    mesh.vertices(row, 0) = points[i].x();
    mesh.vertices(row, 1) = points[i].y();
    mesh.vertices(row, 2) = points[i].z();
  }
  // Indices beyond int32 are clamped to -1 so that they stay out of range for validation
  // rather than wrapping onto a real vertex.
  mesh.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t v = triangles[t][k];
      mesh.triangles(static_cast<Eigen::Index>(t), k) =
          v > kMaxIndex ? -1 : static_cast<std::int32_t>(v);
    }
  }
  if (info != nullptr) {
    info->polygons = static_cast<std::int64_t>(polygons.size());
    info->polygons_triangulated = triangulated;
  }
  return mesh;
}

absl::StatusOr<Mesh> ParseNamed(const std::string& bytes, const std::string& format,
                                const std::string& what, ReadMeshInfo* info) {
  if (internal::IsSceneFormat(format)) {
    return internal::ImportSceneBytes(bytes, format, what, info);
  }
  if (format != "off" && format != "obj" && format != "stl" && format != "ply") {
    return absl::InvalidArgumentError(absl::StrCat(what, ": unsupported mesh format '", format,
                                                   "' (expected off, obj, stl, ply, dae, gltf or "
                                                   "glb)"));
  }
  if (bytes.find_first_not_of(" \t\r\n") == std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": file is empty"));
  }
  if (format == "off") {
    if (std::string why = internal::CheckOffCounts(bytes); !why.empty()) {
      // For a short file, the line-by-line diagnosis says more precisely where it ends.
      if (absl::StrContains(why, "(truncated?)")) {
        if (std::string detail = internal::DiagnoseMeshText(bytes, format); !detail.empty()) {
          why = std::move(detail);
        }
      }
      return absl::InvalidArgumentError(absl::StrCat(what, ": not a valid off file: ", why));
    }
  }
  if (format == "ply") {
    if (std::string why = internal::CheckPlyHeader(bytes); !why.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": not a valid ply file: ", why));
    }
  }
  std::vector<Point> points;
  std::vector<Polygon> polygons;
  bool ok = false;
  try {
    BytesBuffer buffer(bytes);
    std::istream in(&buffer);
    ok = ReadSoup(in, format, points, polygons);
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": not a valid ", Lowercase(format), " file (", e.what(), ")"));
  }
  if (!ok) {
    std::string why = internal::DiagnoseMeshText(bytes, format);
    if (why.empty()) why = "the reader stopped on malformed or truncated data";
    return absl::InvalidArgumentError(absl::StrCat(what, ": not a valid ", format, " file: ", why));
  }
  if (points.empty() || polygons.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": no ", points.empty() ? "vertices" : "faces", " found in the ", format, " file"));
  }
  return SoupToMesh(points, polygons, bytes, format, what, info);
}

}  // namespace

absl::StatusOr<Mesh> ParseMesh(const std::string& bytes, const std::string& format,
                               ReadMeshInfo* info) {
  const std::string fmt = Lowercase(format);
  return ParseNamed(bytes, fmt, absl::StrCat(fmt, " data"), info);
}

absl::StatusOr<Mesh> ReadMesh(const std::string& path, ReadMeshInfo* info) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    return absl::NotFoundError(absl::StrCat(path, ": no such file"));
  }
  if (fs::is_directory(status)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": is a directory, not a mesh file"));
  }
  std::string ext = Lowercase(fs::path(path).extension().string());
  if (!ext.empty()) ext.erase(0, 1);
  if (ext != "off" && ext != "obj" && ext != "stl" && ext != "ply" &&
      !internal::IsSceneFormat(ext)) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": unsupported mesh format '", ext.empty() ? std::string("(no extension)") : ext,
        "' (expected .off, .obj, .stl, .ply, .dae, .gltf or .glb)"));
  }
  if (internal::IsSceneFormat(ext)) {
    // assimp reads the file itself: a .gltf may name its buffers as sibling files.
    if (fs::file_size(path, ec) == 0 && !ec) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": file is empty"));
    }
    return internal::ImportSceneFile(path, info);
  }
  std::ifstream file(path, std::ios::in | std::ios::binary);
  if (!file) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": cannot open (", std::strerror(errno), ")"));
  }
  // Read in one piece into a string of the file's size (a stream copy would grow it, then copy).
  std::string bytes;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec) {
    bytes.resize(static_cast<std::size_t>(size));
    file.read(bytes.data(), static_cast<std::streamsize>(size));
    bytes.resize(static_cast<std::size_t>(file.gcount()));
  }
  if (file.bad()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": read error"));
  }
  // A file that grew while read, or whose size the file system does not report, is read on.
  if (ec || file.gcount() == static_cast<std::streamsize>(size)) {
    file.clear();
    std::ostringstream rest;
    rest << file.rdbuf();
    bytes += rest.str();
  }
  return ParseNamed(bytes, ext, path, info);
}

absl::Status WriteMesh(const std::string& path, const Mesh& mesh) {
  const std::string ext = Lowercase(std::filesystem::path(path).extension().string());
  if (ext != ".off" && ext != ".obj" && ext != ".ply" && ext != ".stl") {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": cannot write mesh format '", ext.empty() ? std::string("(no extension)") : ext,
        "' (use .off, .obj, .ply or .stl)"));
  }
  if (!mesh.vertices.allFinite()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": the mesh has non-finite coordinates"));
  }
  if (mesh.num_triangles() > 0 &&
      (mesh.triangles.minCoeff() < 0 || mesh.triangles.maxCoeff() >= mesh.num_vertices())) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": the mesh has triangle corners naming no vertex"));
  }
  std::vector<Point> points;
  points.reserve(static_cast<std::size_t>(mesh.num_vertices()));
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    points.emplace_back(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
  }
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(static_cast<std::size_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    faces.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                     static_cast<std::size_t>(mesh.triangles(t, 1)),
                     static_cast<std::size_t>(mesh.triangles(t, 2))});
  }
  std::ostringstream out;
  const auto np = CGAL::parameters::stream_precision(17).use_binary_mode(false);
  bool ok = false;
  if (ext == ".off") ok = CGAL::IO::write_OFF(out, points, faces, np);
  if (ext == ".obj") ok = CGAL::IO::write_OBJ(out, points, faces, np);
  if (ext == ".ply") ok = CGAL::IO::write_PLY(out, points, faces, np);
  if (ext == ".stl") ok = CGAL::IO::write_STL(out, points, faces, np);
  if (!ok) return absl::InternalError(absl::StrCat(path, ": CGAL could not format the mesh"));
  return WriteFileAtomically(path, out.str());
}

}  // namespace inscribe
