// A robot's sphere set as planners take it: spheres per link, the link pairs self-collision
// checks may skip, and per-link buffers; read from and written to each planner's format. The one
// model `inscribe convert`, `inscribe urdf --format`, `evaluate --certify` and the Python bindings
// go through.
//
// Formats, and what each carries (RobotSpheresFormatCarries):
//   kCurobo   cuRobo's robot configuration fragment (robot_cfg.kinematics keys):
//             collision_link_names, collision_spheres, collision_sphere_buffer,
//             self_collision_ignore, self_collision_buffer. Everything but pair reasons and the
//             robot's name. Read from a fragment or a whole robot file: the keys are looked for
//             beside the first collision_spheres mapping (breadth first).
//   kXrdf     cuMotion's XRDF 1.0: format, format_version, collision {geometry,
//             buffer_distance}, self_collision {geometry, buffer_distance, ignore} and
//             geometry.<group>.spheres. Carries what kCurobo does.
//   kSrdf     MoveIt's SRDF: <link_sphere_approximation link> with <sphere center radius>
//             children, and <disable_collisions link1 link2 reason>. Name, spheres and pairs
//             with reasons; no buffers. Written into an existing SRDF it replaces only those
//             elements for the model's links and pairs and keeps everything else.
//   kUrdf     the spherized URDF VAMP and cricket read: in each link, one <collision> per
//             sphere (origin xyz = centre, <sphere radius>). Name and spheres of links that
//             have spheres; no pairs or buffers.
//   kMorphit  MorphIt's URDF: per sphere k of link L a child link "L_sphere<k>" holding one
//             sphere <collision> and <visual> at its origin, joined to L by the fixed joint
//             "L_to_L_sphere<k>" whose origin is the centre. Read back onto L in L's frame.
//             Carries what kUrdf does.
// All lengths are metres, all centres in their link's frame. Numbers are written as the
// shortest decimal that reads back as the same double, so a model written and read back in
// one format is the same model (up to what the format carries).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::robot {

struct RobotSpheres {
  std::string robot_name;  // may be empty
  // Each link once (non-empty names), in file order. A link may have no spheres.
  std::vector<LinkSpheres> links;
  // Pairs self-collision checks may skip: (a, b) with a < b (byte order), each once, mapped to
  // MoveIt's reason (Adjacent, Default, Always, Never, User, ...) or "" when unknown.
  std::map<std::pair<std::string, std::string>, std::string> self_collision_ignore;
  // Per link, metres (finite; negative shrinks): added to the radii in self-collision checks
  // only, and in checks against the world only. A link not listed has 0.
  std::map<std::string, double> self_collision_buffer;
  std::map<std::string, double> collision_buffer;
};

bool operator==(const RobotSpheres& a, const RobotSpheres& b);

enum class RobotSpheresFormat { kCurobo, kXrdf, kSrdf, kUrdf, kMorphit };

// "curobo", "xrdf", "srdf", "urdf", "morphit".
const char* RobotSpheresFormatName(RobotSpheresFormat format);
// The names above (also "yaml" and "yml" for kCurobo, "vamp" for kUrdf), case-insensitive.
absl::StatusOr<RobotSpheresFormat> ParseRobotSpheresFormat(absl::string_view name);

// By extension: .yml/.yaml kCurobo, .xrdf kXrdf, .srdf kSrdf, .urdf kUrdf (use
// DetectRobotSpheresFormat to tell MorphIt's layout). INVALID_ARGUMENT for others.
absl::StatusOr<RobotSpheresFormat> RobotSpheresFormatFromPath(const std::string& path);

// By content: YAML with `format: xrdf` is kXrdf, other YAML kCurobo; XML with root <robot>
// is kSrdf when it has no <link> children, kMorphit when a link "P_sphere<k>" hangs from link P
// by a fixed joint, else kUrdf. INVALID_ARGUMENT when it is none of these.
absl::StatusOr<RobotSpheresFormat> DetectRobotSpheresFormat(absl::string_view bytes);

