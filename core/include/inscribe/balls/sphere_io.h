// Sphere-set files: inscribe's own JSON (read + write), spheretree `.sph` (read + write), CSV
// `x,y,z,r` (read + write), cuRobo-style YAML `collision_spheres` (read + write, one link or
// many), and, for viewing, OBJ meshes of the spheres (write only). Coordinates and radii are in the
// mesh's own units and frame.
//
// Every reader refuses bad input with INVALID_ARGUMENT and a message naming the line or the
// index and the problem (`line 4: expected 4 numbers x,y,z,r, found 3`, `sphere 12: radius -1
// is not positive`); no reader allocates from a count the file declares. Spheres read back are
// always finite with radius > 0, and contacts are empty or one per sphere.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

enum class SphereFileFormat {
  // {"format": "inscribe.spheres", "version": 1, "mesh_sha256", "params", "spheres",
  //  "contacts", "stats"}: everything in a SphereFile, doubles bit-exact. Read + write.
  // Written one sphere per line; mesh_sha256 and contacts are left out when empty. Readers
  // ignore unknown keys.
  kJson,
  // spheretree (Bradshaw & O'Sullivan) sphere tree: "levels degree", then level by level
  // (level l holds degree^l slots) one "x y z r ..." line per slot; r <= 0 marks an unused
  // slot. Read + write; only spheres survive. Written as spheretree's own flat-set writer
  // does: "2 N", a root sphere around all the others, then the N spheres, "x y z r 1" each.
  kSph,
  // One "x,y,z,r" line per sphere, optional "x,y,z,r" header. Read + write; only spheres.
  kCsv,
  // Each sphere as a triangulated icosphere (vertices on the sphere), for viewers. Write only.
  kObj,
  // cuRobo's robot-configuration YAML: a `collision_spheres:` mapping from link name to a
  // list of {center: [x, y, z], radius: r}. Written for one link (yaml_link_name); read from
  // any cuRobo file (other keys are ignored), one link at a time (yaml_link). cuRobo's
  // placeholder spheres (radius <= 0) are skipped when read. Read + write; only spheres.
  kYaml,
};

// "json", "sph", "csv", "obj", "yaml" (also "yml"); case-insensitive.
absl::StatusOr<SphereFileFormat> ParseSphereFileFormat(absl::string_view name);

// The canonical name: "json", "sph", "csv", "obj" or "yaml".
absl::string_view SphereFileFormatName(SphereFileFormat format);

// From the extension of `path` (.json, .sph, .csv, .obj, .yaml, .yml; case-insensitive).
// INVALID_ARGUMENT for any other extension.
absl::StatusOr<SphereFileFormat> SphereFileFormatFromPath(const std::string& path);

// kJson, kSph, kCsv and kYaml can be read; kObj is write-only.
bool IsReadableSphereFileFormat(SphereFileFormat format);

// A parameter or statistic value; a JSON number with a fraction or exponent is a double, one
// without is an int64 (so 2.0 and 2 keep their types through a round trip).
using ScalarValue = std::variant<bool, std::int64_t, double, std::string>;

// Named values in file order (names are unique when written).
using NamedValues = std::vector<std::pair<std::string, ScalarValue>>;

// What a sphere file holds. Only kJson carries more than `set.spheres`.
struct SphereFile {
  SphereSet set;
  // Content hash of the mesh the spheres approximate ("sha256:" + 64 lowercase hex digits, see
  // FormatSha256), or empty when unknown.
  std::string mesh_sha256;
  // Generation parameters (e.g. voxel_size in mesh units, object_angle in radians).
  NamedValues params;
  // Figures about the run and the result (e.g. seconds, nerr).
  NamedValues stats;
  // A cover's per-sphere protrusion bounds (CoverCertificate::protrusions), empty or one
  // finite value per sphere. Only JSON holds them.
  std::vector<double> protrusions;
};

struct SphereFileReadOptions {
  // The format; when unset, ReadSphereFile takes it from the extension, or for an unknown
  // extension sniffs the bytes ('{' -> json, a first line of two integers -> sph, a comma ->
  // csv). Ignored by ParseSphereFile, which takes the format as an argument.
  std::optional<SphereFileFormat> format;
  // kSph: the tree level to return (0 = the root); -1 returns the deepest level, the leaves
  // that users compare. Either way only slots with radius > 0 are returned, in file order.
  int sph_level = -1;
  // kYaml: the link whose spheres to return. Empty: the file's only link; a file with several
  // links is then refused with a message listing them.
  std::string yaml_link;
};

