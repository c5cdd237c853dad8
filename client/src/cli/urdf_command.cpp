#include "urdf_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "cli_help.h"
#include "command_outcome.h"
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
#include "nlohmann/json.hpp"
#include "output_files.h"
#include "robot_sphere_files.h"
#include "solid_loading.h"

namespace inscribe::cli {

using robot::ClipPlane;
using robot::LinkSpherizeResult;
using robot::LinkStatus;
using robot::LinkStatusName;
using robot::PackageSearchFromEnvironment;
using robot::RobotSpherizeResult;
using robot::SpherizedCuroboYaml;
using robot::SpherizedUrdf;
using robot::SpherizeRobot;
using robot::UrdfRobot;
using robot::UrdfSpherizeOptions;
namespace {

namespace fs = std::filesystem;

struct UrdfCliOptions {
  std::string urdf_path;
  std::vector<std::string> package_paths;
  std::string kind = "cover";
  std::optional<std::int64_t> max_spheres;
  std::optional<std::int64_t> max_spheres_per_link;
  std::optional<double> max_protrusion;
  std::optional<double> voxel_size;
  std::vector<std::string> link_budgets;  // LINK=N
  RepairOptions repair;                   // --repair and the rest, for every link
  std::vector<std::string> link_repairs;  // LINK=LEVEL
  std::vector<std::string> clips;         // LINK=NX,NY,NZ,OFFSET
  double padding = 0.0;
  std::string output_path;
  std::string yaml_path;
  std::string srdf_path;
  std::vector<std::string> sphere_paths;  // --spheres [FORMAT:]PATH
  std::string sphere_format;
  std::int64_t samples = robot::SelfCollisionOptions{}.samples;
  std::uint64_t seed = robot::SelfCollisionOptions{}.seed;
  bool json = false;
  // MJCF: which geoms are a body's solid (none: MuJoCo's contact rule).
  std::vector<std::string> solid_classes;
  std::vector<int> solid_groups;
};

// "LINK=VALUE" split at the last '=' (link names may hold '=').
absl::StatusOr<std::pair<std::string, std::string>> SplitLinkValue(const std::string& text,
                                                                   const char* flag) {
  const std::size_t at = text.rfind('=');
  if (at == std::string::npos || at == 0 || at + 1 == text.size()) {
    return absl::InvalidArgumentError(absl::StrFormat("%s '%s' is not LINK=VALUE", flag, text));
  }
  return std::pair{text.substr(0, at), text.substr(at + 1)};
}

// The spherizer's options from the flags; the spherizer checks them (CheckUrdfSpherizeOptions).
absl::StatusOr<UrdfSpherizeOptions> SpherizeOptionsOf(const UrdfCliOptions& options) {
  UrdfSpherizeOptions spherize;
  absl::StatusOr<SphereSetKind> kind = ParseSphereSetKind(options.kind);
  if (!kind.ok()) return kind.status();
  spherize.kind = *kind;
  spherize.max_spheres = options.max_spheres;
  spherize.max_spheres_per_link = options.max_spheres_per_link;
  spherize.max_protrusion = options.max_protrusion;
  spherize.voxel_size = options.voxel_size;
  spherize.padding = options.padding;
  for (const std::string& text : options.link_budgets) {
    absl::StatusOr<std::pair<std::string, std::string>> parts =
        SplitLinkValue(text, "--link-max-spheres");
    if (!parts.ok()) return parts.status();
    std::int64_t n = 0;
    if (!absl::SimpleAtoi(parts->second, &n)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "--link-max-spheres '%s': '%s' is not a whole number", text, parts->second));
    }
    spherize.link_max_spheres[parts->first] = n;
  }
  spherize.repair = options.repair;
  for (const std::string& text : options.link_repairs) {
    absl::StatusOr<std::pair<std::string, std::string>> parts =
        SplitLinkValue(text, "--link-repair");
    if (!parts.ok()) return parts.status();
    absl::StatusOr<MeshRepair> level = ParseMeshRepair(parts->second);
    if (!level.ok()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--link-repair '%s': %s", text, level.status().message()));
    }
    RepairOptions repair = options.repair;
    repair.level = *level;
    spherize.link_repair[parts->first] = repair;
  }
  for (const std::string& text : options.clips) {
    absl::StatusOr<std::pair<std::string, std::string>> parts = SplitLinkValue(text, "--clip");
    if (!parts.ok()) return parts.status();
    const std::vector<std::string> numbers = absl::StrSplit(parts->second, ',');
    double values[4];
    bool ok = numbers.size() == 4;
    for (std::size_t k = 0; ok && k < 4; ++k) ok = absl::SimpleAtod(numbers[k], &values[k]);
    if (!ok) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "--clip '%s': expected LINK=NX,NY,NZ,OFFSET (4 numbers after '=')", text));
    }
    spherize.clip_planes.push_back(
        ClipPlane{parts->first, Vector3(values[0], values[1], values[2]), values[3]});
  }
  return spherize;
}