struct RobotSpheresFormatParts {
  bool robot_name = false;
  bool empty_links = false;  // links without spheres
  bool pairs = false;
  bool pair_reasons = false;
  bool buffers = false;
};
RobotSpheresFormatParts RobotSpheresFormatCarries(RobotSpheresFormat format);

// What writing `model` in `format` leaves out, one phrase each (e.g. "self_collision_buffer
// of 7 links", "reasons of 12 pairs"); empty when nothing is lost. O(size of model).
std::vector<std::string> RobotSpheresDropped(const RobotSpheres& model, RobotSpheresFormat format);

// `model` without what `format` does not carry: what reading it back gives (link order aside:
// the URDF formats list links in the document's order).
RobotSpheres RobotSpheresCarried(RobotSpheres model, RobotSpheresFormat format);

// OK, or INVALID_ARGUMENT naming the problem: an empty or repeated link name, a sphere
// CheckSphere refuses (naming link and sphere), a pair not ordered a < b or of a link with
// itself, a buffer that is not finite or of an empty name.
absl::Status CheckRobotSpheres(const RobotSpheres& model);

struct RobotSpheresWriteOptions {
  // kUrdf, kMorphit: the robot's URDF the spheres are written into (required; every link of
  // the model must be in it). kSrdf: an SRDF to merge into (empty: a new document).
  std::string base;
  // A comment line at the top (YAML) or after the declaration (XML); empty for none.
  std::string comment;
  // kXrdf: the geometry group's name.
  std::string xrdf_geometry = "collision_spheres";
};

// `model` in `format`. Errors: CheckRobotSpheres'; kCurobo and kXrdf refuse link names YAML
// keys cannot carry as cuRobo's (FormatCuroboYaml's rule: letters, digits, _ - . /); kUrdf and
// kMorphit refuse a missing or malformed base, a link the base does not have, and (kMorphit) a
// sphere link name the base already uses for another link; kSrdf refuses a malformed base.
// Cost O(size of model + size of base).
absl::StatusOr<std::string> FormatRobotSpheres(const RobotSpheres& model, RobotSpheresFormat format,
                                               const RobotSpheresWriteOptions& options = {});

// Reads `bytes` in `format`. INVALID_ARGUMENT naming the line and key or element for malformed
// content: YAML or XML that does not parse, a missing or ill-typed key (a centre that is not 3
// finite numbers, a radius that is not a positive finite number; cuRobo's placeholder spheres
// of radius <= 0 are skipped as cuRobo does), a link listed twice, an XRDF whose format is
// not xrdf or whose format_version is not 1.x, or whose collision and self_collision name
// different geometry groups, an SRDF sphere without center or radius, a URDF link that mixes
// sphere collisions with other geometry. Cost O(size of bytes).
absl::StatusOr<RobotSpheres> ParseRobotSpheres(absl::string_view bytes, RobotSpheresFormat format);

// Reads the file at `path` (at most 256 MiB) in `format`, or when unset by its extension for
// .xrdf and .srdf and by DetectRobotSpheresFormat for the others (.yml may hold XRDF, .urdf
// either layout); *read_as, when given, is set to the format read. NOT_FOUND for a missing file;
// INVALID_ARGUMENT with "PATH: " before ParseRobotSpheres' message.
absl::StatusOr<RobotSpheres> ReadRobotSpheresFile(
    const std::string& path, std::optional<RobotSpheresFormat> format = std::nullopt,
    RobotSpheresFormat* read_as = nullptr);

// What `inscribe urdf` made, as the model: every kSpherized link's spheres in the robot's
// order, the pairs `matrix` disables with their classes as reasons (when given), and
// `self_collision_buffer` as given. O(#spheres + #pairs).
RobotSpheres RobotSpheresFromSpherized(const std::vector<LinkSpherizeResult>& links,
                                       const std::string& robot_name,
                                       const SelfCollisionMatrix* matrix,
                                       const std::map<std::string, double>& self_collision_buffer);

}  // namespace inscribe::robot
