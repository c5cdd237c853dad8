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

#include "absl/strings/str_format.h"
#include "command_outcome.h"
#include "inscribe/atomic_file.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/robot/urdf_spherize.h"
#include "nlohmann/json.hpp"

namespace inscribe::cli {

using robot::LinkSpherizeResult;
using robot::LinkStatus;
using robot::LinkStatusName;
using robot::PackageSearchFromEnvironment;
using robot::ParseUrdf;
using robot::SpherizedCuroboYaml;
using robot::SpherizedUrdf;
using robot::SpherizeLink;
using robot::UrdfLink;
using robot::UrdfRobot;
using robot::UrdfSpherizeOptions;
namespace {

namespace fs = std::filesystem;

// Larger files are refused before reading: real URDFs are kilobytes to a few megabytes.
constexpr std::uintmax_t kMaxUrdfBytes = 256u << 20;

struct UrdfCliOptions {
  std::string urdf_path;
  std::vector<std::string> package_paths;
  std::optional<std::int64_t> max_spheres_per_link;
  std::optional<double> voxel_size;
  std::string output_path;
  std::string yaml_path;
  bool json = false;
};

// The whole file, or why not (NOT_FOUND, INVALID_ARGUMENT; the message names the path).
absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return absl::NotFoundError(path + ": no such file");
  if (fs::is_directory(path, error)) return absl::InvalidArgumentError(path + ": is a directory");
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > kMaxUrdfBytes) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: %d bytes is more than the %d a URDF may have", path, size, kMaxUrdfBytes));
  }
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) return absl::InvalidArgumentError(path + ": cannot open it for reading");
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(path + ": read error");
  return contents.str();
}

// --yaml, or OUT with its extension replaced by .yml.
std::string YamlPath(const UrdfCliOptions& options) {
  if (!options.yaml_path.empty()) return options.yaml_path;
  return fs::path(options.output_path).replace_extension(".yml").string();
}

bool SameFile(const std::string& a, const std::string& b) {
  return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
}

void PrintJson(const UrdfCliOptions& options, const UrdfRobot& robot,
               const std::vector<LinkSpherizeResult>& results, const std::string& yaml_path,
               const std::vector<std::string>& left_out, double seconds) {
  nlohmann::json report;
  report["urdf"] = options.urdf_path;
  report["robot"] = robot.name;
  report["output"] = options.output_path;
  report["yaml"] = yaml_path;
  if (options.voxel_size) {
    report["voxel_size"] = *options.voxel_size;
  } else {
    report["max_spheres_per_link"] = *options.max_spheres_per_link;
  }
  int spherized = 0, skipped = 0;
  std::int64_t spheres = 0;
  nlohmann::json links = nlohmann::json::array();
  for (const LinkSpherizeResult& result : results) {
    nlohmann::json link;
    link["link"] = result.link;
    link["status"] = LinkStatusName(result.status);
    link["elements"] = result.elements;
    link["from_visual"] = result.from_visual;
    link["spheres"] = result.spheres.size();
    link["generation_runs"] = result.generation_runs;
    link["seconds"] = result.seconds;
    if (result.status == LinkStatus::kSkipped) link["error"] = result.error;
    links.push_back(std::move(link));
    spherized += result.status == LinkStatus::kSpherized;
    skipped += result.status == LinkStatus::kSkipped;
    spheres += static_cast<std::int64_t>(result.spheres.size());
  }
  report["links"] = std::move(links);
  report["spherized"] = spherized;
  report["skipped"] = skipped;
  report["spheres"] = spheres;
  report["left_out_of_yaml"] = left_out;
  report["seconds"] = seconds;
  // Names and messages come from the URDF, whose bytes tinyxml2 does not check as UTF-8.
  std::cout << report.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
}

void PrintTable(const std::vector<LinkSpherizeResult>& results, const std::string& output_path,
                const std::string& yaml_path, const std::vector<std::string>& left_out,
                double seconds) {
  std::size_t width = 4;
  for (const LinkSpherizeResult& result : results) width = std::max(width, result.link.size());
  const int w = static_cast<int>(width);
  std::cout << absl::StrFormat("%-*s  %-11s  %7s  %8s  %s\n", w, "link", "status", "spheres",
                               "seconds", "note");
  int skipped = 0;
  for (const LinkSpherizeResult& result : results) {
    std::string note = result.status == LinkStatus::kSkipped ? result.error : "";
    if (result.status == LinkStatus::kSpherized && result.from_visual) note = "visual geometry";
    std::cout << absl::StrFormat("%-*s  %-11s  %7d  %8.3f  %s\n", w, result.link,
                                 LinkStatusName(result.status), result.spheres.size(),
                                 result.seconds, note);
    skipped += result.status == LinkStatus::kSkipped;
  }
  std::cout << absl::StrFormat("wrote %s and %s in %.3f s", output_path, yaml_path, seconds);
  if (skipped > 0) std::cout << absl::StrFormat("; %d link(s) skipped, kept as they were", skipped);
  if (!left_out.empty()) {
    std::cout << absl::StrFormat("; %d link(s) left out of the YAML (names)", left_out.size());
  }
  std::cout << "\n";
}