// --yaml, or OUT with its extension replaced by .yml.
std::string YamlPath(const UrdfCliOptions& options) {
  if (!options.yaml_path.empty()) return options.yaml_path;
  return fs::path(options.output_path).replace_extension(".yml").string();
}

bool SameFile(const std::string& a, const std::string& b) {
  return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
}

// The mode the run used, as the flags name it.
void AddMode(const UrdfSpherizeOptions& options, nlohmann::json* report) {
  if (options.max_spheres) (*report)["max_spheres"] = *options.max_spheres;
  if (options.max_spheres_per_link) {
    (*report)["max_spheres_per_link"] = *options.max_spheres_per_link;
  }
  if (options.max_protrusion) (*report)["max_protrusion"] = *options.max_protrusion;
  if (options.voxel_size) (*report)["voxel_size"] = *options.voxel_size;
}

nlohmann::json MatrixJson(const robot::SelfCollisionMatrix& matrix, const std::string& srdf) {
  nlohmann::json out;
  out["samples"] = matrix.samples;
  out["seed"] = matrix.seed;
  out["always_fraction"] = matrix.always_fraction;
  out["certified"] = matrix.certified;
  out["seconds"] = matrix.seconds;
  if (!srdf.empty()) out["srdf"] = srdf;
  nlohmann::json pairs = nlohmann::json::array();
  std::int64_t disabled = 0;
  for (const robot::LinkPairCollision& pair : matrix.pairs) {
    nlohmann::json entry;
    entry["link1"] = matrix.links[static_cast<std::size_t>(pair.link_a)];
    entry["link2"] = matrix.links[static_cast<std::size_t>(pair.link_b)];
    entry["class"] = robot::CollisionPairClassName(pair.type);
    entry["disabled"] = robot::CollisionDisabled(pair.type);
    entry["colliding_at_default"] = pair.colliding_at_default;
    if (pair.sampled) {
      entry["colliding_fraction"] = pair.colliding_fraction;
      entry["min_lower"] = pair.min_lower;
      entry["min_upper"] = pair.min_upper;
    }
    disabled += robot::CollisionDisabled(pair.type);
    pairs.push_back(std::move(entry));
  }
  out["pairs"] = std::move(pairs);
  out["disabled"] = disabled;
  return out;
}

// "21 link pairs from 10000 samples (certified): 6 Adjacent, 2 Never, ... disabled; 13 enabled"
std::string MatrixSummary(const robot::SelfCollisionMatrix& matrix) {
  std::map<std::string, int> counts;
  for (const robot::LinkPairCollision& pair : matrix.pairs) {
    ++counts[robot::CollisionPairClassName(pair.type)];
  }
  std::string text = absl::StrFormat(
      "self-collision: %d link pairs from %d samples%s in %.3f s:", matrix.pairs.size(),
      matrix.samples, matrix.certified ? " (certified bounds)" : "", matrix.seconds);
  for (const char* name : {"Adjacent", "Default", "Always", "Never", "Sometimes"}) {
    absl::StrAppendFormat(&text, " %d %s", counts[name], name);
  }
  return text;
}

