// Robots: spherize the links of a URDF or the bodies of a MuJoCo model (what `inscribe urdf`
// does), and write the results.
#include <pybind11/stl.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "inscribe/base/atomic_file.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/robot_file.h"
#include "inscribe/robot/robot_spheres.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/self_collision_srdf.h"
#include "inscribe/robot/spherized_mjcf.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/robot/urdf_spherize.h"
#include "interruptible.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

namespace fs = std::filesystem;
using robot::LinkSpherizeResult;
using robot::LinkStatus;

// (N, 4) float64 [x, y, z, r] rows, a copy.
py::array_t<double> SphereArray(const std::vector<Sphere>& spheres) {
  py::array_t<double> result({static_cast<py::ssize_t>(spheres.size()), py::ssize_t{4}});
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    for (int k = 0; k < 3; ++k) result.mutable_at(i, k) = spheres[i].center[k];
    result.mutable_at(i, 3) = spheres[i].radius;
  }
  return result;
}

// A self-collision matrix and the robot it is about (for its SRDF).
struct PySelfCollision {
  robot::SelfCollisionMatrix matrix;
  std::string robot_name;
};

struct SpherizedRobot {
  robot::RobotFile file;
  std::vector<LinkSpherizeResult> links;  // one per file.robot() link
};

using ClipPlanes = std::vector<std::tuple<std::string, std::array<double, 3>, double>>;

// What spherize_robot and spherize_urdf do: read by content, spherize every link.
SpherizedRobot Spherize(
    const std::string& path, const std::string& kind, std::optional<std::int64_t> max_spheres,
    std::optional<std::int64_t> max_spheres_per_link, std::optional<double> max_protrusion,
    std::optional<double> voxel_size, const std::map<std::string, std::int64_t>& link_max_spheres,
    double padding, const ClipPlanes& clip_planes, const std::vector<std::string>& package_paths,
    const robot::MjcfReadOptions& mjcf, const RepairOptions& repair,
    const std::map<std::string, RepairOptions>& link_repair, const py::object& progress) {
  absl::StatusOr<robot::RobotFile> file = robot::ReadRobotFile(path, mjcf);
  if (!file.ok()) RaiseStatus(file.status());
  robot::UrdfSpherizeOptions options;
  options.kind = ValueOrRaise(ParseSphereSetKind(kind));
  options.max_spheres = max_spheres;
  options.max_spheres_per_link = max_spheres_per_link;
  options.max_protrusion = max_protrusion;
  options.voxel_size = voxel_size;
  options.link_max_spheres = link_max_spheres;
  options.repair = repair;
  options.link_repair = link_repair;
  options.padding = padding;
  for (const auto& [link, normal, offset] : clip_planes) {
    options.clip_planes.push_back(
        robot::ClipPlane{link, Vector3(normal[0], normal[1], normal[2]), offset});
  }
  options.packages = robot::PackageSearchFromEnvironment(package_paths);
  options.urdf_dir = file->directory;
  absl::StatusOr<robot::RobotSpherizeResult> spherized;
  OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
    spherized = robot::SpherizeRobot(file->robot(), options, control);
    return spherized.status();
  }));
  return SpherizedRobot{*std::move(file), std::move(spherized->links)};
}

std::optional<robot::RobotSpheresFormat> FormatArgument(const std::optional<std::string>& name) {
  if (!name) return std::nullopt;
  return ValueOrRaise(robot::ParseRobotSpheresFormat(*name));
}

// The format `path` is written in: `format`, else its extension (.urdf: the urdf layout).
robot::RobotSpheresFormat OutputFormat(const std::string& path,
                                       const std::optional<std::string>& format) {
  if (format) return *FormatArgument(format);
  return ValueOrRaise(robot::RobotSpheresFormatFromPath(path));
}

