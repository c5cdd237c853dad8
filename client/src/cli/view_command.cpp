#include "view_command.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/base/atomic_file.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/view/robot_view.h"
#include "inscribe/view/view_report.h"
#include "output_files.h"
#include "solid_loading.h"

namespace inscribe::cli {

namespace {

namespace fs = std::filesystem;

struct ViewCliOptions {
  std::string mesh_path;
  std::string spheres_path;
  std::string output_path;  // default: spheres_path with extension .html
  std::string format;
  std::string link;
  int sph_level = -1;
  std::int64_t samples = 100'000;
  std::uint64_t seed = 1;
  SolidLoadOptions load;  // --scale and the repair options
  std::string title;
  std::vector<std::string> package_paths;  // robots: where package:// URIs are looked for
  // Options given that only the mesh form reads, by name, to refuse them for a robot.
  std::vector<std::string> mesh_only_given;
};

// The first argument names a robot (`inscribe view ROBOT.urdf SPHERES`), not a mesh.
bool IsRobot(const std::string& path) {
  return absl::AsciiStrToLower(fs::path(path).extension().string()) == ".urdf";
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The voxel size the spheres were generated with, when the file says (inscribe's JSON).
double FileVoxelSize(const SphereFile& file) {
  for (const auto& [key, value] : file.params) {
    if (key == "voxel_size" && std::holds_alternative<double>(value)) {
      return std::get<double>(value);
    }
  }
  return 0.0;
}

// Why the page could not be written to `path`, or "" when it probably can: checked before the
// sampling so that a mistyped -o fails at once. WriteFileAtomically still reports any failure.
std::string OutputPathProblem(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return "it is a directory";
  fs::path directory = fs::path(path).parent_path();
  if (directory.empty()) directory = ".";
  if (!fs::exists(directory, error)) return "directory " + directory.string() + " does not exist";
  if (!fs::is_directory(directory, error)) return directory.string() + " is not a directory";
  if (::access(directory.c_str(), W_OK | X_OK) != 0) {
    return "directory " + directory.string() + " is not writable (" + std::strerror(errno) + ")";
  }
  return "";
}

// The page's path (-o, or SPHERES with .html), checked before any work: it must not be the
// sphere file, and its directory must be writable.
absl::StatusOr<std::string> PagePath(const ViewCliOptions& options) {
  const std::string output =
      !options.output_path.empty()
          ? options.output_path
          : fs::path(options.spheres_path).replace_extension(".html").string();
  std::error_code output_error, spheres_error;
  const fs::path output_canonical = fs::weakly_canonical(output, output_error);
  const fs::path spheres_canonical = fs::weakly_canonical(options.spheres_path, spheres_error);
  if (!output_error && !spheres_error && output_canonical == spheres_canonical) {
    return UsageError("the page would overwrite the sphere file " + options.spheres_path +
                      "; choose another path with -o");
  }
  if (const std::string problem = OutputPathProblem(output); !problem.empty()) {
    return BadInputError("cannot write the page to " + output + ": " + problem);
  }
  return output;
}

// `inscribe view ROBOT.urdf SPHERES`: the robot page (view/robot_view.h).
absl::Status RunRobotView(const ViewCliOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!options.mesh_only_given.empty()) {
    return UsageError(options.mesh_only_given.front() +
                      " applies to a mesh, not to a robot (ROBOT.urdf)");
  }
  absl::StatusOr<std::string> output = PagePath(options);
  if (!output.ok()) return output.status();
  view::RobotViewOptions robot;
  robot.robot_name = fs::path(options.mesh_path).filename().string();
  robot.spheres_name = fs::path(options.spheres_path).filename().string();
  robot.title =
      !options.title.empty() ? options.title : robot.robot_name + " \u00b7 " + robot.spheres_name;
  robot.packages = robot::PackageSearchFromEnvironment(options.package_paths);
  const absl::StatusOr<std::string> page =
      view::MakeRobotViewPageFromFiles(options.mesh_path, options.spheres_path, robot);
  if (!page.ok()) {
    const absl::StatusCode code = page.status().code();
    const bool bad_input =
        code == absl::StatusCode::kInvalidArgument || code == absl::StatusCode::kNotFound;
    return bad_input ? BadInputError(page.status().message()) : BugError(page.status().message());
  }
  if (absl::Status written = WriteFileAtomically(*output, *page); !written.ok()) {
    return BadInputError(written.message());
  }
  std::cout << *output << "\n";
  ReportWritten(
      *output, absl::StrFormat("%.0f KB page, %.2f s", page->size() / 1024.0, SecondsSince(start)));
  return absl::OkStatus();
}

absl::Status RunView(const ViewCliOptions& options) {
  if (IsRobot(options.mesh_path)) return RunRobotView(options);
  if (!options.package_paths.empty()) {
    return UsageError("--package-path applies to a robot (ROBOT.urdf), not to a mesh");
  }
  const auto start = std::chrono::steady_clock::now();
  SphereFileReadOptions read;
  if (!options.format.empty()) read.format = *ParseSphereFileFormat(options.format);
  read.sph_level = options.sph_level;
  read.yaml_link = options.link;
  absl::StatusOr<SphereFile> file = ReadSphereFile(options.spheres_path, read);
  if (!file.ok()) return BadInputError(file.status().message());
  const std::vector<Sphere>& spheres = file->set.spheres;
  if (spheres.empty()) return BadInputError(options.spheres_path + ": no spheres to show");
  absl::StatusOr<std::string> page_path = PagePath(options);
  if (!page_path.ok()) return page_path.status();
  const std::string& output = *page_path;

  absl::StatusOr<LoadedSolid> solid = LoadSolid(options.mesh_path, options.load);
  if (!solid.ok()) return solid.status();
  if (!file->mesh_sha256.empty() && file->mesh_sha256 != solid->solid.sha256) {
    std::cerr << "inscribe: warning: " << options.spheres_path << " was made for mesh "
              << file->mesh_sha256 << ", not " << solid->solid.sha256 << "\n";
  }

  view::ViewReportOptions report;
  report.samples = options.samples;
  report.seed = options.seed;
  report.voxel_size = FileVoxelSize(*file);
  report.mesh_name = fs::path(options.mesh_path).filename().string();
  report.spheres_name = fs::path(options.spheres_path).filename().string();
  report.title =
      !options.title.empty() ? options.title : report.mesh_name + " \u00b7 " + report.spheres_name;
  report.load_seconds = solid->seconds;
  const absl::StatusOr<std::string> page = view::MakeViewReportPage(solid->solid, spheres, report);
  if (!page.ok()) {
    // INVALID_ARGUMENT and RESOURCE_EXHAUSTED (an envelope too small to sample: thousands of
    // copies of one ball) are the sphere set's; anything else is a bug.
    const absl::StatusCode code = page.status().code();
    const bool bad_input =
        code == absl::StatusCode::kInvalidArgument || code == absl::StatusCode::kResourceExhausted;
    return bad_input
               ? BadInputError(options.spheres_path + ": " + std::string(page.status().message()))
               : BugError(page.status().message());
  }
  if (absl::Status written = WriteFileAtomically(output, *page); !written.ok()) {
    return BadInputError(written.message());
  }
  std::cout << output << "\n";
  ReportWritten(output, absl::StrFormat("%d spheres, %.0f KB page, %.2f s", spheres.size(),
                                        page->size() / 1024.0, SecondsSince(start)));
  return absl::OkStatus();
}

}  // namespace

void AddViewCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<ViewCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "One self-contained HTML page (three.js embedded, no network needed) showing the mesh "
      "and the spheres in 3D with the quality report and histograms of signed distances "
      "between the boundary and the spheres' envelope (the paper's Fig. 7); or, for "
      "ROBOT.urdf, the whole robot posed by sliders per joint with every link's spheres");
  cmd->add_option("MESH", options->mesh_path,
                  "Mesh file (.off, .obj, .stl, .ply), or a robot (.urdf)")
      ->required();
  cmd->add_option("SPHERES", options->spheres_path,
                  "Sphere file (.json, .sph, .csv, cuRobo .yml/.yaml); for a robot, what "
                  "`inscribe urdf` wrote: the spherized URDF or the cuRobo YAML")
      ->required();
  cmd->add_option("-o,--output", options->output_path,
                  "HTML file to write (default: SPHERES with the extension .html)")
      ->check(WritableFile());
  cmd->add_option("--format", options->format, "Sphere file format (default: from extension)")
      ->check(CLI::IsMember({"json", "sph", "csv", "yaml", "yml"}, CLI::ignore_case));
  cmd->add_option("--link", options->link,
                  "cuRobo YAML with several links: the link whose spheres to show");
  cmd->add_option("--sph-level", options->sph_level, ".sph tree level to show (-1 = the leaves)")
      ->capture_default_str();
  cmd->add_option("--quality-samples,--samples", options->samples,
                  "Points sampled on the boundary and on the envelope for coverage, Hausdorff "
                  "distance and the histograms")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{10'000'000}));
  cmd->add_option("--seed", options->seed, "Seed of the samples")->capture_default_str();
  AddSolidLoadOptions(cmd, &options->load);
  cmd->add_option("--title", options->title,
                  "Heading of the page (default: the mesh and sphere file names)");
  cmd->add_option("--package-path", options->package_paths,
                  "Robots: a directory where package://NAME/... meshes are looked for (NAME "
                  "under it, or it itself when named NAME); before ROS_PACKAGE_PATH and "
                  "AMENT_PREFIX_PATH. Repeatable");
  SetExitStatusHelp(cmd, "the mesh cannot be used");
  cmd->callback([cmd, options, outcome] {
    for (const char* name :
         {"--format", "--link", "--sph-level", "--samples", "--seed", "--fill-holes", "--repair",
          "--weld-tolerance", "--wrap-alpha", "--wrap-offset", "--scale"}) {
      if (cmd->get_option(name)->count() > 0) options->mesh_only_given.push_back(name);
    }
    outcome->status = RunView(*options);
  });
}

}  // namespace inscribe::cli