absl::Status RunUrdf(UrdfCliOptions options) {
  const auto start = std::chrono::steady_clock::now();
  if (!options.voxel_size && !options.max_spheres_per_link) {
    options.max_spheres_per_link = robot::kDefaultMaxSpheresPerLink;
  }
  if (options.voxel_size && !(*options.voxel_size > 0.0 && std::isfinite(*options.voxel_size))) {
    return UsageError("--voxel-size must be a positive number of metres");
  }
  if (options.max_spheres_per_link && *options.max_spheres_per_link <= 0) {
    return UsageError("--max-spheres-per-link must be at least 1");
  }
  const std::string yaml_path = YamlPath(options);
  if (SameFile(yaml_path, options.output_path)) {
    return UsageError("the YAML would overwrite -o " + options.output_path +
                      "; give --yaml PATH or an -o ending in .urdf");
  }

  // Before any work: a missing output directory would otherwise only show at the end.
  for (const std::string& path : {options.output_path, yaml_path}) {
    const fs::path directory = fs::absolute(path).parent_path();
    std::error_code error;
    if (!fs::is_directory(directory, error)) {
      return BadInputError("cannot write " + path + ": directory " + directory.string() +
                           " does not exist");
    }
  }
  absl::StatusOr<std::string> bytes = ReadWholeFile(options.urdf_path);
  if (!bytes.ok()) return BadInputError(bytes.status().message());
  absl::StatusOr<UrdfRobot> robot = ParseUrdf(*bytes);
  if (!robot.ok()) {
    return BadInputError(options.urdf_path + ": " + std::string(robot.status().message()));
  }

  UrdfSpherizeOptions spherize;
  spherize.max_spheres_per_link = options.max_spheres_per_link.value_or(0);
  spherize.voxel_size = options.voxel_size.value_or(0.0);
  spherize.packages = PackageSearchFromEnvironment(options.package_paths);
  spherize.urdf_dir = fs::absolute(options.urdf_path).parent_path().string();
  // Links one after another: the generation inside each is already parallel over voxels, and
  // per-link times then mean what they say.
  std::vector<LinkSpherizeResult> results;
  for (const UrdfLink& link : robot->links) {
    results.push_back(SpherizeLink(link, spherize));
    if (results.back().status == LinkStatus::kSkipped) {
      std::cerr << "inscribe: link '" << link.name << "' skipped: " << results.back().error << "\n";
    }
  }

  absl::StatusOr<std::string> urdf = SpherizedUrdf(*bytes, results);
  if (!urdf.ok()) return BugError(urdf.status().message());  // ParseUrdf accepted them
  std::vector<std::string> left_out;
  const std::string yaml = SpherizedCuroboYaml(results, robot->name, &left_out);
  for (const std::string& link : left_out) {
    std::cerr << "inscribe: link '" << link << "' is spherized in " << options.output_path
              << " but left out of " << yaml_path
              << ": cuRobo YAML link names are letters, digits and _ - . /\n";
  }
  for (const auto& [path, contents] :
       {std::pair{options.output_path, *urdf}, std::pair{yaml_path, yaml}}) {
    if (absl::Status written = WriteFileAtomically(path, contents); !written.ok()) {
      return BadInputError(written.message());
    }
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.json) {
    PrintJson(options, *robot, results, yaml_path, left_out, seconds);
  } else {
    PrintTable(results, options.output_path, yaml_path, left_out, seconds);
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
      "cylinder and sphere too) become internal spheres in the link's frame; writes the URDF "
      "with sphere collisions and cuRobo's collision_spheres YAML. Links that cannot be done "
      "are named, kept as they were, and make the exit status 1");
  cmd->add_option("ROBOT", options->urdf_path, "URDF file (xacro must be expanded first)")
      ->required();
  cmd->add_option("--package-path", options->package_paths,
                  "Directory holding ROS packages (or a package itself) for package:// URIs; "
                  "repeatable, searched before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH");
  CLI::Option* budget = cmd->add_option(
      "--max-spheres-per-link", options->max_spheres_per_link,
      "At most N spheres per link, shared among its elements by volume (default mode, N = 32)");
  CLI::Option* voxel = cmd->add_option("--voxel-size", options->voxel_size,
                                       "Voxel side sigma for every element, metres");
  voxel->excludes(budget);
  budget->excludes(voxel);
  cmd->add_option("-o,--output", options->output_path, "The spherized URDF to write")->required();
  cmd->add_option("--yaml", options->yaml_path,
                  "cuRobo collision_spheres YAML to write (default: -o with extension .yml)");
  cmd->add_flag("--json", options->json,
                "Print one JSON report on stdout: per link status, spheres, seconds, error");
  cmd->callback([options, outcome] { outcome->status = RunUrdf(*options); });
}

}  // namespace inscribe::cli