// Writes `model` to `path` as the CLI does: URDF layouts into `robot` (a URDF path), SRDF
// merged into the one already at `path`.
void WriteModel(const robot::RobotSpheres& model, const std::string& path,
                robot::RobotSpheresFormat format, const std::string& robot_urdf,
                const std::string& comment) {
  robot::RobotSpheresWriteOptions options;
  options.comment = comment;
  if (format == robot::RobotSpheresFormat::kUrdf || format == robot::RobotSpheresFormat::kMorphit) {
    if (robot_urdf.empty()) {
      RaiseStatus(absl::InvalidArgumentError(
          "urdf and morphit files are the robot's URDF with spheres: pass robot=URDF_PATH"));
    }
    options.base = ValueOrRaise(robot::ReadRobotFileBytes(robot_urdf));
  }
  std::error_code error;
  if (format == robot::RobotSpheresFormat::kSrdf && fs::exists(path, error)) {
    options.base = ValueOrRaise(robot::ReadRobotFileBytes(path));
  }
  const std::string text = ValueOrRaise(robot::FormatRobotSpheres(model, format, options));
  OkOrRaise(WriteFileAtomically(path, text));
}

py::dict ModelDict(const robot::RobotSpheres& model, robot::RobotSpheresFormat format) {
  py::dict spheres;
  for (const LinkSpheres& link : model.links)
    spheres[py::str(link.link)] = SphereArray(link.spheres);
  py::list pairs;
  for (const auto& [pair, reason] : model.self_collision_ignore) {
    pairs.append(py::make_tuple(pair.first, pair.second, reason));
  }
  py::dict out;
  out["format"] = robot::RobotSpheresFormatName(format);
  out["robot_name"] = model.robot_name;
  out["spheres"] = spheres;
  out["self_collision_ignore"] = pairs;
  out["self_collision_buffer"] = model.self_collision_buffer;
  out["collision_buffer"] = model.collision_buffer;
  return out;
}

// The keyword arguments spherize_robot and spherize_urdf share, documented once.
constexpr char kSpherizeDoc[] =
    "each link's collision geometry (visual when none) becomes spheres in the link's frame "
    "(metres): kind 'cover' (default; certified to hold the link, with delta), 'internal' or "
    "'dilated'. At most one mode: max_spheres for the whole robot (covers share it by "
    "greedy marginal gain on their estimated delta), max_spheres_per_link (the default, "
    "DEFAULT_MAX_SPHERES_PER_LINK), max_protrusion (covers: every link's delta at most this, "
    "fewest spheres) or voxel_size (internal, dilated). link_max_spheres: {link: N} budgets "
    "of their own (0 leaves a link out). repair: how each mesh may be repaired (an "
    "inscribe.Repair or a level name, default 'safe'; see inscribe.prepare), link_repair: "
    "{link: repair} instead for those links. padding: metres added to every radius. clip_planes: "
    "[(link, (nx, ny, nz), "
    "offset)] cuts off what lies beyond n . x = offset in the link's frame. package_paths are "
    "searched for package:// before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH. A link that "
    "cannot be done is 'skipped' with its error, never silently dropped. Ctrl-C cancels. "
    "Returns a SpherizedRobot.";

}  // namespace