struct SphereFileWriteOptions {
  // The format; when unset, WriteSphereFile takes it from the extension. Ignored by
  // FormatSphereFile, which takes the format as an argument.
  std::optional<SphereFileFormat> format;
  // kCsv: write the "x,y,z,r" header line first.
  bool csv_header = true;
  // kObj: icosphere subdivision level per sphere, 0..5: 10 * 4^level + 2 vertices and
  // 20 * 4^level triangles each (level 1: 42 and 80).
  int obj_subdivision = 1;
  // kYaml: the link name the spheres are listed under (letters, digits, _ - . /).
  std::string yaml_link_name = "mesh";
};

// The bytes of `file` in `format`. Numbers are written as the shortest decimal that reads
// back as the same double. INVALID_ARGUMENT (naming the sphere, contact or value) when the
// file could not be read back: a non-finite coordinate, a radius <= 0, contacts neither empty
// nor one per sphere, a negative contact triangle or non-finite weight, a malformed
// mesh_sha256, a repeated or non-finite param/stat (kJson), an option out of range.
// Cost O(#spheres), O(#spheres * 4^obj_subdivision) for kObj.
absl::StatusOr<std::string> FormatSphereFile(const SphereFile& file, SphereFileFormat format,
                                             const SphereFileWriteOptions& options = {});

// Parses `bytes` (a whole file) in `format`. INVALID_ARGUMENT for a write-only format and for
// any malformed content; messages start with "<format> data: " (ReadSphereFile puts the path
// there instead). Cost O(size of bytes).
absl::StatusOr<SphereFile> ParseSphereFile(absl::string_view bytes, SphereFileFormat format,
                                           const SphereFileReadOptions& options = {});

// Reads and parses `path`. NOT_FOUND when it does not exist; INVALID_ARGUMENT, with the path
// in the message, for a directory, an unreadable file or malformed content.
absl::StatusOr<SphereFile> ReadSphereFile(const std::string& path,
                                          const SphereFileReadOptions& options = {});

// `file` in units `scale` times larger (e.g. 0.001 for spheres made on a mesh in millimetres,
// to use in metres): centres and radii multiplied by `scale`; contacts kept (they name the
// same triangles of the scaled mesh); the mesh hash, params, stats and protrusions dropped,
// since they describe the unscaled mesh and its generation (a scaled cover is certified again
// against the scaled mesh, e.g. by `evaluate --certify --scale`). INVALID_ARGUMENT for a scale
// that is not finite and > 0 or a sphere that would overflow or vanish. O(#spheres).
absl::StatusOr<SphereFile> ScaledSphereFile(SphereFile file, double scale);

// Formats `file` and writes it to `path` atomically: into a temporary file in the same
// directory, flushed to disk, then renamed over `path`, so readers see the old file or the
// whole new one, never a part. Errors: as FormatSphereFile; NOT_FOUND when the directory does
// not exist; PERMISSION_DENIED; INTERNAL for other I/O failures (message names the path).
absl::Status WriteSphereFile(const std::string& path, const SphereFile& file,
                             const SphereFileWriteOptions& options = {});

// The spheres of one robot link, in the link's frame.
struct LinkSpheres {
  std::string link;  // letters, digits, _ - . / (as URDF link names in practice)
  std::vector<Sphere> spheres;
};

// Whether cuRobo YAML as inscribe writes it carries `name` as a link key: a non-empty run of
// letters, digits and _ - . / (the keys are quoted, so words YAML would resolve to other types,
// such as null or 1, are fine). The one rule FormatCuroboYaml and the robot writers share.
bool IsCuroboLinkName(absl::string_view name);

// cuRobo's `collision_spheres:` YAML for several links, in the order given, under a
// `# comment` header line. INVALID_ARGUMENT naming the link for a bad or repeated link name,
// and naming the link and sphere for a sphere CheckSphere refuses. A link with no spheres is
// written as `link: []`.
absl::StatusOr<std::string> FormatCuroboYaml(const std::vector<LinkSpheres>& links,
                                             absl::string_view comment = "inscribe spheres");

// Every link of a cuRobo YAML's `collision_spheres` mapping, in file order, with spheres of
// radius <= 0 (cuRobo's placeholders) dropped. INVALID_ARGUMENT (with the YAML line) for
// malformed YAML, a missing `collision_spheres` mapping, or a sphere without a 3-number centre
// and a finite radius.
absl::StatusOr<std::vector<LinkSpheres>> ParseCuroboYaml(absl::string_view bytes);

}  // namespace inscribe