void PrintJson(const UrdfCliOptions& options, const UrdfSpherizeOptions& spherize,
               const robot::RobotFile& file, const RobotSpherizeResult& result,
               const std::optional<robot::SelfCollisionMatrix>& matrix,
               const std::string& yaml_path, const std::vector<std::string>& left_out,
               double seconds) {
  nlohmann::json report;
  report["urdf"] = options.urdf_path;
  report["format"] = robot::RobotFormatName(file.format);
  report["robot"] = file.robot().name;
  report["output"] = options.output_path;
  report["yaml"] = yaml_path;
  report["spheres_files"] = options.sphere_paths;
  report["kind"] = SphereSetKindName(spherize.kind);
  report["padding"] = spherize.padding;
  AddMode(robot::WithDefaultMode(spherize), &report);
  int spherized = 0, skipped = 0;
  std::int64_t spheres = 0;
  std::optional<double> delta;
  nlohmann::json links = nlohmann::json::array();
  for (std::size_t l = 0; l < result.links.size(); ++l) {
    // MJCF's links of multi-coordinate joints have no geometry and name no body: not listed.
    if (!file.IsDescribedLink(static_cast<int>(l))) continue;
    const LinkSpherizeResult& link_result = result.links[l];
    nlohmann::json link;
    link["link"] = link_result.link;
    link["status"] = LinkStatusName(link_result.status);
    link["elements"] = link_result.elements;
    link["from_visual"] = link_result.from_visual;
    link["spheres"] = link_result.spheres.size();
    if (link_result.budget > 0) link["budget"] = link_result.budget;
    link["certified"] = link_result.delta.has_value();
    if (link_result.delta) {
      link["delta"] = *link_result.delta;
      delta = std::max(delta.value_or(0.0), *link_result.delta);
    }
    link["generation_runs"] = link_result.generation_runs;
    link["seconds"] = link_result.seconds;
    if (!link_result.error.empty()) link["error"] = link_result.error;
    if (!link_result.warnings.empty()) link["warnings"] = link_result.warnings;
    links.push_back(std::move(link));
    spherized += link_result.status == LinkStatus::kSpherized;
    skipped += link_result.status == LinkStatus::kSkipped;
    spheres += static_cast<std::int64_t>(link_result.spheres.size());
  }
  report["links"] = std::move(links);
  report["spherized"] = spherized;
  report["skipped"] = skipped;
  report["spheres"] = spheres;
  if (delta) report["delta"] = *delta;
  report["left_out_of_yaml"] = left_out;
  report["warnings"] = file.warnings();
  if (matrix) report["self_collision"] = MatrixJson(*matrix, options.srdf_path);
  report["spherize_seconds"] = result.seconds;
  report["seconds"] = seconds;
  // Names and messages come from the URDF, whose bytes tinyxml2 does not check as UTF-8.
  std::cout << report.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
}

void PrintTable(const robot::RobotFile& file, const RobotSpherizeResult& result,
                const std::optional<robot::SelfCollisionMatrix>& matrix,
                const std::string& output_path, const std::string& yaml_path,
                const std::string& srdf_path, const std::vector<std::string>& sphere_paths,
                const std::vector<std::string>& left_out, double seconds) {
  std::size_t width = 4;
  for (const LinkSpherizeResult& link : result.links) width = std::max(width, link.link.size());
  const int w = static_cast<int>(width);
  std::cout << absl::StrFormat("%-*s  %-11s  %7s  %11s  %8s  %s\n", w, "link", "status", "spheres",
                               "delta (mm)", "seconds", "note");
  int skipped = 0;
  std::int64_t spheres = 0;
  for (std::size_t l = 0; l < result.links.size(); ++l) {
    if (!file.IsDescribedLink(static_cast<int>(l))) continue;  // MJCF's joint chains' links
    const LinkSpherizeResult& link = result.links[l];
    std::string note = link.error;
    if (link.status == LinkStatus::kSpherized && link.from_visual) note = "visual geometry";
    const std::string delta =
        link.delta ? absl::StrFormat("%.3f", *link.delta * 1000.0) : std::string("-");
    std::cout << absl::StrFormat("%-*s  %-11s  %7d  %11s  %8.3f  %s\n", w, link.link,
                                 LinkStatusName(link.status), link.spheres.size(), delta,
                                 link.seconds, note);
    skipped += link.status == LinkStatus::kSkipped;
    spheres += static_cast<std::int64_t>(link.spheres.size());
  }
  if (matrix) std::cout << MatrixSummary(*matrix) << "\n";
  std::string written = output_path + ", " + yaml_path;
  for (const std::string& path : sphere_paths) written += ", " + path;
  std::cout << absl::StrFormat("wrote %s%s (%d spheres) in %.3f s", written,
                               srdf_path.empty() ? "" : " and " + srdf_path, spheres, seconds);
  if (skipped > 0) std::cout << absl::StrFormat("; %d link(s) skipped, kept as they were", skipped);
  if (!left_out.empty()) {
    std::cout << absl::StrFormat("; %d link(s) left out of the YAML (names)", left_out.size());
  }
  std::cout << "\n";
}