void BindRobot(py::module_& m) {
  // pybind11 keeps a docstring's pointer until the module is set up: these outlive that.
  static const std::string robot_doc =
      std::string(
          "Spherizes every link of the URDF or every body of the MuJoCo model (MJCF) at `path`, "
          "told apart by the root element, as `inscribe urdf` does. In MJCF a body's solid is "
          "its geoms that take part in contacts (contype or conaffinity non-zero, as MuJoCo "
          "Menagerie's collision class), else its visual ones with a warning; solid_classes "
          "(default classes, inherited ones count) and solid_groups choose others. Then ") +
      kSpherizeDoc;
  static const std::string urdf_doc =
      std::string(
          "Spherizes every link of the robot at `path` as `inscribe urdf` does "
          "(spherize_robot without its MJCF options): ") +
      kSpherizeDoc;
  m.attr("DEFAULT_MAX_SPHERES_PER_LINK") = robot::kDefaultMaxSpheresPerLink;

  py::class_<LinkSpherizeResult>(m, "LinkSpheres", "One link of a spherized robot.")
      .def_readonly("link", &LinkSpherizeResult::link)
      .def_property_readonly(
          "status", [](const LinkSpherizeResult& r) { return robot::LinkStatusName(r.status); },
          "'spherized', 'skipped' or 'no_geometry'")
      .def_readonly("from_visual", &LinkSpherizeResult::from_visual)
      .def_readonly("elements", &LinkSpherizeResult::elements)
      .def_property_readonly(
          "spheres", [](const LinkSpherizeResult& r) { return SphereArray(r.spheres); },
          "(N, 4) float64 [x, y, z, r] in the link's frame, metres")
      .def_property_readonly(
          "kind", [](const LinkSpherizeResult& r) { return SphereSetKindName(r.kind); },
          "'cover', 'internal' or 'dilated'")
      .def_readonly("delta", &LinkSpherizeResult::delta,
                    "covers: the certified bound on how far the spheres reach past the link's "
                    "solid, padding included (metres); None otherwise")
      .def_property_readonly(
          "certified", [](const LinkSpherizeResult& r) { return r.delta.has_value(); },
          "whether the spheres are a certified cover of the link")
      .def_property_readonly(
          "cores", [](const LinkSpherizeResult& r) { return SphereArray(r.cores); },
          "(M, 4) float64 balls inside the link's solid (covers' cores; an internal set "
          "before padding), link frame, metres: the upper-bound side of certified distances")
      .def_readonly("budget", &LinkSpherizeResult::budget,
                    "spheres the link was given (budget modes), else 0")
      .def_readonly("error", &LinkSpherizeResult::error, "why a skipped link was skipped")
      .def_readonly("warnings", &LinkSpherizeResult::warnings,
                    "every validation warning and fix of the link's meshes, one line each")
      .def_readonly("seconds", &LinkSpherizeResult::seconds)
      .def("__repr__", [](const LinkSpherizeResult& r) {
        return absl::StrCat("LinkSpheres('", r.link, "', ", robot::LinkStatusName(r.status), ", ",
                            r.spheres.size(), " spheres)");
      });

  py::class_<SpherizedRobot>(m, "SpherizedRobot", "A URDF robot with spheres for its links.")
      .def_property_readonly("name", [](const SpherizedRobot& r) { return r.file.robot().name; })
      .def_property_readonly(
          "format", [](const SpherizedRobot& r) { return robot::RobotFormatName(r.file.format); },
          "'urdf' or 'mjcf', as read from the file's root element")
      .def_readonly("links", &SpherizedRobot::links,
                    "one LinkSpheres per link; for MJCF also the links of multi-coordinate "
                    "joints (BODY/JOINT, no geometry)")
      .def_property_readonly(
          "spheres",
          [](const SpherizedRobot& r) {
            py::dict out;
            for (std::size_t l = 0; l < r.links.size(); ++l) {
              if (r.links[l].status != LinkStatus::kSpherized) continue;
              out[py::str(r.links[l].link)] = SphereArray(r.links[l].spheres);
            }
            return out;
          },
          "{link or body name: (N, 4) float64 [x, y, z, r]} for every spherized link, in its "
          "own frame (an MJCF body's frame), metres")
      .def_property_readonly(
          "warnings", [](const SpherizedRobot& r) { return r.file.warnings(); },
          "MJCF: bodies whose visual geoms stood in for missing collision ones, geoms that are "
          "no solid (planes); none for URDF")
      .def(
          "urdf",
          [](const SpherizedRobot& r, const std::optional<std::string>& directory) {
            if (r.file.format != robot::RobotFormat::kUrdf) {
              RaiseStatus(absl::InvalidArgumentError(
                  r.file.path +
                  " is an MJCF model: there is no URDF to write; use spheres or "
                  "curobo_yaml()"));
            }
            if (!directory) return ValueOrRaise(robot::SpherizedUrdf(r.file.bytes, r.links));
            return ValueOrRaise(robot::SpherizedUrdf(
                r.file.bytes, r.links, r.file.directory,
                std::filesystem::absolute(*directory).lexically_normal().string()));
          },
          py::arg("directory") = py::none(),
          "The URDF text with one sphere <collision> per sphere in spherized links (URDF "
          "input only). With `directory` (the folder the text will be written to), relative "
          "mesh paths are rewritten to resolve from there, as `inscribe urdf -o` writes them.")
      .def(
          "mjcf",
          [](const SpherizedRobot& r, const std::string& directory) {
            if (r.file.format != robot::RobotFormat::kMjcf) {
              RaiseStatus(absl::InvalidArgumentError(r.file.path +
                                                     " is a URDF: use urdf() for its spheres"));
            }
            return ValueOrRaise(robot::SpherizedMjcf(r.file, r.links, directory));
          },
          py::arg("directory"),
          "The spherized MuJoCo model's text (MJCF input only), as `inscribe robot -o` writes "
          "it, for a file in `directory` (mesh paths are written relative to it): every "
          "spherized body's solid geoms kept for their mass but no longer colliding, one "
          "massless group-3 sphere geom per sphere in the solid geom's class.")
      .def(
          "self_collision",
          [](const SpherizedRobot& r, std::int64_t samples, std::uint64_t seed,
             double always_fraction, const py::object& progress) {
            const robot::Kinematics kinematics =
                ValueOrRaise(robot::Kinematics::Create(r.file.robot()));
            robot::SelfCollisionOptions options;
            options.samples = samples;
            options.seed = seed;
            options.always_fraction = always_fraction;
            absl::StatusOr<robot::SelfCollisionMatrix> matrix;
            OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
              options.control = control;
              matrix = robot::ComputeSelfCollisionMatrix(
                  kinematics, robot::LinkCollisionGeometries(r.links), options);
              return matrix.status();
            }));
            return PySelfCollision{*std::move(matrix), r.file.robot().name};
          },
          py::kw_only(), py::arg("samples") = robot::SelfCollisionOptions{}.samples,
          py::arg("seed") = robot::SelfCollisionOptions{}.seed,
          py::arg("always_fraction") = robot::SelfCollisionOptions{}.always_fraction,
          py::arg("progress") = py::none(),
          "The self-collision matrix as `inscribe urdf` computes it: every pair of links with "
          "spheres classified Adjacent, Default, Always, Never or Sometimes from `samples` "
          "joint configurations drawn from `seed`, with certified distance bounds when the "
          "links are covers. Ctrl-C cancels.")
      .def(
          "curobo_yaml",
          [](const SpherizedRobot& r, const PySelfCollision* self_collision) {
            std::vector<std::string> left_out;
            std::string yaml;
            if (self_collision != nullptr) {
              yaml = ValueOrRaise(robot::SpherizedCuroboYaml(
                  r.links, r.file.robot().name, self_collision->matrix, {}, &left_out));
            } else {
              yaml = robot::SpherizedCuroboYaml(r.links, r.file.robot().name, &left_out);
            }
            if (!left_out.empty()) {
              RaiseStatus(absl::InvalidArgumentError(
                  "links whose names cuRobo's YAML cannot carry: " + left_out.front()));
            }
            return yaml;
          },
          py::arg("self_collision") = py::none(),
          "cuRobo's collision_spheres YAML of the spherized links; with a SelfCollision "
          "(self_collision()), followed by self_collision_ignore and self_collision_buffer "
          "(0: padding is in the radii), as `inscribe urdf` writes it.")
      .def(
          "write",
          [](const SpherizedRobot& r, py::handle path_like,
             const std::optional<std::string>& format, const PySelfCollision* self_collision) {
            const std::string path = PathOf(path_like, "path");
            const robot::RobotSpheres model = robot::RobotSpheresFromSpherized(
                r.links, r.file.robot().name,
                self_collision == nullptr ? nullptr : &self_collision->matrix, {});
            const robot::RobotSpheresFormat target = OutputFormat(path, format);
            if (r.file.format != robot::RobotFormat::kUrdf &&
                (target == robot::RobotSpheresFormat::kUrdf ||
                 target == robot::RobotSpheresFormat::kMorphit)) {
              RaiseStatus(absl::InvalidArgumentError(
                  r.file.path + " is an MJCF model: there is no URDF to write spheres into"));
            }
            WriteModel(model, path, target, r.file.path,
                       self_collision == nullptr
                           ? std::string("inscribe")
                           : robot::SelfCollisionComment(self_collision->matrix));
          },
          py::arg("path"), py::kw_only(), py::arg("format") = py::none(),
          py::arg("self_collision") = py::none(),
          "Writes the spherized links' spheres (and, with a SelfCollision, its disabled pairs "
          "with their classes) as a planner reads them: format 'curobo', 'xrdf', 'srdf' (merged "
          "into an SRDF already at path), 'urdf' (VAMP's layout) or 'morphit', else by path's "
          "extension (.yml, .xrdf, .srdf, .urdf), as `inscribe urdf --spheres` does.");

  m.def(
      "read_robot_spheres",
      [](py::handle path_like, const std::optional<std::string>& format) {
        const std::string path = PathOf(path_like, "path");
        const robot::RobotSpheres model =
            ValueOrRaise(robot::ReadRobotSpheresFile(path, FormatArgument(format)));
        py::dict out;
        for (const LinkSpheres& link : model.links) {
          out[py::str(link.link)] = SphereArray(link.spheres);
        }
        return out;
      },
      py::arg("path"), py::kw_only(), py::arg("format") = py::none(),
      "{link: (N, 4) float64 [x, y, z, r]} of a robot sphere file in any planner format: "
      "'curobo' (.yml), 'xrdf', 'srdf', 'urdf' (VAMP's layout) or 'morphit' (the parent "
      "link's frame), by format, else extension and content. Link frames, metres.");
  m.def(
      "read_robot_sphere_file",
      [](py::handle path_like, const std::optional<std::string>& format) {
        const std::string path = PathOf(path_like, "path");
        robot::RobotSpheresFormat read_as = robot::RobotSpheresFormat::kCurobo;
        const robot::RobotSpheres model =
            ValueOrRaise(robot::ReadRobotSpheresFile(path, FormatArgument(format), &read_as));
        return ModelDict(model, read_as);
      },
      py::arg("path"), py::kw_only(), py::arg("format") = py::none(),
      "Everything read_robot_spheres reads and more: a dict with format, robot_name, spheres "
      "({link: (N, 4)}), self_collision_ignore ([(link_a, link_b, reason)], a < b, reason '' "
      "when the file gives none), self_collision_buffer and collision_buffer ({link: "
      "metres}).");
  m.def(
      "write_robot_spheres",
      [](py::handle path_like, const py::dict& spheres, const std::optional<std::string>& format,
         const std::string& robot_urdf, const std::string& robot_name,
         const std::vector<std::tuple<std::string, std::string, std::string>>& ignore,
         const std::map<std::string, double>& self_collision_buffer,
         const std::map<std::string, double>& collision_buffer) {
        const std::string path = PathOf(path_like, "path");
        robot::RobotSpheres model;
        model.robot_name = robot_name;
        for (const auto& [link, array] : spheres) {
          model.links.push_back({py::cast<std::string>(link), SpheresOf(array)});
        }
        for (const auto& [a, b, reason] : ignore) {
          if (a == b) RaiseStatus(absl::InvalidArgumentError("link '" + a + "' ignores itself"));
          model.self_collision_ignore[std::minmax(a, b)] = reason;
        }
        model.self_collision_buffer = self_collision_buffer;
        model.collision_buffer = collision_buffer;
        WriteModel(model, path, OutputFormat(path, format), robot_urdf, "inscribe");
      },
      py::arg("path"), py::arg("spheres"), py::kw_only(), py::arg("format") = py::none(),
      py::arg("robot") = "", py::arg("robot_name") = "",
      py::arg("self_collision_ignore") =
          std::vector<std::tuple<std::string, std::string, std::string>>{},
      py::arg("self_collision_buffer") = std::map<std::string, double>{},
      py::arg("collision_buffer") = std::map<std::string, double>{},
      "Writes {link: (N, 4) spheres} in a planner's format (format, else path's extension), "
      "with optional self_collision_ignore [(a, b, reason)] and per-link buffers (metres). "
      "'urdf' and 'morphit' are written into the robot's URDF at `robot`; 'srdf' merges into "
      "an SRDF already at path. Links are written in the dict's order.");

  py::class_<PySelfCollision>(m, "SelfCollision", "A robot's self-collision matrix.")
      .def_property_readonly("samples", [](const PySelfCollision& c) { return c.matrix.samples; })
      .def_property_readonly("seed", [](const PySelfCollision& c) { return c.matrix.seed; })
      .def_property_readonly(
          "certified", [](const PySelfCollision& c) { return c.matrix.certified; },
          "every link with spheres is a certified cover: the bounds hold for the solids")
      .def_property_readonly("seconds", [](const PySelfCollision& c) { return c.matrix.seconds; })
      .def_property_readonly(
          "pairs",
          [](const PySelfCollision& c) {
            py::list pairs;
            for (const robot::LinkPairCollision& pair : c.matrix.pairs) {
              py::dict entry;
              entry["link1"] = c.matrix.links[static_cast<std::size_t>(pair.link_a)];
              entry["link2"] = c.matrix.links[static_cast<std::size_t>(pair.link_b)];
              entry["class"] = robot::CollisionPairClassName(pair.type);
              entry["disabled"] = robot::CollisionDisabled(pair.type);
              entry["colliding_at_default"] = pair.colliding_at_default;
              if (pair.sampled) {
                entry["colliding_fraction"] = pair.colliding_fraction;
                entry["min_lower"] = pair.min_lower;
                entry["min_upper"] = pair.min_upper;
              }
              pairs.append(std::move(entry));
            }
            return pairs;
          },
          "one dict per pair of links with spheres: link1, link2, class ('Adjacent', "
          "'Default', 'Always', 'Never', 'Sometimes'), disabled, colliding_at_default and, "
          "when sampled, colliding_fraction, min_lower, min_upper (metres)")
      .def(
          "srdf",
          [](const PySelfCollision& c) { return robot::SelfCollisionSrdf(c.matrix, c.robot_name); },
          "MoveIt's SRDF with the disabled pairs, as `inscribe urdf --srdf` writes it.");

  m.def(
      "spherize_robot",
      [](py::handle path_like, const std::string& kind, std::optional<std::int64_t> max_spheres,
         std::optional<std::int64_t> max_spheres_per_link, std::optional<double> max_protrusion,
         std::optional<double> voxel_size,
         const std::map<std::string, std::int64_t>& link_max_spheres, double padding,
         const ClipPlanes& clip_planes, const std::vector<std::string>& package_paths,
         const std::vector<std::string>& solid_classes, const std::vector<int>& solid_groups,
         const RepairOptions& repair, const std::map<std::string, RepairOptions>& link_repair,
         const py::object& progress) {
        const std::string path = PathOf(path_like, "path");
        robot::MjcfReadOptions mjcf;
        mjcf.solid.classes = solid_classes;
        mjcf.solid.groups = solid_groups;
        return Spherize(path, kind, max_spheres, max_spheres_per_link, max_protrusion, voxel_size,
                        link_max_spheres, padding, clip_planes, package_paths, mjcf, repair,
                        link_repair, progress);
      },
      py::arg("path"), py::kw_only(), py::arg("kind") = "cover",
      py::arg("max_spheres") = py::none(), py::arg("max_spheres_per_link") = py::none(),
      py::arg("max_protrusion") = py::none(), py::arg("voxel_size") = py::none(),
      py::arg("link_max_spheres") = std::map<std::string, std::int64_t>{}, py::arg("padding") = 0.0,
      py::arg("clip_planes") = ClipPlanes{}, py::arg("package_paths") = std::vector<std::string>{},
      py::arg("solid_classes") = std::vector<std::string>{},
      py::arg("solid_groups") = std::vector<int>{}, py::arg("repair") = RepairOptions{},
      py::arg("link_repair") = std::map<std::string, RepairOptions>{},
      py::arg("progress") = py::none(), robot_doc.c_str());
  m.def(
      "spherize_urdf",
      [](py::handle path_like, const std::string& kind, std::optional<std::int64_t> max_spheres,
         std::optional<std::int64_t> max_spheres_per_link, std::optional<double> max_protrusion,
         std::optional<double> voxel_size,
         const std::map<std::string, std::int64_t>& link_max_spheres, double padding,
         const ClipPlanes& clip_planes, const std::vector<std::string>& package_paths,
         const RepairOptions& repair, const std::map<std::string, RepairOptions>& link_repair,
         const py::object& progress) {
        const std::string path = PathOf(path_like, "path");
        return Spherize(path, kind, max_spheres, max_spheres_per_link, max_protrusion, voxel_size,
                        link_max_spheres, padding, clip_planes, package_paths, {}, repair,
                        link_repair, progress);
      },
      py::arg("path"), py::kw_only(), py::arg("kind") = "cover",
      py::arg("max_spheres") = py::none(), py::arg("max_spheres_per_link") = py::none(),
      py::arg("max_protrusion") = py::none(), py::arg("voxel_size") = py::none(),
      py::arg("link_max_spheres") = std::map<std::string, std::int64_t>{}, py::arg("padding") = 0.0,
      py::arg("clip_planes") = ClipPlanes{}, py::arg("package_paths") = std::vector<std::string>{},
      py::arg("repair") = RepairOptions{},
      py::arg("link_repair") = std::map<std::string, RepairOptions>{},
      py::arg("progress") = py::none(), urdf_doc.c_str());
}

}  // namespace inscribe::python