absl::Status RunUrdf(const UrdfCliOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<UrdfSpherizeOptions> spherize = SpherizeOptionsOf(options);
  if (!spherize.ok()) return UsageError(spherize.status().message());
  if (absl::Status checked = robot::CheckUrdfSpherizeOptions(*spherize); !checked.ok()) {
    return UsageError(checked.message());
  }
  // Read first: the outputs depend on the format. A missing output directory is still found
  // before any spherizing.
  robot::MjcfReadOptions mjcf;
  mjcf.solid.classes = options.solid_classes;
  mjcf.solid.groups = options.solid_groups;
  absl::StatusOr<robot::RobotFile> file = robot::ReadRobotFile(options.urdf_path, mjcf);
  if (!file.ok()) return BadInputError(file.status().message());
  const bool is_mjcf = file->format == robot::RobotFormat::kMjcf;
  if (!is_mjcf && (!options.solid_classes.empty() || !options.solid_groups.empty())) {
    return UsageError("--solid-class and --solid-group choose MJCF geoms; " + options.urdf_path +
                      " is a URDF (its links' <collision> elements are the solid)");
  }
  const std::string yaml_path = YamlPath(options);
  if (SameFile(yaml_path, options.output_path)) {
    return UsageError("the YAML would overwrite -o " + options.output_path +
                      "; give --yaml PATH or an -o ending in .urdf");
  }

  if (!options.srdf_path.empty() && (SameFile(options.srdf_path, options.output_path) ||
                                     SameFile(options.srdf_path, yaml_path))) {
    return UsageError("--srdf " + options.srdf_path + " would overwrite another output");
  }
  std::vector<robot::RobotSpheresFormat> sphere_formats;
  std::vector<std::string> sphere_paths;
  for (const std::string& spec : options.sphere_paths) {
    // FORMAT:PATH names the format of that file; otherwise the extension decides where it
    // names one, and --format picks the layout of .urdf files (urdf or morphit) and the
    // format of files with other extensions.
    std::string path = spec;
    std::optional<robot::RobotSpheresFormat> named;
    if (const std::size_t colon = spec.find(':'); colon != std::string::npos) {
      absl::StatusOr<robot::RobotSpheresFormat> prefix =
          robot::ParseRobotSpheresFormat(spec.substr(0, colon));
      if (prefix.ok()) {
        named = *prefix;
        path = spec.substr(colon + 1);
      }
    }
    const absl::StatusOr<robot::RobotSpheresFormat> by_extension =
        robot::RobotSpheresFormatFromPath(path);
    const bool settled = by_extension.ok() && *by_extension != robot::RobotSpheresFormat::kUrdf;
    absl::StatusOr<robot::RobotSpheresFormat> format =
        named     ? *named
        : settled ? *by_extension
                  : RobotOutputFormat(options.sphere_format, path);
    if (!format.ok()) return format.status();
    if (is_mjcf && (*format == robot::RobotSpheresFormat::kUrdf ||
                    *format == robot::RobotSpheresFormat::kMorphit)) {
      return UsageError("--spheres " + path + ": " + options.urdf_path +
                        " is an MJCF model, with no URDF to write spheres into");
    }
    if (SameFile(path, options.output_path) || SameFile(path, yaml_path) ||
        (!options.srdf_path.empty() && SameFile(path, options.srdf_path))) {
      return UsageError("--spheres " + path + " would overwrite another output");
    }
    sphere_formats.push_back(*format);
    sphere_paths.push_back(path);
  }
  if (options.samples < 1 || options.samples > robot::kMaxSelfCollisionSamples) {
    return UsageError(absl::StrFormat("--samples must lie in 1..%d, got %d",
                                      robot::kMaxSelfCollisionSamples, options.samples));
  }

  // Before any work: a missing output directory would otherwise only show at the end.
  std::vector<std::string> written_paths = {options.output_path, yaml_path, options.srdf_path};
  written_paths.insert(written_paths.end(), sphere_paths.begin(), sphere_paths.end());
  for (const std::string& path : written_paths) {
    if (path.empty()) continue;
    const fs::path directory = fs::absolute(path).parent_path();
    std::error_code error;
    if (!fs::is_directory(directory, error)) {
      return BadInputError("cannot write " + path + ": directory " + directory.string() +
                           " does not exist");
    }
  }
  const UrdfRobot& robot = file->robot();
  for (const std::string& warning : file->warnings()) {
    std::cerr << "inscribe: " << options.urdf_path << ": " << warning << "\n";
  }

  spherize->packages = PackageSearchFromEnvironment(options.package_paths);
  spherize->urdf_dir = file->directory;
  absl::StatusOr<RobotSpherizeResult> spherized = SpherizeRobot(robot, *spherize);
  if (!spherized.ok()) return UsageError(spherized.status().message());
  const std::vector<LinkSpherizeResult>& results = spherized->links;
  for (const LinkSpherizeResult& link : results) {
    for (const std::string& warning : link.warnings) {
      std::cerr << "inscribe: link '" << link.link << "': " << warning << "\n";
    }
    if (link.status == LinkStatus::kSkipped) {
      std::cerr << "inscribe: link '" << link.link << "' skipped: " << link.error << "\n";
    }
  }

  // The self-collision matrix, for the SRDF and the YAML's self_collision_ignore. A joint tree
  // the kinematics refuses only matters when an SRDF was asked for.
  std::optional<robot::SelfCollisionMatrix> matrix;
  absl::StatusOr<robot::Kinematics> kinematics = robot::Kinematics::Create(robot);
  if (kinematics.ok()) {
    robot::SelfCollisionOptions collision;
    collision.samples = options.samples;
    collision.seed = options.seed;
    absl::StatusOr<robot::SelfCollisionMatrix> made = robot::ComputeSelfCollisionMatrix(
        *kinematics, robot::LinkCollisionGeometries(results), collision);
    if (!made.ok()) return BugError(made.status().message());  // the spherizer's own spheres
    matrix = *std::move(made);
  } else if (!options.srdf_path.empty()) {
    return BadInputError(options.urdf_path + ": no self-collision matrix: " +
                         std::string(kinematics.status().message()));
  } else {
    std::cerr << "inscribe: no self-collision matrix (the YAML has no self_collision_ignore): "
              << kinematics.status().message() << "\n";
  }

  absl::StatusOr<std::string> spherized_model =
      is_mjcf
          ? robot::SpherizedMjcf(*file, results, fs::absolute(options.output_path).parent_path())
          : SpherizedUrdf(file->bytes, results, file->directory,
                          fs::absolute(options.output_path).parent_path());
  // The parsers accepted these documents.
  if (!spherized_model.ok()) return BugError(spherized_model.status().message());
  std::vector<std::pair<std::string, std::string>> outputs = {
      {options.output_path, *std::move(spherized_model)}};
  std::vector<std::string> left_out;
  std::string yaml;
  if (matrix) {
    // The padding is in the radii already: no extra self-collision buffer.
    absl::StatusOr<std::string> with_matrix =
        SpherizedCuroboYaml(results, robot.name, *matrix, {}, &left_out);
    if (!with_matrix.ok()) return BugError(with_matrix.status().message());
    yaml = *std::move(with_matrix);
  } else {
    yaml = SpherizedCuroboYaml(results, robot.name, &left_out);
  }
  for (const std::string& link : left_out) {
    std::cerr << "inscribe: link '" << link << "' is spherized in " << options.output_path
              << " but left out of " << yaml_path
              << ": cuRobo YAML link names are letters, digits and _ - . /\n";
  }
  outputs.emplace_back(yaml_path, yaml);
  for (const auto& [path, contents] : outputs) {
    if (absl::Status written = WriteFileAtomically(path, contents); !written.ok()) {
      return BadInputError(written.message());
    }
  }
  // The SRDF's disabled pairs, merged into the SRDF already there (its groups and other
  // pairs kept); the --spheres files with every spherized link's spheres too.
  const robot::RobotSpheres model =
      robot::RobotSpheresFromSpherized(results, robot.name, matrix ? &*matrix : nullptr, {});
  const std::string comment = matrix ? robot::SelfCollisionComment(*matrix) : "inscribe urdf";
  if (!options.srdf_path.empty()) {
    robot::RobotSpheres pairs = model;
    pairs.links.clear();
    if (absl::Status written = WriteRobotSpheres(pairs, robot::RobotSpheresFormat::kSrdf,
                                                 options.srdf_path, "", comment);
        !written.ok()) {
      return written;
    }
  }
  for (std::size_t i = 0; i < sphere_paths.size(); ++i) {
    NoteDroppedParts(model, sphere_formats[i]);
    if (absl::Status written = WriteRobotSpheres(model, sphere_formats[i], sphere_paths[i],
                                                 options.urdf_path, comment);
        !written.ok()) {
      return written;
    }
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.json) {
    PrintJson(options, *spherize, *file, *spherized, matrix, yaml_path, left_out, seconds);
  } else {
    PrintTable(*file, *spherized, matrix, options.output_path, yaml_path, options.srdf_path,
               sphere_paths, left_out, seconds);
  }
  const auto skipped = std::count_if(results.begin(), results.end(), [](const auto& result) {
    return result.status == LinkStatus::kSkipped;
  });
  if (skipped > 0) {
    return UnusableMeshError(
        absl::StrFormat("%d of %d links skipped (see above)", skipped, results.size()));
  }
  if (!left_out.empty()) {
    return UnusableMeshError(
        absl::StrFormat("%d links left out of %s (see above)", left_out.size(), yaml_path));
  }
  return absl::OkStatus();
}

}  // namespace

void AddUrdfCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<UrdfCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "urdf",
      "Spherize a robot: every link's collision meshes (visual when it has none; box, "
      "cylinder and sphere too) become spheres in the link's frame, certified covers by "
      "default; writes the URDF with sphere collisions and cuRobo's collision_spheres YAML. "
      "A MuJoCo model (MJCF) is read too: every body's collision geoms (capsules and "
      "ellipsoids too) become spheres in the body's frame, written as the MJCF with sphere "
      "geoms and as cuRobo YAML. "
      "Links that cannot be done are named, kept as they were, and make the exit status 1");
  cmd->alias("robot");
  cmd->add_option("ROBOT", options->urdf_path,
                  "URDF file (expand xacro first: xacro robot.urdf.xacro > robot.urdf) or MuJoCo "
                  "model (MJCF), told apart by the root element")
      ->required();
  cmd->add_option("--solid-class", options->solid_classes,
                  "MJCF: a default class whose geoms (and its sub-classes') are the bodies' "
                  "solids, instead of the geoms that take part in contacts; repeatable");
  cmd->add_option("--solid-group", options->solid_groups,
                  "MJCF: a geom group (e.g. 3, MuJoCo Menagerie's collision group) whose geoms "
                  "are the bodies' solids; repeatable");
  cmd->add_option("--package-path", options->package_paths,
                  "Directory holding ROS packages (or a package itself) for package:// URIs; "
                  "repeatable, searched before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH");
  cmd->add_option("--kind", options->kind,
                  "cover: spheres proven to hold each link, with a certified delta; internal: "
                  "medial spheres inside it; dilated: grown medial spheres")
      ->check(CLI::IsMember({"cover", "internal", "dilated"}))
      ->capture_default_str();
  CLI::Option* robot_budget = cmd->add_option(
      "--max-spheres", options->max_spheres,
      "At most N spheres for the whole robot, shared among links: covers by greedy marginal "
      "gain on their estimated delta, other kinds by volume");
  CLI::Option* budget = cmd->add_option(
      "--max-spheres-per-link", options->max_spheres_per_link,
      "At most N spheres per link, shared among its elements by volume (the default, N = 32)");
  CLI::Option* protrusion = cmd->add_option(
      "--max-protrusion", options->max_protrusion,
      "Covers: every link's certified delta at most D metres (padding included), with the "
      "fewest spheres");
  CLI::Option* voxel = cmd->add_option("--voxel-size", options->voxel_size,
                                       "Internal and dilated sets: voxel side sigma for every "
                                       "element, metres");
  for (CLI::Option* a : {robot_budget, budget, protrusion, voxel}) {
    for (CLI::Option* b : {robot_budget, budget, protrusion, voxel}) {
      if (a != b) a->excludes(b);
    }
  }
  cmd->add_option("--link-max-spheres", options->link_budgets,
                  "LINK=N: that link gets N spheres of its own, outside the shared budget (0: "
                  "leave it out, e.g. a static base); repeatable");
  AddRepairOptions(cmd, &options->repair);
  cmd->add_option("--link-repair", options->link_repairs,
                  "LINK=LEVEL: that link's meshes repaired at this --repair level instead; "
                  "repeatable");
  cmd->add_option("--padding", options->padding,
                  "Metres added to every radius, as a planner's collision buffer (covers: >= 0, "
                  "and their delta grows by it)");
  cmd->add_option("--clip", options->clips,
                  "LINK=NX,NY,NZ,OFFSET: cut off what lies beyond the plane NX x + NY y + NZ z "
                  "= OFFSET in the link's frame (the side the normal points to) before "
                  "spherizing, e.g. a table under the base; repeatable");
  cmd->add_option("-o,--output", options->output_path,
                  "The spherized URDF to write; for an MJCF model, the spherized MJCF (one file, "
                  "includes inlined)")
      ->required()
      ->check(WritableFile());
  cmd->add_option("--yaml", options->yaml_path,
                  "cuRobo collision_spheres YAML to write (default: -o with extension .yml)")
      ->check(WritableFile());
  cmd->add_option("--srdf", options->srdf_path,
                  "Write MoveIt's SRDF with the self-collision matrix's disabled pairs "
                  "(disable_collisions, reason Adjacent, Default, Always or Never); into an SRDF "
                  "already there they are merged, its groups, states and other pairs kept")
      ->check(WritableFile());
  cmd->add_option("--spheres", options->sphere_paths,
                  "Also write the spheres (and the matrix's disabled pairs) as a planner reads "
                  "them, in the format --format names or the extension says: .yml cuRobo's "
                  "robot configuration, .xrdf cuMotion, .srdf MoveIt (merged into an SRDF "
                  "already there), .urdf VAMP's spherized URDF; FORMAT:PATH names the format "
                  "of one file (e.g. morphit:arm_spheres.urdf); repeatable");
  cmd->add_option("--format", options->sphere_format,
                  "The layout of .urdf --spheres files, urdf (VAMP, cricket; the default) or "
                  "morphit (a child link per sphere), and the format of files whose extension "
                  "names none (curobo, xrdf, srdf, urdf, morphit)")
      ->check(CLI::IsMember({"curobo", "yaml", "xrdf", "srdf", "urdf", "vamp", "morphit"},
                            CLI::ignore_case));
  cmd->add_option("--samples", options->samples,
                  "Random joint configurations the self-collision matrix is sampled at (MoveIt's "
                  "default density)")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed,
                  "Seed of the configurations: the same seed, the same "
                  "matrix on every machine")
      ->capture_default_str();
  cmd->add_flag("--json", options->json,
                "Print one JSON report on stdout: per link status, spheres, budget, delta, "
                "certified, seconds, error");
  SetExitStatusHelp(cmd, "a link was skipped or left out of the output (the summary says why)");
  cmd->callback([options, outcome] { outcome->status = RunUrdf(*options); });
}

}  // namespace inscribe::cli
